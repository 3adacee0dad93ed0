//! glTF 2.0 models (`.gltf` with its buffers and images beside it or in `data:` URIs, and
//! `.glb`) through the `gltf` crate: the only code in the crate that reads glTF
//! (docs/design.md §13).
//!
//! The default scene (or the first, or every root node when the file names none) is walked
//! from its roots, each node's transform (matrix, or translation × rotation × scale) composed
//! with its parents'; every triangle of every mesh primitive (indexed or not; strips and fans
//! unrolled; points and lines are not surfaces) becomes a polygon of the [`Scene`], turned
//! round where its node's transform mirrors. Materials follow `materials.rs`, lights
//! [`lights`]. glTF is Y-up and in metres, which are the tool's defaults; `--scale` serves
//! the models that are not. Faces of zero area are dropped with one warning; `--emit`,
//! `--flip` and the merge of doubled faces apply as for OBJ.
//!
//! Anything wrong with the file is one line naming it and the part (buffer, accessor, node,
//! material) — never a panic: the buffers and accessors are read here with checked arithmetic
//! (`data.rs`), the node graph is walked with its cycles found, and the document is validated
//! by the crate first.

mod data;
pub mod lights;
mod materials;
#[cfg(test)]
mod tests;

use super::obj::to_f64;
use super::{Polygon, Scene, SceneError};
use crate::scene::LoadOptions;
use data::{describe, read_accessor, Buffers};
use glam::{DMat4, DVec3, Vec3};
use gltf::mesh::Mode;
use std::path::Path;

/// Extensions a file may require that the loader reads or that do not change diffuse light.
const UNDERSTOOD: &[&str] = &[
    "KHR_lights_punctual",
    "KHR_materials_emissive_strength",
    "KHR_materials_transmission",
    "KHR_materials_unlit",
    "KHR_materials_ior",
    "KHR_materials_specular",
    "KHR_materials_volume",
    "KHR_materials_clearcoat",
    "KHR_materials_sheen",
    "KHR_texture_transform",
];

/// The most node visits a walk makes: a graph that shares nodes between parents (which glTF
/// forbids) can otherwise multiply them without end.
const MAX_NODE_VISITS: usize = 10_000_000;

/// The most triangles a model may unfold into (a mesh counted once per node that places
/// it): about the tool's patch limit, far above a building's.
const MAX_TRIANGLES: usize = 20_000_000;

/// Whether `path` names a glTF model (`.gltf` or `.glb`, any case).
pub fn is_gltf(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"))
}

/// Loads a `.gltf` or `.glb` file, its buffers and images found beside it.
pub fn load_gltf(path: &Path, opts: &LoadOptions) -> Result<Scene, SceneError> {
    let name = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| {
        SceneError::new(
            &name,
            format!("cannot read the file: {}", super::obj::io_reason(&e)),
        )
    })?;
    load_gltf_from_slice(&name, &bytes, path.parent(), opts)
}

/// Loads a glTF model from its bytes; `name` stands for the file in messages, `dir` is where
/// its buffers and images are looked for (`None`: only embedded ones are read).
pub fn load_gltf_from_slice(
    name: &str,
    bytes: &[u8],
    dir: Option<&Path>,
    opts: &LoadOptions,
) -> Result<Scene, SceneError> {
    let fail = |message: String| SceneError::new(name, message);
    let glb_name = Path::new(name)
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"));
    let gltf::Gltf { document, blob } = parse(bytes, glb_name).map_err(fail)?;
    let mut warnings = Vec::new();
    let buffers = Buffers::load(&document, blob, dir).map_err(fail)?;
    let materials =
        materials::convert(&document, &buffers, dir, name, &mut warnings).map_err(fail)?;
    let mut scene = Scene {
        name: name.to_string(),
        materials,
        ..Scene::default()
    };
    let zenith = opts.zenith.map_or(crate::sky::DEFAULT_ZENITH, Vec3::from);
    let walk = Walk {
        buffers: &buffers,
        file: Path::new(name),
        zenith: zenith.as_dvec3(),
    };
    walk.scene(&document, &mut scene, &mut warnings)
        .map_err(fail)?;
    finish(name, scene, warnings, opts)
}

/// The document, validated; a file that is not glTF, a `.glb` cut short, a document the
/// crate finds invalid or one that requires an extension not read here is an error.
fn parse(bytes: &[u8], glb_name: bool) -> Result<gltf::Gltf, String> {
    if glb_name && !bytes.starts_with(b"glTF") && !bytes.trim_ascii_start().starts_with(b"{") {
        return Err("not a .glb file (it does not begin with 'glTF')".into());
    }
    // The crate subtracts the header's 12 bytes from the length it declares unchecked.
    if bytes.starts_with(b"glTF") {
        let declared = bytes
            .get(8..12)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]));
        if declared.is_none_or(|n| n < 12) {
            return Err("not a readable .glb file (its header is cut short)".into());
        }
    }
    let gltf = gltf::Gltf::from_slice_without_validation(bytes).map_err(|e| match e {
        gltf::Error::Binary(b) => format!("not a readable .glb file ({})", glb_fault(&b)),
        gltf::Error::Deserialize(d) => format!("not a readable glTF document ({d})"),
        other => format!("not a readable glTF file ({other})"),
    })?;
    // Before the crate's validation, which refuses every required extension it has no
    // feature for, even those that change nothing here.
    if let Some(ext) = gltf
        .document
        .extensions_required()
        .find(|e| !UNDERSTOOD.contains(e))
    {
        return Err(format!(
            "it requires the extension {ext}, which this tool does not read (compressed \
             geometry and textures must be decompressed first, e.g. with gltf-transform)"
        ));
    }
    validate(gltf.document.as_json())?;
    Ok(gltf)
}

/// What is wrong with a `.glb`'s container, in words.
fn glb_fault(e: &gltf::binary::Error) -> String {
    use gltf::binary::Error as E;
    match e {
        E::Version(v) => format!("glTF binary version {v}; only version 2 is read"),
        E::Length {
            length,
            length_read,
        } => format!("cut short: its header says {length} bytes, the file has {length_read}"),
        E::ChunkLength {
            ty,
            length,
            length_read,
        } => format!("cut short: its {ty:?} chunk says {length} bytes, {length_read} are left"),
        other => other.to_string(),
    }
}

/// The crate's validation of the document (indices in range, required fields, valid
/// enumerations: what its accessors rely on), forgiving only the accessors' `min` and `max`,
/// which exporters leave out and the loader does not read.
fn validate(root: &gltf::json::Root) -> Result<(), String> {
    use gltf::json::validation::{Error, Validate};
    // The crate's check of a primitive's POSITION reads its accessor before any check that
    // it exists (gltf-json 1.4 indexes the accessors unchecked there).
    let accessors = root.accessors.len();
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            if let Some(a) = prim.attributes.values().find(|a| a.value() >= accessors) {
                return Err(format!(
                    "an invalid glTF document (meshes[{m}].primitives[{p}] names accessor {}, of {accessors})",
                    a.value()
                ));
            }
        }
    }
    let mut errors = Vec::new();
    root.validate(root, gltf::json::Path::new, &mut |path, error| {
        let path = path().to_string();
        let bounds = path.ends_with(".min") || path.ends_with(".max");
        let forgiven = match error {
            Error::Missing => bounds,
            // Required extensions were checked against `UNDERSTOOD` already.
            Error::Unsupported => path.starts_with("extensions"),
            _ => false,
        };
        if !forgiven {
            errors.push(format!("{path}: {error}"));
        }
    });
    if errors.is_empty() {
        return Ok(());
    }
    let more = match errors.len() {
        n if n > 3 => format!(" and {} more", n - 3),
        _ => String::new(),
    };
    errors.truncate(3);
    Err(format!(
        "an invalid glTF document ({}{more})",
        errors.join("; ")
    ))
}

/// The common end of loading: faces of zero area dropped (a warning), none left an error;
/// `--emit`, `--flip` and the merge of doubled faces.
fn finish(
    name: &str,
    mut scene: Scene,
    mut warnings: Vec<String>,
    opts: &LoadOptions,
) -> Result<Scene, SceneError> {
    let fail = |message: String| SceneError::new(name, message);
    let total = scene.polygons.len();
    let (lo, hi) = scene.bounds();
    let diag2 = f64::from((hi - lo).length_squared());
    scene.polygons.retain(|p| {
        let v = &scene.indices[p.first as usize..(p.first + p.len) as usize];
        let [a, b, c] = [0, 1, 2].map(|k| scene.positions[v[k] as usize].as_dvec3());
        (b - a).cross(c - a).length() / 2.0 > super::obj::ZERO_AREA * diag2
    });
    if scene.polygons.is_empty() {
        return Err(fail(if total == 0 {
            "no polygons (no mesh with triangles in its scene)".into()
        } else {
            format!("all {total} faces have zero area")
        }));
    }
    if scene.polygons.len() < total {
        warnings.push(format!(
            "{name}: {} faces of zero area dropped",
            total - scene.polygons.len()
        ));
    }
    super::obj::apply_emit(&mut scene.materials, &opts.emit).map_err(fail)?;
    scene.warnings = warnings;
    if opts.flip {
        super::sides::flip(&mut scene);
    }
    scene.merged = super::sides::merge_coincident(&mut scene);
    Ok(scene)
}

/// What the walk over the node graph needs.
struct Walk<'a> {
    buffers: &'a Buffers,
    file: &'a Path,
    zenith: DVec3,
}

impl Walk<'_> {
    /// Every node of the document's scene, depth first, meshes and lights placed.
    fn scene(
        &self,
        doc: &gltf::Document,
        scene: &mut Scene,
        warnings: &mut Vec<String>,
    ) -> Result<(), String> {
        let roots: Vec<gltf::Node> = match doc.default_scene().or_else(|| doc.scenes().next()) {
            Some(s) => s.nodes().collect(),
            None => {
                let mut child = vec![false; doc.nodes().len()];
                for n in doc.nodes() {
                    for c in n.children() {
                        child[c.index()] = true;
                    }
                }
                doc.nodes().filter(|n| !child[n.index()]).collect()
            }
        };
        let mut stack: Vec<(gltf::Node, DMat4, usize)> = roots
            .into_iter()
            .rev()
            .map(|n| (n, DMat4::IDENTITY, 0))
            .collect();
        // The nodes on the path from the root to the one visited: a child among them is a cycle.
        let mut path: Vec<usize> = Vec::new();
        let mut on_path = vec![false; doc.nodes().len()];
        let (mut visits, mut skipped, mut dark) = (0usize, 0usize, Vec::new());
        let mut suns = Vec::new();
        while let Some((node, parent, depth)) = stack.pop() {
            for left in path.drain(depth.min(path.len())..) {
                on_path[left] = false;
            }
            if on_path[node.index()] {
                return Err(format!(
                    "{} is its own ancestor: the node hierarchy has a cycle",
                    describe("node", node.index(), node.name())
                ));
            }
            visits += 1;
            if visits > MAX_NODE_VISITS {
                return Err(format!(
                    "the node hierarchy unfolds into more than {MAX_NODE_VISITS} nodes (nodes shared between parents)"
                ));
            }
            let local = local_transform(&node);
            let world = parent * local;
            if !world.is_finite() {
                return Err(format!(
                    "{}: its transform is not finite",
                    describe("node", node.index(), node.name())
                ));
            }
            if let Some(mesh) = node.mesh() {
                skipped += self.mesh(&mesh, &world, scene)?;
            }
            if let Some(light) = node.light() {
                let label = light
                    .name()
                    .or(node.name())
                    .map_or_else(|| format!("light {}", light.index()), str::to_string);
                match lights::place(&light, &world, (self.file, &label), self.zenith)? {
                    lights::Placed::Luminaire(l) => scene.luminaires.push(l),
                    lights::Placed::Sun(s) => suns.push(s),
                    lights::Placed::Dark(why) => dark.push(why),
                }
            }
            path.push(node.index());
            on_path[node.index()] = true;
            for child in node.children().collect::<Vec<_>>().into_iter().rev() {
                stack.push((child, world, depth + 1));
            }
        }
        let name = self.file.display();
        if skipped > 0 {
            warnings.push(format!(
                "{name}: {skipped} primitives of points or lines left out (not surfaces)"
            ));
        }
        if !dark.is_empty() {
            warnings.push(format!(
                "{name}: lights that give no light left out: {}",
                dark.join(", ")
            ));
        }
        if suns.len() > 1 {
            warnings.push(format!(
                "{name}: {} directional lights; the first, '{}', is the sun, the others are left out",
                suns.len(),
                suns[0].name
            ));
        }
        scene.sun = suns.into_iter().next();
        Ok(())
    }

    /// The triangles of every primitive of `mesh` placed by `world`; the count of primitives
    /// left out (points and lines).
    fn mesh(&self, mesh: &gltf::Mesh, world: &DMat4, scene: &mut Scene) -> Result<usize, String> {
        let mirror = world.determinant() < 0.0;
        let default_material = (scene.materials.len() - 1) as u32;
        let mut skipped = 0;
        for prim in mesh.primitives() {
            let what = format!(
                "{}, primitive {}",
                describe("mesh", mesh.index(), mesh.name()),
                prim.index()
            );
            let Some(acc) = prim.get(&gltf::Semantic::Positions) else {
                return Err(format!("{what} has no POSITION"));
            };
            let (p, n) = read_accessor(&acc, self.buffers, &format!("the positions of {what}"))?;
            if n != 3 {
                return Err(format!("{what}: its positions have {n} components, not 3"));
            }
            let count = p.len() / 3;
            let indices: Vec<usize> = match prim.indices() {
                Some(acc) => {
                    let (v, _) =
                        read_accessor(&acc, self.buffers, &format!("the indices of {what}"))?;
                    let mut out = Vec::with_capacity(v.len());
                    for x in v {
                        let i = x as usize;
                        if x < 0.0 || x.fract() != 0.0 || i >= count {
                            return Err(format!(
                                "{what}: index {x} is not one of its {count} vertices"
                            ));
                        }
                        out.push(i);
                    }
                    out
                }
                None => (0..count).collect(),
            };
            let triangles = match triangles(prim.mode(), &indices) {
                Some(t) => t,
                None => {
                    skipped += 1;
                    continue;
                }
            };
            if scene.polygons.len() + triangles.len() > MAX_TRIANGLES {
                return Err(format!(
                    "the model unfolds into more than {MAX_TRIANGLES} triangles (its meshes placed by all their nodes)"
                ));
            }
            let base = scene.positions.len() as u32;
            for k in 0..count {
                let v = world.transform_point3(DVec3::new(p[3 * k], p[3 * k + 1], p[3 * k + 2]));
                let v = v.as_vec3();
                if !v.is_finite() {
                    return Err(format!(
                        "{what}: vertex {k} placed by its nodes is not finite in single precision"
                    ));
                }
                scene.positions.push(v);
            }
            let material = prim
                .material()
                .index()
                .map_or(default_material, |i| i as u32);
            for [a, b, c] in triangles {
                let (b, c) = if mirror { (c, b) } else { (b, c) };
                let first = scene.indices.len() as u32;
                scene.indices.extend([a, b, c].map(|i| base + i as u32));
                scene.polygons.push(Polygon {
                    first,
                    len: 3,
                    material,
                    back_material: None,
                });
            }
        }
        Ok(skipped)
    }
}

/// A node's own transform in double precision, its numbers read at their decimal value (a
/// translation of 1.8 is 1.8, not 1.7999999523): the matrix, or translation × rotation ×
/// scale with the rotation's quaternion normalised.
fn local_transform(node: &gltf::Node) -> DMat4 {
    let v3 = |v: [f32; 3]| DVec3::from(v.map(to_f64));
    match node.transform() {
        gltf::scene::Transform::Matrix { matrix } => {
            DMat4::from_cols_array_2d(&matrix.map(|c| c.map(to_f64)))
        }
        gltf::scene::Transform::Decomposed {
            translation,
            rotation,
            scale,
        } => {
            let q = glam::DQuat::from_array(rotation.map(to_f64));
            let q = if q.length_squared() > 0.0 {
                q.normalize()
            } else {
                glam::DQuat::IDENTITY
            };
            DMat4::from_scale_rotation_translation(v3(scale), q, v3(translation))
        }
    }
}

/// The triangles of a primitive of `mode` over `indices` (strips and fans unrolled, each
/// wound as its first); `None` for points and lines.
fn triangles(mode: Mode, idx: &[usize]) -> Option<Vec<[usize; 3]>> {
    let t = match mode {
        Mode::Triangles => idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        Mode::TriangleStrip => (2..idx.len())
            .map(|k| {
                if k % 2 == 0 {
                    [idx[k - 2], idx[k - 1], idx[k]]
                } else {
                    [idx[k - 1], idx[k - 2], idx[k]]
                }
            })
            .collect(),
        Mode::TriangleFan => (2..idx.len())
            .map(|k| [idx[0], idx[k - 1], idx[k]])
            .collect(),
        Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip => return None,
    };
    Some(t)
}
