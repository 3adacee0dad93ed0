//! The pinhole camera, and the camera fitted to a scene's bounds.

use glam::Vec3;

/// A pinhole camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub eye: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    /// Vertical field of view in degrees (clamped to 0.01..179 when used).
    pub fov_y_deg: f32,
}

impl Camera {
    /// Fitted to the scene: looks along -z from the +z side (y up), fov 40°, distance so the whole
    /// bounding box fits in view with a small margin, aimed at the box centre.
    ///
    /// A non-finite or inverted box (such as the bounds of an empty mesh) is replaced by the unit
    /// cube around the origin; a non-positive or non-finite `aspect` (width / height) by 1.
    pub fn fit(lo: Vec3, hi: Vec3, aspect: f32) -> Camera {
        let (lo, hi) = if lo.is_finite() && hi.is_finite() && lo.cmple(hi).all() {
            (lo, hi)
        } else {
            (Vec3::splat(-0.5), Vec3::splat(0.5))
        };
        let aspect = if aspect.is_finite() && aspect > 0.0 {
            aspect
        } else {
            1.0
        };
        let fov_y_deg = 40.0_f32;
        let tan_y = (0.5 * fov_y_deg).to_radians().tan();
        let tan_x = tan_y * aspect;
        // Corners end up at most 1/MARGIN of the way from the image centre to its edge.
        const MARGIN: f32 = 1.1;
        let centre = 0.5 * (lo + hi);
        let h = 0.5 * (hi - lo);
        // With the eye at centre + d·z, a corner at offset (x, y, z) lies at depth d − z and is
        // in view when |x| ≤ (d − z)·tan_x / MARGIN (same for y): solve each for d.
        let mut d: f32 = 0.0;
        for z in [-h.z, h.z] {
            d = d
                .max(z + MARGIN * h.x / tan_x)
                .max(z + MARGIN * h.y / tan_y);
        }
        // Keep the box's near face well in front of the eye even when the box is flat.
        let extent = h.length();
        let gap = if extent > 0.0 { 0.1 * extent } else { 1.0 };
        d = d.max(h.z + gap);
        Camera {
            eye: centre + Vec3::new(0.0, 0.0, d),
            target: centre,
            up: Vec3::Y,
            fov_y_deg,
        }
    }
}
