//! Progress on the terminal: one bar per phase of a run (loading, meshing, building the
//! intersectors, solving, writing), through `indicatif`.
//!
//! The solve's bar shows the fraction of the emitted energy already shot,
//! 1 − unshot flux / emitted flux, from the solver's per-wave callback, with an ETA: that is
//! the quantity progressive refinement drives to zero (the stop criterion, Sec. 3, is close to
//! its end). Bars are drawn only when enabled — not `--quiet`, and standard error is a
//! terminal — so logs and pipes never see control characters. Messages printed while a bar is
//! up go through [`Progress::println`], which lifts the bar around them.

use crate::solve::TracePoint;
use indicatif::{ProgressBar, ProgressStyle};
use std::cell::{Cell, RefCell};
use std::io::IsTerminal;
use std::time::Duration;

/// Steps of the solve bar (fraction shot × STEPS).
const STEPS: u64 = 1000;

/// The bars of one run. Methods take `&self`, so a log callback and the pipeline can share it.
pub struct Progress {
    enabled: bool,
    bar: RefCell<Option<ProgressBar>>,
    /// Emitted flux (scalar W) the solve bar measures against.
    emitted: Cell<f64>,
}

impl Progress {
    /// Bars when `enabled`, nothing otherwise.
    pub fn new(enabled: bool) -> Progress {
        Progress {
            enabled,
            bar: RefCell::new(None),
            emitted: Cell::new(0.0),
        }
    }

    /// No bars.
    pub fn hidden() -> Progress {
        Progress::new(false)
    }

    /// Bars unless `quiet`, and only when standard error is a terminal.
    pub fn for_terminal(quiet: bool) -> Progress {
        Progress::new(!quiet && std::io::stderr().is_terminal())
    }

    pub fn is_enabled(&self) -> bool {
        self.enabled
    }

    /// Ends the current bar and starts a spinner for the phase `what` (e.g. "meshing").
    pub fn phase(&self, what: &str) {
        if !self.enabled {
            return;
        }
        let pb = ProgressBar::new_spinner();
        pb.set_style(
            ProgressStyle::with_template("{spinner} {msg} {elapsed}")
                .unwrap_or_else(|_| ProgressStyle::default_spinner()),
        );
        pb.set_message(what.to_string());
        pb.enable_steady_tick(Duration::from_millis(120));
        self.replace(Some(pb));
    }

    /// Starts the solve's bar; `emitted_flux` is the scalar flux the lights put out (W).
    pub fn start_solve(&self, emitted_flux: f64) {
        self.emitted.set(emitted_flux);
        if !self.enabled {
            return;
        }
        let pb = ProgressBar::new(STEPS);
        pb.set_style(
            ProgressStyle::with_template("solving [{bar:20}] {percent:>3}% shot, {msg}, eta {eta}")
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> "),
        );
        pb.enable_steady_tick(Duration::from_millis(250));
        self.replace(Some(pb));
    }

    /// One wave of the solve done: moves the bar to the fraction shot.
    pub fn solve_wave(&self, p: &TracePoint) {
        if !self.enabled {
            return;
        }
        let f = fraction_shot(p.unshot_flux, self.emitted.get());
        if let Some(pb) = &*self.bar.borrow() {
            pb.set_position((f * STEPS as f64) as u64);
            pb.set_message(format!("{} shots", p.shots));
        }
    }

    /// Starts a bar of `total` units of work done by many threads at once (the rows of a
    /// final-gather picture), labelled `what`; the [`Counter`] it returns is moved on from any
    /// thread. Hidden (a counter that does nothing) when bars are off.
    pub fn start_count(&self, what: &str, total: u64) -> Counter {
        if !self.enabled {
            return Counter(None);
        }
        let pb = ProgressBar::new(total);
        pb.set_style(
            ProgressStyle::with_template(&format!(
                "{what} [{{bar:20}}] {{percent:>3}}%, eta {{eta}}"
            ))
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
        );
        pb.enable_steady_tick(Duration::from_millis(250));
        self.replace(Some(pb.clone()));
        Counter(Some(pb))
    }

    /// Prints a line on standard error without tearing the bar.
    pub fn println(&self, line: &str) {
        match &*self.bar.borrow() {
            Some(pb) => pb.suspend(|| eprintln!("{line}")),
            None => eprintln!("{line}"),
        }
    }

    /// Clears the last bar.
    pub fn finish(&self) {
        self.replace(None);
    }

    fn replace(&self, next: Option<ProgressBar>) {
        if let Some(old) = self.bar.replace(next) {
            old.finish_and_clear();
        }
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.finish();
    }
}

/// Moves a [`Progress::start_count`] bar on; shared by the threads doing the work.
pub struct Counter(Option<ProgressBar>);

impl Counter {
    /// A counter without a bar.
    pub fn hidden() -> Counter {
        Counter(None)
    }

    /// `n` more units done.
    pub fn inc(&self, n: u64) {
        if let Some(pb) = &self.0 {
            pb.inc(n);
        }
    }
}

/// 1 − unshot / emitted, in [0, 1] (0 when nothing was emitted or a value is not finite).
pub fn fraction_shot(unshot_flux: f64, emitted_flux: f64) -> f64 {
    let f = 1.0 - unshot_flux / emitted_flux;
    if f.is_finite() && emitted_flux > 0.0 {
        f.clamp(0.0, 1.0)
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fraction_shot_is_bounded() {
        assert_eq!(fraction_shot(10.0, 10.0), 0.0);
        assert_eq!(fraction_shot(0.0, 10.0), 1.0);
        assert_eq!(fraction_shot(2.5, 10.0), 0.75);
        assert_eq!(fraction_shot(1.0, 0.0), 0.0);
        assert_eq!(fraction_shot(f64::NAN, 1.0), 0.0);
        // Clamped, whatever rounding does.
        assert_eq!(fraction_shot(12.0, 10.0), 0.0);
    }

    #[test]
    fn hidden_progress_does_nothing() {
        let p = Progress::hidden();
        p.phase("loading");
        p.start_solve(1.0);
        p.solve_wave(&TracePoint {
            time_s: 0.0,
            shots: 1,
            rays: 1,
            max_unshot_b: 0.0,
            mean_b: 0.0,
            unshot_flux: 0.5,
            ..TracePoint::default()
        });
        assert!(p.bar.borrow().is_none());
        let c = p.start_count("rendering", 10);
        c.inc(3);
        assert!(c.0.is_none() && p.bar.borrow().is_none());
    }
}
