//! Progressive refinement by shooting (Cohen et al. 1988) with the adaptive polar hemisphere
//! sampler of Airey & Ouh-young (1989).
//!
//! Each step takes the patch `i` with the most unshot flux ΔΦ_i and casts X = ΔΦ_i / C rays
//! from it (Sec. 2: samples in proportion to unshot energy, so every ray carries the same
//! energy C), through the equal-area polar cells of [`PolarGrid`], turned by a random angle
//! about the normal (Sec. 3), from points spread uniformly over the patch. The patch `j` a ray
//! hits first receives ρ_j·ΔΦ_i/X; the rest is absorbed.
//!
//! **Waves.** Late in a solve shots are tiny (a few rays each), too small to feed two cores. So
//! shooters are taken from the top of a priority queue in *waves* of about [`WAVE_RAYS`] rays,
//! cast in parallel against the state at the start of the wave, and their hits applied in a
//! fixed order. Picking a shooter costs O(log patches) (a lazily updated binary heap), never
//! O(patches). Every ray's random numbers come from (seed, shot, chunk), and the wave's
//! composition does not depend on the thread count, so results are identical on any number of
//! threads.

use super::checkpoint::{Header, SYNC_WAVES};
use super::cube_shots::{self, CubeCost, CubeHits, CubeKind, CubeShooter, CubeShot, CUBE_WAVE};
use super::error::Estimator;
use super::state::{rng_for, State};
use super::{
    scalar, MethodKind, RunHooks, Solution, SolveError, SolveSettings, SolveStats, StopReason,
    SwitchInfo, TracePoint,
};
use crate::intersect::{Intersector, Ray};
use crate::mesh::Mesh;
use crate::sample::{polar::PolarGrid, Frame};
use crate::scene::Material;
use glam::Vec3;
use rand::Rng;
use rayon::prelude::*;
use std::time::Instant;

/// Rays per wave of shots (see the module docs). Fixed, so results do not depend on threads.
pub const WAVE_RAYS: usize = 32_768;
/// Rays per parallel task.
const CHUNK: usize = 1024;
/// Hit codes: a patch id, a patch id with this bit for a back-face hit, or [`ESCAPED`].
pub(super) const BACK: u32 = 1 << 31;
const ESCAPED: u32 = u32::MAX;

/// The energy per ray C (scalar W) for a requested relative error τ of a typical patch.
///
/// A patch hit N times has a relative sampling error of about 1/√N, so a typical patch should
/// be hit 1/τ² times. All shots together move about Φ_emit / (1 − ρ̄) (every bounce keeps ρ̄),
/// spread over n patches, so C = Φ_emit·τ² / (n·(1 − ρ̄)) — about n/τ² rays in all, whatever ρ̄.
pub fn energy_per_ray(mesh: &Mesh, rho: &[[f64; 3]], emitted: f64, tolerance: f64) -> f64 {
    let area = mesh.total_area().max(f64::MIN_POSITIVE);
    let rho_mean: f64 = mesh
        .patches
        .iter()
        .zip(rho)
        .map(|(p, r)| scalar(r) * p.area)
        .sum::<f64>()
        / area;
    let n = mesh.patches.len().max(1) as f64;
    emitted * tolerance * tolerance / (n * (1.0 - rho_mean).max(1e-3))
}

/// One shooter of a wave.
struct Shot {
    patch: usize,
    /// Global shot number (seeds its random numbers).
    index: u64,
    /// The flux it shoots, RGB.
    phi: [f64; 3],
    /// The same per light channel (empty without `--per-light`).
    ch: Vec<[f64; 3]>,
    grid: PolarGrid,
}

/// Draws points uniformly over the area of one convex patch: a fan triangle chosen by area,
/// then a uniform point in it. Built once per chunk of rays, so no work per ray but the draw.
struct PatchPoints {
    apex: Vec3,
    /// (b, c, cumulative area) of each fan triangle (apex, b, c).
    fan: Vec<(Vec3, Vec3, f32)>,
}

impl PatchPoints {
    fn new(mesh: &Mesh, i: usize) -> PatchPoints {
        let ids = mesh.patch_indices(i);
        let v = |k: usize| mesh.vertices[ids[k] as usize];
        let apex = v(0);
        let mut total = 0.0;
        let fan = (1..ids.len() - 1)
            .map(|k| {
                total += (v(k) - apex).cross(v(k + 1) - apex).length();
                (v(k), v(k + 1), total)
            })
            .collect();
        PatchPoints { apex, fan }
    }

    #[inline]
    fn sample<R: Rng>(&self, rng: &mut R) -> Vec3 {
        let (mut b, mut c, _) = self.fan[0];
        if self.fan.len() > 1 {
            let u = rng.gen::<f32>() * self.fan[self.fan.len() - 1].2;
            let k = self
                .fan
                .iter()
                .position(|f| u < f.2)
                .unwrap_or(self.fan.len() - 1);
            (b, c) = (self.fan[k].0, self.fan[k].1);
        }
        let (r1, r2) = (rng.gen::<f32>().sqrt(), rng.gen::<f32>());
        self.apex * (1.0 - r1) + b * (r1 * (1.0 - r2)) + c * (r1 * r2)
    }
}

/// Everything a shot needs to know about the scene, shared by all threads.
struct Ctx<'a, I> {
    mesh: &'a Mesh,
    isect: &'a I,
    seed: u64,
    jitter: bool,
    /// Smallest offset of ray origins off their patch: a few ulps of the largest coordinate.
    eps_floor: f32,
}

impl<I: Intersector> Ctx<'_, I> {
    /// Casts rays `first..first + count` of `shot`; returns a hit code per ray.
    fn cast(&self, shot: &Shot, chunk: usize, first: usize, count: usize) -> Vec<u32> {
        let i = shot.patch;
        let patch = &self.mesh.patches[i];
        // Sec. 3: a random rotation of the sampling pattern about the normal, per shot.
        let angle = rng_for(self.seed, shot.index, u64::MAX).gen::<f32>() * std::f32::consts::TAU;
        let frame = Frame::new(patch.normal, angle);
        let mut rng = rng_for(self.seed, shot.index, chunk as u64);
        let eps = (1e-4 * (patch.area as f32).sqrt()).max(self.eps_floor);
        let points = PatchPoints::new(self.mesh, i);
        let mut out = Vec::with_capacity(count);
        for k in first..first + count {
            let dir = frame.to_world(shot.grid.direction(k, 0.0, self.jitter, &mut rng));
            let org = points.sample(&mut rng) + patch.normal * eps;
            out.push(self.trace(i, org, dir, eps));
        }
        out
    }

    fn trace(&self, shooter: usize, org: Vec3, dir: Vec3, eps: f32) -> u32 {
        let mut ray = Ray {
            org,
            dir,
            tnear: 0.0,
            tfar: f32::INFINITY,
        };
        // A ray leaving its own (planar, convex) patch cannot meet it again; if rounding says
        // otherwise, step past it.
        for _ in 0..3 {
            match self.isect.intersect(&ray) {
                None => return ESCAPED,
                Some(h) if h.patch as usize == shooter => ray.tnear = h.t + eps,
                Some(h) if h.back => return h.patch | BACK,
                Some(h) => return h.patch,
            }
        }
        ESCAPED
    }

    /// Sec. 4's cost of ray sampling, measured: thread time per ray (s) of a few thousand rays
    /// from `patch`, cast like a shot's but not applied. Twice, keeping the second (the first
    /// warms the caches up).
    fn probe(&self, patch: usize) -> f64 {
        let shot = Shot {
            patch,
            index: u64::MAX - 1,
            phi: [0.0; 3],
            ch: Vec::new(),
            grid: PolarGrid::for_samples((2 * CHUNK) as f64),
        };
        let tasks = tasks_of(std::slice::from_ref(&shot));
        let mut per_ray = 0.0;
        for _ in 0..2 {
            let (secs, rays) = tasks
                .par_iter()
                .map(|t| {
                    let t0 = Instant::now();
                    let n = self.cast(&shot, t.chunk, t.first, t.count).len();
                    (t0.elapsed().as_secs_f64(), n)
                })
                .reduce(|| (0.0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
            per_ray = secs / rays.max(1) as f64;
        }
        per_ray
    }
}

/// Thread time per ray (s) of ray shots from `shooters`, `rays_per_shot` each, cast on the
/// calling thread exactly as the solver casts them (points over the patch, polar cells,
/// rotation) but not applied: Sec. 4's cost of ray sampling, for the shot-cost benchmark.
pub fn seconds_per_ray<I: Intersector>(
    mesh: &Mesh,
    isect: &I,
    shooters: &[usize],
    rays_per_shot: usize,
    seed: u64,
) -> f64 {
    let ctx = Ctx {
        mesh,
        isect,
        seed,
        jitter: true,
        eps_floor: mesh
            .vertices
            .iter()
            .fold(0.0f32, |m, v| m.max(v.abs().max_element()))
            * 5e-7,
    };
    let t = Instant::now();
    let mut rays = 0;
    for (k, &i) in shooters.iter().enumerate() {
        let shot = Shot {
            patch: i,
            index: k as u64,
            phi: [0.0; 3],
            ch: Vec::new(),
            grid: PolarGrid::for_samples(rays_per_shot as f64),
        };
        for task in tasks_of(std::slice::from_ref(&shot)) {
            rays += ctx.cast(&shot, task.chunk, task.first, task.count).len();
        }
    }
    t.elapsed().as_secs_f64() / rays.max(1) as f64
}

/// Applies a wave's hits in task order: receivers gain ρ_j·ΔΦ_i/X, the rest is absorbed.
fn apply_rays(st: &mut State, wave: &[Shot], tasks: &[Task], hits: &[Vec<u32>]) {
    for (task, codes) in tasks.iter().zip(hits) {
        let shot = &wave[task.shot];
        let per_ray = 1.0 / shot.grid.len() as f64;
        let phi_ray = shot.phi.map(|p| p * per_ray);
        for &code in codes {
            if code == ESCAPED {
                st.escape(&phi_ray);
            } else if code & BACK != 0 {
                st.deposit_back(&phi_ray);
            } else {
                st.deposit(code as usize, &phi_ray);
                if !shot.ch.is_empty() {
                    st.deposit_channels(code as usize, &shot.ch, per_ray);
                }
            }
        }
        st.rays += codes.len() as u64;
    }
    st.finish_batch();
}

/// A chunk of one shot's rays: the unit of parallel work.
#[derive(Clone, Copy, Debug)]
struct Task {
    shot: usize,
    chunk: usize,
    first: usize,
    count: usize,
}

/// A wave cast but not yet applied.
struct Pending {
    wave: Vec<Shot>,
    tasks: Vec<Task>,
    hits: Vec<Vec<u32>>,
}

fn tasks_of(wave: &[Shot]) -> Vec<Task> {
    wave.iter()
        .enumerate()
        .flat_map(|(s, shot)| {
            let x = shot.grid.len();
            (0..x.div_ceil(CHUNK)).map(move |c| Task {
                shot: s,
                chunk: c,
                first: c * CHUNK,
                count: CHUNK.min(x - c * CHUNK),
            })
        })
        .collect()
}

/// Shoots until Sec. 3's criterion or a budget stops it, by the method `cfg.method` names
/// (any but gathering). `isect` is needed by the methods that cast rays (`adaptive-rays`,
/// `adaptive-hybrid`); the hemi-cube methods never cast a ray. `on_trace` is called with each
/// new trace point (for progress display).
///
/// Ray waves are pipelined: while one thread applies wave k's hits, the others cast wave
/// k + 1, which was taken off the heap before wave k's deposits reached it. Its shooters are
/// then at most one wave out of date; the energy books stay exact and the order stays fixed,
/// so the result is still the same on any thread count.
pub fn shoot<I: Intersector>(
    mesh: &Mesh,
    materials: &[Material],
    isect: Option<&I>,
    cfg: &SolveSettings,
    hooks: &RunHooks,
    mut on_trace: impl FnMut(&TracePoint),
) -> Result<Solution, SolveError> {
    let start = Instant::now();
    let n = mesh.patches.len();
    if n >= BACK as usize {
        return Err(SolveError::TooManyPatches(n));
    }
    let method = cfg.method;
    if method.casts_rays() && isect.is_none() {
        return Err(SolveError::NoIntersector(method.name()));
    }
    let mut st = State::new(mesh, materials, cfg.stop_fraction);
    if scalar(&st.energy.emitted) <= 0.0 {
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
    let c_ray = cfg
        .energy_per_ray
        .filter(|c| *c > 0.0)
        .unwrap_or_else(|| energy_per_ray(mesh, &rho, scalar(&st.energy.emitted), cfg.tolerance));
    drop(rho);
    let area: Vec<f64> = mesh.patches.iter().map(|p| p.area).collect();
    let emission: Vec<f64> = mesh
        .patches
        .iter()
        .map(|p| scalar(&materials[p.material as usize].emission()))
        .collect();
    let rho_s: Vec<f64> = mesh
        .patches
        .iter()
        .map(|p| scalar(&materials[p.material as usize].rho))
        .collect();
    let est = Estimator {
        area: &area,
        emission: &emission,
        rho: &rho_s,
        energy_per_ray: c_ray,
        rho_mean: rho_s.iter().zip(&area).map(|(r, a)| r * a).sum::<f64>() / mesh.total_area(),
    };
    let reference = hooks.reference.as_deref().map(Vec::as_slice);

    let (lo, hi) = mesh.vertices.iter().fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(l, h), v| (l.min(*v), h.max(*v)),
    );
    let reach = lo.abs().max(hi.abs()).max_element();
    let ctx = isect.map(|isect| Ctx {
        mesh,
        isect,
        seed: cfg.seed,
        jitter: cfg.jitter,
        eps_floor: reach * 5e-7,
    });
    let mut cubes = match method {
        MethodKind::Hemicube | MethodKind::HemicubeJittered => Some(CubeShooter::new(
            CubeKind::Uniform {
                n: cfg.hemicube_n,
                jitter: method == MethodKind::HemicubeJittered,
            },
            c_ray,
        )),
        MethodKind::AdaptiveHemicube | MethodKind::AdaptiveHybrid => {
            Some(CubeShooter::new(CubeKind::Adaptive, c_ray))
        }
        MethodKind::AdaptiveRays | MethodKind::Gathering => None,
    };
    let mut cube_cost = CubeCost::default();
    let mut cube_hits: Vec<CubeHits> = Vec::new();
    let mut ray_cost: Option<f64> = None;

    let mut stats = SolveStats {
        energy_per_ray: c_ray,
        ..SolveStats::default()
    };
    // Resuming: the books, the counters and the trace so far (see `checkpoint`).
    let mut time_offset = 0.0;
    if let Some(snap) = &hooks.resume {
        let h = &snap.header;
        if (h.energy_per_ray - c_ray).abs() > 1e-12 * c_ray {
            return Err(SolveError::Checkpoint(format!(
                "the checkpoint's energy per ray is {} W, this run's {c_ray} W: resume with the same --tolerance or --energy-per-ray",
                h.energy_per_ray
            )));
        }
        st.restore(snap).map_err(SolveError::Checkpoint)?;
        stats.shots = h.shots;
        stats.waves = h.waves;
        stats.hemicube_shots = h.hemicube_shots;
        stats.hemicube_cells = h.hemicube_cells;
        stats.switch = h.switch;
        stats.trace = h.trace.clone();
        if !h.cubes_active {
            cubes = None;
        }
        cube_cost = CubeCost::from_sums(h.cube_cost);
        ray_cost = h.ray_cost;
        time_offset = h.elapsed;
    }
    let mut pending: Option<Pending> = None;
    let mut next_trace = time_offset;
    let mut next_trace_shots = stats.shots;
    let mut last_sync: Option<u64> = None;
    let mut next_checkpoint = time_offset;
    let mut interrupt_now = false;
    let stop_reason = loop {
        let elapsed = time_offset + start.elapsed().as_secs_f64();
        // A safe point every SYNC_WAVES waves, whether or not anyone checkpoints (so runs
        // with and without checkpoints, and resumed runs, shoot the same): the wave in flight
        // lands, then a checkpoint is written if one is due or Ctrl-C was pressed.
        if stats.waves.is_multiple_of(SYNC_WAVES) && last_sync != Some(stats.waves) {
            last_sync = Some(stats.waves);
            if let Some(p) = pending.take() {
                apply_rays(&mut st, &p.wave, &p.tasks, &p.hits);
            }
            let interrupted = hooks
                .interrupt
                .as_ref()
                .is_some_and(|f| f.load(std::sync::atomic::Ordering::Relaxed));
            if let Some(sink) = &hooks.checkpoint {
                if interrupted || elapsed >= next_checkpoint {
                    let snap = st.snapshot(Header {
                        key: sink.key.clone(),
                        elapsed,
                        shots: stats.shots,
                        waves: stats.waves,
                        hemicube_shots: stats.hemicube_shots,
                        hemicube_cells: stats.hemicube_cells,
                        energy_per_ray: c_ray,
                        switch: stats.switch,
                        cubes_active: cubes.is_some(),
                        cube_cost: cube_cost.sums(),
                        ray_cost,
                        trace: stats.trace.clone(),
                        ..Header::default()
                    });
                    (sink.write)(&snap).map_err(SolveError::Checkpoint)?;
                    next_checkpoint = elapsed + sink.every.as_secs_f64();
                }
            }
            // Only here, at a safe point, so a resumed run repeats the same shots.
            interrupt_now = interrupted;
        }
        // Sec. 3's criterion, then the budgets.
        let max_b = st.max_unshot_b();
        let mean_b = st.mean_b();
        let in_flight = pending
            .as_ref()
            .map_or(0, |p| p.hits.iter().map(Vec::len).sum::<usize>())
            as u64;
        let samples = st.rays + st.cells + in_flight;
        let flying = pending
            .as_ref()
            .map_or(0.0, |p| p.wave.iter().map(|s| scalar(&s.phi)).sum::<f64>());
        // Sec. 3's criterion, on the light unshot radiosity will still add (see
        // `State::amplification`).
        let reason = if interrupt_now {
            Some(StopReason::Interrupted)
        } else if max_b * st.amplification(flying) < cfg.stop_fraction * mean_b {
            // The max-ΔB heap holds only patches above the threshold; whether any energy at
            // all is left, the flux heap says.
            if st.has_unshot() {
                Some(StopReason::Converged)
            } else {
                Some(StopReason::Exhausted)
            }
        } else if cfg.max_time.is_some_and(|t| elapsed >= t) {
            Some(StopReason::MaxTime)
        } else if cfg.max_rays.is_some_and(|r| samples >= r) {
            Some(StopReason::MaxRays)
        } else {
            None
        };
        if let Some(r) = reason {
            // Deposits still in flight may change the verdict: apply them and look again.
            if let Some(p) = pending.take() {
                apply_rays(&mut st, &p.wave, &p.tasks, &p.hits);
                continue;
            }
            st.record(
                &mut stats,
                elapsed,
                max_b,
                &est,
                reference,
                0.0,
                &mut on_trace,
            );
            break r;
        }
        // Trace points at geometric steps of time and of shots (even spacing on the log-log
        // plots of error against time).
        if elapsed >= next_trace || stats.shots >= next_trace_shots {
            st.record(
                &mut stats,
                elapsed,
                max_b,
                &est,
                reference,
                flying,
                &mut on_trace,
            );
            next_trace = (elapsed * 1.25).max(elapsed + 0.002);
            next_trace_shots = (stats.shots as f64 * 1.25) as u64 + 8;
        }

        if let Some(shooter) = cubes.as_mut() {
            // A wave of hemi-cube shots; for the hybrid, first ask whether the next shot is
            // cheaper by rays (Sec. 4: the cost of a hemi-cube shot hardly falls with its
            // energy, the cost of a ray shot falls in proportion).
            let mut wave: Vec<CubeShot> = Vec::new();
            let mut switch = None;
            while wave.len() < CUBE_WAVE {
                let Some((i, flux)) = st.peek_shooter() else {
                    break;
                };
                let cube = shooter.cube_for(flux);
                let forced = cfg.switch_at.is_some_and(|k| stats.shots >= k);
                let measured = cfg.switch_at.is_none() && cube_cost.samples() >= 2;
                if method == MethodKind::AdaptiveHybrid && (forced || measured) {
                    let ctx = ctx.as_ref().expect("checked above");
                    let per_ray = *ray_cost.get_or_insert_with(|| ctx.probe(i));
                    let rays = PolarGrid::for_samples(flux / c_ray).len();
                    let by_cube = cube_cost.predict(cube.cell_count());
                    let by_rays = rays as f64 * per_ray;
                    if forced || by_rays < by_cube {
                        switch = Some(SwitchInfo {
                            shot: stats.shots,
                            rays: rays as u64,
                            seconds_per_ray: per_ray,
                            hemicube_shot_seconds: by_cube,
                            ray_shot_seconds: by_rays,
                            hemicube_cells: cube.cell_count() as u64,
                            forced,
                        });
                        break;
                    }
                }
                let (patch, phi) = st.take_shooter().expect("peeked");
                let ch = st.take_channels(patch);
                wave.push(CubeShot {
                    patch,
                    index: stats.shots,
                    phi,
                    ch,
                    cube,
                });
                stats.shots += 1;
            }
            if !wave.is_empty() {
                shooter.cast(mesh, cfg.seed, &wave, &mut cube_hits);
                for (shot, h) in wave.iter().zip(&cube_hits) {
                    cube_cost.add(shot.cube.cell_count(), h.seconds);
                    cube_shots::apply(&mut st, shot, h);
                }
                st.finish_batch();
                stats.hemicube_shots += wave.len() as u64;
                stats.waves += 1;
            }
            if switch.is_some() {
                stats.switch = switch;
                cubes = None;
            }
            continue;
        }
        let ctx = ctx.as_ref().expect("checked above");

        // Take a wave of shooters off the top of the heap (Sec. 2: X = ΔΦ_i / C rays each).
        let mut wave: Vec<Shot> = Vec::new();
        let mut wave_rays = 0usize;
        let ray_cap = cfg
            .max_rays
            .map_or(usize::MAX, |r| r.saturating_sub(samples) as usize);
        while wave_rays < WAVE_RAYS.min(ray_cap.max(1)) {
            let Some((i, phi)) = st.take_shooter() else {
                break;
            };
            let ch = st.take_channels(i);
            let grid = PolarGrid::for_samples(scalar(&phi) / c_ray);
            wave_rays += grid.len();
            wave.push(Shot {
                patch: i,
                index: stats.shots,
                phi,
                ch,
                grid,
            });
            stats.shots += 1;
        }
        if wave.is_empty() {
            // Nothing to shoot until the wave in flight lands.
            if let Some(p) = pending.take() {
                apply_rays(&mut st, &p.wave, &p.tasks, &p.hits);
            }
            continue;
        }

        // Cast this wave in parallel while the previous one is applied.
        let tasks = tasks_of(&wave);
        let cast = || -> Vec<Vec<u32>> {
            tasks
                .par_iter()
                .map(|t| ctx.cast(&wave[t.shot], t.chunk, t.first, t.count))
                .collect()
        };
        let hits = match pending.take() {
            Some(p) => rayon::join(|| apply_rays(&mut st, &p.wave, &p.tasks, &p.hits), cast).1,
            None => cast(),
        };
        pending = Some(Pending { wave, tasks, hits });
        stats.waves += 1;
    };

    st.close_books();
    stats.rays = st.rays;
    stats.hemicube_cells = st.cells;
    stats.energy = st.energy;
    stats.stop_reason = Some(stop_reason);
    stats.seconds = time_offset + start.elapsed().as_secs_f64();
    let channels = match &hooks.light_groups {
        Some(g) => st
            .channel_radiosity(mesh, materials, &g.of_patch)
            .into_iter()
            .zip(&g.names)
            .map(|(b, name)| super::Channel {
                name: name.clone(),
                b,
            })
            .collect(),
        None => Vec::new(),
    };
    Ok(Solution {
        b: st.radiosity(mesh, materials),
        unshot: st.patches.iter().map(|p| p.unshot).collect(),
        stats,
        channels,
    })
}
