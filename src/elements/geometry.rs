//! Elements in their patch's parametric domain, and their regular subdivision (Cohen,
//! Greenberg, Immel & Brock 1986, Sec. 3: "each patch is subdivided into elements").
//!
//! A patch is one or more *roots*: itself when it is a quad or a triangle, else the fan
//! triangles of its convex polygon (from its first vertex). A quad root maps (u, v) ∈ [0, 1]²
//! bilinearly onto its corners q₀…q₃ (its iso-lines are straight: the patch is planar and
//! convex, as `mesh::Builder` makes it), a triangle root maps (u, v), u + v ≤ 1, affinely onto
//! t₀ + u·(t₁ − t₀) + v·(t₂ − t₀). An element keeps its corners in the root's parameters, which
//! are dyadic fractions and so exact in f64: a corner shared by two elements of one root has
//! bit-identical coordinates, whichever path made it. Splitting at the edge midpoints (quads
//! into 4 quads, triangles into 4 similar triangles) keeps every element planar and convex.

use glam::{DVec2, DVec3, Vec3};

/// One root of a patch: a quad (4 corners) or a triangle (3; the fourth is unused).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Root {
    pub tri: bool,
    pub corners: [DVec3; 4],
}

impl Root {
    /// The roots of a patch with corners `pts` (counter-clockwise): a quad or a triangle is
    /// its own root; an n-gon is fan-triangulated from its first corner.
    pub fn of_patch(pts: &[Vec3]) -> Vec<Root> {
        let p: Vec<DVec3> = pts.iter().map(|v| v.as_dvec3()).collect();
        match p.len() {
            4 => vec![Root {
                tri: false,
                corners: [p[0], p[1], p[2], p[3]],
            }],
            n => (1..n.saturating_sub(1))
                .map(|k| Root {
                    tri: true,
                    corners: [p[0], p[k], p[k + 1], p[0]],
                })
                .collect(),
        }
    }

    /// The point of parameters `uv`.
    pub fn at(&self, uv: DVec2) -> DVec3 {
        let c = &self.corners;
        if self.tri {
            c[0] + (c[1] - c[0]) * uv.x + (c[2] - c[0]) * uv.y
        } else {
            let a = c[0].lerp(c[1], uv.x);
            let b = c[3].lerp(c[2], uv.x);
            a.lerp(b, uv.y)
        }
    }

    /// The whole root as an element.
    pub fn element(&self, root: u32) -> Elem {
        let uv = if self.tri {
            [
                DVec2::new(0.0, 0.0),
                DVec2::new(1.0, 0.0),
                DVec2::new(0.0, 1.0),
                DVec2::ZERO,
            ]
        } else {
            [
                DVec2::new(0.0, 0.0),
                DVec2::new(1.0, 0.0),
                DVec2::new(1.0, 1.0),
                DVec2::new(0.0, 1.0),
            ]
        };
        Elem {
            root,
            tri: self.tri,
            depth: 0,
            uv,
        }
    }
}

/// How an element is cut.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cut {
    /// Cohen 1986 Sec. 3: at the edge midpoints into four (a quad also at its centre).
    Four,
    /// A quad cut in two by the line u = its middle (across its u edges, which run along u).
    AcrossU,
    /// A quad cut in two by the line v = its middle.
    AcrossV,
}

/// An element: a quad or triangle of one root, by its corners' parameters, in the patch's
/// winding (counter-clockwise seen from the front).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Elem {
    pub root: u32,
    pub tri: bool,
    /// Subdivisions from the root.
    pub depth: u32,
    pub uv: [DVec2; 4],
}

impl Elem {
    /// Number of corners (3 or 4).
    pub fn count(&self) -> usize {
        if self.tri {
            3
        } else {
            4
        }
    }

    /// The corners' parameters.
    pub fn corners_uv(&self) -> &[DVec2] {
        &self.uv[..self.count()]
    }

    /// The corners in space.
    pub fn corners(&self, roots: &[Root]) -> Vec<DVec3> {
        let r = &roots[self.root as usize];
        self.corners_uv().iter().map(|&uv| r.at(uv)).collect()
    }

    /// The longest edge in space (metres).
    pub fn longest_edge(&self, roots: &[Root]) -> f64 {
        let p = self.corners(roots);
        (0..p.len())
            .map(|k| (p[(k + 1) % p.len()] - p[k]).length())
            .fold(0.0, f64::max)
    }

    /// Its share of its root's parameter area (4^−depth after cuts in four; halved by a cut
    /// in two): its share of the root's area in space too, the maps being bilinear and
    /// affine on planar convex roots up to the quad's non-parallel sides.
    pub fn share(&self) -> f64 {
        let u = &self.uv;
        if self.tri {
            (u[1] - u[0]).perp_dot(u[2] - u[0]).abs()
        } else {
            ((u[2].x - u[0].x) * (u[2].y - u[0].y)).abs()
        }
    }

    /// A quad's longest edge along u and longest along v, in space (metres).
    pub fn extents(&self, roots: &[Root]) -> (f64, f64) {
        let p = self.corners(roots);
        if p.len() < 4 {
            let l = self.longest_edge(roots);
            return (l, l);
        }
        let along_u = (p[1] - p[0]).length().max((p[2] - p[3]).length());
        let along_v = (p[3] - p[0]).length().max((p[2] - p[1]).length());
        (along_u, along_v)
    }

    /// The children of `cut` (a triangle is always cut in four).
    pub fn cut(&self, cut: Cut) -> Vec<Elem> {
        if self.tri || cut == Cut::Four {
            return self.split().to_vec();
        }
        let u = &self.uv;
        let mid = |a: DVec2, b: DVec2| (a + b) * 0.5;
        let child = |uv: [DVec2; 4]| Elem {
            root: self.root,
            tri: false,
            depth: self.depth + 1,
            uv,
        };
        if cut == Cut::AcrossU {
            let (m01, m23) = (mid(u[0], u[1]), mid(u[3], u[2]));
            vec![child([u[0], m01, m23, u[3]]), child([m01, u[1], u[2], m23])]
        } else {
            let (m12, m30) = (mid(u[1], u[2]), mid(u[0], u[3]));
            vec![child([u[0], u[1], m12, m30]), child([m30, m12, u[2], u[3]])]
        }
    }

    /// Cohen 1986 Sec. 3: the four children, cut at the edge midpoints (a quad also at its
    /// centre), each in the parent's winding.
    pub fn split(&self) -> [Elem; 4] {
        let u = &self.uv;
        let mid = |a: DVec2, b: DVec2| (a + b) * 0.5;
        let child = |uv: [DVec2; 4]| Elem {
            root: self.root,
            tri: self.tri,
            depth: self.depth + 1,
            uv,
        };
        if self.tri {
            let (m01, m12, m20) = (mid(u[0], u[1]), mid(u[1], u[2]), mid(u[2], u[0]));
            [
                child([u[0], m01, m20, DVec2::ZERO]),
                child([m01, u[1], m12, DVec2::ZERO]),
                child([m20, m12, u[2], DVec2::ZERO]),
                child([m12, m20, m01, DVec2::ZERO]),
            ]
        } else {
            let (m01, m12, m23, m30) = (
                mid(u[0], u[1]),
                mid(u[1], u[2]),
                mid(u[2], u[3]),
                mid(u[3], u[0]),
            );
            let c = (u[0] + u[1] + u[2] + u[3]) * 0.25;
            [
                child([u[0], m01, c, m30]),
                child([m01, u[1], m12, c]),
                child([c, m12, u[2], m23]),
                child([m30, c, m23, u[3]]),
            ]
        }
    }

    /// The centre in parameters (the mean of the corners: the bilinear centre of a quad, the
    /// centroid of a triangle).
    pub fn centre_uv(&self) -> DVec2 {
        self.corners_uv().iter().copied().sum::<DVec2>() / self.count() as f64
    }

    /// Weights of the corners at parameters `uv` when the element holds it (bilinear on a
    /// quad, barycentric on a triangle), else `None`.
    pub fn weights(&self, uv: DVec2) -> Option<[f64; 4]> {
        const TOL: f64 = 1e-9;
        let u = &self.uv;
        if self.tri {
            let d = (u[1] - u[0]).perp_dot(u[2] - u[0]);
            if d == 0.0 {
                return None;
            }
            let b1 = (uv - u[0]).perp_dot(u[2] - u[0]) / d;
            let b2 = (u[1] - u[0]).perp_dot(uv - u[0]) / d;
            let b0 = 1.0 - b1 - b2;
            (b0 >= -TOL && b1 >= -TOL && b2 >= -TOL).then_some([b0, b1, b2, 0.0])
        } else {
            // Children of the unit square are axis-aligned squares in parameters.
            let (lo, hi) = (u[0].min(u[2]), u[0].max(u[2]));
            let inside = uv.x >= lo.x - TOL
                && uv.x <= hi.x + TOL
                && uv.y >= lo.y - TOL
                && uv.y <= hi.y + TOL;
            if !inside {
                return None;
            }
            let s = ((uv.x - u[0].x) / (u[1].x - u[0].x)).clamp(0.0, 1.0);
            let t = ((uv.y - u[0].y) / (u[3].y - u[0].y)).clamp(0.0, 1.0);
            Some([(1.0 - s) * (1.0 - t), s * (1.0 - t), s * t, (1.0 - s) * t])
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area(p: &[DVec3]) -> f64 {
        let mut n = DVec3::ZERO;
        for k in 1..p.len() - 1 {
            n += (p[k] - p[0]).cross(p[k + 1] - p[0]);
        }
        n.length() * 0.5
    }

    #[test]
    fn children_tile_their_parent() {
        let quad = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(1.5, 1.0, 0.0),
            Vec3::new(0.2, 1.2, 0.0),
        ];
        let tri = [quad[0], quad[1], quad[2]];
        for pts in [&quad[..], &tri[..]] {
            let roots = Root::of_patch(pts);
            let e = roots[0].element(0);
            let whole = area(&e.corners(&roots));
            for cut in [Cut::Four, Cut::AcrossU, Cut::AcrossV] {
                let kids = e.cut(cut);
                let sum: f64 = kids.iter().map(|c| area(&c.corners(&roots))).sum();
                assert!((whole - sum).abs() < 1e-12 * whole, "{whole} {sum}");
                let shares: f64 = kids.iter().map(Elem::share).sum();
                assert!((shares - 1.0).abs() < 1e-12, "{cut:?}: {shares}");
                // Every point of the parent is in a child, which interpolates there.
                for c in &kids {
                    let w = c.weights(c.centre_uv()).unwrap();
                    assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
                }
            }
        }
    }
}
