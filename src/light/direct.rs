//! Direct light from the emitting patches: shadow rays from a point to points drawn on the
//! emitters by what they can give it, or by power ([`super::emitters`]), each sample E_j·cosθ_i·cosθ_j/(π r²) divided by
//! its density and counted at its MIS weight against the hemisphere rays (the power
//! heuristic, `Emitters::weight`).

use super::emitters::{Emitter, Emitters, Learned};
use super::gather::{latin, stratified_var, Gathered, Split, Spot};
use super::{scalar, Kernel, Origin, Rgb};
use crate::intersect::{Intersector, Ray};
use glam::Vec3;
use rand::Rng;

/// A shadow ray's outcome: E_j·cosθ_i·cosθ_j/(π r²) (0 when not seen), the same with nothing
/// in between (`open`), and its geometry.
pub(super) struct Shadow {
    pub e_g: Rgb,
    pub open: Rgb,
    pub cos_i: f64,
    pub cos_j: f64,
    pub dist: f64,
}

impl<I: Intersector> Kernel<'_, I> {
    /// The irradiance sample (RGB, before dividing by the pdf of the emitter's choice) of a
    /// shadow ray from `from` to `y` on emitting patch `j` (`em`: what is read of it):
    /// E_j·cosθ_i·cosθ_j/(π r²), or `None` when `y` faces away or is not seen (no ray is cast
    /// when the geometry says 0).
    pub(super) fn direct(
        &self,
        from: &Origin,
        (j, em): (usize, &Emitter),
        y: Vec3,
    ) -> Option<Shadow> {
        let (x, n, eps) = (from.x, from.n, from.eps);
        let d = y - x;
        let dist = d.length();
        if dist <= 0.0 || !dist.is_finite() {
            return None;
        }
        let dir = d / dist;
        let cos_i = n.dot(dir);
        let cos_j = -em.normal.dot(dir);
        if cos_i <= 0.0 || cos_j <= 0.0 {
            return None;
        }
        let ray = Ray {
            org: x,
            dir,
            tnear: 0.0,
            tfar: dist * (1.0 + 1e-3) + eps,
        };
        // Seen: the ray meets j's emitting side first, or nothing before j's plane (a ray
        // aimed at j may be given to a neighbouring patch of the same plane at an edge).
        let traced = self.cast(from.patch, ray, eps);
        let seen = match traced.hit {
            None => true,
            Some(h) => {
                self.mesh.receiver(h.patch, h.back) == Some(j as u32) || h.t >= dist * (1.0 - 1e-4)
            }
        };
        let open =
            f64::from(cos_i) * f64::from(cos_j) / (std::f64::consts::PI * f64::from(dist).powi(2));
        // Written as it always was, so that a glazed path rounds as before.
        let g = if seen {
            traced.through * f64::from(cos_i) * f64::from(cos_j)
                / (std::f64::consts::PI * f64::from(dist).powi(2))
        } else {
            Rgb::ZERO
        };
        Some(Shadow {
            e_g: em.e * g,
            open: em.e * open,
            cos_i: f64::from(cos_i),
            cos_j: f64::from(cos_j),
            dist: f64::from(dist),
        })
    }

    /// One light sample from `from` to the point `y` of emitter `e` (an index into the
    /// emitters, picked with probability `mass`), its shadow ray weighed by MIS against `n_l`
    /// light samples and `n_c` hemisphere rays as if `e` were picked with probability
    /// `w_mass` (`mass` itself but in a gather split in parts: [`Split::weigh`]) and divided
    /// by the sample's density. Returns the sample (RGB; 0 when not seen), the emitting
    /// patch, and whether a ray was cast.
    pub(super) fn light_sample(
        &self,
        from: &Origin,
        (e, mass, w_mass): (usize, f64, f64),
        y: Vec3,
        (n_l, n_c): (f64, f64),
    ) -> (Rgb, usize, bool) {
        let j = self.emitters.patches[e];
        let em = &self.emitters.at[e];
        let area = em.area;
        let shadow = self.direct(from, (j, em), y);
        let cast = shadow.is_some();
        let (c, mis) = shadow.map_or((Rgb::ZERO, 0.0), |sh| {
            let geometry = (sh.cos_i, sh.cos_j, sh.dist);
            (sh.e_g, Emitters::weight(w_mass, area, geometry, n_l, n_c))
        });
        // ÷ pdf(y) = mass / A_j, × the light sample's MIS weight.
        let scale = area / mass * mis;
        (c * scale, j, cast)
    }

    /// The emitters' part of a gather at `spot`: `split.direct` light samples, emitters by
    /// `split.draw` (stratified along its CDF), points on them uniform, paired with the points in
    /// random order, into `g` (its mean, the emitters' channels and the variance).
    pub(super) fn direct_part<R: Rng>(
        &self,
        spot: &Spot,
        split: &Split,
        g: &mut Gathered,
        mut learned: Option<&mut Learned>,
        rng: &mut R,
    ) {
        let n = split.direct;
        let k = g.ch.len();
        let mut m = Vec::with_capacity(n);
        let mut sum = Rgb::ZERO;
        let here = latin(n, false, rng);
        let there = latin(n, true, rng);
        for (&(u, v), &(s, t)) in here.iter().zip(&there) {
            let from = spot.origin(u, v);
            // Stratified choice of the emitter, then a point on it from the rest of `s`.
            let (e, mass, s2, node) = self.emitters.pick_node(&split.draw, f64::from(s));
            let y = self.emitters.at[e].points.at(s2, t);
            let w_mass = match &split.weigh {
                Some(w) => {
                    let em = &self.emitters.at[e];
                    self.emitters.mass(w, e, scalar(em.e) * em.area)
                }
                None => mass,
            };
            let sample = (e, mass, w_mass);
            let (val, j, cast) = self.light_sample(&from, sample, y, (split.nl, split.nc));
            if let (Some(l), Some(node)) = (learned.as_deref_mut(), node) {
                l.record(node, scalar(val) > 0.0);
            }
            g.rays += u64::from(cast);
            m.push(scalar(spot.rho * val));
            sum += val;
            if let Some(gr) = self.sol.group {
                let gj = gr[j] as usize;
                if gj < k {
                    g.ch[gj] += val / n as f64;
                }
            }
        }
        g.h += sum / n as f64;
        g.var += stratified_var(&m);
    }
}
