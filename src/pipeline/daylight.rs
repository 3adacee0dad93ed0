//! The daylight outputs of a solve (issue 14): the sky's description in `summary.json`, and
//! the sensor grid — `grid.csv`, the false-colour plan `grid.png`, the grid's statistics.

use crate::grid::{self, GridSpec, GridStats};
use crate::intersect::Intersector;
use crate::mesh::Mesh;
use crate::scene::Material;
use crate::sky::{Compass, Sky, SkyKind, SkySpec, EFFICACY};
use crate::solve::final_gather;
use serde::Serialize;

/// Rays each sensor gathers by default (`--grid-rays`): about 1 % noise per sensor.
pub const DEFAULT_GRID_RAYS: usize = 4096;

/// Width of the plan picture's panels, pixels.
pub const PLAN_WIDTH: u32 = 800;

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

/// A grid's sensors and what they measured.
pub struct GridResult {
    pub sensors: Vec<grid::Sensor>,
    pub lux: Vec<f64>,
    pub df: Vec<f64>,
    pub stats: GridStats,
}

/// Lux at each sensor of `spec` from the solution `b`: the gather at each point
/// ([`final_gather::sensor_irradiance`]), luminance-weighted, × 179 lm/W; the daylight factor
/// over `df_base` (0 without a sky).
#[allow(clippy::too_many_arguments)]
pub fn measure<I: Intersector>(
    spec: &GridSpec,
    mesh: &Mesh,
    materials: &[Material],
    isect: &I,
    b: &[[f64; 3]],
    sky: Option<&Sky>,
    frame: &Compass,
    rays: usize,
    seed: u64,
) -> Result<GridResult, grid::GridError> {
    let sensors = spec.sensors(mesh, isect, frame)?;
    let at: Vec<_> = sensors.iter().map(|s| (s.position, s.normal)).collect();
    let h = final_gather::sensor_irradiance(mesh, materials, isect, b, sky, &at, rays, seed);
    let luma = crate::export::patches::LUMA;
    let lux: Vec<f64> = h
        .iter()
        .map(|h| EFFICACY * (0..3).map(|c| luma[c] * h[c]).sum::<f64>())
        .map(|l| if l.is_finite() { l.max(0.0) } else { 0.0 })
        .collect();
    let base = sky.map(|s| {
        let (a, b) = s.horizontal_illuminance();
        a + b
    });
    let df: Vec<f64> = lux
        .iter()
        .map(|l| base.filter(|b| *b > 0.0).map_or(0.0, |b| 100.0 * l / b))
        .collect();
    let stats = grid::stats(&lux, &df);
    Ok(GridResult {
        sensors,
        lux,
        df,
        stats,
    })
}
