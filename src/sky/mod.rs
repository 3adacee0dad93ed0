//! Daylight: the sky and the sun as distant emitters.
//!
//! This module owns the light that comes from outside the model: the sky's luminance
//! distribution ([`cie`]: uniform, CIE overcast, CIE clear), the sun's position ([`solar`]: NOAA's
//! algorithm) and disc ([`sun`]), the ground glow below the horizon, the model's orientation
//! ([`compass`]), the daylight flags' settings and their check ([`settings`]) and the cut of all of it into directional pieces a shooter can fire parallel
//! rays from ([`tregenza`], [`piece`]). For annual daylight, the sky of each hour of a weather
//! file as Radiance's `gendaymtx` makes it: the Perez all-weather sky and luminous efficacy
//! ([`perez`]) over the Reinhart patches ([`reinhart`]), per hour and for a year of hours
//! ([`matrix`]). It follows the conventions of Radiance's `gensky`, so a
//! scene can be checked against Radiance:
//!
//! - the zenith parameter L_z is `gensky -b` (in cd/m² here, W/sr/m² there: divide by 179);
//! - the horizontal illuminance is the sky's alone, without the sun (`gensky -B`);
//! - solar azimuth is degrees west of south (`gensky -ang ALT AZI`);
//! - the ground below the horizon is uniform with radiance ρ_g E_h / π, E_h the sky's plus the
//!   sun's horizontal irradiance and ρ_g the ground reflectance (`gensky -g`, default 0.2).
//!
//! Departures: the horizon is sharp (`skybright.cal` blends sky into ground over a few degrees
//! with weights (cos θ + 1.01)^±10, which lowers an overcast sky's horizontal illuminance by
//! 0.14 % and a vertical window's by 0.3 %), so the pieces carry exactly the stated horizontal
//! illuminance; a clear sky's sun above 87° stays where it is (`gensky` lowers it to 87°); the
//! clear sky's E_h / L_z is integrated (`gensky -B` uses a quartic fit, 0.25 % off at worst);
//! the sun's position is NOAA's (`gensky`'s own date formula is far coarser). To compare with
//! Radiance, give `gensky` the angles ([`Sky::sun_position`], `-ang`) and the zenith parameter
//! ([`Sky::zenith_luminance`] / 179, `-b`) rather than a date and `-B`. Sky and sun are white:
//! equal RGB radiance.
//!
//! **Units.** Radiance is in W/sr/m² and irradiance in W/m², the solver's units; photometric
//! values (cd/m², lux) convert by [`EFFICACY`].

pub mod cie;
pub mod compass;
pub mod matrix;
pub mod perez;
pub mod piece;
pub mod reinhart;
pub mod settings;
pub mod solar;
pub mod sun;
pub mod tregenza;

pub use cie::SkyKind;
pub use compass::{Compass, DEFAULT_NORTH, DEFAULT_ZENITH};
pub use matrix::{Hour, Sampling, SkyMatrix, SkyOptions, SkyVector, SkyVectors, SunBeam, SunMode};
pub use piece::{PieceKind, SkyPiece};
pub use settings::{SkySettings, SunSetting};
pub use solar::{DateTime, Site, SolarAngles};
pub use sun::{Sun, SunLevel};

use crate::settings::Invalid;
use glam::{DVec3, Vec3};
use std::f64::consts::PI;

/// Luminous efficacy of white light, lm/W: luminance (cd/m²) = 179 × radiance (W/sr/m²) and
/// illuminance (lux) = 179 × irradiance (W/m²). Radiance's convention for white light (its
/// `rtrace -I` results are turned into lux with the same factor).
pub const EFFICACY: f64 = 179.0;

/// `gensky`'s default ground reflectance (`-g`).
pub const DEFAULT_GROUND_REFLECTANCE: f64 = 0.2;

/// The default unobstructed horizontal illuminance of the sky, lux (the overcast and uniform
/// skies' default).
pub const DEFAULT_SKY_ILLUMINANCE: f64 = 10_000.0;

/// How bright the sky is; either value gives the other.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SkyLevel {
    /// The zenith parameter L_z, cd/m² (`gensky -b` × 179).
    ZenithLuminance(f64),
    /// Unobstructed horizontal illuminance of the sky alone, lux (`gensky -B` × 179).
    HorizontalIlluminance(f64),
    /// `gensky`'s default from the sun's altitude ([`cie::gensky_zenith_luminance`]).
    Gensky,
}

/// A sky of daylight coefficients ([`Sky::coefficients`]): the Reinhart subdivision MF and,
/// to check a channel against a plain solve, the one column lit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct CoefficientSky {
    pub subdivision: u32,
    /// Light only this column (0 the ground, 1 + k sky patch k); `None`: all at radiance 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub only: Option<usize>,
}

/// What a sky is made of: the settings, checked by [`SkySpec::check`] (which [`Sky::new`]
/// and [`crate::solve::SolveSettings::check`] call). The flags are turned into one by
/// [`SkySettings::spec`].
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SkySpec {
    pub kind: SkyKind,
    pub level: SkyLevel,
    /// Where the sun is. Needed by the clear sky, by a sun and by [`SkyLevel::Gensky`].
    pub sun_position: Option<SolarAngles>,
    /// Draw a sun this bright (`None`: no sun, as `gensky -s`, `-c`, `-u`).
    pub sun: Option<SunLevel>,
    /// ρ_g, in [0, 1].
    pub ground_reflectance: f64,
    /// The model's up direction (any length).
    pub zenith: Vec3,
    /// The model's north (any length; only its horizontal part counts).
    pub north: Vec3,
}

impl Default for SkySpec {
    /// An overcast sky of [`DEFAULT_SKY_ILLUMINANCE`], no sun, ρ_g = 0.2, Y up, north −Z.
    fn default() -> SkySpec {
        SkySpec {
            kind: SkyKind::Overcast,
            level: SkyLevel::HorizontalIlluminance(DEFAULT_SKY_ILLUMINANCE),
            sun_position: None,
            sun: None,
            ground_reflectance: DEFAULT_GROUND_REFLECTANCE,
            zenith: DEFAULT_ZENITH,
            north: DEFAULT_NORTH,
        }
    }
}

/// A sky ready to light a scene.
#[derive(Clone, Debug)]
pub struct Sky {
    kind: SkyKind,
    compass: Compass,
    /// The sun's direction for the clear sky's distribution (local; the zenith if unused).
    sun_local: DVec3,
    sun_position: Option<SolarAngles>,
    sun: Option<Sun>,
    sun_below_horizon: bool,
    /// L_z, W/sr/m².
    zenith_radiance: f64,
    /// E_h / L_z, steradians.
    ratio: f64,
    /// ρ_g E_h / π, W/sr/m².
    ground_radiance: f64,
    pieces: Vec<SkyPiece>,
    /// What a daylight-coefficient sky is ([`Sky::coefficients`]).
    coefficients: Option<CoefficientSky>,
}

impl Sky {
    /// Checks `spec` and builds the sky, its sun and its pieces.
    pub fn new(spec: &SkySpec) -> Result<Sky, Invalid> {
        spec.check()?;
        let compass = Compass::new(spec.zenith, spec.north)?;
        let sun_local = spec.sun_position.map_or(DVec3::Z, |a| a.local_dir());
        let bands = tregenza::patches();
        // ∫ (L / L_z) cos θ dω per patch: the pieces' radiances and, summed, E_h / L_z.
        let q: Vec<f64> = bands
            .iter()
            .map(|b| b.integrate(|d| spec.kind.relative(d, sun_local)))
            .collect();
        let ratio: f64 = q.iter().sum();
        let zenith_radiance = zenith_radiance(spec, ratio);
        let sun = match (spec.sun, spec.sun_position) {
            (Some(level), Some(angles)) => Sun::new(angles, level, &compass),
            _ => None,
        };
        let e_total = zenith_radiance * ratio + sun.map_or(0.0, |s| s.horizontal_irradiance());
        let mut sky = Sky {
            kind: spec.kind,
            compass,
            sun_local,
            sun_position: spec.sun_position,
            sun,
            sun_below_horizon: spec.sun.is_some() && sun.is_none(),
            zenith_radiance,
            ratio,
            ground_radiance: spec.ground_reflectance * e_total / PI,
            pieces: Vec::new(),
            coefficients: None,
        };
        sky.pieces = sky.build_pieces(&bands, &q);
        Ok(sky)
    }

    /// The sky of daylight coefficients (Tregenza 1983; Radiance's `rfluxmtx` sky): every
    /// direction of the sky and of the ground at radiance 1 W/sr/m², cut into the
    /// subdivision's Reinhart patches ([`reinhart::patches`]; MF 1 is Tregenza's 145) and the
    /// ground's mirrored Tregenza patches, with no sun. A solve under it with one light
    /// channel per patch and one for the ground ([`Sky::coefficient_channel`]) holds, in each
    /// channel, the model's response to that patch alone at unit radiance: any sky of those
    /// patches (an hour of a weather file, [`matrix::SkyVectors`]) is then a weighted sum of
    /// the channels. With `only`, that one column alone is lit (0 the ground, 1 + k sky patch
    /// k): the plain solve a channel must agree with. Orientation from `spec`'s zenith and
    /// north; its other fields are not used.
    pub fn coefficients(spec: &SkySpec, c: &CoefficientSky) -> Result<Sky, Invalid> {
        let compass = Compass::new(spec.zenith, spec.north)?;
        let patches = reinhart::patches(c.subdivision)?;
        if let Some(k) = c.only.filter(|&k| k > patches.len()) {
            return Invalid::err(format!(
                "sky column {k} is past the last of MF {} ({})",
                c.subdivision,
                patches.len()
            ));
        }
        let lit = |column: usize| {
            if c.only.is_none_or(|k| k == column) {
                1.0
            } else {
                0.0
            }
        };
        let sky = patches
            .iter()
            .enumerate()
            .map(|(k, p)| SkyPiece::band(PieceKind::Sky, k, p.band, lit(k + 1), compass));
        let ground = tregenza::patches()
            .into_iter()
            .enumerate()
            .map(|(k, b)| SkyPiece::band(PieceKind::Ground, k, b.mirrored(), lit(0), compass));
        Ok(Sky {
            kind: SkyKind::Uniform,
            compass,
            sun_local: DVec3::Z,
            sun_position: None,
            sun: None,
            sun_below_horizon: false,
            zenith_radiance: 1.0,
            ratio: PI,
            ground_radiance: 1.0,
            pieces: sky.chain(ground).collect(),
            coefficients: Some(*c),
        })
    }

    /// A daylight-coefficient sky's subdivision MF ([`Sky::coefficients`]); `None` for others.
    pub fn subdivision(&self) -> Option<u32> {
        self.coefficients.map(|c| c.subdivision)
    }

    /// For a daylight-coefficient sky, the column of [`SkyMatrix`] (0 the ground, 1 + k sky
    /// patch k) that the direction `dir_to_sky` (model coordinates, any length) looks into;
    /// `None` for other skies. At or below the horizon (and for a zero direction): the ground.
    pub fn coefficient_channel(&self, dir_to_sky: Vec3) -> Option<usize> {
        let mf = self.subdivision()?;
        let d = self
            .compass
            .to_local(dir_to_sky.as_dvec3().normalize_or_zero());
        Some(reinhart::patch_of(mf, d).map_or(0, |k| k + 1))
    }

    /// Sky patches (in `tregenza.cal`'s order), then ground patches, then the sun if up.
    fn build_pieces(&self, bands: &[tregenza::Band], q: &[f64]) -> Vec<SkyPiece> {
        let sky = bands.iter().zip(q).enumerate().map(|(k, (b, qk))| {
            let radiance = self.zenith_radiance * qk / b.projected_solid_angle();
            SkyPiece::band(PieceKind::Sky, k, *b, radiance, self.compass)
        });
        let ground = bands.iter().enumerate().map(|(k, b)| {
            SkyPiece::band(
                PieceKind::Ground,
                k,
                b.mirrored(),
                self.ground_radiance,
                self.compass,
            )
        });
        let sun = self.sun.iter().map(|s| SkyPiece::sun(s, self.compass));
        sky.chain(ground).chain(sun).collect()
    }

    /// The distant emitters: 145 sky pieces, 145 ground pieces and the sun when it is up.
    pub fn pieces(&self) -> &[SkyPiece] {
        &self.pieces
    }

    /// The radiance (W/sr/m², RGB) a ray escaping the model towards `dir_to_sky` (any length)
    /// meets: the sky's exact distribution above the horizon, the ground below (and for a zero
    /// or non-finite direction). The sun is **not** included: gathers sample it explicitly
    /// through [`Sky::sun`], as a tiny bright disc is missed by hemisphere sampling.
    pub fn radiance(&self, dir_to_sky: Vec3) -> [f64; 3] {
        let d = self
            .compass
            .to_local(dir_to_sky.as_dvec3().normalize_or_zero());
        if let Some(only) = self.coefficients.and_then(|c| c.only) {
            let column =
                reinhart::patch_of(self.subdivision().unwrap_or(1), d).map_or(0, |k| k + 1);
            return [if column == only { 1.0 } else { 0.0 }; 3];
        }
        if d.z > 0.0 {
            [self.zenith_radiance * self.kind.relative(d, self.sun_local); 3]
        } else {
            [self.ground_radiance; 3]
        }
    }

    /// The sun, when one was asked for and it is above the horizon.
    pub fn sun(&self) -> Option<&Sun> {
        self.sun.as_ref()
    }

    /// Whether a sun was asked for but is below the horizon (so there is none).
    pub fn sun_below_horizon(&self) -> bool {
        self.sun_below_horizon
    }

    /// The sun's position as given (even below the horizon, or with no sun drawn).
    pub fn sun_position(&self) -> Option<SolarAngles> {
        self.sun_position
    }

    /// Unobstructed horizontal illuminance, lux: (sky, sun). Sky + sun is a daylight factor's
    /// denominator only if the sun counts; CIE daylight factors use the overcast sky alone.
    pub fn horizontal_illuminance(&self) -> (f64, f64) {
        let (sky, sun) = self.horizontal_irradiance();
        (sky * EFFICACY, sun * EFFICACY)
    }

    /// Unobstructed horizontal irradiance, W/m²: (sky, sun).
    pub fn horizontal_irradiance(&self) -> (f64, f64) {
        let sun = self.sun.map_or(0.0, |s| s.horizontal_irradiance());
        (self.zenith_radiance * self.ratio, sun)
    }

    /// The zenith parameter L_z, cd/m² (`gensky -b` is this / 179).
    pub fn zenith_luminance(&self) -> f64 {
        self.zenith_radiance * EFFICACY
    }

    /// The ground's radiance ρ_g E_h / π, W/sr/m².
    pub fn ground_radiance(&self) -> f64 {
        self.ground_radiance
    }

    pub fn kind(&self) -> SkyKind {
        self.kind
    }

    pub fn compass(&self) -> &Compass {
        &self.compass
    }
}

impl SkySpec {
    /// Refuses a spec whose directions are no compass ([`Compass::new`]), whose numbers are
    /// out of range or which lacks a sun position it needs: one line naming the flag.
    pub fn check(&self) -> Result<(), Invalid> {
        Compass::new(self.zenith, self.north)?;
        let rho = self.ground_reflectance;
        if !(0.0..=1.0).contains(&rho) {
            return Invalid::err(format!(
                "--ground-reflectance: the ground reflectance {rho} is not within [0, 1]"
            ));
        }
        let level = match self.level {
            SkyLevel::ZenithLuminance(v) => Some(("--zenith-luminance", "zenith luminance", v)),
            SkyLevel::HorizontalIlluminance(v) => Some(("--sky-illuminance", "sky illuminance", v)),
            SkyLevel::Gensky => None,
        };
        let sun = match self.sun {
            Some(SunLevel::NormalIlluminance(v)) => {
                Some(("--sun-illuminance", "sun's normal illuminance", v))
            }
            Some(SunLevel::HorizontalIlluminance(v)) => {
                Some(("--sun", "sun's horizontal illuminance", v))
            }
            _ => None,
        };
        for (flag, what, value) in level.into_iter().chain(sun) {
            if !(value.is_finite() && value >= 0.0) {
                return Invalid::err(format!(
                    "{flag}: the {what} {value} is not a finite, non-negative number"
                ));
            }
        }
        if self.sun_position.is_none() {
            let needs = if self.kind.needs_sun_position() {
                Some("the clear sky")
            } else if self.sun.is_some() {
                Some("a sun")
            } else if self.level == SkyLevel::Gensky {
                Some("gensky's default sky brightness")
            } else {
                None
            };
            if let Some(what) = needs {
                return Invalid::err(format!(
                    "--sky: {what} needs the sun's position (altitude and azimuth, or a site and a time)"
                ));
            }
        }
        Ok(())
    }
}

/// L_z in W/sr/m² from the spec's level, E_h / L_z being `ratio`.
fn zenith_radiance(spec: &SkySpec, ratio: f64) -> f64 {
    match spec.level {
        SkyLevel::ZenithLuminance(cd) => cd / EFFICACY,
        SkyLevel::HorizontalIlluminance(lux) => lux / EFFICACY / ratio,
        SkyLevel::Gensky => {
            let altitude = spec.sun_position.map_or(90.0, |a| a.altitude);
            cie::gensky_zenith_luminance(spec.kind, altitude) / EFFICACY
        }
    }
}

#[cfg(test)]
mod tests;
