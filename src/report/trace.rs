//! `trace.csv`: the error-against-time trace of a solve, one row per trace point.
//!
//! Columns: `time_s,shots,rays,cells,max_unshot_b,mean_b,unshot_flux,` then the solver's own
//! estimate `est_energy,est_weighted_percent,est_rms`, then the error against the reference
//! `energy,weighted_percent,rms` (empty without `--reference`). Errors are fractions
//! (0.01 = 1 %), radiosities W/m², fluxes W.

use crate::solve::TracePoint;
use std::io::{self, Write};

pub const HEADER: &str = "time_s,shots,rays,cells,max_unshot_b,mean_b,unshot_flux,est_energy,est_weighted_percent,est_rms,energy,weighted_percent,rms";

/// Writes the trace, header first.
pub fn write(w: &mut dyn Write, trace: &[TracePoint]) -> io::Result<()> {
    writeln!(w, "{HEADER}")?;
    for p in trace {
        write_row(w, p)?;
    }
    Ok(())
}

/// Writes one trace point as a row of [`HEADER`]'s columns.
pub fn write_row(w: &mut dyn Write, p: &TracePoint) -> io::Result<()> {
    write!(
        w,
        "{},{},{},{},{},{},{},{},{},{}",
        p.time_s,
        p.shots,
        p.rays,
        p.cells,
        p.max_unshot_b,
        p.mean_b,
        p.unshot_flux,
        p.estimate.energy,
        p.estimate.weighted_percent,
        p.estimate.rms_relative
    )?;
    match &p.error {
        Some(e) => writeln!(w, ",{},{},{}", e.energy, e.weighted_percent, e.rms_relative),
        None => writeln!(w, ",,,"),
    }
}
