//! Stiff and extreme cases. The furnace (closed box, uniform E and ρ) at reflectances
//! near 1, where light bounces thousands of times before it is absorbed; lights a million
//! times brighter than others; scenes from millimetres to kilometres across. Invariants
//! everywhere: no NaN or infinity, the energy books close, no ray escapes a closed scene.

use crate::scene_builder::*;
use glam::vec3;
use radiosity::intersect::embree::EmbreeScene;
use radiosity::scene::Scene;
use radiosity::solve::{self, scalar, MethodKind, Solution, SolveSettings, StopReason};

fn solve_scene(scene: &Scene, patch_size: f32, cfg: &SolveSettings) -> Solution {
    let m = mesh_at(scene, Some(patch_size));
    let isect = EmbreeScene::build(&m, |_| true).unwrap();
    solve::solve(&m, &scene.materials, &isect, cfg, |_| {}).unwrap()
}

fn assert_sane(sol: &Solution, what: &str) {
    for b in &sol.b {
        assert!(
            b.iter().all(|x| x.is_finite() && *x >= 0.0),
            "{what}: B {b:?}"
        );
    }
    for u in &sol.unshot {
        assert!(
            u.iter().all(|x| x.is_finite() && *x >= 0.0),
            "{what}: unshot {u:?}"
        );
    }
    for p in &sol.stats.trace {
        let v = [
            p.time_s,
            p.max_unshot_b,
            p.mean_b,
            p.unshot_flux,
            p.estimate.energy,
            p.estimate.weighted_percent,
            p.estimate.rms_relative,
        ];
        assert!(v.iter().all(|x| x.is_finite()), "{what}: trace {p:?}");
    }
    let e = &sol.stats.energy;
    assert!(e.relative_residual() < 1e-9, "{what}: {e:?}");
}

/// Furnace at ρ = 0.9, 0.99, 0.999: B within 1 % of E/(1 − ρ) on every patch. The energy per
/// ray is normalised by 1 − ρ̄, so the run casts about patches/τ² rays whatever ρ is and a
/// patch's sampling error is about τ: τ = 0.25 % puts the worst of 24 patches (4σ) at 1 %.
/// What must not happen near ρ = 1 is a stall (shots that move nothing: light bounces
/// thousands of times) or an overflow. The solve reports its error against time like any
/// other, and its own estimate must agree that it is within 1 %.
#[test]
fn furnace_near_reflectance_one() {
    for rho in [0.9, 0.99, 0.999] {
        let scene = closed_box(
            1.0,
            1.0,
            1.0,
            material("wall", rho, 1.0 / std::f64::consts::PI),
        );
        let cfg = SolveSettings {
            method: MethodKind::AdaptiveRays,
            tolerance: 0.0025,
            ..SolveSettings::default()
        };
        let sol = solve_scene(&scene, 0.5, &cfg);
        let what = format!("rho {rho}");
        assert_sane(&sol, &what);
        assert_eq!(sol.stats.stop_reason, Some(StopReason::Converged), "{what}");
        let exact = 1.0 / (1.0 - rho);
        let worst = sol
            .b
            .iter()
            .map(|b| (scalar(b) - exact).abs() / exact)
            .fold(0.0, f64::max);
        eprintln!(
            "{what}: worst {worst:.4}, {} shots, {} rays, {:.2} s, {} trace points",
            sol.stats.shots,
            sol.stats.rays,
            sol.stats.seconds,
            sol.stats.trace.len()
        );
        assert!(worst < 0.01, "{what}: worst patch off by {worst}");
        assert!(sol.stats.trace.len() >= 5);
        let est = sol.stats.trace.last().unwrap().estimate;
        assert!(est.weighted_percent < 0.01, "{what}: estimate {est:?}");
    }
}

fn rays() -> SolveSettings {
    SolveSettings {
        method: MethodKind::AdaptiveRays,
        ..SolveSettings::default()
    }
}

fn furnace_worst(sol: &Solution, exact: f64) -> f64 {
    sol.b
        .iter()
        .map(|b| (scalar(b) - exact).abs() / exact)
        .fold(0.0, f64::max)
}

/// A lamp 10⁶ times brighter than another in the same room: both lit, nothing overflows, the
/// dim lamp's own light still reaches the books.
#[test]
fn lights_a_million_times_apart() {
    let mut s = closed_box(2.0, 2.0, 2.0, material("wall", 0.5, 0.0));
    s.materials.push(material("bright", 0.5, 1e6));
    s.materials.push(material("dim", 0.5, 1.0));
    let lamp = |s: &mut Scene, x: f32, m: u32| {
        quad(
            s,
            [
                vec3(x, 1.99, 0.5),
                vec3(x + 0.2, 1.99, 0.5),
                vec3(x + 0.2, 1.99, 0.7),
                vec3(x, 1.99, 0.7),
            ],
            m,
        )
    };
    // Facing down: counter-clockwise seen from below.
    lamp(&mut s, 0.3, 1);
    lamp(&mut s, 1.5, 2);
    for p in s.polygons.iter_mut().skip(6) {
        let first = p.first as usize;
        s.indices[first..first + 4].reverse();
    }
    let sol = solve_scene(&s, 0.25, &rays());
    assert_sane(&sol, "bright and dim");
    assert!(sol.b.iter().all(|b| scalar(b) > 0.0));
}

/// The furnace from a millimetre to ten kilometres across: same answer, no ray escapes.
#[test]
fn scenes_from_millimetres_to_kilometres() {
    for size in [1e-3f32, 1.0, 1e4] {
        let s = closed_box(
            size,
            size,
            size,
            material("wall", 0.5, 1.0 / std::f64::consts::PI),
        );
        let sol = solve_scene(&s, size / 4.0, &rays());
        let what = format!("size {size}");
        assert_sane(&sol, &what);
        assert_eq!(sol.stats.energy.escaped, [0.0; 3], "{what}");
        let worst = furnace_worst(&sol, 2.0);
        assert!(worst < 0.12, "{what}: worst {worst}");
    }
}

/// A floor of 200 slivers (1:200), coincident coplanar duplicates of a wall, rays grazing the
/// walls of a 100 m corridor, and patches 10⁴ times different in area side by side: the books
/// close, nothing leaks, and the furnace's mean is right.
#[test]
fn slivers_coincident_faces_grazing_rays_and_mixed_areas() {
    let wall = material("wall", 0.5, 1.0 / std::f64::consts::PI);
    // Slivers: the floor (y = 0) cut into 200 strips along x.
    let mut slivers = closed_box(1.0, 1.0, 1.0, wall.clone());
    slivers.polygons.remove(0);
    for k in 0..200 {
        let (x0, x1) = (k as f32 / 200.0, (k + 1) as f32 / 200.0);
        quad(
            &mut slivers,
            [
                vec3(x0, 0.0, 0.0),
                vec3(x0, 0.0, 1.0),
                vec3(x1, 0.0, 1.0),
                vec3(x1, 0.0, 0.0),
            ],
            0,
        );
    }
    // Coincident coplanar faces: the ceiling twice.
    let mut twice = closed_box(1.0, 1.0, 1.0, wall.clone());
    let ceiling = twice.polygons[1];
    twice.polygons.push(ceiling);
    // Grazing rays: a corridor 100 × 1 × 1.
    let corridor = closed_box(100.0, 1.0, 1.0, wall.clone());
    // Areas 10⁴ apart: the floor as a 1 cm square in a corner and the rest around it.
    let mut mixed = closed_box(1.0, 1.0, 1.0, wall);
    mixed.polygons.remove(0);
    let floor = |s: &mut Scene, x0: f32, z0: f32, x1: f32, z1: f32| {
        quad(
            s,
            [
                vec3(x0, 0.0, z0),
                vec3(x0, 0.0, z1),
                vec3(x1, 0.0, z1),
                vec3(x1, 0.0, z0),
            ],
            0,
        )
    };
    floor(&mut mixed, 0.0, 0.0, 0.01, 0.01);
    floor(&mut mixed, 0.01, 0.0, 1.0, 0.01);
    floor(&mut mixed, 0.0, 0.01, 1.0, 1.0);
    for (name, scene, patch) in [
        ("slivers", &slivers, 2.0),
        ("coincident", &twice, 0.25),
        ("corridor", &corridor, 1.0),
        ("mixed areas", &mixed, 2.0),
    ] {
        let sol = solve_scene(scene, patch, &rays());
        assert_sane(&sol, name);
        assert_eq!(sol.stats.energy.escaped, [0.0; 3], "{name}: light escaped");
        let m = mesh_at(scene, Some(patch));
        let area: f64 = m.patches.iter().map(|p| p.area).sum();
        let mean: f64 = sol
            .b
            .iter()
            .zip(&m.patches)
            .map(|(b, p)| scalar(b) * p.area)
            .sum::<f64>()
            / area;
        // A coincident duplicate shades its twin: only the mean of the other cases is 2.
        if name != "coincident" {
            assert!((mean - 2.0).abs() < 0.05, "{name}: mean B {mean}");
        }
    }
}

/// A lit floor that sees nothing but its own plane: all its light leaves the open scene, the
/// books say so, and nothing else lights up.
#[test]
fn a_patch_that_sees_only_coplanar_neighbours() {
    let mut s = scene(
        "floor",
        vec![material("floor", 0.5, 0.0), material("lamp", 0.5, 1.0)],
    );
    for (x, m) in [(0.0, 0u32), (1.0, 1), (2.0, 0)] {
        quad(
            &mut s,
            [
                vec3(x, 0.0, 0.0),
                vec3(x, 0.0, 1.0),
                vec3(x + 1.0, 0.0, 1.0),
                vec3(x + 1.0, 0.0, 0.0),
            ],
            m,
        );
    }
    let sol = solve_scene(&s, 1.0, &rays());
    assert_sane(&sol, "floor");
    let e = &sol.stats.energy;
    assert!((scalar(&e.escaped) - scalar(&e.emitted)).abs() < 1e-12 * scalar(&e.emitted));
    let m = mesh_at(&s, Some(1.0));
    for (b, p) in sol.b.iter().zip(&m.patches) {
        if p.material == 0 {
            assert_eq!(scalar(b), 0.0);
        }
    }
}
