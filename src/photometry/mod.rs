//! Luminaire photometry: how much light a real luminaire sends in each direction, read from
//! the two file formats lighting manufacturers publish.
//!
//! This module owns reading photometric files and what follows from a web alone (its flux,
//! its cells of equal flux: `cells.rs`). Two formats:
//!
//! - IES (`.ies`): ANSI/IES LM-63-19, *Approved Method: IES Standard File Format for the
//!   Electronic Transfer of Photometric Data and Related Information*, and its earlier editions
//!   LM-63-1986, LM-63-1991 (`IESNA91`), LM-63-1995 and LM-63-2002;
//! - EULUMDAT (`.ldt`): the line-oriented European format after A. W. Stockmar's *EULUMDAT —
//!   ein Leuchtendatenformat für den europäischen Beleuchtungsplaner* (Licht '90), in the
//!   EULUMDAT format description Ian Ashdown published in the 1990s.
//!
//! Both become one [`Photometry`]: a web of absolute candela values over the file's
//! (horizontal, vertical) angles with the symmetry the file declares, so that whatever uses a
//! luminaire asks for its intensity in a direction ([`Photometry::intensity`]) and its flux
//! ([`Photometry::total_lumens`]) without knowing which file it came from. Why a module of its
//! own: the two formats differ in every detail (free-format numbers against one value a line,
//! candela against cd/klm, five symmetry codes against angle ranges) and all of that stops here.
//!
//! The files: `ies.rs` reads LM-63, `eulumdat.rs` reads EULUMDAT, `web.rs` holds what the web
//! does once read (the symmetry, the bilinear interpolation, the integration over the sphere);
//! this file holds the common types, the one error, [`read`] and the number reader both parsers
//! share.
//!
//! Errors: a malformed file gives one [`PhotometryError`] that names the file, the 1-based line
//! and what is wrong. No input makes a parser panic.

pub mod cells;
mod eulumdat;
mod ies;
pub mod summary;
#[cfg(test)]
mod test_webs;
mod web;

pub use eulumdat::parse_ldt;
pub use ies::parse_ies;

use std::path::Path;

/// The most angles (or tilt pairs) a file may declare: far above any goniophotometer's
/// (a 0.1° web has 3601), low enough that a garbled count fails at once.
const MAX_ANGLES: u64 = 100_000;

/// A luminaire's photometric web, in absolute candela, as read from an IES or EULUMDAT file.
#[derive(Clone, Debug, PartialEq)]
pub struct Photometry {
    /// The goniometer convention the angles follow (LM-63's photometric type; EULUMDAT is
    /// always Type C).
    pub kind: PhotometricType,
    /// Which part of the sphere the horizontal angles cover, and so how the rest is filled.
    pub symmetry: Symmetry,
    /// Vertical angles, degrees, strictly increasing: γ from the nadir (Type C), or the angle
    /// within the plane (Types A and B, −90..90).
    pub vertical: Vec<f64>,
    /// Horizontal angles, degrees, strictly increasing: the C-plane (Type C, 0..360), or the
    /// plane about the polar axis (Types A and B, −90..90). A full Type C circle always ends at
    /// 360: a file that stops short of it is closed by repeating its first plane there.
    pub horizontal: Vec<f64>,
    /// Intensities, candela, `candela[h][v]` for `horizontal[h]` and `vertical[v]`: absolute,
    /// with the IES multiplier and ballast factors or the EULUMDAT lamp flux and conversion
    /// factor applied (see [`parse_ies`] and [`parse_ldt`]); the tilt factors are not.
    pub candela: Vec<Vec<f64>>,
    /// Number of lamps (for EULUMDAT, of the first lamp set).
    pub lamps: u32,
    /// Rated flux of each lamp, lumens; `None` for absolute photometry (IES −1, EULUMDAT's
    /// negative lamp count), where the candela values are the luminaire's own.
    pub lumens_per_lamp: Option<f64>,
    /// Electrical input, watts; `None` where the file gives 0 (unknown).
    pub input_watts: Option<f64>,
    /// The luminous opening, metres.
    pub luminous_opening: Opening,
    /// Text fields as `(keyword, value)` in file order: IES `[KEY] value` lines (a `[MORE]`
    /// line is appended to the value before it, after a newline); free text before `TILT=` in
    /// an LM-63-1986 file has the keyword `""`; EULUMDAT's text lines under the IES keyword of
    /// the same meaning (see [`parse_ldt`]).
    pub keywords: Vec<(String, String)>,
    /// The IES tilt table (`TILT=INCLUDE`); `None` for `TILT=NONE` and for EULUMDAT.
    pub tilt: Option<Tilt>,
    /// What only one of the two formats says.
    pub source: Source,
}

/// LM-63's three goniometer conventions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PhotometricType {
    /// Type C (LM-63 code 1): polar axis vertical; horizontal angle = C-plane about it,
    /// vertical angle = γ from the nadir. Architectural and area luminaires.
    C,
    /// Type B (LM-63 code 2): polar axis horizontal, along the luminaire's width; floodlights.
    B,
    /// Type A (LM-63 code 3): polar axis horizontal, along the luminaire's length;
    /// automotive and signal lights.
    A,
}

/// How the horizontal angles of a web cover the directions (LM-63's rules, which EULUMDAT's
/// Isym 0–4 map onto).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Symmetry {
    /// Type C, one horizontal angle: the same in every C-plane (EULUMDAT Isym 1).
    Rotational,
    /// Type C, 0–90: symmetric about the C0–C180 and C90–C270 planes (Isym 4).
    Quadrant,
    /// Type C, 0–180: symmetric about the C0–C180 plane (Isym 2).
    BilateralC0,
    /// Type C, 90–270: symmetric about the C90–C270 plane (Isym 3; LM-63-2002 on).
    BilateralC90,
    /// Type C 0–360 (Isym 0), or Types A and B −90–90: every plane given.
    Asymmetric,
    /// Types A and B, 0–90: laterally symmetric, the half −90..0 mirrors 0..90.
    Lateral,
}

/// The luminous opening: its shape and its three extents, metres, never negative.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Opening {
    pub shape: OpeningShape,
    /// Extent across the luminaire (LM-63: along the 90° plane), metres.
    pub width: f64,
    /// Extent along the luminaire (LM-63: along the 0° plane), metres.
    pub length: f64,
    /// Vertical extent, metres.
    pub height: f64,
}

/// The opening's shape, from the signs of LM-63's width, length and height (ANSI/IES LM-63-19's
/// table of luminous opening shapes: a negative value marks a round extent).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OpeningShape {
    /// 0, 0, 0.
    Point,
    /// Flat rectangle: +, +, 0.
    Rectangle,
    /// Rectangle with luminous sides: +, +, +.
    Box,
    /// Flat circle or ellipse: −, −, 0.
    Ellipse,
    /// Vertical (elliptical) cylinder: −, −, +.
    VerticalCylinder,
    /// Sphere or ellipsoid: −, −, −.
    Ellipsoid,
    /// Horizontal cylinder along the length (the 0° plane): −, +, −.
    HorizontalCylinderAlongLength,
    /// Horizontal cylinder along the width (the 90° plane): +, −, −.
    HorizontalCylinderAlongWidth,
    /// Vertical circle or ellipse facing the 0° plane: −, 0, −.
    VerticalEllipseFacingLength,
    /// Vertical circle or ellipse facing the 90° plane: 0, −, −.
    VerticalEllipseFacingWidth,
    /// A combination of signs the table does not list.
    Other,
}

impl Opening {
    /// The opening LM-63 describes by signed width, length and height, metres.
    pub fn from_signed(width: f64, length: f64, height: f64) -> Opening {
        use std::cmp::Ordering::{Equal, Greater, Less};
        let sign = |x: f64| x.partial_cmp(&0.0).unwrap_or(Equal);
        let shape = match (sign(width), sign(length), sign(height)) {
            (Equal, Equal, Equal) => OpeningShape::Point,
            (Greater, Greater, Equal) => OpeningShape::Rectangle,
            (Greater, Greater, Greater) => OpeningShape::Box,
            (Less, Less, Equal) => OpeningShape::Ellipse,
            (Less, Less, Greater) => OpeningShape::VerticalCylinder,
            (Less, Less, Less) => OpeningShape::Ellipsoid,
            (Less, Greater, Less) => OpeningShape::HorizontalCylinderAlongLength,
            (Greater, Less, Less) => OpeningShape::HorizontalCylinderAlongWidth,
            (Less, Equal, Less) => OpeningShape::VerticalEllipseFacingLength,
            (Equal, Less, Less) => OpeningShape::VerticalEllipseFacingWidth,
            _ => OpeningShape::Other,
        };
        Opening {
            shape,
            width: width.abs(),
            length: length.abs(),
            height: height.abs(),
        }
    }
}

/// An IES tilt table (`TILT=INCLUDE`): how the lamp's output changes as the luminaire is
/// tilted. Kept as read; [`Photometry::candela`] does not include it.
#[derive(Clone, Debug, PartialEq)]
pub struct Tilt {
    /// LM-63's lamp-to-luminaire geometry: 1 lamp vertical (base up or down), 2 lamp
    /// horizontal and staying horizontal as the luminaire tilts, 3 lamp horizontal and tilting
    /// with the luminaire.
    pub geometry: u8,
    /// Tilt angles, degrees, strictly increasing.
    pub angles: Vec<f64>,
    /// Multiplying factor at each angle, dimensionless, never negative.
    pub factors: Vec<f64>,
}

/// What only one of the two formats records.
#[derive(Clone, Debug, PartialEq)]
pub enum Source {
    Ies(IesInfo),
    Eulumdat(EulumdatInfo),
}

/// The edition of LM-63 a file follows, from its first line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IesVersion {
    /// No version line: LM-63-1986, free text up to `TILT=`.
    Lm63_1986,
    /// `IESNA91`.
    Lm63_1991,
    /// `IESNA:LM-63-1995`.
    Lm63_1995,
    /// `IESNA:LM-63-2002`.
    Lm63_2002,
    /// `IES:LM-63-2019`.
    Lm63_2019,
}

/// The IES numbers that scale the candela values, as the file gives them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IesInfo {
    pub version: IesVersion,
    /// Candela multiplier, dimensionless (applied).
    pub multiplier: f64,
    /// Ballast factor, dimensionless (applied).
    pub ballast_factor: f64,
    /// The number after the ballast factor, dimensionless: the ballast-lamp photometric factor
    /// in LM-63-1986 and -1991 (applied), "future use" in 1995 and 2002 and the file generation
    /// type in LM-63-19 (kept, not applied).
    pub ballast_lamp_factor: f64,
    /// Whether the file's dimensions were in feet (LM-63 units type 1) rather than metres (2);
    /// [`Photometry::luminous_opening`] is in metres either way.
    pub feet: bool,
}

/// The EULUMDAT fields that have no place in the common type.
#[derive(Clone, Debug, PartialEq)]
pub struct EulumdatInfo {
    /// Type indicator Ityp: 0 point source without symmetry, 1 symmetric about the vertical
    /// axis, 2 linear luminaire, 3 point source with other symmetry.
    pub ityp: u8,
    /// Symmetry indicator Isym 0–4.
    pub isym: u8,
    /// Number Mc of C-planes in the full circle.
    pub c_planes: usize,
    /// Luminaire length (or diameter), width (0 = round) and height, metres.
    pub luminaire: [f64; 3],
    /// Height of the luminous area in the C0, C90, C180 and C270 planes, metres.
    pub luminous_heights: [f64; 4],
    /// Downward flux fraction DFF, percent.
    pub downward_flux_fraction: f64,
    /// Light output ratio of the luminaire LORL, percent.
    pub light_output_ratio: f64,
    /// Conversion factor for the luminous intensities, dimensionless (applied).
    pub conversion_factor: f64,
    /// Tilt of the luminaire during measurement, degrees.
    pub measurement_tilt: f64,
    /// The standard lamp sets, in file order (the first one scales the intensities).
    pub lamp_sets: Vec<LampSet>,
    /// Direct ratios for the room indices k = 0.6, 0.8, 1, 1.25, 1.5, 2, 2.5, 3, 4, 5.
    pub direct_ratios: [f64; 10],
}

/// One EULUMDAT standard set of lamps.
#[derive(Clone, Debug, PartialEq)]
pub struct LampSet {
    /// Number of lamps; negative marks absolute photometry.
    pub count: i64,
    /// Type of lamps (text).
    pub lamp_type: String,
    /// Total luminous flux of the set, lumens (of the luminaire, for absolute photometry).
    pub flux: f64,
    /// Colour appearance or temperature (text, e.g. `3000` or `ww`).
    pub colour: String,
    /// Colour rendering group or index (text, e.g. `1B` or `80`).
    pub colour_rendering: String,
    /// Wattage including ballast, watts.
    pub watts: f64,
}

/// Why a photometric file could not be read: one line naming the file (and for a malformed
/// file the 1-based line) and what is wrong.
#[derive(Debug, thiserror::Error)]
pub enum PhotometryError {
    /// The file could not be read from disk.
    #[error("{file}: cannot read: {source}")]
    Io {
        file: String,
        #[source]
        source: std::io::Error,
    },
    /// Neither the extension nor the first line says which format the file is in.
    #[error("{file}: not a known photometric format (name it .ies or .ldt; an IES file's first line starts with IESNA or IES:)")]
    UnknownFormat { file: String },
    /// `TILT=<file>`: the tilt table lives in another file.
    #[error("{file}:{line}: TILT={tilt_file}: tilt data in an external file is not supported (use TILT=INCLUDE or TILT=NONE)")]
    ExternalTilt {
        file: String,
        line: usize,
        tilt_file: String,
    },
    /// The file breaks its format.
    #[error("{file}:{line}: {message}")]
    Malformed {
        file: String,
        line: usize,
        message: String,
    },
}

/// The error for line `line` (1-based) of `file`.
fn malformed(file: &str, line: usize, message: impl Into<String>) -> PhotometryError {
    PhotometryError::Malformed {
        file: file.to_string(),
        line,
        message: message.into(),
    }
}

/// Reads a photometric file, choosing the format by extension (`.ies`, `.ldt`, any case) or,
/// failing that, by its first line (`IES…` is LM-63). Bytes that are not UTF-8 are read as
/// Latin-1, the usual encoding of older files; a UTF-8 byte-order mark and CRLF line ends are
/// accepted. Messages name the file by `path` as given.
pub fn read(path: &Path) -> Result<Photometry, PhotometryError> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|source| PhotometryError::Io {
        file: file.clone(),
        source,
    })?;
    let text = crate::text::decode(&bytes);
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    match ext.as_deref() {
        Some("ies") => parse_ies(&text, &file),
        Some("ldt") => parse_ldt(&text, &file),
        _ if first_line_says_ies(&text) => parse_ies(&text, &file),
        _ => Err(PhotometryError::UnknownFormat { file }),
    }
}

/// Whether the first line starts as an LM-63-1991-or-later file's does.
fn first_line_says_ies(text: &str) -> bool {
    let first = without_bom(text).lines().next().unwrap_or("");
    first.trim_start().to_ascii_uppercase().starts_with("IES")
}

/// `text` without a leading UTF-8 byte-order mark.
fn without_bom(text: &str) -> &str {
    text.strip_prefix('\u{feff}').unwrap_or(text)
}

/// A number as written: `,` as the decimal point where `comma_decimal` (EULUMDAT); `None`
/// unless it is a finite number.
fn parse_number(text: &str, comma_decimal: bool) -> Option<f64> {
    let t = text.trim_matches(|c: char| c.is_whitespace() || c == '\u{1a}');
    let v: f64 = if comma_decimal && t.contains(',') {
        t.replace(',', ".").parse().ok()?
    } else {
        t.parse().ok()?
    };
    v.is_finite().then_some(v)
}

/// The numbers of a file from a given line on, read in order: LM-63's free format
/// (whitespace, commas or line ends between numbers) and EULUMDAT's tables (one number a line,
/// `,` possibly the decimal point). Every read names what it expected when it fails.
struct Tokens<'a> {
    file: &'a str,
    /// Each number's text and 1-based line.
    items: Vec<(&'a str, usize)>,
    next: usize,
    /// The file's last line, where "the file ends early" points.
    last_line: usize,
    comma_decimal: bool,
}

impl<'a> Tokens<'a> {
    /// The numbers on `lines[first..]`.
    fn new(file: &'a str, lines: &[&'a str], first: usize, comma_decimal: bool) -> Tokens<'a> {
        let sep = move |c: char| c.is_whitespace() || c == '\u{1a}' || (c == ',' && !comma_decimal);
        let items = lines
            .iter()
            .enumerate()
            .skip(first)
            .flat_map(|(i, l)| {
                l.split(sep)
                    .filter(|t| !t.is_empty())
                    .map(move |text| (text, i + 1))
            })
            .collect();
        Tokens {
            file,
            items,
            next: 0,
            last_line: lines.len().max(1),
            comma_decimal,
        }
    }

    fn error(&self, line: usize, message: impl Into<String>) -> PhotometryError {
        malformed(self.file, line, message)
    }

    /// The next number and its line; `what` names it in the error.
    fn number(&mut self, what: &str) -> Result<(f64, usize), PhotometryError> {
        let Some(&(text, line)) = self.items.get(self.next) else {
            let end = format!("the file ends early: expected {what}");
            return Err(self.error(self.last_line, end));
        };
        self.next += 1;
        match parse_number(text, self.comma_decimal) {
            Some(v) => Ok((v, line)),
            None => Err(self.error(line, format!("expected {what}, found '{text}'"))),
        }
    }

    /// The next number, which must be a whole number in `lo..=hi`.
    fn whole(&mut self, what: &str, lo: u64, hi: u64) -> Result<(u64, usize), PhotometryError> {
        let (v, line) = self.number(what)?;
        whole_in(v, lo, hi)
            .map(|n| (n, line))
            .ok_or_else(|| self.error(line, format!("{what} must be {lo}..{hi}, got {v}")))
    }

    /// The next number, which must be `> 0` (`>= 0` where `zero_ok`).
    fn positive(&mut self, what: &str, zero_ok: bool) -> Result<(f64, usize), PhotometryError> {
        let (v, line) = self.number(what)?;
        if v > 0.0 || (zero_ok && v == 0.0) {
            Ok((v, line))
        } else {
            let bound = if zero_ok {
                "not be negative"
            } else {
                "be positive"
            };
            Err(self.error(line, format!("{what} must {bound}, got {v}")))
        }
    }

    /// `n` angles, degrees, strictly increasing, with their lines; `what` is singular
    /// ("vertical angle").
    fn angles(&mut self, n: usize, what: &str) -> Result<(Vec<f64>, Vec<usize>), PhotometryError> {
        let (mut values, mut lines) = (Vec::new(), Vec::new());
        for _ in 0..n {
            let (v, line) = self.number(what)?;
            if let Some(&before) = values.last() {
                if v <= before {
                    return Err(self.error(
                        line,
                        format!("{what}s must increase, but {v} follows {before}"),
                    ));
                }
            }
            values.push(v);
            lines.push(line);
        }
        Ok((values, lines))
    }

    /// `n` values that must not be negative, for one plane of the table; `what` says what they
    /// are and of which plane ("candela values for horizontal angle 90").
    fn plane(&mut self, n: usize, what: &str) -> Result<Vec<f64>, PhotometryError> {
        let mut out = Vec::new();
        for _ in 0..n {
            if self.items.get(self.next).is_none() {
                let m = format!(
                    "expected {n} {what}, found {} before the file ends",
                    out.len()
                );
                return Err(self.error(self.last_line, m));
            }
            let (v, line) = self.number(what)?;
            if v < 0.0 {
                return Err(self.error(line, format!("negative value {v} among the {what}")));
            }
            out.push(v);
        }
        Ok(out)
    }

    /// Fails if any number is left; `after` names what should have been last.
    fn finish(&self, after: &str) -> Result<(), PhotometryError> {
        match self.items.get(self.next) {
            None => Ok(()),
            Some(&(text, line)) => {
                let m = format!("unexpected '{text}' after {after}: the counts in the file do not match its values");
                Err(self.error(line, m))
            }
        }
    }
}

/// `v` as a whole number in `lo..=hi`.
fn whole_in(v: f64, lo: u64, hi: u64) -> Option<u64> {
    let ok = v.fract() == 0.0 && v >= lo as f64 && v <= hi as f64;
    ok.then_some(v as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn read_chooses_the_format_by_extension_then_by_first_line() {
        let dir = tempfile::tempdir().unwrap();
        let ies = include_str!("testdata/lm63_2002_c90.ies");
        let ldt = include_str!("testdata/isym1_comma.ldt");
        let cases = [
            ("a.IES", ies, PhotometricType::C),
            ("b.Ldt", ldt, PhotometricType::C),
            ("c.txt", ies, PhotometricType::C),
        ];
        for (name, text, kind) in cases {
            let p = dir.path().join(name);
            std::fs::write(&p, text).unwrap();
            assert_eq!(read(&p).unwrap().kind, kind, "{name}");
        }
        let p = dir.path().join("d.txt");
        std::fs::write(&p, ldt).unwrap();
        let e = read(&p).unwrap_err().to_string();
        assert!(e.contains("d.txt") && e.contains("not a known"), "{e}");
        let e = read(&dir.path().join("missing.ies"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("missing.ies: cannot read"), "{e}");
    }

    #[test]
    fn latin1_bytes_bom_and_crlf_are_read() {
        let text = include_str!("testdata/isym1_comma.ldt");
        // A Latin-1 'é' (0xE9, not UTF-8) in the luminaire name, a BOM, CRLF line ends.
        let mut bytes = b"\xEF\xBB\xBF".to_vec();
        for (i, line) in text.lines().enumerate() {
            if i == 8 {
                bytes.extend_from_slice(b"Lumi\xE8re \xE9clairage");
            } else {
                bytes.extend_from_slice(line.as_bytes());
            }
            bytes.extend_from_slice(b"\r\n");
        }
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("latin1.ldt");
        std::fs::write(&p, &bytes).unwrap();
        let web = read(&p).unwrap();
        let name = web.keywords.iter().find(|(k, _)| k == "LUMINAIRE").unwrap();
        assert_eq!(name.1, "Lumière éclairage");
        let plain = parse_ldt(text, "plain.ldt").unwrap();
        assert_eq!(web.candela, plain.candela);
    }

    #[test]
    fn numbers_are_finite_and_commas_are_decimal_points_only_in_eulumdat() {
        assert_eq!(parse_number("1,5", true), Some(1.5));
        assert_eq!(parse_number("1,5", false), None);
        assert_eq!(parse_number(" -2.5e1 ", false), Some(-25.0));
        for bad in ["nan", "inf", "-infinity", "1e999", "", "1.2.3"] {
            assert_eq!(parse_number(bad, false), None, "{bad}");
        }
        assert_eq!(whole_in(3.0, 1, 3), Some(3));
        assert_eq!(whole_in(3.5, 1, 9), None);
        assert_eq!(whole_in(0.0, 1, 9), None);
    }

    #[test]
    fn opening_shapes_follow_the_signs() {
        let o = Opening::from_signed(-0.2, -0.2, 0.0);
        assert_eq!(o.shape, OpeningShape::Ellipse);
        assert_eq!((o.width, o.length, o.height), (0.2, 0.2, 0.0));
        assert_eq!(
            Opening::from_signed(0.0, 0.0, 0.0).shape,
            OpeningShape::Point
        );
        assert_eq!(Opening::from_signed(1.0, 2.0, 0.1).shape, OpeningShape::Box);
        assert_eq!(
            Opening::from_signed(-1.0, -1.0, -1.0).shape,
            OpeningShape::Ellipsoid
        );
        let c = Opening::from_signed(-0.1, 1.2, -0.1).shape;
        assert_eq!(c, OpeningShape::HorizontalCylinderAlongLength);
        assert_eq!(
            Opening::from_signed(1.0, 0.0, 0.0).shape,
            OpeningShape::Other
        );
    }
}
