//! Ray casting against the patches: the closest hit along a ray.
//!
//! [`Intersector`] is the seam between the solver and the geometry. The solver is generic over
//! it (STYLE.md: match the configured kind once, then run generic code — no `dyn` per ray).
//! [`embree::EmbreeScene`] casts through Intel Embree 4; [`brute::BruteForce`] tests every patch
//! and serves as the test oracle; [`plane_merge::PlaneMerge`] is the paper's three-way merge
//! over axis-aligned planes (Sec. 2) and [`hybrid::Hybrid`] adds Embree for the skew patches.
//! [`select::AnyIntersector`] is the enum a solve is built with (`--intersector`).

pub mod brute;
pub mod embree;
pub mod hidden;
pub mod hybrid;
pub mod plane_merge;
pub mod select;

use glam::Vec3;

/// A ray segment: points `org + t·dir` with `tnear ≤ t ≤ tfar`.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    pub org: Vec3,
    pub dir: Vec3,
    pub tnear: f32,
    pub tfar: f32,
}

/// The closest patch a ray meets, where, and from which side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub patch: u32,
    pub t: f32,
    /// The ray met the patch's back face (the side its normal points away from).
    pub back: bool,
}

/// Closest-hit ray queries over a fixed set of patches. `Sync` so rayon threads share one.
pub trait Intersector: Sync {
    /// The closest patch along `ray` within [tnear, tfar], front or back face alike.
    fn intersect(&self, ray: &Ray) -> Option<Hit>;

    /// A short name for reports ("embree", "brute", …).
    fn name(&self) -> &'static str;
}
