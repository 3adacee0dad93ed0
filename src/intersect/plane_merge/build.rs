//! Building the merge (Sec. 2): the axial patches grouped by plane and sorted per axis, the
//! sentinels and bucket tables of the three plane lists, each plane's point-location grid and
//! its polygons' edge blocks.

use super::locate::{PlaneGrid, SkewEdges};
use super::{Block, PlaneMerge, CONTINUED, IN_PLANE, NORMAL_POSITIVE};
use crate::mesh::{Mesh, PatchClass};
use glam::{Vec3, Vec4};

/// The sorted plane list of one axis, with a bucket table that finds a coordinate's place in
/// O(1) for evenly spread planes (a bucket, then a step or two).
#[derive(Clone, Debug, Default)]
pub(super) struct AxisList {
    /// First plane of this axis in the global arrays; one past its last.
    pub(super) first: usize,
    pub(super) end: usize,
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
            .filter(|&(i, _)| mesh.is_surface(i)) // back twins are not surfaces (§7)
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
    pub(super) fn lower_bound(&self, axis: usize, x: f32, or_equal: bool) -> usize {
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
}
