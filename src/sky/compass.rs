//! The sky's orientation in the model: which way is up and which way is north.
//!
//! The sky's formulas work in a local frame (east, north, up), the convention of Radiance's
//! `gensky` (X east, Y north, Z up). A model gives its own zenith and north; east follows as
//! north × up, so the local frame is right-handed whatever the model's axes.
//!
//! **The default north follows the zenith.** With the default zenith +Y (OBJ's usual
//! convention) north is −Z, so a plan seen from above reads as a map with east +X. For any
//! other zenith, the default north is −Z turned by the shortest rotation that takes +Y to the
//! zenith ([`Compass::default_north`]): +Y for a Z-up model (Radiance's and most CAD tools'
//! convention, east +X again), −Z still for an X-up one. For the zenith −Y, where the shortest
//! rotation is not unique, the half turn about +X is taken (north +Z), the limit of the turns
//! through the Z-up case.

use crate::settings::Invalid;
use glam::{DQuat, DVec3, Vec3};

/// The default zenith, +Y: OBJ models are usually Y-up.
pub const DEFAULT_ZENITH: Vec3 = Vec3::Y;

/// The default north with the default zenith, −Z: with +Y up this makes east +X, a plan seen
/// from above as a map. With another zenith, see [`Compass::default_north`].
pub const DEFAULT_NORTH: Vec3 = Vec3::NEG_Z;

/// Smallest horizontal part of the north direction (as a fraction of its length): below it
/// north is taken to be parallel to the zenith (about 0.06° from it).
const MIN_HORIZONTAL: f64 = 1e-3;

/// An orthonormal frame: the model's east, north and up (zenith) directions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Compass {
    east: DVec3,
    north: DVec3,
    up: DVec3,
}

impl Default for Compass {
    /// [`DEFAULT_ZENITH`] and [`DEFAULT_NORTH`]: up +Y, north −Z, east +X.
    fn default() -> Compass {
        Compass {
            east: DVec3::X,
            north: DVec3::NEG_Z,
            up: DVec3::Y,
        }
    }
}

impl Compass {
    /// The frame of `zenith` and `north` (any lengths). North need not be horizontal: only its
    /// part perpendicular to the zenith counts. Refuses zero or non-finite vectors and a north
    /// (nearly) parallel to the zenith, naming the flag (`--zenith`, `--north`).
    pub fn new(zenith: Vec3, north: Vec3) -> Result<Compass, Invalid> {
        let up = unit(zenith, "zenith")?;
        let n = unit(north, "north")?;
        let horizontal = n - n.dot(up) * up;
        if horizontal.length() < MIN_HORIZONTAL {
            return Invalid::err(format!(
                "--north: north {north} is parallel to the zenith {zenith}"
            ));
        }
        let north = horizontal.normalize();
        let east = north.cross(up);
        Ok(Compass { east, north, up })
    }

    /// The north a model has when only its zenith is given (see the [module docs](self)):
    /// [`DEFAULT_NORTH`] turned by the shortest rotation from +Y to `zenith`; exactly
    /// [`DEFAULT_NORTH`] for the default zenith, +Y for +Z. A zenith that is no direction
    /// gets [`DEFAULT_NORTH`] (the zenith's own check refuses it).
    pub fn default_north(zenith: Vec3) -> Vec3 {
        let up = zenith.as_dvec3().normalize_or_zero();
        if up == DVec3::Y || up == DVec3::ZERO || !up.is_finite() {
            return DEFAULT_NORTH;
        }
        let turn = if up.dot(DVec3::Y) < -1.0 + 1e-12 {
            DQuat::from_rotation_x(std::f64::consts::PI)
        } else {
            DQuat::from_rotation_arc(DVec3::Y, up)
        };
        let north = turn * DEFAULT_NORTH.as_dvec3();
        // Round away the rotation's last-bit noise, so +Z up gives exactly +Y.
        let clean = |x: f64| if x.abs() < 1e-12 { 0.0 } else { x };
        DVec3::new(clean(north.x), clean(north.y), clean(north.z)).as_vec3()
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

/// `v` normalised, or the error naming its flag (`--zenith`, `--north`).
fn unit(v: Vec3, which: &'static str) -> Result<DVec3, Invalid> {
    let d = v.as_dvec3();
    let len = d.length();
    if !len.is_finite() || len <= 0.0 {
        return Invalid::err(format!(
            "--{which}: the {which} direction {v} is zero or not finite"
        ));
    }
    Ok(d / len)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_is_y_up_north_minus_z_east_x() {
        let f = Compass::new(DEFAULT_ZENITH, DEFAULT_NORTH).unwrap();
        assert_eq!(f, Compass::default());
        assert_eq!(f.east(), DVec3::X);
    }

    #[test]
    fn default_north_follows_the_zenith() {
        // Y up keeps today's default exactly; Z up is Radiance's north +Y (east +X).
        assert_eq!(Compass::default_north(Vec3::Y), DEFAULT_NORTH);
        assert_eq!(
            Compass::default_north(Vec3::new(0.0, 3.0, 0.0)),
            DEFAULT_NORTH
        );
        assert_eq!(Compass::default_north(Vec3::Z), Vec3::Y);
        assert_eq!(Compass::default_north(Vec3::X), Vec3::NEG_Z);
        assert_eq!(Compass::default_north(Vec3::NEG_Y), Vec3::Z);
        assert_eq!(Compass::default_north(Vec3::NEG_Z), Vec3::NEG_Y);
        let z_up = Compass::new(Vec3::Z, Compass::default_north(Vec3::Z)).unwrap();
        assert_eq!(z_up.east(), DVec3::X);
        // Any zenith gets a north at right angles to it.
        for z in [
            Vec3::new(0.1, 0.2, 3.0),
            Vec3::new(-1.0, 0.5, 0.0),
            Vec3::new(0.001, -1.0, 0.0),
        ] {
            let n = Compass::default_north(z);
            assert!(n.dot(z).abs() < 1e-5 * z.length(), "{z} {n}");
            assert!(Compass::new(z, n).is_ok(), "{z} {n}");
        }
    }

    #[test]
    fn frame_is_orthonormal_and_right_handed() {
        let f = Compass::new(Vec3::new(0.1, 0.2, 3.0), Vec3::new(1.0, 1.0, 0.5)).unwrap();
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
    fn refuses_zero_nan_and_parallel_naming_the_flag() {
        let e = Compass::new(Vec3::ZERO, DEFAULT_NORTH).unwrap_err().0;
        assert!(e.starts_with("--zenith: the zenith direction"), "{e}");
        let e = Compass::new(DEFAULT_ZENITH, Vec3::new(f32::NAN, 0.0, 1.0))
            .unwrap_err()
            .0;
        assert!(e.starts_with("--north: the north direction"), "{e}");
        let e = Compass::new(Vec3::Z, Vec3::new(0.0, 1e-5, -2.0))
            .unwrap_err()
            .0;
        assert!(
            e.starts_with("--north: north") && e.contains("parallel"),
            "{e}"
        );
    }
}
