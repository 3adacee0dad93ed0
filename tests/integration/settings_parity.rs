//! The settings have no leaks, checked against the command line's own argument list (clap's
//! `Command`, walked here, so a new flag or command cannot be left out):
//!
//! - every flag of `solve` reaches the one settings type that the summary, the saved solution
//!   and the checkpoint key serialise ([`radiosity::pipeline::RunSettings`]), or is listed,
//!   with its reason, among the flags that do not shape the result;
//! - every command that takes a flag refuses the values `solve` refuses, with the same
//!   one-line message: the checks live once, in the library's settings types;
//! - the daylight flags are checked before the model is read.
//!
//! The command line is compiled here as a module (its modules name each other through
//! `super::`), so its flags parse into the same jobs as the binary's, without running them.
use crate::common;

#[allow(dead_code, unused_imports)]
#[path = "../../src/bin/radiosity/main.rs"]
mod cli;

use clap::{CommandFactory, Parser};
use common::*;
use std::collections::BTreeSet;

/// Bad settings, each with the commands that take its flags besides `solve` (checked against
/// clap's list: a command that gains the flag must be added here, and refuse it alike).
const BAD: &[(&[&str], &[&str])] = &[
    (&["--grid-outdoor", "maybe"], &["annual"]),
    (
        &["--tolerance", "5"],
        &[
            "annual",
            "sweep",
            "bench-shots",
            "bench-rays",
            "bench-elements",
            "compare",
            "reference",
        ],
    ),
    (
        &["--tolerance", "0"],
        &[
            "annual",
            "sweep",
            "bench-shots",
            "bench-rays",
            "bench-elements",
            "compare",
            "reference",
        ],
    ),
    (
        &["--stop", "-1"],
        &[
            "annual",
            "sweep",
            "bench-shots",
            "bench-rays",
            "bench-elements",
            "compare",
            "reference",
        ],
    ),
    (
        &["--energy-per-ray", "-2"],
        &[
            "annual",
            "sweep",
            "bench-shots",
            "bench-rays",
            "bench-elements",
            "compare",
            "reference",
        ],
    ),
    (
        &["--hemicube-n", "1"],
        &[
            "annual",
            "sweep",
            "bench-shots",
            "bench-rays",
            "bench-elements",
            "compare",
            "reference",
        ],
    ),
    (
        &["--gather-rays", "1"],
        &[
            "annual",
            "sweep",
            "bench-shots",
            "bench-rays",
            "bench-elements",
            "compare",
            "reference",
        ],
    ),
    (
        &["--max-time", "0"],
        &[
            "annual",
            "sweep",
            "bench-shots",
            "bench-rays",
            "bench-elements",
        ],
    ),
    (
        &["--max-rays", "0"],
        &[
            "annual",
            "sweep",
            "bench-shots",
            "bench-rays",
            "bench-elements",
        ],
    ),
    (
        &["--error", "2"],
        &[
            "annual",
            "sweep",
            "bench-shots",
            "bench-rays",
            "bench-elements",
        ],
    ),
    (
        &["--method", "adaptive-rays", "--switch-at", "3"],
        &[
            "annual",
            "sweep",
            "bench-shots",
            "bench-rays",
            "bench-elements",
        ],
    ),
    (
        &["--patch-size", "-1"],
        &[
            "annual",
            "bench-shots",
            "bench-rays",
            "bench-elements",
            "bench-intersect",
            "bench-timing",
            "compare",
            "reference",
            "info",
            "crosscheck",
        ],
    ),
    (
        &["--patch-size", "nan"],
        &[
            "annual",
            "bench-shots",
            "bench-rays",
            "bench-elements",
            "bench-intersect",
            "bench-timing",
            "compare",
            "reference",
            "info",
            "crosscheck",
        ],
    ),
];

/// The command line of `cmd` with `extra` flags, writing into `dir`.
fn line(cmd: &str, extra: &[&str], dir: &str) -> Vec<String> {
    let base: Vec<String> = match cmd {
        "solve" => vec![
            "solve".into(),
            "-q".into(),
            "--out".into(),
            format!("{dir}/solve"),
        ],
        "sweep" => vec![
            "sweep".into(),
            "--sizes".into(),
            "1k".into(),
            "--out".into(),
            format!("{dir}/sweep"),
        ],
        "bench-shots" => vec!["bench".into(), "shots".into()],
        "bench-elements" => vec!["bench".into(), "elements".into()],
        "bench-timing" => vec!["bench".into(), "timing".into()],
        "bench-intersect" => vec![
            "bench".into(),
            "intersect".into(),
            "--generated".into(),
            "none".into(),
        ],
        "bench-rays" => vec![
            "bench".into(),
            "rays".into(),
            "--min-seconds".into(),
            "0".into(),
        ],
        "compare" => vec![
            "compare".into(),
            "--budget".into(),
            "1".into(),
            "--out".into(),
            format!("{dir}/compare"),
        ],
        "reference" => vec![
            "reference".into(),
            "--out".into(),
            format!("{dir}/reference"),
        ],
        "info" => vec!["info".into()],
        "annual" => vec![
            "annual".into(),
            "scenes/office.obj".into(),
            "--weather".into(),
            format!("{dir}/none.wea"),
            "--grid".into(),
            "0.8,1".into(),
            "-q".into(),
            "--out".into(),
            format!("{dir}/annual"),
        ],
        "crosscheck" => vec!["crosscheck".into(), "--rays".into(), "1000".into()],
        other => panic!("{other} takes a flag of the table: give it a command line here"),
    };
    base.into_iter()
        .chain(extra.iter().map(|s| s.to_string()))
        .collect()
}

/// The long flags of the command at `path` (`["bench", "shots"]`), help and version aside.
fn flags_of(path: &[&str]) -> BTreeSet<String> {
    let mut cmd = cli::Cli::command();
    for name in path {
        cmd = cmd
            .find_subcommand(name)
            .unwrap_or_else(|| panic!("no command {path:?}"))
            .clone();
    }
    cmd.get_arguments()
        .filter_map(|a| a.get_long())
        .filter(|l| !matches!(*l, "help" | "version"))
        .map(str::to_string)
        .collect()
}

/// Every command and subcommand, as the words that name it (`["bench", "shots"]`).
fn commands() -> Vec<Vec<String>> {
    fn walk(cmd: &clap::Command, path: Vec<String>, out: &mut Vec<Vec<String>>) {
        if cmd.has_subcommands() {
            for sub in cmd.get_subcommands() {
                let mut p = path.clone();
                p.push(sub.get_name().to_string());
                walk(sub, p, out);
            }
        } else {
            out.push(path);
        }
    }
    let mut out = Vec::new();
    walk(&cli::Cli::command(), Vec::new(), &mut out);
    out
}

#[test]
fn every_command_refuses_what_solve_refuses_in_the_same_words() {
    let t = tempfile::tempdir().unwrap();
    let dir = t.path().to_str().unwrap();
    let all = commands();
    for (flags, _) in BAD {
        let solve = line("solve", flags, dir);
        let args: Vec<&str> = solve.iter().map(String::as_str).collect();
        let (code, _, err) = run(&args);
        assert_eq!(code, 2, "solve {flags:?}: {err}");
        assert_eq!(err.lines().count(), 1, "solve {flags:?}: {err}");
        assert!(
            err.contains(flags[flags.len() - 2]),
            "solve {flags:?}: {err}"
        );
        // Every command that takes these flags, by clap's own list.
        let names: Vec<&str> = flags.iter().filter_map(|f| f.strip_prefix("--")).collect();
        let mut takers = Vec::new();
        for path in &all {
            let p: Vec<&str> = path.iter().map(String::as_str).collect();
            let have = flags_of(&p);
            if p != ["solve"] && names.iter().all(|n| have.contains(*n)) {
                takers.push(p.join("-"));
            }
        }
        for cmd in &takers {
            let l = line(cmd, flags, dir);
            let args: Vec<&str> = l.iter().map(String::as_str).collect();
            let (code, _, other) = run(&args);
            assert_eq!(code, 2, "{cmd} {flags:?}: {other}");
            assert_eq!(
                other, err,
                "{cmd} {flags:?}: the message differs from solve's"
            );
        }
        // The table's list is what clap says (kept as the reader's index).
        let listed: BTreeSet<String> = BAD
            .iter()
            .find(|(f, _)| f == flags)
            .unwrap()
            .1
            .iter()
            .map(|s| s.to_string())
            .collect();
        assert_eq!(
            takers.iter().cloned().collect::<BTreeSet<_>>(),
            listed,
            "{flags:?}: the commands that take these flags"
        );
    }
    // Nothing was left behind by the refused runs.
    assert_eq!(std::fs::read_dir(t.path()).unwrap().count(), 0);
}

/// The flags whose default depends on the command (`reference` solves finer) show it in their
/// help; the text must name the library's constants, not drift from them.
#[test]
fn help_names_the_library_defaults() {
    use radiosity::solve::settings::*;
    let (code, help, _) = run(&["solve", "--help"]);
    assert_eq!(code, 0);
    let help = help.split_whitespace().collect::<Vec<_>>().join(" ");
    for needle in [
        format!("[default: {DEFAULT_TOLERANCE}; reference: {REFERENCE_TOLERANCE}]"),
        format!("first pass at {TARGET_TOLERANCE}× the error target"),
        format!("[default: {DEFAULT_STOP}; reference: {REFERENCE_STOP:e}]"),
        format!("[default: {DEFAULT_SEED}]"),
        format!("[default: {DEFAULT_HEMICUBE_N}]"),
        format!("[default: {DEFAULT_GATHER_CAP_MIB}]"),
        format!("[default: {DEFAULT_GATHER_RAYS}]"),
        format!(
            "[default: {}]",
            if DEFAULT_FINAL_GATHER { "on" } else { "off" }
        ),
    ] {
        assert!(help.contains(&needle), "solve --help lacks {needle}");
    }
}

/// A solve flag that shapes the result, with a value other than its default, and the flags
/// it needs beside it (both runs have them).
struct Shaping {
    flag: &'static str,
    value: &'static [&'static str],
    base: &'static [&'static str],
}

const fn shaping(
    flag: &'static str,
    value: &'static [&'static str],
    base: &'static [&'static str],
) -> Shaping {
    Shaping { flag, value, base }
}

const SKY: &[&str] = &["--sky", "overcast"];
const SUN: &[&str] = &["--sky", "overcast", "--sun", "30,20"];
const SITE: &[&str] = &[
    "--sky",
    "overcast",
    "--sun",
    "2026-06-21T12:00+02:00",
    "--site",
    "45,7",
];

/// Every flag of `solve` that shapes the result: each must change the settings the summary and
/// the saved solution hold, and (but for [`NOT_IN_KEY`]) the checkpoint key.
const SHAPING: &[Shaping] = &[
    shaping("emit", &["--emit", "light=1,2,3"], &[]),
    shaping("patch-size", &["--patch-size", "0.5"], &[]),
    shaping("two-sided", &["--two-sided"], &[]),
    shaping("one-sided", &["--one-sided"], &[]),
    shaping("uniform-patches", &["--uniform-patches"], &[]),
    shaping("flip", &["--flip"], &[]),
    shaping("luminaires", &["--luminaires", "lamps.csv"], &[]),
    shaping("scale", &["--scale", "0.5"], &[]),
    shaping("seed", &["--seed", "7"], &[]),
    shaping("tolerance", &["--tolerance", "0.08"], &[]),
    shaping("energy-per-ray", &["--energy-per-ray", "0.5"], &[]),
    shaping("stop", &["--stop", "0.001"], &[]),
    shaping("polar-centres", &["--polar-centres"], &[]),
    shaping("hemicube-n", &["--hemicube-n", "50"], &[]),
    shaping("gather-cap-mib", &["--gather-cap-mib", "100"], &[]),
    shaping("intersector", &["--intersector", "embree"], &[]),
    shaping("final-gather", &["--final-gather", "off"], &[]),
    shaping("gather-rays", &["--gather-rays", "64"], &[]),
    shaping("max-time", &["--max-time", "5"], &[]),
    shaping("max-rays", &["--max-rays", "1000"], &[]),
    shaping("error", &["--error", "0.02"], &[]),
    shaping("method", &["--method", "adaptive-rays"], &[]),
    shaping("switch-at", &["--switch-at", "3"], &[]),
    shaping("switch-by", &["--switch-by", "measured"], &[]),
    shaping("sky", &["--sky", "uniform"], &[]),
    shaping("sky-illuminance", &["--sky-illuminance", "5000"], SKY),
    shaping("zenith-luminance", &["--zenith-luminance", "3000"], SKY),
    shaping("sun", &["--sun", "40,10"], SKY),
    shaping("site", &["--site", "40,7"], SITE),
    shaping("sun-illuminance", &["--sun-illuminance", "50000"], SUN),
    shaping("ground-reflectance", &["--ground-reflectance", "0.3"], SKY),
    shaping("zenith", &["--zenith", "0,0,1"], SKY),
    shaping("north", &["--north", "1,0,0"], SKY),
    shaping("elements", &["--elements", "off"], &[]),
    shaping("element-threshold", &["--element-threshold", "0.5"], &[]),
    shaping("element-min-size", &["--element-min-size", "0.01"], &[]),
    shaping("element-rays", &["--element-rays", "16"], &[]),
    shaping("element-max", &["--element-max", "16"], &[]),
    shaping("element-test", &["--element-test", "corners"], &[]),
    shaping("element-light", &["--element-light", "direct"], &[]),
    shaping("per-light", &["--per-light"], &[]),
    shaping(
        "light-groups",
        &["--light-groups", "connected"],
        &["--per-light"],
    ),
];

/// Shaping flags the checkpoint key leaves out on purpose
/// ([`radiosity::pipeline::RunSettings::checkpoint_key`]): the budgets and the gathering cap
/// (a run may be resumed with more time), and the elements (refined after the solve, from
/// its result).
const NOT_IN_KEY: &[&str] = &[
    "max-time",
    "max-rays",
    "gather-cap-mib",
    "elements",
    "element-threshold",
    "element-min-size",
    "element-rays",
    "element-max",
    "element-test",
    "element-light",
];

/// The flags of `solve` that do not shape the patch radiosities, and why.
const NOT_SHAPING: &[(&str, &str)] = &[
    ("threads", "results do not depend on the thread count"),
    ("out", "where the outputs go"),
    ("reference", "a table to measure the error against"),
    ("quiet", "what is printed"),
    ("json", "what is printed"),
    ("save", "where the solution is saved"),
    ("checkpoint", "where the solver's state is saved"),
    ("checkpoint-every", "when the solver's state is saved"),
    ("resume", "where a run starts from, checked against the key"),
    (
        "grid",
        "sensors measured on the solution (the summary's `grid`)",
    ),
    ("grid-rays", "the sensors' rays (the summary's `grid`)"),
    (
        "grid-outdoor",
        "which sensors are measured (the summary's `grid`)",
    ),
    ("view", "the picture's camera"),
    ("eye", "the picture's camera"),
    ("target", "the picture's camera"),
    ("up", "the picture's camera"),
    ("fov", "the picture's camera"),
    ("near", "the picture's camera"),
    ("width", "the picture's size"),
    ("height", "the picture's size"),
    ("supersample", "the picture's anti-aliasing"),
    ("exposure", "the picture's exposure"),
    ("shading", "how the picture is shaded"),
    ("pixel-rays", "how the picture is shaded"),
    ("indirect-spacing", "how the picture is shaded"),
];

/// `radiosity solve` with `args` parsed into its job, as the binary does (nothing is run).
fn solve_job(args: &[&str]) -> radiosity::pipeline::SolveJob {
    let line = ["radiosity", "solve"].iter().chain(args);
    let cli = cli::Cli::try_parse_from(line).unwrap_or_else(|e| panic!("{args:?}: {e}"));
    let cli::Command::Solve(a) = cli.command else {
        unreachable!()
    };
    let job = a.job().unwrap_or_else(|e| panic!("{args:?}: {e}"));
    job.check().unwrap_or_else(|e| panic!("{args:?}: {e}"));
    job
}

/// The summary's (and the saved solution's) settings, and the checkpoint key.
fn recorded(job: &radiosity::pipeline::SolveJob) -> (serde_json::Value, String) {
    let s = &job.settings;
    let key = s.checkpoint_key(0, s.mesh.patch_size.unwrap_or(0.25));
    (s.to_json(), key)
}

#[test]
fn every_solve_flag_reaches_the_recorded_settings_or_says_why_not() {
    let flags = flags_of(&["solve"]);
    let mut listed: BTreeSet<String> = SHAPING.iter().map(|s| s.flag.to_string()).collect();
    for (f, _) in NOT_SHAPING {
        assert!(listed.insert(f.to_string()), "--{f} is listed twice");
    }
    let global = flags_of(&[]);
    let flags: BTreeSet<String> = flags.union(&global).cloned().collect();
    assert_eq!(
        flags.difference(&listed).collect::<Vec<_>>(),
        Vec::<&String>::new(),
        "flags of solve in neither SHAPING nor NOT_SHAPING: list each with a value or a reason"
    );
    assert_eq!(
        listed.difference(&flags).collect::<Vec<_>>(),
        Vec::<&String>::new(),
        "listed flags that solve does not have"
    );
    for s in SHAPING {
        assert_eq!(s.value[0], format!("--{}", s.flag));
        let (base_json, base_key) = recorded(&solve_job(s.base));
        // The value added to the base, or put in place of the base's own.
        let mut with: Vec<&str> = Vec::new();
        let mut base = s.base.iter();
        while let Some(a) = base.next() {
            if *a == s.value[0] {
                base.next();
            } else {
                with.push(a);
            }
        }
        with.extend(s.value);
        let (json, key) = recorded(&solve_job(&with));
        assert_ne!(json, base_json, "{:?} does not reach the settings", s.value);
        if NOT_IN_KEY.contains(&s.flag) {
            assert_eq!(key, base_key, "{:?} is in the checkpoint key", s.value);
        } else {
            assert_ne!(key, base_key, "{:?} is not in the checkpoint key", s.value);
        }
    }
}

/// Every bad daylight setting is refused before the model is read: the model named does not
/// exist, and the error is the sky's, one line, exit code 2.
#[test]
fn bad_sky_settings_are_refused_before_the_model_is_read() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("out").display().to_string();
    let missing = t.path().join("missing.obj").display().to_string();
    let bad: &[(&[&str], &str)] = &[
        (&["--sun", "30,20"], "--sun needs --sky"),
        (&["--sky", "overcast", "--zenith", "0,0,0"], "--zenith"),
        (&["--zenith", "0,0,0"], "--zenith"),
        (&["--sky", "overcast", "--north", "0,1,0"], "--north"),
        (&["--sky", "clear"], "--sky"),
        (&["--sky", "overcast", "--sun", "95,0"], "--sun"),
        (
            &["--sky", "overcast", "--sun", "2026-06-21T12:00+02:00"],
            "--site",
        ),
        (
            &[
                "--sky",
                "overcast",
                "--sun",
                "2026-06-21T12:00+02:00",
                "--site",
                "95,0",
            ],
            "--site",
        ),
        (
            &[
                "--sky",
                "overcast",
                "--sun",
                "2026-02-30T12:00+02:00",
                "--site",
                "45,7",
            ],
            "--sun",
        ),
        (
            &["--sky", "overcast", "--ground-reflectance", "1.5"],
            "--ground-reflectance",
        ),
        (
            &["--sky", "overcast", "--sky-illuminance", "-1"],
            "--sky-illuminance",
        ),
        (
            &["--sky", "overcast", "--zenith-luminance", "-1"],
            "--zenith-luminance",
        ),
        (
            &[
                "--sky",
                "overcast",
                "--sun",
                "30,20",
                "--sun-illuminance",
                "-1",
            ],
            "--sun-illuminance",
        ),
        (&["--sky", "overcast", "--method", "hemicube"], "--sky"),
        (&["--grid", "0.8,1", "--method", "hemicube"], "--grid"),
    ];
    for (flags, needle) in bad {
        let args: Vec<&str> = ["solve", missing.as_str(), "--out", out.as_str()]
            .iter()
            .chain(flags.iter())
            .copied()
            .collect();
        let (code, _, err) = run(&args);
        assert_eq!(code, 2, "{flags:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{flags:?}: {err}");
        assert!(err.contains(needle), "{flags:?}: {err}");
        assert!(
            !err.contains("missing.obj"),
            "{flags:?}: the model was read first: {err}"
        );
    }
    assert!(!t.path().join("out").exists(), "nothing is written");
}

/// A Z-up model (Radiance's and most CAD tools' convention): `--zenith 0,0,1` alone gives north
/// +Y, under a sky and for the sensor grid without one.
#[test]
fn a_z_up_model_needs_no_north() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).display().to_string();
    // A floor facing +Z open to the sky, and a closed room with a lamp on its floor.
    std::fs::write(
        p("roof.obj"),
        "mtllib roof.mtl\nv 0 0 0\nv 4 0 0\nv 4 4 0\nv 0 4 0\nusemtl grey\nf 1 2 3 4\n",
    )
    .unwrap();
    std::fs::write(p("roof.mtl"), "newmtl grey\nKd 0.5 0.5 0.5\n").unwrap();
    let (code, _, err) = run(&[
        "solve",
        &p("roof.obj"),
        "--sky",
        "overcast",
        "--zenith",
        "0,0,1",
        "--out",
        &p("sky"),
        "--quiet",
    ]);
    assert_eq!(code, 0, "{err}");
    let summary: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("sky/summary.json")).unwrap(),
    )
    .unwrap();
    let sky = &summary["settings"]["solve"]["sky"];
    assert_eq!(sky["zenith"], serde_json::json!([0.0, 0.0, 1.0]));
    assert_eq!(sky["north"], serde_json::json!([0.0, 1.0, 0.0]));

    std::fs::write(
        p("room.obj"),
        "mtllib room.mtl\n\
         v 0 0 0\nv 4 0 0\nv 4 4 0\nv 0 4 0\nv 0 0 3\nv 4 0 3\nv 4 4 3\nv 0 4 3\n\
         usemtl floor\nf 1 2 3 4\nusemtl wall\nf 1 5 6 2\nf 2 6 7 3\nf 3 7 8 4\nf 4 8 5 1\n\
         usemtl lamp\nf 5 8 7 6\n",
    )
    .unwrap();
    std::fs::write(
        p("room.mtl"),
        "newmtl floor\nKd 0.3 0.3 0.3\nnewmtl wall\nKd 0.5 0.5 0.5\nnewmtl lamp\nKd 0.5 0.5 0.5\nKe 1 1 1\n",
    )
    .unwrap();
    let (code, _, err) = run(&[
        "solve",
        &p("room.obj"),
        "--grid",
        "0.8,1",
        "--zenith",
        "0,0,1",
        "--out",
        &p("grid"),
        "--quiet",
    ]);
    assert_eq!(code, 0, "{err}");
    let csv = std::fs::read_to_string(dir.path().join("grid/grid.csv")).unwrap();
    let rows: Vec<Vec<f64>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 16, "a 4 × 4 lattice on the floor: {csv}");
    for r in &rows {
        assert!((r[2] - 0.8).abs() < 1e-4 && r[5] == 1.0, "{r:?}");
        assert!(r[6] > 0.0, "{r:?}");
    }
    // North +Y: the first row is the northmost (y = 3.5), from west (x = 0.5) to east.
    assert!(
        (rows[0][1] - 3.5).abs() < 1e-4 && (rows[0][0] - 0.5).abs() < 1e-4,
        "{rows:?}"
    );
    assert!((rows[1][0] - 1.5).abs() < 1e-4, "{rows:?}");
}
