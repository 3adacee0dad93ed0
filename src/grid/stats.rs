//! The figures daylighting standards quote of a grid: mean, minimum and maximum illuminance,
//! uniformity U0 = minimum / mean (as EN 12464-1 defines it), Emin / Emax, the median, and the mean daylight
//! factor, of the whole grid ([`GridStats`]) and of each storey and room ([`GridReport`]).
//! They go to `summary.json`.

use super::csv::finite;
use super::{Outdoor, Placed};
use std::collections::BTreeMap;

/// A grid's figures. Every sensor weighs the same: on a work plane's lattice each stands for the
/// same floor area, as the standards' grids assume.
#[derive(serde::Serialize, serde::Deserialize, Clone, Copy, Debug, PartialEq)]
pub struct GridStats {
    /// How many sensors.
    pub points: u64,
    /// Illuminance, lux.
    pub mean_lux: f64,
    pub min_lux: f64,
    pub max_lux: f64,
    /// U0 = min / mean (0 when the mean is 0).
    pub uniformity: f64,
    /// Emin / Emax, the diversity lighting designers quote beside U0 (0 when the maximum is 0).
    #[serde(default)]
    pub min_over_max: f64,
    /// Daylight factor, %.
    pub mean_df: f64,
    /// The middle value (the mean of the two middle values for an even count), lux.
    pub median_lux: f64,
}

/// The figures of `lux` and `df` (one value per sensor each). Every figure of an empty grid is
/// 0, never NaN (JSON has no NaN). A value that is not finite counts as 0, as in
/// [`write_csv`](super::write_csv).
///
/// # Panics
/// If `lux` and `df` differ in length (a caller's bug).
pub fn stats(lux: &[f64], df: &[f64]) -> GridStats {
    assert_eq!(lux.len(), df.len(), "one daylight factor per lux value");
    let mut sorted: Vec<f64> = lux.iter().map(|&v| finite(v)).collect();
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len();
    if n == 0 {
        return GridStats {
            points: 0,
            mean_lux: 0.0,
            min_lux: 0.0,
            max_lux: 0.0,
            uniformity: 0.0,
            min_over_max: 0.0,
            mean_df: 0.0,
            median_lux: 0.0,
        };
    }
    let mean_lux = sorted.iter().sum::<f64>() / n as f64;
    let (min_lux, max_lux) = (sorted[0], sorted[n - 1]);
    GridStats {
        points: n as u64,
        mean_lux,
        min_lux,
        max_lux,
        uniformity: if mean_lux > 0.0 {
            min_lux / mean_lux
        } else {
            0.0
        },
        min_over_max: if max_lux > 0.0 {
            min_lux / max_lux
        } else {
            0.0
        },
        mean_df: df.iter().map(|&v| finite(v)).sum::<f64>() / n as f64,
        median_lux: (sorted[(n - 1) / 2] + sorted[n / 2]) / 2.0,
    }
}

/// A storey's figures (the summary's `grid.storeys`).
#[derive(serde::Serialize, serde::Deserialize, Clone, Debug, PartialEq)]
pub struct StoreyStats {
    /// From 0 at the bottom.
    pub storey: u32,
    /// The height of its lowest sensors along the zenith, metres (as the plan labels it).
    pub height: f64,
    /// How many rooms were found on it.
    pub rooms: u32,
    /// The floor area its sensors stand for, m² (sensors × the lattice's cell).
    pub area: f64,
    #[serde(flatten)]
    pub stats: GridStats,
}

/// A room's figures (the summary's `grid.rooms`).
#[derive(serde::Serialize, serde::Deserialize, Clone, Debug, PartialEq)]
pub struct RoomStats {
    pub storey: u32,
    /// From 1 within its storey, as in `grid.csv`.
    pub room: u32,
    /// The floor area its sensors stand for, m².
    pub area: f64,
    #[serde(flatten)]
    pub stats: GridStats,
}

/// The summary's `grid`: the whole grid's figures (the keys of [`GridStats`], at the top), the
/// outdoor sensors found and what became of them, and the figures of each storey and room.
#[derive(serde::Serialize, serde::Deserialize, Clone, Debug, PartialEq)]
pub struct GridReport {
    #[serde(flatten)]
    pub all: GridStats,
    /// The floor area the sensors stand for, m² (0 for points from a file without a spacing).
    pub area: f64,
    /// `--grid-outdoor`: `drop` or `keep`.
    pub outdoor: Outdoor,
    /// Sensors found outdoors (nothing over them), dropped or kept.
    pub outdoor_points: u64,
    /// Of those, how many were left out of the grid.
    pub dropped_points: u64,
    /// Bottom up.
    pub storeys: Vec<StoreyStats>,
    /// By storey, then room number.
    pub rooms: Vec<RoomStats>,
}

impl GridReport {
    /// The figures of the sensors `placed` (kept ones only) from their `lux` and `df`.
    ///
    /// # Panics
    /// If `lux` or `df` does not hold one value per sensor (a caller's bug).
    pub fn new(placed: &Placed, lux: &[f64], df: &[f64]) -> GridReport {
        let n = placed.sensors.len();
        assert!(lux.len() == n && df.len() == n, "one value per sensor");
        let of = |k: &[usize]| {
            let l: Vec<f64> = k.iter().map(|&k| lux[k]).collect();
            let d: Vec<f64> = k.iter().map(|&k| df[k]).collect();
            stats(&l, &d)
        };
        let area = |s: &GridStats| s.points as f64 * placed.cell_area;
        // The sensors of each storey and of each room, in one pass.
        let mut storey_of: BTreeMap<u32, (Vec<usize>, f64, u32)> = BTreeMap::new();
        let mut room_of: BTreeMap<(u32, u32), Vec<usize>> = BTreeMap::new();
        for (k, (z, &h)) in placed.zones.iter().zip(&placed.heights).enumerate() {
            let s = storey_of.entry(z.storey).or_insert((Vec::new(), h, 0));
            s.0.push(k);
            s.1 = s.1.min(h);
            if z.room > 0 {
                room_of.entry((z.storey, z.room)).or_default().push(k);
            }
        }
        for &(storey, _) in room_of.keys() {
            if let Some(s) = storey_of.get_mut(&storey) {
                s.2 += 1;
            }
        }
        let storeys = storey_of
            .into_iter()
            .map(|(storey, (k, height, rooms))| {
                let stats = of(&k);
                StoreyStats {
                    storey,
                    height,
                    rooms,
                    area: area(&stats),
                    stats,
                }
            })
            .collect();
        let rooms = room_of
            .into_iter()
            .map(|((storey, room), k)| {
                let stats = of(&k);
                RoomStats {
                    storey,
                    room,
                    area: area(&stats),
                    stats,
                }
            })
            .collect();
        let all = stats(lux, df);
        GridReport {
            area: area(&all),
            all,
            outdoor: placed.rule,
            outdoor_points: placed.outdoor_points,
            dropped_points: placed.dropped_points,
            storeys,
            rooms,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_stats_of_known_values() {
        let s = stats(&[300.0, 100.0, 500.0, 200.0], &[3.0, 1.0, 5.0, 2.0]);
        assert_eq!(
            s,
            GridStats {
                points: 4,
                mean_lux: 275.0,
                min_lux: 100.0,
                max_lux: 500.0,
                uniformity: 100.0 / 275.0,
                min_over_max: 100.0 / 500.0,
                mean_df: 2.75,
                median_lux: 250.0,
            }
        );
        assert_eq!(stats(&[7.0, 1.0, 4.0], &[0.0; 3]).median_lux, 4.0);
        let json = serde_json::to_string(&s).unwrap();
        assert_eq!(serde_json::from_str::<GridStats>(&json).unwrap(), s);
    }

    #[test]
    fn grid_stats_of_an_empty_or_dark_grid_are_zero_not_nan() {
        let e = stats(&[], &[]);
        assert_eq!(
            (e.points, e.mean_lux, e.uniformity, e.median_lux),
            (0, 0.0, 0.0, 0.0)
        );
        let dark = stats(&[0.0, 0.0], &[0.0, 0.0]);
        assert_eq!(
            (dark.points, dark.uniformity, dark.min_over_max),
            (2, 0.0, 0.0)
        );
    }
}
