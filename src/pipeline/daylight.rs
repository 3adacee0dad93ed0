//! The measure stage of a solve (docs/design.md §1): the sensor grid of `--grid`, measured on the solution, with its
//! false-colour plan and statistics (written as `grid.csv` and `grid.png`): outdoor sensors
//! left out unless `--grid-outdoor keep`, the figures of each storey and room logged.

use super::stages::{Clock, Solved};
use super::SolveJob;
use crate::grid::{self, GridReport, GridSpec, GridStats};
use crate::intersect::select::AnyIntersector;
use crate::light::LightAt;
use crate::scene::Scene;
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
    for line in lines(&g.stats, job.settings.solve.sky.is_some()) {
        log(&line);
    }
    if let Some(w) = &g.warning {
        log(&format!("warning: {w}"));
    }
    Ok(Some(Measured {
        grid: g,
        plan,
        seconds,
        cpu_seconds,
    }))
}

/// What the log says of a grid: its figures (the daylight factor under a sky), the outdoor
/// sensors, and one short line per storey and per room when there are several.
fn lines(r: &GridReport, daylit: bool) -> Vec<String> {
    let figures = |s: &GridStats| {
        let df = if daylit {
            format!(", mean daylight factor {:.2} %", s.mean_df)
        } else {
            String::new()
        };
        format!(
            "mean {:.0} lux, min {:.0} lux, max {:.0} lux, U0 {:.2}, Emin/Emax {:.2}{df}",
            s.mean_lux, s.min_lux, s.max_lux, s.uniformity, s.min_over_max
        )
    };
    let mut out = vec![format!(
        "grid: {} sensors, {}",
        r.all.points,
        figures(&r.all)
    )];
    if r.outdoor_points > 0 {
        out.push(if r.dropped_points > 0 {
            format!(
                "grid: {} outdoor sensors left out (nothing over them; --grid-outdoor keep keeps them)",
                r.dropped_points
            )
        } else {
            format!(
                "grid: {} outdoor sensors kept (indoor 0 in grid.csv)",
                r.outdoor_points
            )
        });
    }
    if r.storeys.len() > 1 {
        for s in &r.storeys {
            out.push(format!(
                "  storey {} (+{:.1} m): {} sensors, {:.1} m², {} room{}, {}",
                s.storey,
                s.height,
                s.stats.points,
                s.area,
                s.rooms,
                if s.rooms == 1 { "" } else { "s" },
                figures(&s.stats)
            ));
        }
    }
    if r.rooms.len() > 1 {
        for m in &r.rooms {
            out.push(format!(
                "  room {}.{}: {} sensors, {:.1} m², mean {:.0} lux, min {:.0} lux, U0 {:.2}, DF {:.2} %",
                m.storey,
                m.room,
                m.stats.points,
                m.area,
                m.stats.mean_lux,
                m.stats.min_lux,
                m.stats.uniformity,
                m.stats.mean_df
            ));
        }
    }
    out
}

/// The model's sun: a model that brings its own (a glTF directional light, [`crate::scene::ModelSun`]) is lit
/// by it unless `--sun` places one: under the `--sky` asked for, or under a black sky (uniform,
/// 0 lux: the sun alone, and the ground it lights, as `gensky -s` with `-b 0` would give).
/// Returns the job so changed (the settings recorded and saved are then the ones solved), or
/// `None` when nothing changes.
pub fn model_sun(
    job: &SolveJob,
    scene: &Scene,
    log: &mut impl FnMut(&str),
) -> Result<Option<SolveJob>, Error> {
    use crate::sky::{SkyKind, SkyLevel, SkySpec, SolarAngles, SunLevel};
    let Some(sun) = &scene.sun else {
        return Ok(None);
    };
    let sky = job.settings.solve.sky;
    if sky.is_some_and(|s| s.sun_position.is_some()) {
        log(&format!(
            "the model's directional light '{}' is left out: --sun places the sun",
            sun.name
        ));
        return Ok(None);
    }
    let compass = frame_of(job);
    let local = compass.to_local(sun.towards);
    let angles = SolarAngles::from_local_dir(local)?;
    let (altitude, azimuth) = (angles.altitude, angles.azimuth);
    let spec = SkySpec {
        sun_position: Some(angles),
        sun: Some(SunLevel::NormalIlluminance(sun.illuminance)),
        ..sky.unwrap_or(SkySpec {
            kind: SkyKind::Uniform,
            level: SkyLevel::HorizontalIlluminance(0.0),
            zenith: compass.up().as_vec3(),
            north: compass.north().as_vec3(),
            ..SkySpec::default()
        })
    };
    spec.check()?;
    let under = if sky.is_some() {
        "under the sky asked for"
    } else {
        "under a black sky (--sky for daylight too)"
    };
    log(&format!(
        "sun: the model's directional light '{}', {:.0} lux at altitude {altitude:.1}°, azimuth {azimuth:.1}° west of south, {under}{}",
        sun.name,
        sun.illuminance,
        if sun.white { "" } else { "; its colour is left out (the sun is white)" }
    ));
    let mut out = job.clone();
    out.settings.solve.sky = Some(spec);
    Ok(Some(out))
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

/// A grid's sensors, where each is, and what they measured.
pub struct GridResult {
    pub sensors: Vec<grid::Sensor>,
    /// One per sensor: storey, room, indoors (`grid.csv`'s last columns).
    pub zones: Vec<grid::Zone>,
    pub lux: Vec<f64>,
    pub df: Vec<f64>,
    /// The summary's `grid`.
    pub stats: GridReport,
    /// One line to warn of ([`grid::Placed::warning`]).
    pub warning: Option<String>,
}

/// Lux at each sensor `spec` keeps ([`GridSpec::place`], `--grid-outdoor`) from the solution:
/// the gather at each point
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
    let placed = spec.place(mesh, isect, frame, job.grid_outdoor)?;
    let at: Vec<_> = placed
        .sensors
        .iter()
        .map(|s| (s.position, s.normal))
        .collect();
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
    let stats = GridReport::new(&placed, &lux, &df);
    Ok(GridResult {
        sensors: placed.sensors,
        zones: placed.zones,
        lux,
        df,
        stats,
        warning: placed.warning,
    })
}
