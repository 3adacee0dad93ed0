//! Weather files: an hourly series of solar irradiance at a place, for annual daylight.
//!
//! Two formats are read into one typed, checked series ([`Weather`]):
//!
//! - **EPW**, EnergyPlus Weather (EnergyPlus *Auxiliary Programs*, "Weather Converter
//!   Program", the EPW data dictionary): 8 header lines (`LOCATION`, `DESIGN CONDITIONS`,
//!   `TYPICAL/EXTREME PERIODS`, `GROUND TEMPERATURES`, `HOLIDAYS/DAYLIGHT SAVINGS`,
//!   `COMMENTS 1`, `COMMENTS 2`, `DATA PERIODS`), then one comma-separated row an hour;
//! - **`.wea`**, the input of Radiance's `gendaymtx` as Radiance's `epw2wea` writes it: six
//!   header lines (`place`, `latitude`, `longitude`, `time_zone`, `site_elevation`,
//!   `weather_data_file_units`), then `month day hour DNI DHI` a line.
//!
//! # Conventions
//!
//! - **Place.** [`Location`] counts latitude north positive, longitude **east** positive and
//!   the time zone in hours **east** of UTC (Chicago: 41.98, −87.92, −6), as EPW does and as
//!   [`Site`] and [`DateTime`] do. A `.wea` counts longitude and the standard meridian in
//!   degrees **west** (Chicago: `longitude 87.92`, `time_zone 90`); they are converted on
//!   reading (longitude = −`longitude`, UTC offset = −`time_zone` / 15) and back on writing.
//! - **Time.** Every hour is in local **standard** time (no daylight saving: EPW and `.wea`
//!   files have none). [`Hour::hour`] is the decimal hour of the **centre** of the interval
//!   the values stand for: EPW's hour 13, the hour *ending* 13:00, is 12.5; a `.wea` gives
//!   the centre itself (`epw2wea` writes EPW hour − 0.5). [`Hour::datetime`] gives that
//!   instant as a [`DateTime`].
//! - **Year.** A typical-year file (TMY) takes each month from a different year, so the year
//!   column is not read: the series is a typical non-leap year, dated [`TYPICAL_YEAR`]
//!   (29 February, accepted in a leap-year file, is dated [`LEAP_YEAR`]).
//! - **Units.** Irradiance is W/m²: direct normal (DNI), diffuse horizontal (DHI) and global
//!   horizontal (GHI). EPW gives hourly sums in Wh/m², which are the hour's mean irradiance in
//!   W/m². Illuminance, where the file has it (EPW only), is lux.
//! - **Completeness.** An EPW must hold one row an hour for a whole year in calendar order:
//!   8760 rows (1 Jan hour 1 to 31 Dec hour 24), or 8784 with 29 February. A `.wea` may
//!   hold any list of hours (`gendaymtx` accepts one) but they must run forward in time
//!   within one year, each at most once.
//! - **Missing values.** EPW marks a missing irradiance 9999 and a missing illuminance
//!   999999: a missing DNI or DHI is an error (the sky cannot be made without them), a
//!   missing GHI or illuminance is `None`. Negative values are errors.
//!
//! # Errors
//!
//! A file that cannot be read gives one [`WeatherError`], one line that names the file and,
//! for a malformed file, the 1-based line and what is wrong, e.g. `weather.epw line 12:
//! column 15 (direct normal irradiance) is not a number: "abc"`. No input panics.

mod epw;
mod wea;

#[cfg(test)]
mod tests;

use crate::settings::Invalid;
use crate::sky::matrix::Hour as SkyHour;
use crate::sky::solar::{DateTime, Site};
use std::ops::RangeInclusive;
use std::path::{Path, PathBuf};

/// The year a typical-year series is dated in (not a leap year): see the module docs.
pub const TYPICAL_YEAR: i32 = 2023;

/// The year 29 February of a leap-year file is dated in.
pub const LEAP_YEAR: i32 = 2024;

/// Latitude's range, degrees.
const LATITUDE: RangeInclusive<f64> = -90.0..=90.0;
/// Longitude's range, degrees.
const LONGITUDE: RangeInclusive<f64> = -180.0..=180.0;
/// The time zone's range, hours from UTC.
const UTC_OFFSET: RangeInclusive<f64> = -14.0..=14.0;
/// Elevation's range, m (the EPW data dictionary's).
const ELEVATION: RangeInclusive<f64> = -1000.0..=9999.9;

/// Where the weather was recorded.
#[derive(Clone, Debug, PartialEq)]
pub struct Location {
    /// The place's name: EPW's city, or a `.wea` `place` up to its first `_`.
    pub name: String,
    /// The country: EPW's country, or a `.wea` `place` after its first `_` (empty if none).
    pub country: String,
    /// Latitude, degrees north (south negative).
    pub latitude: f64,
    /// Longitude, degrees **east** (west negative).
    pub longitude: f64,
    /// The standard time zone, hours **east** of UTC (−6 for Chicago).
    pub utc_offset: f64,
    /// Elevation above sea level, m.
    pub elevation: f64,
}

impl Location {
    /// Checks the ranges: |latitude| ≤ 90°, |longitude| ≤ 180°, |UTC offset| ≤ 14 h and the
    /// elevation within [−1000, 9999.9] m (the EPW data dictionary's limits).
    pub fn validate(&self) -> Result<(), Invalid> {
        let checks = [
            (self.latitude, LATITUDE, "latitude", "degrees"),
            (self.longitude, LONGITUDE, "longitude", "degrees"),
            (self.utc_offset, UTC_OFFSET, "time zone", "hours"),
            (self.elevation, ELEVATION, "elevation", "m"),
        ];
        for (value, range, what, unit) in checks {
            if !range.contains(&value) {
                return Invalid::err(format!(
                    "{what} {value} is not within [{}, {}] {unit}",
                    range.start(),
                    range.end()
                ));
            }
        }
        Ok(())
    }

    /// The place as the sun's position wants it (latitude, longitude east). A [`Location`]
    /// read from a file has been validated; one built by hand should call
    /// [`Location::validate`] first.
    pub fn site(&self) -> Site {
        Site {
            latitude: self.latitude,
            longitude: self.longitude,
        }
    }
}

/// One hour of weather: its date, the centre of its interval and the sun's and sky's light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hour {
    /// Month, 1–12.
    pub month: u32,
    /// Day of the month, 1–31 (29 February only in a leap-year file).
    pub day: u32,
    /// The centre of the interval, decimal hours of local standard time in [0, 24): EPW's
    /// hour *h* (hour ending *h*:00) is *h* − 0.5; a `.wea` hour as written.
    pub hour: f64,
    /// Direct normal irradiance, W/m².
    pub dni: f64,
    /// Diffuse horizontal irradiance, W/m².
    pub dhi: f64,
    /// Global horizontal irradiance, W/m² (EPW only; `None` where missing).
    pub ghi: Option<f64>,
    /// Global horizontal illuminance, lux (EPW only; `None` where missing).
    pub ghi_lux: Option<f64>,
    /// Direct normal illuminance, lux (EPW only; `None` where missing).
    pub dni_lux: Option<f64>,
    /// Diffuse horizontal illuminance, lux (EPW only; `None` where missing).
    pub dhi_lux: Option<f64>,
}

impl Hour {
    /// Whether there is any daylight: direct or diffuse irradiance above zero.
    pub fn is_daylit(&self) -> bool {
        self.dni > 0.0 || self.dhi > 0.0
    }

    /// The centre of the hour at `location`, local standard time (no daylight saving), dated
    /// [`TYPICAL_YEAR`] (29 February: [`LEAP_YEAR`]). An hour read from a file gives a date
    /// that passes [`DateTime::validate`].
    pub fn datetime(&self, location: &Location) -> DateTime {
        let year = if self.month == 2 && self.day == 29 {
            LEAP_YEAR
        } else {
            TYPICAL_YEAR
        };
        let h = self.hour.clamp(0.0, 24.0 - 1e-9);
        let whole = h.floor();
        let minutes = (h - whole) * 60.0;
        let minute = minutes.floor();
        let second = ((minutes - minute) * 60.0).min(60.0 - 1e-9);
        DateTime {
            year,
            month: self.month,
            day: self.day,
            hour: whole as u32,
            minute: minute as u32,
            second,
            utc_offset: location.utc_offset,
        }
    }
}

/// The format a series was read from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WeatherSource {
    /// EnergyPlus Weather (`.epw`).
    Epw,
    /// Radiance's `gendaymtx` input (`.wea`).
    Wea,
}

/// An hourly weather series at one place, read and checked (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct Weather {
    /// Where it was recorded.
    pub location: Location,
    /// The hours in time order.
    pub hours: Vec<Hour>,
    /// The format it was read from.
    pub source: WeatherSource,
    /// The file it was read from (`None` when parsed from text).
    pub path: Option<PathBuf>,
}

/// Why a weather file could not be read: one line naming the file (and for a malformed file
/// the 1-based line) and what is wrong.
#[derive(Debug, thiserror::Error)]
pub enum WeatherError {
    /// The file could not be read from disk.
    #[error("{file}: cannot read: {source}")]
    Io {
        /// The file as named.
        file: String,
        /// The system's reason.
        #[source]
        source: std::io::Error,
    },
    /// The extension is neither `.epw` nor `.wea`.
    #[error("{file}: not a known weather file format (name it .epw or .wea)")]
    UnknownFormat {
        /// The file as named.
        file: String,
    },
    /// The file breaks its format.
    #[error("{file} line {line}: {message}")]
    Malformed {
        /// The file as named.
        file: String,
        /// The 1-based line.
        line: usize,
        /// What is wrong.
        message: String,
    },
}

impl Weather {
    /// Reads a weather file, choosing the reader by extension (`.epw`, `.wea`, any case).
    /// Messages name the file by `path` as given.
    pub fn read(path: impl AsRef<Path>) -> Result<Weather, WeatherError> {
        let path = path.as_ref();
        let file = path.display().to_string();
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        let source = match ext.as_deref() {
            Some("epw") => WeatherSource::Epw,
            Some("wea") => WeatherSource::Wea,
            _ => return Err(WeatherError::UnknownFormat { file }),
        };
        let bytes = std::fs::read(path).map_err(|source| WeatherError::Io {
            file: file.clone(),
            source,
        })?;
        let mut weather = Weather::from_bytes(&bytes, &file, source)?;
        weather.path = Some(path.to_path_buf());
        Ok(weather)
    }

    /// Parses a file's bytes in the given format; `name` names the file in messages. Bytes
    /// that are not UTF-8 are read as Latin-1 ([`crate::text::decode`]: an older EPW names
    /// "Zürich" so); a byte-order mark and CRLF line ends are accepted.
    pub fn from_bytes(
        bytes: &[u8],
        name: &str,
        source: WeatherSource,
    ) -> Result<Weather, WeatherError> {
        let text = crate::text::decode(bytes);
        let text = text.as_str();
        match source {
            WeatherSource::Epw => Weather::parse_epw(text, name),
            WeatherSource::Wea => Weather::parse_wea(text, name),
        }
    }

    /// Parses the text of an EPW file; `name` names it in messages.
    pub fn parse_epw(text: &str, name: &str) -> Result<Weather, WeatherError> {
        epw::parse(strip_bom(text), name)
    }

    /// Parses the text of a `.wea` file; `name` names it in messages.
    pub fn parse_wea(text: &str, name: &str) -> Result<Weather, WeatherError> {
        wea::parse(strip_bom(text), name)
    }

    /// The number of hours.
    pub fn len(&self) -> usize {
        self.hours.len()
    }

    /// Whether there are no hours (only a `.wea` can be so).
    pub fn is_empty(&self) -> bool {
        self.hours.is_empty()
    }

    /// The hours in time order.
    pub fn iter(&self) -> std::slice::Iter<'_, Hour> {
        self.hours.iter()
    }

    /// The series as a `.wea` file, written as Radiance's `epw2wea` writes one: `place
    /// name_country`, latitude, longitude and standard meridian in degrees west, the
    /// elevation, `weather_data_file_units 1`, then `month day hour DNI DHI` with the hour to
    /// 3 decimals and the irradiances to whole W/m². One departure: a time zone that is not a
    /// whole number of hours is written exactly (`epw2wea` truncates it to whole hours).
    pub fn to_wea_string(&self) -> String {
        wea::write(self)
    }

    /// Each hour as its sky is made ([`crate::sky::matrix`]), the way `gendaymtx` reads a
    /// weather file's line: the hour's centre in local standard time, the sun by `gendaymtx`'s
    /// own formulas, the dew point its default (a `.wea` has none; with the Chicago TMY3
    /// file's own dew points the skies agree no better with its illuminances), so that the
    /// hourly skies are the ones Radiance's annual methods see from `epw2wea`'s file.
    pub fn sky_hours(&self) -> Result<Vec<SkyHour>, Invalid> {
        let site = self.location.site();
        let offset = self.location.utc_offset;
        (self.hours.iter())
            .map(|h| SkyHour::gendaymtx(&site, offset, h.month, h.day, h.hour, h.dni, h.dhi))
            .collect()
    }
}

impl<'a> IntoIterator for &'a Weather {
    type Item = &'a Hour;
    type IntoIter = std::slice::Iter<'a, Hour>;

    fn into_iter(self) -> Self::IntoIter {
        self.hours.iter()
    }
}

/// The error for line `line` (1-based) of `file`.
fn malformed(file: &str, line: usize, message: impl Into<String>) -> WeatherError {
    WeatherError::Malformed {
        file: file.to_string(),
        line,
        message: message.into(),
    }
}

/// `text` without a leading UTF-8 byte-order mark.
fn strip_bom(text: &str) -> &str {
    text.strip_prefix('\u{feff}').unwrap_or(text)
}

/// A piece of the file quoted in a message: escaped, and cut to 40 characters.
fn quote(text: &str) -> String {
    let cut: String = text.chars().take(40).collect();
    if cut.len() < text.len() {
        format!("{:?}…", cut)
    } else {
        format!("{cut:?}")
    }
}

/// A finite number; `what` names it in the message.
fn number(text: &str, what: &str) -> Result<f64, String> {
    let t = text.trim();
    match t.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(format!("{what} is not a finite number: {}", quote(t))),
        Err(_) => Err(format!("{what} is not a number: {}", quote(t))),
    }
}

/// A whole number; `what` names it in the message.
fn whole(text: &str, what: &str) -> Result<u32, String> {
    let t = text.trim();
    t.parse::<u32>()
        .map_err(|_| format!("{what} is not a whole number: {}", quote(t)))
}

/// A non-negative irradiance or illuminance (−0 read as 0); `what` names it.
fn not_negative(value: f64, what: &str) -> Result<f64, String> {
    if value < 0.0 {
        Err(format!("{what} is negative: {value}"))
    } else {
        Ok(value + 0.0)
    }
}

/// The days in `month` (1–12) of a year that has 29 February (the most a file may give).
fn days_in_month(month: u32) -> u32 {
    crate::sky::solar::days_in_month(LEAP_YEAR, month)
}

/// Checks a month and day (29 February allowed).
fn check_date(month: u32, day: u32) -> Result<(), String> {
    if !(1..=12).contains(&month) {
        return Err(format!("month {month} is not within 1-12"));
    }
    if day < 1 || day > days_in_month(month) {
        return Err(format!(
            "day {day} is not a day of {} (1-{})",
            month_name(month),
            days_in_month(month)
        ));
    }
    Ok(())
}

/// The month's three-letter English name (1 = Jan).
fn month_name(month: u32) -> &'static str {
    const NAMES: [&str; 12] = [
        "Jan", "Feb", "Mar", "Apr", "May", "Jun", "Jul", "Aug", "Sep", "Oct", "Nov", "Dec",
    ];
    NAMES
        .get((month as usize).wrapping_sub(1))
        .copied()
        .unwrap_or("?")
}

/// The 0-based day of the year of a checked date, counting 29 February (so 1 March is 60
/// in every year: dates compare in order whether or not the file has 29 February).
fn day_of_year(month: u32, day: u32) -> u32 {
    (1..month).map(days_in_month).sum::<u32>() + day - 1
}
