//! The sky of each hour as Radiance's `gendaymtx` makes it: the Perez all-weather sky
//! ([`super::perez`]) over the Reinhart patches ([`super::reinhart`]), the ground and the sun,
//! one vector per hour, and the hours' matrix.
//!
//! **A sky vector** has 1 + 144 MF² + 1 values, `gendaymtx`'s rows: the ground first (index 0),
//! then the sky patches in `reinhartb.cal`'s order (row by row from the horizon, each from north
//! going east, the zenith cap last). Each value is a radiance in W/sr/m² of visible light,
//! `gendaymtx -O0`'s output: luminance / 179 (Radiance's white efficacy,
//! [`super::EFFICACY`]). Sky and ground are white (`gendaymtx -c 1 1 1`; its default sky colour
//! is a slightly blue 0.96 1.004 1.118 whose luminance is 0.9998 of white).
//!
//! **Normalisation**, as `gendaymtx`'s `ComputeSky`: the relative luminance lv (Perez 1993,
//! eq. 1) is taken at each patch's centre ([`Sampling::Centre`]) and scaled so that
//! Σ L_k sin(a_k) Ω_k over the sky patches, a_k the centre's altitude and Ω_k the solid angle,
//! is the diffuse horizontal illuminance of the efficacy model (Perez 1990, eq. 7) over 179.
//! [`Sampling::Integrated`] integrates lv cos θ over each patch instead (Gauss–Legendre) and
//! normalises by the exact projected solid angles: no longer `gendaymtx`'s numbers near the sun,
//! but an exact horizontal illuminance.
//!
//! **The ground** is uniform: ρ_g (E_d + E_s sin h) / π / 179, E_d the diffuse and E_s the
//! direct normal illuminance, the latter only with the sun above the horizon (h > 0): `-g`.
//!
//! **The sun**, by default ([`SunMode::InPatches`]), is `gendaymtx`'s `AddDirect`: its direct
//! normal illuminance E_s is shared among the 4 patches whose centres are nearest its direction
//! (largest cosine c), weight 1 / (1.002 − c), each share divided by its patch's solid angle,
//! whatever the altitude (`gendaymtx` does so even for a sun just below the horizon).
//! [`SunMode::Separate`] leaves it out of the patches and returns it as a [`SunBeam`] when it is
//! in the sky (altitude above minus the disc's radius, `gendaymtx -D`'s test), for a solver
//! that traces shadow rays to it.
//!
//! **No light** (E_dir + E_dif ≤ 10⁻⁴ W/m²) gives zeros, as `gendaymtx`; a sun below the
//! horizon with diffuse light does not: `gendaymtx` then puts the sun on the horizon (Z = 90°)
//! and makes a sky. The hour's sun position is the caller's: [`Hour::at`] uses the tool's NOAA
//! position ([`SolarAngles::at`]), [`Hour::gendaymtx`] `gendaymtx`'s own (Radiance's `sun.c`).

use super::perez::{PerezInput, PerezSky, DEFAULT_DEW_POINT};
use super::reinhart::{self, SkyPatch};
use super::solar::{DateTime, Site, SolarAngles};
use super::EFFICACY;
use crate::settings::Invalid;
use glam::DVec3;
use std::f64::consts::PI;

/// `gendaymtx`'s solar disc, full angle in degrees (`SUN_ANG_DEG`).
pub const SUN_DISC_DEGREES: f64 = 0.533;

/// Patches `gendaymtx` spreads the sun over (`NSUNPATCH`).
pub const SUN_PATCHES: usize = 4;

/// Below this, W/m² (direct + diffuse), an hour is dark.
const DARK: f64 = 1e-4;

/// One hour of weather at a site: the sun's position, the irradiances and the dew point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hour {
    /// Day of the year, 1 = 1 January (for the extraterrestrial irradiance).
    pub day_of_year: u32,
    /// The sun's position (altitude; azimuth west of south, [`SolarAngles`]' convention).
    pub sun: SolarAngles,
    /// Direct normal irradiance, W/m².
    pub dni: f64,
    /// Diffuse horizontal irradiance, W/m².
    pub dhi: f64,
    /// Surface dew point, °C ([`DEFAULT_DEW_POINT`] when the weather gives none).
    pub dew_point: f64,
}

impl Hour {
    /// An hour from its parts, at the default dew point; the numbers are checked when the sky
    /// is made ([`PerezSky::new`]).
    pub fn new(day_of_year: u32, sun: SolarAngles, dni: f64, dhi: f64) -> Hour {
        Hour {
            day_of_year,
            sun,
            dni,
            dhi,
            dew_point: DEFAULT_DEW_POINT,
        }
    }

    /// The hour at `time` at `site`, the sun by NOAA's algorithm ([`SolarAngles::at`]).
    pub fn at(site: &Site, time: &DateTime, dni: f64, dhi: f64) -> Result<Hour, Invalid> {
        time.validate()?;
        let day = day_of_year(time.month, time.day)?;
        let leap = time.year % 4 == 0 && (time.year % 100 != 0 || time.year % 400 == 0);
        let day = day + u32::from(leap && time.month > 2);
        Ok(Hour::new(day, SolarAngles::at(site, time), dni, dhi))
    }

    /// The hour as `gendaymtx` reads a weather file's line `month day hour dni dhi`: `hour` in
    /// decimal hours of local standard time (`utc_offset` hours east of UTC, the weather
    /// file's time zone) and the sun by `gendaymtx`'s own formulas ([`gendaymtx_sun`]).
    pub fn gendaymtx(
        site: &Site,
        utc_offset: f64,
        month: u32,
        day: u32,
        hour: f64,
        dni: f64,
        dhi: f64,
    ) -> Result<Hour, Invalid> {
        if !(hour.is_finite() && (0.0..=24.0).contains(&hour)) {
            return Invalid::err(format!("the hour {hour} is not within [0, 24]"));
        }
        let day = day_of_year(month, day)?;
        let sun = gendaymtx_sun(site, utc_offset, day, hour);
        Ok(Hour::new(day, sun, dni, dhi))
    }
}

/// Radiance's `jdate`: the day of the year of a date in a common year (29 February is 60,
/// as 1 March).
pub fn day_of_year(month: u32, day: u32) -> Result<u32, Invalid> {
    const FIRST: [u32; 12] = [0, 31, 59, 90, 120, 151, 181, 212, 243, 273, 304, 334];
    // Any leap year: 29 February is a date here.
    if !(1..=12).contains(&month) || day < 1 || day > super::solar::days_in_month(2024, month) {
        return Invalid::err(format!("month {month}, day {day} is not a date"));
    }
    Ok(FIRST[month as usize - 1] + day)
}

/// The sun as `gendaymtx` places it (Radiance's `sun.c`: `sdec`, `stadj`, `salt`, `sazi`):
/// declination δ = 0.4093 sin(2π (J − 81) / 365), solar time t = hour + 0.170 sin(4π (J − 80) /
/// 373) − 0.129 sin(2π (J − 8) / 355) + (standard meridian − longitude) / 15°, then the
/// spherical triangle; no refraction. Coarser than NOAA's by up to about a degree.
pub fn gendaymtx_sun(site: &Site, utc_offset: f64, day_of_year: u32, hour: f64) -> SolarAngles {
    let jd = day_of_year as f64;
    let lat = site.latitude.to_radians();
    // Both west-positive in sun.c; their difference in hours is 12/π per radian.
    let meridian_west = (-15.0 * utc_offset).to_radians();
    let longitude_west = (-site.longitude).to_radians();
    let adjust = 0.170 * (4.0 * PI / 373.0 * (jd - 80.0)).sin()
        - 0.129 * (2.0 * PI / 355.0 * (jd - 8.0)).sin()
        + 12.0 * (meridian_west - longitude_west) / PI;
    let dec = 0.4093 * (2.0 * PI / 365.0 * (jd - 81.0)).sin();
    let h = (hour + adjust) * (PI / 12.0);
    let altitude = (lat.sin() * dec.sin() - lat.cos() * dec.cos() * h.cos())
        .clamp(-1.0, 1.0)
        .asin();
    let azimuth =
        -(dec.cos() * h.sin()).atan2(-lat.cos() * dec.sin() - lat.sin() * dec.cos() * h.cos());
    SolarAngles {
        altitude: altitude.to_degrees(),
        azimuth: azimuth.to_degrees(),
    }
}

/// Where the sun's direct light goes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SunMode {
    /// Into the 4 patches nearest the sun, as `gendaymtx` by default.
    #[default]
    InPatches,
    /// Out of the patches, returned as a [`SunBeam`] (as `gendaymtx -s` plus `-D`).
    Separate,
}

/// How a patch's share of the Perez distribution is taken.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Sampling {
    /// At the patch centre, normalised by Σ lv sin(a) Ω, as `gendaymtx`.
    #[default]
    Centre,
    /// Integrated over the patch (Gauss–Legendre, 2 × 2 cells of 4 × 4 points).
    Integrated,
}

/// What sky vectors are made of.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SkyOptions {
    /// The Reinhart subdivision MF (1 = Tregenza's 145 patches; `gendaymtx -m`).
    pub subdivision: u32,
    /// Ground reflectance ρ_g, in [0, 1] (`gendaymtx -g`, default 0.2).
    pub ground_reflectance: f64,
    pub sun: SunMode,
    pub sampling: Sampling,
}

impl Default for SkyOptions {
    /// `gendaymtx`'s defaults: MF 1, ρ_g 0.2, the sun in the patches, centre sampling.
    fn default() -> SkyOptions {
        SkyOptions {
            subdivision: 1,
            ground_reflectance: super::DEFAULT_GROUND_REFLECTANCE,
            sun: SunMode::InPatches,
            sampling: Sampling::Centre,
        }
    }
}

/// The sun of an hour, for a solver that traces it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SunBeam {
    /// Where it is (as the hour gave it, not clamped).
    pub angles: SolarAngles,
    /// Unit direction towards it: x east, y north, z up.
    pub dir: DVec3,
    /// Direct normal illuminance, lux (Perez 1990, eq. 8).
    pub normal_illuminance: f64,
}

impl SunBeam {
    /// Direct normal irradiance of visible light, W/m²: lux / 179.
    pub fn normal_irradiance(&self) -> f64 {
        self.normal_illuminance / EFFICACY
    }

    /// The radiance of a disc of [`SUN_DISC_DEGREES`] carrying it, W/sr/m² (`gendaymtx -D`'s
    /// `light` value): E / (179 π r²).
    pub fn disc_radiance(&self) -> f64 {
        let r = (SUN_DISC_DEGREES / 2.0).to_radians();
        self.normal_irradiance() / (PI * r * r)
    }
}

/// One hour's sky: the radiance per patch (ground first) and the sun if kept apart.
#[derive(Clone, Debug, PartialEq)]
pub struct SkyVector {
    /// W/sr/m² of visible light: `[ground, sky patches…]` (module docs).
    pub radiance: Vec<f64>,
    /// The sun, with [`SunMode::Separate`] when it is in the sky and shines.
    pub sun: Option<SunBeam>,
    /// Diffuse horizontal illuminance, lux (Perez 1990, eq. 7); 0 for a dark hour.
    pub diffuse_illuminance: f64,
    /// Direct normal illuminance, lux (Perez 1990, eq. 8); 0 for a dark hour.
    pub direct_illuminance: f64,
}

/// The patches and options that turn hours into [`SkyVector`]s.
#[derive(Clone, Debug)]
pub struct SkyVectors {
    options: SkyOptions,
    patches: Vec<SkyPatch>,
    /// Per patch: its centre's direction and sin(altitude) × solid angle (`Centre`), or its
    /// exact projected solid angle (`Integrated`).
    dirs: Vec<DVec3>,
    weights: Vec<f64>,
}

impl SkyVectors {
    /// Checks `options` (the subdivision, ρ_g in [0, 1]) and lays out the patches.
    pub fn new(options: SkyOptions) -> Result<SkyVectors, Invalid> {
        let rho = options.ground_reflectance;
        if !(0.0..=1.0).contains(&rho) {
            return Invalid::err(format!(
                "--ground-reflectance: the ground reflectance {rho} is not within [0, 1]"
            ));
        }
        let patches = reinhart::patches(options.subdivision)?;
        let dirs = patches.iter().map(SkyPatch::dir).collect();
        let weights = patches
            .iter()
            .map(|p| match options.sampling {
                Sampling::Centre => p.cos() * p.solid_angle(),
                Sampling::Integrated => p.band.projected_solid_angle(),
            })
            .collect();
        Ok(SkyVectors {
            options,
            patches,
            dirs,
            weights,
        })
    }

    /// The values per hour: 1 (ground) + the sky patches.
    pub fn len(&self) -> usize {
        1 + self.patches.len()
    }

    /// Never: there is always the ground and the cap.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// The sky patches, in the vectors' order after the ground.
    pub fn patches(&self) -> &[SkyPatch] {
        &self.patches
    }

    /// The sky of `hour` (module docs). Refuses what [`PerezSky::new`] refuses.
    pub fn hour(&self, hour: &Hour) -> Result<SkyVector, Invalid> {
        let sun = &hour.sun;
        let sky = PerezSky::new(&PerezInput {
            day_of_year: hour.day_of_year,
            altitude: sun.altitude,
            azimuth: sun.azimuth_from_north(),
            dni: hour.dni,
            dhi: hour.dhi,
            dew_point: hour.dew_point,
        })?;
        let mut out = SkyVector {
            radiance: vec![0.0; self.len()],
            sun: None,
            diffuse_illuminance: 0.0,
            direct_illuminance: 0.0,
        };
        if hour.dni + hour.dhi <= DARK {
            return Ok(out);
        }
        out.diffuse_illuminance = sky.diffuse_illuminance;
        out.direct_illuminance = sky.direct_illuminance;
        let altitude = sun.altitude.to_radians();
        let on_ground = if altitude > 0.0 {
            sky.direct_illuminance * altitude.sin()
        } else {
            0.0
        };
        out.radiance[0] =
            self.options.ground_reflectance * (sky.diffuse_illuminance + on_ground) / PI / EFFICACY;
        self.fill_sky(&sky, &mut out.radiance[1..]);
        if sky.direct_illuminance > DARK {
            let beam = SunBeam {
                angles: *sun,
                dir: sun.local_dir(),
                normal_illuminance: sky.direct_illuminance,
            };
            match self.options.sun {
                SunMode::InPatches => self.add_sun(&beam, &mut out.radiance[1..]),
                SunMode::Separate => {
                    let in_sky = sun.altitude > -SUN_DISC_DEGREES / 2.0;
                    out.sun = in_sky.then_some(beam);
                }
            }
        }
        Ok(out)
    }

    /// The sky patches' radiances, normalised to the diffuse illuminance (module docs).
    fn fill_sky(&self, sky: &PerezSky, out: &mut [f64]) {
        let sun = sky.sun_dir();
        for (k, v) in out.iter_mut().enumerate() {
            *v = match self.options.sampling {
                Sampling::Centre => sky.relative_luminance(self.dirs[k], sun),
                Sampling::Integrated => {
                    let band = &self.patches[k].band;
                    let q = band.integrate_cells(2, |d| sky.relative_luminance(d, sun));
                    q / self.weights[k]
                }
            };
        }
        let mut norm: f64 = out.iter().zip(&self.weights).map(|(l, w)| l * w).sum();
        if norm <= 1e-9 {
            // gendaymtx: a sky of zero is made uniform.
            out.fill(1.0);
            norm = PI;
        }
        let scale = sky.diffuse_illuminance / norm / EFFICACY;
        out.iter_mut().for_each(|v| *v *= scale);
    }

    /// `gendaymtx`'s `AddDirect`: the sun shared among the [`SUN_PATCHES`] nearest patches.
    fn add_sun(&self, beam: &SunBeam, out: &mut [f64]) {
        // (cosine, patch), largest first; a tie keeps the earlier patch, as gendaymtx.
        let mut near = [(-1.0f64, 0usize); SUN_PATCHES];
        for (k, d) in self.dirs.iter().enumerate() {
            let c = d.dot(beam.dir);
            if let Some(i) = near.iter().position(|&(best, _)| c > best) {
                near.copy_within(i..SUN_PATCHES - 1, i + 1);
                near[i] = (c, k);
            }
        }
        let weight = |c: f64| 1.0 / (1.002 - c);
        let total: f64 = near.iter().map(|&(c, _)| weight(c)).sum();
        for &(c, k) in &near {
            let share = weight(c) / total * beam.normal_irradiance();
            out[k] += share / self.patches[k].solid_angle();
        }
    }
}

/// Sky vectors for many hours: `hours × (1 + sky patches)` radiances (W/sr/m², f32), rows in
/// the hours' order, columns ground first then the sky patches (module docs), and the suns
/// kept apart with [`SunMode::Separate`]. `gendaymtx` writes the transpose (patches as rows).
#[derive(Clone, Debug, PartialEq)]
pub struct SkyMatrix {
    columns: usize,
    values: Vec<f32>,
    suns: Vec<Option<SunBeam>>,
}

impl SkyMatrix {
    /// The sky of every hour; refuses bad options or the first bad hour (naming it, 1-based).
    pub fn build(hours: &[Hour], options: SkyOptions) -> Result<SkyMatrix, Invalid> {
        let vectors = SkyVectors::new(options)?;
        let columns = vectors.len();
        let mut values = Vec::with_capacity(hours.len() * columns);
        let mut suns = Vec::with_capacity(hours.len());
        for (i, hour) in hours.iter().enumerate() {
            let v = vectors
                .hour(hour)
                .map_err(|e| Invalid(format!("hour {}: {}", i + 1, e.0)))?;
            values.extend(v.radiance.iter().map(|&x| x as f32));
            suns.push(v.sun);
        }
        Ok(SkyMatrix {
            columns,
            values,
            suns,
        })
    }

    /// The number of hours (rows).
    pub fn hours(&self) -> usize {
        self.suns.len()
    }

    /// Values per hour: 1 (ground) + the sky patches.
    pub fn columns(&self) -> usize {
        self.columns
    }

    /// Hour `h`'s radiances, ground first; `None` past the last hour.
    pub fn row(&self, h: usize) -> Option<&[f32]> {
        self.values.get(h * self.columns..(h + 1) * self.columns)
    }

    /// Hour `h`'s sun, with [`SunMode::Separate`] when it shone.
    pub fn sun(&self, h: usize) -> Option<&SunBeam> {
        self.suns.get(h).and_then(Option::as_ref)
    }
}

#[cfg(test)]
#[path = "matrix_tests.rs"]
mod tests;
