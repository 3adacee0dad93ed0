//! Daylight (docs/design.md §9): the sky, the ground glow and the sun shoot first, as distant
//! emitters.
//!
//! In the paper's spirit every emitter shoots rays in proportion to its unshot energy, each ray
//! carrying the same energy C (Sec. 2). A distant emitter is a piece of the sky (a Tregenza
//! patch, [`crate::sky::tregenza`]), of the ground below the horizon, or the sun's disc, of
//! radiance L and solid angle Ω. Its light arrives as parallel beams: through any plane
//! perpendicular to a direction ω of the piece it carries irradiance L·dω. So the piece shoots
//! from a disc of radius R (the model's bounding sphere) perpendicular to each ray's own
//! direction, placed outside the sphere: flux Φ = L·Ω·πR² in X = Φ/C rays, each ray's
//! direction uniform over the piece ([`SkyPiece::sample`]) and its origin uniform over the
//! disc (stratified: the equal-area cells of the polar grid of Sec. 2, which cut the unit disc
//! into X cells). A ray that meets nothing leaves (escaped in the books); one that meets a
//! surface deposits like any other shot's. A distant emitter never receives, so its only shot
//! comes first: shooting the pieces before any patch is the order progressive refinement
//! would pick anyway up to ties, and lets C be set from what the model receives.
//!
//! **C.** [`super::ray_shots::energy_per_ray`] spreads the emitted flux over the patches. Most
//! of a sky disc's flux misses the model, so what counts is the flux the model receives: a
//! pilot of [`PILOT_RAYS`] rays per piece (seeded, counted, never the clock) estimates each
//! piece's share that meets a surface.
//!
//! **Books.** The pieces' flux is emitted (`EnergyBalance::emitted`, and
//! `EnergyBalance::distant` for the share that came from outside the model); rays landing on
//! back faces from outside are `EnergyBalance::distant_back` (a one-sided model's exterior,
//! not a winding error).

use super::books::State;
use super::ray_shots::{carried, cast_free, Hits, RayCaster, BACK, CHUNK, ESCAPED};
use super::{rng_for, Stream};
use crate::intersect::Intersector;
use crate::mesh::Mesh;
use crate::sample::polar::PolarGrid;
use crate::sky::{Sky, SkyPiece};
use glam::Vec3;
use rand::Rng;
use rayon::prelude::*;

/// Pilot rays per piece to estimate the share of its flux the model receives.
pub const PILOT_RAYS: usize = 256;

/// Chunks of rays cast and applied together (bounds the memory of hit codes).
const BATCH_CHUNKS: usize = 64;

/// Where distant emitters shoot from: the model's bounding sphere.
#[derive(Clone, Copy, Debug)]
pub struct Bounds {
    pub centre: Vec3,
    pub radius: f32,
}

impl Bounds {
    /// The sphere around the mesh's bounding box (a little larger, so no surface lies on it).
    pub fn of(mesh: &Mesh) -> Bounds {
        let (lo, hi) = mesh.vertices.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), v| (lo.min(*v), hi.max(*v)),
        );
        let centre = (lo + hi) * 0.5;
        let radius = ((hi - lo).length() * 0.5).max(1e-3) * 1.01;
        Bounds { centre, radius }
    }

    /// The ray of direction `dir` through the point (x, y) of the unit disc perpendicular to
    /// it: it starts outside the sphere and crosses it.
    fn ray(&self, dir: Vec3, x: f32, y: f32) -> (Vec3, Vec3) {
        let t = dir.any_orthonormal_vector();
        let b = dir.cross(t);
        let org = self.centre - dir * (2.0 * self.radius) + (t * x + b * y) * self.radius;
        (org, dir)
    }

    /// πR², the disc's area.
    pub fn disc_area(&self) -> f64 {
        std::f64::consts::PI * f64::from(self.radius).powi(2)
    }
}

/// The flux a piece shoots at the model (RGB, W): L·Ω·πR².
pub fn piece_flux(piece: &SkyPiece, bounds: &Bounds) -> [f64; 3] {
    piece
        .radiance
        .map(|l| l * piece.solid_angle * bounds.disc_area())
}

/// Ray `k` of `grid`'s cells shot by `piece`: origin stratified over the disc, direction
/// uniform over the piece.
fn piece_ray<R: Rng>(
    piece: &SkyPiece,
    bounds: &Bounds,
    grid: &PolarGrid,
    k: usize,
    rng: &mut R,
) -> (Vec3, Vec3) {
    let d = grid.direction(k, 0.0, true, rng);
    let dir = piece.sample(rng.gen(), rng.gen()).normalize() * -1.0;
    bounds.ray(dir, d.x, d.y)
}

/// The scalar flux the model receives from the sky (for C): each piece's flux times the
/// share of its pilot rays that meet a surface (front or back). When no pilot ray meets the
/// model, the whole flux shot at it (so C stays finite: the sky's rays then mostly leave).
pub(super) fn received_flux<I: Intersector>(
    caster: &RayCaster<'_, I>,
    sky: &Sky,
    bounds: &Bounds,
    seed: u64,
) -> f64 {
    let grid = PolarGrid::for_samples(PILOT_RAYS as f64);
    let received: f64 = sky
        .pieces()
        .par_iter()
        .enumerate()
        .map(|(k, piece)| {
            let mut rng = rng_for(seed, Stream::SkyPilot, k as u64);
            let hits = (0..grid.len())
                .filter(|&r| {
                    let (org, dir) = piece_ray(piece, bounds, &grid, r, &mut rng);
                    caster.trace(None, org, dir, 0.0, &mut rng).0 != ESCAPED
                })
                .count();
            super::scalar(&piece_flux(piece, bounds)) * hits as f64 / grid.len() as f64
        })
        .sum();
    if received > 0.0 {
        received
    } else {
        sky.pieces()
            .iter()
            .map(|p| super::scalar(&piece_flux(p, bounds)))
            .sum()
    }
}

/// What the sky's shots did.
#[derive(Clone, Copy, Debug, Default)]
pub struct SkyShots {
    pub shots: u64,
    pub rays: u64,
}

/// The per-light channels (`--per-light`): how many, and the sky's and the sun's; for daylight
/// coefficients ([`crate::sky::Sky::coefficients`]) the ground's, each sky patch k's following
/// it at `patches + 1 + k`.
#[derive(Clone, Copy, Debug)]
pub struct Channels {
    pub k: usize,
    pub sky: Option<usize>,
    pub sun: Option<usize>,
    pub patches: Option<usize>,
}

impl Channels {
    /// The channel `piece`'s light goes to.
    fn of(&self, piece: &SkyPiece) -> Option<usize> {
        use crate::sky::PieceKind;
        match (piece.kind, self.patches) {
            (PieceKind::Sun, _) => self.sun,
            (PieceKind::Ground, Some(first)) => Some(first),
            (PieceKind::Sky, Some(first)) => Some(first + 1 + piece.index),
            _ => self.sky,
        }
    }
}

/// Shoots every piece of `sky` into the books at energy per ray `c` (and into its channel).
pub(super) fn shoot<I: Intersector>(
    st: &mut State,
    caster: &RayCaster<'_, I>,
    sky: &Sky,
    bounds: &Bounds,
    c: f64,
    seed: u64,
    channels: Option<Channels>,
) -> SkyShots {
    let mut out = SkyShots::default();
    for (k, piece) in sky.pieces().iter().enumerate() {
        let phi = piece_flux(piece, bounds);
        if super::scalar(&phi) <= 0.0 {
            continue;
        }
        let grid = PolarGrid::for_samples(super::scalar(&phi) / c);
        let x = grid.len();
        let phi_ray = phi.map(|p| p / x as f64);
        // The shot's flux per channel: all of it in the piece's own (the sky's, the sun's, or
        // its patch's).
        let shot_ch: Vec<[f64; 3]> = channels.map_or_else(Vec::new, |ch| {
            let own = ch.of(piece);
            (0..ch.k)
                .map(|c| if Some(c) == own { phi } else { [0.0; 3] })
                .collect()
        });
        st.emit_distant(&phi);
        let chunks: Vec<usize> = (0..x.div_ceil(CHUNK)).collect();
        for batch in chunks.chunks(BATCH_CHUNKS) {
            let hits = cast_free(
                caster,
                batch,
                x,
                |ch| rng_for(seed, Stream::Sky, ((k as u64) << 32) | ch as u64),
                |r, rng| piece_ray(piece, bounds, &grid, r, rng),
            );
            for (code, tint) in hits.iter().flat_map(Hits::iter) {
                // Through tinted glazing, the ray carries its energy on tinted (books: the
                // difference is the panes').
                let phi = carried(st, &phi_ray, tint);
                if code == ESCAPED {
                    st.escape_distant(&phi);
                } else if code & BACK != 0 {
                    st.deposit_back_distant(&phi);
                } else {
                    st.deposit(code as usize, &phi);
                    if !shot_ch.is_empty() {
                        st.deposit_channels(code as usize, &shot_ch, 1.0 / x as f64, tint);
                    }
                }
            }
        }
        st.rays += x as u64;
        out.rays += x as u64;
        out.shots += 1;
    }
    st.finish_batch();
    out
}
