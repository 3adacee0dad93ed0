//! The commands that act on a saved solution ([`crate::export::solution`]), without the OBJ and
//! without solving again: [`render`](mod@render) (`radiosity render`: an image), [`export`](mod@export) (`radiosity
//! export`: a mesh) and [`relight`](mod@relight) (`radiosity relight`: the lights re-weighted, then either).
//! The format follows the extension of `--out` (docs/design.md §5).
//!
//! Given the scene too (`--scene`), the solution is checked against it first and refused when
//! it belongs to another scene or other mesh settings.

pub mod export;
pub mod relight;
pub mod render;

pub use export::{run_export, ExportJob};
pub use relight::{relight, run_relight, run_relight_with, RelightJob};
pub use render::{run_render, run_render_with, RenderJob};

use crate::export::solution::{self, SavedSolution};
use crate::render::false_colour::Scale;
use crate::scene::{LoadOptions, SceneSource};
use crate::Error;
use glam::Vec3;
use std::path::Path;

/// A scene to check a saved solution against.
#[derive(Clone, Debug)]
pub struct SceneCheck {
    pub source: SceneSource,
    pub load: LoadOptions,
    /// Mesh settings to check too; left out, the solution's own are taken, so only the scene
    /// itself is compared.
    pub patch_size: Option<f32>,
    pub two_sided: Option<bool>,
}

/// What a render or export wrote, for the one-line report and `--json`.
#[derive(Clone, Debug, serde::Serialize)]
pub struct OutputReport {
    pub solution: String,
    pub scene: String,
    pub out: String,
    pub format: String,
    pub patches: usize,
    /// The adaptive elements drawn (a Gouraud picture, a mesh), when the solution has them;
    /// none when the patches are (or the output draws no mesh).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub elements: Option<usize>,
    pub vertices: usize,
    /// Exposure of the display colours, when the output has any.
    pub exposure: Option<f32>,
    /// The false-colour scale (W/m²), for `--false-colour`.
    pub scale: Option<Scale>,
    /// How an image was shaded (`gather`, `gouraud`); none for a mesh or false colour.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shading: Option<String>,
    /// What a final-gather picture cost.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gather: Option<crate::render::gather::GatherStats>,
    /// The default view taken when it is not the fitted one (a building's plan: why, and where
    /// it is cut); printed as `note: …`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub view: Option<String>,
    /// What a user should hear of (printed as `warning: …`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
}

/// Loads a solution and, when asked, checks it belongs to the given scene.
pub fn load_checked(path: &Path, check: Option<&SceneCheck>) -> Result<SavedSolution, Error> {
    let sol = SavedSolution::load(path)?;
    if let Some(c) = check {
        let scene = c.source.load(&c.load)?;
        let two_sided = c.two_sided.unwrap_or(sol.meta.two_sided);
        let patch_size = c.patch_size.unwrap_or(sol.meta.patch_size);
        let hash = solution::scene_hash(&scene, patch_size, two_sided);
        sol.check_scene(path, &scene.name, hash)?;
    }
    Ok(sol)
}

/// Bounds of the mesh's vertices (the scene's bounds, as the solve's camera used).
pub(crate) fn bounds(sol: &SavedSolution) -> (Vec3, Vec3) {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for v in &sol.mesh.vertices {
        lo = lo.min(*v);
        hi = hi.max(*v);
    }
    if sol.mesh.vertices.is_empty() {
        (Vec3::ZERO, Vec3::ZERO)
    } else {
        (lo, hi)
    }
}
