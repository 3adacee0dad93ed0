//! `radiosity relight`: re-weights the lights of a solution saved with `--per-light` and
//! renders or exports it (the paper's Images 1a/1b, without solving again).
//!
//! The patch radiosities are linear in the lights, so they are re-weighted exactly
//! ([`relight`]). The adaptive elements are not kept per light: where they are refined and
//! what their vertices gather depend on the light, so an output that shows them (a Gouraud
//! picture, a PLY or glTF mesh) refines them again on the relit patches, gathering under the
//! relit lights, with the element settings and seed the solve used ([`relight_with_elements`];
//! docs/design.md §11). A final-gather picture reads the patches alone and skips this.

use super::export::{export_loaded, ExportJob};
use super::load_checked;
use super::render::{check_render_options, render_loaded, saved_sky_or_warn, RenderJob};
use super::OutputReport;
use crate::elements::{self, ElementSettings, ElementStats};
use crate::export::solution::SavedSolution;
use crate::intersect::select::{self, IntersectorKind};
use crate::light::{LightAt, Relit};
use crate::progress::Progress;
use crate::render::Shading;
use crate::solve::lights::{SKY_CHANNEL, SUN_CHANNEL};
use crate::solve::scalar;
use crate::Error;

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
/// the emission), without solving again (Images 1a/1b). The patches only: the elements are
/// dropped (their gathered values are the saved lights'); [`relight_with_elements`] refines
/// them again.
pub fn relight(sol: &SavedSolution, weights: &[(String, f64)]) -> Result<SavedSolution, Error> {
    let w = channel_weights(sol, weights)?;
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
    // A luminaire's direct light is gathered from the luminaire itself: it is scaled by its
    // group's weight, so the pictures and elements gathered on `out` see it relit too.
    for l in &mut out.mesh.luminaires {
        if let Some(c) = sol.channels.iter().position(|c| c.name == l.group) {
            l.scale *= w[c];
        }
    }
    // The elements' gathered values are the saved lights' ([`relight_with_elements`]).
    out.elements = None;
    Ok(out)
}

/// [`relight`], with the adaptive elements refined again on the relit patches when the
/// solution has any ([`element_settings`]): each corner gathered under the relit lights
/// ([`relit_lights`]), with the solve's element settings and seed, so a relit Gouraud picture
/// or mesh shows what a solve of the re-weighted lights would (Cohen 1986 Sec. 3). Returns
/// what the refinement did (`None`: the solution has no elements, its patches are shown) and
/// pushes what a user should hear of to `warnings`.
pub fn relight_with_elements(
    sol: &SavedSolution,
    weights: &[(String, f64)],
    progress: &Progress,
    warnings: &mut Vec<String>,
) -> Result<(SavedSolution, Option<ElementStats>), Error> {
    let mut out = relight(sol, weights)?;
    let Some(settings) = element_settings(sol) else {
        return Ok((out, None));
    };
    let lights = relit_lights(sol, weights)?;
    progress.phase("refining elements");
    let stats = refine_relit(&mut out, lights, &settings, warnings)?;
    progress.finish();
    if stats.capped {
        warnings.push(format!(
            "the relit elements reached their cap of {} per patch (--element-max); the largest differences were refined first",
            settings.max_factor
        ));
    }
    Ok((out, Some(stats)))
}

/// How the elements of `sol` were refined, to refine them again after relighting: the
/// settings its solve recorded (`settings.elements` in `META`) when they refined this mesh;
/// [`ElementSettings::default`] for a file that did not record them but has elements; `None`
/// when the solution has no elements (`--elements off`, a mesh `--elements auto` skipped, a
/// format-1 file), whose patches stay what is shown.
pub fn element_settings(sol: &SavedSolution) -> Option<ElementSettings> {
    let el = sol.elements.as_ref()?;
    let recorded = sol
        .meta
        .settings
        .get("elements")
        .and_then(|v| serde_json::from_value::<ElementSettings>(v.clone()).ok())
        .filter(|s| s.check().is_ok());
    match recorded {
        Some(s) => s.applies_to(sol.mesh.patches.len()).then_some(s),
        // Elements that are the patches themselves (`--elements off`) are no elements.
        None => (el.mesh.patch_vertices != sol.mesh.patch_vertices
            || el.mesh.vertices != sol.mesh.vertices)
            .then(|| ElementSettings {
                auto_limit: None,
                ..ElementSettings::default()
            }),
    }
}

/// Refines the elements of the relit solution `out` (its patches already re-weighted) under
/// its relit `lights`, as [`crate::pipeline`]'s solve does after solving: the same gather
/// (direct light sampled at each corner, the relit patches as the cache of the indirect
/// light), the same settings and seed (the solve's, `META`'s `seed`).
pub fn refine_relit(
    out: &mut SavedSolution,
    lights: Relit,
    settings: &ElementSettings,
    warnings: &mut Vec<String>,
) -> Result<ElementStats, Error> {
    let mut mesh = out.mesh.clone();
    mesh.pair_twins();
    let (isect, _) = select::select(&mesh, IntersectorKind::Auto)?;
    let materials: Vec<_> = out.meta.materials.iter().map(|m| m.material()).collect();
    let sky = saved_sky_or_warn(out, "the relit elements", warnings);
    let gather = LightAt::new(
        &mesh,
        &materials,
        &isect,
        &out.b,
        sky.as_ref(),
        Some(lights),
    );
    let (el, stats) = elements::refine(&mesh, &gather, &out.b, settings, out.meta.seed);
    out.elements = Some(el);
    Ok(stats)
}

/// The lights of the relit solution, for a final-gather picture: each emitting patch's E times
/// the weight of its light — the channel named after its material (`lamp`, or with
/// `--light-groups connected` one of `lamp#1`, `lamp#2`, …: the one holding its own emission,
/// the largest of them there) — and the weights of `(sky)` and `(sun)`.
pub fn relit_lights(sol: &SavedSolution, weights: &[(String, f64)]) -> Result<Relit, Error> {
    let w = channel_weights(sol, weights)?;
    let named = |name: &str| {
        sol.channels
            .iter()
            .position(|c| c.name == name)
            .map_or(1.0, |c| w[c])
    };
    let emission = (0..sol.mesh.patches.len())
        .map(|i| {
            let e = sol.emission(i);
            if scalar(&e) <= 0.0 {
                return e;
            }
            let mat = &sol.meta.materials[sol.mesh.patches[i].material as usize].name;
            let group = format!("{mat}#");
            let own = (0..sol.channels.len())
                .filter(|&c| {
                    let n = &sol.channels[c].name;
                    n == mat || n.starts_with(&group)
                })
                .max_by(|&a, &b| {
                    scalar(&sol.channels[a].b[i]).total_cmp(&scalar(&sol.channels[b].b[i]))
                });
            let k = own.map_or(1.0, |c| w[c]);
            e.map(|v| v * k)
        })
        .collect();
    Ok(Relit {
        emission,
        sky: named(SKY_CHANNEL),
        sun: named(SUN_CHANNEL),
    })
}

/// The weight of each channel of `sol`: as given by name, 1 for the lights not named.
fn channel_weights(sol: &SavedSolution, weights: &[(String, f64)]) -> Result<Vec<f64>, Error> {
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
    Ok(w)
}

/// `radiosity relight`: the output format from `--out`'s extension.
pub fn run_relight(job: &RelightJob) -> Result<OutputReport, Error> {
    run_relight_with(job, &Progress::hidden())
}

/// [`run_relight`] with a progress bar while a final gather runs.
pub fn run_relight_with(job: &RelightJob, progress: &Progress) -> Result<OutputReport, Error> {
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
        crate::render::view::check_exposure(export.exposure)?;
        let sol = load_checked(&export.solution, export.check.as_ref())?;
        let mut warnings = Vec::new();
        let (relit, _) = relight_with_elements(&sol, &job.weights, progress, &mut warnings)?;
        let mut report = export_loaded(&relit, f.to_string(), &export)?;
        report.warnings.splice(0..0, warnings);
        return Ok(report);
    }
    let kind = check_render_options(&job.render)?;
    let sol = load_checked(&job.render.solution, job.render.check.as_ref())?;
    let lights = relit_lights(&sol, &job.weights)?;
    // Only the Gouraud picture draws the elements (false colour and the final gather draw
    // the patches).
    let mut warnings = Vec::new();
    let relit = if !job.render.false_colour && job.render.shading.shading == Shading::Gouraud {
        relight_with_elements(&sol, &job.weights, progress, &mut warnings)?.0
    } else {
        relight(&sol, &job.weights)?
    };
    let mut report = render_loaded(&relit, kind, &job.render, Some(lights), progress)?;
    report.warnings.splice(0..0, warnings);
    Ok(report)
}
