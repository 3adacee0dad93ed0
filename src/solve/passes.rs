//! An error target (`solve --error E`, docs/design.md §8): keep refining until the solver's own
//! estimate of the average weighted percent error (Sec. 3's metric, [`super::estimate`]) is at or
//! below E, or a budget (`--max-time`, `--max-rays`, Ctrl-C) stops it.
//!
//! A progressive solve at energy per ray C stops at the sampling noise C fixed in advance: its
//! per-patch noise σ_j² ≈ ρ_j·C·G_j / A_j² (G_j the flux patch j kept) does not fall by shooting
//! longer, because every unit of light is shot once. So refinement runs further **independent
//! passes** (seed k of the run's seed, the same scene and settings) and averages their shooting
//! results weighted by their samples (w_k ∝ 1/C_k, the inverse of each pass's noise variance):
//! the mean of passes of C_1, C_2, … has the noise of one pass of C = 1/Σ(1/C_k). Nothing is
//! thrown away, so error against time keeps falling like 1/√rays for as long as the run is let.
//!
//! **The first pass** is the plain solve, final gather included, sized for the gather to make
//! the estimate: without `--tolerance` it shoots at 2·E
//! ([`super::settings::TARGET_TOLERANCE`]), and a pilot on a sample of the patches picks the
//! gather's rays per patch to land at [`ROUND_AIM`] of E (`final_gather`, module `pilot`);
//! when it meets E it is the result. Otherwise each
//! next pass is sized from the estimate: to reach E from e with R samples so far, about
//! R·((e/E)^(1/p) − 1) more are needed, p the rate the estimate falls at (e ∝ R^−p). Pure
//! sampling noise gives p = ½; where the gather's near paths or light still owed weigh in the
//! estimate falls slower (Sibenik under an overcast sky: 7.9 % → 5.35 % for 2.5× the samples,
//! p ≈ 0.43), so p starts at ½ and is then measured from the last two estimates ([`rate`]), and
//! a pass aims [`AIM`] of the way to E, not at E itself: a pass that misses E by a hair costs a
//! whole further pass. A pass casts that many samples (C_k = C_1·R_1/rays), at least as many as
//! the first and at most three times all so far, so a poor estimate is corrected after a pass,
//! not after a long overshoot.
//!
//! **Gather rounds** (docs/design.md §8): where the final gather carries most of the result, a
//! further pass mostly buys a better cache for a gather redone everywhere. Before each further
//! pass, the gathers of the last combination are asked for a round of extra rays placed where
//! the estimate's error is ([`final_gather::Gathers::plan`]); it is taken instead of the pass
//! when it is expected to cast fewer rays than the passes would to reach the same aim, their
//! gathers included (`Route`; counted, not timed), and pooled with the gathers it adds to.
//! A pass's gather is costed grown from the gathers it would replace, rounds included: one
//! gathering fewer rays would throw the rounds' precision away (the furnished room: a round
//! to 5.7 %, then a pass whose cheaper gather landed at 8.9 %, then two more rounds).
//! At most [`MAX_REGATHERS`] rounds.
//!
//! **Judging** a combination: per patch, noise sqrt(Σ w_k² σ_kj²) and light not yet shot
//! Σ w_k·owed_kj (each pass's own estimate's parts, kept by the driver in
//! [`super::ShotResult`]), through [`estimate::from_errors`] — after the final gather when one is
//! asked for, run on the combined shooting result with its rays per patch grown with the
//! shooting's samples. The energy books are the
//! samples-weighted mean of the passes' books, so they close as each pass's do. A pass cut short
//! by a budget is left out (its light still unshot would pull the mean down).

use super::estimate::{self, ErrorMetrics, Parts};
use super::final_gather;
use super::{
    scalar, LightChannel, RunHooks, ShotResult, Solution, SolveError, SolveSettings, StopReason,
    TracePoint,
};
use crate::intersect::Intersector;
use crate::mesh::Mesh;
use crate::scene::Material;
use std::time::Instant;

/// What the error target did (`summary.json`: `error_target`).
#[derive(Clone, Copy, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct ErrorTarget {
    /// The target E (a fraction: 0.02 = 2 %).
    pub target: f64,
    /// The estimate reached (average weighted percent error of the result).
    pub estimate: f64,
    pub reached: bool,
    /// Independent shooting passes averaged.
    pub passes: u32,
    /// Further gather rounds pooled with the last pass's gather ([`MAX_REGATHERS`] at most).
    #[serde(default)]
    pub regathers: u32,
    /// The estimate the last gather round's model predicted (against `estimate`, what it
    /// reached), if a round was taken.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub round_predicted: Option<f64>,
    /// Stopped by the default target's bound ([`super::settings::DEFAULT_ERROR_MAX_FACTOR`]).
    pub gave_up: bool,
}

/// A pass aims at this fraction of the error target (module notes): the estimate is itself
/// noisy and its rate of fall is known only roughly, and undershooting costs a further pass.
pub const AIM: f64 = 0.85;

pub use super::settings::ROUND_AIM;

/// The rate p of e ∝ R^−p from two (samples, estimate) points, kept within [¼, ½]: ½ is pure
/// sampling noise, and a rate below ¼ (an estimate barely moving, say from a noisy point) would
/// ask for an unbounded pass.
pub fn rate(before: (f64, f64), after: (f64, f64)) -> f64 {
    let (r0, e0) = before;
    let (r1, e1) = after;
    let p = (e0 / e1).ln() / (r1 / r0).ln();
    if p.is_finite() {
        p.clamp(0.25, 0.5)
    } else {
        0.5
    }
}

/// Samples (rays and hemi-cube cells) of a solve.
fn samples(sol: &Solution) -> f64 {
    (sol.stats.rays + sol.stats.hemicube_cells).max(1) as f64
}

/// Whether a budget (time, rays, Ctrl-C) stopped a pass.
fn budget_stopped(sol: &Solution) -> bool {
    matches!(
        sol.stats.stop_reason,
        Some(StopReason::MaxTime | StopReason::MaxRays | StopReason::Interrupted)
    )
}

/// The estimate a solve ended with (after its gather, if any).
fn estimate_of(sol: &Solution) -> ErrorMetrics {
    sol.stats
        .trace
        .last()
        .map(|t| t.estimate)
        .unwrap_or_default()
}

/// Σ_k w_k·rows_k, per patch and channel.
fn weighted_mean(w: &[f64], rows: &[&[[f64; 3]]]) -> Vec<[f64; 3]> {
    (0..rows[0].len())
        .map(|j| [0, 1, 2].map(|c| rows.iter().zip(w).map(|(r, wk)| wk * r[j][c]).sum()))
        .collect()
}

/// The samples-weighted mean of the passes' shooting results, in the shape of the last pass's
/// solution, with the combined estimate's parts.
fn combine(
    mesh: &Mesh,
    area: &[f64],
    emission: &[f64],
    sols: &[Solution],
) -> (Solution, ErrorMetrics, Parts) {
    let shot: Vec<&ShotResult> = sols
        .iter()
        .map(|s| s.shooting.as_deref().expect("passes keep their shooting"))
        .collect();
    let total: f64 = sols.iter().map(samples).sum();
    let w: Vec<f64> = sols.iter().map(|s| samples(s) / total).collect();
    let n = area.len();
    let mut out = sols[sols.len() - 1].clone();
    let b: Vec<&[[f64; 3]]> = shot.iter().map(|s| s.b.as_slice()).collect();
    let unshot: Vec<&[[f64; 3]]> = sols.iter().map(|s| s.unshot.as_slice()).collect();
    out.b = weighted_mean(&w, &b);
    out.unshot = weighted_mean(&w, &unshot);
    out.channels = (0..out.channels.len())
        .map(|c| {
            let rows: Vec<&[[f64; 3]]> = shot.iter().map(|s| s.channels[c].b.as_slice()).collect();
            LightChannel {
                name: out.channels[c].name.clone(),
                b: weighted_mean(&w, &rows),
            }
        })
        .collect();
    let e = &mut out.stats.energy;
    for c in 0..3 {
        let avg = |f: &dyn Fn(&super::EnergyBalance) -> f64| -> f64 {
            (0..sols.len())
                .map(|k| w[k] * f(&sols[k].stats.energy))
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
    st.energy_per_ray = 1.0
        / sols
            .iter()
            .map(|s| 1.0 / s.stats.energy_per_ray)
            .sum::<f64>();
    st.switch = sols[0].stats.switch;
    st.final_gather = None;
    let mut sigma: Vec<f64> = (0..n)
        .map(|j| {
            (0..sols.len())
                .map(|k| (w[k] * shot[k].parts.sigma[j]).powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .collect();
    let mut missing: Vec<f64> = (0..n)
        .map(|j| {
            (0..sols.len())
                .map(|k| w[k] * shot[k].parts.missing[j])
                .sum()
        })
        .collect();
    let mut b_est: Vec<f64> = (0..n).map(|j| scalar(&out.b[j]) + missing[j]).collect();
    // The dark-side rule (estimate::DARK_SIDE) on the combination: a side that got light in one
    // pass by a chance leak is still dark beside its lit other side.
    let reflected = |j: usize| scalar(&out.b[j]) - emission[j];
    for j in 0..n {
        let dark = mesh.other_side(j).is_some_and(|o| {
            emission[j] <= 0.0 && reflected(j) <= estimate::DARK_SIDE * reflected(o)
        }) || (emission[j] <= 0.0 && reflected(j) <= 0.0 && mesh.hidden.side(mesh, j));
        if dark {
            (missing[j], sigma[j], b_est[j]) = (0.0, 0.0, 0.0);
        }
    }
    let err = (0..n).map(|j| estimate::combine(missing[j], sigma[j]));
    let m = estimate::from_errors(area, err, &b_est);
    let parts = Parts {
        missing,
        sigma,
        b: b_est,
    };
    (out, m, parts)
}

/// The shooting result a final gather was made on, its estimate's parts and the gathers: what
/// a further gather round starts from.
struct Base {
    pre: Solution,
    parts: Parts,
    gathers: final_gather::Gathers,
}

/// The trace point after a combination (or a gather round): its rays count the final
/// gather's too, as the driver's point after a gather does.
fn trace_point(
    out: &Solution,
    m: ErrorMetrics,
    start: Instant,
    hooks: &RunHooks,
    area: &[f64],
) -> TracePoint {
    let mut point = out.stats.trace.last().copied().unwrap_or_default();
    point.time_s = start.elapsed().as_secs_f64();
    point.shots = out.stats.shots;
    point.rays = out.stats.rays + out.stats.final_gather.map_or(0, |g| g.rays);
    point.cells = out.stats.hemicube_cells;
    point.estimate = m;
    point.error = hooks
        .reference
        .as_ref()
        .map(|r| estimate::against(area, &out.b, r));
    point
}

/// The passes' route to the target, costed to compare with a gather round's (module notes):
/// the samples still wanted, `want`, and the final gather redone on the combination at rays
/// grown with the samples from those of the gathers it replaces (`gathers_now`, the rounds'
/// included: a pass gathering fewer would lose the rounds' precision, not add to it).
struct Route {
    so_far: f64,
    want: f64,
    gathers_now: f64,
}

impl Route {
    /// Whether the passes would cast more rays to reach the target than a round planned to
    /// reach it alone (`round_rays`). Both are costed to the target: a single pass, cut to at
    /// most three times the samples so far, looks cheap against a round that gets there
    /// alone, yet leaves the next choice to be made again; with a small first gather every
    /// choice then went to passes until the default bound gave up.
    fn costs_more_than(&self, round_rays: f64) -> bool {
        let gathers = self.gathers_now * (self.so_far + self.want) / self.so_far.max(1.0);
        round_rays < self.want + gathers
    }
}

/// At most this many further gather rounds in one solve (each is planned to reach the target
/// alone; a second or third only corrects the model's misses).
pub const MAX_REGATHERS: u32 = 3;

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
    let area: Vec<f64> = mesh.patches.iter().map(|p| p.area).collect();
    let emission: Vec<f64> = mesh
        .patches
        .iter()
        .map(|p| scalar(&materials[p.material as usize].emission()))
        .collect();
    let first = super::driver::shoot(mesh, materials, isect, cfg, hooks, &mut on_trace)?;
    let inputs = Inputs {
        mesh,
        materials,
        isect,
        cfg,
        hooks,
        target,
        start,
        area,
        emission,
    };
    let mut passes = Passes::after_first(inputs, first);
    passes.refine(&mut on_trace)?;
    Ok(passes.finish())
}

/// What the passes read: the scene, the first pass's settings and hooks, the target, the
/// patches' areas and scalar emission.
struct Inputs<'a, I> {
    mesh: &'a Mesh,
    materials: &'a [Material],
    isect: Option<&'a I>,
    cfg: &'a SolveSettings,
    hooks: &'a RunHooks,
    target: f64,
    start: Instant,
    area: Vec<f64>,
    emission: Vec<f64>,
}

/// Where an error-target solve stands after each pass or gather round.
struct Passes<'a, I> {
    at: Inputs<'a, I>,
    /// The final gather's intersector, when the settings ask for one: later passes shoot only,
    /// the gather runs on their combination.
    gather: Option<&'a I>,
    /// The later passes' settings (no final gather) and hooks (no checkpoints, no resume).
    shoot_cfg: SolveSettings,
    later_hooks: RunHooks,
    /// The first pass's samples and energy per ray: later passes are sized from them.
    r1: f64,
    c1: f64,
    /// The first pass's gather rays, to cost a shooting pass's gather, and its rays per patch
    /// (its pilot's choice), which later passes' gathers grow from.
    first_gather_rays: f64,
    first_rays_per_patch: usize,
    /// The estimate of the result so far, its trace, the result and the passes it combines.
    m: ErrorMetrics,
    trace: Vec<TracePoint>,
    out: Solution,
    sols: Vec<Solution>,
    /// Stopped by the default target's bound.
    capped: bool,
    /// (samples, estimate) after the last combination, and the rate the estimate falls at.
    last: (f64, f64),
    p: f64,
    /// The last final gather, for further rounds.
    base: Option<Base>,
    regathers: u32,
    round_predicted: Option<f64>,
}

impl<'a, I: Intersector> Passes<'a, I> {
    /// The state after the first pass, `first`.
    fn after_first(at: Inputs<'a, I>, mut first: Solution) -> Self {
        let cfg = at.cfg;
        let r1 = samples(&first);
        let c1 = first.stats.energy_per_ray;
        let m = estimate_of(&first);
        let trace = first.stats.trace.clone();
        // The result holds no copy of the pass's shooting books (the result never shows them):
        // on a million patches they and their gathers are hundreds of MB.
        let shooting = first.shooting.take();
        let out = first.clone();
        first.shooting = shooting;
        let mut sols = vec![first];
        let gather = at
            .isect
            .filter(|_| cfg.final_gather && cfg.method.casts_rays());
        let shoot_cfg = SolveSettings {
            final_gather: false,
            ..cfg.clone()
        };
        let later_hooks = RunHooks {
            reference: at.hooks.reference.clone(),
            light_groups: at.hooks.light_groups.clone(),
            checkpoint: None,
            resume: None,
            interrupt: at.hooks.interrupt.clone(),
        };
        let last = (r1, m.weighted_percent);
        let first_gather_rays = out.stats.final_gather.map_or(0.0, |g| g.rays as f64);
        // What a gather round starts from, made only when the first pass left the target to
        // reach.
        let unmet = m.weighted_percent > at.target;
        // The pass's gathers move to the base: nothing reads them from the pass again.
        let first_gathers = sols[0].shooting.as_mut().and_then(|s| s.gathers.take());
        let first_rays_per_patch = first_gathers
            .as_ref()
            .map_or(cfg.first_gather_rays(), |g| g.first_rays());
        let base = match (gather, first_gathers) {
            (Some(_), Some(gathers)) if unmet => {
                let (pre, _, parts) = combine(at.mesh, &at.area, &at.emission, &sols);
                Some(Base {
                    pre,
                    parts,
                    gathers,
                })
            }
            _ => None,
        };
        Passes {
            at,
            gather,
            shoot_cfg,
            later_hooks,
            r1,
            c1,
            first_gather_rays,
            first_rays_per_patch,
            m,
            trace,
            out,
            sols,
            capped: false,
            last,
            p: 0.5,
            base,
            regathers: 0,
            round_predicted: None,
        }
    }

    /// Further passes or gather rounds until the estimate reaches the target or a budget, or
    /// the default target's bound, stops them.
    fn refine(&mut self, on_trace: &mut impl FnMut(&TracePoint)) -> Result<(), SolveError> {
        let (cfg, target, r1) = (self.at.cfg, self.at.target, self.r1);
        while self.m.weighted_percent > target && !budget_stopped(&self.sols[self.sols.len() - 1]) {
            let so_far: f64 = self.sols.iter().map(samples).sum();
            let bound = cfg.error_bound(r1);
            if bound.is_some_and(|b| so_far >= b) {
                self.capped = true;
                break;
            }
            let want =
                so_far * ((self.m.weighted_percent / (AIM * target)).powf(1.0 / self.p) - 1.0);
            let mut rays = want.clamp(r1, 3.0 * so_far);
            if let Some(b) = bound {
                rays = rays.min((b - so_far).max(r1));
            }
            // A further gather round instead, when the model says it reaches the passes' aim
            // for fewer rays than the passes and their gathers would cast (module notes); once
            // chosen, it is sized for its own aim, [`ROUND_AIM`].
            let plan_for = |aim: f64| match (self.gather, self.base.as_ref()) {
                (Some(_), Some(b)) if self.regathers < MAX_REGATHERS => b.gathers.plan(
                    self.at.mesh.patches.len(),
                    aim * target,
                    super::settings::MAX_GATHER_RAYS,
                ),
                _ => None,
            };
            let plan = plan_for(AIM);
            let passes = Route {
                so_far,
                want,
                gathers_now: self
                    .base
                    .as_ref()
                    .map_or(self.first_gather_rays * so_far / r1, |b| {
                        b.gathers.rays() as f64
                    }),
            };
            // The bound holds the gather rounds too: all rays cast, gathers included, stay
            // within the bound's samples and the first pass's share of gather rays.
            let cast = self.trace.last().map_or(so_far, |t| t.rays as f64);
            let all_rays = bound.map(|b| b * (r1 + self.first_gather_rays) / r1);
            let fits =
                |pl: &final_gather::RegatherPlan| all_rays.is_none_or(|a| cast + pl.rays <= a);
            if let (Some(isect), Some(plan)) = (
                self.gather,
                plan.filter(|pl| passes.costs_more_than(pl.rays) && fits(pl)),
            ) {
                let plan = plan_for(ROUND_AIM).unwrap_or(plan);
                if !self.regather(isect, &plan, so_far, on_trace) {
                    break;
                }
                continue;
            }
            if !self.further_pass(rays, so_far, on_trace)? {
                break;
            }
        }
        Ok(())
    }

    /// A further gather round pooled with the last gather, in place of a pass. False (and the
    /// solve stopped by time) when, under `--max-time`, the round does not fit in the time left.
    fn regather(
        &mut self,
        isect: &I,
        plan: &final_gather::RegatherPlan,
        so_far: f64,
        on_trace: &mut impl FnMut(&TracePoint),
    ) -> bool {
        let elapsed = self.at.start.elapsed().as_secs_f64();
        let cast = self.trace.last().map_or(so_far, |t| t.rays as f64);
        let want = plan.rays.ceil() as usize;
        if super::gather_budget::gather_rays_fitting(self.at.cfg, want, 1, cast, elapsed)
            != Some(want)
        {
            self.out.stats.stop_reason = Some(StopReason::MaxTime);
            return false;
        }
        let b = self.base.take().expect("planned from it");
        let more = Some((b.gathers, plan.extra.as_slice()));
        let (sol, em, nb) = self.gathered(isect, b.pre, b.parts, 1.0, more);
        self.regathers += 1;
        self.round_predicted = Some(plan.predicted);
        (self.out, self.m) = (sol, em);
        self.base = Some(nb);
        self.record(on_trace);
        self.last = (so_far, self.m.weighted_percent);
        true
    }

    /// A further independent pass of about `rays` samples, combined with the others (and
    /// gathered on). False when a budget leaves no room for it or cuts it short: it is left out.
    fn further_pass(
        &mut self,
        rays: f64,
        so_far: f64,
        on_trace: &mut impl FnMut(&TracePoint),
    ) -> Result<bool, SolveError> {
        let cfg = self.at.cfg;
        let elapsed = self.at.start.elapsed().as_secs_f64();
        let used = so_far as u64;
        let next = SolveSettings {
            seed: crate::random::mix(
                cfg.seed ^ (self.sols.len() as u64).wrapping_mul(0x2545_F491_4F6C_DD1D),
            ),
            energy_per_ray: Some(self.c1 * self.r1 / rays),
            max_time: match cfg.max_time {
                Some(t) if elapsed >= t => return Ok(false),
                Some(t) => Some(t - elapsed),
                None => None,
            },
            max_rays: match cfg.max_rays {
                Some(r) if used >= r => return Ok(false),
                Some(r) => Some(r - used),
                None => None,
            },
            ..self.shoot_cfg.clone()
        };
        let (mesh, materials) = (self.at.mesh, self.at.materials);
        let sol = super::driver::shoot(
            mesh,
            materials,
            self.at.isect,
            &next,
            &self.later_hooks,
            |_| {},
        )?;
        if budget_stopped(&sol) {
            // Cut short: left out, the result stays as it was (module notes).
            self.out.stats.stop_reason = sol.stats.stop_reason;
            return Ok(false);
        }
        let Some(scale) = self.gather_scale(so_far, &sol) else {
            self.out.stats.stop_reason = Some(StopReason::MaxTime);
            return Ok(false);
        };
        self.sols.push(sol);
        let combined = combine(mesh, &self.at.area, &self.at.emission, &self.sols);
        (self.out, self.m) = match self.gather {
            Some(isect) => {
                let (pre, _, parts) = combined;
                let (sol, em, b) = self.gathered(isect, pre, parts, scale, None);
                self.base = Some(b);
                (sol, em)
            }
            None => (combined.0, combined.1),
        };
        self.record(on_trace);
        let now = (
            self.sols.iter().map(samples).sum::<f64>(),
            self.m.weighted_percent,
        );
        self.p = rate(self.last, now);
        self.last = now;
        Ok(true)
    }

    /// How much the gather after pass `sol` grows its rays per patch (samples so far / the
    /// first pass's), under `--max-time` cut to the rays that fit; `None` when not even the
    /// fewest do (the pass is then left out, as a pass cut short is).
    fn gather_scale(&self, so_far: f64, sol: &Solution) -> Option<f64> {
        let cfg = self.at.cfg;
        let mut scale = (so_far + samples(sol)) / self.r1;
        if self.gather.is_some() {
            let wanted = (self.first_rays_per_patch as f64 * scale).round() as usize;
            let elapsed = self.at.start.elapsed().as_secs_f64();
            let cast = so_far + samples(sol);
            let np = self.at.mesh.patches.len();
            let r = super::gather_budget::gather_rays_fitting(cfg, wanted, np, cast, elapsed)?;
            scale = scale * r as f64 / wanted.max(1) as f64;
        }
        Some(scale)
    }

    /// The combination through the final gather: rays per patch grown by `scale` (samples so
    /// far / the first pass's) so gather and shooting stay in balance; or, with `more`, a
    /// further round pooled with the gathers the last one was made with.
    fn gathered(
        &self,
        isect: &I,
        pre: Solution,
        parts: Parts,
        scale: f64,
        more: Option<(final_gather::Gathers, &[usize])>,
    ) -> (Solution, ErrorMetrics, Base) {
        let (cfg, hooks) = (self.at.cfg, self.at.hooks);
        let rays = (self.first_rays_per_patch as f64 * scale)
            .round()
            .min(super::settings::MAX_GATHER_RAYS as f64) as usize;
        let shooting = final_gather::Shooting {
            parts,
            energy_per_ray: pre.stats.energy_per_ray,
        };
        let mut sol = pre.clone();
        let sky = cfg.build_sky().ok().flatten();
        let inputs = final_gather::GatherInputs {
            mesh: self.at.mesh,
            materials: self.at.materials,
            isect,
            seed: cfg.seed,
            rays,
            group: hooks.light_groups.as_deref().map(|g| g.of_patch.as_slice()),
            shooting: &shooting,
            sky: sky.as_ref(),
            reference: hooks.reference.as_deref().map(Vec::as_slice),
            pilot: None,
        };
        let more = more.map(|(prior, extra)| final_gather::Regather { prior, extra });
        let gathers = final_gather::apply(&inputs, &mut sol, more, &mut |_| {});
        let m = estimate_of(&sol);
        let base = Base {
            pre,
            parts: shooting.parts,
            gathers,
        };
        (sol, m, base)
    }

    /// Records the trace point of the result as it now stands.
    fn record(&mut self, on_trace: &mut impl FnMut(&TracePoint)) {
        let at = &self.at;
        let point = trace_point(&self.out, self.m, at.start, at.hooks, &at.area);
        on_trace(&point);
        self.trace.push(point);
    }

    /// The result: the last combination, with the whole trace and what the target did.
    fn finish(self) -> Solution {
        let (m, target) = (self.m, self.at.target);
        let mut out = self.out;
        out.shooting = None;
        out.stats.seconds = self.at.start.elapsed().as_secs_f64();
        out.stats.trace = self.trace;
        out.stats.error_target = Some(ErrorTarget {
            target,
            estimate: m.weighted_percent,
            reached: m.weighted_percent <= target,
            passes: self.sols.len() as u32,
            regathers: self.regathers,
            round_predicted: self.round_predicted,
            gave_up: self.capped,
        });
        out
    }
}

#[cfg(test)]
mod tests {
    use super::{rate, Route};

    /// The office-sized case that went wrong: a first pass of 6.2 M samples with a 3.5 M-ray
    /// gather at 17 %, aiming at 4.25 %: the passes need 15× the samples again (93 M) and
    /// their gathers 56 M; a round planned at 108 M rays wins, though one pass capped at 3×
    /// (19 M samples, 14 M of gather) would have looked cheaper.
    #[test]
    fn a_round_is_weighed_against_the_whole_route_of_passes() {
        let so_far = 6.2e6;
        let want = so_far * ((0.17f64 / 0.0425).powi(2) - 1.0);
        let route = Route {
            so_far,
            want,
            gathers_now: 3.5e6,
        };
        assert!(route.costs_more_than(108e6));
        assert!(!route.costs_more_than(200e6));
        let capped = 3.0 * so_far;
        assert!(108e6 > capped + 3.5e6 * (so_far + capped) / so_far);
    }

    #[test]
    fn the_rate_is_measured_and_kept_between_a_quarter_and_a_half() {
        // Sibenik: 7.9 % at R, 5.35 % at 2.5 R.
        let p = rate((1.0, 7.9), (2.5, 5.35));
        assert!((p - 0.425).abs() < 0.005, "{p}");
        // Pure sampling noise, and faster: ½.
        assert_eq!(rate((1.0, 8.0), (4.0, 4.0)), 0.5);
        assert_eq!(rate((1.0, 8.0), (4.0, 1.0)), 0.5);
        // Barely moving, or rising (a noisy estimate): ¼, never a runaway pass.
        assert_eq!(rate((1.0, 8.0), (4.0, 7.9)), 0.25);
        assert_eq!(rate((1.0, 8.0), (4.0, 9.0)), 0.25);
        assert_eq!(rate((1.0, 0.0), (4.0, 0.0)), 0.5);
    }
}
