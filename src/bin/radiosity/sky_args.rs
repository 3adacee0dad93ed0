//! The daylight flags: which sky, how bright, where the sun is, which way is up and north.
//! Parsed here into the library's [`SkySettings`], which checks them
//! ([`SkySettings::check`]) before any model is read, so a bad value is one line naming the
//! flag and exit code 2.

use super::args::{parse_floats, parse_vec3, Xyz};
use clap::Args;
use glam::Vec3;
use radiosity::sky::{
    SkyKind, SkySettings, SunSetting, DEFAULT_GROUND_REFLECTANCE, DEFAULT_ZENITH,
};

/// Daylight: a sky (and sun) that lights the model from outside.
#[derive(Args, Clone)]
pub struct SkyArgs {
    /// Light the model by a sky, with the conventions of Radiance's gensky: the CIE overcast
    /// sky, the CIE clear sky (needs --sun), or a uniform sky; the ground below the horizon
    /// glows with --ground-reflectance.
    #[arg(long, value_enum, value_name = "overcast|clear|uniform")]
    pub sky: Option<SkyKind>,
    /// The sky's unobstructed horizontal illuminance without the sun, lux [default: 10000 for
    /// overcast and uniform; gensky's value from the sun's altitude for clear].
    #[arg(long, value_name = "LUX", allow_negative_numbers = true)]
    pub sky_illuminance: Option<f64>,
    /// The sky's zenith luminance, cd/m² (gensky -b × 179), instead of --sky-illuminance.
    #[arg(
        long,
        value_name = "CD_M2",
        conflicts_with = "sky_illuminance",
        allow_negative_numbers = true
    )]
    pub zenith_luminance: Option<f64>,
    /// A sun: ALT,AZI in degrees (azimuth west of south, as gensky -ang), or a local time
    /// such as 2026-06-21T12:00+02:00 (with --site), or off.
    #[arg(long, value_name = "ALT,AZI|TIME|off", value_parser = parse_sun, allow_hyphen_values = true)]
    pub sun: Option<SunSetting>,
    /// Where the model stands, for --sun TIME: LAT,LON in degrees (north and east positive).
    #[arg(long, value_name = "LAT,LON", value_parser = parse_pair, allow_hyphen_values = true)]
    pub site: Option<(f64, f64)>,
    /// The sun's direct normal illuminance, lux [default: gensky's clear-sky sun].
    #[arg(long, value_name = "LUX", allow_negative_numbers = true)]
    pub sun_illuminance: Option<f64>,
    /// Reflectance of the ground outside the model, which glows below the horizon.
    #[arg(long, default_value_t = DEFAULT_GROUND_REFLECTANCE, value_name = "RHO", allow_negative_numbers = true)]
    pub ground_reflectance: f64,
    /// The model's up direction X,Y,Z. glTF models are Y-up, the default; many OBJ exports
    /// from CAD are Z-up: 0,0,1. (--up is the camera's up, not the model's.)
    #[arg(long, value_parser = Xyz::parse, allow_hyphen_values = true, default_value_t = Xyz(DEFAULT_ZENITH))]
    pub zenith: Xyz,
    /// The model's north X,Y,Z (its horizontal part counts) [default: 0,0,-1 with the default
    /// zenith, 0,1,0 with --zenith 0,0,1 (Radiance's convention); in general −Z turned by the
    /// shortest rotation from +Y to the zenith].
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub north: Option<Vec3>,
    /// Illuminance sensors: HEIGHT,SPACING in metres (a work plane above each floor: an
    /// upward surface with at least 2.3 m clear above it; indoors only, see --grid-outdoor),
    /// or a CSV file of points with columns x,y,z,nx,ny,nz. Writes grid.csv
    /// (x,y,z,nx,ny,nz,lux,df,storey,room,indoor), the plan grid.png, and the grid's
    /// mean/min/uniformity, per storey and per room, in summary.json.
    #[arg(long, value_name = "HEIGHT,SPACING|POINTS.csv")]
    pub grid: Option<radiosity::grid::GridSpec>,
    /// Rays each grid sensor gathers.
    #[arg(long, default_value_t = radiosity::pipeline::daylight::DEFAULT_GRID_RAYS, value_name = "N")]
    pub grid_rays: usize,
    /// The work plane's outdoor sensors (nothing over them: a garden, a terrace): drop leaves
    /// them out (if a model has no roof at all, all are kept, with a warning); keep keeps
    /// them, marked indoor 0 in grid.csv. Points from a file are always kept.
    #[arg(long, value_enum, default_value_t = radiosity::grid::Outdoor::Drop, value_name = "drop|keep")]
    pub grid_outdoor: radiosity::grid::Outdoor,
}

impl SkyArgs {
    /// The daylight flags as the library's settings (checked there: [`SkySettings::check`]).
    pub fn settings(&self) -> SkySettings {
        SkySettings {
            kind: self.sky,
            sky_illuminance: self.sky_illuminance,
            zenith_luminance: self.zenith_luminance,
            sun: self.sun,
            site: self.site,
            sun_illuminance: self.sun_illuminance,
            ground_reflectance: self.ground_reflectance,
            zenith: self.zenith.0,
            north: self.north,
        }
    }
}

fn parse_pair(s: &str) -> Result<(f64, f64), String> {
    parse_floats::<2>(s).map(|[a, b]| (a, b))
}

fn parse_sun(s: &str) -> Result<SunSetting, String> {
    s.parse().map_err(|e: radiosity::settings::Invalid| e.0)
}
