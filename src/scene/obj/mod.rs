//! OBJ + MTL loading through `tobj`: the only code in the crate that knows `tobj`.
//!
//! Polygons stay polygons (no triangulation: quads stay quads) and every model of the file is
//! appended to the flat arrays of [`Scene`]. MTL `Kd` × the mean colour of its `map_Kd` texture
//! (where that loads; linear light) becomes the reflectance ρ, clamped to
//! [`MAX_REFLECTANCE`](crate::scene::MAX_REFLECTANCE) where it is 1 or more (both with a
//! warning); MTL `Ke` becomes the emitted radiance (W/sr/m², docs/design.md §1), and
//! [`LoadOptions::emit`] overrides `Ke` by name.
//! Faces of zero area are dropped with one warning; anything else wrong with the input is a
//! [`SceneError`] whose message is one line naming the file — never a panic.
//!
//! Why the text is read and checked here before `tobj` sees it (tobj 4.0.5):
//! - with `ignore_points`/`ignore_lines`, an `f` line of 1 or 2 vertices is dropped silently, and
//!   an `f` line with none becomes a face of arity 0: a pre-scan rejects them with a line number;
//! - a colour line with fewer than 3 numbers (`Kd 0.5`) panics inside tobj, so MTL colour lines
//!   are checked first (a single number means grey, as the MTL specification allows);
//! - tobj reports a missing material library only when no library loaded at all, so the
//!   material loader here records what became of each library itself;
//! - tobj's errors carry no line number: on failure a small scan finds the offending line;
//! - tobj reads neither a `#` comment after the data (`v 0 0 0 # note` becomes a vertex colour,
//!   `usemtl wall # x` a material of that name) nor a backslash line continuation: both OBJ and
//!   MTL texts are rewritten first, each line kept at its number so messages name the file's
//!   lines.
//!
//! `Ke` arrives in `tobj::Material::emissive` (not in `unknown_param`; that is read as a fallback).

mod mtl;
#[cfg(test)]
mod tests;
mod text;
pub(super) mod texture;

use super::{Material, Polygon, Scene};
use glam::Vec3;
pub(super) use mtl::{clamp_and_glazing, default_grey, to_f64};
use mtl::{convert_material, load_library, textures_and_clamp, MtlLog, MtlSource};
use std::cell::RefCell;
use std::collections::HashSet;
use std::path::{Path, PathBuf};
use text::{
    describe_non_finite, describe_obj_error, fmt3, name_list, normalize, patch_size_hint, prescan,
    without_lines,
};
pub(super) use text::{io_reason, one_line};

/// Options for loading a scene.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct LoadOptions {
    /// `(material, [r, g, b])`: set the emitted radiance `Ke` (W/sr/m², the unit of MTL `Ke`)
    /// of every material of that name. A name that matches no material is an error.
    pub emit: Vec<(String, [f64; 3])>,
    /// Turn every polygon round (`--flip`): for models wound clockwise, whose rooms come out
    /// inside out (docs/design.md §7).
    pub flip: bool,
    /// A schedule of luminaires placed in the model (`--luminaires FILE`, CSV or JSON:
    /// [`crate::luminaire::schedule`]), read with the model.
    pub luminaires: Option<PathBuf>,
    /// The model's up direction the luminaires are aimed by (a luminaire aims straight down,
    /// along −zenith, unless its row says otherwise); `None`: [`crate::sky::DEFAULT_ZENITH`].
    pub zenith: Option<[f32; 3]>,
    /// `--scale`: what the model's coordinates are multiplied by to make metres (0.001 for a
    /// model in millimetres); `None`: 1. The luminaires' schedule is in metres, unscaled.
    pub scale: Option<f64>,
}

impl LoadOptions {
    /// Checks the settings a user can get wrong (one line naming the flag).
    pub fn check(&self) -> Result<(), crate::settings::Invalid> {
        match self.scale {
            Some(s) if !(s.is_finite() && s > 0.0) => crate::settings::Invalid::err(format!(
                "--scale: the factor {s} is not a finite, positive number"
            )),
            _ => Ok(()),
        }
    }
}

/// A scene that cannot be loaded. Displays as one line, `"<file>: <what is wrong>"`.
#[derive(Debug, thiserror::Error)]
#[error("{path}: {message}")]
pub struct SceneError {
    /// The file (or built-in scene name) being loaded.
    pub path: String,
    /// What is wrong, one line.
    pub message: String,
}

impl SceneError {
    pub(super) fn new(path: &str, message: impl Into<String>) -> Self {
        SceneError {
            path: one_line(path),
            message: one_line(&message.into()),
        }
    }

    /// An error already written as one line `"<where>: <what>"` by another reader (the
    /// luminaires' schedule names its file and line itself), kept as it reads; a line with no
    /// `": "` is said of `file`.
    pub(crate) fn from_line(file: &str, line: &str) -> Self {
        match line.split_once(": ") {
            Some((at, what)) => SceneError::new(at, what),
            None => SceneError::new(file, line),
        }
    }
}

/// A face is dropped when its area is below this fraction of the squared scene diagonal.
pub(super) const ZERO_AREA: f64 = 1e-12;

/// Load an OBJ file and the MTL libraries it names (looked up beside it).
///
/// A missing material library is not an error: its faces get a default grey and
/// [`Scene::warnings`] says so.
pub fn load_obj(path: &Path, opts: &LoadOptions) -> Result<Scene, SceneError> {
    let name = path.display().to_string();
    let bytes = std::fs::read(path)
        .map_err(|e| SceneError::new(&name, format!("cannot read the file: {}", io_reason(&e))))?;
    let text = String::from_utf8_lossy(&bytes);
    let dir = path.parent().unwrap_or(Path::new(""));
    load(&name, &text, MtlSource::Dir(dir), opts)
}

/// Load a scene from OBJ and MTL texts; `name` stands for the file in messages.
///
/// `mtl` is the material library for the OBJ's `mtllib` line, whatever file name it gives
/// (without an `mtllib` line, `usemtl` finds no material and the faces are grey).
pub fn load_obj_from_strs(
    name: &str,
    obj: &str,
    mtl: &str,
    opts: &LoadOptions,
) -> Result<Scene, SceneError> {
    load(name, obj, MtlSource::Text(mtl), opts)
}

/// Loads a scene from OBJ text: the pre-pass, tobj's parse, the materials, the geometry and
/// its checks, `--emit` and the patch-size comment, in that order (so in that order of errors);
/// then `--flip` and the merge of coincident faces.
fn load(name: &str, text: &str, mtl: MtlSource, opts: &LoadOptions) -> Result<Scene, SceneError> {
    let fail = |message: String| SceneError::new(name, message);
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    // Comments after the data and continued lines, rewritten with the line numbers kept.
    let normalized = normalize(text);
    let text: &str = &normalized;

    // What tobj would drop silently, and the material names the faces ask for.
    let requested = prescan(text).map_err(fail)?;
    let parsed = parse(text, &mtl).map_err(fail)?;
    let mut warnings = Vec::new();
    let materials = scene_materials(name, &parsed, &requested, &mut warnings).map_err(fail)?;
    let mut scene = geometry(name, &parsed.models, materials).map_err(fail)?;
    check_geometry(name, text, &mut scene, &mut warnings).map_err(fail)?;
    apply_emit(&mut scene.materials, &opts.emit).map_err(fail)?;
    scene.patch_size_hint = patch_size_hint(text).map_err(fail)?;
    scene.warnings = warnings;
    // Sides (docs/design.md §7): `--flip`, then doubled faces merged into two-sided ones.
    if opts.flip {
        super::sides::flip(&mut scene);
    }
    scene.merged = super::sides::merge_coincident(&mut scene);
    Ok(scene)
}

/// What tobj read, and the libraries that do not exist.
struct Parsed {
    models: Vec<tobj::Model>,
    materials: Result<Vec<tobj::Material>, tobj::LoadError>,
    /// Libraries that do not exist (a warning).
    missing: Vec<String>,
}

/// tobj's parse of the text, its material libraries read from `mtl`; a library that exists but
/// cannot be used is an error.
fn parse(text: &str, mtl: &MtlSource) -> Result<Parsed, String> {
    // Parse. Polygons stay polygons; points and lines (`p`, `l`) are not surfaces.
    // tobj reads an `l` line of 3 or more vertices as a polygon: hide `l` lines from it.
    let surfaces = without_lines(text);
    let log = RefCell::new(MtlLog::default());
    let tobj_options = tobj::LoadOptions {
        triangulate: false,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    // tobj has panicked on malformed input before; a panic must not escape as one.
    let parsed = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        tobj::load_obj_buf(&mut surfaces.as_bytes(), &tobj_options, |lib| {
            load_library(lib, mtl, &mut log.borrow_mut())
        })
    }));
    let (models, materials) = match parsed {
        Err(_) => return Err("the OBJ reader (tobj) failed on this file".into()),
        Ok(Err(e)) => return Err(describe_obj_error(text, e)),
        Ok(Ok(parsed)) => parsed,
    };
    let log = log.into_inner();
    if let Some(message) = log.error {
        return Err(message);
    }
    Ok(Parsed {
        models,
        materials,
        missing: log.missing,
    })
}

/// The scene's materials from tobj's, warning of missing libraries and (when every library
/// loaded) of `requested` names that none defines.
fn scene_materials(
    name: &str,
    parsed: &Parsed,
    requested: &HashSet<String>,
    warnings: &mut Vec<String>,
) -> Result<Vec<Material>, String> {
    let tobj_materials = match &parsed.materials {
        Ok(materials) => materials.as_slice(),
        Err(e) => {
            // Not reached with the loader above (it never returns Err), kept for safety.
            warnings.push(format!(
                "{name}: material library not loaded ({e}); using a default grey"
            ));
            &[]
        }
    };
    for lib in &parsed.missing {
        warnings.push(format!(
            "{name}: material library '{lib}' not found; using a default grey"
        ));
    }
    let mut materials = tobj_materials
        .iter()
        .map(convert_material)
        .collect::<Result<Vec<_>, _>>()?;
    textures_and_clamp(name, tobj_materials, &mut materials, warnings);
    if parsed.missing.is_empty() {
        let mut unknown: Vec<&str> = requested
            .iter()
            .map(String::as_str)
            .filter(|r| !materials.iter().any(|m| m.name == *r))
            .collect();
        if !unknown.is_empty() {
            unknown.sort_unstable();
            warnings.push(format!(
                "{name}: usemtl names material(s) not in the material library ({}); \
                 those faces use a default grey",
                name_list(&unknown)
            ));
        }
    }
    Ok(materials)
}

/// Every model appended to the flat arrays of a scene named `name`; faces without a (known)
/// material get a default grey, added after `materials`.
fn geometry(
    name: &str,
    models: &[tobj::Model],
    mut materials: Vec<Material>,
) -> Result<Scene, String> {
    let mut scene = Scene {
        name: name.to_string(),
        ..Default::default()
    };
    let mut default_material = None;
    for model in models {
        let mesh = &model.mesh;
        if mesh.indices.is_empty() {
            continue;
        }
        let material = match mesh.material_id {
            Some(id) if id < materials.len() => id as u32,
            _ => *default_material.get_or_insert_with(|| {
                materials.push(default_grey(&materials));
                (materials.len() - 1) as u32
            }),
        };
        append_mesh(&mut scene, mesh, material)?;
    }
    scene.materials = materials;
    Ok(scene)
}

/// Checks on the whole model: some polygons, finite vertices; drops zero-area faces (with a
/// warning), and fails if that leaves none.
fn check_geometry(
    name: &str,
    text: &str,
    scene: &mut Scene,
    warnings: &mut Vec<String>,
) -> Result<(), String> {
    if scene.polygons.is_empty() {
        return Err("no polygons: the file has no face (`f` line)".into());
    }
    if scene.positions.iter().any(|p| !p.is_finite()) {
        return Err(describe_non_finite(text));
    }
    let dropped = drop_zero_area(scene);
    if scene.polygons.is_empty() {
        return Err(format!("all {dropped} faces have zero area"));
    }
    if dropped > 0 {
        warnings.push(format!(
            "{name}: dropped {dropped} zero-area face(s) (area below {ZERO_AREA:e} of the \
             squared scene diagonal)"
        ));
    }
    Ok(())
}

/// The emission overrides (`--emit`): sets `Ke` of every material of each given name.
pub(super) fn apply_emit(
    materials: &mut [Material],
    emit: &[(String, [f64; 3])],
) -> Result<(), String> {
    for (material, ke) in emit {
        if ke.iter().any(|k| !k.is_finite() || *k < 0.0) {
            return Err(format!(
                "--emit {material}: emitted radiance {} must be finite and not negative",
                fmt3(ke)
            ));
        }
        let mut found = false;
        for m in materials.iter_mut().filter(|m| m.name == *material) {
            m.ke = *ke;
            found = true;
        }
        if !found {
            let names: Vec<&str> = materials.iter().map(|m| m.name.as_str()).collect();
            return Err(format!(
                "--emit names unknown material '{material}'; the materials are: {}",
                name_list(&names)
            ));
        }
    }
    Ok(())
}

/// Append one tobj mesh (its own positions, local indices, faces of `face_arities`).
fn append_mesh(scene: &mut Scene, mesh: &tobj::Mesh, material: u32) -> Result<(), String> {
    let too_big = || "the model has more than 2^32 vertices or indices".to_string();
    let broken = || "the OBJ reader returned inconsistent face data".to_string();

    let base = u32::try_from(scene.positions.len()).map_err(|_| too_big())?;
    if !mesh.positions.len().is_multiple_of(3) {
        return Err(broken());
    }
    let local_count = mesh.positions.len() / 3;
    scene.positions.extend(
        mesh.positions
            .chunks_exact(3)
            .map(|c| Vec3::new(to_f32(c[0]), to_f32(c[1]), to_f32(c[2]))),
    );

    // Empty `face_arities` means "all triangles".
    let triangles;
    let arities: &[u32] = if mesh.face_arities.is_empty() {
        if !mesh.indices.len().is_multiple_of(3) {
            return Err(broken());
        }
        triangles = vec![3u32; mesh.indices.len() / 3];
        &triangles
    } else {
        &mesh.face_arities
    };

    let mut start = 0usize;
    for &arity in arities {
        if arity < 3 {
            return Err(format!(
                "a face with {arity} vertices (a polygon needs at least 3)"
            ));
        }
        let end = start + arity as usize;
        let face = mesh.indices.get(start..end).ok_or_else(broken)?;
        let first = u32::try_from(scene.indices.len()).map_err(|_| too_big())?;
        for &i in face {
            if i as usize >= local_count {
                return Err("a face vertex index is out of range".into());
            }
            scene.indices.push(base.checked_add(i).ok_or_else(too_big)?);
        }
        scene.polygons.push(Polygon {
            first,
            len: arity,
            material,
            back_material: None,
        });
        start = end;
    }
    if start != mesh.indices.len() {
        return Err(broken());
    }
    Ok(())
}

/// Drop faces whose area (Newell's method) is below [`ZERO_AREA`] × the squared diagonal of the
/// scene's bounds; returns how many were dropped. Compacts `indices` and `polygons` in place.
fn drop_zero_area(scene: &mut Scene) -> usize {
    let (lo, hi) = scene.bounds();
    let limit = ZERO_AREA * (hi - lo).as_dvec3().length_squared();
    let (mut written, mut kept, mut dropped) = (0usize, 0usize, 0usize);
    for p in 0..scene.polygons.len() {
        let polygon = scene.polygons[p];
        let (first, len) = (polygon.first as usize, polygon.len as usize);
        let face = &scene.indices[first..first + len];
        // `<=` so that a scene of a single point (diagonal 0) drops everything.
        if newell_area(&scene.positions, face) <= limit {
            dropped += 1;
            continue;
        }
        scene.indices.copy_within(first..first + len, written);
        scene.polygons[kept] = Polygon {
            first: written as u32,
            ..polygon
        };
        written += len;
        kept += 1;
    }
    scene.indices.truncate(written);
    scene.polygons.truncate(kept);
    dropped
}

/// Area of a (planar or nearly planar) polygon by Newell's method, in f64.
fn newell_area(positions: &[Vec3], face: &[u32]) -> f64 {
    let mut n = glam::DVec3::ZERO;
    for (k, &i) in face.iter().enumerate() {
        let a = positions[i as usize].as_dvec3();
        let b = positions[face[(k + 1) % face.len()] as usize].as_dvec3();
        n += a.cross(b);
    }
    0.5 * n.length()
}

/// tobj's float as f32 (the geometry's precision, docs/design.md §1).
fn to_f32<F: Into<f64>>(x: F) -> f32 {
    x.into() as f32
}
