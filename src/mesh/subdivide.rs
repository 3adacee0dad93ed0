//! Subdivision of a planar convex piece into patches no longer than the patch size: quads into
//! an m×n bilinear grid of sub-quads, triangles into k² similar sub-triangles, convex n-gons
//! whole when small enough and fanned from their centroid otherwise. Each patch gets its area,
//! area centroid, normal and class.

use super::classify::classify;
use super::grids::Grid;
use super::near_lights::{NearLights, NEAR_LIGHT_CUTS};
use super::{newell, Mesh, Patch, Side};
use glam::Vec3;
use std::collections::HashMap;

/// Accumulates patches and welds their vertices by (position, facing).
pub(super) struct Builder {
    pub(super) mesh: Mesh,
    size: f32,
    /// Weld grid cell size: positions closer than this (and facing the same way) are one vertex.
    pub(super) quantum: f32,
    pub(super) weld: HashMap<([i64; 3], [i32; 3], u32), u32>,
    /// The scene's lights, to cut patches near them finer (`near_lights.rs`).
    pub(super) near: Option<NearLights>,
    /// Whether the polygon being added is refined near lights (not a light itself).
    pub(super) refine_near: bool,
    /// Whether a patch of the grid being cut was cut finer or dropped (no [`Grid`] then).
    irregular: bool,
}

impl Builder {
    pub(super) fn new(size: f32, diagonal: f32) -> Self {
        Builder {
            mesh: Mesh {
                patch_size: size,
                ..Mesh::default()
            },
            size,
            quantum: diagonal * 1e-6,
            weld: HashMap::new(),
            near: None,
            refine_near: false,
            irregular: false,
        }
    }

    /// Cuts one planar convex polygon into patches no longer than the patch size.
    pub(super) fn add_polygon(&mut self, pts: &[Vec3], material: u32, polygon: u32) {
        let n = newell(pts).normalize_or_zero();
        if n == Vec3::ZERO {
            return;
        }
        let s = self.size;
        let div = |len: f32| ((len / s).ceil() as usize).max(1);
        match pts.len() {
            3 => {
                let longest = (0..3)
                    .map(|k| (pts[(k + 1) % 3] - pts[k]).length())
                    .fold(0.0, f32::max);
                let k = div(longest);
                self.add_subdivided_triangle(pts, k, n, material, polygon);
            }
            4 => {
                let along_u = (pts[1] - pts[0]).length().max((pts[2] - pts[3]).length());
                let along_v = (pts[3] - pts[0]).length().max((pts[2] - pts[1]).length());
                let (m, k) = (div(along_u), div(along_v));
                // Bilinear grid: iso-u and iso-v lines of a planar convex quad are straight,
                // so every cell is a planar convex quad with edges ≤ the patch size.
                let at = |i: usize, j: usize| {
                    let (u, v) = (i as f32 / m as f32, j as f32 / k as f32);
                    let a = along(pts[0], pts[1], u);
                    let b = along(pts[3], pts[2], u);
                    along(a, b, v)
                };
                let grid: Vec<u32> = (0..=k)
                    .flat_map(|j| (0..=m).map(move |i| (i, j)))
                    .map(|(i, j)| at(i, j))
                    .collect::<Vec<_>>()
                    .into_iter()
                    .map(|p| self.vertex(p, n, material))
                    .collect();
                let g = |i: usize, j: usize| grid[j * (m + 1) + i];
                let start = self.begin_grid();
                for j in 0..k {
                    for i in 0..m {
                        let ids = [g(i, j), g(i + 1, j), g(i + 1, j + 1), g(i, j + 1)];
                        self.push_patch(&ids, n, material, polygon);
                    }
                }
                let ids = [g(0, 0), g(m, 0), g(m, k), g(0, k)];
                let grid = Grid::quad(
                    ids,
                    ids.map(|v| self.position(v)),
                    m as u32,
                    k as u32,
                    start,
                );
                self.end_grid(start, grid);
            }
            count => {
                let longest = (0..count)
                    .map(|k| (pts[(k + 1) % count] - pts[k]).length())
                    .fold(0.0, f32::max);
                let c = pts.iter().copied().sum::<Vec3>() / count as f32;
                let radius = pts.iter().map(|p| (*p - c).length()).fold(0.0, f32::max);
                if longest <= s && radius <= s {
                    let ids: Vec<u32> = pts.iter().map(|&p| self.vertex(p, n, material)).collect();
                    self.push_patch(&ids, n, material, polygon);
                } else {
                    // A large n-gon: fan from its centroid, then cut each triangle.
                    for e in 0..count {
                        let tri = [c, pts[e], pts[(e + 1) % count]];
                        let longest = (0..3)
                            .map(|q| (tri[(q + 1) % 3] - tri[q]).length())
                            .fold(0.0, f32::max);
                        self.add_subdivided_triangle(&tri, div(longest), n, material, polygon);
                    }
                }
            }
        }
    }

    /// Cuts a triangle into k² similar triangles on a barycentric grid (edges = original / k).
    fn add_subdivided_triangle(
        &mut self,
        t: &[Vec3],
        k: usize,
        n: Vec3,
        material: u32,
        polygon: u32,
    ) {
        let at = |i: usize, j: usize| {
            // Point i steps along t0→t1 and j steps along t0→t2; on the edges, along them
            // (exactly on an axis-aligned edge's line, see `along`).
            let (a, b) = (i as f32 / k as f32, j as f32 / k as f32);
            if i + j == k {
                along(t[1], t[2], b)
            } else {
                t[0] + (t[1] - t[0]) * a + (t[2] - t[0]) * b
            }
        };
        let mut row_start = Vec::with_capacity(k + 1);
        let mut ids = Vec::new();
        for j in 0..=k {
            row_start.push(ids.len());
            for i in 0..=(k - j) {
                let p = if i + j == k && j == 0 {
                    t[1]
                } else if i == 0 && j == k {
                    t[2]
                } else {
                    at(i, j)
                };
                ids.push(self.vertex(p, n, material));
            }
        }
        let g = |i: usize, j: usize| ids[row_start[j] + i];
        let start = self.begin_grid();
        for j in 0..k {
            for i in 0..(k - j) {
                self.push_patch(&[g(i, j), g(i + 1, j), g(i, j + 1)], n, material, polygon);
                if i + j + 1 < k {
                    self.push_patch(
                        &[g(i + 1, j), g(i + 1, j + 1), g(i, j + 1)],
                        n,
                        material,
                        polygon,
                    );
                }
            }
        }
        let ids = [g(0, 0), g(k, 0), g(0, k)];
        self.end_grid(start, Grid::triangle(ids, k as u32, start));
    }

    /// Where welded vertex `v` is (a grid's corners are its patches' own, welded).
    fn position(&self, v: u32) -> Vec3 {
        self.mesh.vertices[v as usize]
    }

    /// The first patch of a grid about to be cut.
    fn begin_grid(&mut self) -> u32 {
        self.irregular = false;
        self.mesh.patches.len() as u32
    }

    /// Keeps `grid` (its patches from `start` on) if every patch of it was made as cut.
    fn end_grid(&mut self, start: u32, grid: Grid) {
        let made = self.mesh.patches.len() as u32 - start;
        if !self.irregular && made == grid.count() {
            self.mesh.grids.push(grid);
        }
    }

    fn push_patch(&mut self, ids: &[u32], n: Vec3, material: u32, polygon: u32) {
        self.push_near_cut(ids, n, material, polygon, 0);
    }

    /// A patch, cut in four (quads and triangles by their edges' midpoints, other polygons
    /// fanned from their centre) for as long as a light is too near it (`near_lights.rs`).
    fn push_near_cut(&mut self, ids: &[u32], n: Vec3, material: u32, polygon: u32, depth: u32) {
        if !(self.refine_near && depth < NEAR_LIGHT_CUTS && self.near.is_some()) {
            return self.push_final(ids, n, material, polygon);
        }
        let pts: Vec<Vec3> = ids
            .iter()
            .map(|&i| self.mesh.vertices[i as usize])
            .collect();
        let cut = self.near.as_ref().is_some_and(|l| l.too_near(&pts, n));
        if !cut {
            return self.push_final(ids, n, material, polygon);
        }
        self.irregular = true;
        let count = pts.len();
        let mid: Vec<u32> = (0..count)
            .map(|k| self.vertex(along(pts[k], pts[(k + 1) % count], 0.5), n, material))
            .collect();
        let cells: Vec<Vec<u32>> = match count {
            3 => vec![
                vec![ids[0], mid[0], mid[2]],
                vec![mid[0], ids[1], mid[1]],
                vec![mid[2], mid[1], ids[2]],
                vec![mid[0], mid[1], mid[2]],
            ],
            _ => {
                // Quads into four quads; an n-gon into n quads about its centre (both convex).
                let c = self.vertex(
                    pts.iter().copied().sum::<Vec3>() / count as f32,
                    n,
                    material,
                );
                (0..count)
                    .map(|k| vec![ids[k], mid[k], c, mid[(k + count - 1) % count]])
                    .collect()
            }
        };
        for cell in cells {
            self.push_near_cut(&cell, n, material, polygon, depth + 1);
        }
    }

    fn push_final(&mut self, ids: &[u32], n: Vec3, material: u32, polygon: u32) {
        let pts: Vec<Vec3> = ids
            .iter()
            .map(|&i| self.mesh.vertices[i as usize])
            .collect();
        let nn = newell(&pts);
        let area = nn.length() as f64 * 0.5;
        if area <= 0.0 {
            self.irregular = true;
            return;
        }
        // The centroid of the polygon's area (not of its vertices), from its fan triangles.
        let mut c = glam::DVec3::ZERO;
        let mut a_sum = 0.0;
        for k in 1..pts.len() - 1 {
            let (a, b, d) = (pts[0].as_dvec3(), pts[k].as_dvec3(), pts[k + 1].as_dvec3());
            let ak = (b - a).cross(d - a).length() * 0.5;
            c += (a + b + d) / 3.0 * ak;
            a_sum += ak;
        }
        let centre = if a_sum > 0.0 {
            (c / a_sum).as_vec3()
        } else {
            pts[0]
        };
        let first = self.mesh.patch_vertices.len() as u32;
        self.mesh.patch_vertices.extend_from_slice(ids);
        self.mesh.patches.push(Patch {
            first,
            count: ids.len() as u32,
            material,
            polygon,
            area,
            centre,
            normal: n,
            class: classify(&pts, n),
            side: Side::One,
        });
    }
}

/// How many patches [`Builder::add_polygon`] cuts the planar convex piece `pts` into at patch
/// size `s`, before the cuts near lights: the same divisions, counted, not made.
pub(super) fn patches_of_piece(pts: &[Vec3], s: f32) -> f64 {
    let div = |len: f32| ((len / s).ceil() as f64).max(1.0);
    let longest = |p: &[Vec3]| {
        (0..p.len())
            .map(|k| (p[(k + 1) % p.len()] - p[k]).length())
            .fold(0.0, f32::max)
    };
    match pts.len() {
        0..=2 => 0.0,
        3 => div(longest(pts)).powi(2),
        4 => {
            let along_u = (pts[1] - pts[0]).length().max((pts[2] - pts[3]).length());
            let along_v = (pts[3] - pts[0]).length().max((pts[2] - pts[1]).length());
            div(along_u) * div(along_v)
        }
        count => {
            let c = pts.iter().copied().sum::<Vec3>() / count as f32;
            let radius = pts.iter().map(|p| (*p - c).length()).fold(0.0, f32::max);
            if longest(pts) <= s && radius <= s {
                1.0
            } else {
                (0..count)
                    .map(|e| div(longest(&[c, pts[e], pts[(e + 1) % count]])).powi(2))
                    .sum()
            }
        }
    }
}

/// The point a fraction `s` of the way from `a` to `b`: a + (b − a)·s, and `b` itself at
/// s = 1. Exact in every coordinate where `a` and `b` agree, so a cut point of an axis-aligned
/// edge lies on the edge's line, where the neighbour across it has its own vertices: glam's
/// `lerp`, a·(1 − s) + b·s, can put it an ulp off that line and open a crack a ray slips
/// through.
fn along(a: Vec3, b: Vec3, s: f32) -> Vec3 {
    if s >= 1.0 {
        b
    } else {
        a + (b - a) * s
    }
}
