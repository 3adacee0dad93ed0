//! A high-accuracy reference solution (`radiosity reference`) that states its own error bound,
//! and checks it.
//!
//! The reference is shooting with the paper's adaptive ray sampler (Sec. 2) at a far smaller
//! tolerance than any compared run (default 0.005 against 0.05: 100× the rays) and to a far
//! tighter stop than Sec. 3's 0.06 % (default 10⁻⁵). Its samples are split into two independent
//! halves (two seeds, each half at tolerance·√2, so half the rays each and nothing spent
//! twice); the table is their mean.
//!
//! **The bound** is the solver's own error estimate ([`crate::solve::estimate`]) of the mean:
//! each half's final estimate / √2 (sampling noise of independent halves averages down by √2;
//! the light still owed is below the stop fraction and negligible next to it).
//!
//! **The check**: two independent solves with noise σ each differ by √2·σ, so the measured
//! difference between the halves (the same metrics, one half as the other's reference)
//! should be √2 × a half's estimate. The check fails when any metric's measured/expected ratio
//! is off by more than [`CHECK_FACTOR`].

use crate::intersect::Intersector;
use crate::mesh::Mesh;
use crate::scene::Material;
use crate::solve::estimate::{self, ErrorMetrics};
use crate::solve::{self, MethodKind, SolveError, SolveSettings, StopReason};
use std::time::Instant;

/// How far the measured difference of the halves may be from what the bound predicts.
pub const CHECK_FACTOR: f64 = 2.0;

/// A reference solution with its bound and check.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Reference {
    /// Radiosity per patch (RGB, W/m²): the mean of the halves.
    #[serde(skip)]
    pub b: Vec<[f64; 3]>,
    /// Tolerance and stop fraction of the whole (each half ran at tolerance·√2).
    pub tolerance: f64,
    pub stop_fraction: f64,
    /// Seeds of the two halves.
    pub seeds: [u64; 2],
    pub shots: u64,
    pub rays: u64,
    pub seconds: f64,
    /// Why each half stopped.
    pub stop_reasons: [Option<StopReason>; 2],
    /// The stated error bound of the table (fractions; see the module doc).
    pub bound: ErrorMetrics,
    /// Each half's own estimate.
    pub half_estimates: [ErrorMetrics; 2],
    /// The measured difference between the halves (half 1 against half 2).
    pub halves_difference: ErrorMetrics,
    /// What the estimates predict for it: √2 × the mean of the halves' estimates.
    pub expected_difference: ErrorMetrics,
    /// measured / expected per metric (energy, weighted percent, RMS).
    pub check_ratios: [f64; 3],
    /// Whether the energy and weighted-percent ratios are within [1/CHECK_FACTOR, CHECK_FACTOR].
    pub check_passed: bool,
}

impl Reference {
    /// One line with the stated bound and the check.
    pub fn check_line(&self) -> String {
        format!(
            "stated error bound {:.3} % (average weighted percent), {:.3} % (average energy), {:.3} % RMS; halves differ by {:.3} / {:.3} / {:.3} %, the bound predicts {:.3} / {:.3} / {:.3} % (ratios {:.2}, {:.2}, {:.2}; the first two judged): check {}",
            100.0 * self.bound.weighted_percent,
            100.0 * self.bound.energy,
            100.0 * self.bound.rms_relative,
            100.0 * self.halves_difference.weighted_percent,
            100.0 * self.halves_difference.energy,
            100.0 * self.halves_difference.rms_relative,
            100.0 * self.expected_difference.weighted_percent,
            100.0 * self.expected_difference.energy,
            100.0 * self.expected_difference.rms_relative,
            self.check_ratios[1],
            self.check_ratios[0],
            self.check_ratios[2],
            if self.check_passed { "passed" } else { "FAILED" }
        )
    }
}

/// Solves the reference: two half solves with adaptive rays, averaged. `cfg` gives the seed,
/// the tolerance and stop fraction of the whole, and any time or ray budget (per half); its
/// method is ignored.
pub fn build<I: Intersector>(
    mesh: &Mesh,
    materials: &[Material],
    isect: &I,
    cfg: &SolveSettings,
) -> Result<Reference, SolveError> {
    let t = Instant::now();
    let seeds = [cfg.seed, cfg.seed.wrapping_add(0x9E37_79B9_7F4A_7C15)];
    let half = |seed: u64| {
        let c = SolveSettings {
            seed,
            method: MethodKind::AdaptiveRays,
            tolerance: cfg.tolerance * std::f64::consts::SQRT_2,
            // Energy per ray ∝ tolerance²: twice the energy, half the rays.
            energy_per_ray: cfg.energy_per_ray.map(|c| 2.0 * c),
            ..cfg.clone()
        };
        solve::solve(mesh, materials, isect, &c, |_| {})
    };
    let a = half(seeds[0])?;
    let b = half(seeds[1])?;
    let mean: Vec<[f64; 3]> =
        a.b.iter()
            .zip(&b.b)
            .map(|(x, y)| {
                [
                    0.5 * (x[0] + y[0]),
                    0.5 * (x[1] + y[1]),
                    0.5 * (x[2] + y[2]),
                ]
            })
            .collect();
    let estimate =
        |s: &solve::Solution| s.stats.trace.last().map(|p| p.estimate).unwrap_or_default();
    let (ea, eb) = (estimate(&a), estimate(&b));
    let combine = |f: &dyn Fn(&ErrorMetrics) -> f64, k: f64| 0.5 * (f(&ea) + f(&eb)) * k;
    let scaled = |k: f64| ErrorMetrics {
        energy: combine(&|e| e.energy, k),
        weighted_percent: combine(&|e| e.weighted_percent, k),
        rms_relative: combine(&|e| e.rms_relative, k),
    };
    let bound = scaled(std::f64::consts::FRAC_1_SQRT_2);
    let expected = scaled(std::f64::consts::SQRT_2);
    let area: Vec<f64> = mesh.patches.iter().map(|p| p.area).collect();
    let diff = estimate::against(&area, &a.b, &b.b);
    let ratio = |m: f64, e: f64| {
        if e > 0.0 {
            m / e
        } else if m > 0.0 {
            f64::INFINITY
        } else {
            1.0
        }
    };
    let ratios = [
        ratio(diff.energy, expected.energy),
        ratio(diff.weighted_percent, expected.weighted_percent),
        ratio(diff.rms_relative, expected.rms_relative),
    ];
    let passed = ratios[..2]
        .iter()
        .all(|&r| (1.0 / CHECK_FACTOR..=CHECK_FACTOR).contains(&r));
    Ok(Reference {
        b: mean,
        tolerance: cfg.tolerance,
        stop_fraction: cfg.stop_fraction,
        seeds,
        shots: a.stats.shots + b.stats.shots,
        rays: a.stats.rays + b.stats.rays,
        seconds: t.elapsed().as_secs_f64(),
        stop_reasons: [a.stats.stop_reason, b.stats.stop_reason],
        bound,
        half_estimates: [ea, eb],
        halves_difference: diff,
        expected_difference: expected,
        check_ratios: ratios.map(|r| if r.is_finite() { r } else { f64::MAX }),
        check_passed: passed,
    })
}
