//! The sky's orientation in the model: which way is up and which way is north.
//!
//! The sky's formulas work in a local frame (east, north, up), the convention of Radiance's
//! `gensky` (X east, Y north, Z up). A model gives its own zenith and north; east follows as
//! north × up, so the local frame is right-handed whatever the model's axes.

use super::SkyError;
use glam::{DVec3, Vec3};

/// The default zenith, +Y: OBJ models are usually Y-up.
pub const DEFAULT_ZENITH: Vec3 = Vec3::Y;

/// The default north, −Z: with +Y up this makes east +X, a plan seen from above as a map.
pub const DEFAULT_NORTH: Vec3 = Vec3::NEG_Z;

/// Smallest horizontal part of the north direction (as a fraction of its length): below it
/// north is taken to be parallel to the zenith (about 0.06° from it).
const MIN_HORIZONTAL: f64 = 1e-3;

/// An orthonormal frame: the model's east, north and up (zenith) directions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    east: DVec3,
    north: DVec3,
    up: DVec3,
}

impl Default for Frame {
    /// [`DEFAULT_ZENITH`] and [`DEFAULT_NORTH`]: up +Y, north −Z, east +X.
    fn default() -> Frame {
        Frame {
            east: DVec3::X,
            north: DVec3::NEG_Z,
            up: DVec3::Y,
        }
    }
}

impl Frame {
    /// The frame of `zenith` and `north` (any lengths). North need not be horizontal: only its
    /// part perpendicular to the zenith counts. Refuses zero or non-finite vectors and a north
    /// (nearly) parallel to the zenith.
    pub fn new(zenith: Vec3, north: Vec3) -> Result<Frame, SkyError> {
        let up = unit(zenith, "zenith")?;
        let n = unit(north, "north")?;
        let horizontal = n - n.dot(up) * up;
        if horizontal.length() < MIN_HORIZONTAL {
            return Err(SkyError::Parallel { zenith, north });
        }
        let north = horizontal.normalize();
        let east = north.cross(up);
        Ok(Frame { east, north, up })
    }

    /// The zenith (unit).
    pub fn up(&self) -> DVec3 {
        self.up
    }

    /// North, made perpendicular to the zenith (unit).
    pub fn north(&self) -> DVec3 {
        self.north
    }

    /// East = north × up (unit).
    pub fn east(&self) -> DVec3 {
        self.east
    }

    /// A local direction (x east, y north, z up) in model coordinates.
    pub fn to_world(&self, local: DVec3) -> DVec3 {
        local.x * self.east + local.y * self.north + local.z * self.up
    }

    /// A model direction in local coordinates (x east, y north, z up).
    pub fn to_local(&self, world: DVec3) -> DVec3 {
        DVec3::new(
            world.dot(self.east),
            world.dot(self.north),
            world.dot(self.up),
        )
    }
}

/// `v` normalised, or the error naming it.
fn unit(v: Vec3, which: &'static str) -> Result<DVec3, SkyError> {
    let d = v.as_dvec3();
    let len = d.length();
    if !len.is_finite() || len <= 0.0 {
        return Err(SkyError::BadDirection { which, v });
    }
    Ok(d / len)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_is_y_up_north_minus_z_east_x() {
        let f = Frame::new(DEFAULT_ZENITH, DEFAULT_NORTH).unwrap();
        assert_eq!(f, Frame::default());
        assert_eq!(f.east(), DVec3::X);
    }

    #[test]
    fn frame_is_orthonormal_and_right_handed() {
        let f = Frame::new(Vec3::new(0.1, 0.2, 3.0), Vec3::new(1.0, 1.0, 0.5)).unwrap();
        // Products of unit vectors built in f64: exact to a few ulps.
        for (a, b) in [(f.east, f.north), (f.north, f.up), (f.up, f.east)] {
            assert!(a.dot(b).abs() < 1e-12);
            assert!((a.length() - 1.0).abs() < 1e-12);
        }
        assert!((f.east.cross(f.north) - f.up).length() < 1e-12);
        let d = DVec3::new(0.3, -0.4, 0.5);
        assert!((f.to_local(f.to_world(d)) - d).length() < 1e-12);
    }

    #[test]
    fn refuses_zero_nan_and_parallel() {
        assert!(matches!(
            Frame::new(Vec3::ZERO, DEFAULT_NORTH),
            Err(SkyError::BadDirection {
                which: "zenith",
                ..
            })
        ));
        assert!(matches!(
            Frame::new(DEFAULT_ZENITH, Vec3::new(f32::NAN, 0.0, 1.0)),
            Err(SkyError::BadDirection { which: "north", .. })
        ));
        assert!(matches!(
            Frame::new(Vec3::Z, Vec3::new(0.0, 1e-5, -2.0)),
            Err(SkyError::Parallel { .. })
        ));
    }
}
