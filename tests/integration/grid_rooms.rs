//! The work plane on buildings: outdoor sensors (nothing over them) left out by default and
//! kept with `--grid-outdoor keep`, storeys split by height, rooms told apart by the walls
//! between them (a door joins no two rooms), each with its figures in `grid.csv` and the
//! summary. The expected sensors follow by hand from the lattice (1 m, half a metre in from
//! the plan bounds) and the walls.

use glam::{vec3, Vec3};
use radiosity::grid::{GridSpec, Outdoor, Placed};
use radiosity::intersect::embree::EmbreeScene;
use radiosity::scene::{Material, Scene};
use radiosity::sky::Compass;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::scene_builder::*;

const GROUND: u32 = 0;
const WALL: u32 = 1;
const GLASS: u32 = 2;

/// Ground (ρ 0.2), walls (ρ 0.5) and glazing (T 0.7).
fn materials() -> Vec<Material> {
    vec![
        material("ground", 0.2, 0.0),
        material("wall", 0.5, 0.0),
        Material {
            name: "glass".into(),
            transmittance: 0.7,
            ..Material::default()
        },
    ]
}

/// Adds the level quad [x0, x1] × [z0, z1] at height `y`, facing up (+Y) or down.
fn level(s: &mut Scene, x: (f32, f32), z: (f32, f32), y: f32, up: bool, m: u32) {
    let pts = [
        vec3(x.0, y, z.0),
        vec3(x.1, y, z.0),
        vec3(x.1, y, z.1),
        vec3(x.0, y, z.1),
    ];
    polygon_facing(s, &pts, if up { Vec3::Y } else { Vec3::NEG_Y }, m);
}

/// One storey of the house, [0, 8] × [0, 6] in plan, its floor at `y0`, 2.7 m to its ceiling:
/// walls 0.2 m thick as blocks; a window 2 m wide (sill 0.9 m, head 2.0 m) in the south wall
/// (+Z; north is −Z) of each half; an interior wall at x = 4 with a door 1.6 m wide and 2.1 m
/// high, through which the lattice rows z = 2.5 and 3.5 pass.
fn storey(s: &mut Scene, y0: f32) {
    let b = |s: &mut Scene, lo: [f32; 3], hi: [f32; 3]| {
        block(
            s,
            vec3(lo[0], y0 + lo[1], lo[2]),
            vec3(hi[0], y0 + hi[1], hi[2]),
            WALL,
        )
    };
    b(s, [0.0, 0.0, 0.0], [8.0, 2.7, 0.2]); // north wall
    b(s, [0.0, 0.0, 0.2], [0.2, 2.7, 5.8]); // west
    b(s, [7.8, 0.0, 0.2], [8.0, 2.7, 5.8]); // east
                                            // South wall round the two windows (x 1–3 and 5–7).
    b(s, [0.0, 0.0, 5.8], [8.0, 0.9, 6.0]);
    b(s, [0.0, 2.0, 5.8], [8.0, 2.7, 6.0]);
    for (x0, x1) in [(0.0, 1.0), (3.0, 5.0), (7.0, 8.0)] {
        b(s, [x0, 0.9, 5.8], [x1, 2.0, 6.0]);
    }
    // The interior wall and its door (z 2.2–3.8).
    b(s, [3.9, 0.0, 0.2], [4.1, 2.7, 2.2]);
    b(s, [3.9, 0.0, 3.8], [4.1, 2.7, 5.8]);
    b(s, [3.9, 2.1, 2.2], [4.1, 2.7, 3.8]);
}

/// A one-storey house on a garden: the ground [−6, 14] × [−6, 12] (also the rooms' floor),
/// the storey, a flat roof slab 0.2 m thick overhanging the walls by 0.2 m.
fn house() -> Scene {
    let mut s = scene("house", materials());
    level(&mut s, (-6.0, 14.0), (-6.0, 12.0), 0.0, true, GROUND);
    storey(&mut s, 0.0);
    block(&mut s, vec3(-0.2, 2.7, -0.2), vec3(8.2, 2.9, 6.2), WALL);
    s
}

/// The house with two storeys (no garden): the ground floor, a slab 0.2 m thick, the upper
/// storey on it, the roof; the floors are the ground's plan only.
fn two_storeys() -> Scene {
    let mut s = scene("two-storeys", materials());
    level(&mut s, (0.0, 8.0), (0.0, 6.0), 0.0, true, GROUND);
    storey(&mut s, 0.0);
    block(&mut s, vec3(0.0, 2.7, 0.0), vec3(8.0, 2.9, 6.0), WALL);
    storey(&mut s, 2.9);
    block(&mut s, vec3(0.0, 5.6, 0.0), vec3(8.0, 5.8, 6.0), WALL);
    s
}

/// Writes `s` as `NAME.obj` and `NAME.mtl` in `dir`.
fn write_obj(s: &Scene, dir: &Path) -> PathBuf {
    let (obj, mtl) = (
        dir.join(format!("{}.obj", s.name)),
        format!("{}.mtl", s.name),
    );
    let mut o = format!("mtllib {mtl}\n");
    for p in &s.positions {
        writeln!(o, "v {} {} {}", p.x, p.y, p.z).unwrap();
    }
    for p in &s.polygons {
        writeln!(o, "usemtl {}", s.materials[p.material as usize].name).unwrap();
        let idx = &s.indices[p.first as usize..(p.first + p.len) as usize];
        let v: Vec<String> = idx.iter().map(|i| (i + 1).to_string()).collect();
        writeln!(o, "f {}", v.join(" ")).unwrap();
    }
    let mut m = String::new();
    for mat in &s.materials {
        writeln!(
            m,
            "newmtl {}\nKd {} {} {}",
            mat.name, mat.rho[0], mat.rho[1], mat.rho[2]
        )
        .unwrap();
        if mat.transmittance > 0.0 {
            let t = mat.transmittance;
            writeln!(m, "Tf {t} {t} {t}").unwrap();
        }
    }
    std::fs::write(&obj, o).unwrap();
    std::fs::write(dir.join(mtl), m).unwrap();
    obj
}

/// `grid.csv`'s rows as numbers, after checking its header.
fn rows(out: &Path) -> Vec<Vec<f64>> {
    let csv = std::fs::read_to_string(out.join("grid.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some("x,y,z,nx,ny,nz,lux,df,storey,room,indoor")
    );
    lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect()
}

/// Solves `obj` under the overcast sky with a 0.8 m, 1 m grid and `extra` flags: (the log
/// printed, `grid.csv`'s rows, the summary's `grid`).
fn solve(obj: &Path, out: &Path, extra: &[&str]) -> (String, Vec<Vec<f64>>, serde_json::Value) {
    let mut args = vec![
        "solve",
        obj.to_str().unwrap(),
        "--sky",
        "overcast",
        "--patch-size",
        "1",
        "--elements",
        "off",
        "--grid",
        "0.8,1",
        "--grid-rays",
        "256",
        "--width",
        "32",
        "--height",
        "24",
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let (code, stdout, stderr) = crate::common::run(&args);
    assert_eq!(code, 0, "{stderr}");
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    (stdout + &stderr, rows(out), s["grid"].clone())
}

fn inside_house(r: &[f64]) -> bool {
    r[0] > 0.0 && r[0] < 8.0 && r[2] > 0.0 && r[2] < 6.0
}

#[test]
fn grid_house_with_a_garden_measures_its_two_rooms_only() {
    let dir = tempfile::tempdir().unwrap();
    let obj = write_obj(&house(), dir.path());
    let (log, rows, g) = solve(&obj, &dir.path().join("o"), &[]);
    // 4 × 6 sensors in each room (x 0.5–3.5 and 4.5–7.5, z 0.5–5.5), none in the garden or on
    // the roof.
    assert_eq!(rows.len(), 48, "{rows:?}");
    for r in &rows {
        assert!(
            inside_house(r) && (r[1] - 0.8).abs() < 1e-4,
            "outside: {r:?}"
        );
        // Storey 0; room 1 west of the wall (its first sensor, in the north-west corner,
        // comes first), room 2 east; indoors.
        let room = if r[0] < 4.0 { 1.0 } else { 2.0 };
        assert_eq!(r[8..], [0.0, room, 1.0], "{r:?}");
        assert!(r[6] > 0.0, "{r:?}");
    }
    // The garden's 20 × 18 lattice less the house's 48 columns, and the roof's 48: outdoors.
    assert_eq!(g["outdoor"], "drop");
    assert_eq!(g["outdoor_points"], 312 + 48);
    assert_eq!(g["dropped_points"], 312 + 48);
    assert_eq!(g["points"], 48);
    assert_eq!(g["area"], 48.0);
    let storeys = g["storeys"].as_array().unwrap();
    assert_eq!(storeys.len(), 1);
    assert_eq!(storeys[0]["rooms"], 2);
    let rooms = g["rooms"].as_array().unwrap();
    assert_eq!(rooms.len(), 2, "{g}");
    for (k, room) in rooms.iter().enumerate() {
        assert_eq!(
            (room["storey"].as_u64(), room["room"].as_u64()),
            (Some(0), Some(k as u64 + 1))
        );
        assert_eq!(
            (room["points"].as_u64(), room["area"].as_f64()),
            (Some(24), Some(24.0))
        );
        // The room's figures are its sensors'.
        let own: Vec<f64> = rows
            .iter()
            .filter(|r| r[9] == k as f64 + 1.0)
            .map(|r| r[6])
            .collect();
        let mean = own.iter().sum::<f64>() / own.len() as f64;
        let min = own.iter().copied().fold(f64::INFINITY, f64::min);
        let close = |key: &str, want: f64| {
            let got = room[key].as_f64().unwrap();
            assert!(
                (got - want).abs() <= 1e-9 * want.abs().max(1.0),
                "{key} {got} vs {want}"
            );
        };
        close("mean_lux", mean);
        close("min_lux", min);
        close("uniformity", min / mean);
        assert!(room["mean_df"].as_f64().unwrap() > 0.0 && room["max_lux"].as_f64() >= Some(mean));
    }
    // Daylit through its window, well below the open garden's 100 %.
    let df = g["mean_df"].as_f64().unwrap();
    assert!(df > 0.1 && df < 30.0, "mean daylight factor {df} %");
    assert!(
        log.contains("room 0.1: 24 sensors") && log.contains("room 0.2: 24 sensors"),
        "{log}"
    );
    assert!(log.contains("360 outdoor sensors left out"), "{log}");
}

#[test]
fn grid_outdoor_keep_keeps_the_garden_and_marks_it() {
    let dir = tempfile::tempdir().unwrap();
    let obj = write_obj(&house(), dir.path());
    let (_, rows, g) = solve(&obj, &dir.path().join("o"), &["--grid-outdoor", "keep"]);
    // Every column of the 20 × 18 lattice has the ground or the roof.
    assert_eq!(rows.len(), 360 + 48);
    for r in &rows {
        let on_roof = (r[1] - 3.7).abs() < 1e-4;
        let indoor = inside_house(r) && !on_roof;
        assert_eq!(r[10], indoor as u8 as f64, "{r:?}");
        assert_eq!(
            r[8], on_roof as u8 as f64,
            "the roof is a storey of its own: {r:?}"
        );
        if !indoor {
            assert_eq!(r[9], 0.0, "no room outdoors: {r:?}");
        }
    }
    assert_eq!(g["outdoor"], "keep");
    assert_eq!(
        (g["outdoor_points"].as_u64(), g["dropped_points"].as_u64()),
        (Some(360), Some(0))
    );
    assert_eq!(g["points"], 408);
    assert_eq!(g["rooms"].as_array().unwrap().len(), 2);
    assert_eq!(g["storeys"].as_array().unwrap().len(), 2);
    // The garden is brighter than the rooms: the grid's mean is mostly outdoors.
    let rooms_df: f64 = g["rooms"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["mean_df"].as_f64().unwrap())
        .sum::<f64>()
        / 2.0;
    assert!(g["mean_df"].as_f64().unwrap() > 2.0 * rooms_df, "{g}");
}

/// The work plane of `s` placed with Embree (Y up, north −Z), `rule` for the outdoor sensors.
fn placed(s: &Scene, rule: Outdoor) -> Placed {
    let m = mesh_at(s, Some(1.0));
    let embree = EmbreeScene::build(&m, |_| true).unwrap();
    let spec: GridSpec = "0.8,1".parse().unwrap();
    spec.place(&m, &embree, &Compass::default(), rule).unwrap()
}

#[test]
fn grid_two_storeys_split_with_their_own_rooms() {
    let dir = tempfile::tempdir().unwrap();
    let obj = write_obj(&two_storeys(), dir.path());
    let (log, rows, g) = solve(&obj, &dir.path().join("o"), &[]);
    // 48 sensors a storey (the roof's are outdoors and left out).
    assert_eq!(rows.len(), 96);
    for r in &rows {
        let upper = r[1] > 2.0;
        assert!((r[1] - if upper { 3.7 } else { 0.8 }).abs() < 1e-4, "{r:?}");
        let room = if r[0] < 4.0 { 1.0 } else { 2.0 };
        assert_eq!(r[8..], [upper as u8 as f64, room, 1.0], "{r:?}");
    }
    let storeys = g["storeys"].as_array().unwrap();
    assert_eq!(storeys.len(), 2, "{g}");
    for (k, s) in storeys.iter().enumerate() {
        assert_eq!(
            (
                s["storey"].as_u64(),
                s["rooms"].as_u64(),
                s["points"].as_u64()
            ),
            (Some(k as u64), Some(2), Some(48))
        );
        let h = s["height"].as_f64().unwrap();
        assert!((h - [0.8, 3.7][k]).abs() < 1e-4, "{s}");
    }
    assert_eq!(g["rooms"].as_array().unwrap().len(), 4);
    assert_eq!(g["dropped_points"], 48);
    assert!(
        log.contains("storey 1 (+3.7 m): 48 sensors") && log.contains("room 1.2: 24 sensors"),
        "{log}"
    );
}

#[test]
fn grid_glazing_overhead_is_indoors_and_a_roofless_model_keeps_its_sensors() {
    // The house with its roof slab replaced by a pane: a conservatory, indoors (the pane's
    // top, glazing being two-sided, is a floor open to the sky: its 48 sensors are outdoors).
    let mut s = scene("glass-roof", materials());
    level(&mut s, (0.0, 8.0), (0.0, 6.0), 0.0, true, GROUND);
    storey(&mut s, 0.0);
    level(&mut s, (0.0, 8.0), (0.0, 6.0), 2.7, false, GLASS);
    let p = placed(&s, Outdoor::Drop);
    assert_eq!(p.sensors.len(), 48);
    for (sensor, z) in p.sensors.iter().zip(&p.zones) {
        let room = if sensor.position.x < 4.0 { 1 } else { 2 };
        assert!(
            z.indoor && z.storey == 0 && z.room == room,
            "{sensor:?} {z:?}"
        );
    }
    assert_eq!(
        (p.outdoor_points, p.dropped_points, &p.warning),
        (48, 48, &None)
    );
    // Without any roof every sensor is outdoors: all kept, with one line of warning, no rooms.
    let mut s = scene("roofless", materials());
    level(&mut s, (0.0, 8.0), (0.0, 6.0), 0.0, true, GROUND);
    storey(&mut s, 0.0);
    let p = placed(&s, Outdoor::Drop);
    assert_eq!(
        (p.sensors.len(), p.outdoor_points, p.dropped_points),
        (48, 48, 0)
    );
    assert!(p.zones.iter().all(|z| !z.indoor && z.room == 0));
    let w = p.warning.expect("a warning");
    assert!(
        w.contains("--grid-outdoor keep") && !w.contains('\n'),
        "{w}"
    );
    // Asked to keep them, nothing to warn of.
    assert_eq!(placed(&s, Outdoor::Keep).warning, None);
}

#[test]
fn grid_a_crack_in_the_roof_over_a_row_of_sensors_leaves_them_indoors() {
    // The house's roof in two slabs with a 2 cm gap along x = 1.5, right over the column of
    // sensors there: their zenith rays escape through it, the tilted ones do not.
    let mut s = scene("cracked", materials());
    level(&mut s, (0.0, 8.0), (0.0, 6.0), 0.0, true, GROUND);
    storey(&mut s, 0.0);
    block(&mut s, vec3(0.0, 2.7, 0.0), vec3(1.49, 2.9, 6.0), WALL);
    block(&mut s, vec3(1.51, 2.7, 0.0), vec3(8.0, 2.9, 6.0), WALL);
    let p = placed(&s, Outdoor::Keep);
    let under: Vec<_> = p
        .sensors
        .iter()
        .zip(&p.zones)
        .filter(|(s, _)| (s.position.x - 1.5).abs() < 1e-4 && s.position.y < 1.0)
        .collect();
    assert_eq!(under.len(), 6);
    assert!(
        under.iter().all(|(_, z)| z.indoor && z.room == 1),
        "{under:?}"
    );
    // Only the roof's sensors are outdoors (none over the crack): no sensor of the rooms is
    // lost.
    assert_eq!(p.outdoor_points, 48 - 6);
    assert_eq!(p.zones.iter().filter(|z| z.indoor).count(), 48);
}
