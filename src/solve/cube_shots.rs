//! Hemi-cube shots: shooting with hemi-cubes (Cohen et al. 1988 with the hemi-cube of Cohen &
//! Greenberg 1985), jittered (Sec. 3, Table 1), and the paper's adaptive non-uniform variant
//! (Sec. 2). When the hybrid stops using them is [`super::switch`]'s business.
//!
//! A shot puts a hemi-cube at the shooter's centre, turned by a random angle about its normal
//! (Sec. 3), z-buffers every other patch onto it and reads F_ij as the sum of the delta form
//! factors of the cells patch j holds. Patch j then receives ΔΦ_i·F_ij (ρ_j of it is kept);
//! cells that see nothing let ΔΦ_i·(1 − Σ_j F_ij) escape.
//!
//! - **Uniform** (`hemicube`, `hemicube-jittered`): the same N×N cube for every shot, whatever
//!   energy it carries: the non-adaptive baseline.
//! - **Adaptive** (`adaptive-hemicube`): Sec. 2, "the number of samples is determined as a
//!   proportion of the unshot radiosity": N = sqrt(C/3 · unshot), rounded to the closest odd
//!   integer, with C here the samples per unit of unshot flux, 1/(energy per ray). A uniform
//!   N×N cube would have 3N² = ΔΦ/C_e cells (C_e the energy per ray of the ray shots); the
//!   non-uniform cube has about π/12 of them, none with a larger ΔF than the uniform one's
//!   largest, so every cell carries at most the energy the uniform cube's central cell would.
//!
//! Shots run in fixed-size waves ([`CUBE_WAVE`] shooters taken off the queue together, rendered
//! in parallel with one buffer per thread, applied in shot order), so the result does not
//! depend on the thread count.

use super::books::State;
use super::ray_shots::RayCaster;
use super::{rng_for, Stream};
use crate::intersect::Intersector;
use crate::mesh::Mesh;
use crate::sample::hemicube::{Hemicube, HemicubeBuffer, ShotWork};
use crate::sample::Frame;
use rand::Rng;
use rayon::prelude::*;
use std::cell::RefCell;
use std::collections::HashMap;
use std::sync::Arc;
use std::time::Instant;

/// Shooters per wave of hemi-cube shots. Fixed, so results do not depend on threads.
pub const CUBE_WAVE: usize = 8;
/// Largest adaptive resolution (a non-uniform cube of about 0.9 M cells, 14 MiB of buffers per
/// thread). Shots that ask for more are clamped: their cells carry more energy than asked.
pub const MAX_ADAPTIVE_N: usize = 1001;
/// The cache keeps built cubes up to this many cells in all, then starts again.
const CACHE_CELLS: usize = 8 << 20;

/// Which hemi-cube a shot uses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CubeKind {
    /// The uniform N×N cube for every shot; `jitter`: each cell's sample point drawn inside it.
    Uniform { n: usize, jitter: bool },
    /// The paper's non-uniform cube, its resolution from the shot's energy.
    Adaptive,
}

/// One shot by hemi-cube.
pub struct CubeShot {
    pub patch: usize,
    /// Global shot number (seeds its rotation and jitter).
    pub index: u64,
    /// The flux it shoots, RGB.
    pub phi: [f64; 3],
    /// The same per light channel (empty without `--per-light`).
    pub ch: Vec<[f64; 3]>,
    pub cube: Arc<Hemicube>,
}

/// What one shot found: (patch, F, seen from behind) sorted by patch; the work it did,
/// counted; and the thread time it took (s; read only by `--switch-by measured`).
#[derive(Default)]
pub struct CubeHits {
    pub ff: Vec<(u32, f64, bool)>,
    pub work: ShotWork,
    pub seconds: f64,
}

thread_local! {
    /// One z-buffer per thread, reused across shots (no allocation per shot once sized).
    static BUFFER: RefCell<HemicubeBuffer> = RefCell::new(HemicubeBuffer::default());
}

/// Builds and caches the cubes, and renders waves of shots.
pub struct CubeShooter {
    pub kind: CubeKind,
    /// Energy per ray C (scalar W): the ray shots' C, which sets the adaptive resolution.
    energy_per_ray: f64,
    cache: HashMap<usize, Arc<Hemicube>>,
    cached_cells: usize,
}

impl CubeShooter {
    pub fn new(kind: CubeKind, energy_per_ray: f64) -> CubeShooter {
        CubeShooter {
            kind,
            energy_per_ray,
            cache: HashMap::new(),
            cached_cells: 0,
        }
    }

    /// Sec. 2: N = sqrt(C/3 · unshot), C = 1/(energy per ray), rounded to the closest odd
    /// integer; clamped to [3, MAX_ADAPTIVE_N].
    pub fn adaptive_resolution(&self, flux: f64) -> usize {
        let n = (flux / self.energy_per_ray / 3.0).max(0.0).sqrt();
        // Closest odd integer: 2·round((n − 1)/2) + 1.
        let odd = 2.0 * ((n - 1.0) / 2.0).round() + 1.0;
        (odd.max(3.0) as usize).min(MAX_ADAPTIVE_N)
    }

    /// The cube a shot of scalar flux `flux` uses.
    pub fn cube_for(&mut self, flux: f64) -> Arc<Hemicube> {
        let (n, uniform) = match self.kind {
            CubeKind::Uniform { n, .. } => (n, true),
            CubeKind::Adaptive => (self.adaptive_resolution(flux), false),
        };
        if let Some(c) = self.cache.get(&n) {
            return c.clone();
        }
        let cube = Arc::new(if uniform {
            Hemicube::uniform(n)
        } else {
            Hemicube::non_uniform(n)
        });
        if self.cached_cells + cube.cell_count() > CACHE_CELLS {
            self.cache.clear();
            self.cached_cells = 0;
        }
        self.cached_cells += cube.cell_count();
        self.cache.insert(n, cube.clone());
        cube
    }

    /// Renders a wave of shots in parallel into `hits` (one per shot, in shot order; the
    /// vectors are reused from wave to wave, so a shot allocates nothing once they are sized).
    pub fn cast(&self, mesh: &Mesh, seed: u64, wave: &[CubeShot], hits: &mut Vec<CubeHits>) {
        let jitter = matches!(self.kind, CubeKind::Uniform { jitter: true, .. });
        if hits.len() < wave.len() {
            hits.resize_with(wave.len(), CubeHits::default);
        }
        wave.par_iter()
            .zip(hits.par_iter_mut())
            .for_each(|(shot, out)| {
                let t = Instant::now();
                let p = &mesh.patches[shot.patch];
                // Sec. 3: a random rotation about the normal per shot (Cohen & Greenberg).
                let mut rng = rng_for(seed, Stream::Shot(shot.index), u64::MAX);
                let frame = Frame::new(p.normal, rng.gen::<f32>() * std::f32::consts::TAU);
                let mut jitter_rng = rng_for(seed, Stream::Shot(shot.index), 0);
                out.work = BUFFER.with_borrow_mut(|buf| {
                    shot.cube.shoot(
                        mesh,
                        shot.patch,
                        p.centre,
                        &frame,
                        jitter.then_some(&mut jitter_rng),
                        buf,
                        &mut out.ff,
                    )
                });
                out.seconds = t.elapsed().as_secs_f64();
            });
    }
}

/// Applies one shot: j receives ΔΦ_i·F_ij; what no cell saw escapes. Cells that see a hidden
/// back (`mesh::Hidden`: the cube's centre is covered from there, inside a solid) carry
/// nothing, the other cells' factors scaled up by 1 / (1 − their share), unless every cell is
/// covered (then the shot is absorbed on those backs, as before the test).
/// A back is probed the first time a cell sees it (`Hidden::back_of`), with the solve's
/// intersector, `caster`'s; the hemi-cube methods have none, and find no hidden sides.
pub(super) fn apply<I: Intersector>(
    st: &mut State,
    shot: &CubeShot,
    hits: &CubeHits,
    mesh: &Mesh,
    caster: Option<&RayCaster<'_, I>>,
) {
    let back_hidden =
        |j: usize| (mesh.hidden).back_of(j, || caster.is_some_and(|c| c.back_enclosed(j)));
    let is_covered = |j: u32, back: bool| back && back_hidden(j as usize);
    let covered: f64 = (hits.ff.iter())
        .filter(|&&(j, _, back)| is_covered(j, back))
        .map(|&(_, f, _)| f)
        .sum();
    let scale = if covered > 0.0 && covered < 1.0 - 1e-9 {
        1.0 / (1.0 - covered)
    } else {
        1.0
    };
    let mut seen = 0.0;
    // Cells carry ΔΦ/cells on average (equal ΔF for the non-uniform cube).
    let e_cell = super::scalar(&shot.phi) / shot.cube.cell_count() as f64;
    for &(j, f, back) in &hits.ff {
        if scale != 1.0 && is_covered(j, back) {
            continue;
        }
        let f = f * scale;
        let phi = shot.phi.map(|p| p * f);
        if back {
            st.deposit_back(j as usize, &phi);
        } else {
            st.deposit_cube(j as usize, &phi, e_cell);
            if !shot.ch.is_empty() {
                st.deposit_channels(j as usize, &shot.ch, f, None);
            }
        }
        seen += f;
    }
    // The cells' ΔF sum to 1 to rounding; only a real gap (an open scene) counts as escaped.
    let escaped = (1.0 - seen).max(0.0);
    if escaped > 1e-12 {
        st.escape(&shot.phi.map(|p| p * escaped));
    } else {
        // Rounding either way: keep the books closed by crediting it where the rest went.
        let rest = shot.phi.map(|p| p * (1.0 - seen));
        st.energy
            .absorbed
            .iter_mut()
            .zip(rest)
            .for_each(|(a, r)| *a += r);
    }
    st.cells += shot.cube.cell_count() as u64;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn adaptive_resolution_is_the_closest_odd_integer() {
        let s = CubeShooter::new(CubeKind::Adaptive, 1.0);
        // N = sqrt(X/3): X = 3·N².
        assert_eq!(s.adaptive_resolution(3.0 * 101.0 * 101.0), 101);
        assert_eq!(s.adaptive_resolution(3.0 * 100.2 * 100.2), 101);
        assert_eq!(s.adaptive_resolution(3.0 * 99.8 * 99.8), 99);
        assert_eq!(s.adaptive_resolution(3.0 * 10.0 * 10.0), 11);
        assert_eq!(s.adaptive_resolution(0.5), 3);
        assert_eq!(s.adaptive_resolution(1e30), MAX_ADAPTIVE_N);
    }
}
