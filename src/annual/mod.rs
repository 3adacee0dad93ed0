//! Annual daylight: a year of hourly illuminance at the grid's sensors, and the figures the
//! standards read from it (docs/design.md §14 and §15).
//!
//! - **The year** ([`hourly`]): each hour's illuminance E and the direct sun's alone E_sun at
//!   every sensor (lux) from the sensors' daylight coefficients and the hour's sky: two
//!   hours × sensors matrices, row-major, f32 ([`Series`]).
//!
//! - **When people are there** ([`schedule`]): the occupied hours, 8 AM to 6 PM local time by
//!   default, with the daylight-saving rules `none` (IES LM-83-12's reading: standard time,
//!   3,650 h a year), `us` and `eu`.
//! - **The metrics** ([`metrics`]): per sensor DA (daylight autonomy), UDI (useful daylight
//!   illuminance: fell short, useful, exceeded) and ASE hours; of the grid sDA300/50%,
//!   ASE1000,250h and the UDI means, each sensor weighted ([`indoor_weights`]: indoor sensors
//!   alike, outdoor ones not counted).
//! - **EN 17037** ([`en17037`]): the level of daylight provision reached (minimum, medium,
//!   high) over the standard's daylight hours.
//! - **Files** ([`files`]): the matrices as `.npy` (and CSV on request), `hours.csv` naming each
//!   row's hour, the per-sensor metrics as CSV; **pictures** ([`plans`]): a plan of each metric
//!   beside `grid.png`.
//!
//! # Conventions
//!
//! - **Hours.** A [`Stamp`] dates each hour as the weather files do ([`crate::weather`]): month,
//!   day and the **centre** of the hour in local **standard** time (EPW's hour 13 is 12.5). The
//!   [`Period`] is every hour of the weather file, daylit or not; the matrices hold a subset of
//!   its hours (the daylit ones), each row naming its hour in the period. An hour of the period
//!   without a row is dark: E = E_sun = 0 at every sensor.
//! - **Counting.** Hours are counted in whole numbers and shares taken once, in f64; a figure
//!   over nothing (no occupied hour, no weight) is 0, never NaN.
//! - **Bad values.** An illuminance that is not finite (NaN, ±∞) is refused
//!   ([`AnnualError::NotFinite`], naming the matrix, the row's date and the sensor): it is a
//!   fault upstream, and counting it as 0 would hide it in a compliance figure. A negative
//!   value is below every threshold and counts as such.

pub mod en17037;
pub mod files;
pub mod hourly;
pub mod metrics;
pub mod plans;
pub mod schedule;

pub use en17037::{daylight_hours, En17037, LevelResult, LEVELS};
pub use files::{
    write_hours_csv, write_matrix, write_sensors_csv, MatrixFormat, HOURS_HEADER, SENSORS_HEADER,
};
pub use metrics::{
    annual_metrics, indoor_weights, AnnualMetrics, AnnualSummary, SensorMetrics, Thresholds,
};
pub use plans::write_plans;
pub use schedule::{Dst, Occupancy};

use crate::settings::Invalid;
use std::path::PathBuf;

/// When an hour is: month 1–12, day of the month, and the centre of the hour in decimal hours
/// of local standard time, in [0, 24) (as [`crate::weather::Hour`]).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Stamp {
    pub month: u32,
    pub day: u32,
    pub hour: f64,
}

impl From<&crate::weather::Hour> for Stamp {
    fn from(h: &crate::weather::Hour) -> Stamp {
        Stamp {
            month: h.month,
            day: h.day,
            hour: h.hour,
        }
    }
}

impl std::fmt::Display for Stamp {
    /// "3 Jan 10:30" (the hour's centre, local standard time).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        const MONTHS: [&str; 12] = [
            "Jan", "Feb", "Mar", "Apr", "May", "Jun", "Jul", "Aug", "Sep", "Oct", "Nov", "Dec",
        ];
        let month = MONTHS
            .get((self.month as usize).wrapping_sub(1))
            .unwrap_or(&"?");
        let minutes = (self.hour.clamp(0.0, 24.0) * 60.0).round() as u32;
        let (h, m) = (minutes / 60, minutes % 60);
        write!(f, "{} {month} {h:02}:{m:02}", self.day)
    }
}

/// The hours of a weather file, daylit or not, in time order: what the occupied hours and
/// EN 17037's daylight hours are counted over.
#[derive(Clone, Debug, PartialEq)]
pub struct Period {
    /// Each hour's date.
    pub stamps: Vec<Stamp>,
    /// Each hour's diffuse horizontal daylight, what EN 17037's daylight hours are ranked by
    /// ([`daylight_hours`]): illuminance (lux) or irradiance (W/m²), one unit for all hours.
    pub diffuse: Vec<f64>,
}

impl Period {
    /// The hours of `weather`, ranked for EN 17037 by the file's diffuse horizontal
    /// illuminance where every hour has it (an EPW without missing values), else by its diffuse
    /// horizontal irradiance (a `.wea`; the two rank alike but for the sky's luminous efficacy,
    /// which varies from hour to hour).
    pub fn from_weather(weather: &crate::weather::Weather) -> Period {
        let lux: Option<Vec<f64>> = weather.iter().map(|h| h.dhi_lux).collect();
        Period {
            stamps: weather.iter().map(Stamp::from).collect(),
            diffuse: lux.unwrap_or_else(|| weather.iter().map(|h| h.dhi).collect()),
        }
    }

    /// The number of hours.
    pub fn len(&self) -> usize {
        self.stamps.len()
    }

    /// Whether there are no hours.
    pub fn is_empty(&self) -> bool {
        self.stamps.is_empty()
    }

    /// Whether the period holds 29 February (a leap-year file): its hours of the year then
    /// count that day ([`files::hour_of_year`]).
    pub fn is_leap(&self) -> bool {
        self.stamps.iter().any(|s| s.month == 2 && s.day == 29)
    }
}

/// The illuminance of a year at the sensors, as the solver gives it: the matrices' rows are
/// hours of `period` (`rows[r]` is row r's index in it, rising), their columns sensors.
#[derive(Clone, Copy, Debug)]
pub struct Series<'a> {
    pub period: &'a Period,
    /// For each row of the matrices, its hour's index in `period`, strictly rising.
    pub rows: &'a [usize],
    /// How many sensors (the matrices' columns).
    pub sensors: usize,
    /// Total illuminance E, lux, `rows.len() × sensors`, row-major.
    pub lux: &'a [f32],
    /// The direct sun's illuminance alone E_sun, lux, the same shape (what ASE counts).
    pub sun_lux: &'a [f32],
}

impl Series<'_> {
    /// Checks the shapes (one value per row and sensor, rows rising within the period, as many
    /// diffuse values as hours) and that every value is finite.
    pub fn validate(&self) -> Result<(), AnnualError> {
        let p = self.period;
        if p.diffuse.len() != p.stamps.len() {
            return Err(invalid(format!(
                "the period has {} hours but {} diffuse values",
                p.stamps.len(),
                p.diffuse.len()
            )));
        }
        if let Some(w) = self.rows.windows(2).find(|w| w[0] >= w[1]) {
            return Err(invalid(format!(
                "rows must name rising hours of the period: {} then {}",
                w[0], w[1]
            )));
        }
        if let Some(k) = p.diffuse.iter().position(|d| !d.is_finite()) {
            return Err(invalid(format!(
                "hour {k}'s diffuse daylight is not finite"
            )));
        }
        if let Some(&r) = self.rows.last().filter(|&&r| r >= p.len()) {
            return Err(invalid(format!(
                "a row names hour {r} of a period of {} hours",
                p.len()
            )));
        }
        for (what, m) in [("lux", self.lux), ("sun_lux", self.sun_lux)] {
            check_matrix(what, m, self.rows.len(), self.sensors, |r| {
                format!(" ({})", p.stamps[self.rows[r]])
            })?;
        }
        Ok(())
    }
}

/// Checks that `values` is `rows × sensors` and finite; `when(r)` dates row r in messages
/// (" (3 Jan 10:30)", or nothing).
pub(crate) fn check_matrix(
    what: &str,
    values: &[f32],
    rows: usize,
    sensors: usize,
    when: impl Fn(usize) -> String,
) -> Result<(), AnnualError> {
    if rows.checked_mul(sensors) != Some(values.len()) {
        return Err(invalid(format!(
            "{what} holds {} values, not {rows} hours × {sensors} sensors",
            values.len()
        )));
    }
    match values.iter().position(|v| !v.is_finite()) {
        Some(k) => Err(AnnualError::NotFinite {
            what: what.to_string(),
            row: k / sensors,
            when: when(k / sensors),
            sensor: k % sensors,
            value: values[k],
        }),
        None => Ok(()),
    }
}

/// Why annual metrics could not be computed or written: one line.
#[derive(Debug, thiserror::Error)]
pub enum AnnualError {
    /// A bad setting (threshold, occupied hours) or inputs that do not fit together.
    #[error("annual metrics: {0}")]
    Invalid(#[from] Invalid),
    /// An illuminance that is not a finite number.
    #[error(
        "annual metrics: {what} at row {row}{when}, sensor {sensor} is {value}, not a finite \
         illuminance"
    )]
    NotFinite {
        /// Which matrix: `lux`, `sun_lux` or the file being written.
        what: String,
        row: usize,
        /// The row's hour, " (3 Jan 10:30)", where known.
        when: String,
        sensor: usize,
        value: f32,
    },
    /// A file could not be written.
    #[error("{path}: cannot write: {source}")]
    Write {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
}

/// `100 k / n` %, 0 when n is 0.
fn percent(k: usize, n: usize) -> f64 {
    ratio(100.0 * k as f64, n as f64)
}

/// `a / b`, 0 when b is 0 (a figure over nothing).
fn ratio(a: f64, b: f64) -> f64 {
    if b > 0.0 {
        a / b
    } else {
        0.0
    }
}

/// An [`AnnualError::Invalid`] saying `message`.
fn invalid(message: impl Into<String>) -> AnnualError {
    AnnualError::Invalid(Invalid(message.into()))
}
