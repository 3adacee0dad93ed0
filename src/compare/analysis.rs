//! What a comparison reads off the traces of its runs (the paper's Sec. 3 and 4):
//!
//! - [`time_to_error`]: when a run first reaches an error level, interpolated in log–log
//!   between trace points (the traces are taken at geometric steps of time, so straight lines
//!   on a log–log plot are what lies between them);
//! - [`decay_constant`]: the E of Fig. 2, max unshot radiosity ∝ E^p with p the percent of
//!   shots done (the paper: E = 0.87055, so 1/4 after 10 %);
//! - [`cost_per_shot`]: seconds per shot between trace points against the percent of shots
//!   done (Fig. 5: flat for the uniform hemi-cube, falling for the adaptive samplers).

use crate::solve::TracePoint;

/// The time (s) at which the series `(time, error)` first reaches `level` (error ≤ level), or
/// `None` if it never does. Between the two trace points that bracket the crossing the time is
/// interpolated in log–log (linearly where a value is not positive).
pub fn time_to_error(points: &[(f64, f64)], level: f64) -> Option<f64> {
    let k = points
        .iter()
        .position(|&(_, e)| e.is_finite() && e <= level)?;
    if k == 0 {
        return Some(points[0].0);
    }
    let (t1, e1) = points[k - 1];
    let (t2, e2) = points[k];
    if !(e1.is_finite() && e1 > e2) {
        return Some(t2);
    }
    let t = if t1 > 0.0 && e2 > 0.0 && level > 0.0 {
        let f = (level.ln() - e1.ln()) / (e2.ln() - e1.ln());
        (t1.ln() + f * (t2.ln() - t1.ln())).exp()
    } else {
        t1 + (level - e1) / (e2 - e1) * (t2 - t1)
    };
    Some(t.clamp(t1, t2))
}

/// The (time, average weighted percent error) series of a trace against its reference.
pub fn weighted_percent_series(trace: &[TracePoint]) -> Vec<(f64, f64)> {
    trace
        .iter()
        .filter_map(|p| p.error.map(|e| (p.time_s, e.weighted_percent)))
        .collect()
}

/// The (time, average energy error) series of a trace against its reference.
pub fn energy_series(trace: &[TracePoint]) -> Vec<(f64, f64)> {
    trace
        .iter()
        .filter_map(|p| p.error.map(|e| (p.time_s, e.energy)))
        .collect()
}

/// Fig. 2's curve: (percent of the run's shots done, max unshot radiosity / its value at the
/// first trace point) for every trace point with a positive max unshot radiosity.
pub fn decay_curve(trace: &[TracePoint]) -> Vec<(f64, f64)> {
    let total = trace.last().map_or(0, |p| p.shots);
    let Some(first) = trace.first().map(|p| p.max_unshot_b) else {
        return Vec::new();
    };
    if total == 0 || first <= 0.0 {
        return Vec::new();
    }
    trace
        .iter()
        .filter(|p| p.max_unshot_b > 0.0)
        .map(|p| {
            (
                100.0 * p.shots as f64 / total as f64,
                p.max_unshot_b / first,
            )
        })
        .collect()
}

/// The decay constant E of Fig. 2: the slope of the least-squares line
/// ln(relative max unshot) = a + p·ln E over the points of a [`decay_curve`] past 0 %. The
/// intercept a takes up the first shots of the lights, whose radiosity dwarfs everything else
/// (the paper measures the decay "even after excluding light sources"). `None` without two
/// distinct points past 0 %.
pub fn decay_constant(curve: &[(f64, f64)]) -> Option<f64> {
    let pts: Vec<(f64, f64)> = curve
        .iter()
        .filter(|&&(p, y)| p > 0.0 && y > 0.0)
        .map(|&(p, y)| (p, y.ln()))
        .collect();
    let n = pts.len() as f64;
    let (sp, sy) = pts
        .iter()
        .fold((0.0, 0.0), |(a, b), &(p, y)| (a + p, b + y));
    let (mp, my) = (sp / n.max(1.0), sy / n.max(1.0));
    let (mut spy, mut spp) = (0.0, 0.0);
    for &(p, y) in &pts {
        spy += (p - mp) * (y - my);
        spp += (p - mp) * (p - mp);
    }
    (pts.len() >= 2 && spp > 0.0).then(|| (spy / spp).exp())
}

/// Fig. 5's curve: (percent of shots done at the middle of the step, seconds per shot over the
/// step) between consecutive trace points that are apart in shots and in time.
pub fn cost_per_shot(trace: &[TracePoint]) -> Vec<(f64, f64)> {
    let total = trace.last().map_or(0, |p| p.shots);
    if total == 0 {
        return Vec::new();
    }
    trace
        .windows(2)
        .filter(|w| w[1].shots > w[0].shots && w[1].time_s > w[0].time_s)
        .map(|w| {
            let mid = 0.5 * (w[0].shots + w[1].shots) as f64;
            (
                100.0 * mid / total as f64,
                (w[1].time_s - w[0].time_s) / (w[1].shots - w[0].shots) as f64,
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solve::estimate::ErrorMetrics;

    fn point(time_s: f64, shots: u64, max_unshot_b: f64) -> TracePoint {
        TracePoint {
            time_s,
            shots,
            rays: 0,
            cells: 0,
            max_unshot_b,
            mean_b: 1.0,
            unshot_flux: 0.0,
            estimate: ErrorMetrics::default(),
            error: None,
        }
    }

    #[test]
    fn time_to_error_interpolates_in_log_log() {
        // error = 1/t: a straight line in log–log, so the interpolation is exact.
        let pts: Vec<(f64, f64)> = [0.5, 1.0, 2.0, 4.0, 8.0]
            .iter()
            .map(|&t| (t, 1.0 / t))
            .collect();
        let t = time_to_error(&pts, 0.3).unwrap();
        assert!((t - 1.0 / 0.3).abs() < 1e-9, "{t}");
        // Reached at the first point; never reached.
        assert_eq!(time_to_error(&pts, 5.0), Some(0.5));
        assert_eq!(time_to_error(&pts, 0.01), None);
        // The first crossing counts, even if the error rises again afterwards.
        let bumpy = [(1.0, 1.0), (2.0, 0.1), (4.0, 0.5), (8.0, 0.05)];
        assert!(time_to_error(&bumpy, 0.2).unwrap() < 2.0 + 1e-12);
        // A zero time at the start falls back to linear interpolation.
        let t = time_to_error(&[(0.0, 1.0), (1.0, 0.0)], 0.5).unwrap();
        assert!((t - 0.5).abs() < 1e-12, "{t}");
    }

    #[test]
    fn the_decay_fit_recovers_e_from_a_synthetic_trace() {
        // The paper's E: max unshot = E^p over 397 shots, p the percent done.
        let e = 0.87055f64;
        let total = 397u64;
        let trace: Vec<TracePoint> = (0..=total)
            .step_by(7)
            .chain([total])
            .map(|s| {
                let p = 100.0 * s as f64 / total as f64;
                // The lights' shot first: the start is 100× what follows.
                let y = if s == 0 { 300.0 } else { 3.0 * e.powf(p) };
                point(s as f64 * 0.01, s, y)
            })
            .collect();
        let curve = decay_curve(&trace);
        let fit = decay_constant(&curve).unwrap();
        assert!((fit - e).abs() < 1e-9, "{fit}");
        // 1/4 after 10 %, as the paper says of this E.
        assert!((e.powf(10.0) - 0.25).abs() < 2e-3);
        assert_eq!(decay_constant(&[]), None);
    }

    #[test]
    fn cost_per_shot_is_seconds_per_shot_between_points() {
        let trace = [point(0.0, 0, 1.0), point(1.0, 10, 0.5), point(1.5, 20, 0.1)];
        let c = cost_per_shot(&trace);
        assert_eq!(c.len(), 2);
        assert!((c[0].0 - 25.0).abs() < 1e-12 && (c[0].1 - 0.1).abs() < 1e-12);
        assert!((c[1].0 - 75.0).abs() < 1e-12 && (c[1].1 - 0.05).abs() < 1e-12);
    }
}
