//! The shooting driver: progressive refinement by shooting (Cohen et al. 1988) as Airey &
//! Ouh-young (1989) run it, for every shooting method.
//!
//! Each step takes the patches with the most unshot flux ΔΦ_i off a priority queue and shoots
//! them: by rays ([`super::ray_shots`], Sec. 2), by hemi-cubes ([`super::cube_shots`]), or, for
//! `adaptive-hybrid`, by hemi-cubes until the switch policy ([`super::switch`], Sec. 4) says
//! rays are cheaper and by rays from then on. Before each step the stop rule
//! ([`super::stopping`], Sec. 3) is asked whether to go on. The books ([`super::books`]) hold
//! every patch's unshot and kept flux.
//!
//! **Waves.** Late in a solve shots are tiny (a few rays each), too small to feed two cores. So
//! shooters are taken from the top of the queue in *waves* (about [`wave_rays`] rays, or
//! [`CUBE_WAVE`] hemi-cubes), cast in parallel against the books at the start of the wave (in
//! the order of their patches, for the cache), and their hits applied in the queue's order.
//! Picking a shooter costs O(log patches) (an indexed heap, `key_heap::KeyHeap`), not
//! O(patches). Ray waves are pipelined: while one thread applies wave k's hits, the others
//! cast wave k + 1, which was taken off the heap before wave k's deposits reached it; its
//! shooters are then at most one wave out of date, the books stay exact and the order stays
//! fixed. The applying thread then makes the next step's head — the stop rule, a trace point,
//! wave k + 2 taken off the heap — while wave k + 1 is still being cast, on the books a step
//! would see after it (late in a solve, taking tens of thousands of one-ray shooters off the
//! heap was a sixth of the shooting's time with the other core idle).
//!
//! **Reproducible.** Every random number comes from (seed, shot, chunk); a wave's composition
//! depends on the books and the settings only; the hybrid's switch on counted work (by
//! default). So the result is the same on any run and any number of threads. The clock is
//! read for three things that never change the books or the shot order: trace points (taken
//! at geometric steps of elapsed time and of shots, they only read the books), checkpoints
//! (written at safe points that come every [`SYNC_WAVES`] waves whether or not one is due),
//! and `max_time` (a clock budget, the one setting whose result depends on the clock), plus
//! `--switch-by measured`.

use super::books::{self, State};
use super::cube_shots::{self, CubeHits, CubeKind, CubeShooter, CubeShot, CUBE_WAVE};
use super::estimate::PatchScalars;
use super::final_gather;
use super::gather_budget::gather_rays_within;
use super::luminaire_shots;
use super::ray_shots::{
    apply_rays, energy_per_ray, grid_for, tasks_of, wave_rays, Hits, RayCaster, RayShot, Task, BACK,
};
use super::sky_shots;
use super::stopping::{self, Progress};
use super::switch::{self, CostModel, SwitchPolicy};
use super::{
    scalar, LightChannel, MethodKind, RunHooks, Solution, SolveError, SolveSettings, SolveStats,
    StopReason, SwitchInfo, TracePoint,
};
use crate::intersect::Intersector;
use crate::mesh::Mesh;
use crate::scene::Material;
use crate::sky::Sky;
use rayon::prelude::*;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Waves between safe points: one comes every this many waves whether or not anyone
/// checkpoints, so runs with and without checkpoints, and resumed runs, shoot the same.
pub const SYNC_WAVES: u64 = 8;

/// What a checkpoint keeps of a shooting run at a safe point: the driver's counters and
/// trace, and the states of the books and of the switch policy, each saved by its owner.
/// [`super::checkpoint`] writes it to a file and reads it back; a run given one
/// ([`RunHooks::resume`]) continues exactly as the run it was saved from.
#[derive(Clone, Debug, Default)]
pub struct Saved {
    /// Seconds the run had taken.
    pub elapsed: f64,
    /// C, which the resumed run must share.
    pub energy_per_ray: f64,
    pub shots: u64,
    pub waves: u64,
    pub hemicube_shots: u64,
    pub hemicube_cells: u64,
    /// The hybrid's switch, once it has happened.
    pub switched: Option<SwitchInfo>,
    /// Hemi-cube shots still to come (the hemi-cube methods, or the hybrid before switching).
    pub cubes_active: bool,
    pub trace: Vec<TracePoint>,
    pub books: books::Saved,
    pub switch: switch::Saved,
}

/// Writes one saved state somewhere; an error is one line.
pub type WriteFn = dyn Fn(&Saved) -> Result<(), String> + Send + Sync;

/// Where checkpoints go (`--checkpoint`): a writer called with the run's state at the first
/// safe point every `every`, and on interrupt (the pipeline writes the file atomically).
#[derive(Clone)]
pub struct Sink {
    pub every: Duration,
    pub write: Arc<WriteFn>,
}

impl std::fmt::Debug for Sink {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Sink {{ every: {:?} }}", self.every)
    }
}

/// Shoots until Sec. 3's criterion or a budget stops it, by the method `cfg.method` names
/// (any but gathering). `isect` is needed by the methods that cast rays (`adaptive-rays`,
/// `adaptive-hybrid`); the hemi-cube methods never cast a ray. `on_trace` is called with each
/// new trace point (for progress display).
pub fn shoot<I: Intersector>(
    mesh: &Mesh,
    materials: &[Material],
    isect: Option<&I>,
    cfg: &SolveSettings,
    hooks: &RunHooks,
    on_trace: impl FnMut(&TracePoint),
) -> Result<Solution, SolveError> {
    shoot_with(mesh, materials, isect, cfg, hooks, switch::KEPT, on_trace)
}

/// [`shoot`], the hybrid's counted switch weighing work by `model` instead of the kept
/// constants (`radiosity bench shots` compares the two).
pub fn shoot_with<I: Intersector>(
    mesh: &Mesh,
    materials: &[Material],
    isect: Option<&I>,
    cfg: &SolveSettings,
    hooks: &RunHooks,
    model: CostModel,
    mut on_trace: impl FnMut(&TracePoint),
) -> Result<Solution, SolveError> {
    let start = Instant::now();
    let mut d = Driver::new(mesh, materials, isect, cfg, hooks, model)?;
    if let Some(saved) = &hooks.resume {
        d.resume(saved)?;
    } else {
        d.shoot_sky();
        d.shoot_luminaires();
    }
    let reason = d.run(start, &mut on_trace)?;
    // The final gather re-estimates the patches the shooting left noisy (not after Ctrl-C);
    // the hemi-cube baselines stay as they are.
    let gather = (cfg.final_gather && cfg.method.casts_rays() && reason != StopReason::Interrupted)
        .then_some(isect)
        .flatten()
        .map(|isect| {
            let est = d.scalars.estimator(d.energy_per_ray);
            let shooting = final_gather::Shooting {
                parts: d.st.estimate_parts(&est),
                energy_per_ray: d.energy_per_ray,
            };
            (isect, shooting)
        });
    // An error target combines passes by their shooting results and exact estimates.
    let keep = cfg.error_target.map(|_| {
        let est = d.scalars.estimator(d.energy_per_ray);
        d.st.estimate_parts(&est)
    });
    let sky = d.sky.take().map(|(s, _)| s);
    let mut sol = d.finish(reason, start);
    if let Some(parts) = keep {
        sol.shooting = Some(Box::new(super::ShotResult {
            b: sol.b.clone(),
            channels: sol.channels.clone(),
            parts,
            gathers: None,
        }));
    }
    let gather = gather.and_then(|g| {
        let rays = gather_rays_within(cfg, mesh.patches.len(), &sol.stats, start)?;
        Some((g, rays))
    });
    if let Some(((isect, shooting), rays)) = gather {
        let inputs = final_gather::GatherInputs {
            mesh,
            materials,
            isect,
            seed: cfg.seed,
            rays,
            group: hooks.light_groups.as_deref().map(|g| g.of_patch.as_slice()),
            shooting: &shooting,
            sky: sky.as_ref(),
            reference: hooks.reference.as_deref().map(Vec::as_slice),
            pilot: cfg.first_gather_pilot(rays),
        };
        let gathers = final_gather::apply(&inputs, &mut sol, None, &mut on_trace);
        // An error target may add gather rounds to these (`passes`).
        if let Some(shot) = sol.shooting.as_mut() {
            shot.gathers = Some(gathers);
        }
    }
    Ok(sol)
}

/// A ray wave cast but not yet applied.
struct Pending {
    wave: Vec<RayShot>,
    tasks: Vec<Task>,
    hits: Vec<Hits>,
}

/// What a step of the shooting does, once its head ([`Driver::head`]) is made.
enum Step {
    /// Stop, for this reason (its last trace point recorded).
    Stop(StopReason),
    /// Land the wave in flight, then look again: nothing to shoot until it lands, or its
    /// deposits may change the stop rule's verdict.
    Land,
    /// Shoot these ray shots (never none).
    Rays(Vec<RayShot>),
    /// Shoot a wave of hemi-cubes.
    Cubes,
}

/// A ray wave cast but not yet applied, as the stop rule counts it: its rays (every ray has a
/// hit code, a covered one too) and its flux (scalar W).
#[derive(Clone, Copy)]
struct Flight {
    rays: u64,
    flux: f64,
    /// Whether there is such a wave.
    landing: bool,
}

impl Flight {
    /// The wave in flight, `pending`.
    fn of_pending(pending: Option<&Pending>) -> Flight {
        pending.map_or(
            Flight {
                rays: 0,
                flux: 0.0,
                landing: false,
            },
            |p| Flight::of(&p.wave, &p.tasks),
        )
    }

    /// The wave `wave` of tasks `tasks`.
    fn of(wave: &[RayShot], tasks: &[Task]) -> Flight {
        Flight {
            rays: tasks.iter().map(|t| t.count as u64).sum(),
            flux: wave.iter().map(|s| scalar(&s.phi)).sum::<f64>(),
            landing: true,
        }
    }
}

/// One shooting solve in progress.
struct Driver<'a, I> {
    mesh: &'a Mesh,
    materials: &'a [Material],
    cfg: &'a SolveSettings,
    hooks: &'a RunHooks,
    st: State,
    /// C: the energy every ray carries (scalar W; Sec. 2).
    energy_per_ray: f64,
    /// Rays per wave ([`wave_rays`]).
    wave_rays: usize,
    scalars: PatchScalars,
    /// Casts the rays (the methods that cast rays).
    caster: Option<RayCaster<'a, I>>,
    /// The sky and sun and the sphere they shoot at.
    sky: Option<(Sky, sky_shots::Bounds)>,
    /// Hemi-cube shots still to come (the hemi-cube methods, or the hybrid before it switches).
    cubes: Option<CubeShooter>,
    cube_hits: Vec<CubeHits>,
    switch: SwitchPolicy,
    stats: SolveStats,
    pending: Option<Pending>,
    /// The next step's head, made while the last wave was cast ([`Driver::ray_wave`]).
    ahead: Option<Step>,
    /// Seconds the run resumed from had already taken.
    time_offset: f64,
    next_trace: f64,
    next_trace_shots: u64,
    next_checkpoint: f64,
    last_sync: Option<u64>,
    interrupt_now: bool,
}

impl<'a, I: Intersector> Driver<'a, I> {
    /// Checks what a user can get wrong, and sets up the books, C and the shooters.
    fn new(
        mesh: &'a Mesh,
        materials: &'a [Material],
        isect: Option<&'a I>,
        cfg: &'a SolveSettings,
        hooks: &'a RunHooks,
        model: CostModel,
    ) -> Result<Self, SolveError> {
        let n = mesh.patches.len();
        if n >= BACK as usize {
            return Err(SolveError::TooManyPatches(n));
        }
        let method = cfg.method;
        if method.casts_rays() && isect.is_none() {
            return Err(SolveError::NoIntersector(method.name()));
        }
        let mut st = State::new(mesh, materials, cfg.stop_fraction);
        let sky = cfg
            .build_sky()
            .map_err(|e| SolveError::Sky(e.to_string()))?;
        if sky.is_some() && !method.casts_rays() {
            return Err(SolveError::SkyNeedsRays(method.name()));
        }
        let sky_lit = sky.as_ref().is_some_and(|s| {
            s.pieces()
                .iter()
                .any(|p| scalar(&p.radiance) * p.solid_angle > 0.0)
        });
        let from_luminaires = luminaire_shots::emitted_flux(&mesh.luminaires);
        if !mesh.luminaires.is_empty() && !method.casts_rays() {
            return Err(SolveError::LuminairesNeedRays(method.name()));
        }
        if scalar(&st.energy.emitted) <= 0.0
            && !sky_lit
            && from_luminaires.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)
        {
            return Err(SolveError::NoEmitter);
        }
        if let Some(g) = &hooks.light_groups {
            st.start_channels(&g.of_patch, g.len());
        }
        if let Some(r) = &hooks.reference {
            if r.len() != n {
                return Err(SolveError::ReferenceMismatch {
                    reference: r.len(),
                    patches: n,
                });
            }
        }
        let rho: Vec<[f64; 3]> = mesh
            .patches
            .iter()
            .map(|p| materials[p.material as usize].rho)
            .collect();
        // What the surfaces emit: a doubled lamp's back twin shines into the fixture or the
        // void, and must not coarsen the room's sampling (docs/design.md §7).
        let emitted: f64 = (0..n)
            .filter(|&i| mesh.is_surface(i))
            .map(|i| {
                let p = &mesh.patches[i];
                scalar(&materials[p.material as usize].emission()) * p.area
            })
            .sum();
        let caster = isect
            .map(|isect| RayCaster::new(mesh, isect, cfg.seed, cfg.jitter).with_glazing(materials));
        // Glazing: hemi-cubes cannot see through glass, so rays do all the shooting.
        let glazed = materials.iter().any(|m| m.transmittance > 0.0);
        if glazed && !method.casts_rays() {
            return Err(SolveError::GlazingNeedsRays(method.name()));
        }
        let bounds = sky_shots::Bounds::of(mesh);
        // What the sky delivers to the model counts as emitted (sky_shots: "C").
        let from_sky = match (&sky, &caster) {
            (Some(sky), Some(caster)) if cfg.energy_per_ray.is_none() => {
                sky_shots::received_flux(caster, sky, &bounds, cfg.seed)
            }
            _ => 0.0,
        };
        let c = cfg.energy_per_ray.filter(|c| *c > 0.0).unwrap_or_else(|| {
            let all = emitted + from_sky + from_luminaires;
            energy_per_ray(mesh, &rho, all, cfg.tolerance)
        });
        let cubes = match method {
            MethodKind::Hemicube | MethodKind::HemicubeJittered => Some(CubeKind::Uniform {
                n: cfg.hemicube_n,
                jitter: method == MethodKind::HemicubeJittered,
            }),
            MethodKind::AdaptiveHybrid if glazed => None,
            MethodKind::AdaptiveHemicube | MethodKind::AdaptiveHybrid => Some(CubeKind::Adaptive),
            MethodKind::AdaptiveRays | MethodKind::Gathering => None,
        };
        Ok(Driver {
            mesh,
            materials,
            cfg,
            hooks,
            st,
            energy_per_ray: c,
            wave_rays: wave_rays(n),
            scalars: PatchScalars::new(mesh, materials),
            caster,
            sky: sky.map(|s| (s, bounds)),
            cubes: cubes.map(|kind| CubeShooter::new(kind, c)),
            cube_hits: Vec::new(),
            switch: SwitchPolicy::new(cfg, model, n),
            stats: SolveStats {
                energy_per_ray: c,
                ..SolveStats::default()
            },
            pending: None,
            ahead: None,
            time_offset: 0.0,
            next_trace: 0.0,
            next_trace_shots: 0,
            next_checkpoint: 0.0,
            last_sync: None,
            interrupt_now: false,
        })
    }

    /// The sky's pieces and the sun shoot, before any patch ([`sky_shots`]).
    fn shoot_sky(&mut self) {
        if let (Some((sky, bounds)), Some(caster)) = (&self.sky, &self.caster) {
            let channels = self
                .hooks
                .light_groups
                .as_ref()
                .map(|g| sky_shots::Channels {
                    k: g.len(),
                    sky: g.channel(super::lights::SKY_CHANNEL),
                    sun: g.channel(super::lights::SUN_CHANNEL),
                    patches: g.channel(super::lights::GROUND_CHANNEL),
                });
            let done = sky_shots::shoot(
                &mut self.st,
                caster,
                sky,
                bounds,
                self.energy_per_ray,
                self.cfg.seed,
                channels,
            );
            self.stats.shots += done.shots;
        }
    }

    /// The luminaires shoot, after the sky and before any patch ([`luminaire_shots`]).
    fn shoot_luminaires(&mut self) {
        let (Some(caster), false) = (&self.caster, self.mesh.luminaires.is_empty()) else {
            return;
        };
        let groups = self.hooks.light_groups.as_ref();
        let luminaires = &self.mesh.luminaires;
        let of: Vec<Option<usize>> = (luminaires.iter())
            .map(|l| groups.and_then(|g| g.channel(&l.group)))
            .collect();
        let done = luminaire_shots::shoot(
            &mut self.st,
            caster,
            luminaires,
            self.energy_per_ray,
            self.cfg.seed,
            groups.map(|g| (g.len(), of.as_slice())),
        );
        self.stats.shots += done.shots;
    }

    /// What a checkpoint keeps at a safe point (see [`Saved`]).
    fn save(&self, elapsed: f64) -> Saved {
        let stats = &self.stats;
        Saved {
            elapsed,
            energy_per_ray: self.energy_per_ray,
            shots: stats.shots,
            waves: stats.waves,
            hemicube_shots: stats.hemicube_shots,
            hemicube_cells: stats.hemicube_cells,
            switched: stats.switch,
            cubes_active: self.cubes.is_some(),
            trace: stats.trace.clone(),
            books: self.st.save(),
            switch: self.switch.save(),
        }
    }

    /// Carries on from a saved state: the books, the counters, the switch policy's state and
    /// the trace so far.
    fn resume(&mut self, s: &Saved) -> Result<(), SolveError> {
        let c = self.energy_per_ray;
        if (s.energy_per_ray - c).abs() > 1e-12 * c {
            return Err(SolveError::Checkpoint(format!(
                "the checkpoint's energy per ray is {} W, this run's {c} W: resume with the same --tolerance or --energy-per-ray",
                s.energy_per_ray
            )));
        }
        self.st.restore(&s.books).map_err(SolveError::Checkpoint)?;
        let stats = &mut self.stats;
        stats.shots = s.shots;
        stats.waves = s.waves;
        stats.hemicube_shots = s.hemicube_shots;
        stats.hemicube_cells = s.hemicube_cells;
        stats.switch = s.switched;
        stats.trace = s.trace.clone();
        if !s.cubes_active {
            self.cubes = None;
        }
        self.switch.restore(&s.switch);
        self.time_offset = s.elapsed;
        self.next_trace = s.elapsed;
        self.next_trace_shots = s.shots;
        self.next_checkpoint = s.elapsed;
        Ok(())
    }

    /// The loop: a safe point when one is due, the stop rule, a trace point when one is due,
    /// then a wave of hemi-cube or ray shots.
    fn run(
        &mut self,
        start: Instant,
        on_trace: &mut impl FnMut(&TracePoint),
    ) -> Result<StopReason, SolveError> {
        let mut reported = self.stats.trace.len();
        loop {
            let elapsed = self.time_offset + start.elapsed().as_secs_f64();
            self.safe_point(elapsed)?;
            let step = match self.ahead.take() {
                Some(step) => step,
                None => {
                    let flight = Flight::of_pending(self.pending.as_ref());
                    self.head(elapsed, flight)
                }
            };
            for p in &self.stats.trace[reported..] {
                on_trace(p);
            }
            reported = self.stats.trace.len();
            match step {
                Step::Stop(r) => return Ok(r),
                Step::Land => {
                    self.land_pending();
                }
                Step::Rays(wave) => self.ray_wave(wave, start),
                Step::Cubes => self.cube_wave(),
            }
        }
    }

    /// What a step does before it shoots, on the books as they stand with `flight` still to
    /// land: Sec. 3's stop rule, a trace point when one is due, and the next wave's shooters
    /// taken off the queue.
    fn head(&mut self, elapsed: f64, flight: Flight) -> Step {
        let progress = self.progress(elapsed, flight);
        let cfg = self.cfg;
        let st = &mut self.st;
        if let Some(r) = stopping::verdict(cfg, &progress, || st.has_unshot()) {
            if flight.landing {
                return Step::Land;
            }
            self.record(elapsed, progress.max_unshot_b, 0.0);
            return Step::Stop(r);
        }
        // Trace points at geometric steps of time and of shots (even spacing on the log-log
        // plots of error against time). They read the books, never change them.
        if elapsed >= self.next_trace || self.stats.shots >= self.next_trace_shots {
            self.record(elapsed, progress.max_unshot_b, flight.flux);
            self.next_trace = (elapsed * 1.25).max(elapsed + 0.002);
            self.next_trace_shots = (self.stats.shots as f64 * 1.25) as u64 + 8;
        }
        if self.cubes.is_some() {
            return Step::Cubes;
        }
        let wave = self.take_ray_wave(progress.samples);
        if wave.is_empty() {
            Step::Land
        } else {
            Step::Rays(wave)
        }
    }

    /// Applies the ray wave in flight, if any; whether there was one.
    fn land_pending(&mut self) -> bool {
        match self.pending.take() {
            Some(p) => {
                apply_rays(&mut self.st, &p.wave, &p.tasks, &p.hits);
                true
            }
            None => false,
        }
    }

    /// A safe point every SYNC_WAVES waves, whether or not anyone checkpoints (so runs with
    /// and without checkpoints, and resumed runs, shoot the same): the wave in flight lands,
    /// then a checkpoint is written if one is due or Ctrl-C was pressed.
    fn safe_point(&mut self, elapsed: f64) -> Result<(), SolveError> {
        if !self.stats.waves.is_multiple_of(SYNC_WAVES) || self.last_sync == Some(self.stats.waves)
        {
            return Ok(());
        }
        self.last_sync = Some(self.stats.waves);
        self.land_pending();
        let interrupted = self
            .hooks
            .interrupt
            .as_ref()
            .is_some_and(|f| f.load(std::sync::atomic::Ordering::Relaxed));
        if let Some(sink) = &self.hooks.checkpoint {
            if interrupted || elapsed >= self.next_checkpoint {
                (sink.write)(&self.save(elapsed)).map_err(SolveError::Checkpoint)?;
                self.next_checkpoint = elapsed + sink.every.as_secs_f64();
            }
        }
        // Only here, at a safe point, so a resumed run repeats the same shots.
        self.interrupt_now = interrupted;
        Ok(())
    }

    /// What the stop rule looks at, with `flight` cast but not applied.
    fn progress(&mut self, elapsed: f64, flight: Flight) -> Progress {
        Progress {
            interrupted: self.interrupt_now,
            max_unshot_b: self.st.max_unshot_b(),
            amplification: self.st.amplification(flight.flux),
            mean_b: self.st.mean_b(),
            elapsed,
            samples: self.st.rays + self.st.cells + flight.rays,
            unshot_share: self.st.unshot_share(flight.flux),
        }
    }

    /// Adds a trace point (the books are only read); `run` reports it.
    fn record(&mut self, elapsed: f64, max_b: f64, flying: f64) {
        let est = self.scalars.estimator(self.energy_per_ray);
        let reference = self.hooks.reference.as_deref().map(Vec::as_slice);
        let (stats, st) = (&mut self.stats, &self.st);
        st.record(stats, elapsed, max_b, &est, reference, flying, &mut |_| {});
    }

    /// A wave of hemi-cube shots. For the hybrid, each shot first asks the switch policy
    /// whether it is cheaper by rays (Sec. 4); from the first that is, the hemi-cubes stop.
    fn cube_wave(&mut self) {
        let Some(shooter) = self.cubes.as_mut() else {
            return;
        };
        let mut wave: Vec<CubeShot> = Vec::new();
        let mut switch = None;
        while wave.len() < CUBE_WAVE {
            let Some((i, flux)) = self.st.peek_shooter() else {
                break;
            };
            let cube = shooter.cube_for(flux);
            if self.cfg.method == MethodKind::AdaptiveHybrid {
                let rays = grid_for(flux, self.energy_per_ray).len() as u64;
                let caster = self.caster.as_ref().expect("checked in Driver::new");
                let probe = || switch::probe(caster, i);
                switch = self
                    .switch
                    .consider(self.stats.shots, rays, cube.cell_count(), probe);
                if switch.is_some() {
                    break;
                }
            }
            let (patch, phi) = self.st.take_shooter().expect("peeked");
            let ch = self.st.take_channels(patch);
            wave.push(CubeShot {
                patch,
                index: self.stats.shots,
                phi,
                ch,
                cube,
            });
            self.stats.shots += 1;
        }
        if !wave.is_empty() {
            shooter.cast(self.mesh, self.cfg.seed, &wave, &mut self.cube_hits);
            for (shot, h) in wave.iter().zip(&self.cube_hits) {
                self.switch.record(shot.cube.cell_count(), h);
                let caster = self.caster.as_ref();
                cube_shots::apply(&mut self.st, shot, h, self.mesh, caster);
            }
            self.st.finish_batch();
            self.stats.hemicube_shots += wave.len() as u64;
            self.stats.waves += 1;
        }
        if switch.is_some() {
            self.stats.switch = switch;
            self.cubes = None;
        }
    }

    /// Takes a wave of ray shots off the top of the heap (Sec. 2: X = ΔΦ_i / C rays each), at
    /// most what the `max_rays` budget leaves after `samples`.
    fn take_ray_wave(&mut self, samples: u64) -> Vec<RayShot> {
        let mut wave = Vec::new();
        let mut wave_rays = 0usize;
        let ray_cap = self
            .cfg
            .max_rays
            .map_or(usize::MAX, |r| r.saturating_sub(samples) as usize);
        while wave_rays < self.wave_rays.min(ray_cap.max(1)) {
            let Some((i, phi)) = self.st.take_shooter() else {
                break;
            };
            let ch = self.st.take_channels(i);
            let grid = grid_for(scalar(&phi), self.energy_per_ray);
            wave_rays += grid.len();
            wave.push(RayShot {
                patch: i,
                index: self.stats.shots,
                phi,
                ch,
                grid,
            });
            self.stats.shots += 1;
        }
        wave
    }

    /// A wave of ray shots (`wave`, not empty), cast in parallel while the previous wave is
    /// applied; the thread that applies it then makes the next step's head (`Driver::head`:
    /// the stop rule, a trace point, the next wave taken off the queue) while the others cast,
    /// on the same books a step after this one would see, unless a safe point comes first (it
    /// lands this wave before the next head).
    fn ray_wave(&mut self, wave: Vec<RayShot>, start: Instant) {
        let caster = self.caster.take().expect("checked in Driver::new");
        let tasks = tasks_of(&wave);
        let flight = Flight::of(&wave, &tasks);
        let ahead = !(self.stats.waves + 1).is_multiple_of(SYNC_WAVES);
        let cast = || cast_in_patch_order(&caster, &wave, &tasks);
        let hits = match self.pending.take() {
            Some(p) => {
                let me = &mut *self;
                let apply_then_head = || {
                    apply_rays(&mut me.st, &p.wave, &p.tasks, &p.hits);
                    if ahead {
                        let elapsed = me.time_offset + start.elapsed().as_secs_f64();
                        me.ahead = Some(me.head(elapsed, flight));
                    }
                };
                rayon::join(apply_then_head, cast).1
            }
            None => cast(),
        };
        self.caster = Some(caster);
        self.pending = Some(Pending { wave, tasks, hits });
        self.stats.waves += 1;
    }

    /// Closes the books and hands back the solution.
    fn finish(mut self, reason: StopReason, start: Instant) -> Solution {
        let st = &mut self.st;
        st.close_books();
        let mut stats = self.stats;
        stats.rays = st.rays;
        stats.hemicube_cells = st.cells;
        stats.energy = st.energy;
        stats.stop_reason = Some(reason);
        stats.seconds = self.time_offset + start.elapsed().as_secs_f64();
        let channels = match &self.hooks.light_groups {
            Some(g) => st
                .channel_radiosity(self.mesh, self.materials, &g.of_patch)
                .into_iter()
                .zip(&g.names)
                .map(|(b, name)| LightChannel {
                    name: name.clone(),
                    b,
                })
                .collect(),
            None => Vec::new(),
        };
        Solution {
            b: st.radiosity(self.mesh, self.materials),
            unshot: st.patches.iter().map(|p| p.unshot).collect(),
            stats,
            channels,
            shooting: None,
            back: std::mem::take(&mut st.back),
        }
    }
}

/// A wave's tasks cast in the order of their shooters' patches, the hits handed back in task
/// order. Patches are numbered surface by surface, so shots of nearby patches then follow
/// one another and reuse the intersector's nodes and triangles in the cache, where the
/// queue's order jumps across the model (measured: docs/results/pipeline-1m.md). What a
/// task's rays meet depends only on its shot and chunk, so the order changes nothing else.
fn cast_in_patch_order<I: Intersector>(
    caster: &RayCaster<'_, I>,
    wave: &[RayShot],
    tasks: &[Task],
) -> Vec<Hits> {
    let mut order: Vec<u32> = (0..tasks.len() as u32).collect();
    order.sort_by_key(|&k| (wave[tasks[k as usize].shot].patch, k));
    let cast: Vec<Hits> = order
        .par_iter()
        .map(|&k| {
            let t = &tasks[k as usize];
            caster.cast(&wave[t.shot], t.chunk, t.first, t.count)
        })
        .collect();
    let mut hits = vec![Hits::default(); tasks.len()];
    for (&k, h) in order.iter().zip(cast) {
        hits[k as usize] = h;
    }
    hits
}
