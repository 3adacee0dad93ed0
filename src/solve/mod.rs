//! Solvers: progressive refinement by shooting (Cohen et al. 1988) with the two adaptive
//! samplers of Airey & Ouh-young (1989) and their hybrid, and the traditional matrix method
//! they are compared against (`--method gathering`).
//!
//! Notation follows the papers: patch `i` shoots, patch `j` receives; `b` is radiosity
//! (W/m²), `e` emitted radiosity, `rho` reflectance; energies are fluxes Φ = B·A in f64 per RGB
//! channel. A shot moves the shooter's unshot flux ΔΦ_i into the scene: each ray carries
//! ΔΦ_i / X and the patch it hits first gains ρ_j·ΔΦ_i/X (so ΔB_j += ρ_j·ΔΦ_i·F_ij/A_j with
//! F_ij estimated by the fraction of rays).
//!
//! Where the paper's parts are:
//! - [`driver`]: the shooting loop (picks the next shooters, hands them to ray or hemi-cube
//!   shots, asks the stopping rule and the switch policy);
//! - [`ray_shots`]: Sec. 2, the adaptive polar ray shot (X = ΔΦ/C rays, C the energy per ray);
//! - [`cube_shots`]: the uniform, jittered (Table 1) and adaptive non-uniform (Sec. 2)
//!   hemi-cube shots;
//! - [`switch`]: Sec. 4, when `adaptive-hybrid` goes from hemi-cubes (curve C) to rays
//!   (curve D), and the cost model it decides by;
//! - [`stopping`]: Sec. 3, the stop rule (0.06 % of the mean radiosity) and the budgets;
//! - [`estimate`]: Sec. 3's error metrics, and the solver's own estimate of its error;
//! - [`books`]: the energy books every shooting method keeps;
//! - [`matrix`]: the traditional algorithm (full form-factor matrix, Gauss–Seidel);
//! - [`final_gather`]: after shooting, the patches the shooting left noisy (the small ones)
//!   gather their own light with rays, combined with the shooting's estimate by inverse variance;
//! - [`checkpoint`] (the file of a run's saved state: the driver's, the books' and the
//!   switch's, each saved by its owner), [`lights`] (per-light channels), [`settings`].
//!
//! **Reproducible.** The same scene, mesh, settings and seed give bit-identical results on any
//! run and any thread count, for every method: random numbers come from (seed, shot, chunk),
//! waves have a fixed composition and are applied in a fixed order, and the hybrid's switch is
//! decided from counted work ([`SwitchBy::Counted`]). Only `max_time` (a clock budget) and
//! `switch_by: measured` make a result depend on the clock.

pub mod books;
pub mod checkpoint;
pub mod cube_shots;
pub mod driver;
pub mod estimate;
pub mod final_gather;
mod gather_budget;
mod key_heap;
pub mod lights;
pub mod luminaire_shots;
pub mod matrix;
pub mod passes;
pub mod ray_shots;
pub mod settings;
pub mod sky_shots;
pub mod stopping;
pub mod switch;

use crate::intersect::Intersector;
use crate::mesh::Mesh;
use crate::scene::Material;

pub use settings::{MethodKind, SolveSettings, SwitchBy};

pub use crate::light::LightChannel;
pub(crate) use crate::random::rng_for;
pub use crate::random::Stream;

/// What a run plugs into the solver besides its settings: none of it changes the result
/// (a checkpoint or an interrupt changes only where the run stops or resumes).
#[derive(Clone, Default)]
pub struct RunHooks {
    /// Radiosity per patch of a reference solution (`--reference`): every trace point then
    /// records the error against it.
    pub reference: Option<std::sync::Arc<Vec<[f64; 3]>>>,
    /// Keep one channel per light group (`--per-light`): the solution then carries each
    /// light's own radiosity, for relighting without solving again.
    pub light_groups: Option<std::sync::Arc<lights::LightGroups>>,
    /// Write the run's state at the first safe point every so often, and on interrupt
    /// (`--checkpoint`), through this sink.
    pub checkpoint: Option<driver::Sink>,
    /// Continue from this state (`--resume`, read by [`checkpoint::Checkpoint::from_bytes`]).
    pub resume: Option<std::sync::Arc<driver::Saved>>,
    /// Set (by a Ctrl-C handler) to stop at the next safe point.
    pub interrupt: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
}

impl std::fmt::Debug for RunHooks {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RunHooks")
            .field("reference", &self.reference.as_ref().map(|r| r.len()))
            .field("light_groups", &self.light_groups.as_ref().map(|g| g.len()))
            .field("checkpoint", &self.checkpoint.is_some())
            .field("resume", &self.resume.is_some())
            .field("interrupt", &self.interrupt.is_some())
            .finish()
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
    /// The solver's own estimate of its error (see [`estimate`]).
    pub estimate: estimate::ErrorMetrics,
    /// The error against the reference, when the solve was given one.
    pub error: Option<estimate::ErrorMetrics>,
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
    /// Of `emitted`, what the emitters no patch holds shot: the distant ones (sky, ground
    /// glow, sun) at the model, and the luminaires.
    #[serde(default)]
    pub distant: [f64; 3],
    /// Of `absorbed_back`, what came from distant emitters (a one-sided model's outside).
    #[serde(default)]
    pub distant_back: [f64; 3],
    /// Of `escaped`, distant emitters' rays that missed the model.
    #[serde(default)]
    pub distant_missed: [f64; 3],
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
    /// Distant emitters' rays that met the model's outside (a one-sided model's exterior) or
    /// missed it are left out: the fraction is of the light that entered the model.
    pub fn back_fraction(&self) -> f64 {
        let back = scalar(&self.absorbed_back) - scalar(&self.distant_back);
        let into =
            scalar(&self.emitted) - scalar(&self.distant_back) - scalar(&self.distant_missed);
        back.max(0.0) / into.max(f64::MIN_POSITIVE)
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
    /// With `--error`: the target, the estimate reached, and the passes it took.
    pub error_target: Option<passes::ErrorTarget>,
    /// The final gather after the shooting, when one ran ([`final_gather`]).
    pub final_gather: Option<final_gather::GatherStats>,
}

/// The hemi-cube → rays switch of `adaptive-hybrid` (Sec. 4), with the costs it compared (see
/// [`switch`]). Seconds are thread seconds: measured ones with `switch_by: measured`, the cost
/// model's predictions from counted work with `switch_by: counted` (the default).
#[derive(Clone, Copy, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct SwitchInfo {
    /// The first shot cast by rays.
    pub shot: u64,
    /// Rays that shot needed (X = ΔΦ/C).
    pub rays: u64,
    /// Time one ray costs (s), all threads: measured, or the cost model's.
    pub seconds_per_ray: f64,
    /// Time of a hemi-cube shot at that point (s): predicted by the fit of measured shot times,
    /// or by the cost model from counted work.
    pub hemicube_shot_seconds: f64,
    /// The cost of the shot by rays (s): rays × seconds_per_ray (plus the model's per-shot
    /// cost when counted).
    pub ray_shot_seconds: f64,
    /// Cells of the hemi-cube that shot would have used.
    pub hemicube_cells: u64,
    /// Whether `--switch-at` set the shot rather than the costs.
    pub forced: bool,
    /// Which costs were compared: counted work (`counted`) or measured times (`measured`).
    #[serde(default)]
    pub by: SwitchBy,
    /// Counted: the work the hemi-cube shot was predicted to do (faces clipped and cells
    /// depth-tested; from the hemi-cube shots so far), besides `hemicube_cells` and one
    /// transform per patch.
    #[serde(default)]
    pub hemicube_faces: f64,
    #[serde(default)]
    pub hemicube_tested: f64,
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
    pub channels: Vec<LightChannel>,
    /// With an error target: the shooting's own result before any final gather, and its error
    /// estimate's parts per patch, for [`passes`] to combine passes by (`None` otherwise).
    pub shooting: Option<Box<ShotResult>>,
    /// Scalar flux that met the back of each one-sided surface patch (W; the shooting's,
    /// of its last pass): where the winding lost light. Empty when none did.
    pub back: Vec<f64>,
}

/// A shooting pass's radiosity (before any final gather) and its error estimate's parts.
#[derive(Clone, Debug)]
pub struct ShotResult {
    pub b: Vec<[f64; 3]>,
    pub channels: Vec<LightChannel>,
    pub parts: estimate::Parts,
    /// The final gather made on it, when there was one: an error target pools further gather
    /// rounds with it (`passes`, [`final_gather::Gathers::plan`]).
    pub gathers: Option<final_gather::Gathers>,
}

/// The scalar the solver ranks and stops by: the mean of the three channels.
#[inline]
pub fn scalar(v: &[f64; 3]) -> f64 {
    (v[0] + v[1] + v[2]) / 3.0
}

/// Errors a user can cause.
#[derive(Debug, thiserror::Error)]
pub enum SolveError {
    #[error("the scene has no light: no material emits (give one a Ke in the MTL file or an emissive factor in the glTF, or use --emit MATERIAL=R,G,B, --luminaires, --sky)")]
    NoEmitter,
    #[error("the scene has {0} patches; at most {max} are supported", max = ray_shots::BACK - 1)]
    TooManyPatches(usize),
    #[error(transparent)]
    MatrixTooLarge(#[from] matrix::TooLarge),
    #[error("the reference has {reference} patches but this mesh has {patches}: solve the reference with the same scene and --patch-size")]
    ReferenceMismatch { reference: usize, patches: usize },
    #[error("{0}")]
    Checkpoint(String),
    #[error("--method {0} casts rays but no intersector was built")]
    NoIntersector(&'static str),
    #[error("the scene has glazing (a material that transmits light), which hemi-cubes cannot see through: use a method that casts rays (adaptive-hybrid or adaptive-rays), not --method {0}")]
    GlazingNeedsRays(&'static str),
    #[error("--sky: {0}")]
    Sky(String),
    #[error(
        "--sky needs a method that casts rays (adaptive-hybrid or adaptive-rays), not --method {0}"
    )]
    SkyNeedsRays(&'static str),
    #[error(
        "--luminaires needs a method that casts rays (adaptive-hybrid or adaptive-rays), not --method {0}"
    )]
    LuminairesNeedRays(&'static str),
}

/// Solves by the method `cfg.method` names, casting rays through `isect`, with no hooks.
pub fn solve<I: Intersector>(
    mesh: &Mesh,
    materials: &[Material],
    isect: &I,
    cfg: &SolveSettings,
    on_trace: impl FnMut(&TracePoint),
) -> Result<Solution, SolveError> {
    run(
        mesh,
        materials,
        Some(isect),
        cfg,
        &RunHooks::default(),
        on_trace,
    )
}

/// Solves by the method `cfg.method` names. `isect` is needed only by methods that cast rays
/// ([`MethodKind::casts_rays`]): the hemi-cube methods and the matrix method build none.
pub fn run<I: Intersector>(
    mesh: &Mesh,
    materials: &[Material],
    isect: Option<&I>,
    cfg: &SolveSettings,
    hooks: &RunHooks,
    on_trace: impl FnMut(&TracePoint),
) -> Result<Solution, SolveError> {
    match cfg.method {
        MethodKind::Gathering => {
            matrix::check_size(mesh.patches.len(), cfg.gather_cap_mib)?;
            if !mesh
                .patches
                .iter()
                .any(|p| materials[p.material as usize].is_emitter())
            {
                return Err(SolveError::NoEmitter);
            }
            if let Some(r) = &hooks.reference {
                if r.len() != mesh.patches.len() {
                    return Err(SolveError::ReferenceMismatch {
                        reference: r.len(),
                        patches: mesh.patches.len(),
                    });
                }
            }
            Ok(matrix::solve(mesh, materials, cfg, hooks, on_trace))
        }
        _ => match cfg.error_target {
            Some(e) => passes::shoot_to(mesh, materials, isect, cfg, hooks, e, on_trace),
            None => driver::shoot(mesh, materials, isect, cfg, hooks, on_trace),
        },
    }
}
