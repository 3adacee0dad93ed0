//! Planar geometry in whole millimetres: rectangles with holes cut out, axis planes, turned
//! footprints and the triangles that fill their bounding boxes.

use super::*;

/// A rectangle in a plane's (u, v) coordinates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct R2 {
    pub(super) u0: i64,
    pub(super) u1: i64,
    pub(super) v0: i64,
    pub(super) v1: i64,
}

pub(super) const fn r2(u0: i64, u1: i64, v0: i64, v1: i64) -> R2 {
    R2 { u0, u1, v0, v1 }
}

impl R2 {
    pub(super) fn overlaps(&self, o: &R2) -> bool {
        self.u0 < o.u1 && o.u0 < self.u1 && self.v0 < o.v1 && o.v0 < self.v1
    }
    pub(super) fn grown(&self, d: i64) -> R2 {
        r2(self.u0 - d, self.u1 + d, self.v0 - d, self.v1 + d)
    }
    pub(super) fn transposed(&self) -> R2 {
        r2(self.v0, self.v1, self.u0, self.u1)
    }
}

/// An interval [a, b).
pub(super) type Span = (i64, i64);

/// `r` minus the `holes`, as rectangles: slabs between the holes' u-edges, the free
/// v-intervals of each, neighbouring slabs with the same free intervals merged.
pub(super) fn cut(r: R2, holes: &[R2]) -> Vec<R2> {
    let hs: Vec<R2> = holes
        .iter()
        .map(|h| {
            r2(
                h.u0.max(r.u0),
                h.u1.min(r.u1),
                h.v0.max(r.v0),
                h.v1.min(r.v1),
            )
        })
        .filter(|h| h.u1 > h.u0 && h.v1 > h.v0)
        .collect();
    let mut br: Vec<i64> = vec![r.u0, r.u1];
    br.extend(hs.iter().flat_map(|h| [h.u0, h.u1]));
    br.sort_unstable();
    br.dedup();
    // (u0, u1, free v-intervals) of each slab.
    let mut slabs: Vec<(i64, i64, Vec<Span>)> = Vec::new();
    for w in br.windows(2) {
        let (a, b) = (w[0], w[1]);
        let mut cov: Vec<(i64, i64)> = hs
            .iter()
            .filter(|h| h.u0 <= a && h.u1 >= b)
            .map(|h| (h.v0, h.v1))
            .collect();
        cov.sort_unstable();
        let mut free = Vec::new();
        let mut cur = r.v0;
        for (c0, c1) in cov {
            if c0 > cur {
                free.push((cur, c0));
            }
            cur = cur.max(c1);
        }
        if r.v1 > cur {
            free.push((cur, r.v1));
        }
        match slabs.last_mut() {
            Some(last) if last.2 == free => last.1 = b,
            _ => slabs.push((a, b, free)),
        }
    }
    slabs
        .into_iter()
        .flat_map(|(a, b, free)| free.into_iter().map(move |(f0, f1)| r2(a, b, f0, f1)))
        .collect()
}

/// An axis-aligned plane: normal along `axis`; (u, v) = (x, z) for y, (z, y) for x, (x, y) for z.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Axis {
    X,
    Y,
    Z,
}

pub(super) fn to3(axis: Axis, c: i64, u: i64, v: i64) -> P3 {
    match axis {
        Axis::X => [c, v, u],
        Axis::Y => [u, c, v],
        Axis::Z => [u, v, c],
    }
}

pub(super) fn axis_dir(axis: Axis, sign: i64) -> [f64; 3] {
    let s = sign as f64;
    match axis {
        Axis::X => [s, 0.0, 0.0],
        Axis::Y => [0.0, s, 0.0],
        Axis::Z => [0.0, 0.0, s],
    }
}

/// A triangle in a plane's (u, v) coordinates.
pub(super) type T2 = [[i64; 2]; 3];

/// What stands on a floor: its footprint's bounding box and, for a turned block, the four
/// triangles that fill the box around the footprint.
pub(super) struct Footprint {
    pub(super) bbox: R2,
    pub(super) fills: Vec<T2>,
}

/// Holes and fills that cut a floor around the furniture standing on it.
pub(super) fn floor_cuts(placed: &[Footprint]) -> (Vec<R2>, Vec<T2>) {
    let holes = placed.iter().map(|f| f.bbox).collect();
    let fills = placed
        .iter()
        .flat_map(|f| f.fills.iter().copied())
        .collect();
    (holes, fills)
}

/// Corners of a w × d rectangle centred at (cx, cz) turned by `deg` about y, in whole mm.
pub(super) fn footprint(cx: i64, cz: i64, w: i64, d: i64, deg: f64) -> [[i64; 2]; 4] {
    let (s, c) = deg.to_radians().sin_cos();
    let (hw, hd) = (w as f64 / 2.0, d as f64 / 2.0);
    [(-hw, -hd), (hw, -hd), (hw, hd), (-hw, hd)].map(|(u, v)| {
        [
            cx + (u * c - v * s).round() as i64,
            cz + (u * s + v * c).round() as i64,
        ]
    })
}

pub(super) fn bbox(foot: &[[i64; 2]; 4]) -> R2 {
    let xs = foot.map(|p| p[0]);
    let zs = foot.map(|p| p[1]);
    r2(
        *xs.iter().min().unwrap_or(&0),
        *xs.iter().max().unwrap_or(&0),
        *zs.iter().min().unwrap_or(&0),
        *zs.iter().max().unwrap_or(&0),
    )
}

/// The bounding box of a turned footprint minus the footprint: one triangle per edge, between
/// the edge and the box corner outside it.
pub(super) fn corner_fills(foot: &[[i64; 2]; 4], bb: &R2) -> Vec<T2> {
    let centre = [
        foot.iter().map(|p| p[0] as f64).sum::<f64>() / 4.0,
        foot.iter().map(|p| p[1] as f64).sum::<f64>() / 4.0,
    ];
    let side = |a: [i64; 2], b: [i64; 2], p: [f64; 2]| {
        (b[0] - a[0]) as f64 * (p[1] - a[1] as f64) - (b[1] - a[1]) as f64 * (p[0] - a[0] as f64)
    };
    let mut out = Vec::with_capacity(4);
    for k in 0..4 {
        let (a, b) = (foot[k], foot[(k + 1) % 4]);
        let inner = side(a, b, centre);
        for corner in [[a[0], b[1]], [b[0], a[1]]] {
            let on_box = (corner[0] == bb.u0 || corner[0] == bb.u1)
                && (corner[1] == bb.v0 || corner[1] == bb.v1);
            let s = side(a, b, [corner[0] as f64, corner[1] as f64]);
            if on_box && s * inner < 0.0 {
                out.push([a, b, corner]);
                break;
            }
        }
    }
    out
}
