//! glTF materials as the solver's diffuse materials (docs/design.md §13):
//!
//! - reflectance ρ_c = base colour factor_c × the mean of the base-colour texture_c (linear
//!   light: the texture is sRGB-encoded), times (1 − t), t the share transmitted;
//! - transmission as glazing: `KHR_materials_transmission`'s factor t, the light that goes
//!   through tinted by the base colour, T_c = t × base colour_c (as glTF's model has it); a
//!   material blended by its alpha (`alphaMode: BLEND`, alpha a < 1) and without that
//!   extension transmits t = 1 − a untinted (what alpha blending shows);
//! - emission: emissive factor × `KHR_materials_emissive_strength` × the mean of the emissive
//!   texture, read as emitted radiance in W/sr/m² (the unit of MTL `Ke`: × 179 for cd/m²).
//!
//! Metallic and roughness are not read: the solver's surfaces are diffuse, and a metal's
//! base colour is its reflectance.

use super::data::{describe, read_uri, Buffers};
use crate::scene::obj::texture::mean_colour_of_bytes;
use crate::scene::obj::to_f64;
use crate::scene::{Material, RhoSource};
use std::collections::HashMap;
use std::path::Path;

/// The scene's materials from the document's, in its order; then the default grey for
/// primitives without a material (its index is `len − 1`). Textures that do not load are
/// warned of once and leave the factor alone.
pub fn convert(
    doc: &gltf::Document,
    buffers: &Buffers,
    dir: Option<&Path>,
    name: &str,
    warnings: &mut Vec<String>,
) -> Result<Vec<Material>, String> {
    let mut images = Images {
        doc,
        buffers,
        dir,
        means: HashMap::new(),
        failed: Vec::new(),
    };
    let mut out = Vec::new();
    for m in doc.materials() {
        out.push(material(&m, &mut images)?);
    }
    if !images.failed.is_empty() {
        warnings.push(format!(
            "{name}: {} texture(s) not loaded, so those materials use their colour factor alone: {}",
            images.failed.len(),
            images.failed.join(", ")
        ));
    }
    crate::scene::obj::clamp_and_glazing(name, &mut out, warnings);
    out.push(crate::scene::obj::default_grey(&out));
    Ok(out)
}

/// One material (see the module's rules).
fn material(m: &gltf::Material, images: &mut Images) -> Result<Material, String> {
    let index = m.index().unwrap_or(0);
    let label = describe("material", index, m.name());
    let name = m
        .name()
        .map(str::to_string)
        .unwrap_or_else(|| format!("material{index}"));
    let pbr = m.pbr_metallic_roughness();
    let factor = pbr.base_color_factor().map(to_f64);
    let base = [factor[0], factor[1], factor[2]];
    check(&label, "base colour", &factor)?;
    let (colour, rho_source) = match pbr.base_color_texture() {
        Some(info) => match images.mean(&info, &label) {
            Some((file, mean)) => (
                [0, 1, 2].map(|c| base[c] * mean[c]),
                RhoSource::KdTimesTexture {
                    file,
                    kd: base,
                    mean,
                },
            ),
            None => (base, RhoSource::Kd),
        },
        None => (base, RhoSource::Kd),
    };
    let (t, tinted) = match m.transmission() {
        Some(tr) => (to_f64(tr.transmission_factor()), true),
        None if m.alpha_mode() == gltf::material::AlphaMode::Blend && factor[3] < 1.0 => {
            (1.0 - factor[3], false)
        }
        None => (0.0, false),
    };
    check(&label, "transmission", &[t])?;
    let t = t.clamp(0.0, 1.0);
    let transmitted = if tinted {
        colour.map(|c| t * c)
    } else {
        [t; 3]
    };
    let mean_t = transmitted.iter().sum::<f64>() / 3.0;
    let grey = transmitted[0] == transmitted[1] && transmitted[1] == transmitted[2];
    let strength = to_f64(m.emissive_strength().unwrap_or(1.0));
    let emissive = m.emissive_factor().map(|e| to_f64(e) * strength);
    check(&label, "emission", &emissive)?;
    let emissive_mean = match m.emissive_texture() {
        Some(info) => images
            .mean(&info, &label)
            .map_or([1.0; 3], |(_, mean)| mean),
        None => [1.0; 3],
    };
    Ok(Material {
        name,
        rho: colour.map(|c| (1.0 - t) * c),
        ke: [0, 1, 2].map(|c| emissive[c] * emissive_mean[c]),
        rho_source,
        transmittance: mean_t,
        transmittance_rgb: (!grey && mean_t > 0.0).then_some(transmitted),
    })
}

/// Every value of a material's `what` finite and not negative, or an error naming both.
fn check(label: &str, what: &str, values: &[f64]) -> Result<(), String> {
    match values.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
        Some(v) => Err(format!(
            "{label}: its {what} {v} is not a finite, non-negative number"
        )),
        None => Ok(()),
    }
}

/// The document's images, each decoded once, to its mean colour.
struct Images<'a> {
    doc: &'a gltf::Document,
    buffers: &'a Buffers,
    dir: Option<&'a Path>,
    /// Image index → (how it is named, its mean colour), or `None` where it did not load.
    means: HashMap<usize, Option<(String, [f64; 3])>>,
    failed: Vec<String>,
}

impl Images<'_> {
    /// The mean colour of the image a texture shows, in linear light, and its name (its URI,
    /// or `image N` for an embedded one); `None` (warned of once) where it does not load.
    fn mean(&mut self, info: &gltf::texture::Info, label: &str) -> Option<(String, [f64; 3])> {
        let texture = info.texture();
        let json = &self.doc.as_json().textures[texture.index()];
        let index = json.source.value();
        if let Some(known) = self.means.get(&index) {
            return known.clone();
        }
        let image = &self.doc.as_json().images[index];
        let file = image
            .uri
            .as_deref()
            .filter(|u| !u.starts_with("data:"))
            .map_or_else(|| format!("image {index}"), str::to_string);
        let bytes = match (&image.buffer_view, &image.uri) {
            (Some(view), _) => self
                .doc
                .views()
                .nth(view.value())
                .ok_or_else(|| "its buffer view does not exist".to_string())
                .and_then(|v| self.buffers.view(&v).map(<[u8]>::to_vec)),
            (None, Some(uri)) => read_uri(uri, self.dir),
            (None, None) => Err("it has neither a URI nor a buffer view".into()),
        };
        let mean = bytes.and_then(|b| mean_colour_of_bytes(&b));
        let result = match mean {
            Ok(mean) => Some((file, mean)),
            Err(why) => {
                self.failed.push(format!("{label} ({file}: {why})"));
                None
            }
        };
        self.means.insert(index, result.clone());
        result
    }
}
