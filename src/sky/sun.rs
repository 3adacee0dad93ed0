//! The sun as an emitter: a disc of 0.533° seen from the earth, with a direct normal
//! illuminance.
//!
//! The disc's radiance is uniform: L_s = E_n / (π sin²α), α the disc's angular radius, so that
//! a surface facing the sun receives exactly E_n (∫ cos dω over a cap of half-angle α about
//! its axis is π sin²α) and a horizontal one E_n sin h.
//!
//! The default E_n is `gensky`'s clear-sky sun: luminance 1.5 × 10⁹ cd/m² over 6 × 10⁻⁵ sr
//! (its 0.5° disc), converted to radiance with its solar efficacy of 208 lm/W and reduced by the
//! air mass through the factor 1.147 − 0.147 / max(sin h, 0.16):
//!
//! E_n = 1.5 × 10⁹ / 208 · 6 × 10⁻⁵ · (1.147 − 0.147 / max(sin h, 0.16)) W/m²,
//!
//! 432.7 W/m² with the sun overhead. This keeps `gensky`'s watts, so a scene lit by both agrees;
//! in lux by this crate's [`super::EFFICACY`] (179 lm/W, as `rtrace -I` users multiply by) that is
//! 77,452 lux overhead, 66,066 lux at 30°.

use super::compass::Compass;
use super::solar::SolarAngles;
use super::EFFICACY;
use glam::{DVec3, Vec3};
use std::f64::consts::{PI, TAU};

/// The solar disc's mean angular diameter, degrees.
pub const SUN_DIAMETER_DEGREES: f64 = 0.533;

/// How bright the sun is.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SunLevel {
    /// `gensky`'s clear-sky sun (see the module docs).
    Gensky,
    /// Direct normal illuminance, lux.
    NormalIlluminance(f64),
    /// Direct illuminance on an unobstructed horizontal plane, lux (`gensky -R`, in lux).
    HorizontalIlluminance(f64),
}

/// The sun above the horizon: its direction, disc and brightness.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sun {
    /// Unit vector from the scene towards the sun's centre (model coordinates).
    pub dir: Vec3,
    /// Where it is in the local sky.
    pub angles: SolarAngles,
    /// Direct normal irradiance E_n, W/m².
    pub normal_irradiance: f64,
    dir64: DVec3,
}

impl Sun {
    /// The sun at `angles`, as bright as `level` says, oriented by `compass`; `None` when its
    /// centre is not above the horizon.
    pub fn new(angles: SolarAngles, level: SunLevel, compass: &Compass) -> Option<Sun> {
        if angles.altitude <= 0.0 {
            return None;
        }
        let sin_h = angles.altitude.to_radians().sin();
        let normal_irradiance = match level {
            SunLevel::Gensky => gensky_normal_irradiance(sin_h),
            SunLevel::NormalIlluminance(lux) => lux / EFFICACY,
            SunLevel::HorizontalIlluminance(lux) => lux / EFFICACY / sin_h,
        };
        let dir64 = compass.to_world(angles.local_dir()).normalize();
        Some(Sun {
            dir: dir64.as_vec3(),
            angles,
            normal_irradiance,
            dir64,
        })
    }

    /// The disc's angular radius α, radians.
    pub fn half_angle() -> f64 {
        (SUN_DIAMETER_DEGREES / 2.0).to_radians()
    }

    /// The disc's solid angle 2π (1 − cos α), steradians (6.80 × 10⁻⁵).
    pub fn solid_angle() -> f64 {
        TAU * (1.0 - Sun::half_angle().cos())
    }

    /// The disc's radiance E_n / (π sin²α), W/sr/m², white.
    pub fn radiance(&self) -> [f64; 3] {
        [self.normal_irradiance / (PI * Sun::half_angle().sin().powi(2)); 3]
    }

    /// Direct normal illuminance, lux.
    pub fn normal_illuminance(&self) -> f64 {
        self.normal_irradiance * EFFICACY
    }

    /// Direct irradiance on an unobstructed horizontal plane, E_n sin h, W/m².
    pub fn horizontal_irradiance(&self) -> f64 {
        self.normal_irradiance * self.angles.altitude.to_radians().sin()
    }

    /// Projected solid angle of the disc about the zenith: π sin²α · sin h.
    pub fn projected_solid_angle(&self) -> f64 {
        PI * Sun::half_angle().sin().powi(2) * self.angles.altitude.to_radians().sin()
    }

    /// A direction towards the disc at (u, v) ∈ [0, 1]², uniform in solid angle over it.
    pub fn sample(&self, u: f64, v: f64) -> Vec3 {
        cone_sample(self.dir64, Sun::half_angle().cos(), u, v).as_vec3()
    }
}

/// `gensky`'s direct normal irradiance (W/m²) of a clear-sky sun at sin h = `sin_h`.
pub fn gensky_normal_irradiance(sin_h: f64) -> f64 {
    1.5e9 / 208.0 * 6e-5 * (1.147 - 0.147 / sin_h.max(0.16))
}

/// A direction uniform in solid angle within the cone of axis `axis` (unit) and half-angle
/// acos(`cos_max`), at (u, v) ∈ [0, 1]².
fn cone_sample(axis: DVec3, cos_max: f64, u: f64, v: f64) -> DVec3 {
    let cos_t = 1.0 - u.clamp(0.0, 1.0) * (1.0 - cos_max);
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let (sin_p, cos_p) = (TAU * v).sin_cos();
    let (t, b) = axis.any_orthonormal_pair();
    (sin_t * cos_p * t + sin_t * sin_p * b + cos_t * axis).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn compass() -> Compass {
        Compass::default()
    }

    #[test]
    fn gensky_default_sun() {
        // 1.5e9/208 · 6e-5 = 432.69 W/m²; at 30° the factor is 1.147 − 0.294 = 0.853.
        let overhead = gensky_normal_irradiance(1.0);
        assert!((overhead - 432.6923).abs() < 1e-3, "{overhead}");
        let sun = Sun::new(
            SolarAngles::new(30.0, 0.0).unwrap(),
            SunLevel::Gensky,
            &compass(),
        );
        let lux = sun.unwrap().normal_illuminance();
        assert!((lux - 432.6923 * 0.853 * 179.0).abs() < 0.1, "{lux}");
    }

    #[test]
    fn disc_radiance_gives_the_normal_irradiance() {
        let angles = SolarAngles::new(40.0, 20.0).unwrap();
        let sun = Sun::new(angles, SunLevel::NormalIlluminance(80_000.0), &compass()).unwrap();
        // L_s · π sin²α = E_n exactly; E_n sin h on the horizontal.
        let e_n = sun.radiance()[0] * PI * Sun::half_angle().sin().powi(2);
        assert!((e_n * EFFICACY - 80_000.0).abs() < 1e-9);
        let e_h = sun.radiance()[0] * sun.projected_solid_angle();
        assert!((e_h - sun.horizontal_irradiance()).abs() < 1e-12);
        // Solid angle of a 0.533° disc: π α² (1 − α²/12) = 6.7967e-5 sr.
        assert!(
            (Sun::solid_angle() - 6.7967e-5).abs() < 1e-9,
            "{}",
            Sun::solid_angle()
        );
    }

    #[test]
    fn horizontal_level_is_divided_by_sin_h() {
        let angles = SolarAngles::new(30.0, 0.0).unwrap();
        let sun = Sun::new(
            angles,
            SunLevel::HorizontalIlluminance(50_000.0),
            &compass(),
        )
        .unwrap();
        assert!((sun.normal_illuminance() - 100_000.0).abs() < 1e-6);
    }

    #[test]
    fn sun_below_the_horizon_is_none() {
        let angles = SolarAngles::new(-2.0, 0.0).unwrap();
        assert!(Sun::new(angles, SunLevel::Gensky, &compass()).is_none());
    }

    #[test]
    fn samples_fall_in_the_disc_and_sun_points_the_gensky_way() {
        // South at 45° in the default compass (north −Z, up +Y): +Z and +Y.
        let angles = SolarAngles::new(45.0, 0.0).unwrap();
        let sun = Sun::new(angles, SunLevel::Gensky, &compass()).unwrap();
        assert!((sun.dir - Vec3::new(0.0, 1.0, 1.0).normalize()).length() < 1e-6);
        let cos_max = Sun::half_angle().cos();
        for (u, v) in [(0.0, 0.0), (1.0, 0.25), (0.5, 0.9)] {
            let d = sun.sample(u, v).as_dvec3();
            assert!(d.dot(sun.dir64) >= cos_max - 1e-7, "{u} {v}");
        }
    }
}
