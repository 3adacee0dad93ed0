//! The camera: where it stands, where it looks, how it projects (perspective or parallel) and
//! where it clips; the camera fitted to a scene's bounds; and the primary ray through any point
//! of the picture.
//!
//! The conventions are Radiance's view options (`rpict`, `rvu`, src/common/image.c): a view is
//! a point (`-vp`), a direction (`-vd`), an up vector (`-vu`), a horizontal and vertical size
//! (`-vh`, `-vv`: full angles in degrees for a perspective view, the width and height in scene
//! units for a parallel one), a fore and aft clipping distance measured along the view direction
//! (`-vo`, `-va`, 0 for none) and a shift and lift of the picture in fractions of its width and
//! height (`-vs`, `-vl`). [`Camera::ray`] is Radiance's `viewray()` with the picture's y axis
//! pointing down (image rows, top first), and the rasterizer projects with the same numbers, so
//! a point seen through a pixel lies on that pixel's ray.

use glam::{Vec2, Vec3};
use serde::{Deserialize, Serialize};

/// How a camera maps directions onto the picture.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Projection {
    /// A pinhole: the full horizontal and vertical angles of view, in degrees (Radiance's
    /// `-vtv -vh -vv`). Each is clamped to 0.01..179.9 when used.
    Perspective { fov_x_deg: f32, fov_y_deg: f32 },
    /// Orthographic: parallel rays along the view direction; the view's width and height in
    /// scene units (Radiance's `-vtl -vh -vv`). A non-positive or non-finite side is taken as 1.
    Parallel { width: f32, height: f32 },
}

impl Projection {
    /// Perspective with vertical angle `fov_y_deg` and the horizontal angle that makes the
    /// picture `aspect` (width / height) with square pixels: tan(x/2) = aspect·tan(y/2).
    pub fn perspective_for_aspect(fov_y_deg: f32, aspect: f32) -> Projection {
        let tan_y = (0.5 * clamp_angle(fov_y_deg)).to_radians().tan();
        let fov_x_deg = 2.0 * (aspect * tan_y).atan().to_degrees();
        Projection::Perspective {
            fov_x_deg,
            fov_y_deg,
        }
    }

    /// The projection as drawn: angles clamped to 0.01..179.9 degrees (40 if not finite),
    /// parallel sides non-positive or non-finite taken as 1.
    pub fn as_drawn(&self) -> Projection {
        match *self {
            Projection::Perspective {
                fov_x_deg,
                fov_y_deg,
            } => Projection::Perspective {
                fov_x_deg: clamp_angle(fov_x_deg),
                fov_y_deg: clamp_angle(fov_y_deg),
            },
            Projection::Parallel { width, height } => {
                let side = |s: f32| if s.is_finite() && s > 0.0 { s } else { 1.0 };
                Projection::Parallel {
                    width: side(width),
                    height: side(height),
                }
            }
        }
    }

    /// The half-size of the picture on its image plane: (tan(fov_x/2), tan(fov_y/2)) at unit
    /// distance for a perspective view, (width/2, height/2) for a parallel one. Always finite
    /// and positive.
    pub fn half_extent(&self) -> Vec2 {
        match self.as_drawn() {
            Projection::Perspective {
                fov_x_deg,
                fov_y_deg,
            } => Vec2::new(
                (0.5 * fov_x_deg).to_radians().tan(),
                (0.5 * fov_y_deg).to_radians().tan(),
            ),
            Projection::Parallel { width, height } => Vec2::new(0.5 * width, 0.5 * height),
        }
    }

    /// Width / height of the picture this projection shows with square pixels.
    pub fn aspect(&self) -> f32 {
        let h = self.half_extent();
        h.x / h.y
    }

    /// True for [`Projection::Parallel`].
    pub fn is_parallel(&self) -> bool {
        matches!(self, Projection::Parallel { .. })
    }
}

/// An angle of view in degrees as the projection uses it: finite, within 0.01..179.9.
fn clamp_angle(deg: f32) -> f32 {
    if deg.is_finite() {
        deg.clamp(0.01, 179.9)
    } else {
        40.0
    }
}

/// A camera: position, aim, projection and clipping.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub eye: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    pub projection: Projection,
    /// Fore clipping distance along the view direction (Radiance's `-vo`): nothing nearer is
    /// drawn, so a camera inside a wall's thickness sees past it. 0 clips nothing but what is
    /// behind the eye (a perspective view keeps a tiny near plane relative to the scene).
    pub near: f32,
    /// Aft clipping distance along the view direction (Radiance's `-va`); `None` for none.
    pub far: Option<f32>,
    /// The picture's shift and lift (Radiance's `-vs`, `-vl`): its centre moved right and up by
    /// these fractions of its width and height, the eye staying put (an off-axis view, as a
    /// perspective-correcting camera takes to keep verticals vertical).
    pub shift: Vec2,
}

impl Camera {
    /// A perspective camera with vertical angle `fov_y_deg`, showing a picture of `aspect`
    /// (width / height) with square pixels; no clipping, no shift.
    pub fn perspective(eye: Vec3, target: Vec3, up: Vec3, fov_y_deg: f32, aspect: f32) -> Camera {
        Camera {
            eye,
            target,
            up,
            projection: Projection::perspective_for_aspect(fov_y_deg, aspect),
            near: 0.0,
            far: None,
            shift: Vec2::ZERO,
        }
    }

    /// Fitted to the scene: looks along -z from the +z side (y up), fov 40°, distance so the whole
    /// bounding box fits in view with a small margin, aimed at the box centre
    /// ([`Camera::fit_along`] along −z with y up).
    ///
    /// A non-finite or inverted box (such as the bounds of an empty mesh) is replaced by the unit
    /// cube around the origin; a non-positive or non-finite `aspect` (width / height) by 1.
    pub fn fit(lo: Vec3, hi: Vec3, aspect: f32) -> Camera {
        Camera::fit_along(lo, hi, aspect, Vec3::NEG_Z, Vec3::Y)
    }

    /// Fitted to the scene seen along `fwd` with `up` up the picture: fov 40°, distance so the
    /// whole bounding box fits in view with a small margin, aimed at the box centre. The box is
    /// measured along the axes of the camera's frame (its extent along each, which is exact for
    /// an axis-aligned frame), so any direction fits. A degenerate `fwd` or `up` falls back as
    /// [`Camera::frame`] does; the box and `aspect` are sanitised as in [`Camera::fit`].
    pub fn fit_along(lo: Vec3, hi: Vec3, aspect: f32, fwd: Vec3, up: Vec3) -> Camera {
        let (lo, hi) = if lo.is_finite() && hi.is_finite() && lo.cmple(hi).all() {
            (lo, hi)
        } else {
            (Vec3::splat(-0.5), Vec3::splat(0.5))
        };
        let frame = Camera::perspective(Vec3::ZERO, fwd, up, 40.0, 1.0).frame();
        let h = 0.5 * (hi - lo);
        let half = frame.half_extent(h);
        Camera::fit_frame(0.5 * (lo + hi), half, h.length(), &frame, aspect)
    }

    /// Fitted to a box of centre `centre` and half-extents `half` along the frame's right, up
    /// and backward axes (see [`Camera::fit_along`]); `extent` is the scene's size that keeps
    /// the box's near face in front of the eye even when the box is flat.
    pub(crate) fn fit_frame(
        centre: Vec3,
        half: Vec3,
        extent: f32,
        frame: &CameraFrame,
        aspect: f32,
    ) -> Camera {
        let aspect = if aspect.is_finite() && aspect > 0.0 {
            aspect
        } else {
            1.0
        };
        let fov_y_deg = 40.0_f32;
        let projection = Projection::perspective_for_aspect(fov_y_deg, aspect);
        let Vec2 { x: tan_x, y: tan_y } = projection.half_extent();
        // Corners end up at most 1/MARGIN of the way from the image centre to its edge.
        const MARGIN: f32 = 1.1;
        let h = half;
        // With the eye at centre + d·back, a corner at offset (x, y, z) in the frame lies at
        // depth d − z and is in view when |x| ≤ (d − z)·tan_x / MARGIN (same for y): solve each
        // for d.
        let mut d: f32 = 0.0;
        for z in [-h.z, h.z] {
            d = d
                .max(z + MARGIN * h.x / tan_x)
                .max(z + MARGIN * h.y / tan_y);
        }
        // Keep the box's near face well in front of the eye even when the box is flat.
        let gap = if extent > 0.0 { 0.1 * extent } else { 1.0 };
        d = d.max(h.z + gap);
        let back = -frame.fwd;
        Camera {
            projection,
            ..Camera::perspective(centre + d * back, centre, frame.given_up, fov_y_deg, aspect)
        }
    }

    /// The camera's orthonormal frame (right, up, forward), with the up vector it was built
    /// from. A degenerate camera (eye == target, up parallel to the view direction, non-finite
    /// values) falls back to looking along -z and to another up vector (y, z or x), so every
    /// camera can draw.
    pub fn frame(&self) -> CameraFrame {
        let mut fwd = (self.target - self.eye).normalize_or_zero();
        if !fwd.is_finite() || fwd == Vec3::ZERO {
            fwd = Vec3::NEG_Z;
        }
        for up in [self.up, Vec3::Y, Vec3::Z, Vec3::X] {
            let up = up.normalize_or_zero();
            let r = fwd.cross(up);
            // sin of the angle between fwd and up above 1e-3: the frame is well conditioned.
            if r.is_finite() && r.length_squared() > 1e-6 {
                let right = r.normalize();
                return CameraFrame {
                    right,
                    up: right.cross(fwd),
                    fwd,
                    given_up: up,
                };
            }
        }
        // Not reached (one of y, z, x is at least 54° from any unit vector), but never panic.
        CameraFrame {
            right: Vec3::X,
            up: Vec3::Y,
            fwd: Vec3::NEG_Z,
            given_up: Vec3::Y,
        }
    }

    /// The eye, finite (the origin if not).
    pub(crate) fn eye_or_origin(&self) -> Vec3 {
        if self.eye.is_finite() {
            self.eye
        } else {
            Vec3::ZERO
        }
    }

    /// The fore clipping distance as drawn: finite and at least 0.
    pub fn near_distance(&self) -> f32 {
        if self.near.is_finite() {
            self.near.max(0.0)
        } else {
            0.0
        }
    }

    /// The aft clipping distance as drawn: beyond the fore one and finite, or none.
    pub fn far_distance(&self) -> Option<f32> {
        self.far
            .filter(|f| f.is_finite() && *f > self.near_distance())
    }

    /// The shift and lift as drawn: finite (0 if not).
    pub fn shift_or_zero(&self) -> Vec2 {
        if self.shift.is_finite() {
            self.shift
        } else {
            Vec2::ZERO
        }
    }

    /// The point of the image plane (at unit depth for a perspective view, in scene units off
    /// the axis for a parallel one; x right, y up) seen at picture position (u, v): u from 0 at
    /// the left edge to 1 at the right, v from 0 at the top edge to 1 at the bottom.
    fn image_plane(&self, u: f32, v: f32) -> Vec2 {
        let half = self.projection.half_extent();
        let s = self.shift_or_zero();
        // Radiance's viewray(): x' = x + hoff − 0.5, y' = y + voff − 0.5, y up from the bottom.
        Vec2::new(
            2.0 * half.x * (u - 0.5 + s.x),
            2.0 * half.y * (0.5 - v + s.y),
        )
    }

    /// The primary ray through picture position (u, v) (u from 0 at the left edge to 1 at the
    /// right, v from 0 at the top edge to 1 at the bottom; a pixel's centre in a W×H picture is
    /// ((col + 0.5)/W, (row + 0.5)/H)): its origin and unit direction.
    ///
    /// As Radiance's `viewray()`: a perspective ray leaves the eye, moved forward to the fore
    /// clipping plane when there is one; a parallel ray leaves the plane through the eye
    /// square to the view direction (or the fore clipping plane), along the view direction.
    /// The origin is where what the ray meets starts to count, which is what the rasterizer
    /// shows (clipped at the same plane).
    pub fn ray(&self, u: f32, v: f32) -> (Vec3, Vec3) {
        let f = self.frame();
        let p = self.image_plane(u, v);
        let across = p.x * f.right + p.y * f.up;
        let near = self.near_distance();
        let eye = self.eye_or_origin();
        if self.projection.is_parallel() {
            (eye + across + near * f.fwd, f.fwd)
        } else {
            let d = f.fwd + across;
            (eye + near * d, d.normalize())
        }
    }

    /// Where a point lands on the picture, (u, v) as in [`Camera::ray`], with its depth along
    /// the view direction; `None` for a point at or behind the eye (perspective). The
    /// rasterizer's projection, for any caller that wants to place a point on the picture.
    pub fn project(&self, p: Vec3) -> Option<(Vec2, f32)> {
        let f = self.frame();
        let d = p - self.eye_or_origin();
        let (x, y, z) = (d.dot(f.right), d.dot(f.up), d.dot(f.fwd));
        let plane = if self.projection.is_parallel() {
            Vec2::new(x, y)
        } else {
            if z <= 0.0 {
                return None;
            }
            Vec2::new(x / z, y / z)
        };
        let half = self.projection.half_extent();
        let s = self.shift_or_zero();
        let uv = Vec2::new(
            plane.x / (2.0 * half.x) + 0.5 - s.x,
            0.5 - plane.y / (2.0 * half.y) + s.y,
        );
        Some((uv, z))
    }
}

/// A camera's orthonormal frame ([`Camera::frame`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraFrame {
    pub right: Vec3,
    pub up: Vec3,
    pub fwd: Vec3,
    /// The unit up vector the frame was built from: the camera's own, or the fallback.
    pub given_up: Vec3,
}

impl CameraFrame {
    /// The half-extents along (right, up, backward) of the box of half-extents `h` (along x, y,
    /// z): the extent of its projection on each axis, |a.x|·h.x + |a.y|·h.y + |a.z|·h.z.
    pub fn half_extent(&self, h: Vec3) -> Vec3 {
        let along = |a: Vec3| a.abs().dot(h);
        Vec3::new(along(self.right), along(self.up), along(-self.fwd))
    }
}
