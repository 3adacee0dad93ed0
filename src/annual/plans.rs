//! Plans of the annual metrics, pictures like the grid's `grid.png` ([`crate::grid::plan_image`]:
//! one top view per storey, north up) with a fixed linear scale instead of fitted lux:
//!
//! - `da300.png` (the threshold in the name: `da500.png` for DA500), `udi_fell_short.png`,
//!   `udi_useful.png`, `udi_exceeded.png`: % of occupied hours, 0 (dark blue) to 100 (yellow),
//!   ticks every 20;
//! - `ase.png`: the occupied hours of direct sun at or above ASE's illuminance, 0 to twice
//!   ASE's hours (0–500 h by default, so the limit of 250 h is the middle of the scale; more
//!   is drawn as the top colour).
//!
//! A fixed scale lets two designs be compared picture to picture.

use super::metrics::{AnnualMetrics, SensorMetrics};
use super::AnnualError;
use crate::grid::{plan_image_scaled, PlanScale, Sensor};
use crate::render::false_colour::label;
use crate::sky::Compass;
use std::path::{Path, PathBuf};

/// Each plan's file name and picture, in the order of the [module docs](self).
///
/// # Panics
/// If `metrics` does not hold one row per sensor (a caller's bug).
pub fn plans(
    sensors: &[Sensor],
    compass: &Compass,
    spacing_hint: f32,
    width: u32,
    metrics: &AnnualMetrics,
) -> Vec<(String, image::RgbImage)> {
    assert_eq!(
        sensors.len(),
        metrics.sensors.len(),
        "one metric row per sensor"
    );
    let t = &metrics.summary.thresholds;
    let percent = PlanScale::Linear {
        lo: 0.0,
        hi: 100.0,
        step: 20.0,
        unit: "%".into(),
    };
    let ase_top = 2.0 * t.ase_hours.max(1) as f64;
    let hours = PlanScale::Linear {
        lo: 0.0,
        hi: ase_top,
        step: ase_top / 5.0,
        unit: "h".into(),
    };
    type Pick = fn(&SensorMetrics) -> f64;
    let pictures: [(String, Pick, &PlanScale); 5] = [
        (
            format!("da{}.png", label_plain(t.da_lux)),
            |m| m.da_percent,
            &percent,
        ),
        (
            "udi_fell_short.png".into(),
            |m| m.udi_fell_short_percent,
            &percent,
        ),
        ("udi_useful.png".into(), |m| m.udi_useful_percent, &percent),
        (
            "udi_exceeded.png".into(),
            |m| m.udi_exceeded_percent,
            &percent,
        ),
        ("ase.png".into(), |m| m.ase_hours as f64, &hours),
    ];
    pictures
        .into_iter()
        .map(|(name, pick, scale)| {
            let values: Vec<f64> = metrics.sensors.iter().map(pick).collect();
            let img = plan_image_scaled(sensors, &values, compass, spacing_hint, width, scale);
            (name, img)
        })
        .collect()
}

/// Writes [`plans`] as PNG files into `dir`, returning their paths.
pub fn write_plans(
    dir: &Path,
    sensors: &[Sensor],
    compass: &Compass,
    spacing_hint: f32,
    width: u32,
    metrics: &AnnualMetrics,
) -> Result<Vec<PathBuf>, AnnualError> {
    let mut out = Vec::new();
    for (name, img) in plans(sensors, compass, spacing_hint, width, metrics) {
        let path = dir.join(name);
        img.save(&path).map_err(|e| AnnualError::Write {
            path: path.clone(),
            source: std::io::Error::other(e),
        })?;
        out.push(path);
    }
    Ok(out)
}

/// A threshold for a file name: "300", "1000", "250.5" (no "k").
fn label_plain(v: f64) -> String {
    if v >= 1000.0 {
        format!("{}", (v * 1000.0).round() / 1000.0)
    } else {
        label(v)
    }
}

#[cfg(test)]
mod tests {
    use super::super::metrics::Thresholds;
    use super::super::{En17037, Occupancy};
    use super::*;
    use glam::Vec3;

    /// A 4 × 2 lattice of 0.5 m, DA rising eastwards 0, 33, 67, 100 %, ASE hours 0 … 700.
    fn grid() -> (Vec<Sensor>, AnnualMetrics) {
        let mut sensors = Vec::new();
        let mut rows = Vec::new();
        for j in 0..2 {
            for i in 0..4 {
                sensors.push(Sensor {
                    position: Vec3::new(0.25 + 0.5 * i as f32, 0.8, -0.25 - 0.5 * j as f32),
                    normal: Vec3::Y,
                });
                let da = 100.0 * i as f64 / 3.0;
                rows.push(SensorMetrics {
                    weight: 1.0,
                    da_percent: da,
                    udi_fell_short_percent: 100.0 - da,
                    udi_useful_percent: da,
                    udi_exceeded_percent: 0.0,
                    ase_hours: 100 * (i + 4 * j) as u32,
                });
            }
        }
        let summary = super::super::AnnualSummary {
            occupancy: Occupancy::default(),
            thresholds: Thresholds::default(),
            period_hours: 0,
            simulated_hours: 0,
            occupied_hours: 0,
            sensors: 8,
            weight: 8.0,
            sda_percent: 0.0,
            ase_percent: 0.0,
            da_mean_percent: 0.0,
            udi_fell_short_percent: 0.0,
            udi_useful_percent: 0.0,
            udi_exceeded_percent: 0.0,
            en17037: En17037 {
                daylight_hours: 0,
                level: "none".into(),
                levels: vec![],
            },
        };
        (
            sensors,
            AnnualMetrics {
                summary,
                sensors: rows,
            },
        )
    }

    #[test]
    fn annual_plans_are_named_and_drawn_on_fixed_scales() {
        let (sensors, metrics) = grid();
        let compass = Compass::default();
        let pictures = plans(&sensors, &compass, 0.5, 300, &metrics);
        let names: Vec<&str> = pictures.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(
            names,
            [
                "da300.png",
                "udi_fell_short.png",
                "udi_useful.png",
                "udi_exceeded.png",
                "ase.png"
            ]
        );
        // DA 0 % is the scale's bottom colour, 100 % its top, wherever the values lie.
        let da = &pictures[0].1;
        let colours: std::collections::HashSet<[u8; 3]> = da.pixels().map(|p| p.0).collect();
        use crate::render::false_colour::colour_at;
        assert!(colours.contains(&colour_at(0.0)) && colours.contains(&colour_at(1.0)));
        // Exceeded is 0 everywhere: no top colour in its panels (the legend bar has it).
        let w = 300 - 1;
        let top = colour_at(1.0);
        let ex = &pictures[3].1;
        assert!(!(0..w).any(|x| (0..ex.height()).any(|y| ex.get_pixel(x, y).0 == top)));
        // ASE: 700 h is beyond the 500 h top and drawn as it.
        assert!(pictures[4].1.pixels().any(|p| p.0 == top));
        let d = tempfile::tempdir().unwrap();
        let paths = write_plans(d.path(), &sensors, &compass, 0.5, 300, &metrics).unwrap();
        assert_eq!(paths.len(), 5);
        assert!(paths.iter().all(|p| p.exists()));
        let e = write_plans(&d.path().join("no"), &sensors, &compass, 0.5, 300, &metrics);
        assert!(e.unwrap_err().to_string().contains("cannot write"));
    }

    #[test]
    fn annual_plan_names_carry_the_threshold() {
        assert_eq!(label_plain(300.0), "300");
        assert_eq!(label_plain(500.0), "500");
        assert_eq!(label_plain(1000.0), "1000");
        assert_eq!(label_plain(250.5), "250.5");
    }
}
