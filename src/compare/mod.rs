//! Methods side by side (`radiosity compare`) against one reference (`radiosity reference`):
//! the paper's error analysis (Sec. 3, Table 1) and speed analysis (Sec. 4, Figs. 2 and 5)
//! measured in one process, on one scene, mesh and machine.
//!
//! - [`reference`](mod@reference): the high-accuracy reference, its stated error bound and the check of it;
//! - [`analysis`]: time to reach an error level, the decay constant E, cost per shot;
//! - [`report`]: `compare.csv` and `compare.md`; its `plots` the PNG plots.

pub mod analysis;
pub mod reference;
pub mod report;

use crate::export::patches::read_reference;
use crate::export::{self, patches, write_atomic};
use crate::intersect::select::{AnyIntersector, IntersectorKind};
use crate::intersect::Intersector;
use crate::mesh::MeshOptions;
use crate::model::Model;
use crate::scene::LoadOptions;
use crate::scene::SceneSource;
use crate::solve::estimate::ErrorMetrics;
use crate::solve::{self, MethodKind, SolveSettings, StopReason, SwitchInfo, TracePoint};
use crate::Error;
use reference::Reference;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

/// Everything `radiosity reference` does.
#[derive(Clone, Debug)]
pub struct ReferenceJob {
    pub source: SceneSource,
    pub load: LoadOptions,
    pub mesh: MeshOptions,
    /// Seed, tolerance and stop fraction of the reference (its method is ignored).
    pub solve: SolveSettings,
    pub intersector: IntersectorKind,
    pub out: PathBuf,
}

/// The reference's `summary.json`.
#[derive(Clone, Debug, serde::Serialize)]
struct ReferenceSummary<'a> {
    version: &'static str,
    scene: &'a str,
    patches: usize,
    patch_size: f32,
    method: &'static str,
    intersector: &'static str,
    /// The reference's settings as given (each half runs at √2 × the tolerance), derived
    /// from the settings type.
    settings: &'a SolveSettings,
    #[serde(flatten)]
    reference: &'a Reference,
}

/// `radiosity reference`: solves the reference, writes `patches.csv` and `summary.json` into
/// `job.out`, and fails ([`Error::Failed`], after writing) if the check of its bound fails.
pub fn run_reference(job: &ReferenceJob, mut log: impl FnMut(&str)) -> Result<Reference, Error> {
    job.solve.check()?;
    job.mesh.check()?;
    export::prepare_dir(&job.out)?;
    let model = Model::load(&job.source, &job.load, &job.mesh)?;
    let (scene, m) = (&model.scene, &model.mesh);
    log(&model.describe());
    let (isect, _) = model.intersector(job.intersector)?;
    let r = reference::build(m, &scene.materials, &isect, &job.solve).map_err(|source| {
        Error::Solve {
            scene: scene.name.clone(),
            source,
        }
    })?;
    write_atomic(&job.out.join("patches.csv"), |w| {
        patches::write(w, m, &scene.materials, &r.b, None)
    })?;
    let summary = ReferenceSummary {
        version: env!("CARGO_PKG_VERSION"),
        scene: &scene.name,
        patches: m.patches.len(),
        patch_size: m.patch_size,
        method: MethodKind::AdaptiveRays.name(),
        intersector: isect.name(),
        settings: &job.solve,
        reference: &r,
    };
    write_atomic(&job.out.join("summary.json"), |w| {
        serde_json::to_writer_pretty(&mut *w, &summary).map_err(std::io::Error::other)?;
        writeln!(w)
    })?;
    log(&format!(
        "reference: {} shots, {} rays in {:.1} s",
        r.shots, r.rays, r.seconds
    ));
    log(&r.check_line());
    if !r.check_passed {
        return Err(Error::Failed(format!(
            "{}: the reference's stated bound disagrees with the difference of its halves by more than {}×",
            scene.name,
            reference::CHECK_FACTOR
        )));
    }
    Ok(r)
}

/// Everything `radiosity compare` does.
#[derive(Clone, Debug)]
pub struct CompareJob {
    pub source: SceneSource,
    pub load: LoadOptions,
    pub mesh: MeshOptions,
    /// The methods, in order; speedups are of the first over each other.
    pub methods: Vec<MethodKind>,
    /// Time budget per method (seconds).
    pub budget: f64,
    /// Seed, tolerance, stop fraction, hemi-cube resolution and gathering cap of the runs.
    pub solve: SolveSettings,
    /// A reference patch table; built (with `reference_solve`) when none is given.
    pub reference: Option<PathBuf>,
    pub reference_solve: SolveSettings,
    pub intersector: IntersectorKind,
    /// Error levels (fractions) of the time-to-error table.
    pub levels: Vec<f64>,
    pub out: PathBuf,
    /// Run every method this many times, in interleaved rounds, and keep each method's run of
    /// median solve time (millisecond solves are at the mercy of the machine's noise).
    pub repeat: usize,
}

/// One method's run.
#[derive(Clone, Debug, serde::Serialize)]
pub struct MethodRun {
    pub method: MethodKind,
    pub seconds: f64,
    pub shots: u64,
    pub rays: u64,
    /// Hemi-cube cells (form-factor samples; gathering: n · cells of its matrix).
    pub cells: u64,
    pub stop_reason: Option<StopReason>,
    pub switch: Option<SwitchInfo>,
    /// The error against the reference at the end.
    pub error: Option<ErrorMetrics>,
    /// The whole trace (in `compare.csv`, not in `compare.json`).
    #[serde(skip)]
    pub trace: Vec<TracePoint>,
}

impl MethodRun {
    /// Form factors computed: one per ray and per hemi-cube cell.
    pub fn form_factors(&self) -> u64 {
        self.rays + self.cells
    }
}

/// What a comparison measured.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Comparison {
    pub scene: String,
    pub patches: usize,
    pub patch_size: f32,
    pub threads: usize,
    pub intersector: &'static str,
    pub budget_s: f64,
    pub tolerance: f64,
    pub stop_fraction: f64,
    pub hemicube_n: usize,
    /// Where the reference came from (a file, or built here), and its bound if built here.
    pub reference_source: String,
    pub reference: Option<Reference>,
    pub levels: Vec<f64>,
    /// The runs' settings (each run with its own method and `max_time` = the budget),
    /// derived, not listed by hand.
    pub settings: SolveSettings,
    /// The settings of the reference built here (none when one was given).
    pub reference_settings: Option<SolveSettings>,
    pub runs: Vec<MethodRun>,
}

fn validate(job: &CompareJob) -> Result<(), Error> {
    if !(1..=100).contains(&job.repeat) {
        return Err(Error::Invalid(format!(
            "--repeat must be between 1 and 100, got {}",
            job.repeat
        )));
    }
    if job.methods.is_empty() {
        return Err(Error::Invalid("--methods names no method".into()));
    }
    for (k, m) in job.methods.iter().enumerate() {
        if job.methods[..k].contains(m) {
            return Err(Error::Invalid(format!(
                "--methods names {} twice",
                m.name()
            )));
        }
    }
    let b = job.budget;
    if !(b > 0.0 && b.is_finite() && b < 1e7) {
        return Err(Error::Invalid(format!(
            "--budget must be a positive number of seconds, got {b}"
        )));
    }
    if let Some(&l) = job.levels.iter().find(|&&l| !(l > 0.0 && l <= 10.0)) {
        return Err(Error::Invalid(format!(
            "--levels must be error fractions in (0, 10] (0.05 = 5 %), got {l}"
        )));
    }
    let s = &job.solve;
    s.check()?;
    job.mesh.check()?;
    if job.reference.is_none() {
        job.reference_solve
            .check()
            .map_err(|e| Error::Invalid(format!("reference: {e}")))?;
    }
    Ok(())
}

/// One run of `method` within the budget, measured against the reference `b_ref`.
fn run_method(
    job: &CompareJob,
    model: &Model,
    isect: Option<&AnyIntersector>,
    method: MethodKind,
    b_ref: &Arc<Vec<[f64; 3]>>,
) -> Result<MethodRun, Error> {
    let cfg = SolveSettings {
        max_time: Some(job.budget),
        switch_at: None,
        ..job.solve.for_method(method)
    };
    let hooks = solve::RunHooks {
        reference: Some(b_ref.clone()),
        ..Default::default()
    };
    let sol = model.solve(isect, &cfg, &hooks, |_| {})?;
    let last = sol.stats.trace.last();
    Ok(MethodRun {
        method,
        seconds: sol.stats.seconds,
        shots: sol.stats.shots,
        rays: sol.stats.rays,
        cells: last.map_or(sol.stats.hemicube_cells, |p| p.cells),
        stop_reason: sol.stats.stop_reason,
        switch: sol.stats.switch,
        error: last.and_then(|p| p.error),
        trace: sol.stats.trace.clone(),
    })
}

/// `radiosity compare`: runs every method on one mesh against one reference and writes
/// `compare.csv`, `compare.md`, `compare.json` and the plots into `job.out`.
pub fn run_compare(job: &CompareJob, mut log: impl FnMut(&str)) -> Result<Comparison, Error> {
    validate(job)?;
    export::prepare_dir(&job.out)?;
    let model = Model::load(&job.source, &job.load, &job.mesh)?;
    let (scene, m) = (&model.scene, &model.mesh);
    log(&model.describe());
    // One intersector for every method that casts rays, and for the reference.
    let needs_rays = job.reference.is_none() || job.methods.iter().any(|m| m.casts_rays());
    let isect = if needs_rays {
        Some(model.intersector(job.intersector)?.0)
    } else {
        None
    };
    let (b_ref, reference, reference_source) = match (&job.reference, &isect) {
        (Some(path), _) => (read_reference(path, m)?, None, path.display().to_string()),
        (None, Some(isect)) => {
            let t = Instant::now();
            log(&format!(
                "building the reference (adaptive rays, tolerance {}, stop {}) …",
                job.reference_solve.tolerance, job.reference_solve.stop_fraction
            ));
            let r = reference::build(m, &scene.materials, isect, &job.reference_solve).map_err(
                |source| Error::Solve {
                    scene: scene.name.clone(),
                    source,
                },
            )?;
            log(&format!(
                "reference in {:.1} s: {}",
                t.elapsed().as_secs_f64(),
                r.check_line()
            ));
            let dir = job.out.join("reference");
            export::prepare_dir(&dir)?;
            write_atomic(&dir.join("patches.csv"), |w| {
                patches::write(w, m, &scene.materials, &r.b, None)
            })?;
            let b = r.b.clone();
            (b, Some(r), "built here (reference/patches.csv)".to_string())
        }
        (None, None) => unreachable!("an intersector is built whenever no reference is given"),
    };
    let b_ref = Arc::new(b_ref);

    // Rounds of every method in turn: a burst of load on the shared machine then hits all
    // methods alike; each keeps its median run.
    let mut all: Vec<Vec<MethodRun>> = job.methods.iter().map(|_| Vec::new()).collect();
    for round in 0..job.repeat.max(1) {
        for (k, &method) in job.methods.iter().enumerate() {
            let run = run_method(job, &model, isect.as_ref(), method, &b_ref)?;
            log(&format!(
                "{}{}: {} shots, {} form factors in {:.2} s; error {:.2} % (average weighted percent)",
                method.name(),
                if job.repeat > 1 {
                    format!(" (round {})", round + 1)
                } else {
                    String::new()
                },
                run.shots,
                run.form_factors(),
                run.seconds,
                100.0 * run.error.map_or(0.0, |e| e.weighted_percent)
            ));
            all[k].push(run);
        }
    }
    let runs: Vec<MethodRun> = all
        .into_iter()
        .map(|mut v| {
            v.sort_by(|a, b| a.seconds.total_cmp(&b.seconds));
            v.swap_remove(v.len() / 2)
        })
        .collect();
    let cmp = Comparison {
        scene: scene.name.clone(),
        patches: m.patches.len(),
        patch_size: m.patch_size,
        threads: rayon::current_num_threads(),
        intersector: isect.as_ref().map_or("none (no rays cast)", |i| i.name()),
        budget_s: job.budget,
        settings: job.solve.clone(),
        reference_settings: job.reference.is_none().then(|| job.reference_solve.clone()),
        tolerance: job.solve.tolerance,
        stop_fraction: job.solve.stop_fraction,
        hemicube_n: job.solve.hemicube_n,
        reference_source,
        reference,
        levels: job.levels.clone(),
        runs,
    };
    write_outputs(&cmp, &job.out)?;
    Ok(cmp)
}

/// Writes `compare.csv`, `compare.md`, `compare.json` and the three plots into `dir`.
pub fn write_outputs(cmp: &Comparison, dir: &Path) -> Result<(), Error> {
    write_atomic(&dir.join("compare.csv"), |w| report::write_csv(w, cmp))?;
    let md = report::markdown(cmp);
    write_atomic(&dir.join("compare.md"), |w| w.write_all(md.as_bytes()))?;
    write_atomic(&dir.join("compare.json"), |w| {
        serde_json::to_writer_pretty(&mut *w, cmp).map_err(std::io::Error::other)?;
        writeln!(w)
    })?;
    for (name, png) in report::plots(cmp)? {
        write_atomic(&dir.join(name), |w| w.write_all(&png))?;
    }
    Ok(())
}
