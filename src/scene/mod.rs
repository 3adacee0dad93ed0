//! The scene as loaded: polygons, materials (reflectance ρ, emission), and the lights.
//!
//! This module owns everything that knows about model files: OBJ/MTL (`obj/`, the only code
//! that touches `tobj`), glTF 2.0 ([`gltf`], the only code that reads glTF; docs/design.md §13)
//! and the built-in default scene (`default.rs`). Downstream code sees only [`Scene`].
//!
//! Units (docs/design.md §1): metres; MTL `Ke` is emitted *radiance* (W/sr/m²) as path tracers and
//! Radiance read it, so a Lambertian emitter's radiosity is E = π·Ke (W/m²).

mod default;
pub mod gltf;
mod obj;
pub mod sides;

pub use default::{default_scene, DEFAULT_SCENE_MTL, DEFAULT_SCENE_NAME, DEFAULT_SCENE_OBJ};
pub use gltf::{is_gltf, load_gltf, load_gltf_from_slice};
pub use obj::{load_obj, load_obj_from_strs, LoadOptions, SceneError};

use glam::Vec3;
use std::f64::consts::PI;
use std::path::PathBuf;

/// Where a scene comes from.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SceneSource {
    /// The built-in Cornell box.
    Default,
    File(PathBuf),
}

impl SceneSource {
    /// `Some(path)` as a file, `None` as the built-in scene (the command line's optional
    /// scene argument).
    pub fn from_arg(path: Option<PathBuf>) -> SceneSource {
        path.map_or(SceneSource::Default, SceneSource::File)
    }

    /// Loads the scene (OBJ, or glTF by the file's extension `.gltf`/`.glb`), scales it by
    /// `--scale` (its lights too), warns of a size implausible for a building, and reads the
    /// luminaires' schedule when the options name one.
    pub fn load(&self, opts: &LoadOptions) -> Result<Scene, SceneError> {
        let mut scene = match self {
            SceneSource::Default => default_scene(opts),
            SceneSource::File(p) if is_gltf(p) => load_gltf(p, opts),
            SceneSource::File(p) => load_obj(p, opts),
        }?;
        if let Some(s) = opts.scale.filter(|s| *s != 1.0) {
            scene.scale(s);
        }
        if let Some(w) = size_warning(&scene, opts.scale) {
            scene.warnings.push(w);
        }
        if let Some(path) = &opts.luminaires {
            let zenith = Vec3::from(opts.zenith.unwrap_or(crate::sky::DEFAULT_ZENITH.to_array()));
            let placed = crate::luminaire::read_schedule(path, zenith.as_dvec3())
                .map_err(|e| SceneError::from_line(&path.display().to_string(), &e.to_string()))?;
            // After the model's own lights (a glTF's), which keep their places in the list.
            scene.luminaires.extend(placed);
        }
        Ok(scene)
    }
}

/// A model wider than this (metres, its largest extent) is implausible for a building: a
/// warning names `--scale` (an export in millimetres of a 6 m room is 6,000 units across).
pub const MAX_PLAUSIBLE_SIZE: f64 = 3_000.0;

/// The warning for a model whose largest extent is above [`MAX_PLAUSIBLE_SIZE`], naming the
/// scale that would make it metres if it is in millimetres, centimetres or inches.
fn size_warning(scene: &Scene, scale: Option<f64>) -> Option<String> {
    let (lo, hi) = scene.bounds();
    let size = f64::from((hi - lo).max_element());
    if size <= MAX_PLAUSIBLE_SIZE {
        return None;
    }
    let given = match scale {
        Some(s) => format!(" after --scale {s}"),
        None => String::new(),
    };
    Some(format!(
        "{}: the model is {size:.0} m across{given}, implausible for a building: if its units \
         are not metres give --scale (0.001 for millimetres, 0.01 for centimetres, 0.0254 for \
         inches)",
        scene.name
    ))
}

/// A sun given by the model itself (a glTF directional light), used when no `--sun` is given.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelSun {
    /// The light's name, for messages.
    pub name: String,
    /// Unit vector from the model towards the sun.
    pub towards: glam::DVec3,
    /// Illuminance on a plane facing the sun, lux.
    pub illuminance: f64,
    /// Whether the light is white (the tool's sun is: a colour is left out, with a warning).
    pub white: bool,
}

/// The largest reflectance a material is given: an MTL `Kd` (or `Kd` × texture) of 1 or more
/// in a channel is clamped to this, with a warning. Below 1 because a closed room whose
/// surfaces all reflect everything (ρ = 1) never converges: no light is ever absorbed, so the
/// unshot energy never falls.
pub const MAX_REFLECTANCE: f64 = 0.98;

/// A diffuse material: reflectance ρ per RGB channel and emitted radiance `Ke`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Material {
    pub name: String,
    /// Diffuse reflectance ρ, each channel in [0, 1): MTL `Kd`, times the mean colour of its
    /// `map_Kd` texture where that loads, at most [`MAX_REFLECTANCE`] where that was 1 or more.
    pub rho: [f64; 3],
    /// Emitted radiance (MTL `Ke` or `--emit`), W/sr/m².
    pub ke: [f64; 3],
    /// Where [`Material::rho`] came from (shown by `radiosity info`).
    pub rho_source: RhoSource,
    /// Glazing (docs/design.md §9): the share of light that goes straight through, unchanged in
    /// direction (0 for opaque); for tinted glazing, the mean of
    /// [`Material::transmittance_rgb`]. A ray meeting a pane goes through with this
    /// probability (docs/design.md §9). ρ + transmittance ≤ 1; the rest is absorbed. Read from
    /// the MTL by `scene::obj`'s rule (`Tf`, `d`, `Tr`, `illum`).
    pub transmittance: f64,
    /// Tinted glazing's transmittance per channel T_c (`Tf`'s colour), ρ_c + T_c ≤ 1; `None`
    /// for grey glazing (every channel [`Material::transmittance`]) and for opaque materials.
    /// Kept apart from the mean so that grey glazing stays exactly what it was: its rays carry
    /// their energy on untouched (docs/design.md §9, "Tinted glazing").
    pub transmittance_rgb: Option<[f64; 3]>,
}

/// Where a material's reflectance ρ came from.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum RhoSource {
    /// MTL `Kd` (or given directly, as by a program that builds its scene).
    #[default]
    Kd,
    /// No `Kd`: the default grey.
    Default,
    /// MTL `Kd` (1 1 1 when the material has none) times `mean`, the mean colour in linear
    /// light of the `map_Kd` texture `file`.
    KdTimesTexture {
        file: String,
        kd: [f64; 3],
        mean: [f64; 3],
    },
    /// `fallback` alone (`Kd`, or the default grey): the `map_Kd` texture `file` did not
    /// load (a warning says why).
    TextureNotLoaded {
        file: String,
        fallback: Box<RhoSource>,
    },
    /// `from` gave `unclamped`, 1 or more in a channel; those channels are [`MAX_REFLECTANCE`].
    Clamped {
        unclamped: [f64; 3],
        from: Box<RhoSource>,
    },
}

impl std::fmt::Display for RhoSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let rgb = |v: &[f64; 3]| format!("{:.3} {:.3} {:.3}", v[0], v[1], v[2]);
        match self {
            RhoSource::Kd => write!(f, "Kd"),
            RhoSource::Default => write!(f, "default grey (no Kd)"),
            RhoSource::KdTimesTexture { file, kd, mean } => {
                write!(f, "Kd {} × mean of texture '{file}' {}", rgb(kd), rgb(mean))
            }
            RhoSource::TextureNotLoaded { file, fallback } => {
                write!(f, "{fallback} (texture '{file}' not loaded)")
            }
            RhoSource::Clamped { unclamped, from } => write!(
                f,
                "{from} = {}, clamped to {MAX_REFLECTANCE}",
                rgb(unclamped)
            ),
        }
    }
}

impl Material {
    /// Emitted radiosity E = π·Ke (W/m²) of a Lambertian emitter.
    pub fn emission(&self) -> [f64; 3] {
        self.ke.map(|k| PI * k)
    }

    pub fn is_emitter(&self) -> bool {
        self.ke.iter().any(|&k| k > 0.0)
    }

    /// Straight-through transmittance per channel T_c: the colour of tinted glazing, T in
    /// every channel otherwise.
    pub fn transmittance_rgb(&self) -> [f64; 3] {
        self.transmittance_rgb.unwrap_or([self.transmittance; 3])
    }

    /// The factor per channel T_c / T that a ray going through this glazing multiplies its
    /// energy by: it goes through with probability T (the mean, so that every ray that
    /// leaves a shooter carries the same energy, Sec. 2 of the paper), so its channels come
    /// out unbiased, T·(T_c/T) = T_c. Exactly 1 for grey glazing and opaque materials
    /// (docs/design.md §9, "Tinted glazing").
    pub fn tint(&self) -> [f64; 3] {
        match self.transmittance_rgb {
            Some(c) if self.transmittance > 0.0 => c.map(|t| t / self.transmittance),
            _ => [1.0; 3],
        }
    }

    /// Whether this glazing changes the colour of what goes through it.
    pub fn is_tinted(&self) -> bool {
        self.tint() != [1.0; 3]
    }
}

/// One face of the model: a run of `len` vertex indices starting at `first` in
/// [`Scene::indices`], wound counter-clockwise seen from the front.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Polygon {
    pub first: u32,
    pub len: u32,
    pub material: u32,
    /// The material of the back side, for a two-sided polygon (a doubled face merged at load
    /// time, [`sides`]); `None`: one-sided unless the mesh is built `--two-sided`.
    pub back_material: Option<u32>,
}

/// A loaded model. Flat arrays so a million-polygon model costs no allocation per face.
#[derive(Clone, Debug, Default)]
pub struct Scene {
    /// Where it came from (a path, or the built-in scene's name); used in messages.
    pub name: String,
    pub positions: Vec<Vec3>,
    /// Vertex indices of all polygons, back to back.
    pub indices: Vec<u32>,
    pub polygons: Vec<Polygon>,
    pub materials: Vec<Material>,
    /// Non-fatal problems met while loading (missing MTL, dropped zero-area faces, …).
    pub warnings: Vec<String>,
    /// The patch size the model's author intended, from a comment line
    /// `# radiosity: patch-size METRES` in the OBJ; used when no `--patch-size` is given.
    pub patch_size_hint: Option<f32>,
    /// Coincident polygons merged at load time ([`sides::merge_coincident`]).
    pub merged: sides::Merged,
    /// Luminaires placed in the model by a schedule (`--luminaires`): point sources with a
    /// photometric web, shot first and gathered exactly ([`crate::luminaire`]).
    pub luminaires: Vec<crate::luminaire::Luminaire>,
    /// The model's own sun (a glTF directional light), if it has one.
    pub sun: Option<ModelSun>,
}

impl Scene {
    /// The vertex indices of polygon `p`.
    pub fn polygon_indices(&self, p: &Polygon) -> &[u32] {
        &self.indices[p.first as usize..(p.first + p.len) as usize]
    }

    /// Axis-aligned bounds (min, max) of all positions used by polygons.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for &i in &self.indices {
            let p = self.positions[i as usize];
            lo = lo.min(p);
            hi = hi.max(p);
        }
        if self.indices.is_empty() {
            (Vec3::ZERO, Vec3::ZERO)
        } else {
            (lo, hi)
        }
    }

    /// Multiplies every position by `s` (`--scale`), and the positions of the model's own
    /// luminaires (a schedule read after is in metres already).
    pub fn scale(&mut self, s: f64) {
        for p in &mut self.positions {
            *p = (p.as_dvec3() * s).as_vec3();
        }
        for l in &mut self.luminaires {
            l.position *= s;
        }
    }

    /// Does any material emit?
    pub fn has_emitter(&self) -> bool {
        self.polygons
            .iter()
            .any(|p| self.materials[p.material as usize].is_emitter())
    }
}
