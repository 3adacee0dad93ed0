//! Contacts (docs/design.md §7): where a face lies on another one facing it — a keyboard on a
//! desk, a cabinet on the floor, a shelf's back on the wall, as exported models leave them
//! (nothing is cut where it touches). The two faces are coincident and opposite; the part of
//! each under the other is *covered*: no light reaches it, and a ray cast from it would start
//! inside the object on top. Ray casting cannot tell which of two coincident faces it meets, so
//! the contacts are found from the geometry: axis-aligned surface patches (nearly every face of
//! a building and its furniture) in one plane, facing opposite ways, overlapping in it.
//!
//! Used by the shooting (a ray is not cast from a covered point: the shot's light leaves its
//! open part) and by the hidden-side probes (a probe that meets the front of a face where it is
//! covered has met the object on top from inside).

use super::Mesh;
use glam::{Vec2, Vec3};
use std::collections::HashMap;

/// The contacts of a mesh's axis-aligned surface patches: for each patch in contact, the
/// patches lying on it facing the other way, as convex rings in the plane's two coordinates.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Contacts {
    /// Patch → index into `lists` (patches without contact are absent).
    of_patch: HashMap<u32, u32>,
    /// Per patch in contact: (the plane's axis, the rings of the patches on it).
    lists: Vec<(usize, Vec<Vec<Vec2>>)>,
}

impl Contacts {
    /// Whether no patch of the mesh is in contact.
    pub fn is_empty(&self) -> bool {
        self.lists.is_empty()
    }

    /// Patches in contact with another.
    pub fn len(&self) -> usize {
        self.lists.len()
    }

    /// Whether point `p` (on surface patch `i`'s plane) lies under a face in contact with it.
    #[inline]
    pub fn covers(&self, i: usize, p: Vec3) -> bool {
        let Some(&k) = self.of_patch.get(&(i as u32)) else {
            return false;
        };
        let (axis, rings) = &self.lists[k as usize];
        let q = in_plane(p, *axis);
        rings.iter().any(|r| inside(r, q))
    }
}

/// The two in-plane coordinates of `p` for a plane normal to `axis`.
fn in_plane(p: Vec3, axis: usize) -> Vec2 {
    let a = p.to_array();
    Vec2::new(a[(axis + 1) % 3], a[(axis + 2) % 3])
}

/// Whether `q` is inside the convex ring `r` (either winding; on an edge counts as inside).
fn inside(r: &[Vec2], q: Vec2) -> bool {
    let mut sign = 0.0f32;
    for k in 0..r.len() {
        let (a, b) = (r[k], r[(k + 1) % r.len()]);
        let c = (b - a).perp_dot(q - a);
        if c.abs() <= 1e-7 * (b - a).length_squared().max(f32::MIN_POSITIVE).sqrt() {
            continue;
        }
        if sign == 0.0 {
            sign = c.signum();
        } else if c.signum() != sign {
            return false;
        }
    }
    true
}

/// The axis a patch's normal lies along (exactly, as the builder gives axis-aligned faces),
/// and its sign.
fn axis_of(n: Vec3) -> Option<(usize, bool)> {
    let a = n.to_array();
    (0..3).find_map(|k| {
        let others = (0..3).filter(|&j| j != k).all(|j| a[j].abs() < 1e-6);
        (others && a[k].abs() > 0.999_999).then_some((k, a[k] > 0.0))
    })
}

impl Mesh {
    /// Finds the contacts between the surface patches (module notes). Two patches are in one
    /// plane when their coordinates along the axis agree to 1e-6 of the scene's size; they are
    /// in contact when their rings overlap with an area above 1e-6 of the smaller one's.
    pub fn find_contacts(&self) -> Contacts {
        let (lo, hi) = self.bounds();
        let quantum = ((hi - lo).length() * 1e-6).max(f32::MIN_POSITIVE);
        // Plane → (patches facing +axis, patches facing −axis).
        type Sides = (Vec<u32>, Vec<u32>);
        let mut planes: HashMap<(usize, i64), Sides> = HashMap::new();
        for (i, p) in self.patches.iter().enumerate() {
            if !self.is_surface(i) {
                continue;
            }
            let Some((axis, plus)) = axis_of(p.normal) else {
                continue;
            };
            let c = (p.centre.to_array()[axis] / quantum).round() as i64;
            let e = planes.entry((axis, c)).or_default();
            if plus { &mut e.0 } else { &mut e.1 }.push(i as u32);
        }
        let ring = |i: u32, axis: usize| -> Vec<Vec2> {
            (self.patch_indices(i as usize).iter())
                .map(|&v| in_plane(self.vertices[v as usize], axis))
                .collect()
        };
        let bbox = |r: &[Vec2]| {
            r.iter().fold((Vec2::MAX, Vec2::MIN), |(lo, hi), &q| {
                (lo.min(q), hi.max(q))
            })
        };
        let mut found: Vec<(u32, usize, Vec<Vec<Vec2>>)> = Vec::new();
        let mut keys: Vec<&(usize, i64)> = planes.keys().collect();
        keys.sort_unstable();
        for key in keys {
            let (plus, minus) = &planes[key];
            if plus.is_empty() || minus.is_empty() {
                continue;
            }
            let axis = key.0;
            let rings = |ids: &[u32]| -> Vec<(u32, Vec<Vec2>, (Vec2, Vec2))> {
                ids.iter()
                    .map(|&i| {
                        let r = ring(i, axis);
                        let b = bbox(&r);
                        (i, r, b)
                    })
                    .collect()
            };
            let (a, b) = (rings(plus), rings(minus));
            // A grid over the plane, cells the size of the larger side's typical patch.
            let cell = self.patch_size.max(quantum);
            let cells = |bb: &(Vec2, Vec2)| {
                let (x0, y0) = (
                    (bb.0.x / cell).floor() as i64,
                    (bb.0.y / cell).floor() as i64,
                );
                let (x1, y1) = (
                    (bb.1.x / cell).floor() as i64,
                    (bb.1.y / cell).floor() as i64,
                );
                (x0..=x1).flat_map(move |x| (y0..=y1).map(move |y| (x, y)))
            };
            let mut grid: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
            for (k, (_, _, bb)) in b.iter().enumerate() {
                for c in cells(bb) {
                    grid.entry(c).or_default().push(k);
                }
            }
            let mut on_b: Vec<Vec<Vec<Vec2>>> = vec![Vec::new(); b.len()];
            for (i, ra, ba) in &a {
                let mut near: Vec<usize> = cells(ba)
                    .filter_map(|c| grid.get(&c))
                    .flatten()
                    .copied()
                    .collect();
                near.sort_unstable();
                near.dedup();
                let mut on_a = Vec::new();
                for k in near {
                    let (_, rb, bb) = &b[k];
                    if ba.1.x <= bb.0.x || bb.1.x <= ba.0.x || ba.1.y <= bb.0.y || bb.1.y <= ba.0.y
                    {
                        continue;
                    }
                    if overlap_area(ra, rb) > 1e-6 * area(ra).min(area(rb)) {
                        on_a.push(rb.clone());
                        on_b[k].push(ra.clone());
                    }
                }
                if !on_a.is_empty() {
                    found.push((*i, axis, on_a));
                }
            }
            for (k, rs) in on_b.into_iter().enumerate() {
                if !rs.is_empty() {
                    found.push((b[k].0, axis, rs));
                }
            }
        }
        found.sort_by_key(|f| f.0);
        let mut out = Contacts::default();
        for (i, axis, rs) in found {
            out.of_patch.insert(i, out.lists.len() as u32);
            out.lists.push((axis, rs));
        }
        out
    }
}

/// Area of a convex ring.
fn area(r: &[Vec2]) -> f32 {
    area_signed(r).abs()
}

/// Area of the intersection of two convex rings (Sutherland–Hodgman clipping of one by the
/// other).
fn overlap_area(a: &[Vec2], b: &[Vec2]) -> f32 {
    // Clip `a` by each edge of `b`, with b counter-clockwise.
    let mut clip: Vec<Vec2> = b.to_vec();
    if area_signed(&clip) < 0.0 {
        clip.reverse();
    }
    let mut poly = a.to_vec();
    for k in 0..clip.len() {
        if poly.is_empty() {
            return 0.0;
        }
        let (e0, e1) = (clip[k], clip[(k + 1) % clip.len()]);
        let side = |q: Vec2| (e1 - e0).perp_dot(q - e0);
        let mut next = Vec::with_capacity(poly.len() + 1);
        for m in 0..poly.len() {
            let (p, q) = (poly[m], poly[(m + 1) % poly.len()]);
            let (sp, sq) = (side(p), side(q));
            if sp >= 0.0 {
                next.push(p);
            }
            if (sp >= 0.0) != (sq >= 0.0) {
                let t = sp / (sp - sq);
                next.push(p + (q - p) * t);
            }
        }
        poly = next;
    }
    if poly.len() < 3 {
        0.0
    } else {
        area(&poly)
    }
}

/// Signed area of a ring: positive when counter-clockwise.
fn area_signed(r: &[Vec2]) -> f32 {
    let mut a = 0.0;
    for k in 0..r.len() {
        a += r[k].perp_dot(r[(k + 1) % r.len()]);
    }
    a * 0.5
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(x0: f32, y0: f32, s: f32) -> Vec<Vec2> {
        vec![
            Vec2::new(x0, y0),
            Vec2::new(x0 + s, y0),
            Vec2::new(x0 + s, y0 + s),
            Vec2::new(x0, y0 + s),
        ]
    }

    #[test]
    fn overlap_of_squares_is_their_common_area() {
        let a = square(0.0, 0.0, 2.0);
        let b = square(1.0, 1.0, 2.0);
        assert!((overlap_area(&a, &b) - 1.0).abs() < 1e-6);
        let mut rev = b.clone();
        rev.reverse();
        assert!((overlap_area(&a, &rev) - 1.0).abs() < 1e-6);
        assert_eq!(overlap_area(&a, &square(3.0, 3.0, 1.0)), 0.0);
        // Touching along an edge only: no contact.
        assert!(overlap_area(&a, &square(2.0, 0.0, 1.0)) < 1e-9);
    }

    #[test]
    fn inside_a_ring_either_winding() {
        let mut r = square(0.0, 0.0, 1.0);
        assert!(inside(&r, Vec2::new(0.5, 0.5)));
        assert!(!inside(&r, Vec2::new(1.5, 0.5)));
        r.reverse();
        assert!(inside(&r, Vec2::new(0.25, 0.75)));
        assert!(!inside(&r, Vec2::new(-0.1, 0.5)));
    }
}
