//! The paper's combined intersector (Sec. 2): the three-way plane merge for axis-aligned
//! patches, something else for the skew ones, each bounding the other's search.
//!
//! The paper keeps the skew polygons in a BSP tree and walks it front to back "until the
//! previously found intersection point is passed": the axial hit bounds the skew search. Here
//! Embree over the skew patches alone plays the BSP tree's part, and the bound is its `tfar`.
//!
//! **Why the merge first.** In architecture most patches (and most of the area rays hit) are
//! axial, and the merge is cheap when the hit is near. Once it has a hit at t, Embree only has
//! to look at the few skew triangles in front of t: a short `tfar` prunes its BVH traversal
//! early, and over a scene with few skew polygons the BVH is small anyway. The other order
//! would always pay a full unbounded Embree query first — a miss through the whole BVH for
//! most rays — to bound a merge that is cheap regardless.
//!
//! What remains is Embree's fixed cost per call (~60 ns here, about a whole query on a small
//! scene). Skipping the call when the bounded segment misses a few boxes around the skew
//! patches was tried (8 boxes, slab tests): it was slower on the Cornell box, `blocks` and
//! `office` than letting Embree's own BVH reject the ray.
//!
//! Only what the scene has is built: no Embree scene (and no Embree device) without skew
//! patches, no plane lists without axial ones.

use super::embree::{EmbreeError, EmbreeScene};
use super::plane_merge::PlaneMerge;
use super::{Hit, Intersector, Ray};
use crate::mesh::{Mesh, PatchClass};

/// The plane merge over the axial patches and Embree over the skew ones.
pub struct Hybrid {
    merge: Option<PlaneMerge>,
    embree: Option<EmbreeScene>,
}

impl Hybrid {
    /// Builds the parts the mesh needs: the merge if it has axial patches, Embree if skew ones.
    pub fn build(mesh: &Mesh) -> Result<Hybrid, EmbreeError> {
        let skew = |i: usize| mesh.patches[i].class == PatchClass::Skew;
        let surfaces = || (0..mesh.patches.len()).filter(|&i| mesh.is_surface(i));
        let n_skew = surfaces().filter(|&i| skew(i)).count();
        let n_axial = surfaces().count() - n_skew;
        let merge = (n_axial > 0)
            .then(|| PlaneMerge::build(mesh))
            .filter(|m| !m.is_empty());
        let embree = if n_skew > 0 {
            Some(EmbreeScene::build(mesh, skew)?)
        } else {
            None
        };
        Ok(Hybrid { merge, embree })
    }

    /// The plane merge, if the mesh has axial patches.
    pub fn merge(&self) -> Option<&PlaneMerge> {
        self.merge.as_ref()
    }

    /// The Embree scene over the skew patches, if the mesh has any.
    pub fn embree(&self) -> Option<&EmbreeScene> {
        self.embree.as_ref()
    }
}

impl Intersector for Hybrid {
    /// Sec. 2: the axial hit first, then the skew search bounded by it; the closer wins.
    #[inline]
    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let axial = match &self.merge {
            Some(m) => m.intersect(ray),
            None => None,
        };
        let Some(e) = &self.embree else {
            return axial;
        };
        let mut bounded = *ray;
        if let Some(h) = axial {
            bounded.tfar = h.t;
        }
        match (e.intersect(&bounded), axial) {
            (Some(s), Some(a)) if s.t >= a.t => Some(a),
            (Some(s), _) => Some(s),
            (None, a) => a,
        }
    }

    fn name(&self) -> &'static str {
        "hybrid"
    }
}
