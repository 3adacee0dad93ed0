//! Which intersector a solve casts through, chosen once per scene (docs/design.md §4; Sec. 2).
//!
//! [`AnyIntersector`] is the enum at the edge: the pipeline matches the configured
//! [`IntersectorKind`] once, builds only the structures the scene needs, and hands the solver
//! (generic over `I: Intersector`) an enum whose `intersect` is one predictable `match` — no
//! `dyn` in the per-ray loop (STYLE.md).
//!
//! **The `auto` rule** comes from `radiosity bench intersect` (README, "Intersectors"), run on
//! two cores over the scenes of `scenes/` and generated buildings of 1 k to 1 M patches: see
//! [`auto_rule`] for the rule and the figures behind it.

use super::brute::BruteForce;
use super::embree::EmbreeError;
use super::embree::EmbreeScene;
use super::hybrid::Hybrid;
use super::plane_merge::PlaneMerge;
use super::{Hit, Intersector, Ray};
use crate::mesh::{Mesh, PatchClass};

/// Why an intersector could not be built.
#[derive(Debug, thiserror::Error)]
pub enum SelectError {
    /// `--intersector merge` on a scene with skew patches (the user's to fix).
    #[error("--intersector merge needs a scene whose patches are all axis-aligned, but {skew} of {patches} are skew: use hybrid, embree or auto")]
    NotAxial { skew: usize, patches: usize },
    #[error(transparent)]
    Embree(#[from] EmbreeError),
}

/// `--intersector`: which intersector to cast through.
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    serde::Serialize,
    serde::Deserialize,
    clap::ValueEnum,
)]
#[serde(rename_all = "lowercase")]
pub enum IntersectorKind {
    /// Chosen per scene by [`auto_rule`].
    #[default]
    #[value(help = crate::settings::NO_HELP)]
    Auto,
    /// Embree over the whole scene.
    #[value(help = crate::settings::NO_HELP)]
    Embree,
    /// The plane merge alone: only for scenes whose patches are all axis-aligned.
    #[value(help = crate::settings::NO_HELP)]
    Merge,
    /// The plane merge for axial patches, Embree for skew ones (Sec. 2).
    #[value(help = crate::settings::NO_HELP)]
    Hybrid,
}

impl IntersectorKind {
    pub fn name(self) -> &'static str {
        match self {
            IntersectorKind::Auto => "auto",
            IntersectorKind::Embree => "embree",
            IntersectorKind::Merge => "merge",
            IntersectorKind::Hybrid => "hybrid",
        }
    }
}

/// One of the intersectors, dispatched by `match` (static: every arm is a concrete type).
pub enum AnyIntersector {
    Embree(EmbreeScene),
    Merge(PlaneMerge),
    Hybrid(Hybrid),
    /// The test oracle (crosscheck, bench); never chosen for a solve.
    Brute(BruteForce),
}

impl AnyIntersector {
    /// Builds the intersector of `kind` (not `Auto`) over `mesh`: only what it needs.
    pub fn build(mesh: &Mesh, kind: IntersectorKind) -> Result<AnyIntersector, SelectError> {
        Ok(match kind {
            IntersectorKind::Embree => AnyIntersector::Embree(EmbreeScene::build(mesh, |_| true)?),
            IntersectorKind::Merge => {
                let skew = SceneShape::of(mesh).skew;
                if skew > 0 {
                    return Err(SelectError::NotAxial {
                        skew,
                        patches: mesh.patches.len(),
                    });
                }
                AnyIntersector::Merge(PlaneMerge::build(mesh))
            }
            IntersectorKind::Hybrid => AnyIntersector::Hybrid(Hybrid::build(mesh)?),
            IntersectorKind::Auto => return select(mesh, kind).map(|(i, _)| i),
        })
    }

    /// Whether an Embree scene was built (whole scene, or the hybrid's skew part).
    pub fn has_embree(&self) -> bool {
        match self {
            AnyIntersector::Embree(_) => true,
            AnyIntersector::Hybrid(h) => h.embree().is_some(),
            AnyIntersector::Merge(_) | AnyIntersector::Brute(_) => false,
        }
    }

    /// Whether plane lists were built (the merge, or the hybrid's axial part).
    pub fn has_planes(&self) -> bool {
        match self {
            AnyIntersector::Merge(_) => true,
            AnyIntersector::Hybrid(h) => h.merge().is_some(),
            AnyIntersector::Embree(_) | AnyIntersector::Brute(_) => false,
        }
    }
}

impl Intersector for AnyIntersector {
    #[inline]
    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        match self {
            AnyIntersector::Embree(x) => x.intersect(ray),
            AnyIntersector::Merge(x) => x.intersect(ray),
            AnyIntersector::Hybrid(x) => x.intersect(ray),
            AnyIntersector::Brute(x) => x.intersect(ray),
        }
    }

    fn name(&self) -> &'static str {
        match self {
            AnyIntersector::Embree(x) => x.name(),
            AnyIntersector::Merge(x) => x.name(),
            AnyIntersector::Hybrid(x) => x.name(),
            AnyIntersector::Brute(x) => x.name(),
        }
    }
}

/// What the choice looks at, computed from the mesh without building anything.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct SceneShape {
    pub patches: usize,
    pub axial: usize,
    pub skew: usize,
}

impl SceneShape {
    pub fn of(mesh: &Mesh) -> SceneShape {
        let skew = mesh
            .patches
            .iter()
            .filter(|p| p.class == PatchClass::Skew)
            .count();
        SceneShape {
            patches: mesh.patches.len(),
            axial: mesh.patches.len() - skew,
            skew,
        }
    }
}

/// The choice made, and why (for the summary and `info`).
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Selection {
    /// What was asked (`--intersector`).
    pub asked: IntersectorKind,
    /// What runs: embree, merge or hybrid.
    pub chosen: IntersectorKind,
    pub reason: String,
}

/// The `auto` rule, from `radiosity bench intersect` on this machine (README, "Intersectors"):
/// **Embree over the whole scene, always.** Over the scenes of `scenes/` (232 to 5,267 patches)
/// and generated buildings of 1 k to 1 M patches, on the solver's rays, the hybrid ran at 0.3 to
/// 0.95× Embree's rate and the merge alone (hallway, the one axial-only scene) at 0.5–0.9×; no
/// scene or size had either ahead by more than the run-to-run noise. The rule the earlier rough
/// measurements suggested ("merge/hybrid on axial scenes of ≤ 500 k patches with few planes
/// per axis") came from rooms without furniture, whose rays cross a handful of planes; the
/// furnished scenes here make the merge walk many more. A measured probe per scene was not
/// taken: it would make the choice, and through edge cases the result, depend on the
/// machine's load, and the solve reproducible from its seed is worth more than a choice the
/// benchmark says would almost never differ.
pub fn auto_rule(shape: &SceneShape) -> (IntersectorKind, String) {
    let what = if shape.skew == 0 {
        "all patches axis-aligned".to_string()
    } else {
        format!("{} of {} patches skew", shape.skew, shape.patches)
    };
    (
        IntersectorKind::Embree,
        format!(
            "{what}; Embree over the whole scene was measured fastest on every scene and \
             building size (`radiosity bench intersect`)"
        ),
    )
}

/// Resolves `kind` for `mesh` (applying [`auto_rule`] for `Auto`) and builds it.
pub fn select(
    mesh: &Mesh,
    kind: IntersectorKind,
) -> Result<(AnyIntersector, Selection), SelectError> {
    let (chosen, reason) = match kind {
        IntersectorKind::Auto => auto_rule(&SceneShape::of(mesh)),
        k => (k, "forced by --intersector".to_string()),
    };
    let isect = AnyIntersector::build(mesh, chosen)?;
    Ok((
        isect,
        Selection {
            asked: kind,
            chosen,
            reason,
        },
    ))
}
