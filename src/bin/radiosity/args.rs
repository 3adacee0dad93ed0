//! Flag groups shared by several commands, each declared once, and the values they parse to.
//! Defaults are the library's constants; every range check is the library's (the settings
//! types check themselves), so the commands refuse the same values with the same words.

use clap::Args;
use glam::Vec3;
use radiosity::intersect::select::IntersectorKind;
use radiosity::mesh::MeshOptions;
use radiosity::render::gather::{DEFAULT_INDIRECT_SPACING, DEFAULT_PIXEL_RAYS};
use radiosity::render::view::{image_size, DEFAULT_SUPERSAMPLE};
use radiosity::render::view_file::RadianceView;
use radiosity::render::{CameraSpec, RenderOptions, Shading, ShadingSettings, ViewSettings};
use radiosity::saved::SceneCheck;
use radiosity::scene::{LoadOptions, SceneSource};
use radiosity::solve::settings::{
    DEFAULT_FINAL_GATHER, DEFAULT_GATHER_CAP_MIB, DEFAULT_GATHER_RAYS, DEFAULT_HEMICUBE_N,
};
use radiosity::solve::{MethodKind, SolveSettings, SwitchBy};
use std::path::PathBuf;

/// How the scene is read and cut into patches.
#[derive(Args, Clone)]
pub struct SceneArgs {
    /// Make a material emit: MATERIAL=R,G,B emitted radiance in W/sr/m² (the unit of MTL Ke);
    /// repeatable. For models that ship without Ke.
    #[arg(long, value_name = "MATERIAL=R,G,B", value_parser = parse_emit)]
    pub emit: Vec<(String, [f64; 3])>,
    /// Longest patch edge in metres (default: derived from the scene, and printed).
    #[arg(long, value_name = "METRES", allow_negative_numbers = true)]
    pub patch_size: Option<f32>,
    /// Make every polygon two-sided: a back patch of its own, lit from behind (thin surfaces;
    /// models with mixed winding). Lights still shine from their front only.
    #[arg(long, conflicts_with = "one_sided")]
    pub two_sided: bool,
    /// Keep every face one-sided as its winding says: light meeting a back is absorbed there.
    /// By default the faces that light meets from behind (mixed winding, rooms inside out) get
    /// back patches of their own, found by a quick first shooting.
    #[arg(long)]
    pub one_sided: bool,
    /// Cut patches to the patch size only. By default a patch is cut finer (to 1/8 of the size
    /// at most) where a light close to it bends its light across it by more than the scene's
    /// mean irradiance: a hot spot under a hung panel is not averaged away.
    #[arg(long)]
    pub uniform_patches: bool,
    /// Turn every polygon round: for models wound clockwise (rooms inside out, lights facing
    /// away from them).
    #[arg(long)]
    pub flip: bool,
    /// Luminaires to place in the model: a schedule (CSV or JSON) naming for each its IES or
    /// EULUMDAT file, position x,y,z, and optionally an aim point, spin, count and step,
    /// light-loss factor, colour and group (README, "Luminaires"). They shoot first and light
    /// the final gather, the grid and the picture exactly, by shadow rays.
    #[arg(long, value_name = "FILE")]
    pub luminaires: Option<PathBuf>,
    /// Multiply the model's coordinates by this to make metres: 0.001 for a model in
    /// millimetres, 0.01 in centimetres, 0.0254 in inches (a model far too large for a
    /// building gets a warning naming this flag). Its own lights move with it; a
    /// --luminaires schedule is in metres.
    #[arg(long, value_name = "FACTOR", allow_negative_numbers = true)]
    pub scale: Option<f64>,
}

impl SceneArgs {
    pub fn load(&self) -> LoadOptions {
        LoadOptions {
            emit: self.emit.clone(),
            flip: self.flip,
            luminaires: self.luminaires.clone(),
            zenith: None,
            scale: self.scale,
        }
    }
    pub fn mesh(&self) -> MeshOptions {
        MeshOptions {
            patch_size: self.patch_size,
            two_sided: self.two_sided,
            one_sided: self.one_sided,
            uniform_patches: self.uniform_patches,
        }
    }
}

/// The optional scene argument: a file, or the built-in Cornell box.
pub fn source(scene: Option<PathBuf>) -> SceneSource {
    SceneSource::from_arg(scene)
}

/// How form factors are sampled: the settings every command that solves shares (`solve`,
/// `compare`, `reference`, `sweep`, `bench rays`, `bench shots`). Left out, a value takes the
/// command's own default (the solver's, or the reference's for `radiosity reference`).
#[derive(Args, Clone)]
pub struct SamplingArgs {
    /// Seed of all random choices; the same seed gives the same result on any run and thread
    /// count [default: 1].
    #[arg(long)]
    pub seed: Option<u64>,
    /// Relative sampling error wanted for a typical patch's radiosity. Sets the energy each ray
    /// carries (Sec. 2: rays in proportion to unshot energy): about patches/tolerance² rays in
    /// all, so halving it costs 4× the rays. Left out, a solve with an error target shoots its
    /// first pass at 2× the error target, and its final gather makes the estimate
    /// [default: 0.05; reference: 0.005].
    #[arg(long, allow_negative_numbers = true)]
    pub tolerance: Option<f64>,
    /// Energy per ray C in watts (overrides --tolerance).
    #[arg(long, value_name = "WATTS", allow_negative_numbers = true)]
    pub energy_per_ray: Option<f64>,
    /// Stop when the max unshot radiosity is below this fraction of the mean radiosity
    /// (paper Sec. 3) [default: 0.0006; reference: 1e-5].
    #[arg(long, value_name = "FRACTION", allow_negative_numbers = true)]
    pub stop: Option<f64>,
    /// Aim rays at the centres of the polar cells, as the paper does, instead of at random
    /// points inside them (biased at low ray counts; for comparison).
    #[arg(long)]
    pub polar_centres: bool,
    /// Resolution N of the uniform N×N hemi-cube (methods hemicube, hemicube-jittered,
    /// gathering).
    #[arg(long, default_value_t = DEFAULT_HEMICUBE_N, value_name = "N")]
    pub hemicube_n: usize,
    /// Gathering refuses scenes whose form-factor matrix needs more memory than this.
    #[arg(long, default_value_t = DEFAULT_GATHER_CAP_MIB, value_name = "MIB")]
    pub gather_cap_mib: u64,
    /// Ray intersector: auto picks per scene (the rule is in `radiosity info`); merge needs a
    /// scene whose patches are all axis-aligned.
    #[arg(long, value_enum, default_value_t = IntersectorKind::default())]
    pub intersector: IntersectorKind,
    /// After shooting, every patch gathers its own light with rays: shadow rays to the lights
    /// and hemisphere rays (followed on through narrow gaps), weighed against the shooting's
    /// estimate (methods that cast rays).
    #[arg(long, value_enum, default_value_t = OnOff::from(DEFAULT_FINAL_GATHER), value_name = "on|off")]
    pub final_gather: OnOff,
    /// Rays per gathered patch at the default tolerance, growing as 1/tolerance² with a finer
    /// one (half to the lights, half over the hemisphere). With an error target, the most the
    /// first gather casts: a pilot of a quarter of them on a sample of the patches picks the
    /// fewest rays per patch it predicts to reach 0.9× the target, and further rounds add rays
    /// where the error is.
    #[arg(long, default_value_t = DEFAULT_GATHER_RAYS, value_name = "N")]
    pub gather_rays: usize,
}

/// A switch flag's value (`--final-gather on|off`).
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum OnOff {
    On,
    Off,
}

impl From<bool> for OnOff {
    fn from(b: bool) -> OnOff {
        if b {
            OnOff::On
        } else {
            OnOff::Off
        }
    }
}

impl std::fmt::Display for OnOff {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(if *self == OnOff::On { "on" } else { "off" })
    }
}

impl SamplingArgs {
    /// These flags over `base` (the command's defaults).
    pub fn over(&self, base: SolveSettings) -> SolveSettings {
        SolveSettings {
            seed: self.seed.unwrap_or(base.seed),
            tolerance: self.tolerance.unwrap_or(base.tolerance),
            energy_per_ray: self.energy_per_ray.or(base.energy_per_ray),
            stop_fraction: self.stop.unwrap_or(base.stop_fraction),
            jitter: base.jitter && !self.polar_centres,
            hemicube_n: self.hemicube_n,
            gather_cap_mib: self.gather_cap_mib,
            final_gather: self.final_gather == OnOff::On,
            gather_rays: self.gather_rays,
            ..base
        }
    }
}

/// The method and the budgets of one solve.
#[derive(Args, Clone)]
pub struct SolverArgs {
    #[command(flatten)]
    pub sampling: SamplingArgs,
    /// Stop after this many seconds of solving, whatever the criterion says.
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true)]
    pub max_time: Option<f64>,
    /// Stop after about this many form-factor samples (rays, plus hemi-cube cells).
    #[arg(long)]
    pub max_rays: Option<u64>,
    /// Keep refining until the solver's own estimate of the average weighted percent error is at
    /// most this fraction (0.02 = 2 %), or --max-time/--max-rays stops it: independent passes,
    /// averaged, so the error keeps falling for as long as the run is allowed. `off`: one pass,
    /// stopped by --tolerance's sampling alone. [default for `solve` with adaptive-hybrid or
    /// adaptive-rays: 0.05, giving up after 8× the first pass's rays; off otherwise]
    #[arg(long = "error", value_name = "FRACTION|off", value_parser = parse_error_target, allow_negative_numbers = true)]
    pub error_target: Option<ErrorTarget>,
    /// How form factors are sampled.
    #[arg(long, value_enum, default_value_t = MethodKind::default())]
    pub method: MethodKind,
    /// adaptive-hybrid: switch from hemi-cubes to rays at this shot instead of when the cost
    /// model says so (the switch shot a summary.json recorded).
    #[arg(long, value_name = "SHOT")]
    pub switch_at: Option<u64>,
    /// adaptive-hybrid: decide the switch from counted work weighed by the kept cost constants
    /// (reproducible on every run), or from times measured during the solve (adapts to the
    /// machine; the result then varies from run to run).
    #[arg(long, value_enum, default_value_t = SwitchBy::default())]
    pub switch_by: SwitchBy,
}

/// `--error`: a fraction, or `off`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ErrorTarget {
    Off,
    At(f64),
}

fn parse_error_target(s: &str) -> Result<ErrorTarget, String> {
    match s {
        "off" | "none" => Ok(ErrorTarget::Off),
        _ => s
            .parse::<f64>()
            .map(ErrorTarget::At)
            .map_err(|_| format!("expected a fraction such as 0.02, or off; got '{s}'")),
    }
}

impl SolverArgs {
    /// The settings, with no error target unless `--error` gives one.
    pub fn settings(&self) -> SolveSettings {
        let error_target = match self.error_target {
            None | Some(ErrorTarget::Off) => None,
            Some(ErrorTarget::At(e)) => Some(e),
        };
        SolveSettings {
            method: self.method,
            max_time: self.max_time,
            max_rays: self.max_rays,
            error_target,
            switch_at: self.switch_at,
            switch_by: self.switch_by,
            ..self.sampling.over(SolveSettings::default())
        }
        .with_target_tolerance(self.sampling.tolerance.is_some())
    }

    /// The settings of `radiosity solve`: without `--error`, the library's default error
    /// policy ([`SolveSettings::with_solve_default_error`]).
    pub fn solve_settings(&self) -> SolveSettings {
        let s = self.settings();
        match self.error_target {
            None => (s.with_solve_default_error())
                .with_target_tolerance(self.sampling.tolerance.is_some()),
            Some(_) => s,
        }
    }

    pub fn intersector(&self) -> IntersectorKind {
        self.sampling.intersector
    }
}

/// The camera and the image (`solve`, `render`, `relight`).
#[derive(Args)]
pub struct ViewArgs {
    /// The camera from a Radiance view file, as `rvu` saves and `rpict -vf` reads
    /// (`rvu -vtv -vp X Y Z -vd X Y Z -vu X Y Z -vh DEG -vv DEG …`, or a picture's `VIEW=`
    /// line; perspective -vtv and parallel -vtl). The picture is exactly the view's field:
    /// its aspect comes from -vh/-vv (see --width). Not with --eye/--target/--up/--fov.
    #[arg(long, value_name = "FILE")]
    pub view: Option<PathBuf>,
    /// Camera position X,Y,Z (default: fitted to the scene, looking along −z).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub eye: Option<Vec3>,
    /// Point the camera looks at X,Y,Z (default: the scene's centre).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub target: Option<Vec3>,
    /// Camera up direction X,Y,Z (default 0,1,0).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub up: Option<Vec3>,
    /// Vertical field of view in degrees.
    #[arg(long, allow_negative_numbers = true)]
    pub fov: Option<f32>,
    /// Nothing nearer than this distance along the view direction is drawn (metres, scene
    /// units): a camera inside a wall's thickness, or behind a wall, sees past it. Radiance's
    /// -vo; overrides a view file's [default: a tiny distance, nothing clipped].
    #[arg(long, value_name = "DIST", allow_negative_numbers = true)]
    pub near: Option<f32>,
    /// Image width in pixels [default: 640]. With --view the height follows from the view's
    /// aspect; with --view, --width and --height together are a box the picture is fitted
    /// into (the side too long for the view shrinks, as rpict -x -y).
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height in pixels [default: 480]. With --view alone, it sets the height and the
    /// width follows.
    #[arg(long)]
    pub height: Option<u32>,
    /// Samples per pixel along each axis (edges anti-aliased by s×s supersampling).
    #[arg(long, default_value_t = DEFAULT_SUPERSAMPLE)]
    pub supersample: u32,
    /// Exposure multiplier on radiosity for PNG (default: automatic).
    #[arg(long, allow_negative_numbers = true)]
    pub exposure: Option<f32>,
}

impl ViewArgs {
    /// The view; an unreadable or bad `--view` file is an error naming it.
    pub fn settings(&self) -> Result<ViewSettings, radiosity::Error> {
        let view = match &self.view {
            Some(path) => Some(RadianceView::read(path)?),
            None => None,
        };
        let camera = CameraSpec {
            eye: self.eye,
            target: self.target,
            up: self.up,
            fov_y_deg: self.fov,
            near: self.near,
            view,
        };
        let (width, height) = image_size(&camera, self.width, self.height);
        Ok(ViewSettings {
            camera,
            image: RenderOptions {
                width,
                height,
                supersample: self.supersample,
                exposure: self.exposure,
            },
        })
    }
}

/// How a picture is shaded (`solve`, `render`, `relight`).
#[derive(Args)]
pub struct ShadingArgs {
    /// gather: each pixel gathers its light with rays (direct light sampled with shadow rays,
    /// so shadows are sharp whatever the patch size; indirect light from the solved radiosity);
    /// gouraud: the solution's patches interpolated at their vertices, the fast preview
    /// [default: gather for render and relight, gouraud for solve]
    #[arg(long, value_enum)]
    pub shading: Option<Shading>,
    /// --shading gather: rays gathered per anti-aliasing sample (half to the lights, the rest
    /// over the hemisphere); --supersample sets the samples per pixel.
    #[arg(long, default_value_t = DEFAULT_PIXEL_RAYS, value_name = "N")]
    pub pixel_rays: usize,
    /// --shading gather: pixels between the points where the indirect light is gathered
    /// (each with the hemisphere rays of several pixels) and interpolated from over one
    /// surface; the direct light is still sampled at every pixel. 0: gathered at every sample.
    #[arg(long, default_value_t = DEFAULT_INDIRECT_SPACING, value_name = "PIXELS")]
    pub indirect_spacing: usize,
}

impl ShadingArgs {
    /// The settings, with the pixels' random numbers seeded by `seed`; `default` where
    /// `--shading` is left out (the command's own).
    pub fn settings(&self, seed: u64, default: Shading) -> ShadingSettings {
        ShadingSettings {
            shading: self.shading.unwrap_or(default),
            rays: self.pixel_rays,
            seed,
            indirect_spacing: self.indirect_spacing,
        }
    }
}

/// Checking a saved solution against its scene (optional).
#[derive(Args, Clone)]
pub struct CheckArgs {
    /// Refuse the solution unless it was solved on this OBJ (same geometry and reflectances;
    /// emission may differ).
    #[arg(long, value_name = "FILE.obj")]
    pub scene: Option<PathBuf>,
    /// With --scene: the patch size to check too (default: the solution's own).
    #[arg(long, value_name = "METRES", requires = "scene")]
    pub check_patch_size: Option<f32>,
}

impl CheckArgs {
    pub fn check(&self) -> Option<SceneCheck> {
        self.scene.as_ref().map(|p| SceneCheck {
            source: SceneSource::File(p.clone()),
            load: LoadOptions::default(),
            patch_size: self.check_patch_size,
            two_sided: None,
        })
    }
}

/// A list of patch counts.
#[derive(Clone)]
pub struct Sizes(pub Vec<usize>);

pub fn parse_sizes(s: &str) -> Result<Sizes, String> {
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

pub fn parse_floats<const N: usize>(s: &str) -> Result<[f64; N], String> {
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

pub fn parse_threads(s: &str) -> Result<usize, String> {
    match s.trim().parse::<usize>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err(format!(
            "'{s}' is not a thread count of at least 1 (leave --threads out for all cores)"
        )),
    }
}

pub fn parse_vec3(s: &str) -> Result<Vec3, String> {
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

pub fn parse_weight(s: &str) -> Result<(String, f64), String> {
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

/// A direction flag's value X,Y,Z, shown in `--help` as it is typed (`0,1,0`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Xyz(pub Vec3);

impl Xyz {
    pub fn parse(s: &str) -> Result<Xyz, String> {
        parse_vec3(s).map(Xyz)
    }
}

impl std::fmt::Display for Xyz {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{},{},{}", self.0.x, self.0.y, self.0.z)
    }
}
