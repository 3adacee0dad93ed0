//! `radiosity render`: a saved solution to PNG (tone-mapped radiosity, or irradiance in false
//! colour), Radiance HDR or OpenEXR (radiance, W/sr/m²: [`crate::export::image`]), shaded by a
//! final gather per pixel ([`crate::render::gather`]) or as the Gouraud preview.
//!
//! The gather casts rays into the solution's mesh, so it builds the intersector a solve would
//! (`auto`), after pairing the back twins the file does not keep ([`crate::mesh::Mesh::pair_twins`]);
//! the sky of a daylit solve is rebuilt from the settings the file keeps.

use super::{bounds, load_checked, OutputReport, SceneCheck};
use crate::export::image::{self as image_out, ImageKind};
use crate::export::solution::SavedSolution;
use crate::export::write_atomic;
use crate::intersect::select::{self, IntersectorKind};
use crate::light::{LightAt, Relit};
use crate::progress::Progress;
use crate::render::default_view::ModelView;
use crate::render::false_colour;
use crate::render::gather::{render_gather, GatherStats};
use crate::render::{self, Camera, LinearImage, Shading, ShadingSettings, ViewSettings};
use crate::sky::{Compass, Sky, SkySpec, DEFAULT_ZENITH};
use crate::Error;
use glam::Vec3;
use std::path::PathBuf;

/// Everything `radiosity render` does.
#[derive(Clone, Debug)]
pub struct RenderJob {
    pub solution: PathBuf,
    pub check: Option<SceneCheck>,
    /// `.png`, `.hdr` or `.exr` (the last two in radiance, B/π).
    pub out: PathBuf,
    pub view: ViewSettings,
    /// Irradiance in false colour with a legend (PNG only; drawn from the patches, whatever
    /// the shading).
    pub false_colour: bool,
    /// Final gather or Gouraud (`--shading`, `--pixel-rays`, `--seed`).
    pub shading: ShadingSettings,
    /// The model's up for the default view (`--zenith`); left out, the zenith of the sky the
    /// solution was solved under ([`saved_zenith`]), else +y.
    pub zenith: Option<Vec3>,
}

/// The image format from `--out`, after checking the view and that false colour goes to PNG.
pub(crate) fn check_render_options(job: &RenderJob) -> Result<ImageKind, Error> {
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
    job.shading.check()?;
    if let Some(z) = job.zenith {
        Compass::new(z, Compass::default_north(z))?;
    }
    Ok(kind)
}

/// `radiosity render`.
pub fn run_render(job: &RenderJob) -> Result<OutputReport, Error> {
    run_render_with(job, &Progress::hidden())
}

/// [`run_render`] with a progress bar while the gather runs.
pub fn run_render_with(job: &RenderJob, progress: &Progress) -> Result<OutputReport, Error> {
    let kind = check_render_options(job)?;
    let sol = load_checked(&job.solution, job.check.as_ref())?;
    render_loaded(&sol, kind, job, None, progress)
}

/// The sky a saved solution was solved under, rebuilt from the settings it keeps
/// (`settings.solve.sky`, docs/design.md §9); `Err` says why it cannot be (a file from a
/// version whose sky settings this one does not read).
pub fn saved_sky(sol: &SavedSolution) -> Result<Option<Sky>, String> {
    let spec = match sol.meta.settings.get("solve").and_then(|s| s.get("sky")) {
        None | Some(serde_json::Value::Null) => return Ok(None),
        Some(v) => serde_json::from_value::<SkySpec>(v.clone()).map_err(|e| e.to_string())?,
    };
    Sky::new(&spec).map(Some).map_err(|e| e.to_string())
}

/// The zenith of the sky a saved solution was solved under (`settings.solve.sky.zenith`), the
/// one orientation the file keeps; `None` for a solve without a sky (or a file whose sky
/// settings this version does not read).
pub fn saved_zenith(sol: &SavedSolution) -> Option<Vec3> {
    let sky = sol.meta.settings.get("solve")?.get("sky")?;
    serde_json::from_value::<SkySpec>(sky.clone())
        .ok()
        .map(|s| s.zenith)
}

/// The camera of a saved solution's picture: the job's, or the default view of the model
/// ([`crate::render::default_view`]), with what a user should hear of the view taken.
fn camera(sol: &SavedSolution, job: &RenderJob) -> (Camera, Option<String>) {
    let (lo, hi) = bounds(sol);
    let zenith = job
        .zenith
        .or_else(|| saved_zenith(sol))
        .unwrap_or(DEFAULT_ZENITH);
    let mesh = job.view.camera.is_default().then(|| {
        let mut m = sol.mesh.clone();
        m.pair_twins();
        m
    });
    let built = mesh
        .as_ref()
        .and_then(|m| select::select(m, IntersectorKind::Auto).ok());
    let model = ModelView {
        lo,
        hi,
        zenith,
        probe: mesh.as_ref().zip(built.as_ref().map(|(i, _)| i)),
    };
    let (cam, view) = job.view.camera_of(&model);
    (cam, view.and_then(|v| v.describe()))
}

/// [`saved_sky`], or none with a warning that says what `what` (a picture, the elements) then
/// leaves out.
pub(crate) fn saved_sky_or_warn(
    sol: &SavedSolution,
    what: &str,
    warnings: &mut Vec<String>,
) -> Option<Sky> {
    saved_sky(sol).unwrap_or_else(|e| {
        warnings.push(format!(
            "the solution's sky could not be rebuilt ({e}): {what} shows no sky or sun light arriving directly (the solution's own light, which includes the sky's, is still gathered)"
        ));
        None
    })
}

/// The final-gather picture of a loaded (or relit) solution, and what it cost; the warnings a
/// user should hear of (a sky that could not be rebuilt).
pub(crate) fn gather_image(
    sol: &SavedSolution,
    cam: &Camera,
    job: &RenderJob,
    relit: Option<Relit>,
    progress: &Progress,
    warnings: &mut Vec<String>,
) -> Result<(LinearImage, GatherStats), Error> {
    let mut mesh = sol.mesh.clone();
    mesh.pair_twins();
    let (isect, _) = select::select(&mesh, IntersectorKind::Auto)?;
    let materials: Vec<_> = sol.meta.materials.iter().map(|m| m.material()).collect();
    let sky = saved_sky_or_warn(sol, "the gathered picture", warnings);
    let gather = LightAt::new(&mesh, &materials, &isect, &sol.b, sky.as_ref(), relit);
    let rows = progress.start_count("rendering", u64::from(job.view.image.height));
    let out = render_gather(&gather, cam, &job.view.image, &job.shading, &rows);
    progress.finish();
    Ok(out)
}

/// Renders a loaded (or relit: `relit` says its lights) solution as `job` says.
pub(crate) fn render_loaded(
    sol: &SavedSolution,
    kind: ImageKind,
    job: &RenderJob,
    relit: Option<Relit>,
    progress: &Progress,
) -> Result<OutputReport, Error> {
    let (cam, view) = camera(sol, job);
    let mut exposure = None;
    let mut scale = None;
    let mut shading = None;
    let mut gathered = None;
    let mut elements = None;
    let mut warnings = Vec::new();
    if job.false_colour {
        let (img, s) = false_colour::render(&sol.mesh, &sol.irradiance(), &cam, &job.view.image);
        scale = Some(s);
        write_atomic(&job.out, |w| image_out::write_png(w, &img))?;
    } else {
        let lin = match job.shading.shading {
            Shading::Gouraud => {
                elements = sol.elements.as_ref().map(|e| e.mesh.patches.len());
                let (mesh, vertex_b) = sol.display();
                render::render_linear(mesh, vertex_b, &cam, &job.view.image)
            }
            Shading::Gather => {
                let (lin, stats) = gather_image(sol, &cam, job, relit, progress, &mut warnings)?;
                gathered = Some(stats);
                lin
            }
        };
        shading = Some(job.shading.shading.name().to_string());
        match kind {
            ImageKind::Png => {
                let (img, e) = render::tone_map(&lin, job.view.image.exposure);
                exposure = Some(e);
                write_atomic(&job.out, |w| image_out::write_png(w, &img))?;
            }
            ImageKind::Hdr => write_atomic(&job.out, |w| image_out::write_hdr(w, &lin, &cam))?,
            ImageKind::Exr => write_atomic(&job.out, |w| image_out::write_exr(w, &lin, &cam))?,
        }
    }
    Ok(OutputReport {
        solution: job.solution.display().to_string(),
        scene: sol.meta.scene.clone(),
        out: job.out.display().to_string(),
        format: format!("{kind:?}").to_lowercase(),
        patches: sol.mesh.patches.len(),
        elements,
        vertices: sol.mesh.vertices.len(),
        exposure,
        scale,
        shading,
        gather: gathered,
        view,
        warnings,
    })
}
