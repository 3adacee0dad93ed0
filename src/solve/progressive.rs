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
use rand_pcg::Pcg64;
use rayon::prelude::*;
use std::cmp::Ordering;
use std::collections::BinaryHeap;
use std::time::Instant;

/// Rays per wave of shots (see the module docs). Fixed, so results do not depend on threads.
pub const WAVE_RAYS: usize = 16_384;
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

fn rng_for(seed: u64, shot: u64, chunk: u64) -> Pcg64 {
    Pcg64::seed_from_u64(mix(mix(mix(seed) ^ shot) ^ chunk))
}

/// A point uniform over the area of convex patch `i` (fan triangles chosen by area).
fn point_on_patch<R: Rng>(mesh: &Mesh, i: usize, rng: &mut R) -> Vec3 {
    let ids = mesh.patch_indices(i);
    let v = |k: usize| mesh.vertices[ids[k] as usize];
    let a = v(0);
    let mut k = 1;
    if ids.len() > 3 {
        let areas: Vec<f32> = (1..ids.len() - 1)
            .map(|k| (v(k) - a).cross(v(k + 1) - a).length())
            .collect();
        let total: f32 = areas.iter().sum();
        let mut u = rng.gen::<f32>() * total;
        for (q, &ar) in areas.iter().enumerate() {
            k = q + 1;
            if u < ar {
                break;
            }
            u -= ar;
        }
    }
    let (b, c) = (v(k), v(k + 1));
    let (r1, r2) = (rng.gen::<f32>().sqrt(), rng.gen::<f32>());
    a * (1.0 - r1) + b * (r1 * (1.0 - r2)) + c * (r1 * r2)
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
        let mut out = Vec::with_capacity(count);
        for k in first..first + count {
            let dir = frame.to_world(shot.grid.direction(k, 0.0, self.jitter, &mut rng));
            let org = point_on_patch(self.mesh, i, &mut rng) + patch.normal * eps;
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
                Some(h) => {
                    let n = self.mesh.patches[h.patch as usize].normal;
                    return if n.dot(dir) > 0.0 {
                        h.patch | BACK
                    } else {
                        h.patch
                    };
                }
            }
        }
        ESCAPED
    }
}

/// Solves by progressive refinement. `on_wave` is called after every wave with the latest
/// trace point (for progress display).
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
    let rho: Vec<[f64; 3]> = mesh
        .patches
        .iter()
        .map(|p| materials[p.material as usize].rho)
        .collect();
    let area: Vec<f64> = mesh.patches.iter().map(|p| p.area).collect();
    let mut b: Vec<[f64; 3]> = mesh
        .patches
        .iter()
        .map(|p| materials[p.material as usize].emission())
        .collect();
    let mut unshot: Vec<[f64; 3]> = b.iter().zip(&area).map(|(e, a)| e.map(|x| x * a)).collect();
    let mut energy = EnergyBalance::default();
    for u in &unshot {
        add3(&mut energy.emitted, u);
    }
    if scalar(&energy.emitted) <= 0.0 {
        return Err(SolveError::NoEmitter);
    }
    let c_ray = cfg
        .energy_per_ray
        .filter(|c| *c > 0.0)
        .unwrap_or_else(|| energy_per_ray(mesh, &rho, scalar(&energy.emitted), cfg.tolerance));
    let total_area: f64 = area.iter().sum();
    let mut b_flux = [0.0f64; 3]; // Σ B_i A_i, for the mean radiosity
    for (bi, a) in b.iter().zip(&area) {
        for c in 0..3 {
            b_flux[c] += bi[c] * a;
        }
    }

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

    let key_flux = |u: &[[f64; 3]], i: usize| scalar(&u[i]);
    let key_b = |u: &[[f64; 3]], i: usize| scalar(&u[i]) / area[i];
    let mut by_flux = LazyHeap {
        heap: BinaryHeap::new(),
    };
    let mut by_b = LazyHeap {
        heap: BinaryHeap::new(),
    };
    for i in 0..n {
        by_flux.push(key_flux(&unshot, i), i);
        by_b.push(key_b(&unshot, i), i);
    }

    let mut stats = SolveStats {
        energy_per_ray: c_ray,
        ..SolveStats::default()
    };
    let mut touched = vec![false; n];
    let mut touched_list: Vec<usize> = Vec::new();
    let mut next_trace = 0.0f64;
    let stop_reason;
    loop {
        // Sec. 3's criterion, then the budgets.
        let max_b = by_b.peek(|i| key_b(&unshot, i)).map_or(0.0, |e| e.0);
        let mean_b = scalar(&b_flux) / total_area;
        let elapsed = start.elapsed().as_secs_f64();
        let point = TracePoint {
            time_s: elapsed,
            shots: stats.shots,
            rays: stats.rays,
            max_unshot_b: max_b,
            mean_b,
            unshot_flux: 0.0,
        };
        let reason = if max_b <= 0.0 {
            Some(StopReason::Exhausted)
        } else if max_b < cfg.stop_fraction * mean_b {
            Some(StopReason::Converged)
        } else if cfg.max_time.is_some_and(|t| elapsed >= t.as_secs_f64()) {
            Some(StopReason::MaxTime)
        } else if cfg.max_rays.is_some_and(|r| stats.rays >= r) {
            Some(StopReason::MaxRays)
        } else {
            None
        };
        if reason.is_some() || elapsed >= next_trace {
            let mut p = point;
            p.unshot_flux = unshot.iter().map(scalar).sum();
            stats.trace.push(p);
            next_trace = (elapsed * 1.25).max(elapsed + 0.002);
            on_wave(&p);
        }
        if let Some(r) = reason {
            stop_reason = r;
            break;
        }

        // Take a wave of shooters off the top of the heap.
        let mut wave: Vec<Shot> = Vec::new();
        let mut wave_rays = 0usize;
        let ray_cap = cfg
            .max_rays
            .map_or(usize::MAX, |r| r.saturating_sub(stats.rays) as usize);
        while wave_rays < WAVE_RAYS.min(ray_cap.max(1)) {
            let Some(top) = by_flux.peek(|i| key_flux(&unshot, i)) else {
                break;
            };
            by_flux.heap.pop();
            let i = top.1 as usize;
            let grid = PolarGrid::for_samples(top.0 / c_ray);
            wave_rays += grid.len();
            wave.push(Shot {
                patch: i,
                index: stats.shots,
                phi: unshot[i],
                grid,
            });
            unshot[i] = [0.0; 3];
            stats.shots += 1;
        }
        if wave.is_empty() {
            continue; // the heap peek above will report Exhausted
        }

        // Cast in parallel, in fixed chunks.
        let tasks: Vec<(usize, usize, usize, usize)> = wave
            .iter()
            .enumerate()
            .flat_map(|(s, shot)| {
                let x = shot.grid.len();
                (0..x.div_ceil(CHUNK)).map(move |c| (s, c, c * CHUNK, CHUNK.min(x - c * CHUNK)))
            })
            .collect();
        let hits: Vec<Vec<u32>> = tasks
            .par_iter()
            .map(|&(s, c, first, count)| ctx.cast(&wave[s], c, first, count))
            .collect();

        // Apply in task order: receivers gain ρ_j·ΔΦ_i/X.
        for (&(s, ..), codes) in tasks.iter().zip(&hits) {
            let shot = &wave[s];
            let phi_ray = shot.phi.map(|p| p / shot.grid.len() as f64);
            for &code in codes {
                if code == ESCAPED {
                    add3(&mut energy.escaped, &phi_ray);
                } else if code & BACK != 0 {
                    add3(&mut energy.absorbed_back, &phi_ray);
                } else {
                    let j = code as usize;
                    for c in 0..3 {
                        let kept = rho[j][c] * phi_ray[c];
                        unshot[j][c] += kept;
                        b[j][c] += kept / area[j];
                        b_flux[c] += kept;
                        energy.absorbed[c] += phi_ray[c] - kept;
                    }
                    if !touched[j] {
                        touched[j] = true;
                        touched_list.push(j);
                    }
                }
            }
            stats.rays += codes.len() as u64;
        }
        for &j in &touched_list {
            touched[j] = false;
            by_flux.push(key_flux(&unshot, j), j);
            by_b.push(key_b(&unshot, j), j);
        }
        touched_list.clear();
        by_flux.compact(n, |i| key_flux(&unshot, i));
        by_b.compact(n, |i| key_b(&unshot, i));
        stats.waves += 1;
    }

    for u in &unshot {
        add3(&mut energy.unshot, u);
    }
    stats.energy = energy;
    stats.stop_reason = Some(stop_reason);
    stats.seconds = start.elapsed().as_secs_f64();
    Ok(Solution { b, unshot, stats })
}
