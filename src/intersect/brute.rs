//! Brute force: every ray against every patch triangle. O(patches) per ray — the test oracle
//! for small scenes, never for real work.

use super::{Hit, Intersector, Ray};
use crate::mesh::Mesh;
use glam::Vec3;

pub struct BruteForce {
    tris: Vec<([Vec3; 3], u32)>,
    normals: Vec<Vec3>,
}

impl BruteForce {
    pub fn new(mesh: &Mesh) -> BruteForce {
        let tris = mesh
            .surface_triangles()
            .map(|(t, p)| (t.map(|v| mesh.vertices[v as usize]), p))
            .collect();
        let normals = mesh.patches.iter().map(|p| p.normal).collect();
        BruteForce { tris, normals }
    }
}

/// Möller–Trumbore, two-sided, in f64 so the oracle is more precise than what it checks.
fn hit_triangle(ray: &Ray, t: &[Vec3; 3]) -> Option<f64> {
    let o = ray.org.as_dvec3();
    let d = ray.dir.as_dvec3();
    let (a, b, c) = (t[0].as_dvec3(), t[1].as_dvec3(), t[2].as_dvec3());
    let e1 = b - a;
    let e2 = c - a;
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-300 {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - a;
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = d.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv;
    (t >= ray.tnear as f64 && t <= ray.tfar as f64).then_some(t)
}

impl Intersector for BruteForce {
    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let mut best: Option<(f64, u32)> = None;
        for (tri, patch) in &self.tris {
            if let Some(t) = hit_triangle(ray, tri) {
                if best.is_none_or(|(bt, _)| t < bt) {
                    best = Some((t, *patch));
                }
            }
        }
        best.map(|(t, patch)| Hit {
            patch,
            t: t as f32,
            back: self.normals[patch as usize].dot(ray.dir) > 0.0,
        })
    }

    fn name(&self) -> &'static str {
        "brute"
    }
}
