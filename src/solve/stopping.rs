//! Sec. 3 of Airey & Ouh-young (1989): when a shooting solve stops.
//!
//! "The refinement halted … at which point the maximum unshot radiosity was less than 0.06
//! percent of the mean radiosity value. Nothing further can be shown on a 24 bit frame
//! buffer." Here the unshot radiosity is weighed by what it will still add, all bounces
//! counted (`State::amplification` in `books`): in a stiff scene (ρ near 1) unshot light
//! is worth many times itself. Then the budgets (`max_time`, the one clock-dependent setting;
//! `max_rays`, counted samples) and the interrupt flag, which is read only at safe points so a
//! resumed run repeats the same shots.

use super::{SolveSettings, StopReason};

/// What the stop rule looks at, at the top of each step of the driver.
#[derive(Clone, Copy, Debug)]
pub(super) struct Progress {
    /// Ctrl-C was seen at the last safe point.
    pub interrupted: bool,
    /// Max unshot radiosity (scalar, W/m²), over the patches above the stop threshold.
    pub max_unshot_b: f64,
    /// What a unit of unshot radiosity will still add (`State::amplification` in `books`).
    pub amplification: f64,
    /// Area-weighted mean radiosity (scalar, W/m²).
    pub mean_b: f64,
    /// Seconds since the solve started (counting the run it resumed).
    pub elapsed: f64,
    /// Form-factor samples so far: rays (cast, applied or in flight) plus hemi-cube cells.
    pub samples: u64,
    /// The share of the emitted light not yet come to rest (unshot, or in flight).
    pub unshot_share: f64,
}

/// With a final gather to follow, the shooting stops once the light it still owes (unshot,
/// all bounces counted) is below this share of the emitted light, if Sec. 3's rule has not
/// stopped it before. The gather re-estimates every patch from the solution, which then lacks
/// only that share; Sec. 3's rule on the largest unshot *radiosity* goes on for the tail of
/// small patches holding little light each: on a million-patch building, 4.5 M of 9.8 M shots
/// after less than 0.1 % of the light was left, with the error estimate unchanged. 0.2 %
/// rather than the first 0.05 %: the gather reads each patch's B, which holds all the light
/// that reached the patch, so what is owed shows in it one bounce removed — on the 100 k-patch
/// building the signed error against the reference moved by 0.04 % of B (0.1 % at 0.5 %), for
/// 0.82 of the shots and 0.93 of the shooting's time at 1 M (docs/results/hot-queues.md).
pub const GATHER_OWED: f64 = 2e-3;

/// Whether [`GATHER_OWED`] applies: a final gather follows the shooting (`final_gather`, for
/// the methods that cast rays) and no sky lights the model. Under a sky most of the light
/// lands on the model's outside, so a share of all of it says little about the rooms inside:
/// there Sec. 3's rule alone, which looks patch by patch, decides.
fn gathered(cfg: &SolveSettings) -> bool {
    cfg.final_gather && cfg.method.casts_rays() && cfg.sky.is_none()
}

/// The verdict: `None` to go on. `has_unshot` says whether any unshot energy at all is left
/// (asked only when the criterion holds: converged, or exhausted).
pub(super) fn verdict(
    cfg: &SolveSettings,
    p: &Progress,
    has_unshot: impl FnOnce() -> bool,
) -> Option<StopReason> {
    if p.interrupted {
        Some(StopReason::Interrupted)
    } else if p.max_unshot_b * p.amplification < cfg.stop_fraction * p.mean_b
        || p.max_unshot_b <= 0.0
    {
        // (Nothing unshot above the threshold: also when nothing is lit at all, as inside a
        // closed box under a sky.)
        // The max-ΔB heap holds only patches above the threshold; whether any energy at all is
        // left, the flux heap says.
        if has_unshot() {
            Some(StopReason::Converged)
        } else {
            Some(StopReason::Exhausted)
        }
    } else if cfg.stop_unshot.is_some_and(|f| p.unshot_share < f)
        || (gathered(cfg) && p.unshot_share * p.amplification < GATHER_OWED)
    {
        Some(StopReason::Converged)
    } else if cfg.max_time.is_some_and(|t| p.elapsed >= t) {
        Some(StopReason::MaxTime)
    } else if cfg.max_rays.is_some_and(|r| p.samples >= r) {
        Some(StopReason::MaxRays)
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn progress(max_unshot_b: f64) -> Progress {
        Progress {
            interrupted: false,
            max_unshot_b,
            amplification: 2.0,
            mean_b: 1.0,
            elapsed: 0.0,
            samples: 0,
            unshot_share: 0.5,
        }
    }

    #[test]
    fn stops_at_six_hundredths_of_a_percent_of_what_is_left_to_add() {
        let cfg = SolveSettings::default();
        // 0.0006 of the mean, with every unit of unshot radiosity worth two.
        assert_eq!(verdict(&cfg, &progress(0.000_31), || true), None);
        assert_eq!(
            verdict(&cfg, &progress(0.000_29), || true),
            Some(StopReason::Converged)
        );
        assert_eq!(
            verdict(&cfg, &progress(0.0), || false),
            Some(StopReason::Exhausted)
        );
        let budget = SolveSettings {
            max_rays: Some(10),
            ..cfg.clone()
        };
        let p = Progress {
            samples: 10,
            ..progress(1.0)
        };
        assert_eq!(verdict(&budget, &p, || true), Some(StopReason::MaxRays));
        let p = Progress {
            interrupted: true,
            ..p
        };
        assert_eq!(verdict(&budget, &p, || true), Some(StopReason::Interrupted));
    }

    #[test]
    fn a_probe_stops_once_most_light_has_come_to_rest() {
        let probe = SolveSettings {
            stop_unshot: Some(0.25),
            ..SolveSettings::default()
        };
        // Half the emitted light still unshot: go on; a fifth: stop.
        assert_eq!(verdict(&probe, &progress(1.0), || true), None);
        let p = Progress {
            unshot_share: 0.2,
            ..progress(1.0)
        };
        assert_eq!(verdict(&probe, &p, || true), Some(StopReason::Converged));
        // Without the setting, the same progress goes on.
        assert_eq!(verdict(&SolveSettings::default(), &p, || true), None);
    }
}
