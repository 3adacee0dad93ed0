//! Sec. 2 of Airey & Ouh-young (1989): the adaptive ray shot.
//!
//! A shot from patch `i` casts X = ΔΦ_i / C rays, C the *energy per ray* ([`energy_per_ray`]):
//! samples in proportion to the unshot energy, so every ray carries the same energy C. The rays
//! go through the equal-area polar cells of [`PolarGrid`] (the unit circle split into X pieces
//! of form factor 1/X each, twice as many θ divisions as radial ones, radii at √k), turned by a
//! random angle about the normal (Sec. 3: the random rotation of Cohen et al.), from points
//! spread uniformly over the patch (`PatchPoints`). The patch `j` a ray hits first receives
//! ρ_j·ΔΦ_i/X; the rest is absorbed (`apply_rays`).
//!
//! Rays are cast in chunks of [`CHUNK`], the unit of parallel work; every chunk's random
//! numbers come from (seed, shot, chunk), so what a ray hits never depends on which thread cast
//! it. [`super::driver`] groups shots into waves of about [`WAVE_RAYS`] rays.

use super::books::State;
use super::{rng_for, scalar, Stream};
use crate::intersect::hidden::back_enclosed;
use crate::intersect::{Intersector, Ray};
use crate::mesh::Mesh;
use crate::sample::PatchPoints;
use crate::sample::{polar::PolarGrid, Frame};
use glam::Vec3;
use rand::Rng;
use std::time::Instant;

/// Rays per wave of shots (see [`super::driver`]) up to 131,072 patches.
pub const WAVE_RAYS: usize = 32_768;
/// The most rays a wave of shots holds.
pub const MAX_WAVE_RAYS: usize = 1 << 20;

/// Rays per wave of shots for a mesh of `patches` patches: [`WAVE_RAYS`], or a quarter of a
/// ray per patch on larger meshes, up to [`MAX_WAVE_RAYS`]. It depends on the mesh alone, so
/// results do not depend on threads. A wave's shots are cast in the order of their patches
/// (`driver`), and the shots of a larger wave lie nearer one another: on the 1 M-patch
/// building the shooting takes 0.93 of the time of waves of 32,768 rays on an idle machine and
/// 0.61 on a shared one (cache reuse in the intersector, less waiting between waves), for
/// 0.5 % more rays (docs/results/pipeline-1m.md).
pub fn wave_rays(patches: usize) -> usize {
    (patches / 4).clamp(WAVE_RAYS, MAX_WAVE_RAYS)
}
/// Rays per parallel task.
pub const CHUNK: usize = 1024;
/// Hit codes: a patch id, a patch id with this bit for a back-face hit, or [`ESCAPED`].
pub(super) const BACK: u32 = 1 << 31;
pub(super) const ESCAPED: u32 = u32::MAX;
/// Hit code of a ray that met a hidden back (`mesh::Hidden`): it left a covered part of its
/// shooter (the floor under a cabinet), so it carries none of the shot's light.
pub(super) const COVERED: u32 = u32::MAX - 1;
/// Surfaces a ray may step past (its own, glazing) before it is taken as lost.
const MAX_STEPS: usize = 16;

/// The energy per ray C (scalar W) for a requested relative error τ of a typical patch: the
/// paper's "constant of proportionality" between unshot energy and samples (Sec. 2), picked
/// from the accuracy asked for.
///
/// A patch hit N times has a relative sampling error of about 1/√N, so a typical patch should
/// be hit 1/τ² times. All shots together move about Φ_emit / (1 − ρ̄) (every bounce keeps ρ̄),
/// spread over n patches, so C = Φ_emit·τ² / (n·(1 − ρ̄)) — about n/τ² rays in all, whatever ρ̄.
/// n and ρ̄ count surfaces, not back twins (docs/design.md §7): making a model two-sided adds
/// patches that mostly face the void, and must not change the sampling of the room.
pub fn energy_per_ray(mesh: &Mesh, rho: &[[f64; 3]], emitted: f64, tolerance: f64) -> f64 {
    let surfaces = || (0..mesh.patches.len()).filter(|&i| mesh.is_surface(i));
    let area = surfaces()
        .map(|i| mesh.patches[i].area)
        .sum::<f64>()
        .max(f64::MIN_POSITIVE);
    let rho_mean: f64 = surfaces()
        .map(|i| scalar(&rho[i]) * mesh.patches[i].area)
        .sum::<f64>()
        / area;
    let n = surfaces().count().max(1) as f64;
    emitted * tolerance * tolerance / (n * (1.0 - rho_mean).max(1e-3))
}

/// The rays a shot of scalar flux `flux` casts: X = ΔΦ / C, laid out on the polar grid.
pub fn grid_for(flux: f64, energy_per_ray: f64) -> PolarGrid {
    PolarGrid::for_samples(flux / energy_per_ray)
}

/// One ray shot of a wave.
pub(super) struct RayShot {
    pub patch: usize,
    /// Global shot number (seeds its random numbers).
    pub index: u64,
    /// The flux it shoots, RGB.
    pub phi: [f64; 3],
    /// The same per light channel (empty without `--per-light`).
    pub ch: Vec<[f64; 3]>,
    pub grid: PolarGrid,
}

/// Everything a ray shot needs to know about the scene, shared by all threads.
pub(super) struct RayCaster<'a, I> {
    mesh: &'a Mesh,
    isect: &'a I,
    seed: u64,
    jitter: bool,
    /// Smallest offset of ray origins off their patch: a few ulps of the largest coordinate.
    eps_floor: f32,
    /// Straight-through transmittance per patch (glazing, docs/design.md §9); empty when
    /// nothing transmits.
    trans: Vec<f32>,
    /// The factor T_c / T per patch a ray going through it carries its energy on with
    /// (`Material::tint`); empty when no glazing is tinted.
    tint: Vec<[f64; 3]>,
    /// Which patches emit (their rays are never taken as leaving a covered point: light in an
    /// enclosure is in a room wound inside out, not inside a solid); empty: none known.
    lights: Vec<bool>,
}

/// The rays of one chunk: a hit code per ray, and which of them went through tinted glazing.
#[derive(Clone, Debug, Default)]
pub(super) struct Hits {
    pub codes: Vec<u32>,
    /// (the ray's index in `codes`, the product of the tinted panes' T_c / T it went
    /// through), in ray order; empty when no ray met tinted glazing.
    pub tinted: Vec<(u32, [f64; 3])>,
}

impl Hits {
    /// Each ray's hit code and, when it went through tinted glazing, its tint factor.
    pub fn iter(&self) -> impl Iterator<Item = (u32, Option<[f64; 3]>)> + '_ {
        let mut tinted = self.tinted.iter().peekable();
        self.codes.iter().enumerate().map(move |(k, &code)| {
            let tint = tinted.next_if(|(at, _)| *at as usize == k).map(|(_, t)| *t);
            (code, tint)
        })
    }
}

/// The rays of a batch of chunks (`batch`, of [`CHUNK`] rays each, `x` rays in all) shot by an
/// emitter no patch holds (a sky piece, a luminaire), cast in parallel: chunk `ch` draws its
/// random numbers from `rng_of(ch)` and ray `r` is `ray(r, rng)` (an origin and a direction).
/// The hits per chunk, in ray order, so what a ray meets never depends on the thread.
pub(super) fn cast_free<I: Intersector, R: Rng>(
    caster: &RayCaster<'_, I>,
    batch: &[usize],
    x: usize,
    rng_of: impl Fn(usize) -> R + Sync,
    ray: impl Fn(usize, &mut R) -> (Vec3, Vec3) + Sync,
) -> Vec<Hits> {
    use rayon::prelude::*;
    batch
        .par_iter()
        .map(|&ch| {
            let mut rng = rng_of(ch);
            let mut out = Hits::default();
            for r in ch * CHUNK..(ch * CHUNK + CHUNK).min(x) {
                let (org, dir) = ray(r, &mut rng);
                let (code, tint) = caster.trace(None, org, dir, 0.0, &mut rng);
                if let Some(t) = tint {
                    out.tinted.push((out.codes.len() as u32, t));
                }
                out.codes.push(code);
            }
            out
        })
        .collect()
}

/// Flux `phi` of a ray that went through tinted glazing of factor `tint` (the energy it
/// carries on, per channel), the difference booked to the panes ([`State::tint`]); `phi`
/// itself for every other ray.
#[inline]
pub(super) fn carried(st: &mut State, phi: &[f64; 3], tint: Option<[f64; 3]>) -> [f64; 3] {
    match tint {
        Some(t) => {
            let out = [0, 1, 2].map(|c| phi[c] * t[c]);
            st.tint(phi, &out);
            out
        }
        None => *phi,
    }
}

impl<'a, I: Intersector> RayCaster<'a, I> {
    /// Whether the back of surface patch `j` is hidden, probed with this caster's intersector
    /// (`intersect::hidden::back_enclosed`; what `Hidden::back_of` asks the first time).
    pub fn back_enclosed(&self, j: usize) -> bool {
        back_enclosed(self.mesh, self.isect, j)
    }

    pub fn new(mesh: &'a Mesh, isect: &'a I, seed: u64, jitter: bool) -> Self {
        RayCaster {
            mesh,
            isect,
            seed,
            jitter,
            eps_floor: mesh.ray_offset_floor(),
            trans: Vec::new(),
            tint: Vec::new(),
            lights: Vec::new(),
        }
    }

    /// Lets rays through glazing: a ray that meets a patch of transmittance T goes on
    /// unchanged with probability T (every ray keeps its energy C); the rest land on it, which
    /// keeps ρ/(1 − T) of them ([`super::books::State::new`]), so it reflects ρ of all the
    /// light it receives.
    ///
    /// Tinted glazing (docs/design.md §9) lets rays through with the same probability T, the
    /// mean of its T_c, so every ray still carries the same energy C when it leaves its
    /// shooter (Sec. 2); one that goes through carries its energy on times T_c / T per
    /// channel, which makes each channel's transmitted light T_c of what arrives on average.
    /// Grey glazing's factor is exactly 1, and is not applied.
    pub fn with_glazing(mut self, materials: &[crate::scene::Material]) -> Self {
        let mat = |p: &crate::mesh::Patch| &materials[p.material as usize];
        let t = |p: &crate::mesh::Patch| mat(p).transmittance as f32;
        self.lights = self
            .mesh
            .patches
            .iter()
            .map(|p| mat(p).is_emitter())
            .collect();
        if self.mesh.patches.iter().any(|p| t(p) > 0.0) {
            self.trans = self.mesh.patches.iter().map(t).collect();
        }
        if self
            .mesh
            .patches
            .iter()
            .any(|p| t(p) > 0.0 && mat(p).is_tinted())
        {
            self.tint = self.mesh.patches.iter().map(|p| mat(p).tint()).collect();
        }
        self
    }

    /// Casts rays `first..first + count` of `shot` (its chunk `chunk`); a hit code per ray.
    pub fn cast(&self, shot: &RayShot, chunk: usize, first: usize, count: usize) -> Hits {
        let i = shot.patch;
        let patch = &self.mesh.patches[i];
        // Sec. 3: a random rotation of the sampling pattern about the normal, per shot.
        let angle = rng_for(self.seed, Stream::Shot(shot.index), u64::MAX).gen::<f32>()
            * std::f32::consts::TAU;
        let frame = Frame::new(patch.normal, angle);
        let mut rng = rng_for(self.seed, Stream::Shot(shot.index), chunk as u64);
        let eps = (1e-4 * (patch.area as f32).sqrt()).max(self.eps_floor);
        let points = PatchPoints::new(self.mesh, i);
        let mut out = Hits {
            codes: Vec::with_capacity(count),
            tinted: Vec::new(),
        };
        // The shooter's surface: a back twin's rays leave the surface its front patch is.
        let own = Some(self.mesh.surface_of(i));
        // Points of a front under a face lying on it (`mesh::Contacts`) send no light.
        let light = self.lights.get(i).copied().unwrap_or(false);
        let contacts = !light && self.mesh.is_surface(i) && !self.mesh.contacts.is_empty();
        for k in first..first + count {
            let dir = frame.to_world(shot.grid.direction(k, 0.0, self.jitter, &mut rng));
            let at = points.sample(&mut rng);
            if contacts && self.mesh.contacts.covers(i, at) {
                out.codes.push(COVERED);
                continue;
            }
            let org = at + patch.normal * eps;
            let (code, tint) = self.trace(own, org, dir, eps, &mut rng);
            if let Some(t) = tint {
                out.tinted.push(((k - first) as u32, t));
            }
            out.codes.push(code);
        }
        out
    }

    /// The hit code of a ray from `org` along `dir` that starts on surface `own` (none for a
    /// distant emitter's ray), and the factor per channel the ray's energy carries on with when
    /// it went through tinted glazing (the product of the panes' T_c / T; `None` when it met
    /// none).
    pub(super) fn trace<R: Rng>(
        &self,
        own: Option<usize>,
        org: Vec3,
        dir: Vec3,
        eps: f32,
        rng: &mut R,
    ) -> (u32, Option<[f64; 3]>) {
        let mut ray = Ray {
            org,
            dir,
            tnear: 0.0,
            tfar: f32::INFINITY,
        };
        let mut tint: Option<[f64; 3]> = None;
        // A ray leaving its own (planar, convex) patch cannot meet it again; if rounding says
        // otherwise, step past it.
        for _ in 0..MAX_STEPS {
            match self.isect.intersect(&ray) {
                None => return (ESCAPED, tint),
                Some(h) if Some(h.patch as usize) == own => ray.tnear = h.t + eps,
                Some(h) if self.passes(h.patch as usize, rng) => {
                    if let Some(f) = self.tint.get(h.patch as usize).filter(|f| **f != [1.0; 3]) {
                        let t = tint.get_or_insert([1.0; 3]);
                        for c in 0..3 {
                            t[c] *= f[c];
                        }
                    }
                    ray.tnear = h.t + (h.t * 1e-5).max(self.eps_floor);
                }
                // The side met decides the receiver (docs/design.md §7).
                Some(h) => {
                    let code = match self.mesh.receiver(h.patch, h.back) {
                        Some(r) => r,
                        None if own
                            .is_some_and(|o| !self.lights.get(o).copied().unwrap_or(false))
                            && self.mesh.hidden.back_of(h.patch as usize, || {
                                back_enclosed(self.mesh, self.isect, h.patch as usize)
                            }) =>
                        {
                            COVERED
                        }
                        None => h.patch | BACK,
                    };
                    return (code, tint);
                }
            }
        }
        (ESCAPED, tint)
    }

    /// Whether a ray that met `patch` goes through it (glazing).
    #[inline]
    fn passes<R: Rng>(&self, patch: usize, rng: &mut R) -> bool {
        !self.trans.is_empty() && self.trans[patch] > 0.0 && rng.gen::<f32>() < self.trans[patch]
    }

    /// Casts every ray of `shot` on the calling thread, not applied; returns how many.
    pub fn cast_all(&self, shot: &RayShot) -> usize {
        tasks_of(std::slice::from_ref(shot))
            .iter()
            .map(|t| self.cast(shot, t.chunk, t.first, t.count).codes.len())
            .sum()
    }
}

/// Thread time (s) of ray shots from `shooters`, `rays_per_shot` rays each, cast on the calling
/// thread exactly as the solver casts them (points over the patch, polar cells, rotation) but
/// not applied: Sec. 4's cost of ray sampling, for `radiosity bench shots`. Returns the seconds
/// and the rays cast.
pub fn time_ray_shots<I: Intersector>(
    mesh: &Mesh,
    isect: &I,
    shooters: &[usize],
    rays_per_shot: usize,
    seed: u64,
) -> (f64, u64) {
    let caster = RayCaster::new(mesh, isect, seed, true);
    let t = Instant::now();
    let mut rays = 0;
    for (k, &i) in shooters.iter().enumerate() {
        let shot = RayShot {
            patch: i,
            index: k as u64,
            phi: [0.0; 3],
            ch: Vec::new(),
            grid: PolarGrid::for_samples(rays_per_shot as f64),
        };
        rays += caster.cast_all(&shot) as u64;
    }
    (t.elapsed().as_secs_f64(), rays)
}

/// Applies a wave's hits in task order: receivers gain ρ_j·ΔΦ_i/X, the rest is absorbed.
/// A ray that went through tinted glazing carries ΔΦ_i/X times its tint factor.
/// Rays that met a hidden back ([`COVERED`]) carry nothing: a shot's flux goes out through its
/// other rays (all of them covered: the shot's flux is absorbed on the back faces).
pub(super) fn apply_rays(st: &mut State, wave: &[RayShot], tasks: &[Task], hits: &[Hits]) {
    let mut covered = vec![0usize; wave.len()];
    for (task, hits) in tasks.iter().zip(hits) {
        covered[task.shot] += hits.codes.iter().filter(|&&c| c == COVERED).count();
    }
    for (task, hits) in tasks.iter().zip(hits) {
        let shot = &wave[task.shot];
        let x = shot.grid.len();
        let all_covered = covered[task.shot] == x;
        let per_ray = 1.0
            / (if all_covered {
                x
            } else {
                x - covered[task.shot]
            }) as f64;
        let phi_ray = shot.phi.map(|p| p * per_ray);
        for (code, tint) in hits.iter() {
            if code == COVERED && !all_covered {
                continue;
            }
            let phi = carried(st, &phi_ray, tint);
            if code == COVERED {
                st.absorb_back(&phi);
            } else if code == ESCAPED {
                st.escape(&phi);
            } else if code & BACK != 0 {
                st.deposit_back((code & !BACK) as usize, &phi);
            } else {
                st.deposit(code as usize, &phi);
                if !shot.ch.is_empty() {
                    st.deposit_channels(code as usize, &shot.ch, per_ray, tint);
                }
            }
        }
        st.rays += hits.codes.len() as u64;
    }
    st.finish_batch();
}

/// A chunk of one shot's rays: the unit of parallel work.
#[derive(Clone, Copy, Debug)]
pub(super) struct Task {
    pub shot: usize,
    pub chunk: usize,
    pub first: usize,
    pub count: usize,
}

/// The chunks of a wave's shots, in shot order.
pub(super) fn tasks_of(wave: &[RayShot]) -> Vec<Task> {
    wave.iter()
        .enumerate()
        .flat_map(|(s, shot)| {
            let x = shot.grid.len();
            (0..x.div_ceil(CHUNK)).map(move |c| Task {
                shot: s,
                chunk: c,
                first: c * CHUNK,
                count: CHUNK.min(x - c * CHUNK),
            })
        })
        .collect()
}
