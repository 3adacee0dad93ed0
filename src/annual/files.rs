//! The annual results as files other tools read.
//!
//! - **Matrices** ([`write_matrix`]): an hours × sensors matrix of f32 lux as NumPy's `.npy`
//!   (format 1.0, dtype `<f4`, C order, shape `(hours, sensors)`), through the `npyz` crate:
//!   `numpy.load("lux.npy")[row, sensor]`. On request the same as CSV ([`MatrixFormat::Csv`]):
//!   a header `row,0,1,…` (the sensors' indices), then one line per row, the row's index first.
//! - **`hours.csv`** ([`write_hours_csv`], [`HOURS_HEADER`]): which hour each row is.
//! - **Per-sensor metrics** ([`write_sensors_csv`], [`SENSORS_HEADER`]).
//!
//! Numbers are written in their shortest form that reads back exactly (shares of hours
//! rounded to 4 decimals first); no value is NaN or infinite (matrices that hold one are
//! refused before anything is written).

use super::metrics::SensorMetrics;
use super::{check_matrix, invalid, AnnualError, Period, Stamp};
use crate::grid::{Sensor, Zone};
use crate::sky::solar::days_in_month;
use crate::weather::{LEAP_YEAR, TYPICAL_YEAR};
use std::io::Write;
use std::path::Path;

/// `hours.csv`'s header: the matrices' row (from 0), the hour of the year (from 0:
/// [`hour_of_year`]), the month (1–12), the day of the month and the hour's centre in local
/// standard time (12.5 is 12:00–13:00).
pub const HOURS_HEADER: &str = "row,hour_of_year,month,day,hour";

/// The per-sensor metrics' header: the sensor's position (model units), storey (from 0), room
/// (from 1, 0 for none), whether it is indoors (1/0) and its weight in the grid's figures;
/// then DA, UDI fell short, useful and exceeded as % of the occupied hours, and the occupied
/// hours of direct sun at or above ASE's illuminance. The thresholds are in `summary.json`
/// ([`super::AnnualSummary`]).
pub const SENSORS_HEADER: &str = "x,y,z,storey,room,indoor,weight,da_percent,\
udi_fell_short_percent,udi_useful_percent,udi_exceeded_percent,ase_hours";

/// The hour of the year of `stamp`, from 0: 24 × the days before its date plus its hour's
/// start, counting 29 February only in a `leap` year ([`Period::is_leap`]). An hourly
/// weather file's hour k (from 0) is hour k of its year: EPW's data row k + 1.
pub fn hour_of_year(stamp: Stamp, leap: bool) -> u32 {
    let year = if leap { LEAP_YEAR } else { TYPICAL_YEAR };
    let days: u32 = (1..stamp.month)
        .map(|m| days_in_month(year, m))
        .sum::<u32>()
        + stamp.day
        - 1;
    24 * days + stamp.hour.clamp(0.0, 23.0).floor() as u32
}

/// How a matrix is written ([`write_matrix`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MatrixFormat {
    /// NumPy's `.npy`, f32 (the default).
    #[default]
    Npy,
    /// CSV: the header `row,0,1,…`, then each row's index and its values.
    Csv,
}

impl MatrixFormat {
    /// The file name's extension: "npy" or "csv".
    pub fn extension(self) -> &'static str {
        match self {
            MatrixFormat::Npy => "npy",
            MatrixFormat::Csv => "csv",
        }
    }
}

/// Writes the `rows × sensors` matrix `values` (row-major) in `format` (the [module
/// docs](self)); refuses a matrix of another size or holding a value that is not finite before
/// creating the file.
pub fn write_matrix(
    path: &Path,
    values: &[f32],
    rows: usize,
    sensors: usize,
    format: MatrixFormat,
) -> Result<(), AnnualError> {
    let name = path.display().to_string();
    check_matrix(&name, values, rows, sensors, |_| String::new())?;
    write_file(path, |out| match format {
        MatrixFormat::Npy => {
            use npyz::WriterBuilder;
            let mut w = npyz::WriteOptions::<f32>::new()
                .default_dtype()
                .shape(&[rows as u64, sensors as u64])
                .writer(out)
                .begin_nd()?;
            w.extend(values.iter().copied())?;
            w.finish()
        }
        MatrixFormat::Csv => {
            write!(out, "row")?;
            for s in 0..sensors {
                write!(out, ",{s}")?;
            }
            writeln!(out)?;
            for (r, row) in values.chunks(sensors.max(1)).enumerate().take(rows) {
                write!(out, "{r}")?;
                for v in row {
                    write!(out, ",{v}")?;
                }
                writeln!(out)?;
            }
            Ok(())
        }
    })
}

/// Writes `hours.csv` ([`HOURS_HEADER`]): for each row of the matrices, its hour of `period`.
pub fn write_hours_csv(path: &Path, period: &Period, rows: &[usize]) -> Result<(), AnnualError> {
    if let Some(&r) = rows.iter().find(|&&r| r >= period.len()) {
        return Err(invalid(format!(
            "a row names hour {r} of a period of {} hours",
            period.len()
        )));
    }
    let leap = period.is_leap();
    write_file(path, |out| {
        writeln!(out, "{HOURS_HEADER}")?;
        for (row, &p) in rows.iter().enumerate() {
            let s = period.stamps[p];
            let year_hour = hour_of_year(s, leap);
            writeln!(out, "{row},{year_hour},{},{},{}", s.month, s.day, s.hour)?;
        }
        Ok(())
    })
}

/// Writes the per-sensor metrics ([`SENSORS_HEADER`]), one line per sensor.
pub fn write_sensors_csv(
    path: &Path,
    sensors: &[Sensor],
    zones: &[Zone],
    metrics: &[SensorMetrics],
) -> Result<(), AnnualError> {
    if sensors.len() != zones.len() || sensors.len() != metrics.len() {
        return Err(invalid(format!(
            "{} sensors, {} zones and {} metrics do not match",
            sensors.len(),
            zones.len(),
            metrics.len()
        )));
    }
    write_file(path, |out| {
        writeln!(out, "{SENSORS_HEADER}")?;
        for ((s, z), m) in sensors.iter().zip(zones).zip(metrics) {
            let p = s.position;
            writeln!(
                out,
                "{},{},{},{},{},{},{},{},{},{},{},{}",
                p.x,
                p.y,
                p.z,
                z.storey,
                z.room,
                z.indoor as u8,
                m.weight,
                round4(m.da_percent),
                round4(m.udi_fell_short_percent),
                round4(m.udi_useful_percent),
                round4(m.udi_exceeded_percent),
                m.ase_hours
            )?;
        }
        Ok(())
    })
}

/// Creates `path` and writes it through a buffer with `body`; any failure names the file.
fn write_file(
    path: &Path,
    body: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> std::io::Result<()>,
) -> Result<(), AnnualError> {
    let done = std::fs::File::create(path).and_then(|f| {
        let mut out = std::io::BufWriter::new(f);
        body(&mut out)?;
        out.flush()
    });
    done.map_err(|source| AnnualError::Write {
        path: path.to_path_buf(),
        source,
    })
}

/// `v` rounded to 4 decimals (a share of hours in %: 1e-4 % of 8,760 h is 32 ms).
fn round4(v: f64) -> f64 {
    (v * 1e4).round() / 1e4
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn dir() -> tempfile::TempDir {
        tempfile::tempdir().unwrap()
    }

    #[test]
    fn annual_npy_reads_back_with_its_shape() {
        let d = dir();
        let path = d.path().join("lux.npy");
        let values: Vec<f32> = (0..6).map(|k| k as f32 * 1.5).collect();
        write_matrix(&path, &values, 2, 3, MatrixFormat::Npy).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(&bytes[..6], b"\x93NUMPY");
        let npy = npyz::NpyFile::new(&bytes[..]).unwrap();
        assert_eq!(npy.shape(), &[2, 3]);
        assert_eq!(npy.order(), npyz::Order::C);
        assert_eq!(npy.into_vec::<f32>().unwrap(), values);
        // An empty matrix is a valid file too.
        write_matrix(&path, &[], 0, 3, MatrixFormat::Npy).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(npyz::NpyFile::new(&bytes[..]).unwrap().shape(), &[0, 3]);
    }

    #[test]
    fn annual_matrix_files_refuse_nan_and_bad_shapes() {
        let d = dir();
        let path = d.path().join("lux.npy");
        let npy = |path: &Path, values: &[f32], rows| {
            let e = write_matrix(path, values, rows, 2, MatrixFormat::Npy).unwrap_err();
            e.to_string()
        };
        let e = npy(&path, &[1.0, f32::NAN], 1);
        assert_eq!(
            e,
            format!(
                "annual metrics: {} at row 0, sensor 1 is NaN, not a finite illuminance",
                path.display()
            )
        );
        assert!(!path.exists(), "nothing written");
        let e = write_matrix(&path, &[1.0; 5], 2, 3, MatrixFormat::Csv);
        let e = e.unwrap_err().to_string();
        assert!(e.contains("5 values, not 2 hours × 3 sensors"), "{e}");
        let e = npy(&d.path().join("no/dir.npy"), &[1.0, 2.0], 1);
        assert!(e.contains("cannot write"), "{e}");
    }

    #[test]
    fn annual_matrix_csv_has_row_and_sensor_indices() {
        let d = dir();
        let path = d.path().join("lux.csv");
        write_matrix(&path, &[0.5, 300.0, 1e6, 0.0], 2, 2, MatrixFormat::Csv).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(text, "row,0,1\n0,0.5,300\n1,1000000,0\n");
    }

    #[test]
    fn annual_hours_csv_numbers_hours_of_the_year() {
        let at = |month, day, hour| Stamp { month, day, hour };
        assert_eq!(hour_of_year(at(1, 1, 0.5), false), 0);
        assert_eq!(hour_of_year(at(1, 1, 12.5), false), 12);
        assert_eq!(hour_of_year(at(3, 1, 0.5), false), 59 * 24);
        assert_eq!(hour_of_year(at(3, 1, 0.5), true), 60 * 24);
        assert_eq!(hour_of_year(at(12, 31, 23.5), false), 8759);
        assert_eq!(hour_of_year(at(12, 31, 23.5), true), 8783);
        let period = Period {
            stamps: vec![at(1, 1, 0.5), at(1, 1, 8.5), at(6, 21, 12.5)],
            diffuse: vec![0.0, 10.0, 20.0],
        };
        let d = dir();
        let path = d.path().join("hours.csv");
        write_hours_csv(&path, &period, &[1, 2]).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(
            text,
            format!(
                "{HOURS_HEADER}\n0,8,1,1,8.5\n1,{},6,21,12.5\n",
                171 * 24 + 12
            )
        );
        assert!(write_hours_csv(&path, &period, &[3]).is_err());
    }

    #[test]
    fn annual_sensors_csv_has_one_line_per_sensor() {
        let sensors = [Sensor {
            position: Vec3::new(1.25, 0.8, -2.0),
            normal: Vec3::Y,
        }];
        let zones = [Zone {
            storey: 0,
            room: 2,
            indoor: true,
        }];
        let m = SensorMetrics {
            weight: 1.0,
            da_percent: 100.0 / 3.0,
            udi_fell_short_percent: 50.0,
            udi_useful_percent: 100.0 / 6.0,
            udi_exceeded_percent: 100.0 / 3.0,
            ase_hours: 251,
        };
        let d = dir();
        let path = d.path().join("sensors.csv");
        write_sensors_csv(&path, &sensors, &zones, &[m]).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], SENSORS_HEADER);
        assert_eq!(
            lines[1],
            "1.25,0.8,-2,0,2,1,1,33.3333,50,16.6667,33.3333,251"
        );
        assert_eq!(lines[0].split(',').count(), lines[1].split(',').count());
        assert!(write_sensors_csv(&path, &sensors, &zones, &[]).is_err());
    }
}
