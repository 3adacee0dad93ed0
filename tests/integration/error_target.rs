//! The error target: `--error E` keeps refining (independent passes, averaged) until the
//! solver's own estimate is at most E; the true error falls with it; budgets stop it; the books
//! close and the result is reproducible.

use radiosity::intersect::embree::EmbreeScene;
use radiosity::mesh::Mesh;
use radiosity::scene::Scene;
use radiosity::solve::{self, estimate, Solution, SolveSettings, StopReason};

use crate::scene_builder;

fn run(s: &Scene, m: &Mesh, cfg: &SolveSettings) -> Solution {
    let isect = EmbreeScene::build(m, |_| true).unwrap();
    let sol = solve::solve(m, &s.materials, &isect, cfg, |_| {}).unwrap();
    assert!(
        sol.stats.energy.relative_residual() < 1e-9,
        "{:?}",
        sol.stats.energy
    );
    sol
}

fn estimate_of(sol: &Solution) -> f64 {
    sol.stats.trace.last().unwrap().estimate.weighted_percent
}

#[test]
fn the_target_is_reached_and_the_true_error_falls_with_it() {
    let (s, m) = scene_builder::project_scene("blocks.obj");
    let area: Vec<f64> = m.patches.iter().map(|p| p.area).collect();
    let reference = run(&s, &m, &SolveSettings::reference(99));
    let plain = run(&s, &m, &SolveSettings::default());
    let e0 = estimate_of(&plain);
    let target = e0 / 2.5;
    let cfg = SolveSettings {
        error_target: Some(target),
        ..SolveSettings::default()
    };
    let refined = run(&s, &m, &cfg);
    let t = refined.stats.error_target.unwrap();
    // A further pass or gather round (whichever the counted work says reaches it cheaper).
    assert!(
        t.reached && t.estimate <= target && t.passes + t.regathers >= 2,
        "{t:?}"
    );
    assert!((estimate_of(&refined) - t.estimate).abs() < 1e-12);
    let true_plain = estimate::against(&area, &plain.b, &reference.b).weighted_percent;
    let true_refined = estimate::against(&area, &refined.b, &reference.b).weighted_percent;
    assert!(
        true_refined < 0.7 * true_plain,
        "true error {true_plain} → {true_refined} (estimates {e0} → {})",
        t.estimate
    );
    // The estimate stays honest: within a factor of 2 of the true error.
    assert!(t.estimate < 2.0 * true_refined && true_refined < 2.0 * t.estimate);
    // Reproducible.
    assert_eq!(run(&s, &m, &cfg).b, refined.b);
}

#[test]
fn a_budget_stops_the_refinement_and_says_so() {
    let (s, m) = scene_builder::project_scene("blocks.obj");
    let plain = run(&s, &m, &SolveSettings::default());
    let first = plain.stats.rays + plain.stats.hemicube_cells;
    let cfg = SolveSettings {
        error_target: Some(1e-4),
        max_rays: Some(4 * first),
        ..SolveSettings::default()
    };
    let sol = run(&s, &m, &cfg);
    let t = sol.stats.error_target.unwrap();
    assert!(!t.reached, "{t:?}");
    assert_eq!(sol.stats.stop_reason, Some(StopReason::MaxRays));
    assert!(t.estimate < estimate_of(&plain), "{t:?}");
}

#[test]
fn a_bad_target_is_refused() {
    for e in [0.0, -0.1, 1.0, f64::NAN] {
        let cfg = SolveSettings {
            error_target: Some(e),
            ..SolveSettings::default()
        };
        let msg = cfg.check().unwrap_err().to_string();
        assert!(msg.contains("--error"), "{msg}");
    }
}

/// The first gather of an error target is sized by a pilot on a sample of the patches: a
/// looser target gets fewer rays per patch, the estimate lands near what the pilot predicted,
/// and the choice is the same on any thread count.
#[test]
fn a_pilot_sizes_the_first_gather_for_the_target() {
    let (s, m) = scene_builder::project_scene("office.obj");
    let plain = run(&s, &m, &SolveSettings::default());
    let e0 = estimate_of(&plain);
    let at = |target: f64, threads: Option<usize>| {
        let cfg = SolveSettings {
            error_target: Some(target),
            ..SolveSettings::default()
        };
        crate::common::on_threads(threads, || run(&s, &m, &cfg))
    };
    let pilot_of = |sol: &Solution| {
        let g = sol.stats.final_gather.expect("a final gather");
        (g, g.pilot.expect("sized by a pilot"))
    };
    let (tight, loose) = (at(1.3 * e0, None), at(2.0 * e0, None));
    let (gt, pt) = pilot_of(&tight);
    let (gl, pl) = pilot_of(&loose);
    assert!(pl.rays_per_patch < pt.rays_per_patch, "{pl:?} {pt:?}");
    assert!(gl.rays < gt.rays, "{gl:?} {gt:?}");
    // The pilot is a sample, at most half the patches gathered.
    assert!(
        pt.patches > 0 && 2 * pt.patches <= gt.patches,
        "{pt:?} {gt:?}"
    );
    for (sol, p) in [(&tight, pt), (&loose, pl)] {
        // Sized for its goal (the target's gather-round aim), where it could be met.
        assert!((p.goal - 0.9 * sol.stats.error_target.unwrap().target).abs() < 1e-12);
        assert!(p.predicted <= p.goal, "{p:?}");
        // Met by the first pass (the trace's points are taken by the clock, the counts are
        // not): its estimate near the prediction.
        let t = sol.stats.error_target.unwrap();
        assert!(t.reached && t.passes == 1 && t.regathers == 0, "{t:?}");
        assert!(
            (t.estimate / p.predicted - 1.0).abs() < 0.1,
            "{t:?} against {p:?}"
        );
    }
    assert_eq!(at(2.0 * e0, Some(1)).b, loose.b);
    assert_eq!(at(2.0 * e0, Some(2)).b, loose.b);
}
