//! What a solve is asked to do ([`SolveSettings`]: plain, serialisable, checked once) and what
//! the run around it plugs in ([`super::RunHooks`]: a reference to measure against,
//! per-light channels, checkpoints, an interrupt flag).
//!
//! The settings are the whole of what shapes a result: the same scene, mesh and settings give
//! the same patch table on any run and any thread count. So everything that records "how was
//! this solved" (the summary, the saved solution, a comparison's rows, the key a checkpoint must
//! match) is derived from this one type by serialising it, never listed field by field; a new
//! setting added here reaches all of them.
//!
//! Defaults are constants, used by `Default` and by the command line's `default_value_t` alike.

use crate::settings::Invalid;
use serde::{Deserialize, Serialize};

/// Default seed of every random choice.
pub const DEFAULT_SEED: u64 = 1;
/// Default relative sampling error of a typical patch's radiosity (`--tolerance`).
pub const DEFAULT_TOLERANCE: f64 = 0.05;
/// Sec. 3: stop when the max unshot radiosity is below 0.06 % of the mean radiosity.
pub const DEFAULT_STOP: f64 = 0.0006;
/// Default resolution N of the uniform N×N hemi-cube (the paper's reference is 100×100).
pub const DEFAULT_HEMICUBE_N: usize = 100;
/// Gathering refuses form-factor matrices above this many MiB by default.
pub const DEFAULT_GATHER_CAP_MIB: u64 = 4096;
/// The final gather after shooting is on by default (`--final-gather`; ray-casting methods).
pub const DEFAULT_FINAL_GATHER: bool = true;
/// `radiosity solve`'s error target with the ray methods (`--error`; [`super::passes`]): 5 %
/// average weighted error, where patch-to-patch noise no longer shows as mottling on a wall.
/// The library's [`SolveSettings::default`] has none (one pass, as the paper).
pub const DEFAULT_ERROR_TARGET: f64 = 0.05;
/// The default target gives up once passes have cast this many times the samples of a first
/// pass at the default tolerance (so a model whose estimate falls slowly still solves in
/// bounded time; `--error` lifts it): [`SolveSettings::error_bound`].
pub const DEFAULT_ERROR_MAX_FACTOR: f64 = 8.0;
/// With an error target E (`solve --error`, on by default) and no `--tolerance`, the first
/// pass shoots at tolerance E × this (0.1 for the default 5 %) rather than the default
/// tolerance: its final gather then makes the estimate, and the shooting is its cache of the
/// indirect light. With the first gather sized by a pilot (of 128 rays) to land at 0.9·E, the
/// 100 k-patch building reached 4.7, 4.6 and 4.8 % against its reference for 26.5, 18.9 and
/// 15.4 M rays at 1.4, 2 and 2.8 × E; the 1 M one took 105, 88 and 89 s (a gather ray costs
/// about two shooting rays, and the shooting's count of shots hardly falls). 2 × keeps the shooting's estimate of the light
/// still owed honest (at 4 × E the 100 k building's estimate fell 14 % under its error):
/// docs/results/first-gather-pilot.md.
pub const TARGET_TOLERANCE: f64 = 2.0;
/// With an error target the first final gather's pilot casts this share of the rays per patch
/// ([`SolveSettings::first_gather_rays`]) on a sample of the patches, and picks the rays per
/// patch of the rest (`super::final_gather`), at most the settings' rays per patch. A pilot of
/// 128 rays predicted too low an estimate for the 43–70 it chose on the 1 M-patch building
/// (reached 1.09–1.11 × predicted); one of 64 chose 84 and reached 0.99 × (docs/results/
/// first-gather-pilot.md).
pub const FIRST_GATHER_SHARE: f64 = 0.25;
/// A gather round aims at this fraction of the error target (`super::passes`), and so does the
/// first gather, sized by its pilot ([`SolveSettings::first_gather_pilot`]): their models
/// predict them closely (a round reached 1.03–1.07 × predicted on the generated buildings,
/// 100 k to 10 M patches; the pilot 0.99–1.05 ×), and a round that misses is followed by a
/// small one, not a whole pass. Whether to take a round rather than a pass is still judged at
/// `passes::AIM`, where the passes' cost is reckoned: judged at this aim, rounds won where a
/// further pass had been chosen (the converted furnished room: 2 passes and a round instead of
/// 3 and a round, 2.93 % against Radiance instead of 2.58 %). At `passes::AIM` a round after a
/// near miss cost more than the first gather (10 M: 5.08 % → 4.55 % for 1.84 G rays).
pub const ROUND_AIM: f64 = 0.9;
/// Rays per gathered patch (`--gather-rays`): half shadow rays to the emitters, half over the
/// hemisphere (see [`super::final_gather`]).
pub const DEFAULT_GATHER_RAYS: usize = 256;
/// The most rays per patch a final gather casts (`--gather-rays`; `--error` grows it).
pub const MAX_GATHER_RAYS: usize = 1_000_000;
/// `radiosity reference`: tolerance and stop fraction (100× the rays of a default solve).
pub const REFERENCE_TOLERANCE: f64 = 0.005;
pub const REFERENCE_STOP: f64 = 1e-5;

/// How form factors are sampled (`radiosity solve --method …`; the paper's Sec. 2 and 4). The
/// flag's values are the variants' kebab-case names (as in the JSON), each with a one-line
/// description for `--help`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum MethodKind {
    /// Shooting with the adaptive polar hemisphere ray sampler (Sec. 2).
    #[value(help = "Shooting with the paper's adaptive polar hemisphere ray sampler (Sec. 2)")]
    AdaptiveRays,
    /// Shooting with the uniform N×N hemi-cube of Cohen & Greenberg 1985: the non-adaptive
    /// baseline.
    #[value(
        help = "Shooting with the uniform N×N hemi-cube (Cohen & Greenberg 1985): the baseline"
    )]
    Hemicube,
    /// The uniform hemi-cube with each cell's sample point jittered (Table 1, third column).
    #[value(help = "The uniform hemi-cube with jittered sample points (the paper's Table 1)")]
    HemicubeJittered,
    /// Shooting with the paper's non-uniform hemi-cube, its resolution from the unshot energy.
    #[value(
        help = "Shooting with the paper's non-uniform hemi-cube, resolution from the unshot energy"
    )]
    AdaptiveHemicube,
    /// The adaptive hemi-cube while shots carry much energy, then adaptive rays once a ray shot
    /// is cheaper (Sec. 4: curves C then D). The default.
    #[default]
    #[value(
        help = "Adaptive hemi-cube first, adaptive rays once cheaper by the cost model (Sec. 4)"
    )]
    AdaptiveHybrid,
    /// The matrix method ([`super::matrix`]), the traditional algorithm: full form-factor
    /// matrix by the uniform hemi-cube, then Gauss–Seidel. Named `gathering` on the command line.
    #[value(help = "The traditional algorithm: full form-factor matrix, then Gauss–Seidel")]
    Gathering,
}

impl MethodKind {
    /// Every method, in the order `radiosity compare` runs them by default.
    pub const ALL: [MethodKind; 6] = [
        MethodKind::AdaptiveHybrid,
        MethodKind::AdaptiveRays,
        MethodKind::AdaptiveHemicube,
        MethodKind::Hemicube,
        MethodKind::HemicubeJittered,
        MethodKind::Gathering,
    ];

    /// Whether the method casts rays (and so needs an intersector).
    pub fn casts_rays(&self) -> bool {
        matches!(self, MethodKind::AdaptiveRays | MethodKind::AdaptiveHybrid)
    }

    /// Whether the method uses the uniform N×N hemi-cube (and so `hemicube_n`).
    pub fn uses_uniform_cube(&self) -> bool {
        matches!(
            self,
            MethodKind::Hemicube | MethodKind::HemicubeJittered | MethodKind::Gathering
        )
    }

    pub fn name(&self) -> &'static str {
        match self {
            MethodKind::AdaptiveRays => "adaptive-rays",
            MethodKind::Hemicube => "hemicube",
            MethodKind::HemicubeJittered => "hemicube-jittered",
            MethodKind::AdaptiveHemicube => "adaptive-hemicube",
            MethodKind::AdaptiveHybrid => "adaptive-hybrid",
            MethodKind::Gathering => "gathering",
        }
    }
}

/// How `adaptive-hybrid` decides when rays become cheaper than hemi-cubes (Sec. 4;
/// `--switch-by`). See [`super::switch`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum SwitchBy {
    /// From counted work (patches transformed, faces clipped, cells cleared and tested; rays
    /// cast) weighed by cost constants the code keeps ([`super::switch::KEPT`], measured by
    /// `radiosity bench shots`): the same switch shot on every run and thread count. The
    /// default.
    #[default]
    #[value(help = crate::settings::NO_HELP)]
    Counted,
    /// From times measured during the solve (a least-squares fit of hemi-cube shot times
    /// against cells, and a timed probe of a few thousand rays): adapts to the machine, but
    /// the switch shot, and so the result, varies from run to run.
    #[value(help = crate::settings::NO_HELP)]
    Measured,
}

impl SwitchBy {
    pub fn name(&self) -> &'static str {
        match self {
            SwitchBy::Counted => "counted",
            SwitchBy::Measured => "measured",
        }
    }
}

/// What the solver does, independent of the scene: the settings of `solve`, `compare`,
/// `reference`, `sweep` and the benchmarks alike.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SolveSettings {
    pub method: MethodKind,
    /// Seed of every random choice; the result depends on it and nothing else (not the number
    /// of threads, not the clock; but see `max_time` and `switch_by: measured`).
    pub seed: u64,
    /// Requested relative sampling error of a typical patch's radiosity; sets the energy per
    /// ray (see [`super::ray_shots::energy_per_ray`]).
    pub tolerance: f64,
    /// Overrides the energy per ray C (W, scalar flux) derived from `tolerance`.
    pub energy_per_ray: Option<f64>,
    /// Sec. 3: stop when max unshot radiosity < this fraction of the mean radiosity (0.0006).
    pub stop_fraction: f64,
    /// Stop after this many seconds (the one setting that makes a result depend on the clock).
    pub max_time: Option<f64>,
    /// Stop after about this many form-factor samples (rays plus hemi-cube cells).
    pub max_rays: Option<u64>,
    /// Keep refining (independent passes, averaged) until the solver's estimate of the average
    /// weighted percent error is at most this fraction (`--error`; see [`super::passes`]).
    pub error_target: Option<f64>,
    /// With `error_target`: give up once the passes have cast this many times the first pass's
    /// samples (`radiosity solve`'s default target is bounded so; an explicit `--error` is not).
    pub error_max_factor: Option<f64>,
    /// Place each ray uniformly inside its polar cell (default) rather than at its centre.
    pub jitter: bool,
    /// Resolution N of the uniform hemi-cube (the `hemicube` methods and gathering).
    pub hemicube_n: usize,
    /// Gathering refuses scenes whose form-factor matrix needs more memory than this (MiB).
    pub gather_cap_mib: u64,
    /// `adaptive-hybrid`: switch to rays at this shot instead of when the cost model says so.
    pub switch_at: Option<u64>,
    /// `adaptive-hybrid`: decide the switch from counted work and kept cost constants (the
    /// default; reproducible) or from times measured during the run (not reproducible).
    /// `switch_at` overrides both.
    pub switch_by: SwitchBy,
    /// After shooting, re-estimate the patches the shooting left noisy by gathering with
    /// rays of their own ([`super::final_gather`]); methods that cast rays only.
    pub final_gather: bool,
    /// Daylight: the sky, ground glow and sun that shoot at the model from outside
    /// ([`super::sky_shots`]); `None` for none.
    pub sky: Option<crate::sky::SkySpec>,
    /// Daylight coefficients: shoot the unit sky of [`crate::sky::Sky::coefficients`] in
    /// `sky`'s orientation instead of its own luminance (the annual run; not a flag of
    /// `solve`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sky_coefficients: Option<crate::sky::CoefficientSky>,
    /// Rays per gathered patch at the default tolerance ([`SolveSettings::gather_rays_per_patch`]).
    pub gather_rays: usize,
    /// Stop once the light still unshot (or in flight) is below this fraction of the emitted
    /// light: a solve that only asks where light goes, not how bright each patch is (the
    /// first shooting that looks for faces lit from behind, `pipeline::stages::lit_backs`).
    /// Not a flag, and not part of a saved or checkpointed solve.
    #[serde(skip)]
    pub stop_unshot: Option<f64>,
}

impl Default for SolveSettings {
    fn default() -> Self {
        SolveSettings {
            method: MethodKind::default(),
            seed: DEFAULT_SEED,
            tolerance: DEFAULT_TOLERANCE,
            energy_per_ray: None,
            stop_fraction: DEFAULT_STOP,
            max_time: None,
            max_rays: None,
            error_target: None,
            error_max_factor: None,
            jitter: true,
            hemicube_n: DEFAULT_HEMICUBE_N,
            gather_cap_mib: DEFAULT_GATHER_CAP_MIB,
            switch_at: None,
            switch_by: SwitchBy::Counted,
            final_gather: DEFAULT_FINAL_GATHER,
            gather_rays: DEFAULT_GATHER_RAYS,
            sky: None,
            sky_coefficients: None,
            stop_unshot: None,
        }
    }
}

impl SolveSettings {
    /// The sky the solve shoots: the spec's, or with [`SolveSettings::sky_coefficients`] the
    /// unit sky of daylight coefficients in the spec's orientation; `None` without a sky.
    pub fn build_sky(&self) -> Result<Option<crate::sky::Sky>, Invalid> {
        let Some(spec) = &self.sky else {
            return Ok(None);
        };
        match self.sky_coefficients {
            Some(c) => crate::sky::Sky::coefficients(spec, &c).map(Some),
            None => crate::sky::Sky::new(spec).map(Some),
        }
    }

    /// The settings of `radiosity reference` (adaptive rays, 100× the rays of a default solve).
    pub fn reference(seed: u64) -> SolveSettings {
        SolveSettings {
            method: MethodKind::AdaptiveRays,
            seed,
            tolerance: REFERENCE_TOLERANCE,
            stop_fraction: REFERENCE_STOP,
            ..SolveSettings::default()
        }
    }

    /// `radiosity solve`'s error policy where `--error` is left out: the methods that cast rays
    /// refine to [`DEFAULT_ERROR_TARGET`], giving up after [`DEFAULT_ERROR_MAX_FACTOR`] times
    /// the first pass's samples; the others make one pass, as the paper.
    pub fn with_solve_default_error(self) -> SolveSettings {
        if self.method.casts_rays() {
            SolveSettings {
                error_target: Some(DEFAULT_ERROR_TARGET),
                error_max_factor: Some(DEFAULT_ERROR_MAX_FACTOR),
                ..self
            }
        } else {
            self
        }
    }

    /// Rays each patch gathers: `gather_rays` at the default tolerance, grown as 1/τ² with a
    /// finer one, as the shooting's rays grow (`energy_per_ray` ∝ τ²), so the gather's noise
    /// keeps pace with the shooting's (a reference solve's gather is not left at the default's
    /// noise); at most [`MAX_GATHER_RAYS`].
    pub fn gather_rays_per_patch(&self) -> usize {
        let grow = (DEFAULT_TOLERANCE / self.tolerance).powi(2).max(1.0);
        (self.gather_rays as f64 * grow)
            .round()
            .min(MAX_GATHER_RAYS as f64) as usize
    }

    /// Rays each patch gathers in the first final gather: [`Self::gather_rays_per_patch`], or
    /// with an error target those of its pilot, [`FIRST_GATHER_SHARE`] of them (at least 16).
    pub fn first_gather_rays(&self) -> usize {
        let all = self.gather_rays_per_patch();
        if self.error_target.is_some() {
            ((all as f64 * FIRST_GATHER_SHARE).round() as usize).max(16.min(all))
        } else {
            all
        }
    }

    /// With an error target, the pilot that sizes the first final gather for [`ROUND_AIM`] of
    /// it, its own rays at most `most` (the gather's rays per patch under `--max-time`).
    pub fn first_gather_pilot(&self, most: usize) -> Option<super::final_gather::Pilot> {
        self.error_target.map(|e| super::final_gather::Pilot {
            goal: e * ROUND_AIM,
            rays: self.first_gather_rays().min(most),
        })
    }

    /// The samples after which an error target gives up ([`Self::error_max_factor`]), for a
    /// first pass of `r1` samples: the factor times the samples that pass would have cast at
    /// the default tolerance, if coarser (a first pass at [`TARGET_TOLERANCE`] gets the same
    /// bound in rays as one at the default tolerance).
    pub fn error_bound(&self, r1: f64) -> Option<f64> {
        let coarser = (self.tolerance / DEFAULT_TOLERANCE).powi(2).max(1.0);
        let r1 = if self.energy_per_ray.is_none() {
            r1 * coarser
        } else {
            r1
        };
        self.error_max_factor.map(|f| f * r1)
    }

    /// With an error target E and no tolerance given, the first pass's tolerance: E ×
    /// [`TARGET_TOLERANCE`] (see it); otherwise these settings' own.
    pub fn with_target_tolerance(self, tolerance_given: bool) -> SolveSettings {
        match self.error_target {
            // An invalid target is left for `check` to refuse in its own words.
            Some(e)
                if !tolerance_given
                    && self.energy_per_ray.is_none()
                    && e > 0.0
                    && e * TARGET_TOLERANCE < 1.0 =>
            {
                SolveSettings {
                    tolerance: e * TARGET_TOLERANCE,
                    ..self
                }
            }
            _ => self,
        }
    }

    /// These settings for `method` instead: the settings that apply to one method only (the
    /// hybrid's `switch_at` and `switch_by`) fall back to their defaults for the others. For
    /// the commands that run several methods with one set of flags (`compare`, `sweep`, the
    /// benchmarks).
    pub fn for_method(&self, method: MethodKind) -> SolveSettings {
        let hybrid = method == MethodKind::AdaptiveHybrid;
        SolveSettings {
            method,
            switch_at: self.switch_at.filter(|_| hybrid),
            switch_by: if hybrid {
                self.switch_by
            } else {
                SwitchBy::default()
            },
            ..self.clone()
        }
    }

    /// Checks the settings a user can get wrong (one line naming the flag), before any work.
    /// Every command that solves calls this, so each refuses what `solve` refuses, in the same
    /// words.
    pub fn check(&self) -> Result<(), Invalid> {
        if let Some(c) = self.sky_coefficients {
            crate::sky::reinhart::check_subdivision(c.subdivision)?;
            if self.sky.is_none() {
                return Invalid::err(
                    "daylight coefficients need a sky's orientation (zenith and north)",
                );
            }
        }
        if !(self.tolerance > 0.0 && self.tolerance < 1.0) {
            return Invalid::err(format!(
                "--tolerance must be in (0, 1), got {}",
                self.tolerance
            ));
        }
        if !(self.stop_fraction > 0.0 && self.stop_fraction.is_finite()) {
            return Invalid::err(format!(
                "--stop must be a positive fraction, got {}",
                self.stop_fraction
            ));
        }
        if let Some(c) = self.energy_per_ray {
            if !(c > 0.0 && c.is_finite()) {
                return Invalid::err(format!(
                    "--energy-per-ray must be a positive number of watts, got {c}"
                ));
            }
        }
        if let Some(t) = self.max_time {
            if !(t > 0.0 && t.is_finite()) {
                return Invalid::err(format!(
                    "--max-time must be a positive number of seconds, got {t}"
                ));
            }
        }
        if let Some(e) = self.error_target {
            if !(e > 0.0 && e < 1.0) {
                return Invalid::err(format!(
                    "--error must be a fraction between 0 and 1 (0.02 = 2 %), got {e}"
                ));
            }
            if self.method == MethodKind::Gathering {
                return Invalid::err("--error applies to the shooting methods, not gathering");
            }
        }
        if self.max_rays == Some(0) {
            return Invalid::err("--max-rays must be at least 1 (leave it out for no limit)");
        }
        if !(2..=4096).contains(&self.hemicube_n) {
            return Invalid::err(format!(
                "--hemicube-n must be between 2 and 4096, got {}",
                self.hemicube_n
            ));
        }
        if !(4..=MAX_GATHER_RAYS).contains(&self.gather_rays) {
            return Invalid::err(format!(
                "--gather-rays must be between 4 and 1000000, got {}",
                self.gather_rays
            ));
        }
        if self.switch_by != SwitchBy::Counted && self.method != MethodKind::AdaptiveHybrid {
            return Invalid::err(format!(
                "--switch-by applies to --method adaptive-hybrid only, not {}",
                self.method.name()
            ));
        }
        if self.switch_at.is_some() && self.method != MethodKind::AdaptiveHybrid {
            return Invalid::err(format!(
                "--switch-at applies to --method adaptive-hybrid only, not {}",
                self.method.name()
            ));
        }
        if let Some(sky) = &self.sky {
            sky.check()?;
            if !self.method.casts_rays() {
                return Invalid::err(format!(
                    "--sky needs a method that casts rays (adaptive-hybrid or adaptive-rays), not --method {}",
                    self.method.name()
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_round_trip_through_json() {
        let s = SolveSettings {
            method: MethodKind::Hemicube,
            energy_per_ray: Some(0.1 + 0.2),
            max_time: Some(1.5),
            ..SolveSettings::default()
        };
        let text = serde_json::to_string(&s).unwrap();
        assert_eq!(serde_json::from_str::<SolveSettings>(&text).unwrap(), s);
        let measured = SolveSettings {
            switch_by: SwitchBy::Measured,
            ..SolveSettings::default()
        };
        let text = serde_json::to_string(&measured).unwrap();
        assert!(text.contains(r#""switch_by":"measured""#), "{text}");
        assert_eq!(
            serde_json::from_str::<SolveSettings>(&text).unwrap(),
            measured
        );
        // Settings written before the field existed read as the default.
        assert_eq!(
            serde_json::from_str::<SolveSettings>("{}")
                .unwrap()
                .switch_by,
            SwitchBy::Counted
        );
    }

    #[test]
    fn defaults_pass_the_check_and_bad_values_name_their_flag() {
        assert!(SolveSettings::default().check().is_ok());
        let bad = SolveSettings {
            tolerance: 5.0,
            ..SolveSettings::default()
        };
        assert!(bad.check().unwrap_err().0.starts_with("--tolerance"));
    }
}
