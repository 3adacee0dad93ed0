//! PLY mesh with per-vertex radiosity (docs/design.md §5), through `ply-rs-bw` (the maintained fork
//! of `ply-rs`), binary little-endian.
//!
//! One PLY vertex per welded vertex: `x y z` (float, metres), `radiosity_r/g/b` (float, linear
//! W/m², for analysis) and `red green blue` (uchar, tone-mapped sRGB, what Blender, MeshLab and
//! CloudCompare show as vertex colour). One face per patch, its vertex indices as a list
//! (`uchar` count, `uint` indices): patches stay quads where they are quads, as the solve saw them.

use super::{srgb8, vertex_exposure};
use crate::mesh::Mesh;
use ply_rs_bw::ply::{
    Addable, ElementDef, Encoding, Header, PropertyAccess, PropertyDef, PropertyType, ScalarType,
};
use ply_rs_bw::writer::Writer;
use std::io::{self, Write};

/// Names of the linear radiosity properties.
pub const RADIOSITY: [&str; 3] = ["radiosity_r", "radiosity_g", "radiosity_b"];

/// A vertex row as written.
struct Vertex {
    p: [f32; 3],
    b: [f32; 3],
    c: [u8; 3],
}

impl PropertyAccess for Vertex {
    fn new() -> Self {
        Vertex {
            p: [0.0; 3],
            b: [0.0; 3],
            c: [0; 3],
        }
    }
    fn get_float(&self, name: &str) -> Option<f32> {
        match name {
            "x" => Some(self.p[0]),
            "y" => Some(self.p[1]),
            "z" => Some(self.p[2]),
            _ => RADIOSITY.iter().position(|n| *n == name).map(|k| self.b[k]),
        }
    }
    fn get_uchar(&self, name: &str) -> Option<u8> {
        match name {
            "red" => Some(self.c[0]),
            "green" => Some(self.c[1]),
            "blue" => Some(self.c[2]),
            _ => None,
        }
    }
}

/// A face row as written.
struct Face(Vec<u32>);

impl PropertyAccess for Face {
    fn new() -> Self {
        Face(Vec::new())
    }
    fn get_list_uint(&self, name: &str) -> Option<&[u32]> {
        (name == "vertex_indices").then_some(&self.0[..])
    }
}

fn scalar(name: &str, t: ScalarType) -> PropertyDef {
    PropertyDef::new(name.to_string(), PropertyType::Scalar(t))
}

/// Writes `mesh` with per-vertex radiosity `vertex_b` (W/m²); the 8-bit colours use `exposure`
/// (automatic when `None`). Returns the exposure used.
pub fn write(
    w: &mut dyn Write,
    mesh: &Mesh,
    vertex_b: &[[f32; 3]],
    exposure: Option<f32>,
    comment: &str,
) -> io::Result<f32> {
    if vertex_b.len() != mesh.vertices.len() {
        return Err(io::Error::other("vertex colours do not match the mesh"));
    }
    let exposure = vertex_exposure(vertex_b, exposure);
    let mut header = Header::new();
    header.encoding = Encoding::BinaryLittleEndian;
    for line in comment.lines() {
        header.comments.push(line.to_string());
    }
    header.comments.push(format!(
        "radiosity_r/g/b: linear radiosity, W/m2; red/green/blue: sRGB at exposure {exposure}"
    ));
    let mut vdef = ElementDef::new("vertex".to_string());
    for n in ["x", "y", "z"].into_iter().chain(RADIOSITY) {
        vdef.properties.add(scalar(n, ScalarType::Float));
    }
    for n in ["red", "green", "blue"] {
        vdef.properties.add(scalar(n, ScalarType::UChar));
    }
    vdef.count = mesh.vertices.len();
    let mut fdef = ElementDef::new("face".to_string());
    fdef.properties.add(PropertyDef::new(
        "vertex_indices".to_string(),
        PropertyType::List(ScalarType::UChar, ScalarType::UInt),
    ));
    fdef.count = mesh.patches.len();
    header.elements.add(vdef.clone());
    header.elements.add(fdef.clone());

    let clean = |v: [f32; 3]| v.map(|x| if x.is_finite() { x } else { 0.0 });
    let vertices: Vec<Vertex> = mesh
        .vertices
        .iter()
        .zip(vertex_b)
        .map(|(p, b)| Vertex {
            p: clean(p.to_array()),
            b: clean(*b),
            c: srgb8(*b, exposure),
        })
        .collect();
    let faces: Vec<Face> = (0..mesh.patches.len())
        .map(|i| Face(mesh.patch_indices(i).to_vec()))
        .collect();
    if faces.iter().any(|f| f.0.len() > u8::MAX as usize) {
        return Err(io::Error::other("a patch has more than 255 vertices"));
    }

    let mut out = io::BufWriter::new(w);
    Writer::<Vertex>::new().write_header(&mut out, &header)?;
    Writer::<Vertex>::new().write_payload_of_element(&mut out, &vertices, &vdef, &header)?;
    Writer::<Face>::new().write_payload_of_element(&mut out, &faces, &fdef, &header)?;
    out.flush()?;
    Ok(exposure)
}
