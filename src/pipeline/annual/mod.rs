//! `radiosity annual`: a year of daylight at the grid's sensors from one solve (docs/design.md
//! §9, annual daylight). The stages, in order:
//!
//! 1. **weather**: the weather file read and each hour's sky made (Perez over the Reinhart
//!    patches, the sun kept apart: [`crate::sky::SkyMatrix`]) before any model is read, so
//!    a bad file costs nothing;
//! 2. **load, mesh, intersect, sides** as `solve` does; the model's own lights are left dark
//!    (daylight alone is studied);
//! 3. **solve** under the unit sky of daylight coefficients ([`crate::sky::Sky::coefficients`]), one light
//!    channel per sky patch and one for the ground; resumable as `solve` (`--checkpoint`,
//!    `--resume`);
//! 4. **coefficients** at the sensors ([`LightAt::sensor_coefficients`]);
//! 5. **the year**: each hour the coefficients times its sky, the sun's reflected light
//!    through the patch that holds it and its direct light by shadow rays
//!    ([`crate::annual::hourly`]).

use super::stages::{self, Clock};
use super::{hooks, SolveJob};

mod outputs;
mod reuse;
use crate::annual::hourly::{self, Coefficients, Year};
use crate::error::Error;
use crate::grid::Sensor;
use crate::light::coefficients::SensorCoefficients;
use crate::light::{LightAt, Rgb};
use crate::progress::Progress;
use crate::sky::{Sampling, SkyMatrix, SkyOptions, SunMode};
use crate::solve::lights::{self, LightGroups};
use crate::weather::Weather;
use glam::Vec3;
pub use outputs::run_and_write;
use std::path::PathBuf;
use std::sync::Arc;

/// Rays per sky patch of each sensor's direct view by default (`--patch-rays`).
pub const DEFAULT_PATCH_RAYS: usize = 32;

/// What `radiosity annual` is asked: the solve's job (the model, its mesh and solver settings,
/// the sky's orientation and ground reflectance, the grid, checkpoints), the weather file and
/// the sky's subdivision.
#[derive(Clone, Debug)]
pub struct AnnualJob {
    pub solve: SolveJob,
    pub weather: PathBuf,
    /// The Reinhart subdivision MF (1: Tregenza's 145 patches).
    pub subdivision: u32,
    /// Rays per sky patch of each sensor's direct view.
    pub patch_rays: usize,
    /// When the metrics count hours (`--occupied`, `--dst`, `--weekdays-only`).
    pub occupancy: crate::annual::Occupancy,
    pub thresholds: crate::annual::Thresholds,
    /// Also write the hourly matrices as CSV (`--csv`).
    pub csv: bool,
    /// The folder of an earlier run whose coefficients to use instead of solving
    /// (`--coefficients`).
    pub coefficients: Option<PathBuf>,
    /// Turn the model this many degrees clockwise seen from above (`--rotate`).
    pub rotate: f64,
}

/// What the run computed, before anything is written.
pub struct Annual {
    /// The model's name and patch count.
    pub scene: String,
    pub patches: usize,
    /// The model's orientation.
    pub frame: crate::sky::Compass,
    /// The hash of the model and its mesh settings (`--coefficients` checks it).
    pub scene_hash: u64,
    pub weather: Weather,
    /// The sensors, their zones and their coefficients.
    pub sensors: Vec<Sensor>,
    pub zones: Vec<crate::grid::Zone>,
    pub coefficients: Coefficients,
    pub year: Year,
    /// The solve's counters (`None` with `--coefficients`).
    pub solve: Option<crate::solve::SolveStats>,
    /// The stages' seconds (wall, CPU).
    pub seconds: Vec<(&'static str, f64, f64)>,
    /// Rays cast: the solve, the sensors' coefficients, the direct sun.
    pub rays: u64,
}

impl AnnualJob {
    /// The solve job as the annual run solves it: the unit sky of daylight coefficients in the
    /// job's orientation and the job's ground reflectance.
    pub(crate) fn coefficient_job(&self) -> Result<SolveJob, Error> {
        let mut job = self.solve.clone();
        let spec = crate::sky::SkySpec {
            zenith: job.zenith,
            north: job.north,
            ..job.settings.solve.sky.unwrap_or_default()
        };
        job.settings.solve.sky = Some(spec);
        job.settings.solve.sky_coefficients = Some(crate::sky::CoefficientSky {
            subdivision: self.subdivision,
            only: None,
        });
        job.settings.per_light = None;
        job.check()?;
        if job.grid.is_none() {
            return Err(Error::Invalid(
                "annual: --grid is needed (HEIGHT,SPACING or POINTS.csv): the year is computed at its sensors".into(),
            ));
        }
        if !job.settings.solve.method.casts_rays() {
            return Err(Error::Invalid(
                "annual needs a method that casts rays (adaptive-hybrid or adaptive-rays)".into(),
            ));
        }
        self.occupancy.validate()?;
        self.thresholds.validate()?;
        if !self.rotate.is_finite() {
            return Err(Error::Invalid(format!(
                "--rotate: {} is not a number of degrees",
                self.rotate
            )));
        }
        if self.patch_rays == 0 {
            return Err(Error::Invalid("--patch-rays must be at least 1".into()));
        }
        Ok(job)
    }
}

/// The weather file's skies: one row per hour, ground first, the sun apart.
fn skies(job: &AnnualJob, ground: f64) -> Result<(Weather, SkyMatrix), Error> {
    let weather = Weather::read(&job.weather).map_err(|e| Error::Invalid(e.to_string()))?;
    let mut hours = weather
        .sky_hours()
        .map_err(|e| Error::Invalid(format!("{}: {}", job.weather.display(), e.0)))?;
    reuse::rotate(&mut hours, job.rotate);
    let options = SkyOptions {
        subdivision: job.subdivision,
        ground_reflectance: ground,
        sun: SunMode::Separate,
        sampling: Sampling::Centre,
    };
    let sky = SkyMatrix::build(&hours, options)
        .map_err(|e| Error::Invalid(format!("{}: {}", job.weather.display(), e.0)))?;
    Ok((weather, sky))
}

/// The channels of the coefficient sky: the ground's, then each sky patch's.
fn coefficient_groups(subdivision: u32, patches: usize) -> LightGroups {
    let sky = crate::sky::reinhart::sky_patch_count(subdivision);
    let mut names = vec![lights::GROUND_CHANNEL.to_string()];
    names.extend((0..sky).map(lights::sky_patch_channel));
    LightGroups {
        names,
        of_patch: vec![u32::MAX; patches],
    }
}

/// Runs the stages of the module notes; writes nothing.
pub fn run(
    job: &AnnualJob,
    progress: &Progress,
    log: &mut impl FnMut(&str),
) -> Result<Annual, Error> {
    let solve_job = job.coefficient_job()?;
    let mut seconds = Vec::new();
    let clock = Clock::start();
    let spec = solve_job.settings.solve.sky.unwrap_or_default();
    let (weather, sky_matrix) = skies(job, spec.ground_reflectance)?;
    log(&format!(
        "weather: {} ({}), {} hours",
        job.weather.display(),
        weather.location.name,
        weather.len()
    ));
    seconds.push(("weather", clock.seconds(), clock.cpu_seconds()));

    let clock = Clock::start();
    let mut scene = stages::load(&solve_job, progress, log)?;
    darken(&mut scene, log);
    let mut model = stages::mesh(&solve_job, scene, progress, log)?;
    let isect = stages::intersect(&solve_job, &model, progress, log)?;
    stages::sides(&solve_job, &mut model, isect.as_ref(), progress, log);
    stages::lit_backs(&solve_job, &mut model, isect.as_ref(), progress, log)?;
    seconds.push(("model", clock.seconds(), clock.cpu_seconds()));
    let Some((isect_ref, _)) = isect.as_ref() else {
        return Err(Error::Invalid(
            "annual needs a method that casts rays".into(),
        ));
    };

    let sky = solve_job
        .settings
        .solve
        .build_sky()?
        .ok_or_else(|| Error::Invalid("annual: no sky".into()))?;
    let frame = *sky.compass();
    let hash = crate::export::solution::scene_hash(
        &model.scene,
        model.mesh.patch_size,
        solve_job.settings.mesh.two_sided,
    );
    let zero = vec![[0.0; 3]; model.mesh.patches.len()];
    let materials = &model.scene.materials;
    let (found, stats) = match &job.coefficients {
        Some(dir) => {
            let r = reuse::read(dir, hash, job.subdivision)?;
            log(&format!(
                "coefficients of {} sensors read from {} (no solve)",
                r.sensors.len(),
                dir.display()
            ));
            (r, None)
        }
        None => {
            let (r, stats) = solve_for(
                &solve_job,
                job,
                &model,
                isect.as_ref(),
                &sky,
                progress,
                log,
                &mut seconds,
            )?;
            (r, Some(stats))
        }
    };
    let clock = Clock::start();
    progress.phase("the year");
    let at: Vec<(Vec3, Vec3)> = (found.sensors.iter())
        .map(|s: &Sensor| (s.position, s.normal))
        .collect();
    let light = LightAt::new(&model.mesh, materials, isect_ref, &zero, Some(&sky), None);
    let suns = hourly::sun_hours(&sky_matrix, job.subdivision);
    let luma = Rgb::from_array(crate::export::patches::LUMA);
    let view = |h: usize| match sky_matrix.sun(h) {
        Some(beam) => {
            let dir = frame.to_world(beam.dir).as_vec3().normalize();
            light.sun_view(&at, &[dir], luma)
        }
        None => Vec::new(),
    };
    let year = hourly::year(&found.coefficients, &sky_matrix, &suns, &view);
    let sun_rays = (year.hours.iter())
        .filter(|&&h| sky_matrix.sun(h).is_some())
        .count() as u64
        * at.len() as u64;
    seconds.push(("year", clock.seconds(), clock.cpu_seconds()));
    log(&format!(
        "the year: {} daylit hours × {} sensors",
        year.hours.len(),
        year.sensors
    ));
    Ok(Annual {
        scene: model.scene.name.clone(),
        scene_hash: hash,
        patches: model.mesh.patches.len(),
        frame,
        weather,
        sensors: found.sensors,
        zones: found.zones,
        coefficients: found.coefficients,
        year,
        rays: stats.as_ref().map_or(0, |s: &Solved| s.rays) + sun_rays,
        solve: stats.map(|s| s.stats),
        seconds,
    })
}

/// What solving for the coefficients gave besides them: the solve's counters and the rays of
/// the solve and the sensors.
struct Solved {
    stats: crate::solve::SolveStats,
    rays: u64,
}

/// The solve under the coefficient sky and the sensors' coefficients (stages 3 and 4).
#[allow(clippy::too_many_arguments)] // the stage's inputs, each a different thing; used once
fn solve_for(
    solve_job: &SolveJob,
    job: &AnnualJob,
    model: &crate::model::Model,
    isect: Option<&(
        crate::intersect::select::AnyIntersector,
        crate::intersect::select::Selection,
    )>,
    sky: &crate::sky::Sky,
    progress: &Progress,
    log: &mut impl FnMut(&str),
    seconds: &mut Vec<(&'static str, f64, f64)>,
) -> Result<(reuse::Reused, Solved), Error> {
    let mut run_hooks = hooks::build(solve_job, model, log)?;
    let groups = coefficient_groups(job.subdivision, model.mesh.patches.len());
    log(&format!(
        "daylight coefficients: {} channels (the ground and {} sky patches, MF {})",
        groups.len(),
        groups.len() - 1,
        job.subdivision
    ));
    run_hooks.light_groups = Some(Arc::new(groups));
    let clock = Clock::start();
    let sol = stages::solve(solve_job, model, isect, &run_hooks, progress, log)?;
    seconds.push(("solve", clock.seconds(), clock.cpu_seconds()));
    if sol.stats.stop_reason == Some(crate::solve::StopReason::Interrupted) {
        let resume = (solve_job.checkpoint.as_ref())
            .map(|p| format!("; continue with --resume {}", p.display()))
            .unwrap_or_default();
        return Err(Error::Interrupted(format!(
            "interrupted: nothing written (a year from a part-solved sky would mislead){resume}"
        )));
    }

    let clock = Clock::start();
    progress.phase("daylight coefficients at the sensors");
    let Some((isect, _)) = isect else {
        return Err(Error::Invalid(
            "annual needs a method that casts rays".into(),
        ));
    };
    let spec_grid = solve_job.grid.as_ref().expect("checked by coefficient_job");
    let placed = spec_grid
        .place(&model.mesh, isect, sky.compass(), solve_job.grid_outdoor)
        .map_err(|e| Error::Invalid(e.to_string()))?;
    if let Some(w) = &placed.warning {
        log(&format!("warning: {w}"));
    }
    let at: Vec<(Vec3, Vec3)> = (placed.sensors.iter())
        .map(|s: &Sensor| (s.position, s.normal))
        .collect();
    let materials = &model.scene.materials;
    let light =
        LightAt::for_coefficients(&model.mesh, materials, isect, &sol.b, &sol.channels, sky);
    let seed = solve_job.settings.solve.seed;
    let sc: Vec<SensorCoefficients> =
        light.sensor_coefficients(&at, solve_job.grid_rays, job.patch_rays, seed);
    let rays = sol.stats.rays + sc.iter().map(|s| s.rays).sum::<u64>();
    let coefficients = Coefficients::new(job.subdivision, &sc, crate::export::patches::LUMA);
    seconds.push(("coefficients", clock.seconds(), clock.cpu_seconds()));
    let found = reuse::Reused {
        coefficients,
        sensors: placed.sensors,
        zones: placed.zones,
    };
    Ok((
        found,
        Solved {
            stats: sol.stats,
            rays,
        },
    ))
}

/// Leaves the model's own lights dark: annual daylight studies the sky and the sun alone.
fn darken(scene: &mut crate::scene::Scene, log: &mut impl FnMut(&str)) {
    let lit = scene.materials.iter().filter(|m| m.is_emitter()).count();
    for m in &mut scene.materials {
        m.ke = [0.0; 3];
    }
    let luminaires = scene.luminaires.len();
    scene.luminaires.clear();
    let sun = scene.sun.take().is_some();
    if lit + luminaires > 0 || sun {
        log(&format!(
            "annual daylight: the model's own lights are left dark ({lit} emitting materials, {luminaires} luminaires{})",
            if sun { ", its directional light" } else { "" }
        ));
    }
}
