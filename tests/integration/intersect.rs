//! The intersectors against each other: the plane merge (Sec. 2, Fig. 4) and the hybrid against
//! the f64 brute-force oracle and Embree, on scenes built in code, with the edge cases of
//! docs/design.md §4: rays along an axis, origins on a plane, shared edges and vertices, a plane of
//! 5,000 patches, coplanar overlaps, a closed box that must not leak, skew roofs.

use crate::scene_builder::*;
use glam::{vec3, Vec3};
use radiosity::bench::crosscheck::{self, Class, Judge, RayGen, RaySource, TestRay};
use radiosity::intersect::brute::BruteForce;
use radiosity::intersect::embree::EmbreeScene;
use radiosity::intersect::hybrid::Hybrid;
use radiosity::intersect::plane_merge::PlaneMerge;
use radiosity::intersect::{Hit, Intersector, Ray};
use radiosity::mesh::{self, Mesh, MeshOptions, PatchClass};
use radiosity::scene::Scene;
use rayon::prelude::*;

/// Disagreements within this distance of a patch edge (relative to the scene diagonal) are
/// "edge": an order of magnitude above f32 rounding of a crossing point (~5e-7 of the scene).
const EPS: f32 = 1e-5;

fn ray(org: Vec3, dir: Vec3) -> Ray {
    Ray {
        org,
        dir,
        tnear: 0.0,
        tfar: f32::INFINITY,
    }
}

/// Meshes put side by side as one (vertex and patch indices offset).
fn concat(meshes: &[Mesh]) -> Mesh {
    let mut out = Mesh {
        patch_size: meshes.iter().map(|m| m.patch_size).fold(0.0, f32::max),
        ..Mesh::default()
    };
    for m in meshes {
        let (v0, i0) = (out.vertices.len() as u32, out.patch_vertices.len() as u32);
        out.vertices.extend_from_slice(&m.vertices);
        out.patch_vertices
            .extend(m.patch_vertices.iter().map(|&i| i + v0));
        out.patches.extend(m.patches.iter().map(|p| {
            let mut p = *p;
            p.first += i0;
            p
        }));
    }
    out
}

/// A room 4 × 3 × 5 (walls facing in) with a table, a shelf, a pillar and a low partition
/// (faces out): axial only, about 1,700 patches, many distinct planes per axis. Blocks stand on
/// the floor, so their bottoms overlap it: coincident patches facing opposite ways.
fn furnished_room() -> Mesh {
    let mut s = closed_box(4.0, 3.0, 5.0, material("wall", 0.5, 0.0));
    block(&mut s, vec3(0.5, 0.0, 0.5), vec3(1.7, 0.8, 1.3), 0); // table
    block(&mut s, vec3(3.0, 1.2, 0.2), vec3(3.9, 1.25, 1.4), 0); // shelf
    block(&mut s, vec3(2.0, 0.0, 3.0), vec3(2.3, 3.0, 3.3), 0); // pillar, floor to ceiling
    block(&mut s, vec3(0.0, 0.0, 2.5), vec3(1.5, 1.2, 2.55), 0); // partition against the wall
    mesh_at(&s, Some(0.25))
}

/// A closed box whose walls are each cut from two polygons at their own patch sizes, so
/// patches of different sizes meet along T-junctions inside every wall.
fn patchwork_box() -> Mesh {
    let sizes = [0.05, 0.07, 0.11, 0.13, 0.17, 0.19];
    let (w, h, d) = (1.3f32, 1.0f32, 1.7f32);
    let split = 0.37f32; // fraction where each wall is cut in two
    let p = |x: f32, y: f32, z: f32| vec3(x * w, y * h, z * d);
    // Each wall: (corner, edge u, edge v), counter-clockwise seen from inside.
    let walls: [(Vec3, Vec3, Vec3); 6] = [
        (p(0., 0., 0.), p(0., 0., 1.), p(1., 0., 0.)), // floor, +y
        (p(0., 1., 0.), p(1., 0., 0.), p(0., 0., 1.)), // ceiling, −y
        (p(0., 0., 0.), p(1., 0., 0.), p(0., 1., 0.)), // z = 0, +z
        (p(0., 0., 1.), p(0., 1., 0.), p(1., 0., 0.)), // z = d, −z
        (p(0., 0., 0.), p(0., 1., 0.), p(0., 0., 1.)), // x = 0, +x
        (p(1., 0., 0.), p(0., 0., 1.), p(0., 1., 0.)), // x = w, −x
    ];
    let mut meshes = Vec::new();
    for (k, (o, u, v)) in walls.into_iter().enumerate() {
        for (part, (a, b)) in [(0.0, split), (split, 1.0)].into_iter().enumerate() {
            let mut s = grey_scene();
            let (c0, c1) = (o + u * a, o + u * b);
            polygon(&mut s, &[c0, c1, c1 + v, c0 + v], 0);
            meshes.push(mesh_at(&s, Some(sizes[(k + 3 * part) % 6])));
        }
    }
    concat(&meshes)
}

/// A closed house: a 6 × 3 × 4 box of walls (facing in) under a pitched roof (two skew slopes,
/// axial triangular gables), with a skew ramp inside. About 1,000 patches, ~30 % skew.
fn house() -> Mesh {
    let (w, h, d, ridge) = (6.0f32, 3.0f32, 4.0f32, 4.5f32);
    let mut s = grey_scene();
    let q = |s: &mut Scene, a: Vec3, b: Vec3, c: Vec3, e: Vec3| polygon(s, &[a, b, c, e], 0);
    q(
        &mut s,
        vec3(0., 0., 0.),
        vec3(0., 0., d),
        vec3(w, 0., d),
        vec3(w, 0., 0.),
    ); // floor
    q(
        &mut s,
        vec3(0., 0., 0.),
        vec3(w, 0., 0.),
        vec3(w, h, 0.),
        vec3(0., h, 0.),
    ); // z = 0
    q(
        &mut s,
        vec3(0., 0., d),
        vec3(0., h, d),
        vec3(w, h, d),
        vec3(w, 0., d),
    ); // z = d
    q(
        &mut s,
        vec3(0., 0., 0.),
        vec3(0., h, 0.),
        vec3(0., h, d),
        vec3(0., 0., d),
    ); // x = 0
    q(
        &mut s,
        vec3(w, 0., 0.),
        vec3(w, 0., d),
        vec3(w, h, d),
        vec3(w, h, 0.),
    ); // x = w
       // Gables: triangles in x = 0 and x = w above the walls.
    polygon(
        &mut s,
        &[vec3(0., h, 0.), vec3(0., ridge, d / 2.), vec3(0., h, d)],
        0,
    );
    polygon(
        &mut s,
        &[vec3(w, h, 0.), vec3(w, h, d), vec3(w, ridge, d / 2.)],
        0,
    );
    // Roof slopes, facing down into the house.
    q(
        &mut s,
        vec3(0., h, 0.),
        vec3(w, h, 0.),
        vec3(w, ridge, d / 2.),
        vec3(0., ridge, d / 2.),
    );
    q(
        &mut s,
        vec3(0., h, d),
        vec3(0., ridge, d / 2.),
        vec3(w, ridge, d / 2.),
        vec3(w, h, d),
    );
    // A ramp (skew, one-sided, facing up) and a table block.
    q(
        &mut s,
        vec3(1., 0.2, 1.),
        vec3(1., 1.2, 3.),
        vec3(2.5, 1.2, 3.),
        vec3(2.5, 0.2, 1.),
    );
    // Off the floor: a block standing on it would have a bottom face coplanar with the floor,
    // whose rays start outside the house.
    block(&mut s, vec3(4., 0.05, 1.), vec3(5., 0.9, 2.5), 0);
    mesh_at(&s, Some(0.3))
}

/// A disagreement: its class, the ray, and the two answers.
type Diff = (Class, TestRay, Option<Hit>, Option<Hit>);

/// Casts `rays` through `a` and `b` in parallel; returns (agreed, classes of disagreements).
fn compare<A: Intersector, B: Intersector>(
    mesh: &Mesh,
    a: &A,
    b: &B,
    rays: &[TestRay],
) -> (usize, Vec<Diff>) {
    let judge = Judge::new(mesh, EPS);
    let diffs: Vec<_> = rays
        .par_iter()
        .filter_map(|r| {
            let (ha, hb) = (crosscheck::trace(a, r), crosscheck::trace(b, r));
            (ha.map(|h| h.patch) != hb.map(|h| h.patch))
                .then(|| (judge.classify(r, ha, hb), *r, ha, hb))
        })
        .collect();
    (rays.len() - diffs.len(), diffs)
}

fn assert_no_real(what: &str, diffs: &[Diff]) {
    let bad: Vec<_> = diffs
        .iter()
        .filter(|d| d.0 == Class::Real)
        .take(5)
        .collect();
    assert!(bad.is_empty(), "{what}: real disagreements, e.g. {bad:?}");
}

#[test]
fn merge_agrees_with_brute_force_on_random_rays() {
    let m = furnished_room();
    assert!(m.patches.iter().all(|p| p.class != PatchClass::Skew));
    let merge = PlaneMerge::build(&m);
    assert_eq!(merge.patch_count(), m.patches.len());
    assert!(
        merge.plane_counts().iter().all(|&n| n >= 4),
        "{:?}",
        merge.plane_counts()
    );
    let brute = BruteForce::new(&m);
    let rays = RayGen::new(&m).rays(100_000, 1);
    let (agreed, diffs) = compare(&m, &merge, &brute, &rays);
    assert_no_real("merge vs brute", &diffs);
    // Disagreements are f32-vs-f64 rounding within EPS of an edge: rare (~EPS × edge length
    // per area), so 99.9 % agreement leaves an order of magnitude of margin.
    assert!(
        agreed as f64 >= 0.999 * rays.len() as f64,
        "agreed {agreed}"
    );
    // Hit distances agree with the oracle's where the patches do.
    for r in rays.iter().step_by(97) {
        if let (Some(a), Some(b)) = (crosscheck::trace(&merge, r), crosscheck::trace(&brute, r)) {
            if a.patch == b.patch {
                assert!((a.t - b.t).abs() <= 1e-5 * b.t.max(1.0), "{a:?} vs {b:?}");
                assert_eq!(a.back, b.back);
            }
        }
    }
}

#[test]
fn rays_along_an_axis_hit_the_wall_they_point_at() {
    let m = furnished_room();
    let merge = PlaneMerge::build(&m);
    let brute = BruteForce::new(&m);
    let judge = Judge::new(&m, EPS);
    let mut checked = 0;
    for k in 0..2000 {
        // Origins on an irregular lattice inside the room, all six axis directions.
        let f = |i: u32, n: f32| ((k * i) % 997) as f32 / 997.0 * n;
        let org = vec3(0.01 + f(13, 3.98), 0.01 + f(29, 2.98), 0.01 + f(41, 4.98));
        for dir in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z] {
            let r = ray(org, dir);
            let (a, b) = (merge.intersect(&r), brute.intersect(&r));
            assert!(a.is_some(), "escaped along {dir} from {org}");
            if a.map(|h| h.patch) != b.map(|h| h.patch) {
                let t = TestRay {
                    org: org.to_array(),
                    dir: dir.to_array(),
                    source: RaySource::Uniform,
                    shooter: None,
                    eps: 0.0,
                };
                // Edge, or coincident: inside a block standing on the floor, its bottom and
                // the floor overlap.
                let class = judge.classify(&t, a, b);
                assert_ne!(class, Class::Real, "{org} {dir}: {a:?} {b:?}");
            } else if let (Some(a), Some(b)) = (a, b) {
                assert!((a.t - b.t).abs() < 1e-5);
                checked += 1;
            }
        }
    }
    assert!(checked > 11_000);
}

#[test]
fn a_ray_starting_on_a_plane_does_not_see_that_plane() {
    // Decision (plane_merge docs): planes count for tnear < t ≤ tfar, so a ray that starts on
    // a plane never reports it at t = 0, whichever way it leaves. The solver's rays start off
    // the surface (origin + normal·eps) and skip their shooter anyway.
    let m = mesh_at(
        &closed_box(1.0, 1.0, 1.0, material("w", 0.5, 0.0)),
        Some(0.25),
    );
    let merge = PlaneMerge::build(&m);
    let floor = |h: &Hit| m.patches[h.patch as usize].centre.y == 0.0;
    for k in 0..200 {
        let x = 0.013 + (k as f32 * 0.618).fract() * 0.97;
        let z = 0.011 + (k as f32 * 0.414).fract() * 0.97;
        let org = vec3(x, 0.0, z);
        let up = vec3((k % 7) as f32 * 0.1 - 0.3, 1.0, 0.2).normalize();
        let h = merge
            .intersect(&ray(org, up))
            .expect("leaves the floor, hits the room");
        assert!(!floor(&h) && h.t > 0.01, "{h:?}");
        // Leaving through the floor's back: nothing else below.
        assert!(merge.intersect(&ray(org, -up)).is_none());
        // As the solver casts: off the floor by eps, tnear = 0.
        let h = merge.intersect(&ray(org + Vec3::Y * 1e-5, up)).unwrap();
        assert!(!floor(&h));
        // A ray starting just below the floor and going up meets it at t ≈ 0, from behind.
        let h = merge.intersect(&ray(org - Vec3::Y * 1e-5, up)).unwrap();
        assert!(floor(&h) && h.back && h.t < 2e-5, "{h:?}");
    }
}

#[test]
fn a_ray_through_a_shared_edge_or_vertex_hits_exactly_one_patch() {
    // In y = 0: a unit square cut into 8 × 8 quads (edges at exactly representable
    // coordinates) and a right triangle cut into 64 triangles (diagonal shared edges).
    let mut s = grey_scene();
    polygon(
        &mut s,
        &[
            vec3(0., 0., 0.),
            vec3(0., 0., 1.),
            vec3(1., 0., 1.),
            vec3(1., 0., 0.),
        ],
        0,
    );
    let mut t = grey_scene();
    polygon(
        &mut t,
        &[vec3(2., 0., 0.), vec3(2., 0., 1.), vec3(3., 0., 0.)],
        0,
    );
    // 0.18: the hypotenuse √2 is cut in 8, so the triangle's grid is at multiples of 1/8.
    let m = concat(&[mesh_at(&s, Some(0.125)), mesh_at(&t, Some(0.18))]);
    assert_eq!(m.patches.len(), 128);
    let merge = PlaneMerge::build(&m);
    // The hit patch must be one whose closed region holds the point.
    let holds = |h: &Hit, p: Vec3| {
        let ids = m.patch_indices(h.patch as usize);
        let v = |k: usize| m.vertices[ids[k % ids.len()] as usize];
        (0..ids.len()).all(|k| {
            let (a, b) = (v(k), v(k + 1));
            // Counter-clockwise seen from +y: inside is where (b − a) × (p − a) · y ≥ 0.
            (b - a).cross(p - a).y >= -1e-6
        })
    };
    for i in 0..=8 {
        for j in 0..=64 {
            // Points on every grid line (every 1/64 along it, vertices included), both ways.
            for (x, z) in [
                (i as f32 / 8.0, j as f32 / 64.0),
                (j as f32 / 64.0, i as f32 / 8.0),
            ] {
                let p = vec3(x, 0.0, z);
                // The outer boundary borders nothing: the half-open rule gives it to the
                // square or not. Inner edges and vertices must always be covered.
                let outer = x == 0.0 || x == 1.0 || z == 0.0 || z == 1.0;
                // Vertical rays and oblique ones whose crossing is exact (t = 1, unit steps).
                for dir in [vec3(0., -1., 0.), vec3(-1., -1., 0.), vec3(0., -1., 1.)] {
                    match merge.intersect(&ray(p - dir, dir)) {
                        Some(h) => {
                            assert!(h.patch < 64 && holds(&h, p), "{p}: {h:?}");
                            assert_eq!(h.t, 1.0);
                        }
                        None => assert!(outer, "fell through the quads at {p} along {dir}"),
                    }
                }
            }
        }
    }
    // The triangle's grid lines: x − 2 = c, z = c and the diagonals (x − 2) + z = c.
    for k in 0..=8 {
        for j in 0..=64 {
            let c = k as f32 / 8.0;
            let along = (j as f32 / 64.0).min(c);
            let across = (j as f32 / 64.0).min(1.0 - c);
            for p in [
                vec3(2.0 + c, 0.0, across),
                vec3(2.0 + across, 0.0, c),
                vec3(2.0 + c - along, 0.0, along),
            ] {
                let outer = p.x == 2.0 || p.z == 0.0 || p.x - 2.0 + p.z >= 1.0;
                match merge.intersect(&ray(p + Vec3::Y, -Vec3::Y)) {
                    Some(h) => assert!(h.patch >= 64 && holds(&h, p), "{p}: {h:?}"),
                    None => assert!(outer, "fell through the triangle at {p}"),
                }
            }
        }
    }
}

#[test]
fn a_plane_of_5000_patches_matches_brute_force() {
    // A 10 × 5 floor at patch size 0.1: 100 × 50 = 5,000 quads in y = 0, under a ceiling.
    let mut s = grey_scene();
    polygon(
        &mut s,
        &[
            vec3(0., 0., 0.),
            vec3(0., 0., 5.),
            vec3(10., 0., 5.),
            vec3(10., 0., 0.),
        ],
        0,
    );
    let floor = mesh_at(&s, Some(0.1));
    assert_eq!(floor.patches.len(), 5000);
    let mut c = grey_scene();
    polygon(
        &mut c,
        &[
            vec3(0., 1., 0.),
            vec3(10., 1., 0.),
            vec3(10., 1., 5.),
            vec3(0., 1., 5.),
        ],
        0,
    );
    let m = concat(&[floor, mesh_at(&c, Some(5.0))]);
    let merge = PlaneMerge::build(&m);
    assert_eq!(merge.plane_counts(), [0, 2, 0]);
    let brute = BruteForce::new(&m);
    // Brute force is O(10^4) triangles per ray: 10^4 rays keep this test around a second.
    let rays = RayGen::new(&m).rays(10_000, 5);
    let (agreed, diffs) = compare(&m, &merge, &brute, &rays);
    assert_no_real("5000-patch plane", &diffs);
    assert!(agreed >= 9_980, "agreed {agreed}");
    // Straight down onto the floor: the patch under the point, computed by hand.
    for k in 1..20_000u32 {
        // Inside the floor (its outer boundary belongs to it or not, by the half-open rule).
        let x = 0.001 + (k as f64 * 0.618_034).fract() as f32 * 9.998;
        let z = 0.001 + (k as f64 * 0.414_214).fract() as f32 * 4.998;
        let h = merge.intersect(&ray(vec3(x, 0.5, z), -Vec3::Y)).unwrap();
        let p = m.patches[h.patch as usize].centre;
        assert!((p.x - x).abs() <= 0.05 + 1e-5 && (p.z - z).abs() <= 0.05 + 1e-5);
    }
}

#[test]
fn coplanar_overlapping_patches_give_a_deterministic_answer() {
    // Three overlapping quads in z = 0 facing +z (ids 0, 1, 2), then the first one's back.
    let mut s = grey_scene();
    let sq = |x: f32, y: f32, sz: f32| {
        [
            vec3(x, y, 0.),
            vec3(x + sz, y, 0.),
            vec3(x + sz, y + sz, 0.),
            vec3(x, y + sz, 0.),
        ]
    };
    polygon(&mut s, &sq(0.0, 0.0, 1.0), 0);
    polygon(&mut s, &sq(0.5, 0.5, 1.0), 0);
    polygon(&mut s, &sq(0.25, 0.25, 1.0), 0);
    let back: Vec<Vec3> = sq(0.0, 0.0, 1.0).into_iter().rev().collect();
    polygon(&mut s, &back, 0);
    let m = mesh_at(&s, Some(2.0));
    assert_eq!(m.patches.len(), 4);
    let merge = PlaneMerge::build(&m);
    let hit = |x: f32, y: f32, from_front: bool| {
        let z = if from_front { 1.0 } else { -1.0 };
        merge
            .intersect(&ray(vec3(x, y, z), vec3(0.1, -0.05, -z).normalize()))
            .map(|h| h.patch)
    };
    for _ in 0..3 {
        // From the front: the front-facing patch with the lowest id.
        assert_eq!(hit(0.8, 0.8, true), Some(0)); // 0, 1 and 2 overlap
        assert_eq!(hit(1.2, 1.2, true), Some(1)); // 1 and 2
        assert_eq!(hit(0.4, 0.4, true), Some(0)); // 0 (and its back), 2
                                                  // From behind: patch 3 faces the ray where it exists; elsewhere a back hit.
        assert_eq!(hit(0.8, 0.8, false), Some(3));
        assert_eq!(hit(1.2, 1.2, false), Some(1));
    }
}

#[test]
fn a_closed_box_of_mixed_patch_sizes_leaks_no_ray() {
    let m = patchwork_box();
    assert!(m.patches.len() > 1000, "{}", m.patches.len());
    let merge = PlaneMerge::build(&m);
    let embree = EmbreeScene::build(&m, |_| true).unwrap();
    let rays = RayGen::new(&m).rays(200_000, 7);
    // Every ray starts inside the box (uniform origins lie in its bounds): none may escape.
    let leaks = |i: &(dyn Fn(&TestRay) -> Option<Hit> + Sync)| {
        rays.par_iter().filter(|r| i(r).is_none()).count()
    };
    assert_eq!(leaks(&|r| crosscheck::trace(&merge, r)), 0, "merge leaks");
    let embree_leaks = leaks(&|r| crosscheck::trace(&embree, r));
    eprintln!("embree: {embree_leaks} of {} rays escaped", rays.len());
    // And the merge agrees with Embree up to edge/grazing cases.
    let (agreed, diffs) = compare(&m, &merge, &embree, &rays);
    assert_no_real("patchwork box, merge vs embree", &diffs);
    assert!(
        agreed as f64 >= 0.9999 * rays.len() as f64,
        "agreed {agreed}"
    );
}

#[test]
fn rays_aimed_at_corners_and_seams_never_escape() {
    // Rays from inside the patchwork box aimed exactly at its corner lines, its corner points,
    // and the seams inside each wall where patches of different sizes meet (T-junctions): the
    // rounded crossing points scatter by ulps around those lines, where a strict polygon test
    // alone lets some through (measured: dozens in 10^5).
    let m = patchwork_box();
    let merge = PlaneMerge::build(&m);
    let (w, h, d) = (1.3f32, 1.0f32, 1.7f32);
    let targets = |k: u32| -> Vec3 {
        let f = |i: u32| ((k.wrapping_mul(i) % 10007) as f32 + 0.5) / 10007.0;
        let (a, b, c) = (f(7919), f(104_729), f(1_299_709));
        let x = [0.0, w][(k % 2) as usize];
        let y = [0.0, h][(k / 2 % 2) as usize];
        let z = [0.0, d][(k / 4 % 2) as usize];
        match k % 7 {
            0 => vec3(a * w, y, z),          // corner lines along x
            1 => vec3(x, b * h, z),          // along y
            2 => vec3(x, y, c * d),          // along z
            3 => vec3(x, y, z),              // corner points
            4 => vec3(0.37 * w, 0.0, c * d), // the floor's seam
            5 => vec3(x, 0.37 * h, c * d),   // the side walls' seams
            _ => vec3(a * w, 0.37 * h, z),   // the end walls' seams
        }
    };
    let escaped: Vec<(Vec3, Vec3)> = (0..100_000u32)
        .into_par_iter()
        .filter_map(|k| {
            let f = |i: u32| ((k.wrapping_mul(i) % 9973) as f32 + 0.5) / 9973.0;
            let org = vec3(f(31) * w, f(37) * h, f(41) * d);
            let dir = (targets(k) - org).normalize();
            merge
                .intersect(&ray(org, dir))
                .is_none()
                .then_some((org, dir))
        })
        .collect();
    assert!(
        escaped.is_empty(),
        "{} escaped, e.g. {:?}",
        escaped.len(),
        &escaped[..escaped.len().min(3)]
    );
}

#[test]
fn hybrid_agrees_with_embree_under_a_pitched_roof() {
    let m = house();
    let skew = m
        .patches
        .iter()
        .filter(|p| p.class == PatchClass::Skew)
        .count();
    assert!(skew > 100 && skew < m.patches.len() / 2, "{skew} skew");
    let hybrid = Hybrid::build(&m).unwrap();
    let embree = EmbreeScene::build(&m, |_| true).unwrap();
    let rays = RayGen::new(&m).rays(200_000, 11);
    let (agreed, diffs) = compare(&m, &hybrid, &embree, &rays);
    assert_no_real("house, hybrid vs embree", &diffs);
    // The bar for this pair: ≥ 99.99 %.
    assert!(
        agreed as f64 >= 0.9999 * rays.len() as f64,
        "agreed {agreed}"
    );
    // Uniform origins may lie outside the house (under the eaves); surface ones are inside.
    let escapes = rays
        .par_iter()
        .filter(|r| r.source == RaySource::Surface)
        .filter(|r| crosscheck::trace(&hybrid, r).is_none())
        .count();
    assert_eq!(escapes, 0, "the house is closed");
    // And against the oracle on fewer rays.
    let brute = BruteForce::new(&m);
    let (_, diffs) = compare(&m, &hybrid, &brute, &rays[..20_000]);
    assert_no_real("house, hybrid vs brute", &diffs);
}

#[test]
fn hybrid_seals_the_seams_between_walls_and_roof() {
    // Rays from inside the house aimed exactly at the gable–roof seams, the eaves and the
    // gable–wall seams, where axial patches (the merge's) meet skew ones (Embree's) along
    // edges whose vertices do not match. Measured: Embree over the whole house lets ~3.6 % of
    // these through; the hybrid's seam rule (plane_merge docs) none.
    let m = house();
    let hybrid = Hybrid::build(&m).unwrap();
    let (w, h, d, ridge) = (6.0f32, 3.0f32, 4.0f32, 4.5f32);
    let escaped = (0..100_000u32)
        .into_par_iter()
        .filter(|&k| {
            let f = |i: u32| ((k.wrapping_mul(i) % 9973) as f32 + 0.5) / 9973.0;
            let org = vec3(0.1 + f(31) * 5.8, 0.1 + f(37) * 2.0, 0.1 + f(41) * 3.8);
            let a = f(7919);
            let x = [0.0, w][(k % 2) as usize];
            let target = match k % 3 {
                0 => vec3(x, h + a * (ridge - h), a * d / 2.0), // gable–roof
                1 => vec3(a * w, h, [0.0, d][(k / 2 % 2) as usize]), // eaves
                _ => vec3(x, h, a * d),                         // gable–wall
            };
            hybrid
                .intersect(&ray(org, (target - org).normalize()))
                .is_none()
        })
        .count();
    assert_eq!(escaped, 0);
}

#[test]
fn hybrid_builds_only_what_the_scene_needs() {
    let axial = mesh_at(
        &closed_box(1.0, 1.0, 1.0, material("w", 0.5, 0.0)),
        Some(0.5),
    );
    let h = Hybrid::build(&axial).unwrap();
    assert!(h.embree().is_none(), "no Embree scene without skew patches");
    assert_eq!(h.merge().unwrap().patch_count(), axial.patches.len());

    // A tetrahedron has no axis-aligned face when none is normal to an axis.
    let mut s = grey_scene();
    let (a, b, c, d) = (
        vec3(1., 1., 1.),
        vec3(1., -1., -1.),
        vec3(-1., 1., -1.),
        vec3(-1., -1., 1.),
    );
    for f in [[a, c, b], [a, b, d], [a, d, c], [b, c, d]] {
        polygon(&mut s, &f, 0);
    }
    let skew = mesh_at(&s, Some(0.5));
    assert!(skew.patches.iter().all(|p| p.class == PatchClass::Skew));
    let h = Hybrid::build(&skew).unwrap();
    assert!(h.merge().is_none(), "no plane lists without axial patches");
    // Each face is a triangle cut into a grid of patches, which Embree takes whole.
    let e = h.embree().unwrap();
    assert_eq!((e.grid_count(), e.triangle_count()), (4, 4));
    let hit = h
        .intersect(&ray(Vec3::ZERO, Vec3::X))
        .expect("inside the tetrahedron");
    assert!((hit.t - 1.0).abs() < 1e-6, "{hit:?}"); // the face x − y + z = 1
}

#[test]
fn crosscheck_finds_no_real_disagreement_and_is_deterministic() {
    let m = house();
    let a = crosscheck::crosscheck(&m, 20_000, 3, EPS).unwrap();
    assert_eq!(a.oracle.as_deref(), Some("brute"));
    assert_eq!(a.pairs.len(), 3);
    for p in &a.pairs {
        assert_eq!(p.real, 0, "{} vs {}: {:?}", p.a, p.b, p.examples);
        assert_eq!(p.rays, 20_000);
        assert!(p.agreement >= 0.999, "{} vs {}: {}", p.a, p.b, p.agreement);
    }
    for i in &a.intersectors {
        assert_eq!(i.surface_rays, 10_000);
        assert_eq!(i.escapes, 0, "{} leaks", i.name);
    }
    let b = crosscheck::crosscheck(&m, 20_000, 3, EPS).unwrap();
    assert_eq!(
        serde_json::to_string(&a).unwrap(),
        serde_json::to_string(&b).unwrap()
    );
}

#[test]
fn crosscheck_on_the_default_cornell_box() {
    // The built-in scene (open at the front, so surface rays may escape; skew red wall and
    // blocks): no real disagreement among Embree, the hybrid and brute force.
    let scene = radiosity::scene::default_scene(&Default::default()).unwrap();
    let m = mesh::build(&scene, &MeshOptions::default());
    let r = crosscheck::crosscheck(&m, 20_000, 9, EPS).unwrap();
    for p in &r.pairs {
        assert_eq!(p.real, 0, "{} vs {}: {:?}", p.a, p.b, p.examples);
    }
}

#[test]
fn crosscheck_on_a_generated_building() {
    let m = building(10_000);
    assert!(m.patches.len() > 10_000, "{}", m.patches.len());
    let r = crosscheck::crosscheck(&m, 100_000, 5, EPS).unwrap();
    assert_eq!(r.oracle, None, "no brute force above 2,000 patches");
    // Every patch axis-aligned: the merge alone is checked too, against Embree.
    assert_eq!(r.reference, "embree");
    let names: Vec<(&str, &str)> = r.pairs.iter().map(|p| (&*p.a, &*p.b)).collect();
    assert_eq!(names, [("merge", "embree"), ("hybrid", "embree")]);
    assert!(r.closed, "{}", r.closed_reason);
    for p in &r.pairs {
        assert_eq!(p.real, 0, "{:?}", p.examples);
    }
    let p = &r.pairs[1];
    assert_eq!(p.real, 0, "{:?}", p.examples);
    // The bar is 99.999 % over 10^6 rays; over 10^5 a single edge case is 0.001 %.
    assert!(p.agreement >= 0.9999, "{}", p.agreement);
    for i in &r.intersectors {
        assert_eq!(i.escapes, 0, "{} leaks out of a closed room", i.name);
    }
}

/// A generated building: 4 × 2 × 4 closed rooms of 5 × 3 × 4 m on a grid, 0.2 m apart (walls
/// aligned across the building, as architecture has them), meshed to about `target` patches.
fn building(target: usize) -> Mesh {
    let mut s = grey_scene();
    for i in 0..4 {
        for j in 0..2 {
            for k in 0..4 {
                let lo = vec3(i as f32 * 5.2, j as f32 * 3.2, k as f32 * 4.2);
                let hi = lo + vec3(5.0, 3.0, 4.0);
                // A room: a block with its faces turned inwards.
                let start = s.polygons.len();
                block(&mut s, lo, hi, 0);
                for p in &mut s.polygons[start..] {
                    let ids = &mut s.indices[p.first as usize..(p.first + p.len) as usize];
                    ids.reverse();
                }
            }
        }
    }
    let area = 32.0 * 2.0 * (15.0 + 20.0 + 12.0);
    mesh_at(&s, Some((area / target as f32).sqrt()))
}

#[test]
fn selection_builds_only_what_the_scene_needs() {
    use radiosity::intersect::select::{self, AnyIntersector, IntersectorKind};
    let axial = mesh_at(
        &closed_box(1.0, 1.0, 1.0, material("w", 0.5, 0.0)),
        Some(0.5),
    );
    for (kind, embree, planes) in [
        (IntersectorKind::Embree, true, false),
        (IntersectorKind::Merge, false, true),
        (IntersectorKind::Hybrid, false, true),
    ] {
        let i = AnyIntersector::build(&axial, kind).unwrap();
        assert_eq!(
            (i.has_embree(), i.has_planes()),
            (embree, planes),
            "{kind:?}"
        );
        assert_eq!(i.name(), kind.name());
    }
    // auto: the measured rule (Embree), and a reason to print.
    let (i, sel) = select::select(&axial, IntersectorKind::Auto).unwrap();
    assert_eq!(sel.asked, IntersectorKind::Auto);
    assert_eq!(i.name(), sel.chosen.name());
    assert!(sel.reason.contains("axis-aligned"), "{}", sel.reason);

    // Skew only: the hybrid has no plane lists, and the merge alone is refused.
    let mut s = grey_scene();
    let (a, b, c, d) = (
        vec3(1., 1., 1.),
        vec3(1., -1., -1.),
        vec3(-1., 1., -1.),
        vec3(-1., -1., 1.),
    );
    for f in [[a, c, b], [a, b, d], [a, d, c], [b, c, d]] {
        polygon(&mut s, &f, 0);
    }
    let skew = mesh_at(&s, Some(0.5));
    let h = AnyIntersector::build(&skew, IntersectorKind::Hybrid).unwrap();
    assert_eq!((h.has_embree(), h.has_planes()), (true, false));
    let err = radiosity::Error::from(
        AnyIntersector::build(&skew, IntersectorKind::Merge)
            .err()
            .expect("merge on a skew scene"),
    );
    assert_eq!(err.exit_code(), 2);
    assert!(err.to_string().contains("skew"), "{err}");
}

#[test]
fn solves_through_each_intersector_agree() {
    use radiosity::intersect::select::{AnyIntersector, IntersectorKind};
    use radiosity::solve::{self, SolveSettings};
    // blocks (4 skew patches): Embree and the hybrid; hallway (all axial, at 1 m patches to
    // stay quick): Embree, the merge and the hybrid.
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    for (file, patch_size, kinds) in [
        (
            "blocks.obj",
            None,
            &[IntersectorKind::Embree, IntersectorKind::Hybrid][..],
        ),
        (
            "hallway.obj",
            Some(1.0),
            &[
                IntersectorKind::Embree,
                IntersectorKind::Merge,
                IntersectorKind::Hybrid,
            ][..],
        ),
    ] {
        let scene = radiosity::scene::load_obj(&dir.join(file), &Default::default()).unwrap();
        let m = mesh::build(
            &scene,
            &MeshOptions {
                patch_size,
                ..Default::default()
            },
        );
        let cfg = SolveSettings {
            tolerance: 0.1,
            ..SolveSettings::default()
        };
        let solve_with = |k: IntersectorKind| {
            let i = AnyIntersector::build(&m, k).unwrap();
            solve::solve(&m, &scene.materials, &i, &cfg, |_| {})
                .unwrap()
                .b
        };
        let reference = solve_with(kinds[0]);
        let luminance = |b: &[f64; 3]| (b[0] + b[1] + b[2]) / 3.0;
        let area: f64 = m.patches.iter().map(|p| p.area).sum();
        let mean = m
            .patches
            .iter()
            .zip(&reference)
            .map(|(p, b)| p.area * luminance(b))
            .sum::<f64>()
            / area;
        for &k in &kinds[1..] {
            let b = solve_with(k);
            // The same seed casts the same rays; only hits within ε of an edge may differ,
            // and any difference then only reshuffles later samples. The area-weighted mean
            // |ΔB| must stay well inside the sampling error (tolerance 0.1 per patch).
            let diff = m
                .patches
                .iter()
                .zip(b.iter().zip(&reference))
                .map(|(p, (x, y))| p.area * (luminance(x) - luminance(y)).abs())
                .sum::<f64>()
                / area;
            assert!(
                diff <= 0.02 * mean,
                "{file}: {k:?} differs from {:?} by {:.4} of the mean radiosity",
                kinds[0],
                diff / mean
            );
        }
    }
}

/// A block turned 30° about the vertical (axial top, skew sides) standing on a floor.
fn turned_block_on_a_floor() -> (Mesh, Vec<Vec3>) {
    let mut s = grey_scene();
    let (c, sn) = (30f32.to_radians().cos(), 30f32.to_radians().sin());
    let corners: Vec<Vec3> = [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)]
        .iter()
        .map(|&(x, z)| vec3(c * x - sn * z, 0.0, sn * x + c * z))
        .collect();
    let up = Vec3::Y;
    polygon_facing(
        &mut s,
        &corners.iter().map(|p| *p + up).collect::<Vec<_>>(),
        Vec3::Y,
        0,
    );
    for k in 0..4 {
        let (a, b) = (corners[k], corners[(k + 1) % 4]);
        let out = ((a + b) * 0.5).normalize();
        polygon_facing(&mut s, &[a, b, b + up, a + up], out, 0);
    }
    polygon_facing(
        &mut s,
        &[
            vec3(-3., 0., -3.),
            vec3(3., 0., -3.),
            vec3(3., 0., 3.),
            vec3(-3., 0., 3.),
        ],
        Vec3::Y,
        0,
    );
    (mesh_at(&s, Some(2.0)), corners)
}

#[test]
fn rays_passing_just_outside_a_convex_seam_miss_it() {
    // Found by `radiosity crosscheck` on a generated building of 100 k patches: rays passing
    // a few 1e-5 m outside the top edge of a turned table (axial top, skew sides) hit the top
    // in the hybrid — its seam rule sealed the convex edge as if it were a crack — and the
    // floor in Embree and the oracle.
    let (m, corners) = turned_block_on_a_floor();
    let top = m
        .patches
        .iter()
        .position(|p| p.class == PatchClass::Axial(radiosity::mesh::Axis::Y) && p.centre.y > 0.5)
        .expect("the top") as u32;
    let h = Hybrid::build(&m).unwrap();
    let b = BruteForce::new(&m);
    // The merge's crack tolerance is 2e-6 of the scene size (about 8.5 m): pass at a third.
    let delta = 0.33 * 2e-6 * 8.5;
    for k in 0..4 {
        let (a, c) = (corners[k] + Vec3::Y, corners[(k + 1) % 4] + Vec3::Y);
        let out = vec3((a + c).x, 0.0, (a + c).z).normalize();
        for s in [0.1f32, 0.3, 0.5, 0.7, 0.9] {
            let p = a + (c - a) * s + out * delta;
            let dir = (out * 0.5 - Vec3::Y).normalize();
            let r = ray(p - dir, dir);
            let want = b.intersect(&r).map(|x| x.patch);
            assert!(
                want.is_some_and(|p| p != top),
                "the oracle passes by the top to the floor: {want:?}"
            );
            assert_eq!(h.intersect(&r).map(|x| x.patch), want, "edge {k} at {s}");
        }
    }
}

#[test]
fn a_ray_just_beyond_two_patches_ending_on_one_free_edge_misses_them() {
    // Two floor patches meet at a vertex on the floor's free edge (z = 0; a stair hole). A
    // point just beyond that vertex is near both, but outside both across edges facing the
    // same way: no crack between them, and the ray goes on to the floor below.
    let mut s = grey_scene();
    for (x0, x1) in [(-1.0, 0.0), (0.0, 1.0)] {
        polygon_facing(
            &mut s,
            &[
                vec3(x0, 0., -1.),
                vec3(x1, 0., -1.),
                vec3(x1, 0., 0.),
                vec3(x0, 0., 0.),
            ],
            Vec3::Y,
            0,
        );
    }
    polygon_facing(
        &mut s,
        &[
            vec3(-2., -1., -2.),
            vec3(2., -1., -2.),
            vec3(2., -1., 2.),
            vec3(-2., -1., 2.),
        ],
        Vec3::Y,
        0,
    );
    let m = mesh_at(&s, Some(8.0));
    assert_eq!(m.patches.len(), 3);
    let merge = PlaneMerge::build(&m);
    let b = BruteForce::new(&m);
    // The crack tolerance is 2e-6 of the scene size (about 5.7 m): pass at a third of it.
    let delta = 0.33 * 2e-6 * 5.7;
    for dx in [-0.3 * delta, 0.0, 0.3 * delta] {
        let r = ray(vec3(dx, 1.0, delta + 0.1), vec3(0.0, -1.0, -0.1));
        let want = b.intersect(&r).map(|h| h.patch);
        assert_eq!(want, Some(2), "the oracle reaches the floor below");
        assert_eq!(merge.intersect(&r).map(|h| h.patch), want, "dx {dx}");
    }
}

#[test]
fn embree_finds_the_patch_of_a_grid_it_takes_whole_like_brute_force() {
    // Pieces Embree takes whole (a tilted quad far from a parallelogram, a triangle, a large
    // hexagon fanned into triangles) and, near a lamp, patches cut finer that it does not.
    let mut s = grey_scene();
    s.materials.push(material("lamp", 0.0, 10.0));
    let (x, y) = (vec3(0.8, 0.0, 0.6), vec3(0.0, 0.6, -0.8));
    let flat = [(0.0, 0.0), (4.0, 0.5), (5.0, 3.5), (0.5, 2.0)];
    let twisted: Vec<Vec3> = flat.iter().map(|&(a, b)| x * a + y * b).collect();
    polygon(&mut s, &twisted, 0);
    polygon(
        &mut s,
        &[vec3(-3., -2., -4.), vec3(3., -2.5, -4.), vec3(0., 3., -4.2)],
        0,
    );
    let hexagon: Vec<Vec3> = (0..6)
        .map(|k| {
            let a = k as f32 * std::f32::consts::TAU / 6.0;
            vec3(2.0 * a.cos(), -3.0, 2.0 * a.sin() - 1.0)
        })
        .collect();
    polygon_facing(&mut s, &hexagon, Vec3::Y, 0);
    // A floor under a small lamp a hand's width above it: cut finer under the lamp.
    polygon_facing(
        &mut s,
        &[
            vec3(-4., 4., -6.),
            vec3(4., 4., -6.),
            vec3(4., 4., 2.),
            vec3(-4., 4., 2.),
        ],
        -Vec3::Y,
        0,
    );
    polygon_facing(
        &mut s,
        &[
            vec3(-0.2, 3.9, -2.2),
            vec3(0.2, 3.9, -2.2),
            vec3(0.2, 3.9, -1.8),
            vec3(-0.2, 3.9, -1.8),
        ],
        Vec3::Y,
        1,
    );
    let m = mesh_at(&s, Some(0.5));
    let in_grids: usize = m.grids.iter().map(|g| g.count() as usize).sum();
    assert!(m.grids.len() >= 8 && m.grids.iter().any(|g| g.is_triangle()));
    assert!(
        in_grids < m.patches.len(),
        "some patches cut finer near the lamp"
    );
    let e = EmbreeScene::build(&m, |_| true).unwrap();
    assert_eq!(e.grid_count(), m.grids.len());
    let brute = BruteForce::new(&m);
    let rays = RayGen::new(&m).rays(100_000, 3);
    let (agreed, diffs) = compare(&m, &e, &brute, &rays);
    assert_no_real("embree with grids vs brute", &diffs);
    assert!(
        agreed as f64 >= 0.999 * rays.len() as f64,
        "agreed {agreed}"
    );
}
