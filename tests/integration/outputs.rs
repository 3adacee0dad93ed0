//! The outputs as a user meets them: `solve --save` → `render` / `export`, the files
//! read back with their crates' readers, and bad solution files refused with one line and exit
//! code 2, leaving no output behind.

use crate::common::{assert_user_error, run};
use radiosity::export::solution::{SavedSolution, FORMAT_VERSION};
use radiosity::render::false_colour::{BACKGROUND, LEGEND_WIDTH};
use std::path::{Path, PathBuf};

fn ok(args: &[&str]) -> String {
    let (code, out, err) = run(args);
    assert_eq!(code, 0, "{args:?}: {err}");
    out
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Solves the built-in Cornell box once into `dir`, returning the solution's path.
fn solve_default(dir: &Path) -> PathBuf {
    let sol = dir.join("cornell.rad");
    ok(&[
        "solve",
        "--out",
        s(&dir.join("out")),
        "--save",
        s(&sol),
        "--quiet",
    ]);
    sol
}

/// A furnace: the inside of a unit cube (faces wound to look in), one material with
/// ρ = 0.5 and Ke = 1, so every patch has B = E/(1 − ρ) = 2π W/m² exactly.
const FURNACE_OBJ: &str = "mtllib f.mtl\n\
v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
usemtl glow\n\
f 1 5 6 2\nf 4 3 7 8\nf 1 2 3 4\nf 5 8 7 6\nf 1 4 8 5\nf 2 6 7 3\n";
const FURNACE_MTL: &str = "newmtl glow\nKd 0.5 0.5 0.5\nKe 1 1 1\n";
const FURNACE_B: f32 = 2.0 * std::f32::consts::PI;
/// What `.hdr` and `.exr` pixels hold: radiance L = B/π (W/sr/m²), as Radiance's `rpict`.
const FURNACE_L: f32 = FURNACE_B / std::f32::consts::PI;

fn furnace(dir: &Path) -> PathBuf {
    std::fs::write(dir.join("f.mtl"), FURNACE_MTL).unwrap();
    let obj = dir.join("furnace.obj");
    std::fs::write(&obj, FURNACE_OBJ).unwrap();
    obj
}

/// Renders from the cube's centre towards a wall, which fills the view: the Gouraud picture,
/// exact for an exact solution (the gathered one is checked in tests/gather_render.rs).
fn render_inside(sol: &Path, out: &Path) {
    ok(&[
        "render",
        s(sol),
        "--out",
        s(out),
        "--shading",
        "gouraud",
        "--eye",
        "0.5,0.5,0.5",
        "--target",
        "0.5,0.5,0",
        "--fov",
        "60",
        "--width",
        "64",
        "--height",
        "48",
        "--quiet",
    ]);
}

#[test]
fn saved_solution_round_trips_and_matches_the_patch_table() {
    let dir = tempfile::tempdir().unwrap();
    let sol_path = solve_default(dir.path());
    let sol = SavedSolution::load(&sol_path).unwrap();
    // Save → load → save gives the same bytes; load gives the same solution.
    let mut again = Vec::new();
    sol.write(&mut again).unwrap();
    let first = std::fs::read(&sol_path).unwrap();
    let differ = again
        .iter()
        .zip(&first)
        .skip(32)
        .position(|(a, b)| a != b)
        .map(|k| k + 32);
    assert!(
        again.len() == first.len() && differ.is_none(),
        "save → load → save differs at byte {differ:?} (lengths {} and {})",
        again.len(),
        first.len()
    );
    assert_eq!(SavedSolution::from_bytes(&sol_path, &again).unwrap(), sol);
    // The radiosity is the solve's, to the last bit (the CSV prints shortest round-trip f64).
    let csv = std::fs::File::open(dir.path().join("out/patches.csv")).unwrap();
    let rows = radiosity::export::patches::read(std::io::BufReader::new(csv)).unwrap();
    assert_eq!(rows.len(), sol.b.len());
    for (row, b) in rows.iter().zip(&sol.b) {
        assert_eq!(row.b(), *b);
    }
    assert_eq!(sol.meta.scene, "cornell-box");
    assert_eq!(sol.meta.method, "adaptive-hybrid");
    assert!(sol.channels.is_empty());
    let summary = std::fs::read_to_string(dir.path().join("out/summary.json")).unwrap();
    assert!(
        summary.contains("cornell.rad"),
        "the summary lists the saved file"
    );
}

#[test]
fn bad_solution_files_are_refused_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let good = std::fs::read(solve_default(dir.path())).unwrap();
    let out = dir.path().join("x.png");
    let check = |name: &str, bytes: &[u8], needles: &[&str]| {
        let p = dir.path().join(name);
        std::fs::write(&p, bytes).unwrap();
        assert_user_error(&["render", s(&p), "--out", s(&out)], needles);
        assert_user_error(
            &["export", s(&p), "--out", s(&dir.path().join("x.ply"))],
            needles,
        );
        assert!(!out.exists() && !dir.path().join("x.ply").exists());
    };
    check(
        "cut.rad",
        &good[..good.len() / 2],
        &["cut.rad", "truncated"],
    );
    check("head.rad", &good[..20], &["head.rad", "truncated"]);
    check(
        "text.rad",
        b"v 0 0 0\nv 1 0 0\n",
        &["text.rad", "not a radiosity solution"],
    );
    let mut newer = good.clone();
    newer[8..12].copy_from_slice(&(FORMAT_VERSION + 1).to_le_bytes());
    check("newer.rad", &newer, &["newer.rad", "newer"]);
    let mut flipped = good.clone();
    let k = flipped.len() - 7;
    flipped[k] ^= 0xff;
    check("flip.rad", &flipped, &["flip.rad", "damaged"]);
    assert_user_error(
        &["render", s(&dir.path().join("none.rad")), "--out", s(&out)],
        &["none.rad", "cannot read"],
    );
    // Another scene: the solution of the Cornell box checked against the furnace.
    let obj = furnace(dir.path());
    let p = dir.path().join("good.rad");
    std::fs::write(&p, &good).unwrap();
    assert_user_error(
        &["render", s(&p), "--out", s(&out), "--scene", s(&obj)],
        &["good.rad", "another scene"],
    );
    assert!(!out.exists());
    // Formats come from the extension.
    assert_user_error(
        &["render", s(&p), "--out", "x.jpg"],
        &[".png, .hdr or .exr"],
    );
    assert_user_error(&["export", s(&p), "--out", "x.obj"], &[".ply or .glb"]);
    assert_user_error(
        &["render", s(&p), "--out", "x.exr", "--false-colour"],
        &["--false-colour"],
    );
}

#[test]
fn a_uniformly_lit_closed_box_renders_flat_at_e_over_one_minus_rho() {
    let dir = tempfile::tempdir().unwrap();
    let obj = furnace(dir.path());
    let sol = dir.path().join("f.rad");
    // The solution is checked against its own scene, and accepted.
    ok(&[
        "solve",
        s(&obj),
        "--out",
        s(&dir.path().join("o")),
        "--save",
        s(&sol),
        "--patch-size",
        "0.1",
        "--tolerance",
        "0.02",
        "--quiet",
    ]);
    for ext in ["exr", "hdr"] {
        let out = dir.path().join(format!("f.{ext}"));
        render_inside(&sol, &out);
        let img = image::open(&out).unwrap().to_rgb32f();
        assert_eq!((img.width(), img.height()), (64, 48));
        let px: Vec<f32> = img.pixels().flat_map(|p| p.0).collect();
        assert!(px.iter().all(|v| v.is_finite()));
        let mean = px.iter().sum::<f32>() / px.len() as f32;
        // The mean over ~50 patches in view: sampling noise of 2 % per patch averages down
        // well below 2 %; RGBE adds < 1 %.
        assert!(
            (mean / FURNACE_L - 1.0).abs() < 0.02,
            "{ext}: mean {mean}, expected {FURNACE_L}"
        );
        // Every pixel: a single patch's noise (tolerance 2 %, a few σ) plus RGBE rounding.
        for v in &px {
            assert!((v / FURNACE_L - 1.0).abs() < 0.1, "{ext}: pixel {v}");
        }
    }
    // The same solution with the radiosity set exactly: the image is exactly flat.
    let mut exact = SavedSolution::load(&sol).unwrap();
    exact.b.iter_mut().for_each(|b| *b = [FURNACE_B as f64; 3]);
    exact.vertex_b = exact.mesh.vertex_values(&exact.b);
    if let Some(e) = &mut exact.elements {
        e.vertex_b.iter_mut().for_each(|v| *v = [FURNACE_B; 3]);
        e.b.iter_mut().for_each(|b| *b = [FURNACE_B as f64; 3]);
    }
    let exact_path = dir.path().join("exact.rad");
    let mut bytes = Vec::new();
    exact.write(&mut bytes).unwrap();
    std::fs::write(&exact_path, bytes).unwrap();
    let out = dir.path().join("exact.exr");
    render_inside(&exact_path, &out);
    let img = image::open(&out).unwrap().to_rgb32f();
    for p in img.pixels() {
        for v in p.0 {
            assert!((v / FURNACE_L - 1.0).abs() < 1e-5, "pixel {v}");
        }
    }
    // Checked against its own scene, the solution is accepted.
    ok(&[
        "render",
        s(&sol),
        "--out",
        s(&dir.path().join("checked.png")),
        "--scene",
        s(&obj),
        "--quiet",
    ]);
}

#[test]
fn exports_read_back_with_vertex_counts_and_colour_ranges() {
    let dir = tempfile::tempdir().unwrap();
    let sol_path = solve_default(dir.path());
    let sol = SavedSolution::load(&sol_path).unwrap();
    // Exports draw the adaptive elements: the element mesh and its vertex radiosities.
    let (emesh, vertex_b) = sol.display();
    assert!(sol.elements.is_some());
    let n = emesh.vertices.len();
    let b_max = vertex_b.iter().flatten().fold(0.0f32, |a, &b| a.max(b));

    // PLY, through the crate's own reader.
    let ply_path = dir.path().join("m.ply");
    ok(&["export", s(&sol_path), "--out", s(&ply_path), "--quiet"]);
    let mut f = std::fs::File::open(&ply_path).unwrap();
    let ply = ply_rs_bw::parser::Parser::<ply_rs_bw::ply::DefaultElement>::new()
        .read_ply(&mut f)
        .unwrap();
    assert_eq!(
        ply.header.encoding,
        ply_rs_bw::ply::Encoding::BinaryLittleEndian
    );
    let verts = &ply.payload["vertex"];
    assert_eq!(verts.len(), n);
    assert_eq!(ply.payload["face"].len(), emesh.patches.len());
    use ply_rs_bw::ply::Property;
    let (mut max_red, mut max_lin) = (0u8, 0.0f32);
    for (v, want) in verts.iter().zip(vertex_b) {
        for (k, name) in ["radiosity_r", "radiosity_g", "radiosity_b"]
            .iter()
            .enumerate()
        {
            let Property::Float(x) = v[*name] else {
                panic!("{name} is not a float")
            };
            assert!(x.is_finite() && x >= 0.0);
            assert_eq!(x, want[k]);
            max_lin = max_lin.max(x);
        }
        let Property::UChar(r) = v["red"] else {
            panic!("red is not a uchar")
        };
        max_red = max_red.max(r);
    }
    assert_eq!(max_lin, b_max);
    assert!(max_red > 128, "tone-mapped colours use the range");

    // GLB, through the gltf crate.
    let glb_path = dir.path().join("m.glb");
    ok(&["export", s(&sol_path), "--out", s(&glb_path), "--quiet"]);
    let bytes = std::fs::read(&glb_path).unwrap();
    let gltf = gltf::Gltf::from_slice(&bytes).unwrap();
    let blob = gltf.blob.clone().unwrap();
    let mesh = gltf.meshes().next().unwrap();
    let prim = mesh.primitives().next().unwrap();
    let reader = prim.reader(|_| Some(&blob[..]));
    let pos: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
    assert_eq!(pos.len(), n);
    assert_eq!(pos[0], emesh.vertices[0].to_array());
    let normals: Vec<[f32; 3]> = reader.read_normals().unwrap().collect();
    assert!(normals
        .iter()
        .all(|v| ((v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt() - 1.0).abs() < 1e-4));
    let colours: Vec<[f32; 3]> = reader.read_colors(0).unwrap().into_rgb_f32().collect();
    assert_eq!(colours.len(), n);
    assert!(colours.iter().flatten().all(|c| (0.0..=1.0).contains(c)));
    assert!(colours.iter().flatten().any(|c| *c > 0.5));
    let tris = reader.read_indices().unwrap().into_u32().count();
    let expected: usize = (0..emesh.patches.len())
        .map(|i| 3 * (emesh.patch_indices(i).len() - 2))
        .sum();
    assert_eq!(tris, expected);
    assert!(prim.material().unlit());
}

#[test]
fn false_colour_png_has_its_legend() {
    let dir = tempfile::tempdir().unwrap();
    let sol = solve_default(dir.path());
    let out = dir.path().join("fc.png");
    let report = ok(&[
        "render",
        s(&sol),
        "--out",
        s(&out),
        "--false-colour",
        "--width",
        "320",
        "--height",
        "240",
        "--json",
    ]);
    let json: serde_json::Value = serde_json::from_str(&report).unwrap();
    let (lo, hi) = (
        json["scale"]["lo"].as_f64().unwrap(),
        json["scale"]["hi"].as_f64().unwrap(),
    );
    assert!(0.0 < lo && lo < hi, "{json}");
    let img = image::open(&out).unwrap().to_rgb8();
    assert_eq!((img.width(), img.height()), (320 + LEGEND_WIDTH, 240));
    // The legend panel: its background, the colour bar's two ends, and light label ink.
    let legend: Vec<[u8; 3]> = (320..img.width())
        .flat_map(|x| (0..240).map(move |y| (x, y)))
        .map(|(x, y)| img.get_pixel(x, y).0)
        .collect();
    let has = |c: [u8; 3]| legend.contains(&c);
    assert!(has(BACKGROUND));
    assert!(has(radiosity::render::false_colour::colour_at(0.0)));
    assert!(has(radiosity::render::false_colour::colour_at(1.0)));
    assert!(has([230, 230, 230]));
    // The picture itself is in colour, not grey.
    assert!(img
        .enumerate_pixels()
        .filter(|(x, _, _)| *x < 320)
        .any(|(_, _, p)| p.0[2] > p.0[1] + 30));
}

#[test]
fn solve_reports_in_one_line_or_json_and_refuses_a_bad_save_path() {
    let dir = tempfile::tempdir().unwrap();
    let out = ok(&["solve", "--out", s(&dir.path().join("o"))]);
    assert_eq!(out.lines().count(), 1, "{out}");
    let json = ok(&["solve", "--out", s(&dir.path().join("o")), "--json"]);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(v["scene"], "cornell-box");
    assert_user_error(
        &[
            "solve",
            "--out",
            s(&dir.path().join("o")),
            "--save",
            s(&dir.path().join("no/such/dir/x.rad")),
        ],
        &["--save", "does not exist"],
    );
    assert_user_error(
        &[
            "solve",
            "--out",
            s(&dir.path().join("o")),
            "--save",
            s(dir.path()),
        ],
        &["--save", "folder"],
    );
}

/// With the elements off, `elements.csv` is `patches.csv` with each row's own id as its patch
/// column: every other cell the same text, row for row.
#[test]
fn elements_off_give_the_patch_table_with_each_rows_id() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    ok(&["solve", "--out", s(&out), "--elements", "off", "--quiet"]);
    let patches = std::fs::read_to_string(out.join("patches.csv")).unwrap();
    let elements = std::fs::read_to_string(out.join("elements.csv")).unwrap();
    assert!(patches.lines().count() > 100);
    assert_eq!(patches.lines().count(), elements.lines().count());
    for (k, (p, e)) in patches.lines().zip(elements.lines()).enumerate() {
        let want = match k {
            0 => format!("{p},patch"),
            _ => format!("{p},{}", k - 1),
        };
        assert_eq!(e, want, "row {k}");
    }
    assert!(elements.ends_with('\n'));
}
