//! Binary glTF (`.glb`) with per-vertex radiosity (docs/design.md §5): the JSON built with
//! `gltf-json`, the container written by `gltf::binary::Glb`, so a browser viewer or Blender
//! opens it as is.
//!
//! One glTF vertex per welded vertex, with `POSITION` (metres; glTF is y-up like the scenes),
//! `NORMAL` (area-weighted mean of its patches' normals; vertices are welded only within one
//! facing, so this is the facing's normal) and `COLOR_0`; patches are fan-triangulated
//! ([`Mesh::triangles`]). The material is `KHR_materials_unlit`, so viewers show the colours
//! as they are instead of lighting the model a second time (with a plain rough, non-metallic
//! white as the fallback for viewers without it).
//!
//! **Which colour.** glTF defines `COLOR_0` as *linear*, and as floats it must lie in [0, 1];
//! the viewer applies the sRGB curve on display. So `COLOR_0` is the linear radiosity times
//! the exposure, clamped to [0, 1] — the same exposure the PNG renders use, *not* sRGB-encoded
//! (that would be applied twice). The unscaled radiosity (W/m²) is kept beside it in the
//! application-specific attribute `_RADIOSITY` (float VEC3) for analysis, and the exposure
//! in the asset's `extras`.

use super::{exposed, vertex_exposure};
use crate::mesh::Mesh;
use glam::Vec3;
use gltf::json;
use json::validation::Checked::Valid;
use json::validation::USize64;
use std::collections::BTreeMap;
use std::io::{self, Write};

/// Name of the attribute holding the linear radiosity (W/m²), without glTF's leading `_`.
pub const RADIOSITY_ATTRIBUTE: &str = "RADIOSITY";

/// Per-vertex normals: the area-weighted mean of the normals of the patches using a vertex.
fn vertex_normals(mesh: &Mesh) -> Vec<[f32; 3]> {
    let mut n = vec![Vec3::ZERO; mesh.vertices.len()];
    for (i, p) in mesh.patches.iter().enumerate() {
        for &v in mesh.patch_indices(i) {
            n[v as usize] += p.normal * p.area as f32;
        }
    }
    n.into_iter()
        .map(|v| {
            let u = v.normalize_or_zero();
            if u.is_finite() && u != Vec3::ZERO {
                u.to_array()
            } else {
                [0.0, 0.0, 1.0]
            }
        })
        .collect()
}

/// Appends little-endian f32/u32 data to the binary chunk, 4-byte aligned; returns its view.
fn push_view(
    root: &mut json::Root,
    bin: &mut Vec<u8>,
    data: &[u8],
    target: json::buffer::Target,
) -> json::Index<json::buffer::View> {
    let offset = bin.len();
    bin.extend_from_slice(data);
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    root.push(json::buffer::View {
        buffer: json::Index::new(0),
        byte_length: USize64::from(data.len()),
        byte_offset: Some(USize64::from(offset)),
        byte_stride: None,
        extensions: Default::default(),
        extras: Default::default(),
        name: None,
        target: Some(Valid(target)),
    })
}

fn accessor(
    view: json::Index<json::buffer::View>,
    count: usize,
    component: json::accessor::ComponentType,
    type_: json::accessor::Type,
    bounds: Option<([f32; 3], [f32; 3])>,
) -> json::Accessor {
    json::Accessor {
        buffer_view: Some(view),
        byte_offset: None,
        count: USize64::from(count),
        component_type: Valid(json::accessor::GenericComponentType(component)),
        extensions: Default::default(),
        extras: Default::default(),
        type_: Valid(type_),
        min: bounds.map(|b| json::Value::from(b.0.to_vec())),
        max: bounds.map(|b| json::Value::from(b.1.to_vec())),
        name: None,
        normalized: false,
        sparse: None,
    }
}

fn f32_bytes(v: impl Iterator<Item = [f32; 3]>) -> Vec<u8> {
    v.flat_map(|a| a.map(|x| if x.is_finite() { x } else { 0.0 }))
        .flat_map(f32::to_le_bytes)
        .collect()
}

/// Writes `mesh` with per-vertex radiosity `vertex_b` (W/m²) as GLB; `COLOR_0` uses `exposure`
/// (automatic when `None`). Returns the exposure used.
pub fn write(
    w: &mut dyn Write,
    mesh: &Mesh,
    vertex_b: &[[f32; 3]],
    exposure: Option<f32>,
    generator: &str,
) -> io::Result<f32> {
    if vertex_b.len() != mesh.vertices.len() {
        return Err(io::Error::other("vertex colours do not match the mesh"));
    }
    let exposure = vertex_exposure(vertex_b, exposure);
    let mut root = new_root(generator, exposure);
    let mut bin = Vec::new();
    let primitive = push_accessors(&mut root, &mut bin, mesh, vertex_b, exposure);
    push_scene(&mut root, primitive);
    root.push(json::Buffer {
        byte_length: USize64::from(bin.len()),
        extensions: Default::default(),
        extras: Default::default(),
        name: None,
        uri: None,
    });
    write_chunks(w, &root, bin)?;
    Ok(exposure)
}

/// The bounding box of the vertices (zero for an empty mesh), for `POSITION`'s min/max.
fn bounds(mesh: &Mesh) -> ([f32; 3], [f32; 3]) {
    let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
    for v in &mesh.vertices {
        for c in 0..3 {
            lo[c] = lo[c].min(v[c]);
            hi[c] = hi[c].max(v[c]);
        }
    }
    if mesh.vertices.is_empty() {
        (lo, hi) = ([0.0; 3], [0.0; 3]);
    }
    (lo, hi)
}

/// An empty document whose asset names the generator and records the exposure in `extras`.
fn new_root(generator: &str, exposure: f32) -> json::Root {
    let mut root = json::Root::default();
    root.asset.generator = Some(generator.to_string());
    root.asset.extras = serde_json::value::to_raw_value(&serde_json::json!({
        "colour": "COLOR_0 = linear radiosity (W/m2) x exposure, clamped to [0, 1]",
        "exposure": exposure,
        "radiosity_attribute": format!("_{RADIOSITY_ATTRIBUTE}"),
    }))
    .ok();
    root
}

/// The accessors of the one primitive: its vertex attributes and its triangle indices.
struct Primitive {
    attributes:
        BTreeMap<json::validation::Checked<json::mesh::Semantic>, json::Index<json::Accessor>>,
    indices: json::Index<json::Accessor>,
}

/// Appends the vertex data and indices to `bin`, each with its view and accessor, in the
/// order position, normal, colour, radiosity, indices.
fn push_accessors(
    root: &mut json::Root,
    bin: &mut Vec<u8>,
    mesh: &Mesh,
    vertex_b: &[[f32; 3]],
    exposure: f32,
) -> Primitive {
    use json::accessor::{ComponentType as C, Type as T};
    use json::buffer::Target;
    let n = mesh.vertices.len();
    let mut vec3 = |root: &mut json::Root, data: Vec<u8>, bounds| {
        let view = push_view(root, bin, &data, Target::ArrayBuffer);
        root.push(accessor(view, n, C::F32, T::Vec3, bounds))
    };
    let pos = vec3(
        root,
        f32_bytes(mesh.vertices.iter().map(|v| v.to_array())),
        Some(bounds(mesh)),
    );
    let nrm = vec3(root, f32_bytes(vertex_normals(mesh).into_iter()), None);
    let col = vec3(
        root,
        f32_bytes(vertex_b.iter().map(|b| exposed(*b, exposure))),
        None,
    );
    let rad = vec3(root, f32_bytes(vertex_b.iter().copied()), None);
    let indices: Vec<u8> = mesh
        .triangles()
        .flat_map(|(t, _)| t)
        .flat_map(u32::to_le_bytes)
        .collect();
    let count = indices.len() / 4;
    let idx = push_view(root, bin, &indices, Target::ElementArrayBuffer);
    let idx = root.push(accessor(idx, count, C::U32, T::Scalar, None));

    let mut attributes = BTreeMap::new();
    attributes.insert(Valid(json::mesh::Semantic::Positions), pos);
    attributes.insert(Valid(json::mesh::Semantic::Normals), nrm);
    attributes.insert(Valid(json::mesh::Semantic::Colors(0)), col);
    attributes.insert(
        Valid(json::mesh::Semantic::Extras(RADIOSITY_ATTRIBUTE.into())),
        rad,
    );
    Primitive {
        attributes,
        indices: idx,
    }
}

/// Adds the unlit material, the mesh with its one primitive, its node and the scene.
fn push_scene(root: &mut json::Root, primitive: Primitive) {
    let material = root.push(json::Material {
        name: Some("radiosity (unlit vertex colours)".into()),
        pbr_metallic_roughness: json::material::PbrMetallicRoughness {
            metallic_factor: json::material::StrengthFactor(0.0),
            roughness_factor: json::material::StrengthFactor(1.0),
            ..Default::default()
        },
        extensions: Some(json::extensions::material::Material {
            unlit: Some(json::extensions::material::Unlit {}),
            ..Default::default()
        }),
        ..Default::default()
    });
    root.extensions_used.push("KHR_materials_unlit".into());
    let gl_mesh = root.push(json::Mesh {
        extensions: Default::default(),
        extras: Default::default(),
        name: Some("radiosity".into()),
        primitives: vec![json::mesh::Primitive {
            attributes: primitive.attributes,
            extensions: Default::default(),
            extras: Default::default(),
            indices: Some(primitive.indices),
            material: Some(material),
            mode: Valid(json::mesh::Mode::Triangles),
            targets: None,
        }],
        weights: None,
    });
    let node = root.push(json::Node {
        mesh: Some(gl_mesh),
        ..Default::default()
    });
    let scene = root.push(json::Scene {
        extensions: Default::default(),
        extras: Default::default(),
        name: None,
        nodes: vec![node],
    });
    root.scene = Some(scene);
}

/// Serialises the document and writes the GLB header, JSON chunk and binary chunk.
fn write_chunks(w: &mut dyn Write, root: &json::Root, bin: Vec<u8>) -> io::Result<()> {
    let json_text = json::serialize::to_vec(root).map_err(io::Error::other)?;
    // GLB stores its length in 32 bits.
    if (json_text.len() + bin.len() + 64) as u64 > u32::MAX as u64 {
        return Err(io::Error::other(
            "the mesh is too large for a .glb (4 GiB); export .ply instead",
        ));
    }
    let glb = gltf::binary::Glb {
        header: gltf::binary::Header {
            magic: *b"glTF",
            version: 2,
            // Recomputed by the writer.
            length: 0,
        },
        json: json_text.into(),
        bin: Some(bin.into()),
    };
    glb.to_writer(w).map_err(io::Error::other)
}
