//! A second weather file, or the model turned, at the cost of the product alone: the
//! coefficients of an earlier `radiosity annual` run (`--coefficients DIR`) read back instead of
//! solving again, and the model's orientation turned against the sky (`--rotate DEG`).
//!
//! What is read from DIR: `summary.json` (the subdivision and the hash of the model and its
//! mesh settings, which must be this run's), `annual/coefficients.npy` and
//! `annual/reflected.npy` (sensors × columns, f32) and `grid.csv` (the sensors, their facing and
//! zones). The model is still loaded: the direct sun is traced hour by hour.

use crate::annual::hourly::Coefficients;
use crate::error::Error;
use crate::grid::{Sensor, Zone};
use crate::sky::matrix::Hour;
use crate::sky::SolarAngles;
use glam::Vec3;
use std::path::Path;

/// Coefficients and sensors read back from an earlier run.
pub struct Reused {
    pub coefficients: Coefficients,
    pub sensors: Vec<Sensor>,
    pub zones: Vec<Zone>,
}

/// Reads what `dir` holds (module notes) and checks it belongs to a model of hash
/// `scene_hash` solved at `subdivision`.
pub fn read(dir: &Path, scene_hash: u64, subdivision: u32) -> Result<Reused, Error> {
    let what = |name: &str| dir.join(name).display().to_string();
    let bad =
        |name: &str, why: String| Error::Invalid(format!("--coefficients: {}: {why}", what(name)));
    let text = std::fs::read_to_string(dir.join("summary.json"))
        .map_err(|e| bad("summary.json", format!("cannot read it ({e})")))?;
    let summary: serde_json::Value = serde_json::from_str(&text)
        .map_err(|e| bad("summary.json", format!("not a summary ({e})")))?;
    let c = &summary["coefficients"];
    let (Some(mf), Some(hash)) = (c["subdivision"].as_u64(), c["scene_hash"].as_str()) else {
        return Err(bad(
            "summary.json",
            "not the summary of `radiosity annual`".into(),
        ));
    };
    if hash != format!("{scene_hash:016x}") {
        return Err(bad(
            "summary.json",
            "its coefficients are of another model or patch size (the model, --patch-size and --two-sided must be the run's)".into(),
        ));
    }
    if mf != u64::from(subdivision) {
        return Err(bad(
            "summary.json",
            format!("its coefficients are of --subdivision {mf}, not {subdivision}"),
        ));
    }
    let (n, total) = read_matrix(&dir.join("annual/coefficients.npy"))?;
    let (n2, reflected) = read_matrix(&dir.join("annual/reflected.npy"))?;
    let (sensors, zones) = read_grid(&dir.join("grid.csv"))?;
    let columns = 1 + crate::sky::reinhart::sky_patch_count(subdivision);
    if n != [sensors.len(), columns] || n2 != n {
        return Err(bad(
            "annual",
            format!(
                "the coefficients are {} × {} and {} × {}; grid.csv has {} sensors and MF {subdivision} {columns} columns",
                n[0], n[1], n2[0], n2[1], sensors.len()
            ),
        ));
    }
    Ok(Reused {
        coefficients: Coefficients {
            subdivision,
            columns,
            total,
            reflected,
        },
        sensors,
        zones,
    })
}

/// A 2-D `.npy` of f32: its shape and values.
fn read_matrix(path: &Path) -> Result<([usize; 2], Vec<f32>), Error> {
    let bad = |why: String| Error::Invalid(format!("--coefficients: {}: {why}", path.display()));
    let bytes = std::fs::read(path).map_err(|e| bad(format!("cannot read it ({e})")))?;
    let npy = npyz::NpyFile::new(&bytes[..]).map_err(|e| bad(format!("not a .npy file ({e})")))?;
    let shape = npy.shape().to_vec();
    let [rows, cols] = shape[..] else {
        return Err(bad(format!("{} dimensions, not 2", shape.len())));
    };
    let values: Vec<f32> = npy
        .into_vec()
        .map_err(|e| bad(format!("not a matrix of f32 ({e})")))?;
    if values.len() as u64 != rows * cols || values.iter().any(|v| !v.is_finite()) {
        return Err(bad("cut short, or not finite".into()));
    }
    Ok(([rows as usize, cols as usize], values))
}

/// The sensors of an annual `grid.csv` (`x,y,z,nx,ny,nz,lux,df,storey,room,indoor`).
fn read_grid(path: &Path) -> Result<(Vec<Sensor>, Vec<Zone>), Error> {
    let bad = |line: usize, why: &str| {
        Error::Invalid(format!(
            "--coefficients: {} line {line}: {why}",
            path.display()
        ))
    };
    let text =
        std::fs::read_to_string(path).map_err(|e| bad(0, &format!("cannot read it ({e})")))?;
    let mut sensors = Vec::new();
    let mut zones = Vec::new();
    for (i, line) in text.lines().enumerate().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let num = |k: usize| f.get(k).and_then(|v| v.trim().parse::<f32>().ok());
        let int = |k: usize| f.get(k).and_then(|v| v.trim().parse::<u32>().ok());
        let (Some(x), Some(y), Some(z), Some(nx), Some(ny), Some(nz)) =
            (num(0), num(1), num(2), num(3), num(4), num(5))
        else {
            return Err(bad(i + 1, "expected x,y,z,nx,ny,nz first"));
        };
        let (Some(storey), Some(room), Some(indoor)) = (int(8), int(9), int(10)) else {
            return Err(bad(i + 1, "expected storey,room,indoor in columns 9 to 11"));
        };
        sensors.push(Sensor {
            position: Vec3::new(x, y, z),
            normal: Vec3::new(nx, ny, nz),
        });
        zones.push(Zone {
            storey,
            room,
            indoor: indoor != 0,
        });
    }
    Ok((sensors, zones))
}

/// `hours` with the model turned `degrees` clockwise seen from above (its north then points
/// that far east of true north): every sun `degrees` further anticlockwise against the model,
/// so each hour's sky is made about the model's own patches.
pub fn rotate(hours: &mut [Hour], degrees: f64) {
    if degrees == 0.0 {
        return;
    }
    for h in hours {
        let azimuth = (h.sun.azimuth - degrees + 180.0).rem_euclid(360.0) - 180.0;
        h.sun = SolarAngles {
            altitude: h.sun.altitude,
            azimuth,
        };
    }
}
