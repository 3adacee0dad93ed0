//! `radiosity render`: a saved solution to PNG (tone-mapped radiosity, or irradiance in false
//! colour), Radiance HDR or OpenEXR (radiance, W/sr/m²: [`crate::export::image`]).

use super::{bounds, load_checked, OutputReport, SceneCheck};
use crate::export::image::{self as image_out, ImageKind};
use crate::export::solution::SavedSolution;
use crate::export::write_atomic;
use crate::render::false_colour;
use crate::render::{self, ViewSettings};
use crate::Error;
use std::path::PathBuf;

/// Everything `radiosity render` does.
#[derive(Clone, Debug)]
pub struct RenderJob {
    pub solution: PathBuf,
    pub check: Option<SceneCheck>,
    /// `.png`, `.hdr` or `.exr` (the last two in radiance, B/π).
    pub out: PathBuf,
    pub view: ViewSettings,
    /// Irradiance in false colour with a legend (PNG only).
    pub false_colour: bool,
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
    Ok(kind)
}

/// `radiosity render`.
pub fn run_render(job: &RenderJob) -> Result<OutputReport, Error> {
    let kind = check_render_options(job)?;
    let sol = load_checked(&job.solution, job.check.as_ref())?;
    render_loaded(&sol, kind, job)
}

/// Renders a loaded (or relit) solution as `job` says.
pub(crate) fn render_loaded(
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
        vertices: sol.mesh.vertices.len(),
        exposure,
        scale,
    })
}
