//! What `radiosity annual` writes (README "Annual daylight"): the year's matrices, its hours,
//! the grid and the summary.

use super::{run, AnnualJob};
use crate::error::Error;
use crate::progress::Progress;

/// Writes a row-major `rows × cols` matrix of f32 as a NumPy `.npy` file.
pub fn write_npy(path: &std::path::Path, rows: usize, cols: usize, v: &[f32]) -> Result<(), Error> {
    use npyz::WriterBuilder;
    crate::export::write_atomic(path, |w| {
        let mut npy = npyz::WriteOptions::new()
            .default_dtype()
            .shape(&[rows as u64, cols as u64])
            .writer(w)
            .begin_nd()?;
        npy.extend(v.iter().copied())?;
        npy.finish()
    })
    .map_err(|e| Error::Invalid(e.to_string()))
}

/// Runs the year ([`run`]) and writes it into the job's folder: `annual/illuminance.npy` and
/// `annual/direct_sun.npy` (float32, daylit hours × sensors, lux), `annual/hours.csv`
/// (`row,hour_of_year,month,day,hour`: the weather file's hour of each row, its centre in
/// local standard time). Returns the lines to print.
pub fn run_and_write(
    job: &AnnualJob,
    progress: &Progress,
    log: &mut impl FnMut(&str),
) -> Result<Vec<String>, Error> {
    let a = run(job, progress, log)?;
    let dir = job.solve.out.join("annual");
    std::fs::create_dir_all(&dir)
        .map_err(|e| Error::Invalid(format!("{}: cannot create it ({e})", dir.display())))?;
    let (rows, cols) = (a.year.hours.len(), a.year.sensors);
    write_npy(
        &dir.join("illuminance.npy"),
        rows,
        cols,
        &a.year.illuminance,
    )?;
    write_npy(&dir.join("direct_sun.npy"), rows, cols, &a.year.direct_sun)?;
    let mut hours = String::from("row,hour_of_year,month,day,hour\n");
    for (row, &h) in a.year.hours.iter().enumerate() {
        let w = &a.weather.hours[h];
        hours += &format!("{row},{h},{},{},{}\n", w.month, w.day, w.hour);
    }
    let path = dir.join("hours.csv");
    crate::export::write_atomic(&path, |w| w.write_all(hours.as_bytes()))
        .map_err(|e| Error::Invalid(format!("{}: cannot write it ({e})", path.display())))?;
    let mean: Vec<f64> = (0..cols)
        .map(|s| {
            let sum: f64 = (0..rows)
                .map(|r| f64::from(a.year.illuminance[r * cols + s]))
                .sum();
            sum / rows.max(1) as f64
        })
        .collect();
    let df = vec![0.0; cols];
    let path = job.solve.out.join("grid.csv");
    crate::grid::write_csv(&path, &a.placed.sensors, &mean, &df, &a.placed.zones)
        .map_err(|e| Error::Invalid(format!("{}: cannot write it ({e})", path.display())))?;
    let mut lines = vec![format!(
        "annual: {} daylit hours × {} sensors into {}",
        rows,
        cols,
        dir.display()
    )];
    for (stage, wall, cpu) in &a.seconds {
        lines.push(format!("  {stage}: {wall:.1} s ({cpu:.1} s CPU)"));
    }
    Ok(lines)
}
