//! The state the refinement keeps while it runs: where each gathered value is kept ([`At`]:
//! the keys of position and facing, and which of a patch's edges a neighbour shares), the
//! values gathered so far ([`Values`]) and each patch's elements ([`PatchWork`]); shared by the
//! refinement loop ([`super::refine`]), the indirect light's nodes ([`super::indirect`]) and
//! the display ([`super::display`]).

use super::geometry::{Elem, Root};
use crate::light::Vis;
use crate::mesh::Mesh;
use glam::{DVec2, DVec3, Vec3};
use rayon::prelude::*;
use rustc_hash::{FxHashMap as HashMap, FxHashSet as HashSet};

/// Where a point's value is kept ([`super::refine`]'s notes, "Shared points"): its position,
/// facing and material, as the mesh welds its vertices.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(super) struct At(pub [i64; 3], pub [i32; 3], pub u32);

/// A point's gathered light (its direct light, or all of it under
/// [`super::CornerLight::Full`]) and what its shadow rays told of its polygon's whole faces
/// (read by the points between it and its neighbours: `super::refine`, "Told by the corners").
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Direct {
    pub b: [f64; 3],
    pub vis: Vis,
    /// The polygon whose whole faces `vis` numbers (a point on an edge two polygons share is
    /// gathered as one of them).
    pub polygon: u32,
}

/// The points a point lies between (a midpoint its edge's ends, a centre its element's
/// corners), the first `.1` of them: what tells its gather which whole faces it sees.
pub(super) type Parents = ([DVec2; 4], u8);

/// A corner's: none.
pub(super) const NO_PARENTS: Parents = ([DVec2::ZERO; 4], 0);

/// The values gathered so far, and the rays they cost.
#[derive(Default)]
pub(super) struct Values {
    pub map: HashMap<At, Direct>,
    /// [`super::CornerLight::Split`]: the indirect light at the patches' nodes, and the
    /// variance of each (scalar; the gather's own, from its strata: what the refinement's
    /// test takes for noise).
    pub indirect: HashMap<At, ([f64; 3], f64)>,
    pub rays: u64,
    /// Distinct points gathered in all, `map`'s and `indirect`'s (counted as they are
    /// inserted: what is no longer read is dropped from both as the refinement goes).
    pub gathered: u64,
}

/// Patches whose points [`gather_new`] lists and gathers at a time: what the listing holds
/// stays small on a large model.
const CHUNK: usize = 1 << 16;

/// Gathers each distinct point that `list` gives the patches `patch(0)`, …, `patch(n − 1)` (in
/// increasing order; `locate` says where each listed point is kept and lies) and `map` lacks,
/// once, by the first patch listing it, in parallel, into `map`, [`CHUNK`] patches at a time
/// (the same patch gathers each point as if all were listed at once): the map itself marks
/// what is asked for already (`blank` until gathered). The points `later` picks are gathered
/// after the others of their chunk, and `gather` reads the map as it stands then (a midpoint
/// reads what its edge's ends, gathered first, told: [`Direct::vis`]). Returns the rays cast
/// and the points gathered.
pub(super) fn gather_new<P: Copy + Send + Sync, V: Copy + Send + Sync>(
    map: &mut HashMap<At, V>,
    (n, patch): (usize, impl Fn(usize) -> usize + Sync + Send),
    (list, locate, later): (
        impl Fn(usize) -> Vec<P> + Sync + Send,
        impl Fn(usize, P) -> (At, DVec3),
        impl Fn(P) -> bool,
    ),
    gather: impl Fn(&HashMap<At, V>, usize, P, DVec3) -> (V, u64) + Sync + Send,
    blank: V,
) -> (u64, u64) {
    let (mut rays, mut gathered) = (0, 0);
    for lo in (0..n).step_by(CHUNK) {
        let hi = (lo + CHUNK).min(n);
        let lists: Vec<(usize, Vec<P>)> = (lo..hi)
            .into_par_iter()
            .map(|k| (patch(k), list(patch(k))))
            .collect();
        let mut todo = [Vec::new(), Vec::new()];
        for (i, points) in &lists {
            for &p in points {
                let (at, x) = locate(*i, p);
                if let std::collections::hash_map::Entry::Vacant(v) = map.entry(at) {
                    // Filled below, before anything reads it.
                    v.insert(blank);
                    todo[usize::from(later(p))].push((at, *i, x, p));
                }
            }
        }
        drop(lists);
        for todo in todo {
            let m = &*map;
            let got: Vec<(V, u64)> = (todo.par_iter())
                .map(|&(_, i, x, p)| gather(m, i, p, x))
                .collect();
            gathered += todo.len() as u64;
            for ((at, _, _, _), (value, r)) in todo.into_iter().zip(got) {
                map.insert(at, value);
                rays += r;
            }
        }
    }
    (rays, gathered)
}

/// One patch's elements while they are refined.
pub(super) struct PatchWork {
    pub roots: Vec<Root>,
    /// Elements still to decide on, and the ones kept.
    pub active: Vec<Elem>,
    pub done: Vec<Elem>,
    /// Per root, the scalar indirect light the contrast is taken against
    /// ([`super::CornerLight::Direct`]; from the root's first test).
    pub indirect: Vec<f64>,
    /// The kept elements' corner values, corner after corner in the order of `done` (filled
    /// once the refinement ends: [`super::refine::finish`]).
    pub corner_b: Vec<[f64; 3]>,
    /// [`super::CornerLight::Split`]: per root, the indirect light at its quadratic's nodes
    /// ([`super::indirect`]), each with the variance of its value.
    pub ind_nodes: Vec<Vec<([f64; 3], f64)>>,
}

/// The cache key of a position.
pub(super) fn key(p: DVec3, quantum: f64) -> [i64; 3] {
    let q = |x: f64| (x / quantum).round() as i64;
    [q(p.x), q(p.y), q(p.z)]
}

/// A facing, quantised as the mesh welds vertices.
pub(super) fn facing(n: Vec3) -> [i32; 3] {
    let qn = |x: f32| (x * 1000.0).round() as i32;
    [qn(n.x), qn(n.y), qn(n.z)]
}

/// Per patch, which of its edges another patch shares (bit k: corner k to k + 1; the mesh's
/// vertices are welded by position, facing and material, so a neighbour on the same surface
/// runs the edge the other way). Edges past the 64th are never marked shared.
pub(super) fn inner_edges(mesh: &Mesh) -> Vec<u64> {
    let ring = |i: usize| {
        let ids = mesh.patch_indices(i);
        (0..ids.len()).map(move |k| (ids[k], ids[(k + 1) % ids.len()]))
    };
    let edges: HashSet<(u32, u32)> = (0..mesh.patches.len()).flat_map(ring).collect();
    (0..mesh.patches.len())
        .map(|i| {
            ring(i)
                .take(64)
                .enumerate()
                .filter(|&(_, (a, b))| a != b && edges.contains(&(b, a)))
                .fold(0u64, |m, (k, _)| m | 1 << k)
        })
        .collect()
}

/// The edges of an `n`-cornered patch that the point `uv` of root `root` lies on (bit k: edge
/// k), `None` when one of them is past the 64th. A quad root's edges are v = 0, u = 1, v = 1,
/// u = 0; fan triangle `root` has corners 0, root + 1, root + 2, of which only its far side
/// and the fan's first and last sides are the patch's edges. The parameters are dyadic, so
/// the tests are exact.
pub(super) fn on_edges(n: usize, root: usize, tri: bool, uv: DVec2) -> Option<u64> {
    let (u, v) = (uv.x, uv.y);
    let mut edges: Vec<usize> = Vec::new();
    if !tri {
        for (on, k) in [(v == 0.0, 0), (u == 1.0, 1), (v == 1.0, 2), (u == 0.0, 3)] {
            if on {
                edges.push(k);
            }
        }
    } else {
        let k = root + 1;
        if v == 0.0 && k == 1 {
            edges.push(0);
        }
        if u + v == 1.0 {
            edges.push(k);
        }
        if u == 0.0 && k + 2 == n {
            edges.push(n - 1);
        }
    }
    edges
        .iter()
        .try_fold(0u64, |m, &k| (k < 64).then(|| m | 1 << k))
}
