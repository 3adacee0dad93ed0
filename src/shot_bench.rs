//! `radiosity bench shots`: the paper's cost per shot (Sec. 2 and 4), measured side by side in
//! one run on one scene.
//!
//! - The uniform N×N hemi-cube against the non-uniform one with the same largest ΔF (the odd
//!   resolution whose central cell is closest to the uniform cube's): the non-uniform cube has
//!   about π/12 of the cells; the paper found the saving pays off above about 50×50, where
//!   scan conversion starts to outweigh transforming every patch.
//! - A ray shot's cost per ray, cast exactly as the solver casts them.
//! - The shot at which `adaptive-hybrid` switched, in a real solve.
//!
//! Shots come from the same patches for every sampler (spread evenly over the patch list),
//! one at a time on one thread: thread time per shot, the unit the hybrid's switch compares.

use crate::intersect::embree::EmbreeScene;
use crate::mesh::MeshOptions;
use crate::model::Model;
use crate::sample::hemicube::{Hemicube, HemicubeBuffer};
use crate::sample::Frame;
use crate::scene::LoadOptions;
use crate::scene::SceneSource;
use crate::solve::{self, progressive, MethodKind, SolveSettings, SwitchInfo};
use crate::Error;
use serde::Serialize;
use std::time::Instant;

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
    /// The hybrid's solve: shots in all, shots by hemi-cube, and its switch.
    pub hybrid_shots: u64,
    pub hybrid_hemicube_shots: u64,
    pub hybrid_switch: Option<SwitchInfo>,
    pub hybrid_seconds: f64,
}

impl ShotBench {
    /// The figures as a Markdown table with the ray and hybrid lines under it.
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
        match &self.hybrid_switch {
            Some(sw) => {
                s += &format!(
                    "adaptive-hybrid: switched to rays at shot {} of {} (hemi-cube shot {:.3} ms predicted, {} rays {:.3} ms), solve {:.2} s\n",
                    sw.shot,
                    self.hybrid_shots,
                    1e3 * sw.hemicube_shot_seconds,
                    sw.rays,
                    1e3 * sw.ray_shot_seconds,
                    self.hybrid_seconds
                )
            }
            None => {
                s += &format!(
                    "adaptive-hybrid: never switched ({} shots, all by hemi-cube), solve {:.2} s\n",
                    self.hybrid_shots, self.hybrid_seconds
                )
            }
        }
        s
    }
}

/// Runs the benchmark: uniform resolutions `ns`, from `shooters` patches.
pub fn bench_shots(
    source: &SceneSource,
    load: &LoadOptions,
    mesh_opts: &MeshOptions,
    cfg: &SolveSettings,
    ns: &[usize],
    shooters: usize,
) -> Result<ShotBench, Error> {
    cfg.check()?;
    let Model { scene, mesh: m } = Model::load(source, load, mesh_opts)?;
    let n = m.patches.len();
    let count = shooters.clamp(1, n.max(1));
    let from: Vec<usize> = (0..count).map(|k| k * n / count).collect();

    let mut buf = HemicubeBuffer::default();
    let mut out = Vec::new();
    let mut time_cube = |cube: &Hemicube| -> f64 {
        let shoot = |i: usize, buf: &mut HemicubeBuffer, out: &mut Vec<_>| {
            let p = &m.patches[i];
            let frame = Frame::new(p.normal, 0.7 * i as f32);
            cube.shoot::<rand_pcg::Pcg64Mcg>(&m, i, p.centre, &frame, None, buf, out);
        };
        shoot(from[0], &mut buf, &mut out); // warm-up: sizes the buffers
        let t = Instant::now();
        for &i in &from {
            shoot(i, &mut buf, &mut out);
        }
        t.elapsed().as_secs_f64() / from.len() as f64
    };

    let isect = EmbreeScene::build(&m, |_| true)?;
    let per_ray = progressive::seconds_per_ray(&m, &isect, &from, 4096, cfg.seed);

    let mut rows = Vec::new();
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
        let (tu, tn) = (time_cube(&uniform), time_cube(&twin));
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

    let hybrid = SolveSettings {
        method: MethodKind::AdaptiveHybrid,
        ..cfg.clone()
    };
    let sol = solve::solve(&m, &scene.materials, &isect, &hybrid, |_| {}).map_err(|source| {
        Error::Solve {
            scene: scene.name.clone(),
            source,
        }
    })?;
    Ok(ShotBench {
        scene: scene.name.clone(),
        patches: n,
        shooters: from.len(),
        rows,
        ray_us_per_ray: 1e6 * per_ray,
        hybrid_shots: sol.stats.shots,
        hybrid_hemicube_shots: sol.stats.hemicube_shots,
        hybrid_switch: sol.stats.switch,
        hybrid_seconds: sol.stats.seconds,
    })
}
