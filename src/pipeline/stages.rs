//! The stages of a solve up to its result (docs/design.md §1): load the scene, cut it into
//! patches, build the intersector the method needs, solve. Each takes what it needs, logs what a
//! user should hear of, and returns its value; `solve_into` (`super`) calls them in order. What
//! follows the solve reads it through [`Solved`].

use super::SolveJob;
use crate::intersect::select::{AnyIntersector, Selection};
use crate::intersect::Intersector;
use crate::model::Model;
use crate::progress::Progress;
use crate::report::{self, Summary};
use crate::scene::Scene;
use crate::sky::Sky;
use crate::solve::{RunHooks, Solution, TracePoint};
use crate::Error;
use std::time::Instant;

/// The solve's intersector and why it was chosen; `None` for the methods that cast no rays.
pub type SolveIntersector = Option<(AnyIntersector, Selection)>;

/// A finished solve: what the stages after it (refine, measure, picture, write) read.
pub struct Solved<'a> {
    pub model: &'a Model,
    /// The solve's intersector (`None`: the method casts no rays).
    pub isect: Option<&'a (AnyIntersector, Selection)>,
    pub sol: Solution,
    /// The solve's sky, if any: the patch table's daylight columns, the elements, the grid and
    /// the gathered picture see the same one.
    pub sky: Option<Sky>,
    /// When the run started (the elements keep to what is left of `--max-time`; the total time).
    pub t0: Instant,
    /// The bars (the elements and the gathered picture have theirs).
    pub progress: &'a Progress,
}

/// Wall and CPU time of one stage.
pub struct Clock {
    wall: Instant,
    cpu: f64,
}

impl Clock {
    pub fn start() -> Clock {
        Clock {
            wall: Instant::now(),
            cpu: report::process_cpu_seconds(),
        }
    }

    /// Wall seconds since the start.
    pub fn seconds(&self) -> f64 {
        self.wall.elapsed().as_secs_f64()
    }

    /// Process CPU seconds since the start.
    pub fn cpu_seconds(&self) -> f64 {
        report::process_cpu_seconds() - self.cpu
    }
}

/// Load: reads the scene, logging its warnings.
pub fn load(
    job: &SolveJob,
    progress: &Progress,
    log: &mut impl FnMut(&str),
) -> Result<Scene, Error> {
    progress.phase("loading");
    let scene = job.source.load(&job.settings.load)?;
    for w in &scene.warnings {
        log(&format!("warning: {w}"));
    }
    Ok(scene)
}

/// Mesh: cuts the scene into patches, logging the patch size chosen and the counts.
pub fn mesh(
    job: &SolveJob,
    scene: Scene,
    progress: &Progress,
    log: &mut impl FnMut(&str),
) -> Result<Model, Error> {
    let s = &job.settings;
    progress.phase("meshing");
    let model = Model::from_scene(scene, &s.mesh)?;
    if s.mesh.patch_size.is_none() {
        let from = if model.scene.patch_size_hint.is_some() {
            "the scene file's own"
        } else {
            "derived from the scene"
        };
        log(&format!(
            "patch size {} m ({from}; --patch-size to change)",
            model.mesh.patch_size
        ));
    }
    log(&format!(
        "{}: {} polygons, {} patches",
        model.scene.name,
        model.scene.polygons.len(),
        model.mesh.patches.len()
    ));
    Ok(model)
}

/// Intersect: builds the intersector, only for the methods that cast rays (a scene builds what
/// it needs), logging the one chosen and why.
pub fn intersect(
    job: &SolveJob,
    model: &Model,
    progress: &Progress,
    log: &mut impl FnMut(&str),
) -> Result<SolveIntersector, Error> {
    let s = &job.settings;
    progress.phase("building the intersectors");
    let isect = model.intersector_for(s.solve.method, s.intersector)?;
    if let Some((isect, chosen)) = &isect {
        log(&format!("intersector {}: {}", isect.name(), chosen.reason));
    }
    Ok(isect)
}

/// Solve: runs the method with the job's hooks (reference, per-light channels, checkpoints,
/// resume, Ctrl-C; [`super::hooks::build`]), the solve's bar fed by its trace, and logs its
/// counters.
pub fn solve(
    job: &SolveJob,
    model: &Model,
    isect: Option<&(AnyIntersector, Selection)>,
    hooks: &RunHooks,
    progress: &Progress,
    log: &mut impl FnMut(&str),
) -> Result<Solution, Error> {
    progress.start_solve(model.emitted_flux());
    let sol = model.solve(
        isect.map(|(i, _)| i),
        &job.settings.solve,
        hooks,
        |p: &TracePoint| progress.solve_wave(p),
    )?;
    log(&format!("solved: {}", Summary::stats_line(&sol.stats)));
    Ok(sol)
}

/// The solve's sky, for the stages after the solve (the solver builds its own from the same
/// settings).
pub fn sky(job: &SolveJob) -> Option<Sky> {
    job.settings
        .solve
        .sky
        .as_ref()
        .and_then(|s| Sky::new(s).ok())
}

impl Solved<'_> {
    /// The intersector of the stages after the solve that cast rays (the elements, the gathered
    /// picture): the solve's, or one built for them when they need rays and the method cast none.
    pub fn intersector_after(&self, job: &SolveJob) -> Result<Option<AnyIntersector>, Error> {
        let needs_rays = job
            .settings
            .elements
            .applies_to(self.model.mesh.patches.len())
            || job.shading.shading == crate::render::Shading::Gather;
        if self.isect.is_none() && needs_rays {
            Ok(Some(self.model.intersector(job.settings.intersector)?.0))
        } else {
            Ok(None)
        }
    }
}
