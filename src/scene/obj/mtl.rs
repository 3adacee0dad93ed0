//! The MTL side of loading: tobj's material loader (libraries from files or a given text,
//! what became of each logged by name), the colour-line check that keeps tobj from panicking,
//! and the conversion of tobj's materials (`Kd` → ρ, `Ke` → emitted radiance).

use super::text::{fmt3, io_reason, snippet};
use crate::scene::Material;
use std::path::Path;

/// Reflectance of a material without `Kd`, and of the material given to faces without one.
const DEFAULT_GREY: f64 = 0.5;

/// Where `mtllib` libraries come from.
pub(super) enum MtlSource<'a> {
    /// Files, relative to the OBJ's folder.
    Dir(&'a Path),
    /// One text, used for the first `mtllib` line (later ones would only repeat it).
    Text(&'a str),
}

/// What became of the material libraries during tobj's parse.
#[derive(Default)]
pub(super) struct MtlLog {
    /// Libraries that do not exist (a warning).
    pub(super) missing: Vec<String>,
    /// The first library that exists but cannot be used (an error).
    pub(super) error: Option<String>,
    /// Whether the text of [`MtlSource::Text`] was handed out already.
    text_used: bool,
}

/// A scene material from a tobj material, checking `Kd` and `Ke`.
pub(super) fn convert_material(m: &tobj::Material) -> Result<Material, String> {
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
pub(super) fn default_grey(materials: &[Material]) -> Material {
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
pub(super) fn load_library(
    lib: &Path,
    source: &MtlSource,
    log: &mut MtlLog,
) -> tobj::MTLLoadResult {
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

/// Read `r g b` or a single `g` (grey) from text.
pub(super) fn parse_colour(text: &str) -> Option<[f64; 3]> {
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
pub(super) fn to_f64<F: Into<f64> + Copy + std::fmt::Display>(x: F) -> f64 {
    let exact: f64 = x.into();
    if exact.is_finite() {
        x.to_string().parse().unwrap_or(exact)
    } else {
        exact
    }
}
