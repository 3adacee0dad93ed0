//! Welded display vertices: patch corners are one vertex only where position, facing *and*
//! material agree, so Gouraud interpolation smooths over a wall's own patches but never across
//! a crease, and a light's radiosity never bleeds into the ceiling around it.

use super::subdivide::Builder;
use super::Mesh;
use glam::Vec3;

impl Builder {
    /// The welded vertex at `p` for a patch facing `n` of `material`: an earlier one within the
    /// weld quantum of the same facing and material, else a new one.
    pub(super) fn vertex(&mut self, p: Vec3, n: Vec3, material: u32) -> u32 {
        let q = |x: f32| (x / self.quantum).round() as i64;
        let qn = |x: f32| (x * 1000.0).round() as i32;
        let key = (
            [q(p.x), q(p.y), q(p.z)],
            [qn(n.x), qn(n.y), qn(n.z)],
            material,
        );
        let next = self.mesh.vertices.len() as u32;
        let id = *self.weld.entry(key).or_insert(next);
        if id == next {
            self.mesh.vertices.push(p);
        }
        id
    }
}

impl Mesh {
    /// Per-vertex values for display: the area-weighted mean of the patches sharing the vertex
    /// (vertices are welded only within one facing, so creases stay sharp).
    pub fn vertex_values(&self, patch_values: &[[f64; 3]]) -> Vec<[f32; 3]> {
        let mut sum = vec![[0.0f64; 3]; self.vertices.len()];
        let mut w = vec![0.0f64; self.vertices.len()];
        for (i, p) in self.patches.iter().enumerate() {
            for &v in self.patch_indices(i) {
                for c in 0..3 {
                    sum[v as usize][c] += patch_values[i][c] * p.area;
                }
                w[v as usize] += p.area;
            }
        }
        sum.iter()
            .zip(&w)
            .map(|(s, &w)| {
                if w > 0.0 {
                    s.map(|x| (x / w) as f32)
                } else {
                    [0.0; 3]
                }
            })
            .collect()
    }
}
