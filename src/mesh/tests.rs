//! The mesh builder: subdivision, triangulation, welding, sides and the patch size.

use super::*;
use crate::scene::{Material, Polygon};
use glam::vec3;

/// The unit square in z = 0, facing +z.
const UNIT_QUAD: [Vec3; 4] = [
    vec3(0., 0., 0.),
    vec3(1., 0., 0.),
    vec3(1., 1., 0.),
    vec3(0., 1., 0.),
];

fn scene_of(faces: &[&[Vec3]]) -> Scene {
    let mut s = Scene {
        materials: vec![Material {
            name: "m".into(),
            rho: [0.5; 3],
            ke: [0.0; 3],
            ..Material::default()
        }],
        ..Scene::default()
    };
    for f in faces {
        let base = s.positions.len() as u32;
        s.positions.extend_from_slice(f);
        let first = s.indices.len() as u32;
        s.indices.extend(base..base + f.len() as u32);
        s.polygons.push(Polygon {
            first,
            len: f.len() as u32,
            material: 0,
            back_material: None,
        });
    }
    s
}

fn opts(size: f32) -> MeshOptions {
    MeshOptions {
        patch_size: Some(size),
        two_sided: false,
        one_sided: false,
        uniform_patches: false,
    }
}

fn longest_edge(m: &Mesh) -> f32 {
    (0..m.patches.len())
        .flat_map(|i| {
            let ids = m.patch_indices(i);
            (0..ids.len()).map(move |k| {
                (m.vertices[ids[(k + 1) % ids.len()] as usize] - m.vertices[ids[k] as usize])
                    .length()
            })
        })
        .fold(0.0, f32::max)
}

#[test]
fn quad_is_cut_into_a_welded_grid_keeping_area() {
    let quad = [
        vec3(0., 0., 0.),
        vec3(2., 0., 0.),
        vec3(2., 0., -1.),
        vec3(0., 0., -1.),
    ];
    let m = build(&scene_of(&[&quad]), &opts(0.5));
    assert_eq!(m.patches.len(), 4 * 2);
    assert_eq!(m.vertices.len(), 5 * 3, "grid vertices are shared");
    assert!((m.total_area() - 2.0).abs() < 1e-6);
    assert!(longest_edge(&m) <= 0.5 + 1e-6);
    for p in &m.patches {
        assert_eq!(p.count, 4, "quads stay quads");
        assert!((p.normal - Vec3::Y).length() < 1e-6);
        assert_eq!(p.class, PatchClass::Axial(Axis::Y));
    }
}

#[test]
fn triangle_and_large_ngon_keep_their_area() {
    let tri = [vec3(0., 0., 0.), vec3(1., 0., 1.), vec3(0., 1., 0.3)];
    let hexagon: Vec<Vec3> = (0..6)
        .map(|k| {
            let a = k as f32 * std::f32::consts::TAU / 6.0;
            vec3(a.cos(), a.sin(), 0.0)
        })
        .collect();
    let s = scene_of(&[&tri, &hexagon]);
    let m = build(&s, &opts(0.3));
    let tri_area = 0.5 * newell(&tri).length() as f64;
    let hex_area = 3.0 * 3f64.sqrt() / 2.0;
    assert!((m.total_area() - tri_area - hex_area).abs() < 1e-5);
    assert!(longest_edge(&m) <= 0.3 + 1e-5);
    let skew = m
        .patches
        .iter()
        .filter(|p| p.class == PatchClass::Skew)
        .count();
    assert!(skew > 0 && skew < m.patches.len());
}

#[test]
fn non_convex_and_non_planar_faces_are_triangulated() {
    // An L-shape (non-convex) and a twisted quad (non-planar).
    let l = [
        vec3(0., 0., 0.),
        vec3(2., 0., 0.),
        vec3(2., 1., 0.),
        vec3(1., 1., 0.),
        vec3(1., 2., 0.),
        vec3(0., 2., 0.),
    ];
    let twisted = [
        vec3(0., 0., 5.),
        vec3(1., 0., 5.),
        vec3(1., 1., 5.3),
        vec3(0., 1., 5.),
    ];
    let m = build(&scene_of(&[&l, &twisted]), &opts(10.0));
    let l_patches: Vec<_> = m.patches.iter().filter(|p| p.polygon == 0).collect();
    assert_eq!(l_patches.len(), 4, "a hexagonal L needs 4 triangles");
    assert!(l_patches.iter().all(|p| p.count == 3));
    let l_area: f64 = l_patches.iter().map(|p| p.area).sum();
    assert!((l_area - 3.0).abs() < 1e-6);
    assert!(m
        .patches
        .iter()
        .filter(|p| p.polygon == 1)
        .all(|p| p.count == 3));
}

#[test]
fn two_sided_adds_opposite_patches_with_their_own_vertices() {
    let quad = UNIT_QUAD;
    let m = build(
        &scene_of(&[&quad]),
        &MeshOptions {
            patch_size: Some(0.5),
            two_sided: true,
            one_sided: false,
            uniform_patches: false,
        },
    );
    assert_eq!(m.patches.len(), 8);
    let back = m.patches.iter().filter(|p| p.normal.z < 0.0).count();
    assert_eq!(back, 4);
    assert_eq!(m.vertices.len(), 18, "front and back never share a vertex");
    // Each front patch and its twin name each other, and only fronts are surfaces.
    for (i, p) in m.patches.iter().enumerate() {
        match p.side {
            Side::Front { back } => {
                let t = &m.patches[back as usize];
                assert_eq!(t.side, Side::Back { front: i as u32 });
                assert_eq!((t.area, t.centre, t.normal), (p.area, p.centre, -p.normal));
                assert!(m.is_surface(i) && !m.is_surface(back as usize));
                assert_eq!(m.receiver(i as u32, true), Some(back));
                assert_eq!(m.surface_of(back as usize), i);
            }
            Side::Back { .. } => {}
            Side::One => panic!("patch {i} has no twin"),
        }
    }
    assert_eq!(
        m.surface_triangles().count(),
        8,
        "4 quads, 2 triangles each"
    );
    assert_eq!(m.triangles().count(), 16);
}

#[test]
fn twins_lost_by_a_saved_solution_are_paired_again() {
    let quad = UNIT_QUAD;
    let mut s = scene_of(&[&quad, &quad.map(|v| v + Vec3::Z)]);
    s.polygons[1].back_material = Some(0);
    // Polygon 0 one-sided, polygon 1 two-sided (a merged doubled face), 4 patches each side.
    let m = build(&s, &opts(0.5));
    assert_eq!(m.back_twins(), 4);
    let mut lost = m.clone();
    lost.patches.iter_mut().for_each(|p| p.side = Side::One);
    assert_eq!(lost.pair_twins(), 4);
    assert_eq!(lost, m);
    // Pairing again finds nothing more.
    assert_eq!(lost.pair_twins(), 0);
}

#[test]
fn an_emitter_stays_one_sided_and_a_merged_back_material_is_used() {
    let quad = UNIT_QUAD;
    let mut s = scene_of(&[&quad, &quad.map(|v| v + Vec3::Z)]);
    s.materials.push(Material {
        name: "lamp".into(),
        ke: [1.0; 3],
        ..Material::default()
    });
    s.polygons[0].material = 1;
    s.polygons[1].back_material = Some(1);
    let two = MeshOptions {
        patch_size: Some(1.0),
        two_sided: true,
        one_sided: false,
        uniform_patches: false,
    };
    let m = build(&s, &two);
    assert_eq!(m.patches.len(), 3, "lamp one-sided, the other two-sided");
    assert_eq!(m.patches[0].side, Side::One);
    assert_eq!(m.patches[2].material, 1, "the merged back material");
    assert_eq!(
        build(&s, &opts(1.0)).back_twins(),
        1,
        "merged faces need no flag"
    );
}

#[test]
fn crease_vertices_are_not_welded_but_coplanar_ones_are() {
    let floor_a = [
        vec3(0., 0., 0.),
        vec3(0., 0., 1.),
        vec3(1., 0., 1.),
        vec3(1., 0., 0.),
    ];
    let floor_b = [
        vec3(1., 0., 0.),
        vec3(1., 0., 1.),
        vec3(2., 0., 1.),
        vec3(2., 0., 0.),
    ];
    let wall = [
        vec3(0., 0., 0.),
        vec3(1., 0., 0.),
        vec3(1., 1., 0.),
        vec3(0., 1., 0.),
    ];
    let m = build(&scene_of(&[&floor_a, &floor_b, &wall]), &opts(5.0));
    // floors share 2 vertices (6 in all); the wall shares none with them (4 more).
    assert_eq!(m.vertices.len(), 10);
    let vals = m.vertex_values(&[[1.0; 3], [3.0; 3], [7.0; 3]]);
    let shared = m.patch_indices(1)[0] as usize; // (1,0,0) on floor_b
    assert_eq!(vals[shared], [2.0; 3]);
}

#[test]
fn rough_patch_count_counts_the_mesh_and_try_build_refuses_far_too_many() {
    // A quad with one corner typed 800 m away (found by fuzzing: a mutated hallway): not
    // convex, so ear-clipped into two slivers whose longest edge sets the subdivision.
    let dart = [
        vec3(0.9, 2.8, -18.9),
        vec3(1.5, 2.8, -819.0),
        vec3(1.5, 2.8, -17.1),
        vec3(0.9, 2.8, -17.1),
    ];
    let square = [
        vec3(0.0, 0.0, 0.0),
        vec3(1.0, 0.0, 0.0),
        vec3(1.0, 1.0, 0.0),
        vec3(0.0, 1.0, 0.0),
    ];
    // A corridor's wall, long and low: its bounding box's diagonal squared over-counted it
    // 34 times, and refused a 10 M-patch building whose mesh was within the limit.
    let wall = [
        vec3(0.0, 0.0, 2.0),
        vec3(100.0, 0.0, 2.0),
        vec3(100.0, 3.0, 2.0),
        vec3(0.0, 3.0, 2.0),
    ];
    let scene = scene_of(&[&dart, &square, &wall]);
    for size in [5.0, 2.0] {
        let m = build(&scene, &opts(size));
        // No light in the scene, so no cut near one: the count is the mesh's, but for the
        // dart's slivers' degenerate cells, which the mesh drops (0.3 % of them at 0.5 m).
        let n = m.patches.len() as f64;
        let rough = rough_patch_count(&scene, &opts(size));
        assert!(rough >= n && rough <= 1.01 * n, "{rough} for {n}");
    }
    let m = build(&scene, &opts(5.0));
    let e = try_build(&scene, &opts(1e-3)).unwrap_err();
    assert!(e.contains("over the limit") && !e.contains('\n'), "{e}");
    assert_eq!(try_build(&scene, &opts(5.0)).unwrap(), m);
}

#[test]
fn default_patch_size_is_a_nice_length() {
    assert_eq!(nice_length(0.0356), 0.04);
    assert_eq!(nice_length(0.6), 0.6);
    assert_eq!(nice_length(13.0), 15.0);
}
