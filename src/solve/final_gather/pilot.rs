//! The first round of an error target's gather, sized by a pilot (docs/design.md §8).
//!
//! A uniform first gather of a fixed size lands wherever the model puts it: on the generated
//! 1 M-patch building, 128 rays a patch gave an estimate of 3.34 % for a 5 % target, so a
//! third of the solve's rays bought precision nobody asked for; on a model whose gather is
//! noisier the same size misses and a round follows. The gather's noise per ray is what
//! differs between models, and it can be measured before the rays are spent.
//!
//! **The pilot** gathers a sample of the patches first: every k-th run of
//! [`super::LEARNING_RUN`] neighbouring patches in space order (whole runs, so its patches
//! learn which lamps they see as every patch's run does), about [`PILOT_RUNS`] runs, never more
//! than half the patches. Each pilot patch's error model ([`super::PatchModel`]: the
//! shooting's variance, the gather's, the light still owed) then predicts its relative error
//! at any number of rays, and the pilot's patches stand for the others: with n rays on every
//! patch the estimate (the mean relative error, Sec. 3's metric) is predicted as
//!
//! (Σ_fixed + Σ_pilot e_k(n) + (T − P)/P · Σ_pilot e_k(n)) / count,
//!
//! Σ_fixed the patches not gathered (their shooting errors as they stand), T and P the
//! patches gathered and in the pilot. The first round casts the fewest rays per patch whose
//! prediction meets the goal, between [`MIN_RAYS`] and the settings' rays per patch; the pilot's
//! patches are topped up to it with independent random numbers ([`Stream::TopUp`]) and pooled.
//! The choice depends on the model and the seed only, not on the threads.

use super::{
    blacken, first_round, gather_runs, owed_per_reflected, pooled, weigh, GatherInputs, Gathered,
    Gathers, PatchModel, Solution, LEARNING_RUN,
};
use crate::intersect::Intersector;
use crate::light::Kernel;
use crate::mesh::spatial::space_order;
use crate::random::Stream;
use crate::solve::estimate;
use crate::solve::scalar;

/// A first round sized to land the estimate at `goal` ([`super::GatherInputs::pilot`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pilot {
    /// The estimate to land at (average weighted percent error, a fraction: 0.045 = 4.5 %).
    pub goal: f64,
    /// Rays per patch of the pilot's own gathers.
    pub rays: usize,
}

/// What the pilot found (`summary.json`: `final_gather.pilot`).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PilotSizing {
    /// Patches the pilot gathered, and with how many rays each.
    pub patches: u64,
    pub pilot_rays: u64,
    /// Rays per patch it chose for the first round.
    pub rays_per_patch: u64,
    /// The estimate it predicted for them, and the goal it sized them for.
    pub predicted: f64,
    pub goal: f64,
}

/// About this many runs of neighbouring patches make the pilot.
pub const PILOT_RUNS: usize = 64;

/// The fewest rays per patch a first round sized by the pilot casts.
pub const MIN_RAYS: usize = 16;

/// The first round: a pilot on a sample of `todo`, then every patch at the rays per patch the
/// pilot predicts to meet `pilot.goal` (module notes), at most `inp.rays`.
pub(super) fn sized_round<I: Intersector>(
    kernel: &Kernel<'_, I>,
    inp: &GatherInputs<'_, I>,
    todo: Vec<usize>,
    sol: &Solution,
    pilot: Pilot,
) -> Gathers {
    let max_rays = inp.rays.max(4);
    let n_p = pilot.rays.clamp(4, max_rays);
    let in_pilot = pilot_patches(kernel.mesh, &todo);
    let sample: Vec<usize> = (todo.iter().zip(&in_pilot))
        .filter(|(_, &p)| p)
        .map(|(&i, _)| i)
        .collect();
    if sample.is_empty() {
        return first_round(kernel, inp.seed, todo, max_rays);
    }
    let first: Vec<Gathered> = gather_runs(kernel, inp.seed, &sample, |_| n_p, Stream::Gather)
        .into_iter()
        .map(|g| g.expect("every pilot patch asks rays"))
        .collect();
    let pilot_of = (&sample[..], &first[..], n_p);
    let (n, predicted) = choose_rays(kernel, inp, sol, &todo, pilot_of, (pilot.goal, max_rays));
    // The rest at n, the pilot's patches topped up to n.
    let rest = gather_runs(
        kernel,
        inp.seed,
        &todo,
        |k| if in_pilot[k] { 0 } else { n },
        Stream::Gather,
    );
    let top = n.saturating_sub(n_p);
    let topped = gather_runs(kernel, inp.seed, &sample, |_| top, Stream::TopUp);
    let mut got = Vec::with_capacity(todo.len());
    let mut asked = Vec::with_capacity(todo.len());
    let mut pilot_got = first.into_iter().zip(topped);
    for (g, &p) in rest.into_iter().zip(&in_pilot) {
        if p {
            let (g1, g2) = pilot_got.next().expect("one per pilot patch");
            got.push(match g2 {
                Some(g2) => pooled(&g1, n_p, &g2, top),
                None => g1,
            });
            asked.push(n_p.max(n));
        } else {
            got.push(g.expect("every patch but the pilot's asks rays"));
            asked.push(n);
        }
    }
    Gathers {
        pilot: Some(PilotSizing {
            patches: sample.len() as u64,
            pilot_rays: n_p as u64,
            rays_per_patch: n as u64,
            predicted,
            goal: pilot.goal,
        }),
        todo,
        got,
        asked,
        first_rays: n,
        ..Gathers::default()
    }
}

/// Which of `todo` the pilot gathers: whole runs of [`LEARNING_RUN`] patches in space order,
/// every k-th one, k such that about [`PILOT_RUNS`] runs are taken and at least 2.
fn pilot_patches(mesh: &crate::mesh::Mesh, todo: &[usize]) -> Vec<bool> {
    let order = space_order(mesh, todo);
    let runs = order.len().div_ceil(LEARNING_RUN);
    let stride = (runs / PILOT_RUNS).max(2);
    let mut in_pilot = vec![false; todo.len()];
    for (at, &k) in order.iter().enumerate() {
        in_pilot[k as usize] = (at / LEARNING_RUN) % stride == stride / 2;
    }
    in_pilot
}

/// The fewest rays per patch in `[MIN_RAYS, max_rays]` whose predicted estimate (module notes)
/// meets `goal`, and that prediction; `max_rays` when none does.
fn choose_rays<I: Intersector>(
    kernel: &Kernel<'_, I>,
    inp: &GatherInputs<'_, I>,
    sol: &Solution,
    todo: &[usize],
    (sample, first, n_p): (&[usize], &[Gathered], usize),
    (goal, max_rays): (f64, usize),
) -> (usize, f64) {
    let mesh = kernel.mesh;
    let light = (&kernel.sol.e[..], &kernel.sol.rho[..]);
    let areas: Vec<f64> = mesh.patches.iter().map(|p| p.area).collect();
    let area = |i: usize| areas[i];
    let owed = owed_per_reflected(
        inp.shooting,
        light.1,
        area,
        sample.iter().copied().zip(first),
    );
    let mut model: Vec<PatchModel> = (sample.iter().zip(first))
        .map(|(&i, g)| weigh(inp.shooting, &sol.b, light, (area(i), owed), (i, g)).model)
        .collect();
    // The patches not gathered keep the shooting's error; the black floor is the shooting's.
    let parts = &inp.shooting.parts;
    let b_true: Vec<f64> = (sol.b.iter().zip(&parts.missing))
        .map(|(b, m)| scalar(b) + m)
        .collect();
    let black = estimate::black_floor(&areas, &b_true);
    blacken(&mut model, black);
    let mut in_todo = vec![false; mesh.patches.len()];
    for &i in todo {
        in_todo[i] = true;
    }
    let (mut fixed, mut count) = (0.0, 0.0);
    for i in (0..mesh.patches.len()).filter(|&i| !in_todo[i]) {
        let b_true = b_true[i];
        if b_true > black {
            fixed += estimate::combine(parts.missing[i], parts.sigma[i]) / b_true;
            count += 1.0;
        }
    }
    let (t, p) = (todo.len() as f64, sample.len() as f64);
    let lit = model.iter().filter(|m| m.b_true > 0.0).count() as f64;
    count += t * lit / p;
    let predict = |n: usize| -> f64 {
        let at = |rays: usize| rays as f64 / n_p as f64;
        let (own, rest) = model.iter().fold((0.0, 0.0), |(own, rest), m| {
            (own + m.relative(at(n.max(n_p))), rest + m.relative(at(n)))
        });
        (fixed + own + (t - p) / p * rest) / count.max(1.0)
    };
    let (mut lo, mut hi) = (MIN_RAYS.min(max_rays), max_rays);
    if predict(hi) > goal {
        return (hi, predict(hi));
    }
    // The prediction falls with the rays: the smallest n that meets the goal, by bisection.
    while lo < hi {
        let mid = lo + (hi - lo) / 2;
        if predict(mid) <= goal {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    (hi, predict(hi))
}
