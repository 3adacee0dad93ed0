//! `compare.csv` (every trace point of every method) and `compare.md` (the runs, the time each
//! method needs to reach given error levels, and the speedups of the first method at equal
//! error: the paper's Sec. 4 claims, measured).

use super::analysis::{self, time_to_error};
use super::{Comparison, MethodRun};
use crate::report::{plot, trace};
use crate::solve::MethodKind;
use crate::Error;
use std::fmt::Write as _;
use std::io::{self, Write};

/// Writes `compare.csv`: `method,` then the columns of `trace.csv`.
pub fn write_csv(w: &mut dyn Write, cmp: &Comparison) -> io::Result<()> {
    writeln!(w, "method,{}", trace::HEADER)?;
    for run in &cmp.runs {
        for p in &run.trace {
            write!(w, "{},", run.method.name())?;
            trace::write_row(w, p)?;
        }
    }
    Ok(())
}

/// Seconds with a sensible number of digits.
fn secs(t: f64) -> String {
    if t < 0.01 {
        format!("{t:.4} s")
    } else if t < 10.0 {
        format!("{t:.3} s")
    } else {
        format!("{t:.1} s")
    }
}

fn pct(x: f64) -> String {
    if x < 0.1 {
        format!("{:.3} %", 100.0 * x)
    } else {
        format!("{:.2} %", 100.0 * x)
    }
}

/// Fig. 2's decay constant of a run (None for gathering, which does not shoot).
pub fn decay_of(run: &MethodRun) -> Option<f64> {
    if run.method == MethodKind::Gathering {
        return None;
    }
    analysis::decay_constant(&analysis::decay_curve(&run.trace))
}

fn stop_name(run: &MethodRun) -> String {
    run.stop_reason
        .map(|r| {
            serde_json::to_value(r)
                .ok()
                .and_then(|v| v.as_str().map(str::to_string))
                .unwrap_or_default()
        })
        .unwrap_or_else(|| "—".into())
}

/// The time-to-error table and the speedups of the first method, for one metric.
fn level_tables(
    out: &mut String,
    cmp: &Comparison,
    metric: &str,
    series: impl Fn(&MethodRun) -> Vec<(f64, f64)>,
) {
    let names: Vec<&str> = cmp.runs.iter().map(|r| r.method.name()).collect();
    // Where a run never reaches a level, the end of its run bounds the speedup.
    let ends: Vec<f64> = cmp
        .runs
        .iter()
        .map(|r| series(r).last().map_or(r.seconds, |p| p.0))
        .collect();
    let times: Vec<Vec<Option<f64>>> = cmp
        .runs
        .iter()
        .map(|r| {
            let s = series(r);
            cmp.levels.iter().map(|&l| time_to_error(&s, l)).collect()
        })
        .collect();
    let _ = writeln!(out, "\n## Time to reach an {metric}\n");
    let _ = writeln!(out, "| {metric} | {} |", names.join(" | "));
    let _ = writeln!(out, "|---:|{}", "---:|".repeat(names.len()));
    for (k, &l) in cmp.levels.iter().enumerate() {
        let cells: Vec<String> = times
            .iter()
            .map(|t| t[k].map_or("not reached".into(), secs))
            .collect();
        let _ = writeln!(out, "| {} | {} |", pct(l), cells.join(" | "));
    }
    if cmp.runs.len() < 2 {
        return;
    }
    let _ = writeln!(
        out,
        "\n**Speedup of {} at equal {metric}** (the other method's time / its time; where one never reaches the level, the end of its run bounds the ratio):\n",
        names[0]
    );
    let _ = writeln!(
        out,
        "| {metric} | {} |",
        names[1..]
            .iter()
            .map(|n| format!("vs {n}"))
            .collect::<Vec<_>>()
            .join(" | ")
    );
    let _ = writeln!(out, "|---:|{}", "---:|".repeat(names.len() - 1));
    for (k, &l) in cmp.levels.iter().enumerate() {
        let cells: Vec<String> = times[1..]
            .iter()
            .zip(&ends[1..])
            .map(|(t, &end)| match (times[0][k], t[k]) {
                (Some(a), Some(b)) if a > 0.0 => format!("{:.1}×", b / a),
                (Some(a), None) if a > 0.0 => format!("> {:.1}× (never)", end / a),
                (None, Some(b)) if ends[0] > 0.0 => format!("< {:.1}×", b / ends[0]),
                _ => "—".into(),
            })
            .collect();
        let _ = writeln!(out, "| {} | {} |", pct(l), cells.join(" | "));
    }
}

/// `compare.md`.
pub fn markdown(cmp: &Comparison) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Methods compared on {}\n", cmp.scene);
    let _ = writeln!(
        s,
        "{} patches (patch size {} m), {} threads, intersector {}; budget {} per method, tolerance {}, stop at {} of the mean radiosity, uniform hemi-cube {}×{}.\n",
        cmp.patches,
        cmp.patch_size,
        cmp.threads,
        cmp.intersector,
        secs(cmp.budget_s),
        cmp.tolerance,
        cmp.stop_fraction,
        cmp.hemicube_n,
        cmp.hemicube_n
    );
    let _ = write!(s, "Reference: {}", cmp.reference_source);
    match &cmp.reference {
        Some(r) => {
            let _ = writeln!(
                s,
                ", adaptive rays at tolerance {} to stop {} ({} rays, {}). {}.",
                r.tolerance,
                r.stop_fraction,
                r.rays,
                secs(r.seconds),
                r.check_line()
            );
        }
        None => {
            let _ = writeln!(s, ".");
        }
    }
    let gathering = cmp
        .runs
        .iter()
        .find(|r| r.method == MethodKind::Gathering)
        .map(MethodRun::form_factors);
    let _ = writeln!(s, "\n## Runs\n");
    let _ = writeln!(
        s,
        "| method | time | stop | shots | shots / patches | rays | hemi-cube cells | form factors | form factors / gathering's | E (Fig. 2) | E^10: fall over 10 % of shots | energy error | weighted % error | RMS error |"
    );
    let _ = writeln!(
        s,
        "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for r in &cmp.runs {
        let decay = decay_of(r);
        let (energy, weighted, rms) =
            r.error.map_or(("—".into(), "—".into(), "—".into()), |e| {
                (pct(e.energy), pct(e.weighted_percent), pct(e.rms_relative))
            });
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {:.2} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            r.method.name(),
            secs(r.seconds),
            stop_name(r),
            r.shots,
            r.shots as f64 / cmp.patches.max(1) as f64,
            r.rays,
            r.cells,
            r.form_factors(),
            gathering.filter(|&g| g > 0).map_or("—".into(), |g| format!(
                "{:.2}",
                r.form_factors() as f64 / g as f64
            )),
            decay.map_or("—".into(), |e| format!("{e:.4}")),
            decay.map_or("—".into(), |e| format!("{:.3}", e.powi(10))),
            energy,
            weighted,
            rms
        );
    }
    let _ = writeln!(
        s,
        "\nE: max unshot radiosity ∝ E^p, p the percent of the run's shots, fitted past the first trace point (the lights' shots); the paper's Fig. 2: E = 0.87055, E^10 = 1/4. A run stopped by the budget has the percent of its own shots, not of a converged solve's. Gathering's shots are its hemi-cubes (one per patch); its form factors are its matrix's samples."
    );
    level_tables(&mut s, cmp, "average weighted percent error", |r| {
        analysis::weighted_percent_series(&r.trace)
    });
    level_tables(&mut s, cmp, "average energy error", |r| {
        analysis::energy_series(&r.trace)
    });
    s
}

fn shooters(cmp: &Comparison) -> impl Iterator<Item = &MethodRun> {
    cmp.runs
        .iter()
        .filter(|r| r.method != MethodKind::Gathering)
}

/// The three plots of a comparison (error against time, Fig. 2's decay, Fig. 5's cost per
/// shot), as (file name, PNG bytes).
pub fn plots(cmp: &Comparison) -> Result<Vec<(&'static str, Vec<u8>)>, Error> {
    let errors: Vec<plot::Curve> = cmp
        .runs
        .iter()
        .map(|r| plot::Curve {
            label: r.method.name().into(),
            points: analysis::weighted_percent_series(&r.trace)
                .into_iter()
                .map(|(t, e)| (t, 100.0 * e))
                .collect(),
        })
        .collect();
    let decay: Vec<plot::Curve> = shooters(cmp)
        .map(|r| plot::Curve {
            label: match decay_of(r) {
                Some(e) => format!("{} (E = {e:.4})", r.method.name()),
                None => r.method.name().into(),
            },
            points: analysis::decay_curve(&r.trace),
        })
        .collect();
    let cost: Vec<plot::Curve> = shooters(cmp)
        .map(|r| plot::Curve {
            label: r.method.name().into(),
            points: analysis::cost_per_shot(&r.trace),
        })
        .collect();
    Ok(vec![
        (
            "error_vs_time.png",
            plot::draw(
                &format!("{}: error against time", cmp.scene),
                "seconds",
                "average weighted percent error (%)",
                &errors,
                true,
            )?,
        ),
        (
            "decay.png",
            plot::draw(
                &format!("{}: max unshot radiosity (Fig. 2)", cmp.scene),
                "percent of shots",
                "max unshot / its start",
                &decay,
                false,
            )?,
        ),
        (
            "cost_per_shot.png",
            plot::draw(
                &format!("{}: cost per shot (Fig. 5)", cmp.scene),
                "percent of shots",
                "seconds per shot",
                &cost,
                false,
            )?,
        ),
    ])
}
