//! The final gather: every patch the shooting left noisy re-estimates its own irradiance with
//! rays of its own, after the shooting has converged.
//!
//! **Why.** Shooting (Sec. 2) gives a patch j the light of the rays that happen to hit it: its
//! kept flux is a Poisson count of rays, each carrying the same energy C, so a patch expecting
//! λ_j hits has a relative error 1/√λ_j and is exactly black with probability e^{−λ_j}. The
//! tolerance sets C so that a *typical* patch gets 1/τ² hits; a patch 10⁴ times smaller than
//! typical — the 1 cm² parts next to 10 m² walls of real architectural models — expects a
//! tiny fraction of a ray and comes out black. Hence a last pass that looks from the receiver's
//! side, the "final gather" of two-pass methods (Chen, Rushmeier, Miller & Turner, *A
//! Progressive Multi-Pass Method for Global Illumination*, SIGGRAPH 1991, Sec. 4; Lischinski,
//! Tampieri & Greenberg, *Combining Hierarchical Radiosity and Discontinuity Meshing*,
//! SIGGRAPH 1993: the radiosity solution used as the indirect source of a per-point gather).
//!
//! **How** a patch gathers is the light kernel's ([`crate::light`]): direct light by shadow
//! rays to the emitters drawn by what they give the patch, the sun, cosine-weighted hemisphere rays returning the
//! solved B − E of the side they meet (near hits followed, [`crate::light::NEAR`]), combined
//! by multiple importance sampling, at points stratified over the patch
//! (`PatchPoints::at`, Latin hypercube). B_i^gather = E_i + ρ_i·H_i (RGB, f64), with the
//! scalar sample variance of the mean. This module decides which patches gather, with how
//! many rays and rounds, and how the gather's estimate is combined with the shooting's.
//!
//! **Which patches**: every patch that reflects (ρ > 0), but dark sides (below) and hidden
//! sides the shooting left black (inside closed solids: `crate::mesh::Hidden`). Gathering only
//! the patches the shooting left noisier than the tolerance (the first design) left the bias of
//! constant patches in place where the shooting was precise: on the project's furnished office
//! (`scripts/radiance`), a shelf back 5 cm from a wall came out at 2.7× Radiance's irradiance
//! and the whole scene at +1.3 % signed, 3.5 % area-weighted; gathering every patch with near
//! hits followed and biased shooting estimates rejected: +0.1 % signed, 2.0 % (README, "Final
//! gather").
//!
//! **Combining** the two estimates of a gathered patch: inverse-variance weights (both are
//! unbiased estimates of B_i − E_i, away from near surfaces). Where they differ by more than
//! [`BIAS_Z`] combined σ, the shooting's is not noisy but biased (what constant patches beside
//! the receiver sent it) and the gather's is kept alone (`GatherStats::rejected`). The
//! gather's variance is its sample variance. The shooting's is its Poisson model
//! Var(G_i) = ρ_i·C_eff·E(G_i), with E(G_i) taken as the mean of the two estimates (not the
//! shooting's own count, which is 0 exactly where the shooting is worst, and would give a
//! black patch infinite weight), and C_eff the patch's energy per sample from the books (C for
//! rays; more for hemi-cube cells, `super::estimate`). The combined σ = 1/√(w_s + w_g)
//! replaces the shooting's in the error estimate.
//!
//! **The light still owed** (`weigh::owed_per_reflected`). The shooting's estimate spreads
//! the light it has not shot yet evenly per unit area (`super::estimate`): before a gather
//! nothing better is known. A gathered patch's share is then what its own hemisphere rays say:
//! that light arrives reflected by other surfaces, so each gathered patch is owed in
//! proportion to the reflected irradiance its gather found (ρ_i·R_i), the shares adding up to
//! the owed flux of the patches gathered. Measured on the project's furnished room (21,801
//! patches; the first pass against the same pass shot out to nothing owed, the same gather
//! seed, so the difference is the owed light alone): patches the even spread gave 0.2 %,
//! 2.3 %, 11 %, 33 % and 70 % of their B were owed 0.05 %, 0.12 %, 0.31 %, 0.47 % and
//! 0.68 % — the dark faces beside books and under shelves get their light from nearby dark
//! surfaces, not their area's share of the room's. The even spread had made the owed light a
//! third of the estimate after the first gather there, and an error target paid passes for it.
//!
//! **The books stay the shooting's.** The gather casts rays but moves no energy: emitted =
//! absorbed + absorbed on back faces + escaped + unshot is the shooting's account, to 1e-9. It
//! re-estimates the per-patch B that is written out (and the per-light channels, gathered
//! alike: a direct sample goes to its emitter's channel, an indirect ray returns each channel's
//! B − E, and one weight per patch combines them, so they still sum to `b`).
//!
//! **Reproducible**: each patch's random numbers come from (seed, [`Stream::Gather`], patch)
//! — round k of `solve --error`'s further rounds from [`Stream::Regather`]`(k)` — patches are
//! gathered in parallel and written back in patch order, so the result does not depend on the
//! thread count.

use super::estimate::{self, ErrorMetrics, Parts};
use super::{rng_for, scalar, LightChannel, Solution, Stream, TracePoint};
use crate::intersect::Intersector;
use crate::light::emitters::{Learned, Sight};
use crate::light::gather::{Ask, Gathered, Spot};
use crate::light::{self, emission_and_reflectance, Kernel, LightParts, Rgb, Solved};
use crate::mesh::spatial::{facing_class, space_order};
use crate::mesh::Mesh;
use crate::sample::PatchPoints;
use crate::scene::Material;
use crate::sky::Sky;
pub use pilot::{Pilot, PilotSizing};
use rayon::prelude::*;
use std::borrow::Cow;
use std::time::Instant;
use weigh::{owed_per_reflected, weigh};

mod pilot;
mod weigh;

/// What the final gather did (`summary.json`: `final_gather`).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct GatherStats {
    /// Patches gathered (all that reflect light, but dark sides).
    pub patches: u64,
    /// Gathered patches whose shooting estimate was biased (more than [`BIAS_Z`] σ from the
    /// gather's) and was left out.
    #[serde(default)]
    pub rejected: u64,
    /// Rays cast: shadow rays to the emitters and hemisphere rays.
    pub rays: u64,
    /// Wall-clock seconds of the gather.
    pub seconds: f64,
    /// Patches with ρ > 0 and no reflected light at all (B = E exactly), before and after.
    pub black_before: u64,
    pub black_after: u64,
    /// Mean weight the shooting estimate kept in the gathered patches (0: all gather).
    pub mean_shooting_weight: f64,
    /// How a pilot sized the first round (`solve --error`'s first pass), if one did.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pilot: Option<PilotSizing>,
}

/// A shooting estimate this many combined σ from the gather's is biased, not noisy: kept out.
pub const BIAS_Z: f64 = 4.0;

/// Patch `i`'s gather of `rays` rays through `kernel`, its random numbers from `stream`: the
/// first round's ([`Stream::Gather`]), a later round's ([`Gathers::plan`]) or the first
/// round's top-up of its pilot's patches ([`Stream::TopUp`]) draw independent numbers, to be
/// pooled.
fn gather_patch<I: Intersector>(
    kernel: &Kernel<'_, I>,
    seed: u64,
    (i, rays, stream): (usize, usize, Stream),
    learned: &mut Learned,
) -> Gathered {
    let points = PatchPoints::new(kernel.mesh, i);
    let mut rng = rng_for(seed, stream, i as u64);
    let at = |u: f32, v: f32| points.at(u, v);
    let spot = Spot {
        patch: i,
        at: &at,
        n: kernel.mesh.patches[i].normal,
        eps: kernel.eps_of(i),
        rho: kernel.sol.rho[i],
    };
    let ask = Ask {
        rays,
        lights: true,
        parts: LightParts::All,
        known: Default::default(),
    };
    kernel.gather_learning(&spot, ask, Some(learned), &mut rng)
}

/// Runs of at most this many neighbouring patches learn from each other's light samples
/// ([`Learned`]).
const LEARNING_RUN: usize = 256;

/// Gathers `todo[k]` with `rays(k)` rays (none when 0) from `stream`: in parallel over runs
/// of neighbouring patches facing one way ([`crate::mesh::spatial::space_order`], so the runs
/// do not depend on the order of the model's faces), each patch of a run learning from those
/// before it which lamps it sees ([`Learned`]). Results in the order of `todo`.
fn gather_runs<I: Intersector>(
    kernel: &Kernel<'_, I>,
    seed: u64,
    todo: &[usize],
    rays: impl Fn(usize) -> usize + Sync,
    stream: Stream,
) -> Vec<Option<Gathered>> {
    let mesh = kernel.mesh;
    let order = space_order(mesh, todo);
    let class = |at: usize| facing_class(mesh.patches[todo[order[at] as usize]].normal);
    let mut runs = Vec::new();
    let mut start = 0;
    for at in 1..=order.len() {
        if at == order.len() || at - start == LEARNING_RUN || class(at) != class(start) {
            runs.push(&order[start..at]);
            start = at;
        }
    }
    // Every run a job of its own (`with_max_len(1)`): left to rayon's own splitting, one
    // thread was handed a stretch of runs to gather alone at the end while the other waited
    // (2.4 s of the 1 M-patch building's 31 s).
    let got: Vec<Vec<(u32, Option<Gathered>)>> = runs
        .into_par_iter()
        .with_max_len(1)
        .map(|run| {
            let mut learned = Learned::default();
            let mut out = Vec::with_capacity(run.len());
            for group in shared_cuts(mesh, todo, run) {
                let patches: Vec<usize> = (group.iter())
                    .filter(|&&k| rays(k as usize) > 0)
                    .map(|&k| todo[k as usize])
                    .collect();
                kernel.share_cut(&patches, &mut learned);
                for &k in group {
                    let r = rays(k as usize);
                    let i = todo[k as usize];
                    let g =
                        (r > 0).then(|| gather_patch(kernel, seed, (i, r, stream), &mut learned));
                    out.push((k, g));
                }
            }
            out
        })
        .collect();
    let mut out = vec![None; todo.len()];
    for (k, g) in got.into_iter().flatten() {
        out[k as usize] = g;
    }
    out
}

/// At most this many neighbouring patches of one polygon share the shape of a cut of the
/// emitters' tree (`Learned::share_cut`).
const SHARED_CUT: usize = 8;

/// `run` (indices into `todo`) in groups that share a cut: consecutive patches of one
/// polygon with one normal, at most [`SHARED_CUT`] of them.
fn shared_cuts<'r>(mesh: &Mesh, todo: &[usize], run: &'r [u32]) -> Vec<&'r [u32]> {
    let patch = |at: usize| &mesh.patches[todo[run[at] as usize]];
    let mut groups = Vec::new();
    let mut start = 0;
    for at in 1..=run.len() {
        if at == run.len()
            || at - start == SHARED_CUT
            || patch(at).polygon != patch(start).polygon
            || patch(at).normal != patch(start).normal
        {
            groups.push(&run[start..at]);
            start = at;
        }
    }
    groups
}

/// The shooting's estimate of each patch, from the books at the end of the shooting.
pub struct Shooting {
    /// The error estimate's parts (owed light, σ, B) per patch.
    pub parts: Parts,
    /// Energy per ray C (scalar W).
    pub energy_per_ray: f64,
}

/// The gathers [`apply`] made, per gathered patch, and what the error estimate after them was
/// made of: kept so that a further round can add rays where they pay most and pool them with
/// these ([`Gathers::plan`], used by `solve --error`, `passes`).
#[derive(Clone, Debug, Default)]
pub struct Gathers {
    /// The gathered patches, and their pooled gathers.
    todo: Vec<usize>,
    got: Vec<Gathered>,
    /// Rays asked of each so far (the gather's sample count; near hits followed cost more).
    asked: Vec<usize>,
    /// Per gathered patch, the error model after the last round.
    model: Vec<PatchModel>,
    /// The estimate's relative errors of the patches not gathered, summed, and how many
    /// patches the estimate averages over.
    fixed: f64,
    count: usize,
    /// Rounds so far, and their wall-clock seconds.
    rounds: u64,
    seconds: f64,
    /// The emitters' sight rays cast before the first round (`crate::light::emitters`), and
    /// what they found, which the further rounds reuse.
    sight_rays: u64,
    sight: Option<Sight>,
    /// Rays per patch of the first round (the pilot's choice when it was sized by one), and
    /// what the pilot found.
    first_rays: usize,
    pilot: Option<PilotSizing>,
}

/// One gathered patch's error model: the shooting's variance and the gather's (of ρ·H's mean,
/// W²/m⁴), whether the shooting was rejected as biased, the light still owed, and B's
/// estimate (the relative error's denominator).
#[derive(Clone, Copy, Debug)]
struct PatchModel {
    var_s: f64,
    var_g: f64,
    biased: bool,
    missing: f64,
    b_true: f64,
}

impl PatchModel {
    /// The estimate's relative error of this patch with the gather's rays multiplied by `k`
    /// (the gather's variance falls as 1/k: independent rounds pooled by their rays).
    fn relative(&self, k: f64) -> f64 {
        if self.b_true <= 0.0 {
            return 0.0;
        }
        let var_g = self.var_g / k;
        let floor = f64::MIN_POSITIVE;
        let sigma = if self.biased {
            var_g.sqrt()
        } else {
            (1.0 / (1.0 / (self.var_s + floor) + 1.0 / (var_g + floor))).sqrt()
        };
        estimate::combine(self.missing, sigma) / self.b_true
    }
}

/// A further gather round ([`Gathers::plan`]): rays to add per patch (indexed by patch id),
/// how many in all, and the estimate they are predicted to give.
#[derive(Clone, Debug)]
pub struct RegatherPlan {
    pub extra: Vec<usize>,
    pub asked: u64,
    /// Rays the round is expected to cast (asked × the rays per asked ray measured so far).
    pub rays: f64,
    pub predicted: f64,
}

impl Gathers {
    /// Rays per patch of the first round: later passes grow theirs from it.
    pub fn first_rays(&self) -> usize {
        self.first_rays
    }

    /// Rays cast by every round so far.
    pub fn rays(&self) -> u64 {
        self.got.iter().map(|g| g.rays).sum::<u64>() + self.sight_rays
    }

    /// Where to add gather rays so that the estimate (the mean relative error over the
    /// patches, [`estimate::from_errors`]) falls to `goal`, as cheaply as the model knows how.
    ///
    /// With its gather's rays multiplied by k_i, patch i's relative error e_i falls as
    /// e_i/√k_i where the gather dominates it. Minimising Σ e_i/√k_i for a given total of rays
    /// Σ n_i k_i (Lagrange) gives n_i k_i ∝ (e_i·√n_i)^(2/3): rays go where the error is, as
    /// the cube root of its square, never fewer than a patch has. The multiplier is found by
    /// bisection on the model's prediction (`PatchModel::relative`, which also keeps what
    /// rays cannot remove: the shooting's weight, the light still owed). `None` when even
    /// `max_rays` per patch would not reach `goal`, or there is nothing to gather.
    pub fn plan(&self, np: usize, goal: f64, max_rays: usize) -> Option<RegatherPlan> {
        if self.todo.is_empty() || self.count == 0 {
            return None;
        }
        let n = self.count as f64;
        let want: Vec<f64> = self
            .model
            .iter()
            .zip(&self.asked)
            .map(|(m, &a)| (m.relative(1.0) * (a as f64).sqrt()).powf(2.0 / 3.0))
            .collect();
        let rays_at = |lambda: f64| -> Vec<usize> {
            want.iter()
                .zip(&self.asked)
                .map(|(&w, &a)| ((lambda * w).ceil() as usize).clamp(a, max_rays.max(a)))
                .collect()
        };
        let predict = |total: &[usize]| -> f64 {
            let sum: f64 = self
                .model
                .iter()
                .zip(total.iter().zip(&self.asked))
                .map(|(m, (&t, &a))| m.relative(t as f64 / a.max(1) as f64))
                .sum();
            (self.fixed + sum) / n
        };
        let top = want.iter().cloned().fold(0.0, f64::max);
        if top <= 0.0 || predict(&rays_at(f64::INFINITY)) > goal {
            return None;
        }
        // λ so large every patch is at the cap meets the goal; halve the bracket 60 times.
        let (mut lo, mut hi) = (0.0, max_rays as f64 / top.clamp(f64::MIN_POSITIVE, 1.0));
        while predict(&rays_at(hi)) > goal {
            hi *= 2.0;
        }
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if predict(&rays_at(mid)) <= goal {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        let total = rays_at(hi);
        let mut extra = vec![0usize; np];
        for (k, (&t, &a)) in total.iter().zip(&self.asked).enumerate() {
            extra[self.todo[k]] = t - a;
        }
        let asked: u64 = extra.iter().map(|&x| x as u64).sum();
        let asked_so_far: u64 = self.asked.iter().map(|&a| a as u64).sum();
        let per_ray = self.rays() as f64 / asked_so_far.max(1) as f64;
        Some(RegatherPlan {
            extra,
            asked,
            rays: asked as f64 * per_ray,
            predicted: predict(&total),
        })
    }
}

/// A further round for [`apply`]: the gathers so far, and the rays to add per patch.
pub struct Regather<'a> {
    pub prior: Gathers,
    pub extra: &'a [usize],
}

/// What [`apply`] gathers with: the model, the solve's settings for the gather, and the
/// shooting's estimate it is combined with.
pub struct GatherInputs<'a, I> {
    pub mesh: &'a Mesh,
    pub materials: &'a [Material],
    pub isect: &'a I,
    pub seed: u64,
    /// Rays per patch (at least 4 are cast).
    pub rays: usize,
    /// Light group per patch, for the per-light channels.
    pub group: Option<&'a [u32]>,
    pub shooting: &'a Shooting,
    /// The sky that lights the model from outside, when there is one.
    pub sky: Option<&'a Sky>,
    /// The reference solution the trace measures the error against, when there is one.
    pub reference: Option<&'a [[f64; 3]]>,
    /// A first round sized by a pilot to land the estimate at a goal (`solve --error`'s first
    /// pass), `rays` then its most rays per patch.
    pub pilot: Option<Pilot>,
}

/// Gathers the patches that need it (see the module notes) and rewrites `sol.b` and
/// `sol.channels` with the combined estimates; records what it did in `sol.stats` and appends a
/// trace point with the error estimate after the gather (and the error against the
/// reference). With `more`, `sol` must be the shooting result the prior gathers were made on:
/// the patches given extra rays gather them afresh (independent random numbers), pooled with
/// what they had by rays; the others keep theirs. Returns the gathers, for a further round.
pub fn apply<I: Intersector>(
    inp: &GatherInputs<'_, I>,
    sol: &mut Solution,
    more: Option<Regather>,
    on_trace: &mut impl FnMut(&TracePoint),
) -> Gathers {
    let t0 = Instant::now();
    let (e, rho) = emission_and_reflectance(inp.mesh, inp.materials);
    let area: Vec<f64> = inp.mesh.patches.iter().map(|p| p.area).collect();
    let black_before = black(&sol.b, &e, &rho, inp.mesh);
    let mut gathers = {
        let solved = Solved {
            e: Cow::Borrowed(&e),
            rho: Cow::Borrowed(&rho),
            b: &sol.b,
            channels: &sol.channels,
            group: inp.group.filter(|_| !sol.channels.is_empty()),
        };
        let mut kernel = Kernel::new(inp.mesh, inp.materials, inp.isect, solved, inp.sky);
        let mut gathers = match more {
            Some(mut more) => {
                if let Some(sight) = more.prior.sight.take() {
                    kernel.emitters.set_sight(sight);
                }
                regather(&kernel, inp.seed, more)
            }
            None => {
                let sight_rays = kernel.learn_sight(inp.seed);
                let todo = to_gather(&kernel, sol);
                let first = match inp.pilot {
                    Some(p) => pilot::sized_round(&kernel, inp, todo, sol, p),
                    None => first_round(&kernel, inp.seed, todo, inp.rays.max(4)),
                };
                Gathers {
                    sight_rays,
                    ..first
                }
            }
        };
        gathers.sight = kernel.emitters.take_sight();
        gathers
    };
    let c = combine(inp, sol, (&e, &rho), &area, &gathers);
    let seconds = t0.elapsed().as_secs_f64();
    gathers.seconds += seconds;
    let todo_len = gathers.todo.len();
    let stats = GatherStats {
        patches: todo_len as u64,
        rays: gathers.rays(),
        seconds: gathers.seconds,
        black_before,
        black_after: black(&c.b, &e, &rho, inp.mesh),
        rejected: c.rejected,
        mean_shooting_weight: if todo_len == 0 {
            1.0
        } else {
            c.weight_sum / todo_len as f64
        },
        pilot: gathers.pilot,
    };
    sol.b = c.b;
    sol.channels = c.channels;
    sol.stats.seconds += seconds;
    sol.stats.final_gather = Some(stats);
    gathers.model = c.model;
    let est = estimate_after(sol, &area, (&c.missing, &c.sigma), &mut gathers);
    if let Some(last) = sol.stats.trace.last().copied() {
        let total_area: f64 = area.iter().sum();
        let p = TracePoint {
            time_s: last.time_s + seconds,
            rays: last.rays + stats.rays,
            mean_b: sol
                .b
                .iter()
                .zip(&area)
                .map(|(b, a)| scalar(b) * a)
                .sum::<f64>()
                / total_area.max(f64::MIN_POSITIVE),
            estimate: est,
            error: inp.reference.map(|r| estimate::against(&area, &sol.b, r)),
            ..last
        };
        sol.stats.trace.push(p);
        on_trace(&p);
    }
    gathers
}

/// What a patch reflects by `b`: B − E, scalar.
fn reflected(b: &[[f64; 3]], e: &[Rgb], i: usize) -> f64 {
    scalar(&b[i]) - light::scalar(e[i])
}

/// Patches with ρ > 0 and no reflected light at all by `b`, but hidden sides
/// ([`crate::mesh::Hidden`]: black because no light can reach them, counted apart) and the
/// dark sides of two-sided surfaces whose other side is lit (they face the void or the inside
/// of an object, as the gather's `faces_void`).
fn black(b: &[[f64; 3]], e: &[Rgb], rho: &[Rgb], mesh: &Mesh) -> u64 {
    (0..b.len())
        .filter(|&i| light::scalar(rho[i]) > 0.0 && reflected(b, e, i) <= 0.0)
        .filter(|&i| !mesh.hidden.side(mesh, i))
        .filter(|&i| !mesh.other_side(i).is_some_and(|o| reflected(b, e, o) > 0.0))
        .count() as u64
}

/// The patches the first round gathers: every patch that reflects, but the sides that face
/// the void and the hidden sides the shooting left black.
fn to_gather<I: Intersector>(kernel: &Kernel<'_, I>, sol: &Solution) -> Vec<usize> {
    let (mesh, e, rho) = (kernel.mesh, &kernel.sol.e, &kernel.sol.rho);
    // A side of a two-sided surface that the shooting left dark while its other side is lit
    // faces the void or the inside of an object (docs/design.md §7): nothing to gather there.
    let faces_void = |i: usize| {
        mesh.other_side(i).is_some_and(|o| {
            let other = reflected(&sol.b, e, o);
            other > 0.0 && reflected(&sol.b, e, i) <= estimate::DARK_SIDE * other
        })
    };
    // A hidden side (inside a closed solid, `crate::mesh::Hidden`) the shooting brought no
    // light: none can reach it, so no rays are cast for it.
    let hidden = |i: usize| mesh.hidden.side(mesh, i) && reflected(&sol.b, e, i) <= 0.0;
    (0..mesh.patches.len())
        .filter(|&i| !faces_void(i) && !hidden(i) && light::scalar(rho[i]) > 0.0)
        .collect()
}

/// The first round of `rays` rays on every patch of `todo`.
fn first_round<I: Intersector>(
    kernel: &Kernel<'_, I>,
    seed: u64,
    todo: Vec<usize>,
    rays: usize,
) -> Gathers {
    let got: Vec<Gathered> = gather_runs(kernel, seed, &todo, |_| rays, Stream::Gather)
        .into_iter()
        .map(|g| g.expect("every patch asks rays"))
        .collect();
    Gathers {
        asked: vec![rays; todo.len()],
        todo,
        got,
        first_rays: rays,
        ..Gathers::default()
    }
}

/// A further round: the patches given extra rays gather them afresh, pooled with the prior
/// gathers by rays.
fn regather<I: Intersector>(kernel: &Kernel<'_, I>, seed: u64, more: Regather) -> Gathers {
    let Regather { mut prior, extra } = more;
    prior.rounds += 1;
    let round = prior.rounds;
    let todo = &prior.todo;
    let fresh = gather_runs(
        kernel,
        seed,
        todo,
        |k| extra[todo[k]],
        Stream::Regather(round),
    );
    for (k, g2) in fresh.into_iter().enumerate() {
        if let Some(g2) = g2 {
            let i = prior.todo[k];
            prior.got[k] = pooled(&prior.got[k], prior.asked[k], &g2, extra[i]);
            prior.asked[k] += extra[i];
        }
    }
    prior
}

/// The gathered patches' estimates combined with the shooting's: radiosity and channels, the
/// estimate's σ and owed light per patch, each gathered patch's error model, the sum of the
/// shooting's weights and the shooting estimates rejected as biased.
struct Combined {
    b: Vec<[f64; 3]>,
    channels: Vec<LightChannel>,
    sigma: Vec<f64>,
    missing: Vec<f64>,
    model: Vec<PatchModel>,
    weight_sum: f64,
    rejected: u64,
}

/// Combines each gathered patch's estimate with the shooting's in `sol` by inverse variance
/// (see the module notes).
fn combine<I>(
    inp: &GatherInputs<'_, I>,
    sol: &Solution,
    (e, rho): (&[Rgb], &[Rgb]),
    area: &[f64],
    gathers: &Gathers,
) -> Combined {
    let shooting = inp.shooting;
    let mut c = Combined {
        b: sol.b.clone(),
        channels: sol.channels.clone(),
        sigma: shooting.parts.sigma.clone(),
        missing: shooting.parts.missing.clone(),
        model: Vec::with_capacity(gathers.todo.len()),
        weight_sum: 0.0,
        rejected: 0,
    };
    let owed = owed_per_reflected(
        shooting,
        rho,
        |i| area[i],
        gathers.todo.iter().copied().zip(&gathers.got),
    );
    for (&i, g) in gathers.todo.iter().zip(&gathers.got) {
        let w = weigh(shooting, &sol.b, (e, rho), (area[i], owed), (i, g));
        c.rejected += u64::from(w.model.biased);
        c.weight_sum += w.a;
        c.missing[i] = w.model.missing;
        c.sigma[i] = w.sigma;
        c.b[i] = w.b.to_array();
        for (k, chan) in c.channels.iter_mut().enumerate() {
            let own = inp.group.is_some_and(|gr| gr[i] as usize == k);
            let ec = if own { e[i] } else { Rgb::ZERO };
            let gb = rho[i] * g.ch[k];
            let was = Rgb::from_array(chan.b[i]);
            chan.b[i] = (ec + w.a * (was - ec) + (1.0 - w.a) * gb).to_array();
        }
        c.model.push(w.model);
    }
    c
}

/// The estimate after the gather: owed light as before, the combined σ; and what the patches
/// not gathered add to it, kept in `gathers` for a further round's plan.
fn estimate_after(
    sol: &Solution,
    area: &[f64],
    (missing, sigma): (&[f64], &[f64]),
    gathers: &mut Gathers,
) -> ErrorMetrics {
    let err: Vec<f64> = missing
        .iter()
        .zip(sigma)
        .map(|(m, s)| estimate::combine(*m, *s))
        .collect();
    let b_true: Vec<f64> = sol
        .b
        .iter()
        .zip(missing)
        .map(|(b, m)| scalar(b) + m)
        .collect();
    let est = estimate::from_errors(area, err.iter().copied(), &b_true);
    let np = sol.b.len();
    let mut in_todo = vec![false; np];
    for &i in &gathers.todo {
        in_todo[i] = true;
    }
    let black = estimate::black_floor(area, &b_true);
    gathers.fixed = (0..np)
        .filter(|&i| !in_todo[i] && b_true[i] > black)
        .map(|i| err[i] / b_true[i])
        .sum();
    gathers.count = b_true.iter().filter(|&&r| r > black).count();
    blacken(&mut gathers.model, black);
    est
}

/// The patches at or below the `black` floor ([`estimate::black_floor`]) count as black in
/// the error models too: no relative error.
fn blacken(model: &mut [PatchModel], black: f64) {
    for m in model.iter_mut().filter(|m| m.b_true <= black) {
        m.b_true = 0.0;
    }
}

/// Two independent gathers of one patch, of `n1` and `n2` rays, pooled by their rays: the
/// mean of all n1 + n2, and the variance of that mean.
fn pooled(g1: &Gathered, n1: usize, g2: &Gathered, n2: usize) -> Gathered {
    let (a, b) = (n1 as f64, n2 as f64);
    let (w1, w2) = (a / (a + b), b / (a + b));
    Gathered {
        h: w1 * g1.h + w2 * g2.h,
        ch: g1
            .ch
            .iter()
            .zip(&g2.ch)
            .map(|(&x, &y)| w1 * x + w2 * y)
            .collect(),
        var: w1 * w1 * g1.var + w2 * w2 * g2.var,
        rays: g1.rays + g2.rays,
        reflected: w1 * g1.reflected + w2 * g2.reflected,
        vis: Default::default(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gathered(h: f64, var: f64, rays: u64) -> Gathered {
        Gathered {
            h: Rgb::splat(h),
            ch: vec![Rgb::splat(h)],
            var,
            rays,
            reflected: Rgb::splat(h),
            vis: Default::default(),
        }
    }

    #[test]
    fn pooling_weighs_by_rays_and_the_variance_falls_with_them() {
        let p = pooled(
            &gathered(1.0, 0.04, 300),
            256,
            &gathered(4.0, 0.01, 900),
            768,
        );
        assert!((p.h[0] - (0.25 * 1.0 + 0.75 * 4.0)).abs() < 1e-12);
        assert!((p.ch[0][2] - p.h[2]).abs() < 1e-12);
        // The same per-ray variance (0.04·256 = (0.04/3)·768): the pooled mean has it over 1,024.
        let q = pooled(
            &gathered(1.0, 0.04, 1),
            256,
            &gathered(1.0, 0.04 / 3.0, 1),
            768,
        );
        assert!((q.var - 0.04 * 256.0 / 1024.0).abs() < 1e-12, "{}", q.var);
        assert_eq!(p.rays, 1200);
    }

    /// Two patches gathered with 256 rays each, one with ten times the other's relative error:
    /// the plan reaches the goal by its own model, gives the noisy one more rays, and asks
    /// nothing of a goal already met.
    #[test]
    fn a_round_goes_where_the_error_is_and_reaches_its_goal() {
        let model = |rel: f64| PatchModel {
            var_s: f64::INFINITY,
            var_g: (rel * 10.0f64).powi(2) / std::f64::consts::FRAC_2_PI,
            biased: false,
            missing: 0.0,
            b_true: 10.0,
        };
        let g = Gathers {
            todo: vec![0, 2],
            got: vec![gathered(1.0, 0.0, 512), gathered(1.0, 0.0, 512)],
            asked: vec![256, 256],
            model: vec![model(0.01), model(0.1)],
            fixed: 0.0,
            count: 2,
            rounds: 0,
            seconds: 0.0,
            sight_rays: 0,
            sight: None,
            first_rays: 256,
            pilot: None,
        };
        let now = (g.model[0].relative(1.0) + g.model[1].relative(1.0)) / 2.0;
        assert!((now - 0.055).abs() < 1e-9, "{now}");
        let plan = g.plan(3, 0.03, 65_536).expect("reachable");
        assert!(plan.predicted <= 0.03 + 1e-12, "{}", plan.predicted);
        assert!(plan.extra[2] > plan.extra[0], "{:?}", plan.extra);
        assert_eq!(plan.extra[1], 0);
        assert_eq!(
            plan.asked,
            plan.extra.iter().map(|&x| x as u64).sum::<u64>()
        );
        // Two rays cast per ray asked so far.
        assert!((plan.rays - 2.0 * plan.asked as f64).abs() < 1e-6);
        // Met already: nothing to add.
        let none = g.plan(3, 0.06, 65_536).expect("met");
        assert_eq!(none.asked, 0);
        // Unreachable within the cap: no plan.
        assert!(g.plan(3, 1e-6, 1024).is_none());
    }
}
