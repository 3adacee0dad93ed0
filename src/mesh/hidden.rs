//! Hidden sides (docs/design.md §7): which sides of the surface patches no light can reach,
//! inside a closed solid. `intersect::hidden` finds them with probe rays; this is what it found
//! and the queries the solver, the final gather and the reports ask of it.

use super::Mesh;

/// Which sides of the mesh's surface patches are hidden. Indexed by patch; a back twin's entry
/// is its surface's back.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Hidden {
    /// The front of surface patch i is hidden.
    pub front: Vec<bool>,
    /// The back of surface patch i is hidden (the side a one-sided patch has no twin for).
    pub back: Vec<bool>,
}

impl Hidden {
    /// No side hidden (an empty test: a mesh without rays).
    pub fn none(n: usize) -> Hidden {
        Hidden {
            front: vec![false; n],
            back: vec![false; n],
        }
    }

    /// Whether patch `i`'s own side is hidden: a surface patch's front, a twin's back.
    pub fn side(&self, mesh: &Mesh, i: usize) -> bool {
        if i >= self.front.len() {
            return false;
        }
        if mesh.is_surface(i) {
            self.front[i]
        } else {
            self.back[mesh.surface_of(i)]
        }
    }

    /// The patches whose own side is hidden, and their area (m²).
    pub fn count(&self, mesh: &Mesh) -> (usize, f64) {
        (0..mesh.patches.len().min(self.front.len()))
            .filter(|&i| self.side(mesh, i))
            .fold((0, 0.0), |(n, a), i| (n + 1, a + mesh.patches[i].area))
    }

    /// Whether a ray that met the back of surface patch `j` has met a hidden side.
    #[inline]
    pub fn back_of(&self, j: usize) -> bool {
        self.back.get(j).copied().unwrap_or(false)
    }
}
