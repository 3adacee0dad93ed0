//! The daylight flags (issue 14): which sky, how bright, where the sun is, which way is up and
//! north. Parsed here; checked by the library ([`radiosity::sky::Sky::new`]), so a bad value
//! is one line naming the flag and a non-zero exit.

use crate::args::{parse_floats, parse_vec3};
use clap::Args;
use glam::Vec3;
use radiosity::sky::{
    DateTime, Site, SkyKind, SkyLevel, SkySpec, SolarAngles, SunLevel, DEFAULT_GROUND_REFLECTANCE,
    DEFAULT_SKY_ILLUMINANCE,
};

/// Daylight: a sky (and sun) that lights the model from outside.
#[derive(Args, Clone)]
pub struct SkyArgs {
    /// Light the model by a sky, with the conventions of Radiance's gensky: the CIE overcast
    /// sky, the CIE clear sky (needs --sun), or a uniform sky; the ground below the horizon
    /// glows with --ground-reflectance.
    #[arg(long, value_enum, value_name = "overcast|clear|uniform")]
    pub sky: Option<SkyArg>,
    /// The sky's unobstructed horizontal illuminance without the sun, lux [default: 10000 for
    /// overcast and uniform; gensky's value from the sun's altitude for clear].
    #[arg(long, value_name = "LUX")]
    pub sky_illuminance: Option<f64>,
    /// The sky's zenith luminance, cd/m² (gensky -b × 179), instead of --sky-illuminance.
    #[arg(long, value_name = "CD_M2", conflicts_with = "sky_illuminance")]
    pub zenith_luminance: Option<f64>,
    /// A sun: ALT,AZI in degrees (azimuth west of south, as gensky -ang), or a local time
    /// such as 2026-06-21T12:00+02:00 (with --site), or off.
    #[arg(long, value_name = "ALT,AZI|TIME|off", value_parser = parse_sun, allow_hyphen_values = true)]
    pub sun: Option<SunArg>,
    /// Where the model stands, for --sun TIME: LAT,LON in degrees (north and east positive).
    #[arg(long, value_name = "LAT,LON", value_parser = parse_pair, allow_hyphen_values = true)]
    pub site: Option<(f64, f64)>,
    /// The sun's direct normal illuminance, lux [default: gensky's clear-sky sun].
    #[arg(long, value_name = "LUX")]
    pub sun_illuminance: Option<f64>,
    /// Reflectance of the ground outside the model, which glows below the horizon.
    #[arg(long, default_value_t = DEFAULT_GROUND_REFLECTANCE, value_name = "RHO")]
    pub ground_reflectance: f64,
    /// The model's up direction X,Y,Z.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true, default_value = "0,1,0")]
    pub zenith: Vec3,
    /// The model's north X,Y,Z (its horizontal part counts).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true, default_value = "0,0,-1")]
    pub north: Vec3,
    /// Illuminance sensors: HEIGHT,SPACING in metres (a work plane above each floor: an
    /// upward surface with at least 2.3 m clear above it), or a CSV file of points with
    /// columns x,y,z,nx,ny,nz. Writes grid.csv (x,y,z,nx,ny,nz,lux,df), the plan grid.png,
    /// and the grid's mean/min/uniformity in summary.json.
    #[arg(long, value_name = "HEIGHT,SPACING|POINTS.csv")]
    pub grid: Option<radiosity::grid::GridSpec>,
    /// Rays each grid sensor gathers.
    #[arg(long, default_value_t = radiosity::pipeline::daylight::DEFAULT_GRID_RAYS, value_name = "N")]
    pub grid_rays: usize,
}

/// `--sky`.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SkyArg {
    Overcast,
    Clear,
    Uniform,
}

/// `--sun`.
#[derive(Clone, Debug, PartialEq)]
pub enum SunArg {
    Off,
    Angles(f64, f64),
    Time(DateTime),
}

fn parse_sun(s: &str) -> Result<SunArg, String> {
    if s == "off" || s == "none" {
        return Ok(SunArg::Off);
    }
    if let Ok((alt, azi)) = parse_pair(s) {
        return Ok(SunArg::Angles(alt, azi));
    }
    s.parse::<DateTime>().map(SunArg::Time).map_err(|e| {
        format!("expected ALT,AZI in degrees, a time such as 2026-06-21T12:00+02:00, or off ({e})")
    })
}

fn parse_pair(s: &str) -> Result<(f64, f64), String> {
    parse_floats::<2>(s).map(|[a, b]| (a, b))
}

impl SkyArgs {
    /// The sky asked for, unchecked (the solver checks it: `radiosity::sky::Sky::new`), or
    /// `Err` naming the flags when the sun's time has no --site.
    pub fn spec(&self) -> Result<Option<SkySpec>, String> {
        let Some(kind) = self.sky else {
            if self.sun.as_ref().is_some_and(|s| *s != SunArg::Off) {
                return Err("--sun needs --sky overcast|clear|uniform".into());
            }
            return Ok(None);
        };
        let kind = match kind {
            SkyArg::Overcast => SkyKind::Overcast,
            SkyArg::Clear => SkyKind::Clear,
            SkyArg::Uniform => SkyKind::Uniform,
        };
        let sun_position = match &self.sun {
            None | Some(SunArg::Off) => None,
            Some(SunArg::Angles(alt, azi)) => {
                Some(SolarAngles::new(*alt, *azi).map_err(|e| format!("--sun: {e}"))?)
            }
            Some(SunArg::Time(t)) => {
                let (lat, lon) = self
                    .site
                    .ok_or("--sun TIME needs --site LAT,LON (degrees, north and east positive)")?;
                let site = Site::new(lat, lon).map_err(|e| format!("--site: {e}"))?;
                t.validate().map_err(|e| format!("--sun: {e}"))?;
                Some(SolarAngles::at(&site, t))
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
        Ok(Some(SkySpec {
            kind,
            level,
            sun_position,
            sun,
            ground_reflectance: self.ground_reflectance,
            zenith: self.zenith,
            north: self.north,
        }))
    }
}
