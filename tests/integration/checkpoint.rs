//! Checkpoints (docs/design.md §6): a solve resumed from a checkpoint ends exactly where the
//! uninterrupted one does, for the same seed; Ctrl-C (the interrupt flag) stops at a safe
//! point with a checkpoint; corrupt, truncated or foreign checkpoints are refused.

use crate::common;

use radiosity::intersect::embree::EmbreeScene;
use radiosity::mesh::{self, Mesh, MeshOptions};
use radiosity::scene::{self, LoadOptions, Scene};
use radiosity::solve::checkpoint::Checkpoint;
use radiosity::solve::driver::{Saved, Sink};
use radiosity::solve::{self, MethodKind, RunHooks, Solution, SolveSettings, StopReason};
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

fn office() -> (Scene, Mesh) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/office.obj");
    let s = scene::load_obj(&path, &LoadOptions::default()).unwrap();
    let m = mesh::build(
        &s,
        &MeshOptions {
            patch_size: Some(0.6),
            two_sided: false,
            one_sided: false,
            uniform_patches: false,
        },
    );
    (s, m)
}

fn run(s: &Scene, m: &Mesh, cfg: &SolveSettings) -> Solution {
    run_with(s, m, cfg, &RunHooks::default())
}

fn run_with(s: &Scene, m: &Mesh, cfg: &SolveSettings, hooks: &RunHooks) -> Solution {
    let isect = EmbreeScene::build(m, |_| true).unwrap();
    solve::run(m, &s.materials, Some(&isect), cfg, hooks, |_| {}).unwrap()
}

/// Every safe point's saved state, kept in memory.
fn recording_sink() -> (Sink, Arc<Mutex<Vec<Saved>>>) {
    let kept = Arc::new(Mutex::new(Vec::new()));
    let k = kept.clone();
    let sink = Sink {
        every: Duration::ZERO,
        write: Arc::new(move |s: &Saved| {
            k.lock().unwrap().push(s.clone());
            Ok(())
        }),
    };
    (sink, kept)
}

#[test]
fn resumed_runs_equal_uninterrupted_ones() {
    let (s, m) = office();
    // The hybrid with its default switch (counted work): it resumes exactly too.
    for method in [
        MethodKind::AdaptiveRays,
        MethodKind::AdaptiveHemicube,
        MethodKind::AdaptiveHybrid,
    ] {
        let base = SolveSettings {
            method,
            tolerance: 0.03,
            ..SolveSettings::default()
        };
        let plain = run(&s, &m, &base);
        let (sink, kept) = recording_sink();
        let with = run_with(
            &s,
            &m,
            &base,
            &RunHooks {
                checkpoint: Some(sink),
                ..RunHooks::default()
            },
        );
        // Checkpointing does not change the run.
        assert_eq!(with.b, plain.b, "{}", method.name());
        let snaps = kept.lock().unwrap().clone();
        assert!(
            snaps.len() >= 3,
            "{}: {} safe points",
            method.name(),
            snaps.len()
        );
        // Resume from a safe point in the middle, through the file format.
        let mid = &snaps[snaps.len() / 2];
        let bytes = radiosity::solve::checkpoint::to_bytes("test", mid);
        let snap = Checkpoint::from_bytes("mid", &bytes).unwrap();
        assert!(snap.run.shots > 0);
        assert_eq!(snap.key, "test", "the key is in the file");
        let resumed = run_with(
            &s,
            &m,
            &base,
            &RunHooks {
                resume: Some(Arc::new(snap.run)),
                ..RunHooks::default()
            },
        );
        assert_eq!(resumed.b, plain.b, "{}", method.name());
        assert_eq!(resumed.stats.shots, plain.stats.shots);
        assert_eq!(resumed.stats.rays, plain.stats.rays);
        let switch = |s: &Solution| s.stats.switch.map(|w| (w.shot, w.rays, w.forced));
        assert_eq!(switch(&resumed), switch(&plain), "{}", method.name());
        assert_eq!(switch(&with), switch(&plain), "{}", method.name());
    }
}

#[test]
fn an_interrupt_stops_at_a_safe_point_with_a_checkpoint() {
    let (s, m) = office();
    // No final gather: the shooting runs to Sec. 3's stop, well past the third safe point.
    let base = SolveSettings {
        method: MethodKind::AdaptiveRays,
        tolerance: 0.03,
        final_gather: false,
        ..SolveSettings::default()
    };
    let plain = run(&s, &m, &base);
    let flag = Arc::new(AtomicBool::new(false));
    let kept = Arc::new(Mutex::new(Vec::new()));
    let (k, f) = (kept.clone(), flag.clone());
    let sink = Sink {
        every: Duration::ZERO,
        write: Arc::new(move |snap: &Saved| {
            let mut v = k.lock().unwrap();
            v.push(snap.clone());
            // "Ctrl-C" after the third safe point.
            if v.len() == 3 {
                f.store(true, Ordering::SeqCst);
            }
            Ok(())
        }),
    };
    let stopped = run_with(
        &s,
        &m,
        &base,
        &RunHooks {
            checkpoint: Some(sink),
            interrupt: Some(flag),
            ..RunHooks::default()
        },
    );
    assert_eq!(stopped.stats.stop_reason, Some(StopReason::Interrupted));
    assert!(stopped.stats.energy.relative_residual() < 1e-9);
    let last = kept.lock().unwrap().last().unwrap().clone();
    let resumed = run_with(
        &s,
        &m,
        &base,
        &RunHooks {
            resume: Some(Arc::new(last)),
            ..RunHooks::default()
        },
    );
    assert_eq!(resumed.b, plain.b);
}

#[test]
fn command_line_checkpoints_and_refusals() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).display().to_string();
    let blocks = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/blocks.obj");
    let blocks = blocks.to_str().unwrap();
    let (code, _, err) = common::run(&[
        "solve",
        blocks,
        "--method",
        "adaptive-rays",
        "--checkpoint",
        &p("c.ckpt"),
        "--out",
        &p("a"),
        "--quiet",
    ]);
    assert_eq!(code, 0, "{err}");
    let bytes = std::fs::read(p("c.ckpt")).unwrap();
    // Resuming the finished run's checkpoint finishes at once, with the same table.
    let (code, _, err) = common::run(&[
        "solve",
        blocks,
        "--method",
        "adaptive-rays",
        "--resume",
        &p("c.ckpt"),
        "--out",
        &p("b"),
        "--quiet",
    ]);
    assert_eq!(code, 0, "{err}");
    // Another seed, another scene, a truncated or a foreign file: refused, exit 2.
    let refuse = |args: &[&str], needle: &str| {
        let (code, _, err) = common::run(args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: '{needle}' not in {err}");
        assert!(!err.contains("panicked"));
    };
    refuse(
        &[
            "solve",
            blocks,
            "--method",
            "adaptive-rays",
            "--seed",
            "9",
            "--resume",
            &p("c.ckpt"),
            "--out",
            &p("c"),
        ],
        "another run",
    );
    refuse(
        &[
            "solve",
            "--method",
            "adaptive-rays",
            "--resume",
            &p("c.ckpt"),
            "--out",
            &p("d"),
        ],
        "another run",
    );
    std::fs::write(p("short.ckpt"), &bytes[..bytes.len() / 2]).unwrap();
    refuse(
        &[
            "solve",
            blocks,
            "--method",
            "adaptive-rays",
            "--resume",
            &p("short.ckpt"),
            "--out",
            &p("e"),
        ],
        "truncated",
    );
    std::fs::write(p("junk.ckpt"), b"this is not a checkpoint at all").unwrap();
    refuse(
        &[
            "solve",
            blocks,
            "--resume",
            &p("junk.ckpt"),
            "--out",
            &p("f"),
        ],
        "not a radiosity checkpoint",
    );
    refuse(
        &[
            "solve",
            blocks,
            "--method",
            "gathering",
            "--checkpoint",
            &p("g.ckpt"),
            "--out",
            &p("g"),
        ],
        "gathering",
    );
}

/// The checkpoint key is derived from every setting that shapes the result (docs/design.md
/// §6): a setting added to the settings types reaches it without being listed. `--switch-by` (added
/// after the key stopped being written by hand) is in it; the budgets are not, so a run may be
/// resumed with more time.
#[test]
fn the_checkpoint_key_holds_every_shaping_setting_and_no_budget() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).display().to_string();
    let blocks = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/blocks.obj");
    let blocks = blocks.to_str().unwrap();
    let solve = |extra: &[&str], out: &str| {
        let o = p(out);
        let mut args = vec!["solve", blocks, "--quiet", "--out", o.as_str()];
        args.extend_from_slice(extra);
        common::run(&args)
    };
    let ckpt = p("h.ckpt");
    let (code, _, err) = solve(&["--checkpoint", &ckpt], "a");
    assert_eq!(code, 0, "{err}");
    let (code, _, err) = solve(&["--resume", &ckpt, "--switch-by", "measured"], "b");
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("another run"), "{err}");
    let (code, _, err) = solve(&["--resume", &ckpt, "--max-time", "100"], "c");
    assert_eq!(code, 0, "{err}");
    // The summary records the same settings, derived from the same type.
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(p("c/summary.json")).unwrap()).unwrap();
    assert_eq!(summary["settings"]["solve"]["switch_by"], "counted");
    assert_eq!(summary["settings"]["solve"]["max_time"], 100.0);
    assert_eq!(summary["settings"]["mesh"]["two_sided"], false);
}
