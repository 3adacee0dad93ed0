//! The scenes the integration tests solve, built in code (polygons, quads, boxes, blocks, grey
//! materials) or loaded from the project's `scenes/` folder, and cut into patches. Every test
//! builds its scene from these, so two tests that say "a closed box" mean the same box.

use glam::{vec3, Vec3};
use radiosity::mesh::{Mesh, MeshOptions};
use radiosity::scene::{LoadOptions, Material, Polygon, Scene};
use std::path::Path;

/// An empty scene of these materials.
pub fn scene(name: &str, materials: Vec<Material>) -> Scene {
    Scene {
        name: name.into(),
        materials,
        ..Scene::default()
    }
}

/// An empty scene of one grey material (ρ 0.5, no emission), for tests of geometry alone.
pub fn grey_scene() -> Scene {
    scene("test", vec![material("m", 0.5, 0.0)])
}

/// A grey material: reflectance `rho` and emission `ke` in every channel.
pub fn material(name: &str, rho: f64, ke: f64) -> Material {
    Material {
        name: name.into(),
        rho: [rho; 3],
        ke: [ke; 3],
        ..Material::default()
    }
}

/// Adds a polygon (counter-clockwise seen from its front).
pub fn polygon(s: &mut Scene, pts: &[Vec3], material: u32) {
    let base = s.positions.len() as u32;
    s.positions.extend_from_slice(pts);
    let first = s.indices.len() as u32;
    s.indices.extend(base..base + pts.len() as u32);
    s.polygons.push(Polygon {
        first,
        len: pts.len() as u32,
        material,
        back_material: None,
    });
}

/// Adds a quad (counter-clockwise seen from its front).
pub fn quad(s: &mut Scene, pts: [Vec3; 4], material: u32) {
    polygon(s, &pts, material);
}

/// Adds the polygon on `pts` (in order around it), wound so it faces `towards`.
pub fn polygon_facing(s: &mut Scene, pts: &[Vec3], towards: Vec3, material: u32) {
    let mut pts = pts.to_vec();
    if radiosity::mesh::newell(&pts).dot(towards) < 0.0 {
        pts.reverse();
    }
    polygon(s, &pts, material);
}

/// A closed box [0, w]×[0, h]×[0, d] with every face pointing inwards, all of material 0.
pub fn closed_box(w: f32, h: f32, d: f32, mat: Material) -> Scene {
    let mut s = scene("closed-box", vec![mat]);
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

/// The six faces of the axis-aligned block [lo, hi], each facing out, in the order −y, +y,
/// −z, +z, −x, +x.
fn block_faces(lo: Vec3, hi: Vec3) -> [[Vec3; 4]; 6] {
    let p = |x: f32, y: f32, z: f32| {
        vec3(
            lo.x + x * (hi.x - lo.x),
            lo.y + y * (hi.y - lo.y),
            lo.z + z * (hi.z - lo.z),
        )
    };
    [
        [p(0., 0., 0.), p(1., 0., 0.), p(1., 0., 1.), p(0., 0., 1.)], // −y
        [p(0., 1., 0.), p(0., 1., 1.), p(1., 1., 1.), p(1., 1., 0.)], // +y
        [p(0., 0., 0.), p(0., 1., 0.), p(1., 1., 0.), p(1., 0., 0.)], // −z
        [p(0., 0., 1.), p(1., 0., 1.), p(1., 1., 1.), p(0., 1., 1.)], // +z
        [p(0., 0., 0.), p(0., 0., 1.), p(0., 1., 1.), p(0., 1., 0.)], // −x
        [p(1., 0., 0.), p(1., 1., 0.), p(1., 1., 1.), p(1., 0., 1.)], // +x
    ]
}

/// Adds the closed axis-aligned block [lo, hi] (a desk, a beam, a pillar), faces outwards.
pub fn block(s: &mut Scene, lo: Vec3, hi: Vec3, material: u32) {
    for f in block_faces(lo, hi) {
        quad(s, f, material);
    }
}

/// Adds the block [lo, hi] without its bottom (it stands on something), faces outwards.
pub fn open_box(s: &mut Scene, lo: Vec3, hi: Vec3, material: u32) {
    for f in &block_faces(lo, hi)[1..] {
        quad(s, *f, material);
    }
}

/// The scene cut into patches (its own patch size when `None`), one-sided.
pub fn mesh_at(scene: &Scene, patch_size: Option<f32>) -> Mesh {
    radiosity::mesh::build(
        scene,
        &MeshOptions {
            patch_size,
            two_sided: false,
            one_sided: false,
            uniform_patches: false,
        },
    )
}

/// As [`mesh_at`], one patch per face where the patch size allows: no cuts near lights (for
/// tests that count patches or read one face's form factor).
pub fn mesh_uniform(scene: &Scene, patch_size: Option<f32>) -> Mesh {
    radiosity::mesh::build(
        scene,
        &MeshOptions {
            patch_size,
            uniform_patches: true,
            ..MeshOptions::default()
        },
    )
}

/// A scene of the project's `scenes/` folder, loaded with the default options.
pub fn load_project_scene(file: &str) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(file);
    radiosity::scene::load_obj(&path, &LoadOptions::default()).unwrap()
}

/// A scene of the project's `scenes/` folder, meshed at its own `# radiosity: patch-size`.
pub fn project_scene(file: &str) -> (Scene, Mesh) {
    let s = load_project_scene(file);
    let m = radiosity::mesh::build(&s, &MeshOptions::default());
    (s, m)
}
