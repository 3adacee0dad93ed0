//! Where the sun is: solar altitude and azimuth from a site and a time.
//!
//! The algorithm is NOAA's Solar Calculator (NOAA Global Monitoring Laboratory,
//! <https://gml.noaa.gov/grad/solcalc/calcdetails.html>), itself the low-accuracy solar
//! theory of J. Meeus, *Astronomical Algorithms* (2nd ed., 1998), ch. 25 (the sun's apparent
//! longitude and declination), ch. 28 (the equation of time, eq. 28.3) and ch. 13 (horizontal
//! coordinates, eq. 13.5–13.6), with NOAA's atmospheric refraction correction. Universal time
//! stands for dynamical time (ΔT ≈ 1 min moves the sun by under 0.001°).
//!
//! Accuracy, as tested here: against the worked example of NREL's SPA (Reda & Andreas 2008,
//! NREL/TP-560-34302, ±0.0003°) within 0.01° in zenith angle and azimuth, the difference being
//! mostly SPA's topocentric parallax (0.0024°) and its refraction at 820 hPa where NOAA assumes
//! sea level; Meeus's own example (25.a, 28.b) to his printed digits. Radiance's `gensky` uses a
//! much coarser fit (declination and equation of time as single sines): to compare with it, give
//! `gensky -ang` the [`SolarAngles`] computed here rather than the date.
//!
//! Azimuth follows `gensky`: degrees **west of south** (south 0°, west 90°, north ±180°,
//! east −90°). [`SolarAngles::azimuth_from_north`] gives the compass bearing (east of north).

use crate::settings::Invalid;
use glam::DVec3;
use std::str::FromStr;

/// The sun's apparent position in the local sky, in degrees.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SolarAngles {
    /// Altitude above the horizon, degrees (refracted, as the sun is seen).
    pub altitude: f64,
    /// Azimuth in degrees **west of south**, `gensky`'s convention (south 0, west 90).
    pub azimuth: f64,
}

impl SolarAngles {
    /// Altitude and azimuth (degrees west of south), as `gensky -ang ALT AZI`. Refuses
    /// non-finite values and an altitude outside [−90°, 90°].
    pub fn new(altitude: f64, azimuth: f64) -> Result<SolarAngles, Invalid> {
        if !(altitude.is_finite() && azimuth.is_finite() && altitude.abs() <= 90.0) {
            return Invalid::err(format!(
                "--sun: solar altitude {altitude}° and azimuth {azimuth}°: the altitude must be within [-90, 90]"
            ));
        }
        Ok(SolarAngles { altitude, azimuth })
    }

    /// The sun's position seen from `site` at `time` (NOAA's algorithm, see the module docs).
    pub fn at(site: &Site, time: &DateTime) -> SolarAngles {
        let jd = time.julian_day();
        let (declination, eot_minutes) = declination_and_equation_of_time(jd);
        // True solar time: universal time + equation of time + 4 min per degree east.
        let utc_minutes = (jd + 0.5).fract() * 1440.0;
        let solar_minutes = utc_minutes + eot_minutes + 4.0 * site.longitude;
        let hour_angle = wrap_degrees(solar_minutes / 4.0 - 180.0);
        let (altitude, azimuth) = horizontal(site.latitude, declination, hour_angle);
        SolarAngles {
            altitude: altitude + refraction(altitude),
            azimuth,
        }
    }

    /// The compass azimuth: degrees east of north, in [0°, 360°).
    pub fn azimuth_from_north(&self) -> f64 {
        (self.azimuth + 180.0).rem_euclid(360.0)
    }

    /// The unit direction towards the sun in the local frame (x east, y north, z up), as
    /// `gensky` writes it: (−sin A cos h, −cos A cos h, sin h).
    pub fn local_dir(&self) -> DVec3 {
        let (sin_h, cos_h) = self.altitude.to_radians().sin_cos();
        let (sin_a, cos_a) = self.azimuth.to_radians().sin_cos();
        DVec3::new(-sin_a * cos_h, -cos_a * cos_h, sin_h)
    }

    /// The angles of a unit direction towards the sun in the local frame (x east, y north,
    /// z up): the inverse of [`SolarAngles::local_dir`] (straight up reads azimuth 0).
    pub fn from_local_dir(d: DVec3) -> Result<SolarAngles, Invalid> {
        let altitude = d.z.clamp(-1.0, 1.0).asin().to_degrees();
        let azimuth = if d.x == 0.0 && d.y == 0.0 {
            0.0
        } else {
            (-d.x).atan2(-d.y).to_degrees()
        };
        SolarAngles::new(altitude, azimuth)
    }
}

/// A place on the earth, in degrees.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Site {
    /// Latitude, degrees north (south negative).
    pub latitude: f64,
    /// Longitude, degrees **east** of Greenwich (west negative), as ISO 6709 and NREL's SPA.
    /// `gensky -o` counts west positive: see [`Site::from_gensky`].
    pub longitude: f64,
}

impl Site {
    /// Latitude (°N) and longitude (°E); refuses values off the globe.
    pub fn new(latitude: f64, longitude: f64) -> Result<Site, Invalid> {
        if !(latitude.abs() <= 90.0 && longitude.abs() <= 180.0) {
            return Invalid::err(format!(
                "--site: latitude {latitude}°, longitude {longitude}° is not a place on the earth"
            ));
        }
        Ok(Site {
            latitude,
            longitude,
        })
    }

    /// `gensky -a LAT -o LON`: `gensky`'s longitude is degrees **west**.
    pub fn from_gensky(latitude: f64, longitude_west: f64) -> Result<Site, Invalid> {
        Site::new(latitude, -longitude_west)
    }
}

/// A civil date and time (Gregorian calendar) and its offset from UTC.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct DateTime {
    pub year: i32,
    /// 1–12.
    pub month: u32,
    /// 1–31 (as the month allows).
    pub day: u32,
    /// 0–23.
    pub hour: u32,
    /// 0–59.
    pub minute: u32,
    /// [0, 60).
    pub second: f64,
    /// Hours east of UTC: −7 for US Mountain Standard Time, +1 for CET, 0 for UTC. `gensky`'s
    /// standard meridian `-m` (degrees west) is −15 × this.
    pub utc_offset: f64,
}

impl DateTime {
    /// Checks the fields' ranges (the day against the month, leap years included).
    pub fn validate(&self) -> Result<(), Invalid> {
        let ok = (1..=12).contains(&self.month)
            && self.day >= 1
            && self.day <= days_in_month(self.year, self.month)
            && self.hour < 24
            && self.minute < 60
            && (0.0..60.0).contains(&self.second)
            && self.utc_offset.abs() <= 14.0;
        if ok {
            Ok(())
        } else {
            Invalid::err(format!("--sun: bad date and time: {self:?}"))
        }
    }

    /// The Julian day of this instant (UT), Meeus eq. 7.1 (Gregorian calendar).
    pub fn julian_day(&self) -> f64 {
        let (mut y, mut m) = (self.year as f64, self.month as f64);
        if self.month <= 2 {
            y -= 1.0;
            m += 12.0;
        }
        let a = (y / 100.0).floor();
        let b = 2.0 - a + (a / 4.0).floor();
        let day_start =
            (365.25 * (y + 4716.0)).floor() + (30.6001 * (m + 1.0)).floor() + self.day as f64 + b
                - 1524.5;
        let hours = self.hour as f64 + self.minute as f64 / 60.0 + self.second / 3600.0;
        day_start + (hours - self.utc_offset) / 24.0
    }
}

/// `YYYY-MM-DDTHH:MM[:SS[.s]]` then `Z` or `±HH[:MM]` (a space may stand for the `T`), e.g.
/// `2003-10-17T12:30:30-07:00`. The offset is required: a local time alone is ambiguous. The
/// error does not name the flag (the flag's parser does).
impl FromStr for DateTime {
    type Err = Invalid;

    fn from_str(s: &str) -> Result<DateTime, Invalid> {
        let bad = || {
            Invalid(format!(
                "bad date and time: {s:?} (expected e.g. 2003-10-17T12:30:30-07:00)"
            ))
        };
        let s = s.trim();
        let (date, rest) = s.split_once(['T', ' ']).ok_or_else(bad)?;
        let (clock, utc_offset) = split_offset(rest.trim()).ok_or_else(bad)?;
        let d: Vec<&str> = date.split('-').collect();
        let c: Vec<&str> = clock.split(':').collect();
        if d.len() != 3 || !(2..=3).contains(&c.len()) {
            return Err(bad());
        }
        let t = DateTime {
            year: d[0].parse().map_err(|_| bad())?,
            month: d[1].parse().map_err(|_| bad())?,
            day: d[2].parse().map_err(|_| bad())?,
            hour: c[0].parse().map_err(|_| bad())?,
            minute: c[1].parse().map_err(|_| bad())?,
            second: c.get(2).map_or(Ok(0.0), |x| x.parse()).map_err(|_| bad())?,
            utc_offset,
        };
        t.validate()?;
        Ok(t)
    }
}

/// Splits `HH:MM:SS±HH:MM` (or `...Z`) into the clock and the offset in hours.
fn split_offset(s: &str) -> Option<(&str, f64)> {
    if let Some(clock) = s.strip_suffix(['Z', 'z']) {
        return Some((clock, 0.0));
    }
    let at = s.rfind(['+', '-'])?;
    let (clock, offset) = s.split_at(at);
    let sign = if offset.starts_with('-') { -1.0 } else { 1.0 };
    let (h, m) = offset[1..].split_once(':').unwrap_or((&offset[1..], "0"));
    let hours = h.parse::<u32>().ok()? as f64 + m.parse::<u32>().ok()? as f64 / 60.0;
    Some((clock.trim_end(), sign * hours))
}

/// The days in `month` (1–12) of `year` (Gregorian leap years).
pub(crate) fn days_in_month(year: i32, month: u32) -> u32 {
    let leap = (year % 4 == 0 && year % 100 != 0) || year % 400 == 0;
    match month {
        2 if leap => 29,
        2 => 28,
        4 | 6 | 9 | 11 => 30,
        _ => 31,
    }
}

/// The sun's apparent declination (degrees) and the equation of time (minutes) at Julian day
/// `jd`: Meeus ch. 25 (low accuracy) and eq. 28.3, with NOAA's coefficients.
fn declination_and_equation_of_time(jd: f64) -> (f64, f64) {
    let t = (jd - 2451545.0) / 36525.0;
    let l0 = (280.46646 + t * (36000.76983 + t * 0.0003032)).rem_euclid(360.0);
    let m = 357.52911 + t * (35999.05029 - 0.0001537 * t);
    let e = 0.016708634 - t * (0.000042037 + 0.0000001267 * t);
    let centre = sin_d(m) * (1.914602 - t * (0.004817 + 0.000014 * t))
        + sin_d(2.0 * m) * (0.019993 - 0.000101 * t)
        + sin_d(3.0 * m) * 0.000289;
    // Nutation and aberration by the node of the moon's orbit Ω (Meeus 25.8, 25.8 note).
    let omega = 125.04 - 1934.136 * t;
    let lambda = l0 + centre - 0.00569 - 0.00478 * sin_d(omega);
    let eps0 = 23.0 + (26.0 + (21.448 - t * (46.815 + t * (0.00059 - t * 0.001813))) / 60.0) / 60.0;
    let eps = eps0 + 0.00256 * cos_d(omega);
    let declination = (sin_d(eps) * sin_d(lambda)).asin().to_degrees();
    // Meeus eq. 28.3 (after Smart), in radians, then 4 minutes per degree.
    let y = (eps.to_radians() / 2.0).tan().powi(2);
    let eot = y * sin_d(2.0 * l0) - 2.0 * e * sin_d(m) + 4.0 * e * y * sin_d(m) * cos_d(2.0 * l0)
        - 0.5 * y * y * sin_d(4.0 * l0)
        - 1.25 * e * e * sin_d(2.0 * m);
    (declination, 4.0 * eot.to_degrees())
}

/// Altitude and azimuth (west of south), degrees, of a body at `declination` and `hour_angle`
/// seen from `latitude` (Meeus eq. 13.5, 13.6).
fn horizontal(latitude: f64, declination: f64, hour_angle: f64) -> (f64, f64) {
    let (phi, delta, h) = (
        latitude.to_radians(),
        declination.to_radians(),
        hour_angle.to_radians(),
    );
    let sin_alt = phi.sin() * delta.sin() + phi.cos() * delta.cos() * h.cos();
    let azimuth = h.sin().atan2(h.cos() * phi.sin() - delta.tan() * phi.cos());
    (
        sin_alt.clamp(-1.0, 1.0).asin().to_degrees(),
        azimuth.to_degrees(),
    )
}

/// NOAA's atmospheric refraction (degrees) at apparent altitude `altitude` (degrees), for a
/// standard atmosphere: Bennett-like series above 5°, a polynomial near the horizon.
fn refraction(altitude: f64) -> f64 {
    let t = altitude.to_radians().tan();
    let arcsec = if altitude > 85.0 {
        0.0
    } else if altitude > 5.0 {
        58.1 / t - 0.07 / t.powi(3) + 0.000086 / t.powi(5)
    } else if altitude > -0.575 {
        1735.0 + altitude * (-518.2 + altitude * (103.4 + altitude * (-12.79 + altitude * 0.711)))
    } else {
        -20.772 / t
    };
    arcsec / 3600.0
}

/// `a` in (−180°, 180°].
fn wrap_degrees(a: f64) -> f64 {
    180.0 - (180.0 - a).rem_euclid(360.0)
}

fn sin_d(a: f64) -> f64 {
    a.to_radians().sin()
}

fn cos_d(a: f64) -> f64 {
    a.to_radians().cos()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn local_directions_read_back_as_their_angles() {
        for (alt, azi) in [(45.0, 45.0), (10.0, -120.0), (80.0, 179.0), (-5.0, 0.0)] {
            let a = SolarAngles::new(alt, azi).unwrap();
            let b = SolarAngles::from_local_dir(a.local_dir()).unwrap();
            assert!(
                (b.altitude - alt).abs() < 1e-9 && (b.azimuth - azi).abs() < 1e-9,
                "{b:?}"
            );
        }
    }

    #[test]
    fn julian_days_of_meeus_examples() {
        // Meeus Ex. 7.a (1957 Oct 4.81) and the J2000.0 epoch.
        let t = |year, month, day, hour, minute, second| DateTime {
            year,
            month,
            day,
            hour,
            minute,
            second,
            utc_offset: 0.0,
        };
        assert_eq!(t(2000, 1, 1, 12, 0, 0.0).julian_day(), 2451545.0);
        let jd = t(1957, 10, 4, 19, 26, 24.0).julian_day();
        assert!((jd - 2436116.31).abs() < 1e-6, "{jd}");
        // An offset moves the instant: 12:00 at −7 h is 19:00 UT.
        let local = DateTime {
            utc_offset: -7.0,
            ..t(2000, 1, 1, 12, 0, 0.0)
        };
        assert!((local.julian_day() - 2451545.0 - 7.0 / 24.0).abs() < 1e-9);
    }

    /// Meeus Ex. 25.a: 1992 Oct 13.0 TD, apparent declination −7.78507° (low-accuracy theory,
    /// the one used here); Ex. 28.b: equation of time 13m 42.7s by eq. 28.3.
    #[test]
    fn meeus_declination_and_equation_of_time() {
        let (dec, eot) = declination_and_equation_of_time(2448908.5);
        // Meeus prints 5 decimals; NOAA's rounded Ω terms differ from his by < 1e-5°.
        assert!((dec - -7.78507).abs() < 2e-5, "declination {dec}");
        // 13m 42.7s = 13.712 min; Meeus used the fully nutated obliquity (0.003° apart),
        // which moves E by under 0.005 min.
        assert!((eot - 13.712).abs() < 0.01, "equation of time {eot}");
    }

    /// NREL SPA (Reda & Andreas 2008, the report's worked example): 2003-10-17 12:30:30 at −7 h,
    /// 39.742476°N 105.1786°W → topocentric zenith 50.11162°, azimuth 194.34024° east of north.
    #[test]
    fn nrel_spa_example() {
        let site = Site::new(39.742476, -105.1786).unwrap();
        let time: DateTime = "2003-10-17T12:30:30-07:00".parse().unwrap();
        let sun = SolarAngles::at(&site, &time);
        let zenith = 90.0 - sun.altitude;
        // SPA adds parallax (+0.0024°) and refracts at 820 hPa (0.004° less than NOAA's sea
        // level): NOAA's zenith is expected ~0.006° smaller; 0.01° allows the theories' rest.
        assert!((zenith - 50.11162).abs() < 0.01, "zenith {zenith}");
        assert!(
            (sun.azimuth_from_north() - 194.34024).abs() < 0.01,
            "{sun:?}"
        );
    }

    #[test]
    fn noon_at_the_equator_on_the_equinox_is_overhead_and_midnight_is_below() {
        // 2024-03-20 12:00 local solar time at 0°N 0°E is within ~8 min of 12:00 UT (EoT).
        let site = Site::new(0.0, 0.0).unwrap();
        let noon: DateTime = "2024-03-20T12:00Z".parse().unwrap();
        let sun = SolarAngles::at(&site, &noon);
        // Declination −0.1° and EoT −7.5 min (1.9°) put it about 2° from the zenith.
        assert!(sun.altitude > 87.0, "{sun:?}");
        let midnight: DateTime = "2024-03-20T00:00Z".parse().unwrap();
        assert!(SolarAngles::at(&site, &midnight).altitude < -80.0);
    }

    #[test]
    fn morning_sun_is_east_and_local_dir_follows_gensky() {
        let site = Site::new(45.0, 0.0).unwrap();
        let sun = SolarAngles::at(&site, &"2024-06-21T07:00Z".parse().unwrap());
        assert!(sun.azimuth < -60.0 && sun.azimuth > -120.0, "{sun:?}");
        let d = SolarAngles::new(30.0, 90.0).unwrap().local_dir();
        // West of south 90° is west: −x.
        assert!((d - DVec3::new(-(30f64.to_radians().cos()), 0.0, 0.5)).length() < 1e-12);
    }

    #[test]
    fn parsing_and_validation() {
        let t: DateTime = "2003-10-17 12:30:30.5+05:30".parse().unwrap();
        assert_eq!(
            (t.hour, t.minute, t.second, t.utc_offset),
            (12, 30, 30.5, 5.5)
        );
        for bad in [
            "2003-10-17T12:30",
            "2003-02-29T12:00Z",
            "2003-13-01T00:00Z",
            "noon",
        ] {
            assert!(bad.parse::<DateTime>().is_err(), "{bad}");
        }
        assert!("2004-02-29T23:59:59Z".parse::<DateTime>().is_ok());
        assert!(Site::new(91.0, 0.0).is_err() && Site::new(0.0, f64::NAN).is_err());
        assert_eq!(Site::from_gensky(37.8, 122.2).unwrap().longitude, -122.2);
        assert!(SolarAngles::new(95.0, 0.0).is_err());
    }
}
