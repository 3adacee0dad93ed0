//! Placed luminaires and their schedules, on small photometric files written to a temporary
//! folder.

use super::*;
use crate::photometry::PhotometricType;
use std::f64::consts::PI;
use std::path::Path;
use tempfile::TempDir;

/// An asymmetric Type C web: C 0, 90, 180, 270 (closed at 360), γ 0, 45, 90; every plane
/// distinct, 100 cd at the nadir.
const ASYMMETRIC: &str = "IESNA:LM-63-2002
[TEST] asymmetric
TILT=NONE
1 -1 1 3 5 1 2 0 0 0
1 1 0
0 45 90
0 90 180 270 360
100 200 50
100 400 60
100 20 10
100 30 5
100 200 50
";

/// `cd` candela in every direction (one plane, γ 0..180 in 10° steps): 4π·cd lumens.
fn isotropic(cd: f64) -> String {
    let angles: Vec<String> = (0..=18).map(|k| (10 * k).to_string()).collect();
    let values = vec![cd.to_string(); 19].join(" ");
    format!(
        "IESNA:LM-63-2002\n[TEST] iso\nTILT=NONE\n1 -1 1 19 1 1 2 0 0 0\n1 1 0\n{}\n0\n{values}\n",
        angles.join(" ")
    )
}

/// A folder holding the test webs: `asym.ies`, `iso.ies` (1000 cd), `dark.ies` (0 cd),
/// `tilt.ies` (the photometry tests' tilted file), `flood.ies` (Type B) and `garbage.ies`.
fn folder() -> TempDir {
    let dir = tempfile::tempdir().unwrap();
    let files = [
        ("asym.ies", ASYMMETRIC.to_string()),
        ("iso.ies", isotropic(1000.0)),
        ("dark.ies", isotropic(0.0)),
        (
            "tilt.ies",
            include_str!("../photometry/testdata/lm63_2002_tilt.ies").into(),
        ),
        (
            "flood.ies",
            include_str!("../photometry/testdata/type_b_lateral.ies").into(),
        ),
        ("garbage.ies", "IESNA:LM-63-2002\nTILT=NONE\n1 2 x\n".into()),
    ];
    for (name, text) in files {
        std::fs::write(dir.path().join(name), text).unwrap();
    }
    dir
}

/// Writes `text` as `name` in `dir` and reads it as a schedule.
fn schedule(
    dir: &TempDir,
    name: &str,
    text: &str,
    zenith: DVec3,
) -> Result<Vec<Luminaire>, ScheduleError> {
    let path = dir.path().join(name);
    std::fs::write(&path, text).unwrap();
    read_schedule(&path, zenith)
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * b.abs().max(1.0)
}

fn close3(a: DVec3, b: DVec3) -> bool {
    (a - b).length() < 1e-12
}

/// Checks the three rows of the CSV and JSON tests below: two single luminaires and a row of
/// three with a step.
fn check_two_rows_and_a_row_of_three(lums: &[Luminaire], dir: &Path) {
    let names: Vec<&str> = lums.iter().map(|l| l.name.as_str()).collect();
    assert_eq!(names, ["desk", "iso-2", "strip#1", "strip#2", "strip#3"]);
    let groups: Vec<&str> = lums.iter().map(|l| l.group.as_str()).collect();
    assert_eq!(groups, ["office", "iso-2", "strip", "strip", "strip"]);
    let positions: Vec<DVec3> = lums.iter().map(|l| l.position).collect();
    assert_eq!(
        positions,
        [
            DVec3::new(1.0, 2.5, 3.0),
            DVec3::new(-1.0, 2.5, 0.0),
            DVec3::new(0.0, 3.0, 0.0),
            DVec3::new(1.5, 3.0, 0.0),
            DVec3::new(3.0, 3.0, 0.0),
        ]
    );
    let scales: Vec<f64> = lums.iter().map(|l| l.scale).collect();
    assert_eq!(scales, [0.8, 4.0, 0.9, 0.9, 0.9]);
    assert_eq!(lums[0].file, dir.join("asym.ies"));
    // One web per file, shared.
    assert!(Arc::ptr_eq(&lums[0].photometry, &lums[2].photometry));
    assert!(!Arc::ptr_eq(&lums[0].photometry, &lums[1].photometry));
    for l in lums {
        assert_eq!(l.frame.aim, DVec3::NEG_Y);
        assert_eq!(l.colour, [1.0; 3]);
        assert_eq!(l.tilt_factor, 1.0);
    }
}

#[test]
fn csv_rows_give_positions_names_and_scales() {
    let dir = folder();
    let csv = "# luminaires of the test room\n\
               \n\
               Name, file, x, y, z, count, step_x, llf, group\n\
               desk, asym.ies, 1, 2.5, 3, , , 0.8, office\n\
               , iso.ies, -1, 2.5, 0, 4, 0, ,\n\
               # a row of three\n\
               strip, asym.ies, 0, 3, 0, 3, 1.5, 0.9,\r\n";
    let lums = schedule(&dir, "room.csv", csv, DVec3::Y).unwrap();
    check_two_rows_and_a_row_of_three(&lums, dir.path());
}

#[test]
fn json_entries_give_positions_names_and_scales() {
    let dir = folder();
    let json = r#"{"luminaires": [
        {"name": "desk", "group": "office", "file": "asym.ies", "position": [1, 2.5, 3], "llf": 0.8},
        {"file": "iso.ies", "position": [-1, 2.5, 0], "count": 4},
        {"name": "strip", "file": "asym.ies", "position": [0, 3, 0], "count": 3,
         "step": [1.5, 0, 0], "llf": 0.9}
    ]}"#;
    let lums = schedule(&dir, "room.json", json, DVec3::Y).unwrap();
    check_two_rows_and_a_row_of_three(&lums, dir.path());
    // The format follows the text when the extension says nothing.
    let lums = schedule(&dir, "room.schedule", json, DVec3::Y).unwrap();
    assert_eq!(lums.len(), 5);
}

#[test]
fn default_aim_is_straight_down_for_either_zenith() {
    let dir = folder();
    let csv = "file,x,y,z\nasym.ies,0,0,0\n";
    let l = &schedule(&dir, "a.csv", csv, DVec3::Y).unwrap()[0];
    assert_eq!(
        (l.frame.aim, l.frame.c0, l.frame.c90),
        (DVec3::NEG_Y, DVec3::X, DVec3::NEG_Z)
    );
    let l = &schedule(&dir, "a.csv", csv, DVec3::new(0.0, 0.0, 3.0)).unwrap()[0];
    assert_eq!(
        (l.frame.aim, l.frame.c0, l.frame.c90),
        (DVec3::NEG_Z, DVec3::X, DVec3::Y)
    );
    // Straight down is the γ = 0 intensity; straight up is dark (the web stops at 90°).
    assert_eq!(l.intensity_toward(DVec3::NEG_Z), [100.0 / 179.0; 3]);
    assert_eq!(l.intensity_toward(DVec3::Z), [0.0; 3]);
    assert_eq!(l.intensity_toward(DVec3::ZERO), [0.0; 3]);
}

#[test]
fn an_aim_point_turns_the_nadir_toward_it() {
    let dir = folder();
    let csv = "file,x,y,z,aim_x,aim_y,aim_z,spin,llf\n\
               asym.ies,1,2,3,4,0,1,25,0.5\n\
               asym.ies,1,2,3,10,2,3,0,1\n";
    let lums = schedule(&dir, "aim.csv", csv, DVec3::Y).unwrap();
    let l = &lums[0];
    let to_point = DVec3::new(4.0, 0.0, 1.0) - l.position;
    assert!(close3(l.frame.aim, to_point.normalize()));
    let i = l.intensity_toward(to_point * 7.0);
    assert!(i.iter().all(|&w| close(w, 100.0 / 179.0 * 0.5)), "{i:?}");
    // Aimed along +X, the horizontal reference itself: the frame's C0 is then the zenith.
    let l = &lums[1];
    assert_eq!((l.frame.aim, l.frame.c0), (DVec3::X, DVec3::Y));
    // The C0 plane at γ 45 is forward and up: 200 cd.
    let d = DVec3::new(1.0, 1.0, 0.0);
    assert!(close(l.intensity_toward(d)[1], 200.0 / 179.0));
}

#[test]
fn spin_90_puts_the_c0_intensity_where_c90_was() {
    let dir = folder();
    let csv = "file,x,y,z,spin\nasym.ies,0,0,0,0\nasym.ies,0,0,0,90\n";
    let lums = schedule(&dir, "spin.csv", csv, DVec3::Z).unwrap();
    let (plain, spun) = (&lums[0], &lums[1]);
    let toward = |c: f64| {
        plain
            .frame
            .to_world(local_direction(PhotometricType::C, c, 45.0))
    };
    // Unspun: the file's own planes.
    for (c, cd) in [(0.0, 200.0), (90.0, 400.0), (180.0, 20.0), (270.0, 30.0)] {
        assert!(
            close(plain.intensity_toward(toward(c))[0], cd / 179.0),
            "C{c}"
        );
    }
    // Spun 90°: each plane one quarter turn on, counter-clockwise seen from above.
    for (c, cd) in [(90.0, 200.0), (180.0, 400.0), (270.0, 20.0), (0.0, 30.0)] {
        assert!(
            close(spun.intensity_toward(toward(c))[0], cd / 179.0),
            "C{c}"
        );
    }
}

#[test]
fn flux_is_the_webs_lumens_times_llf_and_count() {
    let dir = folder();
    let csv = "file,x,y,z,count,llf,r,g,b\n\
               iso.ies,0,0,0,3,0.7,,,\n\
               iso.ies,0,0,0,1,1,1,0.5,0.25\n";
    let lums = schedule(&dir, "flux.csv", csv, DVec3::Y).unwrap();
    let web_lm = lums[0].photometry.total_lumens();
    // 1000 cd all round carries 4π·1000 lm; 0.5 % is the photometry tests' margin.
    assert!((web_lm / (4000.0 * PI) - 1.0).abs() < 0.005, "{web_lm}");
    assert!(close(lums[0].flux_lumens(), web_lm * 0.7 * 3.0));
    assert_eq!(lums[0].flux_watts(), [lums[0].flux_lumens() / 179.0; 3]);
    // A tint keeps the lumens: its watts weighted by luminance give them back.
    let tinted = &lums[1];
    let w = tinted.flux_watts();
    let lm: f64 = w
        .iter()
        .zip(LUMINANCE_WEIGHTS)
        .map(|(w, k)| w * k)
        .sum::<f64>()
        * 179.0;
    assert!(close(lm, web_lm));
    assert!(close(w[0], 2.0 * w[1]) && close(w[1], 2.0 * w[2]));
    let i = tinted.intensity_toward(DVec3::X);
    assert!(close(i[0], 1000.0 / 179.0 * tinted.colour[0]));
}

#[test]
fn colour_is_normalised_to_unit_luminance() {
    assert_eq!(normalise_colour([1.0; 3]), Some([1.0; 3]));
    let c = normalise_colour([2.0, 1.0, 0.0]).unwrap();
    let y: f64 = c.iter().zip(LUMINANCE_WEIGHTS).map(|(c, w)| c * w).sum();
    assert!(close(y, 1.0) && close(c[0], 2.0 * c[1]));
    for bad in [
        [0.0; 3],
        [-1.0, 1.0, 1.0],
        [f64::NAN, 1.0, 1.0],
        [f64::INFINITY; 3],
    ] {
        assert_eq!(normalise_colour(bad), None, "{bad:?}");
    }
}

#[test]
fn the_tilt_table_is_read_at_the_aims_angle_from_the_nadir() {
    let dir = folder();
    // Z up; the second aims 30° from the nadir, the third 60°, the fourth horizontally.
    let t30 = 30f64.to_radians().tan();
    let t60 = 60f64.to_radians().tan();
    let csv = format!(
        "file,x,y,z,aim_x,aim_y,aim_z\n\
         tilt.ies,0,0,0,,,\n\
         tilt.ies,0,0,0,{t30},0,-1\n\
         tilt.ies,0,0,0,0,{t60},-1\n\
         tilt.ies,0,0,0,5,0,0\n"
    );
    let lums = schedule(&dir, "tilt.csv", &csv, DVec3::Z).unwrap();
    let factors: Vec<f64> = lums.iter().map(|l| l.tilt_factor).collect();
    for (f, expected) in factors.iter().zip([1.0, 0.95, 0.9, 0.8]) {
        assert!((f - expected).abs() < 1e-9, "{factors:?}");
    }
    let web = lums[1].photometry.total_lumens();
    assert!(close(lums[1].flux_lumens(), web * factors[1]));
    let i = lums[1].intensity_toward(lums[1].frame.aim)[0];
    assert!(close(i, 300.0 / 179.0 * factors[1]));
    assert_eq!(tilt_factor(&lums[0].photometry, DVec3::ZERO, DVec3::Z), 1.0);
}

#[test]
fn a_type_b_floodlight_is_dark_behind() {
    let dir = folder();
    // Z up, aimed along +X at the horizon: its polar axis (the width, C90) stays horizontal.
    let csv = "file,x,y,z,aim_x,aim_y,aim_z\nflood.ies,0,0,0,10,0,0\n";
    let l = &schedule(&dir, "flood.csv", csv, DVec3::Z).unwrap()[0];
    assert_eq!(l.photometry.kind, PhotometricType::B);
    assert_eq!((l.frame.c0, l.frame.c90), (DVec3::Z, DVec3::Y));
    assert!(close(l.intensity_toward(DVec3::X)[0], 900.0 / 179.0));
    // H 45 toward the polar axis (+Y), V 0: 600 cd.
    let d = DVec3::new(1.0, 1.0, 0.0);
    assert!(close(l.intensity_toward(d)[0], 600.0 / 179.0));
    for d in [
        DVec3::NEG_X,
        DVec3::new(-1.0, 0.3, 0.2),
        DVec3::new(-1e-3, 1.0, 1.0),
    ] {
        assert_eq!(l.intensity_toward(d), [0.0; 3], "{d}");
    }
}

/// Reads `text` as schedule `name` and checks that it fails with one line that names the
/// schedule and `line` and contains `needle`.
fn fails_at(dir: &TempDir, name: &str, text: &str, line: usize, needle: &str) {
    let e = schedule(dir, name, text, DVec3::Y).unwrap_err().to_string();
    assert!(!e.contains('\n'), "{e}");
    assert!(e.contains(&format!("{name}:{line}: ")), "line {line}: {e}");
    assert!(e.contains(needle), "'{needle}' not in {e}");
}

#[test]
fn csv_errors_name_the_schedule_and_the_line() {
    let dir = folder();
    let head = "# test\nfile,x,y,z,aim_x,aim_y,aim_z,count,llf,r,g,b,name\n";
    let cases = [
        ("asym.ies,1,x1,3,,,,,,,,,", "y: 'x1' is not a finite number"),
        ("asym.ies,1,inf,3,,,,,,,,,", "'inf' is not a finite number"),
        ("asym.ies,1,NaN,3,,,,,,,,,", "'NaN' is not a finite number"),
        ("asym.ies,1,,3,,,,,,,,,", "y: the value is missing"),
        (",1,2,3,,,,,,,,,", "file: the value is missing"),
        (
            "asym.ies,1,2,3,1,2,3,,,,,,",
            "aim point (1, 2, 3) is the luminaire's position",
        ),
        ("asym.ies,1,2,3,1,2,,,,,,,", "aim_x, aim_y, aim_z"),
        ("asym.ies,1,2,3,,,,,0,,,,", "llf must be > 0 and ≤ 2, got 0"),
        ("asym.ies,1,2,3,,,,,2.5,,,,", "got 2.5"),
        ("asym.ies,1,2,3,,,,,-1,,,,", "got -1"),
        ("asym.ies,1,2,3,,,,0,,,,,", "count must be a whole number"),
        ("asym.ies,1,2,3,,,,2.5,,,,,", "got 2.5"),
        ("asym.ies,1,2,3,,,,1e9,,,,,", "1..10000"),
        (
            "asym.ies,1,2,3,,,,,,1,-0.5,1,",
            "colour must not be negative",
        ),
        ("asym.ies,1,2,3,,,,,,0,0,0,", "black"),
        (
            "asym.ies,1,2,3",
            "4 fields, but the header (line 2) names 13 columns",
        ),
        ("missing.ies,1,2,3,,,,,,,,,", "missing.ies: cannot read"),
        ("garbage.ies,1,2,3,,,,,,,,,", "garbage.ies:3: "),
        (
            "dark.ies,1,2,3,,,,,,,,,",
            "dark.ies: the web carries no light",
        ),
    ];
    for (row, needle) in cases {
        // A good row first: the bad one is on line 4.
        let text = format!("{head}asym.ies,0,0,0,,,,,,,,,\n{row}\n");
        fails_at(&dir, "bad.csv", &text, 4, needle);
    }
    let headers = [
        ("file,x,y", "missing column 'z'"),
        ("file,x,y,z,colour", "unknown column 'colour'"),
        ("file,x,y,z,x", "column 'x' is given twice"),
        ("file,x,y,z,r,g", "give all of r, g, b or none"),
    ];
    for (header, needle) in headers {
        fails_at(
            &dir,
            "bad.csv",
            &format!("\n{header}\nasym.ies,0,0,0\n"),
            2,
            needle,
        );
    }
    for empty in ["", "\n  \n", "# nothing\n", "file,x,y,z\n# none yet\n"] {
        let e = schedule(&dir, "empty.csv", empty, DVec3::Y).unwrap_err();
        assert!(
            e.to_string().ends_with("empty.csv: no luminaires listed"),
            "{e}"
        );
    }
    let e = read_schedule(&dir.path().join("absent.csv"), DVec3::Y).unwrap_err();
    assert!(e.to_string().contains("absent.csv: cannot read"), "{e}");
    let e = schedule(&dir, "z.csv", "file,x,y,z\nasym.ies,0,0,0\n", DVec3::ZERO).unwrap_err();
    assert!(
        e.to_string()
            .contains("z.csv: the zenith is not a direction"),
        "{e}"
    );
}

#[test]
fn json_errors_name_the_schedule_and_the_line() {
    let dir = folder();
    let good = r#"{"file": "asym.ies", "position": [0, 0, 0]}"#;
    let cases = [
        (
            r#"{"file": "asym.ies", "position": [0, 0, 0], "llf": 3}"#,
            "llf must be",
        ),
        (
            r#"{"file": "asym.ies", "position": [0, 0, 0], "aim": [0, 0, 0]}"#,
            "aim point",
        ),
        (
            r#"{"file": "asym.ies", "position": [0, 0, 0], "colour": [1, -1, 1]}"#,
            "negative",
        ),
        (
            r#"{"file": "asym.ies", "position": [0, 0, 0], "count": 0}"#,
            "count must be",
        ),
        (r#"{"file": "dark.ies", "position": [0, 0, 0]}"#, "no light"),
        (
            r#"{"file": "nowhere.ies", "position": [0, 0, 0]}"#,
            "nowhere.ies: cannot read",
        ),
        (
            r#"{"file": "asym.ies", "position": [0, 0, 0], "colr": [1, 1, 1]}"#,
            "unknown field `colr`",
        ),
        (
            r#"{"file": "asym.ies", "position": [0, 0]}"#,
            "invalid length 2",
        ),
        (r#"{"position": [0, 0, 0]}"#, "missing field `file`"),
        (
            r#"{"file": "asym.ies", "position": [0, "x", 0]}"#,
            "invalid type",
        ),
        (
            r#"{"file": "asym.ies", "position": [0, 0, 1e999]}"#,
            "out of range",
        ),
        (
            r#"{"file": "asym.ies", "position": [0, 0, 0],}"#,
            "trailing comma",
        ),
    ];
    for (entry, needle) in cases {
        // The bad entry opens on line 4 (and, being one line, ends there).
        let text = format!("{{\n  \"luminaires\": [\n    {good},\n    {entry}\n  ]\n}}\n");
        fails_at(&dir, "bad.json", &text, 4, needle);
    }
    // A checked value names the line where its entry opens, not where it stands.
    let multi = "{\"luminaires\": [\n  {\"file\": \"asym.ies\",\n   \"llf\": 3,\n   \"position\": [0, 0, 0]}\n]}";
    fails_at(&dir, "bad.json", multi, 2, "llf must be");
    fails_at(
        &dir,
        "bad.json",
        "{\"luminaires\": [], \"extra\": 1}",
        1,
        "unknown field `extra`",
    );
    fails_at(&dir, "bad.json", "{\"luminaires\": [\n", 2, "EOF");
    for empty in ["{\"luminaires\": []}", "  "] {
        let e = schedule(&dir, "empty.json", empty, DVec3::Y).unwrap_err();
        assert_eq!(
            e.to_string(),
            format!(
                "{}: no luminaires listed",
                dir.path().join("empty.json").display()
            )
        );
    }
}

#[test]
fn entry_lines_skip_braces_in_strings() {
    let text = "{\"luminaires\": [{\"name\": \"a{b\\\"}\", \"position\": [1,2,3]},\n\n {\"file\": \"x\"}]}";
    assert_eq!(schedule::entry_lines(text), [1, 3]);
}

/// A small deterministic stream of bytes (a linear congruential generator).
fn noise(seed: u64, n: usize) -> Vec<u8> {
    let mut x = seed;
    (0..n)
        .map(|_| {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (x >> 56) as u8
        })
        .collect()
}

#[test]
fn truncated_and_garbage_schedules_never_panic() {
    let dir = folder();
    let csv = "file,x,y,z,aim_x,aim_y,aim_z,spin,count,step_x,llf,r,g,b,name\n\
               asym.ies,1,2,3,4,0,1,30,2,0.5,0.8,1,0.9,0.8,a\n";
    let json = r#"{"luminaires": [{"file": "iso.ies", "position": [1, 2, 3], "aim": [1, 0, 3],
        "spin": 10, "count": 2, "step": [0, 0, 1], "llf": 0.9, "colour": [1, 1, 0.5]}]}"#;
    for (name, text) in [("t.csv", csv), ("t.json", json)] {
        for cut in (0..text.len()).filter(|&k| text.is_char_boundary(k)) {
            let path = dir.path().join(name);
            std::fs::write(&path, &text[..cut]).unwrap();
            if let Err(e) = read_schedule(&path, DVec3::Y) {
                assert!(!e.to_string().contains('\n'), "{e}");
            }
        }
    }
    for seed in 0..40 {
        for name in ["n.csv", "n.json", "n.txt"] {
            let mut bytes = noise(seed, 200);
            if seed % 2 == 0 {
                // Commas, braces and newlines among the noise, to get past the first checks.
                bytes.extend_from_slice(b"file,x,y,z\n,,,\n{[\"luminaires\"]}");
                bytes.rotate_left(seed as usize);
            }
            let path = dir.path().join(name);
            std::fs::write(&path, &bytes).unwrap();
            if let Err(e) = read_schedule(&path, DVec3::Y) {
                assert!(!e.to_string().contains('\n'), "{e}");
            }
        }
    }
}
