//! ANSI/IES LM-63 files (`.ies`), every edition: LM-63-1986 (free text up to `TILT=`),
//! LM-63-1991 (`IESNA91`), LM-63-1995 (`IESNA:LM-63-1995`), LM-63-2002
//! (`IESNA:LM-63-2002`) and ANSI/IES LM-63-19 (`IES:LM-63-2019`).
//!
//! A file is a header of lines (the version, `[KEY] value` keywords, `TILT=`) and then free
//! format numbers: the tilt table if `TILT=INCLUDE`, ten numbers (lamps, lumens per lamp,
//! candela multiplier, the two angle counts, photometric type, units, the opening's width,
//! length and height), three more (ballast factor, ballast-lamp factor or its successors,
//! input watts), the vertical angles, the horizontal angles, and one block of candela values
//! per horizontal angle.

use super::web::{self, Axis};
use super::{
    malformed, without_bom, IesInfo, IesVersion, Opening, PhotometricType, Photometry,
    PhotometryError, Source, Tilt, Tokens, MAX_ANGLES,
};

/// Metres in a foot (LM-63 units type 1).
const FOOT: f64 = 0.3048;

/// What the `TILT=` line says.
enum TiltLine {
    None,
    Include,
    File(String),
}

/// The lines before the numbers.
struct Header {
    version: IesVersion,
    keywords: Vec<(String, String)>,
    tilt: TiltLine,
    /// 0-based index of the `TILT=` line.
    tilt_index: usize,
}

/// The thirteen numbers after the tilt table.
struct Numbers {
    lamps: u32,
    lumens_per_lamp: Option<f64>,
    vertical: usize,
    horizontal: usize,
    kind: PhotometricType,
    opening: Opening,
    input_watts: Option<f64>,
    info: IesInfo,
    /// What every candela value is multiplied by.
    scale: f64,
}

/// Reads an LM-63 file from its text; `name` names it in errors.
///
/// The candela values are made absolute: each is multiplied by the candela multiplier and the
/// ballast factor, and, for LM-63-1986 and -1991 files, by the ballast-lamp photometric factor
/// (the number after the ballast factor, which later editions call "future use" and LM-63-19
/// the file generation type: those are kept in [`IesInfo`], not applied). The opening is
/// converted to metres. A Type C file whose horizontal angles run from 0 to more than 180 but
/// less than 360 gives every plane (LM-63-1995's rule) and is closed at 360 with its C0 plane.
/// Keyword lines are kept in order; a line that is neither a keyword nor `TILT=` before the
/// numbers is kept with the keyword `""`.
pub fn parse_ies(text: &str, name: &str) -> Result<Photometry, PhotometryError> {
    let lines: Vec<&str> = without_bom(text).lines().collect();
    if lines.iter().all(|l| l.trim().is_empty()) {
        return Err(malformed(name, 1, "the file is empty"));
    }
    let header = header(&lines, name)?;
    let mut tokens = Tokens::new(name, &lines, header.tilt_index + 1, false);
    let tilt = match header.tilt {
        TiltLine::None => None,
        TiltLine::Include => Some(tilt(&mut tokens)?),
        TiltLine::File(tilt_file) => {
            return Err(PhotometryError::ExternalTilt {
                file: name.to_string(),
                line: header.tilt_index + 1,
                tilt_file,
            })
        }
    };
    let n = numbers(&mut tokens, header.version)?;
    let (vertical, vlines) = tokens.angles(n.vertical, "vertical angle")?;
    let (mut horizontal, mut hlines) = tokens.angles(n.horizontal, "horizontal angle")?;
    let mut candela = Vec::new();
    for h in &horizontal {
        let what = format!("candela values for horizontal angle {h}");
        let plane = tokens.plane(n.vertical, &what)?;
        candela.push(plane.into_iter().map(|v| v * n.scale).collect::<Vec<f64>>());
    }
    tokens.finish("the last candela value")?;
    if n.kind == PhotometricType::C && web::stops_short_of_360(&horizontal) {
        web::close_circle(&mut horizontal, &mut hlines, &mut candela);
    }
    let symmetry = web::classify(n.kind, &vertical, &horizontal).map_err(|e| {
        let lines = if e.axis == Axis::Vertical {
            &vlines
        } else {
            &hlines
        };
        let line = lines.get(e.index).copied().unwrap_or(header.tilt_index + 1);
        malformed(name, line, e.message)
    })?;
    Ok(Photometry {
        kind: n.kind,
        symmetry,
        vertical,
        horizontal,
        candela,
        lamps: n.lamps,
        lumens_per_lamp: n.lumens_per_lamp,
        input_watts: n.input_watts,
        luminous_opening: n.opening,
        keywords: header.keywords,
        tilt,
        source: Source::Ies(n.info),
    })
}

/// The version line, the keywords and the `TILT=` line.
fn header(lines: &[&str], name: &str) -> Result<Header, PhotometryError> {
    let first = lines.first().map_or("", |l| l.trim());
    let (version, start) = match version(first) {
        Ok(Some(v)) => (v, 1),
        Ok(None) => (IesVersion::Lm63_1986, 0),
        Err(message) => return Err(malformed(name, 1, message)),
    };
    let mut keywords: Vec<(String, String)> = Vec::new();
    let mut first_text = None;
    for (i, raw) in lines.iter().enumerate().skip(start) {
        let line = raw.trim();
        if let Some(spec) = tilt_spec(line) {
            let tilt = match spec.to_ascii_uppercase().as_str() {
                "" => {
                    return Err(malformed(
                        name,
                        i + 1,
                        "TILT= names nothing (NONE, INCLUDE or a file)",
                    ))
                }
                "NONE" => TiltLine::None,
                "INCLUDE" => TiltLine::Include,
                _ => TiltLine::File(spec.to_string()),
            };
            return Ok(Header {
                version,
                keywords,
                tilt,
                tilt_index: i,
            });
        }
        if line.is_empty() {
            continue;
        }
        match keyword(line) {
            Some((k, v)) if k.eq_ignore_ascii_case("MORE") && !keywords.is_empty() => {
                if let Some((_, value)) = keywords.last_mut() {
                    value.push('\n');
                    value.push_str(v);
                }
            }
            Some((k, v)) => keywords.push((k.to_string(), v.to_string())),
            None => {
                first_text.get_or_insert(i + 1);
                keywords.push((String::new(), line.to_string()));
            }
        }
    }
    // In a file with a version line the keywords end where the first other line is; in an
    // LM-63-1986 file free text may run to the end.
    let end = lines.len().max(1);
    let line = match version {
        IesVersion::Lm63_1986 => end,
        _ => first_text.unwrap_or(end),
    };
    Err(malformed(
        name,
        line,
        "no TILT= line (it must end the header, before the numbers)",
    ))
}

/// The LM-63 edition a first line names: `Ok(None)` for none (LM-63-1986), an error for an
/// `IES…` line naming none of the editions.
fn version(first: &str) -> Result<Option<IesVersion>, String> {
    let id: String = first
        .chars()
        .filter(|c| !c.is_whitespace())
        .collect::<String>()
        .to_ascii_uppercase();
    if id == "IESNA91" {
        return Ok(Some(IesVersion::Lm63_1991));
    }
    let year = id
        .strip_prefix("IESNA:LM-63-")
        .or_else(|| id.strip_prefix("IES:LM-63-"));
    match year {
        Some("1991") => Ok(Some(IesVersion::Lm63_1991)),
        Some("1995") => Ok(Some(IesVersion::Lm63_1995)),
        Some("2002") => Ok(Some(IesVersion::Lm63_2002)),
        Some("2019") => Ok(Some(IesVersion::Lm63_2019)),
        _ if id.starts_with("IESNA") || id.starts_with("IES:") => Err(format!(
            "unknown LM-63 version line '{first}' (expected IESNA91, IESNA:LM-63-1995, \
             IESNA:LM-63-2002 or IES:LM-63-2019)"
        )),
        _ => Ok(None),
    }
}

/// What follows `TILT=` on a `TILT=` line (any case, spaces around `=` allowed).
fn tilt_spec(line: &str) -> Option<&str> {
    let head = line.get(..4)?;
    if !head.eq_ignore_ascii_case("TILT") {
        return None;
    }
    line.get(4..)?.trim_start().strip_prefix('=').map(str::trim)
}

/// `[KEY] value` as `("KEY", "value")`.
fn keyword(line: &str) -> Option<(&str, &str)> {
    let rest = line.strip_prefix('[')?;
    let close = rest.find(']')?;
    Some((rest.get(..close)?.trim(), rest.get(close + 1..)?.trim()))
}

/// The tilt table of a `TILT=INCLUDE` file.
fn tilt(t: &mut Tokens) -> Result<Tilt, PhotometryError> {
    let (geometry, _) = t.whole("the lamp-to-luminaire geometry", 1, 3)?;
    let (n, _) = t.whole("the number of tilt angles", 1, MAX_ANGLES)?;
    let (angles, _) = t.angles(n as usize, "tilt angle")?;
    let mut factors = Vec::new();
    for _ in 0..n {
        factors.push(t.positive("a tilt multiplying factor", true)?.0);
    }
    Ok(Tilt {
        geometry: geometry as u8,
        angles,
        factors,
    })
}

/// The thirteen numbers between the tilt table and the angles.
fn numbers(t: &mut Tokens, version: IesVersion) -> Result<Numbers, PhotometryError> {
    let (lamps, _) = t.whole("the number of lamps", 1, u64::from(u32::MAX))?;
    let (lumens, line) = t.number("the lumens per lamp")?;
    let lumens_per_lamp = match lumens {
        // −1 marks absolute photometry (LM-63-1995 on); files write it as -1 or -1.0, and
        // 1e-9 only forgives printing noise, far from any real lamp's lumens.
        l if (l + 1.0).abs() < 1e-9 => None,
        l if l > 0.0 => Some(l),
        l => {
            return Err(t.error(
                line,
                format!(
                    "the lumens per lamp must be positive, or -1 for absolute photometry; got {l}"
                ),
            ))
        }
    };
    let (multiplier, _) = t.positive("the candela multiplier", false)?;
    let (vertical, _) = t.whole("the number of vertical angles", 1, MAX_ANGLES)?;
    let (horizontal, _) = t.whole("the number of horizontal angles", 1, MAX_ANGLES)?;
    let (kind, _) = t.whole("the photometric type (1 = C, 2 = B, 3 = A)", 1, 3)?;
    let (units, _) = t.whole("the units type (1 = feet, 2 = metres)", 1, 2)?;
    let unit = if units == 1 { FOOT } else { 1.0 };
    let (width, _) = t.number("the luminous opening's width")?;
    let (length, _) = t.number("the luminous opening's length")?;
    let (height, _) = t.number("the luminous opening's height")?;
    let (ballast_factor, _) = t.positive("the ballast factor", false)?;
    let (third, line) = t.number("the ballast-lamp factor (future use, file generation type)")?;
    let applies = matches!(version, IesVersion::Lm63_1986 | IesVersion::Lm63_1991);
    if applies && third <= 0.0 {
        return Err(t.error(
            line,
            format!("the ballast-lamp photometric factor must be positive, got {third}"),
        ));
    }
    let (watts, _) = t.positive("the input watts", true)?;
    Ok(Numbers {
        lamps: lamps as u32,
        lumens_per_lamp,
        vertical: vertical as usize,
        horizontal: horizontal as usize,
        kind: match kind {
            1 => PhotometricType::C,
            2 => PhotometricType::B,
            _ => PhotometricType::A,
        },
        opening: Opening::from_signed(width * unit, length * unit, height * unit),
        input_watts: (watts > 0.0).then_some(watts),
        info: IesInfo {
            version,
            multiplier,
            ballast_factor,
            ballast_lamp_factor: third,
            feet: units == 1,
        },
        scale: multiplier * ballast_factor * if applies { third } else { 1.0 },
    })
}

#[cfg(test)]
mod tests {
    use super::super::{OpeningShape, Symmetry};
    use super::*;
    use std::f64::consts::PI;

    const C90: &str = include_str!("testdata/lm63_2002_c90.ies");

    /// `text` with 1-based line `n` replaced by `new` (removed if `None`).
    fn with_line(text: &str, n: usize, new: Option<&str>) -> String {
        let mut lines: Vec<&str> = text.lines().collect();
        match new {
            Some(s) => lines[n - 1] = s,
            None => {
                lines.remove(n - 1);
            }
        }
        lines.join("\n") + "\n"
    }

    fn err(text: &str) -> String {
        parse_ies(text, "lamp.ies").unwrap_err().to_string()
    }

    #[test]
    fn lm63_1986_free_text_header_and_rotational_isotropic_web() {
        let w = parse_ies(include_str!("testdata/lm63_1986_rotational.ies"), "a.ies").unwrap();
        assert_eq!(
            w.source,
            Source::Ies(IesInfo {
                version: IesVersion::Lm63_1986,
                multiplier: 1.0,
                ballast_factor: 1.0,
                ballast_lamp_factor: 1.0,
                feet: false
            })
        );
        assert_eq!(w.keywords.len(), 2);
        assert_eq!(
            w.keywords[0],
            (String::new(), "Lamp test report 1234, ACME Lighting".into())
        );
        assert_eq!(w.symmetry, Symmetry::Rotational);
        assert_eq!(
            (w.lamps, w.lumens_per_lamp, w.input_watts),
            (1, Some(1000.0), Some(100.0))
        );
        // Isotropic 1000 cd: 4π·1000 lm within the brief's 0.5 % (trapezoid error ~3e-5).
        assert!((w.total_lumens() / (4.0 * PI * 1000.0) - 1.0).abs() < 0.005);
        assert_eq!(w.intensity(123.0, 77.0), 1000.0);
    }

    #[test]
    fn iesna91_quadrant_applies_multiplier_ballast_and_ballast_lamp_factor() {
        let w = parse_ies(include_str!("testdata/iesna91_quadrant.ies"), "q.ies").unwrap();
        let Source::Ies(info) = &w.source else {
            panic!()
        };
        assert_eq!((info.version, info.feet), (IesVersion::Lm63_1991, true));
        assert_eq!(w.symmetry, Symmetry::Quadrant);
        // 200 cd × multiplier 0.5 × ballast factor 1 × ballast-lamp factor 0.8 (exact in binary
        // to within one rounding, hence the bound).
        assert!((w.candela[0][0] - 80.0).abs() < 1e-12);
        // Diameter 1 ft, round: a flat circle of 0.3048 m.
        assert_eq!(w.luminous_opening.shape, OpeningShape::Ellipse);
        assert_eq!(w.luminous_opening.width, FOOT);
        let i = w.intensity(30.0, 20.0);
        for c in [150.0, 210.0, 330.0] {
            assert_eq!(w.intensity(c, 20.0), i, "C{c}");
        }
    }

    #[test]
    fn lm63_1995_keywords_more_and_bilateral_web() {
        let w = parse_ies(include_str!("testdata/lm63_1995_bilateral.ies"), "b.ies").unwrap();
        let keys: Vec<&str> = w.keywords.iter().map(|(k, _)| k.as_str()).collect();
        assert_eq!(keys, ["TEST", "MANUFAC", "LUMINAIRE", "LAMP", "_SERIAL"]);
        assert_eq!(w.keywords[2].1, "Wall washer,\nasymmetric reflector");
        assert_eq!(w.symmetry, Symmetry::BilateralC0);
        // Ballast factor 0.9 applied; "future use" 1.5 is not (it would give 675). 500 × 0.9
        // rounds once, a few 1e-14 at most: 1e-9 only absorbs that.
        assert!((w.candela[0][0] - 450.0).abs() < 1e-9);
        assert_eq!(w.intensity(300.0, 45.0), w.intensity(60.0, 45.0));
        assert_eq!(w.luminous_opening.shape, OpeningShape::Rectangle);
    }

    #[test]
    fn lm63_2002_c90_bilateral_and_absolute_photometry() {
        let w = parse_ies(C90, "c.ies").unwrap();
        assert_eq!(w.symmetry, Symmetry::BilateralC90);
        assert_eq!(w.lumens_per_lamp, None);
        assert_eq!(w.intensity(180.0, 45.0), 40.0);
        assert_eq!(w.intensity(30.0, 45.0), w.intensity(150.0, 45.0));
        assert_eq!(w.intensity(0.0, 0.0), 80.0);
    }

    #[test]
    fn lm63_2019_commas_feet_and_file_generation_type() {
        let w = parse_ies(include_str!("testdata/lm63_2019_full.ies"), "f.ies").unwrap();
        let Source::Ies(info) = &w.source else {
            panic!()
        };
        assert_eq!(
            (info.version, info.ballast_lamp_factor),
            (IesVersion::Lm63_2019, 1.1)
        );
        assert_eq!(w.symmetry, Symmetry::Asymmetric);
        assert_eq!(w.candela[1], [110.0, 60.0, 6.0]);
        assert!(w
            .keywords
            .contains(&("_ANYTHING".into(), "user keyword".into())));
        assert_eq!(
            (w.luminous_opening.width, w.luminous_opening.length),
            (2.0 * FOOT, 4.0 * FOOT)
        );
        assert_eq!(w.intensity(315.0, 0.0), 115.0);
    }

    #[test]
    fn a_full_circle_short_of_360_is_closed_with_c0() {
        let text = "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 2 3 1 2 0 0 0\n1 1 0\n0 90\n0 120 240\n10 1 20 2 30 3\n";
        let w = parse_ies(text, "s.ies").unwrap();
        assert_eq!(w.horizontal, [0.0, 120.0, 240.0, 360.0]);
        assert_eq!(w.intensity(300.0, 0.0), 20.0);
    }

    #[test]
    fn tilt_include_is_read_before_the_numbers() {
        let w = parse_ies(include_str!("testdata/lm63_2002_tilt.ies"), "t.ies").unwrap();
        let t = w.tilt.as_ref().unwrap();
        assert_eq!((t.geometry, t.angles.len()), (1, 4));
        assert_eq!(t.factors, [1.0, 0.95, 0.9, 0.8]);
        assert_eq!(w.candela, [[300.0, 200.0, 100.0]]);
    }

    #[test]
    fn type_b_and_type_a_webs() {
        let w = parse_ies(include_str!("testdata/type_b_lateral.ies"), "b.ies").unwrap();
        assert_eq!(
            (w.kind, w.symmetry),
            (PhotometricType::B, Symmetry::Lateral)
        );
        assert_eq!(w.intensity(-45.0, -30.0), w.intensity(45.0, -30.0));
        let a =
            "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 2 2 3 2 0 0 0\n1 1 0\n-90 90\n-90 90\n1 2 3 4\n";
        let w = parse_ies(a, "a.ies").unwrap();
        assert_eq!(
            (w.kind, w.symmetry),
            (PhotometricType::A, Symmetry::Asymmetric)
        );
        assert_eq!(w.intensity(0.0, 0.0), 2.5);
    }

    #[test]
    fn malformed_files_name_the_file_and_line() {
        let cases: Vec<(String, &str)> = vec![
            (with_line(C90, 7, None), "lamp.ies:7: no TILT= line"),
            (
                with_line(C90, 7, Some("TILT=lamp.tlt")),
                "lamp.ies:7: TILT=lamp.tlt: tilt data in an external file",
            ),
            (
                with_line(C90, 14, Some("60 30")),
                "lamp.ies:14: expected 3 candela values for horizontal angle 270, found 2",
            ),
            (
                with_line(C90, 10, Some("0 45 45")),
                "lamp.ies:10: vertical angles must increase, but 45 follows 45",
            ),
            (
                with_line(C90, 13, Some("80 -40 0")),
                "lamp.ies:13: negative value -40 among the candela values for horizontal angle 180",
            ),
            (
                with_line(C90, 8, Some("1 -1 1 3 3 4 2 0 0 0")),
                "lamp.ies:8: the photometric type (1 = C, 2 = B, 3 = A) must be 1..3, got 4",
            ),
            (
                with_line(C90, 8, Some("1 0 1 3 3 1 2 0 0 0")),
                "lamp.ies:8: the lumens per lamp must be positive",
            ),
            (
                with_line(C90, 11, Some("0 30 45")),
                "lamp.ies:11: Type C horizontal angles must run",
            ),
            (
                with_line(C90, 10, Some("0 45 190")),
                "lamp.ies:10: Type C vertical angles must lie in 0..180, got 190",
            ),
            (
                with_line(C90, 14, Some("60 30 0 7")),
                "lamp.ies:14: unexpected '7' after the last candela value",
            ),
            (
                with_line(C90, 9, Some("1 1 twelve")),
                "lamp.ies:9: expected the input watts, found 'twelve'",
            ),
            (
                with_line(C90, 12, Some("100 nan 0")),
                "lamp.ies:12: expected candela values for horizontal angle 90, found 'nan'",
            ),
            (
                with_line(C90, 1, Some("IESNA:LM-63-2077")),
                "lamp.ies:1: unknown LM-63 version line",
            ),
            (
                C90.lines().take(9).collect::<Vec<_>>().join("\n"),
                "lamp.ies:9: the file ends early: expected vertical angle",
            ),
            (String::new(), "lamp.ies:1: the file is empty"),
        ];
        for (text, expected) in cases {
            let e = err(&text);
            assert!(e.starts_with(expected), "got {e:?}, expected {expected:?}");
        }
    }

    #[test]
    fn no_input_panics() {
        let files = [
            C90,
            include_str!("testdata/lm63_1986_rotational.ies"),
            include_str!("testdata/lm63_2002_tilt.ies"),
            include_str!("testdata/lm63_2019_full.ies"),
        ];
        for text in files {
            for (k, _) in text.char_indices() {
                let _ = parse_ies(&text[..k], "cut.ies");
                let _ = parse_ies(&text[k..], "cut.ies");
            }
        }
    }
}
