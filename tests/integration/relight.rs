//! Per-light channels and relighting (the paper's Images 1a/1b): channels sum to the
//! combined solution, relighting equals a fresh solve with the lights re-weighted (within the
//! sampling error), lights group by material or by connected surface, and a solve without
//! `--per-light` keeps no channel.
use crate::common;

use crate::common::*;
use crate::scene_builder::*;
use glam::vec3;
use radiosity::export::solution::{LightChannel, SavedSolution};
use radiosity::scene::Scene;
use radiosity::solve::estimate::against;
use radiosity::solve::lights::{groups, GroupBy};
use radiosity::solve::{scalar, MethodKind, RunHooks, SolveSettings};
use std::path::Path;
use std::sync::Arc;

/// Channels sum to the combined solution, for shooting by rays, by hemi-cube and gathering.
#[test]
fn channels_sum_to_the_combined_solution() {
    let scene = load_project_scene("office.obj");
    let m = mesh_at(&scene, Some(0.6));
    let g = groups(&scene, &m, GroupBy::Material);
    assert_eq!(g.names, ["light_front", "light_rear"]);
    for method in [
        MethodKind::AdaptiveRays,
        MethodKind::AdaptiveHemicube,
        MethodKind::Gathering,
    ] {
        let cfg = SolveSettings {
            method,
            hemicube_n: 40,
            ..SolveSettings::default()
        };
        let hooks = RunHooks {
            light_groups: Some(Arc::new(g.clone())),
            ..RunHooks::default()
        };
        let sol = solve_mesh_with(&scene, &m, &cfg, &hooks);
        assert_eq!(sol.channels.len(), 2);
        for (j, b) in sol.b.iter().enumerate() {
            for (x, &bx) in b.iter().enumerate() {
                let sum: f64 = sol.channels.iter().map(|c| c.b[j][x]).sum();
                // Gathering solves each channel to the stop criterion on its own.
                let tol = if method == MethodKind::Gathering {
                    1e-3
                } else {
                    1e-12
                };
                assert!(
                    (sum - bx).abs() <= tol * bx.abs().max(1e-9),
                    "{}: patch {j}: {sum} vs {bx}",
                    method.name()
                );
            }
        }
    }
    // Without --per-light: nothing per light.
    let sol = solve_mesh(&scene, &m, &SolveSettings::default());
    assert!(sol.channels.is_empty());
}

/// Relighting (front light off, rear light ×2) equals a fresh solve of the scene with those
/// emissions, within the sampling error of the two solves (each ~5 % per patch at the default
/// tolerance: their difference, in the paper's average weighted percent error, stays under
/// 2× the combined estimate).
#[test]
fn relighting_equals_a_fresh_solve_with_the_weights() {
    let scene = load_project_scene("office.obj");
    let m = mesh_at(&scene, Some(0.6));
    let g = groups(&scene, &m, GroupBy::Material);
    let cfg = SolveSettings {
        method: MethodKind::AdaptiveRays,
        tolerance: 0.02,
        ..SolveSettings::default()
    };
    let hooks = RunHooks {
        light_groups: Some(Arc::new(g)),
        ..RunHooks::default()
    };
    let sol = solve_mesh_with(&scene, &m, &cfg, &hooks);
    let relit: Vec<[f64; 3]> = (0..sol.b.len())
        .map(|j| [0, 1, 2].map(|x| 0.0 * sol.channels[0].b[j][x] + 2.0 * sol.channels[1].b[j][x]))
        .collect();
    let mut fresh_scene = scene.clone();
    for mat in &mut fresh_scene.materials {
        match mat.name.as_str() {
            "light_front" => mat.ke = [0.0; 3],
            "light_rear" => mat.ke = mat.ke.map(|k| 2.0 * k),
            _ => {}
        }
    }
    let fresh = solve_mesh(
        &fresh_scene,
        &m,
        &SolveSettings {
            seed: 2,
            ..cfg.clone()
        },
    );
    let area: Vec<f64> = m.patches.iter().map(|p| p.area).collect();
    let diff = against(&area, &relit, &fresh.b);
    let est = fresh.stats.trace.last().unwrap().estimate;
    assert!(
        diff.weighted_percent < 2.0 * std::f64::consts::SQRT_2 * est.weighted_percent,
        "relit vs fresh {diff:?}, estimate {est:?}"
    );
    // And the front light itself is dark in the relit solution.
    let front = m
        .patches
        .iter()
        .position(|p| scene.materials[p.material as usize].name == "light_front")
        .unwrap();
    assert!(scalar(&relit[front]) < 0.5 * scalar(&sol.b[front]));
}

/// Two fixtures of one material: one channel by material, two by connected surface; quads
/// sharing an edge are one fixture.
#[test]
fn lights_group_by_material_or_connected_surface() {
    let mut s = closed_box(4.0, 2.0, 2.0, material("wall", 0.5, 0.0));
    s.materials.push(material("lamp", 0.5, 1.0));
    let lamp = |s: &mut Scene, x: f32| {
        quad(
            s,
            [
                vec3(x, 1.99, 0.5),
                vec3(x + 0.5, 1.99, 0.5),
                vec3(x + 0.5, 1.99, 1.0),
                vec3(x, 1.99, 1.0),
            ],
            1,
        )
    };
    lamp(&mut s, 0.5);
    lamp(&mut s, 1.0); // shares an edge with the first
    lamp(&mut s, 3.0);
    let m = mesh_at(&s, Some(0.5));
    let by_mat = groups(&s, &m, GroupBy::Material);
    assert_eq!(by_mat.names, ["lamp"]);
    let by_conn = groups(&s, &m, GroupBy::Connected);
    assert_eq!(by_conn.names, ["lamp#1", "lamp#2"]);
    let lit: Vec<u32> = by_conn
        .of_patch
        .iter()
        .copied()
        .filter(|&g| g != u32::MAX)
        .collect();
    assert_eq!(lit.iter().filter(|&&g| g == 0).count(), 2);
    assert_eq!(lit.iter().filter(|&&g| g == 1).count(), 1);
}

/// From the command line: solve --per-light --save, relight to PNG and GLB; the saved file
/// carries the channels; relighting a solution without channels, or naming a light that is
/// not there, is a clear error with exit code 2 and no output file.
#[test]
fn relight_from_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).display().to_string();
    let office = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/office.obj");
    let office = office.to_str().unwrap();
    let (code, _, err) = common::run(&[
        "solve",
        office,
        "--patch-size",
        "0.6",
        "--per-light",
        "--save",
        &p("o.rad"),
        "--out",
        &p("o"),
        "--quiet",
    ]);
    assert_eq!(code, 0, "{err}");
    let saved = SavedSolution::load(Path::new(&p("o.rad"))).unwrap();
    let names: Vec<&str> = saved
        .channels
        .iter()
        .map(|c: &LightChannel| c.name.as_str())
        .collect();
    assert_eq!(names, ["light_front", "light_rear"]);
    for out in ["r.png", "r.glb"] {
        let (code, _, err) = common::run(&[
            "relight",
            &p("o.rad"),
            "--weight",
            "light_front=0",
            "--weight",
            "light_rear=2",
            "--out",
            &p(out),
        ]);
        assert_eq!(code, 0, "{err}");
        assert!(Path::new(&p(out)).exists());
    }
    let (code, _, err) = common::run(&[
        "relight",
        &p("o.rad"),
        "--weight",
        "sun=1",
        "--out",
        &p("x.png"),
    ]);
    assert_eq!(code, 2);
    assert!(err.contains("light_front, light_rear"), "{err}");
    assert!(!Path::new(&p("x.png")).exists());
    let (code, _, _) = common::run(&[
        "solve",
        office,
        "--patch-size",
        "0.6",
        "--save",
        &p("plain.rad"),
        "--out",
        &p("o2"),
        "--quiet",
    ]);
    assert_eq!(code, 0);
    let (code, _, err) = common::run(&["relight", &p("plain.rad"), "--out", &p("y.png")]);
    assert_eq!(code, 2);
    assert!(err.contains("--per-light"), "{err}");
    let (code, _, err) = common::run(&[
        "relight",
        &p("o.rad"),
        "--weight",
        "light_rear=-1",
        "--out",
        &p("z.png"),
    ]);
    assert_eq!(code, 2, "{err}");
}

/// Area-weighted radiosity of the elements per patch, Σ A_e·B_e over each patch's elements.
fn element_flux(sol: &SavedSolution) -> Vec<f64> {
    let el = sol.elements.as_ref().expect("elements");
    let mut out = vec![0.0; sol.mesh.patches.len()];
    for (e, &p) in el.patch.iter().enumerate() {
        out[p as usize] += el.mesh.patches[e].area * scalar(&el.b[e]);
    }
    out
}

/// Σ |a − k·b| / Σ k·b: the area-weighted relative difference of two element solutions.
fn relative_difference(a: &[f64], b: &[f64], k: f64) -> f64 {
    let num: f64 = a.iter().zip(b).map(|(x, y)| (x - k * y).abs()).sum();
    num / b.iter().map(|y| k * y).sum::<f64>()
}

/// A relit Gouraud picture and a relit mesh show the adaptive elements, refined again under
/// the relit lights with the solve's element settings (here `--element-rays 32`): more mesh
/// records than patches, and at weight 1 element values within 5 % (area-weighted) of the
/// saved ones, at weight 0.5 half of them. A final-gather picture does not refine them; a
/// solution solved `--elements off` stays without.
#[test]
fn relit_gouraud_and_meshes_refine_the_elements_again() {
    use radiosity::progress::Progress;
    use radiosity::saved::relight::{element_settings, relight_with_elements};
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).display().to_string();
    let spot = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/spot.obj");
    let spot = spot.to_str().unwrap();
    for (file, extra) in [
        ("s.rad", "--element-rays=32"),
        ("off.rad", "--elements=off"),
    ] {
        let (code, _, err) = common::run(&[
            "solve",
            spot,
            "--per-light",
            "--tolerance",
            "0.1",
            extra,
            "--shading",
            "gouraud",
            "--width",
            "64",
            "--height",
            "48",
            "--save",
            &p(file),
            "--out",
            &p(&format!("{file}.out")),
            "--quiet",
        ]);
        assert_eq!(code, 0, "{err}");
    }
    let saved = SavedSolution::load(Path::new(&p("s.rad"))).unwrap();
    let patches = saved.mesh.patches.len();
    let n_saved = saved.elements.as_ref().unwrap().mesh.patches.len();
    assert!(n_saved > patches, "{n_saved} elements, {patches} patches");
    let settings = element_settings(&saved).expect("the solve's element settings");
    assert_eq!(settings.rays, 32);

    // Weight 1: the saved elements again, within the corners' sampling noise; weight 0.5:
    // half of them.
    let progress = Progress::hidden();
    let mut warnings = Vec::new();
    let saved_flux = element_flux(&saved);
    for w in [1.0, 0.5] {
        let weights = [("light".to_string(), w)];
        let (relit, stats) =
            relight_with_elements(&saved, &weights, &progress, &mut warnings).expect("relight");
        let stats = stats.expect("refined");
        assert_eq!(stats.rays_per_corner, 32);
        let n = relit.elements.as_ref().unwrap().mesh.patches.len();
        assert!(n > patches, "weight {w}: {n} elements, {patches} patches");
        let d = relative_difference(&element_flux(&relit), &saved_flux, w);
        assert!(d < 0.05, "weight {w}: element values differ by {d}");
    }
    assert!(warnings.is_empty(), "{warnings:?}");

    // From the command line: the report counts the elements drawn; the PLY has a face per
    // element.
    let report = |args: &[&str]| -> serde_json::Value {
        let (code, out, err) = common::run(args);
        assert_eq!(code, 0, "{args:?}: {err}");
        serde_json::from_str(&out).unwrap()
    };
    let (w, h) = (["--width", "64"], ["--height", "48"]);
    let mut gouraud = vec!["relight", "--weight", "light=0.5", "--json"];
    gouraud.extend(w.iter().chain(&h));
    let rad = p("s.rad");
    let png = p("r.png");
    let r = report(&[&gouraud[..], &[&rad, "--shading", "gouraud", "--out", &png]].concat());
    assert_eq!(r["patches"].as_u64(), Some(patches as u64));
    assert!(r["elements"].as_u64().unwrap() > patches as u64, "{r}");
    let ply = p("r.ply");
    let r = report(&[
        "relight",
        &rad,
        "--weight",
        "light=0.5",
        "--json",
        "--out",
        &ply,
    ]);
    let faces = r["elements"].as_u64().unwrap();
    assert!(faces > patches as u64, "{r}");
    let text = std::fs::read(&ply).unwrap();
    let head = String::from_utf8_lossy(&text[..text.len().min(2000)]).to_string();
    assert!(head.contains(&format!("element face {faces}\n")), "{head}");
    // The final gather reads the patches: no elements refined.
    let gather = p("g.png");
    let r = report(&[&gouraud[..], &[&rad, "--pixel-rays", "4", "--out", &gather]].concat());
    assert!(r.get("elements").is_none(), "{r}");
    // Solved without elements: relit without them.
    let off = SavedSolution::load(Path::new(&p("off.rad"))).unwrap();
    assert!(element_settings(&off).is_none());
    let r = report(
        &[
            &gouraud[..],
            &[&p("off.rad"), "--shading", "gouraud", "--out", &png],
        ]
        .concat(),
    );
    assert!(r.get("elements").is_none(), "{r}");
}
