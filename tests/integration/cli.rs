//! The `radiosity` command as a user meets it: outputs of a solve, and every kind of bad input
//! giving one line naming the file and the problem, exit code 2, never a panic.

use crate::common::{assert_user_error, run};
use std::path::Path;

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

const LIT_MTL: &str = "newmtl white\nKd 0.5 0.5 0.5\nnewmtl lamp\nKd 0.5 0.5 0.5\nKe 5 5 5\n";
/// A floor with a lamp above it, facing down.
const LIT_OBJ: &str = "mtllib m.mtl\n\
v 0 0 0\nv 0 0 1\nv 1 0 1\nv 1 0 0\n\
v 0.4 1 0.4\nv 0.6 1 0.4\nv 0.6 1 0.6\nv 0.4 1 0.6\n\
usemtl white\nf 1 2 3 4\nusemtl lamp\nf 5 6 7 8\n";

#[test]
fn solve_default_scene_writes_the_three_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o");
    let (code, stdout, err) = run(&["solve", "--out", out.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains("patches"), "{stdout}");
    let csv = std::fs::read_to_string(out.join("patches.csv")).unwrap();
    let mut lines = csv.lines();
    // The contract's 17 columns, then the sensor grid's lux and daylight factor.
    assert_eq!(
        lines.next().unwrap(),
        "id,cx,cy,cz,nx,ny,nz,area,rho_r,rho_g,rho_b,e_r,e_g,e_b,b_r,b_g,b_b,lux,df"
    );
    let rows: Vec<&str> = lines.collect();
    assert!(rows.len() > 100);
    assert!(!csv.contains("NaN") && !csv.contains("inf"));
    let png = image::open(out.join("render.png")).unwrap();
    assert_eq!((png.width(), png.height()), (640, 480));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(json["patches"].as_u64().unwrap() as usize, rows.len());
    assert!(json["energy"]["relative_residual"].as_f64().unwrap() < 1e-9);
    assert_eq!(json["stop_reason"], "converged");
    assert!(json["trace"].as_array().unwrap().len() >= 2);
    for phase in ["load", "mesh", "build", "solve", "output", "total"] {
        assert!(json["seconds"][phase].as_f64().is_some(), "{phase}");
    }
    // The peak memory at the end of each stage only grows (Linux: read from the OS).
    let peak = |phase: &str| json["peak_mib"][phase].as_f64().unwrap();
    let phases = ["load", "mesh", "build", "sides", "solve", "output"];
    assert!(peak("load") > 0.0, "{}", json["peak_mib"]);
    for w in phases.windows(2) {
        assert!(peak(w[0]) <= peak(w[1]), "{}", json["peak_mib"]);
    }
}

#[test]
fn info_describes_the_default_scene() {
    let (code, stdout, err) = run(&["info"]);
    assert_eq!(code, 0, "{err}");
    for word in [
        "polygons",
        "patches",
        "axis-aligned",
        "lights",
        "bounds",
        "suggested",
    ] {
        assert!(stdout.contains(word), "{word} missing from {stdout}");
    }
}

#[test]
fn missing_file() {
    assert_user_error(&["solve", "/nonexistent/room.obj"], &["room.obj"]);
    assert_user_error(&["info", "/nonexistent/room.obj"], &["room.obj"]);
}

#[test]
fn unparsable_obj() {
    let d = tempfile::tempdir().unwrap();
    let f = write(
        d.path(),
        "bad.obj",
        "v 1 2 banana\nv 0 0 0\nv 1 0 0\nf 1 2 3\n",
    );
    assert_user_error(&["info", &f], &["bad.obj"]);
}

#[test]
fn missing_mtl_is_a_warning_and_a_default_grey() {
    let d = tempfile::tempdir().unwrap();
    let f = write(
        d.path(),
        "nomtl.obj",
        &LIT_OBJ.replace("m.mtl", "absent.mtl"),
    );
    let (code, stdout, err) = run(&["info", &f]);
    assert_eq!(code, 0, "{err}");
    assert!(
        (stdout + &err).to_lowercase().contains("absent.mtl"),
        "the warning names the missing file"
    );
}

#[test]
fn nan_or_infinite_coordinates() {
    let d = tempfile::tempdir().unwrap();
    for (name, v) in [("nan.obj", "nan"), ("inf.obj", "inf")] {
        let f = write(
            d.path(),
            name,
            &format!("v {v} 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
        );
        assert_user_error(&["info", &f], &[name]);
    }
}

#[test]
fn face_with_fewer_than_three_vertices() {
    let d = tempfile::tempdir().unwrap();
    let f = write(
        d.path(),
        "two.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2\n",
    );
    assert_user_error(&["info", &f], &["two.obj"]);
}

#[test]
fn zero_area_faces_are_dropped_with_one_warning() {
    let d = tempfile::tempdir().unwrap();
    write(d.path(), "m.mtl", LIT_MTL);
    let degenerate = "v 5 5 5\nv 6 6 6\nv 7 7 7\nusemtl white\nf 9 10 11\nf 9 10 11\n";
    let f = write(d.path(), "zero.obj", &format!("{LIT_OBJ}{degenerate}"));
    let out = d.path().join("o");
    let (code, _, err) = run(&[
        "solve",
        &f,
        "--out",
        out.to_str().unwrap(),
        "--patch-size",
        "0.25",
    ]);
    assert_eq!(code, 0, "{err}");
    let warnings: Vec<&str> = err.lines().filter(|l| l.contains("warning")).collect();
    assert_eq!(warnings.len(), 1, "{err}");
    assert!(
        warnings[0].contains('2'),
        "counts the 2 dropped faces: {}",
        warnings[0]
    );
}

#[test]
fn negative_reflectance_is_an_error() {
    let d = tempfile::tempdir().unwrap();
    write(
        d.path(),
        "m.mtl",
        &LIT_MTL.replace("Kd 0.5 0.5 0.5\nnewmtl", "Kd -0.2 0.5 0.5\nnewmtl"),
    );
    let f = write(d.path(), "rho.obj", LIT_OBJ);
    assert_user_error(&["info", &f], &["white", "-0.2"]);
}

#[test]
fn info_shows_where_each_reflectance_came_from() {
    let d = tempfile::tempdir().unwrap();
    let mtl = LIT_MTL.replace("Kd 0.5 0.5 0.5\nnewmtl", "Kd 1.2 0.5 0.5\nnewmtl");
    write(d.path(), "m.mtl", &mtl);
    let f = write(d.path(), "rho.obj", LIT_OBJ);
    let (code, stdout, err) = run(&["info", &f]);
    assert_eq!(code, 0, "{err}");
    for needle in [
        "rho 0.980 0.500 0.500",
        "rho from Kd = 1.200 0.500 0.500, clamped to 0.98",
        "rho from Kd\n",
        "warning: ",
        "'white'",
    ] {
        assert!(stdout.contains(needle), "{needle:?} missing from {stdout}");
    }
    let (code, stdout, err) = run(&["info", "--json", &f]);
    assert_eq!(code, 0, "{err}");
    let json: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let white = &json["materials"][0];
    assert_eq!(white["name"], "white");
    assert_eq!(white["rho_source"]["kind"], "clamped");
    assert_eq!(white["rho_source"]["from"]["kind"], "kd");
    assert_eq!(white["rho_source"]["unclamped"][0], 1.2);
    assert_eq!(json["materials"][1]["rho_source"]["kind"], "kd");
}

/// Tinted glazing: `info` shows its colour and mean (text and JSON); a negative `Tf` channel is
/// a user error (one line, exit 2, no panic).
#[test]
fn info_shows_the_tint_of_glazing() {
    let d = tempfile::tempdir().unwrap();
    let mtl = LIT_MTL.replace(
        "Kd 0.5 0.5 0.5\nnewmtl",
        "Kd 0.05 0.05 0.05\nTf 0.2 0.6 0.3\nillum 4\nnewmtl",
    );
    write(d.path(), "m.mtl", &mtl);
    let f = write(d.path(), "tint.obj", LIT_OBJ);
    let (code, stdout, err) = run(&["info", &f]);
    assert_eq!(code, 0, "{err}");
    assert!(
        stdout.contains("glazing: transmittance 0.367 (mean), tinted 0.200 0.600 0.300"),
        "{stdout}"
    );
    let (code, stdout, err) = run(&["info", "--json", &f]);
    assert_eq!(code, 0, "{err}");
    let json: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let white = &json["materials"][0];
    assert_eq!(
        white["transmittance_rgb"],
        serde_json::json!([0.2, 0.6, 0.3])
    );
    assert!((white["transmittance"].as_f64().unwrap() - 1.1 / 3.0).abs() < 1e-12);
    // Opaque materials show their (zero) transmittance in every channel.
    assert_eq!(
        json["materials"][1]["transmittance_rgb"],
        serde_json::json!([0.0, 0.0, 0.0])
    );

    write(
        d.path(),
        "m.mtl",
        &mtl.replace("Tf 0.2 0.6 0.3", "Tf 0.2 -0.6 0.9"),
    );
    assert_user_error(&["info", &f], &["white", "negative in a channel"]);
}

#[test]
fn no_emitter_suggests_emit() {
    let d = tempfile::tempdir().unwrap();
    write(
        d.path(),
        "m.mtl",
        "newmtl white\nKd 0.5 0.5 0.5\nnewmtl lamp\nKd 0.5 0.5 0.5\n",
    );
    let f = write(d.path(), "dark.obj", LIT_OBJ);
    let out = d.path().join("o");
    assert_user_error(
        &["solve", &f, "--out", out.to_str().unwrap()],
        &["dark.obj", "--emit"],
    );
    // ... and --emit fixes it.
    let (code, _, err) = run(&[
        "solve",
        &f,
        "--out",
        out.to_str().unwrap(),
        "--emit",
        "lamp=5,5,5",
        "-q",
    ]);
    assert_eq!(code, 0, "{err}");
}

#[test]
fn unwritable_output_folder() {
    let d = tempfile::tempdir().unwrap();
    let file = write(d.path(), "plain-file", "x");
    let out = format!("{file}/sub");
    assert_user_error(&["solve", "--out", &out], &["plain-file"]);
}

#[test]
fn bad_flag_values() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("o");
    let out = out.to_str().unwrap();
    for (flag, value, needle) in [
        ("--tolerance", "2", "--tolerance"),
        ("--tolerance", "0", "--tolerance"),
        ("--patch-size", "-1", "--patch-size"),
        ("--stop", "0", "--stop"),
        ("--max-time", "-3", "--max-time"),
        ("--fov", "200", "--fov"),
        ("--width", "0", "--width"),
        ("--emit", "lamp", "--emit"),
        ("--emit", "lamp=1,2", "--emit"),
        ("--emit", "nosuchmaterial=1,1,1", "nosuchmaterial"),
        ("--seed", "x", "--seed"),
        ("--eye", "1,2", "--eye"),
    ] {
        assert_user_error(&["solve", "--out", out, flag, value], &[needle]);
    }
}

#[test]
fn flipped_normals_are_reported() {
    let d = tempfile::tempdir().unwrap();
    write(d.path(), "m.mtl", LIT_MTL);
    // The floor wound clockwise seen from above: its front faces down, away from the lamp.
    let f = write(
        d.path(),
        "flipped.obj",
        &LIT_OBJ.replace("f 1 2 3 4", "f 4 3 2 1"),
    );
    let out = d.path().join("o");
    let (code, _, err) = run(&[
        "solve",
        &f,
        "--out",
        out.to_str().unwrap(),
        "--patch-size",
        "0.25",
        "--one-sided",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("back of one-sided faces") && err.contains("--two-sided"),
        "{err}"
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    // The floor catches about a quarter of the lamp's light (a 1 m square 1 m below a small
    // lamp: F ≈ 0.24); all of it lands on the back face.
    assert!(json["energy"]["back_fraction"].as_f64().unwrap() > 0.15);
    assert!(json["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .any(|w| w.as_str().unwrap().contains("--two-sided")));
}

/// Every `--method` solves the blocks scene from the command line and says what it did; the
/// summary records the hybrid's switch.
#[test]
fn every_method_runs_from_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/blocks.obj");
    for method in [
        "adaptive-rays",
        "hemicube",
        "hemicube-jittered",
        "adaptive-hemicube",
        "adaptive-hybrid",
        "gathering",
    ] {
        let out = dir.path().join(method);
        let (code, stdout, err) = run(&[
            "solve",
            scene.to_str().unwrap(),
            "--method",
            method,
            "--hemicube-n",
            "40",
            "--width",
            "64",
            "--height",
            "48",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{method}: {err}");
        assert!(!stdout.contains("NaN") && !err.contains("NaN"));
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap())
                .unwrap();
        assert_eq!(summary["method"], method);
        if method == "adaptive-hybrid" {
            assert!(
                summary["switch"]["shot"].as_u64().unwrap() >= 1,
                "{summary}"
            );
        }
        if method.contains("hemicube") || method == "gathering" {
            assert_eq!(summary["rays"], 0, "{method}");
            assert!(summary["hemicube_cells"].as_u64().unwrap() > 0);
        }
    }
}

#[test]
fn gathering_refuses_a_matrix_over_the_cap() {
    assert_user_error(
        &["solve", "--method", "gathering", "--gather-cap-mib", "1"],
        &["gathering", "patches", "MiB", "--gather-cap-mib"],
    );
}

fn scene_path(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
        .display()
        .to_string()
}

#[test]
fn crosscheck_passes_on_a_small_scene() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("cross.json");
    let (code, out, err) = run(&[
        "crosscheck",
        &scene_path("blocks.obj"),
        "--rays",
        "20000",
        "--out",
        json.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("bar passed"), "{out}");
    assert!(out.contains("embree vs brute"), "{out}");
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(v["passed"], true);
    assert_eq!(v["closed"], true);
    assert_eq!(v["rays"], 20000);
}

#[test]
fn crosscheck_bad_flags() {
    assert_user_error(&["crosscheck", "--rays", "0"], &["--rays"]);
    assert_user_error(&["crosscheck", "--rays", "10", "--eps", "-1"], &["--eps"]);
}

#[test]
fn intersector_merge_on_a_skew_scene_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    assert_user_error(
        &[
            "solve",
            &scene_path("blocks.obj"),
            "--intersector",
            "merge",
            "--out",
            out.to_str().unwrap(),
        ],
        &["--intersector merge", "skew"],
    );
}

#[test]
fn switch_at_needs_the_hybrid() {
    assert_user_error(
        &["solve", "--method", "hemicube", "--switch-at", "3"],
        &["--switch-at", "adaptive-hybrid"],
    );
    assert_user_error(&["solve", "--hemicube-n", "1"], &["--hemicube-n"]);
}

#[test]
fn solve_reports_the_intersector_and_why() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let (code, stdout, err) = run(&[
        "solve",
        &scene_path("blocks.obj"),
        "--intersector",
        "hybrid",
        "--tolerance",
        "0.2",
        "--json",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(v["intersector"], "hybrid");
    assert_eq!(v["intersector_reason"], "forced by --intersector");
    let (code, stdout, _) = run(&["info", &scene_path("hallway.obj")]);
    assert_eq!(code, 0);
    assert!(stdout.contains("intersector    embree (auto:"), "{stdout}");
}

#[test]
fn bench_intersect_writes_a_table_and_csv() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("bench.csv");
    let (code, out, err) = run(&[
        "bench",
        "intersect",
        &scene_path("blocks.obj"),
        "--generated",
        "none",
        "--rays",
        "4000",
        "--out",
        csv.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(out.starts_with("| scene | patches |"), "{out}");
    let text = std::fs::read_to_string(&csv).unwrap();
    assert_eq!(text.lines().count(), 2, "{text}");
    assert!(text.starts_with("scene,patches,"), "{text}");
    assert_user_error(
        &["bench", "intersect", "--generated", "0"],
        &["--generated"],
    );
}

/// A small sweep keeps the command working (full sizes are run by hand; README).
#[test]
fn a_small_sweep_writes_its_table_and_plots() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sweep");
    let (code, stdout, err) = run(&[
        "sweep",
        "--sizes",
        "1k,2k",
        "--tolerance",
        "0.2",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains("Growth exponents"), "{stdout}");
    let csv = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    assert_eq!(csv.lines().count(), 3, "{csv}");
    assert!(!csv.contains("NaN"));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("sweep.json")).unwrap()).unwrap();
    assert_eq!(json["settings"]["tolerance"], 0.2);
    assert_eq!(json["rows"].as_array().unwrap().len(), 2);
    for png in ["time.png", "memory.png"] {
        let img = image::open(out.join(png)).unwrap();
        assert!(img.width() > 100);
    }
    assert_user_error(&["sweep", "--sizes", "0", "--out", "x"], &["--sizes"]);
}

/// The end-to-end sweep runs the whole pipeline per size: every stage timed, the elements
/// refined (under the auto limit), the peaks rising stage by stage, the outputs removed.
#[test]
fn an_end_to_end_sweep_times_every_stage() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("e2e");
    let (code, stdout, err) = run(&[
        "sweep",
        "--end-to-end",
        "--sizes",
        "1k,2k",
        "--tolerance",
        "0.2",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains("Growth exponents"), "{stdout}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("end-to-end.json")).unwrap())
            .unwrap();
    let rows = json["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 2);
    for r in rows {
        let f = |k: &str| r[k].as_f64().unwrap();
        assert!(
            f("solve_s") > 0.0 && f("elements_s") > 0.0 && f("picture_s") > 0.0,
            "{r}"
        );
        assert!(
            f("elements") > f("patches") && f("element_rays") > 0.0,
            "{r}"
        );
        assert!(f("gather_rays") > 0.0 && f("shoot_rays") > 0.0, "{r}");
        let parts = f("load_s") + f("mesh_s") + f("build_s") + f("sides_s") + f("solve_s");
        assert!(
            parts + f("elements_s") + f("picture_s") <= f("total_s") * 1.001,
            "{r}"
        );
        assert!(f("peak_solve_mib") <= f("peak_elements_mib"), "{r}");
        assert!(
            f("peak_elements_mib") <= f("peak_mib") && f("peak_mib") > 1.0,
            "{r}"
        );
    }
    let summaries = json["summaries"].as_array().unwrap();
    assert_eq!(summaries.len(), 2);
    for s in summaries {
        // `radiosity solve`'s defaults, its error target included.
        assert_eq!(s["error_target"]["target"].as_f64(), Some(0.05), "{s}");
    }
    let csv = std::fs::read_to_string(out.join("end-to-end.csv")).unwrap();
    assert_eq!(csv.lines().count(), 3, "{csv}");
    assert!(!csv.contains("NaN"));
    assert!(!out.join("1000").exists(), "the outputs are removed");
    for png in ["end-to-end-time.png", "end-to-end-memory.png"] {
        assert!(image::open(out.join(png)).unwrap().width() > 100);
    }
}

/// A reader that stops early (`radiosity info … | head -1`) ends the command quietly, without
/// a panic on the broken pipe.
#[test]
fn a_closed_standard_output_is_not_a_panic() {
    let bin = assert_cmd::cargo::cargo_bin("radiosity");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/church.obj");
    let out = std::process::Command::new("sh")
        .arg("-c")
        .arg(format!(
            "'{}' info '{}' | true",
            bin.display(),
            scene.display()
        ))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn bench_timing_refuses_a_bad_grid_before_timing() {
    assert_user_error(&["bench", "timing", "--grid", "0.8,0"], &["--grid"]);
    // The built-in Cornell box has no floor with a storey's clearance above it.
    assert_user_error(&["bench", "timing", "--grid", "0.8,0.5"], &["no sensor"]);
}

/// `info` sums up a luminaire file: its format, its flux against the lamps', its peak; a
/// malformed one gets one line naming the file and the line, and exit code 2.
#[test]
fn info_sums_up_a_luminaire_file() {
    let dir = tempfile::tempdir().unwrap();
    let ies = dir.path().join("Downlight.IES");
    // A cosine (Lambertian) downlight of 1,000 cd at the nadir on 10° steps, one 4,000 lm
    // lamp: its flux is π·1000 lm, so its light output ratio π/4 = 78.5 %.
    let gammas: Vec<String> = (0..=9).map(|k| (10 * k).to_string()).collect();
    let cd: Vec<String> = (0..=9)
        .map(|k| format!("{:.3}", 1000.0 * (10.0 * k as f64).to_radians().cos()))
        .collect();
    let text = format!(
        "IESNA:LM-63-2002\n[MANUFAC] ACME\nTILT=NONE\n1 4000 1 10 1 1 2 -0.2 -0.2 0\n1 1 25\n{}\n0\n{}\n",
        gammas.join(" "),
        cd.join(" ")
    );
    std::fs::write(&ies, text).unwrap();
    let (code, out, err) = run(&["info", ies.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("IES LM-63-2002") && out.contains("manufac        ACME"),
        "{out}"
    );
    // 10° steps of a cosine lose a little to the bilinear web between nodes: 78.3 %.
    assert!(out.contains("light output ratio 78."), "{out}");
    assert!(
        out.contains("peak           1000 cd at C 0°, γ 0°"),
        "{out}"
    );
    assert!(out.contains("circle or ellipse"), "{out}");
    let (code, json, err) = run(&["info", ies.to_str().unwrap(), "--json"]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    let lumens = v["luminaire_lumens"].as_f64().unwrap();
    assert!(
        (lumens / std::f64::consts::PI / 1000.0 - 1.0).abs() < 0.01,
        "{lumens}"
    );
    let bad = dir.path().join("bad.ldt");
    std::fs::write(&bad, "ACME\n1\n9\n").unwrap();
    assert_user_error(&["info", bad.to_str().unwrap()], &["bad.ldt:3:", "Isym"]);
}
