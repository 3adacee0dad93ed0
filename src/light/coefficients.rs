//! Daylight coefficients at sensors (Tregenza & Waters, *Daylight coefficients*, Lighting
//! Research & Technology 15(2), 1983): the irradiance each sky patch gives a sensor at unit
//! radiance, split into the part the sensor sees of the patch itself and the part reflected by
//! the model, so that any sky of those patches lights the sensor as a weighted sum.
//!
//! The solve runs under the unit sky of [`crate::sky::Sky::coefficients`] with one light
//! channel per patch (docs/design.md §9, annual daylight), so every patch's B holds, channel by
//! channel, the light each sky patch brings it. At a sensor:
//!
//! - **direct** (the view of each patch, through glazing): `rays_per_patch` directions uniform
//!   in solid angle over each patch (Latin-hypercube strata), a ray cast along each that must
//!   leave the model, irradiance Ω/n Σ T·cos θ at radiance 1. Sampled patch by patch, not by
//!   hemisphere rays binned to patches, so every patch the sensor sees gets its own rays and a
//!   sun binned into a patch (the annual run's interreflected sun) finds a coefficient as
//!   well-sampled as the rest;
//! - **reflected**: the sensor's gather (`Kernel::gather_at`) over the solution, per channel,
//!   its own rays that leave the model left out (the direct part counts them).

use super::gather::{latin, Ask, Spot};
use super::{Kernel, LightParts, Rgb, NO_PATCH};
use crate::intersect::{Intersector, Ray};
use crate::random::{rng_for, Stream};
use crate::sky::PieceKind;
use glam::Vec3;
use rayon::prelude::*;

/// One sensor's daylight coefficients, one per channel of the coefficient sky (index 0 the
/// ground, 1 + k sky patch k: the columns of [`crate::sky::SkyMatrix`]): irradiance (W/m²,
/// RGB) per unit radiance (W/sr/m²) of that patch.
#[derive(Clone, Debug, PartialEq)]
pub struct SensorCoefficients {
    /// What the sensor sees of each patch, through glazing.
    pub direct: Vec<Rgb>,
    /// What the model reflects to the sensor of each patch's light.
    pub reflected: Vec<Rgb>,
    /// Rays cast.
    pub rays: u64,
}

impl SensorCoefficients {
    /// Direct plus reflected, channel by channel.
    pub fn total(&self, c: usize) -> Rgb {
        self.direct[c] + self.reflected[c]
    }
}

impl<I: Intersector> Kernel<'_, I> {
    /// The daylight coefficients of the sensors `(point, facing)` (module notes): the gather
    /// `rays` rays each, and `rays_per_patch` for each patch's direct view; sensor k draws from
    /// (seed, [`Stream::Sensors`], k). Needs the coefficient sky and its channels (first
    /// channel the ground's, [`super::sun::SkyLight::patch_channels`]); empty coefficients
    /// without them.
    pub(crate) fn sensor_coefficients(
        &self,
        sensors: &[(Vec3, Vec3)],
        rays: usize,
        rays_per_patch: usize,
        seed: u64,
    ) -> Vec<SensorCoefficients> {
        let (Some(sky), Some(first)) = (self.sky.sky, self.sky.patch_channels) else {
            return vec![
                SensorCoefficients {
                    direct: Vec::new(),
                    reflected: Vec::new(),
                    rays: 0,
                };
                sensors.len()
            ];
        };
        let columns = 1 + sky
            .pieces()
            .iter()
            .filter(|p| p.kind == PieceKind::Sky)
            .count();
        sensors
            .par_iter()
            .enumerate()
            .map(|(i, &(x, n))| {
                let mut rng = rng_for(seed, Stream::Sensors, i as u64);
                let n = n.normalize_or_zero();
                let mut out = SensorCoefficients {
                    direct: vec![Rgb::ZERO; columns],
                    reflected: vec![Rgb::ZERO; columns],
                    rays: 0,
                };
                let at = |_: f32, _: f32| x;
                let spot = Spot {
                    patch: NO_PATCH,
                    at: &at,
                    n,
                    eps: self.eps_floor,
                    rho: Rgb::ONE,
                };
                let ask = Ask {
                    rays: rays.max(4),
                    lights: true,
                    parts: LightParts::All,
                    known: Default::default(),
                };
                let g = self.gather_at(&spot, ask, &mut rng);
                out.rays += g.rays;
                for (c, v) in out.reflected.iter_mut().enumerate() {
                    *v = g.ch.get(first + c).copied().unwrap_or(Rgb::ZERO);
                }
                for piece in sky.pieces() {
                    let c = match piece.kind {
                        PieceKind::Ground => 0,
                        PieceKind::Sky => 1 + piece.index,
                        PieceKind::Sun => continue,
                    };
                    let m = rays_per_patch.max(1);
                    let w = piece.solid_angle / m as f64;
                    for (u, v) in latin(m, false, &mut rng) {
                        let dir = piece.sample(f64::from(u), f64::from(v)).normalize();
                        out.rays += u64::from(n.dot(dir) > 0.0);
                        if let Some((through, cos)) = self.sky_through(x, n, dir) {
                            out.direct[c] += through * (cos * w);
                        }
                    }
                }
                out
            })
            .collect()
    }
}

impl<I: Intersector> Kernel<'_, I> {
    /// Whether a ray from the sensor at `x` facing `n` (unit) along `dir` leaves the model:
    /// the glazing's transmittance on the way and cos θ, or `None` when the model blocks it or
    /// `dir` is behind the sensor (no ray cast).
    fn sky_through(&self, x: Vec3, n: Vec3, dir: Vec3) -> Option<(Rgb, f64)> {
        let cos = n.dot(dir);
        if cos <= 0.0 {
            return None;
        }
        let ray = Ray {
            org: x + n * self.eps_floor,
            dir,
            tnear: 0.0,
            tfar: f32::INFINITY,
        };
        let seen = self.cast(NO_PATCH, ray, self.eps_floor);
        seen.hit.is_none().then_some((seen.through, f64::from(cos)))
    }

    /// The direct sun's share at each sensor for each sun direction `dirs` (model coordinates,
    /// unit, towards the sun): cos θ times the luminous transmittance (`luma`-weighted) of
    /// the glazing on the way, 0 where the model blocks it; one ray at the disc's centre
    /// (the sun's half-degree penumbra is below a sensor grid's spacing). Rows by direction,
    /// sensors along each row.
    pub(crate) fn sun_view(&self, sensors: &[(Vec3, Vec3)], dirs: &[Vec3], luma: Rgb) -> Vec<f32> {
        dirs.par_iter()
            .flat_map_iter(|&dir| {
                sensors.iter().map(move |&(x, n)| {
                    let n = n.normalize_or_zero();
                    self.sky_through(x, n, dir)
                        .map_or(0.0, |(through, cos)| (cos * through.dot(luma)) as f32)
                })
            })
            .collect()
    }
}
