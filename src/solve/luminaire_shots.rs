//! Luminaires shoot first (docs/design.md §12): a placed luminaire ([`crate::luminaire`]) is a
//! point with a photometric web, an emitter that never receives, so its one shot comes before
//! any patch's, as the sky's does ([`super::sky_shots`]).
//!
//! In the paper's spirit every ray carries the same energy C (Sec. 2): a luminaire of radiant
//! flux Φ casts X = Φ / C rays, one through each of X cells of equal flux over its
//! distribution ([`FluxCells`]), its direction drawn inside the cell in proportion to the
//! intensity, so the rays' density is I(ω)/Φ exactly, stratified by the cells. The cells are
//! turned by a random offset per luminaire, as the hemisphere's polar cells are turned per
//! shot. The rays leave the luminaire's photometric centre, or a point drawn uniformly over
//! its luminous opening where the file gives one with an area; a ray that meets a front face
//! deposits Φ/X there like any shot's, one meeting a back face is lost on it (the books'
//! `absorbed_back`), one that meets nothing leaves.
//!
//! The flux is what the cells integrate: the web bilinear between its nodes, as
//! [`crate::photometry::Photometry::intensity`] reads it, times the luminaire's scale (light
//! loss × count), its tilt factor and colour, in watts at 179 lm/W. The final gather takes a
//! luminaire's direct light again exactly, by shadow rays (`light::luminaires`), and keeps the
//! shot's deposits only for what they light in turn.

use super::books::State;
use super::ray_shots::{carried, cast_free, Hits, RayCaster, BACK, CHUNK, COVERED, ESCAPED};
use super::{rng_for, Stream};
use crate::intersect::Intersector;
use crate::luminaire::Luminaire;
use crate::photometry::cells::FluxCells;
use crate::sky::EFFICACY;
use rand::Rng;

/// Chunks of rays cast and applied together (bounds the memory of hit codes).
const BATCH_CHUNKS: usize = 64;

/// The most cells one luminaire's table is cut into: a shot of more rays casts several rays
/// per cell (each cell's flux split evenly), so a very bright luminaire costs no more memory.
pub const MAX_CELLS: usize = 1 << 20;

/// A luminaire's radiant flux per RGB channel as its shot carries it (W): the cells' lumens ×
/// scale × tilt factor / 179 × colour.
pub fn shot_flux(l: &Luminaire, cells: &FluxCells) -> [f64; 3] {
    let watts = cells.total_lumens() * l.scale * l.tilt_factor / EFFICACY;
    l.colour.map(|c| watts * c)
}

/// The scalar flux (W) all the luminaires emit, from their webs (for C, before any shot).
pub fn emitted_flux(luminaires: &[Luminaire]) -> f64 {
    luminaires
        .iter()
        .map(|l| super::scalar(&l.flux_watts()))
        .sum()
}

/// What the luminaires' shots did.
#[derive(Clone, Copy, Debug, Default)]
pub struct LuminaireShots {
    pub shots: u64,
    pub rays: u64,
}

/// Shoots every luminaire into the books at energy per ray `c`; with `--per-light`,
/// `channels` is (how many light channels, luminaire k's channel if it has one).
pub(super) fn shoot<I: Intersector>(
    st: &mut State,
    caster: &RayCaster<'_, I>,
    luminaires: &[Luminaire],
    c: f64,
    seed: u64,
    channels: Option<(usize, &[Option<usize>])>,
) -> LuminaireShots {
    let mut out = LuminaireShots::default();
    for (k, l) in luminaires.iter().enumerate() {
        let want = (super::scalar(&l.flux_watts()) / c).ceil().max(1.0);
        let rays = if want.is_finite() { want as usize } else { 1 };
        let cells = FluxCells::new(&l.photometry, rays.min(MAX_CELLS));
        let phi = shot_flux(l, &cells);
        if cells.is_empty() || super::scalar(&phi) <= 0.0 {
            continue;
        }
        let per_cell = rays.div_ceil(cells.len()).max(1);
        let x = cells.len() * per_cell;
        let phi_ray = phi.map(|p| p / x as f64);
        let shot_ch: Vec<[f64; 3]> = channels.map_or_else(Vec::new, |(n, of)| {
            let own = of.get(k).copied().flatten();
            (0..n)
                .map(|c| if Some(c) == own { phi } else { [0.0; 3] })
                .collect()
        });
        st.emit_point(&phi);
        let (org, opening) = (l.position.as_vec3(), l.has_opening());
        let mut rng = rng_for(seed, Stream::Luminaires, (k as u64) << 32);
        let turn: f64 = rng.gen();
        let chunks: Vec<usize> = (0..x.div_ceil(CHUNK)).collect();
        for batch in chunks.chunks(BATCH_CHUNKS) {
            let hits = cast_free(
                caster,
                batch,
                x,
                |ch| {
                    rng_for(
                        seed,
                        Stream::Luminaires,
                        ((k as u64) << 32) | (ch as u64 + 1),
                    )
                },
                |r, rng: &mut _| {
                    let local = cells.sample(r / per_cell, rng.gen(), rng.gen(), turn);
                    let dir = l.frame.to_world(local).as_vec3().normalize_or_zero();
                    // From a point of the luminous opening, where the file gives one.
                    let from = match opening {
                        true => l.opening_point(rng.gen(), rng.gen()).as_vec3(),
                        false => org,
                    };
                    (from, dir)
                },
            );
            for (code, tint) in hits.iter().flat_map(Hits::iter) {
                let phi = carried(st, &phi_ray, tint);
                if code == ESCAPED {
                    st.escape(&phi);
                } else if code == COVERED {
                    st.absorb_back(&phi);
                } else if code & BACK != 0 {
                    // Noted where it met a back: a face lit from behind gets a back patch of
                    // its own (`pipeline::stages::lit_backs`), as from any shot.
                    st.deposit_back((code & !BACK) as usize, &phi);
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
