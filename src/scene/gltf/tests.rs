//! The glTF loader on documents written here: transforms, winding, primitives, materials,
//! lights and the faults a file can have.

use super::*;
use base64::Engine;
use serde_json::{json, Value};

/// A document of one buffer (a data URI) holding `positions` (f32 VEC3) and, if given,
/// `indices` (u16), with `extra` merged into its top level (meshes, nodes, …).
fn document(positions: &[[f32; 3]], indices: Option<&[u16]>, extra: Value) -> Vec<u8> {
    let mut buf: Vec<u8> = positions
        .iter()
        .flat_map(|p| p.iter().flat_map(|c| c.to_le_bytes()))
        .collect();
    let pos_len = buf.len();
    let mut accessors = vec![json!({"bufferView": 0, "componentType": 5126,
        "count": positions.len(), "type": "VEC3"})];
    let mut views = vec![json!({"buffer": 0, "byteOffset": 0, "byteLength": pos_len})];
    if let Some(idx) = indices {
        buf.extend(idx.iter().flat_map(|i| i.to_le_bytes()));
        views.push(json!({"buffer": 0, "byteOffset": pos_len, "byteLength": idx.len() * 2}));
        accessors.push(
            json!({"bufferView": 1, "componentType": 5123, "count": idx.len(),
            "type": "SCALAR"}),
        );
    }
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&buf)
    );
    let mut doc = json!({
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": buf.len(), "uri": uri}],
        "bufferViews": views,
        "accessors": accessors,
    });
    for (k, v) in extra.as_object().unwrap() {
        doc[k] = v.clone();
    }
    serde_json::to_vec(&doc).unwrap()
}

fn load(bytes: &[u8]) -> Result<Scene, SceneError> {
    load_gltf_from_slice("t.gltf", bytes, None, &LoadOptions::default())
}

/// One triangle in the XZ plane facing +Y (counter-clockwise seen from above).
const TRI: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]];

fn normal(s: &Scene, p: usize) -> DVec3 {
    let v = s.polygon_indices(&s.polygons[p]);
    let [a, b, c] = [0, 1, 2].map(|k| s.positions[v[k] as usize].as_dvec3());
    (b - a).cross(c - a).normalize()
}

fn one_mesh(nodes: Value) -> Value {
    json!({
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "nodes": nodes,
        "scenes": [{"nodes": [0]}],
        "scene": 0,
    })
}

#[test]
fn node_transforms_compose_from_the_root() {
    // Root: translate (10, 0, 0); child: scale 2 then rotate 90° about Y, holding the mesh.
    let q = (std::f64::consts::FRAC_PI_4).sin() as f32;
    let nodes = json!([
        {"translation": [10.0, 0.0, 0.0], "children": [1]},
        {"scale": [2.0, 2.0, 2.0], "rotation": [0.0, q, 0.0, q], "mesh": 0},
    ]);
    let s = load(&document(&TRI, None, one_mesh(nodes))).unwrap();
    // Rotating 90° about +Y takes +Z to +X and +X to −Z.
    let want = [[10.0, 0.0, 0.0], [12.0, 0.0, 0.0], [10.0, 0.0, -2.0]];
    for (p, w) in s.positions.iter().zip(want) {
        assert!(
            (p.as_dvec3() - DVec3::from(w)).length() < 1e-5,
            "{p} vs {w:?}"
        );
    }
    assert!((normal(&s, 0) - DVec3::Y).length() < 1e-6);
}

#[test]
fn a_mirroring_transform_keeps_faces_facing_out() {
    let nodes = json!([{"scale": [-1.0, 1.0, 1.0], "mesh": 0}]);
    let s = load(&document(&TRI, None, one_mesh(nodes))).unwrap();
    // Mirrored in X, the triangle still faces +Y: its winding was turned round.
    assert!((normal(&s, 0) - DVec3::Y).length() < 1e-6);
}

#[test]
fn strips_fans_and_indexed_triangles_unroll_alike() {
    let quad = [
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [1.0, 0.0, 0.0],
    ];
    for (mode, idx) in [
        (4, vec![0u16, 1, 2, 0, 2, 3]),
        (5, vec![1, 2, 0, 3]),
        (6, vec![0, 1, 2, 3]),
    ] {
        let extra = json!({
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "mode": mode}]}],
            "nodes": [{"mesh": 0}],
            "scenes": [{"nodes": [0]}],
        });
        let s = load(&document(&quad, Some(&idx), extra)).unwrap();
        assert_eq!(s.polygons.len(), 2, "mode {mode}");
        for p in 0..2 {
            assert!(
                (normal(&s, p) - DVec3::Y).length() < 1e-6,
                "mode {mode}, triangle {p}"
            );
        }
    }
    // Lines are not surfaces: a file of lines only has no polygons.
    let extra = json!({
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "mode": 1}]}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}],
    });
    let e = load(&document(&TRI[..2], None, extra)).unwrap_err();
    assert!(e.to_string().contains("no polygons"), "{e}");
}

/// A 2×1 PNG of the sRGB colours (255, 0, 0) and (0, 0, 255), as a data URI.
fn png_uri() -> String {
    let img = image::RgbImage::from_raw(2, 1, vec![255, 0, 0, 0, 0, 255]).unwrap();
    let mut png = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    format!(
        "data:image/png;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&png)
    )
}

#[test]
fn materials_become_reflectance_glazing_and_emission() {
    let materials = json!([
        {"name": "textured", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.6, 0.4, 1.0],
            "baseColorTexture": {"index": 0}}},
        {"name": "glass", "pbrMetallicRoughness": {"baseColorFactor": [0.9, 1.0, 0.9, 1.0]},
            "extensions": {"KHR_materials_transmission": {"transmissionFactor": 0.8}}},
        {"name": "blend", "alphaMode": "BLEND",
            "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 0.25]}},
        {"name": "panel", "emissiveFactor": [1.0, 0.5, 0.25],
            "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}}},
    ]);
    let prims: Vec<Value> = (0..4)
        .map(|m| json!({"attributes": {"POSITION": 0}, "material": m}))
        .collect();
    let extra = json!({
        "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_emissive_strength"],
        "images": [{"uri": png_uri()}],
        "textures": [{"source": 0}],
        "materials": materials,
        "meshes": [{"primitives": prims}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}],
    });
    let s = load(&document(&TRI, None, extra)).unwrap();
    let m = |n: &str| s.materials.iter().find(|m| m.name == n).unwrap();
    let close = |a: [f64; 3], b: [f64; 3]| (0..3).all(|c| (a[c] - b[c]).abs() < 1e-9);
    // The texture's mean in linear light: (0.5, 0, 0.5).
    assert!(
        close(m("textured").rho, [0.4, 0.0, 0.2]),
        "{:?}",
        m("textured").rho
    );
    let glass = m("glass");
    assert!(close(glass.rho, [0.18, 0.2, 0.18]), "{:?}", glass.rho);
    assert!(close(glass.transmittance_rgb.unwrap(), [0.72, 0.8, 0.72]));
    assert!((glass.transmittance - 2.24 / 3.0).abs() < 1e-9);
    let blend = m("blend");
    assert!(close(blend.rho, [0.125; 3]) && (blend.transmittance - 0.75).abs() < 1e-12);
    assert_eq!(blend.transmittance_rgb, None);
    assert!(close(m("panel").ke, [4.0, 2.0, 1.0]));
}

#[test]
fn punctual_lights_are_luminaires_and_a_directional_light_the_sun() {
    // A spot 3 m up, its node turned so that its −Z points down (−90° about X).
    let q = (std::f64::consts::FRAC_PI_4).sin() as f32;
    let extra = json!({
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "point", "intensity": 100.0, "color": [1.0, 1.0, 1.0], "name": "bulb"},
            {"type": "spot", "intensity": 500.0, "spot": {"innerConeAngle": 0.3, "outerConeAngle": 0.6}},
            {"type": "directional", "intensity": 50000.0, "name": "sun"},
        ]}},
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "nodes": [
            {"mesh": 0, "children": [1, 2, 3]},
            {"translation": [1.0, 2.0, 3.0], "extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"name": "downlight", "translation": [0.0, 3.0, 0.0], "rotation": [-q, 0.0, 0.0, q],
                "extensions": {"KHR_lights_punctual": {"light": 1}}},
            {"rotation": [-q, 0.0, 0.0, q], "extensions": {"KHR_lights_punctual": {"light": 2}}},
        ],
        "scenes": [{"nodes": [0]}],
    });
    let s = load(&document(&TRI, None, extra)).unwrap();
    assert_eq!(s.luminaires.len(), 2);
    let bulb = &s.luminaires[0];
    assert_eq!(bulb.name, "bulb");
    assert!((bulb.position - DVec3::new(1.0, 2.0, 3.0)).length() < 1e-12);
    let lm = bulb.flux_lumens();
    assert!(
        (lm / (400.0 * std::f64::consts::PI) - 1.0).abs() < 1e-4,
        "{lm}"
    );
    let spot = &s.luminaires[1];
    assert_eq!(spot.name, "downlight");
    assert!(
        (spot.frame.aim - DVec3::NEG_Y).length() < 1e-6,
        "{}",
        spot.frame.aim
    );
    // Straight down it gives its peak; 40° off its aim (past the outer cone), nothing.
    let peak = spot.intensity_toward(DVec3::NEG_Y);
    assert!(
        (peak[1] * crate::sky::EFFICACY - 500.0).abs() < 1e-9,
        "{peak:?}"
    );
    let off = DVec3::new(40f64.to_radians().sin(), -40f64.to_radians().cos(), 0.0);
    assert_eq!(spot.intensity_toward(off), [0.0; 3]);
    let sun = s.sun.as_ref().unwrap();
    assert!((sun.towards - DVec3::Y).length() < 1e-6 && sun.illuminance == 50000.0);
}

#[test]
fn every_fault_is_one_line_naming_its_part() {
    let cycle = json!({
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "nodes": [{"mesh": 0, "children": [1]}, {"name": "loop", "children": [2]}, {"children": [1]}],
        "scenes": [{"nodes": [0]}],
    });
    let nan = [[0.0, 0.0, 0.0], [f32::NAN, 0.0, 1.0], [1.0, 0.0, 0.0]];
    let mut missing: Value =
        serde_json::from_slice(&document(&TRI, None, one_mesh(json!([{"mesh": 0}])))).unwrap();
    missing["buffers"][0]["uri"] = json!("walls.bin");
    let mut short = missing.clone();
    short["buffers"][0]["uri"] = json!("data:application/octet-stream;base64,AAAA");
    let required = json!({"extensionsRequired": ["KHR_draco_mesh_compression"],
        "extensionsUsed": ["KHR_draco_mesh_compression"]});
    let cases: Vec<(Vec<u8>, &[&str])> = vec![
        (document(&TRI, None, cycle), &["node 1 'loop'", "cycle"]),
        (
            document(&nan, None, one_mesh(json!([{"mesh": 0}]))),
            &["accessor 0", "element 1", "NaN"],
        ),
        (
            serde_json::to_vec(&missing).unwrap(),
            &["buffer 0", "walls.bin"],
        ),
        (
            serde_json::to_vec(&short).unwrap(),
            &["buffer 0", "3 bytes", "byteLength says 36"],
        ),
        (
            document(
                &TRI,
                Some(&[0, 1, 7]),
                json!({
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
            "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}]}),
            ),
            &["index 7", "3 vertices"],
        ),
        (
            document(&TRI, None, required),
            &["KHR_draco_mesh_compression"],
        ),
        (b"glTF\x02\x00\x00\x00\xff\xff".to_vec(), &[".glb"]),
        (b"{ not json".to_vec(), &["glTF document"]),
    ];
    for (bytes, words) in cases {
        let e = load(&bytes).unwrap_err().to_string();
        assert!(!e.contains('\n'), "{e}");
        assert!(e.starts_with("t.gltf: "), "{e}");
        for w in words {
            assert!(e.contains(w), "'{w}' not in: {e}");
        }
    }
}

#[test]
fn scale_multiplies_the_model_and_its_lights_and_a_huge_model_is_warned_of() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("mm.gltf");
    let big = TRI.map(|p| p.map(|c| c * 6000.0));
    let extra = json!({
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 10.0}]}},
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "nodes": [{"mesh": 0}, {"translation": [3000.0, 2000.0, 0.0],
            "extensions": {"KHR_lights_punctual": {"light": 0}}}],
        "scenes": [{"nodes": [0, 1]}],
    });
    std::fs::write(&path, document(&big, None, extra)).unwrap();
    let source = crate::scene::SceneSource::File(path);
    let raw = source.load(&LoadOptions::default()).unwrap();
    assert!(
        raw.warnings
            .iter()
            .any(|w| w.contains("6000 m across") && w.contains("--scale")),
        "{:?}",
        raw.warnings
    );
    let opts = LoadOptions {
        scale: Some(0.001),
        ..LoadOptions::default()
    };
    let s = source.load(&opts).unwrap();
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    assert_eq!(s.bounds().1, Vec3::new(6.0, 0.0, 6.0));
    assert!((s.luminaires[0].position - DVec3::new(3.0, 2.0, 0.0)).length() < 1e-12);
}

#[test]
fn a_required_extension_that_changes_nothing_here_is_read_past() {
    let extra = json!({
        "extensionsRequired": ["KHR_texture_transform", "KHR_materials_specular"],
        "extensionsUsed": ["KHR_texture_transform", "KHR_materials_specular"],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}],
    });
    let s = load(&document(&TRI, None, extra)).unwrap();
    assert_eq!(s.polygons.len(), 1);
}
