//! The figures daylighting standards quote of a grid: mean, minimum and maximum illuminance,
//! uniformity U0 = minimum / mean (as EN 12464-1 defines it), the median, and the mean daylight
//! factor. They go to `summary.json`.

use super::csv::finite;

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
            mean_df: 0.0,
            median_lux: 0.0,
        };
    }
    let mean_lux = sorted.iter().sum::<f64>() / n as f64;
    let min_lux = sorted[0];
    GridStats {
        points: n as u64,
        mean_lux,
        min_lux,
        max_lux: sorted[n - 1],
        uniformity: if mean_lux > 0.0 {
            min_lux / mean_lux
        } else {
            0.0
        },
        mean_df: df.iter().map(|&v| finite(v)).sum::<f64>() / n as f64,
        median_lux: (sorted[(n - 1) / 2] + sorted[n / 2]) / 2.0,
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
        assert_eq!((dark.points, dark.uniformity), (2, 0.0));
    }
}
