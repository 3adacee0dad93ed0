//! The sensor grid's work plane (`--grid HEIGHT,SPACING`): sensors HEIGHT above each
//! floor on a lattice offset half a spacing from the plan bounds; a floor needs 2.3 m clear above
//! it; a sensor needs the segment up to it free. Every expected count and position below follows
//! from that rule by hand; Embree and the brute-force oracle must agree to the bit.

use glam::{vec3, Vec3};
use radiosity::grid::{self, GridError, GridSpec, Sensor};
use radiosity::intersect::brute::BruteForce;
use radiosity::intersect::embree::EmbreeScene;
use radiosity::mesh::{Mesh, MeshOptions};
use radiosity::scene::Scene;
use radiosity::sky::Compass;

use crate::scene_builder::*;

/// A level quad over the room's whole plan [0, 4] × [0, 5] at height `y`, facing `normal`.
fn slab(s: &mut Scene, y: f32, normal: Vec3) {
    let pts = [
        vec3(0.0, y, 0.0),
        vec3(4.0, y, 0.0),
        vec3(4.0, y, 5.0),
        vec3(0.0, y, 5.0),
    ];
    polygon_facing(s, &pts, normal, 0);
}

/// A room 4 m (x) × `h` (y, up) × 5 m (z), closed, faces inwards.
fn room(h: f32) -> Scene {
    closed_box(4.0, h, 5.0, material("white", 0.5, 0.0))
}

fn mesh(s: &Scene, two_sided: bool) -> Mesh {
    radiosity::mesh::build(
        s,
        &MeshOptions {
            patch_size: Some(1.0),
            two_sided,
            one_sided: false,
            uniform_patches: false,
        },
    )
}

/// The work plane by Embree, checked against the brute-force oracle (Y up, north −Z).
fn plane(m: &Mesh, height: f32, spacing: f32) -> Result<Vec<Sensor>, GridError> {
    let frame = Compass::default();
    let embree = EmbreeScene::build(m, |_| true).unwrap();
    let got = grid::work_plane(m, &embree, &frame, height, spacing);
    if let Ok(sensors) = &got {
        let oracle = grid::work_plane(m, &BruteForce::new(m), &frame, height, spacing).unwrap();
        assert_eq!(sensors, &oracle, "Embree and the oracle disagree");
    }
    got
}

/// The lattice of the 4 × 5 m plan at 0.5 m, `y` high, in the rule's order: rows from north
/// (z = 0.25, since north is −z) to south, each from west (x = 0.25) to east; 8 × 10 points.
fn lattice(y: f32) -> Vec<Sensor> {
    (0..10)
        .flat_map(|r| (0..8).map(move |c| (r, c)))
        .map(|(r, c)| Sensor {
            position: vec3(0.25 + 0.5 * c as f32, y, 0.25 + 0.5 * r as f32),
            normal: Vec3::Y,
        })
        .collect()
}

fn in_footprint(p: Vec3, x: (f32, f32), z: (f32, f32)) -> bool {
    p.x > x.0 && p.x < x.1 && p.z > z.0 && p.z < z.1
}

#[test]
fn grid_room_gets_the_lattice_at_the_height_exactly() {
    let got = plane(&mesh(&room(3.0), false), 0.8, 0.5).unwrap();
    assert_eq!(got, lattice(0.8));
}

#[test]
fn grid_desk_leaves_a_hole_and_no_second_plane() {
    // A desk over columns x = 1.25, 1.75 at z = 1.25; its top 2.25 m under the ceiling. The
    // floor under it has only the desk's height clear: no sensor in those two columns,
    // whether the desk top is under the sensors' height or over it.
    for (bottom, top) in [(0.72, 0.75), (0.9, 0.95)] {
        let mut s = room(3.0);
        block(&mut s, vec3(1.0, bottom, 1.0), vec3(2.0, top, 1.6), 0);
        let got = plane(&mesh(&s, false), 0.8, 0.5).unwrap();
        let want: Vec<Sensor> = lattice(0.8)
            .into_iter()
            .filter(|s| !in_footprint(s.position, (1.0, 2.0), (1.0, 1.6)))
            .collect();
        assert_eq!(want.len(), 78);
        assert_eq!(got, want, "desk top at {top}");
    }
}

#[test]
fn grid_desk_is_a_floor_only_with_the_storey_clearance_above_it() {
    // A desk top (one quad) 0.75 m high: with a ceiling at 3.0 m, 2.25 m above it; at 3.1 m,
    // 2.35 m, which makes it a floor with its own sensors (at 1.55 m: the same storey).
    for (ceiling, desk_sensors) in [(3.0, 0), (3.1, 2)] {
        let mut s = room(ceiling);
        let top = [
            vec3(1.0, 0.75, 1.0),
            vec3(2.0, 0.75, 1.0),
            vec3(2.0, 0.75, 1.6),
            vec3(1.0, 0.75, 1.6),
        ];
        polygon_facing(&mut s, &top, Vec3::Y, 0);
        let got = plane(&mesh(&s, false), 0.8, 0.5).unwrap();
        let on_desk = got
            .iter()
            .filter(|s| (s.position.y - 1.55).abs() < 1e-6)
            .count();
        assert_eq!(on_desk, desk_sensors, "ceiling at {ceiling}");
        assert_eq!(got.len(), 78 + desk_sensors);
    }
}

#[test]
fn grid_sensor_needs_the_segment_up_to_it_free() {
    // A beam under a 4 m ceiling, its underside 2.4 m high, over the rows z = 2.25 and 2.75:
    // the floor under it is a floor (2.4 ≥ 2.3 m clear), so a plane at 0.8 m is whole, but one
    // at 2.5 m would put those 16 sensors inside the beam.
    let mut s = room(4.0);
    block(&mut s, vec3(0.0, 2.4, 2.0), vec3(4.0, 2.6, 3.0), 0);
    let m = mesh(&s, false);
    assert_eq!(plane(&m, 0.8, 0.5).unwrap(), lattice(0.8));
    let high = plane(&m, 2.5, 0.5).unwrap();
    let want: Vec<Sensor> = lattice(2.5)
        .into_iter()
        .filter(|s| !in_footprint(s.position, (0.0, 4.0), (2.0, 3.0)))
        .collect();
    assert_eq!(want.len(), 64);
    assert_eq!(high, want);
}

#[test]
fn grid_two_storeys_give_two_planes_bottom_up() {
    // A slab between two 3 m storeys: its top faces up at 3.0 m, the ceiling under it down at
    // 2.8 m. The plane over the lower storey comes first.
    let mut s = room(6.0);
    slab(&mut s, 3.0, Vec3::Y);
    slab(&mut s, 2.8, Vec3::NEG_Y);
    let want: Vec<Sensor> = lattice(0.8).into_iter().chain(lattice(3.8)).collect();
    assert_eq!(plane(&mesh(&s, false), 0.8, 0.5).unwrap(), want);

    // One two-sided slab: the ray from above meets its back, whose twin faces up.
    let mut s = room(6.0);
    slab(&mut s, 3.0, Vec3::NEG_Y);
    s.polygons.last_mut().unwrap().back_material = Some(0);
    assert_eq!(plane(&mesh(&s, false), 0.8, 0.5).unwrap(), want);
}

#[test]
fn grid_flat_roof_open_to_the_sky_is_a_floor() {
    // All two-sided: the roof's outer side faces up with nothing above it (a limit of the rule,
    // documented: terraces and courtyards are floors); the ground's underside is not.
    let mut s = room(6.0);
    slab(&mut s, 3.0, Vec3::NEG_Y);
    let got = plane(&mesh(&s, true), 0.8, 0.5).unwrap();
    let want: Vec<Sensor> = [0.8, 3.8, 6.8].into_iter().flat_map(lattice).collect();
    assert_eq!(got, want);
}

#[test]
fn grid_follows_the_frame_north_and_zenith() {
    // North +X with Y up: east = north × up = +Z. The same 80 points, in rows along z.
    let m = mesh(&room(3.0), false);
    let embree = EmbreeScene::build(&m, |_| true).unwrap();
    let frame = Compass::new(Vec3::Y, Vec3::X).unwrap();
    let got = grid::work_plane(&m, &embree, &frame, 0.8, 0.5).unwrap();
    let key = |s: &Sensor| (s.position.x.to_bits(), s.position.z.to_bits());
    let mut sorted = got.clone();
    sorted.sort_by_key(key);
    let mut want = lattice(0.8);
    want.sort_by_key(key);
    assert_eq!(sorted, want);
    // First the northmost row (x = 3.75) from west (z = 0.25) to east.
    assert_eq!(got[0].position, vec3(3.75, 0.8, 0.25));
    assert_eq!(got[1].position, vec3(3.75, 0.8, 0.75));

    // A Z-up model: the room turned so its height is along z; north +Y, east +X.
    let mut z_up = room(3.0);
    for p in &mut z_up.positions {
        *p = vec3(p.x, -p.z, p.y);
    }
    let m = mesh(&z_up, false);
    let embree = EmbreeScene::build(&m, |_| true).unwrap();
    let frame = Compass::new(Vec3::Z, Vec3::Y).unwrap();
    let got = grid::work_plane(&m, &embree, &frame, 0.8, 0.5).unwrap();
    let want: Vec<Sensor> = lattice(0.8)
        .iter()
        .map(|s| Sensor {
            position: vec3(s.position.x, -s.position.z, 0.8),
            normal: Vec3::Z,
        })
        .collect();
    assert_eq!(got, want);
}

/// Whether the convex patch `i` of `m`, seen from above, covers (x, z).
fn covers(m: &Mesh, i: usize, x: f32, z: f32) -> bool {
    let ring: Vec<Vec3> = m
        .patch_indices(i)
        .iter()
        .map(|&v| m.vertices[v as usize])
        .collect();
    let side = |a: Vec3, b: Vec3| (b.x - a.x) * (z - a.z) - (b.z - a.z) * (x - a.x);
    let sides: Vec<f32> = (0..ring.len())
        .map(|k| side(ring[k], ring[(k + 1) % ring.len()]))
        .collect();
    sides.iter().all(|&s| s >= 0.0) || sides.iter().all(|&s| s <= 0.0)
}

#[test]
fn grid_office_plane_avoids_the_furniture() {
    let (_, m) = project_scene("office.obj");
    // 0.47 m puts every column at an odd multiple of 5 mm, off the office's 5 cm edges: a
    // column exactly on a block's edge meets it or not as each intersector rounds.
    let got = plane(&m, 0.8, 0.47).unwrap();
    // Without rays: the office's plan is x in [0, 5.4], z in [-5.6, 0] (with the window
    // recess), so 11 × 12 columns, rows from north (z = -5.405) to south. A column gets a
    // sensor if it is in the room (z > -5.4: the recess's sill is 1.3 m under its head) and no
    // level face of a block (every block has a top) lies over it lower than 2.3 m.
    let blocks: Vec<usize> = (0..m.patches.len())
        .filter(|&i| {
            let p = &m.patches[i];
            p.normal.y.abs() > 0.99 && p.centre.y > 0.01 && p.centre.y < 2.3
        })
        .collect();
    let want: Vec<Sensor> = (0..12)
        .flat_map(|j| (0..11).map(move |i| (i, j)))
        .map(|(i, r)| {
            vec3(
                0.235 + 0.47 * i as f32,
                0.8,
                -0.235 - 0.47 * (11 - r) as f32,
            )
        })
        .filter(|p| p.z > -5.4 && !blocks.iter().any(|&b| covers(&m, b, p.x, p.z)))
        .map(|position| Sensor {
            position,
            normal: Vec3::Y,
        })
        .collect();
    assert_eq!(got.len(), want.len());
    for (g, w) in got.iter().zip(&want) {
        assert!((g.position - w.position).length() < 1e-5, "{g:?} {w:?}");
    }
    assert!(got
        .iter()
        .all(|s| s.position.y == 0.8 && s.normal == Vec3::Y));
    assert!(want.len() < 11 * 11 - 10, "the furniture leaves holes");
}

#[test]
fn grid_spec_errors_name_the_flag() {
    let m = mesh(&room(3.0), false);
    let embree = EmbreeScene::build(&m, |_| true).unwrap();
    let frame = Compass::default();
    let e = grid::work_plane(&m, &embree, &frame, 0.8, 1e-4).unwrap_err();
    assert!(matches!(e, GridError::TooMany { .. }), "{e}");
    assert!(
        e.to_string().starts_with("--grid 0.8,0.0001: a spacing"),
        "{e}"
    );
    let e = grid::work_plane(&m, &embree, &frame, f32::NAN, 0.5).unwrap_err();
    assert!(e.to_string().starts_with("--grid expects"), "{e}");

    // A lone wall: nothing faces up.
    let mut wall = scene("", vec![material("white", 0.5, 0.0)]);
    polygon_facing(
        &mut wall,
        &[
            vec3(0.0, 0.0, 0.0),
            vec3(4.0, 0.0, 0.0),
            vec3(4.0, 3.0, 0.0),
            vec3(0.0, 3.0, 0.0),
        ],
        Vec3::Z,
        0,
    );
    let m = mesh(&wall, false);
    let embree = EmbreeScene::build(&m, |_| true).unwrap();
    let spec: GridSpec = "0.8,0.5".parse().unwrap();
    let e = spec.sensors(&m, &embree, &frame).unwrap_err();
    assert!(matches!(e, GridError::NoFloor { .. }), "{e}");
}
