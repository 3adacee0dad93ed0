//! The refinement loop (Cohen, Greenberg, Immel & Brock 1986, Sec. 3): radiosity at the
//! elements' corners, and every element whose corners differ by more than the threshold cut
//! in four, level by level, until none is, or they reach the minimum size.
//!
//! **Values at the corners.** Cohen 1986 computes the radiosity at element vertices by
//! hemi-cubes placed there, with the patches as the light's sources; here a gather takes the
//! hemi-cube's place ([`LightAt::radiosity_at`]): direct light from every emitter (and the
//! sun, the sky) sampled with shadow rays at the point, indirect light from the solved patch
//! radiosities (the patch solution is the cache). A corner on a patch's boundary is gathered
//! at a point moved [`INSET`] of the way towards the patch's centre, so that a corner in a
//! room's edge does not cast its rays from inside the wall beside it.
//!
//! **Common random numbers.** Every corner of one scene polygon is gathered with a generator
//! seeded alike, from (seed, [`Stream::Elements`], polygon): neighbouring corners then use the
//! same directions and light samples, so the difference between two corners — what the
//! refinement tests — is the light's, not the noise's.
//!
//! **Reproducible**: the patches are refined in parallel, each with its own corner cache, and
//! the cap ([`super::ElementSettings::max_factor`]) is applied over all the candidates of a
//! level in a fixed order, so the result does not depend on the thread count.

use super::geometry::{Cut, Elem, Root};
use crate::intersect::Intersector;
use crate::light::LightAt;
use crate::mesh::Mesh;
use crate::solve::{rng_for, scalar, Stream};
use glam::{DVec3, Vec3};
use rayon::prelude::*;
use std::collections::HashMap;

/// A corner on a patch's boundary is gathered this fraction of the way towards the patch's
/// centre.
pub const INSET: f64 = 2e-3;

/// What an element's difference is measured on.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, clap::ValueEnum,
)]
#[serde(rename_all = "kebab-case")]
pub enum Test {
    /// Cohen 1986 Sec. 3: the largest difference between the element's corners.
    #[value(help = crate::settings::NO_HELP)]
    Corners,
    /// The largest difference, at the points the cut would add (edge midpoints, a quad's
    /// centre), between the radiosity gathered there and the element's interpolation of its
    /// corners — the error of the picture itself, so a smooth gradient (which Gouraud shading
    /// draws exactly) is not cut and a shadow edge or a peak is — times the element's share
    /// of its patch's area (4^−depth): its part in the area-weighted error. Measured against
    /// `Corners` in README, "Adaptive elements": the same error with about a third of the
    /// elements.
    #[value(help = crate::settings::NO_HELP)]
    Midpoints,
    /// The midpoint test, and a quad cut in *two* rather than four: across the direction in
    /// which cutting leaves the smaller interpolation error at the points gathered (a shadow
    /// edge or a wall's fall-off along one direction is followed by one cut per level, where a
    /// cut in four spends three elements), the longer side when the two are alike. Two cuts
    /// in two make the cut in four where the light changes both ways. Triangles are cut in
    /// four. README, "Adaptive elements", measures it against [`Test::Midpoints`].
    #[value(help = crate::settings::NO_HELP)]
    Halves,
}

/// How to decide which elements to cut.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Rule {
    /// Cohen 1986 Sec. 3: cut while the difference `test` measures exceeds `threshold`
    /// relative to max(the corners' mean, `floor`) and the longest edge is at least twice
    /// `min_size`.
    Adaptive {
        threshold: f64,
        floor: f64,
        min_size: f64,
        test: Test,
    },
    /// Every root cut to this depth (the uniform meshing adaptive elements are compared with).
    Uniform(u32),
}

/// One patch's elements while they are refined.
pub(super) struct PatchWork {
    pub roots: Vec<Root>,
    /// Elements still to decide on, and the ones kept.
    pub active: Vec<Elem>,
    pub done: Vec<Elem>,
    /// Gathered radiosity by corner position (quantised), RGB W/m².
    pub cache: HashMap<[i64; 3], [f64; 3]>,
    pub rays: u64,
}

/// Everything the per-patch work reads.
pub(super) struct Refiner<'a, I> {
    pub mesh: &'a Mesh,
    pub gather: &'a LightAt<'a, I>,
    pub seed: u64,
    pub rays: usize,
    pub quantum: f64,
    /// Ctrl-C and `--max-time`: refine no further (what is refined is kept).
    pub stop: Stop<'a>,
}

/// What ends a refinement early, keeping what is refined: Ctrl-C's flag, and the deadline
/// `--max-time` sets.
#[derive(Clone, Copy, Debug, Default)]
pub struct Stop<'a> {
    pub flag: Option<&'a std::sync::atomic::AtomicBool>,
    pub deadline: Option<std::time::Instant>,
}

impl Stop<'_> {
    /// Whether Ctrl-C was pressed.
    pub fn interrupted(&self) -> bool {
        self.flag
            .is_some_and(|f| f.load(std::sync::atomic::Ordering::Relaxed))
    }

    /// Whether the deadline has passed.
    pub fn out_of_time(&self) -> bool {
        self.deadline
            .is_some_and(|d| std::time::Instant::now() >= d)
    }
}

/// The cache key of a position.
pub(super) fn key(p: DVec3, quantum: f64) -> [i64; 3] {
    let q = |x: f64| (x / quantum).round() as i64;
    [q(p.x), q(p.y), q(p.z)]
}

impl<I: Intersector> Refiner<'_, I> {
    /// Whether Ctrl-C or the deadline asks to stop.
    pub fn stopped(&self) -> bool {
        self.stop.interrupted() || self.stop.out_of_time()
    }

    /// The radiosity at corner `p` of patch `patch`, gathered once (Cohen 1986 Sec. 3, with a
    /// gather for the hemi-cube).
    fn corner(&self, patch: usize, p: DVec3, w: &mut PatchWork) -> [f64; 3] {
        let k = key(p, self.quantum);
        if let Some(v) = w.cache.get(&k) {
            return *v;
        }
        let c = self.mesh.patches[patch].centre.as_dvec3();
        let at = p + (c - p) * INSET;
        let polygon = self.mesh.patches[patch].polygon as u64;
        let mut rng = rng_for(self.seed, Stream::Elements, polygon);
        let (b, rays) = self
            .gather
            .radiosity_at(patch, &[at.as_vec3()], self.rays, &mut rng);
        w.rays += rays;
        let b = b
            .to_array()
            .map(|x| if x.is_finite() { x.max(0.0) } else { 0.0 });
        w.cache.insert(k, b);
        b
    }

    /// The corner values of `e`, gathered where not yet cached.
    pub fn values(&self, patch: usize, e: &Elem, w: &mut PatchWork) -> Vec<[f64; 3]> {
        let pts = e.corners(&w.roots);
        pts.iter().map(|&p| self.corner(patch, p, w)).collect()
    }

    /// The largest difference between the radiosity gathered at the corners `e`'s children
    /// would add (its edge midpoints and, for a quad, its centre) and what `e` interpolates
    /// there from its corner values `v` (scalar): the interpolation error the cut would remove.
    /// For a quad also the error each cut in two would leave at those points (across u, across
    /// v: [`Test::Halves`]).
    fn deviation(
        &self,
        patch: usize,
        e: &Elem,
        v: &[f64],
        w: &mut PatchWork,
    ) -> (f64, Option<(f64, f64)>) {
        let uv = e.corners_uv();
        let n = uv.len();
        let root = w.roots[e.root as usize];
        // Scalar radiosity gathered at the edge midpoints, edge k running from corner k.
        let mut m = [0.0; 4];
        let mut worst = 0.0f64;
        for k in 0..n {
            let p = root.at((uv[k] + uv[(k + 1) % n]) * 0.5);
            m[k] = scalar(&self.corner(patch, p, w));
            worst = worst.max((m[k] - 0.5 * (v[k] + v[(k + 1) % n])).abs());
        }
        if e.tri {
            return (worst, None);
        }
        let c = scalar(&self.corner(patch, root.at(e.centre_uv()), w));
        worst = worst.max((c - v.iter().sum::<f64>() / n as f64).abs());
        // Edges 0 and 2 run along u, 1 and 3 along v.
        let along_u = (m[0] - 0.5 * (v[0] + v[1]))
            .abs()
            .max((m[2] - 0.5 * (v[2] + v[3])).abs());
        let along_v = (m[1] - 0.5 * (v[1] + v[2]))
            .abs()
            .max((m[3] - 0.5 * (v[3] + v[0])).abs());
        // Cut across u: the new edge from m₀ to m₂ interpolates the centre; the v edges stay.
        let left_u = along_v.max((c - 0.5 * (m[0] + m[2])).abs());
        let left_v = along_u.max((c - 0.5 * (m[1] + m[3])).abs());
        (worst, Some((left_u, left_v)))
    }

    /// One level of patch `patch`: the active elements that `rule` would cut, with their
    /// contrast (largest first wins under the cap) and how; the others are kept.
    pub fn level(&self, patch: usize, w: &mut PatchWork, rule: Rule) -> Vec<(f64, usize, Cut)> {
        let active = std::mem::take(&mut w.active);
        let mut cut = Vec::new();
        let mut keep = Vec::new();
        if self.stopped() {
            w.done.extend(active);
            return cut;
        }
        for e in active {
            let c = match rule {
                Rule::Uniform(depth) => (e.depth < depth).then_some((f64::INFINITY, Cut::Four)),
                Rule::Adaptive {
                    threshold,
                    floor,
                    min_size,
                    test,
                } => self.decide(patch, &e, w, threshold, floor, min_size, test),
            };
            if let Some((c, how)) = c {
                cut.push((c, w.done.len() + keep.len(), how));
            }
            keep.push(e);
        }
        // Candidates sit in `done` until the caller says which are cut.
        w.done.extend(keep);
        cut
    }

    /// Whether `rule`'s threshold cuts `e`, with its contrast and how it is cut.
    // Seven: the element, its patch's work, and the fields of `Rule::Adaptive` taken apart by
    // the one `match` that calls this (a struct of them would be the enum variant again).
    #[allow(clippy::too_many_arguments)]
    fn decide(
        &self,
        patch: usize,
        e: &Elem,
        w: &mut PatchWork,
        threshold: f64,
        floor: f64,
        min_size: f64,
        test: Test,
    ) -> Option<(f64, Cut)> {
        let least = 2.0 * min_size * (1.0 - 1e-6);
        let (along_u, along_v) = e.extents(&w.roots);
        if along_u.max(along_v) < least {
            return None;
        }
        let v: Vec<f64> = self.values(patch, e, w).iter().map(scalar).collect();
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        let (d, how) = match test {
            Test::Corners => {
                let (lo, hi) = v
                    .iter()
                    .fold((f64::INFINITY, 0.0f64), |(l, h), &x| (l.min(x), h.max(x)));
                (hi - lo, Cut::Four)
            }
            Test::Midpoints => (self.deviation(patch, e, &v, w).0, Cut::Four),
            Test::Halves => {
                let (d, left) = self.deviation(patch, e, &v, w);
                let how = match left {
                    None => Cut::Four,
                    Some((left_u, left_v)) => {
                        // Alike (within 20 %): the longer side, so that elements stay near
                        // square where the light changes both ways (measured: 0.4–1 here
                        // change little).
                        let u = if left_u < 0.8 * left_v {
                            true
                        } else if left_v < 0.8 * left_u {
                            false
                        } else {
                            along_u >= along_v
                        };
                        if (u && along_u >= least) || along_v < least {
                            Cut::AcrossU
                        } else {
                            Cut::AcrossV
                        }
                    }
                };
                (d, how)
            }
        };
        let mut contrast = d / mean.max(floor).max(f64::MIN_POSITIVE);
        if test != Test::Corners {
            // Weighed by the element's share of its root's area (4^−depth after cuts in four):
            // its part in the patch's area-weighted error.
            contrast *= e.share();
        }
        (contrast > threshold).then_some((contrast, how))
    }
}

/// Runs the refinement of every patch to its fixed point under `rule`, with at most `cap`
/// elements in all (the candidates with the largest contrast are cut first; patch order
/// breaks ties). Returns each patch's work and whether the cap stopped it. Ctrl-C or the
/// deadline ([`Refiner::stop`]) ends it at the next patch, keeping what is refined.
pub(super) fn run<I: Intersector>(
    r: &Refiner<'_, I>,
    rule: Rule,
    cap: usize,
) -> (Vec<PatchWork>, bool) {
    let mesh = r.mesh;
    let mut work: Vec<PatchWork> = (0..mesh.patches.len())
        .map(|i| {
            let pts: Vec<Vec3> = mesh
                .patch_indices(i)
                .iter()
                .map(|&v| mesh.vertices[v as usize])
                .collect();
            let roots = Root::of_patch(&pts);
            let active = roots
                .iter()
                .enumerate()
                .map(|(k, root)| root.element(k as u32))
                .collect();
            PatchWork {
                roots,
                active,
                done: Vec::new(),
                cache: HashMap::new(),
                rays: 0,
            }
        })
        .collect();
    let mut total: usize = work.iter().map(|w| w.active.len()).sum();
    let mut capped = false;
    loop {
        if work.iter().all(|w| w.active.is_empty()) {
            break;
        }
        let cands: Vec<Vec<(f64, usize, Cut)>> = work
            .par_iter_mut()
            .enumerate()
            .map(|(i, w)| r.level(i, w, rule))
            .collect();
        let mut all: Vec<(f64, usize, usize, Cut)> = cands
            .iter()
            .enumerate()
            .flat_map(|(p, c)| c.iter().map(move |&(x, at, how)| (x, p, at, how)))
            .collect();
        // A cut in four adds three elements, a cut in two one.
        let added = |how: Cut, w: &PatchWork, at: usize| {
            if how == Cut::Four || w.done[at].tri {
                3
            } else {
                1
            }
        };
        if r.stopped() {
            for w in &mut work {
                let a = std::mem::take(&mut w.active);
                w.done.extend(a);
            }
            break;
        }
        let room = cap.saturating_sub(total);
        let wanted: usize = all.iter().map(|c| added(c.3, &work[c.1], c.2)).sum();
        if wanted > room {
            capped = true;
            all.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
            let mut used = 0;
            all.retain(|c| {
                let n = added(c.3, &work[c.1], c.2);
                let fits = used + n <= room;
                if fits {
                    used += n;
                }
                fits
            });
        }
        let mut chosen: Vec<Vec<(usize, Cut)>> = vec![Vec::new(); work.len()];
        for &(_, p, at, how) in &all {
            total += added(how, &work[p], at);
            chosen[p].push((at, how));
        }
        for (w, mut picks) in work.iter_mut().zip(chosen) {
            // Remove the cut ones from `done` (largest index first) and make their children
            // the next level.
            picks.sort_unstable_by_key(|p| std::cmp::Reverse(p.0));
            for (at, how) in picks {
                let e = w.done.swap_remove(at);
                w.active.extend(e.cut(how));
            }
        }
        if capped {
            // Whatever is still active after the cap is kept as it is.
            for w in &mut work {
                let a = std::mem::take(&mut w.active);
                w.done.extend(a);
            }
            break;
        }
    }
    (work, capped)
}
