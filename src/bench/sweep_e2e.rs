//! `radiosity sweep --end-to-end`: the scene-size sweep of what a user waits for.
//!
//! Where [`super::sweep`] times the solver alone, this runs the whole `solve` pipeline on each
//! generated building, as `radiosity solve BUILDING.obj --out DIR` does (docs/design.md §1):
//! load, mesh, the intersector's build, the sides (hidden faces, faces lit from behind), the
//! solve with its final gather, the elements, the picture and the files; and reports each
//! stage's wall time and the process's peak resident memory at its end (the high-water mark,
//! reset before each size), the rays of the shooting, the gather and the elements, and the
//! solver's own error estimate, with the growth exponent of every column. Writes
//! `end-to-end.csv`, `end-to-end.json` (the rows, every setting, each size's `summary.json`),
//! `end-to-end.md` (table and exponents) and log–log plots `end-to-end-time.png` and
//! `end-to-end-memory.png`.
//!
//! Each building is written to a file and solved from it; its outputs go to a folder that is
//! removed once its row is kept (`keep_outputs` keeps them), since at ten million patches
//! the tables alone are gigabytes.

use super::sweep::{growth_exponent, SweepJob};
use crate::elements::ElementSettings;
use crate::export::write_atomic;
use crate::generate::{self, BuildingOptions};
use crate::pipeline::{self, RunSettings, SolveJob};
use crate::progress::Progress;
use crate::report::plot::{self, Curve};
use crate::report::Summary;
use crate::scene::SceneSource;
use crate::Error;
use serde::Serialize;
use std::io::Write;
use std::path::Path;

/// One size of the end-to-end sweep: wall seconds and peak MiB per stage.
#[derive(Clone, Debug, Serialize)]
pub struct EndToEndRow {
    pub target: usize,
    pub patches: usize,
    pub method: &'static str,
    pub load_s: f64,
    pub mesh_s: f64,
    pub build_s: f64,
    pub sides_s: f64,
    /// The solve with its final gather (and the error target's passes); `gather_s` of it.
    pub solve_s: f64,
    pub gather_s: f64,
    pub elements_s: f64,
    pub picture_s: f64,
    /// The files (the output stage less the elements and the picture).
    pub files_s: f64,
    pub total_s: f64,
    /// Process CPU seconds of the whole run.
    pub cpu_s: f64,
    pub shoot_rays: u64,
    pub gather_rays: u64,
    pub element_rays: u64,
    /// Elements made (0 when they were off or skipped).
    pub elements: u64,
    pub est_weighted_percent: f64,
    /// Peak resident memory at the end of each stage (MiB).
    pub peak_load_mib: f64,
    pub peak_mesh_mib: f64,
    pub peak_build_mib: f64,
    pub peak_sides_mib: f64,
    pub peak_solve_mib: f64,
    pub peak_elements_mib: f64,
    pub peak_mib: f64,
}

impl EndToEndRow {
    fn of(target: usize, s: &Summary) -> EndToEndRow {
        let (t, p) = (&s.seconds, &s.peak_mib);
        let gather = s.final_gather.unwrap_or_default();
        let el = s.elements.unwrap_or_default();
        EndToEndRow {
            target,
            patches: s.patches,
            method: s.method,
            load_s: t.load,
            mesh_s: t.mesh,
            build_s: t.build,
            sides_s: t.sides,
            solve_s: t.solve,
            gather_s: gather.seconds,
            elements_s: t.elements,
            picture_s: t.picture,
            files_s: (t.output - t.elements - t.picture - t.grid).max(0.0),
            total_s: t.total,
            cpu_s: s.cpu_seconds.total,
            shoot_rays: s.rays,
            gather_rays: gather.rays,
            element_rays: el.rays,
            elements: el.count,
            est_weighted_percent: s.error_estimate.weighted_percent,
            peak_load_mib: p.load,
            peak_mesh_mib: p.mesh,
            peak_build_mib: p.build,
            peak_sides_mib: p.sides,
            peak_solve_mib: p.solve,
            peak_elements_mib: p.elements,
            peak_mib: p.output,
        }
    }
}

/// Runs the end-to-end sweep of `job` (its first method) with `elements` for the refine
/// stage; `log` hears each stage's lines and one line per size.
pub fn run(
    job: &SweepJob,
    elements: &ElementSettings,
    keep_outputs: bool,
    mut log: impl FnMut(&str),
) -> Result<Vec<EndToEndRow>, Error> {
    job.check()?;
    crate::export::prepare_dir(&job.out)?;
    let method = job.methods[0];
    let mut rows = Vec::new();
    let mut summaries = Vec::new();
    for &target in &job.sizes {
        let dir = job.out.join(format!("{target}"));
        std::fs::create_dir_all(&dir)
            .map_err(|e| Error::Invalid(format!("{}: {e}", dir.display())))?;
        let obj = dir.join("building.obj");
        write_building(&dir, &obj, &BuildingOptions::for_patches(target, job.seed))?;
        super::sweep::reset_peak();
        let mut solve = SolveJob::new(SceneSource::File(obj.clone()), dir.join("solve"));
        solve.settings = RunSettings {
            solve: job.cfg.for_method(method),
            intersector: job.intersector,
            elements: elements.clone(),
            ..RunSettings::default()
        };
        solve.shading.shading = crate::render::Shading::Gouraud;
        solve.shading.seed = job.cfg.seed;
        solve.check()?;
        let summary = pipeline::run_solve_with(&solve, &Progress::hidden(), &mut log)?;
        let r = EndToEndRow::of(target, &summary);
        log(&format!(
            "{:>9} patches  total {:.1} s (solve {:.1}, gather {:.1}, elements {:.1}, picture {:.1}, files {:.1})  peak {:.0} MiB  est. error {:.2} %",
            r.patches, r.total_s, r.solve_s, r.gather_s, r.elements_s, r.picture_s, r.files_s,
            r.peak_mib, 100.0 * r.est_weighted_percent
        ));
        summaries.push(serde_json::to_value(&summary).unwrap_or_default());
        rows.push(r);
        if !keep_outputs {
            let _ = std::fs::remove_dir_all(&dir);
        }
        write_outputs(job, &rows, &summaries)?;
    }
    Ok(rows)
}

/// Writes the building of `opts` to `obj` (and its MTL beside it).
fn write_building(dir: &Path, obj: &Path, opts: &BuildingOptions) -> Result<(), Error> {
    let written = (|| -> std::io::Result<()> {
        let mut o = std::io::BufWriter::new(std::fs::File::create(obj)?);
        let mut m = std::io::BufWriter::new(std::fs::File::create(dir.join("building.mtl"))?);
        generate::write_building(&mut o, &mut m, "building.mtl", opts)?;
        o.flush()?;
        m.flush()
    })();
    written.map_err(|e| Error::Invalid(format!("generating a building: {e}")))
}

/// The stages' columns: name and value.
type Column = (&'static str, fn(&EndToEndRow) -> f64);

const TIMES: [Column; 9] = [
    ("load", |r| r.load_s),
    ("mesh", |r| r.mesh_s),
    ("build", |r| r.build_s),
    ("sides", |r| r.sides_s),
    ("solve", |r| r.solve_s),
    ("gather", |r| r.gather_s),
    ("elements", |r| r.elements_s),
    ("picture", |r| r.picture_s),
    ("total", |r| r.total_s),
];

/// The table as Markdown, with the growth exponent of every column.
pub fn markdown(rows: &[EndToEndRow]) -> String {
    let mut s = String::from(
        "| patches | load s | mesh s | build s | sides s | solve s (gather) | elements s (count) | picture s | files s | total s | CPU s | rays: shoot / gather / elements | peak MiB: solve / elements / run | est. error |\n|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---|---:|\n",
    );
    for r in rows {
        s += &format!(
            "| {} | {:.2} | {:.2} | {:.2} | {:.2} | {:.1} ({:.1}) | {:.1} ({}) | {:.2} | {:.2} | {:.1} | {:.1} | {:.1} M / {:.1} M / {:.1} M | {:.0} / {:.0} / {:.0} | {:.2} % |\n",
            r.patches, r.load_s, r.mesh_s, r.build_s, r.sides_s, r.solve_s, r.gather_s,
            r.elements_s, r.elements, r.picture_s, r.files_s, r.total_s, r.cpu_s,
            r.shoot_rays as f64 / 1e6, r.gather_rays as f64 / 1e6, r.element_rays as f64 / 1e6,
            r.peak_solve_mib, r.peak_elements_mib, r.peak_mib, 100.0 * r.est_weighted_percent
        );
    }
    // A stage's exponent is taken over the sizes where it ran: the elements' skip above the
    // auto limit costs a few milliseconds that say nothing of their growth.
    let exponent = |name: &str, f: &dyn Fn(&EndToEndRow) -> f64| {
        let pts: Vec<(f64, f64)> = (rows.iter())
            .filter(|r| name != "elements" || r.elements > 0)
            .map(|r| (r.patches as f64, f(r)))
            .collect();
        growth_exponent(&pts).map_or("—".to_string(), |e| format!("{e:.2}"))
    };
    s += "\nGrowth exponents (least-squares slope of log value against log patches, over the sizes where the stage ran): ";
    let parts: Vec<String> = (TIMES.iter())
        .map(|(name, f)| format!("{name} {}", exponent(name, f)))
        .chain([format!("peak memory {}", exponent("peak", &|r| r.peak_mib))])
        .collect();
    s += &parts.join(", ");
    s += "\n";
    s
}

fn write_outputs(
    job: &SweepJob,
    rows: &[EndToEndRow],
    summaries: &[serde_json::Value],
) -> Result<(), Error> {
    write_atomic(&job.out.join("end-to-end.csv"), |w| {
        writeln!(w, "target,patches,method,load_s,mesh_s,build_s,sides_s,solve_s,gather_s,elements_s,picture_s,files_s,total_s,cpu_s,shoot_rays,gather_rays,element_rays,elements,est_weighted_percent,peak_load_mib,peak_mesh_mib,peak_build_mib,peak_sides_mib,peak_solve_mib,peak_elements_mib,peak_mib")?;
        for r in rows {
            writeln!(
                w,
                "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
                r.target,
                r.patches,
                r.method,
                r.load_s,
                r.mesh_s,
                r.build_s,
                r.sides_s,
                r.solve_s,
                r.gather_s,
                r.elements_s,
                r.picture_s,
                r.files_s,
                r.total_s,
                r.cpu_s,
                r.shoot_rays,
                r.gather_rays,
                r.element_rays,
                r.elements,
                r.est_weighted_percent,
                r.peak_load_mib,
                r.peak_mesh_mib,
                r.peak_build_mib,
                r.peak_sides_mib,
                r.peak_solve_mib,
                r.peak_elements_mib,
                r.peak_mib
            )?;
        }
        Ok(())
    })?;
    let md = markdown(rows);
    write_atomic(&job.out.join("end-to-end.md"), |w| {
        w.write_all(md.as_bytes())
    })?;
    let json = serde_json::json!({
        "settings": job.cfg,
        "intersector": job.intersector,
        "building_seed": job.seed,
        "rows": rows,
        "summaries": summaries,
    });
    write_atomic(&job.out.join("end-to-end.json"), |w| {
        serde_json::to_writer_pretty(&mut *w, &json).map_err(std::io::Error::other)?;
        writeln!(w)
    })?;
    if rows.len() < 2 {
        return Ok(());
    }
    let curve = |(name, f): &Column| Curve {
        label: name.to_string(),
        points: (rows.iter())
            .filter(|r| *name != "elements" || r.elements > 0)
            .map(|r| (r.patches as f64, f(r)))
            .collect(),
    };
    // The elements' curve only where they were refined (as their exponent in `markdown`).
    let times: Vec<Curve> = (TIMES.iter().map(curve))
        .filter(|c| !c.points.is_empty())
        .collect();
    let png = plot::draw(
        "Time per stage against scene size",
        "patches",
        "wall seconds",
        &times,
        true,
    )?;
    write_atomic(&job.out.join("end-to-end-time.png"), |w| w.write_all(&png))?;
    let peaks: [Column; 3] = [
        ("after the solve", |r| r.peak_solve_mib),
        ("after the elements", |r| r.peak_elements_mib),
        ("the run", |r| r.peak_mib),
    ];
    let mem: Vec<Curve> = peaks.iter().map(curve).collect();
    let png = plot::draw(
        "Peak memory against scene size",
        "patches",
        "peak resident set (MiB)",
        &mem,
        true,
    )?;
    write_atomic(&job.out.join("end-to-end-memory.png"), |w| {
        w.write_all(&png)
    })?;
    Ok(())
}
