//! An error target (`solve --error E`, issue 13 item 4): keep refining until the solver's own
//! estimate of the average weighted percent error (Sec. 3's metric, [`super::estimate`]) is at or
//! below E, or a budget (`--max-time`, `--max-rays`, Ctrl-C) stops it.
//!
//! A progressive solve at energy per ray C stops at the sampling noise C fixed in advance: its
//! per-patch noise σ_j² ≈ ρ_j·C·G_j / A_j² (G_j the flux patch j kept) does not fall by shooting
//! longer, because every unit of light is shot once. So refinement runs further **independent
//! passes** (seed k of the run's seed, the same scene and settings) and averages them weighted by
//! their rays (w_k ∝ 1/C_k, the inverse of each pass's noise variance): the mean of passes of
//! C_1, C_2, … has the noise of one pass of C = 1/Σ(1/C_k). Nothing is thrown away, so error
//! against time keeps falling like 1/√rays for as long as the user lets it run.
//!
//! Each next pass is sized from the estimate: to reach E from e with R rays so far, about
//! R·((e/E)² − 1) more rays are needed; a pass casts that many (C_k = C_1·R_1/rays), at least
//! as many as the first pass and at most three times all so far, so a poor estimate is
//! corrected after a pass, not after a long overshoot.
//!
//! The combined estimate per patch: noise sqrt(Σ w_k² σ_kj²), light not yet shot Σ w_k·owed_kj,
//! put through [`estimate::from_errors`]. The energy books are the rays-weighted mean of the
//! passes' books, so they close as each pass's do.

use super::driver::PatchScalars;
use super::estimate::{self, Books, ErrorMetrics, Parts};
use super::final_gather;
use super::{scalar, RunHooks, Solution, SolveError, SolveSettings, StopReason, TracePoint};
use crate::intersect::Intersector;
use crate::mesh::Mesh;
use crate::scene::Material;
use std::time::Instant;

/// What the error target did (`summary.json`: `error_target`).
#[derive(Clone, Copy, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct ErrorTarget {
    /// The target E (a fraction: 0.02 = 2 %).
    pub target: f64,
    /// The estimate reached (average weighted percent error of the combined passes).
    pub estimate: f64,
    pub reached: bool,
    /// Independent passes averaged.
    pub passes: u32,
}

/// One pass's per-patch expected error split into its parts, and its weight.
struct Pass {
    rays: f64,
    /// Per patch: sampling noise variance (W²/m⁴) and light still owed (W/m²).
    var: Vec<f64>,
    owed: Vec<f64>,
}

/// The per-patch noise and owed light of a finished pass, from its solution: rays and hemi-cube
/// cells alike counted as samples of energy C, then scaled so that the pass's metric is the one
/// its own solve estimated (early hemi-cube cells carry more than C each).
fn pass_errors(ps: &PatchScalars, mesh: &Mesh, sol: &Solution) -> Pass {
    let n = mesh.patches.len();
    let gathered: Vec<f64> = (0..n)
        .map(|j| ((scalar(&sol.b[j]) - ps.emission[j]) * ps.area[j]).max(0.0))
        .collect();
    let c = sol.stats.energy_per_ray;
    let est = ps.estimator(c);
    let books = Books {
        gathered: &gathered,
        cube_gathered: &[],
        cube_var: &[],
        kept: gathered.iter().sum(),
        unshot: sol.unshot.iter().map(scalar).sum(),
        shot: 0.0,
    };
    let (err, b) = est.per_patch(&books);
    // Scaled to the pass's own estimate (which knows what each hemi-cube cell carried), so one
    // pass reports exactly what the solve without a target would.
    let own = sol.stats.trace.last().map(|t| t.estimate.weighted_percent);
    let approx = estimate::from_errors(&ps.area, err.into_iter(), &b).weighted_percent;
    let s = match own {
        Some(e) if approx > 0.0 && e > 0.0 => e / approx,
        _ => 1.0,
    };
    let var: Vec<f64> = (0..n)
        .map(|j| s * s * ps.rho[j] * c * gathered[j] / (ps.area[j] * ps.area[j]))
        .collect();
    let owed = (0..n)
        // The estimator's B includes what is owed: b − (E + G/A).
        .map(|j| s * (b[j] - ps.emission[j] - gathered[j] / ps.area[j]).max(0.0))
        .collect();
    Pass {
        rays: (sol.stats.rays + sol.stats.hemicube_cells).max(1) as f64,
        var,
        owed,
    }
}

/// The rays-weighted mean of `sols` (the last one's shape), its estimated metrics, and the
/// estimate's parts per patch (for the final gather).
fn combine(
    ps: &PatchScalars,
    passes: &[Pass],
    sols: &[Solution],
) -> (Solution, ErrorMetrics, Parts) {
    let total: f64 = passes.iter().map(|p| p.rays).sum();
    let w: Vec<f64> = passes.iter().map(|p| p.rays / total).collect();
    let n = ps.area.len();
    let mut out = sols[sols.len() - 1].clone();
    let mix = |get: &dyn Fn(&Solution) -> &Vec<[f64; 3]>, dst: &mut Vec<[f64; 3]>| {
        for (j, d) in dst.iter_mut().enumerate() {
            *d = [0, 1, 2].map(|c| sols.iter().zip(&w).map(|(s, wk)| wk * get(s)[j][c]).sum());
        }
    };
    mix(&|s| &s.b, &mut out.b);
    mix(&|s| &s.unshot, &mut out.unshot);
    for (k, ch) in out.channels.iter_mut().enumerate() {
        mix(&|s| &s.channels[k].b, &mut ch.b);
    }
    let e = &mut out.stats.energy;
    for c in 0..3 {
        let avg = |f: &dyn Fn(&super::EnergyBalance) -> f64| {
            sols.iter()
                .zip(&w)
                .map(|(s, wk)| wk * f(&s.stats.energy))
                .sum()
        };
        e.emitted[c] = avg(&|x| x.emitted[c]);
        e.absorbed[c] = avg(&|x| x.absorbed[c]);
        e.absorbed_back[c] = avg(&|x| x.absorbed_back[c]);
        e.escaped[c] = avg(&|x| x.escaped[c]);
        e.unshot[c] = avg(&|x| x.unshot[c]);
    }
    let st = &mut out.stats;
    st.shots = sols.iter().map(|s| s.stats.shots).sum();
    st.rays = sols.iter().map(|s| s.stats.rays).sum();
    st.waves = sols.iter().map(|s| s.stats.waves).sum();
    st.hemicube_shots = sols.iter().map(|s| s.stats.hemicube_shots).sum();
    st.hemicube_cells = sols.iter().map(|s| s.stats.hemicube_cells).sum();
    st.seconds = sols.iter().map(|s| s.stats.seconds).sum();
    st.energy_per_ray = 1.0
        / sols
            .iter()
            .map(|s| 1.0 / s.stats.energy_per_ray)
            .sum::<f64>();
    st.switch = sols[0].stats.switch;
    let sigma: Vec<f64> = (0..n)
        .map(|j| {
            let var: f64 = passes
                .iter()
                .zip(&w)
                .map(|(p, wk)| wk * wk * p.var[j])
                .sum();
            var.sqrt()
        })
        .collect();
    let missing: Vec<f64> = (0..n)
        .map(|j| passes.iter().zip(&w).map(|(p, wk)| wk * p.owed[j]).sum())
        .collect();
    let b_est: Vec<f64> = (0..n).map(|j| scalar(&out.b[j]) + missing[j]).collect();
    let err = (0..n).map(|j| estimate::combine(missing[j], sigma[j]));
    let m = estimate::from_errors(&ps.area, err, &b_est);
    let parts = Parts {
        missing,
        sigma,
        b: b_est,
    };
    (out, m, parts)
}

/// What the run is judged by after each pass: the combined passes, through the final gather
/// when the settings ask for one (then with the gather's rays per patch grown with the shooting's
/// rays, `scale` = rays so far / the first pass's, so the two stay in balance).
#[allow(clippy::too_many_arguments)]
fn judged<I: Intersector>(
    mesh: &Mesh,
    materials: &[Material],
    gather: Option<&I>,
    cfg: &SolveSettings,
    hooks: &RunHooks,
    combined: (Solution, ErrorMetrics, Parts),
    scale: f64,
) -> (Solution, ErrorMetrics) {
    let (mut sol, m, parts) = combined;
    let Some(isect) = gather else {
        return (sol, m);
    };
    let rays = (cfg.gather_rays as f64 * scale)
        .round()
        .min(super::settings::MAX_GATHER_RAYS as f64) as usize;
    let shooting = final_gather::Shooting {
        parts,
        energy_per_ray: sol.stats.energy_per_ray,
        // A patch is gathered when its shooting noise is above what the run aims at.
        tolerance: cfg.tolerance.min(cfg.error_target.unwrap_or(f64::INFINITY)),
    };
    final_gather::apply(
        mesh,
        materials,
        isect,
        cfg.seed,
        rays,
        hooks.light_groups.as_deref().map(|g| g.of_patch.as_slice()),
        &shooting,
        hooks.reference.as_deref().map(Vec::as_slice),
        &mut sol,
        &mut |_| {},
    );
    let m = sol.stats.trace.last().map_or(m, |t| t.estimate);
    (sol, m)
}

/// Whether a budget (time, rays, Ctrl-C) stopped a pass.
fn budget_stopped(sol: &Solution) -> bool {
    matches!(
        sol.stats.stop_reason,
        Some(StopReason::MaxTime | StopReason::MaxRays | StopReason::Interrupted)
    )
}

/// Shoots passes until the estimate reaches `target` (see the module notes). The first pass is
/// `cfg` as given (with `hooks`: checkpoints, resume); later ones are seeded from it.
pub(super) fn shoot_to<I: Intersector>(
    mesh: &Mesh,
    materials: &[Material],
    isect: Option<&I>,
    cfg: &SolveSettings,
    hooks: &RunHooks,
    target: f64,
    mut on_trace: impl FnMut(&TracePoint),
) -> Result<Solution, SolveError> {
    let start = Instant::now();
    let ps = PatchScalars::new(mesh, materials);
    // Passes shoot; the final gather, if asked for, runs on their combination.
    let gather = isect.filter(|_| cfg.final_gather && cfg.method.casts_rays());
    let shoot_cfg = SolveSettings {
        final_gather: false,
        ..cfg.clone()
    };
    let cfg = &shoot_cfg;
    let first = super::driver::shoot(mesh, materials, isect, cfg, hooks, &mut on_trace)?;
    let c1 = first.stats.energy_per_ray;
    let r1 = (first.stats.rays + first.stats.hemicube_cells).max(1) as f64;
    let mut passes = vec![pass_errors(&ps, mesh, &first)];
    let mut trace = first.stats.trace.clone();
    let mut sols = vec![first];
    let interrupted = |s: &Solution| s.stats.stop_reason == Some(StopReason::Interrupted);
    let gather_now = |s: &Solution| gather.filter(|_| !interrupted(s));
    let (mut out, mut m) = judged(
        mesh,
        materials,
        gather_now(&sols[0]),
        cfg,
        hooks,
        combine(&ps, &passes, &sols),
        1.0,
    );
    if out.stats.final_gather.is_some() {
        // The gather's own trace point (its estimate, and the error against a reference).
        if let Some(p) = out.stats.trace.last().copied() {
            on_trace(&p);
            trace.push(p);
        }
    }
    let later_hooks = RunHooks {
        reference: hooks.reference.clone(),
        light_groups: hooks.light_groups.clone(),
        checkpoint: None,
        resume: None,
        interrupt: hooks.interrupt.clone(),
    };
    loop {
        if m.weighted_percent <= target || budget_stopped(&sols[sols.len() - 1]) {
            break;
        }
        let so_far: f64 = passes.iter().map(|p| p.rays).sum();
        let want = so_far * ((m.weighted_percent / target).powi(2) - 1.0);
        let rays = want.clamp(r1, 3.0 * so_far);
        let elapsed = start.elapsed().as_secs_f64();
        let used = so_far as u64;
        let next = SolveSettings {
            seed: super::mix(cfg.seed ^ (sols.len() as u64).wrapping_mul(0x2545_F491_4F6C_DD1D)),
            energy_per_ray: Some(c1 * r1 / rays),
            max_time: match cfg.max_time {
                Some(t) if elapsed >= t => break,
                Some(t) => Some(t - elapsed),
                None => None,
            },
            max_rays: match cfg.max_rays {
                Some(r) if used >= r => break,
                Some(r) => Some(r - used),
                None => None,
            },
            ..cfg.clone()
        };
        let sol = super::driver::shoot(mesh, materials, isect, &next, &later_hooks, |_| {})?;
        if budget_stopped(&sol) {
            // Cut short, its radiosity is short of the light it had still to shoot: averaged
            // in, it would pull the result down. Its time is spent; the result stays as it was.
            out.stats.stop_reason = sol.stats.stop_reason;
            break;
        }
        passes.push(pass_errors(&ps, mesh, &sol));
        sols.push(sol);
        let scale = passes.iter().map(|p| p.rays).sum::<f64>() / r1;
        (out, m) = judged(
            mesh,
            materials,
            gather_now(&sols[sols.len() - 1]),
            cfg,
            hooks,
            combine(&ps, &passes, &sols),
            scale,
        );
        let mut point = out.stats.trace.last().copied().unwrap_or_default();
        point.time_s = start.elapsed().as_secs_f64();
        point.shots = out.stats.shots;
        point.rays = out.stats.rays;
        point.cells = out.stats.hemicube_cells;
        point.estimate = m;
        point.error = hooks
            .reference
            .as_ref()
            .map(|r| estimate::against(&ps.area, &out.b, r));
        on_trace(&point);
        trace.push(point);
    }
    out.stats.seconds = start.elapsed().as_secs_f64();
    out.stats.trace = trace;
    out.stats.error_target = Some(ErrorTarget {
        target,
        estimate: m.weighted_percent,
        reached: m.weighted_percent <= target,
        passes: sols.len() as u32,
    });
    Ok(out)
}
