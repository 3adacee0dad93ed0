//! Faces → planar convex pieces: a face that is already planar and convex stays whole, any
//! other (non-planar, non-convex) is triangulated by ear clipping first.

use super::newell;
use glam::Vec3;

/// Splits a face into planar convex pieces: itself when it already is one, else triangles
/// (ear clipping in the plane of its Newell normal).
pub(super) fn planar_convex_pieces(pts: &[Vec3]) -> Vec<Vec<Vec3>> {
    let n = newell(pts);
    if pts.len() == 3 || (is_planar(pts, n) && is_convex(pts, n)) {
        return vec![pts.to_vec()];
    }
    ear_clip(pts, n)
}

fn is_planar(pts: &[Vec3], n: Vec3) -> bool {
    let n = n.normalize_or_zero();
    let c = pts.iter().copied().sum::<Vec3>() / pts.len() as f32;
    let diam = pts.iter().map(|p| (*p - c).length()).fold(0.0f32, f32::max);
    pts.iter()
        .all(|p| (*p - c).dot(n).abs() <= 1e-4 * diam.max(f32::MIN_POSITIVE))
}

fn is_convex(pts: &[Vec3], n: Vec3) -> bool {
    let m = pts.len();
    (0..m).all(|k| {
        let a = pts[k];
        let b = pts[(k + 1) % m];
        let c = pts[(k + 2) % m];
        (b - a).cross(c - b).dot(n) >= -1e-9 * n.length_squared()
    })
}

/// Ear clipping of a simple polygon, projected onto the plane of its normal `n`.
fn ear_clip(pts: &[Vec3], n: Vec3) -> Vec<Vec<Vec3>> {
    let n = n.normalize_or_zero();
    let u = n.any_orthonormal_vector();
    let v = n.cross(u);
    let p2: Vec<glam::DVec2> = pts
        .iter()
        .map(|p| glam::dvec2(p.dot(u) as f64, p.dot(v) as f64))
        .collect();
    let cross = |a: glam::DVec2, b: glam::DVec2, c: glam::DVec2| (b - a).perp_dot(c - a);
    let mut idx: Vec<usize> = (0..pts.len()).collect();
    let mut out = Vec::new();
    let mut guard = 0;
    while idx.len() > 3 && guard < 10 * pts.len() {
        guard += 1;
        let m = idx.len();
        let mut clipped = false;
        for k in 0..m {
            let (ia, ib, ic) = (idx[(k + m - 1) % m], idx[k], idx[(k + 1) % m]);
            let (a, b, c) = (p2[ia], p2[ib], p2[ic]);
            if cross(a, b, c) <= 0.0 {
                continue; // reflex corner
            }
            let inside = idx.iter().any(|&j| {
                j != ia
                    && j != ib
                    && j != ic
                    && cross(a, b, p2[j]) >= 0.0
                    && cross(b, c, p2[j]) >= 0.0
                    && cross(c, a, p2[j]) >= 0.0
            });
            if !inside {
                out.push(vec![pts[ia], pts[ib], pts[ic]]);
                idx.remove(k);
                clipped = true;
                break;
            }
        }
        if !clipped {
            break;
        }
    }
    if idx.len() >= 3 {
        // What is left (a triangle, or a degenerate remainder): fan it.
        for k in 1..idx.len() - 1 {
            out.push(vec![pts[idx[0]], pts[idx[k]], pts[idx[k + 1]]]);
        }
    }
    out
}
