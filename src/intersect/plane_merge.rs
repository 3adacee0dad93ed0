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
use crate::mesh::{Mesh, PatchClass};
use glam::{DVec3, Vec3, Vec4};
use std::collections::HashMap;

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

/// How a point relates to one polygon.
#[derive(Clone, Copy)]
struct Test {
    /// Inside by the half-open rules.
    strict: bool,
    /// Within `tol` of it.
    near: bool,
    /// Outside only across seams with skew patches (and within `tol`).
    seam: bool,
}

/// The sorted plane list of one axis, with a bucket table that finds a coordinate's place in
/// O(1) for evenly spread planes (a bucket, then a step or two).
#[derive(Clone, Debug, Default)]
struct AxisList {
    /// First plane of this axis in the global arrays; one past its last.
    first: usize,
    end: usize,
    min: f32,
    /// Buckets per unit length.
    scale: f32,
    /// `buckets[k]`: the first plane (global index) whose bucket is ≥ k.
    buckets: Vec<u32>,
}

impl AxisList {
    #[inline]
    fn bucket(&self, x: f32) -> usize {
        (((x - self.min) * self.scale).max(0.0) as usize).min(self.buckets.len() - 1)
    }
}

/// Point location in one plane: the bounds of its polygons (grown by `tol`) and a uniform grid
/// over them, each cell listing the polygons whose bounds overlap it, in patch-id order.
#[derive(Clone, Copy, Debug)]
struct PlaneGrid {
    /// Cells per unit length along u and v.
    scale: [f32; 2],
    dims: [u32; 2],
    /// This plane's first cell in [`PlaneMerge::cell_start`].
    cell_base: u32,
    /// The plane holds polygons facing both ways (so facing decides between overlaps).
    mixed_facing: bool,
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

/// Grid cells per polygon: enough that a cell holds about one polygon edge-on.
const CELLS_PER_POLY: f64 = 2.0;
/// Buckets per plane in an axis's bucket table.
const BUCKETS_PER_PLANE: usize = 4;
/// Sentinel planes around each axis's list.
const PAD: usize = 1;

impl PlaneMerge {
    /// Sec. 2: sorts the axial patches of `mesh` by plane into three lists, one per axis, and
    /// builds each plane's point-location grid. Skew patches are left out (but their edges are
    /// noted, to seal the seams between the two kinds).
    pub fn build(mesh: &Mesh) -> PlaneMerge {
        // Scene scale: tolerances are relative to it.
        let (mut lo, mut hi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
        for v in &mesh.vertices {
            lo = lo.min(*v);
            hi = hi.max(*v);
        }
        let scale = if mesh.vertices.is_empty() {
            1.0
        } else {
            (hi - lo)
                .length()
                .max(lo.abs().max(hi.abs()).max_element())
                .max(f32::MIN_POSITIVE)
        };
        // Rounding of a crossing point and of the edge coefficients is a few ulps of the
        // scene's scale (about 5e-7 of it); 2e-6 seals cracks of that width with margin.
        let tol = 2e-6 * scale;
        // Planes closer than this are one plane (f32 cannot tell them apart meaningfully).
        let merge_tol = 1e-6 * scale as f64;

        // Sec. 2: the axial patches, keyed by (axis, plane coordinate of their first vertex).
        let mut keyed: Vec<(usize, f32, u32)> = mesh
            .patches
            .iter()
            .enumerate()
            .filter_map(|(i, p)| match p.class {
                PatchClass::Axial(axis) => {
                    let a = axis as usize;
                    let c = mesh.vertices[mesh.patch_indices(i)[0] as usize][a];
                    Some((a, c + 0.0, i as u32)) // + 0.0 turns −0 into +0
                }
                PatchClass::Skew => None,
            })
            .collect();
        keyed.sort_by(|x, y| x.0.cmp(&y.0).then(x.1.total_cmp(&y.1)).then(x.2.cmp(&y.2)));

        let mut me = PlaneMerge {
            coords: Vec::new(),
            bounds: Vec::new(),
            grids: Vec::new(),
            axes: Default::default(),
            cell_start: vec![0],
            cell_items: Vec::new(),
            blocks: Vec::new(),
            patches: 0,
            tol,
            corner_gap: 16.0 * tol,
        };
        let seams = SkewEdges::new(mesh, tol);
        let mut s = 0;
        for axis in 0..3 {
            // Each axis's planes sit between sentinel planes with empty bounds, at −∞ below and
            // +∞ above: t = +∞ whichever way a ray walks into them, which ends its stream.
            me.add_sentinels(f32::NEG_INFINITY);
            let first = me.coords.len();
            while s < keyed.len() && keyed[s].0 == axis {
                // One plane: the run of coordinates within merge_tol of its first, placed at
                // their median (patches cut by interpolation differ from it by an ulp or two).
                let c0 = keyed[s].1;
                let mut e = s;
                while e < keyed.len() && keyed[e].0 == axis && (keyed[e].1 - c0) as f64 <= merge_tol
                {
                    e += 1;
                }
                let c = keyed[(s + e) / 2].1;
                let mut ids: Vec<(u32, f32)> = keyed[s..e].iter().map(|k| (k.2, k.1)).collect();
                ids.sort_unstable_by_key(|k| k.0);
                me.add_plane(mesh, &seams, axis, c, &ids);
                s = e;
            }
            me.axes[axis] = me.axis_list(first);
            me.add_sentinels(f32::INFINITY);
        }
        me
    }

    fn add_sentinels(&mut self, c: f32) {
        for _ in 0..PAD {
            self.coords.push(c);
            self.bounds.push(Vec4::INFINITY);
            self.grids.push(PlaneGrid {
                scale: [0.0; 2],
                dims: [1, 1],
                cell_base: 0,
                mixed_facing: false,
            });
        }
    }

    /// The bucket table over planes `first..` (the planes added last).
    fn axis_list(&self, first: usize) -> AxisList {
        let end = self.coords.len();
        let list = &self.coords[first..end];
        let (min, max) = match (list.first(), list.last()) {
            (Some(&a), Some(&b)) => (a, b),
            _ => (0.0, 0.0),
        };
        let n = (list.len() * BUCKETS_PER_PLANE).max(1);
        let width = ((max - min) as f64).max(f32::MIN_POSITIVE as f64);
        let mut me = AxisList {
            first,
            end,
            min,
            scale: (n as f64 / width) as f32,
            buckets: vec![0; n],
        };
        // buckets[k] = first plane whose bucket is ≥ k (bucket() is monotonic in x).
        let mut k = 0;
        for (i, &c) in list.iter().enumerate() {
            let b = me.bucket(c);
            while k <= b {
                me.buckets[k] = (first + i) as u32;
                k += 1;
            }
        }
        for slot in &mut me.buckets[k..] {
            *slot = end as u32;
        }
        me
    }

    /// The first plane (global index) of `axis` whose coordinate is ≥ x (`or_equal` false) or
    /// > x (`or_equal` true).
    #[inline]
    fn lower_bound(&self, axis: usize, x: f32, or_equal: bool) -> usize {
        let l = &self.axes[axis];
        let below = |c: f32| c < x || (or_equal && c == x);
        // Planes in earlier buckets lie below x; scan the few in x's bucket (a binary search
        // if it holds many: coordinates bunched in a small part of the range).
        let mut i = l.buckets[l.bucket(x)] as usize;
        for _ in 0..8 {
            if i == l.end || !below(self.coords[i]) {
                return i;
            }
            i += 1;
        }
        i + self.coords[i..l.end].partition_point(|&c| below(c))
    }

    /// Adds one plane normal to `axis` at coordinate `c` holding the patches `ids` (ascending,
    /// each with its own plane coordinate).
    fn add_plane(
        &mut self,
        mesh: &Mesh,
        seams: &SkewEdges,
        axis: usize,
        c: f32,
        ids: &[(u32, f32)],
    ) {
        let (u, v) = IN_PLANE[axis];
        let tol = self.tol;
        // The polygons in plane coordinates, with their bounds.
        let mut firsts: Vec<u32> = Vec::with_capacity(ids.len());
        let mut bounds: Vec<[f32; 4]> = Vec::with_capacity(ids.len());
        let mut pts: Vec<[f32; 2]> = Vec::new();
        let (mut pos, mut neg) = (false, false);
        for &(id, coord) in ids {
            let ring = mesh.patch_indices(id as usize);
            let corner = |k: usize| mesh.vertices[ring[k % ring.len()] as usize];
            pts.clear();
            pts.extend((0..ring.len()).map(|k| [corner(k)[u], corner(k)[v]]));
            let normal = mesh.patches[id as usize].normal;
            let normal_positive = normal[axis] > 0.0;
            let Some(first) = self.add_polygon(&pts, id, coord, normal_positive, |k| {
                // Beyond the edge, in the plane: edge × normal (the polygon winds
                // counter-clockwise about its normal, so it lies the other way).
                let (p, q) = (corner(k), corner(k + 1));
                let beyond = (q - p).as_dvec3().cross(normal.as_dvec3());
                seams.touches(p, q, beyond)
            }) else {
                continue; // no area in this plane
            };
            pos |= normal_positive;
            neg |= !normal_positive;
            firsts.push(first);
            let mut b = [f32::MAX, f32::MAX, f32::MIN, f32::MIN];
            for p in &pts {
                b = [
                    b[0].min(p[0]),
                    b[1].min(p[1]),
                    b[2].max(p[0]),
                    b[3].max(p[1]),
                ];
            }
            bounds.push([b[0] - tol, b[1] - tol, b[2] + tol, b[3] + tol]);
        }
        self.patches += firsts.len();
        let n = bounds.len();
        let mut lo = [f32::MAX; 2];
        let mut hi = [f32::MIN; 2];
        for b in &bounds {
            lo = [lo[0].min(b[0]), lo[1].min(b[1])];
            hi = [hi[0].max(b[2]), hi[1].max(b[3])];
        }
        if n == 0 {
            (lo, hi) = ([1.0; 2], [0.0; 2]); // empty: every point is outside
        }
        // Sec. 2, point location: a uniform grid of about CELLS_PER_POLY cells per polygon,
        // shaped like the plane's bounds, so a query costs O(1) whatever the plane holds.
        let w = ((hi[0] - lo[0]) as f64).max(1e-30);
        let h = ((hi[1] - lo[1]) as f64).max(1e-30);
        let cells = (n as f64 * CELLS_PER_POLY).max(1.0);
        let nu = (cells * w / h).sqrt().round().clamp(1.0, cells) as u32;
        let nv = (cells / nu as f64).ceil().clamp(1.0, cells) as u32;
        let scale = [(nu as f64 / w) as f32, (nv as f64 / h) as f32];
        let cell_of = |x: f32, k: usize, d: u32| {
            (((x - lo[k]) * scale[k]).max(0.0) as u32).min(d - 1) as usize
        };
        // Bin the polygons (a counting sort: count, prefix-sum, fill in id order).
        let ncell = (nu * nv) as usize;
        let ranges: Vec<[usize; 4]> = bounds
            .iter()
            .map(|b| {
                [
                    cell_of(b[0], 0, nu),
                    cell_of(b[1], 1, nv),
                    cell_of(b[2], 0, nu),
                    cell_of(b[3], 1, nv),
                ]
            })
            .collect();
        let cells_of = |r: [usize; 4]| {
            (r[1]..=r[3]).flat_map(move |j| (r[0]..=r[2]).map(move |i| j * nu as usize + i))
        };
        let mut count = vec![0u32; ncell + 1];
        for &r in &ranges {
            for k in cells_of(r) {
                count[k + 1] += 1;
            }
        }
        for k in 1..=ncell {
            count[k] += count[k - 1];
        }
        let base = *self.cell_start.last().expect("starts with 0");
        let items_base = self.cell_items.len();
        self.cell_items
            .resize(items_base + count[ncell] as usize, 0);
        let mut fill = count.clone();
        for (&r, &first) in ranges.iter().zip(&firsts) {
            for k in cells_of(r) {
                self.cell_items[items_base + fill[k] as usize] = first;
                fill[k] += 1;
            }
        }
        let cell_base = (self.cell_start.len() - 1) as u32;
        self.cell_start.extend(count[1..].iter().map(|&k| base + k));
        self.coords.push(c);
        self.bounds.push(Vec4::new(lo[0], lo[1], -hi[0], -hi[1]));
        self.grids.push(PlaneGrid {
            scale,
            dims: [nu, nv],
            cell_base,
            mixed_facing: pos && neg,
        });
    }

    /// Appends the blocks of a convex polygon given in plane coordinates (`seam(k)`: the edge
    /// from point k to k + 1 borders a skew patch); returns its first block, or `None` when it
    /// has no area.
    fn add_polygon(
        &mut self,
        pts: &[[f32; 2]],
        patch: u32,
        coord: f32,
        normal_positive: bool,
        seam: impl Fn(usize) -> bool,
    ) -> Option<u32> {
        let m = pts.len();
        let area2: f64 = (0..m)
            .map(|k| {
                let (p, q) = (pts[k], pts[(k + 1) % m]);
                p[0] as f64 * q[1] as f64 - q[0] as f64 * p[1] as f64
            })
            .sum();
        if area2 == 0.0 || !area2.is_finite() {
            return None;
        }
        // (a, b, c, tie, seam) per edge.
        let mut edges: Vec<(f32, f32, f32, bool, bool)> = Vec::with_capacity(m);
        for k in 0..m {
            let (p, q) = (pts[k], pts[(k + 1) % m]);
            if p == q {
                continue;
            }
            // The canonical direction: from the lexicographically smaller end point.
            let forward = (p[0], p[1]) < (q[0], q[1]);
            let (lo, hi) = if forward { (p, q) } else { (q, p) };
            let (du, dv) = ((hi[0] - lo[0]) as f64, (hi[1] - lo[1]) as f64);
            let len = (du * du + dv * dv).sqrt();
            // The left normal of lo→hi: n_v = du ≥ 0, and n_u < 0 when du = 0 — "positive".
            let (a, b) = ((-dv / len) as f32, (du / len) as f32);
            let c = (-(a as f64 * lo[0] as f64 + b as f64 * lo[1] as f64)) as f32;
            // The polygon lies left of each directed edge when counter-clockwise (area > 0).
            // Negating all three coefficients negates the value exactly (IEEE rounding is
            // symmetric), so the neighbour across the edge sees exactly the opposite sign.
            edges.push(if forward == (area2 > 0.0) {
                (a, b, c, true, seam(k))
            } else {
                (-a, -b, -c, false, seam(k))
            });
        }
        let first = self.blocks.len() as u32;
        let chunks = edges.chunks(4).count();
        for (n, chunk) in edges.chunks(4).enumerate() {
            let mut blk = Block {
                a: [0.0; 4],
                b: [0.0; 4],
                c: [1.0; 4],
                patch,
                coord,
                tie: 0,
                seam: 0,
                flags: if normal_positive { NORMAL_POSITIVE } else { 0 }
                    | if n + 1 < chunks { CONTINUED } else { 0 },
            };
            for (lane, &(a, b, c, tie, seam)) in chunk.iter().enumerate() {
                (blk.a[lane], blk.b[lane], blk.c[lane]) = (a, b, c);
                blk.tie |= (tie as u8) << lane;
                blk.seam |= (seam as u8) << lane;
            }
            self.blocks.push(blk);
        }
        Some(first)
    }

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

    /// The point (pu, pv) against the polygon starting at block `k`: all four edges of a block
    /// at once.
    #[inline]
    fn test(&self, mut k: usize, pu: f32, pv: f32) -> Test {
        let mut t = Test {
            strict: true,
            near: true,
            seam: true,
        };
        loop {
            let blk = &self.blocks[k];
            let val = Vec4::from(blk.a) * pu + Vec4::from(blk.b) * pv + Vec4::from(blk.c);
            let positive = val.cmpgt(Vec4::ZERO).bitmask() as u8;
            let zero = val.cmpeq(Vec4::ZERO).bitmask() as u8;
            let inside = positive | (zero & blk.tie);
            let within = val.cmpge(Vec4::splat(-self.tol)).bitmask() as u8;
            t.strict &= inside == 0xF;
            t.near &= within == 0xF;
            t.seam &= !inside & !blk.seam & 0xF == 0;
            if blk.flags & CONTINUED == 0 {
                return t;
            }
            k += 1;
        }
    }

    /// The inward normal (a, b) of the edge of the polygon at block `k` that (pu, pv) lies
    /// furthest outside of. Only asked for near misses, so it need not be fast.
    fn most_violated(&self, mut k: usize, pu: f32, pv: f32) -> (f32, f32) {
        let mut worst = (f32::INFINITY, (0.0, 0.0));
        loop {
            let blk = &self.blocks[k];
            for l in 0..4 {
                let val = blk.a[l] * pu + blk.b[l] * pv + blk.c[l];
                if val < worst.0 {
                    worst = (val, (blk.a[l], blk.b[l]));
                }
            }
            if blk.flags & CONTINUED == 0 {
                return worst.1;
            }
            k += 1;
        }
    }

    /// Sec. 2, point location: the polygon of plane `pi` under the in-plane point (pu, pv), for
    /// a ray whose direction component along the plane's axis is `da` (it decides between
    /// overlapping polygons facing opposite ways).
    #[inline]
    fn locate(&self, pi: usize, pu: f32, pv: f32, da: f32) -> Found<'_> {
        // The caller checked the plane's bounds.
        let g = &self.grids[pi];
        let lo = self.bounds[pi];
        let i = (((pu - lo.x) * g.scale[0]) as u32).min(g.dims[0] - 1);
        let j = (((pv - lo.y) * g.scale[1]) as u32).min(g.dims[1] - 1);
        let cell = (g.cell_base + j * g.dims[0] + i) as usize;
        let items =
            &self.cell_items[self.cell_start[cell] as usize..self.cell_start[cell + 1] as usize];
        let mut back_hit: Option<&Block> = None;
        let mut seam_hit: Option<&Block> = None;
        let mut near: Option<&Block> = None;
        // The inward normals of the edges the near polygons are outside of (a few suffice).
        let mut outside: [(f32, f32); 4] = [(0.0, 0.0); 4];
        let mut near_count = 0;
        let mut crack = false;
        for &k in items {
            let t = self.test(k as usize, pu, pv);
            let blk = &self.blocks[k as usize];
            if t.strict {
                if !g.mixed_facing || !blk.back(da) {
                    return Found::Owner(blk);
                }
                back_hit.get_or_insert(blk);
            } else if t.near {
                if t.seam {
                    seam_hit.get_or_insert(blk);
                }
                near.get_or_insert(blk);
                if !crack {
                    let n = self.most_violated(k as usize, pu, pv);
                    crack = outside[..near_count.min(4)]
                        .iter()
                        .any(|m| m.0 * n.0 + m.1 * n.1 < 0.0);
                    if near_count < 4 {
                        outside[near_count] = n;
                    }
                }
                near_count += 1;
            }
        }
        match (back_hit.or(seam_hit), near) {
            (Some(p), _) => Found::Owner(p),
            (None, Some(p)) => Found::Near(p, crack),
            (None, None) => Found::Nothing,
        }
    }
}

/// What point location found in one plane.
enum Found<'a> {
    /// A polygon owns the point (half-open rules; front-facing, then lowest id, on overlaps),
    /// or the point lies in a seam with a skew patch next to it.
    Owner(&'a Block),
    /// No owner, but polygons lie within `tol` of the point (the lowest id given); `true` when
    /// two of them are outside across edges facing each other — the point is in a sliver
    /// between them, not beyond a free boundary that both end on.
    Near(&'a Block, bool),
    Nothing,
}

/// The edges of the skew patches, hashed on a coarse 3-D grid, to find the axial edges that a
/// skew patch continues across (the seams between the merge's and Embree's halves).
struct SkewEdges {
    cell: f32,
    cells: HashMap<[i32; 3], Vec<u32>>,
    /// Edges too long to hash; checked against every query.
    long: Vec<u32>,
    segs: Vec<(DVec3, DVec3)>,
    /// The normal of each edge's skew patch.
    normals: Vec<DVec3>,
    tol: f64,
}

impl SkewEdges {
    fn new(mesh: &Mesh, tol: f32) -> SkewEdges {
        let mut segs = Vec::new();
        let mut normals = Vec::new();
        for (i, p) in mesh.patches.iter().enumerate() {
            if p.class == PatchClass::Skew {
                let ring = mesh.patch_indices(i);
                for k in 0..ring.len() {
                    let a = mesh.vertices[ring[k] as usize].as_dvec3();
                    let b = mesh.vertices[ring[(k + 1) % ring.len()] as usize].as_dvec3();
                    segs.push((a, b));
                    normals.push(p.normal.as_dvec3());
                }
            }
        }
        let longest = segs
            .iter()
            .map(|(a, b)| (*a - *b).length())
            .fold(0.0, f64::max);
        let cell = (mesh.patch_size as f64)
            .min(longest)
            .max(tol as f64 * 1e3)
            .max(f32::MIN_POSITIVE as f64) as f32;
        let mut me = SkewEdges {
            cell,
            cells: HashMap::new(),
            long: Vec::new(),
            segs,
            normals,
            tol: tol as f64,
        };
        for (k, &(a, b)) in me.segs.iter().enumerate() {
            let (lo, hi) = me.cell_range(a, b);
            let n = (0..3).map(|j| (hi[j] - lo[j] + 1) as i64).product::<i64>();
            if n > 64 {
                me.long.push(k as u32);
                continue;
            }
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    for z in lo[2]..=hi[2] {
                        me.cells.entry([x, y, z]).or_default().push(k as u32);
                    }
                }
            }
        }
        me
    }

    fn cell_range(&self, a: DVec3, b: DVec3) -> ([i32; 3], [i32; 3]) {
        let c = self.cell as f64;
        let t = self.tol;
        let lo = a.min(b) - t;
        let hi = a.max(b) + t;
        let q = |x: f64| (x / c).floor().clamp(i32::MIN as f64, i32::MAX as f64) as i32;
        ([q(lo.x), q(lo.y), q(lo.z)], [q(hi.x), q(hi.y), q(hi.z)])
    }

    /// Does a skew edge run along the segment a–b (collinear within tol, overlapping), of a
    /// skew patch facing away from `beyond` (the in-plane direction out of the axial polygon)?
    /// Only then does a point just beyond the edge lie behind the skew patch, in a crack of a
    /// concave seam (a floor round a turned block's foot, a knee wall under the roof); beyond
    /// a convex edge (the top of a turned block) it lies in front of both, in the open air,
    /// where a ray passing by must miss both.
    fn touches(&self, a: Vec3, b: Vec3, beyond: DVec3) -> bool {
        if self.segs.is_empty() {
            return false;
        }
        let (a, b) = (a.as_dvec3(), b.as_dvec3());
        let along = |(p, q): (DVec3, DVec3), (r, s): (DVec3, DVec3)| {
            // Both ends of r–s on the line of p–q, and the two overlap along it.
            let d = q - p;
            let len2 = d.length_squared();
            if len2 == 0.0 {
                return false;
            }
            let off = |x: DVec3| (x - p - d * ((x - p).dot(d) / len2)).length();
            let (tr, ts) = ((r - p).dot(d) / len2, (s - p).dot(d) / len2);
            let slack = self.tol / len2.sqrt();
            off(r) <= self.tol
                && off(s) <= self.tol
                && tr.max(ts) > slack
                && tr.min(ts) < 1.0 - slack
        };
        let hit = |k: &u32| {
            let e = self.segs[*k as usize];
            self.normals[*k as usize].dot(beyond) < 0.0 && (along((a, b), e) || along(e, (a, b)))
        };
        if self.long.iter().any(hit) {
            return true;
        }
        let (lo, hi) = self.cell_range(a, b);
        if (0..3).map(|j| (hi[j] - lo[j] + 1) as i64).product::<i64>() > 4096 {
            return self.segs.iter().enumerate().any(|(k, _)| hit(&(k as u32)));
        }
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    if self
                        .cells
                        .get(&[x, y, z])
                        .is_some_and(|v| v.iter().any(hit))
                    {
                        return true;
                    }
                }
            }
        }
        false
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{Axis, Patch};
    use glam::{vec3, Vec3};

    /// Two unit quads side by side in z = 0 (sharing the edge x = 1), facing +z.
    fn two_quads() -> Mesh {
        let vertices = vec![
            vec3(0., 0., 0.),
            vec3(1., 0., 0.),
            vec3(2., 0., 0.),
            vec3(0., 1., 0.),
            vec3(1., 1., 0.),
            vec3(2., 1., 0.),
        ];
        let quad = |first: u32, cx: f32| Patch {
            first,
            count: 4,
            material: 0,
            polygon: 0,
            area: 1.0,
            centre: vec3(cx, 0.5, 0.0),
            normal: Vec3::Z,
            class: PatchClass::Axial(Axis::Z),
        };
        Mesh {
            vertices,
            patch_vertices: vec![0, 1, 4, 3, 1, 2, 5, 4],
            patches: vec![quad(0, 0.5), quad(4, 1.5)],
            patch_size: 1.0,
        }
    }

    fn ray(org: Vec3, dir: Vec3) -> Ray {
        Ray {
            org,
            dir,
            tnear: 0.0,
            tfar: f32::INFINITY,
        }
    }

    #[test]
    fn a_point_on_a_shared_edge_belongs_to_exactly_one_quad() {
        let m = PlaneMerge::build(&two_quads());
        assert_eq!(m.plane_counts(), [0, 0, 1]);
        for y in [0.0, 0.25, 0.5, 1.0 - f32::EPSILON] {
            let h = m.intersect(&ray(vec3(1.0, y, 1.0), -Vec3::Z)).unwrap();
            assert!(h.patch == 0 || h.patch == 1);
            assert_eq!(h.t, 1.0);
            assert!(!h.back);
        }
        let h = m.intersect(&ray(vec3(0.5, 0.5, -1.0), Vec3::Z)).unwrap();
        assert_eq!((h.patch, h.back), (0, true));
    }

    #[test]
    fn tnear_and_tfar_bound_the_walk() {
        let m = PlaneMerge::build(&two_quads());
        let mut r = ray(vec3(1.5, 0.5, 1.0), -Vec3::Z);
        r.tfar = 0.999;
        assert!(m.intersect(&r).is_none());
        r.tfar = 1.0;
        assert_eq!(m.intersect(&r).map(|h| h.patch), Some(1));
        r.tnear = 1.0;
        assert!(
            m.intersect(&r).is_none(),
            "planes at t = tnear are not taken"
        );
        // Starting on the plane: it is behind (t = 0) either way the ray leaves.
        assert!(m.intersect(&ray(vec3(0.5, 0.5, 0.0), Vec3::Z)).is_none());
        assert!(m.intersect(&ray(vec3(0.5, 0.5, 0.0), -Vec3::Z)).is_none());
    }

    /// A 5 × 5 grid of quads in y = 2 (facing −y) and a fan of 12 triangles round a point, in
    /// x = 0: arbitrary edge directions.
    fn grid_and_fan() -> Mesh {
        let mut m = Mesh::default();
        let push = |m: &mut Mesh, pts: &[Vec3], normal: Vec3, axis: Axis| {
            let first = m.patch_vertices.len() as u32;
            for p in pts {
                m.patch_vertices.push(m.vertices.len() as u32);
                m.vertices.push(*p);
            }
            m.patches.push(Patch {
                first,
                count: pts.len() as u32,
                material: 0,
                polygon: 0,
                area: 1.0,
                centre: pts[0],
                normal,
                class: PatchClass::Axial(axis),
            });
        };
        let g = |i: u32| i as f32 * 0.3;
        for j in 0..5 {
            for i in 0..5 {
                // Counter-clockwise seen from −y: (x, z) turning clockwise in the x–z plane.
                let q = [
                    vec3(g(i), 2.0, g(j)),
                    vec3(g(i), 2.0, g(j + 1)),
                    vec3(g(i + 1), 2.0, g(j + 1)),
                    vec3(g(i + 1), 2.0, g(j)),
                ];
                push(&mut m, &q, -Vec3::Y, Axis::Y);
            }
        }
        let centre = vec3(0.0, 0.123, -0.31);
        let rim = |k: u32| {
            let a = (k % 12) as f32 * std::f32::consts::TAU / 12.0;
            centre + vec3(0.0, a.cos(), a.sin()) * 0.7
        };
        for k in 0..12 {
            push(&mut m, &[centre, rim(k), rim(k + 1)], Vec3::X, Axis::X);
        }
        m
    }

    /// The patches whose polygons own the in-plane point (pu, pv) strictly, over all planes.
    fn owners(m: &PlaneMerge, pu: f32, pv: f32) -> Vec<u32> {
        let mut firsts: Vec<u32> = m.cell_items.clone();
        firsts.sort_unstable();
        firsts.dedup();
        firsts
            .into_iter()
            .filter(|&k| m.test(k as usize, pu, pv).strict)
            .map(|k| m.blocks[k as usize].patch)
            .collect()
    }

    #[test]
    fn shared_edges_and_vertices_have_exactly_one_strict_owner() {
        let mesh = grid_and_fan();
        let m = PlaneMerge::build(&mesh);
        assert_eq!(m.plane_counts(), [1, 1, 0]);
        let g = |i: u32| i as f32 * 0.3;
        // Grid (plane y = 2; u = z, v = x): every point on an inner grid line, vertices too.
        for a in 1..5 {
            for b in 1..50 {
                // Inside the grid's span (0, 1.5), through the inner vertices (k·0.3) too.
                let along = if b % 10 == 0 {
                    g(b / 10)
                } else {
                    0.03 * b as f32
                };
                for (x, z) in [(a as f32 * 0.3, along), (along, a as f32 * 0.3)] {
                    let own: Vec<u32> = owners(&m, z, x).into_iter().filter(|&p| p < 25).collect();
                    assert_eq!(own.len(), 1, "({x}, {z}) owned by {own:?}");
                }
            }
        }
        // Fan (plane x = 0; u = y, v = z): points along each spoke, and the hub itself.
        let hub = (0.123f32, -0.31f32);
        for k in 0..12 {
            let a = k as f32 * std::f32::consts::TAU / 12.0;
            let rim = (hub.0 + a.cos() * 0.7, hub.1 + a.sin() * 0.7);
            for s in 0..20 {
                let f = s as f32 / 20.0;
                // The spoke's points as the merge would meet them: rounded interpolations.
                let p = (hub.0 + (rim.0 - hub.0) * f, hub.1 + (rim.1 - hub.1) * f);
                let own: Vec<u32> = owners(&m, p.0, p.1)
                    .into_iter()
                    .filter(|&p| p >= 25)
                    .collect();
                // Rounding may move a point off the spoke: then it is strictly inside one
                // triangle. On it, the half-open rule gives it to exactly one.
                assert_eq!(own.len(), 1, "spoke {k} at {f}: {own:?}");
            }
        }
    }

    #[test]
    fn bucket_table_finds_places_like_a_binary_search() {
        // 40 planes bunched near z = 0 (many per bucket) and a few far away.
        let mut m = Mesh::default();
        let zs: Vec<f32> = (0..40)
            .map(|k| k as f32 * 1e-3)
            .chain([5.0, 7.5, 100.0])
            .collect();
        for &z in &zs {
            let first = m.patch_vertices.len() as u32;
            for (x, y) in [(0., 0.), (1., 0.), (1., 1.), (0., 1.)] {
                m.patch_vertices.push(m.vertices.len() as u32);
                m.vertices.push(vec3(x, y, z));
            }
            m.patches.push(Patch {
                first,
                count: 4,
                material: 0,
                polygon: 0,
                area: 1.0,
                centre: vec3(0.5, 0.5, z),
                normal: Vec3::Z,
                class: PatchClass::Axial(Axis::Z),
            });
        }
        let pm = PlaneMerge::build(&m);
        assert_eq!(pm.plane_counts(), [0, 0, zs.len()]);
        let l = &pm.axes[2];
        let list = &pm.coords[l.first..l.end];
        for k in -10i32..2000 {
            let x = k as f32 * 0.06 - 0.5 + (k % 7) as f32 * 1e-4;
            for x in [x, zs[(k.unsigned_abs() as usize) % zs.len()]] {
                for or_equal in [false, true] {
                    let want = l.first + list.partition_point(|&c| c < x || (or_equal && c == x));
                    assert_eq!(pm.lower_bound(2, x, or_equal), want, "x = {x}");
                }
            }
        }
    }
}
