//! Which emitters reach which surfaces, seen from the emitters' side. A receiver's cut (the
//! parent module) weighs each node of the emitters' tree by what it could give the receiver
//! with nothing in between, and what a surface's earlier gathers found ([`super::Learned`])
//! corrects that only after its first patches have spent their samples. In a large building
//! the lamps behind walls and slabs outweigh a room's own: on the generated million-patch
//! building (19 storeys of 69 rooms, 16,774 emitting patches) 87 % of a gather's light
//! samples met something before their lamp without the learning and 69 % with it, and the
//! hemisphere rays that met the room's own lamp — drawn too seldom by the light samples to
//! take its light from them by MIS — carried ten times the variance they carry on a 100 k-patch
//! building (docs/results/lamps-seen.md).
//!
//! So before a gather each emitting patch casts a few cosine-distributed rays from random
//! points on it ([`Kernel::learn_sight`]; [`SIGHT_PER_PATCH`] rays per patch of the model in
//! all, shared by the emitters, between [`SIGHT_RAYS_MIN`] and [`SIGHT_RAYS`] each), and each
//! side of each cell of the model (the patches facing one way whose centres lie in one cube of
//! [`CELL`] mean patch sizes) remembers which emitters' rays reached it: light found from the
//! emitters' end, as in bidirectional importance sampling of many lights (Wang & Åkerlund,
//! *Bidirectional Importance Sampling for Unstructured Direct Illumination*, Eurographics
//! 2009). A patch on a side that [`TRUSTED_HITS`] or more sight rays reached makes its cut
//! splitting the nodes the side sees ([`SPLIT_UNSEEN`], [`Emitters::draw_shaped`]), and the
//! nodes none of its sight rays came from keep at most [`UNSEEN`] of its draw together
//! ([`Emitters::sighted`]). Every emitter the cut can draw stays drawable and the draw's
//! density is used throughout (the light samples, the hemisphere rays' MIS weights), so the
//! gather stays unbiased; a lamp missed by chance costs variance, not bias, and the thresholds
//! keep that rare (a lamp giving a tenth of a trusted side's light is missed by all of its
//! rays with probability e^(−4.8) < 1 %). Polygons were tried as the sides first: a building's
//! are too small (8.7 patches each on the generated one) to be reached often enough.
//!
//! Reproducible: emitter e's rays come from (seed, [`Stream::Sight`], e), whatever thread
//! casts them.

use super::{Cluster, Draw, Emitters, Receiver};
use crate::intersect::{Intersector, Ray};
use crate::light::Kernel;
use crate::mesh::Mesh;
use crate::random::{rng_for, Stream};
use crate::sample::Frame;
use glam::Vec3;
use rand::Rng;
use rayon::prelude::*;
use std::collections::HashMap;

/// The most sight rays an emitting patch casts.
pub const SIGHT_RAYS: usize = 256;
/// The fewest sight rays an emitting patch casts (models with more emitting patches than
/// patches over [`SIGHT_PER_PATCH`]: a luminous ceiling).
pub const SIGHT_RAYS_MIN: usize = 16;
/// Sight rays in all, per patch of the model, shared by the emitting patches: 1–3 % of a
/// first gather's rays.
pub const SIGHT_PER_PATCH: usize = 4;
/// A side reached by fewer sight rays than this keeps its cut as it is: too few to say which
/// lamps it does not see.
pub const TRUSTED_HITS: u32 = 48;
/// The share of a trusted side's draw left to the nodes of its cut that none of the side's
/// sight rays came from, together, at most (in their own proportions; all of their share if
/// they had less).
pub const UNSEEN: f64 = 0.1;

/// A node of a trusted side's cut that none of its sight rays came from is split, as the cut
/// is made, as if it could give this share of its estimate: the cut's nodes go to the lamps
/// the side sees (any cut is unbiased: it covers every emitter that can light the receiver).
pub const SPLIT_UNSEEN: f64 = 0.01;

/// The sides of a cell of the model are the patches facing one way (the dominant axis of
/// their normal and its sign) whose centres lie in one cube of this many times the mean patch
/// size: what a cell's patches see of the lamps is much alike, and the cell is large enough
/// for its sight rays to be counted in tens (the rays' budget is per patch).
pub const CELL: f32 = 5.0;

/// Per side of each cell (`CELL`), the emitters whose sight rays reached it.
#[derive(Clone, Debug, Default)]
pub(crate) struct Sight {
    /// Per patch: its side of a cell.
    of_patch: Vec<u32>,
    /// Per side: its stretch of `pos` (`start[k]..start[k + 1]`).
    start: Vec<u32>,
    /// The places in the tree order of the emitters that reached each side, ascending.
    pos: Vec<u32>,
    /// Whether each side was reached by [`TRUSTED_HITS`] sight rays or more.
    trusted: Vec<bool>,
}

/// Each patch's side of a cell (`CELL`), numbered densely, and how many there are.
fn cell_sides(mesh: &Mesh) -> (Vec<u32>, usize) {
    let n = mesh.patches.len().max(1);
    let size = CELL * (mesh.total_area() / n as f64).sqrt() as f32;
    let size = if size > 0.0 && size.is_finite() {
        size
    } else {
        1.0
    };
    let mut ids: HashMap<(u8, [i32; 3]), u32> = HashMap::new();
    let of_patch = (mesh.patches.iter())
        .map(|p| {
            let a = p.normal.abs();
            let axis = if a.x >= a.y && a.x >= a.z {
                0
            } else if a.y >= a.z {
                1
            } else {
                2
            };
            let facing = axis as u8 * 2 + u8::from(p.normal[axis] < 0.0);
            let c = (p.centre / size).floor();
            let key = (facing, [c.x as i32, c.y as i32, c.z as i32]);
            let next = ids.len() as u32;
            *ids.entry(key).or_insert(next)
        })
        .collect();
    (of_patch, ids.len())
}

impl Sight {
    /// The emitters (places in the tree order, ascending) that reached patch `i`'s side of its
    /// cell, if the side was reached often enough to judge by.
    fn reached(&self, i: usize) -> Option<&[u32]> {
        let key = *self.of_patch.get(i)? as usize;
        if !self.trusted[key] {
            return None;
        }
        Some(&self.pos[self.start[key] as usize..self.start[key + 1] as usize])
    }
}

/// Whether a sight ray from an emitter of `node` reached the side whose emitters are `reached`.
fn seen(node: &Cluster, reached: &[u32]) -> bool {
    let at = reached.partition_point(|&p| (p as usize) < node.start);
    reached.get(at).is_some_and(|&p| (p as usize) < node.end)
}

/// How a cut made for a side that `reached` (when trusted) ranks `node` for splitting: its
/// estimate's share, 1 or [`SPLIT_UNSEEN`].
pub(super) fn split_priority(node: &Cluster, reached: Option<&[u32]>) -> f64 {
    match reached {
        Some(r) if !seen(node, r) => SPLIT_UNSEEN,
        _ => 1.0,
    }
}

impl Emitters {
    /// Takes the sight cast for these emitters ([`Kernel::learn_sight`]), to be handed to the
    /// kernel of a later gather round of the same solution ([`Emitters::set_sight`]) rather
    /// than cast again (the same seed would cast the same rays).
    pub(crate) fn take_sight(&mut self) -> Option<Sight> {
        self.sight.take()
    }

    /// Gives these emitters a sight cast before ([`Emitters::take_sight`]).
    pub(crate) fn set_sight(&mut self, sight: Sight) {
        self.sight = Some(sight);
    }

    /// The emitters that reached patch `i`'s side of its cell, if it is trusted.
    fn reached_by(&self, i: usize) -> Option<&[u32]> {
        self.sight.as_ref()?.reached(i)
    }

    /// [`Emitters::draw_for`] for the receiver `r` of patch `i`, its cut's nodes split where
    /// `i`'s side sees the lamps ([`SPLIT_UNSEEN`]); weighed by the estimates alone (see
    /// [`Emitters::sighted`]).
    pub fn draw_shaped(&self, r: &Receiver, i: usize) -> Option<Draw> {
        let (nodes, est) = self.cut_for(r, self.reached_by(i));
        self.draw_of(nodes, est)
    }

    /// The nodes of the cut [`Emitters::draw_shaped`] makes, to be shared by the patches `r`
    /// covers ([`Learned::share_cut`](super::Learned)).
    pub fn cut_nodes_shaped(&self, r: &Receiver, i: usize) -> Vec<u32> {
        self.cut_for(r, self.reached_by(i)).0
    }

    /// `draw` (a receiver's cut) for patch `i`: the nodes of its cut from which no sight ray
    /// reached its side of its cell drawn at [`UNSEEN`] of the draw together, when the side is
    /// trusted (module notes). A draw by power, or with no sight learnt, is left as it is.
    pub fn sighted(&self, mut draw: Draw, i: usize) -> Draw {
        let Some(reached) = self.reached_by(i) else {
            return draw;
        };
        let Some(cut) = draw.local.as_mut() else {
            return draw;
        };
        let (mut lo, mut seen_mass, mut unseen_mass) = (0.0, 0.0, 0.0);
        let q: Vec<(f64, bool)> = (cut.nodes.iter().zip(&cut.cdf))
            .map(|(&n, &c)| {
                let seen = seen(&self.nodes[n as usize], reached);
                let p = c - lo;
                lo = c;
                if seen {
                    seen_mass += p;
                } else {
                    unseen_mass += p;
                }
                (p, seen)
            })
            .collect();
        if seen_mass <= 0.0 || unseen_mass <= 0.0 {
            return draw;
        }
        // The unseen nodes together keep at most UNSEEN of the draw, in their own proportions.
        let scale = (UNSEEN / (1.0 - UNSEEN) * seen_mass / unseen_mass).min(1.0);
        let total = seen_mass + scale * unseen_mass;
        let mut acc = 0.0;
        for (c, &(p, seen)) in cut.cdf.iter_mut().zip(&q) {
            acc += if seen { p } else { p * scale } / total;
            *c = acc;
        }
        *cut.cdf.last_mut().expect("a cut is never empty") = 1.0;
        draw
    }
}

impl<I: Intersector> Kernel<'_, I> {
    /// Casts the emitters' sight rays and keeps which sides they reached (module notes), for
    /// [`Emitters::sighted`]; returns the rays cast (none when nothing emits).
    pub(crate) fn learn_sight(&mut self, seed: u64) -> u64 {
        let n = self.emitters.patches.len();
        if n == 0 {
            return 0;
        }
        let rays =
            (SIGHT_PER_PATCH * self.mesh.patches.len() / n).clamp(SIGHT_RAYS_MIN, SIGHT_RAYS);
        let found: Vec<Vec<(u32, u32)>> = (0..n)
            .into_par_iter()
            .map(|e| self.sight_of(e, rays, seed))
            .collect();
        let (of_patch, keys) = cell_sides(self.mesh);
        let found: Vec<Vec<(u32, u32)>> = found
            .into_iter()
            .map(|list| merge_counts(list.iter().map(|&(r, c)| (of_patch[r as usize], c))))
            .collect();
        let mut hits = vec![0u32; keys];
        let mut pairs: Vec<(u32, u32)> = Vec::new();
        for (e, list) in found.iter().enumerate() {
            for &(key, count) in list {
                hits[key as usize] += count;
                pairs.push((key, self.emitters.position[e]));
            }
        }
        pairs.sort_unstable();
        let mut start = vec![0u32; keys + 1];
        for &(key, _) in &pairs {
            start[key as usize + 1] += 1;
        }
        for k in 0..keys {
            start[k + 1] += start[k];
        }
        self.emitters.sight = Some(Sight {
            of_patch,
            start,
            pos: pairs.into_iter().map(|(_, p)| p).collect(),
            trusted: hits.iter().map(|&h| h >= TRUSTED_HITS).collect(),
        });
        (rays * n) as u64
    }

    /// Emitter `e`'s sight rays: `rays` cosine-distributed directions from uniform points on
    /// it, each to the first opaque side it meets (through glazing). Returns the patches met
    /// and how many rays met each, by patch.
    fn sight_of(&self, e: usize, rays: usize, seed: u64) -> Vec<(u32, u32)> {
        let j = self.emitters.patches[e];
        let at = &self.emitters.at[e];
        let mut rng = rng_for(seed, Stream::Sight, e as u64);
        let frame = Frame::new(at.normal, rng.gen::<f32>() * std::f32::consts::TAU);
        let eps = self.eps_of(j);
        let mut keys: Vec<(u32, u32)> = Vec::with_capacity(rays);
        for _ in 0..rays {
            let (u, v): (f32, f32) = (rng.gen(), rng.gen());
            let (a, b): (f32, f32) = (rng.gen(), rng.gen());
            let r = a.sqrt();
            let (s, c) = (std::f32::consts::TAU * b).sin_cos();
            let local = Vec3::new(r * c, r * s, (1.0 - a).max(0.0).sqrt());
            let ray = Ray {
                org: at.points.at(u, v) + at.normal * eps,
                dir: frame.to_world(local),
                tnear: 0.0,
                tfar: f32::INFINITY,
            };
            if let Some((r, _)) = self.receiver_of(self.cast(j, ray, eps).hit) {
                keys.push((r as u32, 1));
            }
        }
        merge_counts(keys.into_iter())
    }
}

/// (key, count) pairs with each key once, its counts added, by key.
fn merge_counts(pairs: impl Iterator<Item = (u32, u32)>) -> Vec<(u32, u32)> {
    let mut v: Vec<(u32, u32)> = pairs.collect();
    v.sort_unstable_by_key(|&(k, _)| k);
    let mut out: Vec<(u32, u32)> = Vec::with_capacity(v.len());
    for (k, c) in v {
        match out.last_mut() {
            Some((last, count)) if *last == k => *count += c,
            _ => out.push((k, c)),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::intersect::brute::BruteForce;
    use crate::light::{emission_and_reflectance, scalar, Solved};
    use crate::scene::{Material, Polygon, Scene};
    use std::borrow::Cow;

    /// Two closed rooms 4 × 2.5 × 4 m, one above the other with a 0.3 m slab between, each
    /// lit by a 1 m² lamp under its ceiling; the upper lamp 4× as bright.
    fn stacked_rooms() -> Scene {
        let mut scene = Scene {
            materials: vec![
                Material {
                    name: "wall".into(),
                    rho: [0.5; 3],
                    ..Material::default()
                },
                Material {
                    name: "lamp".into(),
                    ke: [1.0; 3],
                    ..Material::default()
                },
                Material {
                    name: "bright".into(),
                    ke: [4.0; 3],
                    ..Material::default()
                },
            ],
            ..Scene::default()
        };
        // A quad from corner c along u then v, facing u × v.
        let mut quad = |c: Vec3, u: Vec3, v: Vec3, material: u32| {
            let first = scene.positions.len() as u32;
            scene
                .positions
                .extend_from_slice(&[c, c + u, c + u + v, c + v]);
            scene.indices.extend(first..first + 4);
            scene.polygons.push(Polygon {
                first,
                len: 4,
                material,
                back_material: None,
            });
        };
        let (x, z) = (Vec3::X * 4.0, Vec3::Z * 4.0);
        for (y0, lamp) in [(0.0, 1), (2.8, 2)] {
            let (h, c) = (Vec3::Y * 2.5, Vec3::Y * y0);
            quad(c, z, x, 0);
            quad(c + h, x, z, 0);
            quad(c, h, z, 0);
            quad(c + x, z, h, 0);
            quad(c, x, h, 0);
            quad(c + z, h, x, 0);
            let at = Vec3::new(1.5, y0 + 2.49, 1.5);
            quad(at, Vec3::X, Vec3::Z, lamp);
        }
        scene
    }

    /// A floor patch's cut weighs the lamp above the slab by what it could give with nothing
    /// between; once the emitters' sight rays are cast, it keeps at most [`UNSEEN`] of the
    /// draw, every lamp the cut could draw is still drawn (the gather stays unbiased), the
    /// probabilities still add up to one, and the same seed casts the same sight.
    #[test]
    fn a_lamp_behind_a_slab_keeps_at_most_the_unseen_share() {
        let scene = stacked_rooms();
        let opts = crate::mesh::MeshOptions {
            patch_size: Some(0.5),
            uniform_patches: true,
            ..Default::default()
        };
        let mesh = crate::mesh::build(&scene, &opts);
        let (e, rho) = emission_and_reflectance(&mesh, &scene.materials);
        let b = vec![[0.0; 3]; mesh.patches.len()];
        let isect = BruteForce::new(&mesh);
        let solved = || Solved {
            e: Cow::Borrowed(&e),
            rho: Cow::Borrowed(&rho),
            b: &b,
            channels: &[],
            group: None,
        };
        let mut kernel = Kernel::new(&mesh, &scene.materials, &isect, solved(), None);
        let floor: Vec<usize> = (0..mesh.patches.len())
            .filter(|&i| mesh.patches[i].normal.y > 0.99 && mesh.patches[i].centre.y < 0.1)
            .collect();
        assert_eq!(floor.len(), 64);
        let lamps = kernel.emitters.patches.clone();
        let power = |k: usize| scalar(e[lamps[k]]) * mesh.patches[lamps[k]].area;
        let upstairs = |m: &[f64]| {
            (0..m.len())
                .filter(|&k| mesh.patches[lamps[k]].centre.y > 2.8)
                .map(|k| m[k])
                .sum::<f64>()
        };
        let receivers: Vec<_> = floor.iter().map(|&i| kernel.patch_receiver(i)).collect();
        let masses = |em: &Emitters, at: usize, sighted: bool| -> Vec<f64> {
            let d = em.draw_for(&receivers[at]).expect("lit from above");
            let d = if sighted { em.sighted(d, floor[at]) } else { d };
            (0..lamps.len()).map(|k| em.mass(&d, k, power(k))).collect()
        };
        let before: Vec<Vec<f64>> = (0..floor.len())
            .map(|at| masses(&kernel.emitters, at, false))
            .collect();
        kernel.learn_sight(7);
        let mut again = Kernel::new(&mesh, &scene.materials, &isect, solved(), None);
        again.learn_sight(7);
        let (s1, s2) = (
            kernel.emitters.sight.as_ref(),
            again.emitters.sight.as_ref(),
        );
        let (s1, s2) = (s1.expect("cast"), s2.expect("cast"));
        assert_eq!((&s1.start, &s1.pos), (&s2.start, &s2.pos));
        for (at, b) in before.iter().enumerate() {
            let a = masses(&kernel.emitters, at, true);
            assert!((a.iter().sum::<f64>() - 1.0).abs() < 1e-9);
            for (x, y) in b.iter().zip(&a) {
                assert_eq!(*x > 0.0, *y > 0.0, "drawable before and after alike");
            }
            assert!(upstairs(b) > 0.3, "the lamp upstairs held {}", upstairs(b));
            assert!(upstairs(&a) <= UNSEEN + 1e-9, "{} after", upstairs(&a));
        }
    }
}
