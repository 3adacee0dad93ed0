//! Every command that solves refuses the settings `solve` refuses, with the same one-line
//! message (issue 12): the checks live once, in the library's settings types.

use crate::common::*;

/// Bad settings, each with the commands that take its flag besides `solve`.
const BAD: &[(&[&str], &[&str])] = &[
    (
        &["--tolerance", "5"],
        &["sweep", "bench-shots", "bench-rays", "compare", "reference"],
    ),
    (
        &["--tolerance", "0"],
        &["sweep", "bench-shots", "bench-rays", "compare", "reference"],
    ),
    (
        &["--stop", "-1"],
        &["sweep", "bench-shots", "bench-rays", "compare", "reference"],
    ),
    (
        &["--energy-per-ray", "-2"],
        &["sweep", "bench-shots", "bench-rays", "compare", "reference"],
    ),
    (
        &["--hemicube-n", "1"],
        &["sweep", "bench-shots", "bench-rays", "compare", "reference"],
    ),
    (
        &["--gather-rays", "1"],
        &["sweep", "bench-shots", "bench-rays", "compare", "reference"],
    ),
    (
        &["--max-time", "0"],
        &["sweep", "bench-shots", "bench-rays"],
    ),
    (
        &["--max-rays", "0"],
        &["sweep", "bench-shots", "bench-rays"],
    ),
    (&["--error", "2"], &["sweep", "bench-shots", "bench-rays"]),
    (
        &["--method", "adaptive-rays", "--switch-at", "3"],
        &["sweep", "bench-shots", "bench-rays"],
    ),
    (
        &["--patch-size", "-1"],
        &[
            "bench-shots",
            "bench-rays",
            "compare",
            "reference",
            "info",
            "crosscheck",
        ],
    ),
    (
        &["--patch-size", "nan"],
        &[
            "bench-shots",
            "bench-rays",
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
        "crosscheck" => vec!["crosscheck".into(), "--rays".into(), "1000".into()],
        other => panic!("unknown command {other}"),
    };
    base.into_iter()
        .chain(extra.iter().map(|s| s.to_string()))
        .collect()
}

#[test]
fn every_command_refuses_what_solve_refuses_in_the_same_words() {
    let t = tempfile::tempdir().unwrap();
    let dir = t.path().to_str().unwrap();
    for (flags, commands) in BAD {
        let solve = line("solve", flags, dir);
        let args: Vec<&str> = solve.iter().map(String::as_str).collect();
        let (code, _, err) = run(&args);
        assert_eq!(code, 2, "solve {flags:?}: {err}");
        assert_eq!(err.lines().count(), 1, "solve {flags:?}: {err}");
        assert!(
            err.contains(flags[flags.len() - 2]),
            "solve {flags:?}: {err}"
        );
        for cmd in *commands {
            let l = line(cmd, flags, dir);
            let args: Vec<&str> = l.iter().map(String::as_str).collect();
            let (code, _, other) = run(&args);
            assert_eq!(code, 2, "{cmd} {flags:?}: {other}");
            assert_eq!(
                other, err,
                "{cmd} {flags:?}: the message differs from solve's"
            );
        }
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
