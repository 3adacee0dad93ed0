//! The view flags and picture units as a user meets them: `render --view FILE` (a
//! Radiance view file) gives the view's field and aspect, `--near` clips, and `.hdr`/`.exr`
//! pixels are radiance B/π with the view and the unit in the header; bad view files are refused
//! with one line and exit code 2. Pictures are drawn `--shading gouraud`, whose pixels are exact
//! (the gather's noise is `tests/gather_render.rs`'s business).

use crate::common::{assert_user_error, run};
use radiosity::export::solution::SavedSolution;
use std::path::{Path, PathBuf};

fn ok(args: &[&str]) -> String {
    let (code, out, err) = run(args);
    assert_eq!(code, 0, "{args:?}: {err}");
    out
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A furnace: the inside of a unit cube, ρ = 0.5 and Ke = 1 everywhere, so every patch has
/// B = E/(1 − ρ) = 2π W/m² and radiance L = B/π = 2 W/sr/m² exactly.
const FURNACE_OBJ: &str = "mtllib f.mtl\n\
v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
usemtl glow\n\
f 1 5 6 2\nf 4 3 7 8\nf 1 2 3 4\nf 5 8 7 6\nf 1 4 8 5\nf 2 6 7 3\n";
const FURNACE_MTL: &str = "newmtl glow\nKd 0.5 0.5 0.5\nKe 1 1 1\n";
const FURNACE_L: f32 = 2.0;

/// Solves the furnace (coarse, quick) and saves it; also writes a copy whose radiosity is set
/// exactly. Returns (solved, exact).
fn furnace(dir: &Path) -> (PathBuf, PathBuf) {
    std::fs::write(dir.join("f.mtl"), FURNACE_MTL).unwrap();
    let obj = dir.join("furnace.obj");
    std::fs::write(&obj, FURNACE_OBJ).unwrap();
    let sol = dir.join("f.rad");
    ok(&[
        "solve",
        s(&obj),
        "--out",
        s(&dir.join("o")),
        "--save",
        s(&sol),
        "--patch-size",
        "0.2",
        "--tolerance",
        "0.02",
        "--quiet",
    ]);
    let mut exact = SavedSolution::load(&sol).unwrap();
    let b = f64::from(FURNACE_L) * std::f64::consts::PI;
    exact.b.iter_mut().for_each(|x| *x = [b; 3]);
    exact.vertex_b = exact.mesh.vertex_values(&exact.b);
    // The elements (what Gouraud pictures draw) too.
    if let Some(e) = &mut exact.elements {
        e.vertex_b.iter_mut().for_each(|v| *v = [b as f32; 3]);
        e.b.iter_mut().for_each(|x| *x = [b; 3]);
    }
    let exact_path = dir.join("exact.rad");
    let mut bytes = Vec::new();
    exact.write(&mut bytes).unwrap();
    std::fs::write(&exact_path, bytes).unwrap();
    (sol, exact_path)
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// The header lines of a Radiance picture.
fn hdr_header(path: &Path) -> Vec<String> {
    let bytes = std::fs::read(path).unwrap();
    let end = bytes.windows(2).position(|w| w == b"\n\n").unwrap();
    String::from_utf8(bytes[..end].to_vec())
        .unwrap()
        .lines()
        .map(str::to_string)
        .collect()
}

fn pixels(path: &Path) -> ((u32, u32), Vec<f32>) {
    let img = image::open(path).unwrap().to_rgb32f();
    (img.dimensions(), img.pixels().flat_map(|p| p.0).collect())
}

#[test]
fn render_with_a_view_file_draws_its_field_in_radiance() {
    let dir = tempfile::tempdir().unwrap();
    let (sol, exact) = furnace(dir.path());
    // From the cube's centre towards the wall z = 0: 90° × 53.13°, a 2:1 picture, all wall.
    let view = write(
        dir.path(),
        "v.vf",
        "rview -vtv -vp 0.5 0.5 0.5 -vd 0 0 -1 -vu 0 1 0 -vh 90 -vv 53.130102 -vo 0 -va 0 -vs 0 -vl 0\n",
    );
    let hdr = dir.path().join("v.hdr");
    let out = ok(&[
        "render",
        "--shading",
        "gouraud",
        s(&sol),
        "--view",
        s(&view),
        "--width",
        "64",
        "--out",
        s(&hdr),
    ]);
    assert!(out.contains("W/sr/m²"), "{out}");
    let ((w, h), px) = pixels(&hdr);
    assert_eq!((w, h), (64, 32));
    assert!(px.iter().all(|v| v.is_finite()));
    // Mean over the patches in view: 2 % sampling noise per patch averages down; RGBE
    // truncation (the `image` reader adds no half step) costs < 0.4 %.
    let mean = px.iter().sum::<f32>() / px.len() as f32;
    assert!(
        (mean / FURNACE_L - 1.0).abs() < 0.02,
        "mean {mean}, expected B/π = {FURNACE_L}"
    );
    for v in &px {
        assert!((v / FURNACE_L - 1.0).abs() < 0.1, "pixel {v}");
    }
    let header = hdr_header(&hdr);
    assert_eq!(header[0], "#?RADIANCE");
    assert!(header.iter().any(|l| l.starts_with("SOFTWARE= radiosity ")));
    assert!(header.iter().any(|l| l.contains("radiance in W/sr/m2")));
    assert!(
        header
            .iter()
            .any(|l| l
                .starts_with("VIEW= -vtv -vp 0.5 0.5 0.5 -vd 0 0 -1 -vu 0 1 0 -vh 90 -vv 53.1301")),
        "{header:?}"
    );

    // The exact solution: every EXR pixel is B/π to float precision.
    let exr = dir.path().join("v.exr");
    ok(&[
        "render",
        "--shading",
        "gouraud",
        s(&exact),
        "--view",
        s(&view),
        "--height",
        "20",
        "--out",
        s(&exr),
        "--quiet",
    ]);
    let ((w, h), px) = pixels(&exr);
    assert_eq!((w, h), (40, 20));
    for v in &px {
        assert!((v / FURNACE_L - 1.0).abs() < 1e-5, "pixel {v}");
    }

    // --width and --height together: fitted inside the box, as rpict -x -y.
    let png = dir.path().join("v.png");
    ok(&[
        "render",
        "--shading",
        "gouraud",
        s(&sol),
        "--view",
        s(&view),
        "--width",
        "50",
        "--height",
        "50",
        "--out",
        s(&png),
        "--quiet",
    ]);
    assert_eq!(image::open(&png).unwrap().to_rgb8().dimensions(), (50, 25));

    // A parallel view (0.8 × 0.4 of the wall) from a picture's VIEW= line.
    let par = write(
        dir.path(),
        "par.vf",
        "#?RADIANCE\nrpict -vf x.vf -x 512\nVIEW= -vtl -vp 0.5 0.5 0.5 -vd 0 0 -1 -vu 0 1 0 -vh 0.8 -vv 0.4\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 1\n",
    );
    let exr = dir.path().join("par.exr");
    ok(&[
        "render",
        "--shading",
        "gouraud",
        s(&exact),
        "--view",
        s(&par),
        "--width",
        "30",
        "--out",
        s(&exr),
        "--quiet",
    ]);
    let ((w, h), px) = pixels(&exr);
    assert_eq!((w, h), (30, 15));
    assert!(px.iter().all(|v| (v / FURNACE_L - 1.0).abs() < 1e-5));
}

#[test]
fn near_clips_the_wall_in_front_of_the_eye() {
    let dir = tempfile::tempdir().unwrap();
    let (_, exact) = furnace(dir.path());
    // 0.1 from the wall z = 1, looking at it: without clipping the wall fills the view;
    // clipped at 0.2 the outside (nothing) shows.
    let look = [
        "--eye",
        "0.5,0.5,0.9",
        "--target",
        "0.5,0.5,2",
        "--fov",
        "60",
        "--width",
        "16",
        "--height",
        "12",
        "--quiet",
    ];
    let out = dir.path().join("a.exr");
    let mut args = vec![
        "render",
        "--shading",
        "gouraud",
        s(&exact),
        "--out",
        s(&out),
    ];
    args.extend(look);
    ok(&args);
    assert!(pixels(&out).1.iter().all(|v| (v - FURNACE_L).abs() < 1e-4));
    args.extend(["--near", "0.2"]);
    ok(&args);
    assert!(pixels(&out).1.iter().all(|v| *v == 0.0));
    // A view file's -vo does the same; --near overrides it.
    let view = write(
        dir.path(),
        "in.vf",
        "-vtv -vp 0.5 0.5 0.9 -vd 0 0 1 -vu 0 1 0 -vh 60 -vv 45 -vo 0.2\n",
    );
    let base = [
        "render",
        "--shading",
        "gouraud",
        s(&exact),
        "--out",
        s(&out),
        "--view",
        s(&view),
        "--quiet",
    ];
    ok(&base);
    assert!(pixels(&out).1.iter().all(|v| *v == 0.0));
    let mut near0 = base.to_vec();
    near0.extend(["--near", "0"]);
    ok(&near0);
    assert!(pixels(&out).1.iter().all(|v| (v - FURNACE_L).abs() < 1e-4));
}

#[test]
fn solve_takes_the_view_too() {
    let dir = tempfile::tempdir().unwrap();
    let view = write(
        dir.path(),
        "v.vf",
        "rvu -vtv -vp 0.28 0.27 -0.8 -vd 0 0 1 -vu 0 1 0 -vh 60 -vv 30\n",
    );
    ok(&[
        "solve",
        "--out",
        s(&dir.path().join("o")),
        "--view",
        s(&view),
        "--width",
        "100",
        "--max-rays",
        "20000",
        "--error",
        "off",
        "--quiet",
    ]);
    let img = image::open(dir.path().join("o/render.png"))
        .unwrap()
        .to_rgb8();
    // tan 30° / tan 15° = 2.1547.
    assert_eq!(img.dimensions(), (100, 46));
}

#[test]
fn bad_views_are_refused_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    // The solution is not read before the view is: any path will do.
    let sol = dir.path().join("none.rad");
    let out = dir.path().join("x.hdr");
    let missing = dir.path().join("missing.vf");
    let render = |extra: &[&str], needles: &[&str]| {
        let mut args = vec!["render", "--shading", "gouraud", s(&sol), "--out", s(&out)];
        args.extend(extra);
        assert_user_error(&args, needles);
    };
    render(
        &["--view", s(&missing)],
        &["--view", "missing.vf", "cannot open"],
    );
    for (text, needles) in [
        (
            "rvu -vp 1 2\n",
            &["bad.vf", "line 1", "-vp needs 3 numbers"][..],
        ),
        (
            "-vtv\n-vz 1\n",
            &["bad.vf", "line 2", "unknown view option -vz"],
        ),
        (
            "rvu -vth -vh 180 -vv 180\n",
            &["-vth (hemispherical fisheye) is not supported"],
        ),
        ("-vd 0 0 0\n", &["-vd 0 0 0", "must not be zero"]),
        ("-vh 200 -vd 1 0 0\n", &["-vh 200", "between 0 and 180"]),
        ("hello\n", &["'hello' is not a view"]),
    ] {
        let bad = write(dir.path(), "bad.vf", text);
        render(&["--view", s(&bad)], needles);
    }
    let good = write(dir.path(), "good.vf", "-vtv -vd 1 0 0\n");
    render(
        &["--view", s(&good), "--eye", "1,2,3"],
        &["--view sets the whole camera"],
    );
    render(&["--near", "-1"], &["--near must be a distance"]);
    let tall = write(dir.path(), "tall.vf", "-vtl -vh 1 -vv 100\n");
    render(&["--view", s(&tall)], &["640x64000"]);
    // Nothing was written.
    assert!(!out.exists());
}
