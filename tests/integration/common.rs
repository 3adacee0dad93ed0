//! What the integration tests share besides their scenes (`scene_builder`): running the
//! `radiosity` binary and reading its error line, solving a mesh, and running on a thread pool.

use radiosity::scene::Scene;

/// The `radiosity` binary, without RUST_BACKTRACE (so a panic shows as the one-line "panicked"
/// the tests look for).
pub fn radiosity() -> assert_cmd::Command {
    let mut c = assert_cmd::Command::cargo_bin("radiosity").unwrap();
    c.env_remove("RUST_BACKTRACE");
    c
}

/// Runs the binary and returns (exit code, stdout, stderr).
pub fn run(args: &[&str]) -> (i32, String, String) {
    let out = radiosity().args(args).output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A user error: exit code 2, no panic, and an error line holding every needle.
pub fn assert_user_error(args: &[&str], needles: &[&str]) {
    let (code, _, err) = run(args);
    assert_eq!(code, 2, "args {args:?}: stderr {err}");
    assert!(!err.contains("panicked"), "panic: {err}");
    let line = err
        .lines()
        .find(|l| l.starts_with("Error:") || l.starts_with("error:"))
        .unwrap_or_else(|| panic!("no error line in {err}"));
    for n in needles {
        assert!(line.contains(n), "'{n}' not in error line '{line}'");
    }
}

/// Solves by `cfg.method`, building an Embree scene only for the methods that cast rays.
pub fn solve_mesh(
    scene: &Scene,
    m: &radiosity::mesh::Mesh,
    cfg: &radiosity::solve::SolveSettings,
) -> radiosity::solve::Solution {
    solve_mesh_with(scene, m, cfg, &Default::default())
}

/// [`solve_mesh`] with hooks (per-light channels, a reference, checkpoints).
pub fn solve_mesh_with(
    scene: &Scene,
    m: &radiosity::mesh::Mesh,
    cfg: &radiosity::solve::SolveSettings,
    hooks: &radiosity::solve::RunHooks,
) -> radiosity::solve::Solution {
    let isect = cfg
        .method
        .casts_rays()
        .then(|| radiosity::intersect::embree::EmbreeScene::build(m, |_| true).unwrap());
    radiosity::solve::run(m, &scene.materials, isect.as_ref(), cfg, hooks, |_| {}).unwrap()
}

/// Runs `f` on a pool of `threads` threads, or on rayon's global pool when `None`: what the
/// "same result on any thread count" tests compare.
pub fn on_threads<T: Send>(threads: Option<usize>, f: impl FnOnce() -> T + Send) -> T {
    match threads {
        None => f(),
        Some(t) => rayon::ThreadPoolBuilder::new()
            .num_threads(t)
            .build()
            .unwrap()
            .install(f),
    }
}
