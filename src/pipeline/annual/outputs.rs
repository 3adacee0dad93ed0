//! What `radiosity annual` writes (README "Annual daylight"): the year's matrices and hours,
//! the coefficients, the metrics per sensor and their plans, the grid and the summary.

use super::{run, Annual, AnnualJob};
use crate::annual::{self, hourly, AnnualMetrics, MatrixFormat, Period, Series};
use crate::error::Error;
use crate::grid;
use crate::pipeline::daylight::PLAN_WIDTH;
use crate::pipeline::stages::Clock;
use crate::progress::Progress;
use serde_json::json;
use std::path::Path;

/// Runs the year ([`run`]), computes its metrics and writes everything into the job's folder
/// (README "Annual daylight"); returns the lines to print.
pub fn run_and_write(
    job: &AnnualJob,
    progress: &Progress,
    log: &mut impl FnMut(&str),
) -> Result<Vec<String>, Error> {
    let out = &job.solve.out;
    // Settings first, then the folders (so a refused flag leaves nothing behind); on any
    // failure the folders made here are taken away again.
    job.coefficient_job()?;
    let made = crate::export::prepare_dir(&out.join("annual"))?;
    let result = run_into(job, progress, log);
    if result.is_err() {
        crate::export::remove_made_dirs(&made);
    }
    result
}

/// [`run_and_write`] once the folder is made.
fn run_into(
    job: &AnnualJob,
    progress: &Progress,
    log: &mut impl FnMut(&str),
) -> Result<Vec<String>, Error> {
    let out = &job.solve.out;
    let mut a = run(job, progress, log)?;
    progress.phase("writing outputs");
    let clock = Clock::start();
    let period = Period::from_weather(&a.weather);
    let series = Series {
        period: &period,
        rows: &a.year.hours,
        sensors: a.year.sensors,
        lux: &a.year.illuminance,
        sun_lux: &a.year.direct_sun,
    };
    let weights = annual::indoor_weights(&a.zones);
    let metrics = annual::annual_metrics(&series, &weights, &job.occupancy, &job.thresholds)?;
    write_files(job, &a, &period, &metrics)?;
    a.seconds
        .push(("output", clock.seconds(), clock.cpu_seconds()));
    let summary = summary(job, &a, &metrics);
    let path = out.join("summary.json");
    let text = serde_json::to_string_pretty(&summary).unwrap_or_default();
    crate::export::write_atomic(&path, |w| w.write_all(text.as_bytes()))?;
    Ok(lines(job, &a, &metrics))
}

/// The matrices, hours, coefficients, per-sensor metrics, grid and plans.
fn write_files(
    job: &AnnualJob,
    a: &Annual,
    period: &Period,
    metrics: &AnnualMetrics,
) -> Result<(), Error> {
    let out = &job.solve.out;
    let dir = out.join("annual");
    let (rows, n) = (a.year.hours.len(), a.year.sensors);
    let mut formats = vec![MatrixFormat::Npy];
    if job.csv {
        formats.push(MatrixFormat::Csv);
    }
    for f in formats {
        let name = |stem: &str| dir.join(format!("{stem}.{}", f.extension()));
        annual::write_matrix(&name("illuminance"), &a.year.illuminance, rows, n, f)?;
        annual::write_matrix(&name("direct_sun"), &a.year.direct_sun, rows, n, f)?;
    }
    let c = &a.coefficients;
    annual::write_matrix(
        &dir.join("coefficients.npy"),
        &c.total,
        n,
        c.columns,
        MatrixFormat::Npy,
    )?;
    annual::write_matrix(
        &dir.join("reflected.npy"),
        &c.reflected,
        n,
        c.columns,
        MatrixFormat::Npy,
    )?;
    annual::write_hours_csv(&dir.join("hours.csv"), period, &a.year.hours)?;
    let sensors = &a.sensors;
    annual::write_sensors_csv(
        &dir.join("sensors.csv"),
        sensors,
        &a.zones,
        &metrics.sensors,
    )?;
    let mean = mean_occupied(a, period, job);
    let df = daylight_factors(job, a);
    grid::write_csv(&out.join("grid.csv"), sensors, &mean, &df, &a.zones).map_err(|e| {
        Error::Invalid(format!(
            "{}: cannot write it ({e})",
            out.join("grid.csv").display()
        ))
    })?;
    let spacing = job
        .solve
        .grid
        .as_ref()
        .map_or(0.0, grid::GridSpec::spacing_hint);
    let plan = grid::plan_image(sensors, &mean, &a.frame, spacing, PLAN_WIDTH);
    let path = out.join("grid.png");
    plan.save(&path)
        .map_err(|e| Error::Invalid(format!("{}: cannot write it ({e})", path.display())))?;
    annual::write_plans(out, sensors, &a.frame, spacing, PLAN_WIDTH, metrics)?;
    Ok(())
}

/// Each sensor's mean illuminance over the occupied hours (dark ones included), lux: the
/// `lux` column of the annual `grid.csv`.
fn mean_occupied(a: &Annual, period: &Period, job: &AnnualJob) -> Vec<f64> {
    let occupied = job.occupancy.occupied(&period.stamps);
    let hours = occupied.iter().filter(|&&o| o).count().max(1) as f64;
    let n = a.year.sensors;
    let mut sum = vec![0.0f64; n];
    for (row, &h) in a.year.hours.iter().enumerate() {
        if occupied.get(h).copied().unwrap_or(false) {
            let lux = &a.year.illuminance[row * n..(row + 1) * n];
            sum.iter_mut()
                .zip(lux)
                .for_each(|(s, &l)| *s += f64::from(l));
        }
    }
    sum.into_iter().map(|s| s / hours).collect()
}

/// Each sensor's CIE overcast daylight factor, %, from its coefficients.
fn daylight_factors(job: &AnnualJob, a: &Annual) -> Vec<f64> {
    let rho = job
        .solve
        .settings
        .solve
        .sky
        .unwrap_or_default()
        .ground_reflectance;
    let sky = hourly::overcast_columns(job.subdivision, rho);
    hourly::daylight_factors(&a.coefficients, &sky)
}

/// `summary.json`.
fn summary(job: &AnnualJob, a: &Annual, metrics: &AnnualMetrics) -> serde_json::Value {
    let w = &a.weather;
    let c = &a.coefficients;
    let seconds: serde_json::Map<_, _> = a
        .seconds
        .iter()
        .map(|(k, s, _)| (k.to_string(), json!(s)))
        .collect();
    let mut cpu: serde_json::Map<_, _> = a
        .seconds
        .iter()
        .map(|(k, _, s)| (k.to_string(), json!(s)))
        .collect();
    cpu.insert(
        "total".into(),
        json!(a.seconds.iter().map(|s| s.2).sum::<f64>()),
    );
    let channels = c.columns as u64;
    json!({
        "version": env!("CARGO_PKG_VERSION"),
        "scene": a.scene,
        "patches": a.patches,
        "settings": job.solve.settings.to_json(),
        "weather": {
            "file": job.weather.display().to_string(),
            "place": w.location.name,
            "latitude": w.location.latitude,
            "longitude": w.location.longitude,
            "utc_offset": w.location.utc_offset,
            "hours": w.len(),
            "daylit_hours": a.year.hours.len(),
        },
        "coefficients": {
            "subdivision": c.subdivision,
            "scene_hash": format!("{:016x}", a.scene_hash),
            "from": job.coefficients.as_ref().map(|p| p.display().to_string()),
            "rotate_degrees": job.rotate,
            "columns": c.columns,
            "sensors": c.sensors(),
            "patch_rays": job.patch_rays,
            "grid_rays": job.solve.grid_rays,
            "solver_channel_mib": (48 * channels * a.patches as u64) as f64 / 1048576.0,
            "sensor_coefficients_mib": (8 * channels * c.sensors() as u64) as f64 / 1048576.0,
        },
        "solve": a.solve,
        "rays": a.rays,
        "metrics": metrics.summary,
        "seconds": seconds,
        "cpu_seconds": cpu,
        "peak_mib": crate::report::peak_mib(),
    })
}

/// What the command prints.
fn lines(job: &AnnualJob, a: &Annual, m: &AnnualMetrics) -> Vec<String> {
    let s = &m.summary;
    let t = &s.thresholds;
    let dir: &Path = &job.solve.out;
    let cpu: f64 = a.seconds.iter().map(|s| s.2).sum();
    vec![
        format!(
            "annual: {} daylit hours × {} sensors, {} occupied hours ({}–{} h, daylight saving {})",
            a.year.hours.len(),
            a.year.sensors,
            s.occupied_hours,
            job.occupancy.start,
            job.occupancy.end,
            job.occupancy.dst.name()
        ),
        format!(
            "sDA{}/{}%: {:.1} %   ASE{},{}h: {:.1} %   DA{} mean {:.1} %",
            t.da_lux,
            t.sda_percent,
            s.sda_percent,
            t.ase_lux,
            t.ase_hours,
            s.ase_percent,
            t.da_lux,
            s.da_mean_percent
        ),
        format!(
            "UDI fell short {:.1} %, useful {:.1} %, exceeded {:.1} %   EN 17037: {}",
            s.udi_fell_short_percent, s.udi_useful_percent, s.udi_exceeded_percent, s.en17037.level
        ),
        format!("written into {} ({:.1} s CPU)", dir.display(), cpu),
    ]
}
