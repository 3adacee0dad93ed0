//! glTF models: a furnished room written as a glTF 2.0 file (a room mesh, one box mesh placed
//! four times by node transforms — one of them mirrored —, a textured floor, a point light and
//! an aimed spot light of `KHR_lights_punctual`) and as the same room in OBJ + MTL with a
//! `--luminaires` schedule of IES files holding the lights' webs. Both solve to the same
//! answer: the same triangles, the same reflectances, the same luminaires, so the same patch
//! table and grid, byte for byte. A `.glb` of the same document reads the same as the `.gltf`.

use base64::Engine;
use glam::{DMat4, DQuat, DVec3};
use radiosity::scene::gltf::lights::{web_text, Web};
use serde_json::{json, Value};
use std::fmt::Write as _;
use std::path::Path;

use crate::common::run;

/// The unit cube's corners and its 12 triangles, wound to face out.
fn cube() -> (Vec<[f32; 3]>, Vec<[u16; 3]>) {
    let p: Vec<[f32; 3]> = (0..8)
        .map(|i| [(i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32])
        .collect();
    // Quads (a, b, c, d) counter-clockwise seen from outside.
    let quads = [
        [0, 4, 6, 2], // x = 0
        [1, 3, 7, 5], // x = 1
        [0, 1, 5, 4], // y = 0
        [2, 6, 7, 3], // y = 1
        [0, 2, 3, 1], // z = 0
        [4, 5, 7, 6], // z = 1
    ];
    let t = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    (p, t)
}

/// The room's mesh: the cube's triangles turned inside out (faces looking in).
fn room_triangles(t: &[[u16; 3]]) -> Vec<[u16; 3]> {
    t.iter().map(|&[a, b, c]| [a, c, b]).collect()
}

/// (mesh: 0 the room, 1 a box; material; node transform). Node k shows a mesh of its own,
/// naming its material.
fn placements() -> Vec<(usize, usize, DMat4)> {
    let srt = |s: [f64; 3], t: [f64; 3]| {
        DMat4::from_scale_rotation_translation(DVec3::from(s), DQuat::IDENTITY, DVec3::from(t))
    };
    vec![
        (0, 0, srt([5.0, 2.8, 4.0], [0.0, 0.0, 0.0])),
        (1, 1, srt([1.6, 0.05, 0.9], [1.0, 0.72, 1.2])), // table top
        (1, 1, srt([0.05, 0.72, 0.9], [1.0, 0.0, 1.2])), // its leg panel
        // A cabinet mirrored in X: scale −0.5 from x = 4.9 covers 4.4..4.9.
        (1, 2, srt([-0.5, 1.9, 1.2], [4.9, 0.0, 2.6])),
        (1, 3, srt([5.0, 0.001, 4.0], [0.0, 0.0, 0.0])), // a floor covering
    ]
}

/// (name, Kd).
const MATERIALS: [(&str, [f64; 3]); 4] = [
    ("walls", [0.7, 0.68, 0.65]),
    ("wood", [0.45, 0.3, 0.2]),
    ("metal", [0.6, 0.6, 0.62]),
    ("carpet", [0.9, 0.8, 0.7]),
];

/// A 2×2 sRGB texture for the carpet.
fn texture_png() -> Vec<u8> {
    let img = image::RgbImage::from_raw(
        2,
        2,
        vec![200, 40, 40, 40, 200, 40, 40, 40, 200, 90, 90, 90],
    )
    .unwrap();
    let mut png = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    png
}

/// Where the lights are: (name, position, the spot's cone or none, its aim).
fn lights() -> Vec<(&'static str, DVec3, Web, DVec3, f64)> {
    let tilt = 20f64.to_radians();
    vec![
        (
            "bulb",
            DVec3::new(3.5, 2.5, 1.0),
            Web::Point,
            DVec3::NEG_Y,
            180.0,
        ),
        (
            "spot",
            DVec3::new(1.8, 2.7, 1.6),
            Web::Spot {
                inner: 0.25,
                outer: 0.5,
            },
            DVec3::new(0.0, -tilt.cos(), tilt.sin()),
            900.0,
        ),
    ]
}

/// The glTF document (its buffer inline).
fn gltf_document() -> Value {
    let (p, t) = cube();
    let mut buf: Vec<u8> = p
        .iter()
        .flat_map(|v| v.iter().flat_map(|c| c.to_le_bytes()))
        .collect();
    let pos_len = buf.len();
    for tri in room_triangles(&t).iter().chain(&t) {
        buf.extend(tri.iter().flat_map(|i| i.to_le_bytes()));
    }
    let idx_len = t.len() * 6;
    let enc = |b: &[u8]| base64::engine::general_purpose::STANDARD.encode(b);
    let mut nodes: Vec<Value> = placements()
        .iter()
        .enumerate()
        .map(|(k, (_, _, m))| json!({"name": format!("n{k}"), "mesh": k, "matrix": m.to_cols_array()}))
        .collect();
    // Each light looks down its node's −Z: a node turned from −Z to the aim about +X.
    for (k, (name, at, _, aim, _)) in lights().iter().enumerate() {
        let rot = DQuat::from_rotation_arc(DVec3::NEG_Z, *aim);
        nodes.push(
            json!({"name": name, "rotation": rot.to_array(), "translation": at.to_array(),
            "extensions": {"KHR_lights_punctual": {"light": k}}}),
        );
    }
    let lights: Vec<Value> = lights()
        .iter()
        .map(|(name, _, web, _, cd)| match web {
            Web::Point => json!({"type": "point", "name": name, "intensity": cd}),
            Web::Spot { inner, outer } => json!({"type": "spot", "name": name, "intensity": cd,
                "spot": {"innerConeAngle": inner, "outerConeAngle": outer}}),
        })
        .collect();
    let materials: Vec<Value> = MATERIALS
        .iter()
        .map(|(name, kd)| {
            let mut pbr = json!({"baseColorFactor": [kd[0], kd[1], kd[2], 1.0]});
            if *name == "carpet" {
                pbr["baseColorTexture"] = json!({"index": 0});
            }
            json!({"name": name, "pbrMetallicRoughness": pbr})
        })
        .collect();
    let mesh = |first: usize, material: usize| json!({"primitives": [{"attributes": {"POSITION": 0}, "indices": first, "material": material}]});
    let meshes: Vec<Value> = (0..5)
        .map(|k| mesh(1 + (k > 0) as usize, placements()[k].1))
        .collect();
    json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": lights}},
        "buffers": [{"byteLength": buf.len(), "uri": format!("data:application/octet-stream;base64,{}", enc(&buf))}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": pos_len},
            {"buffer": 0, "byteOffset": pos_len, "byteLength": idx_len},
            {"buffer": 0, "byteOffset": pos_len + idx_len, "byteLength": idx_len},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3"},
            {"bufferView": 1, "componentType": 5123, "count": 36, "type": "SCALAR"},
            {"bufferView": 2, "componentType": 5123, "count": 36, "type": "SCALAR"},
        ],
        "images": [{"uri": format!("data:image/png;base64,{}", enc(&texture_png()))}],
        "textures": [{"source": 0}],
        "materials": materials,
        "meshes": meshes,
        "nodes": nodes,
        "scenes": [{"nodes": (0..7).collect::<Vec<_>>()}],
        "scene": 0,
    })
}

/// The same room as OBJ + MTL (triangles in the glTF walk's order, placed and wound as the
/// loader places them) and a luminaire schedule with an IES file per light.
fn write_obj(dir: &Path) {
    let (p, t) = cube();
    let (mut obj, mut n) = ("mtllib room.mtl\n".to_string(), 0);
    for (k, (_, material, m)) in placements().iter().enumerate() {
        let tris = if k == 0 {
            room_triangles(&t)
        } else {
            t.clone()
        };
        let mirror = m.determinant() < 0.0;
        writeln!(obj, "usemtl {}", MATERIALS[*material].0).unwrap();
        for v in &p {
            let w = m
                .transform_point3(DVec3::new(v[0].into(), v[1].into(), v[2].into()))
                .as_vec3();
            writeln!(obj, "v {} {} {}", w.x, w.y, w.z).unwrap();
        }
        for [a, b, c] in tris {
            let (b, c) = if mirror { (c, b) } else { (b, c) };
            writeln!(
                obj,
                "f {} {} {}",
                n + a as usize + 1,
                n + b as usize + 1,
                n + c as usize + 1
            )
            .unwrap();
        }
        n += 8;
    }
    std::fs::write(dir.join("room.obj"), obj).unwrap();
    let mut mtl = String::new();
    for (name, kd) in MATERIALS {
        writeln!(mtl, "newmtl {name}\nKd {} {} {}", kd[0], kd[1], kd[2]).unwrap();
        if name == "carpet" {
            mtl += "map_Kd carpet.png\n";
        }
    }
    std::fs::write(dir.join("room.mtl"), mtl).unwrap();
    std::fs::write(dir.join("carpet.png"), texture_png()).unwrap();
    let mut csv = "name,file,x,y,z,aim_x,aim_y,aim_z\n".to_string();
    for (name, at, web, aim, cd) in lights() {
        std::fs::write(dir.join(format!("{name}.ies")), web_text(web, cd, name)).unwrap();
        let to = at + aim;
        writeln!(
            csv,
            "{name},{name}.ies,{},{},{},{},{},{}",
            at.x, at.y, at.z, to.x, to.y, to.z
        )
        .unwrap();
    }
    std::fs::write(dir.join("lights.csv"), csv).unwrap();
}

/// `solve` of `args` into `dir/out`; the patch table and grid it wrote.
fn solve(dir: &Path, out: &str, args: &[&str]) -> (String, String) {
    let o = dir.join(out);
    let o = o.to_str().unwrap();
    let saved = format!("{o}.rad");
    let mut all = vec![
        "solve",
        "-q",
        "--out",
        o,
        "--grid",
        "0.8,0.4",
        "--elements",
        "off",
        "--seed",
        "5",
        "--save",
        &saved,
    ];
    all.extend(args);
    let (code, _, err) = run(&all);
    assert_eq!(code, 0, "{err}");
    let read = |f: &str| std::fs::read_to_string(Path::new(o).join(f)).unwrap();
    (read("patches.csv"), read("grid.csv"))
}

/// The rows of a CSV file of numbers, its header left out.
fn table(csv: &str) -> Vec<Vec<f64>> {
    csv.lines()
        .skip(1)
        .map(|l| {
            l.split(',')
                .map(|x| x.parse().unwrap_or(f64::NAN))
                .collect()
        })
        .collect()
}

/// A `.glb` of `doc`: its JSON chunk and no binary chunk (the buffer stays a data URI).
fn glb(doc: &Value) -> Vec<u8> {
    let mut json = serde_json::to_vec(doc).unwrap();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let total = 12 + 8 + json.len();
    let mut out = Vec::new();
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(json);
    out
}

#[test]
fn a_gltf_room_solves_as_the_same_room_in_obj_with_a_schedule() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let doc = gltf_document();
    std::fs::write(d.join("room.gltf"), serde_json::to_vec(&doc).unwrap()).unwrap();
    std::fs::write(d.join("room.glb"), glb(&doc)).unwrap();
    write_obj(d);
    let gltf = solve(d, "g", &[d.join("room.gltf").to_str().unwrap()]);
    let obj = solve(
        d,
        "o",
        &[
            d.join("room.obj").to_str().unwrap(),
            "--luminaires",
            d.join("lights.csv").to_str().unwrap(),
        ],
    );
    let glb = solve(d, "b", &[d.join("room.glb").to_str().unwrap()]);
    assert!(gltf.1.lines().count() > 50, "a grid of sensors");
    assert!(gltf == glb, "the .glb reads otherwise than the .gltf");
    // The same patches; the lights' rotations are single precision in glTF (aims differ by
    // 1e-9), so the figures agree far inside the sampling error (a few per cent a patch),
    // not bit for bit: measured 5e-10 area-weighted, 3e-8 at the worst sensor.
    let (g, o) = (table(&gltf.0), table(&obj.0));
    assert_eq!(g.len(), o.len(), "patch counts");
    let lux = |row: &Vec<f64>| row[row.len() - 2];
    let (mut diff, mut total) = (0.0, 0.0);
    for (a, b) in g.iter().zip(&o) {
        assert_eq!(a[..8], b[..8], "patch {} is not the same patch", a[0]);
        diff += a[7] * (lux(a) - lux(b)).abs();
        total += a[7] * lux(b);
    }
    assert!(
        diff < 1e-4 * total,
        "patches differ by {} area-weighted",
        diff / total
    );
    for (a, b) in table(&gltf.1).iter().zip(&table(&obj.1)) {
        let (x, y) = (a[6], b[6]);
        assert!(
            (x - y).abs() <= 1e-4 * y,
            "sensor at {:?}: {x} against {y} lux",
            &a[..3]
        );
    }
    // A saved solution of the glTF model finds its lights again (in the model) for a picture.
    let mean = |name: &str| {
        let (sol, png) = (d.join(format!("{name}.rad")), d.join(format!("{name}.hdr")));
        let (sol, png) = (sol.to_str().unwrap(), png.to_str().unwrap());
        let args = [
            "render", sol, "--out", png, "--width", "48", "--height", "36",
        ];
        let (code, _, err) = run(&args);
        assert_eq!(code, 0, "{err}");
        let img = image::open(png).unwrap().into_rgb32f();
        img.pixels().map(|px| f64::from(px[1])).sum::<f64>() / img.pixels().len() as f64
    };
    let (a, b) = (mean("g"), mean("o"));
    assert!(
        b > 0.0 && (a / b - 1.0).abs() < 1e-3,
        "pictures: {a} against {b}"
    );
}
