//! Sensors to and from CSV: `--grid POINTS.csv` in, `grid.csv` out.
//!
//! The format is plain comma-separated numbers with a header line, what a spreadsheet or a
//! script writes: no quoting, blank lines and lines starting with `#` skipped, a byte-order
//! mark tolerated. A file written by [`write_csv`] reads back with [`read_points`] to the same
//! sensors, bit for bit, so a grid can be reused for another sky or another design.

use super::{GridError, Sensor, Zone};
use glam::Vec3;
use std::io::Write;
use std::path::Path;

/// The columns [`read_points`] needs, in the order of [`Sensor`]'s fields.
const NEEDED: [&str; 6] = ["x", "y", "z", "nx", "ny", "nz"];

/// The header [`write_csv`] writes: position, facing, illuminance (lux), daylight factor (%),
/// then where the sensor is ([`Zone`]): its storey (from 0), its room (from 1 within the
/// storey, 0 for none) and whether it is indoors (1) or outdoors (0).
pub const CSV_HEADER: &str = "x,y,z,nx,ny,nz,lux,df,storey,room,indoor";

/// Reads sensors from a CSV file whose header names at least `x,y,z,nx,ny,nz` (any order, any
/// case; other columns are ignored): model coordinates and the direction each sensor faces,
/// normalised here. A line that is not numbers, not finite, too short or with a zero normal is
/// refused with the file and the line number; so is a file without points.
pub fn read_points(path: &Path) -> Result<Vec<Sensor>, GridError> {
    let text = std::fs::read_to_string(path).map_err(|source| GridError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(k, l)| (k + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let (hline, header) = lines
        .next()
        .ok_or_else(|| GridError::csv(path, 1, "no header line (x,y,z,nx,ny,nz)"))?;
    let columns = column_indices(header).map_err(|m| GridError::csv(path, hline, m))?;
    let sensors = lines
        .map(|(k, l)| sensor(l, &columns).map_err(|m| GridError::csv(path, k, m)))
        .collect::<Result<Vec<Sensor>, GridError>>()?;
    if sensors.is_empty() {
        return Err(GridError::NoPoints(path.to_path_buf()));
    }
    Ok(sensors)
}

/// Where each of [`NEEDED`] is in the header, or which are missing.
fn column_indices(header: &str) -> Result<[usize; 6], String> {
    let names: Vec<String> = header
        .split(',')
        .map(|n| n.trim().trim_matches('"').to_ascii_lowercase())
        .collect();
    let find = |want: &str| names.iter().position(|n| n == want);
    let missing: Vec<&str> = NEEDED.into_iter().filter(|w| find(w).is_none()).collect();
    if !missing.is_empty() {
        return Err(format!(
            "the header lacks the column{} {} (it needs x,y,z,nx,ny,nz)",
            if missing.len() > 1 { "s" } else { "" },
            missing.join(",")
        ));
    }
    Ok(NEEDED.map(|w| find(w).unwrap_or(0)))
}

/// One data line as a sensor, or what is wrong with it.
fn sensor(line: &str, columns: &[usize; 6]) -> Result<Sensor, String> {
    let fields: Vec<&str> = line.split(',').map(str::trim).collect();
    let value = |k: usize| -> Result<f32, String> {
        let name = NEEDED[k];
        let text = fields.get(columns[k]).ok_or_else(|| {
            format!(
                "{} fields, but column {name} is field {}",
                fields.len(),
                columns[k] + 1
            )
        })?;
        match text.parse::<f32>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(format!("{name} = {text:?} is not a finite number")),
        }
    };
    let v: Vec<f32> = (0..6).map(value).collect::<Result<_, _>>()?;
    let normal = Vec3::new(v[3], v[4], v[5]);
    let len = normal.length();
    if !(len > 0.0 && len.is_finite()) {
        return Err(format!(
            "the normal ({}, {}, {}) has no direction",
            v[3], v[4], v[5]
        ));
    }
    Ok(Sensor {
        position: Vec3::new(v[0], v[1], v[2]),
        // A normal already unit to within rounding is kept as written, so a grid.csv reads
        // back bit for bit; normalising it again could move its last bit.
        normal: if (len - 1.0).abs() > 1e-6 {
            normal / len
        } else {
            normal
        },
    })
}

/// Writes `grid.csv`: the header [`CSV_HEADER`] and one line per sensor, numbers in their
/// shortest form that reads back exactly.
///
/// A value that is not finite is written as 0: the file must stay numbers for spreadsheets and
/// for [`read_points`], and [`stats`](super::stats) counts it as 0 too, so the file and the
/// summary agree. Such a value is a bug in the gather, not an input to report: debug builds
/// stop on it.
///
/// # Panics
/// If `lux`, `df` or `zones` does not hold one value per sensor (a caller's bug).
pub fn write_csv(
    path: &Path,
    sensors: &[Sensor],
    lux: &[f64],
    df: &[f64],
    zones: &[Zone],
) -> std::io::Result<()> {
    assert_eq!(sensors.len(), lux.len(), "one lux value per sensor");
    assert_eq!(sensors.len(), df.len(), "one daylight factor per sensor");
    assert_eq!(sensors.len(), zones.len(), "one zone per sensor");
    let mut out = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(out, "{CSV_HEADER}")?;
    for (((s, &l), &d), z) in sensors.iter().zip(lux).zip(df).zip(zones) {
        let (p, n) = (s.position, s.normal);
        writeln!(
            out,
            "{},{},{},{},{},{},{},{},{},{},{}",
            p.x,
            p.y,
            p.z,
            n.x,
            n.y,
            n.z,
            finite(l),
            finite(d),
            z.storey,
            z.room,
            z.indoor as u8
        )?;
    }
    out.flush()
}

/// `v`, or 0 if it is not finite (see [`write_csv`]); debug builds stop instead.
pub(super) fn finite(v: f64) -> f64 {
    debug_assert!(v.is_finite(), "a grid value is {v}");
    if v.is_finite() {
        v
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sensors() -> Vec<Sensor> {
        vec![
            Sensor {
                position: Vec3::new(0.25, 0.8, -4.75),
                normal: Vec3::Y,
            },
            Sensor {
                position: Vec3::new(1.0 / 3.0, 1e-7, 123456.79),
                normal: Vec3::new(0.6, 0.0, -0.8).normalize(),
            },
        ]
    }

    #[test]
    fn grid_csv_round_trips_bit_for_bit() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("grid.csv");
        let s = sensors();
        let zones = [
            Zone {
                storey: 0,
                room: 2,
                indoor: true,
            },
            Zone {
                storey: 3,
                room: 0,
                indoor: false,
            },
        ];
        write_csv(&path, &s, &[512.25, 1.0 / 7.0], &[2.5, 0.001], &zones).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(
            text.lines().next(),
            Some("x,y,z,nx,ny,nz,lux,df,storey,room,indoor")
        );
        assert_eq!(
            text.lines().nth(1),
            Some("0.25,0.8,-4.75,0,1,0,512.25,2.5,0,2,1")
        );
        assert!(text.lines().nth(2).unwrap().ends_with(",3,0,0"), "{text}");
        assert_eq!(read_points(&path).unwrap(), s);
    }

    #[test]
    fn grid_csv_columns_in_any_order_extra_ignored_normal_normalised() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.csv");
        let text =
            "\u{feff}# my sensors\nName, NZ,ny,nx,z,y,x\n\nA,2,0,0,3,2,1\r\nB,0,0,-5,0,0,0\n";
        std::fs::write(&path, text).unwrap();
        let s = read_points(&path).unwrap();
        assert_eq!(s.len(), 2);
        assert_eq!(s[0].position, Vec3::new(1.0, 2.0, 3.0));
        assert_eq!(s[0].normal, Vec3::Z);
        assert_eq!(s[1].normal, Vec3::NEG_X);
    }

    /// Writes `text` to a file and returns the one-line error reading it gives.
    fn error_of(text: &str) -> (String, String) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("pts.csv");
        std::fs::write(&path, text).unwrap();
        let e = read_points(&path).unwrap_err().to_string();
        assert!(!e.contains('\n'), "{e}");
        (e, path.display().to_string())
    }

    #[test]
    fn grid_csv_errors_name_file_and_line() {
        let head = "x,y,z,nx,ny,nz\n";
        let (e, p) = error_of(&format!("{head}0,0,0,0,0,1\n\n1,2,abc,0,0,1\n"));
        assert!(e.starts_with(&format!("--grid: {p}:4: z = \"abc\"")), "{e}");
        let (e, p) = error_of(&format!("{head}0,0,0,0,0,0\n"));
        assert!(e.contains(&format!("{p}:2: the normal")), "{e}");
        let (e, _) = error_of(&format!("{head}0,0,NaN,0,0,1\n"));
        assert!(e.contains(":2: z = \"NaN\" is not a finite number"), "{e}");
        let (e, _) = error_of(&format!("{head}0,0,0,0,1\n"));
        assert!(e.contains(":2: 5 fields, but column nz is field 6"), "{e}");
        let (e, p) = error_of("x,y,z,normal\n1,2,3,4\n");
        assert!(
            e.contains(&format!("{p}:1: the header lacks the columns nx,ny,nz")),
            "{e}"
        );
        let (e, _) = error_of(head);
        assert!(e.ends_with("holds no points"), "{e}");
        let (e, _) = error_of("");
        assert!(e.contains(":1: no header line"), "{e}");
        let missing = read_points(Path::new("/nonexistent/pts.csv")).unwrap_err();
        assert!(
            missing
                .to_string()
                .starts_with("--grid: cannot read /nonexistent/pts.csv"),
            "{missing}"
        );
    }

    #[test]
    fn grid_csv_writes_no_nan() {
        // Debug builds stop on a non-finite value (a bug upstream); release builds write 0.
        if cfg!(debug_assertions) {
            return;
        }
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("grid.csv");
        let zone = Zone {
            storey: 0,
            room: 1,
            indoor: true,
        };
        write_csv(
            &path,
            &sensors()[..1],
            &[f64::NAN],
            &[f64::INFINITY],
            &[zone],
        )
        .unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.ends_with(",0,0,0,1,1\n"), "{text}");
    }
}
