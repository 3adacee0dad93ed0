//! `radiosity reference` and `radiosity compare`: the paper's error and speed analyses.

use super::args::{source, SamplingArgs, SceneArgs};
use crate::out;
use clap::Args;
use radiosity::compare::{self, CompareJob, ReferenceJob};
use radiosity::solve::settings::{REFERENCE_STOP, REFERENCE_TOLERANCE};
use radiosity::solve::{MethodKind, SolveSettings};
use std::path::PathBuf;

#[derive(Args)]
pub struct ReferenceArgs {
    /// OBJ file (with its MTL beside it); the built-in Cornell box if left out.
    scene: Option<PathBuf>,
    #[command(flatten)]
    scene_args: SceneArgs,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
    #[command(flatten)]
    sampling: SamplingArgs,
}

#[derive(Args)]
pub struct CompareArgs {
    /// OBJ file (with its MTL beside it); the built-in Cornell box if left out.
    scene: Option<PathBuf>,
    #[command(flatten)]
    scene_args: SceneArgs,
    /// Methods to run, in order; speedups are of the first over each other.
    #[arg(
        long,
        value_enum,
        value_delimiter = ',',
        default_value = "adaptive-hybrid,adaptive-rays,adaptive-hemicube,hemicube,hemicube-jittered,gathering"
    )]
    methods: Vec<MethodKind>,
    /// Time budget per method in seconds (gathering always finishes its matrix).
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true)]
    budget: f64,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
    /// A reference patch table of the same scene and patch size (default: build one, as
    /// `radiosity reference` does, and write it to OUT/reference/patches.csv).
    #[arg(long, value_name = "PATCHES.csv")]
    reference: Option<PathBuf>,
    /// Tolerance of the reference built here.
    #[arg(long, default_value_t = REFERENCE_TOLERANCE, allow_negative_numbers = true)]
    reference_tolerance: f64,
    /// Stop fraction of the reference built here.
    #[arg(long, default_value_t = REFERENCE_STOP, allow_negative_numbers = true)]
    reference_stop: f64,
    /// Error levels (fractions: 0.05 = 5 %) of the time-to-error table.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "0.2,0.1,0.05,0.03,0.02,0.01",
        allow_negative_numbers = true
    )]
    levels: Vec<f64>,
    /// Run every method this many times in interleaved rounds and keep each one's run of
    /// median solve time (steadier figures for solves of milliseconds).
    #[arg(long, default_value_t = 1, value_name = "N")]
    repeat: usize,
    /// Seed, tolerance, stop fraction, hemi-cube resolution, … of the compared runs.
    #[command(flatten)]
    sampling: SamplingArgs,
}

pub fn reference(a: ReferenceArgs) -> Result<(), radiosity::Error> {
    let job = ReferenceJob {
        source: source(a.scene),
        load: a.scene_args.load(),
        mesh: a.scene_args.mesh(),
        solve: a.sampling.over(SolveSettings::reference(1)),
        intersector: a.sampling.intersector,
        out: a.out,
    };
    compare::run_reference(&job, |line| eprintln!("{line}")).map(|_| ())
}

pub fn compare(a: CompareArgs) -> Result<(), radiosity::Error> {
    let solve = a.sampling.over(SolveSettings::default());
    let job = CompareJob {
        source: source(a.scene),
        load: a.scene_args.load(),
        mesh: a.scene_args.mesh(),
        methods: a.methods,
        budget: a.budget,
        reference: a.reference,
        reference_solve: SolveSettings {
            tolerance: a.reference_tolerance,
            stop_fraction: a.reference_stop,
            ..SolveSettings::reference(solve.seed.wrapping_add(1_000_003))
        },
        solve,
        intersector: a.sampling.intersector,
        levels: a.levels,
        repeat: a.repeat,
        out: a.out.clone(),
    };
    let cmp = compare::run_compare(&job, |line| eprintln!("{line}"))?;
    out!("{}", compare::report::markdown(&cmp));
    eprintln!("outputs in {}", a.out.display());
    Ok(())
}
