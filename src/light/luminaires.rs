//! Direct light from the luminaires (docs/design.md §12): a placed luminaire is a point with a
//! photometric web ([`crate::luminaire`]), so its irradiance at a point x facing n is exact:
//! E = I(ω)·cos θ / r², I its intensity toward x (W/sr), θ the angle at x, r the distance —
//! when a shadow ray from x reaches the luminaire (through glazing, tinted by it). Where the
//! file gives a luminous opening with an area, the web is spread evenly over it (as
//! Radiance's `ies2rad` sources are) and E is its mean over stratified points of the opening,
//! each with its own shadow ray: right near the luminaire, the point's value far from it. A hemisphere ray never meets a point, so no MIS weight is needed:
//! the shadow rays carry all of a luminaire's direct light and the hemisphere rays what its
//! light does after its first bounce.
//!
//! A gather over a patch takes the luminaires at stratified points of it (Latin hypercube, as
//! the other light samples). With few luminaires every point sees every one of them
//! ([`ALL_BELOW`]); with more, each point draws one, with probability by what each gives the
//! receiver's centre unoccluded (mixed with a uniform share, so a luminaire the centre does
//! not see but a corner does is still drawn), and divides by that probability.

use super::gather::{latin, stratified_var, Gathered, Spot};
use super::{scalar, Kernel, Origin, Rgb};
use crate::intersect::{Intersector, Ray};
use crate::luminaire::Luminaire;
use glam::{DVec3, Vec3};
use rand::Rng;

/// Up to this many luminaires, each point of a gather takes the light of every one.
pub const ALL_BELOW: usize = 8;

/// The share of the draw spread evenly over the luminaires, the rest by their unoccluded
/// light at the receiver's centre.
const UNIFORM_SHARE: f64 = 0.1;

/// The unoccluded irradiance (RGB, W/m²) luminaire `l` gives a point `x` facing `n`, with the
/// direction and distance to it; `None` when it is behind the point or gives nothing.
pub fn unoccluded(l: &Luminaire, x: Vec3, n: Vec3) -> Option<(Rgb, Vec3, f32)> {
    unoccluded_from(l, l.position, x, n)
}

/// [`unoccluded`] from point `at` of the luminaire's opening.
fn unoccluded_from(l: &Luminaire, at: DVec3, x: Vec3, n: Vec3) -> Option<(Rgb, Vec3, f32)> {
    let d = at - x.as_dvec3();
    let r2 = d.length_squared();
    if !(r2 > 0.0 && r2.is_finite()) {
        return None;
    }
    let r = r2.sqrt();
    let cos = n.as_dvec3().dot(d) / r;
    if cos <= 0.0 {
        return None;
    }
    let i = Rgb::from_array(l.intensity_toward(-d));
    let e = i * (cos / r2);
    (scalar(e) > 0.0).then(|| (e, (d / r).as_vec3(), r as f32))
}

impl<I: Intersector> Kernel<'_, I> {
    /// Luminaire `k`'s irradiance at `from` (RGB): its unoccluded light where a shadow ray
    /// reaches it (tinted by the glazing it passes), else 0; and whether a ray was cast.
    /// `opening`: where on a luminaire's luminous opening the light is taken from
    /// ([`Luminaire::opening_point`]; ignored without an opening).
    pub(super) fn luminaire_sample(
        &self,
        from: &Origin,
        k: usize,
        opening: (f64, f64),
    ) -> (Rgb, bool) {
        let l = &self.mesh.luminaires[k];
        let at = l.opening_point(opening.0, opening.1);
        let Some((e, dir, r)) = unoccluded_from(l, at, from.x, from.n) else {
            return (Rgb::ZERO, false);
        };
        let ray = Ray {
            org: from.x,
            dir,
            tnear: 0.0,
            tfar: r * (1.0 - 1e-5),
        };
        let seen = self.cast(from.patch, ray, from.eps);
        if seen.hit.is_some() {
            return (Rgb::ZERO, true);
        }
        (e * seen.through, true)
    }

    /// One luminaire drawn by its flux (`s` uniform in [0, 1)) and its light at `from` divided
    /// by the chance of the draw (RGB), the luminaire, and whether a ray was cast.
    pub(super) fn luminaire_by_flux<R: Rng>(
        &self,
        from: &Origin,
        rng: &mut R,
    ) -> (Rgb, usize, bool) {
        let (k, p) = pick(&self.luminaire_flux_cdf, rng.gen());
        let (e, cast) =
            self.luminaire_sample(from, k, opening_sample(&self.mesh.luminaires[k], rng));
        (e / p, k, cast)
    }

    /// The luminaires' part of a gather at `spot` whose other parts cast `rays`: stratified
    /// points ([`luminaire_points`]), each taking every luminaire (few) or one drawn by its
    /// light at the spot's centre (many), into `g` (its mean, the luminaires' channels and the
    /// variance of ρ·H's mean).
    pub(super) fn luminaires_part<R: Rng>(
        &self,
        spot: &Spot,
        rays: usize,
        g: &mut Gathered,
        rng: &mut R,
    ) {
        let lums = &self.mesh.luminaires;
        let n = luminaire_points(spot, rays, lums);
        let points = latin(n, true, rng);
        // Points of the luminous openings, stratified apart from the receiver's (drawn only
        // where a luminaire has an opening, so point sources keep their random numbers).
        let openings = if lums.iter().any(Luminaire::has_opening) {
            latin(n, true, rng)
        } else {
            Vec::new()
        };
        let draw = (lums.len() > ALL_BELOW).then(|| self.luminaire_draw(spot));
        let (mut m, mut sum) = (Vec::with_capacity(n), Rgb::ZERO);
        for (j, &(u, v)) in points.iter().enumerate() {
            let from = spot.origin(u, v);
            let at = openings
                .get(j)
                .map_or((0.5, 0.5), |&(a, b)| (f64::from(a), f64::from(b)));
            let mut val = Rgb::ZERO;
            match &draw {
                None => {
                    for k in 0..lums.len() {
                        let (e, cast) = self.luminaire_sample(&from, k, at);
                        g.rays += u64::from(cast);
                        self.add_luminaire_channel(g, k, e, n as f64);
                        val += e;
                    }
                }
                Some(cdf) => {
                    let (k, p) = pick(cdf, rng.gen());
                    let (e, cast) = self.luminaire_sample(&from, k, at);
                    g.rays += u64::from(cast);
                    let e = e / p;
                    self.add_luminaire_channel(g, k, e, n as f64);
                    val = e;
                }
            }
            m.push(scalar(spot.rho * val));
            sum += val;
        }
        g.h += sum / n as f64;
        g.var += stratified_var(&m);
    }

    /// The cumulative probabilities the points draw the luminaires by: by each one's
    /// unoccluded light at the spot's centre, mixed with [`UNIFORM_SHARE`] spread evenly.
    fn luminaire_draw(&self, spot: &Spot) -> Vec<f64> {
        let lums = &self.mesh.luminaires;
        let centre = (spot.at)(0.5, 0.5);
        let w: Vec<f64> = (lums.iter())
            .map(|l| unoccluded(l, centre, spot.n).map_or(0.0, |(e, _, _)| scalar(e)))
            .collect();
        let total: f64 = w.iter().sum();
        let even = 1.0 / lums.len() as f64;
        let mut acc = 0.0;
        w.iter()
            .map(|&x| {
                acc += if total > 0.0 {
                    UNIFORM_SHARE * even + (1.0 - UNIFORM_SHARE) * x / total
                } else {
                    even
                };
                acc
            })
            .collect()
    }

    /// Adds sample `e` of luminaire `k` (one of `n` points) to its light channel, if it has one.
    fn add_luminaire_channel(&self, g: &mut Gathered, k: usize, e: Rgb, n: f64) {
        if let Some(c) = self.luminaire_channels.get(k).copied().flatten() {
            if let Some(x) = g.ch.get_mut(c) {
                *x += e / n;
            }
        }
    }
}

/// How many points of `spot` take the luminaires' light, on top of the gather's `rays`: a
/// quarter as many, at least 4 — or one, for a single point (a sensor) lit by few enough
/// luminaires that it takes every one's light exactly.
fn luminaire_points(spot: &Spot, rays: usize, lums: &[Luminaire]) -> usize {
    let exact = lums.len() <= ALL_BELOW && !lums.iter().any(Luminaire::has_opening);
    if spot.patch == super::NO_PATCH && exact {
        1
    } else {
        (rays / 4).max(4)
    }
}

/// Where on `l`'s luminous opening a sample takes its light: two uniform numbers drawn from
/// `rng` where it has an opening, none (the centre) where it has not, so that point sources
/// draw exactly what they drew before openings were read.
fn opening_sample<R: Rng>(l: &Luminaire, rng: &mut R) -> (f64, f64) {
    if l.has_opening() {
        (rng.gen(), rng.gen())
    } else {
        (0.5, 0.5)
    }
}

/// The cumulative shares of the luminaires' scalar flux (evenly where none has any).
pub(super) fn flux_cdf(luminaires: &[Luminaire]) -> Vec<f64> {
    let flux: Vec<f64> = luminaires
        .iter()
        .map(|l| scalar(Rgb::from_array(l.flux_watts())))
        .collect();
    let total: f64 = flux.iter().sum();
    let mut acc = 0.0;
    flux.iter()
        .map(|&f| {
            acc += if total > 0.0 {
                f / total
            } else {
                1.0 / flux.len() as f64
            };
            acc
        })
        .collect()
}

/// The entry of cumulative probabilities `cdf` that `s` (uniform in [0, 1)) falls in, and its
/// probability.
fn pick(cdf: &[f64], s: f64) -> (usize, f64) {
    let total = cdf.last().copied().unwrap_or(1.0);
    let x = s * total;
    let k = cdf.partition_point(|&c| c <= x).min(cdf.len() - 1);
    let lo = if k == 0 { 0.0 } else { cdf[k - 1] };
    (k, ((cdf[k] - lo) / total).max(f64::MIN_POSITIVE))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The draw picks each entry with its own probability, and says so.
    #[test]
    fn pick_returns_the_entry_and_its_probability() {
        let cdf = [0.1, 0.1, 0.7, 1.0];
        assert_eq!(pick(&cdf, 0.05), (0, 0.1));
        let (k, p) = pick(&cdf, 0.5);
        assert_eq!(k, 2);
        assert!((p - 0.6).abs() < 1e-12);
        let (k, p) = pick(&cdf, 0.99);
        assert_eq!(k, 3);
        assert!((p - 0.3).abs() < 1e-12);
    }
}
