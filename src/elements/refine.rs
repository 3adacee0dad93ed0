//! The refinement loop (Cohen, Greenberg, Immel & Brock 1986, Sec. 3): radiosity at the
//! elements' corners, and every element whose corners differ by more than the threshold cut
//! in four, level by level, until none is, or they reach the minimum size.
//!
//! **Values at the corners.** Cohen 1986 computes the radiosity at element vertices by
//! hemi-cubes placed there, with the patches as the light's sources. Here each corner may gather
//! the whole light ([`CornerLight::Full`]; [`LightAt::radiosity_at`]): the
//! emitters and the sun by shadow rays at the point, the rest over the hemisphere, with the
//! patch solution as the cache of the indirect light. [`CornerLight::Direct`] gathers only
//! the direct light there ([`LightAt::part_at`]: the part with the shadow edges and the peaks
//! beside lights) and takes the indirect part from the patch solution: a patch's solved
//! radiosity less the mean of its elements' direct light, averaged to the welded vertices and
//! interpolated between them as the patches' display is. The direct light at a point takes
//! the lamps its polygon draws most whole ([`LightParts::DirectWhole`], `light::exact`): their
//! unoccluded light in closed form, times what its shadow rays find unblocked, a third of them
//! first and the rest only where those disagree — so a point that sees its lamps whole, or
//! none of them, has no noise and casts a third of the rays. That costs about a quarter of the
//! rays, but the indirect light's own variation within a patch (contact shadows, under a
//! table) is then neither seen by the test nor shown: on `scenes/spot.obj` it leaves a floor
//! of 1.6 % under every mesh's error, where the full gather's is under 1 %.
//! [`CornerLight::Split`] (the default) gathers the direct light at every point too, and the
//! indirect part only on the patches that see geometry near enough to shape it (Ward's
//! split-sphere criterion, `elements/indirect.rs`), at their corners and, where those differ,
//! at nine nodes, interpolated beneath: the contact shadows' fall-off is seen at the patch's
//! scale; every other patch's indirect light is the patch solution's, as under
//! [`CornerLight::Direct`].
//!
//! **Shared points.** A point that no patch boundary of its surface runs through — inside a
//! patch, or on an edge two patches share — has one value for every patch that has it,
//! gathered once (by the lowest-numbered patch that asks). A point on a patch's edge that no
//! neighbour of its surface shares (a room's edge, where the floor meets a wall) is gathered
//! at a point moved [`INSET`] of the way towards the asking patch's centre, so that a corner
//! in a room's edge does not cast its rays from inside the wall beside it; it too is kept by
//! position, facing and material, once for the patches along that edge that have it (the
//! display welds them into one vertex anyway, and the insets differ by 0.2 % of a patch).
//!
//! **Told by the corners.** A point's direct light is the closed form of each whole lamp face
//! times what its shadow rays find unblocked (`light::exact`); where every ray of a face
//! arrived, or none did, the gather says so ([`crate::light::Vis`]). A level gathers its
//! elements' corners first, then the points between them: an edge's midpoint takes as seen
//! (or hidden) the faces both ends of its edge saw whole (or not at all), a quad's centre
//! those all four corners did, and casts rays only to the rest — in a room most points see
//! their lamps whole, so a midpoint there costs the closed form and no ray. A shadow smaller
//! than an element that falls between its corners is then missed where the midpoint's own
//! rays might have met it (a third of them, eight at the default, might not either);
//! measured with `bench elements` (docs/results/adaptive-elements.md): the same error on
//! `scenes/spot.obj` for 16 % fewer rays. Only points of the same polygon tell each other
//! (the faces are numbered per polygon).
//!
//! **Common random numbers.** Every point of one scene polygon is gathered with a generator
//! seeded alike, from (seed, [`crate::solve::Stream::Elements`], polygon): neighbouring
//! corners then use the same directions and light samples, so the difference between two
//! corners — what the refinement tests — is the light's, not the noise's.
//!
//! **Reproducible**: each level first lists the points its tests need, gathers the new ones in
//! parallel (a point's value depends only on the point and the patch chosen to gather it),
//! then decides every patch in parallel; the cap ([`super::ElementSettings::max_factor`]) is
//! applied over all the candidates of a level in a fixed order. So the result does not depend
//! on the thread count.

use super::geometry::{Cut, Elem, Root};
pub(super) use super::work::{facing, inner_edges, key, At, PatchWork, Values};
use super::work::{on_edges, NO_PARENTS};
use super::NOISE_Z;
use crate::intersect::Intersector;
use crate::light::{LightAt, LightParts};
use crate::mesh::Mesh;
use crate::solve::scalar;
use glam::{DVec2, DVec3, Vec3};
use rayon::prelude::*;

/// A corner on a patch's boundary is gathered this fraction of the way towards the patch's
/// centre.
pub const INSET: f64 = 2e-3;

/// What is gathered at the elements' corners (`--element-light`; module notes).
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    serde::Serialize,
    serde::Deserialize,
    clap::ValueEnum,
)]
#[serde(rename_all = "kebab-case")]
pub enum CornerLight {
    /// The direct light (emitters and sun, by shadow rays) at every corner; the indirect
    /// light from the patch solution, interpolated across each patch. About a quarter of
    /// [`CornerLight::Full`]'s rays, but the indirect light's own variation (contact shadows,
    /// under furniture) is neither refined nor shown: a preview, not the default.
    #[value(help = crate::settings::NO_HELP)]
    Direct,
    /// The whole gather at every corner (direct and hemisphere rays).
    #[value(help = crate::settings::NO_HELP)]
    Full,
    /// The direct light at every corner (3/8 of `--element-rays`); the indirect light,
    /// on the patches that see geometry near enough to shape it (`indirect::near_patches`),
    /// gathered (with all of them) at each patch's corners, shared with its neighbours, and
    /// where they differ at its edge midpoints and centre too, interpolated across its
    /// elements (bilinearly, or quadratically through the nine); on the others, the patch
    /// solution's, as [`CornerLight::Direct`] takes it. The default: at 64 rays, 0.07 of
    /// [`CornerLight::Full`]'s rays at 256 on the office (docs/results/adaptive-elements.md).
    #[default]
    #[value(help = crate::settings::NO_HELP)]
    Split,
}

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

/// Everything the per-patch work reads.
pub(super) struct Refiner<'a, I> {
    pub mesh: &'a Mesh,
    pub gather: &'a LightAt<'a, I>,
    /// The patch solution: the level of every patch's elements (`display`'s notes, "Level"),
    /// and the indirect light of [`CornerLight::Direct`].
    pub b: &'a [[f64; 3]],
    pub seed: u64,
    pub rays: usize,
    pub light: CornerLight,
    /// [`CornerLight::Split`]: rays of each patch corner's indirect gather.
    pub indirect_rays: usize,
    /// [`CornerLight::Split`]: per patch, whether it gathers the indirect light at its nodes
    /// (`indirect::near_patches`); the others', and every patch's under
    /// [`CornerLight::Direct`], is interpolated from the patch solution.
    pub near: Vec<bool>,
    pub quantum: f64,
    /// Per patch, bit k set: its edge k (corner k to k + 1) is shared with a neighbour
    /// ([`inner_edges`]).
    pub inner: Vec<u64>,
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

/// The points a decision on `e` reads: its corners and, unless the test is on the corners
/// alone, the points a cut would add (edge midpoints, a quad's centre).
pub(super) fn test_points(e: &Elem, test: Test) -> Vec<DVec2> {
    let uv = e.corners_uv();
    let mut pts = uv.to_vec();
    if test != Test::Corners {
        let n = uv.len();
        pts.extend((0..n).map(|k| (uv[k] + uv[(k + 1) % n]) * 0.5));
        if !e.tri {
            pts.push(e.centre_uv());
        }
    }
    pts
}

/// What [`Refiner::deviation`] measures: the worst interpolation error at the added points,
/// for a quad the error each cut in two leaves, and the Simpson mean of the points read.
struct Deviation {
    worst: f64,
    halves: Option<(f64, f64)>,
    mean: f64,
}

impl<I: Intersector> Refiner<'_, I> {
    /// Whether patch `patch`'s points hold its indirect light (gathered at its nodes, or in
    /// the whole gather): otherwise their values are the direct light, and the indirect is
    /// added from the patch solution when the refinement ends ([`finish`]).
    fn gathers_indirect(&self, patch: usize) -> bool {
        match self.light {
            CornerLight::Full => true,
            CornerLight::Direct => false,
            CornerLight::Split => self.near[patch],
        }
    }

    /// Whether Ctrl-C or the deadline asks to stop.
    pub fn stopped(&self) -> bool {
        self.stop.interrupted() || self.stop.out_of_time()
    }

    /// Where the value of the point `uv` of root `root` of patch `patch` is kept, and the
    /// point its gather is made at.
    pub(super) fn at(&self, patch: usize, w: &PatchWork, root: u32, uv: DVec2) -> (At, DVec3) {
        let r = &w.roots[root as usize];
        let p = r.at(uv);
        let k = key(p, self.quantum);
        let pt = &self.mesh.patches[patch];
        let n = pt.count as usize;
        let at = At(k, facing(pt.normal), pt.material);
        let shared =
            on_edges(n, root as usize, r.tri, uv).is_some_and(|m| m & !self.inner[patch] == 0);
        if shared {
            (at, p)
        } else {
            let c = pt.centre.as_dvec3();
            (at, p + (c - p) * INSET)
        }
    }

    /// The value of a point gathered earlier (0 if it was not: a refinement stopped early).
    fn value(&self, patch: usize, w: &PatchWork, root: u32, uv: DVec2, v: &Values) -> [f64; 3] {
        let (at, _) = self.at(patch, w, root, uv);
        let b = v.map.get(&at).map_or([0.0; 3], |d| d.b);
        // Split corners' gathered indirect light is at the nodes; Full's is in `b`.
        if self.light != CornerLight::Split || !self.near[patch] {
            return b;
        }
        let ind = super::indirect::at(&w.ind_nodes[root as usize], uv);
        [0, 1, 2].map(|c| b[c] + ind[c])
    }

    /// The variance of the indirect light [`Refiner::value`] interpolates at the same point
    /// from its patch's nodes (Σ wₖ² σₖ²; [`CornerLight::Split`] on the patches that gather
    /// nodes, else 0).
    fn variance(&self, patch: usize, w: &PatchWork, root: u32, uv: DVec2) -> f64 {
        if self.light != CornerLight::Split || !self.near[patch] {
            return 0.0;
        }
        super::indirect::var_at(&w.ind_nodes[root as usize], uv)
    }

    /// Forgets the centres of the quads this level kept (`done` from `decided_from`): a kept
    /// element is never cut again and nothing else of its patch lies inside it, so nothing
    /// reads them again (but a doubled face of the same facing and material, which would
    /// gather such a point again itself).
    fn forget_centres(&self, work: &[PatchWork], decided_from: &[usize], values: &mut Values) {
        let gone: Vec<At> = (work.par_iter().zip(decided_from).enumerate())
            .flat_map_iter(|(i, (w, &from))| {
                (w.done[from..].iter().filter(|e| !e.tri))
                    .map(move |e| self.at(i, w, e.root, e.centre_uv()).0)
            })
            .collect();
        for at in &gone {
            values.map.remove(at);
        }
    }

    /// The scalar values at `e`'s corners.
    fn corner_values(&self, patch: usize, e: &Elem, w: &PatchWork, v: &Values) -> Vec<f64> {
        (e.corners_uv().iter())
            .map(|&uv| scalar(&self.value(patch, w, e.root, uv, v)))
            .collect()
    }

    /// The largest difference between the radiosity gathered at the points `e`'s children
    /// would add (its edge midpoints and, for a quad, its centre) and what `e` interpolates
    /// there from its corner values `c` (scalar): the interpolation error the cut would remove.
    /// For a quad also the error each cut in two would leave at those points (across u, across
    /// v: [`Test::Halves`]); and the mean over `e` of the points read (Simpson's rule on a
    /// quad's 3 × 3 points; a triangle's edge midpoints).
    fn deviation(&self, patch: usize, e: &Elem, c: &[f64], w: &PatchWork, v: &Values) -> Deviation {
        let uv = e.corners_uv();
        let n = uv.len();
        // Scalar radiosity gathered at the edge midpoints, edge k running from corner k.
        let mut m = [0.0; 4];
        let mut worst = 0.0f64;
        for k in 0..n {
            let at = (uv[k] + uv[(k + 1) % n]) * 0.5;
            m[k] = scalar(&self.value(patch, w, e.root, at, v));
            worst = worst.max((m[k] - 0.5 * (c[k] + c[(k + 1) % n])).abs());
        }
        if e.tri {
            return Deviation {
                worst,
                halves: None,
                mean: (m[0] + m[1] + m[2]) / 3.0,
            };
        }
        let mid = scalar(&self.value(patch, w, e.root, e.centre_uv(), v));
        worst = worst.max((mid - c.iter().sum::<f64>() / n as f64).abs());
        // Edges 0 and 2 run along u, 1 and 3 along v.
        let along_u = (m[0] - 0.5 * (c[0] + c[1]))
            .abs()
            .max((m[2] - 0.5 * (c[2] + c[3])).abs());
        let along_v = (m[1] - 0.5 * (c[1] + c[2]))
            .abs()
            .max((m[3] - 0.5 * (c[3] + c[0])).abs());
        // Cut across u: the new edge from m₀ to m₂ interpolates the centre; the v edges stay.
        let left_u = along_v.max((mid - 0.5 * (m[0] + m[2])).abs());
        let left_v = along_u.max((mid - 0.5 * (m[1] + m[3])).abs());
        let mean = (c.iter().sum::<f64>() + 4.0 * m.iter().sum::<f64>() + 16.0 * mid) / 36.0;
        Deviation {
            worst,
            halves: Some((left_u, left_v)),
            mean,
        }
    }

    /// The variance the interpolated indirect light's noise puts in the difference `test`
    /// measures on `e`: the largest variance among the points it reads, times 2 (two corners'
    /// difference) or 1.5 (a midpoint against its edge's two corners). The direct light's
    /// noise is left out: every point of a polygon draws the same light samples and
    /// directions, so its differences are the light's (a shadow's penumbra, whose points are
    /// each noisy, is still refined), where the few nodes of the indirect light are
    /// interpolated and their noise would show as curvature.
    fn test_noise(&self, patch: usize, e: &Elem, w: &PatchWork, test: Test) -> f64 {
        let worst = (test_points(e, test).into_iter())
            .map(|uv| self.variance(patch, w, e.root, uv))
            .fold(0.0f64, f64::max);
        worst * if test == Test::Corners { 2.0 } else { 1.5 }
    }

    /// One level of patch `patch`: the active elements that `rule` would cut, with their
    /// contrast (largest first wins under the cap) and how; the others are kept.
    fn level(
        &self,
        patch: usize,
        w: &mut PatchWork,
        rule: Rule,
        v: &Values,
    ) -> Vec<(f64, usize, Cut)> {
        let active = std::mem::take(&mut w.active);
        let mut cut = Vec::new();
        let mut keep = Vec::new();
        for e in active {
            let c = match rule {
                Rule::Uniform(depth) => (e.depth < depth).then_some((f64::INFINITY, Cut::Four)),
                Rule::Adaptive {
                    threshold,
                    floor,
                    min_size,
                    test,
                } => self.decide(patch, &e, w, v, (threshold, floor, min_size), test),
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

    /// Whether `rule`'s threshold cuts `e`, with its contrast and how it is cut; `limits` are
    /// the rule's (threshold, floor, min_size).
    fn decide(
        &self,
        patch: usize,
        e: &Elem,
        w: &mut PatchWork,
        v: &Values,
        limits: (f64, f64, f64),
        test: Test,
    ) -> Option<(f64, Cut)> {
        let (threshold, floor, min_size) = limits;
        if !big_enough(e, w, min_size) {
            return None;
        }
        let least = 2.0 * min_size * (1.0 - 1e-6);
        let (along_u, along_v) = e.extents(&w.roots);
        let c = self.corner_values(patch, e, w, v);
        let corners_mean = c.iter().sum::<f64>() / c.len() as f64;
        let (d, how, mean) = match test {
            Test::Corners => {
                let (lo, hi) = c
                    .iter()
                    .fold((f64::INFINITY, 0.0f64), |(l, h), &x| (l.min(x), h.max(x)));
                (hi - lo, Cut::Four, corners_mean)
            }
            Test::Midpoints => {
                let dev = self.deviation(patch, e, &c, w, v);
                (dev.worst, Cut::Four, dev.mean)
            }
            Test::Halves => {
                let dev = self.deviation(patch, e, &c, w, v);
                let how = match dev.halves {
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
                (dev.worst, how, dev.mean)
            }
        };
        // The direct light's differences against the whole light there: the root's first
        // test gives its indirect part (the patch's radiosity less the direct light's mean).
        let r = e.root as usize;
        if !self.gathers_indirect(patch) && e.depth == 0 {
            w.indirect[r] = (scalar(&self.b[patch]) - mean).max(0.0);
        }
        let whole = corners_mean + w.indirect[r];
        // The difference less the noise the indirect nodes put in it (in quadrature).
        let d = (d * d - NOISE_Z * NOISE_Z * self.test_noise(patch, e, w, test))
            .max(0.0)
            .sqrt();
        let mut contrast = d / whole.max(floor).max(f64::MIN_POSITIVE);
        if test != Test::Corners {
            // Weighed by the element's share of its root's area (4^−depth after cuts in four):
            // its part in the patch's area-weighted error.
            contrast *= e.share();
        }
        (contrast > threshold).then_some((contrast, how))
    }
}

/// Whether `e` is at least twice the smallest element edge along its longer side.
pub(super) fn big_enough(e: &Elem, w: &PatchWork, min_size: f64) -> bool {
    let (along_u, along_v) = e.extents(&w.roots);
    along_u.max(along_v) >= 2.0 * min_size * (1.0 - 1e-6)
}

/// The area of a root in space.
fn root_area(r: &Root) -> f64 {
    let c = &r.corners;
    if r.tri {
        0.5 * (c[1] - c[0]).cross(c[2] - c[0]).length()
    } else {
        0.5 * (c[2] - c[0]).cross(c[3] - c[1]).length()
    }
}

/// The value at `uv` of root `root` of a patch whose corners hold `at` (bilinear on a quad
/// root, affine on a fan triangle).
fn interpolate(at: &[[f32; 3]], root: usize, tri: bool, uv: DVec2) -> [f64; 3] {
    let g = |k: usize| at[k].map(|x| x as f64);
    if tri {
        let (a, b, c) = (g(0), g(root + 1), g(root + 2));
        [0, 1, 2].map(|i| a[i] + (b[i] - a[i]) * uv.x + (c[i] - a[i]) * uv.y)
    } else {
        let (a, b, c, d) = (g(0), g(1), g(2), g(3));
        [0, 1, 2].map(|i| {
            let lo = a[i] + (b[i] - a[i]) * uv.x;
            let hi = d[i] + (c[i] - d[i]) * uv.x;
            lo + (hi - lo) * uv.y
        })
    }
}

/// Gathers the kept elements' corners and sets every patch's [`PatchWork::corner_b`]: the
/// gathered values, plus, where they are the direct light alone ([`CornerLight::Direct`], and
/// the patches of [`CornerLight::Split`] that gather no indirect nodes), the indirect light
/// interpolated from the patches' (their radiosity less the mean of their elements' direct
/// light, averaged to the welded vertices).
pub(super) fn finish<I: Intersector>(
    r: &Refiner<'_, I>,
    work: &mut [PatchWork],
    values: &mut Values,
) {
    let corners = |w: &PatchWork| {
        (w.done.iter())
            .flat_map(|e| {
                e.corners_uv()
                    .iter()
                    .map(move |&uv| (e.root, uv, NO_PARENTS))
            })
            .collect()
    };
    r.gather_all(work, corners, values);
    let v = &*values;
    // Per patch, its kept corners' direct light (what `values.map` holds).
    let direct: Vec<Vec<[f64; 3]>> = (work.par_iter().enumerate())
        .map(|(i, w)| {
            (w.done.iter())
                .flat_map(|e| {
                    e.corners_uv().iter().map(move |&uv| {
                        let (at, _) = r.at(i, w, e.root, uv);
                        v.map.get(&at).map_or([0.0; 3], |d| d.b)
                    })
                })
                .collect()
        })
        .collect();
    let indirect: Vec<[f32; 3]> = if (0..work.len()).all(|i| r.gathers_indirect(i)) {
        Vec::new()
    } else {
        let own: Vec<[f64; 3]> = (work.iter().zip(&direct).enumerate())
            .map(|(i, (w, d))| {
                let (mut s, mut a) = ([0.0f64; 3], 0.0);
                let mut k = 0;
                for e in &w.done {
                    let n = e.count();
                    let ae = e.share() * root_area(&w.roots[e.root as usize]);
                    for dv in &d[k..k + n] {
                        for c in 0..3 {
                            s[c] += ae * dv[c] / n as f64;
                        }
                    }
                    a += ae;
                    k += n;
                }
                let mean = s.map(|x| if a > 0.0 { x / a } else { 0.0 });
                [0, 1, 2].map(|c| r.b[i][c] - mean[c])
            })
            .collect();
        r.mesh.vertex_values(&own)
    };
    work.par_iter_mut()
        .zip(direct)
        .enumerate()
        .for_each(|(i, (w, d))| {
            if r.gathers_indirect(i) {
                w.corner_b = (w.done.iter())
                    .flat_map(|e| {
                        e.corners_uv()
                            .iter()
                            .map(|&uv| r.value(i, w, e.root, uv, v))
                    })
                    .collect();
                return;
            }
            w.corner_b = d;
            let at: Vec<[f32; 3]> = (r.mesh.patch_indices(i).iter())
                .map(|&k| indirect[k as usize])
                .collect();
            let mut k = 0;
            for e in &w.done {
                let tri = w.roots[e.root as usize].tri;
                for &uv in e.corners_uv() {
                    let ind = interpolate(&at, e.root as usize, tri, uv);
                    let b = &mut w.corner_b[k];
                    for c in 0..3 {
                        b[c] = (b[c] + ind[c]).max(0.0);
                    }
                    k += 1;
                }
            }
        });
}
/// Each patch's refinement state before the first level: its roots, each one active.
fn patch_work(mesh: &Mesh) -> Vec<PatchWork> {
    (0..mesh.patches.len())
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
                indirect: vec![0.0; roots.len()],
                roots,
                active,
                done: Vec::new(),
                corner_b: Vec::new(),
                ind_nodes: Vec::new(),
            }
        })
        .collect()
}

/// Runs the refinement of every patch to its fixed point under `rule`, with at most `cap`
/// elements in all (the candidates with the largest contrast are cut first; patch order
/// breaks ties), and gathers the kept elements' corners ([`finish`]). Returns each patch's
/// work, the values gathered and whether the cap stopped it. Ctrl-C or the deadline
/// ([`Refiner::stop`]) ends it at the next level, keeping what is refined.
pub(super) fn run<I: Intersector>(
    r: &Refiner<'_, I>,
    rule: Rule,
    cap: usize,
) -> (Vec<PatchWork>, Values, bool) {
    let mut work = patch_work(r.mesh);
    let mut values = Values::default();
    if r.light == CornerLight::Split {
        super::indirect::gather(
            &mut work,
            &r.near,
            |i, w, root, uv| r.at(i, w, root, uv),
            |i, x| r.gather_part(i, x, LightParts::IndirectOnce, r.indirect_rays),
            &mut values,
        );
    }
    let mut total: usize = work.iter().map(|w| w.active.len()).sum();
    let mut capped = false;
    loop {
        if work.iter().all(|w| w.active.is_empty()) {
            break;
        }
        if r.stopped() {
            for w in &mut work {
                let a = std::mem::take(&mut w.active);
                w.done.extend(a);
            }
            break;
        }
        r.gather_all(&work, |w| r.wanted(w, rule), &mut values);
        let v = &values;
        // Kept elements sit in `done` below these; the level's candidates are put after.
        let decided_from: Vec<usize> = work.iter().map(|w| w.done.len()).collect();
        let cands: Vec<Vec<(f64, usize, Cut)>> = work
            .par_iter_mut()
            .enumerate()
            .map(|(i, w)| r.level(i, w, rule, v))
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
        r.forget_centres(&work, &decided_from, &mut values);
        if capped {
            // Whatever is still active after the cap is kept as it is.
            for w in &mut work {
                let a = std::mem::take(&mut w.active);
                w.done.extend(a);
            }
            break;
        }
    }
    finish(r, &mut work, &mut values);
    // The display reads each patch's roots, kept elements and their corners' values only.
    for w in &mut work {
        // A vector grown from empty holds room for four elements; most patches keep one.
        w.done.shrink_to_fit();
        w.active = Vec::new();
        w.indirect = Vec::new();
        w.ind_nodes = Vec::new();
    }
    values.map = Default::default();
    (work, values, capped)
}
