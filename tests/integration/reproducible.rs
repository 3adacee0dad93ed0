//! Reproducibility: the same scene, settings and seed give bit-identical results on any run and any
//! thread count, for every method, the default `adaptive-hybrid` included (its switch from
//! hemi-cubes to rays is decided from counted work, not from measured times).

use crate::common;
use crate::scene_builder;

use radiosity::intersect::embree::EmbreeScene;
use radiosity::mesh::Mesh;
use radiosity::scene::Scene;
use radiosity::solve::{self, MethodKind, Solution, SolveSettings, SwitchBy};

fn solve_in(threads: Option<usize>, s: &Scene, m: &Mesh, cfg: &SolveSettings) -> Solution {
    let isect = EmbreeScene::build(m, |_| true).unwrap();
    common::on_threads(threads, || {
        solve::solve(m, &s.materials, &isect, cfg, |_| {}).unwrap()
    })
}

/// Bit for bit: the radiosities, and the shots that led to them.
fn assert_same(a: &Solution, b: &Solution, what: &str) {
    assert_eq!(a.b.len(), b.b.len(), "{what}");
    let differ = a.b.iter().zip(&b.b).filter(|(x, y)| x != y).count();
    assert_eq!(differ, 0, "{what}: {differ} patches differ");
    assert_eq!(a.stats.shots, b.stats.shots, "{what}: shots");
    assert_eq!(a.stats.rays, b.stats.rays, "{what}: rays");
    assert_eq!(a.stats.hemicube_shots, b.stats.hemicube_shots, "{what}");
    let shot = |s: &Solution| s.stats.switch.map(|w| w.shot);
    assert_eq!(shot(a), shot(b), "{what}: switch shot");
    // The costs the switch compared, to the bit: counted work gives the same predictions on
    // every run and thread count.
    let costs = |s: &Solution| {
        s.stats.switch.map(|w| {
            [
                w.seconds_per_ray,
                w.hemicube_shot_seconds,
                w.ray_shot_seconds,
                w.hemicube_faces,
                w.hemicube_tested,
            ]
            .map(f64::to_bits)
        })
    };
    assert_eq!(costs(a), costs(b), "{what}: the switch's costs");
}

#[test]
fn default_solves_are_bit_identical_on_every_scene_and_thread_count() {
    let cfg = SolveSettings::default();
    assert_eq!(cfg.method, MethodKind::AdaptiveHybrid);
    assert_eq!(cfg.switch_by, SwitchBy::Counted);
    for file in [
        "blocks.obj",
        "office.obj",
        "hallway.obj",
        "church.obj",
        "cornell-box.obj",
    ] {
        let (s, m) = scene_builder::project_scene(file);
        let first = solve_in(None, &s, &m, &cfg);
        // The hybrid really switched, by its counted rule (so the test covers the switch).
        let sw = first
            .stats
            .switch
            .unwrap_or_else(|| panic!("{file}: no switch"));
        assert!(!sw.forced && sw.by == SwitchBy::Counted, "{file}: {sw:?}");
        assert_same(
            &first,
            &solve_in(None, &s, &m, &cfg),
            &format!("{file}, again"),
        );
        assert_same(
            &first,
            &solve_in(Some(1), &s, &m, &cfg),
            &format!("{file}, 1 thread"),
        );
        assert_same(
            &first,
            &solve_in(Some(2), &s, &m, &cfg),
            &format!("{file}, 2 threads"),
        );
    }
}

/// Every other method too, on the smallest scene: one thread against two.
#[test]
fn every_method_is_bit_identical_on_one_and_two_threads() {
    let (s, m) = scene_builder::project_scene("blocks.obj");
    for method in MethodKind::ALL {
        let cfg = SolveSettings {
            method,
            ..SolveSettings::default()
        };
        let one = solve_in(Some(1), &s, &m, &cfg);
        let two = solve_in(Some(2), &s, &m, &cfg);
        assert_same(&one, &two, method.name());
    }
}

/// `--switch-at` replays a recorded switch exactly; `--switch-by measured` still decides from
/// measured times (and says so), and is the one way, with `max_time`, to a result that may
/// vary from run to run.
#[test]
fn switch_at_replays_the_counted_switch_and_measured_is_kept() {
    let (s, m) = scene_builder::project_scene("office.obj");
    let counted = solve_in(None, &s, &m, &SolveSettings::default());
    let sw = counted.stats.switch.expect("switched");
    let replay = SolveSettings {
        switch_at: Some(sw.shot),
        ..SolveSettings::default()
    };
    let replayed = solve_in(None, &s, &m, &replay);
    assert_same(&counted, &replayed, "replayed at the counted switch");
    let r = replayed.stats.switch.expect("switched");
    assert!(r.forced && r.by == SwitchBy::Counted, "{r:?}");
    // The forced switch records the counted model's predictions, the same as the rule's.
    assert_eq!(r.hemicube_shot_seconds, sw.hemicube_shot_seconds);
    assert_eq!(r.ray_shot_seconds, sw.ray_shot_seconds);

    let measured = SolveSettings {
        switch_by: SwitchBy::Measured,
        ..SolveSettings::default()
    };
    let sol = solve_in(None, &s, &m, &measured);
    let w = sol.stats.switch.expect("the measured rule switched too");
    assert!(!w.forced && w.by == SwitchBy::Measured, "{w:?}");
    // It fits the hemi-cube's time to two timed shots at least, and timed a ray probe.
    assert!(w.shot >= 2, "{w:?}");
    assert!(
        w.seconds_per_ray > 0.0 && w.seconds_per_ray.is_finite(),
        "{w:?}"
    );
    assert_eq!(w.shot, sol.stats.hemicube_shots);
}

/// The bar as a user meets it: two default `radiosity solve` runs of each scene in `scenes/`
/// write identical `patches.csv` files, and so does a run on one thread.
#[test]
fn two_default_cli_solves_write_identical_patch_tables() {
    let t = tempfile::tempdir().unwrap();
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    for name in ["blocks", "office", "hallway", "church", "cornell-box"] {
        let obj = root.join("scenes").join(format!("{name}.obj"));
        let obj = obj.to_str().unwrap();
        let table = |run: &str, extra: &[&str]| {
            let out = t.path().join(format!("{name}-{run}"));
            let mut args = vec!["solve", obj, "--quiet", "--out", out.to_str().unwrap()];
            args.extend_from_slice(extra);
            let (code, _, err) = common::run(&args);
            assert_eq!(code, 0, "{name} {run}: {err}");
            std::fs::read(out.join("patches.csv")).unwrap()
        };
        let a = table("a", &[]);
        assert!(a == table("b", &[]), "{name}: two default solves differ");
        assert!(
            a == table("one-thread", &["--threads", "1"]),
            "{name}: one thread differs from the default"
        );
    }
}

/// A mesh of more than 131,072 patches shoots in larger waves (a quarter of a ray per patch),
/// cast in the order of their patches: still the same on one thread and two.
#[test]
fn large_meshes_shoot_larger_waves_alike_on_any_thread_count() {
    let s = scene_builder::load_project_scene("cornell-box.obj");
    let m = scene_builder::mesh_uniform(&s, Some(0.003));
    let n = m.patches.len();
    assert!(n > 8 * solve::ray_shots::WAVE_RAYS, "{n} patches");
    let cfg = SolveSettings {
        method: MethodKind::AdaptiveRays,
        tolerance: 0.5,
        final_gather: false,
        error_target: None,
        ..SolveSettings::default()
    };
    let one = solve_in(Some(1), &s, &m, &cfg);
    // Waves of more than WAVE_RAYS rays each (the last one may be short).
    let per_wave = one.stats.rays as f64 / one.stats.waves as f64;
    assert!(
        per_wave > 2.0 * solve::ray_shots::WAVE_RAYS as f64,
        "{per_wave} rays a wave"
    );
    assert_same(&one, &solve_in(Some(2), &s, &m, &cfg), "2 threads");
}
