//! Models as exporters leave them, solved with no flag: furniture standing on whole floors
//! (contacts), walls built as overlapping boxes (buried, hidden faces), and faces wound either
//! way (back patches made for the faces lit from behind). Each scene is written as an OBJ and
//! solved by the binary, as a user would.

use super::common::run;
use super::scene_builder::{block, closed_box, material, mesh_at, quad, scene};
use glam::{vec3, Vec3};
use radiosity::mesh::Mesh;
use std::fmt::Write as _;
use std::path::Path;

/// An OBJ of quads (each counter-clockwise seen from its front) with their materials, and the
/// MTL of `(name, Kd, Ke)`.
fn write_obj(dir: &Path, name: &str, quads: &[([Vec3; 4], &str)], mtl: &[(&str, f64, f64)]) {
    let mut m = String::new();
    for (n, kd, ke) in mtl {
        writeln!(m, "newmtl {n}\nKd {kd} {kd} {kd}\nKe {ke} {ke} {ke}\n").unwrap();
    }
    std::fs::write(dir.join(format!("{name}.mtl")), m).unwrap();
    let mut o = format!("mtllib {name}.mtl\n");
    for (k, (q, mat)) in quads.iter().enumerate() {
        writeln!(o, "usemtl {mat}").unwrap();
        for v in q {
            writeln!(o, "v {} {} {}", v.x, v.y, v.z).unwrap();
        }
        let b = 4 * k + 1;
        writeln!(o, "f {} {} {} {}", b, b + 1, b + 2, b + 3).unwrap();
    }
    std::fs::write(dir.join(format!("{name}.obj")), o).unwrap();
}

/// The six outward faces of the box [lo, hi] (as the scene builder's `block`).
fn box_faces(lo: Vec3, hi: Vec3) -> Vec<[Vec3; 4]> {
    let mut s = scene("b", vec![material("m", 0.5, 0.0)]);
    block(&mut s, lo, hi, 0);
    (0..6)
        .map(|k| std::array::from_fn(|j| s.positions[s.indices[4 * k + j] as usize]))
        .collect()
}

/// The inward faces of a room [0, w]×[0, h]×[0, d] (the scene builder's closed box), and a
/// light panel 1 m² facing down just under the ceiling's middle.
fn room(w: f32, h: f32, d: f32) -> (Vec<[Vec3; 4]>, [Vec3; 4]) {
    let s = closed_box(w, h, d, material("m", 0.5, 0.0));
    let faces = (0..6)
        .map(|k| std::array::from_fn(|j| s.positions[s.indices[4 * k + j] as usize]))
        .collect();
    let (cx, cz, y) = (w / 2.0, d / 2.0, h - 0.01);
    let light = [
        vec3(cx - 0.5, y, cz - 0.5),
        vec3(cx + 0.5, y, cz - 0.5),
        vec3(cx + 0.5, y, cz + 0.5),
        vec3(cx - 0.5, y, cz + 0.5),
    ];
    (faces, light)
}

fn flipped(q: [Vec3; 4]) -> [Vec3; 4] {
    [q[3], q[2], q[1], q[0]]
}

const MTL: &[(&str, f64, f64)] = &[("wall", 0.6, 0.0), ("solid", 0.5, 0.0), ("lamp", 0.0, 10.0)];

/// Solves `dir/name.obj` with `flags` into `dir/name-out`; returns (summary, rows of
/// patches.csv as (centre, normal, area, scalar B)).
fn solve(dir: &Path, name: &str, flags: &[&str]) -> (serde_json::Value, Vec<Row>) {
    let obj = dir.join(format!("{name}.obj"));
    let out = dir.join(format!("{name}-out{}", flags.join("")));
    let (o, s) = (obj.to_str().unwrap(), out.to_str().unwrap());
    let mut args = vec!["solve", o, "--out", s, "--quiet", "--elements", "off"];
    args.extend_from_slice(flags);
    let (code, _, err) = run(&args);
    assert_eq!(code, 0, "{err}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let csv = std::fs::read_to_string(out.join("patches.csv")).unwrap();
    let rows = csv
        .lines()
        .skip(1)
        .map(|l| {
            let f: Vec<f64> = l.split(',').map(|x| x.parse().unwrap_or(0.0)).collect();
            Row {
                centre: vec3(f[1] as f32, f[2] as f32, f[3] as f32),
                normal: vec3(f[4] as f32, f[5] as f32, f[6] as f32),
                area: f[7],
                b: (f[14] + f[15] + f[16]) / 3.0,
            }
        })
        .collect();
    (summary, rows)
}

struct Row {
    centre: Vec3,
    normal: Vec3,
    area: f64,
    b: f64,
}

/// Area-weighted mean B of the rows `keep` selects.
fn mean_b(rows: &[Row], keep: impl Fn(&Row) -> bool) -> f64 {
    let (s, a) = rows
        .iter()
        .filter(|r| keep(r))
        .fold((0.0, 0.0), |(s, a), r| (s + r.b * r.area, a + r.area));
    s / a
}

/// Floor patches facing up inside the room's floor area.
fn on_floor(r: &Row) -> bool {
    r.centre.y.abs() < 1e-4 && r.normal.y > 0.9
}

/// A floor 2 × 2 facing up, a box 0.5 × 0.2 × 0.5 standing on it (bottom facing down, on the
/// floor).
fn box_on_a_floor() -> radiosity::scene::Scene {
    let mut s = scene("contact", vec![material("m", 0.5, 0.0)]);
    quad(
        &mut s,
        [
            vec3(0., 0., 0.),
            vec3(0., 0., 2.),
            vec3(2., 0., 2.),
            vec3(2., 0., 0.),
        ],
        0,
    );
    block(&mut s, vec3(0.2, 0.0, 0.2), vec3(0.7, 0.2, 0.7), 0);
    s
}

/// The patch at height 0 facing up (the floor) or down (the box's bottom).
fn level_face(mesh: &Mesh, up: bool) -> usize {
    (0..mesh.patches.len())
        .find(|&i| (mesh.patches[i].normal.y > 0.9) == up && mesh.patches[i].centre.y.abs() < 1e-6)
        .unwrap()
}

#[test]
fn a_face_lying_on_another_covers_it_and_only_where_it_lies() {
    // The box on the floor, and a second box floating 1 cm above the floor (no contact).
    let mut s = box_on_a_floor();
    block(&mut s, vec3(1.2, 0.01, 1.2), vec3(1.7, 0.2, 1.7), 0);
    let mesh: Mesh = mesh_at(&s, Some(4.0));
    let c = mesh.find_contacts();
    let floor = level_face(&mesh, true);
    assert!(c.covers(floor, vec3(0.45, 0.0, 0.45)));
    assert!(!c.covers(floor, vec3(0.9, 0.0, 0.45)), "beside the box");
    assert!(
        !c.covers(floor, vec3(1.45, 0.0, 1.45)),
        "under the floating box"
    );
    // The box's bottom is covered by the floor, and only the two faces are in contact.
    let bottom = level_face(&mesh, false);
    assert!(c.covers(bottom, vec3(0.45, 0.0, 0.45)));
    assert_eq!(c.len(), 2);
}

/// The back of a one-sided face is probed when first asked (`Hidden::back_of`), not by
/// `find`: a box standing on a floor has its bottom's back (inside the box) hidden and the
/// floor's back (under the model, open) not, whichever is asked first and on whichever thread;
/// a clone keeps what was found, and a back never asked is never probed.
#[test]
fn the_backs_of_one_sided_faces_are_probed_when_first_asked() {
    use radiosity::intersect::embree::EmbreeScene;
    use radiosity::intersect::hidden::{back_enclosed, find};
    let mut mesh: Mesh = mesh_at(&box_on_a_floor(), Some(4.0));
    mesh.contacts = mesh.find_contacts();
    let isect = EmbreeScene::build(&mesh, |_| true).unwrap();
    let open = vec![false; mesh.patches.len()];
    mesh.hidden = find(&mesh, &isect, &open, 1);
    let (floor, bottom) = (level_face(&mesh, true), level_face(&mesh, false));
    let probes = std::sync::atomic::AtomicUsize::new(0);
    let ask = |m: &Mesh, j: usize| {
        m.hidden.back_of(j, || {
            probes.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            back_enclosed(m, &isect, j)
        })
    };
    let copy = mesh.clone();
    assert!(ask(&mesh, bottom), "the box's bottom faces into the box");
    assert!(!ask(&mesh, floor), "the floor's back is under the model");
    assert_eq!(probes.load(std::sync::atomic::Ordering::Relaxed), 2);
    // Asked again: what was found, no probe.
    assert!(ask(&mesh, bottom) && !ask(&mesh, floor));
    assert_eq!(probes.load(std::sync::atomic::Ordering::Relaxed), 2);
    // The copy made before, asked in the other order from two threads: the same answers.
    let (f, b) = rayon::join(|| ask(&copy, floor), || ask(&copy, bottom));
    assert!(!f && b);
    assert_eq!(probes.load(std::sync::atomic::Ordering::Relaxed), 4);
    // A clone made after keeps what was found.
    let later = mesh.clone();
    assert!(ask(&later, bottom) && !ask(&later, floor));
    assert_eq!(probes.load(std::sync::atomic::Ordering::Relaxed), 4);
}

/// A room 4 × 2.5 × 4 with a wall across it built as two overlapping boxes (the overlap's faces
/// are buried) against the same wall as one box: the buried faces are reported hidden and are
/// black, the gather casts no rays for them, and the faces one can see come out the same.
#[test]
fn buried_faces_are_hidden_cost_no_gather_rays_and_change_nothing_visible() {
    let t = tempfile::tempdir().unwrap();
    let (shell, light) = room(4.0, 2.5, 4.0);
    let mut base: Vec<([Vec3; 4], &str)> = shell.iter().map(|q| (*q, "wall")).collect();
    base.push((light, "lamp"));
    let mut one = base.clone();
    for q in box_faces(vec3(1.0, 0.0, 1.8), vec3(3.0, 1.5, 2.2)) {
        one.push((q, "solid"));
    }
    let mut two = base.clone();
    for q in box_faces(vec3(1.0, 0.0, 1.8), vec3(2.2, 1.5, 2.2))
        .into_iter()
        .chain(box_faces(vec3(1.8, 0.0, 1.8), vec3(3.0, 1.5, 2.2)))
    {
        two.push((q, "solid"));
    }
    write_obj(t.path(), "one", &one, MTL);
    write_obj(t.path(), "two", &two, MTL);
    let flags = ["--patch-size", "0.25", "--error", "off"];
    let (s1, r1) = solve(t.path(), "one", &flags);
    let (s2, r2) = solve(t.path(), "two", &flags);
    let hidden = s2["hidden"]["patches"].as_u64().unwrap();
    // The overlap's faces: the two end faces inside the other box (0.4 × 1.5 m each) and the
    // parts of the top and bottom and sides inside the other box (the bottom faces lie on the
    // floor: covered).
    assert!(hidden > 0, "{}", s2["hidden"]);
    let area = s2["hidden"]["area_m2"].as_f64().unwrap();
    assert!(area >= 2.0 * 0.4 * 1.5 - 1e-6, "hidden area {area}");
    // What the final gather cast rays for: every reflecting patch but the hidden ones.
    let gathered = |s: &serde_json::Value| s["final_gather"]["patches"].as_u64().unwrap();
    let reflecting = |rows: &[Row], s: &serde_json::Value| {
        rows.len() as u64 - s["lights"].as_array().map_or(0, |l| l.len() as u64)
    };
    assert!(gathered(&s2) <= reflecting(&r2, &s2) - hidden + 1);
    // The black-patch count leaves the hidden ones out.
    assert!(s2["final_gather"]["black_after"].as_u64().unwrap() < hidden);
    // The room's walls and floor, seen from inside, come out the same either way.
    let shell_b = |rows: &[Row]| {
        mean_b(rows, |r| {
            let p = r.centre;
            p.x.abs() < 1e-4 || (p.x - 4.0).abs() < 1e-4 || (p.z - 4.0).abs() < 1e-4
        })
    };
    let (a, b) = (shell_b(&r1), shell_b(&r2));
    assert!((a - b).abs() < 0.02 * a, "walls {a} against {b}");
    let (a, b) = (mean_b(&r1, on_floor), mean_b(&r2, on_floor));
    assert!((a - b).abs() < 0.03 * a, "floor {a} against {b}");
    assert!(s1["hidden"]["patches"].as_u64().unwrap() < hidden);
}

/// A room with half its walls wound the wrong way round, and a room wound inside out: a plain
/// solve lights them as the correctly wound room, losing under 1 % more of the light on backs;
/// `--one-sided` keeps the old behaviour (the light lost there).
#[test]
fn faces_wound_either_way_need_no_flag() {
    let t = tempfile::tempdir().unwrap();
    let (shell, light) = room(3.0, 2.5, 3.0);
    let mut desk = box_faces(vec3(1.0, 0.0, 1.0), vec3(2.0, 0.75, 1.6));
    desk.remove(0); // standing on the floor, no bottom
    let build = |flip: &dyn Fn(usize) -> bool| {
        let mut q: Vec<([Vec3; 4], &str)> = shell
            .iter()
            .enumerate()
            .map(|(k, f)| (if flip(k) { flipped(*f) } else { *f }, "wall"))
            .collect();
        q.extend(desk.iter().map(|f| (*f, "solid")));
        q.push((light, "lamp"));
        q
    };
    write_obj(t.path(), "right", &build(&|_| false), MTL);
    write_obj(t.path(), "mixed", &build(&|k| k % 2 == 1), MTL);
    write_obj(t.path(), "inside-out", &build(&|_| true), MTL);
    let flags = ["--patch-size", "0.3", "--error", "off"];
    let (sr, rr) = solve(t.path(), "right", &flags);
    assert!(sr.get("lit_backs").is_none() || sr["lit_backs"]["polygons"] == 0);
    let right = mean_b(&rr, on_floor);
    let back = |s: &serde_json::Value| s["energy"]["back_fraction"].as_f64().unwrap();
    for name in ["mixed", "inside-out"] {
        let (s, rows) = solve(t.path(), name, &flags);
        // Beyond what the right room loses on the lamp's back (a light is one-sided).
        assert!(back(&s) < back(&sr) + 0.01, "{name}: {}", s["energy"]);
        assert!(s["lit_backs"]["polygons"].as_u64().unwrap() >= 3, "{name}");
        assert_eq!(s["warnings"], sr["warnings"], "{name}");
        // The floor's light, on whichever side the room sees (the back patch of a flipped
        // floor has its normal up too).
        let floor = mean_b(&rows, on_floor);
        assert!(
            (floor - right).abs() < 0.04 * right,
            "{name}: {floor} against {right}"
        );
        let (s1, _) = solve(
            t.path(),
            name,
            &["--patch-size", "0.3", "--error", "off", "--one-sided"],
        );
        assert!(back(&s1) > 0.1, "{name} --one-sided: {}", s1["energy"]);
        assert!(s1.get("lit_backs").is_none());
    }
}
