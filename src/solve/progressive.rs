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

use super::{scalar, EnergyBalance, Solution, SolveConfig, SolveStats, StopReason, TracePoint};
use crate::intersect::{Intersector, Ray};
use crate::mesh::Mesh;
use crate::sample::{polar::PolarGrid, Frame};
use crate::scene::Material;
use glam::Vec3;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use rayon::prelude::*;
use std::cmp::Ordering;
use std::collections::BinaryHeap;
use std::time::Instant;

/// Rays per wave of shots (see the module docs). Fixed, so results do not depend on threads.
pub const WAVE_RAYS: usize = 32_768;
/// Rays per parallel task.
const CHUNK: usize = 1024;
/// Hit codes: a patch id, a patch id with this bit for a back-face hit, or [`ESCAPED`].
const BACK: u32 = 1 << 31;
const ESCAPED: u32 = u32::MAX;

/// Errors a user can cause.
#[derive(Debug, thiserror::Error)]
pub enum SolveError {
    #[error("the scene has no light: no material emits (give one a Ke in the MTL file, or use --emit MATERIAL=R,G,B)")]
    NoEmitter,
    #[error("the scene has {0} patches; at most {max} are supported", max = BACK - 1)]
    TooManyPatches(usize),
}

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

/// A heap entry: a key and the patch it was computed for. Stale when the patch's current key
/// differs (the heap is updated lazily: new entries are pushed, old ones skipped when popped).
#[derive(Clone, Copy, PartialEq)]
struct Entry(f64, u32);
impl Eq for Entry {}
impl PartialOrd for Entry {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Entry {
    fn cmp(&self, o: &Self) -> Ordering {
        self.0.total_cmp(&o.0).then(o.1.cmp(&self.1))
    }
}

/// Max-heap of patches by a key, with lazy deletion.
struct LazyHeap {
    heap: BinaryHeap<Entry>,
}

impl LazyHeap {
    fn push(&mut self, key: f64, i: usize) {
        if key > 0.0 {
            self.heap.push(Entry(key, i as u32));
        }
    }
    /// The top entry still current under `key_of`, dropping stale ones.
    fn peek(&mut self, key_of: impl Fn(usize) -> f64) -> Option<Entry> {
        while let Some(&top) = self.heap.peek() {
            if key_of(top.1 as usize) == top.0 {
                return Some(top);
            }
            self.heap.pop();
        }
        None
    }
    /// Rebuilds from scratch when stale entries pile up (keeps memory O(patches)).
    fn compact(&mut self, n: usize, key_of: impl Fn(usize) -> f64) {
        if self.heap.len() > 4 * n + 1024 {
            self.heap = (0..n)
                .map(|i| Entry(key_of(i), i as u32))
                .filter(|e| e.0 > 0.0)
                .collect();
        }
    }
}

/// One shooter of a wave.
struct Shot {
    patch: usize,
    /// Global shot number (seeds its random numbers).
    index: u64,
    /// The flux it shoots, RGB.
    phi: [f64; 3],
    grid: PolarGrid,
}

/// a += b, per channel.
#[inline]
fn add3(a: &mut [f64; 3], b: &[f64; 3]) {
    for (x, y) in a.iter_mut().zip(b) {
        *x += y;
    }
}

/// splitmix64: decorrelates (seed, shot, chunk) into independent RNG seeds.
fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

fn rng_for(seed: u64, shot: u64, chunk: u64) -> Pcg64Mcg {
    Pcg64Mcg::seed_from_u64(mix(mix(mix(seed) ^ shot) ^ chunk))
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
}

/// Per-patch solver state, packed into one cache line so applying a hit costs one miss.
/// Energies are f64; ρ and 1/A are stored as f32 (exact enough for a reflectance, and the
/// energy books stay exact because what is absorbed is computed as Φ − ρΦ in f64).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct PatchState {
    /// Unshot flux ΔΦ_j (W).
    unshot: [f64; 3],
    /// Flux received and kept (ρ_j × what arrived), W: B_j = E_j + gathered/A_j.
    gathered: [f64; 3],
    rho: [f32; 3],
    inv_area: f32,
}

/// The solver's mutable state: patches, heaps and energy accounts.
struct State {
    patches: Vec<PatchState>,
    by_flux: LazyHeap,
    by_b: LazyHeap,
    energy: EnergyBalance,
    /// Σ B_j·A_j, for the mean radiosity.
    b_flux: [f64; 3],
    touched: Vec<bool>,
    touched_list: Vec<u32>,
    rays: u64,
    stop_fraction: f64,
    total_area: f64,
}

impl State {
    #[inline]
    fn key_flux(&self, i: usize) -> f64 {
        scalar(&self.patches[i].unshot)
    }
    #[inline]
    fn key_b(&self, i: usize) -> f64 {
        scalar(&self.patches[i].unshot) * self.patches[i].inv_area as f64
    }

    /// Max unshot radiosity (scalar) over all patches, from the heap.
    fn max_unshot_b(&mut self) -> f64 {
        let patches = &self.patches;
        self.by_b
            .peek(|i| scalar(&patches[i].unshot) * patches[i].inv_area as f64)
            .map_or(0.0, |e| e.0)
    }

    /// Is any unshot energy left?
    fn has_unshot(&mut self) -> bool {
        let patches = &self.patches;
        self.by_flux.peek(|i| scalar(&patches[i].unshot)).is_some()
    }

    /// Takes the patch with the most unshot flux off the heap, if any.
    fn pop_shooter(&mut self) -> Option<(usize, f64)> {
        let patches = &self.patches;
        let top = self.by_flux.peek(|i| scalar(&patches[i].unshot))?;
        self.by_flux.heap.pop();
        Some((top.1 as usize, top.0))
    }

    /// Applies a wave's hits in task order: receivers gain ρ_j·ΔΦ_i/X, the rest is absorbed.
    fn apply(&mut self, wave: &[Shot], tasks: &[Task], hits: &[Vec<u32>]) {
        for (task, codes) in tasks.iter().zip(hits) {
            let shot = &wave[task.shot];
            let phi_ray = shot.phi.map(|p| p / shot.grid.len() as f64);
            for &code in codes {
                if code == ESCAPED {
                    add3(&mut self.energy.escaped, &phi_ray);
                } else if code & BACK != 0 {
                    add3(&mut self.energy.absorbed_back, &phi_ray);
                } else {
                    let j = code as usize;
                    let p = &mut self.patches[j];
                    for (c, &phi) in phi_ray.iter().enumerate() {
                        let kept = p.rho[c] as f64 * phi;
                        p.unshot[c] += kept;
                        p.gathered[c] += kept;
                        self.b_flux[c] += kept;
                        self.energy.absorbed[c] += phi - kept;
                    }
                    if !self.touched[j] {
                        self.touched[j] = true;
                        self.touched_list.push(code);
                    }
                }
            }
            self.rays += codes.len() as u64;
        }
        // New heap entries for every patch whose unshot energy grew. The max-ΔB heap only
        // needs patches that could block convergence: the threshold f·mean(B) never falls
        // (B only grows), so a patch below it now matters again only once it grows, and then
        // it is pushed again.
        let threshold = self.stop_fraction * scalar(&self.b_flux) / self.total_area;
        let list = std::mem::take(&mut self.touched_list);
        for &j in &list {
            let j = j as usize;
            self.touched[j] = false;
            let (kf, kb) = (self.key_flux(j), self.key_b(j));
            self.by_flux.push(kf, j);
            if kb >= threshold {
                self.by_b.push(kb, j);
            }
        }
        self.touched_list = list;
        self.touched_list.clear();
        let n = self.patches.len();
        let patches = &self.patches;
        self.by_flux.compact(n, |i| scalar(&patches[i].unshot));
        self.by_b.compact(n, |i| {
            scalar(&patches[i].unshot) * patches[i].inv_area as f64
        });
    }
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

/// Solves by progressive refinement. `on_wave` is called with each new trace point (for
/// progress display).
///
/// Waves are pipelined: while one thread applies wave k's hits, the others cast wave k + 1,
/// which was taken off the heap before wave k's deposits reached it. Its shooters are then
/// at most one wave out of date; the energy books stay exact and the order stays fixed, so the
/// result is still the same on any thread count.
pub fn solve<I: Intersector>(
    mesh: &Mesh,
    materials: &[Material],
    isect: &I,
    cfg: &SolveConfig,
    mut on_wave: impl FnMut(&TracePoint),
) -> Result<Solution, SolveError> {
    let start = Instant::now();
    let n = mesh.patches.len();
    if n >= BACK as usize {
        return Err(SolveError::TooManyPatches(n));
    }
    let patches: Vec<PatchState> = mesh
        .patches
        .iter()
        .map(|p| {
            let m = &materials[p.material as usize];
            let e = m.emission();
            PatchState {
                unshot: e.map(|x| x * p.area),
                gathered: [0.0; 3],
                rho: m.rho.map(|r| r as f32),
                inv_area: (1.0 / p.area) as f32,
            }
        })
        .collect();
    let mut st = State {
        patches,
        by_flux: LazyHeap {
            heap: BinaryHeap::new(),
        },
        by_b: LazyHeap {
            heap: BinaryHeap::new(),
        },
        energy: EnergyBalance::default(),
        b_flux: [0.0; 3],
        touched: vec![false; n],
        touched_list: Vec::new(),
        rays: 0,
        stop_fraction: cfg.stop_fraction,
        total_area: mesh.total_area(),
    };
    for i in 0..n {
        let p = st.patches[i];
        add3(&mut st.energy.emitted, &p.unshot);
        add3(&mut st.b_flux, &p.unshot);
        let (kf, kb) = (st.key_flux(i), st.key_b(i));
        st.by_flux.push(kf, i);
        st.by_b.push(kb, i);
    }
    if scalar(&st.energy.emitted) <= 0.0 {
        return Err(SolveError::NoEmitter);
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
    let total_area = mesh.total_area();

    let (lo, hi) = mesh.vertices.iter().fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(l, h), v| (l.min(*v), h.max(*v)),
    );
    let reach = lo.abs().max(hi.abs()).max_element();
    let ctx = Ctx {
        mesh,
        isect,
        seed: cfg.seed,
        jitter: cfg.jitter,
        eps_floor: reach * 5e-7,
    };

    let mut stats = SolveStats {
        energy_per_ray: c_ray,
        ..SolveStats::default()
    };
    let mut pending: Option<Pending> = None;
    let mut next_trace = 0.0f64;
    let stop_reason = loop {
        // Sec. 3's criterion, then the budgets.
        let max_b = st.max_unshot_b();
        let mean_b = scalar(&st.b_flux) / total_area;
        let elapsed = start.elapsed().as_secs_f64();
        let in_flight = pending
            .as_ref()
            .map_or(0, |p| p.hits.iter().map(Vec::len).sum::<usize>());
        let reason = if max_b < cfg.stop_fraction * mean_b {
            // The max-ΔB heap holds only patches above the threshold; whether any energy at
            // all is left, the flux heap says.
            if st.has_unshot() {
                Some(StopReason::Converged)
            } else {
                Some(StopReason::Exhausted)
            }
        } else if cfg.max_time.is_some_and(|t| elapsed >= t.as_secs_f64()) {
            Some(StopReason::MaxTime)
        } else if cfg
            .max_rays
            .is_some_and(|r| st.rays + in_flight as u64 >= r)
        {
            Some(StopReason::MaxRays)
        } else {
            None
        };
        if let Some(r) = reason {
            // Deposits still in flight may change the verdict: apply them and look again.
            if let Some(p) = pending.take() {
                st.apply(&p.wave, &p.tasks, &p.hits);
                continue;
            }
            record(&mut stats, &st, elapsed, max_b, mean_b, &mut on_wave);
            break r;
        }
        if elapsed >= next_trace {
            record(&mut stats, &st, elapsed, max_b, mean_b, &mut on_wave);
            next_trace = (elapsed * 1.25).max(elapsed + 0.002);
        }

        // Take a wave of shooters off the top of the heap (Sec. 2: X = ΔΦ_i / C rays each).
        let mut wave: Vec<Shot> = Vec::new();
        let mut wave_rays = 0usize;
        let ray_cap = cfg.max_rays.map_or(usize::MAX, |r| {
            r.saturating_sub(st.rays + in_flight as u64) as usize
        });
        while wave_rays < WAVE_RAYS.min(ray_cap.max(1)) {
            let Some((i, key)) = st.pop_shooter() else {
                break;
            };
            let grid = PolarGrid::for_samples(key / c_ray);
            wave_rays += grid.len();
            wave.push(Shot {
                patch: i,
                index: stats.shots,
                phi: st.patches[i].unshot,
                grid,
            });
            st.patches[i].unshot = [0.0; 3];
            stats.shots += 1;
        }
        if wave.is_empty() {
            // Nothing to shoot until the wave in flight lands.
            if let Some(p) = pending.take() {
                st.apply(&p.wave, &p.tasks, &p.hits);
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
            Some(p) => rayon::join(|| st.apply(&p.wave, &p.tasks, &p.hits), cast).1,
            None => cast(),
        };
        pending = Some(Pending { wave, tasks, hits });
        stats.waves += 1;
    };

    for p in &st.patches {
        add3(&mut st.energy.unshot, &p.unshot);
    }
    stats.rays = st.rays;
    stats.energy = st.energy;
    stats.stop_reason = Some(stop_reason);
    stats.seconds = start.elapsed().as_secs_f64();
    Ok(Solution {
        b: st
            .patches
            .iter()
            .zip(&mesh.patches)
            .map(|(s, p)| {
                let e = materials[p.material as usize].emission();
                [0, 1, 2].map(|c| e[c] + s.gathered[c] / p.area)
            })
            .collect(),
        unshot: st.patches.iter().map(|p| p.unshot).collect(),
        stats,
    })
}

/// Adds a trace point (and tells the caller).
fn record(
    stats: &mut SolveStats,
    st: &State,
    elapsed: f64,
    max_b: f64,
    mean_b: f64,
    on_wave: &mut impl FnMut(&TracePoint),
) {
    // The heap knows the max only above the stop threshold; a trace point is rare enough to
    // scan for the exact value.
    let exact_max = st
        .patches
        .iter()
        .map(|p| scalar(&p.unshot) * p.inv_area as f64)
        .fold(max_b, f64::max);
    let p = TracePoint {
        time_s: elapsed,
        shots: stats.shots,
        rays: st.rays,
        max_unshot_b: exact_max,
        mean_b,
        unshot_flux: st.patches.iter().map(|p| scalar(&p.unshot)).sum(),
    };
    stats.trace.push(p);
    on_wave(&p);
}
