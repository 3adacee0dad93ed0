//! The write stage (docs/design.md §1): the files a solve writes into its output folder, and
//! nothing else — `patches.csv` (docs/design.md §5), `elements.csv` (the adaptive elements,
//! [`crate::elements`]; the patches themselves with `--elements off`), `grid.csv` and
//! `grid.png` (with `--grid`), `trace.csv`, `render.png`, `summary.json` and, with `--save`,
//! the saved solution. Also the solution's warnings, and the checks a solve makes of its
//! output paths before any work.

use super::daylight::Measured;
use super::refine::Refined;
use super::stages::Solved;
use super::SolveJob;
use crate::elements::Elements;
use crate::export::solution::{self, SavedMaterial, SolutionMeta};
use crate::export::{self, patches, write_atomic};
use crate::intersect::Intersector;
use crate::model::Model;
use crate::report::{self, EnergyReport, Summary, Timings};
use crate::solve;
use crate::Error;
use std::path::PathBuf;
use std::time::Instant;

/// What the stages after the solve made, ready to be written.
pub struct Results {
    pub refined: Refined,
    pub measured: Option<Measured>,
    /// `render.png`.
    pub picture: image::RgbImage,
    /// The solution's warnings ([`warnings`]).
    pub warnings: Vec<String>,
}

/// Share of the emitted light lost on back faces above which a solve warns: a consistently
/// wound model loses none, so 1 % already means faces wound the wrong way.
pub const BACK_WARNING: f64 = 0.01;
/// Share of the emitted light escaping the model above which a solve warns, if the lights'
/// backs see the model (open models, such as a courtyard, lose light to the sky legitimately).
pub const ESCAPE_WARNING: f64 = 0.5;

/// Warnings about a solution a user should hear of.
///
/// `backs_meet`: of rays from the lights' backs, the share meeting a surface
/// ([`crate::solve::lights::backs_meeting_surfaces`]; asked only when most light escaped).
fn solution_warnings(energy: &EnergyReport, backs_meet: f64) -> Vec<String> {
    let mut w = Vec::new();
    // docs/design.md §7: a model with wrong winding never gives a silent black image.
    if energy.back_fraction > BACK_WARNING {
        w.push(format!(
            "{:.1} % of the emitted light met the back of one-sided faces and was lost there (faces wound clockwise: an inside-out room, or mixed winding): solve without --one-sided, or with --two-sided",
            100.0 * energy.back_fraction
        ));
    }
    if energy.escaped_fraction > ESCAPE_WARNING && backs_meet >= 0.5 {
        w.push(format!(
            "{:.1} % of the emitted light left the model without meeting a surface: if the lights face away from the rooms (faces wound clockwise), solve with --flip",
            100.0 * energy.escaped_fraction
        ));
    }
    w
}

/// The solution's warnings, logged: light lost on back faces, or escaping the model (then
/// rays from the lights' backs tell whether they face away from the rooms).
pub fn warnings(solved: &Solved, log: &mut impl FnMut(&str)) -> Vec<String> {
    let energy = EnergyReport::from(&solved.sol.stats.energy);
    let backs_meet = match solved.isect {
        Some((isect, _)) if energy.escaped_fraction > ESCAPE_WARNING => {
            let (m, materials) = (&solved.model.mesh, &solved.model.scene.materials);
            crate::solve::lights::backs_meeting_surfaces(m, materials, isect)
        }
        _ => 0.0,
    };
    let w = solution_warnings(&energy, backs_meet);
    for w in &w {
        log(&format!("warning: {w}"));
    }
    w
}

/// Write: the outputs of a solve into `job.out` (and `job.save`), each file recorded in
/// `written` as soon as it exists; returns the summary it wrote. `after` is when the solve
/// ended: the stages since count as the output's time.
pub fn write(
    job: &SolveJob,
    solved: &Solved,
    results: Results,
    timings: Timings,
    after: Instant,
    written: &mut Vec<PathBuf>,
) -> Result<Summary, Error> {
    let (model, sol) = (solved.model, &solved.sol);
    let (scene, m) = (&model.scene, &model.mesh);
    let elements = &results.refined.elements;
    let mut outputs = Vec::new();
    let mut wrote = |path: PathBuf| {
        outputs.push(path.display().to_string());
        written.push(path);
    };
    let sky_lux = solved.sky.as_ref().map(|s| {
        let (sky, sun) = s.horizontal_illuminance();
        sky + sun
    });
    let csv = job.out.join("patches.csv");
    write_atomic(&csv, |w| {
        patches::write(w, m, &scene.materials, &sol.b, sky_lux)
    })?;
    wrote(csv.clone());
    let el_csv = job.out.join("elements.csv");
    if elements.are_the_patches(m, &sol.b) {
        write_atomic(&el_csv, |w| {
            let mut table = std::io::BufReader::new(std::fs::File::open(&csv)?);
            patches::elements_of_patch_table(&mut table, w)
        })?;
    } else {
        write_atomic(&el_csv, |w| {
            patches::write_elements(
                w,
                &elements.mesh,
                &scene.materials,
                &elements.b,
                sky_lux,
                &elements.patch,
            )
        })?;
    }
    wrote(el_csv);
    if let Some(g) = &results.measured {
        let grid_csv = job.out.join("grid.csv");
        let (s, lux, df) = (&g.grid.sensors, &g.grid.lux, &g.grid.df);
        crate::grid::write_csv(&grid_csv, s, lux, df, &g.grid.zones).map_err(|source| {
            crate::export::WriteError {
                path: grid_csv.clone(),
                source,
            }
        })?;
        wrote(grid_csv);
        let plan = job.out.join("grid.png");
        write_png(&plan, &g.plan)?;
        wrote(plan);
    }
    let trace_csv = job.out.join("trace.csv");
    write_atomic(&trace_csv, |w| report::trace::write(w, &sol.stats.trace))?;
    wrote(trace_csv);
    let png = job.out.join("render.png");
    write_png(&png, &results.picture)?;
    wrote(png);
    if let Some(save) = &job.save {
        save_solution(save, job, model, sol, elements)?;
        wrote(save.clone());
    }

    let json = job.out.join("summary.json");
    outputs.push(json.display().to_string());
    let mut timings = timings;
    timings.output = after.elapsed().as_secs_f64();
    if let Some(g) = &results.measured {
        (timings.grid, timings.cpu.grid) = (g.seconds, g.cpu_seconds);
    }
    timings.total = solved.t0.elapsed().as_secs_f64();
    timings.cpu.total = report::process_cpu_seconds();
    timings.peak.output = report::peak_mib();
    let warnings = scene
        .warnings
        .iter()
        .cloned()
        .chain(results.warnings)
        .chain(
            results
                .measured
                .as_ref()
                .and_then(|g| g.grid.warning.clone()),
        )
        .collect();
    let mut summary = summary(job, solved, timings, warnings, outputs);
    summary.grid = results.measured.map(|g| g.grid.stats);
    summary.elements = results.refined.stats;
    summary.sky = job
        .settings
        .solve
        .sky
        .as_ref()
        .zip(solved.sky.as_ref())
        .map(|(spec, sky)| crate::report::sky::SkyReport::new(spec, sky));
    write_atomic(&json, |w| {
        serde_json::to_writer_pretty(&mut *w, &summary).map_err(std::io::Error::other)?;
        writeln!(w)
    })?;
    written.push(json);
    Ok(summary)
}

/// The summary of a finished solve: the scene, the settings (all of them, derived from
/// [`super::RunSettings`]; the older top-level fields stay for the scripts that read them),
/// the counters, the energy books, the final error and the trace.
fn summary(
    job: &SolveJob,
    solved: &Solved,
    timings: Timings,
    warnings: Vec<String>,
    outputs: Vec<String>,
) -> Summary {
    let (model, sol) = (solved.model, &solved.sol);
    let energy = EnergyReport::from(&sol.stats.energy);
    let (scene, m) = (&model.scene, &model.mesh);
    let s = &job.settings.solve;
    let last = sol.stats.trace.last().copied();
    Summary {
        version: env!("CARGO_PKG_VERSION"),
        scene: scene.name.clone(),
        polygons: scene.polygons.len(),
        patches: m.patches.len(),
        patch_size: m.patch_size,
        axial_fraction_area: report::axial_fractions(m).1,
        lights: report::lights(scene, m),
        luminaires: report::luminaires(scene),
        method: s.method.name(),
        intersector: solved
            .isect
            .map_or("none (no rays cast)", |(i, _)| i.name()),
        intersector_reason: solved.isect.map_or_else(
            || "the method casts no rays".to_string(),
            |(_, c)| c.reason.clone(),
        ),
        seed: s.seed,
        threads: rayon::current_num_threads(),
        tolerance: s.tolerance,
        energy_per_ray: sol.stats.energy_per_ray,
        stop_fraction: s.stop_fraction,
        stop_reason: sol.stats.stop_reason,
        error_target: sol.stats.error_target,
        shots: sol.stats.shots,
        rays: sol.stats.rays,
        waves: sol.stats.waves,
        hemicube_shots: sol.stats.hemicube_shots,
        hemicube_cells: sol.stats.hemicube_cells,
        hemicube_n: s.method.uses_uniform_cube().then_some(s.hemicube_n),
        switch: sol.stats.switch,
        final_gather: sol.stats.final_gather,
        hidden: {
            let (patches, area_m2) = m.hidden.count(m);
            report::HiddenReport { patches, area_m2 }
        },
        lit_backs: solved.lit_backs,
        elements: None,
        rays_per_second: sol.stats.rays as f64 / timings.solve.max(1e-9),
        cpu_seconds: timings.cpu,
        peak_mib: timings.peak,
        seconds: timings,
        energy,
        light_channels: sol.channels.iter().map(|c| c.name.clone()).collect(),
        error_estimate: last.map(|p| p.estimate).unwrap_or_default(),
        error: last.and_then(|p| p.error),
        max_unshot_over_mean: last
            .map_or(0.0, |p| p.max_unshot_b / p.mean_b.max(f64::MIN_POSITIVE)),
        warnings,
        outputs,
        settings: job.settings.to_json(),
        trace: sol.stats.trace.clone(),
        sky: None,
        grid: None,
    }
}

/// Writes a PNG atomically.
fn write_png(path: &std::path::Path, img: &image::RgbImage) -> Result<(), Error> {
    write_atomic(path, |w| {
        let mut buf = std::io::Cursor::new(Vec::new());
        img.write_to(&mut buf, image::ImageFormat::Png)
            .map_err(std::io::Error::other)?;
        w.write_all(buf.get_ref())
    })?;
    Ok(())
}

/// Makes the output folder (`--out`, and the folders above it that are missing), then checks
/// `--save` ([`check_save_path`]), so a solution saved into the folder being made
/// (`--out DIR --save DIR/s.rad`) is taken. On a refused `--save` the folders just made are
/// removed again. Returns the folders made (for [`export::remove_made_dirs`] on failure).
pub fn prepare_out(job: &SolveJob) -> Result<Vec<PathBuf>, Error> {
    let made = export::prepare_dir(&job.out)?;
    if let Some(save) = &job.save {
        if let Err(e) = check_save_path(save) {
            export::remove_made_dirs(&made);
            return Err(e);
        }
    }
    Ok(made)
}

/// Refuses a `--save` path that cannot be written, before any work is spent (after the
/// output folder is made: [`prepare_out`]).
pub fn check_save_path(path: &std::path::Path) -> Result<(), Error> {
    if path.is_dir() {
        return Err(Error::Invalid(format!(
            "--save {}: is a folder; give a file name such as solution.rad",
            path.display()
        )));
    }
    let parent = path.parent().filter(|p| !p.as_os_str().is_empty());
    if let Some(dir) = parent {
        if dir.is_file() {
            return Err(Error::Invalid(format!(
                "--save {}: {} is a file, not a folder",
                path.display(),
                dir.display()
            )));
        }
        if !dir.is_dir() {
            return Err(Error::Invalid(format!(
                "--save {}: the folder {} does not exist",
                path.display(),
                dir.display()
            )));
        }
    }
    Ok(())
}

/// Writes the saved solution of a finished solve (`--save`).
fn save_solution(
    path: &std::path::Path,
    job: &SolveJob,
    model: &Model,
    sol: &solve::Solution,
    elements: &Elements,
) -> Result<(), Error> {
    let (scene, m) = (&model.scene, &model.mesh);
    let meta = SolutionMeta {
        tool_version: env!("CARGO_PKG_VERSION").to_string(),
        scene: scene.name.clone(),
        scene_hash: solution::scene_hash(scene, m.patch_size, job.settings.mesh.two_sided),
        patch_size: m.patch_size,
        two_sided: job.settings.mesh.two_sided,
        method: job.settings.solve.method.name().to_string(),
        seed: job.settings.solve.seed,
        tolerance: job.settings.solve.tolerance,
        energy_per_ray: sol.stats.energy_per_ray,
        stop_fraction: job.settings.solve.stop_fraction,
        stop_reason: sol
            .stats
            .stop_reason
            .and_then(|r| serde_json::to_value(r).ok())
            .and_then(|v| v.as_str().map(str::to_string)),
        shots: sol.stats.shots,
        rays: sol.stats.rays,
        materials: scene
            .materials
            .iter()
            .map(|mat| SavedMaterial {
                name: mat.name.clone(),
                rho: mat.rho,
                ke: mat.ke,
                transmittance: mat.transmittance,
                transmittance_rgb: mat.transmittance_rgb,
            })
            .collect(),
        settings: job.settings.to_json(),
    };
    let vertex_b = m.vertex_values(&sol.b);
    write_atomic(path, |w| {
        solution::write(
            w,
            &meta,
            m,
            &sol.b,
            &sol.unshot,
            &vertex_b,
            &sol.channels,
            Some(elements),
        )
    })?;
    Ok(())
}
