//! `radiosity relight`: re-weights the lights of a solution saved with `--per-light` and
//! renders or exports it (the paper's Images 1a/1b, without solving again).

use super::export::{export_loaded, ExportJob};
use super::load_checked;
use super::render::{check_render_options, render_loaded, RenderJob};
use super::OutputReport;
use crate::export::solution::SavedSolution;
use crate::progress::Progress;
use crate::solve::final_gather::Relit;
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
/// the emission), without solving again (Images 1a/1b).
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
    // The elements' gathered values are the saved lights': a relit solution shows its patches.
    out.elements = None;
    Ok(out)
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
        let sol = load_checked(&export.solution, export.check.as_ref())?;
        return export_loaded(&relight(&sol, &job.weights)?, f.to_string(), &export);
    }
    let kind = check_render_options(&job.render)?;
    let sol = load_checked(&job.render.solution, job.render.check.as_ref())?;
    let relit = relit_lights(&sol, &job.weights)?;
    render_loaded(
        &relight(&sol, &job.weights)?,
        kind,
        &job.render,
        Some(relit),
        progress,
    )
}
