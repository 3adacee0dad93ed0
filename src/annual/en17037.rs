//! EN 17037:2018 *Daylight in buildings*, daylight provision by the illuminance method (Annex
//! A, Table A.1): the level a grid reaches over the standard's daylight hours.
//!
//! **The criteria**, for daylight openings in vertical and inclined surfaces (windows): a
//! level is met when, for at least half of the daylight hours (F_time = 50 %),
//!
//! - the **target illuminance** E_T is reached over at least half of the reference plane
//!   (F_plane = 50 %), and
//! - the **minimum target illuminance** E_TM is reached over at least 95 % of it,
//!
//! each criterion counted on its own hours. The levels ([`LEVELS`]): minimum E_T 300 / E_TM
//! 100 lux, medium 500 / 300, high 750 / 500. "Reached" is taken as E ≥ the threshold; the
//! plane's share is the share of sensor weight ([`super::indoor_weights`]). The level
//! reported is the highest whose two criteria are both met, or "none". Openings in
//! horizontal surfaces (rooflights), for which the standard asks E_T over 95 % of the plane
//! instead, are not treated separately. The reference plane itself (0.85 m above the floor,
//! a 0.5 m band along the walls left out) is the grid's to place.
//!
//! **Daylight hours.** The standard counts the half of the year's hours with the most
//! daylight: 4,380 of 8,760, the hours of the weather file with the largest **diffuse
//! horizontal illuminance** (the same half whose median, E_v,d,med, sets the daylight-factor
//! targets of its other method). This is how tools implementing the standard read it
//! (ClimateStudio: "the 4380 hours with the most diffuse horizontal illuminance in the weather
//! file"; Ladybug Tools' `epw-to-daylight-hours`: "half the year with the largest quantity of
//! daylight"). Here: the ⌊n/2⌋ hours of the period's n with the largest
//! [`Period::diffuse`](super::Period::diffuse), equal values taken earliest first
//! ([`daylight_hours`]). They are not the occupied hours: EN 17037 has no schedule. A daylight
//! hour without a row in the matrices is dark at every sensor and meets no criterion.

use super::{percent, Series};

/// A level of daylight provision: its name, target and minimum target illuminance (lux).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Level {
    pub name: &'static str,
    pub target_lux: f64,
    pub minimum_lux: f64,
}

/// EN 17037's levels for vertical and inclined openings (Table A.1), lowest first.
pub const LEVELS: [Level; 3] = [
    Level {
        name: "minimum",
        target_lux: 300.0,
        minimum_lux: 100.0,
    },
    Level {
        name: "medium",
        target_lux: 500.0,
        minimum_lux: 300.0,
    },
    Level {
        name: "high",
        target_lux: 750.0,
        minimum_lux: 500.0,
    },
];

/// The share of the reference plane that must reach the target illuminance.
pub const PLANE_TARGET: f64 = 0.5;
/// The share of the reference plane that must reach the minimum target illuminance.
pub const PLANE_MINIMUM: f64 = 0.95;
/// The share of daylight hours each criterion must hold for.
pub const TIME: f64 = 0.5;

/// How one level fared.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LevelResult {
    /// "minimum", "medium" or "high".
    pub level: String,
    /// E_T and E_TM, lux.
    pub target_lux: f64,
    pub minimum_lux: f64,
    /// The share of daylight hours with E ≥ E_T over ≥ 50 % of the plane, %.
    pub target_hours_percent: f64,
    /// The share of daylight hours with E ≥ E_TM over ≥ 95 % of the plane, %.
    pub minimum_hours_percent: f64,
    /// Whether both shares are at least 50 %.
    pub met: bool,
}

/// EN 17037's daylight provision of a grid.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct En17037 {
    /// How many daylight hours were counted (4,380 in a year of 8,760).
    pub daylight_hours: usize,
    /// The highest level met: "minimum", "medium", "high", or "none".
    pub level: String,
    /// Each level, lowest first.
    pub levels: Vec<LevelResult>,
}

/// EN 17037's daylight hours among the hours whose diffuse daylight is `diffuse`: the ⌊n/2⌋
/// with the most, equal values earliest first (the [module docs](self)).
pub fn daylight_hours(diffuse: &[f64]) -> Vec<bool> {
    let mut order: Vec<usize> = (0..diffuse.len()).collect();
    order.sort_by(|&a, &b| diffuse[b].total_cmp(&diffuse[a]).then(a.cmp(&b)));
    let mut out = vec![false; diffuse.len()];
    for &k in &order[..diffuse.len() / 2] {
        out[k] = true;
    }
    out
}

/// The levels `series` meets over the period's hours marked in `daylight`, the plane shared by
/// `weights` (both checked by the caller: one weight per sensor, one mark per hour).
pub fn evaluate(series: &Series, weights: &[f64], daylight: &[bool]) -> En17037 {
    let n = series.sensors;
    let total: f64 = weights.iter().sum();
    // Per level, the hours meeting the target and the minimum criteria.
    let mut hours = [[0usize; 2]; LEVELS.len()];
    for (r, &p) in series.rows.iter().enumerate() {
        if !daylight[p] || total <= 0.0 {
            continue;
        }
        let lux = &series.lux[r * n..(r + 1) * n];
        for (level, h) in LEVELS.iter().zip(hours.iter_mut()) {
            let reached = |lim: f64| -> f64 {
                let w = lux.iter().zip(weights).filter(|(&e, _)| e as f64 >= lim);
                w.map(|(_, &w)| w).sum::<f64>() / total
            };
            h[0] += (reached(level.target_lux) >= PLANE_TARGET) as usize;
            h[1] += (reached(level.minimum_lux) >= PLANE_MINIMUM) as usize;
        }
    }
    let count = daylight.iter().filter(|&&d| d).count();
    let levels: Vec<LevelResult> = LEVELS
        .iter()
        .zip(hours)
        .map(|(level, [t, m])| LevelResult {
            level: level.name.to_string(),
            target_lux: level.target_lux,
            minimum_lux: level.minimum_lux,
            target_hours_percent: percent(t, count),
            minimum_hours_percent: percent(m, count),
            met: count > 0 && t as f64 / count as f64 >= TIME && m as f64 / count as f64 >= TIME,
        })
        .collect();
    let level = (levels.iter().rev().find(|l| l.met)).map_or("none", |l| l.level.as_str());
    En17037 {
        daylight_hours: count,
        level: level.to_string(),
        levels,
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Period, Stamp};
    use super::*;

    fn period(diffuse: Vec<f64>) -> Period {
        let stamps = (0..diffuse.len())
            .map(|k| Stamp {
                month: 1,
                day: 1 + k as u32 / 24,
                hour: (k % 24) as f64 + 0.5,
            })
            .collect();
        Period { stamps, diffuse }
    }

    #[test]
    fn annual_daylight_hours_are_the_brighter_half() {
        let d = daylight_hours(&[0.0, 5.0, 3.0, 5.0, 1.0, 0.0, 4.0]);
        // ⌊7/2⌋ = 3: the two 5s and the 4.
        assert_eq!(d, [false, true, false, true, false, false, true]);
        // Ties go to the earlier hour.
        assert_eq!(daylight_hours(&[1.0; 4]), [true, true, false, false]);
        assert!(daylight_hours(&[]).is_empty());
        // A year: 4,380 hours.
        let year: Vec<f64> = (0..8760).map(|k| ((k * 7919) % 1000) as f64).collect();
        assert_eq!(daylight_hours(&year).iter().filter(|&&b| b).count(), 4380);
    }

    /// Four hours, all daylight hours (the period's other four are dark), and 20 sensors of
    /// weight 1: `lux[h]` gives each hour's values.
    fn levels_of(lux: &[[f32; 20]; 4]) -> En17037 {
        let p = period(vec![1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0]);
        let flat: Vec<f32> = lux.iter().flatten().copied().collect();
        let series = Series {
            period: &p,
            rows: &[0, 1, 2, 3],
            sensors: 20,
            lux: &flat,
            sun_lux: &vec![0.0; flat.len()],
        };
        evaluate(&series, &[1.0; 20], &daylight_hours(&p.diffuse))
    }

    #[test]
    fn annual_en17037_levels_by_plane_and_time() {
        // 10 of 20 sensors at 500 lux, 8 at 300, one at 299 and one at 99: 19 of 20 (95 %)
        // at 100 lux or more, 18 at 300.
        let mut bright = [300.0f32; 20];
        bright[..10].fill(500.0);
        bright[18] = 299.0;
        bright[19] = 99.0;
        let dark = [0.0f32; 20];
        // Two of four hours bright: F_time exactly 50 % meets it.
        let r = levels_of(&[bright, dark, bright, dark]);
        assert_eq!(r.daylight_hours, 4);
        assert_eq!(r.levels[0].target_hours_percent, 50.0);
        assert_eq!(r.levels[0].minimum_hours_percent, 50.0);
        assert!(r.levels[0].met);
        // Medium: 500 lux over 10 of 20 = 50 % of the plane meets the target, but 300 lux
        // over 18 of 20 = 90 % misses the minimum's 95 %.
        assert_eq!(r.levels[1].target_hours_percent, 50.0);
        assert_eq!(r.levels[1].minimum_hours_percent, 0.0);
        assert!(!r.levels[1].met);
        assert_eq!(r.level, "minimum");
        // One bright hour of four: 25 % < 50 %.
        let r = levels_of(&[bright, dark, dark, dark]);
        assert_eq!(r.level, "none");
        // 18 of 20 (90 %) at 100 lux: the minimum criterion fails however long it lasts.
        let mut patchy = [1000.0f32; 20];
        patchy[18..].fill(50.0);
        let r = levels_of(&[patchy; 4]);
        assert_eq!(r.levels[0].target_hours_percent, 100.0);
        assert_eq!(r.levels[0].minimum_hours_percent, 0.0);
        assert_eq!(r.level, "none");
        // Everything at 750 lux: high.
        let r = levels_of(&[[750.0; 20]; 4]);
        assert!(r.levels.iter().all(|l| l.met));
        assert_eq!(r.level, "high");
    }

    #[test]
    fn annual_en17037_counts_dark_daylight_hours_and_no_weight() {
        // Four daylight hours of eight, only two with rows: at most 50 %.
        let p = period(vec![1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0]);
        let lux = vec![1000.0f32; 2];
        let series = Series {
            period: &p,
            rows: &[0, 1],
            sensors: 1,
            lux: &lux,
            sun_lux: &[0.0, 0.0],
        };
        let daylight = daylight_hours(&p.diffuse);
        let r = evaluate(&series, &[1.0], &daylight);
        assert_eq!(r.levels[2].target_hours_percent, 50.0);
        assert_eq!(r.level, "high");
        let r = evaluate(&series, &[0.0], &daylight);
        assert_eq!(r.levels[0].target_hours_percent, 0.0);
        assert_eq!(r.level, "none");
        // No hours at all: nothing met, nothing NaN.
        let empty = Period {
            stamps: vec![],
            diffuse: vec![],
        };
        let none = Series {
            period: &empty,
            rows: &[],
            sensors: 1,
            lux: &[],
            sun_lux: &[],
        };
        let r = evaluate(&none, &[1.0], &[]);
        assert_eq!((r.daylight_hours, r.level.as_str()), (0, "none"));
        assert_eq!(r.levels[0].target_hours_percent, 0.0);
    }
}
