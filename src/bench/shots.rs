//! `radiosity bench shots`: the paper's cost per shot (Sec. 2 and 4), measured side by side in
//! one run on one scene, and the constants of the hybrid's switch (`solve::switch`) measured.
//!
//! - The uniform N×N hemi-cube against the non-uniform one with the same largest ΔF (the odd
//!   resolution whose central cell is closest to the uniform cube's): the non-uniform cube has
//!   about π/12 of the cells; the paper found the saving pays off above about 50×50, where
//!   scan conversion starts to outweigh transforming every patch.
//! - A ray shot's cost per ray, cast exactly as the solver casts them.
//! - The cost model's constants: hemi-cube shots of several resolutions (the uniform and
//!   non-uniform cubes above, and the small non-uniform cubes the hybrid shoots before it
//!   switches) and ray shots of several sizes, each timed on its own with its work counted;
//!   the constants fitted to them by least squares with non-negative coefficients, printed
//!   beside the kept ones.
//! - The shot at which `adaptive-hybrid` switches in a real solve: counted with the kept
//!   constants (the default), counted with the fitted ones, and measured.
//!
//! Shots come from the same patches for every sampler (spread evenly over the patch list),
//! one at a time on one thread: thread time per shot, the unit the hybrid's switch compares.

use crate::intersect::embree::EmbreeScene;
use crate::mesh::{Mesh, MeshOptions};
use crate::model::Model;
use crate::sample::hemicube::{Hemicube, HemicubeBuffer, ShotWork};
use crate::sample::Frame;
use crate::scene::{LoadOptions, Scene, SceneSource};
use crate::settings::Invalid;
use crate::solve::ray_shots::time_ray_shots;
use crate::solve::switch::{self, CostModel, CubeWork};
use crate::solve::{self, MethodKind, RunHooks, SolveSettings, SwitchBy, SwitchInfo};
use crate::Error;
use serde::Serialize;
use std::time::Instant;

/// Non-uniform resolutions timed for the cost model besides the rows' cubes: the small cubes
/// the hybrid shoots before it switches.
const MODEL_NS: [usize; 4] = [5, 11, 21, 41];
/// Ray shot sizes timed for the cost model.
const MODEL_RAYS: [usize; 3] = [256, 1024, 4096];

/// One resolution: the uniform cube and its non-uniform twin.
#[derive(Clone, Debug, Serialize)]
pub struct CubeRow {
    pub uniform_n: usize,
    pub uniform_cells: usize,
    pub uniform_max_ff: f64,
    /// Thread time per shot (ms).
    pub uniform_ms: f64,
    pub non_uniform_n: usize,
    pub non_uniform_cells: usize,
    pub non_uniform_max_ff: f64,
    pub non_uniform_ms: f64,
    /// Non-uniform cells / uniform cells (the paper: π/12 ≈ 0.26).
    pub cell_ratio: f64,
    /// Non-uniform time / uniform time (< 1: the non-uniform cube is cheaper).
    pub time_ratio: f64,
    /// Rays a ray shot could cast for the time of one uniform hemi-cube shot.
    pub rays_per_uniform_shot: f64,
}

/// One timed hemi-cube shot of the cost model's fit.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct CubeSample {
    pub n: usize,
    pub uniform: bool,
    pub patches: u64,
    pub faces: u64,
    pub cells: u64,
    pub tested: u64,
    pub seconds: f64,
}

/// One timed ray shot of the cost model's fit.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct RaySample {
    pub rays: u64,
    /// Patches in the scene (the model's per-ray cost grows with their log₂).
    pub patches: usize,
    pub seconds: f64,
}

/// A hybrid solve's switch.
#[derive(Clone, Debug, Serialize)]
pub struct HybridRun {
    /// `counted, kept constants`, `counted, fitted constants` or `measured`.
    pub rule: String,
    pub shots: u64,
    pub hemicube_shots: u64,
    pub switch: Option<SwitchInfo>,
    pub seconds: f64,
}

/// What `radiosity bench shots` measured.
#[derive(Clone, Debug, Serialize)]
pub struct ShotBench {
    pub scene: String,
    pub patches: usize,
    /// Shooters each sampler shot from.
    pub shooters: usize,
    pub rows: Vec<CubeRow>,
    /// Thread time per ray of ray shots (µs).
    pub ray_us_per_ray: f64,
    /// The default hybrid's solve (counted, kept constants): shots in all, shots by
    /// hemi-cube, and its switch.
    pub hybrid_shots: u64,
    pub hybrid_hemicube_shots: u64,
    pub hybrid_switch: Option<SwitchInfo>,
    pub hybrid_seconds: f64,
    /// The cost model: the constants the code keeps, those fitted here, and the mean relative
    /// error of each over the timed shots (hemi-cube, ray).
    pub kept: CostModel,
    pub fitted: CostModel,
    pub kept_error: [f64; 2],
    pub fitted_error: [f64; 2],
    pub cube_samples: Vec<CubeSample>,
    pub ray_samples: Vec<RaySample>,
    /// The hybrid solved under each rule.
    pub hybrids: Vec<HybridRun>,
}

impl ShotBench {
    /// The figures as Markdown tables with the ray and hybrid lines under them.
    pub fn markdown(&self) -> String {
        let mut s = format!(
            "{}: {} patches, {} shooters, thread time per shot\n\n\
             | uniform N | cells | ms/shot | non-uniform N | cells | ms/shot | cells ratio | time ratio | rays per uniform shot |\n\
             |---|---|---|---|---|---|---|---|---|\n",
            self.scene, self.patches, self.shooters
        );
        for r in &self.rows {
            s += &format!(
                "| {} | {} | {:.3} | {} | {} | {:.3} | {:.3} | {:.2} | {:.0} |\n",
                r.uniform_n,
                r.uniform_cells,
                r.uniform_ms,
                r.non_uniform_n,
                r.non_uniform_cells,
                r.non_uniform_ms,
                r.cell_ratio,
                r.time_ratio,
                r.rays_per_uniform_shot
            );
        }
        s += &format!("\nray shots: {:.3} µs per ray\n", self.ray_us_per_ray);
        s += &format!(
            "\ncost model (solve::switch; thread seconds, least squares with non-negative \
             coefficients on the relative error, over {} hemi-cube and {} ray shots, each the \
             fastest of {ROUNDS}):\n\n\
             | constant | kept | fitted |\n|---|---|---|\n",
            self.cube_samples.len(),
            self.ray_samples.len()
        );
        let (k, f) = (&self.kept, &self.fitted);
        for (name, a, b) in [
            ("PATCH_SECONDS (per patch transformed)", k.patch, f.patch),
            ("FACE_SECONDS (per patch-face clipped)", k.face, f.face),
            ("CELL_SECONDS (per cell)", k.cell, f.cell),
            ("TESTED_SECONDS (per cell depth-tested)", k.tested, f.tested),
            ("RAY_LOG2_SECONDS (per ray and log2 patches)", k.ray, f.ray),
        ] {
            s += &format!("| {name} | {a:.3e} | {b:.3e} |\n");
        }
        s += &format!(
            "| mean relative error, hemi-cube / ray shots | {:.1} % / {:.1} % | {:.1} % / {:.1} % |\n\n",
            100.0 * self.kept_error[0],
            100.0 * self.kept_error[1],
            100.0 * self.fitted_error[0],
            100.0 * self.fitted_error[1]
        );
        for h in &self.hybrids {
            s += &format!("adaptive-hybrid, {}: ", h.rule);
            s += &match &h.switch {
                Some(sw) => format!(
                    "switched to rays at shot {} of {} (hemi-cube shot {:.3} ms predicted, {} rays {:.3} ms), solve {:.2} s\n",
                    sw.shot,
                    h.shots,
                    1e3 * sw.hemicube_shot_seconds,
                    sw.rays,
                    1e3 * sw.ray_shot_seconds,
                    h.seconds
                ),
                None => format!(
                    "never switched ({} shots, all by hemi-cube), solve {:.2} s\n",
                    h.shots, h.seconds
                ),
            };
        }
        s
    }
}

/// Rounds every timed shot is repeated, keeping its fastest: a shot preempted by another
/// process (the machine is shared) would otherwise weigh on the fit.
const ROUNDS: usize = 3;

/// Times one hemi-cube shot from each of `from` (after a warm-up shot that sizes the
/// buffers), the fastest of [`ROUNDS`] rounds: (work, seconds) per shot.
fn time_cube(m: &Mesh, cube: &Hemicube, from: &[usize]) -> Vec<(ShotWork, f64)> {
    let mut buf = HemicubeBuffer::default();
    let mut out = Vec::new();
    let mut shoot = |i: usize| {
        let p = &m.patches[i];
        let frame = Frame::new(p.normal, 0.7 * i as f32);
        cube.shoot::<rand_pcg::Pcg64Mcg>(m, i, p.centre, &frame, None, &mut buf, &mut out)
    };
    shoot(from[0]);
    let mut best = vec![(ShotWork::default(), f64::INFINITY); from.len()];
    for _ in 0..ROUNDS {
        for (b, &i) in best.iter_mut().zip(from) {
            let t = Instant::now();
            let w = shoot(i);
            let secs = t.elapsed().as_secs_f64();
            if secs < b.1 {
                *b = (w, secs);
            }
        }
    }
    best
}

/// Times a ray shot of each size in `sizes` from each of `from`, the fastest of [`ROUNDS`].
fn time_rays(
    m: &Mesh,
    isect: &EmbreeScene,
    from: &[usize],
    sizes: &[usize],
    seed: u64,
) -> Vec<RaySample> {
    let mut out = Vec::new();
    for &x in sizes {
        for &i in from {
            let mut best = RaySample {
                rays: 0,
                patches: m.patches.len(),
                seconds: f64::INFINITY,
            };
            for _ in 0..ROUNDS {
                let (seconds, rays) = time_ray_shots(m, isect, &[i], x, seed);
                if seconds < best.seconds {
                    best = RaySample {
                        rays,
                        seconds,
                        ..best
                    };
                }
            }
            out.push(best);
        }
    }
    out
}

fn mean_seconds(shots: &[(ShotWork, f64)]) -> f64 {
    shots.iter().map(|s| s.1).sum::<f64>() / shots.len().max(1) as f64
}

/// Mean |predicted − measured| / measured of `model` over the timed shots (hemi-cube, ray).
fn model_error(model: &CostModel, cubes: &[CubeSample], rays: &[RaySample]) -> [f64; 2] {
    let rel = |p: f64, t: f64| (p - t).abs() / t.max(1e-12);
    let cube: f64 = cubes
        .iter()
        .map(|c| {
            let w = CubeWork {
                patches: c.patches as f64,
                faces: c.faces as f64,
                cells: c.cells as f64,
                tested: c.tested as f64,
            };
            rel(model.cube_seconds(&w), c.seconds)
        })
        .sum();
    let ray: f64 = rays
        .iter()
        .map(|r| rel(model.ray_seconds(r.rays, r.patches), r.seconds))
        .sum();
    [
        cube / cubes.len().max(1) as f64,
        ray / rays.len().max(1) as f64,
    ]
}

/// Times the uniform cubes of resolutions `ns` and their non-uniform twins (the table's rows),
/// and the small non-uniform cubes of [`MODEL_NS`], from `from`; every timed shot is also a
/// sample of the cost model's fit.
fn time_cubes(
    m: &Mesh,
    ns: &[usize],
    from: &[usize],
    per_ray: f64,
) -> (Vec<CubeRow>, Vec<CubeSample>) {
    let mut rows = Vec::new();
    let mut cube_samples = Vec::new();
    let mut add_samples = |cube: &Hemicube, shots: &[(ShotWork, f64)]| {
        cube_samples.extend(shots.iter().map(|(w, t)| CubeSample {
            n: cube.resolution(),
            uniform: cube.is_uniform(),
            patches: w.patches,
            faces: w.faces,
            cells: w.cells,
            tested: w.tested,
            seconds: *t,
        }))
    };
    for &un in ns {
        let uniform = Hemicube::uniform(un);
        // The odd resolution whose largest ΔF is closest to the uniform cube's.
        let twin = [un.saturating_sub(1).max(3) | 1, (un + 1) | 1]
            .map(Hemicube::non_uniform)
            .into_iter()
            .min_by(|a, b| {
                let d = |c: &Hemicube| (c.max_delta_ff() / uniform.max_delta_ff()).ln().abs();
                d(a).total_cmp(&d(b))
            })
            .expect("two candidates");
        let (su, sn) = (time_cube(m, &uniform, from), time_cube(m, &twin, from));
        add_samples(&uniform, &su);
        add_samples(&twin, &sn);
        let (tu, tn) = (mean_seconds(&su), mean_seconds(&sn));
        rows.push(CubeRow {
            uniform_n: uniform.resolution(),
            uniform_cells: uniform.cell_count(),
            uniform_max_ff: uniform.max_delta_ff(),
            uniform_ms: 1e3 * tu,
            non_uniform_n: twin.resolution(),
            non_uniform_cells: twin.cell_count(),
            non_uniform_max_ff: twin.max_delta_ff(),
            non_uniform_ms: 1e3 * tn,
            cell_ratio: twin.cell_count() as f64 / uniform.cell_count() as f64,
            time_ratio: tn / tu,
            rays_per_uniform_shot: tu / per_ray,
        });
    }
    for small in MODEL_NS {
        let cube = Hemicube::non_uniform(small);
        let shots = time_cube(m, &cube, from);
        add_samples(&cube, &shots);
    }
    (rows, cube_samples)
}

/// The cost model fitted to timed shots ([`switch::fit_cube`], [`switch::fit_rays`]); the
/// kept constants for what there is no data for.
pub fn fit_model(cubes: &[CubeSample], rays: &[RaySample]) -> CostModel {
    let kept = switch::KEPT;
    let cube_shots: Vec<(ShotWork, f64)> = cubes
        .iter()
        .map(|c| {
            let w = ShotWork {
                patches: c.patches,
                faces: c.faces,
                cells: c.cells,
                tested: c.tested,
            };
            (w, c.seconds)
        })
        .collect();
    let c = switch::fit_cube(&cube_shots).unwrap_or(kept.cube_coefficients());
    let ray_shots: Vec<(u64, usize, f64)> = rays
        .iter()
        .map(|r| (r.rays, r.patches, r.seconds))
        .collect();
    CostModel {
        patch: c[0],
        face: c[1],
        cell: c[2],
        tested: c[3],
        ray: switch::fit_rays(&ray_shots).unwrap_or(kept.ray),
    }
}

/// The cost model fitted to the timed shots of several benchmarks together (several scenes:
/// how the kept constants of `solve::switch` were set).
pub fn pooled_fit(benches: &[ShotBench]) -> CostModel {
    let cubes: Vec<CubeSample> = benches
        .iter()
        .flat_map(|b| b.cube_samples.iter().copied())
        .collect();
    let rays: Vec<RaySample> = benches
        .iter()
        .flat_map(|b| b.ray_samples.iter().copied())
        .collect();
    fit_model(&cubes, &rays)
}

/// Solves with the hybrid under one rule.
fn hybrid(
    scene: &Scene,
    m: &Mesh,
    isect: &EmbreeScene,
    cfg: &SolveSettings,
    rule: &str,
    by: SwitchBy,
    model: CostModel,
) -> Result<HybridRun, Error> {
    let cfg = SolveSettings {
        method: MethodKind::AdaptiveHybrid,
        switch_by: by,
        ..cfg.clone()
    };
    let hooks = RunHooks::default();
    let sol = solve::driver::shoot_with(
        m,
        &scene.materials,
        Some(isect),
        &cfg,
        &hooks,
        model,
        |_| {},
    )
    .map_err(|source| Error::Solve {
        scene: scene.name.clone(),
        source,
    })?;
    Ok(HybridRun {
        rule: rule.into(),
        shots: sol.stats.shots,
        hemicube_shots: sol.stats.hemicube_shots,
        switch: sol.stats.switch,
        seconds: sol.stats.seconds,
    })
}

/// `radiosity bench shots --resolutions`: the uniform hemi-cube resolutions compared.
pub const DEFAULT_RESOLUTIONS: &str = "25,50,100,200";
/// `radiosity bench shots --shooters`: patches shot from.
pub const DEFAULT_SHOOTERS: usize = 64;

/// Everything `radiosity bench shots` does.
#[derive(Clone, Debug)]
pub struct ShotsJob {
    pub source: SceneSource,
    pub load: LoadOptions,
    pub mesh: MeshOptions,
    /// The hybrid runs' settings (and the seed of the timed shots).
    pub solve: SolveSettings,
    /// Uniform hemi-cube resolutions to compare (`--resolutions`).
    pub resolutions: Vec<usize>,
    /// Patches to shoot from, spread over the scene (`--shooters`).
    pub shooters: usize,
}

impl ShotsJob {
    /// Refuses what `solve` refuses, and a resolution the hemi-cube does not take.
    pub fn check(&self) -> Result<(), Invalid> {
        self.mesh.check()?;
        self.solve.check()?;
        if let Some(&bad) = self.resolutions.iter().find(|&&n| !(2..=4096).contains(&n)) {
            return Invalid::err(format!(
                "--resolutions must be between 2 and 4096, got {bad}"
            ));
        }
        Ok(())
    }
}

/// Runs the benchmark: the job's uniform resolutions, from its shooters.
pub fn bench_shots(job: &ShotsJob) -> Result<ShotBench, Error> {
    job.check()?;
    let (cfg, ns, shooters) = (&job.solve, &job.resolutions[..], job.shooters);
    let Model { scene, mesh: m } = Model::load(&job.source, &job.load, &job.mesh)?;
    let n = m.patches.len();
    let count = shooters.clamp(1, n.max(1));
    let from: Vec<usize> = (0..count).map(|k| k * n / count).collect();

    let isect = EmbreeScene::build(&m, |_| true)?;
    let (secs, rays) = time_ray_shots(&m, &isect, &from, 4096, cfg.seed);
    let per_ray = secs / rays.max(1) as f64;

    let (rows, cube_samples) = time_cubes(&m, ns, &from, per_ray);
    let ray_samples = time_rays(&m, &isect, &from, &MODEL_RAYS, cfg.seed);

    let kept = switch::KEPT;
    let fitted = fit_model(&cube_samples, &ray_samples);

    let hybrids = [
        ("counted, kept constants", SwitchBy::Counted, kept),
        ("counted, fitted constants", SwitchBy::Counted, fitted),
        ("measured", SwitchBy::Measured, kept),
    ]
    .into_iter()
    .map(|(rule, by, model)| hybrid(&scene, &m, &isect, cfg, rule, by, model))
    .collect::<Result<Vec<_>, _>>()?;
    let default = &hybrids[0];
    Ok(ShotBench {
        scene: scene.name.clone(),
        patches: n,
        shooters: from.len(),
        rows,
        ray_us_per_ray: 1e6 * per_ray,
        hybrid_shots: default.shots,
        hybrid_hemicube_shots: default.hemicube_shots,
        hybrid_switch: default.switch,
        hybrid_seconds: default.seconds,
        kept,
        fitted,
        kept_error: model_error(&kept, &cube_samples, &ray_samples),
        fitted_error: model_error(&fitted, &cube_samples, &ray_samples),
        cube_samples,
        ray_samples,
        hybrids,
    })
}
