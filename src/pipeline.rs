//! The pipeline a command runs (DESIGN.md §1): load → mesh → build the intersector → solve →
//! write the patch table, the image and the JSON summary. The binary only fills a [`SolveJob`].

use crate::export::solution::{self, SavedMaterial, SolutionMeta};
use crate::export::{self, patches, write_atomic};
use crate::intersect::embree::EmbreeScene;
use crate::intersect::{Intersector, Ray};
use crate::mesh::{self, Mesh, MeshOptions};
use crate::progress::Progress;
use crate::render::{self, Camera, RenderOptions};
use crate::report::{self, EnergyReport, Summary, Timings};
use crate::scene::{self, LoadOptions, Scene};
use crate::solve::{self, SolveConfig, TracePoint};
use crate::Error;
use glam::Vec3;
use rand::{Rng, SeedableRng};
use rayon::prelude::*;
use std::path::PathBuf;
use std::time::Instant;

/// Where the scene comes from.
#[derive(Clone, Debug)]
pub enum SceneSource {
    /// The built-in Cornell box.
    Default,
    File(PathBuf),
}

/// A camera from the command line; what is left out is fitted to the scene.
#[derive(Clone, Debug, Default)]
pub struct CameraSpec {
    pub eye: Option<Vec3>,
    pub target: Option<Vec3>,
    pub up: Option<Vec3>,
    pub fov_y_deg: Option<f32>,
}

impl CameraSpec {
    /// The camera for a scene with bounds (lo, hi): fitted unless an eye is given.
    pub fn resolve(&self, lo: Vec3, hi: Vec3, aspect: f32) -> Camera {
        let mut cam = Camera::fit(lo, hi, aspect);
        if let Some(eye) = self.eye {
            cam.eye = eye;
            cam.target = self.target.unwrap_or((lo + hi) * 0.5);
        } else if let Some(t) = self.target {
            cam.target = t;
        }
        if let Some(up) = self.up {
            cam.up = up;
        }
        if let Some(f) = self.fov_y_deg {
            cam.fov_y_deg = f;
        }
        cam
    }
}

/// Everything `radiosity solve` does.
#[derive(Clone, Debug)]
pub struct SolveJob {
    pub source: SceneSource,
    pub load: LoadOptions,
    pub mesh: MeshOptions,
    pub solve: SolveConfig,
    pub out: PathBuf,
    pub camera: CameraSpec,
    pub render: RenderOptions,
    /// Also save the solution here (`--save`), for `render` and `export` (see
    /// [`crate::export::solution`]).
    pub save: Option<PathBuf>,
}

/// Loads the scene named by `source`.
pub fn load_scene(source: &SceneSource, opts: &LoadOptions) -> Result<Scene, Error> {
    Ok(match source {
        SceneSource::Default => scene::default_scene(opts)?,
        SceneSource::File(p) => scene::load_obj(p, opts)?,
    })
}

/// Checks settings a user can get wrong, before any work.
pub fn validate(job: &SolveJob) -> Result<(), Error> {
    let s = &job.solve;
    if s.method != crate::solve::MethodKind::AdaptiveRays {
        return Err(Error::Invalid(format!(
            "--method {} is not available yet",
            s.method.name()
        )));
    }
    if !(s.tolerance > 0.0 && s.tolerance < 1.0) {
        return Err(Error::Invalid(format!(
            "--tolerance must be in (0, 1), got {}",
            s.tolerance
        )));
    }
    if !(s.stop_fraction > 0.0 && s.stop_fraction.is_finite()) {
        return Err(Error::Invalid(format!(
            "--stop must be a positive fraction, got {}",
            s.stop_fraction
        )));
    }
    if let Some(ps) = job.mesh.patch_size {
        if !(ps > 0.0 && ps.is_finite()) {
            return Err(Error::Invalid(format!(
                "--patch-size must be a positive length in metres, got {ps}"
            )));
        }
    }
    if job.render.width == 0
        || job.render.height == 0
        || job.render.width > 16384
        || job.render.height > 16384
    {
        return Err(Error::Invalid(format!(
            "--width and --height must be between 1 and 16384, got {}x{}",
            job.render.width, job.render.height
        )));
    }
    if let Some(f) = job.camera.fov_y_deg {
        if !(f > 0.0 && f < 180.0) {
            return Err(Error::Invalid(format!(
                "--fov must be in (0, 180) degrees, got {f}"
            )));
        }
    }
    Ok(())
}

/// Warnings about a solution a user should hear of.
fn solution_warnings(energy: &EnergyReport) -> Vec<String> {
    let mut w = Vec::new();
    if energy.back_fraction > 0.05 {
        w.push(format!(
            "{:.1} % of the emitted light arrived on back faces and was absorbed: are some normals flipped (faces wound clockwise)? Use --two-sided for thin surfaces seen from both sides",
            100.0 * energy.back_fraction
        ));
    }
    w
}

/// Runs a whole solve and writes its outputs into `job.out`. `log` receives progress lines.
pub fn run_solve(job: &SolveJob, log: impl FnMut(&str)) -> Result<Summary, Error> {
    run_solve_with(job, &Progress::hidden(), log)
}

/// [`run_solve`] with progress bars.
pub fn run_solve_with(
    job: &SolveJob,
    progress: &Progress,
    mut log: impl FnMut(&str),
) -> Result<Summary, Error> {
    validate(job)?;
    let t0 = Instant::now();
    let mut timings = Timings::default();
    // Fail on an unwritable folder before spending any time.
    export::prepare_dir(&job.out)?;
    if let Some(save) = &job.save {
        check_save_path(save)?;
    }

    progress.phase("loading");
    let scene = load_scene(&job.source, &job.load)?;
    for w in &scene.warnings {
        log(&format!("warning: {w}"));
    }
    timings.load = t0.elapsed().as_secs_f64();

    let t = Instant::now();
    progress.phase("meshing");
    let m = mesh::build(&scene, &job.mesh);
    timings.mesh = t.elapsed().as_secs_f64();
    if job.mesh.patch_size.is_none() {
        let from = if scene.patch_size_hint.is_some() {
            "the scene file's own"
        } else {
            "derived from the scene"
        };
        log(&format!(
            "patch size {} m ({from}; --patch-size to change)",
            m.patch_size
        ));
    }
    log(&format!(
        "{}: {} polygons, {} patches",
        scene.name,
        scene.polygons.len(),
        m.patches.len()
    ));

    let t = Instant::now();
    progress.phase("building the intersectors");
    let isect = EmbreeScene::build(&m, |_| true)?;
    timings.build = t.elapsed().as_secs_f64();

    let t = Instant::now();
    progress.start_solve(emitted_flux(&m, &scene.materials));
    let sol = solve::solve(
        &m,
        &scene.materials,
        &isect,
        &job.solve,
        |p: &TracePoint| progress.solve_wave(p),
    )
    .map_err(|source| Error::Solve {
        scene: scene.name.clone(),
        source,
    })?;
    timings.solve = t.elapsed().as_secs_f64();
    log(&format!("solved: {}", Summary::stats_line(&sol.stats)));

    // Outputs.
    progress.phase("writing outputs");
    let t = Instant::now();
    let mut outputs = Vec::new();
    let csv = job.out.join("patches.csv");
    write_atomic(&csv, |w| patches::write(w, &m, &scene.materials, &sol.b))?;
    outputs.push(csv.display().to_string());

    let png = job.out.join("render.png");
    let (lo, hi) = scene.bounds();
    let cam = job
        .camera
        .resolve(lo, hi, job.render.width as f32 / job.render.height as f32);
    let img = render_solution(&m, &sol.b, &cam, &job.render);
    write_atomic(&png, |w| {
        let mut buf = std::io::Cursor::new(Vec::new());
        img.write_to(&mut buf, image::ImageFormat::Png)
            .map_err(std::io::Error::other)?;
        w.write_all(buf.get_ref())
    })?;
    outputs.push(png.display().to_string());

    if let Some(save) = &job.save {
        save_solution(save, job, &scene, &m, &sol)?;
        outputs.push(save.display().to_string());
    }

    let energy = EnergyReport::from(&sol.stats.energy);
    let warnings: Vec<String> = scene
        .warnings
        .iter()
        .cloned()
        .chain(solution_warnings(&energy))
        .collect();
    for w in solution_warnings(&energy) {
        log(&format!("warning: {w}"));
    }
    let json = job.out.join("summary.json");
    outputs.push(json.display().to_string());
    let last = sol.stats.trace.last().copied();
    timings.output = t.elapsed().as_secs_f64();
    timings.total = t0.elapsed().as_secs_f64();
    let summary = Summary {
        version: env!("CARGO_PKG_VERSION"),
        scene: scene.name.clone(),
        polygons: scene.polygons.len(),
        patches: m.patches.len(),
        patch_size: m.patch_size,
        axial_fraction_area: report::axial_fractions(&m).1,
        lights: report::lights(&scene, &m),
        method: job.solve.method.name(),
        intersector: isect.name(),
        seed: job.solve.seed,
        threads: rayon::current_num_threads(),
        tolerance: job.solve.tolerance,
        energy_per_ray: sol.stats.energy_per_ray,
        stop_fraction: job.solve.stop_fraction,
        stop_reason: sol.stats.stop_reason,
        shots: sol.stats.shots,
        rays: sol.stats.rays,
        waves: sol.stats.waves,
        rays_per_second: sol.stats.rays as f64 / timings.solve.max(1e-9),
        seconds: timings,
        energy,
        max_unshot_over_mean: last
            .map_or(0.0, |p| p.max_unshot_b / p.mean_b.max(f64::MIN_POSITIVE)),
        warnings,
        outputs,
        trace: sol.stats.trace.clone(),
    };
    write_atomic(&json, |w| {
        serde_json::to_writer_pretty(&mut *w, &summary).map_err(std::io::Error::other)?;
        writeln!(w)
    })?;
    progress.finish();
    Ok(summary)
}

/// Scalar flux the lights emit (W): what the solve's progress is measured against.
fn emitted_flux(m: &Mesh, materials: &[scene::Material]) -> f64 {
    m.patches
        .iter()
        .map(|p| solve::scalar(&materials[p.material as usize].emission()) * p.area)
        .sum()
}

/// Refuses a `--save` path that cannot be written, before any work is spent.
fn check_save_path(path: &std::path::Path) -> Result<(), Error> {
    if path.is_dir() {
        return Err(Error::Invalid(format!(
            "--save {}: is a folder; give a file name such as solution.rad",
            path.display()
        )));
    }
    let parent = path.parent().filter(|p| !p.as_os_str().is_empty());
    if let Some(dir) = parent {
        if !dir.is_dir() {
            return Err(Error::Invalid(format!(
                "--save {}: the folder {} does not exist",
                path.display(),
                dir.display()
            )));
        }
    }
    Ok(())
}

/// Writes the saved solution of a finished solve (`--save`).
fn save_solution(
    path: &std::path::Path,
    job: &SolveJob,
    scene: &Scene,
    m: &Mesh,
    sol: &solve::Solution,
) -> Result<(), Error> {
    let meta = SolutionMeta {
        tool_version: env!("CARGO_PKG_VERSION").to_string(),
        scene: scene.name.clone(),
        scene_hash: solution::scene_hash(scene, m.patch_size, job.mesh.two_sided),
        patch_size: m.patch_size,
        two_sided: job.mesh.two_sided,
        method: job.solve.method.name().to_string(),
        seed: job.solve.seed,
        tolerance: job.solve.tolerance,
        energy_per_ray: sol.stats.energy_per_ray,
        stop_fraction: job.solve.stop_fraction,
        stop_reason: sol
            .stats
            .stop_reason
            .and_then(|r| serde_json::to_value(r).ok())
            .and_then(|v| v.as_str().map(str::to_string)),
        shots: sol.stats.shots,
        rays: sol.stats.rays,
        materials: scene
            .materials
            .iter()
            .map(|mat| SavedMaterial {
                name: mat.name.clone(),
                rho: mat.rho,
                ke: mat.ke,
            })
            .collect(),
    };
    let vertex_b = m.vertex_values(&sol.b);
    write_atomic(path, |w| {
        solution::write(w, &meta, m, &sol.b, &sol.unshot, &vertex_b, &[])
    })?;
    Ok(())
}

/// Renders patch radiosities, Gouraud-interpolated at the welded vertices, tone-mapped.
pub fn render_solution(
    m: &Mesh,
    b: &[[f64; 3]],
    cam: &Camera,
    opts: &RenderOptions,
) -> image::RgbImage {
    let vertex = m.vertex_values(b);
    let lin = render::render_linear(m, &vertex, cam, opts);
    render::tone_map(&lin, opts.exposure).0
}

/// `radiosity info`.
pub fn info(
    source: &SceneSource,
    load: &LoadOptions,
    mesh_opts: &MeshOptions,
) -> Result<report::SceneInfo, Error> {
    let scene = load_scene(source, load)?;
    let m = mesh::build(&scene, mesh_opts);
    Ok(report::scene_info(
        &scene,
        &m,
        mesh::default_patch_size(&scene),
    ))
}

/// What `radiosity bench rays` measured.
#[derive(Clone, Debug, serde::Serialize)]
pub struct RayBench {
    pub scene: String,
    pub triangles: usize,
    pub patches: usize,
    pub threads: usize,
    /// Closest-hit queries per second on random rays (origins uniform in the bounds,
    /// directions uniform on the sphere), all threads.
    pub raw_rays_per_second: f64,
    pub raw_rays: u64,
    /// The raw rate measured before and after the solve.
    pub raw_before_after: [f64; 2],
    /// Rays per second of the solver's whole solve phase (sampling, casting, bookkeeping).
    pub solver_rays_per_second: f64,
    pub solver_rays: u64,
    /// solver / raw.
    pub ratio: f64,
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

/// `radiosity bench rays`: raw Embree throughput and the solver's, side by side in one run.
pub fn bench_rays(
    source: &SceneSource,
    load: &LoadOptions,
    mesh_opts: &MeshOptions,
    cfg: &SolveConfig,
    raw_rays: u64,
) -> Result<RayBench, Error> {
    let scene = load_scene(source, load)?;
    let m = mesh::build(&scene, mesh_opts);
    let isect = EmbreeScene::build(&m, |_| true)?;
    let (lo, hi) = scene.bounds();
    // Warm up (page in the BVH, spin up the threads), then measure the raw rate before and
    // after the solve, so a drift of the machine's speed shows and averages out.
    raw_throughput(&isect, lo, hi, raw_rays / 10 + 1, cfg.seed);
    let (n1, s1) = raw_throughput(&isect, lo, hi, raw_rays / 2, cfg.seed);
    let sol =
        solve::solve(&m, &scene.materials, &isect, cfg, |_| {}).map_err(|source| Error::Solve {
            scene: scene.name.clone(),
            source,
        })?;
    let (n2, s2) = raw_throughput(&isect, lo, hi, raw_rays / 2, cfg.seed ^ 1);
    let (n_raw, s_raw) = (n1 + n2, s1 + s2);
    let raw = n_raw as f64 / s_raw.max(1e-9);
    let solver = sol.stats.rays as f64 / sol.stats.seconds.max(1e-9);
    Ok(RayBench {
        scene: scene.name.clone(),
        triangles: isect.triangle_count(),
        patches: m.patches.len(),
        threads: rayon::current_num_threads(),
        raw_rays_per_second: raw,
        raw_rays: n_raw,
        raw_before_after: [n1 as f64 / s1.max(1e-9), n2 as f64 / s2.max(1e-9)],
        solver_rays_per_second: solver,
        solver_rays: sol.stats.rays,
        ratio: solver / raw,
    })
}
