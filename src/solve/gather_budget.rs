//! The final gather's rays under a clock budget (`--max-time`): how many rays per patch fit in
//! the time the shooting left.

use super::{SolveSettings, SolveStats};
use std::time::Instant;

/// Rays per patch for the final gather, the most a pilot may choose under an error target: the
/// settings' ([`SolveSettings::gather_rays_per_patch`]),
/// or, under `--max-time`, as many as the time left allows at the rate the shooting cast rays
/// (a gather ray costing [`GATHER_RAY_COST`] shooting rays), down to [`MIN_BUDGET_GATHER`];
/// `None` (no gather) when not even that fits. Only this clock budget makes the gather depend
/// on the clock, as it does the shooting.
pub(super) fn gather_rays_within(
    cfg: &SolveSettings,
    patches: usize,
    stats: &SolveStats,
    start: Instant,
) -> Option<usize> {
    let elapsed = start.elapsed().as_secs_f64();
    gather_rays_fitting(
        cfg,
        cfg.gather_rays_per_patch(),
        patches,
        stats.rays as f64,
        elapsed,
    )
}

/// [`gather_rays_within`]'s rule for `rays` wanted per patch, after `shot` shooting rays in
/// `elapsed` seconds (the rate the time left is spent at); the error target's later passes
/// and gather rounds (`passes`) keep to `--max-time` by it too.
pub(super) fn gather_rays_fitting(
    cfg: &SolveSettings,
    rays: usize,
    patches: usize,
    shot: f64,
    elapsed: f64,
) -> Option<usize> {
    let Some(limit) = cfg.max_time else {
        return Some(rays);
    };
    let rate = shot / elapsed.max(1e-9);
    let fits = (limit - elapsed).max(0.0) * rate / (GATHER_RAY_COST * patches.max(1) as f64);
    if fits >= rays as f64 {
        Some(rays)
    } else if fits >= MIN_BUDGET_GATHER as f64 {
        Some(fits as usize)
    } else {
        None
    }
}

/// What a gather ray costs in shooting rays, for budgeting the gather under `--max-time`
/// (Sibenik: 9.5 M shooting rays a second, 5.7 M gather rays: their near hits and light
/// samples cost more per ray).
const GATHER_RAY_COST: f64 = 2.0;

/// Fewest rays per patch a gather cut to the time left is run with.
const MIN_BUDGET_GATHER: usize = 16;

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    #[test]
    fn the_gather_fits_the_time_left_or_is_left_out() {
        let cfg = SolveSettings::default();
        let stats = SolveStats {
            rays: 10_000_000,
            ..SolveStats::default()
        };
        let started = |s: f64| Instant::now() - Duration::from_secs_f64(s);
        // No budget: the settings' rays.
        assert_eq!(
            gather_rays_within(&cfg, 1000, &stats, started(1.0)),
            Some(cfg.gather_rays_per_patch())
        );
        let within = |limit: f64, elapsed: f64| {
            let cfg = SolveSettings {
                max_time: Some(limit),
                ..SolveSettings::default()
            };
            gather_rays_within(&cfg, 100_000, &stats, started(elapsed))
        };
        // 10 M rays in 1 s; 100,000 patches at 2 shooting rays per gather ray: 50 a second.
        assert_eq!(within(100.0, 1.0), Some(cfg.gather_rays_per_patch()));
        let cut = within(2.0, 1.0).expect("about 50 rays fit");
        assert!((45..=50).contains(&cut), "{cut}");
        assert_eq!(within(1.2, 1.0), None);
        assert_eq!(within(0.5, 1.0), None);
    }
}
