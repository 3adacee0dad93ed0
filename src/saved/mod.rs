//! `radiosity render` and `radiosity export`: read a saved solution
//! ([`crate::export::solution`]) and write one image or one mesh, without the OBJ and without
//! solving again. The format follows the extension of `--out` (docs/design.md §5).
//!
//! Given the scene too (`--scene`), the solution is checked against it first and refused when
//! it belongs to another scene or other mesh settings.

use crate::export::image::{self as image_out, ImageKind};
use crate::export::solution::{self, SavedSolution};
use crate::export::{glb, ply, write_atomic};
use crate::render::false_colour::{self, Scale};
use crate::render::{self, ViewSettings};
use crate::scene::LoadOptions;
use crate::scene::SceneSource;
use crate::Error;
use glam::Vec3;
use std::path::{Path, PathBuf};

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

/// Everything `radiosity render` does.
#[derive(Clone, Debug)]
pub struct RenderJob {
    pub solution: PathBuf,
    pub check: Option<SceneCheck>,
    /// `.png`, `.hdr` or `.exr`.
    pub out: PathBuf,
    pub view: ViewSettings,
    /// Irradiance in false colour with a legend (PNG only).
    pub false_colour: bool,
}

/// Everything `radiosity export` does.
#[derive(Clone, Debug)]
pub struct ExportJob {
    pub solution: PathBuf,
    pub check: Option<SceneCheck>,
    /// `.ply` or `.glb`.
    pub out: PathBuf,
    /// Exposure of the display colours (automatic when `None`).
    pub exposure: Option<f32>,
}

/// What a render or export wrote, for the one-line report and `--json`.
#[derive(Clone, Debug, serde::Serialize)]
pub struct OutputReport {
    pub solution: String,
    pub scene: String,
    pub out: String,
    pub format: String,
    pub patches: usize,
    pub vertices: usize,
    /// Exposure of the display colours, when the output has any.
    pub exposure: Option<f32>,
    /// The false-colour scale (W/m²), for `--false-colour`.
    pub scale: Option<Scale>,
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

fn check_render_options(job: &RenderJob) -> Result<ImageKind, Error> {
    let kind = ImageKind::from_path(&job.out).ok_or_else(|| {
        Error::Invalid(format!(
            "--out {}: the image format comes from the extension: .png, .hdr or .exr",
            job.out.display()
        ))
    })?;
    if job.false_colour && kind != ImageKind::Png {
        return Err(Error::Invalid(
            "--false-colour draws a display image: use --out FILE.png".into(),
        ));
    }
    job.view.check()?;
    Ok(kind)
}

/// Bounds of the mesh's vertices (the scene's bounds, as the solve's camera used).
fn bounds(sol: &SavedSolution) -> (Vec3, Vec3) {
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

/// `radiosity render`.
pub fn run_render(job: &RenderJob) -> Result<OutputReport, Error> {
    let kind = check_render_options(job)?;
    let sol = load_checked(&job.solution, job.check.as_ref())?;
    render_loaded(&sol, kind, job)
}

/// Renders a loaded (or relit) solution as `job` says.
fn render_loaded(
    sol: &SavedSolution,
    kind: ImageKind,
    job: &RenderJob,
) -> Result<OutputReport, Error> {
    let (lo, hi) = bounds(sol);
    let cam = job.view.camera_for(lo, hi);
    let mut exposure = None;
    let mut scale = None;
    if job.false_colour {
        let (img, s) = false_colour::render(&sol.mesh, &sol.irradiance(), &cam, &job.view.image);
        scale = Some(s);
        write_atomic(&job.out, |w| image_out::write_png(w, &img))?;
    } else {
        let lin = render::render_linear(&sol.mesh, &sol.vertex_b, &cam, &job.view.image);
        match kind {
            ImageKind::Png => {
                let (img, e) = render::tone_map(&lin, job.view.image.exposure);
                exposure = Some(e);
                write_atomic(&job.out, |w| image_out::write_png(w, &img))?;
            }
            ImageKind::Hdr => write_atomic(&job.out, |w| image_out::write_hdr(w, &lin))?,
            ImageKind::Exr => write_atomic(&job.out, |w| image_out::write_exr(w, &lin))?,
        }
    }
    Ok(OutputReport {
        solution: job.solution.display().to_string(),
        scene: sol.meta.scene.clone(),
        out: job.out.display().to_string(),
        format: format!("{kind:?}").to_lowercase(),
        patches: sol.mesh.patches.len(),
        vertices: sol.mesh.vertices.len(),
        exposure,
        scale,
    })
}

/// `radiosity export`.
pub fn run_export(job: &ExportJob) -> Result<OutputReport, Error> {
    let ext = job
        .out
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let format = match ext.as_deref() {
        Some(f @ ("ply" | "glb")) => f.to_string(),
        _ => {
            return Err(Error::Invalid(format!(
                "--out {}: the mesh format comes from the extension: .ply or .glb",
                job.out.display()
            )))
        }
    };
    crate::render::view::check_exposure(job.exposure)?;
    let sol = load_checked(&job.solution, job.check.as_ref())?;
    export_loaded(&sol, format, job)
}

/// Writes a loaded (or relit) solution as the mesh `job` asks for.
fn export_loaded(
    sol: &SavedSolution,
    format: String,
    job: &ExportJob,
) -> Result<OutputReport, Error> {
    let about = format!(
        "radiosity {} from {} ({}, seed {})",
        env!("CARGO_PKG_VERSION"),
        sol.meta.scene,
        sol.meta.method,
        sol.meta.seed
    );
    let mut exposure = 0.0;
    write_atomic(&job.out, |w| {
        exposure = if format == "ply" {
            ply::write(w, &sol.mesh, &sol.vertex_b, job.exposure, &about)?
        } else {
            glb::write(w, &sol.mesh, &sol.vertex_b, job.exposure, &about)?
        };
        Ok(())
    })?;
    Ok(OutputReport {
        solution: job.solution.display().to_string(),
        scene: sol.meta.scene.clone(),
        out: job.out.display().to_string(),
        format,
        patches: sol.mesh.patches.len(),
        vertices: sol.mesh.vertices.len(),
        exposure: Some(exposure),
        scale: None,
    })
}

/// Everything `radiosity relight` does: re-weights the lights of a solution saved with
/// `--per-light`, then renders (`.png`, `.hdr`, `.exr`) or exports (`.ply`, `.glb`) it.
#[derive(Clone, Debug)]
pub struct RelightJob {
    pub render: RenderJob,
    /// (light channel name, weight); lights not named keep weight 1.
    pub weights: Vec<(String, f64)>,
}

/// The solution with light c's channel scaled by its weight: B = Σ_c w_c·B_c, which is what
/// solving again with each light's emission scaled by w_c would give (radiosity is linear in
/// the emission), without solving again (Images 1a/1b).
pub fn relight(sol: &SavedSolution, weights: &[(String, f64)]) -> Result<SavedSolution, Error> {
    if sol.channels.is_empty() {
        return Err(Error::Invalid(format!(
            "{} has no per-light channels: solve with --per-light --save FILE.rad",
            sol.meta.scene
        )));
    }
    let mut w = vec![1.0; sol.channels.len()];
    for (name, weight) in weights {
        if !(weight.is_finite() && *weight >= 0.0) {
            return Err(Error::Invalid(format!(
                "--weight {name}={weight}: a weight must be a finite number ≥ 0"
            )));
        }
        let c = sol
            .channels
            .iter()
            .position(|c| &c.name == name)
            .ok_or_else(|| {
                Error::Invalid(format!(
                    "--weight {name}: no such light; the solution's lights are {}",
                    sol.channels
                        .iter()
                        .map(|c| c.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
            })?;
        w[c] = *weight;
    }
    let mut out = sol.clone();
    for (j, b) in out.b.iter_mut().enumerate() {
        *b = [0, 1, 2].map(|x| {
            sol.channels
                .iter()
                .zip(&w)
                .map(|(c, w)| w * c.b[j][x])
                .sum()
        });
    }
    out.vertex_b = out.mesh.vertex_values(&out.b);
    Ok(out)
}

/// `radiosity relight`: the output format from `--out`'s extension.
pub fn run_relight(job: &RelightJob) -> Result<OutputReport, Error> {
    let ext = job
        .render
        .out
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    if let Some(f @ ("ply" | "glb")) = ext.as_deref() {
        let export = ExportJob {
            solution: job.render.solution.clone(),
            check: job.render.check.clone(),
            out: job.render.out.clone(),
            exposure: job.render.view.image.exposure,
        };
        let sol = load_checked(&export.solution, export.check.as_ref())?;
        return export_loaded(&relight(&sol, &job.weights)?, f.to_string(), &export);
    }
    let kind = check_render_options(&job.render)?;
    let sol = load_checked(&job.render.solution, job.render.check.as_ref())?;
    render_loaded(&relight(&sol, &job.weights)?, kind, &job.render)
}
