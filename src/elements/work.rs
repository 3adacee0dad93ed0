//! The state the refinement keeps while it runs: where each gathered value is kept ([`At`]),
//! the values gathered so far ([`Values`]) and each patch's elements ([`PatchWork`]). Types
//! only, shared by the refinement loop ([`super::refine`]) and the indirect light's nodes
//! ([`super::indirect`]).

use super::geometry::{Elem, Root};
use std::collections::HashMap;

/// Where a point's value is kept ([`super::refine`]'s notes, "Shared points"): its position,
/// facing and material, as the mesh welds its vertices.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(super) struct At(pub [i64; 3], pub [i32; 3], pub u32);

/// The values gathered so far, and the rays they cost.
#[derive(Default)]
pub(super) struct Values {
    pub map: HashMap<At, [f64; 3]>,
    /// [`super::CornerLight::Split`]: the indirect light at the patches' corners.
    pub indirect: HashMap<At, [f64; 3]>,
    pub rays: u64,
}

/// One patch's elements while they are refined.
pub(super) struct PatchWork {
    pub roots: Vec<Root>,
    /// Elements still to decide on, and the ones kept.
    pub active: Vec<Elem>,
    pub done: Vec<Elem>,
    /// Per root, the scalar indirect light the contrast is taken against
    /// ([`super::CornerLight::Direct`]; from the root's first test).
    pub indirect: Vec<f64>,
    /// The kept elements' corner values, corner after corner in the order of `done` (filled
    /// once the refinement ends: [`super::refine::finish`]).
    pub corner_b: Vec<[f64; 3]>,
    /// [`super::CornerLight::Split`]: per root, the indirect light at its quadratic's nodes
    /// ([`super::indirect`]).
    pub ind_nodes: Vec<Vec<[f64; 3]>>,
}
