//! Solvers: progressive refinement by shooting (Cohen et al. 1988) with the adaptive
//! polar hemisphere sampler of Airey & Ouh-young (1989, Sec. 2).
//!
//! Notation follows the papers: patch `i` shoots, patch `j` receives; `b` is radiosity
//! (W/m²), `e` emitted radiosity, `rho` reflectance; energies are fluxes Φ = B·A in f64 per RGB
//! channel. A shot moves the shooter's unshot flux ΔΦ_i into the scene: each ray carries
//! ΔΦ_i / X and the patch it hits first gains ρ_j·ΔΦ_i/X (so ΔB_j += ρ_j·ΔΦ_i·F_ij/A_j with
//! F_ij estimated by the fraction of rays).

pub mod checkpoint;
pub mod cube_shots;
pub mod error;
pub mod gathering;
pub mod lights;
pub mod progressive;
mod state;

use crate::intersect::Intersector;
use crate::mesh::Mesh;
use crate::scene::Material;

use std::time::Duration;

/// How form factors are sampled (`radiosity solve --method …`; the paper's Sec. 2 and 4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum MethodKind {
    /// Shooting with the adaptive polar hemisphere ray sampler (Sec. 2).
    AdaptiveRays,
    /// Shooting with the uniform N×N hemi-cube of Cohen & Greenberg 1985: the non-adaptive
    /// baseline.
    Hemicube,
    /// The uniform hemi-cube with each cell's sample point jittered (Table 1, third column).
    HemicubeJittered,
    /// Shooting with the paper's non-uniform hemi-cube, its resolution from the unshot energy.
    AdaptiveHemicube,
    /// The adaptive hemi-cube while shots carry much energy, then adaptive rays once a ray shot
    /// is measured to be cheaper (Sec. 4: curves C then D). The default.
    #[default]
    AdaptiveHybrid,
    /// The traditional algorithm: full form-factor matrix by the uniform hemi-cube, then
    /// Gauss–Seidel.
    Gathering,
}

impl MethodKind {
    /// Whether the method casts rays (and so needs an intersector).
    pub fn casts_rays(&self) -> bool {
        matches!(self, MethodKind::AdaptiveRays | MethodKind::AdaptiveHybrid)
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

/// What the solver does, independent of the scene.
#[derive(Clone, Debug)]
pub struct SolveConfig {
    /// Seed of every random choice; the result depends on it and nothing else (not the number
    /// of threads).
    pub seed: u64,
    /// Requested relative sampling error of a typical patch's radiosity; sets the energy per
    /// ray (see [`progressive::energy_per_ray`]).
    pub tolerance: f64,
    /// Overrides the energy per ray C (W, scalar flux) derived from `tolerance`.
    pub energy_per_ray: Option<f64>,
    /// Sec. 3: stop when max unshot radiosity < this fraction of the mean radiosity (0.0006).
    pub stop_fraction: f64,
    pub max_time: Option<Duration>,
    pub max_rays: Option<u64>,
    /// Place each ray uniformly inside its polar cell (default) rather than at its centre.
    pub jitter: bool,
    pub method: MethodKind,
    /// Resolution N of the uniform hemi-cube (the `hemicube` methods and gathering).
    pub hemicube_n: usize,
    /// Gathering refuses scenes whose form-factor matrix needs more memory than this (MiB).
    pub gather_cap_mib: u64,
    /// `adaptive-hybrid`: switch to rays at this shot instead of when measured costs say so.
    /// The measured switch depends on timings, so it can differ between runs; giving the shot
    /// a summary recorded makes the run reproducible exactly.
    pub switch_at: Option<u64>,
    /// Radiosity per patch of a reference solution (`--reference`): every trace point then
    /// records the error against it.
    pub reference: Option<std::sync::Arc<Vec<[f64; 3]>>>,
    /// Keep one channel per light group (`--per-light`): the solution then carries each
    /// light's own radiosity, for relighting without solving again.
    pub light_groups: Option<std::sync::Arc<lights::LightGroups>>,
    /// Write a checkpoint at the first safe point every so often, and on interrupt
    /// (`--checkpoint`), through this sink.
    pub checkpoint: Option<checkpoint::Sink>,
    /// Continue from this checkpoint (`--resume`).
    pub resume: Option<std::sync::Arc<checkpoint::Snapshot>>,
    /// Set (by a Ctrl-C handler) to stop at the next safe point.
    pub interrupt: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
}

impl Default for SolveConfig {
    fn default() -> Self {
        SolveConfig {
            seed: 1,
            tolerance: 0.05,
            energy_per_ray: None,
            stop_fraction: 0.0006,
            max_time: None,
            max_rays: None,
            jitter: true,
            method: MethodKind::AdaptiveHybrid,
            hemicube_n: 100,
            gather_cap_mib: 4096,
            switch_at: None,
            reference: None,
            light_groups: None,
            checkpoint: None,
            resume: None,
            interrupt: None,
        }
    }
}

impl SolveConfig {
    /// Checks the settings a user can get wrong (one line naming the flag), before any work.
    pub fn check(&self) -> Result<(), String> {
        if !(self.tolerance > 0.0 && self.tolerance < 1.0) {
            return Err(format!(
                "--tolerance must be in (0, 1), got {}",
                self.tolerance
            ));
        }
        if !(self.stop_fraction > 0.0 && self.stop_fraction.is_finite()) {
            return Err(format!(
                "--stop must be a positive fraction, got {}",
                self.stop_fraction
            ));
        }
        if !(2..=4096).contains(&self.hemicube_n) {
            return Err(format!(
                "--hemicube-n must be between 2 and 4096, got {}",
                self.hemicube_n
            ));
        }
        if self.switch_at.is_some() && self.method != MethodKind::AdaptiveHybrid {
            return Err(format!(
                "--switch-at applies to --method adaptive-hybrid only, not {}",
                self.method.name()
            ));
        }
        Ok(())
    }
}

/// Why the solve stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StopReason {
    /// Sec. 3: max unshot radiosity fell below the requested fraction of the mean radiosity.
    Converged,
    /// No unshot energy left at all.
    Exhausted,
    MaxTime,
    MaxRays,
    /// Ctrl-C: stopped at the next safe point (after writing a checkpoint, if asked).
    Interrupted,
}

/// One point of the convergence trace.
#[derive(Clone, Copy, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct TracePoint {
    pub time_s: f64,
    pub shots: u64,
    pub rays: u64,
    /// Hemi-cube cells of the shots so far (form-factor samples, like rays).
    pub cells: u64,
    /// Max unshot radiosity over patches (scalar: mean of RGB), W/m².
    pub max_unshot_b: f64,
    /// Area-weighted mean radiosity (scalar), W/m².
    pub mean_b: f64,
    /// Total unshot flux (scalar), W.
    pub unshot_flux: f64,
    /// The solver's own estimate of its error (see [`error`]).
    pub estimate: error::ErrorMetrics,
    /// The error against the reference, when the solve was given one.
    pub error: Option<error::ErrorMetrics>,
}

/// Where the emitted energy went (W per RGB channel). emitted = absorbed + absorbed_back +
/// escaped + unshot, to rounding.
#[derive(Clone, Copy, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct EnergyBalance {
    pub emitted: [f64; 3],
    /// Absorbed by front faces: (1 − ρ) of what they received.
    pub absorbed: [f64; 3],
    /// Arrived on back faces (absorbed there; a large share means flipped normals).
    pub absorbed_back: [f64; 3],
    /// Left an open scene.
    pub escaped: [f64; 3],
    /// Still waiting to be shot.
    pub unshot: [f64; 3],
}

impl EnergyBalance {
    /// |emitted − (absorbed + back + escaped + unshot)| / emitted, worst channel.
    pub fn relative_residual(&self) -> f64 {
        (0..3)
            .map(|c| {
                let out =
                    self.absorbed[c] + self.absorbed_back[c] + self.escaped[c] + self.unshot[c];
                if self.emitted[c] > 0.0 {
                    (self.emitted[c] - out).abs() / self.emitted[c]
                } else {
                    0.0
                }
            })
            .fold(0.0, f64::max)
    }

    /// Fraction of the emitted flux (scalar) that arrived on back faces.
    pub fn back_fraction(&self) -> f64 {
        scalar(&self.absorbed_back) / scalar(&self.emitted).max(f64::MIN_POSITIVE)
    }
}

/// Counters of a solve.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct SolveStats {
    pub shots: u64,
    pub rays: u64,
    pub waves: u64,
    pub seconds: f64,
    /// Energy per ray C (scalar W) the run used.
    pub energy_per_ray: f64,
    pub stop_reason: Option<StopReason>,
    pub energy: EnergyBalance,
    pub trace: Vec<TracePoint>,
    /// Shots taken by hemi-cube, and form-factor samples (cells) they used.
    pub hemicube_shots: u64,
    pub hemicube_cells: u64,
    /// For `adaptive-hybrid`: when and why it switched from the hemi-cube to rays.
    pub switch: Option<SwitchInfo>,
}

/// The hemi-cube → rays switch of `adaptive-hybrid` (Sec. 4), with the costs it compared.
#[derive(Clone, Copy, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct SwitchInfo {
    /// The first shot cast by rays.
    pub shot: u64,
    /// Rays that shot needed (X = ΔΦ/C).
    pub rays: u64,
    /// Measured wall time one ray costs (s), all threads.
    pub seconds_per_ray: f64,
    /// Measured wall time of a hemi-cube shot at that point (s).
    pub hemicube_shot_seconds: f64,
    /// The cost of the shot by rays: rays × seconds_per_ray (s).
    pub ray_shot_seconds: f64,
    /// Cells of the hemi-cube that shot would have used.
    pub hemicube_cells: u64,
    /// Whether `--switch-at` set the shot rather than the measured costs.
    pub forced: bool,
}

/// The result: radiosity per patch, and the energy not yet shot.
#[derive(Clone, Debug)]
pub struct Solution {
    /// Radiosity B_i per patch (W/m²), RGB.
    pub b: Vec<[f64; 3]>,
    /// Unshot flux ΔΦ_i per patch (W), RGB.
    pub unshot: Vec<[f64; 3]>,
    pub stats: SolveStats,
    /// Per light group, the radiosity with only that light on (empty unless asked for); they
    /// sum to `b` (to rounding).
    pub channels: Vec<Channel>,
}

/// One light group's radiosity per patch (W/m², RGB).
#[derive(Clone, Debug, PartialEq)]
pub struct Channel {
    pub name: String,
    pub b: Vec<[f64; 3]>,
}

/// The scalar the solver ranks and stops by: the mean of the three channels.
#[inline]
pub fn scalar(v: &[f64; 3]) -> f64 {
    (v[0] + v[1] + v[2]) / 3.0
}

/// Errors a user can cause.
#[derive(Debug, thiserror::Error)]
pub enum SolveError {
    #[error("the scene has no light: no material emits (give one a Ke in the MTL file, or use --emit MATERIAL=R,G,B)")]
    NoEmitter,
    #[error("the scene has {0} patches; at most {max} are supported", max = progressive::BACK - 1)]
    TooManyPatches(usize),
    #[error(transparent)]
    GatherTooLarge(#[from] gathering::TooLarge),
    #[error("the reference has {reference} patches but this mesh has {patches}: solve the reference with the same scene and --patch-size")]
    ReferenceMismatch { reference: usize, patches: usize },
    #[error("{0}")]
    Checkpoint(String),
    #[error("--method {0} casts rays but no intersector was built")]
    NoIntersector(&'static str),
}

/// Solves by the method `cfg.method` names, casting rays through `isect`.
pub fn solve<I: Intersector>(
    mesh: &Mesh,
    materials: &[Material],
    isect: &I,
    cfg: &SolveConfig,
    on_trace: impl FnMut(&TracePoint),
) -> Result<Solution, SolveError> {
    run(mesh, materials, Some(isect), cfg, on_trace)
}

/// Solves by the method `cfg.method` names. `isect` is needed only by methods that cast rays
/// ([`MethodKind::casts_rays`]): the hemi-cube methods and gathering build none.
pub fn run<I: Intersector>(
    mesh: &Mesh,
    materials: &[Material],
    isect: Option<&I>,
    cfg: &SolveConfig,
    on_trace: impl FnMut(&TracePoint),
) -> Result<Solution, SolveError> {
    match cfg.method {
        MethodKind::Gathering => {
            gathering::check_size(mesh.patches.len(), cfg.gather_cap_mib)?;
            if !mesh
                .patches
                .iter()
                .any(|p| materials[p.material as usize].is_emitter())
            {
                return Err(SolveError::NoEmitter);
            }
            if let Some(r) = &cfg.reference {
                if r.len() != mesh.patches.len() {
                    return Err(SolveError::ReferenceMismatch {
                        reference: r.len(),
                        patches: mesh.patches.len(),
                    });
                }
            }
            Ok(gathering::gather(mesh, materials, cfg, on_trace))
        }
        _ => progressive::shoot(mesh, materials, isect, cfg, on_trace),
    }
}
