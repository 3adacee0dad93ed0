//! Tests of OBJ/MTL loading: the built-in scene, materials, geometry and every error.

use super::mtl::{parse_colour, to_f64};
use super::text::{name_list, one_line, snippet};
use super::*;
use crate::scene::{default_scene, RhoSource, DEFAULT_SCENE_NAME, MAX_REFLECTANCE};
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
fn negative_or_non_finite_reflectance_is_an_error() {
    for kd in ["0.5 -0.1 0.5", "0.5 0.5 nan", "inf 0.5 0.5"] {
        let mtl = format!("newmtl m\nKd {kd}\n");
        assert_error(
            load_strs(TRIANGLE_USING_M, &mtl),
            "test.obj",
            &["'m'", "Kd", "not a reflectance", "at least 0"],
        );
    }
    // Just below 1 is kept as it is, without a warning.
    let scene = load_strs(TRIANGLE_USING_M, "newmtl m\nKd 0.999 0 0\n").unwrap();
    assert_eq!(scene.materials[0].rho, [0.999, 0.0, 0.0]);
    assert_eq!(scene.materials[0].rho_source, RhoSource::Kd);
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
}

#[test]
fn reflectance_of_one_or_more_is_clamped_with_one_warning() {
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\n\
               usemtl white\nf 1 2 3\nusemtl hot\nf 2 4 3\nusemtl fine\nf 1 2 5\n";
    let mtl = "newmtl white\nKd 1 1 1\nnewmtl hot\nKd 1.5 0.5 0.25\nnewmtl fine\nKd 0.5 0.5 0.5\n";
    let scene = load_strs(obj, mtl).unwrap();
    assert_eq!(material(&scene, "white").rho, [MAX_REFLECTANCE; 3]);
    assert_eq!(material(&scene, "hot").rho, [MAX_REFLECTANCE, 0.5, 0.25]);
    assert_eq!(material(&scene, "fine").rho, [0.5; 3]);
    assert_eq!(
        material(&scene, "hot").rho_source,
        RhoSource::Clamped {
            unclamped: [1.5, 0.5, 0.25],
            from: Box::new(RhoSource::Kd)
        }
    );
    assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
    let w = &scene.warnings[0];
    for needle in ["test.obj", "clamped to 0.98", "'white'", "'hot'"] {
        assert!(w.contains(needle), "{w:?} lacks {needle:?}");
    }
    assert!(!w.contains("'fine'"), "{w}");
    const { assert!(MAX_REFLECTANCE < 1.0) };
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

// ---- OBJ spellings: comments after the data, continued lines ----

#[test]
fn comments_after_the_data_are_ignored() {
    let obj = "mtllib m.mtl   # the library\n\
               v 0 0 0   # note\nv 1 0 0 #x\nv 0 1 0\t# tab\nv 1 1 0# no space\n\
               g room # group\nusemtl grey # x\nf 1 2 3 # door\nf 2 4 3#\n";
    let mtl = "newmtl grey # the walls\nKd 0.5 0.5 0.5 # grey\nKe 0.25 # dim\n";
    let scene = load_strs(obj, mtl).unwrap();
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    assert_eq!(scene.positions.len(), 4);
    assert_eq!(scene.polygons.len(), 2);
    let m = &scene.materials[scene.polygons[0].material as usize];
    assert_eq!(
        (m.name.as_str(), m.rho, m.ke),
        ("grey", [0.5; 3], [0.25; 3])
    );
}

#[test]
fn a_hash_inside_a_name_is_part_of_it() {
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl wall#2 # comment\nf 1 2 3\n";
    let scene = load_strs(obj, "newmtl wall#2\nKd 0.25 0.25 0.25\n").unwrap();
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    assert_eq!(scene.materials[0].name, "wall#2");
    assert_eq!(scene.materials[0].rho, [0.25; 3]);
}

#[test]
fn backslash_continues_a_line() {
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 \\\n  0\nv 1 1 0\nv 0 1 0\nusemtl grey\n\
               f 1 \\\n2 \\\n  3 \\\r\n4   # a quad over four lines\nf 1 2 3\n";
    let scene = load_strs(obj, GREY_MTL).unwrap();
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    assert_eq!(scene.positions.len(), 4);
    let arities: Vec<u32> = scene.polygons.iter().map(|p| p.len).collect();
    assert_eq!(arities, [4, 3]);
    assert_eq!(scene.positions[1], Vec3::new(1.0, 0.0, 0.0));
}

#[test]
fn a_backslash_in_a_comment_continues_nothing() {
    let obj = "v 0 0 0 # ends in \\\nv 1 0 0\nv 0 1 0\n# a comment \\\nf 1 2 3\n";
    let scene = load_strs(obj, "").unwrap();
    assert_eq!(scene.positions.len(), 3);
    assert_eq!(scene.polygons.len(), 1);
}

#[test]
fn errors_name_the_original_line_after_continued_lines() {
    // Lines 2-4 are one vertex; line 7 is the bad face.
    let obj = "# model\nv 0 \\\n0 \\\n0\nv 1 0 0 # x\nv 0 1 0\nf 1 2 x\n";
    assert_error(
        load_strs(obj, ""),
        "test.obj",
        &["line 7", "cannot read a face", "f 1 2 x"],
    );
    let obj = "v 0 0 0\nf 1 \\\n 2 \\\n 3\nv 1 0 0\nf 1 \\\n 2\n";
    assert_error(
        load_strs(obj, ""),
        "test.obj",
        &["line 6", "a face with 2 vertices"],
    );
    let obj = "v 0 0 0\nv 1 0 0\\\n\nv 0 1 0\nf 1 2 9 # far\n";
    assert_error(
        load_strs(obj, ""),
        "test.obj",
        &["line 5", "vertex 9", "has 3 vertices"],
    );
    let mtl = "newmtl m\nKd 0.5 \\\n 0.5\nNs \\\n shiny\n";
    assert_error(
        load_strs(TRIANGLE_USING_M, mtl),
        "test.obj",
        &["line 2", "needs 3 numbers"],
    );
}

#[test]
fn the_patch_size_comment_still_reads() {
    let obj = "# radiosity: patch-size 0.5\nv 0 0 0 # a\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let scene = load_strs(obj, "").unwrap();
    assert_eq!(scene.patch_size_hint, Some(0.5));
}

#[test]
fn normalize_keeps_every_line_at_its_number() {
    use super::text::normalize;
    assert!(matches!(
        normalize("v 0 0 0\n# c\n"),
        std::borrow::Cow::Borrowed(_)
    ));
    let text = "a \\\nb\nc # x\n# d \\\ne \\\n# f\ng\\";
    let out = normalize(text);
    assert_eq!(out.lines().count(), text.lines().count());
    assert_eq!(out, "a  b\n\nc\n# d \\\ne  \n\ng \n");
}

// ---- textures ----

/// A folder with `model.obj` (a lit triangle of material `m`), `mat/m.mtl` holding `mtl` and
/// the files `files` (paths relative to the folder).
fn textured(mtl: &str, files: &[(&str, Vec<u8>)]) -> (tempfile::TempDir, std::path::PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("model.obj");
    std::fs::write(
        &path,
        "mtllib mat/m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n",
    )
    .unwrap();
    std::fs::create_dir_all(dir.path().join("mat")).unwrap();
    std::fs::write(dir.path().join("mat/m.mtl"), mtl).unwrap();
    for (name, bytes) in files {
        let file = dir.path().join(name);
        std::fs::create_dir_all(file.parent().unwrap()).unwrap();
        std::fs::write(file, bytes).unwrap();
    }
    (dir, path)
}

/// An image of `texels` (RGB, 8-bit) in one row, encoded as `format`.
fn encode(texels: &[[u8; 3]], format: image::ImageFormat) -> Vec<u8> {
    let image = image::RgbImage::from_fn(texels.len() as u32, 1, |x, _| {
        image::Rgb(texels[x as usize])
    });
    let mut bytes = std::io::Cursor::new(Vec::new());
    image.write_to(&mut bytes, format).unwrap();
    bytes.into_inner()
}

fn close(a: [f64; 3], b: [f64; 3], tol: f64) -> bool {
    (0..3).all(|c| (a[c] - b[c]).abs() <= tol)
}

#[test]
fn reflectance_is_kd_times_the_mean_texture_colour_in_linear_light() {
    // Half black, half white: 0.5 in linear light (an sRGB mean would say so too, but see
    // the grey below).
    let half = encode(
        &[[0; 3], [255; 3], [0; 3], [255; 3]],
        image::ImageFormat::Png,
    );
    // sRGB 188 is 0.5 in linear light (not 0.737).
    let grey = encode(&[[188, 188, 188]], image::ImageFormat::Png);
    let mtl = "newmtl m\nKd 0.8 0.6 0.4\nmap_Kd -s 1 1 1 -bm 1 -clamp on textures/half.png\n\
               newmtl g\nKd 1 1 1\nmap_Kd textures/grey.png # grey\n";
    let (_dir, path) = textured(
        mtl,
        &[
            ("mat/textures/half.png", half),
            ("mat/textures/grey.png", grey),
        ],
    );
    let scene = load_obj(&path, &LoadOptions::default()).unwrap();
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let m = material(&scene, "m");
    assert!(close(m.rho, [0.4, 0.3, 0.2], 1e-12), "{:?}", m.rho);
    assert_eq!(
        m.rho_source,
        RhoSource::KdTimesTexture {
            file: "textures/half.png".into(),
            kd: [0.8, 0.6, 0.4],
            mean: [0.5; 3]
        }
    );
    // Kd 1 1 1 with a texture, as exporters write it: ρ is the texture's mean, no clamp.
    let g = material(&scene, "g");
    assert!(close(g.rho, [0.5; 3], 0.005), "{:?}", g.rho);
    assert!(matches!(g.rho_source, RhoSource::KdTimesTexture { .. }));
}

#[test]
fn jpeg_tga_and_bmp_textures_decode() {
    let colour = [[200, 100, 50]; 16];
    let expected = [200.0, 100.0, 50.0].map(|v: f64| super::texture::srgb_to_linear(v / 255.0));
    for (ext, format) in [
        ("jpg", image::ImageFormat::Jpeg),
        ("tga", image::ImageFormat::Tga),
        ("bmp", image::ImageFormat::Bmp),
    ] {
        let file = format!("t.{ext}");
        let mtl = format!("newmtl m\nKd 0.9 0.9 0.9\nmap_Kd ../{file}\n");
        let (_dir, path) = textured(&mtl, &[(&file, encode(&colour, format))]);
        let scene = load_obj(&path, &LoadOptions::default()).unwrap();
        assert!(scene.warnings.is_empty(), "{ext}: {:?}", scene.warnings);
        let rho = scene.materials[0].rho;
        // JPEG is lossy: a few levels of 255.
        assert!(
            close(rho, expected.map(|e| 0.9 * e), 0.02),
            "{ext}: {rho:?}"
        );
    }
}

#[test]
fn a_texture_that_does_not_load_is_one_warning_and_kd_alone() {
    let mtl = "newmtl m\nKd 0.25 0.5 0.75\nmap_Kd missing.png\n\
               newmtl broken\nKd 0.5 0.5 0.5\nmap_Kd broken.png\n\
               newmtl bare\nmap_Kd -bm 1\n";
    let (_dir, path) = textured(mtl, &[("mat/broken.png", b"not a png".to_vec())]);
    let scene = load_obj(&path, &LoadOptions::default()).unwrap();
    assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
    let w = &scene.warnings[0];
    for needle in [
        "3 texture(s) not loaded",
        "Kd alone",
        "'m'",
        "missing.png: no such file",
        "'broken'",
        "broken.png: cannot decode",
        "'bare'",
        "no file name",
    ] {
        assert!(w.contains(needle), "{w:?} lacks {needle:?}");
    }
    let m = material(&scene, "m");
    assert_eq!(m.rho, [0.25, 0.5, 0.75]);
    assert_eq!(
        m.rho_source,
        RhoSource::TextureNotLoaded {
            file: "missing.png".into(),
            fallback: Box::new(RhoSource::Kd)
        }
    );
    assert_eq!(material(&scene, "bare").rho, [0.5; 3]);
}

#[test]
fn texture_paths_as_windows_exporters_write_them() {
    let white = encode(&[[255; 3]], image::ImageFormat::Png);
    let mtl = "newmtl m\nKd 0.5 0.5 0.5\nmap_Kd Textures\\WALL.PNG\n";
    let (_dir, path) = textured(mtl, &[("mat/Textures/wall.png", white)]);
    let scene = load_obj(&path, &LoadOptions::default()).unwrap();
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    assert!(close(scene.materials[0].rho, [0.5; 3], 1e-12));
}

#[test]
fn a_texture_that_makes_one_or_more_is_clamped() {
    let white = encode(&[[255; 3]], image::ImageFormat::Png);
    let mtl = "newmtl m\nKd 1 1 1\nmap_Kd white.png\n";
    let (_dir, path) = textured(mtl, &[("mat/white.png", white)]);
    let scene = load_obj(&path, &LoadOptions::default()).unwrap();
    assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
    assert!(scene.warnings[0].contains("'m'"), "{:?}", scene.warnings);
    assert_eq!(scene.materials[0].rho, [MAX_REFLECTANCE; 3]);
    let RhoSource::Clamped { from, .. } = &scene.materials[0].rho_source else {
        panic!("{:?}", scene.materials[0].rho_source);
    };
    assert!(matches!(**from, RhoSource::KdTimesTexture { .. }));
}

#[test]
fn map_file_skips_the_options() {
    use super::texture::map_file;
    for (value, file) in [
        ("wall.png", "wall.png"),
        ("-s 1 1 1 wall.png", "wall.png"),
        ("-s 2 wall.png", "wall.png"),
        (
            "-bm 1 -o 0 0 0 -t 0.1 0.1 textures/wall.png",
            "textures/wall.png",
        ),
        (
            "-clamp on -blendu off -imfchan r -mm 0 1 a b.png",
            "a b.png",
        ),
        ("-type sphere -texres 512 -boost 2 w.jpg", "w.jpg"),
        ("my wall.png", "my wall.png"),
        ("-bm", "-bm"),
        ("-bm 1", ""),
        ("", ""),
        ("-s 1 1 1 -tex.png", "-tex.png"),
    ] {
        assert_eq!(map_file(value), file, "{value}");
    }
}

// ---- glazing: grey and tinted (docs/design.md §9) ----

const PANE_OBJ: &str = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nusemtl glass\nf 1 2 3\n";

#[test]
fn a_tinted_tf_keeps_its_colour_and_its_mean_is_the_transmittance() {
    let s = load_strs(
        PANE_OBJ,
        "newmtl glass\nKd 0.05 0.05 0.05\nTf 0.2 0.6 0.3\nillum 4\n",
    )
    .unwrap();
    let m = material(&s, "glass");
    assert_eq!(m.transmittance_rgb, Some([0.2, 0.6, 0.3]));
    assert_eq!(m.transmittance_rgb(), [0.2, 0.6, 0.3]);
    assert!((m.transmittance - (0.2 + 0.6 + 0.3) / 3.0).abs() < 1e-15);
    let tint = m.tint();
    assert!(
        (tint[0] + tint[1] + tint[2] - 3.0).abs() < 1e-12,
        "{tint:?}"
    );
    assert!((tint[1] / tint[0] - 3.0).abs() < 1e-12, "{tint:?}");
    assert!(m.is_tinted());
    // Dissolve scales the colour as it scales the mean.
    let s = load_strs(PANE_OBJ, "newmtl glass\nKd 0 0 0\nTf 0.2 0.6 0.4\nd 0.5\n").unwrap();
    let m = material(&s, "glass");
    assert_eq!(m.transmittance_rgb, Some([0.1, 0.3, 0.2]));
    assert!((m.transmittance - 0.2).abs() < 1e-15);
}

#[test]
fn a_grey_tf_stays_grey_exactly() {
    let s = load_strs(
        PANE_OBJ,
        "newmtl glass\nKd 0.1 0.1 0.1\nTf 0.5 0.5 0.5\nillum 4\n",
    )
    .unwrap();
    let m = material(&s, "glass");
    assert_eq!(m.transmittance, 0.5);
    assert_eq!(m.transmittance_rgb, None);
    assert_eq!(m.transmittance_rgb(), [0.5; 3]);
    assert_eq!(m.tint(), [1.0; 3]);
    assert!(!m.is_tinted());
    // Opaque materials have no colour either.
    let s = load_strs(PANE_OBJ, "newmtl glass\nKd 0.1 0.1 0.1\nTf 1 0.5 1\nd 1\n").unwrap();
    let m = material(&s, "glass");
    assert!(
        m.transmittance > 0.0,
        "Tf strictly between 0 and 1 in a channel transmits"
    );
    let s = load_strs(PANE_OBJ, "newmtl glass\nKd 0.1 0.1 0.1\nTf 0 0 0\n").unwrap();
    let m = material(&s, "glass");
    assert_eq!((m.transmittance, m.transmittance_rgb), (0.0, None));
}

#[test]
fn tinted_glazing_is_cut_per_channel_where_rho_plus_t_exceeds_one() {
    let s = load_strs(
        PANE_OBJ,
        "newmtl glass\nKd 0.5 0.1 0.1\nTf 0.9 0.6 0.3\nillum 4\n",
    )
    .unwrap();
    let m = material(&s, "glass");
    assert_eq!(m.transmittance_rgb, Some([0.5, 0.6, 0.3]));
    assert!((m.transmittance - 1.4 / 3.0).abs() < 1e-15);
    let w = s.warnings.join("\n");
    assert!(
        w.contains("'glass' (0.900 0.600 0.300 → 0.500 0.600 0.300)"),
        "{w}"
    );
    // Grey glazing keeps the rule T ≤ 1 − max ρ, and stays grey.
    let s = load_strs(
        PANE_OBJ,
        "newmtl glass\nKd 0.5 0.1 0.1\nTf 0.9 0.9 0.9\nillum 4\n",
    )
    .unwrap();
    let m = material(&s, "glass");
    assert_eq!((m.transmittance, m.transmittance_rgb), (0.5, None));
}

#[test]
fn a_negative_tf_channel_is_an_error() {
    let r = load_strs(
        PANE_OBJ,
        "newmtl glass\nKd 0 0 0\nTf -0.1 0.5 0.5\nillum 4\n",
    );
    assert_error(r, "test.obj", &["glass", "negative in a channel"]);
}
