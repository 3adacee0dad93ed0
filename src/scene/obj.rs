//! OBJ + MTL loading through `tobj`: the only code in the crate that knows `tobj`.
//!
//! Polygons stay polygons (no triangulation: quads stay quads) and every model of the file is
//! appended to the flat arrays of [`Scene`]. MTL `Kd` becomes the reflectance ρ, MTL `Ke` the
//! emitted radiance (W/sr/m², docs/design.md §1), and [`LoadOptions::emit`] overrides `Ke` by name.
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
//! - tobj's errors carry no line number: on failure a small scan finds the offending line.
//!
//! `Ke` arrives in `tobj::Material::emissive` (not in `unknown_param`; that is read as a fallback).

use super::{Material, Polygon, Scene};
use glam::Vec3;
use std::cell::RefCell;
use std::collections::HashSet;
use std::path::Path;

/// Options for loading a scene.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct LoadOptions {
    /// `(material, [r, g, b])`: set the emitted radiance `Ke` (W/sr/m², the unit of MTL `Ke`)
    /// of every material of that name. A name that matches no material is an error.
    pub emit: Vec<(String, [f64; 3])>,
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
    fn new(path: &str, message: impl Into<String>) -> Self {
        SceneError {
            path: one_line(path),
            message: one_line(&message.into()),
        }
    }
}

/// Reflectance of a material without `Kd`, and of the material given to faces without one.
const DEFAULT_GREY: f64 = 0.5;

/// A face is dropped when its area is below this fraction of the squared scene diagonal.
const ZERO_AREA: f64 = 1e-12;

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

/// Where `mtllib` libraries come from.
enum MtlSource<'a> {
    /// Files, relative to the OBJ's folder.
    Dir(&'a Path),
    /// One text, used for the first `mtllib` line (later ones would only repeat it).
    Text(&'a str),
}

/// What became of the material libraries during tobj's parse.
#[derive(Default)]
struct MtlLog {
    /// Libraries that do not exist (a warning).
    missing: Vec<String>,
    /// The first library that exists but cannot be used (an error).
    error: Option<String>,
    /// Whether the text of [`MtlSource::Text`] was handed out already.
    text_used: bool,
}

fn load(name: &str, text: &str, mtl: MtlSource, opts: &LoadOptions) -> Result<Scene, SceneError> {
    let fail = |message: String| SceneError::new(name, message);
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);

    // What tobj would drop silently, and the material names the faces ask for.
    let requested = prescan(text).map_err(fail)?;

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
            load_library(lib, &mtl, &mut log.borrow_mut())
        })
    }));
    let (models, tobj_materials) = match parsed {
        Err(_) => return Err(fail("the OBJ reader (tobj) failed on this file".into())),
        Ok(Err(e)) => return Err(fail(describe_obj_error(text, e))),
        Ok(Ok(parsed)) => parsed,
    };
    let log = log.into_inner();
    if let Some(message) = log.error {
        return Err(fail(message));
    }

    // Materials.
    let mut warnings = Vec::new();
    let tobj_materials = tobj_materials.unwrap_or_else(|e| {
        // Not reached with the loader above (it never returns Err), kept for safety.
        warnings.push(format!(
            "{name}: material library not loaded ({e}); using a default grey"
        ));
        Vec::new()
    });
    for lib in &log.missing {
        warnings.push(format!(
            "{name}: material library '{lib}' not found; using a default grey"
        ));
    }
    let mut materials = tobj_materials
        .iter()
        .map(convert_material)
        .collect::<Result<Vec<_>, _>>()
        .map_err(fail)?;
    if log.missing.is_empty() {
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

    // Geometry: every model appended to the flat arrays.
    let mut scene = Scene {
        name: name.to_string(),
        ..Default::default()
    };
    let mut default_material = None;
    for model in &models {
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
        append_mesh(&mut scene, mesh, material).map_err(fail)?;
    }
    scene.materials = materials;

    // Checks on the whole model.
    if scene.polygons.is_empty() {
        return Err(fail("no polygons: the file has no face (`f` line)".into()));
    }
    if scene.positions.iter().any(|p| !p.is_finite()) {
        return Err(fail(describe_non_finite(text)));
    }
    let dropped = drop_zero_area(&mut scene);
    if scene.polygons.is_empty() {
        return Err(fail(format!("all {dropped} faces have zero area")));
    }
    if dropped > 0 {
        warnings.push(format!(
            "{name}: dropped {dropped} zero-area face(s) (area below {ZERO_AREA:e} of the \
             squared scene diagonal)"
        ));
    }

    // Emission overrides.
    for (material, ke) in &opts.emit {
        if ke.iter().any(|k| !k.is_finite() || *k < 0.0) {
            return Err(fail(format!(
                "--emit {material}: emitted radiance {} must be finite and not negative",
                fmt3(ke)
            )));
        }
        let mut found = false;
        for m in scene.materials.iter_mut().filter(|m| m.name == *material) {
            m.ke = *ke;
            found = true;
        }
        if !found {
            let names: Vec<&str> = scene.materials.iter().map(|m| m.name.as_str()).collect();
            return Err(fail(format!(
                "--emit names unknown material '{material}'; the materials are: {}",
                name_list(&names)
            )));
        }
    }

    scene.patch_size_hint = patch_size_hint(text).map_err(fail)?;
    scene.warnings = warnings;
    Ok(scene)
}

/// The author's patch size: a comment line `# radiosity: patch-size METRES`.
fn patch_size_hint(text: &str) -> Result<Option<f32>, String> {
    for (i, line) in text.lines().enumerate() {
        let Some(rest) = line.trim().strip_prefix('#') else {
            continue;
        };
        let Some(value) = rest.trim().strip_prefix("radiosity:") else {
            continue;
        };
        let Some(value) = value.trim().strip_prefix("patch-size") else {
            continue;
        };
        return match value.trim().parse::<f32>() {
            Ok(v) if v.is_finite() && v > 0.0 => Ok(Some(v)),
            _ => Err(format!(
                "line {}: `# radiosity: patch-size` needs a positive length in metres: `{}`",
                i + 1,
                snippet(line)
            )),
        };
    }
    Ok(None)
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

/// A scene material from a tobj material, checking `Kd` and `Ke`.
fn convert_material(m: &tobj::Material) -> Result<Material, String> {
    let rho = match m.diffuse {
        Some(kd) => {
            let rho = kd.map(to_f64);
            if rho.iter().any(|r| !(0.0..1.0).contains(r)) {
                return Err(format!(
                    "material '{}': Kd {} {} {} is outside [0, 1) (a reflectance must be at \
                     least 0 and below 1)",
                    m.name, kd[0], kd[1], kd[2]
                ));
            }
            rho
        }
        None => [DEFAULT_GREY; 3],
    };
    let ke = match (m.emissive, m.unknown_param.get("Ke")) {
        (Some(ke), _) => ke.map(to_f64),
        (None, Some(text)) => parse_colour(text)
            .ok_or_else(|| format!("material '{}': cannot read Ke '{text}'", m.name))?,
        (None, None) => [0.0; 3],
    };
    if ke.iter().any(|k| !k.is_finite() || *k < 0.0) {
        return Err(format!(
            "material '{}': Ke {} must be finite and not negative",
            m.name,
            fmt3(&ke)
        ));
    }
    Ok(Material {
        name: m.name.clone(),
        rho,
        ke,
    })
}

/// The material of faces without one: grey, named "default" unless the library has that name.
fn default_grey(materials: &[Material]) -> Material {
    let taken = |n: &str| materials.iter().any(|m| m.name == n);
    let name = if taken("default") {
        "default-grey"
    } else {
        "default"
    };
    Material {
        name: name.into(),
        rho: [DEFAULT_GREY; 3],
        ke: [0.0; 3],
    }
}

/// tobj's material loader: read (or hand out) one `mtllib` library, logging what went wrong.
/// Always returns `Ok`, so problems are reported by name from the log, not by tobj.
fn load_library(lib: &Path, source: &MtlSource, log: &mut MtlLog) -> tobj::MTLLoadResult {
    let lib_name = lib.display().to_string();
    match source {
        MtlSource::Text(text) => {
            if log.text_used {
                return Ok(Default::default());
            }
            log.text_used = true;
            Ok(parse_library(&lib_name, text, log))
        }
        MtlSource::Dir(dir) => {
            // `mtllib a.mtl b.mtl` names two files; tobj passes the rest of the line as one
            // name (file names may hold spaces), so split only if that whole name is no file.
            let parts: Vec<String> =
                if dir.join(lib).exists() || !lib_name.contains(char::is_whitespace) {
                    vec![lib_name]
                } else {
                    lib_name.split_whitespace().map(str::to_string).collect()
                };
            let mut all: Vec<tobj::Material> = Vec::new();
            for part in parts {
                match std::fs::read(dir.join(&part)) {
                    Err(e) if e.kind() == std::io::ErrorKind::NotFound => log.missing.push(part),
                    Err(e) => {
                        log.error.get_or_insert(format!(
                            "material library '{part}': cannot read it: {}",
                            io_reason(&e)
                        ));
                    }
                    Ok(bytes) => {
                        let text = String::from_utf8_lossy(&bytes);
                        all.extend(parse_library(&part, &text, log).0);
                    }
                }
            }
            // Rebuild the name → index map tobj expects (its map type is tobj's own).
            let (_, mut index) = empty_library();
            for (i, m) in all.iter().enumerate() {
                index.insert(m.name.clone(), i);
            }
            Ok((all, index))
        }
    }
}

/// `(Vec<tobj::Material>, tobj's name → index map)`, empty.
fn empty_library() -> (Vec<tobj::Material>, MtlIndex) {
    tobj::load_mtl_buf(&mut &b""[..]).unwrap_or_default()
}

/// The name → index map type of [`tobj::MTLLoadResult`] (a `HashMap` or `AHashMap`).
type MtlIndex = <tobj::MTLLoadResult as ResultOk>::Index;

/// Names the `Ok` type's map so the code does not depend on tobj's hasher feature.
trait ResultOk {
    type Index: Default;
}
impl<M: Default> ResultOk for Result<(Vec<tobj::Material>, M), tobj::LoadError> {
    type Index = M;
}

/// Parse one library's text, checked first; on a problem, log it and return no materials.
fn parse_library(lib_name: &str, text: &str, log: &mut MtlLog) -> (Vec<tobj::Material>, MtlIndex) {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let fixed = match check_mtl(text) {
        Ok(fixed) => fixed,
        Err(problem) => {
            log.error
                .get_or_insert(format!("material library '{lib_name}': {problem}"));
            return empty_library();
        }
    };
    let text = fixed.as_deref().unwrap_or(text);
    match tobj::load_mtl_buf(&mut text.as_bytes()) {
        Ok(library) => library,
        Err(e) => {
            // Each MTL statement stands alone, so the first line that fails alone is the one.
            let at = text
                .lines()
                .enumerate()
                .find(|(_, line)| tobj::load_mtl_buf(&mut line.as_bytes()).is_err())
                .map(|(i, line)| format!("line {}: {e}: `{}`", i + 1, snippet(line)))
                .unwrap_or_else(|| e.to_string());
            log.error
                .get_or_insert(format!("material library '{lib_name}': {at}"));
            empty_library()
        }
    }
}

/// Check the colour lines tobj reads (`Ka Kd Ks Ke`): a single number is expanded to three
/// (grey), anything but 1 or 3+ numbers is an error (tobj would panic on it).
/// Returns the rewritten text when a line was expanded.
fn check_mtl(text: &str) -> Result<Option<String>, String> {
    let mut fixed: Option<String> = None;
    for (i, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let key = match words.next() {
            Some(key @ ("Ka" | "Kd" | "Ks" | "Ke")) => key,
            _ => {
                if let Some(out) = fixed.as_mut() {
                    out.push_str(line);
                    out.push('\n');
                }
                continue;
            }
        };
        let values: Vec<&str> = words.collect();
        let at = || format!("line {}", i + 1);
        if let Some(&kind @ ("spectral" | "xyz")) = values.first() {
            return Err(format!(
                "{}: `{key} {kind}` is not supported; give r g b: `{}`",
                at(),
                snippet(line)
            ));
        }
        // tobj reads the first three and ignores the rest.
        if let Some(bad) = values.iter().take(3).find(|v| v.parse::<f32>().is_err()) {
            return Err(format!(
                "{}: '{bad}' is not a number: `{}`",
                at(),
                snippet(line)
            ));
        }
        let expanded = match values.len() {
            1 => Some(format!("{key} {0} {0} {0}", values[0])),
            0 | 2 => {
                return Err(format!(
                    "{}: {key} needs 3 numbers (r g b): `{}`",
                    at(),
                    snippet(line)
                ))
            }
            _ => None,
        };
        if expanded.is_some() && fixed.is_none() {
            // Copy the lines before this one, then continue line by line.
            let mut out = String::with_capacity(text.len() + 16);
            for earlier in text.lines().take(i) {
                out.push_str(earlier);
                out.push('\n');
            }
            fixed = Some(out);
        }
        if let Some(out) = fixed.as_mut() {
            out.push_str(expanded.as_deref().unwrap_or(line));
            out.push('\n');
        }
    }
    Ok(fixed)
}

/// The text with every `l` (polyline) line emptied, line numbers kept; borrowed if it has none.
fn without_lines(text: &str) -> std::borrow::Cow<'_, str> {
    let is_line = |line: &str| line.split_whitespace().next() == Some("l");
    if !text.lines().any(is_line) {
        return text.into();
    }
    let mut out = String::with_capacity(text.len());
    for line in text.lines() {
        if !is_line(line) {
            out.push_str(line);
        }
        out.push('\n');
    }
    out.into()
}

/// One pass over the OBJ text: reject faces of fewer than 3 vertices (tobj drops them
/// silently) and collect the material names `usemtl` asks for.
fn prescan(text: &str) -> Result<HashSet<String>, String> {
    let mut requested = HashSet::new();
    for (i, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("f") => {
                let n = words.count();
                if n < 3 {
                    return Err(format!(
                        "line {}: a face with {n} {} (a polygon needs at least 3): `{}`",
                        i + 1,
                        if n == 1 { "vertex" } else { "vertices" },
                        snippet(line)
                    ));
                }
            }
            Some("usemtl") => {
                // As tobj reads the name: everything after the first space, trimmed.
                let name = line.split_once(' ').map_or("", |(_, rest)| rest).trim();
                if !name.is_empty() && !requested.contains(name) {
                    requested.insert(name.to_string());
                }
            }
            _ => {}
        }
    }
    Ok(requested)
}

/// A one-line description of a tobj parse error, with the line when it can be found.
fn describe_obj_error(text: &str, e: tobj::LoadError) -> String {
    use tobj::LoadError as E;
    let first_line = |wanted: &dyn Fn(&str, &[&str]) -> bool| {
        text.lines().enumerate().find_map(|(i, line)| {
            let mut words = line.split_whitespace();
            let key = words.next()?;
            let rest: Vec<&str> = words.collect();
            wanted(key, &rest).then(|| (i + 1, snippet(line)))
        })
    };
    let (what, at) = match e {
        E::PositionParseError | E::ScalingByZeroError | E::ColorParseError => (
            format!("cannot read a vertex ({e})"),
            first_line(&|key, rest| key == "v" && !vertex_ok(rest)),
        ),
        E::NormalParseError => (
            format!("cannot read a normal ({e})"),
            first_line(&|key, rest| key == "vn" && !numbers_ok(rest, 3)),
        ),
        E::TexcoordParseError => (
            format!("cannot read a texture coordinate ({e})"),
            first_line(&|key, rest| key == "vt" && !numbers_ok(rest, 2)),
        ),
        E::FaceParseError => (
            format!("cannot read a face ({e})"),
            first_line(&|key, rest| {
                (key == "f" || key == "l") && !rest.iter().all(|w| face_word_ok(w))
            }),
        ),
        E::MaterialParseError => (
            "`usemtl` without a material name".to_string(),
            first_line(&|key, rest| key == "usemtl" && rest.is_empty()),
        ),
        E::FaceVertexOutOfBounds | E::FaceTexCoordOutOfBounds | E::FaceNormalOutOfBounds => {
            match find_bad_index(text) {
                Some(message) => return message,
                None => (format!("{e}"), None),
            }
        }
        _ => (format!("cannot read the OBJ ({e})"), None),
    };
    match at {
        Some((n, line)) => format!("line {n}: {what}: `{line}`"),
        None => what,
    }
}

/// Whether a `v` line's values read as tobj reads them: x y z, then nothing, w ≠ 0, or r g b.
fn vertex_ok(rest: &[&str]) -> bool {
    let number = |s: &&str| s.parse::<f32>().is_ok();
    rest.len() >= 3
        && rest[..3].iter().all(number)
        && match rest.len() {
            3 | 6 => true,
            4 => rest[3].parse::<f32>().is_ok_and(|w| w != 0.0),
            _ => false,
        }
}

fn numbers_ok(rest: &[&str], n: usize) -> bool {
    rest.len() >= n && rest[..n].iter().all(|s| s.parse::<f32>().is_ok())
}

/// `v`, `v/vt`, `v//vn` or `v/vt/vn`, each present part an integer.
fn face_word_ok(word: &str) -> bool {
    let parts: Vec<&str> = word.split('/').collect();
    parts.len() <= 3
        && parts
            .iter()
            .all(|p| p.is_empty() || p.parse::<isize>().is_ok())
}

/// The first face corner that refers to a vertex (or texture coordinate, or normal) that does
/// not exist, as a message; `None` if this scan finds none.
fn find_bad_index(text: &str) -> Option<String> {
    const KINDS: [(&str, &str, &str); 3] = [
        ("v", "vertex", "vertices"),
        ("vt", "texture coordinate", "texture coordinates"),
        ("vn", "normal", "normals"),
    ];
    let mut totals = [0usize; 3];
    for line in text.lines() {
        if let Some(slot) = KINDS
            .iter()
            .position(|(k, _, _)| line.split_whitespace().next() == Some(k))
        {
            totals[slot] += 1;
        }
    }
    let mut so_far = [0usize; 3];
    for (i, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let key = words.next();
        if let Some(slot) = KINDS.iter().position(|(k, _, _)| key == Some(k)) {
            so_far[slot] += 1;
            continue;
        }
        if key != Some("f") {
            continue;
        }
        for word in words {
            for (slot, part) in word.split('/').enumerate().take(3) {
                // tobj ignores texture and normal indices when the file has none of them.
                if part.is_empty() || (slot > 0 && totals[slot] == 0) {
                    continue;
                }
                let Ok(x) = part.parse::<isize>() else {
                    continue;
                };
                let resolved = if x > 0 {
                    Some(x.unsigned_abs() - 1)
                } else if x < 0 {
                    so_far[slot].checked_sub(x.unsigned_abs())
                } else {
                    None
                };
                if resolved.is_none_or(|r| r >= totals[slot]) {
                    let (_, kind, kinds) = KINDS[slot];
                    let have = match totals[slot] {
                        1 => format!("1 {kind}"),
                        n => format!("{n} {kinds}"),
                    };
                    let why = if x == 0 {
                        format!("{kind} index 0 (OBJ indices start at 1)")
                    } else {
                        format!("{kind} {x}, but the file has {have}")
                    };
                    return Some(format!(
                        "line {}: a face refers to {why}: `{}`",
                        i + 1,
                        snippet(line)
                    ));
                }
            }
        }
    }
    None
}

/// Which vertex has a coordinate that is not finite, read as tobj reads it (f32, `/ w`).
fn describe_non_finite(text: &str) -> String {
    let mut vertex = 0usize;
    for (i, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        if words.next() != Some("v") {
            continue;
        }
        vertex += 1;
        let values: Vec<f32> = words.take(4).map_while(|w| w.parse().ok()).collect();
        if values.len() < 3 {
            continue;
        }
        let w = if values.len() == 4 { values[3] } else { 1.0 };
        if values[..3].iter().any(|c| !(c / w).is_finite()) {
            return format!(
                "vertex {vertex} (line {}) has a coordinate that is not finite: `{}`",
                i + 1,
                snippet(line)
            );
        }
    }
    "a vertex has a coordinate that is not finite (NaN or infinite)".into()
}

/// Read `r g b` or a single `g` (grey) from text.
fn parse_colour(text: &str) -> Option<[f64; 3]> {
    let values: Vec<f64> = text
        .split_whitespace()
        .map(str::parse)
        .collect::<Result<_, _>>()
        .ok()?;
    match values[..] {
        [g] => Some([g; 3]),
        [r, g, b, ..] => Some([r, g, b]),
        _ => None,
    }
}

/// tobj's float (f32, or f64 with its `use_f64` feature) as f64, keeping its decimal value:
/// `Kd 0.725` gives ρ = 0.725, not 0.7250000238418579.
fn to_f64<F: Into<f64> + Copy + std::fmt::Display>(x: F) -> f64 {
    let exact: f64 = x.into();
    if exact.is_finite() {
        x.to_string().parse().unwrap_or(exact)
    } else {
        exact
    }
}

/// tobj's float as f32 (the geometry's precision, docs/design.md §1).
fn to_f32<F: Into<f64>>(x: F) -> f32 {
    x.into() as f32
}

fn fmt3(v: &[f64; 3]) -> String {
    format!("{} {} {}", v[0], v[1], v[2])
}

/// `a, b, c`, shortened after 20 names.
fn name_list(names: &[&str]) -> String {
    const SHOWN: usize = 20;
    let mut list = names
        .iter()
        .take(SHOWN)
        .map(|n| format!("'{n}'"))
        .collect::<Vec<_>>()
        .join(", ");
    if names.len() > SHOWN {
        list += &format!(" and {} more", names.len() - SHOWN);
    }
    if list.is_empty() {
        list = "none".into();
    }
    list
}

/// A line of input quoted in a message: trimmed, at most 60 characters.
fn snippet(line: &str) -> String {
    let line = line.trim();
    if line.chars().count() > 60 {
        line.chars().take(57).collect::<String>() + "..."
    } else {
        line.to_string()
    }
}

fn one_line(s: &str) -> String {
    if s.contains(['\n', '\r']) {
        s.split(['\n', '\r'])
            .filter(|part| !part.is_empty())
            .collect::<Vec<_>>()
            .join(" ")
    } else {
        s.to_string()
    }
}

fn io_reason(e: &std::io::Error) -> String {
    match e.kind() {
        std::io::ErrorKind::NotFound => "no such file".into(),
        std::io::ErrorKind::PermissionDenied => "permission denied".into(),
        _ => e.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{default_scene, DEFAULT_SCENE_NAME};
    use glam::DVec3;

    const GREY_MTL: &str = "newmtl grey\nKd 0.5 0.5 0.5\n";

    fn load_strs(obj: &str, mtl: &str) -> Result<Scene, SceneError> {
        load_obj_from_strs("test.obj", obj, mtl, &LoadOptions::default())
    }

    /// The error's message is one line, names the file first, and holds every `needle`.
    fn assert_error(result: Result<Scene, SceneError>, file: &str, needles: &[&str]) -> String {
        let message = match result {
            Ok(_) => panic!("expected an error mentioning {needles:?}"),
            Err(e) => e.to_string(),
        };
        assert!(!message.contains('\n'), "not one line: {message:?}");
        assert!(
            message.starts_with(&format!("{file}: ")),
            "does not name {file} first: {message}"
        );
        for needle in needles {
            assert!(message.contains(needle), "{message:?} lacks {needle:?}");
        }
        message
    }

    fn newell_normal(scene: &Scene, p: &Polygon) -> DVec3 {
        let face = scene.polygon_indices(p);
        let mut n = DVec3::ZERO;
        for (k, &i) in face.iter().enumerate() {
            let a = scene.positions[i as usize].as_dvec3();
            let b = scene.positions[face[(k + 1) % face.len()] as usize].as_dvec3();
            n += a.cross(b);
        }
        n.normalize()
    }

    fn centroid(scene: &Scene, p: &Polygon) -> DVec3 {
        let face = scene.polygon_indices(p);
        face.iter()
            .map(|&i| scene.positions[i as usize].as_dvec3())
            .sum::<DVec3>()
            / face.len() as f64
    }

    fn material<'a>(scene: &'a Scene, name: &str) -> &'a Material {
        scene
            .materials
            .iter()
            .find(|m| m.name == name)
            .unwrap_or_else(|| panic!("no material {name}"))
    }

    // ---- the built-in Cornell box ----

    #[test]
    fn default_scene_loads_as_authored() {
        let scene = default_scene(&LoadOptions::default()).unwrap();
        assert_eq!(scene.name, DEFAULT_SCENE_NAME);
        assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
        // floor, 8 ceiling quads around the light, back, red, green, light, 2 blocks × 5.
        assert_eq!(scene.polygons.len(), 23);
        assert!(scene.polygons.iter().all(|p| p.len == 4), "all quads");
        let names: Vec<&str> = scene.materials.iter().map(|m| m.name.as_str()).collect();
        assert_eq!(names, ["white", "red", "green", "light"]);
        let emitters: Vec<&Material> = scene.materials.iter().filter(|m| m.is_emitter()).collect();
        assert_eq!(emitters.len(), 1);
        assert_eq!(emitters[0].name, "light");
        assert_eq!(emitters[0].ke, [17.0, 12.0, 4.0]);
        assert_eq!(material(&scene, "white").rho, [0.725, 0.71, 0.68]);
        assert_eq!(material(&scene, "red").rho, [0.63, 0.065, 0.05]);
        assert_eq!(material(&scene, "green").rho, [0.14, 0.45, 0.091]);
        assert!(scene.has_emitter());
    }

    #[test]
    fn default_scene_bounds_in_metres() {
        let scene = default_scene(&LoadOptions::default()).unwrap();
        let (lo, hi) = scene.bounds();
        let size = hi - lo;
        // 1e-6 m: the file's coordinates are exact to 0.1 mm, f32 holds them to ~3e-8.
        assert!(
            (size - Vec3::new(0.556, 0.5488, 0.5592))
                .abs()
                .max_element()
                < 1e-6
        );
        assert!((lo - Vec3::new(0.0, 0.0, -0.5592)).abs().max_element() < 1e-6);
        assert!(hi.z.abs() < 1e-6, "open side at z = 0");
    }

    #[test]
    fn default_scene_normals_face_the_light_side() {
        let scene = default_scene(&LoadOptions::default()).unwrap();
        let room_centre = DVec3::new(0.278, 0.2744, -0.2796);
        let mut counts = std::collections::BTreeMap::new();
        for p in &scene.polygons {
            let n = newell_normal(&scene, p);
            let c = centroid(&scene, p);
            let ys: Vec<f32> = scene
                .polygon_indices(p)
                .iter()
                .map(|&i| scene.positions[i as usize].y)
                .collect();
            let all_y = |y: f32| ys.iter().all(|v| (v - y).abs() < 1e-6);
            let name = scene.materials[p.material as usize].name.as_str();
            // Directions within 0.01 (0.6°): the red wall leans by 0.5°, the rest is exact.
            let near = |want: DVec3| (n - want).length() < 0.01;
            let kind = match name {
                "light" => {
                    assert!(near(DVec3::NEG_Y), "light {n}");
                    assert!(all_y(0.5488));
                    "light"
                }
                "red" => {
                    assert!(n.x > 0.99 && c.x < 0.01, "red wall on the left, {n}");
                    "red"
                }
                "green" => {
                    assert!(
                        near(DVec3::NEG_X) && c.x > 0.55,
                        "green wall on the right, {n}"
                    );
                    "green"
                }
                "white" if all_y(0.0) => {
                    assert!(near(DVec3::Y), "floor {n}");
                    "floor"
                }
                "white" if all_y(0.5488) => {
                    assert!(near(DVec3::NEG_Y), "ceiling {n}");
                    "ceiling"
                }
                "white" if (c.z + 0.5592).abs() < 1e-6 => {
                    assert!(near(DVec3::Z), "back wall {n}");
                    "back"
                }
                "white" => {
                    // A block face: outward from the block's vertical axis, or up for a top.
                    let top = ys.iter().cloned().fold(0.0f32, f32::max);
                    let (axis, block) = if (top - 0.165).abs() < 1e-6 {
                        (DVec3::new(0.3705, 0.0, -0.169), "short block")
                    } else {
                        (DVec3::new(0.1875, 0.0, -0.35125), "tall block")
                    };
                    if all_y(top) {
                        assert!(near(DVec3::Y), "{block} top {n}");
                    } else {
                        let out = (c - axis) * DVec3::new(1.0, 0.0, 1.0);
                        assert!(n.y.abs() < 1e-6 && n.dot(out) > 0.0, "{block} side {n}");
                    }
                    block
                }
                other => panic!("unexpected material {other}"),
            };
            if kind != "short block" && kind != "tall block" {
                assert!(n.dot(room_centre - c) > 0.0, "{kind} faces into the room");
            }
            *counts.entry(kind).or_insert(0) += 1;
        }
        let want = [
            ("back", 1),
            ("ceiling", 8),
            ("floor", 1),
            ("green", 1),
            ("light", 1),
            ("red", 1),
            ("short block", 5),
            ("tall block", 5),
        ];
        assert_eq!(counts.into_iter().collect::<Vec<_>>(), want);
    }

    #[test]
    fn default_scene_files_load_from_disk_too() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell-box.obj");
        let scene = load_obj(&path, &LoadOptions::default()).unwrap();
        assert_eq!(scene.name, path.display().to_string());
        assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
        assert_eq!(scene.polygons.len(), 23);
        assert_eq!(material(&scene, "light").ke, [17.0, 12.0, 4.0]);
    }

    #[test]
    fn light_area_and_emission() {
        let scene = default_scene(&LoadOptions::default()).unwrap();
        let light = scene
            .polygons
            .iter()
            .find(|p| scene.materials[p.material as usize].is_emitter())
            .unwrap();
        let area = newell_area(&scene.positions, scene.polygon_indices(light));
        // 130 mm × 105 mm; f32 coordinates give ~1e-8 m² of slack.
        assert!((area - 0.13 * 0.105).abs() < 1e-7, "{area}");
        let e = scene.materials[light.material as usize].emission();
        assert!((e[0] - 17.0 * std::f64::consts::PI).abs() < 1e-12);
    }

    // ---- emission overrides ----

    #[test]
    fn emit_sets_the_named_material() {
        let opts = LoadOptions {
            emit: vec![("white".into(), [1.0, 2.0, 3.0])],
        };
        let scene = default_scene(&opts).unwrap();
        assert_eq!(material(&scene, "white").ke, [1.0, 2.0, 3.0]);
        assert_eq!(material(&scene, "light").ke, [17.0, 12.0, 4.0]);
        // Turning the light off leaves a scene without emitter: not this loader's concern.
        let opts = LoadOptions {
            emit: vec![("light".into(), [0.0; 3])],
        };
        let scene = default_scene(&opts).unwrap();
        assert!(!scene.has_emitter());
    }

    #[test]
    fn emit_unknown_material_is_an_error_listing_the_materials() {
        let opts = LoadOptions {
            emit: vec![("lamp".into(), [1.0; 3])],
        };
        assert_error(
            default_scene(&opts),
            DEFAULT_SCENE_NAME,
            &["'lamp'", "'white', 'red', 'green', 'light'"],
        );
    }

    #[test]
    fn emit_negative_or_nan_is_an_error() {
        for ke in [[-1.0, 0.0, 0.0], [f64::NAN, 1.0, 1.0]] {
            let opts = LoadOptions {
                emit: vec![("light".into(), ke)],
            };
            assert_error(
                default_scene(&opts),
                DEFAULT_SCENE_NAME,
                &["light", "negative"],
            );
        }
    }

    // ---- general loading ----

    #[test]
    fn polygons_keep_their_arity_and_models_are_concatenated() {
        let obj = "mtllib any.mtl\n\
            v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 1.5 0\n\
            o first\nusemtl grey\nf 1 2 3\nf 1 2 3 5 4\n\
            o second\nusemtl grey\nf -5 -4 -3 -2\n";
        let scene = load_strs(obj, GREY_MTL).unwrap();
        let arities: Vec<u32> = scene.polygons.iter().map(|p| p.len).collect();
        assert_eq!(arities, [3, 5, 4]);
        let corners: Vec<Vec<Vec3>> = scene
            .polygons
            .iter()
            .map(|p| {
                scene
                    .polygon_indices(p)
                    .iter()
                    .map(|&i| scene.positions[i as usize])
                    .collect()
            })
            .collect();
        assert_eq!(corners[1][3], Vec3::new(0.5, 1.5, 0.0));
        assert_eq!(
            corners[2],
            [
                Vec3::ZERO,
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0)
            ]
        );
        assert_eq!(scene.materials.len(), 1);
        assert!(scene.polygons.iter().all(|p| p.material == 0));
        assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    }

    #[test]
    fn faces_without_material_get_the_default_grey() {
        let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
        let scene = load_strs(obj, "").unwrap();
        assert_eq!(scene.materials.len(), 1);
        assert_eq!(scene.materials[0].name, "default");
        assert_eq!(scene.materials[0].rho, [0.5; 3]);
        assert_eq!(scene.materials[0].ke, [0.0; 3]);
        assert!(scene.warnings.is_empty());
    }

    #[test]
    fn material_without_kd_is_grey_and_single_kd_means_grey() {
        let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n\
                   usemtl bare\nf 1 2 3\nusemtl one\nf 1 3 2\n";
        let mtl = "newmtl bare\nKe 1 2 3\nnewmtl one\nKd 0.25\n";
        let scene = load_strs(obj, mtl).unwrap();
        assert_eq!(material(&scene, "bare").rho, [0.5; 3]);
        assert_eq!(material(&scene, "bare").ke, [1.0, 2.0, 3.0]);
        assert_eq!(material(&scene, "one").rho, [0.25; 3]);
    }

    #[test]
    fn unknown_usemtl_warns_and_uses_grey() {
        let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl nosuch\nf 1 2 3\n";
        let scene = load_strs(obj, GREY_MTL).unwrap();
        assert_eq!(scene.warnings.len(), 1);
        assert!(
            scene.warnings[0].contains("'nosuch'"),
            "{:?}",
            scene.warnings
        );
        let m = &scene.materials[scene.polygons[0].material as usize];
        assert_eq!((m.name.as_str(), m.rho), ("default", [0.5; 3]));
    }

    #[test]
    fn crlf_and_byte_order_mark_are_read() {
        let obj =
            "\u{feff}mtllib m.mtl\r\nv 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nusemtl grey\r\nf 1 2 3\r\n";
        let mtl = "\u{feff}newmtl grey\r\nKd 0.5 0.5 0.5\r\n";
        let scene = load_strs(obj, mtl).unwrap();
        assert_eq!(scene.polygons.len(), 1);
        assert_eq!(scene.materials[0].name, "grey");
        assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    }

    #[test]
    fn zero_area_faces_are_dropped_with_one_warning() {
        let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\n\
                   f 1 2 3\nf 1 2 4\nf 1 1 2\nf 2 3 4 1\n";
        let scene = load_strs(obj, "").unwrap();
        // f 1 2 4 is collinear, f 1 1 2 repeats a vertex; the quad has area.
        assert_eq!(scene.polygons.len(), 2);
        assert_eq!(
            scene.polygons[1],
            Polygon {
                first: 3,
                len: 4,
                material: 0
            }
        );
        assert_eq!(scene.indices.len(), 7);
        assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
        assert!(scene.warnings[0].starts_with("test.obj: dropped 2 zero-area"));
    }

    #[test]
    fn all_faces_zero_area_is_an_error() {
        let obj = "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n";
        assert_error(
            load_strs(obj, ""),
            "test.obj",
            &["all 1 faces have zero area"],
        );
    }

    // ---- files ----

    #[test]
    fn missing_file_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("absent.obj");
        let file = path.display().to_string();
        assert_error(
            load_obj(&path, &LoadOptions::default()),
            &file,
            &["no such file"],
        );
        // A folder is not a file either.
        let folder = dir.path().display().to_string();
        assert_error(
            load_obj(dir.path(), &LoadOptions::default()),
            &folder,
            &["cannot read"],
        );
    }

    #[test]
    fn missing_mtl_warns_and_uses_grey() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("model.obj");
        std::fs::write(
            &path,
            "mtllib x.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n",
        )
        .unwrap();
        let scene = load_obj(&path, &LoadOptions::default()).unwrap();
        let file = path.display().to_string();
        assert_eq!(
            scene.warnings,
            [format!(
                "{file}: material library 'x.mtl' not found; using a default grey"
            )]
        );
        assert_eq!(scene.materials.len(), 1);
        assert_eq!(scene.materials[0].rho, [0.5; 3]);
        assert_eq!(scene.polygons.len(), 1);
    }

    #[test]
    fn mtl_files_load_beside_the_obj() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("model.obj");
        std::fs::write(
            &path,
            "mtllib a.mtl b.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n\
             usemtl lamp\nf 1 2 3\nusemtl wall\nf 1 3 2\n",
        )
        .unwrap();
        std::fs::write(
            dir.path().join("a.mtl"),
            "newmtl lamp\nKd 0.1 0.2 0.3\nKe 4 5 6\n",
        )
        .unwrap();
        std::fs::write(dir.path().join("b.mtl"), "newmtl wall\nKd 0.7 0.7 0.7\n").unwrap();
        let scene = load_obj(&path, &LoadOptions::default()).unwrap();
        assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
        let used: Vec<&str> = scene
            .polygons
            .iter()
            .map(|p| scene.materials[p.material as usize].name.as_str())
            .collect();
        assert_eq!(used, ["lamp", "wall"]);
        assert_eq!(material(&scene, "lamp").ke, [4.0, 5.0, 6.0]);
        assert_eq!(material(&scene, "lamp").rho, [0.1, 0.2, 0.3]);
    }

    #[test]
    fn broken_mtl_file_is_an_error_naming_it() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("model.obj");
        std::fs::write(&path, "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
        std::fs::write(dir.path().join("m.mtl"), "newmtl a\nNs shiny\n").unwrap();
        let file = path.display().to_string();
        assert_error(
            load_obj(&path, &LoadOptions::default()),
            &file,
            &["'m.mtl'", "line 2", "Ns shiny"],
        );
    }

    // ---- errors in the OBJ ----

    #[test]
    fn unparsable_obj_is_an_error_with_its_line() {
        let obj = "v 0 0 0\nv 1 zero 0\nv 0 1 0\nf 1 2 3\n";
        assert_error(
            load_strs(obj, ""),
            "test.obj",
            &["vertex", "line 2", "v 1 zero 0"],
        );
        let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n";
        assert_error(load_strs(obj, ""), "test.obj", &["face", "line 4"]);
        let obj = "v 0 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
        assert_error(load_strs(obj, ""), "test.obj", &["vertex", "line 1"]);
    }

    #[test]
    fn non_finite_vertex_is_an_error_naming_it() {
        for (bad, needle) in [("nan 0 0", "NaN"), ("0 inf 0", "inf"), ("0 0 1e39", "1e39")] {
            let obj = format!("v 0 0 0\nv 1 0 0\nv {bad}\nf 1 2 3\n");
            let message = assert_error(
                load_strs(&obj, ""),
                "test.obj",
                &["vertex 3 (line 3)", "not finite"],
            );
            assert!(message.to_lowercase().contains(&needle.to_lowercase()));
        }
        // An unused bad vertex is harmless.
        let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv nan 0 0\nf 1 2 3\n";
        assert_eq!(load_strs(obj, "").unwrap().polygons.len(), 1);
    }

    #[test]
    fn faces_of_fewer_than_three_vertices_are_errors() {
        for (face, n) in [
            ("f 1 2", "2 vertices"),
            ("f 1", "1 vertex"),
            ("f", "0 vertices"),
        ] {
            let obj = format!("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n{face}\n");
            assert_error(
                load_strs(&obj, ""),
                "test.obj",
                &["line 5", &format!("a face with {n} ")],
            );
        }
        // Lines and points are not faces and are skipped.
        let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\np 3\nf 1 2 3\n";
        assert_eq!(load_strs(obj, "").unwrap().polygons.len(), 1);
    }

    #[test]
    fn index_out_of_range_is_an_error() {
        let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n";
        assert_error(
            load_strs(obj, ""),
            "test.obj",
            &["line 4", "vertex 9, but the file has 3 vertices"],
        );
        let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n";
        assert_error(load_strs(obj, ""), "test.obj", &["line 4", "index 0"]);
        let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n";
        assert_error(load_strs(obj, ""), "test.obj", &["line 4", "vertex -4"]);
    }

    #[test]
    fn polylines_of_three_or_more_vertices_are_not_polygons() {
        let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2 3\nl 1 2 3 1\n";
        assert_error(load_strs(obj, ""), "test.obj", &["no polygons"]);
        let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2 3\nf 1 2 3\n";
        assert_eq!(load_strs(obj, "").unwrap().polygons.len(), 1);
    }

    #[test]
    fn no_polygons_is_an_error() {
        assert_error(load_strs("", ""), "test.obj", &["no polygons"]);
        let obj = "v 0 0 0\nv 1 0 0\nl 1 2\n";
        assert_error(load_strs(obj, ""), "test.obj", &["no polygons"]);
    }

    // ---- errors in the MTL ----

    const TRIANGLE_USING_M: &str = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n";

    #[test]
    fn reflectance_outside_zero_one_is_an_error() {
        for kd in ["1 0.5 0.5", "0.5 -0.1 0.5", "0.5 0.5 nan"] {
            let mtl = format!("newmtl m\nKd {kd}\n");
            let message = assert_error(
                load_strs(TRIANGLE_USING_M, &mtl),
                "test.obj",
                &["'m'", "Kd"],
            );
            assert!(message.contains("outside [0, 1)"), "{message}");
        }
        // Just below 1 is fine.
        let scene = load_strs(TRIANGLE_USING_M, "newmtl m\nKd 0.999 0 0\n").unwrap();
        assert_eq!(scene.materials[0].rho, [0.999, 0.0, 0.0]);
    }

    #[test]
    fn negative_or_non_finite_ke_is_an_error() {
        for ke in ["-1 0 0", "0 inf 0", "nan 1 1"] {
            let mtl = format!("newmtl m\nKd 0.5 0.5 0.5\nKe {ke}\n");
            assert_error(
                load_strs(TRIANGLE_USING_M, &mtl),
                "test.obj",
                &["'m'", "Ke", "finite and not negative"],
            );
        }
    }

    #[test]
    fn short_or_bad_colour_lines_are_errors_not_panics() {
        for (line, needle) in [
            ("Kd 0.5 0.5", "needs 3 numbers"),
            ("Kd", "needs 3 numbers"),
            ("Ke one two three", "'one' is not a number"),
            ("Kd spectral file.rfl", "not supported"),
        ] {
            let mtl = format!("newmtl m\n{line}\n");
            assert_error(
                load_strs(TRIANGLE_USING_M, &mtl),
                "test.obj",
                &["line 2", needle],
            );
        }
    }

    #[test]
    fn patch_size_hint_is_read_from_its_comment() {
        let obj = "# radiosity: patch-size 0.6\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
        let s = load_obj_from_strs("hint.obj", obj, "", &LoadOptions::default()).unwrap();
        assert_eq!(s.patch_size_hint, Some(0.6));
        let none = load_obj_from_strs("none.obj", &obj[28..], "", &LoadOptions::default()).unwrap();
        assert_eq!(none.patch_size_hint, None);
        let bad = obj.replace("0.6", "-1");
        let e = load_obj_from_strs("bad.obj", &bad, "", &LoadOptions::default()).unwrap_err();
        assert!(e.to_string().contains("patch-size"), "{e}");
    }

    #[test]
    fn helpers_behave() {
        assert_eq!(one_line("a\nb\r\nc"), "a b c");
        assert_eq!(to_f64(0.725f32), 0.725);
        assert_eq!(parse_colour("2"), Some([2.0; 3]));
        assert_eq!(parse_colour("1 2"), None);
        assert_eq!(name_list(&[]), "none");
        assert_eq!(snippet(&"x".repeat(100)).len(), 60);
    }
}
