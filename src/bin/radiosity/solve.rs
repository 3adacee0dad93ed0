//! `radiosity solve`.

use super::args::{source, SceneArgs, ShadingArgs, SolverArgs, ViewArgs};
use super::interrupt_flag;
use super::sky_args::SkyArgs;
use crate::outln;
use clap::Args;
use radiosity::elements;
use radiosity::pipeline::{self, RunSettings, SolveJob, DEFAULT_CHECKPOINT_EVERY};
use radiosity::progress::Progress;
use radiosity::solve::lights::GroupBy;
use radiosity::solve::StopReason;
use std::path::PathBuf;

#[derive(Args)]
pub struct SolveArgs {
    /// OBJ file (with its MTL beside it); the built-in Cornell box if left out.
    scene: Option<PathBuf>,
    #[command(flatten)]
    scene_args: SceneArgs,
    #[command(flatten)]
    solve_args: SolverArgs,
    #[command(flatten)]
    sky: SkyArgs,
    #[command(flatten)]
    elements: ElementArgs,
    /// Output folder.
    #[arg(long, default_value = "out")]
    out: PathBuf,
    /// A reference patch table (a patches.csv of the same scene and patch size, e.g. from
    /// `radiosity reference`): the trace then records the error against it.
    #[arg(long, value_name = "PATCHES.csv")]
    reference: Option<PathBuf>,
    #[command(flatten)]
    view: ViewArgs,
    #[command(flatten)]
    shading: ShadingArgs,
    /// Print nothing but errors.
    #[arg(long, short)]
    quiet: bool,
    /// Print the JSON summary on stdout.
    #[arg(long)]
    json: bool,
    /// Also save the solution to this file (read by `render`, `export` and `relight`).
    #[arg(long, value_name = "FILE.rad")]
    save: Option<PathBuf>,
    /// Keep one channel per light (saved with --save), so `radiosity relight` can re-weight
    /// the lights without solving again.
    #[arg(long)]
    per_light: bool,
    /// Write the solver's state to this file (atomically) every --checkpoint-every seconds and
    /// on Ctrl-C; `--resume FILE` continues from it.
    #[arg(long, value_name = "FILE")]
    checkpoint: Option<PathBuf>,
    /// Seconds between checkpoints.
    #[arg(
        long,
        value_name = "SECONDS",
        default_value_t = DEFAULT_CHECKPOINT_EVERY,
        requires = "checkpoint",
        allow_negative_numbers = true
    )]
    checkpoint_every: f64,
    /// Continue a solve from a checkpoint of the same scene and settings.
    #[arg(long, value_name = "FILE")]
    resume: Option<PathBuf>,
    /// With --per-light: one channel per emitting material, or per connected emitting surface.
    #[arg(long, value_enum, default_value_t = GroupBy::default(), requires = "per_light")]
    light_groups: GroupBy,
}

/// Adaptive elements (Cohen et al. 1986): patches shoot, elements receive.
#[derive(Args)]
pub struct ElementArgs {
    /// After the solve, cut each patch into elements where its light changes (shadow edges,
    /// corners, beside lights), each corner's radiosity gathered with rays; the picture,
    /// the exports and elements.csv use them. auto: on for meshes of up to 1,000,000 patches;
    /// off: the elements are the patches.
    #[arg(long, value_enum, default_value_t = ElementsArg::Auto, value_name = "auto|on|off")]
    elements: ElementsArg,
    /// Cut an element while the error of its interpolation (the radiosity gathered at the
    /// points a cut would add, against what its corners interpolate there), relative to its
    /// mean and times its share of its patch's area, exceeds this (with --element-test
    /// corners: while its corners differ by more than this fraction of their mean).
    #[arg(long, value_name = "FRACTION", default_value_t = elements::DEFAULT_THRESHOLD, allow_negative_numbers = true)]
    element_threshold: f64,
    /// The smallest element edge, metres [default: the patch size / 8].
    #[arg(long, value_name = "METRES", allow_negative_numbers = true)]
    element_min_size: Option<f32>,
    /// Rays of each element corner's gather (split: of each indirect node's, 3/8 as many
    /// for each corner's direct light; full wants 256).
    #[arg(long, value_name = "N", default_value_t = elements::DEFAULT_RAYS)]
    element_rays: usize,
    /// At most this many elements per patch in all (the largest differences are cut first).
    #[arg(long, value_name = "FACTOR", default_value_t = elements::DEFAULT_MAX_FACTOR, allow_negative_numbers = true)]
    element_max: f64,
    /// What the threshold applies to, and how an element is cut: halves (the radiosity
    /// gathered at the points a cut would add against the element's interpolation there, its
    /// picture's error; a quad cut in two across the direction the light changes along),
    /// midpoints (the same test, cut in four) or corners (Cohen et al. 1986: the difference
    /// between its corners, cut in four).
    #[arg(long, value_enum, default_value_t = elements::ElementSettings::default().test)]
    element_test: elements::Test,
    /// What each corner gathers: split (the direct light at every corner; the indirect
    /// light, on the patches that see geometry nearby, gathered at their corners, and at their
    /// edge midpoints and centre where those differ, interpolated beneath, elsewhere the patch
    /// solution's), full (the whole light, direct and hemisphere
    /// rays, at every corner: about 14× split's rays at 256) or direct (the emitters' and the
    /// sun's light by shadow rays; the indirect light interpolated from the patch solution: a
    /// preview that misses the indirect light's contact shadows). Every patch's elements are
    /// scaled to its solved radiosity on average.
    #[arg(long, value_enum, default_value_t = elements::ElementSettings::default().light)]
    element_light: elements::CornerLight,
}

/// `--elements`.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ElementsArg {
    Auto,
    On,
    Off,
}

impl ElementArgs {
    pub fn settings(&self) -> elements::ElementSettings {
        elements::ElementSettings {
            enabled: self.elements != ElementsArg::Off,
            auto_limit: (self.elements == ElementsArg::Auto).then_some(elements::AUTO_MAX_PATCHES),
            threshold: self.element_threshold,
            min_size: self.element_min_size,
            rays: self.element_rays,
            max_factor: self.element_max,
            test: self.element_test,
            light: self.element_light,
        }
    }
}

impl SolveArgs {
    /// The job these flags ask for, its sky checked (before any model is read; the rest of the
    /// settings are checked by the job: [`SolveJob::check`]).
    pub fn job(&self) -> Result<SolveJob, radiosity::Error> {
        let sky = self.sky.settings();
        let solve = radiosity::solve::SolveSettings {
            sky: sky.spec()?,
            ..self.solve_args.solve_settings()
        };
        let (zenith, north) = sky.directions();
        let solve_seed = solve.seed;
        Ok(SolveJob {
            source: source(self.scene.clone()),
            settings: RunSettings {
                // The zenith aims the luminaires (recorded only when there are some).
                load: radiosity::scene::LoadOptions {
                    zenith: (self.scene_args.luminaires.as_ref()).map(|_| zenith.to_array()),
                    ..self.scene_args.load()
                },
                mesh: self.scene_args.mesh(),
                solve,
                intersector: self.solve_args.intersector(),
                per_light: self.per_light.then_some(self.light_groups),
                elements: self.elements.settings(),
            },
            view: self.view.settings()?,
            out: self.out.clone(),
            reference: self.reference.clone(),
            save: self.save.clone(),
            checkpoint: self.checkpoint.clone(),
            checkpoint_every: self.checkpoint_every,
            resume: self.resume.clone(),
            interrupt: None,
            grid: self.sky.grid.clone(),
            grid_rays: self.sky.grid_rays,
            grid_outdoor: self.sky.grid_outdoor,
            zenith,
            north,
            shading: self
                .shading
                .settings(solve_seed, radiosity::render::Shading::Gouraud),
        })
    }
}

pub fn run(a: SolveArgs) -> Result<(), radiosity::Error> {
    let job = SolveJob {
        interrupt: Some(interrupt_flag()),
        ..a.job()?
    };
    job.check()?;
    let quiet = a.quiet || a.json;
    let progress = Progress::for_terminal(quiet);
    let summary = pipeline::run_solve_with(&job, &progress, |line| {
        if !quiet {
            progress.println(line);
        }
    })?;
    drop(progress);
    if a.json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&summary).unwrap_or_default()
        );
    } else if !a.quiet {
        outln!(
            "{}: {} patches, {} shots, {} rays{} in {:.2} s; {}; energy balance residual {:.1e}; outputs in {}{}",
            summary.scene,
            summary.patches,
            summary.shots,
            summary.rays,
            summary
                .final_gather
                .as_ref()
                .map(|g| format!(", {}", radiosity::report::Summary::gather_line(g)))
                .unwrap_or_default(),
            summary.seconds.total,
            summary.error_line(),
            summary.energy.relative_residual,
            a.out.display(),
            a.save
                .as_ref()
                .map(|p| format!(", solution saved to {}", p.display()))
                .unwrap_or_default()
        );
    }
    if summary.stop_reason == Some(StopReason::Interrupted) {
        eprintln!(
            "interrupted: the outputs hold the solution so far{}",
            a.checkpoint
                .as_ref()
                .map(|p| format!("; continue with --resume {}", p.display()))
                .unwrap_or_default()
        );
        std::process::exit(130);
    }
    Ok(())
}
