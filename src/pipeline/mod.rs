//! What `radiosity solve` and `radiosity info` do (docs/design.md §1). The binary only fills a
//! [`SolveJob`]; [`run_solve`] runs its stages in order, each a function that takes what it
//! needs and returns a value (read `solve_into` top to bottom):
//!
//! | stage     | function                     | returns                              |
//! |-----------|------------------------------|--------------------------------------|
//! | load      | [`stages::load`]             | the [`Scene`](crate::scene::Scene)   |
//! | mesh      | [`stages::mesh`]             | the [`Model`] (scene and patches)    |
//! | intersect | [`stages::intersect`]        | the intersector, if the method casts rays |
//! | sides     | [`stages::sides`], [`stages::lit_backs`] (or [`stages::lit_backs_ahead`], run beside the mesh, then [`stages::lit_backs_found`]) | the hidden sides and the back patches of faces lit from behind, kept in the mesh |
//! | solve     | [`stages::solve`]            | the [`Solution`](crate::solve::Solution), read on as [`stages::Solved`] |
//! | refine    | [`refine::refine`]           | the adaptive elements ([`refine::Refined`]) |
//! | measure   | [`daylight::measure_grid`]   | the sensor grid ([`daylight::Measured`]) |
//! | picture   | [`picture::picture`]         | `render.png`'s image                 |
//! | write     | [`outputs::write`]           | the files, and the [`Summary`]       |
//!
//! - [`RunSettings`]: everything that shapes a solve's result, in one serialisable record. The
//!   summary, the saved solution and the checkpoint key are derived from it.
//! - [`hooks`]: what the run plugs into the solver (reference, per-light channels,
//!   checkpoints, resume, Ctrl-C).

pub mod annual;
pub mod daylight;
pub mod hooks;
pub mod outputs;
pub mod picture;
pub mod refine;
pub mod stages;

use crate::export;
use crate::intersect::select::IntersectorKind;
use crate::mesh::{self, MeshOptions};
use crate::model::Model;
use crate::progress::Progress;
use crate::render::ViewSettings;
use crate::report::{self, Summary, Timings};
use crate::scene::{LoadOptions, SceneSource};
use crate::settings::Invalid;
use crate::solve::lights::GroupBy;
use crate::solve::{MethodKind, SolveSettings};
use crate::Error;
use serde::{Deserialize, Serialize};
use stages::{Clock, Solved};
use std::path::PathBuf;
use std::time::Instant;

/// Everything that shapes a solve's result: how the model is read and cut, how it is solved,
/// the intersector, the per-light channels. Serialised, it is the `settings` of
/// `summary.json` and of a saved solution, and (with the budgets left out) the key a
/// checkpoint must match: a setting added to any of these types reaches all three.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct RunSettings {
    pub load: LoadOptions,
    pub mesh: MeshOptions,
    pub solve: SolveSettings,
    pub intersector: IntersectorKind,
    /// Keep per-light channels, grouped so (`--per-light`, `--light-groups`).
    pub per_light: Option<GroupBy>,
    /// Adaptive elements after the solve (`--elements`, `--element-threshold`, …).
    pub elements: crate::elements::ElementSettings,
}

impl RunSettings {
    /// Checks every setting a user can get wrong (one line naming the flag).
    pub fn check(&self) -> Result<(), Invalid> {
        self.load.check()?;
        self.mesh.check()?;
        self.elements.check()?;
        self.solve.check()
    }

    /// These settings as JSON (for the summary and the saved solution).
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::to_value(self).unwrap_or_default()
    }

    /// What a checkpoint must match to be resumed: the scene (its hash) and every setting that
    /// shapes the result, with the patch size as the mesh resolved it. The budgets
    /// (`--max-time`, `--max-rays`), the gathering cap and the elements (refined after the
    /// solve, from its result) are left out: a run may be resumed with more time.
    pub fn checkpoint_key(&self, scene_hash: u64, patch_size: f32) -> String {
        let shaping = RunSettings {
            mesh: MeshOptions {
                patch_size: Some(patch_size),
                ..self.mesh.clone()
            },
            solve: SolveSettings {
                max_time: None,
                max_rays: None,
                gather_cap_mib: SolveSettings::default().gather_cap_mib,
                ..self.solve.clone()
            },
            elements: Default::default(),
            ..self.clone()
        };
        format!(
            "scene {scene_hash:016x}, settings {}",
            serde_json::to_string(&shaping).unwrap_or_default()
        )
    }
}

/// Everything `radiosity solve` does.
#[derive(Clone, Debug)]
pub struct SolveJob {
    pub source: SceneSource,
    pub settings: RunSettings,
    pub view: ViewSettings,
    pub out: PathBuf,
    /// A reference patch table (`--reference`): the trace then records the error against it.
    pub reference: Option<PathBuf>,
    /// Also save the solution here (`--save`), for `render`, `export` and `relight` (see
    /// [`crate::export::solution`]).
    pub save: Option<PathBuf>,
    /// Checkpoint file (`--checkpoint`) and seconds between checkpoints.
    pub checkpoint: Option<PathBuf>,
    pub checkpoint_every: f64,
    /// Continue from this checkpoint (`--resume`).
    pub resume: Option<PathBuf>,
    /// Set on Ctrl-C: stop at the next safe point.
    pub interrupt: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
    /// Sensors to measure (`--grid`): `grid.csv`, `grid.png`, the summary's `grid`.
    pub grid: Option<crate::grid::GridSpec>,
    /// Rays each sensor gathers (`--grid-rays`).
    pub grid_rays: usize,
    /// What becomes of the work plane's outdoor sensors (`--grid-outdoor`).
    pub grid_outdoor: crate::grid::Outdoor,
    /// The model's up and north (`--zenith`, `--north`, the default north following the
    /// zenith: [`crate::sky::Compass::default_north`]): the sky's compass, and the work
    /// plane's up when a grid is asked for without a sky.
    pub zenith: glam::Vec3,
    pub north: glam::Vec3,
    /// How `render.png` is shaded (`--shading`, `--pixel-rays`; the seed is the solve's).
    pub shading: crate::render::ShadingSettings,
}

/// Seconds between checkpoints by default (`--checkpoint-every`).
pub const DEFAULT_CHECKPOINT_EVERY: f64 = 60.0;

impl SolveJob {
    /// A job with default settings on `source`, writing into `out`.
    pub fn new(source: SceneSource, out: PathBuf) -> SolveJob {
        SolveJob {
            source,
            settings: RunSettings::default(),
            view: ViewSettings::default(),
            out,
            reference: None,
            save: None,
            checkpoint: None,
            checkpoint_every: DEFAULT_CHECKPOINT_EVERY,
            resume: None,
            interrupt: None,
            grid: None,
            grid_rays: daylight::DEFAULT_GRID_RAYS,
            grid_outdoor: crate::grid::Outdoor::Drop,
            zenith: crate::sky::DEFAULT_ZENITH,
            north: crate::sky::DEFAULT_NORTH,
            shading: Default::default(),
        }
    }

    /// Checks the settings a user can get wrong, before any work.
    pub fn check(&self) -> Result<(), Invalid> {
        self.settings.check()?;
        self.view.check()?;
        self.shading.check()?;
        if (self.checkpoint.is_some() || self.resume.is_some())
            && self.settings.solve.method == MethodKind::Gathering
        {
            return Invalid::err(
                "--checkpoint and --resume need a shooting method: gathering has no useful state before it converges",
            );
        }
        if !(self.checkpoint_every > 0.0 && self.checkpoint_every.is_finite()) {
            return Invalid::err(format!(
                "--checkpoint-every must be a positive number of seconds, got {}",
                self.checkpoint_every
            ));
        }
        // The orientation serves the sky and the grid's work plane; checked even without them.
        crate::sky::Compass::new(self.zenith, self.north)?;
        if self.grid.is_some() && !self.settings.solve.method.casts_rays() {
            return Invalid::err(
                "--grid needs a method that casts rays (adaptive-hybrid or adaptive-rays)",
            );
        }
        Ok(())
    }
}

/// Runs a whole solve and writes its outputs into `job.out`. `log` receives progress lines.
pub fn run_solve(job: &SolveJob, log: impl FnMut(&str)) -> Result<Summary, Error> {
    run_solve_with(job, &Progress::hidden(), log)
}

/// [`run_solve`] with progress bars.
pub fn run_solve_with(
    job: &SolveJob,
    progress: &Progress,
    mut log: impl FnMut(&str),
) -> Result<Summary, Error> {
    job.check()?;
    let t0 = Instant::now();
    // Fail on an unwritable folder or a bad --save before spending any time.
    let made = outputs::prepare_out(job)?;
    // On failure leave nothing behind: not the files written so far, not the new folders.
    let mut written = Vec::new();
    let result = solve_into(job, progress, &mut log, t0, &mut written);
    if result.is_err() {
        for path in &written {
            let _ = std::fs::remove_file(path);
        }
        export::remove_made_dirs(&made);
    }
    result
}

/// The mesh, intersect and sides stages (docs/design.md §1), their times into `timings`;
/// the clock of the sides stage is handed back running, for the faces lit from behind.
fn mesh_and_sides(
    job: &SolveJob,
    scene: crate::scene::Scene,
    progress: &Progress,
    log: &mut impl FnMut(&str),
    timings: &mut Timings,
) -> Result<(Model, stages::SolveIntersector, Clock), Error> {
    let clock = Clock::start();
    let mut model = stages::mesh(job, scene, progress, log)?;
    timings.mesh = clock.seconds();
    timings.peak.mesh = report::peak_mib();

    let clock = Clock::start();
    let isect = stages::intersect(job, &model, progress, log)?;
    timings.build = clock.seconds();
    timings.peak.build = report::peak_mib();

    let clock = Clock::start();
    stages::sides(job, &mut model, isect.as_ref(), progress, log);
    Ok((model, isect, clock))
}

/// The work of [`run_solve_with`] once the output folder is ready: the stages in order
/// (docs/design.md §1). Every file written is recorded in `written` as soon as it exists.
fn solve_into(
    job: &SolveJob,
    progress: &Progress,
    log: &mut impl FnMut(&str),
    t0: Instant,
    written: &mut Vec<PathBuf>,
) -> Result<Summary, Error> {
    let mut timings = Timings::default();
    let scene = stages::load(job, progress, log)?;
    let sunlit = daylight::model_sun(job, &scene, log)?;
    let job = sunlit.as_ref().unwrap_or(job);
    timings.load = t0.elapsed().as_secs_f64();
    timings.peak.load = report::peak_mib();

    // The mesh, its intersector and its hidden sides; beside them, on a thread of its own, the
    // probe for faces lit from behind when the model is too large to be probed on its own mesh
    // (`stages::lit_backs_ahead`: it cuts the scene coarser for itself). Its seconds are
    // `lit_backs.seconds`; the sides stage counts any wait for it.
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let (built, ahead) = std::thread::scope(|threads| {
        let ahead = stages::probes_lit_backs(job).then(|| {
            let (scene, stop) = (scene.clone(), stop.clone());
            threads.spawn(move || stages::lit_backs_ahead(job, &scene, stop))
        });
        let built = mesh_and_sides(job, scene, progress, log, &mut timings);
        if built.is_err() {
            stop.store(true, std::sync::atomic::Ordering::Relaxed);
        }
        (built, ahead.map(|probe| probe.join()))
    });
    let (mut model, isect, sides_clock) = built?;
    let ahead = match ahead {
        Some(joined) => joined.unwrap_or_else(|panic| std::panic::resume_unwind(panic))?,
        None => None,
    };
    let lit_backs = match (ahead, isect.as_ref()) {
        (Some(found), Some((i, _))) => {
            Some(stages::lit_backs_found(job, &mut model, i, found, log))
        }
        _ => stages::lit_backs(job, &mut model, isect.as_ref(), progress, log)?,
    };
    timings.sides = sides_clock.seconds();
    timings.peak.sides = report::peak_mib();

    let hooks = hooks::build(job, &model, log)?;
    let clock = Clock::start();
    let sol = stages::solve(job, &model, isect.as_ref(), &hooks, progress, log)?;
    (timings.solve, timings.cpu.solve) = (clock.seconds(), clock.cpu_seconds());
    timings.peak.solve = report::peak_mib();

    // From here on the solution is read, not changed; this time counts as the output's.
    let after = Instant::now();
    let solved = Solved {
        model: &model,
        isect: isect.as_ref(),
        sol,
        sky: stages::sky(job),
        t0,
        progress,
        lit_backs,
    };
    // The elements and the gathered picture cast rays: through the solve's intersector, or
    // one built for them (the methods that cast none).
    let clock = Clock::start();
    let built = solved.intersector_after(job)?;
    let rays = solved.isect.map(|(i, _)| i).or(built.as_ref());
    let refined = refine::refine(job, &solved, rays, log);
    timings.elements = clock.seconds();
    timings.peak.elements = report::peak_mib();
    let measured = daylight::measure_grid(job, &solved, log)?;
    let clock = Clock::start();
    let picture = picture::picture(job, &solved, rays, &refined, log)?;
    timings.picture = clock.seconds();
    timings.peak.picture = report::peak_mib();
    let warnings = outputs::warnings(&solved, log);

    progress.phase("writing outputs");
    let results = outputs::Results {
        refined,
        measured,
        picture,
        warnings,
    };
    let summary = outputs::write(job, &solved, results, timings, after, written)?;
    progress.finish();
    Ok(summary)
}

/// `radiosity info`.
pub fn info(
    source: &SceneSource,
    load: &LoadOptions,
    mesh_opts: &MeshOptions,
) -> Result<report::SceneInfo, Error> {
    load.check()?;
    let mut model = Model::load(source, load, mesh_opts)?;
    // The hidden sides need rays: Embree (or the plane merge) over the patches, as a solve's.
    let (isect, _) = model.intersector(IntersectorKind::default())?;
    model.mesh.contacts = model.mesh.find_contacts();
    model.find_hidden(&isect, crate::solve::SolveSettings::default().seed);
    Ok(report::scene_info(
        &model.scene,
        &model.mesh,
        mesh::default_patch_size(&model.scene),
    ))
}
