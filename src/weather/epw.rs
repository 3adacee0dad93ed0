//! EnergyPlus Weather (EPW): the `LOCATION` and `DATA PERIODS` header lines and the hourly
//! rows, checked for a whole year in calendar order (see the module docs of `weather`).

use super::{
    check_date, day_of_year, malformed, month_name, not_negative, number, quote, whole, Hour,
    Location, Weather, WeatherError, WeatherSource,
};

/// The header lines' keywords, in the order the data dictionary gives them.
const HEADER: [&str; 8] = [
    "LOCATION",
    "DESIGN CONDITIONS",
    "TYPICAL/EXTREME PERIODS",
    "GROUND TEMPERATURES",
    "HOLIDAYS/DAYLIGHT SAVINGS",
    "COMMENTS 1",
    "COMMENTS 2",
    "DATA PERIODS",
];

/// How many fields of a data row are read: through the diffuse horizontal illuminance.
const FIELDS_READ: usize = 19;

/// Missing-value codes: irradiance (Wh/m²) and illuminance (lux).
const MISSING_IRRADIANCE: f64 = 9999.0;
const MISSING_ILLUMINANCE: f64 = 999_999.0;

/// A date and EPW hour (1–24, the hour ending then): month, day, hour.
type Slot = (u32, u32, u32);

/// Parses an EPW file's text; `file` names it in messages.
pub(super) fn parse(text: &str, file: &str) -> Result<Weather, WeatherError> {
    let lines: Vec<&str> = text.lines().collect();
    let location = header(&lines, file)?;
    let mut calendar = Calendar::default();
    let mut hours = Vec::with_capacity(8784);
    let mut last_line = HEADER.len();
    for (i, line) in lines.iter().enumerate().skip(HEADER.len()) {
        if line.trim().is_empty() {
            continue;
        }
        let (slot, hour) = row(line).map_err(|m| malformed(file, i + 1, m))?;
        calendar
            .accept(slot)
            .map_err(|m| malformed(file, i + 1, m))?;
        hours.push(hour);
        last_line = i + 1;
    }
    calendar
        .finish()
        .map_err(|m| malformed(file, last_line, m))?;
    Ok(Weather {
        location,
        hours,
        source: WeatherSource::Epw,
        path: None,
    })
}

/// Checks the 8 header lines' keywords and reads `LOCATION` and `DATA PERIODS`.
fn header(lines: &[&str], file: &str) -> Result<Location, WeatherError> {
    for (i, keyword) in HEADER.iter().enumerate() {
        let Some(line) = lines.get(i) else {
            let message = if i == 0 {
                "the file is empty (an EPW file starts with a LOCATION line)".to_string()
            } else {
                format!(
                    "the file ends in the header: expected the {keyword} line (an EPW file has 8 header lines)"
                )
            };
            return Err(malformed(file, i + 1, message));
        };
        let first = line.split(',').next().unwrap_or("").trim();
        if !first.eq_ignore_ascii_case(keyword) {
            return Err(malformed(
                file,
                i + 1,
                format!("expected the {keyword} header line, found {}", quote(first)),
            ));
        }
    }
    let location = location(lines[0]).map_err(|m| malformed(file, 1, m))?;
    data_periods(lines[7]).map_err(|m| malformed(file, 8, m))?;
    Ok(location)
}

/// `LOCATION,city,state,country,source,WMO,latitude,longitude,time zone,elevation`.
fn location(line: &str) -> Result<Location, String> {
    let f: Vec<&str> = line.split(',').collect();
    if f.len() < 10 {
        return Err(format!(
            "LOCATION has {} fields; expected 10: LOCATION,city,state,country,source,WMO,latitude,longitude,time zone,elevation",
            f.len()
        ));
    }
    let location = Location {
        name: f[1].trim().to_string(),
        country: f[3].trim().to_string(),
        latitude: number(f[6], "LOCATION field 7 (latitude)")?,
        longitude: number(f[7], "LOCATION field 8 (longitude)")?,
        utc_offset: number(f[8], "LOCATION field 9 (time zone)")?,
        elevation: number(f[9], "LOCATION field 10 (elevation)")?,
    };
    location
        .validate()
        .map_err(|e| format!("LOCATION: {}", e.0))?;
    Ok(location)
}

/// `DATA PERIODS,periods,records per hour,...`: only hourly files are read.
fn data_periods(line: &str) -> Result<(), String> {
    let f: Vec<&str> = line.split(',').collect();
    if f.len() < 3 {
        return Err(
            "DATA PERIODS has no records-per-hour field (DATA PERIODS,periods,records per hour,...)"
                .to_string(),
        );
    }
    let periods = whole(f[1], "DATA PERIODS field 2 (number of data periods)")?;
    let per_hour = whole(f[2], "DATA PERIODS field 3 (records per hour)")?;
    if periods == 0 {
        return Err("DATA PERIODS: the file declares no data period".to_string());
    }
    if per_hour != 1 {
        return Err(format!(
            "DATA PERIODS: {per_hour} records per hour is not supported (only hourly files, 1 record per hour, are read)"
        ));
    }
    Ok(())
}

/// One data row: its slot (month, day, EPW hour) and the hour it gives.
fn row(line: &str) -> Result<(Slot, Hour), String> {
    let f: Vec<&str> = line.split(',').collect();
    if f.len() < FIELDS_READ {
        return Err(format!(
            "a data row has 35 fields; this one has {} (the first {FIELDS_READ} are needed, through the diffuse horizontal illuminance)",
            f.len()
        ));
    }
    let month = whole(f[1], "column 2 (month)")?;
    let day = whole(f[2], "column 3 (day)")?;
    let hour = whole(f[3], "column 4 (hour)")?;
    check_date(month, day)?;
    if !(1..=24).contains(&hour) {
        return Err(format!("column 4: hour {hour} is not within 1-24"));
    }
    let required = |i: usize, what: &str| -> Result<f64, String> {
        column(&f, i, what, MISSING_IRRADIANCE)?.ok_or_else(|| {
            format!(
                "column {} ({what}) is missing ({}); the sky cannot be made without it",
                i + 1,
                f[i].trim()
            )
        })
    };
    let hour_record = Hour {
        month,
        day,
        hour: f64::from(hour) - 0.5,
        dni: required(14, "direct normal irradiance")?,
        dhi: required(15, "diffuse horizontal irradiance")?,
        ghi: column(&f, 13, "global horizontal irradiance", MISSING_IRRADIANCE)?,
        ghi_lux: column(&f, 16, "global horizontal illuminance", MISSING_ILLUMINANCE)?,
        dni_lux: column(&f, 17, "direct normal illuminance", MISSING_ILLUMINANCE)?,
        dhi_lux: column(
            &f,
            18,
            "diffuse horizontal illuminance",
            MISSING_ILLUMINANCE,
        )?,
    };
    Ok(((month, day, hour), hour_record))
}

/// Field `i` (0-based) as a non-negative number, `None` at or above the `missing` code.
fn column(f: &[&str], i: usize, what: &str, missing: f64) -> Result<Option<f64>, String> {
    let label = format!("column {} ({what})", i + 1);
    let value = number(f[i], &label)?;
    if value >= missing {
        return Ok(None);
    }
    not_negative(value, &label).map(Some)
}

/// The calendar a year of hourly rows must follow.
#[derive(Default)]
struct Calendar {
    /// The slot the next row must have (`None` before the first row is `(1, 1, 1)`).
    expected: Option<Slot>,
    /// The last row's slot.
    last: Option<Slot>,
    /// Whether the file has 29 February.
    leap: bool,
    /// Whether 31 December hour 24 has been read.
    done: bool,
}

impl Calendar {
    /// Takes the next row's slot, or says why it is not the next hour.
    fn accept(&mut self, found: Slot) -> Result<(), String> {
        if self.done {
            return Err(format!(
                "found {} after 31 Dec hour 24 (a year has 8760 hourly rows, or 8784 with 29 Feb)",
                show(found)
            ));
        }
        let expected = self.expected.unwrap_or((1, 1, 1));
        if found != expected {
            if !self.leap && expected == (3, 1, 1) && found == (2, 29, 1) {
                self.leap = true;
            } else {
                return Err(format!(
                    "expected {}, found {} ({})",
                    show(expected),
                    show(found),
                    self.why(expected, found)
                ));
            }
        }
        self.last = Some(found);
        match next_slot(found, self.leap) {
            Some(next) => self.expected = Some(next),
            None => self.done = true,
        }
        Ok(())
    }

    /// What a row other than the expected one means.
    fn why(&self, expected: Slot, found: Slot) -> String {
        let (e, f) = (ordinal(expected, self.leap), ordinal(found, self.leap));
        if Some(found) == self.last {
            "an hour is repeated".to_string()
        } else if f == e + 1 {
            "an hour is missing".to_string()
        } else if f > e {
            format!("{} hours are missing", f - e)
        } else {
            "the rows are out of time order".to_string()
        }
    }

    /// Checks that the rows reached 31 December hour 24.
    fn finish(&self) -> Result<(), String> {
        match (self.last, self.done) {
            (_, true) => Ok(()),
            (None, _) => Err("no data rows after the header".to_string()),
            (Some(last), false) => Err(format!(
                "the data end at {}; an EPW file holds a whole year of hourly rows, 1 Jan hour 1 to 31 Dec hour 24",
                show(last)
            )),
        }
    }
}

/// The slot after `s` (`None` after 31 December hour 24).
fn next_slot((month, day, hour): Slot, leap: bool) -> Option<Slot> {
    let days = match month {
        2 if leap => 29,
        2 => 28,
        4 | 6 | 9 | 11 => 30,
        _ => 31,
    };
    if hour < 24 {
        Some((month, day, hour + 1))
    } else if day < days {
        Some((month, day + 1, 1))
    } else if month < 12 {
        Some((month + 1, 1, 1))
    } else {
        None
    }
}

/// The 0-based hour of the year of a checked slot in a year with or without 29 February.
fn ordinal((month, day, hour): Slot, leap: bool) -> u32 {
    let skip_leap_day = u32::from(!leap && month > 2);
    (day_of_year(month, day) - skip_leap_day) * 24 + hour - 1
}

/// `1 Jul hour 3`.
fn show((month, day, hour): Slot) -> String {
    format!("{day} {} hour {hour}", month_name(month))
}
