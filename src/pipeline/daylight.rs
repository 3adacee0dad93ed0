//! The measure stage of a solve (docs/design.md §1): the sensor grid of `--grid`, measured on the solution, with its
//! false-colour plan and statistics (written as `grid.csv` and `grid.png`).

use super::stages::{Clock, Solved};
use super::SolveJob;
use crate::grid::{self, GridSpec, GridStats};
use crate::intersect::select::AnyIntersector;
use crate::light::LightAt;
use crate::sky::{Compass, EFFICACY};
use crate::Error;

/// Rays each sensor gathers by default (`--grid-rays`): about 1 % noise per sensor.
pub const DEFAULT_GRID_RAYS: usize = 4096;

/// Width of the plan picture's panels, pixels.
pub const PLAN_WIDTH: u32 = 800;

/// What the measure stage made: the grid's sensors and values, its plan picture (`grid.png`)
/// and the time measuring took (the plan's drawing left out).
pub struct Measured {
    pub grid: GridResult,
    pub plan: image::RgbImage,
    pub seconds: f64,
    pub cpu_seconds: f64,
}

/// Measure: the sensors of `--grid` on the solution (they need the solve's intersector), the
/// plan picture, the statistics logged; `None` without `--grid`.
pub fn measure_grid(
    job: &SolveJob,
    solved: &Solved,
    log: &mut impl FnMut(&str),
) -> Result<Option<Measured>, Error> {
    let Some(spec) = &job.grid else {
        return Ok(None);
    };
    solved.progress.phase("measuring the grid");
    let clock = Clock::start();
    let Some((isect, _)) = solved.isect else {
        return Err(Error::Invalid(
            "--grid needs a method that casts rays (adaptive-hybrid or adaptive-rays)".into(),
        ));
    };
    let frame = frame_of(job);
    let g = measure(job, spec, solved, isect, &frame).map_err(|e| Error::Invalid(e.to_string()))?;
    let (seconds, cpu_seconds) = (clock.seconds(), clock.cpu_seconds());
    let plan = grid::plan_image(&g.sensors, &g.lux, &frame, spec.spacing_hint(), PLAN_WIDTH);
    log(&format!(
        "grid: {} sensors, mean {:.0} lux, min {:.0} lux, uniformity {:.2}, mean daylight factor {:.2} %",
        g.stats.points, g.stats.mean_lux, g.stats.min_lux, g.stats.uniformity, g.stats.mean_df
    ));
    Ok(Some(Measured {
        grid: g,
        plan,
        seconds,
        cpu_seconds,
    }))
}

/// The model's orientation: the sky's zenith and north, else the job's (checked), else the
/// defaults (Y up, north −Z).
pub fn frame_of(job: &SolveJob) -> Compass {
    let (z, n) = job
        .settings
        .solve
        .sky
        .as_ref()
        .map_or((job.zenith, job.north), |s| (s.zenith, s.north));
    Compass::new(z, n).unwrap_or_else(|_| {
        Compass::new(crate::sky::DEFAULT_ZENITH, crate::sky::DEFAULT_NORTH)
            .expect("the default compass is valid")
    })
}

/// A grid's sensors and what they measured.
pub struct GridResult {
    pub sensors: Vec<grid::Sensor>,
    pub lux: Vec<f64>,
    pub df: Vec<f64>,
    pub stats: GridStats,
}

/// Lux at each sensor of `spec` from the solution: the gather at each point
/// ([`LightAt::sensor_irradiance`], `--grid-rays` each, the solve's seed),
/// luminance-weighted, × 179 lm/W; the daylight factor over `df_base` (0 without a sky).
fn measure(
    job: &SolveJob,
    spec: &GridSpec,
    solved: &Solved,
    isect: &AnyIntersector,
    frame: &Compass,
) -> Result<GridResult, grid::GridError> {
    let (mesh, materials) = (&solved.model.mesh, &solved.model.scene.materials);
    let (b, sky) = (&solved.sol.b, solved.sky.as_ref());
    let (rays, seed) = (job.grid_rays, job.settings.solve.seed);
    let sensors = spec.sensors(mesh, isect, frame)?;
    let at: Vec<_> = sensors.iter().map(|s| (s.position, s.normal)).collect();
    let h = LightAt::new(mesh, materials, isect, b, sky, None).sensor_irradiance(&at, rays, seed);
    let luma = crate::export::patches::LUMA;
    let lux: Vec<f64> = h
        .iter()
        .map(|h| EFFICACY * (0..3).map(|c| luma[c] * h[c]).sum::<f64>())
        .map(|l| if l.is_finite() { l.max(0.0) } else { 0.0 })
        .collect();
    let base = sky.map(|s| {
        let (a, b) = s.horizontal_illuminance();
        a + b
    });
    let df: Vec<f64> = lux
        .iter()
        .map(|l| base.filter(|b| *b > 0.0).map_or(0.0, |b| 100.0 * l / b))
        .collect();
    let stats = grid::stats(&lux, &df);
    Ok(GridResult {
        sensors,
        lux,
        df,
        stats,
    })
}
