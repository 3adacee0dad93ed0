//! The MTL side of loading: tobj's material loader (libraries from files or a given text,
//! what became of each logged by name), the colour-line check that keeps tobj from panicking,
//! and the conversion of tobj's materials (`Kd` × `map_Kd` → ρ, `Ke` → emitted radiance).

use super::text::{fmt3, io_reason, normalize, snippet};
use super::texture::{map_file, mean_colours, resolve};
use crate::scene::{Material, RhoSource, MAX_REFLECTANCE};
use std::path::{Path, PathBuf};

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

/// The key under which a material read from a file carries its MTL's folder in
/// `tobj::Material::unknown_param` (an MTL keyword has no space, so no file can set it).
const FOLDER_KEY: &str = "radiosity mtl folder";

/// A scene material from a tobj material, checking `Kd` and `Ke`: ρ is `Kd` as written (the
/// texture and the clamp to [`MAX_REFLECTANCE`] come after, in [`textures_and_clamp`]).
pub(super) fn convert_material(m: &tobj::Material) -> Result<Material, String> {
    let (rho, rho_source) = match m.diffuse {
        Some(kd) => {
            let rho = kd.map(to_f64);
            if rho.iter().any(|r| !r.is_finite() || *r < 0.0) {
                return Err(format!(
                    "material '{}': Kd {} {} {} is not a reflectance (each channel must be a \
                     finite number, at least 0)",
                    m.name, kd[0], kd[1], kd[2]
                ));
            }
            (rho, RhoSource::Kd)
        }
        None => ([DEFAULT_GREY; 3], RhoSource::Default),
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
    let (transmittance, transmittance_rgb) = transmittance(m)?;
    Ok(Material {
        name: m.name.clone(),
        rho,
        ke,
        rho_source,
        transmittance,
        transmittance_rgb,
    })
}

/// The straight-through transmittance of a glazing material, from what exporters write:
///
/// - dissolve below opaque (`d` < 1, or `Tr` > 0 where there is no `d`): T = (1 − d) × the
///   mean of `Tf` (1 where there is none);
/// - a transparency illumination model (`illum` 4, 6, 7 or 9) with `Tf`: T = mean `Tf`;
/// - a `Tf` strictly between 0 and 1 in some channel: T = mean `Tf`;
/// - otherwise opaque: exporters write `Tf 1 1 1` (and some `Tf 0 0 0`) on every material.
///
/// The colour of `Tf` is kept as T_c (the same rule per channel, e.g. (1 − d) × `Tf`_c) when
/// its channels differ: tinted glazing (docs/design.md §9, "Tinted glazing"); `None` when
/// they are equal (grey glazing, exactly as before colour was kept) or the material is opaque.
fn transmittance(m: &tobj::Material) -> Result<(f64, Option<[f64; 3]>), String> {
    let number = |key: &str| -> Result<Option<f64>, String> {
        m.unknown_param
            .get(key)
            .map(|t| {
                t.trim()
                    .parse::<f64>()
                    .map_err(|_| format!("material '{}': cannot read {key} '{t}'", m.name))
            })
            .transpose()
    };
    let tf = match m.unknown_param.get("Tf") {
        Some(t) => Some(
            parse_colour(t)
                .ok_or_else(|| format!("material '{}': cannot read Tf '{t}'", m.name))?,
        ),
        None => None,
    };
    let opacity = match m.dissolve {
        Some(d) => Some(to_f64(d)),
        None => number("Tr")?.map(|tr| 1.0 - tr),
    };
    let mean = |c: [f64; 3]| (c[0] + c[1] + c[2]) / 3.0;
    // The colour of `Tf` where it transmits: kept only when its channels differ.
    let colour =
        |c: [f64; 3], scale: f64| (c[0] != c[1] || c[1] != c[2]).then(|| c.map(|x| scale * x));
    let (t, rgb) = match (opacity, tf) {
        (Some(d), _) if d < 1.0 => (
            (1.0 - d) * tf.map_or(1.0, mean),
            tf.and_then(|c| colour(c, 1.0 - d)),
        ),
        (_, Some(c)) if matches!(m.illumination_model, Some(4 | 6 | 7 | 9)) => {
            (mean(c), colour(c, 1.0))
        }
        (_, Some(c)) if c.iter().any(|x| *x > 0.0 && *x < 1.0) => (mean(c), colour(c, 1.0)),
        _ => (0.0, None),
    };
    if !(0.0..=1.0).contains(&t) {
        return Err(format!(
            "material '{}': its transmittance {t} (from Tf, d, Tr) is not within [0, 1]",
            m.name
        ));
    }
    if let Some(c) = rgb.filter(|c| c.iter().any(|x| !x.is_finite() || *x < 0.0)) {
        return Err(format!(
            "material '{}': its transmittance {} (from Tf, d, Tr) is negative in a channel \
             (each channel must be within [0, 1])",
            m.name,
            fmt3(&c)
        ));
    }
    // A pane that transmits nothing on the mean is opaque, whatever its colour.
    Ok((t, rgb.filter(|_| t > 0.0)))
}

/// ρ = `Kd` × the mean colour of `map_Kd` where the texture loads (one warning, naming each
/// material and file, for those that do not: they keep `Kd` alone), then every channel of 1 or
/// more clamped to [`MAX_REFLECTANCE`] (one warning naming the materials). `materials[i]` is
/// the conversion of `tobj_materials[i]`.
pub(super) fn textures_and_clamp(
    name: &str,
    tobj_materials: &[tobj::Material],
    materials: &mut [Material],
    warnings: &mut Vec<String>,
) {
    // (material index, the file as written, where it was looked for).
    let textured: Vec<(usize, &str, PathBuf)> = tobj_materials
        .iter()
        .enumerate()
        .filter_map(|(i, m)| {
            let file = map_file(m.diffuse_texture.as_deref()?);
            let folder = m.unknown_param.get(FOLDER_KEY).map_or("", String::as_str);
            Some((i, file, resolve(Path::new(folder), file)))
        })
        .collect();
    let paths: Vec<PathBuf> = textured.iter().map(|(_, _, p)| p.clone()).collect();
    let means = mean_colours(&paths);
    let mut failed = Vec::new();
    for (i, file, path) in textured {
        let material = &mut materials[i];
        let outcome = if file.is_empty() {
            Err("no file name after the options".to_string())
        } else {
            means[&path].clone()
        };
        match outcome {
            Ok(mean) => {
                let kd = match material.rho_source {
                    RhoSource::Default => [1.0; 3],
                    _ => material.rho,
                };
                material.rho = [0, 1, 2].map(|c| kd[c] * mean[c]);
                material.rho_source = RhoSource::KdTimesTexture {
                    file: file.to_string(),
                    kd,
                    mean,
                };
            }
            Err(why) => {
                failed.push(format!("'{}' ({}: {why})", material.name, path.display()));
                let fallback = std::mem::take(&mut material.rho_source);
                material.rho_source = RhoSource::TextureNotLoaded {
                    file: file.to_string(),
                    fallback: Box::new(fallback),
                };
            }
        }
    }
    if !failed.is_empty() {
        warnings.push(format!(
            "{name}: {} texture(s) not loaded, so those materials use Kd alone: {}",
            failed.len(),
            list(&failed)
        ));
    }
    clamp_and_glazing(name, materials, warnings);
}

/// Every reflectance channel of 1 or more clamped to [`MAX_REFLECTANCE`] (one warning naming
/// the materials), then glazing that would give back more than it receives made to transmit
/// less ([`glazing`]).
pub(in crate::scene) fn clamp_and_glazing(
    name: &str,
    materials: &mut [Material],
    warnings: &mut Vec<String>,
) {
    let mut clamped = Vec::new();
    for m in materials.iter_mut() {
        if m.rho.iter().any(|r| *r >= 1.0) {
            let unclamped = m.rho;
            m.rho = unclamped.map(|r| if r >= 1.0 { MAX_REFLECTANCE } else { r });
            let from = Box::new(std::mem::take(&mut m.rho_source));
            m.rho_source = RhoSource::Clamped { unclamped, from };
            clamped.push(format!("'{}'", m.name));
        }
    }
    if !clamped.is_empty() {
        warnings.push(format!(
            "{name}: a reflectance of 1 or more is clamped to {MAX_REFLECTANCE} (a closed room \
             that reflects everything never converges) in material(s) {}",
            list(&clamped)
        ));
    }
    glazing(name, materials, warnings);
}

/// Glazing that would reflect and transmit more than it receives (ρ_c + T_c > 1 in a
/// channel) transmits less, with one warning naming the materials: grey glazing is given
/// T = 1 − max ρ (it stays grey); tinted glazing T_c = 1 − ρ_c in each channel over, and T
/// the mean of its new colour.
fn glazing(name: &str, materials: &mut [Material], warnings: &mut Vec<String>) {
    let mut cut = Vec::new();
    for m in materials.iter_mut().filter(|m| m.transmittance > 0.0) {
        if let Some(rgb) = m.transmittance_rgb {
            let room = m.rho.map(|r| (1.0 - r).max(0.0));
            if (0..3).any(|c| rgb[c] > room[c]) {
                let kept: [f64; 3] = [0, 1, 2].map(|c| rgb[c].min(room[c]));
                let f = |v: [f64; 3]| format!("{:.3} {:.3} {:.3}", v[0], v[1], v[2]);
                cut.push(format!("'{}' ({} → {})", m.name, f(rgb), f(kept)));
                m.transmittance = (kept[0] + kept[1] + kept[2]) / 3.0;
                m.transmittance_rgb = (m.transmittance > 0.0).then_some(kept);
            }
            continue;
        }
        let room = 1.0 - m.rho.iter().copied().fold(0.0, f64::max);
        if m.transmittance > room {
            cut.push(format!(
                "'{}' ({:.3} → {:.3})",
                m.name,
                m.transmittance,
                room.max(0.0)
            ));
            m.transmittance = room.max(0.0);
        }
    }
    if !cut.is_empty() {
        warnings.push(format!(
            "{name}: glazing that would reflect and transmit more light than it receives (Kd + \
             transmittance above 1) transmits less: {}",
            list(&cut)
        ));
    }
}

/// `a, b, c`, shortened after 20 items.
fn list(items: &[String]) -> String {
    const SHOWN: usize = 20;
    let mut out = items[..items.len().min(SHOWN)].join(", ");
    if items.len() > SHOWN {
        out += &format!(" and {} more", items.len() - SHOWN);
    }
    out
}

/// The material of faces without one: grey, named "default" unless the library has that name.
pub(in crate::scene) fn default_grey(materials: &[Material]) -> Material {
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
        rho_source: RhoSource::Default,
        transmittance: 0.0,
        transmittance_rgb: None,
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
                        // Its textures are named relative to its folder.
                        let path = dir.join(&part);
                        let folder = path.parent().unwrap_or(Path::new(""));
                        let folder = folder.display().to_string();
                        all.extend(parse_library(&part, &text, log).0.into_iter().map(|mut m| {
                            m.unknown_param.insert(FOLDER_KEY.into(), folder.clone());
                            m
                        }));
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
    let normalized = normalize(text);
    let text: &str = &normalized;
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
pub(in crate::scene) fn to_f64<F: Into<f64> + Copy + std::fmt::Display>(x: F) -> f64 {
    let exact: f64 = x.into();
    if exact.is_finite() {
        x.to_string().parse().unwrap_or(exact)
    } else {
        exact
    }
}
