//! Daylight: the sky and the sun as distant emitters (issue 14).
//!
//! This module owns the light that comes from outside the model: the sky's luminance
//! distribution ([`cie`]: uniform, CIE overcast, CIE clear), the sun's position ([`solar`]: NOAA's
//! algorithm) and disc (`sun`), the ground glow below the horizon, the model's orientation
//! ([`frame`]) and the cut of all of it into directional pieces a shooter can fire parallel
//! rays from ([`tregenza`], `piece`). It follows the conventions of Radiance's `gensky`, so a
//! scene can be checked against Radiance:
//!
//! - the zenith parameter L_z is `gensky -b` (in cd/m² here, W/sr/m² there: divide by 179);
//! - the horizontal illuminance is the sky's alone, without the sun (`gensky -B`);
//! - solar azimuth is degrees west of south (`gensky -ang ALT AZI`);
//! - the ground below the horizon is uniform with radiance ρ_g E_h / π, E_h the sky's plus the
//!   sun's horizontal irradiance and ρ_g the ground reflectance (`gensky -g`, default 0.2).
//!
//! Two departures: the horizon is sharp (`skybright.cal` blends sky into ground over a few
//! degrees with weights (cos θ + 1.01)^±10), so the pieces carry exactly the stated horizontal
//! illuminance; and a clear sky's sun above 87° stays where it is (`gensky` lowers it to 87°).
//! Sky and sun are white: equal RGB radiance.
//!
//! **Units.** Radiance is in W/sr/m² and irradiance in W/m², the solver's units; photometric
//! values (cd/m², lux) convert by [`EFFICACY`].

pub mod cie;
pub mod frame;
pub mod solar;
pub mod tregenza;

pub use cie::SkyKind;
pub use frame::{Frame, DEFAULT_NORTH, DEFAULT_ZENITH};
pub use solar::{DateTime, Site, SolarAngles};

use glam::Vec3;

/// Luminous efficacy of white light, lm/W: luminance (cd/m²) = 179 × radiance (W/sr/m²) and
/// illuminance (lux) = 179 × irradiance (W/m²). Radiance's convention for white light (its
/// `rtrace -I` results are turned into lux with the same factor).
pub const EFFICACY: f64 = 179.0;

/// A sky that cannot be built.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SkyError {
    #[error("the {which} direction {v} is zero or not finite")]
    BadDirection { which: &'static str, v: Vec3 },
    #[error("north {north} is parallel to the zenith {zenith}")]
    Parallel { zenith: Vec3, north: Vec3 },
    #[error("the ground reflectance {0} is not within [0, 1]")]
    BadReflectance(f64),
    #[error("the {what} {value} is not a finite, non-negative number")]
    BadLevel { what: &'static str, value: f64 },
    #[error("{0} needs the sun's position (altitude and azimuth, or a site and a time)")]
    NoSunPosition(&'static str),
    #[error(
        "solar altitude {altitude}° and azimuth {azimuth}°: the altitude must be within [-90, 90]"
    )]
    BadAngles { altitude: f64, azimuth: f64 },
    #[error("latitude {latitude}°, longitude {longitude}° is not a place on the earth")]
    BadSite { latitude: f64, longitude: f64 },
    #[error("bad date and time: {0}")]
    BadTime(String),
}
