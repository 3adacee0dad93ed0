//! The stages of a solve up to its result (docs/design.md §1): load the scene, cut it into
//! patches, build the intersector the method needs, solve. Each takes what it needs, logs what a
//! user should hear of, and returns its value; `solve_into` (`super`) calls them in order. What
//! follows the solve reads it through [`Solved`].

use super::SolveJob;
use crate::intersect::select::{AnyIntersector, Selection};
use crate::intersect::Intersector;
use crate::model::Model;
use crate::progress::Progress;
use crate::report::{self, LitBacks, Summary};
use crate::scene::Scene;
use crate::sky::Sky;
use crate::solve::{RunHooks, Solution, TracePoint};
use crate::Error;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Instant;

/// The solve's intersector and why it was chosen; `None` for the methods that cast no rays.
pub type SolveIntersector = Option<(AnyIntersector, Selection)>;

/// A finished solve: what the stages after it (refine, measure, picture, write) read.
pub struct Solved<'a> {
    pub model: &'a Model,
    /// The solve's intersector (`None`: the method casts no rays).
    pub isect: Option<&'a (AnyIntersector, Selection)>,
    pub sol: Solution,
    /// The solve's sky, if any: the patch table's daylight columns, the elements, the grid and
    /// the gathered picture see the same one.
    pub sky: Option<Sky>,
    /// When the run started (the elements keep to what is left of `--max-time`; the total time).
    pub t0: Instant,
    /// The bars (the elements and the gathered picture have theirs).
    pub progress: &'a Progress,
    /// What [`lit_backs`] did, when it ran.
    pub lit_backs: Option<LitBacks>,
}

/// Wall and CPU time of one stage.
pub struct Clock {
    wall: Instant,
    cpu: f64,
}

impl Clock {
    pub fn start() -> Clock {
        Clock {
            wall: Instant::now(),
            cpu: report::process_cpu_seconds(),
        }
    }

    /// Wall seconds since the start.
    pub fn seconds(&self) -> f64 {
        self.wall.elapsed().as_secs_f64()
    }

    /// Process CPU seconds since the start.
    pub fn cpu_seconds(&self) -> f64 {
        report::process_cpu_seconds() - self.cpu
    }
}

/// Load: reads the scene, logging its warnings.
pub fn load(
    job: &SolveJob,
    progress: &Progress,
    log: &mut impl FnMut(&str),
) -> Result<Scene, Error> {
    progress.phase("loading");
    let scene = job.source.load(&job.settings.load)?;
    for w in &scene.warnings {
        log(&format!("warning: {w}"));
    }
    Ok(scene)
}

/// Mesh: cuts the scene into patches, logging the patch size chosen and the counts.
pub fn mesh(
    job: &SolveJob,
    scene: Scene,
    progress: &Progress,
    log: &mut impl FnMut(&str),
) -> Result<Model, Error> {
    let s = &job.settings;
    progress.phase("meshing");
    let model = Model::from_scene(scene, &s.mesh)?;
    if s.mesh.patch_size.is_none() {
        let from = if model.scene.patch_size_hint.is_some() {
            "the scene file's own"
        } else {
            "derived from the scene"
        };
        log(&format!(
            "patch size {} m ({from}; --patch-size to change)",
            model.mesh.patch_size
        ));
    }
    log(&format!(
        "{}: {} polygons, {} patches",
        model.scene.name,
        model.scene.polygons.len(),
        model.mesh.patches.len()
    ));
    Ok(model)
}

/// Intersect: builds the intersector, only for the methods that cast rays (a scene builds what
/// it needs), logging the one chosen and why.
pub fn intersect(
    job: &SolveJob,
    model: &Model,
    progress: &Progress,
    log: &mut impl FnMut(&str),
) -> Result<SolveIntersector, Error> {
    let s = &job.settings;
    progress.phase("building the intersectors");
    let isect = model.intersector_for(s.solve.method, s.intersector)?;
    if let Some((isect, chosen)) = &isect {
        log(&format!("intersector {}: {}", isect.name(), chosen.reason));
    }
    Ok(isect)
}

/// Sides: finds the sides no light can reach (`intersect::hidden`), when the method casts
/// rays, and logs how many there are. They are kept in the mesh for the stages after.
pub fn sides(
    job: &SolveJob,
    model: &mut Model,
    isect: Option<&(AnyIntersector, Selection)>,
    progress: &Progress,
    log: &mut impl FnMut(&str),
) {
    let Some((isect, _)) = isect else { return };
    progress.phase("finding hidden faces");
    model.mesh.contacts = model.mesh.find_contacts();
    model.find_hidden(isect, job.settings.solve.seed);
    let (n, area) = model.mesh.hidden.count(&model.mesh);
    if n > 0 {
        log(&format!(
            "hidden: {n} patches ({area:.2} m²) inside closed solids or under other faces: no light reaches them, no rays are spent on them"
        ));
    }
}

/// Light that met backs below this share of the emitted light is left absorbed there: a
/// consistently wound model leaks about 1e-5 at its creases, and up to a few 1e-3 where an
/// open box stands on a floor or a leg sinks into it (the floor inside sends its light into
/// the box); what a model wound both ways loses is far above (a third of the light on the
/// furnished rooms with 30 % of their faces turned round).
pub const LIT_BACKS_MIN: f64 = 1e-2;
/// Back patches are made for the polygons lit from behind, the most lit first, until what
/// meets the remaining backs is below this share of the emitted light.
pub const LIT_BACKS_LEFT: f64 = 2e-4;

/// The first shooting of [`lit_backs`] samples at this tolerance at least ...
pub const LIT_BACKS_TOLERANCE: f64 = 0.15;
/// ... and with its light in no more than about this many rays' worth (n/τ², n the surface
/// patches; `solve::ray_shots::energy_per_ray`): what it decides, polygon by polygon, is
/// measured against the emitted light ([`LIT_BACKS_LEFT`]), so the rays it needs do not grow
/// with the patches (a million-patch building would otherwise spend 18 M).
pub const LIT_BACKS_RAYS: f64 = 4e6;
/// ... and stops once less than this share of the emitted light is still unshot: where light
/// meets backs is told by the light's first bounces, and the paper's stop (Sec. 3) would cost
/// as many shots as the solve itself.
pub const LIT_BACKS_UNSHOT: f64 = 0.05;

/// Past this many surface patches the probe runs on a coarser mesh of the same scene, of
/// about this many patches (`probe_model`): where light meets backs is decided polygon by
/// polygon, and on the model's own mesh the probe's shots grow with its patches (a
/// million-patch building took 2.2 M shots for 6 M rays, most of them one ray each).
pub const LIT_BACKS_PROBE_PATCHES: usize = 100_000;

/// The loosest tolerance a solve takes (`SolveSettings::check`: under 1): past about
/// [`LIT_BACKS_RAYS`] surface patches the probe's rays grow as the patches, one a patch.
const LIT_BACKS_LOOSEST: f64 = 0.99;

/// The patches of `mesh` that are not back twins.
fn surface_patches(mesh: &crate::mesh::Mesh) -> usize {
    (0..mesh.patches.len())
        .filter(|&i| mesh.is_surface(i))
        .count()
}

/// The tolerance of [`lit_backs`]'s first shooting for a model of `n` surface patches:
/// [`LIT_BACKS_TOLERANCE`], looser where they would make it cast more than [`LIT_BACKS_RAYS`]
/// (up to [`LIT_BACKS_LOOSEST`]).
fn lit_backs_tolerance_for(n: f64) -> f64 {
    LIT_BACKS_TOLERANCE
        .max((n / LIT_BACKS_RAYS).sqrt())
        .min(LIT_BACKS_LOOSEST)
}

/// Lit backs: unless the mesh is two-sided or `--one-sided` is asked for, a first shooting
/// (no final gather, no error target, the tolerance at least `lit_backs_tolerance_for`, until
/// [`LIT_BACKS_UNSHOT`] of the light is left) finds where light meets the back of a one-sided
/// face — a model wound both ways, a room inside out — and the polygons lit so get back
/// patches of their own (appended, so the intersector stays valid), as Radiance, whose
/// surfaces are all two-sided, sees them. Rays
/// that left a covered part of their shooter are not cast (`crate::mesh::Contacts`) or carry
/// nothing (`crate::mesh::Hidden`), so they make no back patches. The hidden sides are probed
/// again once the back patches exist. The solve proper runs after, on the new mesh. Past
/// [`LIT_BACKS_PROBE_PATCHES`] surface patches the first shooting runs on a coarser cut of the
/// scene (`probe_model`).
pub fn lit_backs(
    job: &SolveJob,
    model: &mut Model,
    isect: Option<&(AnyIntersector, Selection)>,
    progress: &Progress,
    log: &mut impl FnMut(&str),
) -> Result<Option<LitBacks>, Error> {
    lit_backs_probing(job, model, isect, progress, log, LIT_BACKS_PROBE_PATCHES)
}

/// [`lit_backs`], its first shooting on a coarser cut of the scene past `most` surface patches
/// (tests and studies set it; the solve's is [`LIT_BACKS_PROBE_PATCHES`]).
pub fn lit_backs_probing(
    job: &SolveJob,
    model: &mut Model,
    isect: Option<&(AnyIntersector, Selection)>,
    progress: &Progress,
    log: &mut impl FnMut(&str),
    most: usize,
) -> Result<Option<LitBacks>, Error> {
    let Some((isect, _)) = isect else {
        return Ok(None);
    };
    if !probes_lit_backs(job) {
        return Ok(None);
    }
    progress.phase("looking for faces lit from behind");
    let n = surface_patches(&model.mesh);
    let hooks = RunHooks::default();
    let coarse = coarse_probe(job, &model.scene, (model.mesh.patch_size, n, most), &hooks)?;
    let found = match coarse {
        Some(found) => found,
        None => shoot_probe(job, model, isect, n, &hooks)?,
    };
    Ok(Some(lit_backs_found(job, model, isect, found, log)))
}

/// Whether the job looks for faces lit from behind ([`lit_backs`]): not with `--two-sided`
/// or `--one-sided`, not for the methods that cast no rays.
pub fn probes_lit_backs(job: &SolveJob) -> bool {
    let s = &job.settings;
    !(s.mesh.two_sided || s.mesh.one_sided || !s.solve.method.casts_rays())
}

/// What the first shooting of [`lit_backs`] found: the light that met each polygon's back (a
/// non-emitting one, scalar W), the light that came to rest in the model, and its counts.
pub struct BackLight {
    per_polygon: std::collections::BTreeMap<u32, f64>,
    rested: f64,
    shots: u64,
    rays: u64,
    probe_patches: usize,
    seconds: f64,
}

/// [`lit_backs`]'s first shooting made before the model's own mesh, from `scene` alone, when
/// the model will have more than [`LIT_BACKS_PROBE_PATCHES`] surface patches (counted as
/// `mesh::rough_surface_patch_count` counts them, the mesh not yet made): it runs on a
/// coarser cut of the scene of its own, so it can run beside the meshing of the model
/// (`solve_into`); [`lit_backs_found`] then gives the model its back patches. `None` when the
/// job does not look for lit backs or the model is small enough to be probed on its own mesh.
/// Nor when the model's mesh will be refused (a bad or too fine `--patch-size`: the mesh
/// stage says so). `stop`, once set (the model's own stages failed), ends its shooting at
/// the next safe point: nothing waits long for a probe nobody needs.
pub fn lit_backs_ahead(
    job: &SolveJob,
    scene: &Scene,
    stop: Arc<AtomicBool>,
) -> Result<Option<BackLight>, Error> {
    lit_backs_ahead_probing(job, scene, LIT_BACKS_PROBE_PATCHES, Some(stop))
}

/// [`lit_backs_ahead`] past `most` surface patches (tests and studies set it).
pub fn lit_backs_ahead_probing(
    job: &SolveJob,
    scene: &Scene,
    most: usize,
    stop: Option<Arc<AtomicBool>>,
) -> Result<Option<BackLight>, Error> {
    let opts = &job.settings.mesh;
    if !probes_lit_backs(job) || opts.check().is_err() {
        return Ok(None);
    }
    let all = crate::mesh::rough_patch_count(scene, opts);
    if all.is_nan() || all > crate::mesh::MAX_PATCHES {
        return Ok(None);
    }
    let n = crate::mesh::rough_surface_patch_count(scene, opts).round() as usize;
    let size = crate::mesh::patch_size(scene, opts);
    let hooks = RunHooks {
        interrupt: stop,
        ..RunHooks::default()
    };
    coarse_probe(job, scene, (size, n, most), &hooks)
}

/// The first shooting on a coarser cut of `scene` when the model (patch size `size`, `n`
/// surface patches) has more than `most` surface patches (`probe_model`); `None` otherwise.
fn coarse_probe(
    job: &SolveJob,
    scene: &Scene,
    (size, n, most): (f32, usize, usize),
    hooks: &RunHooks,
) -> Result<Option<BackLight>, Error> {
    let t = Instant::now();
    let Some((coarse, Some((i, _)))) = probe_model(job, scene, size, n, most)? else {
        return Ok(None);
    };
    let mut found = shoot_probe(job, &coarse, &i, n, hooks)?;
    found.seconds = t.elapsed().as_secs_f64();
    Ok(Some(found))
}

/// The first shooting itself, on `probed` (the model's own mesh or a coarser one) for a model
/// of `n` surface patches: the rays the model's own mesh would have had (n/τ² rays for n
/// patches), so a coarser mesh shoots at a coarser tolerance.
fn shoot_probe(
    job: &SolveJob,
    probed: &Model,
    probe_isect: &AnyIntersector,
    n: usize,
    hooks: &RunHooks,
) -> Result<BackLight, Error> {
    let t = Instant::now();
    let s = &job.settings;
    let coarser = (surface_patches(&probed.mesh) as f64 / n.max(1) as f64).sqrt();
    let probe = crate::solve::SolveSettings {
        tolerance: (s.solve.tolerance.max(lit_backs_tolerance_for(n as f64)) * coarser)
            .min(LIT_BACKS_LOOSEST),
        energy_per_ray: None,
        error_target: None,
        final_gather: false,
        stop_unshot: Some(LIT_BACKS_UNSHOT),
        ..s.solve.clone()
    };
    let sol = probed.solve(Some(probe_isect), &probe, hooks, |_| {})?;
    // What met backs is measured against the light that came to rest in the model before the
    // probe stopped (a sky's light that missed it never was in it): the share the rest would
    // leave on backs too.
    let energy = &sol.stats.energy;
    let scalar = crate::solve::scalar;
    let rested =
        (scalar(&energy.emitted) - scalar(&energy.unshot) - scalar(&energy.distant_missed))
            .max(f64::MIN_POSITIVE);
    let mesh = &probed.mesh;
    let mut per_polygon: std::collections::BTreeMap<u32, f64> = Default::default();
    for (i, &phi) in sol.back.iter().enumerate() {
        let p = &mesh.patches[i];
        let m = &probed.scene.materials[p.material as usize];
        if phi > 0.0 && !m.is_emitter() {
            *per_polygon.entry(p.polygon).or_default() += phi;
        }
    }
    Ok(BackLight {
        per_polygon,
        rested,
        shots: sol.stats.shots,
        rays: sol.stats.rays,
        probe_patches: probed.mesh.patches.len(),
        seconds: t.elapsed().as_secs_f64(),
    })
}

/// Gives `model` back patches for the polygons whose backs the first shooting found lit
/// (`found`; [`lit_backs`]), the most lit first, and probes its hidden sides again if any
/// were made.
pub fn lit_backs_found(
    job: &SolveJob,
    model: &mut Model,
    isect: &AnyIntersector,
    found: BackLight,
    log: &mut impl FnMut(&str),
) -> LitBacks {
    let t = Instant::now();
    let BackLight {
        per_polygon,
        rested,
        ..
    } = found;
    // `+ 0.0`: an empty sum is −0.0, which the summary would print as such.
    let total: f64 = per_polygon.values().sum::<f64>() + 0.0;
    let mut out = LitBacks {
        back_fraction: total / rested,
        shots: found.shots,
        rays: found.rays,
        probe_patches: found.probe_patches,
        ..LitBacks::default()
    };
    if total >= LIT_BACKS_MIN * rested {
        let mut ranked: Vec<(u32, f64)> = per_polygon.into_iter().collect();
        ranked.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
        let mut left = total;
        let mut chosen = Vec::new();
        for (poly, phi) in ranked {
            if left < LIT_BACKS_LEFT * rested {
                break;
            }
            chosen.push(poly);
            left -= phi;
        }
        chosen.sort_unstable();
        out.polygons = chosen.len();
        out.patches = model.mesh.add_back_twins_for(&chosen);
        // The new back patches are sides light reaches: probe again with them in place (a
        // room wound inside out looked closed from inside before).
        model.find_hidden(isect, job.settings.solve.seed);
        log(&format!(
            "lit from behind: {:.1} % of the light met the backs of one-sided faces in a first shooting; {} faces given back patches ({} patches; --one-sided to keep them one-sided)",
            100.0 * out.back_fraction,
            out.polygons,
            out.patches
        ));
    }
    out.seconds = found.seconds + t.elapsed().as_secs_f64();
    out
}

/// The model [`lit_backs`] probes when the model (patch size `size`) has `n` surface patches,
/// more than `most`: the same scene cut at a patch size √(n / `most`) times its own, so about
/// `most` patches, with its own intersector, contacts and hidden sides (the rays that leave a
/// covered part carry no light in the probe either). The polygons are the scene's, so what
/// the probe finds on them is given back to the model's own mesh. `None`: the model's own
/// mesh is probed.
fn probe_model(
    job: &SolveJob,
    scene: &Scene,
    size: f32,
    n: usize,
    most: usize,
) -> Result<Option<(Model, SolveIntersector)>, Error> {
    if n <= most {
        return Ok(None);
    }
    let s = &job.settings;
    let opts = crate::mesh::MeshOptions {
        patch_size: Some(size * (n as f32 / most as f32).sqrt()),
        two_sided: false,
        one_sided: false,
        uniform_patches: true,
    };
    let mut coarse = Model::from_scene(scene.clone(), &opts)?;
    let isect = coarse.intersector_for(s.solve.method, s.intersector)?;
    let Some((i, _)) = &isect else {
        return Ok(None);
    };
    coarse.mesh.contacts = coarse.mesh.find_contacts();
    coarse.find_hidden(i, s.solve.seed);
    Ok(Some((coarse, isect)))
}

/// Solve: runs the method with the job's hooks (reference, per-light channels, checkpoints,
/// resume, Ctrl-C; [`super::hooks::build`]), the solve's bar fed by its trace, and logs its
/// counters.
pub fn solve(
    job: &SolveJob,
    model: &Model,
    isect: Option<&(AnyIntersector, Selection)>,
    hooks: &RunHooks,
    progress: &Progress,
    log: &mut impl FnMut(&str),
) -> Result<Solution, Error> {
    progress.start_solve(model.emitted_flux());
    let sol = model.solve(
        isect.map(|(i, _)| i),
        &job.settings.solve,
        hooks,
        |p: &TracePoint| progress.solve_wave(p),
    )?;
    log(&format!("solved: {}", Summary::stats_line(&sol.stats)));
    Ok(sol)
}

/// The solve's sky, for the stages after the solve (the solver builds its own from the same
/// settings).
pub fn sky(job: &SolveJob) -> Option<Sky> {
    job.settings.solve.build_sky().ok().flatten()
}

impl Solved<'_> {
    /// The intersector of the stages after the solve that cast rays (the elements, the gathered
    /// picture): the solve's, or one built for them when they need rays and the method cast none.
    pub fn intersector_after(&self, job: &SolveJob) -> Result<Option<AnyIntersector>, Error> {
        let needs_rays = job
            .settings
            .elements
            .applies_to(self.model.mesh.patches.len())
            || job.shading.shading == crate::render::Shading::Gather;
        if self.isect.is_none() && needs_rays {
            Ok(Some(self.model.intersector(job.settings.intersector)?.0))
        } else {
            Ok(None)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The probe's tolerance stays the default on small models, loosens to keep its rays near
    /// [`LIT_BACKS_RAYS`] on large ones, and never reaches 1, which a solve refuses (a 10 M-patch
    /// building asked for 1.59).
    #[test]
    fn the_probes_tolerance_is_one_a_solve_takes() {
        assert_eq!(lit_backs_tolerance_for(10_000.0), LIT_BACKS_TOLERANCE);
        let t = lit_backs_tolerance_for(1e6);
        assert!((1e6 / (t * t) - LIT_BACKS_RAYS).abs() < 1.0, "{t}");
        for n in [4e6, 1e7, 1e8] {
            let t = lit_backs_tolerance_for(n);
            let probe = crate::solve::SolveSettings {
                tolerance: t,
                ..Default::default()
            };
            assert!(probe.check().is_ok(), "{n} patches: tolerance {t}");
        }
    }
}
