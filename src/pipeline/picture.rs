//! The picture stage (docs/design.md §1): `render.png`'s image from the job's view, either the
//! elements' radiosities Gouraud-shaded (`--shading gouraud`) or a final gather at every pixel
//! (`--shading gather`, through the post-solve intersector, with the solve's sky and seed).

use super::refine::Refined;
use super::stages::Solved;
use super::SolveJob;
use crate::intersect::select::AnyIntersector;
use crate::mesh::Mesh;
use crate::render::default_view::ModelView;
use crate::render::{self, Camera, RenderOptions, Shading, ShadingSettings};
use crate::Error;

/// Picture: the tone-mapped `render.png` of the job's view.
pub fn picture(
    job: &SolveJob,
    solved: &Solved,
    isect: Option<&AnyIntersector>,
    refined: &Refined,
    log: &mut impl FnMut(&str),
) -> Result<image::RgbImage, Error> {
    let cam = camera(job, solved, isect, log);
    let elements = &refined.elements;
    let img = match job.shading.shading {
        Shading::Gouraud => {
            let lin =
                render::render_linear(&elements.mesh, &elements.vertex_b, &cam, &job.view.image);
            render::tone_map(&lin, job.view.image.exposure).0
        }
        Shading::Gather => {
            let isect = isect.ok_or_else(|| Error::Invalid("no intersector".into()))?;
            let (lin, stats) = gather_picture(job, solved, isect, &cam);
            log(&format!(
                "render.png: final gather, {:.0} rays per pixel, {:.2} s",
                stats.rays_per_pixel, stats.seconds
            ));
            render::tone_map(&lin, job.view.image.exposure).0
        }
    };
    Ok(img)
}

/// The camera of `render.png`: the job's, or the default view of the model
/// ([`render::default_view`]: fitted with the zenith up, or a building's plan), its rays
/// probing through `isect` or, for a method that cast none, an intersector built for them.
fn camera(
    job: &SolveJob,
    solved: &Solved,
    isect: Option<&AnyIntersector>,
    log: &mut impl FnMut(&str),
) -> Camera {
    let (lo, hi) = solved.model.scene.bounds();
    let zenith = job
        .settings
        .solve
        .sky
        .as_ref()
        .map_or(job.zenith, |s| s.zenith);
    let built = match isect {
        None if job.view.camera.is_default() => solved
            .model
            .intersector(job.settings.intersector)
            .ok()
            .map(|(i, _)| i),
        _ => None,
    };
    let probe = isect.or(built.as_ref()).map(|i| (&solved.model.mesh, i));
    let model = ModelView {
        lo,
        hi,
        zenith,
        probe,
    };
    let (cam, view) = job.view.camera_of(&model);
    if let Some(line) = view.and_then(|v| v.describe()) {
        log(&format!("render.png: {line}"));
    }
    cam
}

/// The final-gather picture of a solve (`--shading gather`) with the solve's sky and seed.
fn gather_picture(
    job: &SolveJob,
    solved: &Solved,
    isect: &AnyIntersector,
    cam: &Camera,
) -> (render::LinearImage, render::gather::GatherStats) {
    let gather = crate::light::LightAt::new(
        &solved.model.mesh,
        &solved.model.scene.materials,
        isect,
        &solved.sol.b,
        solved.sky.as_ref(),
        None,
    );
    let shading = ShadingSettings {
        seed: job.settings.solve.seed,
        ..job.shading
    };
    let rows = solved
        .progress
        .start_count("rendering", u64::from(job.view.image.height));
    render::render_gather(&gather, cam, &job.view.image, &shading, &rows)
}

/// Renders patch radiosities, Gouraud-interpolated at the welded vertices, tone-mapped.
pub fn render_solution(
    m: &Mesh,
    b: &[[f64; 3]],
    cam: &Camera,
    opts: &RenderOptions,
) -> image::RgbImage {
    let vertex = m.vertex_values(b);
    let lin = render::render_linear(m, &vertex, cam, opts);
    render::tone_map(&lin, opts.exposure).0
}
