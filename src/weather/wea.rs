//! Radiance's `.wea` (the input of `gendaymtx`, as `epw2wea` writes it): reading, with the
//! west-positive longitude and standard meridian turned east-positive, and writing.

use super::{
    check_date, day_of_year, malformed, month_name, not_negative, number, quote, whole, Hour,
    Location, Weather, WeatherError, WeatherSource, ELEVATION, LATITUDE, LONGITUDE, UTC_OFFSET,
};
use std::fmt::Write;

/// The header lines' keywords, in the order `epw2wea` writes them and `gendaymtx` reads them.
const HEADER: [&str; 6] = [
    "place",
    "latitude",
    "longitude",
    "time_zone",
    "site_elevation",
    "weather_data_file_units",
];

/// Parses a `.wea` file's text; `file` names it in messages.
pub(super) fn parse(text: &str, file: &str) -> Result<Weather, WeatherError> {
    let lines: Vec<&str> = text.lines().collect();
    let mut values = [""; 6];
    for (i, keyword) in HEADER.iter().enumerate() {
        let Some(line) = lines.get(i) else {
            return Err(malformed(
                file,
                i + 1,
                format!("the file ends in the header: expected a {keyword} line (a .wea file has 6 header lines: place, latitude, longitude, time_zone, site_elevation, weather_data_file_units)"),
            ));
        };
        let t = line.trim();
        let (key, value) = t.split_once(char::is_whitespace).unwrap_or((t, ""));
        if key != *keyword {
            return Err(malformed(
                file,
                i + 1,
                format!("expected a {keyword} line, found {}", quote(t)),
            ));
        }
        values[i] = value.trim();
    }
    let location = location(&values).map_err(|(line, m)| malformed(file, line, m))?;
    let mut hours = Vec::new();
    let mut previous: Option<(f64, String)> = None;
    for (i, line) in lines.iter().enumerate().skip(HEADER.len()) {
        if line.trim().is_empty() {
            continue;
        }
        let hour = row(line).map_err(|m| malformed(file, i + 1, m))?;
        let at = f64::from(day_of_year(hour.month, hour.day)) * 24.0 + hour.hour;
        let this = show(&hour);
        if let Some((before, shown)) = &previous {
            if at <= *before {
                return Err(malformed(
                    file,
                    i + 1,
                    format!("{this} does not come after the row before ({shown}): the rows must run forward in time"),
                ));
            }
        }
        previous = Some((at, this));
        hours.push(hour);
    }
    Ok(Weather {
        location,
        hours,
        source: WeatherSource::Wea,
        path: None,
    })
}

/// The location from the header's values; an error gives its 1-based line.
fn location(values: &[&str; 6]) -> Result<Location, (usize, String)> {
    let (name, country) = values[0].split_once('_').unwrap_or((values[0], ""));
    let latitude = number(values[1], "latitude").map_err(|m| (2, m))?;
    let west = number(values[2], "longitude").map_err(|m| (3, m))?;
    let meridian = number(values[3], "time_zone").map_err(|m| (4, m))?;
    let elevation = number(values[4], "site_elevation").map_err(|m| (5, m))?;
    let units = whole(values[5], "weather_data_file_units").map_err(|m| (6, m))?;
    if units != 1 {
        return Err((
            6,
            format!(
                "weather_data_file_units {units} is not supported: only 1 (direct normal and diffuse horizontal irradiance, W/m²) is read"
            ),
        ));
    }
    let location = Location {
        name: name.trim().to_string(),
        country: country.trim().to_string(),
        latitude,
        longitude: -west + 0.0,
        utc_offset: -meridian / 15.0 + 0.0,
        elevation,
    };
    // Each value is checked against its own line, in the file's terms.
    let checks = [
        (
            2,
            LATITUDE.contains(&latitude),
            "latitude",
            "[-90, 90] degrees north",
        ),
        (
            3,
            LONGITUDE.contains(&west),
            "longitude",
            "[-180, 180] degrees west",
        ),
        (
            4,
            UTC_OFFSET.contains(&(meridian / 15.0)),
            "time_zone",
            "[-210, 210] degrees west (14 hours either side of UTC)",
        ),
        (
            5,
            ELEVATION.contains(&elevation),
            "site_elevation",
            "[-1000, 9999.9] m",
        ),
    ];
    for (line, ok, key, range) in checks {
        if !ok {
            return Err((
                line,
                format!("{key} {} is not within {range}", values[line - 1]),
            ));
        }
    }
    Ok(location)
}

/// One data row: `month day hour DNI DHI`, more fields (`epw2wea -a`'s aerosol optical depth
/// and cloud cover) ignored.
fn row(line: &str) -> Result<Hour, String> {
    let f: Vec<&str> = line.split_whitespace().collect();
    if f.len() < 5 {
        return Err(format!(
            "a data row is `month day hour DNI DHI`; this one has {} field(s): {}",
            f.len(),
            quote(line.trim())
        ));
    }
    let month = whole(f[0], "month")?;
    let day = whole(f[1], "day")?;
    check_date(month, day)?;
    let hour = number(f[2], "hour")?;
    if !(0.0..24.0).contains(&hour) {
        return Err(format!("hour {hour} is not within [0, 24)"));
    }
    let dni = number(f[3], "direct normal irradiance")?;
    let dhi = number(f[4], "diffuse horizontal irradiance")?;
    Ok(Hour {
        month,
        day,
        hour,
        dni: not_negative(dni, "direct normal irradiance")?,
        dhi: not_negative(dhi, "diffuse horizontal irradiance")?,
        ghi: None,
        ghi_lux: None,
        dni_lux: None,
        dhi_lux: None,
    })
}

/// `1 Jul hour 2.500`.
fn show(h: &Hour) -> String {
    format!("{} {} hour {:.3}", h.day, month_name(h.month), h.hour)
}

/// The `.wea` text of a series (see `Weather::to_wea_string`).
pub(super) fn write(weather: &Weather) -> String {
    let loc = &weather.location;
    let mut s = String::with_capacity(160 + 24 * weather.len());
    let place = if loc.country.is_empty() {
        loc.name.clone()
    } else {
        format!("{}_{}", loc.name, loc.country)
    };
    let meridian = -15.0 * loc.utc_offset + 0.0;
    // `writeln!` into a String cannot fail.
    let _ = writeln!(s, "place {place}");
    let _ = writeln!(s, "latitude {:?}", loc.latitude);
    let _ = writeln!(s, "longitude {:.2}", -loc.longitude + 0.0);
    if meridian.fract() == 0.0 {
        let _ = writeln!(s, "time_zone {meridian:.0}");
    } else {
        let _ = writeln!(s, "time_zone {meridian}");
    }
    let _ = writeln!(s, "site_elevation {:?}", loc.elevation);
    let _ = writeln!(s, "weather_data_file_units 1");
    for h in weather {
        let _ = writeln!(
            s,
            "{} {} {:.3} {:.0} {:.0}",
            h.month, h.day, h.hour, h.dni, h.dhi
        );
    }
    s
}
