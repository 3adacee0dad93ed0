//! A year at the sensors from their daylight coefficients: each hour's illuminance is the
//! coefficients weighted by that hour's sky (docs/design.md §9, annual daylight), the
//! five-phase split of Radiance's annual methods (McNeil, *The Five-Phase Method*, 2013)
//! done with a radiosity solution:
//!
//! E(h, s) = 179 · [ Σ_c D_s,c · L_c(h)  +  R_s,c(h) · E_n(h) / Ω_c(h) ]  +  E_n,lux(h) · V_s(h)
//!
//! - D_s,c: sensor s's luminous coefficient of column c (the ground, then each sky patch):
//!   its direct view of the patch plus what the model reflects of it, per unit radiance;
//!   L_c(h) the hour's sky (Perez, without the sun: [`crate::sky::SunMode::Separate`]);
//! - the sun's **reflected** light: the hour's direct-normal irradiance E_n put into the one
//!   sky patch c(h) that holds the sun, as a radiance E_n / Ω_c over it, through that patch's
//!   reflected coefficient R alone (a patch is 0.04 sr at MF 1: where a sunlit floor patch
//!   lands moves by a few degrees, which the reflected light, spread over the room, hardly
//!   sees);
//! - the sun's **direct** light: V_s(h) = cos θ × the glazing's transmittance by a shadow ray
//!   towards the sun itself ([`crate::light::LightAt::sun_view`]), so sun patches keep their
//!   sharp edges; this term alone is LM-83's direct sunlight for ASE.

use crate::light::coefficients::SensorCoefficients;
use crate::sky::{reinhart, SkyMatrix, EFFICACY};
use rayon::prelude::*;

/// The sensors' luminous daylight coefficients, sensors × columns (the ground, then each sky
/// patch of the subdivision), in sr: lux per (179 × W/sr/m²) of a patch's radiance.
#[derive(Clone, Debug, PartialEq)]
pub struct Coefficients {
    /// The Reinhart subdivision MF.
    pub subdivision: u32,
    /// 1 (ground) + sky patches.
    pub columns: usize,
    /// Direct plus reflected, row-major (sensor, column).
    pub total: Vec<f32>,
    /// Reflected alone, row-major (sensor, column).
    pub reflected: Vec<f32>,
}

impl Coefficients {
    /// The luminous coefficients (`luma`-weighted RGB) of `sensors`.
    pub fn new(subdivision: u32, sensors: &[SensorCoefficients], luma: [f64; 3]) -> Coefficients {
        let columns = 1 + reinhart::sky_patch_count(subdivision);
        let y = |v: crate::light::Rgb| (v.x * luma[0] + v.y * luma[1] + v.z * luma[2]) as f32;
        let mut total = Vec::with_capacity(sensors.len() * columns);
        let mut reflected = Vec::with_capacity(sensors.len() * columns);
        for s in sensors {
            for c in 0..columns {
                let (d, r) = (s.direct.get(c), s.reflected.get(c));
                let d = d.copied().unwrap_or_default();
                let r = r.copied().unwrap_or_default();
                total.push(y(d + r));
                reflected.push(y(r));
            }
        }
        Coefficients {
            subdivision,
            columns,
            total,
            reflected,
        }
    }

    /// The number of sensors.
    pub fn sensors(&self) -> usize {
        self.total.len() / self.columns.max(1)
    }

    fn row<'a>(&self, m: &'a [f32], s: usize) -> &'a [f32] {
        &m[s * self.columns..(s + 1) * self.columns]
    }
}

/// The year's hourly results at the sensors, for the hours kept (those with daylight).
#[derive(Clone, Debug, PartialEq)]
pub struct Year {
    /// The weather file's hour (0-based row) of each row kept.
    pub hours: Vec<usize>,
    pub sensors: usize,
    /// Illuminance, lux, row-major (hour kept, sensor).
    pub illuminance: Vec<f32>,
    /// The direct sun alone, lux, as [`Year::illuminance`].
    pub direct_sun: Vec<f32>,
}

/// Where each hour's sun is for the product: its direction's sky column and solid angle, and
/// its direct-normal illuminance (lux); `None` for an hour without sun.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SunHour {
    pub column: usize,
    pub solid_angle: f64,
    pub normal_illuminance: f64,
}

/// The sun of each of `sky`'s hours, binned to its subdivision's patches.
pub fn sun_hours(sky: &SkyMatrix, subdivision: u32) -> Vec<Option<SunHour>> {
    let patches = reinhart::patches(subdivision).unwrap_or_default();
    (0..sky.hours())
        .map(|h| {
            let beam = sky.sun(h)?;
            let k = reinhart::patch_of(subdivision, beam.dir)?;
            Some(SunHour {
                column: 1 + k,
                solid_angle: patches.get(k)?.solid_angle(),
                normal_illuminance: beam.normal_illuminance,
            })
        })
        .collect()
}

/// The year (module notes): every hour of `sky` with daylight (some sky radiance, or a sun),
/// the coefficients `coef` weighted by it; `view(h)` is the direct sun's row of hour `h`
/// (cos θ × transmittance per sensor; only asked for hours with a sun).
pub fn year(
    coef: &Coefficients,
    sky: &SkyMatrix,
    suns: &[Option<SunHour>],
    view: &(dyn Fn(usize) -> Vec<f32> + Sync),
) -> Year {
    let n = coef.sensors();
    let kept: Vec<usize> = (0..sky.hours())
        .filter(|&h| {
            let lit = sky.row(h).is_some_and(|r| r.iter().any(|&v| v > 0.0));
            lit || suns.get(h).copied().flatten().is_some()
        })
        .collect();
    let rows: Vec<(Vec<f32>, Vec<f32>)> = kept
        .par_iter()
        .map(|&h| {
            let radiance = sky.row(h).unwrap_or(&[]);
            let sun = suns.get(h).copied().flatten();
            let direct = sun.map(|_| view(h)).unwrap_or_default();
            let mut e = Vec::with_capacity(n);
            let mut d = Vec::with_capacity(n);
            for s in 0..n {
                let t = coef.row(&coef.total, s);
                let mut sum: f64 = t
                    .iter()
                    .zip(radiance)
                    .map(|(&a, &b)| f64::from(a) * f64::from(b))
                    .sum();
                let mut beam = 0.0;
                if let Some(sun) = sun {
                    let r = f64::from(coef.row(&coef.reflected, s)[sun.column]);
                    sum += r * sun.normal_illuminance / EFFICACY / sun.solid_angle;
                    beam =
                        sun.normal_illuminance * f64::from(direct.get(s).copied().unwrap_or(0.0));
                }
                let lux = EFFICACY * sum + beam;
                e.push(finite(lux));
                d.push(finite(beam));
            }
            (e, d)
        })
        .collect();
    let (illuminance, direct_sun) = rows.into_iter().fold(
        (
            Vec::with_capacity(kept.len() * n),
            Vec::with_capacity(kept.len() * n),
        ),
        |(mut e, mut d), (re, rd)| {
            e.extend(re);
            d.extend(rd);
            (e, d)
        },
    );
    Year {
        hours: kept,
        sensors: n,
        illuminance,
        direct_sun,
    }
}

/// A value for the files: finite and not below 0.
fn finite(v: f64) -> f32 {
    if v.is_finite() {
        v.max(0.0) as f32
    } else {
        0.0
    }
}

/// The CIE overcast sky (and its ground glow, reflectance `ground_reflectance`) as radiances
/// per column (the ground, then each sky patch of `subdivision`) for an unobstructed horizontal
/// illuminance of 1 W/m² from the sky: each patch's cos-weighted mean radiance, as the solver's
/// own pieces ([`crate::sky::piece`]). The coefficients weighted by it are a sensor's daylight
/// factor (× 100 %): what `solve --sky overcast` would give, with no solve of its own.
pub fn overcast_columns(subdivision: u32, ground_reflectance: f64) -> Vec<f64> {
    use crate::sky::SkyKind;
    let patches = reinhart::patches(subdivision).unwrap_or_default();
    let relative = |d: glam::DVec3| SkyKind::Overcast.relative(d, glam::DVec3::Z);
    let q: Vec<f64> = patches.iter().map(|p| p.band.integrate(relative)).collect();
    let total: f64 = q.iter().sum();
    let mut out = vec![ground_reflectance / std::f64::consts::PI];
    out.extend(
        patches
            .iter()
            .zip(&q)
            .map(|(p, qk)| qk / total / p.band.projected_solid_angle()),
    );
    out
}

/// Each sensor's daylight factor, %, under [`overcast_columns`] `sky`.
pub fn daylight_factors(coef: &Coefficients, sky: &[f64]) -> Vec<f64> {
    (0..coef.sensors())
        .map(|s| {
            let row = coef.row(&coef.total, s);
            100.0
                * row
                    .iter()
                    .zip(sky)
                    .map(|(&d, &l)| f64::from(d) * l)
                    .sum::<f64>()
        })
        .collect()
}
