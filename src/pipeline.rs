//! The pipeline a command runs (DESIGN.md §1): load → mesh → build the intersector → solve →
//! write the patch table, the image and the JSON summary. The binary only fills a [`SolveJob`].

use crate::export::solution::{self, SavedMaterial, SolutionMeta};
use crate::export::{self, patches, write_atomic};
use crate::intersect::select::{self, IntersectorKind};
use crate::intersect::{Intersector, Ray};
use crate::mesh::{self, Mesh, MeshOptions};
use crate::progress::Progress;
use crate::render::{self, Camera, RenderOptions};
use crate::report::{self, EnergyReport, Summary, Timings};
use crate::scene::{self, LoadOptions, Scene};
use crate::solve::{self, MethodKind, SolveSettings, TracePoint};
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
    /// Refuses a camera that cannot look anywhere: `--fov` outside (0, 180) degrees, `--eye`
    /// on `--target`, a zero `--up` or one along the line of sight.
    pub fn check(&self) -> Result<(), String> {
        if let Some(f) = self.fov_y_deg {
            if !(f > 0.0 && f < 180.0) {
                return Err(format!("--fov must be in (0, 180) degrees, got {f}"));
            }
        }
        if let (Some(eye), Some(target)) = (self.eye, self.target) {
            if eye == target {
                return Err(format!(
                    "--eye and --target are the same point ({eye}): the camera looks nowhere"
                ));
            }
            if let Some(up) = self.up {
                if up.cross(target - eye).length_squared() == 0.0 && up != Vec3::ZERO {
                    return Err(format!(
                        "--up {up} is along the line of sight from --eye to --target"
                    ));
                }
            }
        }
        if self.up == Some(Vec3::ZERO) {
            return Err("--up must not be 0,0,0".into());
        }
        Ok(())
    }

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
    pub solve: SolveSettings,
    pub out: PathBuf,
    /// `--intersector`.
    pub intersector: IntersectorKind,
    pub camera: CameraSpec,
    pub render: RenderOptions,
    /// A reference patch table (`--reference`): the trace then records the error against it.
    pub reference: Option<PathBuf>,
    /// Also save the solution here (`--save`), for `render` and `export` (see
    /// [`crate::export::solution`]).
    pub save: Option<PathBuf>,
    /// Keep per-light channels, grouped so (`--per-light`, `--light-groups`).
    pub per_light: Option<solve::lights::GroupBy>,
    /// Checkpoint file (`--checkpoint`) and seconds between checkpoints.
    pub checkpoint: Option<PathBuf>,
    pub checkpoint_every: f64,
    /// Continue from this checkpoint (`--resume`).
    pub resume: Option<PathBuf>,
    /// Set on Ctrl-C: stop at the next safe point.
    pub interrupt: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
}

/// Loads the scene named by `source`.
pub fn load_scene(source: &SceneSource, opts: &LoadOptions) -> Result<Scene, Error> {
    Ok(match source {
        SceneSource::Default => scene::default_scene(opts)?,
        SceneSource::File(p) => scene::load_obj(p, opts)?,
    })
}

/// Cuts the scene into patches, refusing a patch size that would make far too many.
pub fn build_mesh(scene: &Scene, opts: &MeshOptions) -> Result<Mesh, Error> {
    mesh::try_build(scene, opts).map_err(|message| {
        Error::Scene(scene::SceneError {
            path: scene.name.clone(),
            message,
        })
    })
}

/// Checks settings a user can get wrong, before any work.
pub fn validate(job: &SolveJob) -> Result<(), Error> {
    let s = &job.solve;
    if (job.checkpoint.is_some() || job.resume.is_some()) && s.method == MethodKind::Gathering {
        return Err(Error::Invalid(
            "--checkpoint and --resume need a shooting method: gathering has no useful state before it converges".into(),
        ));
    }
    if !(job.checkpoint_every > 0.0 && job.checkpoint_every.is_finite()) {
        return Err(Error::Invalid(format!(
            "--checkpoint-every must be a positive number of seconds, got {}",
            job.checkpoint_every
        )));
    }
    s.check()?;
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
    job.camera.check().map_err(Error::Invalid)?;
    if let Some(e) = job.render.exposure {
        if !(e > 0.0 && e.is_finite()) {
            return Err(Error::Invalid(format!(
                "--exposure must be a positive number, got {e}"
            )));
        }
    }
    if s.max_rays == Some(0) {
        return Err(Error::Invalid(
            "--max-rays must be at least 1 (leave it out for no limit)".into(),
        ));
    }
    Ok(())
}

/// Reads a reference patch table and checks it belongs to this mesh (same patch count, and
/// every patch's centre where this mesh has it). Returns its radiosity per patch.
pub fn load_reference(path: &std::path::Path, m: &Mesh) -> Result<Vec<[f64; 3]>, Error> {
    let bad = |what: String| Error::Invalid(format!("--reference {}: {what}", path.display()));
    let file = std::fs::File::open(path).map_err(|e| bad(format!("cannot read it ({e})")))?;
    let rows = patches::read(std::io::BufReader::new(file)).map_err(|e| bad(e.to_string()))?;
    if rows.len() != m.patches.len() {
        return Err(bad(format!(
            "it has {} patches but this mesh has {}: solve the reference with the same scene and --patch-size",
            rows.len(),
            m.patches.len()
        )));
    }
    let (lo, hi) = m.vertices.iter().fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(l, h), v| (l.min(*v), h.max(*v)),
    );
    let tol = 1e-4 * (hi - lo).max_element().max(f32::MIN_POSITIVE) as f64 + 1e-6;
    for (k, (row, p)) in rows.iter().zip(&m.patches).enumerate() {
        let c = [row.values[0], row.values[1], row.values[2]];
        let far = (0..3).any(|a| (c[a] - p.centre[a] as f64).abs() > tol);
        if row.id != k || far {
            return Err(bad(format!(
                "patch {k} is not where this mesh has it: the reference comes from another scene or patch size"
            )));
        }
        if row.b().iter().any(|x| !x.is_finite() || *x < 0.0) {
            return Err(bad(format!(
                "patch {k} has a radiosity that is not a finite non-negative number"
            )));
        }
    }
    Ok(rows.iter().map(|r| r.b()).collect())
}

/// What a checkpoint must match to be resumed: the scene and mesh (hash), and every setting
/// that shapes the result.
fn checkpoint_key(job: &SolveJob, scene: &Scene, m: &Mesh) -> String {
    let s = &job.solve;
    format!(
        "scene {:016x}, method {}, seed {}, tolerance {}, energy per ray {:?}, stop {}, hemicube-n {}, jitter {}, switch-at {:?}, per-light {:?}",
        crate::export::solution::scene_hash(scene, m.patch_size, job.mesh.two_sided),
        s.method.name(),
        s.seed,
        s.tolerance,
        s.energy_per_ray,
        s.stop_fraction,
        s.hemicube_n,
        s.jitter,
        s.switch_at,
        job.per_light.map(|g| format!("{g:?}"))
    )
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
    if let Some(save) = &job.save {
        check_save_path(save)?;
    }
    // Fail on an unwritable folder before spending any time.
    let made = export::prepare_dir(&job.out)?;
    // On failure leave nothing behind: not the files written so far, not the new folders.
    let mut written = Vec::new();
    let result = solve_into(job, progress, &mut log, t0, &mut written);
    if result.is_err() {
        for path in &written {
            let _ = std::fs::remove_file(path);
        }
        export::remove_made_dirs(&made);
    }
    result
}

/// The work of [`run_solve_with`] once the output folder is ready; every file it writes is
/// recorded in `written` as soon as it exists.
fn solve_into(
    job: &SolveJob,
    progress: &Progress,
    log: &mut impl FnMut(&str),
    t0: Instant,
    written: &mut Vec<std::path::PathBuf>,
) -> Result<Summary, Error> {
    let mut timings = Timings::default();

    progress.phase("loading");
    let scene = load_scene(&job.source, &job.load)?;
    for w in &scene.warnings {
        log(&format!("warning: {w}"));
    }
    timings.load = t0.elapsed().as_secs_f64();

    let t = Instant::now();
    progress.phase("meshing");
    let m = build_mesh(&scene, &job.mesh)?;
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

    // Only the methods that cast rays need an intersector (a scene builds what it needs).
    let t = Instant::now();
    progress.phase("building the intersectors");
    let (isect, chosen) = if job.solve.method.casts_rays() {
        let (isect, chosen) = select::select(&m, job.intersector)?;
        (Some(isect), Some(chosen))
    } else {
        (None, None)
    };
    timings.build = t.elapsed().as_secs_f64();
    if let (Some(isect), Some(chosen)) = (&isect, &chosen) {
        log(&format!("intersector {}: {}", isect.name(), chosen.reason));
    }

    let cfg = &job.solve;
    let mut hooks = solve::RunHooks::default();
    if let Some(by) = job.per_light {
        let g = solve::lights::groups(&scene, &m, by);
        log(&format!(
            "per-light channels: {} ({})",
            g.len(),
            g.names.join(", ")
        ));
        hooks.light_groups = Some(std::sync::Arc::new(g));
    }
    if let Some(path) = &job.reference {
        hooks.reference = Some(std::sync::Arc::new(load_reference(path, &m)?));
    }
    hooks.interrupt = job.interrupt.clone();
    if job.checkpoint.is_some() || job.resume.is_some() {
        let key = checkpoint_key(job, &scene, &m);
        if let Some(path) = &job.checkpoint {
            let path = path.clone();
            hooks.checkpoint = Some(solve::checkpoint::Sink {
                every: std::time::Duration::from_secs_f64(job.checkpoint_every),
                key: key.clone(),
                write: std::sync::Arc::new(move |snap: &solve::checkpoint::Snapshot| {
                    let bytes = snap.to_bytes();
                    write_atomic(&path, |w| w.write_all(&bytes)).map_err(|e| e.to_string())
                }),
            });
        }
        if let Some(path) = &job.resume {
            let what = path.display().to_string();
            let bytes = std::fs::read(path)
                .map_err(|e| Error::Invalid(format!("--resume {what}: cannot read it ({e})")))?;
            let snap =
                solve::checkpoint::Snapshot::from_bytes(&what, &bytes).map_err(Error::Invalid)?;
            snap.check_key(&what, &key).map_err(Error::Invalid)?;
            log(&format!(
                "resuming from {what}: {} shots, {:.1} s done",
                snap.header.shots, snap.header.elapsed
            ));
            hooks.resume = Some(std::sync::Arc::new(snap));
        }
    }
    let t = Instant::now();
    progress.start_solve(emitted_flux(&m, &scene.materials));
    let sol = solve::run(
        &m,
        &scene.materials,
        isect.as_ref(),
        cfg,
        &hooks,
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
    written.push(csv.clone());
    outputs.push(csv.display().to_string());
    let trace_csv = job.out.join("trace.csv");
    write_atomic(&trace_csv, |w| export::trace::write(w, &sol.stats.trace))?;
    written.push(trace_csv.clone());
    outputs.push(trace_csv.display().to_string());

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
    written.push(png.clone());
    outputs.push(png.display().to_string());

    if let Some(save) = &job.save {
        save_solution(save, job, &scene, &m, &sol)?;
        written.push(save.clone());
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
        intersector: isect.as_ref().map_or("none (no rays cast)", |i| i.name()),
        intersector_reason: chosen.as_ref().map_or_else(
            || "the method casts no rays".to_string(),
            |c| c.reason.clone(),
        ),
        seed: job.solve.seed,
        threads: rayon::current_num_threads(),
        tolerance: job.solve.tolerance,
        energy_per_ray: sol.stats.energy_per_ray,
        stop_fraction: job.solve.stop_fraction,
        stop_reason: sol.stats.stop_reason,
        shots: sol.stats.shots,
        rays: sol.stats.rays,
        waves: sol.stats.waves,
        hemicube_shots: sol.stats.hemicube_shots,
        hemicube_cells: sol.stats.hemicube_cells,
        hemicube_n: matches!(
            job.solve.method,
            MethodKind::Hemicube | MethodKind::HemicubeJittered | MethodKind::Gathering
        )
        .then_some(job.solve.hemicube_n),
        switch: sol.stats.switch,
        rays_per_second: sol.stats.rays as f64 / timings.solve.max(1e-9),
        seconds: timings,
        energy,
        light_channels: sol.channels.iter().map(|c| c.name.clone()).collect(),
        error_estimate: last.map(|p| p.estimate).unwrap_or_default(),
        error: last.and_then(|p| p.error),
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
        if dir.is_file() {
            return Err(Error::Invalid(format!(
                "--save {}: {} is a file, not a folder",
                path.display(),
                dir.display()
            )));
        }
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
    let channels: Vec<solution::LightChannel> = sol
        .channels
        .iter()
        .map(|c| solution::LightChannel {
            name: c.name.clone(),
            b: c.b.clone(),
        })
        .collect();
    write_atomic(path, |w| {
        solution::write(w, &meta, m, &sol.b, &sol.unshot, &vertex_b, &channels)
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
    let m = build_mesh(&scene, mesh_opts)?;
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

/// `radiosity bench rays`: the intersector's raw throughput and the solver's, side by side in
/// one run.
pub fn bench_rays(
    source: &SceneSource,
    load: &LoadOptions,
    mesh_opts: &MeshOptions,
    cfg: &SolveSettings,
    kind: IntersectorKind,
    raw_rays: u64,
    min_seconds: f64,
) -> Result<RayBench, Error> {
    // The solver's rays are what is measured: the ray shooter, whatever --method says.
    let cfg = &SolveSettings {
        method: solve::MethodKind::AdaptiveRays,
        ..cfg.clone()
    };
    let scene = load_scene(source, load)?;
    let m = build_mesh(&scene, mesh_opts)?;
    let (isect, chosen) = select::select(&m, kind)?;
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
        let sol = solve::solve(&m, &scene.materials, &isect, &round, |_| {}).map_err(|source| {
            Error::Solve {
                scene: scene.name.clone(),
                source,
            }
        })?;
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
