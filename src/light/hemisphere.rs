//! Hemisphere rays: cosine-weighted directions (the stratified polar grid of the paper's
//! Sec. 2, turned by a random angle) cast through glazing (`Kernel::cast`), each returning
//! what the side it meets reflects towards it — the solution's B − E from afar, the light at
//! the point it met when nearer than that side's size (the near-hit rule, [`NEAR`]) — plus an
//! emitter's E at the hemisphere ray's MIS weight.

use super::emitters::{Draw, Emitters};
use super::gather::{latin, stratified_var, Gathered, Split, Spot};
use super::{add_to, scalar, Kernel, Origin, Rgb, NO_PATCH};
use crate::intersect::{Hit, Intersector, Ray};
use crate::sample::Frame;
use glam::Vec3;
use rand::Rng;

/// The share of a followed point's light samples drawn from the cut of the point that
/// gathers (the rest by power). A followed point lies within its side's size of the gathering
/// point, so the lamps that light one mostly light the other; drawn by power alone, its one
/// light sample mostly went to lamps in other rooms (on the generated 100 k-patch building the
/// near hits held 37 % of the final gather's variance; with the mixture the solve's error fell
/// from 3.0 to 2.78 % for the same rays, docs/results/gather-building.md). The draw by power
/// keeps every emitter that can light the followed point possible, so the estimate stays
/// unbiased; the sample's density and the cosine ray's MIS weight are the mixture's.
pub const FOLLOWED_NEAR: f64 = 0.8;

/// The draws a followed point's light samples come from, with their shares: the gathering
/// point's cut and the draw by power ([`FOLLOWED_NEAR`]), or by power alone.
fn followed_draws<'d>(near: &'d Draw, by_power: &'d Draw) -> Mixture<'d> {
    if near.is_local() {
        Mixture {
            d: [(near, FOLLOWED_NEAR), (by_power, 1.0 - FOLLOWED_NEAR)],
            len: 2,
        }
    } else {
        Mixture {
            d: [(by_power, 1.0), (by_power, 0.0)],
            len: 1,
        }
    }
}

/// One or two draws with their shares (a mixture's, adding up to one).
struct Mixture<'d> {
    d: [(&'d Draw, f64); 2],
    len: usize,
}

impl<'d> std::ops::Deref for Mixture<'d> {
    type Target = [(&'d Draw, f64)];
    fn deref(&self) -> &Self::Target {
        &self.d[..self.len]
    }
}

/// A hemisphere ray meeting a side closer than this many times the side's size (√A) takes the
/// light at the point it met, not the side's B (`Kernel::reflected_at`): a constant B over a
/// patch is what the patch sends afar, not what its own parts send to something beside them.
pub const NEAR: f32 = 1.0;

/// Near hits followed one after another before the solution's B is taken as it is.
pub const NEAR_DEPTH: u32 = 3;

/// Surfaces a ray may step past (its own, glazing) before it is taken as lost.
pub(super) const MAX_STEPS: usize = 16;

/// What a ray met ([`Kernel::cast`]): the first opaque hit, the transmittance per channel of
/// the glazing before it (the product of its panes' T_c), and what the panes' sides it met
/// reflect towards it.
pub(super) struct Traced {
    pub hit: Option<Hit>,
    pub through: Rgb,
    pub panes: Rgb,
}

/// What a side reflects towards one hemisphere ray (RGB, per channel) and the rays it cost.
#[derive(Default)]
struct Reflected {
    v: Rgb,
    ch: Vec<Rgb>,
    rays: u64,
}

impl<I: Intersector> Kernel<'_, I> {
    /// The closest opaque hit along `ray`, stepping past patch `i`'s own surface (a ray leaving
    /// a planar patch cannot meet it again; rounding may say otherwise).
    ///
    /// Glazing is seen and seen through: each pane met adds what its side reflects (B − E,
    /// times the transmittance of the panes before it) and passes on its transmittance T_c
    /// per channel (tinted glazing's colour: docs/design.md §9); the ray goes on to the first
    /// opaque surface.
    pub(super) fn cast(&self, i: usize, mut ray: Ray, eps: f32) -> Traced {
        let own = (i != NO_PATCH).then(|| self.mesh.surface_of(i));
        let mut out = Traced {
            hit: None,
            through: Rgb::ONE,
            panes: Rgb::ZERO,
        };
        for _ in 0..MAX_STEPS {
            match self.isect.intersect(&ray) {
                Some(h) if Some(h.patch as usize) == own => ray.tnear = h.t + eps,
                Some(h)
                    if self
                        .glazing
                        .get(h.patch as usize)
                        .is_some_and(|t| t.to_array().iter().any(|c| *c > 0.0)) =>
                {
                    if let Some(r) = self.mesh.receiver(h.patch, h.back) {
                        out.panes += out.through * self.sol.reflected(r as usize);
                    }
                    out.through *= self.glazing[h.patch as usize];
                    ray.tnear = h.t + (h.t * 1e-5).max(self.eps_floor);
                }
                other => {
                    out.hit = other;
                    return out;
                }
            }
        }
        // Lost among surfaces: nothing seen beyond.
        out.through = Rgb::ZERO;
        out
    }

    /// The side a ray's hit gives its light to, and how far it is.
    pub(super) fn receiver_of(&self, hit: Option<Hit>) -> Option<(usize, f32)> {
        hit.and_then(|h| Some((self.mesh.receiver(h.patch, h.back)? as usize, h.t)))
    }

    /// What emitter `r`, met at distance `t` by a hemisphere ray along `dir` from a point
    /// facing `n`, adds to it: its E on its emitting side, times the complement of the weight
    /// its light samples have (none when there are none, `n_l` = 0), drawn from the mixture
    /// `draws` (each draw at its share).
    fn emitted_towards(
        &self,
        r: usize,
        (n, dir, t): (Vec3, Vec3, f32),
        draws: &[(&Draw, f64)],
        (n_l, n_c): (f64, f64),
    ) -> Rgb {
        let e = self.sol.e[r];
        let mut emitted = Rgb::ZERO;
        if scalar(e) > 0.0 {
            let p = &self.mesh.patches[r];
            let cos_r = -f64::from(p.normal.dot(dir));
            if cos_r > 0.0 {
                let w = match self.emitters.index_of(r).filter(|_| n_l > 0.0) {
                    Some(ei) => {
                        let cos_i = f64::from(n.dot(dir));
                        let mass = self.mixture_mass(draws, ei, scalar(e) * p.area);
                        Emitters::weight(mass, p.area, (cos_i, cos_r, f64::from(t)), n_l, n_c)
                    }
                    None => 0.0,
                };
                emitted = e * (1.0 - w);
            }
        }
        emitted
    }

    /// The hemisphere's part of a gather at `spot`: cosine-weighted rays through the polar
    /// cells, each taking what the side it meets reflects (`reflected_at`) and, when there are
    /// light samples too, its emission at the hemisphere ray's MIS weight (the light samples
    /// count the rest of it); rays that leave see the sky. Into `g`.
    pub(super) fn hemisphere_part<R: Rng>(
        &self,
        spot: &Spot,
        split: &Split,
        g: &mut Gathered,
        rng: &mut R,
    ) {
        let x_count = split.grid.len();
        let angle = rng.gen::<f32>() * std::f32::consts::TAU;
        let frame = Frame::new(spot.n, angle);
        let here = latin(x_count, false, rng);
        let mut m = Vec::with_capacity(x_count);
        let (mut sum, mut reflected) = (Rgb::ZERO, Rgb::ZERO);
        for (cell, &(u, v)) in here.iter().enumerate() {
            let dir = frame.to_world(split.grid.direction(cell, 0.0, true, rng));
            let org = spot.origin(u, v).x;
            let ray = Ray {
                org,
                dir,
                tnear: 0.0,
                tfar: f32::INFINITY,
            };
            g.rays += 1;
            let seen = self.cast(spot.patch, ray, spot.eps);
            let recv = self.receiver_of(seen.hit);
            let mut emitted = Rgb::ZERO;
            let mut sub = Reflected::default();
            if let Some((r, t)) = recv {
                // An emitter taken whole is the direct part's alone (`exact`).
                let whole = !split.whole.ids.is_empty()
                    && (self.emitters.index_of(r)).is_some_and(|e| split.whole.has(e));
                if split.nl > 0.0 && !whole {
                    emitted = self.emitted_towards(
                        r,
                        (spot.n, dir, t),
                        &[(split.weigh.as_ref().unwrap_or(&split.draw), 1.0)],
                        (split.nl, split.nc),
                    );
                }
                sub = self.reflected_at(r, (org + dir * t, t), split.follow, &split.draw, rng);
                g.rays += sub.rays;
            }
            if seen.hit.is_none() {
                sub.v = self.sky.exitance(dir);
            }
            let val = seen.panes + seen.through * (sub.v + emitted);
            m.push(scalar(spot.rho * val));
            sum += val;
            if let Some((r, _)) = recv {
                reflected += seen.through * sub.v;
                for (c, chc) in g.ch.iter_mut().enumerate() {
                    let lit = if self.sol.own(r, c) {
                        emitted
                    } else {
                        Rgb::ZERO
                    };
                    *chc += seen.through * (sub.ch[c] + lit) / x_count as f64;
                }
            } else if seen.hit.is_none() && self.sky.first_escapes {
                let w = seen.through / x_count as f64;
                add_to(&mut g.ch, self.sky.channel_of(dir), sub.v, w);
            }
        }
        g.h += sum / x_count as f64;
        g.reflected += reflected / x_count as f64;
        g.var += stratified_var(&m);
    }

    /// The light side `r` reflects towards a hemisphere ray that met it at `y` from distance
    /// `t` (RGB, and per channel). From afar, the solution's B_r − E_r. From nearer than r's
    /// size (√A_r · [`NEAR`]), where a constant B over r is not what this point sees (the wall
    /// behind a shelf 5 cm in front of it is dark, the 0.5 m wall patch is not), ρ_r times the
    /// irradiance at `y` itself ([`Self::followed`]), `left` more times at most
    /// ([`NEAR_DEPTH`] from a gather's own rays): a path followed through the narrow gap until
    /// it leaves it (the close-hit rule of final gathers, Jensen, *Realistic Image Synthesis
    /// Using Photon Mapping*, 2001, Sec. 9.4.2, with the solution as the cache).
    fn reflected_at<R: Rng>(
        &self,
        r: usize,
        (y, t): (Vec3, f32),
        left: u32,
        near_draw: &Draw,
        rng: &mut R,
    ) -> Reflected {
        let area = self.mesh.patches[r].area as f32;
        let near = t < NEAR * area.sqrt();
        if left == 0 || !near || scalar(self.sol.rho[r]) <= 0.0 {
            return self.solved(r);
        }
        self.followed(r, y, left, near_draw, rng)
    }

    /// A followed point's emitter for the number `s` ∈ [0, 1), drawn from `mix`
    /// ([`followed_draws`]: one draw, or the gathering point's cut then the draw by power),
    /// and its probability under the mixture.
    fn followed_pick(&self, mix: &[(&Draw, f64)], s: f64) -> (usize, f64) {
        let [(near, a), (power, _)] = mix else {
            let (e, mass, _) = self.emitters.pick(mix[0].0, s);
            return (e, mass);
        };
        let (e, _, _) = if s < *a {
            self.emitters.pick(near, s / a)
        } else {
            self.emitters.pick(power, ((s - a) / (1.0 - a)).min(1.0))
        };
        let em = &self.emitters.at[e];
        (e, self.mixture_mass(mix, e, scalar(em.e) * em.area))
    }

    /// The probability that the mixture `draws` (each draw at its share) picks emitter `e` of
    /// power `w_e`.
    fn mixture_mass(&self, draws: &[(&Draw, f64)], e: usize, w_e: f64) -> f64 {
        (draws.iter())
            .map(|&(d, share)| share * self.emitters.mass(d, e, w_e))
            .sum()
    }

    /// What the solution says side `r` reflects: B_r − E_r, and per channel the channel's B
    /// less r's own emission where r's light is that channel's.
    fn solved(&self, r: usize) -> Reflected {
        let k = self.sol.channels.len();
        Reflected {
            v: self.sol.reflected(r),
            ch: (0..k)
                .map(|c| {
                    let e = if self.sol.own(r, c) {
                        self.sol.e[r]
                    } else {
                        Rgb::ZERO
                    };
                    (Rgb::from_array(self.sol.channels[c].b[r]) - e).max(Rgb::ZERO)
                })
                .collect(),
            rays: 0,
        }
    }

    /// ρ_r times the irradiance at `y` on side `r`, from one light sample, one cosine-weighted
    /// ray (its hit taken by [`Self::reflected_at`] one level deeper, `left` − 1 more near
    /// hits to follow), one sun sample and one luminaire's light.
    fn followed<R: Rng>(
        &self,
        r: usize,
        y: Vec3,
        left: u32,
        near_draw: &Draw,
        rng: &mut R,
    ) -> Reflected {
        let k = self.sol.channels.len();
        let n = self.mesh.patches[r].normal;
        let eps = self.eps_of(r);
        let from = Origin {
            patch: r,
            x: y + n * eps,
            n,
            eps,
        };
        let x = from.x;
        let mut acc = Reflected {
            v: Rgb::ZERO,
            ch: vec![Rgb::ZERO; k],
            rays: 0,
        };
        let nl = if self.emitters.is_empty() { 0.0 } else { 1.0 };
        let by_power = Draw::by_power();
        let mix = followed_draws(near_draw, &by_power);
        // One light sample.
        if nl > 0.0 {
            let (e, mass) = self.followed_pick(&mix, rng.gen());
            let yj = self.emitters.at[e].points.at(rng.gen(), rng.gen());
            let (v, j, cast) = self.light_sample(&from, (e, mass, mass), yj, (1.0, 1.0));
            if cast {
                acc.rays += 1;
                acc.v += v;
                if let Some(c) = self.sol.group.and_then(|g| acc.ch.get_mut(g[j] as usize)) {
                    *c += v;
                }
            }
        }
        // One cosine-weighted ray.
        let (u1, u2) = (rng.gen::<f32>(), rng.gen::<f32>());
        let (s, c) = (std::f32::consts::TAU * u2).sin_cos();
        let rr = u1.sqrt();
        let dir =
            Frame::new(n, 0.0).to_world(Vec3::new(rr * c, rr * s, (1.0 - u1).max(0.0).sqrt()));
        let ray = Ray {
            org: x,
            dir,
            tnear: 0.0,
            tfar: f32::INFINITY,
        };
        acc.rays += 1;
        let seen = self.cast(r, ray, eps);
        let (hit, w) = (seen.hit, seen.through);
        let l = if hit.is_none() {
            self.sky.exitance(dir)
        } else {
            Rgb::ZERO
        };
        acc.v += seen.panes + w * l;
        add_to(&mut acc.ch, self.sky.channel_of(dir), l, w);
        if let Some(sun) = self.sky.sun() {
            acc.rays += 1;
            let l = self.sun_sample(&from, sun, (rng.gen(), rng.gen()));
            acc.v += l;
            add_to(&mut acc.ch, self.sky.sun_channel, l, Rgb::ONE);
        }
        if !self.mesh.luminaires.is_empty() {
            // One luminaire, drawn by its flux: its exact light at y by a shadow ray.
            let (l, k, cast) = self.luminaire_by_flux(&from, rng);
            acc.rays += u64::from(cast);
            acc.v += l;
            if let Some(c) =
                (self.luminaire_channels.get(k).copied().flatten()).and_then(|c| acc.ch.get_mut(c))
            {
                *c += l;
            }
        }
        if let Some((s, t2)) = self.receiver_of(hit) {
            let emitted = self.emitted_towards(s, (n, dir, t2), &mix, (nl, 1.0));
            let sub = self.reflected_at(s, (x + dir * t2, t2), left - 1, near_draw, rng);
            acc.rays += sub.rays;
            acc.v += w * (sub.v + emitted);
            for (c, chc) in acc.ch.iter_mut().enumerate() {
                let lit = if self.sol.own(s, c) {
                    emitted
                } else {
                    Rgb::ZERO
                };
                *chc += w * (sub.ch[c] + lit);
            }
        }
        let rho = self.sol.rho[r];
        Reflected {
            v: rho * acc.v,
            ch: acc.ch.into_iter().map(|c| rho * c).collect(),
            rays: acc.rays,
        }
    }
}
