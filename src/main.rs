//! The `radiosity` command: parses flags, fills the library's jobs, prints results. All the
//! work is in the library (`radiosity::pipeline`).

use clap::{Args, Parser, Subcommand};
use glam::Vec3;
use radiosity::compare::{self, CompareJob, ReferenceJob};
use radiosity::intersect::select::IntersectorKind;
use radiosity::intersect_jobs::{self, CrossJob};
use radiosity::mesh::MeshOptions;
use radiosity::pipeline::{self, CameraSpec, SceneSource, SolveJob};
use radiosity::render::RenderOptions;
use radiosity::scene::LoadOptions;
use radiosity::solve::{MethodKind, SolveSettings};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

/// `println!` that ends the process quietly when standard output is closed (`radiosity info |
/// head -1`) instead of panicking on the broken pipe.
macro_rules! outln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        if writeln!(std::io::stdout(), $($arg)*).is_err() {
            std::process::exit(0);
        }
    }};
}

/// `print!` likewise.
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        if write!(std::io::stdout(), $($arg)*).is_err() {
            std::process::exit(0);
        }
    }};
}

#[derive(Parser)]
#[command(
    name = "radiosity",
    version,
    about = "Adaptive progressive-refinement radiosity (Airey & Ouh-young 1989) for architectural models"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Worker threads (default: all cores). Results do not depend on it.
    #[arg(long, global = true, value_parser = parse_threads)]
    threads: Option<usize>,
}

#[derive(Subcommand)]
enum Command {
    /// Solve a scene and write patches.csv, render.png and summary.json into --out.
    Solve(SolveArgs),
    /// Describe a scene: polygons, patches, axis-aligned share, materials, lights, bounds.
    Info {
        /// OBJ file (with its MTL beside it); the built-in Cornell box if left out.
        scene: Option<PathBuf>,
        #[command(flatten)]
        scene_args: SceneArgs,
        /// Print JSON instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Cast the same rays through every intersector the scene supports and compare the hit
    /// patches against the reference (exit code 1 if the bar fails).
    Crosscheck(CrosscheckArgs),
    /// Solve a high-accuracy reference (adaptive rays, two independent halves averaged) and
    /// write DIR/patches.csv and DIR/summary.json with its stated error bound, checked against
    /// the difference of the halves (exit code 1 if they disagree by more than 2×).
    Reference(ReferenceArgs),
    /// Run methods side by side against one reference and write compare.csv, compare.md,
    /// compare.json and the plots (error against time, Fig. 2's decay, Fig. 5's cost per shot).
    Compare(CompareArgs),
    /// The scene-size performance sweep over generated buildings: times, rays per second,
    /// peak memory and the solver's error estimate per size and method; CSV, Markdown with
    /// growth exponents, log-log plots.
    Sweep(SweepArgs),
    /// Benchmarks.
    #[command(subcommand)]
    Bench(BenchCommand),
    /// Generate models.
    #[command(subcommand)]
    Generate(GenerateCommand),
    /// Render a saved solution (from `solve --save`) to PNG, Radiance HDR or OpenEXR.
    Render(RenderArgs),
    /// Export a saved solution as a mesh with per-vertex radiosity: PLY or binary glTF.
    Export(ExportArgs),
    /// Re-weight the lights of a solution saved with --per-light, without solving again, and
    /// render it (.png/.hdr/.exr) or export it (.ply/.glb).
    Relight(RelightArgs),
}

#[derive(Args)]
struct RelightArgs {
    /// LIGHT=WEIGHT (repeatable): scale that light's channel (its name as `solve --per-light`
    /// printed it); lights not named keep weight 1.
    #[arg(long = "weight", value_name = "LIGHT=W", value_parser = parse_weight)]
    weights: Vec<(String, f64)>,
    #[command(flatten)]
    render: RenderArgs,
}

fn parse_weight(s: &str) -> Result<(String, f64), String> {
    let (name, w) = s
        .rsplit_once('=')
        .ok_or_else(|| format!("expected LIGHT=WEIGHT, got '{s}'"))?;
    let w: f64 = w
        .trim()
        .parse()
        .map_err(|_| format!("'{w}' is not a number in '{s}'"))?;
    if !(w.is_finite() && w >= 0.0) {
        return Err(format!("the weight in '{s}' must be a finite number ≥ 0"));
    }
    Ok((name.trim().to_string(), w))
}

/// Checking a saved solution against its scene (optional).
#[derive(Args, Clone)]
struct CheckArgs {
    /// Refuse the solution unless it was solved on this OBJ (same geometry and reflectances;
    /// emission may differ).
    #[arg(long, value_name = "FILE.obj")]
    scene: Option<PathBuf>,
    /// With --scene: the patch size to check too (default: the solution's own).
    #[arg(long, value_name = "METRES", requires = "scene")]
    check_patch_size: Option<f32>,
}

impl CheckArgs {
    fn check(&self, two_sided: Option<bool>) -> Option<radiosity::outputs::SceneCheck> {
        self.scene.as_ref().map(|p| radiosity::outputs::SceneCheck {
            source: SceneSource::File(p.clone()),
            load: LoadOptions::default(),
            patch_size: self.check_patch_size,
            two_sided,
        })
    }
}

/// The camera and the image (`solve`, `render`, `relight`).
#[derive(Args)]
struct ViewArgs {
    /// Camera position X,Y,Z (default: fitted to the scene, looking along −z).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    eye: Option<Vec3>,
    /// Point the camera looks at X,Y,Z (default: the scene's centre).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    target: Option<Vec3>,
    /// Camera up direction X,Y,Z (default 0,1,0).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    up: Option<Vec3>,
    /// Vertical field of view in degrees.
    #[arg(long, allow_negative_numbers = true)]
    fov: Option<f32>,
    #[arg(long, default_value_t = 640)]
    width: u32,
    #[arg(long, default_value_t = 480)]
    height: u32,
    /// Samples per pixel along each axis (edges anti-aliased by s×s supersampling).
    #[arg(long, default_value_t = 3)]
    supersample: u32,
    /// Exposure multiplier on radiosity for PNG (default: automatic).
    #[arg(long, allow_negative_numbers = true)]
    exposure: Option<f32>,
}

impl ViewArgs {
    fn camera(&self) -> CameraSpec {
        CameraSpec {
            eye: self.eye,
            target: self.target,
            up: self.up,
            fov_y_deg: self.fov,
        }
    }

    fn render(&self) -> RenderOptions {
        RenderOptions {
            width: self.width,
            height: self.height,
            supersample: self.supersample,
            exposure: self.exposure,
        }
    }
}

#[derive(Args)]
struct RenderArgs {
    /// The saved solution (`radiosity solve --save FILE.rad`).
    solution: PathBuf,
    /// Image to write: .png (tone-mapped sRGB), .hdr or .exr (linear radiosity, W/m²).
    #[arg(long)]
    out: PathBuf,
    #[command(flatten)]
    check: CheckArgs,
    #[command(flatten)]
    view: ViewArgs,
    /// Irradiance in false colour on a log scale, with a legend in W/m² (PNG only).
    #[arg(long, alias = "false-color")]
    false_colour: bool,
    /// Print the report as JSON on stdout.
    #[arg(long)]
    json: bool,
    /// Print nothing but errors.
    #[arg(long, short)]
    quiet: bool,
}

#[derive(Args)]
struct ExportArgs {
    /// The saved solution (`radiosity solve --save FILE.rad`).
    solution: PathBuf,
    /// Mesh to write: .ply or .glb.
    #[arg(long)]
    out: PathBuf,
    #[command(flatten)]
    check: CheckArgs,
    /// Exposure of the display colours (default: automatic, as for images).
    #[arg(long, allow_negative_numbers = true)]
    exposure: Option<f32>,
    /// Print the report as JSON on stdout.
    #[arg(long)]
    json: bool,
    /// Print nothing but errors.
    #[arg(long, short)]
    quiet: bool,
}

#[derive(Subcommand)]
enum GenerateCommand {
    /// A multi-storey building (OBJ, with its MTL beside it under the same stem).
    Building {
        /// The OBJ file to write.
        #[arg(long)]
        out: PathBuf,
        #[arg(long, default_value_t = 3)]
        floors: u32,
        /// Rooms per floor.
        #[arg(long, default_value_t = 8)]
        rooms: u32,
        /// Aim at about this many patches (overrides --floors and --rooms).
        #[arg(long)]
        patches: Option<usize>,
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
}

#[derive(Args)]
struct ReferenceArgs {
    /// OBJ file (with its MTL beside it); the built-in Cornell box if left out.
    scene: Option<PathBuf>,
    #[command(flatten)]
    scene_args: SceneArgs,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Relative sampling error wanted (solve's default is 0.05: 100× fewer rays).
    #[arg(long, default_value_t = 0.005, allow_negative_numbers = true)]
    tolerance: f64,
    /// Stop when the max unshot radiosity is below this fraction of the mean radiosity.
    #[arg(
        long,
        default_value_t = 1e-5,
        value_name = "FRACTION",
        allow_negative_numbers = true
    )]
    stop: f64,
    #[arg(long, value_enum, default_value_t = IntersectorArg::Auto)]
    intersector: IntersectorArg,
}

#[derive(Args)]
struct CompareArgs {
    /// OBJ file (with its MTL beside it); the built-in Cornell box if left out.
    scene: Option<PathBuf>,
    #[command(flatten)]
    scene_args: SceneArgs,
    /// Methods to run, in order; speedups are of the first over each other.
    #[arg(
        long,
        value_enum,
        value_delimiter = ',',
        default_value = "adaptive-hybrid,adaptive-rays,adaptive-hemicube,hemicube,hemicube-jittered,gathering"
    )]
    methods: Vec<Method>,
    /// Time budget per method in seconds (gathering always finishes its matrix).
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true)]
    budget: f64,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
    /// A reference patch table of the same scene and patch size (default: build one, as
    /// `radiosity reference` does, and write it to OUT/reference/patches.csv).
    #[arg(long, value_name = "PATCHES.csv")]
    reference: Option<PathBuf>,
    /// Tolerance of the reference built here.
    #[arg(long, default_value_t = 0.005, allow_negative_numbers = true)]
    reference_tolerance: f64,
    /// Stop fraction of the reference built here.
    #[arg(long, default_value_t = 1e-5, allow_negative_numbers = true)]
    reference_stop: f64,
    /// Error levels (fractions: 0.05 = 5 %) of the time-to-error table.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "0.2,0.1,0.05,0.03,0.02,0.01",
        allow_negative_numbers = true
    )]
    levels: Vec<f64>,
    /// Run every method this many times in interleaved rounds and keep each one's run of
    /// median solve time (steadier figures for solves of milliseconds).
    #[arg(long, default_value_t = 1, value_name = "N")]
    repeat: usize,
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Relative sampling error of the compared runs (sets the rays' energy, as in solve).
    #[arg(long, default_value_t = 0.05, allow_negative_numbers = true)]
    tolerance: f64,
    /// Stop fraction of the compared runs (paper Sec. 3: 0.06 %).
    #[arg(long, default_value_t = 0.0006, allow_negative_numbers = true)]
    stop: f64,
    /// Resolution N of the uniform N×N hemi-cube (hemicube, hemicube-jittered, gathering).
    #[arg(long, default_value_t = 100, value_name = "N")]
    hemicube_n: usize,
    #[arg(long, default_value_t = 4096, value_name = "MIB")]
    gather_cap_mib: u64,
    #[arg(long, value_enum, default_value_t = IntersectorArg::Auto)]
    intersector: IntersectorArg,
}

#[derive(Args)]
struct CrosscheckArgs {
    /// OBJ file (with its MTL beside it); the built-in Cornell box if left out.
    scene: Option<PathBuf>,
    #[command(flatten)]
    scene_args: SceneArgs,
    /// Rays to cast (half from patch surfaces as the solver casts them, half uniform).
    #[arg(long)]
    rays: u64,
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Edge distance, relative to the scene's diagonal, within which a disagreement counts as
    /// crossing a patch edge.
    #[arg(long, default_value_t = 1e-5, allow_negative_numbers = true)]
    eps: f32,
    /// The scene is open: rays escaping it do not fail the bar (default: judged by the
    /// reference's escapes).
    #[arg(long, conflicts_with = "closed")]
    open: bool,
    /// The scene is closed: any escape fails the bar.
    #[arg(long)]
    closed: bool,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
    /// Also write the report to this file (JSON if it ends in .json, else text).
    #[arg(long)]
    out: Option<PathBuf>,
}

#[derive(Subcommand)]
enum BenchCommand {
    /// Mrays/s of Embree (whole scene), the plane merge, the hybrid and brute force, side by
    /// side on each scene and on generated buildings.
    Intersect {
        /// OBJ files (with their MTL beside them).
        scenes: Vec<PathBuf>,
        #[command(flatten)]
        scene_args: SceneArgs,
        /// Generated buildings of about these many patches (1k = 1000, 1M = 1000000; "none"
        /// for none). 1M takes minutes and a few GB.
        #[arg(long, value_parser = parse_sizes, default_value = "1k,10k,100k")]
        generated: Sizes,
        /// Rays per intersector and scene (brute force casts fewer).
        #[arg(long, default_value_t = 1_000_000)]
        rays: u64,
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Which rays: from patch surfaces as the solver casts them, uniform (origin in the
        /// bounds, direction on the sphere), or half of each.
        #[arg(long, value_enum, default_value_t = RaysArg::Both)]
        source: RaysArg,
        /// Also write the table as CSV to this file.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Raw Embree closest-hit throughput on random rays against the solver's rays per second,
    /// measured in one run.
    Rays {
        scene: Option<PathBuf>,
        #[command(flatten)]
        scene_args: SceneArgs,
        #[command(flatten)]
        solve_args: SolverArgs,
        /// Random rays for the raw measurement (a quarter before each solve).
        #[arg(long, default_value_t = 4_000_000)]
        rays: u64,
        /// Solve again (next seeds) until the solves took this long in all, alternating with
        /// raw measurements, so both see the same machine.
        #[arg(long, default_value_t = 3.0, value_name = "SECONDS")]
        min_seconds: f64,
        /// Also write the figures as JSON to this file.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Cost per shot (Sec. 4): uniform against non-uniform hemi-cubes with the same largest
    /// delta form factor, ray shots per ray, and where adaptive-hybrid switches.
    Shots {
        scene: Option<PathBuf>,
        #[command(flatten)]
        scene_args: SceneArgs,
        #[command(flatten)]
        solve_args: SolverArgs,
        /// Uniform hemi-cube resolutions to compare.
        #[arg(long, value_delimiter = ',', default_value = "25,50,100,200")]
        resolutions: Vec<usize>,
        /// Patches to shoot from (spread over the scene), the same for every sampler.
        #[arg(long, default_value_t = 64)]
        shooters: usize,
        /// Also write the figures as JSON to this file.
        #[arg(long)]
        out: Option<PathBuf>,
    },
}

/// How the scene is read and cut into patches.
#[derive(Args, Clone)]
struct SceneArgs {
    /// Make a material emit: MATERIAL=R,G,B emitted radiance in W/sr/m² (the unit of MTL Ke);
    /// repeatable. For models that ship without Ke.
    #[arg(long, value_name = "MATERIAL=R,G,B", value_parser = parse_emit)]
    emit: Vec<(String, [f64; 3])>,
    /// Longest patch edge in metres (default: derived from the scene, and printed).
    #[arg(long, value_name = "METRES", allow_negative_numbers = true, value_parser = parse_length)]
    patch_size: Option<f32>,
    /// Give every polygon a back patch of its own (thin surfaces lit from both sides).
    #[arg(long)]
    two_sided: bool,
}

/// How the solver runs.
#[derive(Args, Clone)]
struct SolverArgs {
    /// Seed of all random choices; the same seed gives the same result on any thread count.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Relative sampling error wanted for a typical patch's radiosity. Sets the energy each ray
    /// carries (Sec. 2: rays in proportion to unshot energy): about patches/tolerance² rays in
    /// all, so halving it costs 4× the rays.
    #[arg(long, default_value_t = 0.05, allow_negative_numbers = true)]
    tolerance: f64,
    /// Energy per ray C in watts (overrides --tolerance).
    #[arg(long, value_name = "WATTS", allow_negative_numbers = true)]
    energy_per_ray: Option<f64>,
    /// Stop when the max unshot radiosity is below this fraction of the mean radiosity
    /// (paper Sec. 3: 0.06 %).
    #[arg(
        long,
        default_value_t = 0.0006,
        value_name = "FRACTION",
        allow_negative_numbers = true
    )]
    stop: f64,
    /// Stop after this many seconds of solving, whatever the criterion says.
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true)]
    max_time: Option<f64>,
    /// Stop after about this many form-factor samples (rays, plus hemi-cube cells).
    #[arg(long)]
    max_rays: Option<u64>,
    /// Aim rays at the centres of the polar cells, as the paper does, instead of at random
    /// points inside them (biased at low ray counts; for comparison).
    #[arg(long)]
    polar_centres: bool,
    /// How form factors are sampled.
    #[arg(long, value_enum, default_value_t = Method::AdaptiveHybrid)]
    method: Method,
    /// Resolution N of the uniform N×N hemi-cube (methods hemicube, hemicube-jittered,
    /// gathering).
    #[arg(long, default_value_t = 100, value_name = "N")]
    hemicube_n: usize,
    /// Gathering refuses scenes whose form-factor matrix needs more memory than this.
    #[arg(long, default_value_t = 4096, value_name = "MIB")]
    gather_cap_mib: u64,
    /// adaptive-hybrid: switch from hemi-cubes to rays at this shot instead of when the
    /// measured costs say so (the switch shot a summary.json recorded: an exact replay).
    #[arg(long, value_name = "SHOT")]
    switch_at: Option<u64>,
    /// Ray intersector: auto picks per scene (the rule is in `radiosity info`); merge needs a
    /// scene whose patches are all axis-aligned.
    #[arg(long, value_enum, default_value_t = IntersectorArg::Auto)]
    intersector: IntersectorArg,
}

/// `--intersector`: see `radiosity::intersect::select::IntersectorKind`.
#[derive(Clone, Copy, clap::ValueEnum)]
enum IntersectorArg {
    Auto,
    Embree,
    Merge,
    Hybrid,
}

impl From<IntersectorArg> for IntersectorKind {
    fn from(a: IntersectorArg) -> IntersectorKind {
        match a {
            IntersectorArg::Auto => IntersectorKind::Auto,
            IntersectorArg::Embree => IntersectorKind::Embree,
            IntersectorArg::Merge => IntersectorKind::Merge,
            IntersectorArg::Hybrid => IntersectorKind::Hybrid,
        }
    }
}

/// `bench intersect --source`.
#[derive(Clone, Copy, clap::ValueEnum)]
enum RaysArg {
    Both,
    Surface,
    Uniform,
}

#[derive(Args)]
struct SweepArgs {
    /// Building sizes in patches (1k = 1000, 1M = 1000000).
    #[arg(long, value_parser = parse_sizes, default_value = "1k,4k,16k,64k,256k,1M")]
    sizes: Sizes,
    /// Methods to run at every size.
    #[arg(
        long,
        value_enum,
        value_delimiter = ',',
        default_value = "adaptive-hybrid"
    )]
    methods: Vec<Method>,
    #[command(flatten)]
    solve_args: SolverArgs,
    /// Output folder (sweep.csv, sweep.md, time.png, memory.png).
    #[arg(long)]
    out: PathBuf,
    /// Seed of the generated buildings.
    #[arg(long, default_value_t = 1)]
    building_seed: u64,
}

/// A list of patch counts.
#[derive(Clone)]
struct Sizes(Vec<usize>);

fn parse_sizes(s: &str) -> Result<Sizes, String> {
    if s.trim().is_empty() || s.trim() == "none" {
        return Ok(Sizes(Vec::new()));
    }
    s.split(',')
        .map(|p| {
            let p = p.trim();
            let (num, mul) = match p.chars().last() {
                Some('k' | 'K') => (&p[..p.len() - 1], 1_000.0),
                Some('M' | 'm') => (&p[..p.len() - 1], 1_000_000.0),
                _ => (p, 1.0),
            };
            match num.parse::<f64>() {
                Ok(v) if v > 0.0 && (v * mul) <= 1e7 => Ok((v * mul).round() as usize),
                _ => Err(format!(
                    "'{p}' is not a patch count between 1 and 10M (like 1000, 10k or 1M)"
                )),
            }
        })
        .collect::<Result<Vec<_>, _>>()
        .map(Sizes)
}

/// `--light-groups`.
#[derive(Clone, Copy, clap::ValueEnum)]
enum LightGroupsArg {
    /// One channel per emitting material.
    Material,
    /// One channel per connected emitting surface (fixtures of one material apart).
    Connected,
}

impl From<LightGroupsArg> for radiosity::solve::lights::GroupBy {
    fn from(a: LightGroupsArg) -> Self {
        match a {
            LightGroupsArg::Material => radiosity::solve::lights::GroupBy::Material,
            LightGroupsArg::Connected => radiosity::solve::lights::GroupBy::Connected,
        }
    }
}

/// `--method`: see `radiosity::solve::MethodKind`.
#[derive(Clone, Copy, clap::ValueEnum)]
enum Method {
    /// Shooting with the paper's adaptive polar hemisphere ray sampler (Sec. 2).
    AdaptiveRays,
    /// Shooting with the uniform N×N hemi-cube (Cohen & Greenberg 1985): the baseline.
    Hemicube,
    /// The uniform hemi-cube with jittered sample points (the paper's Table 1).
    HemicubeJittered,
    /// Shooting with the paper's non-uniform hemi-cube, resolution from the unshot energy.
    AdaptiveHemicube,
    /// Adaptive hemi-cube first, adaptive rays once measured cheaper (Sec. 4).
    AdaptiveHybrid,
    /// The traditional algorithm: full form-factor matrix, then Gauss–Seidel.
    Gathering,
}

impl From<Method> for MethodKind {
    fn from(m: Method) -> MethodKind {
        match m {
            Method::AdaptiveRays => MethodKind::AdaptiveRays,
            Method::Hemicube => MethodKind::Hemicube,
            Method::HemicubeJittered => MethodKind::HemicubeJittered,
            Method::AdaptiveHemicube => MethodKind::AdaptiveHemicube,
            Method::AdaptiveHybrid => MethodKind::AdaptiveHybrid,
            Method::Gathering => MethodKind::Gathering,
        }
    }
}

#[derive(Args)]
struct SolveArgs {
    /// OBJ file (with its MTL beside it); the built-in Cornell box if left out.
    scene: Option<PathBuf>,
    #[command(flatten)]
    scene_args: SceneArgs,
    #[command(flatten)]
    solve_args: SolverArgs,
    /// Output folder.
    #[arg(long, default_value = "out")]
    out: PathBuf,
    /// A reference patch table (a patches.csv of the same scene and patch size, e.g. from
    /// `radiosity reference`): the trace then records the error against it.
    #[arg(long, value_name = "PATCHES.csv")]
    reference: Option<PathBuf>,
    #[command(flatten)]
    view: ViewArgs,
    /// Print nothing but errors.
    #[arg(long, short)]
    quiet: bool,
    /// Print the JSON summary on stdout.
    #[arg(long)]
    json: bool,
    /// Also save the solution to this file (read by `render`, `export` and `relight`).
    #[arg(long, value_name = "FILE.rad")]
    save: Option<PathBuf>,
    /// Keep one channel per light (saved with --save), so `radiosity relight` can re-weight
    /// the lights without solving again.
    #[arg(long)]
    per_light: bool,
    /// Write the solver's state to this file (atomically) every --checkpoint-every seconds and
    /// on Ctrl-C; `--resume FILE` continues from it.
    #[arg(long, value_name = "FILE")]
    checkpoint: Option<PathBuf>,
    /// Seconds between checkpoints.
    #[arg(
        long,
        value_name = "SECONDS",
        default_value_t = 60.0,
        requires = "checkpoint",
        allow_negative_numbers = true
    )]
    checkpoint_every: f64,
    /// Continue a solve from a checkpoint of the same scene and settings.
    #[arg(long, value_name = "FILE")]
    resume: Option<PathBuf>,
    /// With --per-light: one channel per emitting material, or per connected emitting surface.
    #[arg(long, value_enum, default_value_t = LightGroupsArg::Material, requires = "per_light")]
    light_groups: LightGroupsArg,
}

fn parse_floats<const N: usize>(s: &str) -> Result<[f64; N], String> {
    let parts: Vec<&str> = s.split(',').collect();
    if parts.len() != N {
        return Err(format!("expected {N} comma-separated numbers, got '{s}'"));
    }
    let mut out = [0.0; N];
    for (o, p) in out.iter_mut().zip(parts) {
        let v: f64 = p
            .trim()
            .parse()
            .map_err(|_| format!("'{p}' is not a number"))?;
        if !v.is_finite() {
            return Err(format!("'{p}' is not a finite number"));
        }
        *o = v;
    }
    Ok(out)
}

fn parse_threads(s: &str) -> Result<usize, String> {
    match s.trim().parse::<usize>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err(format!(
            "'{s}' is not a thread count of at least 1 (leave --threads out for all cores)"
        )),
    }
}

/// A positive length in metres (`--patch-size`).
fn parse_length(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(v) if v > 0.0 && v.is_finite() => Ok(v),
        _ => Err(format!("'{s}' is not a positive length in metres")),
    }
}

/// A command-line error of clap's on one line: its message without the usage and help lines
/// (help and version go to stdout as clap prints them).
fn clap_error_line(e: &clap::Error) -> String {
    let text = e.render().to_string();
    let mut parts = Vec::new();
    for line in text.lines() {
        let line = line.trim();
        if line.starts_with("Usage:") || line.starts_with("For more information") {
            break;
        }
        if !line.is_empty() {
            parts.push(line);
        }
    }
    parts.join(" ")
}

fn parse_vec3(s: &str) -> Result<Vec3, String> {
    let v = parse_floats::<3>(s)?;
    Ok(Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32))
}

fn parse_emit(s: &str) -> Result<(String, [f64; 3]), String> {
    let (name, rgb) = s
        .split_once('=')
        .ok_or_else(|| format!("expected MATERIAL=R,G,B, got '{s}'"))?;
    let rgb = parse_floats::<3>(rgb)?;
    if rgb.iter().any(|&x| x < 0.0) {
        return Err(format!("emission must not be negative, got '{s}'"));
    }
    Ok((name.to_string(), rgb))
}

fn source(scene: Option<PathBuf>) -> SceneSource {
    scene.map_or(SceneSource::Default, SceneSource::File)
}

impl SceneArgs {
    fn load(&self) -> LoadOptions {
        LoadOptions {
            emit: self.emit.clone(),
        }
    }
    fn mesh(&self) -> MeshOptions {
        MeshOptions {
            patch_size: self.patch_size,
            two_sided: self.two_sided,
        }
    }
}

impl SolverArgs {
    fn config(&self) -> Result<SolveSettings, radiosity::Error> {
        let max_time = match self.max_time {
            Some(t) if !(t > 0.0 && t.is_finite()) => {
                return Err(radiosity::Error::Invalid(format!(
                    "--max-time must be a positive number of seconds, got {t}"
                )))
            }
            t => t,
        };
        if let Some(c) = self.energy_per_ray {
            if !(c > 0.0 && c.is_finite()) {
                return Err(radiosity::Error::Invalid(format!(
                    "--energy-per-ray must be a positive number of watts, got {c}"
                )));
            }
        }
        Ok(SolveSettings {
            seed: self.seed,
            tolerance: self.tolerance,
            energy_per_ray: self.energy_per_ray,
            stop_fraction: self.stop,
            max_time,
            max_rays: self.max_rays,
            jitter: !self.polar_centres,
            method: self.method.into(),
            hemicube_n: self.hemicube_n,
            gather_cap_mib: self.gather_cap_mib,
            switch_at: self.switch_at,
            ..SolveSettings::default()
        })
    }
}

fn run(cli: Cli) -> Result<(), radiosity::Error> {
    match cli.command {
        Command::Solve(a) => {
            let job = SolveJob {
                source: source(a.scene),
                load: a.scene_args.load(),
                mesh: a.scene_args.mesh(),
                solve: a.solve_args.config()?,
                out: a.out.clone(),
                reference: a.reference.clone(),
                intersector: a.solve_args.intersector.into(),
                camera: a.view.camera(),
                render: a.view.render(),
                save: a.save.clone(),
                per_light: a.per_light.then_some(a.light_groups.into()),
                checkpoint: a.checkpoint.clone(),
                checkpoint_every: a.checkpoint_every,
                resume: a.resume.clone(),
                interrupt: Some(interrupt_flag()),
            };
            let quiet = a.quiet || a.json;
            let progress = radiosity::progress::Progress::for_terminal(quiet);
            let summary = pipeline::run_solve_with(&job, &progress, |line| {
                if !quiet {
                    progress.println(line);
                }
            })?;
            drop(progress);
            if a.json {
                outln!(
                    "{}",
                    serde_json::to_string_pretty(&summary).unwrap_or_default()
                );
            } else if !a.quiet {
                outln!(
                    "{}: {} patches, {} shots, {} rays in {:.2} s; {}; energy balance residual {:.1e}; outputs in {}{}",
                    summary.scene,
                    summary.patches,
                    summary.shots,
                    summary.rays,
                    summary.seconds.total,
                    summary.error_line(),
                    summary.energy.relative_residual,
                    a.out.display(),
                    a.save
                        .as_ref()
                        .map(|p| format!(", solution saved to {}", p.display()))
                        .unwrap_or_default()
                );
            }
            if summary.stop_reason == Some(radiosity::solve::StopReason::Interrupted) {
                eprintln!(
                    "interrupted: the outputs hold the solution so far{}",
                    a.checkpoint
                        .as_ref()
                        .map(|p| format!("; continue with --resume {}", p.display()))
                        .unwrap_or_default()
                );
                std::process::exit(130);
            }
            Ok(())
        }
        Command::Render(a) => {
            let (json, quiet) = (a.json, a.quiet);
            let r = radiosity::outputs::run_render(&render_job(a))?;
            print_output_report(&r, json, quiet);
            Ok(())
        }
        Command::Relight(a) => {
            let (json, quiet) = (a.render.json, a.render.quiet);
            let job = radiosity::outputs::RelightJob {
                render: render_job(a.render),
                weights: a.weights,
            };
            let r = radiosity::outputs::run_relight(&job)?;
            print_output_report(&r, json, quiet);
            Ok(())
        }
        Command::Export(a) => {
            let job = radiosity::outputs::ExportJob {
                solution: a.solution,
                check: a.check.check(None),
                out: a.out,
                exposure: a.exposure,
            };
            let r = radiosity::outputs::run_export(&job)?;
            print_output_report(&r, a.json, a.quiet);
            Ok(())
        }
        Command::Generate(GenerateCommand::Building {
            out,
            floors,
            rooms,
            patches,
            seed,
        }) => {
            if floors == 0 || rooms == 0 {
                return Err(radiosity::Error::Invalid(
                    "--floors and --rooms must be at least 1".into(),
                ));
            }
            let opts = match patches {
                Some(n) => radiosity::generate::BuildingOptions::for_patches(n, seed),
                None => radiosity::generate::BuildingOptions {
                    floors,
                    rooms_per_floor: rooms,
                    seed,
                    ..Default::default()
                },
            };
            let st = generate_building(&out, &opts)?;
            outln!(
                "{}: {} floors × {} rooms, {} polygons, about {} patches at {} m, {} lights",
                out.display(),
                opts.floors,
                opts.rooms_per_floor,
                st.polygons,
                st.estimated_patches,
                radiosity::generate::BUILDING_PATCH_SIZE,
                st.lights
            );
            Ok(())
        }
        Command::Info {
            scene,
            scene_args,
            json,
        } => {
            let info = pipeline::info(&source(scene), &scene_args.load(), &scene_args.mesh())?;
            if json {
                outln!(
                    "{}",
                    serde_json::to_string_pretty(&info).unwrap_or_default()
                );
            } else {
                out!("{info}");
            }
            Ok(())
        }
        Command::Bench(BenchCommand::Shots {
            scene,
            scene_args,
            solve_args,
            resolutions,
            shooters,
            out,
        }) => {
            if let Some(&bad) = resolutions.iter().find(|&&n| !(2..=4096).contains(&n)) {
                return Err(radiosity::Error::Invalid(format!(
                    "--resolutions must be between 2 and 4096, got {bad}"
                )));
            }
            let b = radiosity::shot_bench::bench_shots(
                &source(scene),
                &scene_args.load(),
                &scene_args.mesh(),
                &solve_args.config()?,
                &resolutions,
                shooters,
            )?;
            out!("{}", b.markdown());
            if let Some(path) = out {
                radiosity::export::write_atomic(&path, |w| {
                    serde_json::to_writer_pretty(&mut *w, &b).map_err(std::io::Error::other)
                })?;
            }
            Ok(())
        }
        Command::Crosscheck(a) => crosscheck(a),
        Command::Reference(a) => {
            let job = ReferenceJob {
                source: source(a.scene),
                load: a.scene_args.load(),
                mesh: a.scene_args.mesh(),
                solve: SolveSettings {
                    seed: a.seed,
                    tolerance: a.tolerance,
                    stop_fraction: a.stop,
                    ..SolveSettings::default()
                },
                intersector: a.intersector.into(),
                out: a.out,
            };
            compare::run_reference(&job, |line| eprintln!("{line}")).map(|_| ())
        }
        Command::Sweep(a) => {
            if a.sizes.0.is_empty() {
                return Err(radiosity::Error::Invalid("--sizes names no size".into()));
            }
            let job = radiosity::sweep::SweepJob {
                sizes: a.sizes.0.clone(),
                methods: a.methods.iter().copied().map(MethodKind::from).collect(),
                cfg: a.solve_args.config()?,
                intersector: a.solve_args.intersector.into(),
                out: a.out.clone(),
                seed: a.building_seed,
            };
            let rows = radiosity::sweep::run(&job, |l| outln!("{l}"))?;
            outln!("{}", radiosity::sweep::markdown(&rows, &job.methods));
            outln!("outputs in {}", a.out.display());
            Ok(())
        }
        Command::Compare(a) => {
            if !(a.budget > 0.0 && a.budget.is_finite() && a.budget < 1e7) {
                return Err(radiosity::Error::Invalid(format!(
                    "--budget must be a positive number of seconds, got {}",
                    a.budget
                )));
            }
            let job = CompareJob {
                source: source(a.scene),
                load: a.scene_args.load(),
                mesh: a.scene_args.mesh(),
                methods: a.methods.into_iter().map(MethodKind::from).collect(),
                budget: Duration::from_secs_f64(a.budget),
                solve: SolveSettings {
                    seed: a.seed,
                    tolerance: a.tolerance,
                    stop_fraction: a.stop,
                    hemicube_n: a.hemicube_n,
                    gather_cap_mib: a.gather_cap_mib,
                    ..SolveSettings::default()
                },
                reference: a.reference,
                reference_solve: SolveSettings {
                    seed: a.seed.wrapping_add(1_000_003),
                    tolerance: a.reference_tolerance,
                    stop_fraction: a.reference_stop,
                    ..SolveSettings::default()
                },
                intersector: a.intersector.into(),
                levels: a.levels,
                repeat: a.repeat,
                out: a.out.clone(),
            };
            let cmp = compare::run_compare(&job, |line| eprintln!("{line}"))?;
            out!("{}", compare::report::markdown(&cmp));
            eprintln!("outputs in {}", a.out.display());
            Ok(())
        }
        Command::Bench(BenchCommand::Intersect {
            scenes,
            scene_args,
            generated,
            rays,
            seed,
            source: rays_from,
            out,
        }) => {
            use radiosity::intersect::crosscheck::RaySource;
            let rays_from = match rays_from {
                RaysArg::Both => None,
                RaysArg::Surface => Some(RaySource::Surface),
                RaysArg::Uniform => Some(RaySource::Uniform),
            };
            let sources: Vec<SceneSource> = scenes.into_iter().map(SceneSource::File).collect();
            let job = intersect_jobs::BenchJob {
                scenes: sources,
                generated: generated.0,
                load: scene_args.load(),
                mesh: scene_args.mesh(),
                rays,
                seed,
                rays_from,
            };
            let rows = intersect_jobs::bench_intersect(&job, |r| {
                eprintln!(
                    "{}: {} patches, embree {:.2}, hybrid {:.2} Mrays/s",
                    r.scene, r.shape.patches, r.embree.mrays, r.hybrid.mrays
                )
            })?;
            out!("{}", radiosity::intersect::bench::markdown(&rows));
            if let Some(path) = out {
                let text = radiosity::intersect::bench::csv(&rows);
                radiosity::export::write_atomic(&path, |w| w.write_all(text.as_bytes()))?;
            }
            Ok(())
        }
        Command::Bench(BenchCommand::Rays {
            scene,
            scene_args,
            solve_args,
            rays,
            min_seconds,
            out,
        }) => {
            if !(min_seconds >= 0.0 && min_seconds.is_finite()) {
                return Err(radiosity::Error::Invalid(format!(
                    "--min-seconds must be a non-negative number, got {min_seconds}"
                )));
            }
            let b = pipeline::bench_rays(
                &source(scene),
                &scene_args.load(),
                &scene_args.mesh(),
                &solve_args.config()?,
                solve_args.intersector.into(),
                rays,
                min_seconds,
            )?;
            outln!(
                "{}: {} triangles, {} patches, {} threads\n  raw {} closest hit: {:.2} Mrays/s ({} rays; {:.2} to {:.2} over the run)\n  solver:                 {:.2} Mrays/s ({} rays in {} solves)\n  solver / raw:           {:.0} %",
                b.scene,
                b.triangles,
                b.patches,
                b.threads,
                b.intersector,
                b.raw_rays_per_second / 1e6,
                b.raw_rays,
                b.raw_min_max[0] / 1e6,
                b.raw_min_max[1] / 1e6,
                b.solver_rays_per_second / 1e6,
                b.solver_rays,
                b.solves,
                100.0 * b.ratio
            );
            if let Some(path) = out {
                radiosity::export::write_atomic(&path, |w| {
                    serde_json::to_writer_pretty(&mut *w, &b).map_err(std::io::Error::other)?;
                    writeln!(w)
                })?;
            }
            Ok(())
        }
    }
}

fn crosscheck(a: CrosscheckArgs) -> Result<(), radiosity::Error> {
    let job = CrossJob {
        source: source(a.scene),
        load: a.scene_args.load(),
        mesh: a.scene_args.mesh(),
        rays: a.rays,
        seed: a.seed,
        eps: a.eps,
        closed: match (a.open, a.closed) {
            (true, _) => Some(false),
            (_, true) => Some(true),
            _ => None,
        },
    };
    let c = intersect_jobs::crosscheck(&job)?;
    let json = serde_json::to_string_pretty(&c).unwrap_or_default();
    if a.json {
        outln!("{json}");
    } else {
        out!("{c}");
    }
    if let Some(path) = a.out {
        let text = if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("json"))
        {
            json + "\n"
        } else {
            c.to_string()
        };
        radiosity::export::write_atomic(&path, |w| w.write_all(text.as_bytes()))?;
    }
    if c.report.passed {
        Ok(())
    } else {
        Err(radiosity::Error::Failed(format!(
            "{}: the cross-check bar failed: {}",
            c.scene,
            c.report.failures.join("; ")
        )))
    }
}

fn render_job(a: RenderArgs) -> radiosity::outputs::RenderJob {
    radiosity::outputs::RenderJob {
        solution: a.solution,
        check: a.check.check(None),
        out: a.out,
        camera: a.view.camera(),
        render: a.view.render(),
        false_colour: a.false_colour,
    }
}

/// The one-line report of `render` and `export`, or its JSON.
fn print_output_report(r: &radiosity::outputs::OutputReport, json: bool, quiet: bool) {
    if json {
        outln!("{}", serde_json::to_string_pretty(r).unwrap_or_default());
    } else if !quiet {
        let extra = match (&r.scale, r.exposure) {
            (Some(s), _) => format!(", irradiance {}–{} W/m² on a log scale", s.lo, s.hi),
            (None, Some(e)) => format!(", exposure {e:.4}"),
            (None, None) => ", linear radiosity in W/m²".to_string(),
        };
        outln!(
            "{}: {} of {} ({} patches, {} vertices){extra}",
            r.out,
            r.format,
            r.scene,
            r.patches,
            r.vertices
        );
    }
}

fn generate_building(
    out: &std::path::Path,
    opts: &radiosity::generate::BuildingOptions,
) -> Result<radiosity::generate::BuildingStats, radiosity::Error> {
    use radiosity::export::write_atomic;
    let mtl_path = out.with_extension("mtl");
    let mtl_name = mtl_path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "building.mtl".into());
    let mut mtl_text = Vec::new();
    let mut stats = None;
    write_atomic(out, |w| {
        stats = Some(radiosity::generate::write_building(
            w,
            &mut mtl_text,
            &mtl_name,
            opts,
        )?);
        Ok(())
    })?;
    write_atomic(&mtl_path, |w| w.write_all(&mtl_text))?;
    stats.ok_or_else(|| radiosity::Error::Invalid("the generator wrote nothing".into()))
}

/// Ctrl-C asks the solve to stop at its next safe point (writing a checkpoint if asked, then
/// its outputs); a second Ctrl-C ends the process at once.
fn interrupt_flag() -> std::sync::Arc<std::sync::atomic::AtomicBool> {
    use std::sync::atomic::{AtomicBool, Ordering};
    let flag = std::sync::Arc::new(AtomicBool::new(false));
    let f = flag.clone();
    let _ = ctrlc::set_handler(move || {
        if f.swap(true, Ordering::SeqCst) {
            std::process::exit(130);
        }
        eprintln!("\nstopping at the next safe point (Ctrl-C again to quit at once)…");
    });
    flag
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e)
            if !e.use_stderr()
                || e.kind() == clap::error::ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand =>
        {
            let _ = e.print();
            return ExitCode::from(e.exit_code() as u8);
        }
        Err(e) => {
            eprintln!("{}", clap_error_line(&e));
            return ExitCode::from(2);
        }
    };
    let threads = cli.threads.unwrap_or(0);
    if let Err(e) = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .start_handler(|_| radiosity::intersect::embree::set_flush_denormals())
        .build_global()
    {
        eprintln!("Error: cannot start worker threads: {e}");
        return ExitCode::from(1);
    }
    radiosity::intersect::embree::set_flush_denormals();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("Error: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
