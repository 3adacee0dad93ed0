//! `radiosity reference` states an error bound that holds, and `radiosity compare`
//! writes its CSV, plots and Markdown. Nothing here is timed: the speedups are measured by the
//! reproduction (README), not asserted.

use crate::common::radiosity;
use radiosity::compare::reference;
use radiosity::intersect::embree::EmbreeScene;
use radiosity::mesh::{self, MeshOptions};
use radiosity::scene::{self, LoadOptions};
use radiosity::solve::estimate;
use radiosity::solve::SolveSettings;
use std::path::Path;

/// The reference's stated bound holds against a second, independent reference: two tables
/// with bounds σ₁, σ₂ should differ by about sqrt(σ₁² + σ₂²); the bar is a factor of 2 either
/// way (the same bar as the estimate's own test, tests/solve_methods.rs).
#[test]
fn the_references_bound_holds_against_an_independent_reference() {
    let scene = scene::default_scene(&LoadOptions::default()).unwrap();
    // Patches of 0.1 m (≈ 300): a modest tolerance runs in well under a second.
    let m = mesh::build(
        &scene,
        &MeshOptions {
            patch_size: Some(0.1),
            two_sided: false,
            one_sided: false,
            uniform_patches: false,
        },
    );
    let isect = EmbreeScene::build(&m, |_| true).unwrap();
    let solve = |seed| {
        let cfg = SolveSettings {
            seed,
            tolerance: 0.01,
            stop_fraction: 1e-5,
            ..SolveSettings::default()
        };
        reference::build(&m, &scene.materials, &isect, &cfg).unwrap()
    };
    let (a, b) = (solve(1), solve(1_000));
    assert!(
        a.check_passed && b.check_passed,
        "{}\n{}",
        a.check_line(),
        b.check_line()
    );
    let area: Vec<f64> = m.patches.iter().map(|p| p.area).collect();
    let diff = estimate::against(&area, &a.b, &b.b);
    let expected = |f: fn(&estimate::ErrorMetrics) -> f64| f(&a.bound).hypot(f(&b.bound));
    for (name, measured, predicted) in [
        ("energy", diff.energy, expected(|e| e.energy)),
        (
            "weighted percent",
            diff.weighted_percent,
            expected(|e| e.weighted_percent),
        ),
    ] {
        let ratio = measured / predicted;
        assert!(
            (0.5..=2.0).contains(&ratio),
            "{name}: measured {measured}, bounds predict {predicted}"
        );
    }
}

#[test]
fn reference_command_writes_the_table_and_states_its_bound() {
    let dir = tempfile::tempdir().unwrap();
    let out = radiosity()
        .args([
            "reference",
            "--patch-size",
            "0.1",
            "--tolerance",
            "0.02",
            "--out",
        ])
        .arg(dir.path())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("stated error bound") && err.contains("check passed"),
        "{err}"
    );
    let table = std::fs::read_to_string(dir.path().join("patches.csv")).unwrap();
    assert!(table.starts_with("id,cx,"));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("summary.json")).unwrap())
            .unwrap();
    assert!(summary["bound"]["weighted_percent"].as_f64().unwrap() > 0.0);
    assert_eq!(summary["check_passed"], true);
}

/// A small comparison on blocks writes every output: the CSV with a row per trace point of
/// every method, three PNGs that decode, and the Markdown with its tables.
#[test]
fn compare_writes_csv_plots_and_markdown() {
    let blocks = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/blocks.obj");
    let dir = tempfile::tempdir().unwrap();
    let out = radiosity()
        .arg("compare")
        .arg(&blocks)
        .args([
            "--methods",
            "adaptive-hybrid,hemicube,gathering",
            "--budget",
            "2",
            "--hemicube-n",
            "40",
            "--reference-tolerance",
            "0.02",
            "--repeat",
            "3",
            "--out",
        ])
        .arg(dir.path())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    // --repeat 3: three rounds of every method, one kept each.
    assert!(err.contains("hemicube (round 3)"), "{err}");
    let csv = std::fs::read_to_string(dir.path().join("compare.csv")).unwrap();
    let mut lines = csv.lines();
    assert!(lines.next().unwrap().starts_with("method,time_s,shots,"));
    for m in ["adaptive-hybrid", "hemicube", "gathering"] {
        assert!(csv.lines().any(|l| l.starts_with(&format!("{m},"))), "{m}");
    }
    assert!(!csv.contains("NaN") && !csv.contains("inf"));
    // Every row carries the error against the reference (the last column is filled).
    assert!(lines.all(|l| !l.ends_with(',')));
    for png in ["error_vs_time.png", "decay.png", "cost_per_shot.png"] {
        let img = image::open(dir.path().join(png)).unwrap();
        assert!(img.width() > 100 && img.height() > 100, "{png}");
    }
    let md = std::fs::read_to_string(dir.path().join("compare.md")).unwrap();
    assert!(md.contains("| method | time |"), "{md}");
    assert!(md.contains("## Time to reach an average weighted percent error"));
    assert!(md.contains("Speedup of adaptive-hybrid"));
    assert!(!md.contains("NaN"));
    assert!(dir.path().join("reference/patches.csv").exists());
}

#[test]
fn compare_rejects_bad_settings_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&[&str], &str); 6] = [
        (&["--budget", "0"], "--budget"),
        (&["--budget", "1", "--patch-size", "0.0001"], "--patch-size"),
        (&["--budget", "1", "--repeat", "0"], "--repeat"),
        (
            &["--budget", "1", "--methods", "hemicube,hemicube"],
            "twice",
        ),
        (&["--budget", "1", "--levels", "-0.1"], "--levels"),
        (
            &["--budget", "1", "--reference", "/nonexistent/patches.csv"],
            "--reference",
        ),
    ];
    for (args, needle) in cases {
        let out = radiosity()
            .arg("compare")
            .args(args)
            .arg("--out")
            .arg(dir.path())
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
        assert!(
            err.lines()
                .any(|l| l.starts_with("Error:") && l.contains(needle)),
            "{args:?}: {err}"
        );
    }
}
