//! The refine stage (docs/design.md §1, §11): the adaptive elements of a finished solve, cut
//! where the solution's light changes and gathered at their vertices ([`crate::elements`]), or
//! the patches themselves when the elements are off, skipped or out of time.

use super::stages::Solved;
use super::SolveJob;
use crate::elements::{self, ElementStats, Elements};
use crate::intersect::select::AnyIntersector;

/// What the refine stage made: `elements.csv`, the Gouraud picture and the saved solution read
/// the elements; `summary.json` the statistics (`None` when nothing was refined).
pub struct Refined {
    pub elements: Elements,
    pub stats: Option<ElementStats>,
}

/// Refine: the elements of `solved`, gathering through `isect` (`None` only when nothing is
/// refined). They keep to what is left of `--max-time` (counted from the run's start); a solve
/// Ctrl-C stopped, or one with no time left, keeps its patches at once.
pub fn refine(
    job: &SolveJob,
    solved: &Solved,
    isect: Option<&AnyIntersector>,
    log: &mut impl FnMut(&str),
) -> Refined {
    let (scene, m) = (&solved.model.scene, &solved.model.mesh);
    let sol = &solved.sol;
    let wanted = job.settings.elements.applies_to(m.patches.len());
    if job.settings.elements.enabled && !wanted {
        log(&format!(
            "elements: skipped for {} patches (--elements auto refines up to {}; --elements on to refine anyway)",
            m.patches.len(),
            elements::AUTO_MAX_PATCHES
        ));
    }
    let stop = elements::Stop {
        flag: job.interrupt.as_deref(),
        deadline: job
            .settings
            .solve
            .max_time
            .map(|t| solved.t0 + std::time::Duration::from_secs_f64(t.max(0.0))),
    };
    match isect {
        Some(isect) if wanted && !stop.interrupted() && !stop.out_of_time() => {
            solved.progress.phase("refining elements");
            let gather = crate::light::LightAt::new(
                m,
                &scene.materials,
                isect,
                &sol.b,
                solved.sky.as_ref(),
                None,
            );
            let (el, st) = elements::refine_until(
                m,
                &gather,
                &sol.b,
                &job.settings.elements,
                job.settings.solve.seed,
                stop,
            );
            log_stats(job, &st, log);
            Refined {
                elements: el,
                stats: Some(st),
            }
        }
        _ => Refined {
            elements: Elements::of_patches(m, &sol.b),
            stats: None,
        },
    }
}

/// The lines a refine logs: the counts, why it stopped early, the cap.
fn log_stats(job: &SolveJob, st: &ElementStats, log: &mut impl FnMut(&str)) {
    log(&format!(
        "elements: {} from {} patches (threshold {}, min size {:.4} m), {} rays, {:.2} s",
        st.count, st.patches, st.threshold, st.min_size, st.rays, st.seconds
    ));
    if st.interrupted {
        log("interrupted: the elements refined so far are kept");
    } else if st.out_of_time {
        log("--max-time reached: the elements refined so far are kept");
    }
    if st.capped {
        log(&format!(
            "warning: the elements reached their cap of {} per patch (--element-max); the largest differences were refined first",
            job.settings.elements.max_factor
        ));
    }
}
