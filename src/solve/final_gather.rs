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
//! SIGGRAPH 1993: the radiosity solution used as the indirect source of a per-point gather):
//!
//! - **Direct light** by sampling the emitters explicitly: an emitting patch j drawn in
//!   proportion to its power E_j·A_j (a CDF over the emitting patches, stratified), a point y
//!   uniform on it, a shadow ray from the point x on patch i. The ray must reach j's emitting
//!   side (a one-sided emitter emits from its front only; a back twin from the back of its
//!   surface, `Mesh::receiver`) with nothing before it; the sample is
//!   E_j·cosθ_i·cosθ_j/(π r²) / p(y), p(y) = (E_j·A_j / Σ E·A) / A_j.
//! - **Indirect light** by cosine-weighted rays (the stratified polar grid of Sec. 2, turned
//!   by a random angle) returning the solved B_k − E_k of the *side* they meet
//!   (`Mesh::receiver(hit, back)`; the back of a one-sided patch, or the void, gives 0). With
//!   cosine-weighted directions the irradiance is the plain mean of what the rays return.
//! - The two are combined by multiple importance sampling (the balance heuristic, Veach &
//!   Guibas 1995): a hemisphere ray that meets an emitter's emitting side also counts its E at
//!   its MIS weight, and a light sample counts at its own, so a patch beside a big emitter
//!   (where 1/r² makes light samples heavy-tailed) takes that light from its hemisphere rays.
//! - Points on patch i are stratified (Latin hypercube over an area-preserving map of the unit
//!   square, `PatchPoints::at`), paired with the cells or emitter draws in random order.
//! - **Near hits** ([`NEAR`], [`NEAR_DEPTH`]): a hemisphere ray that meets a side closer than
//!   that side's size does not take its B (constant over the patch: right seen from afar,
//!   wrong from beside it — the 0.5 m wall patch behind a shelf 5 cm in front of it is lit on
//!   its exposed part and dark behind the shelf). It takes the light at the point it met, from
//!   one light sample and one cosine ray there, followed the same way through the gap
//!   (`Ctx::reflected_at`).
//! - B_i^gather = E_i + ρ_i·H_i (RGB, f64), with the scalar sample variance of the mean.
//!
//! **Which patches**: every patch that reflects (ρ > 0), but dark sides (below). Gathering only
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
//! the receiver sent it) and the gather's is kept alone (`GatherStats::rejected`). The gather's variance is its sample variance. The
//! shooting's is its Poisson model Var(G_i) = ρ_i·C_eff·E(G_i), with E(G_i) taken as the mean of
//! the two estimates (not the shooting's own count, which is 0 exactly where the shooting is
//! worst, and would give a black patch infinite weight), and C_eff the patch's energy per
//! sample from the books (C for rays; more for hemi-cube cells, `super::estimate`). The
//! combined σ = 1/√(w_s + w_g) replaces the shooting's in the error estimate.
//!
//! **The books stay the shooting's.** The gather casts rays but moves no energy: emitted =
//! absorbed + absorbed on back faces + escaped + unshot is the shooting's account, to 1e-9. It
//! re-estimates the per-patch B that is written out (and the per-light channels, gathered
//! alike: a direct sample goes to its emitter's channel, an indirect ray returns each channel's
//! B − E, and one weight per patch combines them, so they still sum to `b`).
//!
//! **Reproducible**: each patch's random numbers come from (seed, [`GATHER_STREAM`], patch),
//! patches are gathered in parallel and written back in patch order, so the result does not
//! depend on the thread count.

use super::estimate::{self, Parts};
use super::ray_shots::PatchPoints;
use super::{rng_for, scalar, LightChannel, Solution, TracePoint};
use crate::intersect::{Intersector, Ray};
use crate::mesh::Mesh;
use crate::sample::{polar::PolarGrid, Frame};
use crate::scene::Material;
use crate::sky::{Sky, Sun};
use glam::Vec3;
use rand::seq::SliceRandom;
use rand::Rng;
use rayon::prelude::*;
use std::borrow::Cow;
use std::sync::OnceLock;
use std::time::Instant;

/// The "shot number" the gather's random numbers are drawn under (never a real shot's).
pub const GATHER_STREAM: u64 = u64::MAX - 1;
/// The stream of the sensors' gathers.
pub const SENSOR_STREAM: u64 = u64::MAX - 3;
/// Re-gather round k draws under stream `GATHER_STREAM − k·REGATHER_STREAMS` (far from every
/// other stream: shots count up from 0, the sensors' and pictures' are `u64::MAX − 3, − 4`).
const REGATHER_STREAMS: u64 = 1 << 32;

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
}

/// Everything the gather reads, shared by all threads.
struct Ctx<'a, I> {
    mesh: &'a Mesh,
    isect: &'a I,
    /// Emitted radiosity and reflectance per patch: borrowed by the solver's gather, owned by a
    /// [`PointGather`] (which derives them from the materials itself).
    e: Cow<'a, [[f64; 3]]>,
    rho: Cow<'a, [[f64; 3]]>,
    /// The shooting's radiosity, and per light channel.
    b: &'a [[f64; 3]],
    channels: &'a [LightChannel],
    /// Light group per patch (`u32::MAX` for none), when there are channels.
    group: Option<&'a [u32]>,
    /// Emitting patches, the CDF of their scalar power, their points, and the total power.
    emitters: Vec<usize>,
    cdf: Vec<f64>,
    emitter_points: Vec<PatchPoints>,
    power: f64,
    eps_floor: f32,
    seed: u64,
    rays: usize,
    /// The sky that lights the model from outside (issue 14): rays that leave see it, and its
    /// sun is sampled like a light.
    sky: Option<&'a Sky>,
    /// Straight-through transmittance per patch and channel T_c (glazing, tinted or grey:
    /// docs/design.md §9); empty when nothing transmits.
    trans: Vec<[f64; 3]>,
    /// The sky's and the sun's per-light channels, when kept.
    sky_channel: Option<usize>,
    sun_channel: Option<usize>,
    /// Weights of the sky's and the sun's light (1; a relit picture's, [`Relit`]).
    sky_weight: f64,
    sun_weight: f64,
}

/// A hemisphere ray meeting a side closer than this many times the side's size (√A) takes the
/// light at the point it met, not the side's B (`Ctx::reflected_at`): a constant B over a
/// patch is what the patch sends afar, not what its own parts send to something beside them.
pub const NEAR: f32 = 1.0;

/// Near hits followed one after another before the solution's B is taken as it is.
pub const NEAR_DEPTH: u32 = 3;

/// A shooting estimate this many combined σ from the gather's is biased, not noisy: kept out.
pub const BIAS_Z: f64 = 4.0;

/// Adds `w`·`v` to channel `c` of `ch`, when there is one.
fn add_to(ch: &mut [[f64; 3]], c: Option<usize>, v: [f64; 3], w: f64) {
    add_to3(ch, c, v, [w; 3]);
}

/// Adds `w`·`v` per colour to channel `c` of `ch`, when there is one (`w`: a weight per colour,
/// as tinted glazing's transmittance).
fn add_to3(ch: &mut [[f64; 3]], c: Option<usize>, v: [f64; 3], w: [f64; 3]) {
    if let Some(x) = c.and_then(|c| ch.get_mut(c)) {
        for q in 0..3 {
            x[q] += w[q] * v[q];
        }
    }
}

/// What a ray met ([`Ctx::cast`]): the first opaque hit, the transmittance per channel of the
/// glazing before it (the product of its panes' T_c), and what the panes' sides it met
/// reflect towards it.
struct Traced {
    hit: Option<crate::intersect::Hit>,
    through: [f64; 3],
    panes: [f64; 3],
}

/// The "patch" a sensor's rays leave: none (a point in the air).
pub const NO_PATCH: usize = usize::MAX;

/// Surfaces a gather ray may step past (its own, glazing) before it is taken as lost.
const MAX_STEPS: usize = 16;

/// What a side reflects towards one hemisphere ray (RGB, per channel) and the rays it cost.
#[derive(Default)]
struct Reflected {
    v: [f64; 3],
    ch: Vec<[f64; 3]>,
    rays: u64,
}

/// The solution a gather reads.
struct Inputs<'a> {
    e: Cow<'a, [[f64; 3]]>,
    rho: Cow<'a, [[f64; 3]]>,
    b: &'a [[f64; 3]],
    channels: &'a [LightChannel],
    group: Option<&'a [u32]>,
}

impl<'a, I: Intersector> Ctx<'a, I> {
    fn new(
        mesh: &'a Mesh,
        materials: &[Material],
        isect: &'a I,
        inputs: Inputs<'a>,
        seed: u64,
        rays: usize,
        sky: Option<&'a Sky>,
    ) -> Self {
        // Emitters by scalar power; a back twin emits from the back of its surface.
        let (mut emitters, mut cdf, mut power) = (Vec::new(), Vec::new(), 0.0);
        for (i, p) in mesh.patches.iter().enumerate() {
            let w = scalar(&inputs.e[i]) * p.area;
            if w > 0.0 {
                power += w;
                emitters.push(i);
                cdf.push(power);
            }
        }
        let reach = mesh
            .vertices
            .iter()
            .fold(0.0f32, |m, v| m.max(v.abs().max_element()));
        let t = |p: &crate::mesh::Patch| materials[p.material as usize].transmittance_rgb();
        let channel = |name: &str| inputs.channels.iter().position(|c| c.name == name);
        Ctx {
            mesh,
            isect,
            emitter_points: emitters
                .iter()
                .map(|&j| PatchPoints::new(mesh, j))
                .collect(),
            e: inputs.e,
            rho: inputs.rho,
            b: inputs.b,
            channels: inputs.channels,
            group: inputs.group,
            emitters,
            cdf,
            power,
            eps_floor: reach * 5e-7,
            seed,
            rays: rays.max(4),
            sky,
            trans: if materials.iter().any(|m| m.transmittance > 0.0) {
                mesh.patches.iter().map(t).collect()
            } else {
                Vec::new()
            },
            sky_channel: channel(super::lights::SKY_CHANNEL),
            sun_channel: channel(super::lights::SUN_CHANNEL),
            sky_weight: 1.0,
            sun_weight: 1.0,
        }
    }
}

/// Irradiance (RGB, W/m²) at sensors (point, facing direction) from the solved radiosity `b`
/// (issue 14's grid): each sensor gathers as a patch does (`Ctx::gather_at`: light samples of
/// the emitters and the sun, hemisphere rays that see the solution, the sky and through
/// glazing, near hits followed), `rays` rays each; reproducible for `seed`.
#[allow(clippy::too_many_arguments)]
pub fn sensor_irradiance<I: Intersector>(
    mesh: &Mesh,
    materials: &[Material],
    isect: &I,
    b: &[[f64; 3]],
    sky: Option<&Sky>,
    sensors: &[(Vec3, Vec3)],
    rays: usize,
    seed: u64,
) -> Vec<[f64; 3]> {
    let (e, rho) = emission_and_reflectance(mesh, materials);
    let inputs = Inputs {
        e: Cow::Owned(e),
        rho: Cow::Owned(rho),
        b,
        channels: &[],
        group: None,
    };
    let ctx = Ctx::new(mesh, materials, isect, inputs, seed, rays, sky);
    sensors
        .par_iter()
        .enumerate()
        .map(|(k, &(x, n))| {
            let mut rng = rng_for(seed, SENSOR_STREAM, k as u64);
            let n = n.normalize_or_zero();
            let at = |_: f32, _: f32| x;
            ctx.gather_at(
                NO_PATCH,
                &at,
                n,
                ctx.eps_floor,
                [1.0; 3],
                ctx.rays,
                true,
                LightParts::All,
                &mut rng,
            )
            .h
        })
        .collect()
}

/// One patch's gather: irradiance H (RGB), per channel, the scalar variance of ρ·H's mean.
#[derive(Clone, Debug)]
struct Gathered {
    h: [f64; 3],
    ch: Vec<[f64; 3]>,
    var: f64,
    rays: u64,
}

/// The variance of the mean of stratified samples, by collapsing neighbouring strata in
/// pairs (Cochran, *Sampling Techniques*, 3rd ed., 1977, Sec. 5A.12; Wolter, *Introduction to
/// Variance Estimation*, 2nd ed., 2007, Sec. 8.2, the successive-difference estimator): samples
/// `2m` and `2m + 1` come from neighbouring strata (adjacent polar cells of one ring; adjacent
/// draws along the emitters' CDF), so Var(mean) ≈ Σ_m (x_2m − x_2m+1)² / N². The sample
/// variance of independent draws would ignore what stratification removes and overstate the
/// gather's noise several times over.
fn stratified_var(x: &[f64]) -> f64 {
    let n = x.len();
    if n < 2 {
        return 0.0;
    }
    let sum: f64 = x.chunks_exact(2).map(|p| (p[0] - p[1]).powi(2)).sum();
    // An odd last sample counts as a pair's worth of the others.
    let pairs = n / 2;
    sum * (n as f64 / (2 * pairs) as f64) / (n * n) as f64
}

/// Latin-hypercube points on the unit square: both coordinates stratified into `n` strata,
/// each coordinate's strata in an independent random order — or, with `ordered`, the first
/// coordinate's strata in index order (sample k in stratum k, for the collapsed-pair variance).
/// Two sets zipped together must not both be ordered: their first coordinates would be
/// perfectly correlated (points on one part of the patch always paired with one light).
fn latin<R: Rng>(n: usize, ordered: bool, rng: &mut R) -> Vec<(f32, f32)> {
    let mut pu: Vec<usize> = (0..n).collect();
    let mut pv = pu.clone();
    if !ordered {
        pu.shuffle(rng);
    }
    pv.shuffle(rng);
    pu.iter()
        .zip(&pv)
        .map(|(&a, &b)| {
            let u = (a as f32 + rng.gen::<f32>()) / n as f32;
            let v = (b as f32 + rng.gen::<f32>()) / n as f32;
            (u.min(1.0), v.min(1.0))
        })
        .collect()
}

impl<I: Intersector> Ctx<'_, I> {
    /// The closest opaque hit along `ray`, stepping past patch `i`'s own surface (a ray leaving
    /// a planar patch cannot meet it again; rounding may say otherwise).
    ///
    /// Glazing (issue 14) is seen and seen through: each pane met adds what its side reflects
    /// (B − E, times the transmittance of the panes before it) and passes on its transmittance
    /// T_c per channel (tinted glazing's colour: docs/design.md §9); the ray goes on to the
    /// first opaque surface.
    fn cast(&self, i: usize, mut ray: Ray, eps: f32) -> Traced {
        let own = (i != NO_PATCH).then(|| self.mesh.surface_of(i));
        let mut out = Traced {
            hit: None,
            through: [1.0; 3],
            panes: [0.0; 3],
        };
        for _ in 0..MAX_STEPS {
            match self.isect.intersect(&ray) {
                Some(h) if Some(h.patch as usize) == own => ray.tnear = h.t + eps,
                Some(h)
                    if self
                        .trans
                        .get(h.patch as usize)
                        .is_some_and(|t| t.iter().any(|c| *c > 0.0)) =>
                {
                    if let Some(r) = self.mesh.receiver(h.patch, h.back) {
                        let r = r as usize;
                        for q in 0..3 {
                            out.panes[q] += out.through[q] * (self.b[r][q] - self.e[r][q]).max(0.0);
                        }
                    }
                    let t = self.trans[h.patch as usize];
                    for (x, t) in out.through.iter_mut().zip(t) {
                        *x *= t;
                    }
                    ray.tnear = h.t + (h.t * 1e-5).max(self.eps_floor);
                }
                other => {
                    out.hit = other;
                    return out;
                }
            }
        }
        // Lost among surfaces: nothing seen beyond.
        out.through = [0.0; 3];
        out
    }

    /// Patch `i`'s gather of `rays` rays; `round` 0 is the first, later rounds
    /// ([`Gathers::plan`]) draw independent random numbers to be pooled with it.
    fn gather(&self, i: usize, rays: usize, round: u64) -> Gathered {
        let patch = &self.mesh.patches[i];
        let eps = (1e-4 * (patch.area as f32).sqrt()).max(self.eps_floor);
        let points = PatchPoints::new(self.mesh, i);
        let stream = GATHER_STREAM.wrapping_sub(REGATHER_STREAMS * round);
        let mut rng = rng_for(self.seed, stream, i as u64);
        let at = |u: f32, v: f32| points.at(u, v);
        self.gather_at(
            i,
            &at,
            patch.normal,
            eps,
            self.rho[i],
            rays,
            true,
            LightParts::All,
            &mut rng,
        )
    }

    /// The gather at the points `at(u, v)` of the unit square's map (a patch's, or one
    /// sensor's point) facing `n`, rays leaving patch `i`'s surface ([`NO_PATCH`] for a
    /// sensor in the air); `rho` weighs the channels of the variance; `rays` in all (half to
    /// the emitters, a quarter to the sun when there is one, the rest over the hemisphere).
    /// `lights` false sends the emitters' half over the hemisphere too: for points no emitter
    /// faces, which a hemisphere ray then cannot meet on its emitting side either.
    #[allow(clippy::too_many_arguments)]
    fn gather_at<R: Rng>(
        &self,
        i: usize,
        at: &dyn Fn(f32, f32) -> Vec3,
        n: Vec3,
        eps: f32,
        rho: [f64; 3],
        rays_wanted: usize,
        lights: bool,
        parts: LightParts,
        rng: &mut R,
    ) -> Gathered {
        let mesh = self.mesh;
        let k = self.channels.len();
        let mut h = [0.0f64; 3];
        let mut ch = vec![[0.0f64; 3]; k];
        let mut var = 0.0;
        let mut rays = 0u64;
        // Half the rays to the emitters (when there are any), half over the hemisphere.
        let lamps = !self.emitters.is_empty() && lights;
        let sun = self.sky.and_then(Sky::sun);
        let (n_direct, n_sun) = match (parts, lamps, sun.is_some()) {
            (LightParts::Indirect, _, _) => (0, 0),
            (LightParts::All, l, s) => (
                if l { (rays_wanted / 2).max(1) } else { 0 },
                if s { (rays_wanted / 4).max(1) } else { 0 },
            ),
            // All the rays to the lights: two thirds to the emitters when there is a sun too.
            (LightParts::Direct, true, true) => {
                let d = (rays_wanted * 2 / 3).max(1);
                (d, rays_wanted.saturating_sub(d).max(1))
            }
            (LightParts::Direct, true, false) => (rays_wanted.max(1), 0),
            (LightParts::Direct, false, true) => (0, rays_wanted.max(1)),
            (LightParts::Direct, false, false) => (0, 0),
        };
        let grid =
            PolarGrid::for_samples(rays_wanted.saturating_sub(n_direct + n_sun).max(2) as f64);
        // The MIS weights (balance heuristic, by the counts of light and hemisphere samples).
        // Split in two parts gathered apart, both weigh as if by equal counts (the split of
        // `All` without a sun), so that the two weights of a path still add up to one: the
        // light samples of `Direct` and the hemisphere rays of `Indirect` share each
        // emitter's light, neither taking it all (light samples alone are unbounded beside an
        // emitter, at a room's corner).
        let (nl, nc) = match parts {
            LightParts::All => (n_direct as f64, grid.len() as f64),
            LightParts::Direct | LightParts::Indirect => (if lamps { 1.0 } else { 0.0 }, 1.0),
        };

        // Direct: emitters by power, points on them uniform, shadow rays.
        if n_direct > 0 {
            let mut m = Vec::with_capacity(n_direct);
            let mut sum = [0.0f64; 3];
            let here = latin(n_direct, false, rng);
            let there = latin(n_direct, true, rng);
            for (&(u, v), &(s, t)) in here.iter().zip(&there) {
                let x = at(u, v) + n * eps;
                // Stratified choice of the emitter, then a point on it from the rest of `s`.
                let (e, w, s2) = self.pick_emitter(f64::from(s));
                let j = self.emitters[e];
                let y = self.emitter_points[e].at(s2, t);
                let shadow = self.direct(i, j, x, y, n, eps);
                rays += u64::from(shadow.is_some());
                let (c, mis) = shadow.map_or(([0.0; 3], 0.0), |sh| {
                    let mis = self.light_weight(j, sh.cos_i, sh.cos_j, sh.dist, nl, nc);
                    (sh.e_g, mis)
                });
                // ÷ pdf(y) = (E_j·A_j / Σ E·A) / A_j, × the light sample's MIS weight.
                let scale = self.power * mesh.patches[j].area / w * mis;
                let val = [0, 1, 2].map(|q| c[q] * scale);
                m.push(scalar(&[0, 1, 2].map(|q| rho[q] * val[q])));
                for q in 0..3 {
                    sum[q] += val[q];
                }
                if let Some(g) = self.group {
                    let gj = g[j] as usize;
                    if gj < k {
                        for q in 0..3 {
                            ch[gj][q] += val[q] / n_direct as f64;
                        }
                    }
                }
            }
            for q in 0..3 {
                h[q] += sum[q] / n_direct as f64;
            }
            var += stratified_var(&m);
        }

        // The sun: directions over its disc, shadow rays to the sky.
        if let Some(sun) = sun.filter(|_| n_sun > 0) {
            let (mut m, mut sum) = (Vec::with_capacity(n_sun), [0.0f64; 3]);
            let here = latin(n_sun, false, rng);
            let there = latin(n_sun, true, rng);
            for (&(u, v), &(s, t)) in here.iter().zip(&there) {
                let x = at(u, v) + n * eps;
                let val = self.sun_sample(i, sun, x, n, eps, f64::from(s), f64::from(t));
                rays += 1;
                m.push(scalar(&[0, 1, 2].map(|q| rho[q] * val[q])));
                for q in 0..3 {
                    sum[q] += val[q];
                }
                add_to(&mut ch, self.sun_channel, val, 1.0 / n_sun as f64);
            }
            for q in 0..3 {
                h[q] += sum[q] / n_sun as f64;
            }
            var += stratified_var(&m);
        }

        if parts == LightParts::Direct {
            return Gathered { h, ch, var, rays };
        }
        // Indirect: cosine-weighted rays through the polar cells, B − E of the side met.
        let x_count = grid.len();
        let angle = rng.gen::<f32>() * std::f32::consts::TAU;
        let frame = Frame::new(n, angle);
        let here = latin(x_count, false, rng);
        let mut m = Vec::with_capacity(x_count);
        let mut sum = [0.0f64; 3];
        for (cell, &(u, v)) in here.iter().enumerate() {
            let dir = frame.to_world(grid.direction(cell, 0.0, true, rng));
            let org = at(u, v) + n * eps;
            let ray = Ray {
                org,
                dir,
                tnear: 0.0,
                tfar: f32::INFINITY,
            };
            rays += 1;
            let seen = self.cast(i, ray, eps);
            let hit = seen.hit;
            let recv = hit.and_then(|h| Some((mesh.receiver(h.patch, h.back)? as usize, h.t)));
            // What it reflects (the solution's, or followed on when near: `reflected_at`), plus
            // (when there are light samples too) its emission at the hemisphere ray's MIS
            // weight: the light samples count the rest of it.
            let mut emitted = [0.0; 3];
            let mut sub = Reflected::default();
            if let Some((r, t)) = recv {
                if nl > 0.0 && scalar(&self.e[r]) > 0.0 {
                    let cos_r = -f64::from(mesh.patches[r].normal.dot(dir));
                    if cos_r > 0.0 {
                        let w = self.light_weight(
                            r,
                            f64::from(n.dot(dir)),
                            cos_r,
                            f64::from(t),
                            nl,
                            nc,
                        );
                        emitted = self.e[r].map(|e| e * (1.0 - w));
                    }
                }
                sub = self.reflected_at(r, org + dir * t, t, 0, rng);
                rays += sub.rays;
            }
            if hit.is_none() {
                sub.v = self.sky_exitance(dir);
            }
            let val = [0, 1, 2].map(|q| seen.panes[q] + seen.through[q] * (sub.v[q] + emitted[q]));
            m.push(scalar(&[0, 1, 2].map(|q| rho[q] * val[q])));
            for q in 0..3 {
                sum[q] += val[q];
            }
            if let Some((r, _)) = recv {
                for (c, chc) in ch.iter_mut().enumerate() {
                    let own = self.group.is_some_and(|g| g[r] as usize == c);
                    for q in 0..3 {
                        let lit = if own { emitted[q] } else { 0.0 };
                        chc[q] += seen.through[q] * (sub.ch[c][q] + lit) / x_count as f64;
                    }
                }
            } else if hit.is_none() {
                let w = seen.through.map(|t| t / x_count as f64);
                add_to3(&mut ch, self.sky_channel, sub.v, w);
            }
        }
        for q in 0..3 {
            h[q] += sum[q] / x_count as f64;
        }
        var += stratified_var(&m);
        Gathered { h, ch, var, rays }
    }

    /// What a ray leaving the model along `dir` returns: the sky's (or the ground glow's)
    /// radiance as an exitance, π·L (the unit of B that the hemisphere rays average), the sun
    /// left out (sampled on its own).
    fn sky_exitance(&self, dir: Vec3) -> [f64; 3] {
        self.sky.map_or([0.0; 3], |s| {
            s.radiance(dir)
                .map(|l| l * std::f64::consts::PI * self.sky_weight)
        })
    }

    /// One sample of the sun's irradiance at `x` (normal `n`, on patch `i`): the direction
    /// (u, v) of its disc, L_sun·Ω_sun·cos θ where a shadow ray leaves the model, else 0.
    #[allow(clippy::too_many_arguments)]
    fn sun_sample(
        &self,
        i: usize,
        sun: &Sun,
        x: Vec3,
        n: Vec3,
        eps: f32,
        u: f64,
        v: f64,
    ) -> [f64; 3] {
        let dir = sun.sample(u, v).normalize();
        let cos = n.dot(dir);
        if cos <= 0.0 {
            return [0.0; 3];
        }
        let ray = Ray {
            org: x,
            dir,
            tnear: 0.0,
            tfar: f32::INFINITY,
        };
        let seen = self.cast(i, ray, eps);
        if seen.hit.is_some() {
            return [0.0; 3];
        }
        let w = seen
            .through
            .map(|t| t * Sun::solid_angle() * f64::from(cos) * self.sun_weight);
        let l = sun.radiance();
        [0, 1, 2].map(|q| l[q] * w[q])
    }

    /// The emitter (index into `emitters`) that `s` ∈ [0, 1) picks along the power CDF, its
    /// power, and what is left of `s` within its stretch (for a point on it).
    fn pick_emitter(&self, s: f64) -> (usize, f64, f32) {
        let target = s * self.power;
        let e = self
            .cdf
            .partition_point(|&c| c <= target)
            .min(self.cdf.len() - 1);
        let lo = if e == 0 { 0.0 } else { self.cdf[e - 1] };
        let w = (self.cdf[e] - lo).max(f64::MIN_POSITIVE);
        (e, w, (((target - lo) / w) as f32).clamp(0.0, 1.0))
    }

    /// The light side `r` reflects towards a hemisphere ray that met it at `y` from distance
    /// `t` (RGB, and per channel). From afar, the solution's B_r − E_r. From nearer than r's
    /// size (√A_r · [`NEAR`]), where a constant B over r is not what this point sees (the wall
    /// behind a shelf 5 cm in front of it is dark, the 0.5 m wall patch is not), ρ_r times the
    /// irradiance at `y` itself, from one light sample and one cosine-weighted ray, that ray's
    /// hit taken the same way, at most [`NEAR_DEPTH`] times: a path followed through the narrow
    /// gap until it leaves it (the close-hit rule of final gathers, Jensen, *Realistic Image
    /// Synthesis Using Photon Mapping*, 2001, Sec. 9.4.2, with the solution as the cache).
    fn reflected_at<R: Rng>(
        &self,
        r: usize,
        y: Vec3,
        t: f32,
        depth: u32,
        rng: &mut R,
    ) -> Reflected {
        let mesh = self.mesh;
        let k = self.channels.len();
        let area = mesh.patches[r].area as f32;
        let rho = self.rho[r];
        let near = t < NEAR * area.sqrt();
        if depth >= NEAR_DEPTH || !near || scalar(&rho) <= 0.0 {
            let own = |c: usize| self.group.is_some_and(|g| g[r] as usize == c);
            return Reflected {
                v: [0, 1, 2].map(|q| (self.b[r][q] - self.e[r][q]).max(0.0)),
                ch: (0..k)
                    .map(|c| {
                        let e = if own(c) { self.e[r] } else { [0.0; 3] };
                        [0, 1, 2].map(|q| (self.channels[c].b[r][q] - e[q]).max(0.0))
                    })
                    .collect(),
                rays: 0,
            };
        }
        let n = mesh.patches[r].normal;
        let eps = (1e-4 * area.sqrt()).max(self.eps_floor);
        let x = y + n * eps;
        let mut h = [0.0f64; 3];
        let mut ch = vec![[0.0f64; 3]; k];
        let mut rays = 0u64;
        let nl = if self.emitters.is_empty() { 0.0 } else { 1.0 };
        let to_channel = |ch: &mut [[f64; 3]], j: usize, v: [f64; 3]| {
            if let Some(g) = self.group {
                if let Some(c) = ch.get_mut(g[j] as usize) {
                    for q in 0..3 {
                        c[q] += v[q];
                    }
                }
            }
        };
        // One light sample.
        if nl > 0.0 {
            let (e, w, _) = self.pick_emitter(rng.gen());
            let j = self.emitters[e];
            let yj = self.emitter_points[e].at(rng.gen(), rng.gen());
            if let Some(sh) = self.direct(r, j, x, yj, n, eps) {
                rays += 1;
                let mis = self.light_weight(j, sh.cos_i, sh.cos_j, sh.dist, 1.0, 1.0);
                let scale = self.power * mesh.patches[j].area / w * mis;
                let v = sh.e_g.map(|c| c * scale);
                for q in 0..3 {
                    h[q] += v[q];
                }
                to_channel(&mut ch, j, v);
            }
        }
        // One cosine-weighted ray.
        let (u1, u2) = (rng.gen::<f32>(), rng.gen::<f32>());
        let (s, c) = (std::f32::consts::TAU * u2).sin_cos();
        let rr = u1.sqrt();
        let dir =
            Frame::new(n, 0.0).to_world(Vec3::new(rr * c, rr * s, (1.0 - u1).max(0.0).sqrt()));
        let ray = Ray {
            org: x,
            dir,
            tnear: 0.0,
            tfar: f32::INFINITY,
        };
        rays += 1;
        let seen = self.cast(r, ray, eps);
        let (hit, w) = (seen.hit, seen.through);
        let l = if hit.is_none() {
            self.sky_exitance(dir)
        } else {
            [0.0; 3]
        };
        for q in 0..3 {
            h[q] += seen.panes[q] + w[q] * l[q];
        }
        add_to3(&mut ch, self.sky_channel, l, w);
        if let Some(sun) = self.sky.and_then(Sky::sun) {
            rays += 1;
            let l = self.sun_sample(r, sun, x, n, eps, rng.gen(), rng.gen());
            for q in 0..3 {
                h[q] += l[q];
            }
            add_to(&mut ch, self.sun_channel, l, 1.0);
        }
        if let Some((s, t2)) =
            hit.and_then(|h| Some((mesh.receiver(h.patch, h.back)? as usize, h.t)))
        {
            let mut emitted = [0.0; 3];
            if scalar(&self.e[s]) > 0.0 {
                let cos_s = -f64::from(mesh.patches[s].normal.dot(dir));
                if cos_s > 0.0 {
                    let w = if nl > 0.0 {
                        self.light_weight(s, f64::from(n.dot(dir)), cos_s, f64::from(t2), nl, 1.0)
                    } else {
                        0.0
                    };
                    emitted = self.e[s].map(|e| e * (1.0 - w));
                }
            }
            let sub = self.reflected_at(s, x + dir * t2, t2, depth + 1, rng);
            rays += sub.rays;
            for q in 0..3 {
                h[q] += w[q] * (sub.v[q] + emitted[q]);
            }
            for (c, chc) in ch.iter_mut().enumerate() {
                let own = self.group.is_some_and(|g| g[s] as usize == c);
                for q in 0..3 {
                    chc[q] += w[q] * (sub.ch[c][q] + if own { emitted[q] } else { 0.0 });
                }
            }
        }
        Reflected {
            v: [0, 1, 2].map(|q| rho[q] * h[q]),
            ch: ch
                .into_iter()
                .map(|c| [0, 1, 2].map(|q| rho[q] * c[q]))
                .collect(),
            rays,
        }
    }

    /// The irradiance sample (RGB, before dividing by the pdf of the emitter's choice) of a
    /// shadow ray from `x` on patch `i` to `y` on emitter `j`: E_j·cosθ_i·cosθ_j/(π r²), or
    /// `None` when `y` faces away or is not seen (no ray is cast when the geometry says 0).
    fn direct(&self, i: usize, j: usize, x: Vec3, y: Vec3, n: Vec3, eps: f32) -> Option<Shadow> {
        let d = y - x;
        let dist = d.length();
        if dist <= 0.0 || !dist.is_finite() {
            return None;
        }
        let dir = d / dist;
        let cos_i = n.dot(dir);
        let cos_j = -self.mesh.patches[j].normal.dot(dir);
        if cos_i <= 0.0 || cos_j <= 0.0 {
            return None;
        }
        let ray = Ray {
            org: x,
            dir,
            tnear: 0.0,
            tfar: dist * (1.0 + 1e-3) + eps,
        };
        // Seen: the ray meets j's emitting side first, or nothing before j's plane (a ray
        // aimed at j may be given to a neighbouring patch of the same plane at an edge).
        let traced = self.cast(i, ray, eps);
        let seen = match traced.hit {
            None => true,
            Some(h) => {
                self.mesh.receiver(h.patch, h.back) == Some(j as u32) || h.t >= dist * (1.0 - 1e-4)
            }
        };
        let g = if seen {
            traced.through.map(|t| {
                t * f64::from(cos_i) * f64::from(cos_j)
                    / (std::f64::consts::PI * f64::from(dist).powi(2))
            })
        } else {
            [0.0; 3]
        };
        Some(Shadow {
            e_g: [0, 1, 2].map(|q| self.e[j][q] * g[q]),
            cos_i: f64::from(cos_i),
            cos_j: f64::from(cos_j),
            dist: f64::from(dist),
        })
    }

    /// The balance heuristic's weight of a light sample against a hemisphere ray for the same
    /// direction (Veach & Guibas, *Optimally Combining Sampling Techniques for Monte Carlo
    /// Rendering*, SIGGRAPH 1995, Sec. 3): both strategies see an emitter, each counts it with
    /// its share n·p / (n_l·p_l + n_c·p_c), the densities in solid angle. The light sample's
    /// p_l = (E_j / Σ E·A)·r²/cos θ_j, the hemisphere ray's p_c = cos θ_i / π. So a patch beside
    /// a big emitter (where r²/cos θ_j → 0 and light samples blow up) takes that light from its
    /// hemisphere rays, and a small bright lamp far away from its light samples.
    fn light_weight(&self, j: usize, cos_i: f64, cos_j: f64, dist: f64, n_l: f64, n_c: f64) -> f64 {
        let p_l = scalar(&self.e[j]) / self.power * dist * dist / cos_j.max(1e-12);
        let p_c = cos_i.max(0.0) / std::f64::consts::PI;
        let (a, b) = (n_l * p_l, n_c * p_c);
        if a + b > 0.0 {
            a / (a + b)
        } else {
            1.0
        }
    }
}

/// Each patch's emission E and reflectance ρ (RGB), from its material.
fn emission_and_reflectance(mesh: &Mesh, materials: &[Material]) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let mat = |p: &crate::mesh::Patch| &materials[p.material as usize];
    mesh.patches
        .iter()
        .map(|p| (mat(p).emission(), mat(p).rho))
        .unzip()
}

/// Which parts of the light a gather samples (the final-gather renderer gathers the indirect
/// light at a few points of the image and interpolates it: [`PointGather::part_at`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightParts {
    /// Everything: the emitters and the sun by shadow rays, the rest over the hemisphere, the
    /// emitters met by hemisphere rays weighed against the light samples (MIS).
    All,
    /// The shadow rays alone: the emitters (at their MIS weight) and the sun.
    Direct,
    /// The hemisphere rays alone: what they meet, emitters at the complement of the weight
    /// `Direct` gives them. `Direct` + `Indirect` is `All` in expectation.
    Indirect,
}

/// A shadow ray's outcome: E_j·cosθ_i·cosθ_j/(π r²) (0 when not seen) and its geometry.
struct Shadow {
    e_g: [f64; 3],
    cos_i: f64,
    cos_j: f64,
    dist: f64,
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
    /// Rays cast by every round so far.
    pub fn rays(&self) -> u64 {
        self.got.iter().map(|g| g.rays).sum()
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

/// Gathers the patches that need it (see the module notes) and rewrites `sol.b` and
/// `sol.channels` with the combined estimates; records what it did in `sol.stats` and appends a
/// trace point with the error estimate after the gather (and the error against `reference`).
/// With `more`, `sol` must be the shooting result the prior gathers were made on: the patches
/// given extra rays gather them afresh (independent random numbers), pooled with what they
/// had by rays; the others keep theirs. Returns the gathers, for a further round.
#[allow(clippy::too_many_arguments)]
pub fn apply<I: Intersector>(
    mesh: &Mesh,
    materials: &[Material],
    isect: &I,
    seed: u64,
    rays: usize,
    group: Option<&[u32]>,
    shooting: &Shooting,
    sky: Option<&Sky>,
    reference: Option<&[[f64; 3]]>,
    sol: &mut Solution,
    more: Option<Regather>,
    on_trace: &mut impl FnMut(&TracePoint),
) -> Gathers {
    let t0 = Instant::now();
    let np = mesh.patches.len();
    let (e, rho) = emission_and_reflectance(mesh, materials);
    let area: Vec<f64> = mesh.patches.iter().map(|p| p.area).collect();
    let reflected = |b: &[[f64; 3]], i: usize| scalar(&b[i]) - scalar(&e[i]);
    let black = |b: &[[f64; 3]]| {
        (0..np)
            .filter(|&i| scalar(&rho[i]) > 0.0 && reflected(b, i) <= 0.0)
            .count() as u64
    };
    let black_before = black(&sol.b);
    // A side of a two-sided surface that the shooting left dark while its other side is lit
    // faces the void or the inside of an object (docs/design.md §7): nothing to gather there.
    let faces_void = |i: usize| {
        mesh.other_side(i).is_some_and(|o| {
            let other = reflected(&sol.b, o);
            other > 0.0 && reflected(&sol.b, i) <= estimate::DARK_SIDE * other
        })
    };
    let inputs = Inputs {
        e: Cow::Borrowed(&e),
        rho: Cow::Borrowed(&rho),
        b: &sol.b,
        channels: &sol.channels,
        group: group.filter(|_| !sol.channels.is_empty()),
    };
    let ctx = Ctx::new(mesh, materials, isect, inputs, seed, rays, sky);
    let mut gathers = match more {
        Some(Regather { mut prior, extra }) => {
            prior.rounds += 1;
            let round = prior.rounds;
            let fresh: Vec<Option<Gathered>> = prior
                .todo
                .par_iter()
                .map(|&i| (extra[i] > 0).then(|| ctx.gather(i, extra[i], round)))
                .collect();
            for (k, g2) in fresh.into_iter().enumerate() {
                if let Some(g2) = g2 {
                    let i = prior.todo[k];
                    prior.got[k] = pooled(&prior.got[k], prior.asked[k], &g2, extra[i]);
                    prior.asked[k] += extra[i];
                }
            }
            prior
        }
        None => {
            let todo: Vec<usize> = (0..np)
                .filter(|&i| !faces_void(i) && scalar(&rho[i]) > 0.0)
                .collect();
            let n = ctx.rays;
            let got: Vec<Gathered> = todo.par_iter().map(|&i| ctx.gather(i, n, 0)).collect();
            Gathers {
                asked: vec![n; todo.len()],
                todo,
                got,
                ..Gathers::default()
            }
        }
    };

    let mut sigma = shooting.parts.sigma.clone();
    let mut missing = shooting.parts.missing.clone();
    let mut b = sol.b.clone();
    let mut channels = sol.channels.clone();
    let (mut weight_sum, mut rejected) = (0.0, 0u64);
    let mut model = Vec::with_capacity(gathers.todo.len());
    for (&i, g) in gathers.todo.iter().zip(&gathers.got) {
        let x_s = reflected(&sol.b, i).max(0.0);
        let x_g = scalar(&[0, 1, 2].map(|q| rho[i][q] * g.h[q]));
        let mu = 0.5 * (x_s + x_g);
        // The shooting's Poisson variance at the pooled mean: Var(G) = ρ·C_eff·E[G].
        let var_s = if x_s > 0.0 && shooting.parts.sigma[i] > 0.0 {
            shooting.parts.sigma[i].powi(2) * mu / x_s
        } else {
            scalar(&rho[i]) * shooting.energy_per_ray * mu / area[i]
        };
        let floor = 1e-24 * mu * mu + f64::MIN_POSITIVE;
        let (w_s, w_g) = (1.0 / (var_s + floor), 1.0 / (g.var + floor));
        let a = w_s / (w_s + w_g);
        let a = if a.is_finite() { a } else { 0.5 };
        let biased = (x_s - x_g).powi(2) > BIAS_Z * BIAS_Z * (var_s + g.var);
        let a = if biased { 0.0 } else { a };
        rejected += u64::from(biased);
        weight_sum += a;
        if x_s <= 0.0 && x_g <= 0.0 {
            // Neither the shooting nor the gather's rays found light here (a face against a
            // wall, the underside of a box on the floor): the light still owed, which arrives
            // like the indirect light the gather saw none of, is not owed here either.
            missing[i] = 0.0;
        }
        sigma[i] = if biased {
            g.var.sqrt()
        } else {
            (1.0 / (w_s + w_g)).sqrt()
        };

        for q in 0..3 {
            let gb = rho[i][q] * g.h[q];
            b[i][q] = e[i][q] + a * (sol.b[i][q] - e[i][q]) + (1.0 - a) * gb;
        }
        for (c, chan) in channels.iter_mut().enumerate() {
            let own = group.is_some_and(|gr| gr[i] as usize == c);
            for q in 0..3 {
                let ec = if own { e[i][q] } else { 0.0 };
                let gb = rho[i][q] * g.ch[c][q];
                chan.b[i][q] = ec + a * (chan.b[i][q] - ec) + (1.0 - a) * gb;
            }
        }
        model.push(PatchModel {
            var_s,
            var_g: g.var,
            biased,
            missing: missing[i],
            b_true: scalar(&b[i]) + missing[i],
        });
    }
    let seconds = t0.elapsed().as_secs_f64();
    gathers.seconds += seconds;
    let todo_len = gathers.todo.len();
    let stats = GatherStats {
        patches: todo_len as u64,
        rays: gathers.rays(),
        seconds: gathers.seconds,
        black_before,
        black_after: black(&b),
        rejected,
        mean_shooting_weight: if todo_len == 0 {
            1.0
        } else {
            weight_sum / todo_len as f64
        },
    };
    sol.b = b;
    sol.channels = channels;
    sol.stats.seconds += seconds;
    sol.stats.final_gather = Some(stats);

    // The estimate after the gather: owed light as before, the combined σ.
    let err: Vec<f64> = missing
        .iter()
        .zip(&sigma)
        .map(|(m, s)| estimate::combine(*m, *s))
        .collect();
    let b_true: Vec<f64> = sol
        .b
        .iter()
        .zip(&missing)
        .map(|(b, m)| scalar(b) + m)
        .collect();
    let est = estimate::from_errors(&area, err.iter().copied(), &b_true);
    // What the patches not gathered add to the estimate, for a further round's plan.
    let mut in_todo = vec![false; np];
    for &i in &gathers.todo {
        in_todo[i] = true;
    }
    gathers.fixed = (0..np)
        .filter(|&i| !in_todo[i] && b_true[i] > 0.0)
        .map(|i| err[i] / b_true[i])
        .sum();
    gathers.count = b_true.iter().filter(|&&r| r > 0.0).count();
    gathers.model = model;
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
            error: reference.map(|r| estimate::against(&area, &sol.b, r)),
            ..last
        };
        sol.stats.trace.push(p);
        on_trace(&p);
    }
    gathers
}

/// Two independent gathers of one patch, of `n1` and `n2` rays, pooled by their rays: the
/// mean of all n1 + n2, and the variance of that mean.
fn pooled(g1: &Gathered, n1: usize, g2: &Gathered, n2: usize) -> Gathered {
    let (a, b) = (n1 as f64, n2 as f64);
    let (w1, w2) = (a / (a + b), b / (a + b));
    Gathered {
        h: [0, 1, 2].map(|q| w1 * g1.h[q] + w2 * g2.h[q]),
        ch: g1
            .ch
            .iter()
            .zip(&g2.ch)
            .map(|(x, y)| [0, 1, 2].map(|q| w1 * x[q] + w2 * y[q]))
            .collect(),
        var: w1 * w1 * g1.var + w2 * w2 * g2.var,
        rays: g1.rays + g2.rays,
    }
}

/// The final gather at points a camera sees (issue 15, `--shading gather`): the solution as
/// the cache of a per-pixel gather, after Reichert (*A Two-Pass Radiosity Method Driven by
/// Lights and Viewer Position*, MSc thesis, Cornell 1992) and Lischinski, Tampieri &
/// Greenberg (SIGGRAPH 1993): direct light from every emitter (and the sun) sampled with
/// shadow rays at the point itself, so shadows are as sharp as the geometry makes them, not as
/// the mesh does; indirect light from cosine-weighted rays that take the solved B of the side
/// they meet, with the near-hit rule of the solver's own gather ([`NEAR`]) so that corners and
/// narrow gaps are not blotchy with the constant B of the patches beside them.
///
/// It is the solver's gather ([`apply`], [`sensor_irradiance`]) applied to the points of one
/// patch seen through one pixel: the same light sampling, multiple importance sampling, sky,
/// sun and glazing. Built once per image; shared by every thread.
pub struct PointGather<'a, I> {
    ctx: Ctx<'a, I>,
    /// Per patch, once asked: whether any emitter faces it ([`PointGather::radiosity_at`]).
    facing: Vec<OnceLock<bool>>,
}

/// Above this many emitting patches, every patch is taken as facing one (the test is O(emitters)
/// per patch seen).
const FACING_TEST_MAX: usize = 4096;

/// What a ray from the camera met ([`PointGather::view`]).
#[derive(Clone, Copy, Debug)]
pub struct ViewHit {
    /// The side seen: the patch, or the back twin of a two-sided surface.
    pub patch: usize,
    /// Where the ray met it.
    pub point: Vec3,
}

/// What a camera ray sees: the first side that faces it (backs of one-sided patches are passed
/// through, as the Gouraud rasterizer culls them), the transmittance per channel of the glazing
/// before it (tinted glazing colours what is seen through it: docs/design.md §9) and what the
/// panes' sides reflect towards the camera (W/m², already weighed).
#[derive(Clone, Copy, Debug)]
pub struct ViewSeen {
    pub hit: Option<ViewHit>,
    pub through: [f64; 3],
    pub panes: [f64; 3],
    /// Rays cast.
    pub rays: u64,
}

/// The lights of a relit solution (`radiosity relight`): each patch's emitted radiosity E
/// times its light's weight, and the weights of the sky and the sun.
#[derive(Clone, Debug, PartialEq)]
pub struct Relit {
    pub emission: Vec<[f64; 3]>,
    pub sky: f64,
    pub sun: f64,
}

impl<'a, I: Intersector> PointGather<'a, I> {
    /// The gather of the solution `b` (W/m² per patch of `mesh`) through `isect` (built over
    /// `mesh`, whose sides say which patch a back hit goes to), lit by `sky` when it has one;
    /// with `relit`, by the re-weighted lights that made `b`, so that the direct light, the
    /// emitters seen and the B − E of the sides met all agree with it.
    pub fn new(
        mesh: &'a Mesh,
        materials: &[Material],
        isect: &'a I,
        b: &'a [[f64; 3]],
        sky: Option<&'a Sky>,
        relit: Option<Relit>,
    ) -> Self {
        let (own, rho) = emission_and_reflectance(mesh, materials);
        let (e, sky_weight, sun_weight) = match relit {
            Some(r) if r.emission.len() == mesh.patches.len() => (r.emission, r.sky, r.sun),
            _ => (own, 1.0, 1.0),
        };
        let inputs = Inputs {
            e: Cow::Owned(e),
            rho: Cow::Owned(rho),
            b,
            channels: &[],
            group: None,
        };
        let mut ctx = Ctx::new(mesh, materials, isect, inputs, 0, 4, sky);
        ctx.sky_weight = sky_weight;
        ctx.sun_weight = sun_weight;
        PointGather {
            ctx,
            facing: (0..mesh.patches.len()).map(|_| OnceLock::new()).collect(),
        }
    }

    /// Whether some emitter could light `patch`: one with a corner in front of the patch's
    /// plane while the patch has a corner in front of the emitter's (a planar emitter lights
    /// its front only; a patch receives on its front only). When none does — a ceiling beside
    /// its flush lamps — light samples could only miss, so the gather's rays all go over the
    /// hemisphere instead: half the noise variance where the picture is lit indirectly alone.
    fn lit_by_an_emitter(&self, patch: usize) -> bool {
        let ctx = &self.ctx;
        if ctx.emitters.len() > FACING_TEST_MAX {
            return true;
        }
        let mesh = ctx.mesh;
        let tol = ctx.eps_floor;
        let corners = |i: usize| {
            mesh.patch_indices(i)
                .iter()
                .map(|&v| mesh.vertices[v as usize])
        };
        let in_front = |i: usize, of: usize| {
            let (n, c) = (mesh.patches[of].normal, mesh.patches[of].centre);
            corners(i).any(|v| n.dot(v - c) > tol)
        };
        ctx.emitters
            .iter()
            .any(|&j| j != patch && in_front(j, patch) && in_front(patch, j))
    }

    /// What the ray from `org` along `dir` sees. The backs of one-sided patches are passed
    /// through (a camera outside a closed room sees into it, as in the Gouraud image); glazing
    /// is seen and seen through as by the gather's rays.
    pub fn view(&self, org: Vec3, dir: Vec3) -> ViewSeen {
        let ctx = &self.ctx;
        let mut ray = Ray {
            org,
            dir,
            tnear: 0.0,
            tfar: f32::INFINITY,
        };
        let mut out = ViewSeen {
            hit: None,
            through: [1.0; 3],
            panes: [0.0; 3],
            rays: 0,
        };
        for _ in 0..MAX_STEPS {
            let seen = ctx.cast(NO_PATCH, ray, ctx.eps_floor);
            out.rays += 1;
            for q in 0..3 {
                out.panes[q] += out.through[q] * seen.panes[q];
                out.through[q] *= seen.through[q];
            }
            let Some(h) = seen.hit else {
                return out;
            };
            if let Some(r) = ctx.mesh.receiver(h.patch, h.back) {
                out.hit = Some(ViewHit {
                    patch: r as usize,
                    point: org + dir * h.t,
                });
                return out;
            }
            ray.tnear = h.t + (h.t * 1e-5).max(ctx.eps_floor);
        }
        out.through = [0.0; 3];
        out
    }

    /// The radiosity B = E + ρ·H (RGB, W/m²) leaving `patch` at the points `points` (on it,
    /// seen through one pixel), H their mean irradiance gathered with about `rays` rays in
    /// all: half shadow rays to the emitters, a quarter to the sun when there is one, the rest
    /// cosine-weighted over the hemisphere (points, light samples and directions stratified
    /// together, so the points of one pixel share one stratified gather). Returns B and the
    /// rays cast. A side that reflects nothing is its emission alone, without a ray.
    pub fn radiosity_at<R: Rng>(
        &self,
        patch: usize,
        points: &[Vec3],
        rays: usize,
        rng: &mut R,
    ) -> ([f64; 3], u64) {
        let (b, _, rays) = self.part_at(patch, points, rays, LightParts::All, rng);
        (b, rays)
    }

    /// [`Self::radiosity_at`]'s `parts` of the light: `All` is B = E + ρ·H; `Direct` is
    /// E + ρ·H_direct (the emitters and the sun by shadow rays, all `rays` theirs); `Indirect`
    /// is ρ·H_indirect (the hemisphere, the emitters' light left out). `Direct` and `Indirect`
    /// add up to `All`'s B in expectation. Returns the value, the variance of the scalar ρ·H
    /// it gathered (of its mean; 0 where nothing was gathered) and the rays cast.
    pub fn part_at<R: Rng>(
        &self,
        patch: usize,
        points: &[Vec3],
        rays: usize,
        parts: LightParts,
        rng: &mut R,
    ) -> ([f64; 3], f64, u64) {
        let ctx = &self.ctx;
        let (e, rho) = (ctx.e[patch], ctx.rho[patch]);
        let e = if parts == LightParts::Indirect {
            [0.0; 3]
        } else {
            e
        };
        if points.is_empty() || scalar(&rho) <= 0.0 {
            return (e, 0.0, 0);
        }
        let p = &ctx.mesh.patches[patch];
        let eps = (1e-4 * (p.area as f32).sqrt()).max(ctx.eps_floor);
        let m = points.len();
        let at = |u: f32, _: f32| points[((u * m as f32) as usize).min(m - 1)];
        let lights = *self.facing[patch].get_or_init(|| self.lit_by_an_emitter(patch));
        let g = ctx.gather_at(
            patch,
            &at,
            p.normal,
            eps,
            rho,
            rays.max(2),
            lights,
            parts,
            rng,
        );
        let b = [0, 1, 2].map(|q| {
            let v = e[q] + rho[q] * g.h[q];
            if v.is_finite() {
                v.max(0.0)
            } else {
                0.0
            }
        });
        let var = if g.var.is_finite() { g.var } else { 0.0 };
        (b, var, g.rays)
    }

    /// What a camera ray that leaves the model sees: the sky's radiance as an exitance, π·L
    /// (the unit of B), black without a sky; the sun's disc is left out.
    pub fn sky_exitance(&self, dir: Vec3) -> [f64; 3] {
        self.ctx.sky_exitance(dir)
    }

    /// The mesh the gather casts into.
    pub fn mesh(&self) -> &Mesh {
        self.ctx.mesh
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gathered(h: f64, var: f64, rays: u64) -> Gathered {
        Gathered {
            h: [h; 3],
            ch: vec![[h; 3]],
            var,
            rays,
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
