//! `radiosity bench rays`: the intersector's raw closest-hit throughput on random rays against
//! the solver's rays per second, measured side by side in one run (the bar: the solver keeps
//! at least 70 % of what Embree can do).

use crate::intersect::select::IntersectorKind;
use crate::intersect::{Intersector, Ray};
use crate::mesh::MeshOptions;
use crate::model::Model;
use crate::scene::{LoadOptions, SceneSource};
use crate::settings::Invalid;
use crate::solve::{self, SolveSettings};
use crate::Error;
use glam::Vec3;
use rand::{Rng, SeedableRng};
use rayon::prelude::*;
use std::time::Instant;

/// What `radiosity bench rays` measured.
#[derive(Clone, Debug, serde::Serialize)]
pub struct RayBench {
    pub scene: String,
    pub triangles: usize,
    pub patches: usize,
    pub threads: usize,
    /// The intersector measured and solved with (`--intersector`), and why.
    pub intersector: &'static str,
    pub intersector_reason: String,
    /// Closest-hit queries per second on random rays (origins uniform in the bounds,
    /// directions uniform on the sphere), all threads.
    pub raw_rays_per_second: f64,
    pub raw_rays: u64,
    /// The slowest and fastest of the raw measurements (one before each solve, one after the
    /// last): how much the machine's speed drifted during the run.
    pub raw_min_max: [f64; 2],
    /// Solves run (seeds seed, seed + 1, …) to fill the requested solve time.
    pub solves: usize,
    /// Rays per second of the solver's whole solve phases (sampling, casting, bookkeeping).
    pub solver_rays_per_second: f64,
    pub solver_rays: u64,
    /// solver / raw.
    pub ratio: f64,
}

impl RayBench {
    /// The figures as the few lines `radiosity bench rays` prints.
    pub fn text(&self) -> String {
        format!(
            "{}: {} triangles, {} patches, {} threads\n  raw {} closest hit: {:.2} Mrays/s ({} rays; {:.2} to {:.2} over the run)\n  solver:                 {:.2} Mrays/s ({} rays in {} solves)\n  solver / raw:           {:.0} %",
            self.scene,
            self.triangles,
            self.patches,
            self.threads,
            self.intersector,
            self.raw_rays_per_second / 1e6,
            self.raw_rays,
            self.raw_min_max[0] / 1e6,
            self.raw_min_max[1] / 1e6,
            self.solver_rays_per_second / 1e6,
            self.solver_rays,
            self.solves,
            100.0 * self.ratio
        )
    }
}

/// Random rays cast through `isect` in parallel; returns (rays, seconds).
pub fn raw_throughput<I: Intersector>(
    isect: &I,
    lo: Vec3,
    hi: Vec3,
    rays: u64,
    seed: u64,
) -> (u64, f64) {
    let chunks = rays.div_ceil(4096);
    let t = Instant::now();
    let hits: u64 = (0..chunks)
        .into_par_iter()
        .map(|c| {
            let mut rng =
                rand_pcg::Pcg64::seed_from_u64(seed ^ c.wrapping_mul(0x9E37_79B9_7F4A_7C15));
            let mut hits = 0u64;
            for _ in 0..4096 {
                let org = lo + (hi - lo) * Vec3::new(rng.gen(), rng.gen(), rng.gen());
                let z: f32 = rng.gen::<f32>() * 2.0 - 1.0;
                let phi: f32 = rng.gen::<f32>() * std::f32::consts::TAU;
                let r = (1.0 - z * z).max(0.0).sqrt();
                let dir = Vec3::new(r * phi.cos(), r * phi.sin(), z);
                let ray = Ray {
                    org,
                    dir,
                    tnear: 0.0,
                    tfar: f32::INFINITY,
                };
                hits += isect.intersect(&ray).is_some() as u64;
            }
            hits
        })
        .sum();
    std::hint::black_box(hits);
    (chunks * 4096, t.elapsed().as_secs_f64())
}

/// `radiosity bench rays --rays`: random rays of the raw measurement.
pub const DEFAULT_RAW_RAYS: u64 = 4_000_000;
/// `radiosity bench rays --min-seconds`: the solves' least total time.
pub const DEFAULT_MIN_SECONDS: f64 = 3.0;

/// Everything `radiosity bench rays` does.
#[derive(Clone, Debug)]
pub struct RaysJob {
    pub source: SceneSource,
    pub load: LoadOptions,
    pub mesh: MeshOptions,
    /// The solves' settings (the method is always adaptive rays: the solver's rays are
    /// measured).
    pub solve: SolveSettings,
    pub intersector: IntersectorKind,
    /// Random rays for the raw measurement (a quarter before each solve).
    pub raw_rays: u64,
    /// Solve again until the solves took this long in all (seconds).
    pub min_seconds: f64,
}

impl RaysJob {
    /// Refuses what `solve` refuses, and a negative or non-finite `--min-seconds`.
    pub fn check(&self) -> Result<(), Invalid> {
        self.mesh.check()?;
        self.solve.check()?;
        if !(self.min_seconds >= 0.0 && self.min_seconds.is_finite()) {
            return Invalid::err(format!(
                "--min-seconds must be a non-negative number, got {}",
                self.min_seconds
            ));
        }
        Ok(())
    }
}

/// `radiosity bench rays`: the intersector's raw throughput and the solver's, side by side in
/// one run.
pub fn bench_rays(job: &RaysJob) -> Result<RayBench, Error> {
    job.check()?;
    let (raw_rays, min_seconds) = (job.raw_rays, job.min_seconds);
    // The solver's rays are what is measured: the ray shooter, whatever --method says, and
    // only it — its rays over its time (the final gather and further passes would add their
    // seconds but not their rays to `stats`).
    let cfg = &SolveSettings {
        final_gather: false,
        error_target: None,
        ..job.solve.for_method(solve::MethodKind::AdaptiveRays)
    };
    let model = Model::load(&job.source, &job.load, &job.mesh)?;
    let (scene, m) = (&model.scene, &model.mesh);
    let (isect, chosen) = model.intersector(job.intersector)?;
    let (lo, hi) = scene.bounds();
    // Warm up (page in the BVH, spin up the threads). Then alternate raw measurements and
    // solves (seeds seed, seed + 1, …) until the solves add up to `min_seconds`, ending with
    // a raw one: a drift of the machine's speed (it is shared) then hits both sides alike.
    raw_throughput(&isect, lo, hi, raw_rays / 10 + 1, cfg.seed);
    let rounds_raw = (raw_rays / 4).max(4096);
    let mut raw_rates = Vec::new();
    let (mut n_raw, mut s_raw) = (0u64, 0.0f64);
    let (mut solver_rays, mut solver_s, mut solves) = (0u64, 0.0f64, 0usize);
    loop {
        let (n, s) = raw_throughput(&isect, lo, hi, rounds_raw, cfg.seed ^ solves as u64);
        raw_rates.push(n as f64 / s.max(1e-9));
        (n_raw, s_raw) = (n_raw + n, s_raw + s);
        if solves > 0 && (solver_s >= min_seconds || solves >= 100) {
            break;
        }
        let round = SolveSettings {
            seed: cfg.seed.wrapping_add(solves as u64),
            ..cfg.clone()
        };
        let sol = model.solve(Some(&isect), &round, &Default::default(), |_| {})?;
        solver_rays += sol.stats.rays;
        solver_s += sol.stats.seconds;
        solves += 1;
    }
    let raw = n_raw as f64 / s_raw.max(1e-9);
    let solver = solver_rays as f64 / solver_s.max(1e-9);
    let spread = |v: &[f64]| {
        [
            v.iter().copied().fold(f64::INFINITY, f64::min),
            v.iter().copied().fold(0.0, f64::max),
        ]
    };
    Ok(RayBench {
        scene: scene.name.clone(),
        triangles: m.triangles().count(),
        patches: m.patches.len(),
        threads: rayon::current_num_threads(),
        intersector: isect.name(),
        intersector_reason: chosen.reason,
        raw_rays_per_second: raw,
        raw_rays: n_raw,
        raw_min_max: spread(&raw_rates),
        solves,
        solver_rays_per_second: solver,
        solver_rays,
        ratio: solver / raw,
    })
}
