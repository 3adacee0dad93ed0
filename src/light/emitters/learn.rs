//! Light samples that learn what a surface sees. A receiver's cut (the parent module) weighs
//! each node by the irradiance it could give the receiver if nothing stood between them; it
//! knows nothing of walls and slabs. On the generated 100 k-patch building a floor patch's
//! light samples went 79 % (median) to lamps it cannot see — those of the rooms beside it and
//! of the storey above, as near as its own — and a floor's direct light was the noisiest part
//! of its gather (docs/results/ray-path.md).
//!
//! Neighbouring patches of one surface see the same lamps, so the gathers of a surface's
//! patches, made one after another, pass on what they found ([`Learned`]): per node of the
//! emitters' tree, how many of its light samples reached it. The next patch draws each node of
//! its cut by the cut's probability times the share of that node's samples seen so far,
//! v = (seen + ½)/(tried + 1) (½ for a node not tried yet), mixed with [`KEEP`] of the cut's
//! own draw, so that every emitter the cut can draw stays drawn (what a node's samples found
//! on one patch need not hold on the next: a shadow's edge runs across a floor).
//!
//! Unbiased: a patch's draw is fixed before its own samples are drawn (it depends on other
//! patches' random numbers only), and its density is used throughout — for the samples, for
//! the hemisphere rays' MIS weights and for the followed points' light samples. Reproducible:
//! which patches learn from which is fixed by the order of the patches, not by the threads.
//!
//! A few neighbouring patches of one polygon also share the *shape* of their cut
//! ([`Learned::share_cut`]): which nodes of the tree it holds, made once for a receiver that
//! covers them all, each patch then weighing those nodes for itself
//! ([`Emitters::draw_among`]). A node that can light none of a patch's points weighs nothing
//! for it and is dropped; every node that can is in the shared cut, since the covering
//! receiver's plane lies behind each patch's and its sphere holds each patch's: still
//! unbiased, for a fraction of the cost of a cut of its own (the tree's nodes are searched
//! once for the group).

use super::{contribution, Draw, Emitters, Receiver};
use glam::Vec3;

/// The share of a learned draw that stays the cut's own (see the module notes): a node found
/// dark is still drawn at least this share of what the cut gives it.
pub const KEEP: f64 = 0.25;

/// Counts older than this many samples of a node are halved, so what nearer patches found
/// weighs more than what the first patches of a long surface found.
const MEMORY: f32 = 64.0;

/// What the gathers made so far on one surface found: per node of the emitters' tree, the
/// light samples seen (reaching the emitter) and tried, sorted by node.
#[derive(Clone, Debug, Default)]
pub(crate) struct Learned {
    counts: Vec<(u32, f32, f32)>,
    /// This gather's samples, (node, seen), merged into `counts` by [`Learned::settle`].
    fresh: Vec<(u32, bool)>,
    /// The nodes of the cut the current neighbours share ([`Learned::share_cut`]); empty when
    /// each patch makes its own.
    shared: Vec<u32>,
}

impl Learned {
    /// Notes a light sample of node `node`: whether it reached its emitter.
    pub fn record(&mut self, node: u32, seen: bool) {
        self.fresh.push((node, seen));
    }

    /// Merges this gather's samples into the counts (after the gather: the draw of a gather
    /// never depends on its own samples).
    pub fn settle(&mut self) {
        if self.fresh.is_empty() {
            return;
        }
        self.fresh.sort_unstable_by_key(|&(n, _)| n);
        for &(node, seen) in &self.fresh {
            let at = self.counts.partition_point(|&(n, _, _)| n < node);
            if self.counts.get(at).is_none_or(|&(n, _, _)| n != node) {
                self.counts.insert(at, (node, 0.0, 0.0));
            }
            let c = &mut self.counts[at];
            c.1 += f32::from(u8::from(seen));
            c.2 += 1.0;
            if c.2 > MEMORY {
                c.1 *= 0.5;
                c.2 *= 0.5;
            }
        }
        self.fresh.clear();
    }

    /// The gathers that follow, until the next call, draw among the nodes of `nodes` (a cut
    /// made for a receiver covering them all, [`Receiver::covering`]); none: each its own cut.
    pub fn share_cut(&mut self, nodes: Option<Vec<u32>>) {
        self.shared = nodes.unwrap_or_default();
    }

    /// The cut the current neighbours share, if any.
    pub fn shared_cut(&self) -> Option<&[u32]> {
        (!self.shared.is_empty()).then_some(&self.shared[..])
    }

    /// The share of node `node`'s samples seen so far: (seen + ½)/(tried + 1).
    fn seen_share(&self, node: u32) -> f64 {
        match self.counts.binary_search_by_key(&node, |&(n, _, _)| n) {
            Ok(at) => {
                let (_, seen, tried) = self.counts[at];
                (f64::from(seen) + 0.5) / (f64::from(tried) + 1.0)
            }
            Err(_) => 0.5,
        }
    }
}

impl Receiver {
    /// A receiver covering `parts` (receivers of one plane's patches, with their areas): their
    /// area-weighted centre, moved back along the normal to the hindmost of their centres, and
    /// a sphere holding each part's. What no point of it can see, no point of theirs can.
    pub fn covering(parts: &[(Receiver, f32)]) -> Receiver {
        let normal = parts[0].0.normal;
        let (mut sum, mut area) = (Vec3::ZERO, 0.0f32);
        for (r, a) in parts {
            sum += r.centre * *a;
            area += *a;
        }
        let mean = if area > 0.0 {
            sum / area
        } else {
            parts[0].0.centre
        };
        let back = (parts.iter())
            .map(|(r, _)| normal.dot(r.centre))
            .fold(f32::INFINITY, f32::min);
        let centre = mean - normal * (normal.dot(mean) - back).max(0.0);
        let radius = (parts.iter())
            .map(|(r, _)| r.centre.distance(centre) + r.radius)
            .fold(0.0f32, f32::max);
        Receiver {
            centre,
            normal,
            radius,
        }
    }
}

impl Emitters {
    /// The draw of receiver `r` among the nodes of a shared cut, each weighed for `r` as its
    /// own cut would weigh it; the nodes that can give `r` nothing dropped. `None` when none
    /// can.
    pub fn draw_among(&self, nodes: &[u32], r: &Receiver) -> Option<Draw> {
        let (mut kept, mut est) = (Vec::with_capacity(nodes.len()), Vec::new());
        for &n in nodes {
            let w = contribution(&self.nodes[n as usize], r);
            if w > 0.0 {
                kept.push(n);
                est.push(w);
            }
        }
        self.draw_of(kept, est)
    }

    /// `draw` weighed by what `learned` found (module notes); a draw by power, or a cut none
    /// of whose nodes has been tried, stays as it is.
    pub fn learned(&self, mut draw: Draw, learned: &Learned) -> Draw {
        let Some(cut) = draw.local.as_ref() else {
            return draw;
        };
        if learned.counts.is_empty() {
            return draw;
        }
        let mut lo = 0.0;
        let mut p: Vec<f64> = Vec::with_capacity(cut.nodes.len());
        let mut total = 0.0;
        for (&n, &c) in cut.nodes.iter().zip(&cut.cdf) {
            let q = (c - lo) * learned.seen_share(n);
            lo = c;
            p.push(q);
            total += q;
        }
        if total <= 0.0 || !total.is_finite() {
            return draw;
        }
        let mut lo = 0.0;
        let mut acc = 0.0;
        let mut cdf: Vec<f64> = (p.iter().zip(&cut.cdf))
            .map(|(&q, &c)| {
                acc += KEEP * (c - lo) + (1.0 - KEEP) * q / total;
                lo = c;
                acc
            })
            .collect();
        *cdf.last_mut().expect("a cut is never empty") = 1.0;
        // The same nodes, drawn by the new CDF.
        if let Some(cut) = draw.local.as_mut() {
            cut.cdf = cdf;
        }
        draw
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::{scalar, Rgb};

    /// Lamps facing down over a floor (a 12 × 12 grid at z = 3) and a column of lamps on a
    /// wall at x = 6 facing +x: every emitter a floor patch's own cut can draw, the shared cut
    /// of its neighbours can draw too, the probabilities still add up to one, and the wall's
    /// lamps, which the group spanning x = 6 can see, are dropped for a patch wholly behind
    /// their plane.
    #[test]
    fn a_shared_cut_draws_every_emitter_a_patch_can_see() {
        use super::super::tests::{ceiling, lamps};
        let mut quads = ceiling(12);
        for j in 0..12 {
            let y = j as f32;
            // Facing +x.
            quads.push([
                Vec3::new(6.0, y, 1.0),
                Vec3::new(6.0, y + 0.2, 1.0),
                Vec3::new(6.0, y + 0.2, 1.2),
                Vec3::new(6.0, y, 1.2),
            ]);
        }
        let mesh = lamps(&quads);
        let e = vec![Rgb::ONE; mesh.patches.len()];
        let em = Emitters::new(&mesh, &e);
        assert!(
            em.patches.len() > super::super::CLUSTERS,
            "a tree, not one node per emitter"
        );
        // Four floor patches, 0.2 m across, on both sides of the wall's plane.
        let floor = |x: f32, y: f32| Receiver {
            centre: Vec3::new(x, y, 0.0),
            normal: Vec3::Z,
            radius: 0.15,
        };
        let group = [
            floor(5.5, 3.0),
            floor(5.8, 3.0),
            floor(6.2, 3.0),
            floor(6.5, 3.1),
        ];
        let parts: Vec<(Receiver, f32)> = group.iter().map(|&r| (r, 0.04)).collect();
        let cover = Receiver::covering(&parts);
        assert!(group
            .iter()
            .all(|r| cover.centre.distance(r.centre) + r.radius <= cover.radius));
        let shared = em.cut_for(&cover, None).0;
        let w = |k: usize| scalar(e[em.patches[k]]) * mesh.patches[em.patches[k]].area;
        let on_wall = |k: usize| mesh.patches[em.patches[k]].normal.x > 0.5;
        for r in &group {
            let own = em.draw_for(r).expect("lit from above");
            let among = em.draw_among(&shared, r).expect("lit from above");
            let (mut sum, mut wall) = (0.0, 0.0);
            for k in 0..em.patches.len() {
                let (m_own, m_among) = (em.mass(&own, k, w(k)), em.mass(&among, k, w(k)));
                assert!(m_own == 0.0 || m_among > 0.0, "emitter {k} lost");
                sum += m_among;
                if on_wall(k) {
                    wall += m_among;
                }
            }
            assert!((sum - 1.0).abs() < 1e-9, "{sum}");
            assert_eq!(wall > 0.0, r.centre.x + r.radius > 6.0, "{r:?}: {wall}");
        }
    }

    /// A node whose samples were all dark is drawn at about KEEP of its share; one whose
    /// samples were all seen takes the rest; the CDF still ends at exactly 1, and a pick
    /// reports the node it drew from (what the next sample is recorded against).
    #[test]
    fn a_dark_node_keeps_only_its_defensive_share() {
        // Three emitters: node 3 holds the first two, node 2 is the third.
        let em = super::super::tests::three([1.0, 1.0, 1.0]);
        let draw = Draw {
            local: Some(super::super::Cut {
                nodes: vec![3, 2],
                cdf: vec![0.5, 1.0],
            }),
        };
        let mut l = Learned::default();
        for _ in 0..200 {
            l.record(3, false);
            l.record(2, true);
        }
        l.settle();
        assert!(l.counts.iter().all(|&(_, _, t)| t <= MEMORY));
        let d = em.learned(draw, &l);
        let cdf = &d.local.as_ref().unwrap().cdf;
        let dark = cdf[0];
        assert!((dark - KEEP * 0.5).abs() < 0.01, "{dark}");
        assert_eq!(cdf[1], 1.0);
        let (e, _, _, node) = em.pick_node(&d, 0.05);
        assert_eq!((node, e < 2), (Some(3), true));
        let (e, mass, _, node) = em.pick_node(&d, 0.5);
        assert_eq!((e, node), (2, Some(2)));
        assert!((mass - (1.0 - dark)).abs() < 1e-12, "{mass}");
    }
}
