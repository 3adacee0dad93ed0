//! Hidden sides (docs/design.md §7): the sides of surfaces that no light can reach because they
//! lie inside a closed solid — a face buried in a wall where two exported solids overlap, the
//! floor under a cabinet standing on it, the bottom of a box lying on a table, a face under a
//! coincident one. Models converted from CAD, IFC and glTF are full of them (a CAD house had a
//! fifth of its patches black after the final gather, mostly such faces).
//!
//! **The test.** From a side of a surface patch, [`PROBES`] rays leave stratified points over
//! the patch in cosine-distributed directions (the polar grid of Sec. 2). Seen from inside a
//! consistently wound closed solid, every face is met from its back; seen from the air, some
//! ray escapes, or meets the front of a face, or a side that receives light (a two-sided
//! surface's back, glazing). So a side is *hidden* when every probe ray meets the back of a
//! one-sided face. It is a geometric test: it runs before the solve, the same on every run
//! (the rays' numbers come from (seed, [`Stream::Hidden`], patch)), and `radiosity info` can
//! report it.
//!
//! **What it is used for.** A hidden side receives no light: the final gather casts no rays for
//! it (unless the shooting did bring it light: then the test was wrong for it and it is
//! gathered as any other), it is counted apart from the black patches, and a shooting ray that
//! meets a hidden back has left a covered part of its shooter (the floor under the cabinet):
//! it carries no light, and the shot's flux goes out through its other rays (`solve::ray_shots`).
//! That back, a one-sided patch's, is probed only when a ray first meets it ([`back_enclosed`]):
//! [`find`] probes the fronts and the backs that are sides of twins.
//!
//! **Limits.** A solid wound the wrong way round (mixed winding) is not closed to this test;
//! its inside is taken as air (a cost in rays, never a lost light). A patch only partly covered
//! is visible if any probe leaves its open part; [`PROBES`] points miss an open part smaller
//! than about a sixteenth of the patch, which then counts as hidden but still receives and
//! shoots what the shooting brings it.

use super::{Intersector, Ray};
use crate::mesh::{Hidden, Mesh};
use crate::random::{rng_for, Stream};
use crate::sample::polar::PolarGrid;
use crate::sample::{Frame, PatchPoints};
use rand::Rng;
use rayon::prelude::*;

/// Probe rays per side: 4 × 4 stratified points, one direction each from a 16-cell polar grid.
pub const PROBES: usize = 16;

/// Finds the hidden sides of `mesh`'s surface patches. `open[j]`: surface patch j lets light
/// through (glazing), so a ray meeting it is in the air. The back of a one-sided patch is left
/// to be probed when a ray meets it ([`back_enclosed`], through `Hidden::back_of`).
pub fn find<I: Intersector>(mesh: &Mesh, isect: &I, open: &[bool], seed: u64) -> Hidden {
    let eps_floor = mesh.ray_offset_floor();
    let grid = PolarGrid::for_samples(PROBES as f64);
    let sides: Vec<(bool, Option<bool>)> = (0..mesh.patches.len())
        .into_par_iter()
        .map(|i| {
            if !mesh.is_surface(i) {
                return (false, Some(false));
            }
            let probe = |back: bool| enclosed(mesh, isect, open, &grid, i, back, seed, eps_floor);
            let twin = mesh.receiver(i as u32, true).is_some();
            (probe(false), twin.then(|| probe(true)))
        })
        .collect();
    Hidden::new(
        sides.iter().map(|s| s.0).collect(),
        sides.iter().map(|s| s.1).collect(),
        open.to_vec(),
        (seed, eps_floor),
    )
}

/// Whether the back of surface patch `j` is hidden, probed now with what `find` kept in
/// `mesh.hidden` (the same rays `find` would have cast for it, so the same answer).
pub fn back_enclosed<I: Intersector>(mesh: &Mesh, isect: &I, j: usize) -> bool {
    let h = &mesh.hidden;
    let grid = PolarGrid::for_samples(PROBES as f64);
    enclosed(mesh, isect, &h.open, &grid, j, true, h.seed, h.eps_floor)
}

// Eight arguments: the probe of one side needs the mesh, its intersector, the glazing, the
// directions, which patch and side, and the seed and offset that make it reproducible.
#[allow(clippy::too_many_arguments)]
/// Whether every probe ray from side `back` of surface patch `i` meets the back of a one-sided
/// face.
fn enclosed<I: Intersector>(
    mesh: &Mesh,
    isect: &I,
    open: &[bool],
    grid: &PolarGrid,
    i: usize,
    back: bool,
    seed: u64,
    eps_floor: f32,
) -> bool {
    let p = &mesh.patches[i];
    let n = if back { -p.normal } else { p.normal };
    let mut rng = rng_for(seed, Stream::Hidden, 2 * i as u64 + back as u64);
    let frame = Frame::new(n, rng.gen::<f32>() * std::f32::consts::TAU);
    let points = PatchPoints::new(mesh, i);
    let eps = (1e-4 * (p.area as f32).sqrt()).max(eps_floor);
    let side = (PROBES as f64).sqrt() as usize;
    for k in 0..grid.len() {
        // Stratified points: cell (k mod 4, k div 4) of a 4 × 4 grid over the unit square,
        // matched to the directions by a shuffle of the rows.
        let (a, b) = (k % side, (k / side + k % side) % side);
        let u = (a as f32 + rng.gen::<f32>()) / side as f32;
        let v = (b as f32 + rng.gen::<f32>()) / side as f32;
        let at = points.at(u, v);
        let dir = frame.to_world(grid.direction(k, 0.0, true, &mut rng));
        // A point of the front under a face lying on it (`mesh::Contacts`) is inside that
        // face's object.
        if !back && mesh.contacts.covers(i, at) {
            continue;
        }
        if !meets_a_back(mesh, isect, open, i, at + n * eps, dir, eps) {
            return false;
        }
    }
    true
}

/// Whether the ray from `org` along `dir` (leaving surface patch `own`) first meets the back
/// of a one-sided face: not glazing, not a two-sided surface's back, not the void.
fn meets_a_back<I: Intersector>(
    mesh: &Mesh,
    isect: &I,
    open: &[bool],
    own: usize,
    org: glam::Vec3,
    dir: glam::Vec3,
    eps: f32,
) -> bool {
    let mut ray = Ray {
        org,
        dir,
        tnear: 0.0,
        tfar: f32::INFINITY,
    };
    for _ in 0..8 {
        match isect.intersect(&ray) {
            None => return false,
            Some(h) if h.patch as usize == own => ray.tnear = h.t + eps,
            Some(h) => {
                let j = h.patch as usize;
                if open.get(j).copied().unwrap_or(false) {
                    return false;
                }
                // The front of a face where another lies on it: the ray met the two coincident
                // faces, and the other one from its back.
                if !h.back {
                    return mesh.contacts.covers(j, org + dir * h.t);
                }
                return mesh.receiver(h.patch, true).is_none();
            }
        }
    }
    false
}
