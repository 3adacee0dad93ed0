//! Point location in one plane (Sec. 2) and the crack rules: the uniform grid over a plane's
//! polygons, the half-open edge tests with their `tol` margin, the in-plane crack test, and the
//! skew edges that mark the seams between the merge's and Embree's halves.

use super::{Block, PlaneMerge, CONTINUED};
use crate::mesh::{Mesh, PatchClass};
use glam::{DVec3, Vec3, Vec4};
use std::collections::HashMap;

/// How a point relates to one polygon.
#[derive(Clone, Copy)]
pub(super) struct Test {
    /// Inside by the half-open rules.
    pub(super) strict: bool,
    /// Within `tol` of it.
    near: bool,
    /// Outside only across seams with skew patches (and within `tol`).
    seam: bool,
}

/// Point location in one plane: the bounds of its polygons (grown by `tol`) and a uniform grid
/// over them, each cell listing the polygons whose bounds overlap it, in patch-id order.
#[derive(Clone, Copy, Debug)]
pub(super) struct PlaneGrid {
    /// Cells per unit length along u and v.
    pub(super) scale: [f32; 2],
    pub(super) dims: [u32; 2],
    /// This plane's first cell in [`PlaneMerge::cell_start`].
    pub(super) cell_base: u32,
    /// The plane holds polygons facing both ways (so facing decides between overlaps).
    pub(super) mixed_facing: bool,
}

impl PlaneMerge {
    /// The point (pu, pv) against the polygon starting at block `k`: all four edges of a block
    /// at once.
    #[inline]
    pub(super) fn test(&self, mut k: usize, pu: f32, pv: f32) -> Test {
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
    pub(super) fn locate(&self, pi: usize, pu: f32, pv: f32, da: f32) -> Found<'_> {
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
pub(super) enum Found<'a> {
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
pub(super) struct SkewEdges {
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
    pub(super) fn new(mesh: &Mesh, tol: f32) -> SkewEdges {
        let mut segs = Vec::new();
        let mut normals = Vec::new();
        for (i, p) in mesh.patches.iter().enumerate() {
            if p.class == PatchClass::Skew && mesh.is_surface(i) {
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
    pub(super) fn touches(&self, a: Vec3, b: Vec3, beyond: DVec3) -> bool {
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
