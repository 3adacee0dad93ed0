//! The light from outside the model (docs/design.md §9): the sky's radiance seen by rays that
//! leave the model, as an exitance π·L (the unit of B the hemisphere rays average), and the
//! sun, sampled like a light: directions over its disc, shadow rays that must leave the model
//! (through glazing, tinted by it), L_sun·Ω_sun·cos θ each.

use super::gather::{latin, stratified_var, Gathered, Spot};
use super::{
    add_to, scalar, Kernel, LightChannel, Origin, Rgb, GROUND_CHANNEL, SKY_CHANNEL, SUN_CHANNEL,
};
use crate::intersect::{Intersector, Ray};
use crate::sky::{Sky, Sun};
use glam::Vec3;
use rand::Rng;

/// The sky that lights the model from outside: rays that leave see it, and its sun is sampled
/// like a light; their weights (1; a relit picture's, [`super::Relit`]) and their per-light
/// channels, when kept.
pub(crate) struct SkyLight<'a> {
    pub sky: Option<&'a Sky>,
    pub sky_weight: f64,
    pub sun_weight: f64,
    pub sky_channel: Option<usize>,
    pub sun_channel: Option<usize>,
    /// Daylight coefficients: the ground's channel, each sky patch's after it
    /// ([`crate::light::GROUND_CHANNEL`]); rays that leave go to the channel of the patch
    /// they look into.
    pub patch_channels: Option<usize>,
    /// Whether the rays a gather casts from its own point and that leave the model count in
    /// the channels (false where the caller samples that direct view of the sky itself,
    /// patch by patch: the sensors' daylight coefficients).
    pub first_escapes: bool,
}

impl<'a> SkyLight<'a> {
    /// `sky`'s light at weight 1, into the channels of `channels` named after the sky and the
    /// sun.
    pub fn new(sky: Option<&'a Sky>, channels: &[LightChannel]) -> Self {
        let channel = |name: &str| channels.iter().position(|c| c.name == name);
        SkyLight {
            sky,
            sky_weight: 1.0,
            sun_weight: 1.0,
            sky_channel: channel(SKY_CHANNEL),
            sun_channel: channel(SUN_CHANNEL),
            patch_channels: channel(GROUND_CHANNEL)
                .filter(|_| sky.is_some_and(|s| s.subdivision().is_some())),
            first_escapes: true,
        }
    }

    /// The channel of the light a ray that leaves the model along `dir` sees: its sky
    /// patch's (or the ground's) for daylight coefficients, else the sky's.
    pub fn channel_of(&self, dir: Vec3) -> Option<usize> {
        match (self.patch_channels, self.sky) {
            (Some(first), Some(sky)) => sky.coefficient_channel(dir).map(|c| first + c),
            _ => self.sky_channel,
        }
    }

    /// The sun, when the sky has one.
    pub fn sun(&self) -> Option<&'a Sun> {
        self.sky.and_then(Sky::sun)
    }

    /// What a ray leaving the model along `dir` returns: the sky's (or the ground glow's)
    /// radiance as an exitance, π·L (the unit of B that the hemisphere rays average), the sun
    /// left out (sampled on its own); black without a sky.
    pub fn exitance(&self, dir: Vec3) -> Rgb {
        self.sky.map_or(Rgb::ZERO, |s| {
            Rgb::from_array(s.radiance(dir)) * std::f64::consts::PI * self.sky_weight
        })
    }
}

impl<I: Intersector> Kernel<'_, I> {
    /// One sample of the sun's irradiance at `from`: the direction (u, v) of its disc,
    /// L_sun·Ω_sun·cos θ where a shadow ray leaves the model, else 0.
    pub(super) fn sun_sample(&self, from: &Origin, sun: &Sun, (u, v): (f64, f64)) -> Rgb {
        let dir = sun.sample(u, v).normalize();
        let cos = from.n.dot(dir);
        if cos <= 0.0 {
            return Rgb::ZERO;
        }
        let ray = Ray {
            org: from.x,
            dir,
            tnear: 0.0,
            tfar: f32::INFINITY,
        };
        let seen = self.cast(from.patch, ray, from.eps);
        if seen.hit.is_some() {
            return Rgb::ZERO;
        }
        let w = seen.through * Sun::solid_angle() * f64::from(cos) * self.sky.sun_weight;
        Rgb::from_array(sun.radiance()) * w
    }

    /// The sun's part of a gather at `spot`: `n` directions over its disc, stratified and
    /// paired with the points in random order, into `g` (its mean, channel and variance).
    pub(super) fn sun_part<R: Rng>(
        &self,
        spot: &Spot,
        sun: &Sun,
        n: usize,
        g: &mut Gathered,
        rng: &mut R,
    ) {
        let (mut m, mut sum) = (Vec::with_capacity(n), Rgb::ZERO);
        let here = latin(n, false, rng);
        let there = latin(n, true, rng);
        for (&(u, v), &(s, t)) in here.iter().zip(&there) {
            let val = self.sun_sample(&spot.origin(u, v), sun, (f64::from(s), f64::from(t)));
            g.rays += 1;
            m.push(scalar(spot.rho * val));
            sum += val;
            add_to(
                &mut g.ch,
                self.sky.sun_channel,
                val,
                Rgb::splat(1.0 / n as f64),
            );
        }
        g.h += sum / n as f64;
        g.var += stratified_var(&m);
    }
}
