//! The emitting patches as light samples are drawn from them, and the balance heuristic's
//! weight of such a sample against a hemisphere ray for the same direction (Veach & Guibas,
//! *Optimally Combining Sampling Techniques for Monte Carlo Rendering*, SIGGRAPH 1995, Sec. 3).
//!
//! **Two ways to draw an emitter.** By power alone (`Draw::by_power`): a patch j chosen in
//! proportion to E_j·A_j (a CDF over the emitting patches, walked with a stratified number),
//! a point uniform on it. Or by what each emitter can give the receiver at hand
//! (`Emitters::draw_for`): the emitting patches are grouped into at most [`CLUSTERS`]
//! clusters (each patch its own when there are no more; otherwise neighbours of one facing,
//! in Morton order), and each cluster is weighed by an estimate of the irradiance it gives the
//! receiver's centre — its power over π d², the cosines at both ends loosened by the
//! clusters' and the receiver's extents, at most the cluster's exitance (a Lambertian emitter
//! filling the whole hemisphere gives no more) — mixed with [`DEFENSIVE`] of the draw by
//! power (Hesterberg's defensive importance sampling, so an estimate that is too low never
//! makes the variance unbounded). A cluster lying wholly behind the receiver's plane, or a
//! receiver wholly behind a one-facing cluster's planes, gives nothing and is never drawn;
//! when every cluster gives nothing the gather sends no light samples at all.
//!
//! Why: a luminaire modelled as a closed box or a thin panel with every face emitting (as CAD
//! and glTF exports write them) sends half its power away from a ceiling 0.3 m above it, and
//! the faces that do light the ceiling give it light in proportion to 1/r², which a draw by
//! power ignores: on such a panel the ceiling's patches came out 10–18 % off with 500 rays
//! each (docs/results/converted-models.md). Within a cluster, patches are drawn by power.

use super::{scalar, Rgb};
use crate::mesh::Mesh;
use crate::sample::PatchPoints;
use glam::Vec3;

/// At most this many clusters of emitting patches weighed per receiver (each patch is its own
/// cluster when there are no more emitting patches than this).
pub const CLUSTERS: usize = 128;

/// The share of a receiver's light samples drawn by power among the emitters that can light
/// it, whatever the estimate of their contributions says.
pub const DEFENSIVE: f64 = 0.2;

/// One cluster of emitting patches: `order[start..end]`.
#[derive(Clone, Debug)]
struct Cluster {
    start: usize,
    end: usize,
    /// Σ scalar(E)·A of the members (W).
    power: f64,
    /// The power-weighted centre of the members.
    centre: Vec3,
    /// The bounding box of the members' corners.
    lo: Vec3,
    hi: Vec3,
    /// Half the box's diagonal.
    half: f32,
    /// The normal every member shares (within 1e-4), if they do, and the least of the
    /// members' corner offsets along it.
    facing: Option<(Vec3, f32)>,
    /// The largest scalar exitance among the members (W/m²).
    e_max: f64,
}

/// The emitting patches, the CDF of their scalar power, their points, their clusters and the
/// total power.
pub(crate) struct Emitters {
    /// The emitting patches, ascending (a back twin emits from the back of its surface).
    pub patches: Vec<usize>,
    cdf: Vec<f64>,
    /// Uniform points on each, in the order of `patches`.
    pub points: Vec<PatchPoints>,
    /// Σ E·A (scalar W).
    pub power: f64,
    clusters: Vec<Cluster>,
    /// Emitters (indices into `patches`) in cluster order.
    order: Vec<u32>,
    /// Per emitter: its cluster.
    cluster_of: Vec<u32>,
    /// In `order`: the cumulative power within the member's cluster, up to and including it.
    within: Vec<f64>,
}

/// How one receiver draws its light samples: by power, or by the clusters' estimated
/// contributions (a CDF over the clusters of probabilities).
#[derive(Clone, Debug)]
pub(crate) struct Draw {
    /// The CDF over the clusters and the last cluster of non-zero probability.
    local: Option<(Vec<f64>, usize)>,
}

impl Draw {
    /// Every emitter in proportion to its power.
    pub fn by_power() -> Draw {
        Draw { local: None }
    }

    /// The probability of cluster `c`.
    fn cluster_mass(&self, em: &Emitters, c: usize) -> f64 {
        match &self.local {
            None => em.clusters[c].power / em.power,
            Some((cdf, _)) => cdf[c] - if c == 0 { 0.0 } else { cdf[c - 1] },
        }
    }
}

/// The receiver a [`Draw`] is made for: its centre, normal and radius (0 for a point).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Receiver {
    pub centre: Vec3,
    pub normal: Vec3,
    pub radius: f32,
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
        let order = cluster_order(mesh, &patches);
        let chunk = patches.len().div_ceil(CLUSTERS).max(1);
        let mut clusters = Vec::new();
        let mut cluster_of = vec![0u32; patches.len()];
        let mut within = vec![0.0; patches.len()];
        let mut start = 0;
        while start < order.len() {
            // A cluster: up to `chunk` neighbours of one facing class.
            let class = facing_class(mesh.patches[patches[order[start] as usize]].normal);
            let mut end = start + 1;
            while end < order.len()
                && end - start < chunk
                && facing_class(mesh.patches[patches[order[end] as usize]].normal) == class
            {
                end += 1;
            }
            let c = clusters.len();
            let mut acc = 0.0;
            for k in start..end {
                let ei = order[k] as usize;
                acc += scalar(e[patches[ei]]) * mesh.patches[patches[ei]].area;
                within[k] = acc;
                cluster_of[ei] = c as u32;
            }
            clusters.push(cluster(mesh, e, &patches, &order[start..end], (start, end)));
            start = end;
        }
        Emitters {
            points: patches.iter().map(|&j| PatchPoints::new(mesh, j)).collect(),
            patches,
            cdf,
            power,
            clusters,
            order,
            cluster_of,
            within,
        }
    }

    /// Whether nothing emits.
    pub fn is_empty(&self) -> bool {
        self.patches.is_empty()
    }

    /// The emitter (index into `patches`) of patch `j`, if it emits.
    pub fn index_of(&self, j: usize) -> Option<usize> {
        self.patches.binary_search(&j).ok()
    }

    /// The draw of a receiver: each cluster weighed by the irradiance it can give `r`'s
    /// centre, [`DEFENSIVE`] of it by power among the clusters that can light `r` at all.
    /// `None` when none can: no light sample could reach `r`.
    pub fn draw_for(&self, r: &Receiver) -> Option<Draw> {
        let mut est = Vec::with_capacity(self.clusters.len());
        let (mut total, mut reach) = (0.0, 0.0);
        for c in &self.clusters {
            let w = contribution(c, r);
            if w > 0.0 {
                total += w;
                reach += c.power;
            }
            est.push(w);
        }
        if total <= 0.0 || !total.is_finite() {
            return None;
        }
        let (mut acc, mut last) = (0.0, 0);
        for (k, (w, c)) in est.iter_mut().zip(&self.clusters).enumerate() {
            if *w > 0.0 {
                acc += (1.0 - DEFENSIVE) * *w / total + DEFENSIVE * c.power / reach;
                last = k;
            }
            *w = acc;
        }
        // Rounding: the last cluster that can light r ends at exactly 1.
        est[last..].fill(1.0);
        Some(Draw {
            local: Some((est, last)),
        })
    }

    /// The emitter (index into `patches`) that `s` ∈ [0, 1) picks by `draw`, its probability
    /// of being picked, and what is left of `s` within its stretch (for a point on it).
    pub fn pick(&self, draw: &Draw, s: f64) -> (usize, f64, f32) {
        match &draw.local {
            None => {
                let target = s * self.power;
                let e = self
                    .cdf
                    .partition_point(|&c| c <= target)
                    .min(self.cdf.len() - 1);
                let lo = if e == 0 { 0.0 } else { self.cdf[e - 1] };
                let w = (self.cdf[e] - lo).max(f64::MIN_POSITIVE);
                let rest = (((target - lo) / w) as f32).clamp(0.0, 1.0);
                (e, w / self.power, rest)
            }
            Some((cdf, last)) => {
                let c = cdf.partition_point(|&x| x <= s).min(*last);
                let lo = if c == 0 { 0.0 } else { cdf[c - 1] };
                let q = (cdf[c] - lo).max(f64::MIN_POSITIVE);
                let s1 = ((s - lo) / q).clamp(0.0, 1.0);
                let cl = &self.clusters[c];
                let target = s1 * cl.power;
                let k = cl.start
                    + self.within[cl.start..cl.end]
                        .partition_point(|&x| x <= target)
                        .min(cl.end - cl.start - 1);
                let lo2 = if k == cl.start {
                    0.0
                } else {
                    self.within[k - 1]
                };
                let w = (self.within[k] - lo2).max(f64::MIN_POSITIVE);
                let rest = (((target - lo2) / w) as f32).clamp(0.0, 1.0);
                (self.order[k] as usize, q * w / cl.power, rest)
            }
        }
    }

    /// The probability that `draw` picks emitter `e` (an index into `patches`) of power `w_e`.
    pub fn mass(&self, draw: &Draw, e: usize, w_e: f64) -> f64 {
        let c = self.cluster_of[e] as usize;
        draw.cluster_mass(self, c) * w_e / self.clusters[c].power
    }

    /// The balance heuristic's weight of a light sample of an emitter picked with probability
    /// `mass`, of area `area`, against a hemisphere ray for the same direction: both
    /// strategies see the emitter, each counts it with its share n·p / (n_l·p_l + n_c·p_c),
    /// the densities in solid angle. The light sample's p_l = (mass / A_j)·r²/cos θ_j, the
    /// hemisphere ray's p_c = cos θ_i / π. So a point beside a big emitter (where
    /// r²/cos θ_j → 0 and light samples blow up) takes that light from its hemisphere rays,
    /// and a small bright lamp far away from its light samples.
    pub fn weight(
        mass: f64,
        area: f64,
        (cos_i, cos_j, dist): (f64, f64, f64),
        n_l: f64,
        n_c: f64,
    ) -> f64 {
        let p_l = mass / area.max(f64::MIN_POSITIVE) * dist * dist / cos_j.max(1e-12);
        let p_c = cos_i.max(0.0) / std::f64::consts::PI;
        let (a, b) = (n_l * p_l, n_c * p_c);
        if a + b > 0.0 {
            a / (a + b)
        } else {
            1.0
        }
    }
}

/// The irradiance cluster `c` can give the centre of receiver `r`, roughly (module notes):
/// 0 exactly when no point of `r`'s plane in front of it can see any of `c`'s emitting sides.
fn contribution(c: &Cluster, r: &Receiver) -> f64 {
    // The cluster wholly behind the receiver's plane (or in it).
    let far = Vec3::select(r.normal.cmpgt(Vec3::ZERO), c.hi, c.lo);
    if r.normal.dot(far - r.centre) <= 0.0 {
        return 0.0;
    }
    // The receiver wholly behind the planes of a one-facing cluster.
    if let Some((n, least)) = c.facing {
        if n.dot(r.centre) + r.radius <= least {
            return 0.0;
        }
    }
    let d = c.centre - r.centre;
    let d2 = f64::from(d.length_squared()).max(1e-12);
    let dist = d2.sqrt();
    let spread = f64::from(c.half + r.radius);
    let sin_a = (spread / dist).min(1.0);
    let cos_i = (f64::from(r.normal.dot(d)) / dist).max(0.0);
    let cos_i = (cos_i + sin_a).min(1.0);
    let cos_j = match c.facing {
        Some((n, _)) => ((-f64::from(n.dot(d)) / dist).max(0.0) + sin_a).min(1.0),
        None => 1.0,
    };
    (c.power * cos_i * cos_j / (std::f64::consts::PI * d2)).min(c.e_max)
}

/// The six axis facings, and 6 for any other: clusters never mix them.
fn facing_class(n: Vec3) -> u8 {
    let a = n.abs();
    let (axis, v) = if a.x >= a.y && a.x >= a.z {
        (0, n.x)
    } else if a.y >= a.z {
        (1, n.y)
    } else {
        (2, n.z)
    };
    if a.max_element() < 1.0 - 1e-4 {
        6
    } else {
        axis * 2 + u8::from(v < 0.0)
    }
}

/// The emitters (indices into `patches`) in cluster order: by facing, then along the Morton
/// curve of their centres in the emitters' bounding box (so a chunk of the order is a
/// compact group). When each is its own cluster the order is theirs.
fn cluster_order(mesh: &Mesh, patches: &[usize]) -> Vec<u32> {
    let mut order: Vec<u32> = (0..patches.len() as u32).collect();
    if patches.len() <= CLUSTERS {
        return order;
    }
    let centre = |e: u32| mesh.patches[patches[e as usize]].centre;
    let (lo, hi) = order.iter().fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(lo, hi), &e| (lo.min(centre(e)), hi.max(centre(e))),
    );
    let size = (hi - lo).max(Vec3::splat(1e-6));
    let key = |e: u32| {
        let q = ((centre(e) - lo) / size * 1023.0).clamp(Vec3::ZERO, Vec3::splat(1023.0));
        let m = morton(q.x as u32) | (morton(q.y as u32) << 1) | (morton(q.z as u32) << 2);
        (facing_class(mesh.patches[patches[e as usize]].normal), m, e)
    };
    order.sort_by_key(|&e| key(e));
    order
}

/// The bits of a 10-bit `v` spread to every third bit.
fn morton(v: u32) -> u32 {
    let mut x = v & 0x3ff;
    x = (x | (x << 16)) & 0x0300_00ff;
    x = (x | (x << 8)) & 0x0300_f00f;
    x = (x | (x << 4)) & 0x030c_30c3;
    x = (x | (x << 2)) & 0x0924_9249;
    x
}

/// The cluster of the emitters `members` (indices into `patches`), `span` in the order.
fn cluster(
    mesh: &Mesh,
    e: &[Rgb],
    patches: &[usize],
    members: &[u32],
    (start, end): (usize, usize),
) -> Cluster {
    let (mut lo, mut hi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
    let (mut power, mut sum, mut e_max) = (0.0, glam::DVec3::ZERO, 0.0f64);
    let n0 = mesh.patches[patches[members[0] as usize]].normal;
    let mut shared = true;
    let mut least = f32::MAX;
    for &m in members {
        let j = patches[m as usize];
        let p = &mesh.patches[j];
        let w = scalar(e[j]) * p.area;
        power += w;
        sum += p.centre.as_dvec3() * w;
        e_max = e_max.max(scalar(e[j]));
        shared &= (p.normal - n0).length() <= 1e-4;
        for &v in mesh.patch_indices(j) {
            let v = mesh.vertices[v as usize];
            lo = lo.min(v);
            hi = hi.max(v);
            least = least.min(n0.dot(v));
        }
    }
    Cluster {
        start,
        end,
        power,
        centre: (sum / power.max(f64::MIN_POSITIVE)).as_vec3(),
        lo,
        hi,
        half: 0.5 * (hi - lo).length(),
        facing: shared.then_some((n0, least)),
        e_max,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn three(power: [f64; 3]) -> Emitters {
        let mut acc = 0.0;
        let cdf = power
            .iter()
            .map(|p| {
                acc += p;
                acc
            })
            .collect();
        let cl = |k: usize, p: f64| Cluster {
            start: k,
            end: k + 1,
            power: p,
            centre: Vec3::new(k as f32, 0.0, 0.0),
            lo: Vec3::new(k as f32, 0.0, 0.0),
            hi: Vec3::new(k as f32 + 0.1, 0.0, 0.1),
            half: 0.07,
            facing: Some((Vec3::NEG_Y, 0.0)),
            e_max: p,
        };
        Emitters {
            patches: vec![3, 5, 8],
            cdf,
            points: Vec::new(),
            power: acc,
            clusters: (0..3).map(|k| cl(k, power[k])).collect(),
            order: vec![0, 1, 2],
            cluster_of: vec![0, 1, 2],
            within: power.to_vec(),
        }
    }

    /// Three emitters of power 1, 2 and 1: the CDF picks each for its share of [0, 1), and
    /// passes on where in its stretch the number fell.
    #[test]
    fn the_cdf_picks_by_power() {
        let em = three([1.0, 2.0, 1.0]);
        let d = Draw::by_power();
        assert_eq!(em.pick(&d, 0.1).0, 0);
        let (e, q, rest) = em.pick(&d, 0.5);
        assert_eq!((e, q), (1, 0.5));
        assert!((rest - 0.5).abs() < 1e-6);
        assert_eq!(em.pick(&d, 0.9).0, 2);
        assert_eq!(em.pick(&d, 1.0).0, 2);
        assert_eq!(em.mass(&d, 1, 2.0), 0.5);
    }

    /// A receiver below the three (facing up, emitters facing down): the nearest is drawn
    /// most, each at the probability `mass` says, and the probabilities add up to one; a
    /// receiver above them (behind their planes) gets no draw at all.
    #[test]
    fn a_receiver_draws_the_emitters_near_it_most() {
        let em = three([1.0, 1.0, 1.0]);
        let below = Receiver {
            centre: Vec3::new(0.05, -0.5, 0.05),
            normal: Vec3::Y,
            radius: 0.1,
        };
        let d = em.draw_for(&below).expect("lit from above");
        let masses: Vec<f64> = (0..3).map(|e| em.mass(&d, e, 1.0)).collect();
        assert!(
            (masses.iter().sum::<f64>() - 1.0).abs() < 1e-12,
            "{masses:?}"
        );
        assert!(masses[0] > masses[1] && masses[1] > masses[2], "{masses:?}");
        assert!(masses[2] >= DEFENSIVE / 3.0 - 1e-12, "{masses:?}");
        let mut picked = [0usize; 3];
        for k in 0..1000 {
            let (e, q, _) = em.pick(&d, (k as f64 + 0.5) / 1000.0);
            assert!((q - masses[e]).abs() < 1e-12);
            picked[e] += 1;
        }
        for e in 0..3 {
            assert!(
                (picked[e] as f64 / 1000.0 - masses[e]).abs() < 2e-3,
                "{picked:?}"
            );
        }
        let above = Receiver {
            centre: Vec3::new(0.05, 0.5, 0.05),
            normal: Vec3::NEG_Y,
            radius: 0.1,
        };
        assert!(em.draw_for(&above).is_none());
        let facing_away = Receiver {
            normal: Vec3::NEG_Y,
            ..below
        };
        assert!(em.draw_for(&facing_away).is_none());
    }

    /// The balance heuristic: a light sample's and a hemisphere ray's weights for one
    /// direction add up to one.
    #[test]
    fn the_weights_of_a_path_add_up_to_one() {
        let (mass, area) = (0.25, 0.5);
        let w = Emitters::weight(mass, area, (0.7, 0.4, 1.5), 8.0, 24.0);
        assert!(w > 0.0 && w < 1.0, "{w}");
        let p_l = mass / area * 1.5 * 1.5 / 0.4;
        let p_c = 0.7 / std::f64::consts::PI;
        assert!((w - 8.0 * p_l / (8.0 * p_l + 24.0 * p_c)).abs() < 1e-12);
        assert_eq!(Emitters::weight(mass, area, (0.0, 0.4, 1.5), 0.0, 1.0), 1.0);
    }

    #[test]
    fn morton_interleaves_bits() {
        assert_eq!(morton(0b1), 0b1);
        assert_eq!(morton(0b11), 0b1001);
        assert_eq!(morton(0x3ff), 0x0924_9249);
    }
}
