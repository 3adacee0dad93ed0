//! The default view (`radiosity::render::default_view`): it follows `--zenith`, it shows the
//! inside of a building whose outside would fill the fitted view (a plan of the top storey,
//! cut at mid-height), the scenes viewed from outside today keep their view, and `solve --out
//! DIR --save DIR/s.rad` saves into the folder it makes.

use crate::common::{assert_user_error, run};
use crate::scene_builder::{block, closed_box, material, polygon, project_scene, quad, scene};
use glam::{vec3, Vec3};
use radiosity::intersect::embree::EmbreeScene;
use radiosity::pipeline::{run_solve, SolveJob};
use radiosity::render::default_view::{default_camera, outside_share, DefaultView, ModelView};
use radiosity::render::Camera;
use radiosity::scene::{Material, Scene, SceneSource};
use std::path::{Path, PathBuf};

/// Y up to Z up: the rotation by 90° about x that takes +y to +z (and north −z to +y).
fn turn(p: Vec3) -> Vec3 {
    vec3(p.x, -p.z, p.y)
}

fn coloured(name: &str, rho: [f64; 3], ke: f64) -> Material {
    Material {
        rho,
        ..material(name, 0.0, ke)
    }
}

/// Material indices of [`house`].
const WALL: u32 = 0;
const FLOOR: u32 = 1;
const ROOF: u32 = 2;
const LAMP: u32 = 3;

/// A two-storey house 8 × 6 m built as a CAD export is, of closed solids with their faces
/// looking out: slabs (the upper floor's top red), outer walls and a partition per storey,
/// a table upstairs, two lamps under each ceiling, and a green gable roof (a closed prism
/// standing on the top slab, overhanging 0.3 m). Y up, north −z; turned to Z up when `z_up`.
fn house(z_up: bool) -> Scene {
    house_in(z_up, false)
}

/// [`house`], in a garden 40 m square (a ground face looking up, level with its bottom) when
/// `garden`.
fn house_in(z_up: bool, garden: bool) -> Scene {
    let mut s = scene(
        if z_up { "house-z" } else { "house-y" },
        vec![
            coloured("wall", [0.6; 3], 0.0),
            coloured("floor", [0.8, 0.1, 0.1], 0.0),
            coloured("roof", [0.1, 0.6, 0.1], 0.0),
            coloured("lamp", [0.0; 3], 20.0),
        ],
    );
    let (w, d, t) = (8.0, 6.0, 0.2);
    block(&mut s, vec3(0., 0., 0.), vec3(w, 0.2, d), WALL);
    block(&mut s, vec3(0., 2.8, 0.), vec3(w, 3.0, d), FLOOR);
    block(&mut s, vec3(0., 5.6, 0.), vec3(w, 5.8, d), WALL);
    for (y0, y1) in [(0.2, 2.8), (3.0, 5.6)] {
        block(&mut s, vec3(0., y0, 0.), vec3(w, y1, t), WALL);
        block(&mut s, vec3(0., y0, d - t), vec3(w, y1, d), WALL);
        block(&mut s, vec3(0., y0, t), vec3(t, y1, d - t), WALL);
        block(&mut s, vec3(w - t, y0, t), vec3(w, y1, d - t), WALL);
        block(&mut s, vec3(3.9, y0, t), vec3(4.1, y1, d - t), WALL);
        for cx in [2.0, 6.0] {
            let y = y1 - 0.01;
            let p = |x: f32, z: f32| vec3(cx + x, y, 3.0 + z);
            // Facing down.
            quad(
                &mut s,
                [p(-0.3, -0.3), p(0.3, -0.3), p(0.3, 0.3), p(-0.3, 0.3)],
                LAMP,
            );
        }
    }
    block(&mut s, vec3(1.2, 3.0, 2.2), vec3(2.8, 3.75, 3.8), WALL);
    let (x0, x1, z0, z1, eave, ridge) = (-0.3, w + 0.3, -0.3, d + 0.3, 5.8, 7.8);
    let (a, b) = (
        |x: f32, z: f32| vec3(x, eave, z),
        |x: f32| vec3(x, ridge, 3.0),
    );
    quad(&mut s, [a(x0, z0), a(x1, z0), a(x1, z1), a(x0, z1)], ROOF);
    quad(&mut s, [a(x0, z0), b(x0), b(x1), a(x1, z0)], ROOF);
    quad(&mut s, [a(x0, z1), a(x1, z1), b(x1), b(x0)], ROOF);
    polygon(&mut s, &[a(x0, z0), a(x0, z1), b(x0)], ROOF);
    polygon(&mut s, &[a(x1, z0), b(x1), a(x1, z1)], ROOF);
    if garden {
        let g = |x: f32, z: f32| vec3(4.0 + x, 0.0, 3.0 + z);
        quad(
            &mut s,
            [g(-20., -20.), g(-20., 20.), g(20., 20.), g(20., -20.)],
            WALL,
        );
    }
    if z_up {
        for p in &mut s.positions {
            *p = turn(*p);
        }
    }
    s
}

/// Writes `scene` as `NAME.obj` and `NAME.mtl` in `dir`, with its patch size.
fn write_obj(scene: &Scene, dir: &Path, name: &str, patch_size: f32) -> PathBuf {
    let mut obj = format!("mtllib {name}.mtl\n# radiosity: patch-size {patch_size}\n");
    for p in &scene.positions {
        obj += &format!("v {} {} {}\n", p.x, p.y, p.z);
    }
    for poly in &scene.polygons {
        obj += &format!("usemtl {}\nf", scene.materials[poly.material as usize].name);
        for k in poly.first..poly.first + poly.len {
            obj += &format!(" {}", scene.indices[k as usize] + 1);
        }
        obj += "\n";
    }
    let mut mtl = String::new();
    for m in &scene.materials {
        let [r, g, b] = m.rho;
        let [er, eg, eb] = m.ke;
        mtl += &format!("newmtl {}\nKd {r} {g} {b}\nKe {er} {eg} {eb}\n", m.name);
    }
    std::fs::write(dir.join(format!("{name}.mtl")), mtl).unwrap();
    let path = dir.join(format!("{name}.obj"));
    std::fs::write(&path, obj).unwrap();
    path
}

/// A solve of `obj` into `out` with a small picture, coarse patches and no elements; the log.
fn solve(obj: &Path, out: &Path, zenith: Vec3, edit: impl FnOnce(&mut SolveJob)) -> Vec<String> {
    let mut job = SolveJob::new(SceneSource::File(obj.to_path_buf()), out.to_path_buf());
    job.zenith = zenith;
    job.north = radiosity::sky::Compass::default_north(zenith);
    job.view.image.width = 160;
    job.view.image.height = 120;
    job.settings.elements.enabled = false;
    edit(&mut job);
    let mut log = Vec::new();
    run_solve(&job, |l| log.push(l.to_string())).unwrap();
    log
}

/// The picture's pixels, RGB in [0, 1].
fn picture(path: &Path) -> Vec<[f32; 3]> {
    let img = image::open(path).unwrap().to_rgb32f();
    img.pixels().map(|p| p.0).collect()
}

/// The share of pixels of the upper floor's red, and of the roof's green.
fn red_and_green(px: &[[f32; 3]]) -> (f64, f64) {
    let share =
        |f: &dyn Fn(&[f32; 3]) -> bool| px.iter().filter(|p| f(p)).count() as f64 / px.len() as f64;
    (
        share(&|[r, g, b]| *r > 0.2 && *r > 2.0 * g && *r > 2.0 * b),
        share(&|[r, g, b]| *g > 0.05 && *g > 2.0 * r && *g > 2.0 * b),
    )
}

/// The default overcast sky of a Z-up model.
fn z_up_sky() -> radiosity::sky::SkySpec {
    radiosity::sky::SkySpec {
        zenith: Vec3::Z,
        north: Vec3::Y,
        ..Default::default()
    }
}

#[test]
fn a_z_up_houses_default_picture_is_its_upper_floor_not_its_roof() {
    let dir = tempfile::tempdir().unwrap();
    let obj = write_obj(&house(true), dir.path(), "house", 1.0);
    // Under a sky, so the outside is lit too.
    let sky = |j: &mut SolveJob| j.settings.solve.sky = Some(z_up_sky());
    let out = dir.path().join("plan");
    let log = solve(&obj, &out, Vec3::Z, sky);
    let note = log.iter().find(|l| l.contains("plan of its top storey"));
    // The top storey: floor at 3.0, ceiling at 5.6, cut half way.
    assert!(
        note.is_some_and(|l| l.contains("floor at height 3.00, cut at 4.30")),
        "{log:?}"
    );
    let (red, green) = red_and_green(&picture(&out.join("render.png")));
    assert!(red > 0.4, "the upper floor fills the plan: {red}");
    assert_eq!(green, 0.0, "the roof is clipped");
    // Any camera flag takes the fitted view, the zenith up: the house's outside, its roof
    // and walls; of the red slab only its edge, a thin band along the façade.
    let out = dir.path().join("fitted");
    let log = solve(&obj, &out, Vec3::Z, |j| {
        sky(j);
        j.view.camera.near = Some(0.0);
    });
    assert!(!log.iter().any(|l| l.contains("plan")), "{log:?}");
    let (red, green) = red_and_green(&picture(&out.join("render.png")));
    assert!(red < 0.03, "no floor seen from outside: {red}");
    assert!(green > 0.05, "the roof, from the side: {green}");
}

#[test]
fn y_up_and_z_up_houses_give_the_same_picture() {
    let dir = tempfile::tempdir().unwrap();
    let mut pictures = Vec::new();
    for (z_up, zenith) in [(false, Vec3::Y), (true, Vec3::Z)] {
        let name = if z_up { "z" } else { "y" };
        let obj = write_obj(&house(z_up), dir.path(), name, 1.0);
        let out = dir.path().join(name);
        solve(&obj, &out, zenith, |_| {});
        pictures.push(picture(&out.join("render.png")));
    }
    let (y, z) = (&pictures[0], &pictures[1]);
    assert_eq!(y.len(), z.len());
    // The same camera, turned (exactly, see views_of_turned_models_are_turned): the pixels
    // differ only by the solves' noise (their random rays leave the patches in frames that
    // are not turned with them).
    let diff: Vec<f32> = y
        .iter()
        .zip(z)
        .map(|(a, b)| (0..3).map(|c| (a[c] - b[c]).abs()).fold(0.0, f32::max))
        .collect();
    let mean = diff.iter().sum::<f32>() / diff.len() as f32;
    let far = diff.iter().filter(|d| **d > 0.1).count();
    assert!(mean < 0.01, "mean difference {mean}");
    assert!(
        far * 100 < diff.len(),
        "{far} pixels differ by more than 0.1"
    );
    let (ry, rz) = (red_and_green(y).0, red_and_green(z).0);
    assert!(ry > 0.4 && (ry - rz).abs() < 0.01, "{ry} {rz}");
}

/// The default camera of a scene with zenith `up`, the view taken, and the share of the
/// fitted view that sees the outside.
fn default_of(scene: &Scene, up: Vec3) -> (Camera, DefaultView, f64) {
    default_of_sided(scene, up, false)
}

/// [`default_of`], the mesh two-sided when `two_sided`.
fn default_of_sided(scene: &Scene, up: Vec3, two_sided: bool) -> (Camera, DefaultView, f64) {
    let opts = radiosity::mesh::MeshOptions {
        patch_size: None,
        two_sided,
        ..Default::default()
    };
    let m = radiosity::mesh::build(scene, &opts);
    let isect = EmbreeScene::build(&m, |_| true).unwrap();
    let (lo, hi) = scene.bounds();
    let model = ModelView {
        lo,
        hi,
        zenith: up,
        probe: Some((&m, &isect)),
    };
    let (cam, view) = default_camera(&model, 4.0 / 3.0);
    (cam, view, outside_share(&model, 4.0 / 3.0).unwrap())
}

#[test]
fn scenes_seen_through_their_near_wall_or_open_side_keep_the_fitted_view() {
    let mut scenes: Vec<Scene> = [
        "cornell-box.obj",
        "office.obj",
        "blocks.obj",
        "spot.obj",
        "hallway.obj",
        "church.obj",
    ]
    .iter()
    .map(|f| project_scene(f).0)
    .collect();
    scenes.push(SceneSource::Default.load(&Default::default()).unwrap());
    for s in &scenes {
        let (lo, hi) = s.bounds();
        let (cam, view, outside) = default_of(s, Vec3::Y);
        assert_eq!(
            (cam, view),
            (Camera::fit(lo, hi, 4.0 / 3.0), DefaultView::Fitted),
            "{}",
            s.name
        );
        // Well clear of the rule's 1/2: the Cornell box's blocks, seen from outside, are the
        // most.
        eprintln!(
            "{}: {:.0} % of the fitted view sees the outside",
            s.name,
            100.0 * outside
        );
        assert!(outside < 0.3, "{}: {outside}", s.name);
    }
}

#[test]
fn views_of_turned_models_are_turned() {
    // The closed office, Z up: the same fitted view of itself, turned.
    let (office, _) = project_scene("office.obj");
    let mut z_office = office.clone();
    for p in &mut z_office.positions {
        *p = turn(*p);
    }
    let (y, vy, _) = default_of(&office, Vec3::Y);
    let (z, vz, _) = default_of(&z_office, Vec3::Z);
    assert_eq!((vy, vz), (DefaultView::Fitted, DefaultView::Fitted));
    assert_eq!(
        (turn(y.eye), turn(y.target), z.up),
        (z.eye, z.target, Vec3::Z)
    );
    // The house: the same plan, turned.
    let (y, vy, _) = default_of(&house(false), Vec3::Y);
    let (z, vz, _) = default_of(&house(true), Vec3::Z);
    let DefaultView::Plan { floor, cut, .. } = vz else {
        panic!("{vz:?}")
    };
    assert!(
        (floor - 3.0).abs() < 1e-4 && (cut - 4.3).abs() < 1e-4,
        "{vz:?}"
    );
    assert!(matches!(vy, DefaultView::Plan { .. }), "{vy:?}");
    assert!((turn(y.eye) - z.eye).length() < 1e-4, "{y:?} {z:?}");
    assert!((y.near - z.near).abs() < 1e-4 && z.near > 0.0);
    // Looking straight down, north (+y for Z up) up the picture.
    let f = z.frame();
    assert!(
        f.fwd.dot(Vec3::NEG_Z) > 0.9999 && f.up.dot(Vec3::Y) > 0.9999,
        "{f:?}"
    );
    // The eye is above the cut by `near`.
    assert!((z.eye.z - z.near - cut).abs() < 1e-4);
}

#[test]
fn a_house_in_a_garden_gets_the_plan_of_its_top_storey_filling_the_picture() {
    let (cam, view, outside) = default_of(&house_in(true, true), Vec3::Z);
    let DefaultView::Plan { floor, cut, .. } = view else {
        panic!("{view:?}, outside {outside}")
    };
    assert!(
        (floor - 3.0).abs() < 1e-4 && (cut - 4.3).abs() < 1e-4,
        "{view:?}"
    );
    // The garden is left out: the upper floor's corners (north-west, north-east, south-east,
    // south-west; Z up, north +y) are in the picture, and it spans most of it.
    let corners = [(0.0, 0.0), (8.0, 0.0), (8.0, -6.0), (0.0, -6.0)];
    let uv: Vec<_> = corners
        .iter()
        .map(|&(x, y)| cam.project(vec3(x, y, 3.0)).unwrap().0)
        .collect();
    assert!(
        uv.iter()
            .all(|p| p.cmpge(glam::Vec2::ZERO).all() && p.cmple(glam::Vec2::ONE).all()),
        "{uv:?}"
    );
    let (u, v) = (uv[1].x - uv[0].x, uv[3].y - uv[0].y);
    assert!(
        u > 0.6 && v > 0.6,
        "the floor spans {u} × {v} of the picture"
    );
}

#[test]
fn a_two_sided_closed_room_gets_its_plan_not_its_near_walls_outside() {
    // Two-sided, the office's near wall shows its back patch to the fitted camera: the
    // outside, unlit.
    let (office, _) = project_scene("office.obj");
    let (_, view, outside) = default_of_sided(&office, Vec3::Y, true);
    let DefaultView::Plan { floor, cut, .. } = view else {
        panic!("{view:?}, outside {outside}")
    };
    // The floor at 0, the ceiling at 2.7.
    assert!(floor.abs() < 1e-3 && (cut - 1.35).abs() < 1e-3, "{view:?}");
}

/// A small closed box that glows, as an OBJ in `dir`.
fn glowing_box(dir: &Path) -> PathBuf {
    write_obj(
        &closed_box(1.0, 1.0, 1.0, material("glow", 0.5, 1.0)),
        dir,
        "box",
        0.5,
    )
}

#[test]
fn solve_saves_into_the_out_folder_it_makes() {
    let dir = tempfile::tempdir().unwrap();
    let obj = glowing_box(dir.path());
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let out = dir.path().join("new").join("run");
    let save = out.join("s.rad");
    let (code, _, err) = run(&[
        "solve",
        &s(&obj),
        "--out",
        &s(&out),
        "--save",
        &s(&save),
        "--width",
        "16",
        "--height",
        "12",
        "--quiet",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(save.is_file() && out.join("render.png").is_file());
    // A folder that is neither --out nor there is still refused, before the solve, and the
    // --out folder made for it is taken away again.
    let other = dir.path().join("other");
    assert_user_error(
        &[
            "solve",
            &s(&obj),
            "--out",
            &s(&other),
            "--save",
            &s(&dir.path().join("missing").join("s.rad")),
            "--quiet",
        ],
        &["--save", "missing", "does not exist"],
    );
    assert!(!other.exists());
}

#[test]
fn render_of_a_saved_z_up_house_takes_the_zenith_it_was_solved_under_or_given() {
    let dir = tempfile::tempdir().unwrap();
    let obj = write_obj(&house(true), dir.path(), "house", 1.0);
    let out = dir.path().join("solve");
    let save = out.join("s.rad");
    // Solved under a sky with --zenith 0,0,1: the file keeps the zenith in its sky.
    solve(&obj, &out, Vec3::Z, |j| {
        j.save = Some(save.clone());
        j.settings.solve.sky = Some(z_up_sky());
    });
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let png = dir.path().join("r.png");
    let render = |extra: &[&str]| {
        let mut args = vec![
            "render".to_string(),
            s(&save),
            "--out".into(),
            s(&png),
            "--shading".into(),
            "gouraud".into(),
            "--width".into(),
            "160".into(),
            "--height".into(),
            "120".into(),
        ];
        args.extend(extra.iter().map(|a| a.to_string()));
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let (code, _, err) = run(&args);
        assert_eq!(code, 0, "{err}");
        (err, red_and_green(&picture(&png)))
    };
    let (err, (red, _)) = render(&[]);
    assert!(
        err.contains("note:") && err.contains("plan of its top storey"),
        "{err}"
    );
    assert!(red > 0.4, "{red}");
    let (_, (red_z, _)) = render(&["--zenith", "0,0,1"]);
    assert_eq!(red_z, red);
    // Told Y is up, the house lies on its side: no plan of the upper floor.
    let (_, (red_y, _)) = render(&["--zenith", "0,1,0"]);
    assert!(red_y < 0.2, "{red_y}");
    assert_user_error(
        &["render", &s(&save), "--out", &s(&png), "--zenith", "0,0,0"],
        &["--zenith", "zero or not finite"],
    );
}
