//! EULUMDAT files (`.ldt`), after the EULUMDAT format description (A. W. Stockmar, Licht '90;
//! the field list Ian Ashdown published in the 1990s): one field a line, in a fixed order.
//!
//! Lines 1–26 are the header (identification, Ityp, Isym, Mc, Dc, Ng, Dg, five text lines,
//! the luminaire's and the luminous area's dimensions in mm, DFF, LORL, the conversion factor,
//! the measurement tilt, the number n of lamp sets), then the n lamp sets, then the tables:
//! 10 direct ratios, the Mc C-plane angles, the Ng γ angles and the intensities in cd/klm, Ng
//! per stored C-plane. Numbers may use `,` as the decimal point; the tables are read as a
//! stream of numbers, so a file that puts several on a line is read too.

use super::web::{self, Axis};
use super::{
    malformed, parse_number, without_bom, EulumdatInfo, LampSet, Opening, PhotometricType,
    Photometry, PhotometryError, Source, Tokens, MAX_ANGLES,
};

/// The most lamp sets a file may declare (the format leaves room for company extensions; a
/// count beyond this is a garbled file).
const MAX_LAMP_SETS: u64 = 1000;

/// The header lines, one field at a time, each error at its line.
struct Lines<'a> {
    file: &'a str,
    lines: &'a [&'a str],
    next: usize,
}

impl<'a> Lines<'a> {
    /// The next line, trimmed, and its 1-based number.
    fn text(&mut self, what: &str) -> Result<(&'a str, usize), PhotometryError> {
        let line = self.next + 1;
        let Some(text) = self.lines.get(self.next) else {
            let end = self.lines.len().max(1);
            return Err(malformed(
                self.file,
                end,
                format!("the file ends early: expected {what} on line {line}"),
            ));
        };
        self.next += 1;
        Ok((text.trim(), line))
    }

    fn number(&mut self, what: &str) -> Result<(f64, usize), PhotometryError> {
        let (text, line) = self.text(what)?;
        match parse_number(text, true) {
            Some(v) => Ok((v, line)),
            None => Err(malformed(
                self.file,
                line,
                format!("expected {what}, found '{text}'"),
            )),
        }
    }

    /// A whole number in `lo..=hi`.
    fn whole(&mut self, what: &str, lo: i64, hi: i64) -> Result<(i64, usize), PhotometryError> {
        let (v, line) = self.number(what)?;
        if v.fract() == 0.0 && v >= lo as f64 && v <= hi as f64 {
            Ok((v as i64, line))
        } else {
            Err(malformed(
                self.file,
                line,
                format!("{what} must be {lo}..{hi}, got {v}"),
            ))
        }
    }

    /// A number that must not be negative.
    fn non_negative(&mut self, what: &str) -> Result<f64, PhotometryError> {
        let (v, line) = self.number(what)?;
        if v >= 0.0 {
            Ok(v)
        } else {
            Err(malformed(
                self.file,
                line,
                format!("{what} must not be negative, got {v}"),
            ))
        }
    }

    /// A length in mm, as metres.
    fn mm(&mut self, what: &str) -> Result<f64, PhotometryError> {
        Ok(self.non_negative(&format!("{what} (mm)"))? / 1000.0)
    }
}

/// Lines 1–26 and the lamp sets.
struct Header {
    info: EulumdatInfo,
    keywords: Vec<(String, String)>,
    /// Ng, the number of γ angles.
    gammas: usize,
    /// Indices into the Mc C-planes of the planes the file stores, in file order.
    stored: Vec<usize>,
    /// Length (or diameter) and width (0 = round) of the luminous area, metres.
    area: [f64; 2],
}

/// Reads an EULUMDAT file from its text; `name` names it in errors.
///
/// Decisions the format description leaves open, and how they are taken here:
///
/// - Intensities are cd per 1000 lm of lamp flux. Absolute candela = value × Φ / 1000 × the
///   conversion factor (line 24), Φ being the total luminous flux of the *first* lamp set
///   (26c; already the whole set's flux). Further sets are alternative lampings and are only
///   kept in [`EulumdatInfo::lamp_sets`].
/// - The lamp-set lines come field by field, each repeated n times (n lamp counts, then n lamp
///   types, … , then n wattages), as the description lays them out (26a–26f each "n lines").
/// - A negative lamp count marks absolute photometry (26c is then the luminaire's flux):
///   [`Photometry::lumens_per_lamp`] is `None`; [`Photometry::lamps`] is the count's size.
/// - Stored C-planes follow the description's Mc1..Mc2: Isym 0 all Mc planes (closed at C360
///   with C0), 1 the first plane, 2 planes C0..C180, 4 planes C0..C90, and 3 the Mc/2 + 1
///   planes from index 3·Mc/4 + 1 on, wrapping past C360: C270 through C0 to C90. Those are
///   mirrored (I(C) = I(180° − C)) into LM-63's 90–270 range, so [`Photometry::horizontal`]
///   runs 90..270 as for an IES file.
/// - Keywords: line 1 as `MANUFAC`, 8 `TEST`, 9 `LUMINAIRE`, 10 `LUMCAT`, 11 `_FILENAME`,
///   12 `_DATE_USER`, each lamp set's type as `LAMP`; empty lines are left out.
/// - The luminous opening is the luminous area (lines 16, 17; width 0 = round) with the
///   largest of the four heights (lines 18–21), in metres, length and width as the file gives
///   them (the description does not tie them to a C-plane).
pub fn parse_ldt(text: &str, name: &str) -> Result<Photometry, PhotometryError> {
    let lines: Vec<&str> = without_bom(text).lines().collect();
    let mut r = Lines {
        file: name,
        lines: &lines,
        next: 0,
    };
    let header = header(&mut r)?;
    let mut t = Tokens::new(name, &lines, r.next, true);
    let tables = tables(&mut t, &header)?;
    let isym = header.info.isym;
    let symmetry =
        web::classify(PhotometricType::C, &tables.gamma, &tables.horizontal).map_err(|e| {
            let (lines, what) = match e.axis {
                Axis::Vertical => (&tables.g_lines, String::new()),
                Axis::Horizontal => (&tables.h_lines, format!("Isym {isym}: ")),
            };
            let line = lines.get(e.index).copied().unwrap_or(r.next);
            malformed(name, line, format!("{what}{}", e.message))
        })?;
    let set = header.info.lamp_sets.first();
    let count = set.map_or(0, |s| s.count);
    let flux = set.map_or(0.0, |s| s.flux);
    let watts = set.map_or(0.0, |s| s.watts);
    let luminous_opening = opening(&header);
    let mut info = header.info;
    info.direct_ratios = tables.direct_ratios;
    Ok(Photometry {
        kind: PhotometricType::C,
        symmetry,
        vertical: tables.gamma,
        horizontal: tables.horizontal,
        candela: tables.candela,
        lamps: u32::try_from(count.unsigned_abs()).unwrap_or(u32::MAX),
        lumens_per_lamp: (count > 0).then(|| flux / count as f64),
        input_watts: (watts > 0.0).then_some(watts),
        luminous_opening,
        keywords: header.keywords,
        tilt: None,
        source: Source::Eulumdat(info),
    })
}

/// The tables after the lamp sets, the stored planes in candela as LM-63 ranges them.
struct Tables {
    direct_ratios: [f64; 10],
    gamma: Vec<f64>,
    g_lines: Vec<usize>,
    horizontal: Vec<f64>,
    h_lines: Vec<usize>,
    candela: Vec<Vec<f64>>,
}

/// Reads the direct ratios, the angles and the intensities (made candela), then turns
/// Isym 3's C270..C90 into 90..270 and closes Isym 0's circle at C360.
fn tables(t: &mut Tokens, header: &Header) -> Result<Tables, PhotometryError> {
    let mut direct_ratios = [0.0; 10];
    for d in &mut direct_ratios {
        *d = t.number("a direct ratio")?.0;
    }
    let (c_angles, c_lines) = t.angles(header.info.c_planes, "C-plane angle")?;
    if let Some(i) = c_angles.iter().position(|&c| !(0.0..360.0).contains(&c)) {
        let line = c_lines.get(i).copied().unwrap_or(t.last_line);
        return Err(t.error(line, "C-plane angles must lie in 0..360 (C360 is C0)"));
    }
    let (gamma, g_lines) = t.angles(header.gammas, "gamma angle")?;
    let (mut horizontal, mut h_lines, mut candela) = (Vec::new(), Vec::new(), Vec::new());
    let scale = scale(&header.info);
    for &k in &header.stored {
        let (Some(&c), Some(&line)) = (c_angles.get(k), c_lines.get(k)) else {
            continue;
        };
        let plane = t.plane(header.gammas, &format!("intensities for C-plane {c}"))?;
        horizontal.push(c);
        h_lines.push(line);
        candela.push(plane.into_iter().map(|v| v * scale).collect::<Vec<f64>>());
    }
    t.finish("the last intensity")?;
    if header.info.isym == 3 {
        // C270..C360/C0..C90 mirrored through the C90–C270 plane onto 90..270.
        horizontal = horizontal
            .iter()
            .rev()
            .map(|c| (180.0 - c).rem_euclid(360.0))
            .collect();
        h_lines.reverse();
        candela.reverse();
    }
    let short = horizontal.last().is_some_and(|&c| c < 360.0);
    if header.info.isym == 0 && horizontal.len() > 1 && short {
        web::close_circle(&mut horizontal, &mut h_lines, &mut candela);
    }
    Ok(Tables {
        direct_ratios,
        gamma,
        g_lines,
        horizontal,
        h_lines,
        candela,
    })
}

/// The luminous area (width 0 = round) with the largest of its four heights, metres.
fn opening(header: &Header) -> Opening {
    let [length, width] = header.area;
    let heights = header.info.luminous_heights;
    let height = heights.iter().fold(0.0, |a: f64, &b| a.max(b));
    if width == 0.0 {
        Opening::from_signed(-length, -length, height)
    } else {
        Opening::from_signed(width, length, height)
    }
}

/// Candela per (cd/klm): the first lamp set's flux / 1000 × the conversion factor.
fn scale(info: &EulumdatInfo) -> f64 {
    let flux = info.lamp_sets.first().map_or(0.0, |s| s.flux);
    flux / 1000.0 * info.conversion_factor
}

/// Lines 1–26 and the lamp sets.
fn header(r: &mut Lines) -> Result<Header, PhotometryError> {
    let mut keywords = Vec::new();
    let mut keep = |key: &str, text: &str| {
        if !text.is_empty() {
            keywords.push((key.to_string(), text.to_string()));
        }
    };
    keep("MANUFAC", r.text("the company identification")?.0);
    let (ityp, _) = r.whole("Ityp", 0, 3)?;
    let (isym, _) = r.whole("Isym", 0, 4)?;
    let (mc, mc_line) = r.whole("Mc (the number of C-planes)", 1, MAX_ANGLES as i64)?;
    let mc = mc as usize;
    let stored = stored_planes(isym, mc).map_err(|m| malformed(r.file, mc_line, m))?;
    r.number("Dc (the distance between C-planes)")?;
    let (ng, _) = r.whole("Ng (the number of gamma angles)", 1, MAX_ANGLES as i64)?;
    r.number("Dg (the distance between gamma angles)")?;
    for key in ["TEST", "LUMINAIRE", "LUMCAT", "_FILENAME", "_DATE_USER"] {
        keep(key, r.text(&format!("the {key} text line"))?.0);
    }
    let luminaire = [
        r.mm("the luminaire's length or diameter")?,
        r.mm("the luminaire's width")?,
        r.mm("the luminaire's height")?,
    ];
    let area = [
        r.mm("the luminous area's length or diameter")?,
        r.mm("the luminous area's width")?,
    ];
    let mut luminous_heights = [0.0; 4];
    for (h, c) in luminous_heights
        .iter_mut()
        .zip(["C0", "C90", "C180", "C270"])
    {
        *h = r.mm(&format!("the luminous area's height in the {c} plane"))?;
    }
    let downward_flux_fraction = r.non_negative("the downward flux fraction DFF")?;
    let light_output_ratio = r.non_negative("the light output ratio LORL")?;
    let (conversion_factor, cf_line) =
        r.number("the conversion factor for luminous intensities")?;
    if conversion_factor <= 0.0 {
        let m = format!("the conversion factor must be positive, got {conversion_factor}");
        return Err(malformed(r.file, cf_line, m));
    }
    let measurement_tilt = r.number("the tilt during measurement")?.0;
    let (n, _) = r.whole("n (the number of lamp sets)", 1, MAX_LAMP_SETS as i64)?;
    let lamp_sets = lamp_sets(r, n as usize)?;
    for set in &lamp_sets {
        keep("LAMP", &set.lamp_type);
    }
    Ok(Header {
        info: EulumdatInfo {
            ityp: ityp as u8,
            isym: isym as u8,
            c_planes: mc,
            luminaire,
            luminous_heights,
            downward_flux_fraction,
            light_output_ratio,
            conversion_factor,
            measurement_tilt,
            lamp_sets,
            direct_ratios: [0.0; 10],
        },
        keywords,
        gammas: ng as usize,
        stored,
        area,
    })
}

/// The indices (0-based, into the Mc C-planes) of the planes an Isym stores, in file order
/// (the description's Mc1..Mc2), or why Mc does not suit the Isym.
fn stored_planes(isym: i64, mc: usize) -> Result<Vec<usize>, String> {
    match isym {
        0 => Ok((0..mc).collect()),
        1 => Ok(vec![0]),
        2 if mc.is_multiple_of(2) => Ok((0..=mc / 2).collect()),
        3 if mc.is_multiple_of(4) => Ok((0..=mc / 2).map(|k| (3 * mc / 4 + k) % mc).collect()),
        4 if mc.is_multiple_of(4) => Ok((0..=mc / 4).collect()),
        2 => Err(format!(
            "Isym 2 needs an even number of C-planes, got Mc = {mc}"
        )),
        _ => Err(format!(
            "Isym {isym} needs a number of C-planes divisible by 4, got Mc = {mc}"
        )),
    }
}

/// The n lamp sets: n lines of each field in turn (26a–26f).
fn lamp_sets(r: &mut Lines, n: usize) -> Result<Vec<LampSet>, PhotometryError> {
    let mut counts = Vec::new();
    for k in 1..=n {
        let what = format!("the number of lamps of lamp set {k}");
        counts.push(r.whole(&what, -1_000_000, 1_000_000)?.0);
    }
    let mut types = Vec::new();
    for k in 1..=n {
        types.push(r.text(&format!("the lamp type of lamp set {k}"))?.0);
    }
    let mut fluxes = Vec::new();
    for k in 1..=n {
        let (flux, line) = r.number(&format!("the total luminous flux of lamp set {k}"))?;
        if flux < 0.0 || (k == 1 && flux == 0.0) {
            let m = format!("lamp set {k}'s luminous flux must be positive (it turns cd/klm into candela), got {flux}");
            return Err(malformed(r.file, line, m));
        }
        fluxes.push(flux);
    }
    let mut colours = Vec::new();
    for k in 1..=n {
        colours.push(
            r.text(&format!("the colour temperature of lamp set {k}"))?
                .0,
        );
    }
    let mut rendering = Vec::new();
    for k in 1..=n {
        rendering.push(r.text(&format!("the colour rendering of lamp set {k}"))?.0);
    }
    let mut sets = Vec::new();
    for k in 0..n {
        let watts = r.non_negative(&format!("the wattage of lamp set {}", k + 1))?;
        sets.push(LampSet {
            count: counts.get(k).copied().unwrap_or(0),
            lamp_type: types.get(k).map_or(String::new(), |s| s.to_string()),
            flux: fluxes.get(k).copied().unwrap_or(0.0),
            colour: colours.get(k).map_or(String::new(), |s| s.to_string()),
            colour_rendering: rendering.get(k).map_or(String::new(), |s| s.to_string()),
            watts,
        });
    }
    Ok(sets)
}

#[cfg(test)]
mod tests {
    use super::super::{OpeningShape, Symmetry};
    use super::*;
    use std::f64::consts::PI;

    const ISYM0: &str = include_str!("testdata/isym0.ldt");

    /// `text` with 1-based line `n` replaced by `new`.
    fn with_line(text: &str, n: usize, new: &str) -> String {
        let mut lines: Vec<&str> = text.lines().collect();
        lines[n - 1] = new;
        lines.join("\n") + "\n"
    }

    fn err(text: &str) -> String {
        parse_ldt(text, "x.ldt").unwrap_err().to_string()
    }

    #[test]
    fn isym0_reads_every_plane_and_closes_the_circle() {
        let w = parse_ldt(ISYM0, "0.ldt").unwrap();
        assert_eq!(w.symmetry, Symmetry::Asymmetric);
        assert_eq!(w.horizontal, [0.0, 90.0, 180.0, 270.0, 360.0]);
        // cd/klm × 2000 lm / 1000 × conversion factor 1.
        assert_eq!(w.candela[0], [600.0, 300.0, 0.0]);
        // Halfway between C270 (400) and C360 = C0 (600).
        assert_eq!(w.intensity(315.0, 0.0), 500.0);
        assert_eq!(
            (w.lamps, w.lumens_per_lamp, w.input_watts),
            (2, Some(1000.0), Some(24.0))
        );
        let keys: Vec<&str> = w.keywords.iter().map(|(k, _)| k.as_str()).collect();
        assert_eq!(
            keys,
            [
                "MANUFAC",
                "TEST",
                "LUMINAIRE",
                "LUMCAT",
                "_FILENAME",
                "_DATE_USER",
                "LAMP"
            ]
        );
        assert_eq!(w.luminous_opening.shape, OpeningShape::Rectangle);
        assert_eq!(w.luminous_opening.length, 0.08);
        let Source::Eulumdat(info) = &w.source else {
            panic!()
        };
        assert_eq!((info.ityp, info.isym, info.c_planes), (3, 0, 4));
        assert_eq!(info.direct_ratios[9], 1.0);
    }

    #[test]
    fn isym1_with_comma_decimals_is_rotationally_symmetric() {
        let w = parse_ldt(include_str!("testdata/isym1_comma.ldt"), "1.ldt").unwrap();
        assert_eq!(w.symmetry, Symmetry::Rotational);
        // 100,0 cd/klm × 1500,5 lm / 1000 × conversion factor 1,2.
        let cd = 100.0 * 1500.5 / 1000.0 * 1.2;
        // Two multiplications of the parsed values: well within 1e-12 relative.
        assert!((w.intensity(77.0, 33.0) / cd - 1.0).abs() < 1e-12);
        // Isotropic: 4π·I within the brief's 0.5 % (the trapezoid rule's error is ~3e-5).
        assert!((w.total_lumens() / (4.0 * PI * cd) - 1.0).abs() < 0.005);
        assert_eq!(w.luminous_opening.shape, OpeningShape::VerticalCylinder);
        let Source::Eulumdat(info) = &w.source else {
            panic!()
        };
        assert_eq!(info.downward_flux_fraction, 50.5);
    }

    #[test]
    fn isym2_mirrors_about_c0_c180() {
        let w = parse_ldt(&with_line(ISYM0, 3, "2"), "2.ldt");
        // The Isym 0 file holds 4 planes, Isym 2 reads 3: one plane too many is left over.
        assert!(w
            .unwrap_err()
            .to_string()
            .starts_with("2.ldt:59: unexpected"));
        let w = parse_ldt(include_str!("testdata/isym2.ldt"), "2.ldt").unwrap();
        assert_eq!(w.symmetry, Symmetry::BilateralC0);
        assert_eq!(w.horizontal, [0.0, 90.0, 180.0]);
        assert_eq!(w.intensity(270.0, 90.0), w.intensity(90.0, 90.0));
        assert_eq!(w.intensity(200.0, 45.0), w.intensity(160.0, 45.0));
    }

    #[test]
    fn isym3_reads_c270_through_c0_to_c90_and_mirrors_about_c90_c270() {
        let w = parse_ldt(include_str!("testdata/isym3.ldt"), "3.ldt").unwrap();
        assert_eq!(w.symmetry, Symmetry::BilateralC90);
        assert_eq!(w.horizontal, [90.0, 180.0, 270.0]);
        // The file's planes, in order C270, C0, C90, have γ0 values 100, 300, 200 (cd/klm,
        // × 1 klm): C0 comes back as C0, C270 as C270, C90 as C90.
        assert_eq!(w.intensity(0.0, 0.0), 300.0);
        assert_eq!(w.intensity(270.0, 0.0), 100.0);
        assert_eq!(w.intensity(90.0, 0.0), 200.0);
        assert_eq!(w.intensity(180.0, 0.0), 300.0);
        assert_eq!(w.intensity(30.0, 45.0), w.intensity(150.0, 45.0));
    }

    #[test]
    fn isym4_mirrors_into_four_quadrants() {
        let w = parse_ldt(include_str!("testdata/isym4.ldt"), "4.ldt").unwrap();
        assert_eq!(w.symmetry, Symmetry::Quadrant);
        let i = w.intensity(30.0, 60.0);
        assert!(i > 0.0);
        for c in [150.0, 210.0, 330.0] {
            assert_eq!(w.intensity(c, 60.0), i, "C{c}");
        }
    }

    #[test]
    fn malformed_files_name_the_file_and_line() {
        let short: String = ISYM0.lines().take(45).map(|l| format!("{l}\n")).collect();
        let cases = [
            (
                with_line(ISYM0, 3, "7"),
                "x.ldt:3: Isym must be 0..4, got 7",
            ),
            (
                with_line(&with_line(ISYM0, 3, "4"), 4, "6"),
                "x.ldt:4: Isym 4 needs a number of C-planes divisible by 4, got Mc = 6",
            ),
            (
                short,
                "x.ldt:45: the file ends early: expected C-plane angle",
            ),
            (
                with_line(ISYM0, 55, "-5"),
                "x.ldt:55: negative value -5 among the intensities for C-plane 90",
            ),
            (
                with_line(ISYM0, 48, "0"),
                "x.ldt:48: gamma angles must increase, but 0 follows 0",
            ),
            (
                with_line(ISYM0, 29, "0"),
                "x.ldt:29: lamp set 1's luminous flux must be positive",
            ),
            (
                with_line(ISYM0, 22, "abc"),
                "x.ldt:22: expected the downward flux fraction DFF, found 'abc'",
            ),
            (
                with_line(ISYM0, 61, "0 7"),
                "x.ldt:61: unexpected '7' after the last intensity",
            ),
            (
                with_line(ISYM0, 24, "0"),
                "x.ldt:24: the conversion factor must be positive, got 0",
            ),
            (
                with_line(ISYM0, 46, "360"),
                "x.ldt:46: C-plane angles must lie in 0..360",
            ),
            (
                with_line(include_str!("testdata/isym2.ldt"), 45, "200"),
                "x.ldt:45: Isym 2: Type C horizontal angles must run",
            ),
            (
                String::new(),
                "x.ldt:1: the file ends early: expected the company identification on line 1",
            ),
        ];
        for (text, expected) in cases {
            let e = err(&text);
            assert!(e.starts_with(expected), "got {e:?}, expected {expected:?}");
        }
    }

    #[test]
    fn no_input_panics() {
        for text in [
            ISYM0,
            include_str!("testdata/isym3.ldt"),
            include_str!("testdata/isym1_comma.ldt"),
        ] {
            for (k, _) in text.char_indices() {
                let _ = parse_ldt(&text[..k], "cut.ldt");
                let _ = parse_ldt(&text[k..], "cut.ldt");
            }
        }
    }
}
