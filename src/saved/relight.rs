//! `radiosity relight`: re-weights the lights of a solution saved with `--per-light` and
//! renders or exports it (the paper's Images 1a/1b, without solving again).

use super::export::{export_loaded, ExportJob};
use super::load_checked;
use super::render::{check_render_options, render_loaded, RenderJob};
use super::OutputReport;
use crate::export::solution::SavedSolution;
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
