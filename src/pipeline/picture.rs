//! The picture stage (docs/design.md §1): `render.png`'s image from the job's view, either the
//! elements' radiosities Gouraud-shaded (`--shading gouraud`) or a final gather at every pixel
//! (`--shading gather`, through the post-solve intersector, with the solve's sky and seed).

use super::refine::Refined;
use super::stages::Solved;
use super::SolveJob;
use crate::intersect::select::AnyIntersector;
use crate::mesh::Mesh;
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
    let (lo, hi) = solved.model.scene.bounds();
    let cam = job.view.camera_for(lo, hi);
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
