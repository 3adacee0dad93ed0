//! The emitting patches as light samples are drawn from them: chosen in proportion to their
//! power E_j·A_j (a CDF over the emitting patches, walked with a stratified number), a point
//! uniform on the chosen one (`PatchPoints`, area-preserving), and the balance heuristic's
//! weight of such a sample against a hemisphere ray for the same direction (Veach & Guibas,
//! *Optimally Combining Sampling Techniques for Monte Carlo Rendering*, SIGGRAPH 1995, Sec. 3).

use super::{scalar, Rgb};
use crate::mesh::Mesh;
use crate::sample::PatchPoints;

/// The emitting patches, the CDF of their scalar power, their points, and the total power.
pub(crate) struct Emitters {
    /// The emitting patches (a back twin emits from the back of its surface).
    pub patches: Vec<usize>,
    cdf: Vec<f64>,
    /// Uniform points on each, in the order of `patches`.
    pub points: Vec<PatchPoints>,
    /// Σ E·A (scalar W).
    pub power: f64,
}

impl Emitters {
    /// The patches of `mesh` that emit by `e` (E per patch), by scalar power.
    pub fn new(mesh: &Mesh, e: &[Rgb]) -> Self {
        let (mut patches, mut cdf, mut power) = (Vec::new(), Vec::new(), 0.0);
        for (i, p) in mesh.patches.iter().enumerate() {
            let w = scalar(e[i]) * p.area;
            if w > 0.0 {
                power += w;
                patches.push(i);
                cdf.push(power);
            }
        }
        Emitters {
            points: patches.iter().map(|&j| PatchPoints::new(mesh, j)).collect(),
            patches,
            cdf,
            power,
        }
    }

    /// Whether nothing emits.
    pub fn is_empty(&self) -> bool {
        self.patches.is_empty()
    }

    /// How many patches emit.
    pub fn len(&self) -> usize {
        self.patches.len()
    }

    /// The emitter (index into `patches`) that `s` ∈ [0, 1) picks along the power CDF, its
    /// power, and what is left of `s` within its stretch (for a point on it).
    pub fn pick(&self, s: f64) -> (usize, f64, f32) {
        let target = s * self.power;
        let e = self
            .cdf
            .partition_point(|&c| c <= target)
            .min(self.cdf.len() - 1);
        let lo = if e == 0 { 0.0 } else { self.cdf[e - 1] };
        let w = (self.cdf[e] - lo).max(f64::MIN_POSITIVE);
        (e, w, (((target - lo) / w) as f32).clamp(0.0, 1.0))
    }

    /// The balance heuristic's weight of a light sample of an emitter of emission `e_j`
    /// against a hemisphere ray for the same direction: both strategies see the emitter, each
    /// counts it with its share n·p / (n_l·p_l + n_c·p_c), the densities in solid angle. The
    /// light sample's p_l = (E_j / Σ E·A)·r²/cos θ_j, the hemisphere ray's p_c = cos θ_i / π.
    /// So a point beside a big emitter (where r²/cos θ_j → 0 and light samples blow up) takes
    /// that light from its hemisphere rays, and a small bright lamp far away from its light
    /// samples.
    pub fn weight(&self, e_j: Rgb, cos_i: f64, cos_j: f64, dist: f64, n_l: f64, n_c: f64) -> f64 {
        let p_l = scalar(e_j) / self.power * dist * dist / cos_j.max(1e-12);
        let p_c = cos_i.max(0.0) / std::f64::consts::PI;
        let (a, b) = (n_l * p_l, n_c * p_c);
        if a + b > 0.0 {
            a / (a + b)
        } else {
            1.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Three emitters of power 1, 2 and 1: the CDF picks each for its share of [0, 1), and
    /// passes on where in its stretch the number fell.
    #[test]
    fn the_cdf_picks_by_power() {
        let em = Emitters {
            patches: vec![3, 5, 8],
            cdf: vec![1.0, 3.0, 4.0],
            points: Vec::new(),
            power: 4.0,
        };
        assert_eq!(em.pick(0.1).0, 0);
        let (e, w, rest) = em.pick(0.5);
        assert_eq!((e, w), (1, 2.0));
        assert!((rest - 0.5).abs() < 1e-6);
        assert_eq!(em.pick(0.9).0, 2);
        assert_eq!(em.pick(1.0).0, 2);
    }

    /// The balance heuristic: a light sample's and a hemisphere ray's weights for one
    /// direction add up to one.
    #[test]
    fn the_weights_of_a_path_add_up_to_one() {
        let em = Emitters {
            patches: vec![0],
            cdf: vec![2.0],
            points: Vec::new(),
            power: 2.0,
        };
        let e = Rgb::splat(10.0);
        let w = em.weight(e, 0.7, 0.4, 1.5, 8.0, 24.0);
        assert!(w > 0.0 && w < 1.0, "{w}");
        let p_l = 10.0 / 2.0 * 1.5 * 1.5 / 0.4;
        let p_c = 0.7 / std::f64::consts::PI;
        assert!((w - 8.0 * p_l / (8.0 * p_l + 24.0 * p_c)).abs() < 1e-12);
        assert_eq!(em.weight(e, 0.0, 0.4, 1.5, 0.0, 1.0), 1.0);
    }
}
