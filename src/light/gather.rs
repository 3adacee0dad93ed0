//! The gather at a point: the irradiance H at some points of one surface (a patch's, one
//! pixel's, one sensor's point) from light samples of the emitters ([`super::direct`]), of the
//! sun ([`super::sun`]) and cosine-weighted hemisphere rays ([`super::hemisphere`]), the
//! rays shared out between them and their estimates combined by multiple importance sampling
//! (see the module notes of [`super`]); with the variance of its mean, from the strata.

use super::emitters::{Draw, Learned, Receiver, WholeSet};
use super::{Kernel, Origin, Rgb};
use crate::intersect::Intersector;
use crate::sample::polar::PolarGrid;
use glam::Vec3;
use rand::seq::SliceRandom;
use rand::Rng;
use std::cell::RefCell;

/// Which parts of the light a gather samples (the final-gather renderer gathers the indirect
/// light at a few points of the image and interpolates it: [`super::LightAt::part_at`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightParts {
    /// Everything: the emitters and the sun by shadow rays, the rest over the hemisphere, the
    /// emitters met by hemisphere rays weighed against the light samples (MIS).
    All,
    /// The shadow rays alone: the emitters (at their MIS weight) and the sun.
    Direct,
    /// The hemisphere rays alone: what they meet, emitters at the complement of the weight
    /// `Direct` gives them. `Direct` + `Indirect` is `All` in expectation.
    Indirect,
    /// `Indirect` with a near hit followed one step, not [`super::NEAR_DEPTH`] ([`super::NEAR`]:
    /// the point met then takes the solution's B − E of what its own ray meets, near or not).
    /// What the adaptive elements' indirect nodes gather (`crate::elements`): they give the
    /// light's shape across a patch whose level the final gather (which follows three deep)
    /// has set, and each step followed is a path of one light sample and one ray, the noisiest
    /// and costliest part of a node (docs/results/adaptive-elements.md).
    IndirectOnce,
    /// `Direct`, the emitters the surface's polygon draws most taken whole: their unoccluded
    /// irradiance in closed form times what the shadow rays find unblocked ([`super::exact`]),
    /// the rest by light samples; with `IndirectOnce`, whose hemisphere rays leave those
    /// emitters out, the adaptive elements' split of the light at a point of a patch.
    DirectWhole,
}

impl LightParts {
    /// Whether the emitters' and the sun's light samples (and a patch's own emission) are in.
    pub fn direct(self) -> bool {
        matches!(
            self,
            LightParts::All | LightParts::Direct | LightParts::DirectWhole
        )
    }

    /// Whether the hemisphere rays are cast.
    pub fn hemisphere(self) -> bool {
        !matches!(self, LightParts::Direct | LightParts::DirectWhole)
    }

    /// Whether the polygon's whole emitters ([`super::exact`]) are set apart: taken whole by
    /// `DirectWhole`, left out by `IndirectOnce`.
    fn sets_whole_apart(self) -> bool {
        matches!(self, LightParts::DirectWhole | LightParts::IndirectOnce)
    }
}

/// One gather: irradiance H (RGB), per light channel, the scalar variance of ρ·H's mean, the
/// rays it cast, and of H the irradiance its hemisphere rays found reflected by other surfaces
/// (not emitted, not the sky's): how the light still to be shot will arrive
/// (`solve::final_gather`, "The light still owed").
#[derive(Clone, Debug)]
pub(crate) struct Gathered {
    pub h: Rgb,
    pub ch: Vec<Rgb>,
    pub var: f64,
    pub rays: u64,
    pub reflected: Rgb,
    /// With [`LightParts::DirectWhole`], what its rays told of the whole faces
    /// ([`Vis`]).
    pub vis: Vis,
}

/// What a gather of the direct light in parts (`LightParts::DirectWhole`) found of its
/// polygon's whole faces (bit k: face k of its `WholeSet`): each seen whole (`lit`) or not at
/// all (`dark`); neither where its rays disagreed. Handed the other way (`Ask`),
/// what the points around a point found alike, which that point then takes without a ray.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Vis {
    pub lit: u64,
    pub dark: u64,
}

impl Vis {
    /// What both `self` and `o` tell.
    pub fn and(self, o: Vis) -> Vis {
        Vis {
            lit: self.lit & o.lit,
            dark: self.dark & o.dark,
        }
    }
}

/// Where a gather is made: the points `at(u, v)` of the unit square's map (a patch's, or one
/// sensor's point) facing `n`, rays leaving patch `patch`'s surface ([`super::NO_PATCH`] for a
/// sensor in the air) `eps` off it; `rho` weighs the channels of the variance.
pub(crate) struct Spot<'s> {
    pub patch: usize,
    pub at: &'s dyn Fn(f32, f32) -> Vec3,
    pub n: Vec3,
    pub eps: f32,
    pub rho: Rgb,
}

impl Spot<'_> {
    /// Where rays leave from the point (u, v).
    pub(super) fn origin(&self, u: f32, v: f32) -> Origin {
        Origin {
            patch: self.patch,
            x: (self.at)(u, v) + self.n * self.eps,
            n: self.n,
            eps: self.eps,
        }
    }
}

/// What a gather is asked for: `rays` in all (half to the emitters, a quarter to the sun when
/// there is one, the rest over the hemisphere), which `parts` of the light; `lights` false
/// sends the emitters' half over the hemisphere too: for points no emitter faces, which a
/// hemisphere ray then cannot meet on its emitting side either.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Ask {
    pub rays: usize,
    pub lights: bool,
    pub parts: LightParts,
    /// [`LightParts::DirectWhole`]: the whole faces the points around this one all saw whole
    /// or all not at all, taken so here without a ray (the adaptive elements' midpoints,
    /// from their edge's or element's corners). Nothing told by default.
    pub known: Vis,
}

/// How a gather's rays are shared out: light samples of the emitters and of the sun, the
/// hemisphere's polar grid, and the counts the MIS weights use.
pub(super) struct Split {
    /// How the light samples pick their emitters (and what the MIS weights take as their
    /// density).
    pub draw: Draw,
    pub direct: usize,
    pub sun: usize,
    pub grid: PolarGrid,
    pub nl: f64,
    pub nc: f64,
    /// How many near hits one after another a hemisphere ray's path follows ([`super::NEAR`]).
    pub follow: u32,
    /// What the MIS weights between the light samples and the hemisphere rays take for the
    /// light samples' density, when not `draw`'s own: a gather split in parts samples its
    /// polygon's cut but weighs by power, so that the weights of a path still add up to one
    /// wherever its two parts are gathered (any weights that do are unbiased; by power they
    /// are the same at every point, and so is what each part holds in expectation).
    pub weigh: Option<Draw>,
    /// The emitters taken whole (indices into the emitters, ascending; [`super::exact`]):
    /// their light is `DirectWhole`'s alone, and `IndirectOnce`'s hemisphere rays leave it
    /// out. Empty for the other parts.
    pub whole: WholeSet,
}

impl Split {
    /// `rays_wanted` rays for `parts`, with emitters to sample (`lamps`) and a `sun` or not.
    fn new(
        parts: LightParts,
        (draw, whole): (Option<Draw>, WholeSet),
        sun: bool,
        rays_wanted: usize,
    ) -> Split {
        let lamps = draw.is_some();
        let (direct, n_sun) = match (parts, lamps, sun) {
            (LightParts::Indirect | LightParts::IndirectOnce, _, _) => (0, 0),
            (LightParts::All, l, s) => (
                if l { (rays_wanted / 2).max(1) } else { 0 },
                if s { (rays_wanted / 4).max(1) } else { 0 },
            ),
            // All the rays to the lights: two thirds to the emitters when there is a sun too.
            (LightParts::Direct | LightParts::DirectWhole, true, true) => {
                let d = (rays_wanted * 2 / 3).max(1);
                (d, rays_wanted.saturating_sub(d).max(1))
            }
            (LightParts::Direct | LightParts::DirectWhole, true, false) => (rays_wanted.max(1), 0),
            (LightParts::Direct | LightParts::DirectWhole, false, true) => (0, rays_wanted.max(1)),
            (LightParts::Direct | LightParts::DirectWhole, false, false) => (0, 0),
        };
        let grid = PolarGrid::for_samples(rays_wanted.saturating_sub(direct + n_sun).max(2) as f64);
        // The MIS weights (power heuristic, by the counts of light and hemisphere samples).
        // Split in two parts gathered apart, both weigh as if by equal counts (the split of
        // `All` without a sun), so that the two weights of a path still add up to one: the
        // light samples of `Direct` and the hemisphere rays of `Indirect` share each
        // emitter's light, neither taking it all (light samples alone are unbounded beside an
        // emitter, at a room's corner).
        let (nl, nc) = match parts {
            LightParts::All => (direct as f64, grid.len() as f64),
            _ => (if lamps { 1.0 } else { 0.0 }, 1.0),
        };
        Split {
            draw: draw.unwrap_or_else(Draw::by_power),
            direct,
            sun: n_sun,
            grid,
            nl,
            nc,
            weigh: (parts != LightParts::All && lamps).then(Draw::by_power),
            whole,
            follow: if parts == LightParts::IndirectOnce {
                1
            } else {
                super::NEAR_DEPTH
            },
        }
    }
}

impl<I: Intersector> Kernel<'_, I> {
    /// The gather at `spot` that `ask` asks for: the emitters' light samples, the sun's, then
    /// the hemisphere rays, in that order (so the random numbers are drawn in that order).
    pub(crate) fn gather_at<R: Rng>(&self, spot: &Spot, ask: Ask, rng: &mut R) -> Gathered {
        self.gather_learning(spot, ask, None, rng)
    }

    /// [`Self::gather_at`], its cut's draw weighed by what the gathers before it on the same
    /// surface found (`learned`, [`super::emitters::Learned`]), and what its own light samples
    /// find added to it.
    pub(crate) fn gather_learning<R: Rng>(
        &self,
        spot: &Spot,
        ask: Ask,
        mut learned: Option<&mut Learned>,
        rng: &mut R,
    ) -> Gathered {
        let mut g = Gathered {
            h: Rgb::ZERO,
            ch: vec![Rgb::ZERO; self.sol.channels.len()],
            var: 0.0,
            rays: 0,
            reflected: Rgb::ZERO,
            vis: Default::default(),
        };
        let lamps = !self.emitters.is_empty() && ask.lights;
        // A gather draws its emitters by what they can give its spot (none: no light samples
        // at all); a patch's gather split in parts (`LightParts`) by what they can give its
        // whole polygon (`Kernel::polygon_draw`), its MIS weights by power (`Split::weigh`):
        // drawn by power over the whole model, most of a point's light samples went to other
        // rooms' lamps. What earlier gathers learnt (`learned`) only shapes a whole gather's.
        // A point in the air split in parts draws by power.
        let mut whole = WholeSet::default();
        let draw = match (lamps, ask.parts) {
            (false, _) => None,
            (true, parts) if parts != LightParts::All && spot.patch == super::NO_PATCH => {
                Some(Draw::by_power())
            }
            (true, parts) if parts != LightParts::All => {
                let (draw, w) = self.polygon_draw(spot, parts.sets_whole_apart());
                whole = w;
                draw
            }
            (true, _) => {
                let r = self.receiver(spot);
                let l = learned.as_deref();
                let draw = match l.and_then(Learned::shared_cut) {
                    Some(nodes) => self.emitters.draw_among(nodes, &r),
                    None if spot.patch == super::NO_PATCH => self.emitters.draw_for(&r),
                    None => self.emitters.draw_shaped(&r, spot.patch),
                };
                let draw = match spot.patch {
                    super::NO_PATCH => draw,
                    i => draw.map(|d| self.emitters.sighted(d, i)),
                };
                draw.map(|d| match l {
                    Some(l) => self.emitters.learned(d, l),
                    None => d,
                })
            }
        };
        let sun = self.sky.sun();
        let split = Split::new(ask.parts, (draw, whole), sun.is_some(), ask.rays);
        if split.direct > 0 && ask.parts == LightParts::DirectWhole {
            self.whole_direct_part(spot, (&split, ask.known), &mut g, rng);
        } else if split.direct > 0 {
            self.direct_part(spot, &split, &mut g, learned.as_deref_mut(), rng);
        }
        if let Some(sun) = sun.filter(|_| split.sun > 0) {
            self.sun_part(spot, sun, split.sun, &mut g, rng);
        }
        if !self.mesh.luminaires.is_empty() && ask.parts.direct() {
            self.luminaires_part(spot, ask.rays, &mut g, rng);
        }
        if ask.parts.hemisphere() {
            self.hemisphere_part(spot, &split, &mut g, rng);
        }
        if let Some(l) = learned {
            l.settle();
        }
        g
    }
}

thread_local! {
    /// The draw of the polygon this thread last gathered in parts on, keyed by the kernel, the
    /// polygon and the facing ([`Kernel::polygon_draw`]).
    static POLYGON_DRAW: RefCell<Option<(PolygonKey, PolygonDraw)>> =
        const { RefCell::new(None) };
}

/// A polygon's draw, and the emitters it takes whole ([`super::exact`]) once a gather asked.
type PolygonDraw = (Option<Draw>, Option<WholeSet>);

/// A kept polygon draw's key: the kernel's id, the polygon and the facing (its bits).
type PolygonKey = (u64, u32, [u32; 3]);

impl<I> Kernel<'_, I> {
    /// The draw of the polygon `spot`'s patch is cut from, facing the patch's way: its cut of
    /// the emitters' tree for the polygon's bounding sphere ([`super::emitters::Emitters::draw_for`]),
    /// what every gather in parts on the polygon draws from. The same for every point of the
    /// polygon, as their random numbers are (`elements` seeds a point's gather by its polygon),
    /// so two points' values differ by the light, not by the samples: drawn per patch, a
    /// patch's corner gathered as its neighbour and its own midpoints read different lamps'
    /// samples, and a uniformly lit furnace was refined for that noise. A polygon's points are
    /// gathered one after another (the elements' corners, a picture's pixels), so the last
    /// polygon's draw is kept per thread (a cut per point was 28 % of a generated 100 k-patch
    /// building's run). A pure function of the kernel, the polygon and the facing, so the
    /// results do not depend on it. With the draw, when `whole` asks, the emitters it takes
    /// whole ([`super::emitters::WHOLE_MASS`]; made once per polygon, and only then).
    fn polygon_draw(&self, spot: &Spot, whole: bool) -> (Option<Draw>, WholeSet) {
        let p = &self.mesh.patches[spot.patch];
        let key = (p.polygon, p.normal.to_array().map(f32::to_bits));
        let key = (self.id, key.0, key.1);
        POLYGON_DRAW.with(|kept| {
            let mut kept = kept.borrow_mut();
            if kept.as_ref().is_none_or(|(k, _)| *k != key) {
                let (centre, radius) =
                    self.polygons.get_or_init(|| polygon_spheres(self.mesh))[p.polygon as usize];
                let r = Receiver {
                    centre,
                    normal: p.normal,
                    radius,
                };
                *kept = Some((key, (self.emitters.draw_for(&r), None)));
            }
            let (_, (draw, taken)) = kept.as_mut().expect("kept above");
            if !whole {
                return (draw.clone(), WholeSet::default());
            }
            let taken = taken.get_or_insert_with(|| {
                draw.as_ref().map_or_else(WholeSet::default, |d| {
                    use super::emitters::{WHOLE_MASS, WHOLE_MOST};
                    self.emitters.whole(self.mesh, d, WHOLE_MASS, WHOLE_MOST)
                })
            });
            (draw.clone(), taken.clone())
        })
    }

    /// The gathers of `patches` (neighbours on one plane, facing one way, gathered next with
    /// `learned`) share the shape of one cut of the emitters' tree ([`Learned::share_cut`]);
    /// a single patch makes its own.
    pub(crate) fn share_cut(&self, patches: &[usize], learned: &mut Learned) {
        if patches.len() < 2 || self.emitters.is_empty() {
            learned.share_cut(None);
            return;
        }
        let parts: Vec<(Receiver, f32)> = (patches.iter())
            .map(|&i| (self.patch_receiver(i), self.mesh.patches[i].area as f32))
            .collect();
        let nodes = (self.emitters).cut_nodes_shaped(&Receiver::covering(&parts), patches[0]);
        learned.share_cut(Some(nodes));
    }

    /// The receiver a spot's emitters are weighed for: its patch (centre, normal and the
    /// distance to its farthest corner), or the sensor's point.
    fn receiver(&self, spot: &Spot) -> Receiver {
        if spot.patch == super::NO_PATCH {
            return Receiver {
                centre: (spot.at)(0.5, 0.5),
                normal: spot.n,
                radius: 0.0,
            };
        }
        self.patch_receiver(spot.patch)
    }

    /// Patch `i` as a receiver: its centre, normal and the distance to its farthest corner.
    pub(super) fn patch_receiver(&self, i: usize) -> Receiver {
        let p = &self.mesh.patches[i];
        let radius = (self.mesh.patch_indices(i).iter())
            .map(|&v| self.mesh.vertices[v as usize].distance(p.centre))
            .fold(0.0f32, f32::max);
        Receiver {
            centre: p.centre,
            normal: p.normal,
            radius,
        }
    }
}

/// Per polygon of `mesh` (by id), the centre and half-diagonal of the bounding box of its
/// patches' corners (a polygon no patch was cut from: the origin, radius 0).
fn polygon_spheres(mesh: &crate::mesh::Mesh) -> Vec<(Vec3, f32)> {
    let n = (mesh.patches.iter())
        .map(|p| p.polygon as usize + 1)
        .max()
        .unwrap_or(0);
    let mut boxes = vec![(Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)); n];
    for (i, p) in mesh.patches.iter().enumerate() {
        let b = &mut boxes[p.polygon as usize];
        for &v in mesh.patch_indices(i) {
            let x = mesh.vertices[v as usize];
            *b = (b.0.min(x), b.1.max(x));
        }
    }
    (boxes.into_iter())
        .map(|(lo, hi)| match lo.x <= hi.x {
            true => ((lo + hi) * 0.5, (hi - lo).length() * 0.5),
            false => (Vec3::ZERO, 0.0),
        })
        .collect()
}

/// The variance of the mean of stratified samples, by collapsing neighbouring strata in
/// pairs (Cochran, *Sampling Techniques*, 3rd ed., 1977, Sec. 5A.12; Wolter, *Introduction to
/// Variance Estimation*, 2nd ed., 2007, Sec. 8.2, the successive-difference estimator): samples
/// `2m` and `2m + 1` come from neighbouring strata (adjacent polar cells of one ring; adjacent
/// draws along the emitters' CDF), so Var(mean) ≈ Σ_m (x_2m − x_2m+1)² / N². The sample
/// variance of independent draws would ignore what stratification removes and overstate the
/// gather's noise several times over.
pub(super) fn stratified_var(x: &[f64]) -> f64 {
    let n = x.len();
    if n < 2 {
        return 0.0;
    }
    let sum: f64 = x.chunks_exact(2).map(|p| (p[0] - p[1]).powi(2)).sum();
    // An odd last sample counts as a pair's worth of the others.
    let pairs = n / 2;
    sum * (n as f64 / (2 * pairs) as f64) / (n * n) as f64
}

/// Latin-hypercube points on the unit square: both coordinates stratified into `n` strata,
/// each coordinate's strata in an independent random order — or, with `ordered`, the first
/// coordinate's strata in index order (sample k in stratum k, for the collapsed-pair variance).
/// Two sets zipped together must not both be ordered: their first coordinates would be
/// perfectly correlated (points on one part of the patch always paired with one light).
pub(super) fn latin<R: Rng>(n: usize, ordered: bool, rng: &mut R) -> Vec<(f32, f32)> {
    let mut pu: Vec<usize> = (0..n).collect();
    let mut pv = pu.clone();
    if !ordered {
        pu.shuffle(rng);
    }
    pv.shuffle(rng);
    pu.iter()
        .zip(&pv)
        .map(|(&a, &b)| {
            let u = (a as f32 + rng.gen::<f32>()) / n as f32;
            let v = (b as f32 + rng.gen::<f32>()) / n as f32;
            (u.min(1.0), v.min(1.0))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    /// Collapsed pairs: the variance of the mean from the differences within pairs, an odd
    /// last sample counted as a pair's worth.
    #[test]
    fn stratified_variance_collapses_pairs() {
        assert_eq!(stratified_var(&[3.0]), 0.0);
        let v = stratified_var(&[1.0, 3.0, 2.0, 2.0]);
        assert!((v - 4.0 / 16.0).abs() < 1e-15, "{v}");
        let odd = stratified_var(&[1.0, 3.0, 5.0]);
        assert!((odd - 4.0 * 1.5 / 9.0).abs() < 1e-15, "{odd}");
    }

    /// Latin-hypercube points: one per stratum in each coordinate, the first in index order
    /// when asked.
    #[test]
    fn latin_points_fill_every_stratum() {
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(3);
        let n = 16;
        for ordered in [false, true] {
            let pts = latin(n, ordered, &mut rng);
            let cell = |x: f32| ((x * n as f32) as usize).min(n - 1);
            let mut us: Vec<usize> = pts.iter().map(|p| cell(p.0)).collect();
            let mut vs: Vec<usize> = pts.iter().map(|p| cell(p.1)).collect();
            if ordered {
                assert_eq!(us, (0..n).collect::<Vec<_>>());
            }
            us.sort_unstable();
            vs.sort_unstable();
            assert_eq!(us, (0..n).collect::<Vec<_>>());
            assert_eq!(vs, (0..n).collect::<Vec<_>>());
        }
    }
}
