//! Hidden sides (docs/design.md §7): which sides of the surface patches no light can reach,
//! inside a closed solid. `intersect::hidden` finds them with probe rays; this is what it found
//! and the queries the solver, the final gather and the reports ask of it.
//!
//! The back of a one-sided patch (a side with no patch of its own) matters only when a ray
//! meets it, which in a consistently wound model is rare; so it is probed the first time it is
//! asked ([`Hidden::back_of`]), not up front: on a generated building those probes were 16 of
//! every 17 probe rays. The answer is the same whenever it is found (the probe's rays depend
//! on the patch and the seed alone), so the solution does not depend on which thread asks first.

use super::Mesh;
use std::sync::atomic::{AtomicU8, Ordering};

/// A back not probed yet ...
const UNKNOWN: u8 = 0;
/// ... one some probe ray leaves ...
const OPEN: u8 = 1;
/// ... and one every probe ray meets the back of a one-sided face from.
const HIDDEN: u8 = 2;

/// Which sides of the mesh's surface patches are hidden. Indexed by patch; a back twin's entry
/// is its surface's back.
#[derive(Debug, Default)]
pub struct Hidden {
    /// The front of surface patch i is hidden.
    pub front: Vec<bool>,
    /// The back of surface patch i: [`OPEN`] or [`HIDDEN`] once probed, [`UNKNOWN`] until then
    /// (probed up front where the back is a twin's side, else when first asked).
    back: Vec<AtomicU8>,
    /// What a later probe of a back needs: the surface patches that let light through
    /// (glazing), the seed, and the least offset of a ray's origin.
    pub open: Vec<bool>,
    pub seed: u64,
    pub eps_floor: f32,
}

impl Clone for Hidden {
    fn clone(&self) -> Hidden {
        Hidden {
            front: self.front.clone(),
            back: (self.back.iter())
                .map(|s| AtomicU8::new(s.load(Ordering::Relaxed)))
                .collect(),
            open: self.open.clone(),
            seed: self.seed,
            eps_floor: self.eps_floor,
        }
    }
}

impl PartialEq for Hidden {
    fn eq(&self, o: &Hidden) -> bool {
        let backs =
            |h: &Hidden| -> Vec<u8> { h.back.iter().map(|s| s.load(Ordering::Relaxed)).collect() };
        self.front == o.front
            && backs(self) == backs(o)
            && self.open == o.open
            && self.seed == o.seed
            && self.eps_floor == o.eps_floor
    }
}

impl Hidden {
    /// No side hidden (an empty test: a mesh without rays).
    pub fn none(n: usize) -> Hidden {
        Hidden {
            front: vec![false; n],
            back: (0..n).map(|_| AtomicU8::new(OPEN)).collect(),
            ..Hidden::default()
        }
    }

    /// What the probes found: the fronts, the backs probed (`None`: to be probed when asked),
    /// and what a later probe needs (the glazing, the seed, the least ray offset).
    pub fn new(
        front: Vec<bool>,
        back: Vec<Option<bool>>,
        open: Vec<bool>,
        (seed, eps_floor): (u64, f32),
    ) -> Hidden {
        let state = |b: Option<bool>| match b {
            None => UNKNOWN,
            Some(false) => OPEN,
            Some(true) => HIDDEN,
        };
        Hidden {
            front,
            back: back.into_iter().map(|b| AtomicU8::new(state(b))).collect(),
            open,
            seed,
            eps_floor,
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
            self.back[mesh.surface_of(i)].load(Ordering::Relaxed) == HIDDEN
        }
    }

    /// The patches whose own side is hidden, and their area (m²).
    pub fn count(&self, mesh: &Mesh) -> (usize, f64) {
        (0..mesh.patches.len().min(self.front.len()))
            .filter(|&i| self.side(mesh, i))
            .fold((0, 0.0), |(n, a), i| (n + 1, a + mesh.patches[i].area))
    }

    /// Whether a ray that met the back of surface patch `j` has met a hidden side; `probe`
    /// finds it the first time it is asked (`intersect::hidden::back_enclosed`).
    #[inline]
    pub fn back_of(&self, j: usize, probe: impl FnOnce() -> bool) -> bool {
        let Some(s) = self.back.get(j) else {
            return false;
        };
        match s.load(Ordering::Relaxed) {
            OPEN => false,
            HIDDEN => true,
            _ => {
                let hidden = probe();
                s.store(if hidden { HIDDEN } else { OPEN }, Ordering::Relaxed);
                hidden
            }
        }
    }
}
