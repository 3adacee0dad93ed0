//! The paper's intersector for axis-aligned polygons: three sorted plane lists walked by a
//! three-way merge (Airey & Ouh-young 1989, Sec. 2, Fig. 4; docs/design.md §4).
//!
//! Polygons normal to x, y or z are grouped by plane and the planes sorted by coordinate, one
//! list per axis. A ray crosses the planes of one list in coordinate order (ascending when its
//! direction component is positive, descending when negative), so each list yields its crossing
//! parameters t already sorted; merging the three streams visits every candidate plane in
//! increasing t. At each plane a uniform 2-D grid over that plane's polygons finds the polygon
//! under the crossing point; the first plane with one is the closest hit. Only axial patches
//! are here — [`super::hybrid::Hybrid`] adds the skew ones.
//!
//! **Which points belong to a polygon.** Each polygon is stored as the half-planes of its
//! edges, `a·u + b·v + c ≥ 0` inside, with (a, b) of unit length. A point lies in a polygon when
//! every edge value is positive, or zero on an edge whose inward normal is "positive" (n_v > 0,
//! or n_v = 0 and n_u < 0). That is the same as testing the point moved by an infinitesimal
//! fixed offset, so on an edge shared by two polygons of one plane exactly one of them owns the
//! point. To make the zero test exact on both sides, an edge's coefficients are computed once
//! from its end points in a canonical order (lexicographically smallest first) and the polygon
//! on the other side stores their negation — IEEE rounding is symmetric, so it evaluates to
//! exactly the negated value. Axis-parallel edges (b = 0 or a = 0) are evaluated exactly.
//!
//! **Cracks.** Meshes are not watertight in floating point: a T-junction (a big patch beside
//! two small ones, whose interpolated vertices sit an ulp off the big one's edge) leaves a
//! sliver, and where two planes meet at a corner both rounded crossing points can land just
//! outside their polygons. Aimed at such seams, a strict test lets a few per cent of rays
//! through (measured). So a point outside every polygon of its plane but within `tol` (2e-6 of
//! the scene size, a few ulps) of one is still a hit when it lies in a crack:
//! - *in-plane*: two polygons of the plane are that near and the point is outside them across
//!   edges that face each other (a sliver between them, or a gap at a vertex). Two polygons
//!   that end on one free boundary (a floor's edge at a stair hole) are both near a point just
//!   beyond their common vertex, but across edges facing the same way: that is not a crack,
//!   and counting it as one made the merge hit floors the oracle's rays pass by (see the test
//!   `a_ray_just_beyond_two_patches_ending_on_one_free_edge_misses_them`);
//! - *corner*: two perpendicular planes, crossed within `corner_gap` of each other, both have a
//!   single near polygon, and the ray crosses both the same way (front to back, or back to
//!   front) — it is slipping through a concave corner. A ray passing *outside* a convex edge
//!   (a table top's rim) crosses one plane each way, and is not caught: so free edges keep
//!   their exact extent and the merge agrees with the f64 oracle there;
//! - *seam*: the polygon is only outside across edges that a skew patch continues in a concave
//!   seam (found at build time: the skew patch faces away from the polygon's side of the
//!   edge): the other side is Embree's, which cannot report its own near miss. Across a
//!   convex edge (the top of a turned block) the point is in the open air beyond both, and
//!   sealing it made the merge hit block tops the oracle's rays passed by (about 1.5 per 10⁵
//!   rays in a generated building of 100 k patches).
//!
//! Such hits lie within `tol` of an edge: the cross-check classifies them as "edge".
//!
//! **Coplanar overlapping polygons.** The polygon whose front faces the ray wins (a two-sided
//! thin surface has a patch per side, and the ray should reach the one facing it), then the
//! lowest patch id; a plane whose polygons all face one way stops at the first (lowest id).
//!
//! **Interval.** Planes are taken for tnear < t ≤ tfar: a ray starting exactly on a plane does
//! not see that plane at t = 0, whichever way it leaves. The solver offsets its origins along
//! the normal anyway (and skips its own shooter), so this only matters for callers that start
//! rays on surfaces.

use super::{Hit, Intersector, Ray};
use glam::Vec4;

mod build;
mod locate;
#[cfg(test)]
mod tests;

use build::AxisList;
use locate::{Found, PlaneGrid};

/// Up to four edge half-planes `a·u + b·v + c ≥ 0` of one polygon, in its plane's (u, v)
/// coordinates, laid out for one SIMD evaluation and one cache line. A polygon of more than
/// four edges continues in the next block. Unused lanes hold 0·u + 0·v + 1 (always inside).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Block {
    a: [f32; 4],
    b: [f32; 4],
    c: [f32; 4],
    patch: u32,
    /// The patch's own plane coordinate (its plane's may differ by an ulp or two): hit
    /// distances are computed from it, so grazing rays get the oracle's t.
    coord: f32,
    /// Lane bits: a point exactly on the edge line belongs to this polygon.
    tie: u8,
    /// Lane bits: a skew patch continues the surface across this edge (module docs: cracks).
    seam: u8,
    /// [`NORMAL_POSITIVE`] | [`CONTINUED`].
    flags: u8,
}

/// The patch normal points along +axis.
const NORMAL_POSITIVE: u8 = 1;
/// The polygon's edges continue in the next block.
const CONTINUED: u8 = 2;

impl Block {
    /// Does a ray with direction component `da` along the plane's axis meet the back?
    #[inline]
    fn back(&self, da: f32) -> bool {
        if self.flags & NORMAL_POSITIVE != 0 {
            da > 0.0
        } else {
            da < 0.0
        }
    }
}

/// The three sorted plane lists and their point-location grids, in flat arrays.
pub struct PlaneMerge {
    /// Plane coordinates, ascending within each axis's range.
    coords: Vec<f32>,
    /// Per plane, the bounds of its polygons (grown by `tol`). Kept apart from the grids: the
    /// walk reads them for every plane it crosses, the grids only for the few it may hit.
    /// As [u_lo, v_lo, −u_hi, −v_hi]: one SIMD compare with [u, v, −u, −v].
    bounds: Vec<Vec4>,
    grids: Vec<PlaneGrid>,
    axes: [AxisList; 3],
    /// Cell `k` of all planes lists `cell_items[cell_start[k]..cell_start[k + 1]]`.
    cell_start: Vec<u32>,
    /// The first block of each polygon listed.
    cell_items: Vec<u32>,
    blocks: Vec<Block>,
    patches: usize,
    /// How far outside a polygon a crossing point may fall and still hit it when it falls in a
    /// crack (see the module docs).
    tol: f32,
    /// How far apart (along the ray) two near misses may be and still be one corner crack.
    corner_gap: f32,
}

/// The two in-plane coordinates (u, v) for planes normal to each axis.
const IN_PLANE: [(usize, usize); 3] = [(1, 2), (2, 0), (0, 1)];

impl PlaneMerge {
    /// No axial patches: every ray misses.
    pub fn is_empty(&self) -> bool {
        self.patches == 0
    }

    /// Number of axial patches held.
    pub fn patch_count(&self) -> usize {
        self.patches
    }

    /// Number of distinct planes per axis (x, y, z).
    pub fn plane_counts(&self) -> [usize; 3] {
        [0, 1, 2].map(|a| self.axes[a].end - self.axes[a].first)
    }
}

/// What one walk through the planes did (for `radiosity bench intersect`, to see where the
/// merge's time goes): planes whose crossing point was tested, and point locations inside a
/// plane's bounds.
#[derive(Clone, Copy, Debug, Default)]
pub struct WalkCount {
    pub planes: u64,
    pub locates: u64,
}

/// Counts the work of a walk, or not: the solver's path uses [`NoCount`], which compiles away.
pub trait Counter {
    fn plane(&mut self);
    fn locate(&mut self);
}

/// No counting (the solver's path).
pub struct NoCount;

impl Counter for NoCount {
    #[inline(always)]
    fn plane(&mut self) {}
    #[inline(always)]
    fn locate(&mut self) {}
}

impl Counter for WalkCount {
    #[inline]
    fn plane(&mut self) {
        self.planes += 1;
    }
    #[inline]
    fn locate(&mut self) {
        self.locates += 1;
    }
}

impl PlaneMerge {
    /// [`Intersector::intersect`] that also counts its work into `count`.
    pub fn intersect_counted(&self, ray: &Ray, count: &mut WalkCount) -> Option<Hit> {
        self.walk(ray, count)
    }

    /// Sec. 2, Fig. 4: the three-way merge. Each axis the ray is not parallel to contributes
    /// its planes in crossing order; the stream with the smallest next t is tested and advanced
    /// until a plane has a polygon under the crossing point or t passes tfar.
    #[allow(clippy::neg_cmp_op_on_partial_ord)] // `!(x <= y)`: NaN must fail these tests
    #[inline]
    fn walk<C: Counter>(&self, ray: &Ray, count: &mut C) -> Option<Hit> {
        let o = ray.org.to_array();
        let d = ray.dir.to_array();
        let mut inv = [0.0f32; 3];
        // Per axis: the next plane's index and the walking direction (±1), and the next
        // plane's t (∞ once exhausted).
        let mut next = [0isize; 3];
        let mut step = [0isize; 3];
        let mut tn = [f32::INFINITY; 3];
        // Each list: find the first plane beyond tnear in the ray's direction.
        for a in 0..3 {
            let l = &self.axes[a];
            if !(d[a].abs() >= f32::MIN_POSITIVE) || l.first == l.end {
                continue; // parallel to this axis's planes (or a subnormal/NaN component)
            }
            inv[a] = 1.0 / d[a];
            // With tnear = 0 (the usual case) a plane is ahead exactly when its coordinate is
            // beyond the origin's: c − o rounds to a value of the same sign, so t > 0. Else
            // start one plane early and let the t test settle the rounding of o + tnear·d.
            let exact = ray.tnear == 0.0;
            let c0 = o[a] + ray.tnear * d[a];
            let (mut i, di, end) = if d[a] > 0.0 {
                let k = self.lower_bound(a, c0, true);
                let k = if exact { k } else { k.max(l.first + 1) - 1 };
                (k as isize, 1, l.end as isize)
            } else {
                let k = self.lower_bound(a, c0, false) as isize - 1;
                let k = if exact {
                    k
                } else {
                    (k + 1).min(l.end as isize - 1)
                };
                (k, -1, l.first as isize - 1)
            };
            while i != end {
                let t = (self.coords[i as usize] - o[a]) * inv[a];
                if t > ray.tnear {
                    tn[a] = t;
                    break;
                }
                i += di;
            }
            (next[a], step[a]) = (i, di);
        }
        // A near miss waiting for its partner across a corner: (t, polygon, axis).
        let mut pending: Option<(f32, &Block, usize)> = None;
        let dlen = ray.dir.length();
        let hit = |p: &Block, a: usize, t: f32| {
            // The distance to the patch's own plane, unless that leaves (tnear, tfar].
            let tp = (p.coord - o[a]) * inv[a];
            Some(Hit {
                patch: p.patch,
                t: if tp > ray.tnear && tp <= ray.tfar {
                    tp
                } else {
                    t
                },
                back: p.back(d[a]),
            })
        };
        // The merge: always the stream whose next plane is nearest. That stream is then walked
        // on its own for as long as it stays nearest: most planes fail the bounds test.
        loop {
            let a01 = if tn[1] < tn[0] { 1 } else { 0 };
            let a = if tn[2] < tn[a01] { 2 } else { a01 };
            let mut t = tn[a];
            if !(t <= ray.tfar) || t == f32::INFINITY {
                return None;
            }
            let (b, c) = ((a + 1) % 3, (a + 2) % 3);
            let bound = tn[b].min(tn[c]).min(ray.tfar);
            let (u, v) = IN_PLANE[a];
            let mut i = next[a];
            loop {
                let pi = i as usize;
                let pu = o[u] + t * d[u];
                let pv = o[v] + t * d[v];
                count.plane();
                // The plane's bounds (NaN falls outside), then its grid.
                let p = Vec4::new(pu, pv, -pu, -pv);
                if p.cmpge(self.bounds[pi]).bitmask() == 0xF {
                    count.locate();
                    match self.locate(pi, pu, pv, d[a]) {
                        Found::Nothing => {}
                        Found::Owner(p) => return hit(p, a, t),
                        // In-plane crack: a sliver between polygons (T-junction), a vertex.
                        Found::Near(p, true) => return hit(p, a, t),
                        Found::Near(p, _) => match pending {
                            // Corner crack: near misses on two perpendicular planes at the
                            // same place, crossed the same way (both front to back: leaving
                            // through a concave corner). Passing by a convex edge crosses
                            // one plane each way.
                            Some((tq, q, aq))
                                if aq != a
                                    && q.back(d[aq]) == p.back(d[a])
                                    && (t - tq) * dlen <= self.corner_gap =>
                            {
                                return hit(q, aq, tq)
                            }
                            _ => pending = Some((t, p, a)),
                        },
                    }
                }
                // The next plane; a sentinel (at ±∞) gives t = +∞ and ends the stream.
                i += step[a];
                t = (self.coords[i as usize] - o[a]) * inv[a];
                if !(t <= bound) || t == f32::INFINITY {
                    next[a] = i;
                    tn[a] = t;
                    break;
                }
            }
        }
    }
}

impl Intersector for PlaneMerge {
    #[inline]
    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.walk(ray, &mut NoCount)
    }

    fn name(&self) -> &'static str {
        "merge"
    }
}
