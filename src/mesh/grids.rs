//! Patch grids: the pieces whose patches are a regular grid (a quad cut into an m×k bilinear
//! grid, a triangle into k² similar triangles, none cut finer near a light), so a ray can meet
//! the piece whole and find its patch by arithmetic (docs/design.md §3, "Grids").
//!
//! Embree then holds two triangles per piece rather than one or two per patch: on the 1 M-patch
//! building 0.46 M triangles against 1.9 M, a smaller, faster-built scene.

use glam::Vec3;

/// A piece cut into a regular grid of patches `first..first + count()`, numbered as
/// the mesh builder (`subdivide.rs`) pushes them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    /// The piece's corners (welded vertices of [`super::Mesh::vertices`]), counter-clockwise
    /// seen from the front; a triangle repeats its third corner (`corners[3] == corners[2]`).
    pub corners: [u32; 4],
    /// Its patches' layout, as a hit on the first half of its quad reads it.
    pub cells: Cells,
}

impl Grid {
    /// A planar convex quad with corners `ids` at `pts`, cut at u = i/m and v = j/k (the
    /// bilinear parameters of corners 0 → 1 and 0 → 3): patch (i, j) is `first + j·m + i`.
    pub fn quad(ids: [u32; 4], pts: [Vec3; 4], m: u32, k: u32, first: u32) -> Grid {
        let (e, f) = (pts[1] - pts[0], pts[3] - pts[0]);
        let g = pts[0] - pts[1] + pts[2] - pts[3];
        debug_assert!(
            m <= Cells::MAX_SIDE,
            "more cells than the flags leave room for"
        );
        Grid {
            corners: ids,
            cells: Cells {
                first,
                m,
                k,
                twist: in_basis(g, e, f),
            },
        }
    }

    /// A triangle with corners `ids` cut into k² similar triangles on the barycentric grid of
    /// corners 1 and 2 (row j, step i: the triangle (i, j) then, unless on the far edge, the
    /// one above it).
    pub fn triangle(ids: [u32; 3], k: u32, first: u32) -> Grid {
        Grid {
            corners: [ids[0], ids[1], ids[2], ids[2]],
            cells: Cells {
                first,
                m: Cells::TRIANGLE,
                k,
                twist: [0.0; 2],
            },
        }
    }

    /// Whether the grid is a triangle's (its quad's second half is empty).
    pub fn is_triangle(&self) -> bool {
        self.cells.m & Cells::TRIANGLE != 0
    }

    /// How many patches the grid holds.
    pub fn count(&self) -> u32 {
        let k = self.cells.k;
        if self.is_triangle() {
            k * k
        } else {
            self.cells.m * k
        }
    }

    /// The grid's patches.
    pub fn patches(&self) -> std::ops::Range<usize> {
        let first = self.cells.first as usize;
        first..first + self.count() as usize
    }

    /// What a hit on the second half of the grid's quad, the triangle (2, 3, 1), reads.
    pub fn second_half(&self) -> Cells {
        Cells {
            m: self.cells.m | Cells::SECOND,
            ..self.cells
        }
    }
}

/// What a ray that meets a primitive needs to find its patch: a grid's layout or a single
/// patch, in 20 bytes (one per Embree triangle, read once a hit).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cells {
    /// The first patch.
    pub first: u32,
    /// Cells along u, or [`Cells::TRIANGLE`]; with [`Cells::SECOND`] for the second half of a
    /// quad.
    m: u32,
    /// Cells along v (a triangle's divisions).
    k: u32,
    /// A quad's corner 2 offset from a parallelogram's, p0 − p1 + p2 − p3, in the basis
    /// (p1 − p0, p3 − p0).
    twist: [f32; 2],
}

impl Cells {
    const TRIANGLE: u32 = 1 << 31;
    const SECOND: u32 = 1 << 30;
    /// The largest number of cells along a quad's side.
    pub const MAX_SIDE: u32 = Cells::SECOND - 1;

    /// A primitive of one patch.
    pub fn single(patch: u32) -> Cells {
        Cells {
            first: patch,
            m: 1,
            k: 1,
            twist: [0.0; 2],
        }
    }

    /// The patch at quad coordinates (u, v) of a hit, as Embree defines them for a quad: the
    /// weights of corners 1 and 3 on the triangle (0, 1, 3), or one minus those of corners 3
    /// and 1 on (2, 3, 1); for a triangle the barycentric weights of corners 1 and 2. A point
    /// on a line between two patches goes to either.
    #[inline]
    pub fn patch_at(&self, u: f32, v: f32) -> u32 {
        let (m, k) = (self.m, self.k);
        if m == 1 && k == 1 {
            return self.first;
        }
        let (u, v) = if m & Cells::SECOND != 0 {
            (1.0 - u, 1.0 - v)
        } else {
            (u, v)
        };
        if m & Cells::TRIANGLE != 0 {
            let (x, y) = (u * k as f32, v * k as f32);
            let j = cell(v, k);
            let i = cell(u, k).min(k - 1 - j);
            let upper = i + j + 1 < k && (x - i as f32) + (y - j as f32) > 1.0;
            return self.first + 2 * j * k - j * j + 2 * i + upper as u32;
        }
        let m = m & !Cells::SECOND;
        // The hit in the basis (p1 − p0, p3 − p0): exact on the first triangle; on the
        // second, p2 = p0 + e + f + g puts it (u + v − 1)·g further.
        let w = (u + v - 1.0).max(0.0);
        let (a, b) = (u + w * self.twist[0], v + w * self.twist[1]);
        let (s, t) = inverse_bilinear(a, b, self.twist);
        self.first + cell(t, k) * m + cell(s, m)
    }
}

/// The cell of `n` equal cells of [0, 1] that `x` falls in, clamped to the grid.
fn cell(x: f32, n: u32) -> u32 {
    ((x * n as f32) as i64).clamp(0, n as i64 - 1) as u32
}

/// Coordinates (α, β) of `g` in the basis (e, f) of the plane they span.
fn in_basis(g: Vec3, e: Vec3, f: Vec3) -> [f32; 2] {
    let (ee, ff, ef) = (e.dot(e), f.dot(f), e.dot(f));
    let (ge, gf) = (g.dot(e), g.dot(f));
    let det = ee * ff - ef * ef;
    if det.abs() <= f32::MIN_POSITIVE {
        return [0.0, 0.0];
    }
    [(ge * ff - gf * ef) / det, (gf * ee - ge * ef) / det]
}

/// The bilinear parameters (s, t) of the point (a, b) of the quad with corners (0, 0), (1, 0),
/// (1, 1) + twist, (0, 1): a = s + s·t·α, b = t + s·t·β, solved for the root in the quad (the
/// form with no cancellation as the twist goes to zero, where s = a, t = b).
pub fn inverse_bilinear(a: f32, b: f32, twist: [f32; 2]) -> (f32, f32) {
    let [ga, gb] = twist;
    if ga == 0.0 && gb == 0.0 {
        return (a, b);
    }
    // a·β − b·α = s·β − t·α; eliminate the larger twist's unknown.
    let c = a * gb - b * ga;
    let root = |lin: f32, quad: f32, rhs: f32| {
        // quad·x² + lin·x − rhs = 0, the root near rhs / lin.
        let disc = (lin * lin + 4.0 * quad * rhs).max(0.0);
        let den = lin + lin.signum() * disc.sqrt();
        if den == 0.0 {
            0.0
        } else {
            2.0 * rhs / den
        }
    };
    if ga.abs() >= gb.abs() {
        let s = root(1.0 - c, gb, a);
        (s, b / (1.0 + s * gb))
    } else {
        let t = root(1.0 + c, ga, b);
        (a / (1.0 + t * ga), t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::vec3;
    use rand::{Rng, SeedableRng};

    fn bilinear(p: &[Vec3; 4], s: f32, t: f32) -> Vec3 {
        let a = p[0] + (p[1] - p[0]) * s;
        let b = p[3] + (p[2] - p[3]) * s;
        a + (b - a) * t
    }

    /// The patch a hit at Embree's quad coordinates (u, v) meets, through the half of the
    /// quad that holds it.
    fn patch_at(g: &Grid, u: f32, v: f32) -> u32 {
        if u + v <= 1.0 {
            g.cells.patch_at(u, v)
        } else {
            g.second_half().patch_at(1.0 - u, 1.0 - v)
        }
    }

    /// Embree's quad coordinates of a point of the quad: barycentric on (0, 1, 3) or on
    /// (2, 3, 1), whichever holds it.
    fn embree_uv(p: &[Vec3; 4], x: Vec3) -> (f32, f32) {
        let bary = |a: Vec3, b: Vec3, c: Vec3| {
            let (e, f, d) = (b - a, c - a, x - a);
            let [u, v] = in_basis(d, e, f);
            (u, v)
        };
        let (u, v) = bary(p[0], p[1], p[3]);
        if u + v <= 1.0 {
            (u, v)
        } else {
            let (u2, v2) = bary(p[2], p[3], p[1]);
            (1.0 - u2, 1.0 - v2)
        }
    }

    #[test]
    fn a_point_of_a_twisted_quad_finds_its_bilinear_cell() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(3);
        // A planar convex quad far from a parallelogram, tilted out of the axes.
        let (x, y) = (vec3(0.8, 0.0, 0.6), vec3(0.0, 1.0, 0.0));
        let flat = [(0.0, 0.0), (4.0, 0.5), (5.0, 3.5), (0.5, 2.0)];
        let p = flat.map(|(a, b)| vec3(10.0, -3.0, 7.0) + x * a + y * b);
        let g = Grid::quad([0, 1, 2, 3], p, 7, 5, 100);
        let mut hits = 0;
        for _ in 0..20000 {
            let (s, t): (f32, f32) = (rng.gen(), rng.gen());
            let (i, j) = ((s * 7.0) as u32, (t * 5.0) as u32);
            // Away from the lines between cells, where either side is right.
            let (fi, fj) = (s * 7.0 - i as f32, t * 5.0 - j as f32);
            if fi.min(1.0 - fi) < 1e-3 || fj.min(1.0 - fj) < 1e-3 {
                continue;
            }
            let (u, v) = embree_uv(&p, bilinear(&p, s, t));
            assert_eq!(patch_at(&g, u, v), 100 + j * 7 + i, "s {s} t {t}");
            hits += 1;
        }
        assert!(hits > 15000);
    }

    #[test]
    fn a_parallelogram_reads_the_cell_straight_from_the_coordinates() {
        let p = [
            vec3(0., 0., 0.),
            vec3(2., 0., 0.),
            vec3(3., 1., 0.),
            vec3(1., 1., 0.),
        ];
        let g = Grid::quad([0, 1, 2, 3], p, 4, 2, 0);
        assert_eq!(g.cells.twist, [0.0, 0.0]);
        assert_eq!(patch_at(&g, 0.3, 0.7), 4 + 1);
        assert_eq!(patch_at(&g, 0.9, 0.9), 7);
        // Out of range by rounding: clamped into the grid.
        assert_eq!(patch_at(&g, 1.0, 1.0), 7);
        assert_eq!(patch_at(&g, -1e-7, 0.0), 0);
        assert_eq!(Cells::single(42).patch_at(0.9, 0.05), 42);
    }

    #[test]
    fn a_triangle_grid_numbers_its_patches_as_the_builder_pushes_them() {
        let k = 4u32;
        let g = Grid::triangle([0, 1, 2], k, 10);
        // The builder's order: row j, step i: (i, j) lower, then upper if i + j + 1 < k.
        let mut expected = Vec::new();
        for j in 0..k {
            for i in 0..(k - j) {
                let c = (i as f32 + 0.3, j as f32 + 0.3);
                expected.push((c.0 / k as f32, c.1 / k as f32));
                if i + j + 1 < k {
                    let c = (i as f32 + 0.7, j as f32 + 0.7);
                    expected.push((c.0 / k as f32, c.1 / k as f32));
                }
            }
        }
        assert_eq!(expected.len() as u32, g.count());
        for (n, &(u, v)) in expected.iter().enumerate() {
            assert_eq!(
                g.cells.patch_at(u, v),
                10 + n as u32,
                "patch {n} at ({u}, {v})"
            );
        }
    }
}
