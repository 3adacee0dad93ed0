//! `radiosity annual`.

use super::args::{parse_floats, parse_vec3, source, SceneArgs, SolverArgs, Xyz};
use super::interrupt_flag;
use crate::outln;
use clap::Args;
use glam::Vec3;
use radiosity::annual::{Dst, Occupancy, Thresholds};
use radiosity::pipeline::annual::{self, AnnualJob, DEFAULT_PATCH_RAYS};
use radiosity::pipeline::{RunSettings, SolveJob, DEFAULT_CHECKPOINT_EVERY};
use radiosity::progress::Progress;
use radiosity::sky::{SkySettings, DEFAULT_GROUND_REFLECTANCE, DEFAULT_ZENITH};
use std::path::PathBuf;

#[derive(Args)]
pub struct AnnualArgs {
    /// OBJ or glTF model (with its MTL beside it).
    scene: PathBuf,
    /// The weather file: EnergyPlus EPW or Radiance .wea (hourly direct-normal and
    /// diffuse-horizontal irradiance).
    #[arg(long, value_name = "FILE.epw|FILE.wea")]
    weather: PathBuf,
    /// Illuminance sensors: HEIGHT,SPACING in metres (a work plane above each floor, indoors
    /// only, see --grid-outdoor), or a CSV file of points with columns x,y,z,nx,ny,nz.
    #[arg(long, value_name = "HEIGHT,SPACING|POINTS.csv")]
    grid: radiosity::grid::GridSpec,
    /// Rays each sensor gathers of the light the model reflects.
    #[arg(long, default_value_t = radiosity::pipeline::daylight::DEFAULT_GRID_RAYS, value_name = "N")]
    grid_rays: usize,
    /// Rays each sensor casts at each sky patch it faces (its direct view of the sky).
    #[arg(long, default_value_t = DEFAULT_PATCH_RAYS, value_name = "N")]
    patch_rays: usize,
    /// The work plane's outdoor sensors: drop or keep.
    #[arg(long, value_enum, default_value_t = radiosity::grid::Outdoor::Drop, value_name = "drop|keep")]
    grid_outdoor: radiosity::grid::Outdoor,
    /// The sky's Reinhart subdivision MF: 1 is Tregenza's 145 patches, 2 gives 577, 4 gives
    /// 2,305 (one light channel each: memory grows with it).
    #[arg(long, default_value_t = 1, value_name = "MF")]
    subdivision: u32,
    /// The occupied hours START,END on the clock, hours: an hour counts when its centre is in
    /// [START, END) (IES LM-83-12: 8,18, 3,650 hours a year).
    #[arg(long, value_name = "START,END", value_parser = parse_window, default_value = "8,18")]
    occupied: (f64, f64),
    /// Daylight saving: none (LM-83-12 counts local standard time), us (second Sunday of March
    /// to first Sunday of November) or eu (last Sunday of March to last Sunday of October):
    /// the occupied window then starts an hour earlier in standard time.
    #[arg(long, value_enum, default_value_t = Dst::None)]
    dst: Dst,
    /// Count Mondays to Fridays only (no holidays).
    #[arg(long)]
    weekdays_only: bool,
    /// Use the daylight coefficients of an earlier `annual` run (its --out folder) instead of
    /// solving: another weather file, --rotate or other occupied hours at the cost of the
    /// product and the direct sun's shadow rays. The model and its mesh flags must be the run's.
    #[arg(long, value_name = "DIR")]
    coefficients: Option<PathBuf>,
    /// Turn the model DEG degrees clockwise seen from above (its north then points DEG east of
    /// --north): another orientation without solving again (with --coefficients).
    #[arg(
        long,
        value_name = "DEG",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    rotate: f64,
    /// Also write the hourly matrices as CSV (illuminance.csv, direct_sun.csv) beside the .npy.
    #[arg(long)]
    csv: bool,
    /// Reflectance of the ground outside the model, which glows below the horizon.
    #[arg(long, default_value_t = DEFAULT_GROUND_REFLECTANCE, value_name = "RHO", allow_negative_numbers = true)]
    ground_reflectance: f64,
    /// The model's up direction X,Y,Z (CAD exports are often Z-up: 0,0,1).
    #[arg(long, value_parser = Xyz::parse, allow_hyphen_values = true, default_value_t = Xyz(DEFAULT_ZENITH))]
    zenith: Xyz,
    /// The model's north X,Y,Z [default: −Z with the default zenith, +Y with --zenith 0,0,1].
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    north: Option<Vec3>,
    #[command(flatten)]
    scene_args: SceneArgs,
    #[command(flatten)]
    solve_args: SolverArgs,
    /// Output folder.
    #[arg(long, default_value = "out")]
    out: PathBuf,
    /// Write the solve's state to this file every --checkpoint-every seconds and on Ctrl-C;
    /// `--resume FILE` continues from it.
    #[arg(long, value_name = "FILE")]
    checkpoint: Option<PathBuf>,
    /// Seconds between checkpoints.
    #[arg(long, value_name = "SECONDS", default_value_t = DEFAULT_CHECKPOINT_EVERY, requires = "checkpoint", allow_negative_numbers = true)]
    checkpoint_every: f64,
    /// Continue the solve from a checkpoint of the same model and settings.
    #[arg(long, value_name = "FILE")]
    resume: Option<PathBuf>,
    /// Print nothing but errors.
    #[arg(long, short)]
    quiet: bool,
}

impl AnnualArgs {
    /// The job these flags ask for (checked by the library before any model is read).
    fn job(&self) -> Result<AnnualJob, radiosity::Error> {
        let sky = SkySettings {
            ground_reflectance: self.ground_reflectance,
            zenith: self.zenith.0,
            north: self.north,
            ..SkySettings::default()
        };
        let (zenith, north) = sky.directions();
        let solve = radiosity::solve::SolveSettings {
            sky: Some(radiosity::sky::SkySpec {
                ground_reflectance: self.ground_reflectance,
                zenith,
                north,
                ..Default::default()
            }),
            ..self.solve_args.solve_settings()
        };
        let mut job = SolveJob::new(source(Some(self.scene.clone())), self.out.clone());
        job.settings = RunSettings {
            load: self.scene_args.load(),
            mesh: self.scene_args.mesh(),
            solve,
            intersector: self.solve_args.intersector(),
            per_light: None,
            elements: Default::default(),
        };
        job.checkpoint = self.checkpoint.clone();
        job.checkpoint_every = self.checkpoint_every;
        job.resume = self.resume.clone();
        job.interrupt = Some(interrupt_flag());
        job.grid = Some(self.grid.clone());
        job.grid_rays = self.grid_rays;
        job.grid_outdoor = self.grid_outdoor;
        (job.zenith, job.north) = (zenith, north);
        Ok(AnnualJob {
            solve: job,
            weather: self.weather.clone(),
            subdivision: self.subdivision,
            patch_rays: self.patch_rays,
            occupancy: Occupancy {
                start: self.occupied.0,
                end: self.occupied.1,
                dst: self.dst,
                weekdays_only: self.weekdays_only,
                ..Occupancy::default()
            },
            thresholds: Thresholds::default(),
            csv: self.csv,
            coefficients: self.coefficients.clone(),
            rotate: self.rotate,
        })
    }
}

pub fn run(a: AnnualArgs) -> Result<(), radiosity::Error> {
    let job = a.job()?;
    let progress = Progress::for_terminal(a.quiet);
    let quiet = a.quiet;
    let done = annual::run_and_write(&job, &progress, &mut |line: &str| {
        if !quiet {
            progress.println(line);
        }
    })?;
    drop(progress);
    if !a.quiet {
        for line in done {
            outln!("{line}");
        }
    }
    Ok(())
}

fn parse_window(s: &str) -> Result<(f64, f64), String> {
    parse_floats::<2>(s).map(|[a, b]| (a, b))
}
