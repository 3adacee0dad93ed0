//! `radiosity sweep`: the scene-size performance sweep.
//!
//! Over generated buildings from about 1 k to 1 M patches and more, for each size and method:
//! load, mesh, intersector build and solve time; shots, rays, rays per second; peak memory (the
//! resident set's high-water mark, read from the OS, reset before each run) and the memory the
//! Embree scene took (resident set before and after building it); the solver's own error
//! estimate. Writes `sweep.csv`, `sweep.json` (the rows with every setting), `sweep.md` (table
//! and fitted growth exponents) and log–log
//! plots `time.png` and `memory.png`.
//!
//! Each building is written to a file and loaded from it, as a user would; the file is removed
//! afterwards.

use crate::export::write_atomic;
use crate::generate::{self, BuildingOptions};
use crate::intersect::select::IntersectorKind;
use crate::intersect::Intersector;
use crate::mesh::MeshOptions;
use crate::model::Model;
use crate::report::plot::{self, Curve};
use crate::scene::{self, LoadOptions};
use crate::solve::{MethodKind, SolveSettings};
use crate::Error;
use serde::Serialize;
use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

/// What to sweep.
#[derive(Clone, Debug)]
pub struct SweepJob {
    /// Target patch counts.
    pub sizes: Vec<usize>,
    pub methods: Vec<MethodKind>,
    pub cfg: SolveSettings,
    pub intersector: IntersectorKind,
    /// Output folder.
    pub out: PathBuf,
    pub seed: u64,
}

impl SweepJob {
    /// Refuses what `solve` refuses (the same settings check) and an empty or absurd size list.
    pub fn check(&self) -> Result<(), crate::settings::Invalid> {
        self.cfg.check()?;
        if self.sizes.is_empty() {
            return crate::settings::Invalid::err("--sizes names no size");
        }
        if self.methods.is_empty() {
            return crate::settings::Invalid::err("--methods names no method");
        }
        Ok(())
    }
}

/// One (size, method) run.
#[derive(Clone, Debug, Serialize)]
pub struct SweepRow {
    pub target: usize,
    pub patches: usize,
    pub method: &'static str,
    pub intersector: &'static str,
    pub load_s: f64,
    pub mesh_s: f64,
    pub build_s: f64,
    pub solve_s: f64,
    pub shots: u64,
    pub rays: u64,
    pub cells: u64,
    pub rays_per_s: f64,
    pub stop_reason: String,
    /// The solver's own estimate of its final error (fractions).
    pub est_weighted_percent: f64,
    pub est_energy: f64,
    /// Resident-set high-water mark of the run, and the Embree scene's share (MiB).
    pub peak_mib: f64,
    pub embree_mib: f64,
    /// (peak − Embree − what the process held before loading) per patch, bytes.
    pub bytes_per_patch: f64,
}

/// Resets the high-water mark to the current resident set (Linux ≥ 4.0).
pub(crate) fn reset_peak() {
    let _ = std::fs::write("/proc/self/clear_refs", "5");
}

/// Least-squares slope of log y against log x: the growth exponent.
pub fn growth_exponent(points: &[(f64, f64)]) -> Option<f64> {
    let p: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0)
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    if p.len() < 2 {
        return None;
    }
    let n = p.len() as f64;
    let (sx, sy) = p.iter().fold((0.0, 0.0), |(a, b), (x, y)| (a + x, b + y));
    let (mx, my) = (sx / n, sy / n);
    let (num, den) = p.iter().fold((0.0, 0.0), |(a, b), (x, y)| {
        (a + (x - mx) * (y - my), b + (x - mx) * (x - mx))
    });
    (den > 0.0).then(|| num / den)
}

/// Runs the sweep; `log` hears one line per run.
pub fn run(job: &SweepJob, mut log: impl FnMut(&str)) -> Result<Vec<SweepRow>, Error> {
    job.check()?;
    crate::export::prepare_dir(&job.out)?;
    let mut rows = Vec::new();
    for &target in &job.sizes {
        let opts = BuildingOptions::for_patches(target, job.seed);
        let dir =
            std::env::temp_dir().join(format!("radiosity-sweep-{}-{target}", std::process::id()));
        std::fs::create_dir_all(&dir)
            .map_err(|e| Error::Invalid(format!("{}: {e}", dir.display())))?;
        let obj = dir.join("building.obj");
        let written = (|| -> std::io::Result<()> {
            let mut o = std::io::BufWriter::new(std::fs::File::create(&obj)?);
            let mut m = std::io::BufWriter::new(std::fs::File::create(dir.join("building.mtl"))?);
            generate::write_building(&mut o, &mut m, "building.mtl", &opts)?;
            o.flush()?;
            m.flush()
        })();
        if let Err(e) = written {
            let _ = std::fs::remove_dir_all(&dir);
            return Err(Error::Invalid(format!("generating a building: {e}")));
        }
        for &method in &job.methods {
            let row = run_one(job, target, &obj, method);
            match row {
                Ok(r) => {
                    log(&format!(
                        "{:>8} patches  {:<18} load {:.2} s  mesh {:.2} s  build {:.2} s  solve {:.2} s  {:.2} Mrays/s  peak {:.0} MiB ({:.0} B/patch beyond Embree)  est. error {:.1} %",
                        r.patches,
                        r.method,
                        r.load_s,
                        r.mesh_s,
                        r.build_s,
                        r.solve_s,
                        r.rays_per_s / 1e6,
                        r.peak_mib,
                        r.bytes_per_patch,
                        100.0 * r.est_weighted_percent
                    ));
                    rows.push(r);
                }
                Err(e) => {
                    let _ = std::fs::remove_dir_all(&dir);
                    return Err(e);
                }
            }
        }
        let _ = std::fs::remove_dir_all(&dir);
        write_outputs(job, &rows)?;
    }
    Ok(rows)
}

fn run_one(
    job: &SweepJob,
    target: usize,
    obj: &std::path::Path,
    method: MethodKind,
) -> Result<SweepRow, Error> {
    reset_peak();
    let (base, _) = crate::report::resident_kib();
    let t = Instant::now();
    let scene = scene::load_obj(obj, &LoadOptions::default())?;
    let load_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let model = Model::from_scene(scene, &MeshOptions::default())?;
    let m = &model.mesh;
    let mesh_s = t.elapsed().as_secs_f64();
    let (before, _) = crate::report::resident_kib();
    let t = Instant::now();
    let isect = if method.casts_rays() {
        Some(model.intersector(job.intersector)?.0)
    } else {
        None
    };
    let build_s = t.elapsed().as_secs_f64();
    let (after, _) = crate::report::resident_kib();
    let cfg = job.cfg.for_method(method);
    let sol = model.solve(isect.as_ref(), &cfg, &Default::default(), |_| {})?;
    let (_, peak) = crate::report::resident_kib();
    let embree = (after - before).max(0.0);
    let est = sol
        .stats
        .trace
        .last()
        .map(|p| p.estimate)
        .unwrap_or_default();
    let n = m.patches.len();
    Ok(SweepRow {
        target,
        patches: n,
        method: method.name(),
        intersector: isect.as_ref().map_or("none", |i| i.name()),
        load_s,
        mesh_s,
        build_s,
        solve_s: sol.stats.seconds,
        shots: sol.stats.shots,
        rays: sol.stats.rays,
        cells: sol.stats.hemicube_cells,
        rays_per_s: sol.stats.rays as f64 / sol.stats.seconds.max(1e-9),
        stop_reason: sol
            .stats
            .stop_reason
            .map_or_else(|| "none".into(), |r| format!("{r:?}").to_lowercase()),
        est_weighted_percent: est.weighted_percent,
        est_energy: est.energy,
        peak_mib: peak / 1024.0,
        embree_mib: embree / 1024.0,
        bytes_per_patch: ((peak - embree - base).max(0.0) * 1024.0) / n.max(1) as f64,
    })
}

/// The table as Markdown, with growth exponents per method.
pub fn markdown(rows: &[SweepRow], methods: &[MethodKind]) -> String {
    let mut s = String::from(
        "| patches | method | load s | mesh s | build s | solve s | shots | rays | Mrays/s | peak MiB | Embree MiB | B/patch beyond Embree | est. error (weighted %) | stop |\n|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n",
    );
    for r in rows {
        s += &format!(
            "| {} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {} | {} | {:.2} | {:.0} | {:.0} | {:.0} | {:.2} % | {} |\n",
            r.patches,
            r.method,
            r.load_s,
            r.mesh_s,
            r.build_s,
            r.solve_s,
            r.shots,
            r.rays,
            r.rays_per_s / 1e6,
            r.peak_mib,
            r.embree_mib,
            r.bytes_per_patch,
            100.0 * r.est_weighted_percent,
            r.stop_reason
        );
    }
    s += "\nGrowth exponents (least-squares slope of log value against log patches):\n\n";
    for m in methods {
        let of = |f: &dyn Fn(&SweepRow) -> f64| {
            let pts: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| r.method == m.name())
                .map(|r| (r.patches as f64, f(r)))
                .collect();
            growth_exponent(&pts).map_or("—".to_string(), |e| format!("{e:.2}"))
        };
        s += &format!(
            "- {}: solve time {}, rays {}, peak memory {}, load {}, mesh {}\n",
            m.name(),
            of(&|r| r.solve_s),
            of(&|r| r.rays as f64),
            of(&|r| r.peak_mib),
            of(&|r| r.load_s),
            of(&|r| r.mesh_s)
        );
    }
    s
}

fn write_outputs(job: &SweepJob, rows: &[SweepRow]) -> Result<(), Error> {
    let csv = job.out.join("sweep.csv");
    write_atomic(&csv, |w| {
        writeln!(w, "target,patches,method,intersector,load_s,mesh_s,build_s,solve_s,shots,rays,cells,rays_per_s,stop_reason,est_weighted_percent,est_energy,peak_mib,embree_mib,bytes_per_patch")?;
        for r in rows {
            writeln!(
                w,
                "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
                r.target,
                r.patches,
                r.method,
                r.intersector,
                r.load_s,
                r.mesh_s,
                r.build_s,
                r.solve_s,
                r.shots,
                r.rays,
                r.cells,
                r.rays_per_s,
                r.stop_reason,
                r.est_weighted_percent,
                r.est_energy,
                r.peak_mib,
                r.embree_mib,
                r.bytes_per_patch
            )?;
        }
        Ok(())
    })?;
    let md = markdown(rows, &job.methods);
    write_atomic(&job.out.join("sweep.md"), |w| w.write_all(md.as_bytes()))?;
    // The rows with every setting they were run with (derived from the settings type).
    let json = serde_json::json!({
        "settings": job.cfg,
        "intersector": job.intersector,
        "building_seed": job.seed,
        "rows": rows,
    });
    write_atomic(&job.out.join("sweep.json"), |w| {
        serde_json::to_writer_pretty(&mut *w, &json).map_err(std::io::Error::other)?;
        writeln!(w)
    })?;
    let curves = |f: &dyn Fn(&SweepRow) -> f64| -> Vec<Curve> {
        job.methods
            .iter()
            .map(|m| Curve {
                label: m.name().to_string(),
                points: rows
                    .iter()
                    .filter(|r| r.method == m.name())
                    .map(|r| (r.patches as f64, f(r)))
                    .collect(),
            })
            .collect()
    };
    if rows.len() >= 2 {
        type Plot = (
            &'static str,
            &'static str,
            &'static str,
            fn(&SweepRow) -> f64,
        );
        let plots: [Plot; 2] = [
            (
                "time.png",
                "Solve time against scene size",
                "solve time (s)",
                |r| r.solve_s,
            ),
            (
                "memory.png",
                "Peak memory against scene size",
                "peak resident set (MiB)",
                |r| r.peak_mib,
            ),
        ];
        for (file, title, y, f) in plots {
            let png = plot::draw(title, "patches", y, &curves(&f), true)?;
            write_atomic(&job.out.join(file), |w| w.write_all(&png))?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn growth_exponent_of_a_power_law() {
        let pts: Vec<(f64, f64)> = [1e3, 1e4, 1e5]
            .iter()
            .map(|&x: &f64| (x, 3.0 * x.powf(1.1)))
            .collect();
        assert!((growth_exponent(&pts).unwrap() - 1.1).abs() < 1e-9);
        assert_eq!(growth_exponent(&pts[..1]), None);
    }
}
