//! Unit tests of the weather readers, on small files written here.

use super::*;
use crate::sky::solar::SolarAngles;

const HEADER: &str = "\
LOCATION,Chicago Ohare Intl Ap,IL,USA,TMY3,725300,41.98,-87.92,-6.0,201.0
DESIGN CONDITIONS,1,Climate Design Data 2009 ASHRAE Handbook,,Heating,1,-20
TYPICAL/EXTREME PERIODS,6,Summer - Week Nearest Max Temperature For Period,Extreme,7/13,7/19
GROUND TEMPERATURES,3,.5,,,,-1.89,-3.06
HOLIDAYS/DAYLIGHT SAVINGS,No,0,0,0
COMMENTS 1,Custom/User Format -- WMO#725300
COMMENTS 2, -- Ground temps
DATA PERIODS,1,1,Data,Sunday, 1/ 1,12/31
";

const WEA: &str = "\
place Chicago_Ohare_Intl_Ap
latitude 41.98
longitude 87.92
time_zone 90
site_elevation 201.0
weather_data_file_units 1
1 1 0.500 0 0
6 21 12.500 850 120 0.120 0.3
";

/// A synthetic DNI for a slot: daylight from 7:00 to 17:00, varying by day.
fn dni_of(month: u32, day: u32, hour: u32) -> u32 {
    if (8..=17).contains(&hour) {
        100 + 10 * hour + month + day
    } else {
        0
    }
}

/// One EPW data row, laid out as a TMY3 row (35 fields).
fn epw_row(month: u32, day: u32, hour: u32) -> String {
    let dni = dni_of(month, day, hour);
    let dhi = if dni > 0 { 50 + hour } else { 0 };
    let ghi = dni / 2 + dhi;
    format!(
        "1986,{month},{day},{hour},60,?9?9?9?9E0?9?9?9?9?9?9?9?9?9?9?9?9?9?9*_*9*9*9*9*9,-12.2,-16.1,73,99500,0,0,218,{ghi},{dni},{dhi},{},{},{},0,270,2.6,9,9,24.1,2740,9,999999999,40,0.0000,0,88,999.000,999.0,99.0",
        ghi * 110,
        dni * 100,
        dhi * 120
    )
}

/// A whole year of rows (with 29 February when `leap`).
fn year_rows(leap: bool) -> Vec<String> {
    let days = [
        31,
        if leap { 29 } else { 28 },
        31,
        30,
        31,
        30,
        31,
        31,
        30,
        31,
        30,
        31,
    ];
    let mut rows = Vec::new();
    for (m, &n) in days.iter().enumerate() {
        for d in 1..=n {
            for h in 1..=24 {
                rows.push(epw_row(m as u32 + 1, d, h));
            }
        }
    }
    rows
}

fn epw_text(rows: &[String]) -> String {
    let mut s = HEADER.to_string();
    for r in rows {
        s.push_str(r);
        s.push('\n');
    }
    s
}

/// The 1-based file line of data row `index` (0-based).
fn line_of(index: usize) -> usize {
    index + 9
}

/// The 0-based row index of a slot in a non-leap year.
fn index_of(month: u32, day: u32, hour: u32) -> usize {
    (day_of_year(month, day) - u32::from(month > 2)) as usize * 24 + hour as usize - 1
}

fn epw_err(text: &str) -> String {
    let e = Weather::parse_epw(text, "weather.epw").expect_err("should fail");
    let msg = e.to_string();
    assert_eq!(msg.lines().count(), 1, "one line: {msg}");
    msg
}

fn wea_err(text: &str) -> String {
    let e = Weather::parse_wea(text, "weather.wea").expect_err("should fail");
    let msg = e.to_string();
    assert_eq!(msg.lines().count(), 1, "one line: {msg}");
    msg
}

/// The year with row `index` replaced by `row`.
fn year_with(index: usize, row: &str) -> String {
    let mut rows = year_rows(false);
    rows[index] = row.to_string();
    epw_text(&rows)
}

#[test]
fn epw_reads_a_typical_year() {
    let w = Weather::parse_epw(&epw_text(&year_rows(false)), "weather.epw").unwrap();
    assert_eq!(w.len(), 8760);
    assert_eq!(w.source, WeatherSource::Epw);
    let l = &w.location;
    assert_eq!(
        (l.name.as_str(), l.country.as_str()),
        ("Chicago Ohare Intl Ap", "USA")
    );
    assert_eq!(
        (l.latitude, l.longitude, l.utc_offset, l.elevation),
        (41.98, -87.92, -6.0, 201.0)
    );
    assert_eq!(l.site().longitude, -87.92);
    let first = w.hours[0];
    assert_eq!((first.month, first.day, first.hour), (1, 1, 0.5));
    let last = w.hours[8759];
    assert_eq!((last.month, last.day, last.hour), (12, 31, 23.5));
    let noon = w.hours[index_of(7, 1, 13)];
    assert_eq!((noon.month, noon.day, noon.hour), (7, 1, 12.5));
    assert_eq!(noon.dni, f64::from(dni_of(7, 1, 13)));
    assert_eq!(noon.dhi, 63.0);
    assert_eq!(noon.ghi, Some(noon.dni.div_euclid(2.0) + 63.0));
    assert_eq!(noon.dni_lux, Some(noon.dni * 100.0));
    assert_eq!(noon.dhi_lux, Some(63.0 * 120.0));
    assert!(noon.is_daylit() && !first.is_daylit());
    assert_eq!(w.iter().filter(|h| h.is_daylit()).count(), 365 * 10);
    assert_eq!((&w).into_iter().count(), 8760);
}

#[test]
fn an_hour_is_dated_at_its_centre_in_local_standard_time() {
    let w = Weather::parse_epw(&epw_text(&year_rows(false)), "weather.epw").unwrap();
    let t = w.hours[index_of(6, 21, 13)].datetime(&w.location);
    let want = (TYPICAL_YEAR, 6, 21, 12, 30, 0.0, -6.0);
    assert_eq!(
        (
            t.year,
            t.month,
            t.day,
            t.hour,
            t.minute,
            t.second,
            t.utc_offset
        ),
        want
    );
    for h in &w {
        h.datetime(&w.location).validate().unwrap();
    }
    // Chicago at 12:30 CST on 21 June: solar noon is near 11:53, so the sun stands about 9°
    // of hour angle past the meridian, some 70° up (71.5° at noon).
    let sun = SolarAngles::at(&w.location.site(), &t);
    assert!(
        (sun.altitude - 70.0).abs() < 0.5 && sun.azimuth > 0.0,
        "{sun:?}"
    );
    // A decimal .wea hour keeps its minutes and seconds.
    let odd = Hour {
        hour: 7.2575,
        ..w.hours[0]
    };
    let t = odd.datetime(&w.location);
    assert_eq!((t.hour, t.minute), (7, 15));
    assert!((t.second - 27.0).abs() < 1e-6);
}

#[test]
fn epw_with_29_february_is_a_leap_year() {
    let w = Weather::parse_epw(&epw_text(&year_rows(true)), "weather.epw").unwrap();
    assert_eq!(w.len(), 8784);
    let leap_day = w.hours[59 * 24];
    assert_eq!((leap_day.month, leap_day.day), (2, 29));
    let t = leap_day.datetime(&w.location);
    assert_eq!(t.year, LEAP_YEAR);
    t.validate().unwrap();
    assert_eq!(w.hours[60 * 24].datetime(&w.location).year, TYPICAL_YEAR);
}

#[test]
fn epw_calendar_errors_name_the_line_and_the_hour_expected() {
    let mut rows = year_rows(false);
    let i = index_of(7, 1, 3);
    rows.remove(i);
    let want = format!(
        "weather.epw line {}: expected 1 Jul hour 3, found 1 Jul hour 4 (an hour is missing)",
        line_of(i)
    );
    assert_eq!(epw_err(&epw_text(&rows)), want);

    let mut rows = year_rows(false);
    rows.drain(i..i + 5);
    assert!(epw_err(&epw_text(&rows)).ends_with("found 1 Jul hour 8 (5 hours are missing)"));

    let i = index_of(3, 2, 5);
    let repeated = year_with(i, &epw_row(3, 2, 4));
    let want = format!(
        "weather.epw line {}: expected 2 Mar hour 5, found 2 Mar hour 4 (an hour is repeated)",
        line_of(i)
    );
    assert_eq!(epw_err(&repeated), want);

    let back = year_with(i, &epw_row(1, 1, 1));
    assert!(epw_err(&back).ends_with("found 1 Jan hour 1 (the rows are out of time order)"));

    // 29 February only where 1 March hour 1 is due.
    let late_leap = year_with(index_of(3, 1, 2), &epw_row(2, 29, 1));
    assert!(epw_err(&late_leap).contains("expected 1 Mar hour 2, found 29 Feb hour 1"));
}

#[test]
fn epw_must_hold_the_whole_year() {
    let mut rows = year_rows(false);
    rows.truncate(8000);
    let msg = epw_err(&epw_text(&rows));
    assert!(
        msg.starts_with(&format!(
            "weather.epw line {}: the data end at",
            line_of(7999)
        )),
        "{msg}"
    );

    let mut rows = year_rows(false);
    rows.push(epw_row(1, 1, 1));
    let msg = epw_err(&epw_text(&rows));
    assert!(
        msg.starts_with(&format!(
            "weather.epw line {}: found 1 Jan hour 1 after 31 Dec hour 24",
            line_of(8760)
        )),
        "{msg}"
    );

    assert_eq!(
        epw_err(HEADER),
        "weather.epw line 8: no data rows after the header"
    );
    // Blank lines at the end are no rows.
    let text = epw_text(&year_rows(false)) + "\n  \n";
    assert_eq!(Weather::parse_epw(&text, "w").unwrap().len(), 8760);
}

#[test]
fn epw_value_errors_name_the_column() {
    let row = epw_row(1, 1, 4).replacen(",0,0,0,0,0,0,0,270", ",0,abc,0,0,0,0,0,270", 1);
    let text = year_with(3, &row);
    assert_eq!(
        epw_err(&text),
        "weather.epw line 12: column 15 (direct normal irradiance) is not a number: \"abc\""
    );
    for (bad, want) in [
        ("NaN", "column 15 (direct normal irradiance) is not a finite number: \"NaN\""),
        ("inf", "column 15 (direct normal irradiance) is not a finite number: \"inf\""),
        ("-3", "column 15 (direct normal irradiance) is negative: -3"),
        ("9999", "column 15 (direct normal irradiance) is missing (9999); the sky cannot be made without it"),
        ("1e999", "column 15 (direct normal irradiance) is not a finite number: \"1e999\""),
        ("", "column 15 (direct normal irradiance) is not a number: \"\""),
    ] {
        let row = epw_row(1, 1, 4).replacen(",0,0,0,0,0,0,0,270", &format!(",0,{bad},0,0,0,0,0,270"), 1);
        assert_eq!(epw_err(&year_with(3, &row)), format!("weather.epw line 12: {want}"));
    }
    let dhi = epw_row(1, 1, 4).replacen(",0,0,0,0,0,0,0,270", ",0,0,9999,0,0,0,0,270", 1);
    assert!(epw_err(&year_with(3, &dhi))
        .contains("column 16 (diffuse horizontal irradiance) is missing"));
}

#[test]
fn epw_missing_optional_values_are_none() {
    let row = epw_row(1, 1, 4).replacen(
        ",0,0,0,0,0,0,0,270",
        ",9999,0,0,999999,999999,999999,0,270",
        1,
    );
    let w = Weather::parse_epw(&year_with(3, &row), "w").unwrap();
    let h = w.hours[3];
    assert_eq!(
        (h.ghi, h.ghi_lux, h.dni_lux, h.dhi_lux),
        (None, None, None, None)
    );
    assert_eq!((h.dni, h.dhi), (0.0, 0.0));
    let neg = epw_row(1, 1, 4).replacen(",0,0,0,0,0,0,0,270", ",0,0,0,-1,0,0,0,270", 1);
    assert!(epw_err(&year_with(3, &neg))
        .ends_with("column 17 (global horizontal illuminance) is negative: -1"));
}

#[test]
fn epw_bad_dates_and_short_rows() {
    for (row, want) in [
        ("1986,13,1,4", "month 13 is not within 1-12"),
        ("1986,2,30,4", "day 30 is not a day of Feb (1-29)"),
        ("1986,1,1,0", "column 4: hour 0 is not within 1-24"),
        ("1986,1,1,25", "column 4: hour 25 is not within 1-24"),
        ("1986,1,x,4", "column 3 (day) is not a whole number: \"x\""),
        (
            "1986,-1,1,4",
            "column 2 (month) is not a whole number: \"-1\"",
        ),
    ] {
        let full = epw_row(1, 1, 4).replacen("1986,1,1,4", row, 1);
        assert_eq!(
            epw_err(&year_with(3, &full)),
            format!("weather.epw line 12: {want}")
        );
    }
    let short = "1986,1,1,4,60,x,1,2,3";
    let msg = epw_err(&year_with(3, short));
    assert!(
        msg.starts_with("weather.epw line 12: a data row has 35 fields; this one has 9"),
        "{msg}"
    );
}

#[test]
fn epw_header_errors() {
    let body = epw_text(&year_rows(false));
    let swap = |from: &str, to: &str| body.replacen(from, to, 1);
    for (text, want) in [
        (
            String::new(),
            "line 1: the file is empty (an EPW file starts with a LOCATION line)",
        ),
        (
            swap("41.98,", "95,"),
            "line 1: LOCATION: latitude 95 is not within [-90, 90] degrees",
        ),
        (
            swap("-87.92,", "-187.92,"),
            "line 1: LOCATION: longitude -187.92 is not within [-180, 180] degrees",
        ),
        (
            swap("-6.0,", "-15,"),
            "line 1: LOCATION: time zone -15 is not within [-14, 14] hours",
        ),
        (
            swap("41.98,", "north,"),
            "line 1: LOCATION field 7 (latitude) is not a number: \"north\"",
        ),
        (
            swap("TMY3,725300,", ""),
            "line 1: LOCATION has 8 fields; expected 10",
        ),
        (
            swap("LOCATION,", "PLACE,"),
            "line 1: expected the LOCATION header line, found \"PLACE\"",
        ),
        (
            swap("COMMENTS 2,", "REMARKS,"),
            "line 7: expected the COMMENTS 2 header line, found \"REMARKS\"",
        ),
        (
            swap("DATA PERIODS,1,1,", "DATA PERIODS,1,4,"),
            "line 8: DATA PERIODS: 4 records per hour is not supported",
        ),
        (
            swap("DATA PERIODS,1,1,", "DATA PERIODS,1,x,"),
            "line 8: DATA PERIODS field 3 (records per hour) is not a whole number",
        ),
        (
            HEADER.lines().take(3).collect::<Vec<_>>().join("\n"),
            "line 4: the file ends in the header: expected the GROUND TEMPERATURES line",
        ),
    ] {
        let msg = epw_err(&text);
        assert!(
            msg.starts_with(&format!("weather.epw {want}")),
            "{msg}\nwanted {want}"
        );
    }
    // Header keywords in any case; CRLF line ends and a byte-order mark.
    let crlf = format!(
        "\u{feff}{}",
        body.replace('\n', "\r\n")
            .replacen("COMMENTS 1", "Comments 1", 1)
    );
    assert_eq!(Weather::parse_epw(&crlf, "w").unwrap().len(), 8760);
}

#[test]
fn wea_reads_radiance_conventions() {
    let w = Weather::parse_wea(WEA, "weather.wea").unwrap();
    assert_eq!(w.source, WeatherSource::Wea);
    let l = &w.location;
    assert_eq!(
        (l.name.as_str(), l.country.as_str()),
        ("Chicago", "Ohare_Intl_Ap")
    );
    assert_eq!(
        (l.latitude, l.longitude, l.utc_offset, l.elevation),
        (41.98, -87.92, -6.0, 201.0)
    );
    assert_eq!(w.len(), 2);
    let h = w.hours[1];
    assert_eq!(
        (h.month, h.day, h.hour, h.dni, h.dhi, h.ghi),
        (6, 21, 12.5, 850.0, 120.0, None)
    );
    let t = h.datetime(l);
    assert_eq!((t.hour, t.minute, t.utc_offset), (12, 30, -6.0));
    // East of Greenwich: negative west longitude and meridian.
    let east = WEA
        .replace("longitude 87.92", "longitude -13.4")
        .replace("time_zone 90", "time_zone -15");
    let e = Weather::parse_wea(&east, "w").unwrap().location;
    assert_eq!((e.longitude, e.utc_offset), (13.4, 1.0));
    // Header only: no hours is a valid (empty) list.
    let header: String = WEA.lines().take(6).map(|l| format!("{l}\n")).collect();
    assert!(Weather::parse_wea(&header, "w").unwrap().is_empty());
}

#[test]
fn wea_errors_name_the_line() {
    let with = |from: &str, to: &str| WEA.replacen(from, to, 1);
    for (text, want) in [
        (
            with("weather_data_file_units 1", "weather_data_file_units 2"),
            "line 6: weather_data_file_units 2 is not supported",
        ),
        (
            with("longitude 87.92", "longitude 187.92"),
            "line 3: longitude 187.92 is not within [-180, 180] degrees west",
        ),
        (
            with("time_zone 90", "time_zone 90x"),
            "line 4: time_zone is not a number: \"90x\"",
        ),
        (
            with("latitude 41.98", "latitude -91"),
            "line 2: latitude -91 is not within [-90, 90] degrees north",
        ),
        (
            with("time_zone 90\n", ""),
            "line 4: expected a time_zone line, found \"site_elevation 201.0\"",
        ),
        (
            with("6 21 12.500 850 120", "6 21 12.500 -850 120"),
            "line 8: direct normal irradiance is negative: -850",
        ),
        (
            with("6 21 12.500 850 120", "6 21 24 850 120"),
            "line 8: hour 24 is not within [0, 24)",
        ),
        (
            with("6 21 12.500 850 120", "6 31 12.5 850 120"),
            "line 8: day 31 is not a day of Jun (1-30)",
        ),
        (
            with("6 21 12.500 850 120 0.120 0.3", "6 21 12.5 850"),
            "line 8: a data row is `month day hour DNI DHI`; this one has 4 field(s)",
        ),
        (
            with("6 21 12.500", "1 1 0.5"),
            "line 8: 1 Jan hour 0.500 does not come after the row before (1 Jan hour 0.500)",
        ),
        (
            with("6 21 12.500 850 120", "6 21 12.5 inf 120"),
            "line 8: direct normal irradiance is not a finite number: \"inf\"",
        ),
        (
            String::new(),
            "line 1: the file ends in the header: expected a place line",
        ),
    ] {
        let msg = wea_err(&text);
        assert!(
            msg.starts_with(&format!("weather.wea {want}")),
            "{msg}\nwanted {want}"
        );
    }
}

#[test]
fn epw_written_as_wea_reads_back_the_same_hours() {
    let epw = Weather::parse_epw(&epw_text(&year_rows(false)), "weather.epw").unwrap();
    let text = epw.to_wea_string();
    let head: Vec<&str> = text.lines().take(8).collect();
    assert_eq!(
        head,
        [
            "place Chicago Ohare Intl Ap_USA",
            "latitude 41.98",
            "longitude 87.92",
            "time_zone 90",
            "site_elevation 201.0",
            "weather_data_file_units 1",
            "1 1 0.500 0 0",
            "1 1 1.500 0 0",
        ]
    );
    let wea = Weather::parse_wea(&text, "weather.wea").unwrap();
    assert_eq!(wea.len(), epw.len());
    let (a, b) = (&epw.location, &wea.location);
    assert_eq!(
        (a.name.as_str(), a.country.as_str()),
        (b.name.as_str(), b.country.as_str())
    );
    assert_eq!(
        (a.latitude, a.longitude, a.utc_offset, a.elevation),
        (b.latitude, b.longitude, b.utc_offset, b.elevation)
    );
    for (x, y) in epw.iter().zip(&wea) {
        assert_eq!(
            (x.month, x.day, x.hour, x.dni, x.dhi),
            (y.month, y.day, y.hour, y.dni, y.dhi)
        );
    }
    // And the .wea written again is the same text.
    assert_eq!(wea.to_wea_string(), text);
    // A half-hour zone is written exactly (India, UTC+5:30: a meridian 82.5° east).
    let mut india = wea.clone();
    india.location.utc_offset = 5.5;
    assert!(india.to_wea_string().contains("\ntime_zone -82.5\n"));
}

#[test]
fn read_chooses_the_reader_by_extension() {
    let dir = tempfile::tempdir().unwrap();
    let epw = dir.path().join("Chicago.EPW");
    std::fs::write(&epw, epw_text(&year_rows(false))).unwrap();
    let w = Weather::read(&epw).unwrap();
    assert_eq!(
        (w.len(), w.source, w.path.as_deref()),
        (8760, WeatherSource::Epw, Some(epw.as_path()))
    );
    let wea = dir.path().join("chicago.wea");
    std::fs::write(&wea, WEA).unwrap();
    assert_eq!(Weather::read(&wea).unwrap().source, WeatherSource::Wea);

    let txt = dir.path().join("chicago.txt");
    let msg = Weather::read(&txt).unwrap_err().to_string();
    assert!(msg.ends_with("chicago.txt: not a known weather file format (name it .epw or .wea)"));
    let gone = dir.path().join("gone.wea");
    let msg = Weather::read(&gone).unwrap_err().to_string();
    assert!(
        msg.contains("gone.wea: cannot read:") && msg.lines().count() == 1,
        "{msg}"
    );
}

#[test]
fn latin1_bytes_are_read_as_latin1() {
    // An older EPW's place in Latin-1 ('ü' as the byte 0xfc), and a stray byte in a number.
    let text = WEA.replacen("Chicago", "Z\u{fc}rich", 1);
    let bytes: Vec<u8> = text.chars().map(|c| c as u32 as u8).collect();
    let w = Weather::from_bytes(&bytes, "weather.wea", WeatherSource::Wea).unwrap();
    assert!(w.location.name.starts_with("Zürich"), "{}", w.location.name);
    let mut bad = WEA.as_bytes().to_vec();
    let at = WEA.find("850").unwrap();
    bad[at] = 0xff;
    let msg = Weather::from_bytes(&bad, "weather.wea", WeatherSource::Wea)
        .unwrap_err()
        .to_string();
    assert!(msg.starts_with("weather.wea line 8: "), "{msg}");
}

/// Every truncation and many byte changes of valid files give `Ok` or a one-line `Err`.
#[test]
fn damaged_files_never_panic() {
    let mut rows = year_rows(false);
    rows.truncate(40);
    let epw = epw_text(&rows).into_bytes();
    let wea = WEA.as_bytes().to_vec();
    let tries = |bytes: &[u8], source: WeatherSource| {
        if let Err(e) = Weather::from_bytes(bytes, "f", source) {
            let msg = e.to_string();
            assert!(
                msg.lines().count() == 1 && msg.starts_with("f line "),
                "{msg}"
            );
        }
    };
    for (text, source) in [(&epw, WeatherSource::Epw), (&wea, WeatherSource::Wea)] {
        for cut in 0..text.len().min(3000) {
            tries(&text[..cut], source);
        }
        let flips = [0x00, 0x0a, b',', b' ', b'-', b'9', b'e', b'.', 0x80, 0xff];
        for i in (0..text.len()).step_by(7) {
            for &b in &flips {
                let mut t = text.clone();
                t[i] = b;
                tries(&t, source);
            }
        }
    }
    for junk in [
        &b"\xff\xfe\x00"[..],
        b"\n\n\n\n\n\n\n\n\n",
        b",,,,,,,,,,,,,,,,,,,,,",
        b"place",
    ] {
        tries(junk, WeatherSource::Epw);
        tries(junk, WeatherSource::Wea);
    }
}

/// The EPW named by `RADIOSITY_EPW` (a real file, tried by hand), and its path.
fn epw_from_env() -> Option<(String, Weather)> {
    let path = std::env::var("RADIOSITY_EPW").ok()?;
    let w = Weather::read(&path).unwrap();
    Some((path, w))
}

/// A real EPW read by hand: `RADIOSITY_EPW=path cargo test --release --lib weather -- --ignored`.
#[test]
#[ignore]
fn reads_the_epw_named_by_radiosity_epw() {
    let Some((path, w)) = epw_from_env() else {
        return;
    };
    let (dni, dhi): (f64, f64) = (w.iter().map(|h| h.dni).sum(), w.iter().map(|h| h.dhi).sum());
    let daylit = w.iter().filter(|h| h.is_daylit()).count();
    println!(
        "{path}: {} hours ({daylit} daylit), {:?}",
        w.len(),
        w.location
    );
    println!("sum DNI {dni} Wh/m², sum DHI {dhi} Wh/m²");
    let back = Weather::parse_wea(&w.to_wea_string(), "written.wea").unwrap();
    assert_eq!(back.len(), w.len());
}

/// The hours' skies (Perez, through `gendaymtx`'s reading of a line): dark hours give no
/// light, a daylit hour's diffuse and direct illuminance come out of its irradiances.
#[test]
fn each_hour_gives_its_sky() {
    let w = Weather::parse_wea(WEA, "weather.wea").unwrap();
    let hours = w.sky_hours().unwrap();
    assert_eq!(hours.len(), w.len());
    let vectors = crate::sky::matrix::SkyVectors::new(Default::default()).unwrap();
    let night = vectors.hour(&hours[0]).unwrap();
    assert!(night.radiance.iter().all(|&r| r == 0.0));
    // 21 June, 12:30 in Chicago: the sun high in the south, DNI 850 W/m², DHI 120 W/m².
    let noon = vectors.hour(&hours[1]).unwrap();
    assert!(hours[1].sun.altitude > 60.0, "{:?}", hours[1].sun);
    assert!(noon.direct_illuminance > 850.0 * 80.0 && noon.direct_illuminance < 850.0 * 115.0);
    assert!(noon.diffuse_illuminance > 120.0 * 90.0 && noon.diffuse_illuminance < 120.0 * 150.0);
}

/// A real EPW's global horizontal illuminance against the Perez model's from the same hour's
/// irradiances (diffuse + direct normal × sin h), hour by hour:
/// `RADIOSITY_EPW=path cargo test --release --lib weather -- --ignored --nocapture`.
#[test]
#[ignore]
fn perez_horizontal_illuminance_against_the_epw() {
    let Some((path, w)) = epw_from_env() else {
        return;
    };
    let hours = w.sky_hours().unwrap();
    let vectors = crate::sky::matrix::SkyVectors::new(Default::default()).unwrap();
    let (mut sum_model, mut sum_file, mut rel, mut n) = (0.0, 0.0, 0.0, 0usize);
    for (h, sky) in w.iter().zip(&hours) {
        let Some(file) = h.ghi_lux.filter(|&e| e > 100.0) else {
            continue;
        };
        let v = vectors.hour(sky).unwrap();
        let sin_h = sky.sun.altitude.to_radians().sin().max(0.0);
        let model = v.diffuse_illuminance + v.direct_illuminance * sin_h;
        sum_model += model;
        sum_file += file;
        rel += (model - file).abs() / file;
        n += 1;
    }
    println!(
        "{path}: {n} hours over 100 lux: annual sum model/file {:.4}, mean |hourly difference| {:.2} %",
        sum_model / sum_file,
        100.0 * rel / n as f64
    );
}
