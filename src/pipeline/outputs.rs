//! The files a solve writes into its output folder: `patches.csv` (docs/design.md §5),
//! `elements.csv` (the adaptive elements, [`crate::elements`]; the patches themselves with
//! `--elements off`), `trace.csv`, `render.png` (drawn from the elements), `summary.json` and,
//! with `--save`, the saved solution.

use super::SolveJob;
use crate::elements::{self, Elements};
use crate::export::solution::{self, SavedMaterial, SolutionMeta};
use crate::export::{patches, write_atomic};
use crate::intersect::select::{AnyIntersector, Selection};
use crate::intersect::Intersector;
use crate::mesh::Mesh;
use crate::model::Model;
use crate::render::{self, Camera, RenderOptions, Shading, ShadingSettings};
use crate::report::{self, EnergyReport, Summary, Timings};
use crate::solve::{self, Solution};
use crate::Error;
use std::path::PathBuf;
use std::time::Instant;

/// A finished solve, ready to be written.
pub struct Run<'a> {
    pub model: &'a Model,
    pub isect: Option<&'a (AnyIntersector, Selection)>,
    pub sol: &'a Solution,
    pub timings: Timings,
    /// When the run started (for the total time).
    pub t0: Instant,
    /// The bars (the gathered picture has one).
    pub progress: &'a crate::progress::Progress,
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
            "{:.1} % of the emitted light met the back of one-sided faces and was lost there (faces wound clockwise: an inside-out room, or mixed winding): solve with --two-sided",
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

/// Writes the outputs of `run` into `job.out` (and `job.save`), each file recorded in
/// `written` as soon as it exists, and returns the summary it wrote.
pub fn write(
    job: &SolveJob,
    run: &Run,
    log: &mut impl FnMut(&str),
    written: &mut Vec<PathBuf>,
) -> Result<Summary, Error> {
    let (model, sol) = (run.model, run.sol);
    let (scene, m) = (&model.scene, &model.mesh);
    let t = Instant::now();
    let mut outputs = Vec::new();
    let mut wrote = |path: PathBuf| {
        outputs.push(path.display().to_string());
        written.push(path);
    };
    let csv = job.out.join("patches.csv");
    let sky = job
        .settings
        .solve
        .sky
        .as_ref()
        .and_then(|s| crate::sky::Sky::new(s).ok());
    let sky_lux = sky.as_ref().map(|s| {
        let (sky, sun) = s.horizontal_illuminance();
        sky + sun
    });
    write_atomic(&csv, |w| {
        patches::write(w, m, &scene.materials, &sol.b, sky_lux)
    })?;
    wrote(csv);
    // The elements and the gathered picture cast rays: through the solve's intersector, or
    // one built for them (the methods that cast none).
    let built;
    let refine = job.settings.elements.applies_to(m.patches.len());
    if job.settings.elements.enabled && !refine {
        log(&format!(
            "elements: skipped for {} patches (--elements auto refines up to {}; --elements on to refine anyway)",
            m.patches.len(),
            elements::AUTO_MAX_PATCHES
        ));
    }
    let needs_rays = refine || job.shading.shading == Shading::Gather;
    let isect = match run.isect {
        Some((i, _)) => Some(i),
        None if needs_rays => {
            built = model.intersector(job.settings.intersector)?;
            Some(&built.0)
        }
        None => None,
    };
    // The elements keep to what is left of --max-time (counted from the run's start); a solve
    // Ctrl-C stopped, or one with no time left, writes what it has at once: its patches.
    let stop = elements::Stop {
        flag: job.interrupt.as_deref(),
        deadline: job
            .settings
            .solve
            .max_time
            .map(|t| run.t0 + std::time::Duration::from_secs_f64(t.max(0.0))),
    };
    let (elements, element_stats) = match isect {
        Some(isect) if refine && !stop.interrupted() && !stop.out_of_time() => {
            run.progress.phase("refining elements");
            let gather = crate::solve::final_gather::PointGather::new(
                m,
                &scene.materials,
                isect,
                &sol.b,
                sky.as_ref(),
                None,
            );
            let (el, st) = elements::refine_until(
                m,
                &gather,
                &sol.b,
                &job.settings.elements,
                job.settings.solve.seed,
                stop,
            );
            log(&format!(
                "elements: {} from {} patches (threshold {}, min size {:.4} m), {} rays, {:.2} s",
                st.count, st.patches, st.threshold, st.min_size, st.rays, st.seconds
            ));
            if st.interrupted {
                log("interrupted: the elements refined so far are kept");
            } else if st.out_of_time {
                log("--max-time reached: the elements refined so far are kept");
            }
            if st.capped {
                log(&format!(
                    "warning: the elements reached their cap of {} per patch (--element-max); the largest differences were refined first",
                    job.settings.elements.max_factor
                ));
            }
            (el, Some(st))
        }
        _ => (Elements::of_patches(m, &sol.b), None),
    };
    let el_csv = job.out.join("elements.csv");
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
    wrote(el_csv);
    let (mut grid_seconds, mut grid_cpu) = (0.0, 0.0);
    let grid = match &job.grid {
        Some(spec) => {
            let (tg, cg) = (Instant::now(), report::process_cpu_seconds());
            let g = measure_grid(job, run, spec, sky.as_ref())?;
            grid_seconds = tg.elapsed().as_secs_f64();
            grid_cpu = report::process_cpu_seconds() - cg;
            let grid_csv = job.out.join("grid.csv");
            crate::grid::write_csv(&grid_csv, &g.sensors, &g.lux, &g.df).map_err(|source| {
                crate::export::WriteError {
                    path: grid_csv.clone(),
                    source,
                }
            })?;
            wrote(grid_csv);
            let plan = job.out.join("grid.png");
            let img = crate::grid::plan_image(
                &g.sensors,
                &g.lux,
                &frame_of(job),
                spec.spacing_hint(),
                super::daylight::PLAN_WIDTH,
            );
            write_png(&plan, &img)?;
            wrote(plan);
            log(&format!(
                "grid: {} sensors, mean {:.0} lux, min {:.0} lux, uniformity {:.2}, mean daylight factor {:.2} %",
                g.stats.points, g.stats.mean_lux, g.stats.min_lux, g.stats.uniformity, g.stats.mean_df
            ));
            Some(g.stats)
        }
        None => None,
    };
    let trace_csv = job.out.join("trace.csv");
    write_atomic(&trace_csv, |w| report::trace::write(w, &sol.stats.trace))?;
    wrote(trace_csv);

    let png = job.out.join("render.png");
    let (lo, hi) = scene.bounds();
    let cam = job.view.camera_for(lo, hi);
    let img = match job.shading.shading {
        Shading::Gouraud => {
            let lin =
                render::render_linear(&elements.mesh, &elements.vertex_b, &cam, &job.view.image);
            render::tone_map(&lin, job.view.image.exposure).0
        }
        Shading::Gather => {
            let isect = isect.ok_or_else(|| Error::Invalid("no intersector".into()))?;
            let (lin, stats) = gather_picture(job, run, isect, sky.as_ref(), &cam)?;
            log(&format!(
                "render.png: final gather, {:.0} rays per pixel, {:.2} s",
                stats.rays_per_pixel, stats.seconds
            ));
            render::tone_map(&lin, job.view.image.exposure).0
        }
    };
    write_png(&png, &img)?;
    wrote(png);
    if let Some(save) = &job.save {
        save_solution(save, job, model, sol, &elements)?;
        wrote(save.clone());
    }

    let energy = EnergyReport::from(&sol.stats.energy);
    let backs_meet = match run.isect {
        Some((isect, _)) if energy.escaped_fraction > ESCAPE_WARNING => {
            crate::solve::lights::backs_meeting_surfaces(m, &scene.materials, isect)
        }
        _ => 0.0,
    };
    for w in solution_warnings(&energy, backs_meet) {
        log(&format!("warning: {w}"));
    }
    let warnings: Vec<String> = scene
        .warnings
        .iter()
        .cloned()
        .chain(solution_warnings(&energy, backs_meet))
        .collect();
    let json = job.out.join("summary.json");
    outputs.push(json.display().to_string());
    let mut timings = run.timings.clone();
    timings.output = t.elapsed().as_secs_f64();
    timings.grid = grid_seconds;
    timings.total = run.t0.elapsed().as_secs_f64();
    timings.cpu.grid = grid_cpu;
    timings.cpu.total = report::process_cpu_seconds();
    let mut summary = summary(job, run, timings, energy, warnings, outputs);
    summary.grid = grid;
    summary.elements = element_stats;
    summary.sky = job
        .settings
        .solve
        .sky
        .as_ref()
        .zip(sky.as_ref())
        .map(|(spec, sky)| super::daylight::SkyReport::new(spec, sky));
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
    run: &Run,
    timings: Timings,
    energy: EnergyReport,
    warnings: Vec<String>,
    outputs: Vec<String>,
) -> Summary {
    let (model, sol) = (run.model, run.sol);
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
        method: s.method.name(),
        intersector: run.isect.map_or("none (no rays cast)", |(i, _)| i.name()),
        intersector_reason: run.isect.map_or_else(
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
        elements: None,
        rays_per_second: sol.stats.rays as f64 / timings.solve.max(1e-9),
        cpu_seconds: timings.cpu,
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

/// The model's orientation: the sky's zenith and north, else the defaults (Y up, north −Z).
fn frame_of(job: &SolveJob) -> crate::sky::Compass {
    // The sky's own frame when there is one (the same flags), else the job's (checked).
    let (z, n) = job
        .settings
        .solve
        .sky
        .as_ref()
        .map_or((job.zenith, job.north), |s| (s.zenith, s.north));
    crate::sky::Compass::new(z, n).unwrap_or_default()
}

/// The grid's sensors measured on the solution (they need the rays' intersector).
fn measure_grid(
    job: &SolveJob,
    run: &Run,
    spec: &crate::grid::GridSpec,
    sky: Option<&crate::sky::Sky>,
) -> Result<super::daylight::GridResult, Error> {
    let Some((isect, _)) = run.isect else {
        return Err(Error::Invalid(
            "--grid needs a method that casts rays (adaptive-hybrid or adaptive-rays)".into(),
        ));
    };
    super::daylight::measure(
        spec,
        &run.model.mesh,
        &run.model.scene.materials,
        isect,
        &run.sol.b,
        sky,
        &frame_of(job),
        job.grid_rays,
        job.settings.solve.seed,
    )
    .map_err(|e| Error::Invalid(e.to_string()))
}

/// Scalar flux the lights emit (W): what the solve's progress is measured against.
pub fn emitted_flux(model: &Model) -> f64 {
    let materials = &model.scene.materials;
    model
        .mesh
        .patches
        .iter()
        .map(|p| solve::scalar(&materials[p.material as usize].emission()) * p.area)
        .sum()
}

/// Refuses a `--save` path that cannot be written, before any work is spent.
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

/// The final-gather picture of a solve (`--shading gather`), through the solve's intersector
/// (one is built for the methods that cast no rays), with the solve's sky and seed.
fn gather_picture(
    job: &SolveJob,
    run: &Run,
    isect: &AnyIntersector,
    sky: Option<&crate::sky::Sky>,
    cam: &Camera,
) -> Result<(render::LinearImage, render::gather::GatherStats), Error> {
    let m = &run.model.mesh;
    let gather = crate::solve::final_gather::PointGather::new(
        m,
        &run.model.scene.materials,
        isect,
        &run.sol.b,
        sky,
        None,
    );
    let shading = ShadingSettings {
        seed: job.settings.solve.seed,
        ..job.shading
    };
    let rows = run
        .progress
        .start_count("rendering", u64::from(job.view.image.height));
    let out = render::render_gather(&gather, cam, &job.view.image, &shading, &rows);
    run.progress.phase("writing outputs");
    Ok(out)
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
