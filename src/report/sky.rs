//! The sky of a solve as `summary.json` gives it (`sky`): enough to draw the same sky with
//! Radiance's `gensky` (docs/design.md §9).

use crate::sky::{Sky, SkyKind, SkySpec, EFFICACY};
use serde::Serialize;

/// The sky of a solve, as `summary.json` gives it: enough to draw the same sky with
/// Radiance's `gensky -ang ALT AZI -b ZENITH/179` (`scripts/radiance/daylight.py` does).
#[derive(Clone, Debug, Serialize)]
pub struct SkyReport {
    pub kind: SkyKind,
    /// The zenith parameter L_z, cd/m² (`gensky -b` × 179).
    pub zenith_luminance: f64,
    /// The sky's unobstructed horizontal illuminance without the sun, lux.
    pub sky_illuminance: f64,
    pub sun: Option<SunReport>,
    pub ground_reflectance: f64,
    pub zenith: [f32; 3],
    pub north: [f32; 3],
    /// The luminous efficacy lux and cd/m² are converted with (Radiance's, for white light).
    pub efficacy: f64,
    /// What the daylight factor is taken over: the sky's and sun's unobstructed horizontal
    /// illuminance, lux.
    pub df_base: f64,
}

/// The sun of a [`SkyReport`].
#[derive(Clone, Copy, Debug, Serialize)]
pub struct SunReport {
    /// Degrees above the horizon.
    pub altitude: f64,
    /// Degrees west of south (`gensky -ang`).
    pub azimuth: f64,
    /// Direct normal illuminance, lux.
    pub normal_illuminance: f64,
}

impl SkyReport {
    pub fn new(spec: &SkySpec, sky: &Sky) -> SkyReport {
        let (sky_lux, sun_lux) = sky.horizontal_illuminance();
        SkyReport {
            kind: spec.kind,
            zenith_luminance: sky.zenith_luminance(),
            sky_illuminance: sky_lux,
            sun: sky.sun().map(|s| SunReport {
                altitude: s.angles.altitude,
                azimuth: s.angles.azimuth,
                normal_illuminance: s.normal_illuminance(),
            }),
            ground_reflectance: spec.ground_reflectance,
            zenith: spec.zenith.to_array(),
            north: spec.north.to_array(),
            efficacy: EFFICACY,
            df_base: sky_lux + sun_lux,
        }
    }
}
