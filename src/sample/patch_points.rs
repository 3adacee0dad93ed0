//! Points on a patch: the area-uniform draws a ray shot starts its rays from (Sec. 2: a shot
//! leaves from all over the shooter, not from its centre), and the stratified points of a
//! gather (an area-preserving map of the unit square onto the patch).

use crate::mesh::Mesh;
use glam::Vec3;
use rand::Rng;
use smallvec::SmallVec;

/// Draws points uniformly over the area of one convex patch: a fan triangle chosen by area,
/// then a uniform point in it. Built once per chunk of rays, so no work per ray but the draw.
/// The fan of a triangle or a quadrilateral is held inline: the emitters' points are read at
/// random by every light sample, and a fan on the heap cost a second cache miss each
/// (docs/results/gather-building.md).
pub struct PatchPoints {
    apex: Vec3,
    /// (b, c, cumulative area) of each fan triangle (apex, b, c).
    fan: SmallVec<[(Vec3, Vec3, f32); 2]>,
}

impl PatchPoints {
    pub fn new(mesh: &Mesh, i: usize) -> PatchPoints {
        let ids = mesh.patch_indices(i);
        let v = |k: usize| mesh.vertices[ids[k] as usize];
        let apex = v(0);
        let mut total = 0.0;
        let fan = (1..ids.len() - 1)
            .map(|k| {
                total += (v(k) - apex).cross(v(k + 1) - apex).length();
                (v(k), v(k + 1), total)
            })
            .collect();
        PatchPoints { apex, fan }
    }

    /// The point at (u, v) of the unit square, an area-preserving map onto the patch (u picks
    /// the fan triangle and its first barycentric coordinate), so stratified (u, v) give
    /// stratified points (the final gather's).
    pub fn at(&self, u: f32, v: f32) -> Vec3 {
        let total = self.fan[self.fan.len() - 1].2;
        let x = u.clamp(0.0, 1.0) * total;
        let k = self
            .fan
            .iter()
            .position(|f| x < f.2)
            .unwrap_or(self.fan.len() - 1);
        let lo = if k == 0 { 0.0 } else { self.fan[k - 1].2 };
        let w = self.fan[k].2 - lo;
        let u1 = if w > 0.0 {
            ((x - lo) / w).clamp(0.0, 1.0)
        } else {
            0.5
        };
        let (b, c) = (self.fan[k].0, self.fan[k].1);
        let r1 = u1.sqrt();
        self.apex * (1.0 - r1) + b * (r1 * (1.0 - v)) + c * (r1 * v)
    }

    /// A point drawn uniformly over the patch.
    #[inline]
    pub fn sample<R: Rng>(&self, rng: &mut R) -> Vec3 {
        let (mut b, mut c, _) = self.fan[0];
        if self.fan.len() > 1 {
            let u = rng.gen::<f32>() * self.fan[self.fan.len() - 1].2;
            let k = self
                .fan
                .iter()
                .position(|f| u < f.2)
                .unwrap_or(self.fan.len() - 1);
            (b, c) = (self.fan[k].0, self.fan[k].1);
        }
        let (r1, r2) = (rng.gen::<f32>().sqrt(), rng.gen::<f32>());
        self.apex * (1.0 - r1) + b * (r1 * (1.0 - r2)) + c * (r1 * r2)
    }
}
