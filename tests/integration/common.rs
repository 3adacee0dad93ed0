//! Analytic scenes built in code, shared by the integration tests.
#![allow(dead_code)]

use glam::{vec3, Vec3};
use radiosity::scene::{Material, Polygon, Scene};

/// Adds a quad (counter-clockwise seen from its front).
pub fn quad(s: &mut Scene, pts: [Vec3; 4], material: u32) {
    let base = s.positions.len() as u32;
    s.positions.extend_from_slice(&pts);
    let first = s.indices.len() as u32;
    s.indices.extend(base..base + 4);
    s.polygons.push(Polygon {
        first,
        len: 4,
        material,
        back_material: None,
    });
}

pub fn material(name: &str, rho: f64, ke: f64) -> Material {
    Material {
        name: name.into(),
        rho: [rho; 3],
        ke: [ke; 3],
        ..Material::default()
    }
}

/// A closed box [0, w]×[0, h]×[0, d] with every face pointing inwards, all of material 0.
pub fn closed_box(w: f32, h: f32, d: f32, mat: Material) -> Scene {
    let mut s = Scene {
        name: "closed-box".into(),
        materials: vec![mat],
        ..Scene::default()
    };
    let p = |x: f32, y: f32, z: f32| vec3(x * w, y * h, z * d);
    // floor (+y), ceiling (−y), walls facing in
    quad(
        &mut s,
        [p(0., 0., 0.), p(0., 0., 1.), p(1., 0., 1.), p(1., 0., 0.)],
        0,
    );
    quad(
        &mut s,
        [p(0., 1., 0.), p(1., 1., 0.), p(1., 1., 1.), p(0., 1., 1.)],
        0,
    );
    quad(
        &mut s,
        [p(0., 0., 0.), p(1., 0., 0.), p(1., 1., 0.), p(0., 1., 0.)],
        0,
    );
    quad(
        &mut s,
        [p(0., 0., 1.), p(0., 1., 1.), p(1., 1., 1.), p(1., 0., 1.)],
        0,
    );
    quad(
        &mut s,
        [p(0., 0., 0.), p(0., 1., 0.), p(0., 1., 1.), p(0., 0., 1.)],
        0,
    );
    quad(
        &mut s,
        [p(1., 0., 0.), p(1., 0., 1.), p(1., 1., 1.), p(1., 1., 0.)],
        0,
    );
    s
}

/// The `radiosity` binary, without RUST_BACKTRACE (so a panic shows as the one-line "panicked"
/// the tests look for).
pub fn radiosity() -> assert_cmd::Command {
    let mut c = assert_cmd::Command::cargo_bin("radiosity").unwrap();
    c.env_remove("RUST_BACKTRACE");
    c
}

/// Runs the binary and returns (exit code, stdout, stderr).
pub fn run(args: &[&str]) -> (i32, String, String) {
    let out = radiosity().args(args).output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A user error: exit code 2, no panic, and an error line holding every needle.
pub fn assert_user_error(args: &[&str], needles: &[&str]) {
    let (code, _, err) = run(args);
    assert_eq!(code, 2, "args {args:?}: stderr {err}");
    assert!(!err.contains("panicked"), "panic: {err}");
    let line = err
        .lines()
        .find(|l| l.starts_with("Error:") || l.starts_with("error:"))
        .unwrap_or_else(|| panic!("no error line in {err}"));
    for n in needles {
        assert!(line.contains(n), "'{n}' not in error line '{line}'");
    }
}

/// The scene cut into patches (its own patch size when `None`).
pub fn mesh_at(scene: &Scene, patch_size: Option<f32>) -> radiosity::mesh::Mesh {
    radiosity::mesh::build(
        scene,
        &radiosity::mesh::MeshOptions {
            patch_size,
            two_sided: false,
        },
    )
}

/// Solves by `cfg.method`, building an Embree scene only for the methods that cast rays.
pub fn solve_mesh(
    scene: &Scene,
    m: &radiosity::mesh::Mesh,
    cfg: &radiosity::solve::SolveSettings,
) -> radiosity::solve::Solution {
    solve_mesh_with(scene, m, cfg, &Default::default())
}

/// [`solve_mesh`] with hooks (per-light channels, a reference, checkpoints).
pub fn solve_mesh_with(
    scene: &Scene,
    m: &radiosity::mesh::Mesh,
    cfg: &radiosity::solve::SolveSettings,
    hooks: &radiosity::solve::RunHooks,
) -> radiosity::solve::Solution {
    let isect = cfg
        .method
        .casts_rays()
        .then(|| radiosity::intersect::embree::EmbreeScene::build(m, |_| true).unwrap());
    radiosity::solve::run(m, &scene.materials, isect.as_ref(), cfg, hooks, |_| {}).unwrap()
}

/// A scene of the project's `scenes/` folder, meshed at its own `# radiosity: patch-size`.
pub fn project_scene(file: &str) -> (Scene, radiosity::mesh::Mesh) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(file);
    let s = radiosity::scene::load_obj(&path, &radiosity::scene::LoadOptions::default()).unwrap();
    let m = radiosity::mesh::build(&s, &radiosity::mesh::MeshOptions::default());
    (s, m)
}

/// Runs `f` on a pool of `threads` threads, or on rayon's global pool when `None`: what the
/// "same result on any thread count" tests compare.
pub fn on_threads<T: Send>(threads: Option<usize>, f: impl FnOnce() -> T + Send) -> T {
    match threads {
        None => f(),
        Some(t) => rayon::ThreadPoolBuilder::new()
            .num_threads(t)
            .build()
            .unwrap()
            .install(f),
    }
}
