//! The daylight flags as the user gives them (`--sky`, `--sun`, `--site`, `--zenith`,
//! `--north`, …), checked here, once, before any model is read, and turned into the
//! [`SkySpec`] a solve is lit by ([`SkySettings::spec`]) and the [`Compass`] the sensor grid's
//! work plane and plans are laid out in ([`SkySettings::compass`]).

use super::{
    Compass, DateTime, Site, SkyKind, SkyLevel, SkySpec, SolarAngles, SunLevel,
    DEFAULT_GROUND_REFLECTANCE, DEFAULT_SKY_ILLUMINANCE, DEFAULT_ZENITH,
};
use crate::settings::Invalid;
use glam::Vec3;
use std::str::FromStr;

/// `--sun`: where the sun is, or none.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SunSetting {
    /// `off` (or `none`): no sun.
    Off,
    /// `ALT,AZI`: altitude and azimuth in degrees (west of south, as `gensky -ang`).
    Angles(f64, f64),
    /// A local time with its UTC offset (needs `--site`).
    Time(DateTime),
}

/// `off`, `ALT,AZI` or a time such as `2026-06-21T12:00+02:00`. The error does not name the
/// flag (the flag's parser does).
impl FromStr for SunSetting {
    type Err = Invalid;

    fn from_str(s: &str) -> Result<SunSetting, Invalid> {
        if s == "off" || s == "none" {
            return Ok(SunSetting::Off);
        }
        if let Some((alt, azi)) = pair(s) {
            return Ok(SunSetting::Angles(alt, azi));
        }
        s.parse::<DateTime>().map(SunSetting::Time).map_err(|e| {
            Invalid(format!(
                "expected ALT,AZI in degrees, a time such as 2026-06-21T12:00+02:00, or off ({e})"
            ))
        })
    }
}

/// Two finite comma-separated numbers.
fn pair(s: &str) -> Option<(f64, f64)> {
    let (a, b) = s.split_once(',')?;
    let a: f64 = a.trim().parse().ok()?;
    let b: f64 = b.trim().parse().ok()?;
    (a.is_finite() && b.is_finite()).then_some((a, b))
}

/// The daylight flags, unchecked: what [`SkySettings::check`] refuses, one line naming the
/// flag, before any work.
#[derive(Clone, Debug, PartialEq)]
pub struct SkySettings {
    /// `--sky`: no sky if `None`.
    pub kind: Option<SkyKind>,
    /// `--sky-illuminance`, lux.
    pub sky_illuminance: Option<f64>,
    /// `--zenith-luminance`, cd/m² (instead of the illuminance).
    pub zenith_luminance: Option<f64>,
    /// `--sun`.
    pub sun: Option<SunSetting>,
    /// `--site LAT,LON`, degrees north and east.
    pub site: Option<(f64, f64)>,
    /// `--sun-illuminance`: the sun's direct normal illuminance, lux.
    pub sun_illuminance: Option<f64>,
    /// `--ground-reflectance`.
    pub ground_reflectance: f64,
    /// `--zenith`: the model's up.
    pub zenith: Vec3,
    /// `--north`; `None`: the default north, which follows the zenith
    /// ([`Compass::default_north`]).
    pub north: Option<Vec3>,
}

impl Default for SkySettings {
    /// No sky; Y up, north −Z.
    fn default() -> SkySettings {
        SkySettings {
            kind: None,
            sky_illuminance: None,
            zenith_luminance: None,
            sun: None,
            site: None,
            sun_illuminance: None,
            ground_reflectance: DEFAULT_GROUND_REFLECTANCE,
            zenith: DEFAULT_ZENITH,
            north: None,
        }
    }
}

impl SkySettings {
    /// Everything [`SkySettings::spec`] and [`Sky::new`](super::Sky::new) would refuse: the
    /// zenith and north (even without a sky: they orient the sensor grid too), a sun without
    /// a sky, a time without a site, the angles, the site, the date, the levels and the
    /// reflectance.
    pub fn check(&self) -> Result<(), Invalid> {
        self.spec().map(|_| ())
    }

    /// The zenith and the north, the default north following the zenith.
    pub fn directions(&self) -> (Vec3, Vec3) {
        let north = self
            .north
            .unwrap_or_else(|| Compass::default_north(self.zenith));
        (self.zenith, north)
    }

    /// The model's orientation (`--zenith`, `--north`).
    pub fn compass(&self) -> Result<Compass, Invalid> {
        let (zenith, north) = self.directions();
        Compass::new(zenith, north)
    }

    /// The sky asked for (checked), or `None` without `--sky`.
    pub fn spec(&self) -> Result<Option<SkySpec>, Invalid> {
        self.compass()?;
        let Some(kind) = self.kind else {
            if self.sun.is_some_and(|s| s != SunSetting::Off) {
                return Invalid::err("--sun needs --sky overcast|clear|uniform");
            }
            return Ok(None);
        };
        let sun_position = match self.sun {
            None | Some(SunSetting::Off) => None,
            Some(SunSetting::Angles(alt, azi)) => Some(SolarAngles::new(alt, azi)?),
            Some(SunSetting::Time(t)) => {
                let Some((lat, lon)) = self.site else {
                    return Invalid::err(
                        "--sun TIME needs --site LAT,LON (degrees, north and east positive)",
                    );
                };
                let site = Site::new(lat, lon)?;
                t.validate()?;
                Some(SolarAngles::at(&site, &t))
            }
        };
        let level = match (self.sky_illuminance, self.zenith_luminance, kind) {
            (Some(lux), _, _) => SkyLevel::HorizontalIlluminance(lux),
            (None, Some(cd), _) => SkyLevel::ZenithLuminance(cd),
            (None, None, SkyKind::Clear) => SkyLevel::Gensky,
            (None, None, _) => SkyLevel::HorizontalIlluminance(DEFAULT_SKY_ILLUMINANCE),
        };
        let sun = sun_position.map(|_| {
            self.sun_illuminance
                .map_or(SunLevel::Gensky, SunLevel::NormalIlluminance)
        });
        let (zenith, north) = self.directions();
        let spec = SkySpec {
            kind,
            level,
            sun_position,
            sun,
            ground_reflectance: self.ground_reflectance,
            zenith,
            north,
        };
        spec.check()?;
        Ok(Some(spec))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn overcast() -> SkySettings {
        SkySettings {
            kind: Some(SkyKind::Overcast),
            ..SkySettings::default()
        }
    }

    #[test]
    fn the_default_north_follows_the_zenith() {
        let y_up = overcast().spec().unwrap().unwrap();
        assert_eq!((y_up.zenith, y_up.north), (Vec3::Y, Vec3::NEG_Z));
        let z_up = SkySettings {
            zenith: Vec3::Z,
            ..overcast()
        };
        let spec = z_up.spec().unwrap().unwrap();
        assert_eq!((spec.zenith, spec.north), (Vec3::Z, Vec3::Y));
        // A north given is kept as given.
        let given = SkySettings {
            north: Some(Vec3::new(1.0, 0.0, 0.0)),
            ..z_up
        };
        assert_eq!(given.spec().unwrap().unwrap().north, Vec3::X);
    }

    #[test]
    fn every_bad_setting_is_one_line_naming_its_flag() {
        let bad = [
            (
                SkySettings {
                    sun: Some(SunSetting::Angles(30.0, 0.0)),
                    ..SkySettings::default()
                },
                "--sun needs --sky",
            ),
            (
                SkySettings {
                    zenith: Vec3::ZERO,
                    ..SkySettings::default()
                },
                "--zenith",
            ),
            (
                SkySettings {
                    north: Some(Vec3::Y),
                    ..overcast()
                },
                "--north",
            ),
            (
                SkySettings {
                    sun: Some(SunSetting::Angles(95.0, 0.0)),
                    ..overcast()
                },
                "--sun: solar altitude",
            ),
            (
                SkySettings {
                    sun: Some("2026-06-21T12:00+02:00".parse().unwrap()),
                    ..overcast()
                },
                "--sun TIME needs --site",
            ),
            (
                SkySettings {
                    sun: Some("2026-06-21T12:00+02:00".parse().unwrap()),
                    site: Some((95.0, 0.0)),
                    ..overcast()
                },
                "--site",
            ),
            (
                SkySettings {
                    // Parsing checks the date too; a date built in code is checked here.
                    sun: Some(SunSetting::Time(DateTime {
                        year: 2026,
                        month: 2,
                        day: 30,
                        hour: 12,
                        minute: 0,
                        second: 0.0,
                        utc_offset: 2.0,
                    })),
                    site: Some((45.0, 0.0)),
                    ..overcast()
                },
                "--sun: bad date",
            ),
            (
                SkySettings {
                    ground_reflectance: 2.0,
                    ..overcast()
                },
                "--ground-reflectance",
            ),
            (
                SkySettings {
                    sky_illuminance: Some(-1.0),
                    ..overcast()
                },
                "--sky-illuminance",
            ),
            (
                SkySettings {
                    zenith_luminance: Some(f64::NAN),
                    ..overcast()
                },
                "--zenith-luminance",
            ),
            (
                SkySettings {
                    sun: Some(SunSetting::Angles(30.0, 0.0)),
                    sun_illuminance: Some(-5.0),
                    ..overcast()
                },
                "--sun-illuminance",
            ),
            (
                SkySettings {
                    kind: Some(SkyKind::Clear),
                    ..SkySettings::default()
                },
                "--sky: the clear sky needs the sun's position",
            ),
        ];
        for (s, start) in bad {
            let e = s.check().unwrap_err().0;
            assert!(e.starts_with(start), "{e:?} does not start with {start:?}");
            assert_eq!(e.lines().count(), 1, "{e}");
        }
    }

    #[test]
    fn sun_values_parse() {
        assert_eq!("off".parse::<SunSetting>().unwrap(), SunSetting::Off);
        assert_eq!(
            "30,-20".parse::<SunSetting>().unwrap(),
            SunSetting::Angles(30.0, -20.0)
        );
        assert!(matches!(
            "2026-06-21T12:00+02:00".parse::<SunSetting>().unwrap(),
            SunSetting::Time(_)
        ));
        assert!("noon".parse::<SunSetting>().is_err());
    }
}
