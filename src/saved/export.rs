//! `radiosity export`: a saved solution as a mesh with per-vertex radiosity, PLY or binary
//! glTF.

use super::{load_checked, OutputReport, SceneCheck};
use crate::export::solution::SavedSolution;
use crate::export::{glb, ply, write_atomic};
use crate::Error;
use std::path::PathBuf;

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
pub(crate) fn export_loaded(
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
    // The elements when the solution has them (the patches otherwise).
    let (mesh, vertex_b) = sol.display();
    let mut exposure = 0.0;
    write_atomic(&job.out, |w| {
        exposure = if format == "ply" {
            ply::write(w, mesh, vertex_b, job.exposure, &about)?
        } else {
            glb::write(w, mesh, vertex_b, job.exposure, &about)?
        };
        Ok(())
    })?;
    Ok(OutputReport {
        solution: job.solution.display().to_string(),
        scene: sol.meta.scene.clone(),
        out: job.out.display().to_string(),
        format,
        patches: sol.mesh.patches.len(),
        elements: sol.elements.as_ref().map(|e| e.mesh.patches.len()),
        vertices: mesh.vertices.len(),
        exposure: Some(exposure),
        scale: None,
        shading: None,
        gather: None,
        view: None,
        warnings: Vec::new(),
    })
}
