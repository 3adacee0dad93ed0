//! Tests of OBJ/MTL loading: the built-in scene, emission overrides, geometry and files here;
//! every error and the OBJ spellings tobj misses in [`errors`]; textures and glazing in
//! [`materials`].

use super::mtl::{parse_colour, to_f64};
use super::text::{name_list, one_line, snippet};
use super::*;
use crate::scene::{default_scene, RhoSource, DEFAULT_SCENE_NAME, MAX_REFLECTANCE};
use glam::DVec3;

mod errors;
mod materials;

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
        ..LoadOptions::default()
    };
    let scene = default_scene(&opts).unwrap();
    assert_eq!(material(&scene, "white").ke, [1.0, 2.0, 3.0]);
    assert_eq!(material(&scene, "light").ke, [17.0, 12.0, 4.0]);
    // Turning the light off leaves a scene without emitter: not this loader's concern.
    let opts = LoadOptions {
        emit: vec![("light".into(), [0.0; 3])],
        ..LoadOptions::default()
    };
    let scene = default_scene(&opts).unwrap();
    assert!(!scene.has_emitter());
}

#[test]
fn emit_unknown_material_is_an_error_listing_the_materials() {
    let opts = LoadOptions {
        emit: vec![("lamp".into(), [1.0; 3])],
        ..LoadOptions::default()
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
            ..LoadOptions::default()
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
    let obj = "\u{feff}mtllib m.mtl\r\nv 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nusemtl grey\r\nf 1 2 3\r\n";
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
            material: 0,
            back_material: None,
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
        "mtllib a.mtl b.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n\
         usemtl lamp\nf 1 2 3\nusemtl wall\nf 2 4 3\n",
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
