//! Sides and back twins (docs/design.md §7): which patch receives light meeting a surface on
//! either side, the back twins the builder adds, and the pairing of twins a saved solution lost.

use super::subdivide::Builder;
use super::{Mesh, Patch, Side};
use glam::Vec3;
use std::collections::HashMap;

impl Mesh {
    /// The patch that receives light meeting surface patch `patch` on its front (`back` false)
    /// or its back: the patch itself, its back twin, or `None` for the back of a one-sided
    /// patch (that light is absorbed there).
    pub fn receiver(&self, patch: u32, back: bool) -> Option<u32> {
        match (back, self.patches[patch as usize].side) {
            (false, _) => Some(patch),
            (true, Side::Front { back }) => Some(back),
            (true, _) => None,
        }
    }

    /// The surface patch `i` is a side of: itself, or the front patch of a back twin.
    pub fn surface_of(&self, i: usize) -> usize {
        match self.patches[i].side {
            Side::Back { front } => front as usize,
            _ => i,
        }
    }

    /// The other side of a two-sided surface's patch `i` (its twin, or its front), if any.
    pub fn other_side(&self, i: usize) -> Option<usize> {
        match self.patches[i].side {
            Side::Front { back } => Some(back as usize),
            Side::Back { front } => Some(front as usize),
            Side::One => None,
        }
    }

    /// Gives every patch of the polygons `polygons` (sorted ids) a back twin of its front
    /// material, appended after every existing patch, so the surface patches keep their
    /// indices and the intersectors built over them stay valid: the back patches made where a
    /// model's winding lets light meet backs (`pipeline::stages::lit_backs`). Patches that are
    /// already sides of a two-sided surface are left alone. Returns the twins made. Their
    /// vertices are welded among themselves (within one facing and material), as a builder's.
    pub fn add_back_twins_for(&mut self, polygons: &[u32]) -> usize {
        let quantum = (self.patch_size * 1e-4).max(f32::MIN_POSITIVE);
        let mut weld: HashMap<([i64; 3], [i32; 3], u32), u32> = HashMap::new();
        let n = self.patches.len();
        let mut made = 0;
        for k in 0..n {
            let front = self.patches[k];
            if front.side != Side::One || polygons.binary_search(&front.polygon).is_err() {
                continue;
            }
            let ring: Vec<Vec3> = (self.patch_indices(k).iter().rev())
                .map(|&v| self.vertices[v as usize])
                .collect();
            let normal = -front.normal;
            let q = |x: f32| (x / quantum).round() as i64;
            let qn = |x: f32| (x * 1000.0).round() as i32;
            let ids: Vec<u32> = ring
                .iter()
                .map(|&p| {
                    let key = (
                        [q(p.x), q(p.y), q(p.z)],
                        [qn(normal.x), qn(normal.y), qn(normal.z)],
                        front.material,
                    );
                    let next = self.vertices.len() as u32;
                    let id = *weld.entry(key).or_insert(next);
                    if id == next {
                        self.vertices.push(p);
                    }
                    id
                })
                .collect();
            let twin = self.patches.len() as u32;
            let first = self.patch_vertices.len() as u32;
            self.patch_vertices.extend_from_slice(&ids);
            self.patches.push(Patch {
                first,
                normal,
                side: Side::Back { front: k as u32 },
                ..front
            });
            self.patches[k].side = Side::Front { back: twin };
            made += 1;
        }
        made
    }

    /// How many patches are back twins.
    pub fn back_twins(&self) -> usize {
        (0..self.patches.len())
            .filter(|&i| !self.is_surface(i))
            .count()
    }

    /// Pairs the back twins of a mesh that lost its sides (a saved solution keeps none,
    /// docs/design.md §7) again, so that rays cast into it meet each surface once and a back
    /// hit goes to the twin: a one-sided patch of the same polygon, centre and area as an
    /// earlier one, and the exactly opposite normal, is that one's twin (the builder copies
    /// them from the front; a twin always comes after its front). Returns the pairs made.
    pub fn pair_twins(&mut self) -> usize {
        type Key = (u32, [u32; 3], u64);
        let key = |p: &Patch| -> Key {
            (
                p.polygon,
                p.centre.to_array().map(f32::to_bits),
                p.area.to_bits(),
            )
        };
        let mut open: HashMap<Key, Vec<usize>> = HashMap::new();
        let mut pairs = 0;
        for i in 0..self.patches.len() {
            let p = self.patches[i];
            if p.side != Side::One {
                continue;
            }
            let k = key(&p);
            let list = open.entry(k).or_default();
            let front = list
                .iter()
                .position(|&j| self.patches[j].normal == -p.normal && p.normal != Vec3::ZERO);
            match front {
                Some(at) => {
                    let j = list.swap_remove(at);
                    self.patches[j].side = Side::Front { back: i as u32 };
                    self.patches[i].side = Side::Back { front: j as u32 };
                    pairs += 1;
                }
                None => list.push(i),
            }
        }
        pairs
    }
}

impl Builder {
    /// Gives each patch from `start` on a back twin of `material` (docs/design.md §7): the same
    /// polygon wound the other way, on vertices of its own (welded with the back's facing).
    pub(super) fn add_back_twins(&mut self, start: usize, material: u32) {
        for k in start..self.mesh.patches.len() {
            let front = self.mesh.patches[k];
            let ring: Vec<Vec3> = self
                .mesh
                .patch_indices(k)
                .iter()
                .rev()
                .map(|&v| self.mesh.vertices[v as usize])
                .collect();
            let ids: Vec<u32> = ring
                .iter()
                .map(|&p| self.vertex(p, -front.normal, material))
                .collect();
            let twin = self.mesh.patches.len() as u32;
            let first = self.mesh.patch_vertices.len() as u32;
            self.mesh.patch_vertices.extend_from_slice(&ids);
            self.mesh.patches.push(Patch {
                first,
                material,
                normal: -front.normal,
                side: Side::Back { front: k as u32 },
                ..front
            });
            self.mesh.patches[k].side = Side::Front { back: twin };
        }
    }
}
