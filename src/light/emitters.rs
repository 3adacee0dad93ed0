//! The emitting patches as light samples are drawn from them, and the power heuristic's
//! weight of such a sample against a hemisphere ray for the same direction (Veach & Guibas,
//! *Optimally Combining Sampling Techniques for Monte Carlo Rendering*, SIGGRAPH 1995).
//!
//! **Two ways to draw an emitter.** By power alone (`Draw::by_power`): a patch j chosen in
//! proportion to E_j·A_j (a CDF over the emitting patches, walked with a stratified number),
//! a point uniform on it. Or by what each emitter can give the receiver at hand
//! (`Emitters::draw_for`): the emitting patches are the leaves of a binary tree (by facing,
//! then along the Morton curve of their centres, halved again and again), and each receiver
//! takes a *cut* of it, at most [`CLUSTERS`] nodes covering every emitter that can light it:
//! the node that can give the receiver the most is split into its halves until the cut is
//! full (lightcuts, Walter et al., SIGGRAPH 2005, here to draw rather than to bound). Each node
//! of the cut is weighed by an estimate of the irradiance it gives the receiver's centre — its
//! power over π d², the cosines at both ends loosened by the node's and the receiver's
//! extents, at most its exitance (a Lambertian emitter filling the whole hemisphere gives no
//! more) — mixed with [`DEFENSIVE`] of the draw by power (Hesterberg's defensive importance
//! sampling, so an estimate that is too low never makes the variance unbounded). A node lying
//! wholly behind the receiver's plane, or a receiver wholly behind a one-facing node's planes,
//! gives nothing and is never drawn; when no node can give anything the gather sends no light
//! samples at all. With no more emitting patches than [`CLUSTERS`], each is its own node of
//! every cut.
//!
//! Why the tree: a building has thousands of lamps; the flat list of 128 clusters it replaced
//! held some twenty lamps each on the generated million-patch building, drawn by power within,
//! so most light samples went to other rooms. A cut draws the lamps near the receiver one by
//! one: the final gather's estimate fell from 3.61 to 2.93 % on the 100 k-patch building, from
//! 4.12 to 3.60 % on the million-patch one (docs/results/pipeline-1m.md).
//!
//! Why: a luminaire modelled as a closed box or a thin panel with every face emitting (as CAD
//! and glTF exports write them) sends half its power away from a ceiling 0.3 m above it, and
//! the faces that do light the ceiling give it light in proportion to 1/r², which a draw by
//! power ignores: on such a panel the ceiling's patches came out 10–18 % off with 500 rays
//! each (docs/results/converted-models.md). Within a node of the cut, patches are drawn by
//! power.

mod learn;
mod sight;
mod whole;

use super::{scalar, Rgb};
use crate::mesh::spatial::{facing_class, space_order};
use crate::mesh::Mesh;
use crate::sample::PatchPoints;
use glam::Vec3;
pub(crate) use learn::Learned;
pub(crate) use sight::Sight;
pub(crate) use whole::{Shape, WholeSet, WHOLE_MASS, WHOLE_MOST};

/// At most this many nodes of the emitters' tree in a receiver's cut (each emitting patch is
/// its own node of the cut when there are no more emitting patches than this).
pub const CLUSTERS: usize = 128;

/// The share of a receiver's light samples drawn by power among the emitters that can light
/// it, whatever the estimate of their contributions says (docs/results/ray-path.md).
pub const DEFENSIVE: f64 = 0.05;

/// One node of the emitters' tree: the emitters `order[start..end]`.
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
    /// The two halves (indices into the tree's nodes); none for one emitter.
    children: Option<[u32; 2]>,
}

/// The emitting patches, the CDF of their scalar power, their points, the tree of their
/// clusters and the total power.
pub(crate) struct Emitters {
    /// The emitting patches, ascending (a back twin emits from the back of its surface).
    pub patches: Vec<usize>,
    cdf: Vec<f64>,
    /// What a light sample reads of each, in the order of `patches`.
    pub at: Vec<Emitter>,
    /// Σ E·A (scalar W).
    pub power: f64,
    /// The tree: every node a contiguous stretch of `order`, the halves after their parent.
    nodes: Vec<Cluster>,
    /// The nodes a cut starts from: one per facing class (one in all when each emitter is its
    /// own node of every cut).
    roots: Vec<u32>,
    /// Emitters (indices into `patches`) in tree order.
    order: Vec<u32>,
    /// Per emitter: its place in `order`.
    position: Vec<u32>,
    /// Per place in `order`: the cumulative power up to and including it.
    within: Vec<f64>,
    /// Which sides the emitters' sight rays reached ([`Kernel::learn_sight`](crate::light::Kernel)), once cast.
    sight: Option<sight::Sight>,
}

/// How one receiver draws its light samples: by power, or by the estimated contributions of
/// the nodes of its cut of the emitters' tree.
#[derive(Clone, Debug)]
pub(crate) struct Draw {
    local: Option<Cut>,
}

/// What a light sample reads of one emitting patch (uniform points on it, its normal, area
/// and exitance E), held together: in four arrays, each cost a cache miss per light sample.
pub(crate) struct Emitter {
    pub points: PatchPoints,
    pub normal: Vec3,
    pub area: f64,
    pub e: Rgb,
}

/// A receiver's cut: nodes of the tree covering every emitter that can light it, each once,
/// in tree order, with the CDF of their probabilities (the last exactly 1).
#[derive(Clone, Debug)]
struct Cut {
    nodes: Vec<u32>,
    cdf: Vec<f64>,
}

impl Draw {
    /// Every emitter in proportion to its power.
    pub fn by_power() -> Draw {
        Draw { local: None }
    }

    /// Whether the draw is a receiver's own (a cut), not by power.
    pub fn is_local(&self) -> bool {
        self.local.is_some()
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
        let mut position = vec![0u32; patches.len()];
        let mut within = Vec::with_capacity(patches.len());
        let mut acc = 0.0;
        for (k, &ei) in order.iter().enumerate() {
            position[ei as usize] = k as u32;
            acc += scalar(e[patches[ei as usize]]) * mesh.patches[patches[ei as usize]].area;
            within.push(acc);
        }
        let mut tree = Tree {
            mesh,
            e,
            patches: &patches,
            order: &order,
            nodes: Vec::new(),
        };
        let roots = tree.roots();
        let nodes = tree.nodes;
        Emitters {
            at: (patches.iter())
                .map(|&j| Emitter {
                    points: PatchPoints::new(mesh, j),
                    normal: mesh.patches[j].normal,
                    area: mesh.patches[j].area,
                    e: e[j],
                })
                .collect(),
            patches,
            cdf,
            power,
            nodes,
            roots,
            order,
            position,
            within,
            sight: None,
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

    /// The draw of a receiver: its cut of the emitters' tree ([`Emitters::cut_for`]), each node
    /// weighed by the irradiance it can give `r`'s centre, [`DEFENSIVE`] of it by power among
    /// the nodes that can light `r` at all. `None` when none can: no light sample could reach
    /// `r`.
    pub fn draw_for(&self, r: &Receiver) -> Option<Draw> {
        let (nodes, est) = self.cut_for(r, None);
        self.draw_of(nodes, est)
    }

    /// The draw of the cut `nodes` with the estimates `est` (all positive), as
    /// [`Emitters::draw_for`] makes it.
    fn draw_of(&self, nodes: Vec<u32>, est: Vec<f64>) -> Option<Draw> {
        let (mut total, mut reach) = (0.0, 0.0);
        for (&n, &w) in nodes.iter().zip(&est) {
            total += w;
            reach += self.nodes[n as usize].power;
        }
        if nodes.is_empty() || total <= 0.0 || !total.is_finite() {
            return None;
        }
        let mut acc = 0.0;
        let mut cdf: Vec<f64> = (nodes.iter().zip(&est))
            .map(|(&n, &w)| {
                acc += (1.0 - DEFENSIVE) * w / total
                    + DEFENSIVE * self.nodes[n as usize].power / reach;
                acc
            })
            .collect();
        // Rounding: the last node ends at exactly 1.
        *cdf.last_mut().expect("not empty") = 1.0;
        Some(Draw {
            local: Some(Cut { nodes, cdf }),
        })
    }

    /// A receiver's cut of the tree (lightcuts' idea, Walter et al., SIGGRAPH 2005, used to
    /// draw rather than to bound): from the roots, the node that can give `r` the most is
    /// split into its halves, again and again, until the cut holds [`CLUSTERS`] nodes or only
    /// single emitters are left to split; a node that can give `r` nothing is dropped (its
    /// halves can give no more). So the emitters near the receiver are drawn one by one, by
    /// their own estimates, and those far away by the power of the whole node holding them.
    /// Returns the nodes in tree order and their estimates, all positive.
    fn cut_for(&self, r: &Receiver, reached: Option<&[u32]>) -> (Vec<u32>, Vec<f64>) {
        use std::collections::BinaryHeap;
        // An open node as (its priority's bits, u32::MAX − the node, its estimate's slot in
        // `open_w`): a positive f64's bits order as the f64 does, so the largest priority
        // comes first, ties to the lower node (a deterministic split); 16 bytes compared as
        // integers (popping a heap of f64 triples was a fifth of the cuts' samples in a
        // profile of the 1 M-patch building's gather).
        let mut open: BinaryHeap<(u64, u32, u32)> = BinaryHeap::new();
        let mut open_w: Vec<f64> = Vec::new();
        // (the node's first place in the order, the node, its estimate): sorted by the first.
        let mut done: Vec<(u32, u32, f64)> = Vec::new();
        let start = |n: u32| self.nodes[n as usize].start as u32;
        // Files node n where it belongs; whether it can light r (then it holds a place).
        let file = |n: u32,
                    open: &mut BinaryHeap<(u64, u32, u32)>,
                    open_w: &mut Vec<f64>,
                    done: &mut Vec<(u32, u32, f64)>| {
            let node = &self.nodes[n as usize];
            let w = contribution(node, r);
            if w > 0.0 {
                match node.children {
                    Some(_) => {
                        let priority = w * sight::split_priority(node, reached);
                        open.push((priority.to_bits(), u32::MAX - n, open_w.len() as u32));
                        open_w.push(w);
                    }
                    None => done.push((node.start as u32, n, w)),
                }
            }
            w > 0.0
        };
        let mut held = 0usize;
        for &n in &self.roots {
            held += usize::from(file(n, &mut open, &mut open_w, &mut done));
        }
        while held < CLUSTERS {
            let Some((_, rev, _)) = open.pop() else {
                break;
            };
            let n = u32::MAX - rev;
            let [a, b] = self.nodes[n as usize]
                .children
                .expect("only inner nodes are open");
            held -= 1;
            held += usize::from(file(a, &mut open, &mut open_w, &mut done));
            held += usize::from(file(b, &mut open, &mut open_w, &mut done));
        }
        // The cut is full: the nodes still open join it as they are (their order is the sort's).
        done.extend((open.into_iter()).map(|(_, rev, slot)| {
            let n = u32::MAX - rev;
            (start(n), n, open_w[slot as usize])
        }));
        // Nodes of a cut cover disjoint stretches of the order: their first places differ.
        done.sort_unstable_by_key(|&(s, _, _)| s);
        done.into_iter().map(|(_, n, w)| (n, w)).unzip()
    }

    /// The emitter (index into `patches`) that `s` ∈ [0, 1) picks by `draw`, its probability
    /// of being picked, and what is left of `s` within its stretch (for a point on it).
    pub fn pick(&self, draw: &Draw, s: f64) -> (usize, f64, f32) {
        let (e, mass, rest, _) = self.pick_node(draw, s);
        (e, mass, rest)
    }

    /// [`Emitters::pick`], and the node of the cut it picked from (`None` for a draw by power),
    /// for what the gathers of a surface learn (`Learned::record`).
    pub fn pick_node(&self, draw: &Draw, s: f64) -> (usize, f64, f32, Option<u32>) {
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
                (e, w / self.power, rest, None)
            }
            Some(cut) => {
                let last = cut.cdf.len() - 1;
                let c = cut.cdf.partition_point(|&x| x <= s).min(last);
                let lo = if c == 0 { 0.0 } else { cut.cdf[c - 1] };
                let q = (cut.cdf[c] - lo).max(f64::MIN_POSITIVE);
                let s1 = ((s - lo) / q).clamp(0.0, 1.0);
                let node = &self.nodes[cut.nodes[c] as usize];
                let base = if node.start == 0 {
                    0.0
                } else {
                    self.within[node.start - 1]
                };
                // A single emitter takes its own power (its leaf's, to the bit).
                let span = if node.end - node.start == 1 {
                    node.power
                } else {
                    self.within[node.end - 1] - base
                };
                let target = s1 * span;
                let k = node.start
                    + self.within[node.start..node.end]
                        .partition_point(|&x| x - base <= target)
                        .min(node.end - node.start - 1);
                let lo2 = if k == node.start {
                    0.0
                } else {
                    self.within[k - 1] - base
                };
                let w = if node.end - node.start == 1 {
                    node.power
                } else {
                    (self.within[k] - base - lo2).max(f64::MIN_POSITIVE)
                };
                let rest = (((target - lo2) / w) as f32).clamp(0.0, 1.0);
                (
                    self.order[k] as usize,
                    q * w / span,
                    rest,
                    Some(cut.nodes[c]),
                )
            }
        }
    }

    /// The probability that `draw` picks emitter `e` (an index into `patches`) of power `w_e`.
    pub fn mass(&self, draw: &Draw, e: usize, w_e: f64) -> f64 {
        match &draw.local {
            None => w_e / self.power,
            Some(cut) => {
                // The node of the cut holding e, if any (none: e cannot light the receiver).
                let at = self.position[e] as usize;
                let c = cut
                    .nodes
                    .partition_point(|&n| self.nodes[n as usize].start <= at);
                if c == 0 {
                    return 0.0;
                }
                let node = &self.nodes[cut.nodes[c - 1] as usize];
                if at >= node.end {
                    return 0.0;
                }
                let lo = if c == 1 { 0.0 } else { cut.cdf[c - 2] };
                (cut.cdf[c - 1] - lo) * w_e / node.power
            }
        }
    }

    /// The power heuristic's weight (β = 2) of a light sample of an emitter picked with
    /// probability `mass`, of area `area`, against a hemisphere ray for the same direction:
    /// each counts it with its share (n·p)² / ((n_l·p_l)² + (n_c·p_c)²), the densities in solid
    /// angle: p_l = (mass / A_j)·r²/cos θ_j, p_c = cos θ_i / π. So a point beside a big emitter
    /// (r²/cos θ_j → 0: light samples blow up) takes that light from its hemisphere rays, a
    /// small bright lamp far away from its light samples; the squares give a direction more
    /// nearly all to the strategy that samples it well (docs/results/ray-path.md).
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
        // a² / (a² + b²), written so that neither square overflows.
        match (a > 0.0, b > 0.0) {
            (true, _) => 1.0 / (1.0 + (b / a).powi(2)),
            (false, true) => 0.0,
            (false, false) => 1.0,
        }
    }
}

/// Builds the emitters' tree over their order: a leaf per emitter, an inner node per stretch
/// of two or more, cut in halves (at a change of facing class where the stretch has several).
struct Tree<'a> {
    mesh: &'a Mesh,
    e: &'a [Rgb],
    patches: &'a [usize],
    order: &'a [u32],
    nodes: Vec<Cluster>,
}

impl Tree<'_> {
    /// The roots: one per facing class along the order when the emitters are too many to be
    /// a cut's nodes one by one, else a single one (every cut then splits down to the leaves).
    fn roots(&mut self) -> Vec<u32> {
        let n = self.order.len();
        if n == 0 {
            return Vec::new();
        }
        if n <= CLUSTERS {
            return vec![self.build(0, n)];
        }
        let mut roots = Vec::new();
        let mut start = 0;
        while start < n {
            let class = self.class_at(start);
            let end = (start + 1..n)
                .find(|&k| self.class_at(k) != class)
                .unwrap_or(n);
            roots.push(self.build(start, end));
            start = end;
        }
        roots
    }

    fn class_at(&self, k: usize) -> u8 {
        facing_class(self.mesh.patches[self.patches[self.order[k] as usize]].normal)
    }

    /// The node of `order[start..end]`, its halves built first.
    fn build(&mut self, start: usize, end: usize) -> u32 {
        if end - start == 1 {
            let leaf = cluster(
                self.mesh,
                self.e,
                self.patches,
                &self.order[start..end],
                (start, end),
            );
            self.nodes.push(leaf);
            return (self.nodes.len() - 1) as u32;
        }
        let mid = start + (end - start) / 2;
        let (a, b) = (self.build(start, mid), self.build(mid, end));
        let node = join(&self.nodes[a as usize], &self.nodes[b as usize], [a, b]);
        self.nodes.push(node);
        (self.nodes.len() - 1) as u32
    }
}

/// The node holding the emitters of `x` and of `y`, the stretch right after it.
fn join(x: &Cluster, y: &Cluster, children: [u32; 2]) -> Cluster {
    let power = x.power + y.power;
    let centre = if power > 0.0 {
        ((x.centre.as_dvec3() * x.power + y.centre.as_dvec3() * y.power) / power).as_vec3()
    } else {
        x.centre
    };
    let (lo, hi) = (x.lo.min(y.lo), x.hi.max(y.hi));
    let facing = match (x.facing, y.facing) {
        (Some((n, a)), Some((m, b))) if (n - m).length() <= 1e-4 => Some((n, a.min(b))),
        _ => None,
    };
    Cluster {
        start: x.start,
        end: y.end,
        power,
        centre,
        lo,
        hi,
        half: 0.5 * (hi - lo).length(),
        facing,
        e_max: x.e_max.max(y.e_max),
        children: Some(children),
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

/// The emitters (indices into `patches`) in cluster order: by facing, then along the Morton
/// curve of their centres (`crate::mesh::spatial`: a chunk of the order is a compact group).
/// When each is its own cluster the order is theirs.
fn cluster_order(mesh: &Mesh, patches: &[usize]) -> Vec<u32> {
    if patches.len() <= CLUSTERS {
        return (0..patches.len() as u32).collect();
    }
    space_order(mesh, patches)
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
        children: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    pub(super) fn three(power: [f64; 3]) -> Emitters {
        let mut acc = 0.0;
        let cdf: Vec<f64> = power
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
            children: None,
        };
        let mut nodes: Vec<Cluster> = (0..3).map(|k| cl(k, power[k])).collect();
        let ab = join(&nodes[0], &nodes[1], [0, 1]);
        nodes.push(ab);
        let abc = join(&nodes[3], &nodes[2], [3, 2]);
        nodes.push(abc);
        Emitters {
            patches: vec![3, 5, 8],
            within: cdf.clone(),
            cdf,
            at: Vec::new(),
            power: acc,
            nodes,
            roots: vec![4],
            order: vec![0, 1, 2],
            position: vec![0, 1, 2],
            sight: None,
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

    /// A ceiling of `n` × `n` lamps 0.2 m across, 1 m apart, at z = 3, facing down.
    pub(super) fn ceiling(n: usize) -> Vec<[Vec3; 4]> {
        let mut quads = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let (x, y) = (i as f32, j as f32);
                // Wound clockwise seen from above: facing down.
                quads.push([
                    Vec3::new(x, y, 3.0),
                    Vec3::new(x, y + 0.2, 3.0),
                    Vec3::new(x + 0.2, y + 0.2, 3.0),
                    Vec3::new(x + 0.2, y, 3.0),
                ]);
            }
        }
        quads
    }

    /// A mesh of lamps (exitance 1, one patch each) on the quadrilaterals `quads`.
    pub(super) fn lamps(quads: &[[Vec3; 4]]) -> Mesh {
        use crate::scene::{Material, Polygon, Scene};
        let mut scene = Scene {
            materials: vec![Material {
                name: "lamp".into(),
                rho: [0.0; 3],
                ke: [1.0; 3],
                ..Material::default()
            }],
            ..Scene::default()
        };
        for q in quads {
            let base = scene.positions.len() as u32;
            scene.positions.extend_from_slice(q);
            scene.indices.extend(base..base + 4);
            scene.polygons.push(Polygon {
                first: base,
                len: 4,
                material: 0,
                back_material: None,
            });
        }
        let opts = crate::mesh::MeshOptions {
            patch_size: Some(1.0),
            uniform_patches: true,
            ..Default::default()
        };
        crate::mesh::build(&scene, &opts)
    }

    /// A ceiling of 20 × 20 small lamps facing down, more than a cut holds: a receiver on the
    /// floor draws from its cut of the tree, the probabilities `pick` reports are the ones
    /// `mass` gives, they add up to one, and the lamp straight above is drawn far more often
    /// than one across the room, which is still drawn (the defensive share).
    #[test]
    fn a_cut_of_many_lamps_draws_the_near_ones_one_by_one() {
        let mesh = lamps(&ceiling(20));
        assert_eq!(mesh.patches.len(), 400);
        let e = vec![Rgb::ONE; mesh.patches.len()];
        let em = Emitters::new(&mesh, &e);
        assert!(em.roots.len() == 1 && em.nodes.len() == 799);
        let under = |i: usize, j: usize| Receiver {
            centre: Vec3::new(i as f32 + 0.1, j as f32 + 0.1, 0.0),
            normal: Vec3::Z,
            radius: 0.1,
        };
        let d = em.draw_for(&under(5, 5)).expect("lit from above");
        let cut = d.local.as_ref().expect("a cut");
        assert!(cut.nodes.len() <= CLUSTERS && cut.nodes.len() > CLUSTERS / 2);
        let w = |k: usize| scalar(e[em.patches[k]]) * mesh.patches[em.patches[k]].area;
        let mass: Vec<f64> = (0..400).map(|k| em.mass(&d, k, w(k))).collect();
        let total: f64 = mass.iter().sum();
        assert!((total - 1.0).abs() < 1e-9, "{total} {}", em.power);
        let of = |i: usize, j: usize| {
            let c = Vec3::new(i as f32 + 0.1, j as f32 + 0.1, 3.0);
            (0..400)
                .find(|&k| mesh.patches[em.patches[k]].centre.distance(c) < 1e-3)
                .expect("a lamp there")
        };
        let (near, far) = (mass[of(5, 5)], mass[of(19, 19)]);
        assert!(near > 20.0 * far && far > 0.0, "{near} {far}");
        for k in 0..2000 {
            let (e, q, rest) = em.pick(&d, (k as f64 + 0.5) / 2000.0);
            assert!((q - mass[e]).abs() < 1e-9 * q.max(1e-9), "{q} {}", mass[e]);
            assert!((0.0..=1.0).contains(&rest));
        }
        // From above the lamps, nothing can be drawn.
        let above = Receiver {
            centre: Vec3::new(5.0, 5.0, 4.0),
            ..under(5, 5)
        };
        assert!(em.draw_for(&above).is_none());
    }

    /// The power heuristic: a light sample's and a hemisphere ray's weights for one
    /// direction add up to one, each its strategy's (n·p)² over the sum of both.
    #[test]
    fn the_weights_of_a_path_add_up_to_one() {
        let (mass, area) = (0.25, 0.5);
        let w = Emitters::weight(mass, area, (0.7, 0.4, 1.5), 8.0, 24.0);
        let p_l = mass / area * 1.5 * 1.5 / 0.4;
        let p_c = 0.7 / std::f64::consts::PI;
        let (a, b) = ((8.0 * p_l).powi(2), (24.0 * p_c).powi(2));
        assert!((w - a / (a + b)).abs() < 1e-12);
        let tiny = Emitters::weight(1.0, 1e-300, (0.7, 0.4, 1.5), 8.0, 24.0);
        assert_eq!(tiny, 1.0, "a tiny emitter's weight does not overflow");
        assert_eq!(Emitters::weight(mass, area, (0.0, 0.4, 1.5), 0.0, 1.0), 1.0);
    }
}
