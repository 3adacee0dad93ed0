//! Unit tests of the plane merge: edge ownership, the walk's interval, and the bucket
//! tables against a binary search.

use super::*;
use crate::mesh::{Axis, Mesh, Patch, PatchClass, Side};
use glam::{vec3, Vec3};

/// Two unit quads side by side in z = 0 (sharing the edge x = 1), facing +z.
fn two_quads() -> Mesh {
    let vertices = vec![
        vec3(0., 0., 0.),
        vec3(1., 0., 0.),
        vec3(2., 0., 0.),
        vec3(0., 1., 0.),
        vec3(1., 1., 0.),
        vec3(2., 1., 0.),
    ];
    let quad = |first: u32, cx: f32| Patch {
        first,
        count: 4,
        material: 0,
        polygon: 0,
        area: 1.0,
        centre: vec3(cx, 0.5, 0.0),
        normal: Vec3::Z,
        class: PatchClass::Axial(Axis::Z),
        side: Side::One,
    };
    Mesh {
        vertices,
        patch_vertices: vec![0, 1, 4, 3, 1, 2, 5, 4],
        patches: vec![quad(0, 0.5), quad(4, 1.5)],
        patch_size: 1.0,
        ..Mesh::default()
    }
}

fn ray(org: Vec3, dir: Vec3) -> Ray {
    Ray {
        org,
        dir,
        tnear: 0.0,
        tfar: f32::INFINITY,
    }
}

#[test]
fn a_point_on_a_shared_edge_belongs_to_exactly_one_quad() {
    let m = PlaneMerge::build(&two_quads());
    assert_eq!(m.plane_counts(), [0, 0, 1]);
    for y in [0.0, 0.25, 0.5, 1.0 - f32::EPSILON] {
        let h = m.intersect(&ray(vec3(1.0, y, 1.0), -Vec3::Z)).unwrap();
        assert!(h.patch == 0 || h.patch == 1);
        assert_eq!(h.t, 1.0);
        assert!(!h.back);
    }
    let h = m.intersect(&ray(vec3(0.5, 0.5, -1.0), Vec3::Z)).unwrap();
    assert_eq!((h.patch, h.back), (0, true));
}

#[test]
fn tnear_and_tfar_bound_the_walk() {
    let m = PlaneMerge::build(&two_quads());
    let mut r = ray(vec3(1.5, 0.5, 1.0), -Vec3::Z);
    r.tfar = 0.999;
    assert!(m.intersect(&r).is_none());
    r.tfar = 1.0;
    assert_eq!(m.intersect(&r).map(|h| h.patch), Some(1));
    r.tnear = 1.0;
    assert!(
        m.intersect(&r).is_none(),
        "planes at t = tnear are not taken"
    );
    // Starting on the plane: it is behind (t = 0) either way the ray leaves.
    assert!(m.intersect(&ray(vec3(0.5, 0.5, 0.0), Vec3::Z)).is_none());
    assert!(m.intersect(&ray(vec3(0.5, 0.5, 0.0), -Vec3::Z)).is_none());
}

/// A 5 × 5 grid of quads in y = 2 (facing −y) and a fan of 12 triangles round a point, in
/// x = 0: arbitrary edge directions.
fn grid_and_fan() -> Mesh {
    let mut m = Mesh::default();
    let push = |m: &mut Mesh, pts: &[Vec3], normal: Vec3, axis: Axis| {
        let first = m.patch_vertices.len() as u32;
        for p in pts {
            m.patch_vertices.push(m.vertices.len() as u32);
            m.vertices.push(*p);
        }
        m.patches.push(Patch {
            first,
            count: pts.len() as u32,
            material: 0,
            polygon: 0,
            area: 1.0,
            centre: pts[0],
            normal,
            class: PatchClass::Axial(axis),
            side: Side::One,
        });
    };
    let g = |i: u32| i as f32 * 0.3;
    for j in 0..5 {
        for i in 0..5 {
            // Counter-clockwise seen from −y: (x, z) turning clockwise in the x–z plane.
            let q = [
                vec3(g(i), 2.0, g(j)),
                vec3(g(i), 2.0, g(j + 1)),
                vec3(g(i + 1), 2.0, g(j + 1)),
                vec3(g(i + 1), 2.0, g(j)),
            ];
            push(&mut m, &q, -Vec3::Y, Axis::Y);
        }
    }
    let centre = vec3(0.0, 0.123, -0.31);
    let rim = |k: u32| {
        let a = (k % 12) as f32 * std::f32::consts::TAU / 12.0;
        centre + vec3(0.0, a.cos(), a.sin()) * 0.7
    };
    for k in 0..12 {
        push(&mut m, &[centre, rim(k), rim(k + 1)], Vec3::X, Axis::X);
    }
    m
}

/// The patches whose polygons own the in-plane point (pu, pv) strictly, over all planes.
fn owners(m: &PlaneMerge, pu: f32, pv: f32) -> Vec<u32> {
    let mut firsts: Vec<u32> = m.cell_items.clone();
    firsts.sort_unstable();
    firsts.dedup();
    firsts
        .into_iter()
        .filter(|&k| m.test(k as usize, pu, pv).strict)
        .map(|k| m.blocks[k as usize].patch)
        .collect()
}

#[test]
fn shared_edges_and_vertices_have_exactly_one_strict_owner() {
    let mesh = grid_and_fan();
    let m = PlaneMerge::build(&mesh);
    assert_eq!(m.plane_counts(), [1, 1, 0]);
    let g = |i: u32| i as f32 * 0.3;
    // Grid (plane y = 2; u = z, v = x): every point on an inner grid line, vertices too.
    for a in 1..5 {
        for b in 1..50 {
            // Inside the grid's span (0, 1.5), through the inner vertices (k·0.3) too.
            let along = if b % 10 == 0 {
                g(b / 10)
            } else {
                0.03 * b as f32
            };
            for (x, z) in [(a as f32 * 0.3, along), (along, a as f32 * 0.3)] {
                let own: Vec<u32> = owners(&m, z, x).into_iter().filter(|&p| p < 25).collect();
                assert_eq!(own.len(), 1, "({x}, {z}) owned by {own:?}");
            }
        }
    }
    // Fan (plane x = 0; u = y, v = z): points along each spoke, and the hub itself.
    let hub = (0.123f32, -0.31f32);
    for k in 0..12 {
        let a = k as f32 * std::f32::consts::TAU / 12.0;
        let rim = (hub.0 + a.cos() * 0.7, hub.1 + a.sin() * 0.7);
        for s in 0..20 {
            let f = s as f32 / 20.0;
            // The spoke's points as the merge would meet them: rounded interpolations.
            let p = (hub.0 + (rim.0 - hub.0) * f, hub.1 + (rim.1 - hub.1) * f);
            let own: Vec<u32> = owners(&m, p.0, p.1)
                .into_iter()
                .filter(|&p| p >= 25)
                .collect();
            // Rounding may move a point off the spoke: then it is strictly inside one
            // triangle. On it, the half-open rule gives it to exactly one.
            assert_eq!(own.len(), 1, "spoke {k} at {f}: {own:?}");
        }
    }
}

#[test]
fn bucket_table_finds_places_like_a_binary_search() {
    // 40 planes bunched near z = 0 (many per bucket) and a few far away.
    let mut m = Mesh::default();
    let zs: Vec<f32> = (0..40)
        .map(|k| k as f32 * 1e-3)
        .chain([5.0, 7.5, 100.0])
        .collect();
    for &z in &zs {
        let first = m.patch_vertices.len() as u32;
        for (x, y) in [(0., 0.), (1., 0.), (1., 1.), (0., 1.)] {
            m.patch_vertices.push(m.vertices.len() as u32);
            m.vertices.push(vec3(x, y, z));
        }
        m.patches.push(Patch {
            first,
            count: 4,
            material: 0,
            polygon: 0,
            area: 1.0,
            centre: vec3(0.5, 0.5, z),
            normal: Vec3::Z,
            class: PatchClass::Axial(Axis::Z),
            side: Side::One,
        });
    }
    let pm = PlaneMerge::build(&m);
    assert_eq!(pm.plane_counts(), [0, 0, zs.len()]);
    let l = &pm.axes[2];
    let list = &pm.coords[l.first..l.end];
    for k in -10i32..2000 {
        let x = k as f32 * 0.06 - 0.5 + (k % 7) as f32 * 1e-4;
        for x in [x, zs[(k.unsigned_abs() as usize) % zs.len()]] {
            for or_equal in [false, true] {
                let want = l.first + list.partition_point(|&c| c < x || (or_equal && c == x));
                assert_eq!(pm.lower_bound(2, x, or_equal), want, "x = {x}");
            }
        }
    }
}
