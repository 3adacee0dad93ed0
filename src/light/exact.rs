//! The direct light of the emitters a surface draws most, taken whole: their unoccluded
//! irradiance in closed form, times the share of it the shadow rays find unblocked
//! ([`LightParts::DirectWhole`](super::LightParts::DirectWhole), the adaptive elements'
//! corners).
//!
//! **Closed form.** A Lambertian polygon of exitance E gives a point x facing n the irradiance
//! E·F, F = (1/2π) Σ_k θ_k (n·ĉ_k) over its edges (v_k, v_k+1) seen from x: θ_k the angle
//! the edge subtends, ĉ_k the unit normal of the plane through x and the edge (Lambert's
//! contour integral; Baum, Rushmeier & Winget, *Improving Radiosity Solutions Through the Use
//! of Analytically Determined Form-Factors*, SIGGRAPH 1989, Sec. 3), the polygon first
//! clipped to the part above x's plane. The whole emitters cut from one face of the model
//! (`emitters::Shape`: one polygon, facing one way, one exitance) are summed over the face's
//! outline, the terms of the edges they share cancelling (a lamp of eight patches costs its
//! four sides, not thirty-two), unless part of the face lies below x's plane.
//!
//! **Visibility.** Of a light sample to such a face only its ray is used: the rays give the
//! ratio V = Σ f/p ÷ Σ g/p of what reached x (f, through any glazing) to what would have with
//! nothing in between (g), and the light is E·F·V. The rays pick the faces by their
//! unoccluded light at the point, a point uniform on the face. Each face that gives the point
//! at least 2/8 of the whole faces' light has its own V (a lamp is seen or hidden as one; the
//! first stage's stratified rays reach it), the others share one. Where a unit's rays agree — all
//! unblocked or all blocked, as at most points of a room — its V is exactly 1 or 0 and its
//! light has no noise at all, where light samples alone carry the spread of 1/r² and the
//! cosines (beside a lamp, unbounded). So the rays come in two stages: a first third,
//! stratified on its own; the rest only for the units whose
//! first rays disagree or found nothing (adaptive shadow testing; Ward, *Adaptive Shadow
//! Testing for Ray Tracing*, Eurographics Rendering Workshop 1991). The ratio is consistent,
//! not unbiased: a penumbra that every first-stage ray of its unit misses reads as lit or
//! dark (measured: docs/results/adaptive-elements.md).
//!
//! **Told by the points around** ([`Vis`]): a gather reports which faces its units saw whole
//! or not at all (a face that gives the point no light counts as not seen: it lies behind the
//! point's plane or the point behind its own, which holds across a planar patch as it holds
//! at the patch's corners), and takes the faces its caller says the points around it all saw
//! alike as seen so, with no ray (`Ask::known`; the adaptive elements' midpoints, from their
//! edge's or element's corners). Its rays go to the other faces only.
//!
//! The emitters taken whole are the ones the polygon's cut holds as leaves of their own, each
//! drawn with probability at least `emitters::WHOLE_MASS` (`Emitters::whole`); the rest keep
//! their light samples at their MIS weights (a sample that draws a whole emitter counts 0, no
//! ray). The hemisphere rays of the same surface (`IndirectOnce`) leave the whole emitters'
//! light out entirely: the two parts still add up to the whole light.

use super::emitters::Shape;
use super::gather::{latin, stratified_var, Gathered, Split, Spot, Vis};
use super::{scalar, Kernel, Origin, Rgb};
use crate::intersect::Intersector;
use glam::DVec3;
use rand::Rng;
use smallvec::SmallVec;

/// The first stage's share of the light samples: one in this many.
const FIRST_STAGE: usize = 3;

/// The form factor from a point `x` facing `n` to the polygon `poly` (planar, convex or
/// not; wound either way), in closed form: the part of it above x's plane.
pub fn point_to_polygon(x: DVec3, n: DVec3, poly: &[DVec3]) -> f64 {
    // Sutherland–Hodgman against the plane n·(y − x) = 0, keeping the side n points to (all
    // of it, as mostly, when no corner lies below).
    let mut clipped: SmallVec<[DVec3; 8]> = SmallVec::new();
    if poly.iter().all(|&a| n.dot(a - x) >= 0.0) {
        clipped.extend(poly.iter().map(|&a| a - x));
    } else {
        for (k, &a) in poly.iter().enumerate() {
            let b = poly[(k + 1) % poly.len()];
            let (ha, hb) = (n.dot(a - x), n.dot(b - x));
            if ha >= 0.0 {
                clipped.push(a - x);
            }
            if (ha >= 0.0) != (hb >= 0.0) {
                let t = ha / (ha - hb);
                clipped.push(a + (b - a) * t - x);
            }
        }
    }
    if clipped.len() < 3 {
        return 0.0;
    }
    let sum: f64 = (0..clipped.len())
        .map(|k| edge_term(clipped[k], clipped[(k + 1) % clipped.len()], n))
        .sum();
    (sum.abs() / std::f64::consts::TAU).min(1.0)
}

/// One edge's term of the contour integral, its ends `a`, `b` relative to the point facing
/// `n`: the angle it subtends times the cosine between n and the normal of its plane.
fn edge_term(a: DVec3, b: DVec3, n: DVec3) -> f64 {
    let c = a.cross(b);
    let len = c.length();
    if len <= 1e-300 {
        return 0.0;
    }
    len.atan2(a.dot(b)) * n.dot(c) / len
}

/// The unoccluded irradiance (RGB) the face `shape` gives the point `x` facing `n`: 0 where x
/// lies behind its emitting side; over its outline where all of it lies above x's plane (the
/// terms of the edges its members share cancel), else member by member, clipped.
fn shape_light(shape: &Shape, x: DVec3, n: DVec3) -> Rgb {
    if shape.normal.dot(x - shape.corners[0]) <= 0.0 {
        return Rgb::ZERO;
    }
    let f = if shape.corners.iter().all(|&c| n.dot(c - x) >= 0.0) {
        let sum: f64 = (shape.outline.iter())
            .map(|&[a, b]| edge_term(a - x, b - x, n))
            .sum();
        (sum.abs() / std::f64::consts::TAU).min(1.0)
    } else {
        (0..shape.first.len())
            .map(|k| {
                let end = shape
                    .first
                    .get(k + 1)
                    .copied()
                    .unwrap_or(shape.corners.len());
                point_to_polygon(x, n, &shape.corners[shape.first[k]..end])
            })
            .sum::<f64>()
            .min(1.0)
    };
    shape.e * f
}

impl<I: Intersector> Kernel<'_, I> {
    /// The emitters' direct light at `spot`'s point (u, v = ½): the whole emitters'
    /// (`split.whole`) in closed form, each times what its shadow rays find unblocked, in two
    /// stages (module notes); the others' by `split.direct` light samples as
    /// [`Self::direct_part`] takes them (a sample that draws a whole emitter counts 0 and
    /// casts nothing); the faces `known` tells taken as told (module notes, "Told by the points
    /// around"). Into `g`, with what its rays told ([`Gathered::vis`]).
    pub(super) fn whole_direct_part<R: Rng>(
        &self,
        spot: &Spot,
        (split, known): (&Split, Vis),
        g: &mut Gathered,
        rng: &mut R,
    ) {
        let from = spot.origin(0.5, 0.5);
        let n = split.direct.max(1);
        let first = (n / FIRST_STAGE).max(1);
        let all = whole_faces(&split.whole.shapes, &from);
        // The faces the points around this one saw whole or not at all, seen alike here
        // (module notes, "Told by the points around"): no ray.
        let told = |w: &Whole| (known.lit | known.dark) & bit(w.shape) != 0;
        let given: Rgb = (all.iter())
            .filter(|w| known.lit & bit(w.shape) != 0)
            .map(|w| w.open)
            .sum();
        let (whole, mut units) = whole_units(all.iter().filter(|w| !told(w)).cloned(), first);
        // Stage one: a third of the rays over the whole faces by their unoccluded light;
        // stage two: the rest over those of the units whose rays disagreed or that none told.
        let at = (&from, &split.whole.shapes[..]);
        self.shadow_stage(at, (&whole, &mut units), first, |_| true, g, rng);
        let unsettled: Vec<bool> = units.iter().map(|u| !u.settled()).collect();
        let rest = n - first;
        self.shadow_stage(at, (&whole, &mut units), rest, |u| unsettled[u], g, rng);
        let mut pooled = Unit::new();
        for u in &units {
            pooled.reached += u.reached;
            pooled.unblocked += u.unblocked;
        }
        let pooled = ratio(pooled.reached, pooled.unblocked, Rgb::ONE);
        let seen: Vec<Rgb> = (units.iter())
            .map(|u| match (u.told > 0, u.lit, u.dark) {
                (true, true, _) => Rgb::ONE,
                (true, _, true) => Rgb::ZERO,
                _ => ratio(u.reached, u.unblocked, pooled),
            })
            .collect();
        let k = g.ch.len();
        let mut sum = given;
        g.vis = told_here(split.whole.shapes.len(), &all, known, &whole, &units);
        for w in &whole {
            let light = w.open * seen[w.unit];
            sum += light;
            if let Some(gr) = self.sol.group {
                let e = split.whole.shapes[w.shape].members[0] as usize;
                let gj = gr[self.emitters.patches[e]] as usize;
                if gj < k {
                    g.ch[gj] += light;
                }
            }
        }
        // The other emitters: light samples by the draw, those of whole emitters counting 0.
        let mut m = Vec::with_capacity(n);
        let samples = if split.whole.leaves_some() {
            latin(n, true, rng)
        } else {
            Vec::new()
        };
        for (s, t) in samples {
            let (e, mass, s2, _) = self.emitters.pick_node(&split.draw, f64::from(s));
            if split.whole.has(e) {
                m.push(0.0);
                continue;
            }
            let em = &self.emitters.at[e];
            let y = em.points.at(s2, t);
            let w = (split.weigh.as_ref())
                .map_or(mass, |w| self.emitters.mass(w, e, scalar(em.e) * em.area));
            let (val, j, cast) = self.light_sample(&from, (e, mass, w), y, (split.nl, split.nc));
            g.rays += u64::from(cast);
            m.push(scalar(spot.rho * val));
            sum += val / n as f64;
            if let Some(gr) = self.sol.group {
                let gj = gr[j] as usize;
                if gj < k {
                    g.ch[gj] += val / n as f64;
                }
            }
        }
        g.h += sum;
        g.var += stratified_var(&m);
    }

    /// `count` shadow rays from `from` to the whole faces of the units `which` picks, drawn in
    /// proportion to their unoccluded light (stratified), a member of the face by its area and
    /// a point uniform on it: what each ray finds, over its density, is added to its unit's
    /// books.
    fn shadow_stage<R: Rng>(
        &self,
        (from, shapes): (&Origin, &[Shape]),
        (whole, units): (&[Whole], &mut [Unit]),
        count: usize,
        which: impl Fn(usize) -> bool,
        g: &mut Gathered,
        rng: &mut R,
    ) {
        let picked: Vec<&Whole> = whole.iter().filter(|w| which(w.unit)).collect();
        let total: f64 = picked.iter().map(|w| scalar(w.open)).sum();
        // Drawn whether or not any face is left to cast to (the faces told by the points
        // around take none): the light samples after them then draw the same numbers at every
        // point of the polygon, whose differences are then the light's, not the noise's.
        let draws = latin(count, true, rng);
        if count == 0 || total <= 0.0 {
            return;
        }
        for (s, t) in draws {
            // The face at s along the CDF of their light, its member at the rest of s by area.
            let mut x = f64::from(s) * total;
            let mut at = picked[picked.len() - 1];
            for &w in &picked {
                if x < scalar(w.open) {
                    at = w;
                    break;
                }
                x -= scalar(w.open);
            }
            let shape = &shapes[at.shape];
            let area = shape.areas[shape.areas.len() - 1];
            let a = (x / scalar(at.open)).clamp(0.0, 1.0) * area;
            let k = shape
                .areas
                .partition_point(|&c| c <= a)
                .min(shape.areas.len() - 1);
            let lo = if k == 0 { 0.0 } else { shape.areas[k - 1] };
            let rest = ((a - lo) / (shape.areas[k] - lo).max(f64::MIN_POSITIVE)) as f32;
            let e = shape.members[k] as usize;
            let em = &self.emitters.at[e];
            let y = em.points.at(rest.clamp(0.0, 1.0), t);
            let Some(sh) = self.direct(from, (self.emitters.patches[e], em), y) else {
                continue;
            };
            g.rays += 1;
            // ÷ the density: the face's share of the stage's light, over its area.
            let scale = area * total / scalar(at.open);
            let open = sh.open;
            let u = &mut units[at.unit];
            u.lit &= scalar(sh.e_g) >= scalar(open) * (1.0 - 1e-9);
            u.dark &= scalar(sh.e_g) <= 0.0;
            u.told += 1;
            u.reached += sh.e_g * scale;
            u.unblocked += open * scale;
        }
    }
}

/// The whole faces that give `from` light unoccluded, each with that light.
fn whole_faces(shapes: &[Shape], from: &Origin) -> Vec<Whole> {
    let (x, n) = (from.x.as_dvec3(), from.n.as_dvec3());
    (shapes.iter().enumerate())
        .map(|(k, sh)| Whole {
            shape: k,
            open: shape_light(sh, x, n),
            unit: 0,
        })
        .filter(|w| scalar(w.open) > 0.0)
        .collect()
}

/// The units the visibility of the faces `faces` is told by: one per face (a lamp's face is
/// seen or not as one) that gives at least 2/`first` of their light — so the first stage's
/// stratified rays reach it — and one for all the rest together.
fn whole_units(faces: impl Iterator<Item = Whole>, first: usize) -> (Vec<Whole>, Vec<Unit>) {
    let mut out: Vec<Whole> = faces.collect();
    let total: f64 = out.iter().map(|w| scalar(w.open)).sum();
    let mut big = 0;
    for w in &mut out {
        if scalar(w.open) >= 2.0 / first as f64 * total {
            big += 1;
            w.unit = big;
        }
    }
    let units = (0..=big).map(|_| Unit::new()).collect();
    (out, units)
}

/// Face `k`'s bit in a [`Vis`] (faces past the 64th have none: always told by rays).
fn bit(k: usize) -> u64 {
    if k < 64 {
        1 << k
    } else {
        0
    }
}

/// What a point's gather tells of each of its polygon's `count` whole faces: seen whole (every
/// ray its unit cast arrived, or the points around said so), or dark (every ray blocked, the
/// points around said so, or the face gives the point no light: it lies behind the point's
/// plane, or the point behind the face's, which holds across a patch as it holds at its
/// corners).
fn told_here(count: usize, all: &[Whole], known: Vis, whole: &[Whole], units: &[Unit]) -> Vis {
    let mut v = known;
    let lights: u64 = all.iter().map(|w| bit(w.shape)).fold(0, |a, b| a | b);
    let faces = if count >= 64 {
        u64::MAX
    } else {
        (1u64 << count) - 1
    };
    v.dark |= faces & !lights;
    for w in whole {
        let u = &units[w.unit];
        if u.settled() && u.lit {
            v.lit |= bit(w.shape);
        } else if u.settled() && u.dark {
            v.dark |= bit(w.shape);
        }
    }
    v
}

/// One whole face at a point: its unoccluded light and the unit its visibility is told by.
#[derive(Clone)]
struct Whole {
    shape: usize,
    open: Rgb,
    unit: usize,
}

/// A unit's books at a point: what its shadow rays found, the sum of their samples reached
/// and of the same unblocked (each over its density), and whether they all agreed.
struct Unit {
    reached: Rgb,
    unblocked: Rgb,
    lit: bool,
    dark: bool,
    told: u32,
}

impl Unit {
    fn new() -> Unit {
        Unit {
            reached: Rgb::ZERO,
            unblocked: Rgb::ZERO,
            lit: true,
            dark: true,
            told: 0,
        }
    }

    /// Whether its rays told its visibility and agreed.
    fn settled(&self) -> bool {
        self.told > 0 && (self.lit || self.dark)
    }
}

/// `reached / unblocked` per channel, in [0, 1]; `or` where nothing was told.
fn ratio(reached: Rgb, unblocked: Rgb, or: Rgb) -> Rgb {
    Rgb::from_array([0, 1, 2].map(|c| {
        if unblocked[c] > 0.0 {
            (reached[c] / unblocked[c]).clamp(0.0, 1.0)
        } else {
            or[c]
        }
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit square 1 m above a point facing it, centred: F = 0.2395 (the parallel
    /// point-to-rectangle formula with a = b = 0.5, c = 1, times four quarters).
    #[test]
    fn a_square_overhead_gives_the_textbook_form_factor() {
        let sq = [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)]
            .map(|(x, y)| DVec3::new(x, y, 1.0));
        let f = point_to_polygon(DVec3::ZERO, DVec3::Z, &sq);
        // Quarter rectangle a × b at height c: (1/2π)[A/√(1+A²) atan(B/√(1+A²)) + B/√(1+B²)
        // atan(A/√(1+B²))], A = a/c, B = b/c.
        let (a, b) = (0.5f64, 0.5f64);
        let q = (a / (1.0 + a * a).sqrt() * (b / (1.0 + a * a).sqrt()).atan()
            + b / (1.0 + b * b).sqrt() * (a / (1.0 + b * b).sqrt()).atan())
            / std::f64::consts::TAU;
        assert!((f - 4.0 * q).abs() < 1e-12, "{f} against {}", 4.0 * q);
        // Wound the other way: the same.
        let mut rev = sq;
        rev.reverse();
        assert!((point_to_polygon(DVec3::ZERO, DVec3::Z, &rev) - f).abs() < 1e-12);
    }

    /// A polygon straddling the point's plane counts its part above only; one below gives 0;
    /// one filling the hemisphere gives 1.
    #[test]
    fn the_horizon_clips_the_polygon() {
        let wall = [
            (1.0, -1.0, -1.0),
            (1.0, 1.0, -1.0),
            (1.0, 1.0, 1.0),
            (1.0, -1.0, 1.0),
        ]
        .map(|(x, y, z)| DVec3::new(x, y, z));
        let half = [
            (1.0, -1.0, 0.0),
            (1.0, 1.0, 0.0),
            (1.0, 1.0, 1.0),
            (1.0, -1.0, 1.0),
        ]
        .map(|(x, y, z)| DVec3::new(x, y, z));
        let f = point_to_polygon(DVec3::ZERO, DVec3::Z, &wall);
        let h = point_to_polygon(DVec3::ZERO, DVec3::Z, &half);
        assert!(f > 0.0 && (f - h).abs() < 1e-12, "{f} {h}");
        assert_eq!(point_to_polygon(DVec3::ZERO, -DVec3::X, &half), 0.0);
        let sky = [(-1e6, -1e6), (1e6, -1e6), (1e6, 1e6), (-1e6, 1e6)]
            .map(|(x, y)| DVec3::new(x, y, 1.0));
        assert!((point_to_polygon(DVec3::ZERO, DVec3::Z, &sky) - 1.0).abs() < 1e-5);
    }
}
