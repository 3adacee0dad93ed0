//! The emitters a draw takes *whole*: those its cut holds as leaves of their own and draws
//! often. A gather that knows their unoccluded irradiance in closed form ([`crate::light::exact`])
//! needs its light samples of them only for their visibility.

use super::{Draw, Emitters};
use crate::light::Rgb;
use crate::mesh::Mesh;
use glam::DVec3;
use std::rc::Rc;

/// The least probability of being drawn for an emitter to be taken whole.
pub const WHOLE_MASS: f64 = 1.0 / 64.0;
/// At most this many emitters are taken whole per surface (each costs its closed form at
/// every point).
pub const WHOLE_MOST: usize = 32;

/// The emitters a surface takes whole and the probability its draw gives them together.
#[derive(Clone, Debug, Default)]
pub(crate) struct WholeSet {
    /// Indices into the emitters' `patches`, ascending.
    pub ids: Vec<u32>,
    /// Σ of their probabilities of being drawn (what the draw's other emitters leave).
    pub mass: f64,
    /// The same emitters by the face they were cut from: what their closed form sums over.
    pub shapes: Rc<Vec<Shape>>,
}

/// Whole emitters cut from one face (one polygon, facing one way, one exitance): their
/// outline — the edges of theirs no other of them shares — and their corners.
#[derive(Debug)]
pub(crate) struct Shape {
    /// The emitters (indices into `patches`), and the cumulative sum of their areas.
    pub members: Vec<u32>,
    pub areas: Vec<f64>,
    /// The outline's edges, wound as the patches are.
    pub outline: Vec<[DVec3; 2]>,
    /// Every member's corners, and where each member's corners begin.
    pub corners: Vec<DVec3>,
    pub first: Vec<usize>,
    /// The emitting side's normal, and the exitance every member shares.
    pub normal: DVec3,
    pub e: Rgb,
}

impl Shape {
    /// The faces of the emitters `ids` (ascending) of `mesh`, `emitters` the model's.
    fn of(emitters: &Emitters, mesh: &Mesh, ids: &[u32]) -> Vec<Shape> {
        let key = |e: u32| {
            let em = &emitters.at[e as usize];
            let p = &mesh.patches[emitters.patches[e as usize]];
            let bits = |v: [f64; 3]| v.map(f64::to_bits);
            (
                p.polygon,
                p.normal.to_array().map(f32::to_bits),
                bits(em.e.to_array()),
            )
        };
        let mut groups: Vec<(_, Vec<u32>)> = Vec::new();
        for &e in ids {
            let k = key(e);
            match groups.iter_mut().find(|(g, _)| *g == k) {
                Some((_, members)) => members.push(e),
                None => groups.push((k, vec![e])),
            }
        }
        (groups.into_iter())
            .map(|(_, members)| {
                let patch = |e: u32| emitters.patches[e as usize];
                let mut edges: Vec<(u32, u32)> = Vec::new();
                let (mut corners, mut first, mut areas) = (Vec::new(), Vec::new(), Vec::new());
                let mut area = 0.0;
                for &e in &members {
                    let ids = mesh.patch_indices(patch(e));
                    first.push(corners.len());
                    corners.extend(ids.iter().map(|&v| mesh.vertices[v as usize].as_dvec3()));
                    edges.extend((0..ids.len()).map(|k| (ids[k], ids[(k + 1) % ids.len()])));
                    area += mesh.patches[patch(e)].area;
                    areas.push(area);
                }
                let outline = (edges.iter())
                    .filter(|&&(a, b)| !edges.contains(&(b, a)))
                    .map(|&(a, b)| [a, b].map(|v| mesh.vertices[v as usize].as_dvec3()))
                    .collect();
                let em = &emitters.at[members[0] as usize];
                Shape {
                    members,
                    areas,
                    outline,
                    corners,
                    first,
                    normal: em.normal.as_dvec3(),
                    e: em.e,
                }
            })
            .collect()
    }
}

impl WholeSet {
    /// Whether emitter `e` (an index into the emitters) is taken whole.
    pub fn has(&self, e: usize) -> bool {
        self.ids.binary_search(&(e as u32)).is_ok()
    }

    /// Whether the draw can pick an emitter not taken whole.
    pub fn leaves_some(&self) -> bool {
        self.mass < 1.0 - 1e-9
    }
}

impl Emitters {
    /// The emitters that `draw` holds as leaves of its cut with probability at least
    /// `min_mass` each, at most `most` of them (the most probable; ties to the lower index),
    /// and the faces they were cut from in `mesh`. None for a draw by power.
    pub fn whole(&self, mesh: &Mesh, draw: &Draw, min_mass: f64, most: usize) -> WholeSet {
        let Some(cut) = &draw.local else {
            return WholeSet::default();
        };
        let mut leaves: Vec<(f64, u32)> = (cut.nodes.iter().enumerate())
            .filter_map(|(c, &n)| {
                let node = &self.nodes[n as usize];
                if node.end - node.start != 1 {
                    return None;
                }
                let lo = if c == 0 { 0.0 } else { cut.cdf[c - 1] };
                let q = cut.cdf[c] - lo;
                (q >= min_mass).then_some((q, self.order[node.start]))
            })
            .collect();
        leaves.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        leaves.truncate(most);
        let mass = leaves.iter().map(|l| l.0).sum();
        let mut ids: Vec<u32> = leaves.into_iter().map(|(_, e)| e).collect();
        ids.sort_unstable();
        let shapes = Rc::new(Shape::of(self, mesh, &ids));
        WholeSet { ids, mass, shapes }
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{ceiling, lamps};
    use super::super::{Emitters, Receiver};
    use crate::light::Rgb;
    use glam::Vec3;

    #[test]
    fn a_room_takes_its_near_lamps_whole_and_not_the_far_ones() {
        let quads = ceiling(16);
        let mesh = lamps(&quads);
        let e = vec![Rgb::splat(10.0); mesh.patches.len()];
        let em = Emitters::new(&mesh, &e);
        let below = quads[0].iter().fold(Vec3::ZERO, |s, &v| s + v) / 4.0 - Vec3::Z * 1.0;
        let r = Receiver {
            centre: below,
            normal: Vec3::Z,
            radius: 0.1,
        };
        let draw = em.draw_for(&r).expect("the lamps light it");
        let whole = em.whole(&mesh, &draw, 0.05, 32).ids;
        assert!(!whole.is_empty() && whole.len() < em.patches.len());
        // The lamp straight above is among them, and every one taken is drawn often.
        let above = em.index_of(0).expect("patch 0 emits") as u32;
        assert!(whole.contains(&above), "{whole:?}");
        for &w in &whole {
            let m = em.mass(
                &draw,
                w as usize,
                10.0 * mesh.patches[em.patches[w as usize]].area,
            );
            assert!(m >= 0.05, "{m}");
        }
        assert!(em.whole(&mesh, &draw, 0.05, 1).ids.len() == 1);
        assert!(em
            .whole(&mesh, &super::super::Draw::by_power(), 0.0, 32)
            .ids
            .is_empty());
    }
}
