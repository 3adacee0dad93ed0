//! Hemisphere samplers that turn a shooter's unshot energy into directions.
//!
//! [`polar`] is the paper's adaptive polar hemisphere sampler (Sec. 2); [`patch_points`] draws
//! the points on a patch that rays leave from. Directions are in the shooter's local frame
//! (z = the patch normal); [`Frame`] maps them to world space.

pub mod hemicube;
pub mod patch_points;
pub mod polar;

pub use patch_points::PatchPoints;

use glam::Vec3;

/// An orthonormal frame around a patch normal, turned by `angle` about it (Sec. 3: a random
/// rotation per shot keeps axis-aligned architecture from aliasing).
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    pub t: Vec3,
    pub b: Vec3,
    pub n: Vec3,
}

impl Frame {
    pub fn new(n: Vec3, angle: f32) -> Frame {
        let t0 = n.any_orthonormal_vector();
        let b0 = n.cross(t0);
        let (s, c) = angle.sin_cos();
        let t = t0 * c + b0 * s;
        let b = n.cross(t);
        Frame { t, b, n }
    }

    /// Local (x, y, z) with z along the normal → world.
    #[inline]
    pub fn to_world(&self, d: Vec3) -> Vec3 {
        self.t * d.x + self.b * d.y + self.n * d.z
    }
}
