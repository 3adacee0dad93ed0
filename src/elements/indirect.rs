//! The indirect light of [`CornerLight::Split`]: gathered once at the nodes of every patch's
//! first test (corners, edge midpoints, a quad's centre; the hemisphere's rays, the emitters'
//! light left out: [`LightParts::Indirect`]) and interpolated quadratically across the
//! patch's elements, whose corners gather only the direct light.
//!
//! **Why.** What changes fast across a patch — shadow edges, the peak beside a light — is the
//! emitters' and the sun's light, which shadow rays sample with little noise; the light the
//! patch solution sends (the indirect part) changes slowly, and its hemisphere rays are the
//! noisy, costly part of a corner's gather. So they are cast only at a few nodes per patch,
//! each shared by every patch of the surface that has it, and the elements refine on the direct
//! light with the indirect interpolated beneath (the test then sees the indirect's curvature
//! too: it is in every point's value).
//!
//! **Why quadratic.** Near a contact (a wall meeting the floor, under a table) the indirect
//! light falls off along a curve that a bilinear interpolation of the patch's corners misses:
//! on `scenes/spot.obj` (0.4 m patches), corners alone left an error floor of 1.48 % under
//! every mesh even at 2,048 rays a corner, the quadratic through the nine nodes 0.86 % at 256
//! (the whole gather at every corner: 0.76 %). README, "Adaptive elements", has the costs.
//!
//! **Which patches.** Only those that see geometry near enough to bend their indirect light
//! within them by more than the threshold of their whole light ([`near_patches`]: Ward,
//! Rubinstein & Clear's criterion from the harmonic mean distance of what a patch sees, times
//! the indirect light's share of the patch's radiosity, both measured with a few probe rays).
//! Elsewhere the indirect light
//! is as smooth as the patch solution draws it, and the final gather has measured every
//! patch's B with more rays than a node gets: such a patch's points gather the direct light
//! only, its indirect light is the patch solution's (B less its elements' mean direct light,
//! averaged to the welded vertices, as [`super::CornerLight::Direct`] takes it), at no
//! hemisphere ray. On the office 581 of 2,092 patches gather nodes (803 before the share was
//! weighed in), on a generated 100 k-patch building 31,317 of 97,703 (42,219); on
//! `scenes/spot.obj` leaving the rest to the patch solution lowered the error too (1.19 → 1.14
//! % at the default mesh: the patches' estimates are less noisy than 64-ray nodes;
//! docs/results/adaptive-elements.md).
//!
//! **Which nodes.** Every root's corners first (about one distinct point a patch, shared);
//! only a patch whose corners' indirect light differs by more than [`SPREAD`], beyond what
//! their own noise explains, gathers its midpoints and centre and is interpolated
//! quadratically, the others bilinearly: where the corners agree, the light between them is
//! as flat as the noise can tell.

use super::geometry::Elem;
use super::work::{gather_new, At, PatchWork, Values};
use super::NOISE_Z;
use crate::intersect::Intersector;
use crate::light::LightAt;
use crate::mesh::Mesh;
use crate::sample::Frame;
use crate::solve::{rng_for, scalar, Stream};
use glam::{DVec2, DVec3, Vec3};
use rand::Rng;
use rayon::prelude::*;

/// The nodes of root element `e`'s quadratic: its corners, then its edge midpoints (edge k
/// from corner k), then a quad's centre — the points of its first midpoint test. The first
/// `e.count()` are the corners, all a root whose indirect light is smooth keeps.
fn nodes(e: &Elem) -> Vec<DVec2> {
    let uv = e.corners_uv();
    let n = uv.len();
    let mut pts = uv.to_vec();
    pts.extend((0..n).map(|k| (uv[k] + uv[(k + 1) % n]) * 0.5));
    if !e.tri {
        pts.push(e.centre_uv());
    }
    pts
}

/// The indirect light at parameters `uv` of a root whose nodes have the values `f` (in the
/// order of `nodes`; a patch's [`PatchWork::ind_nodes`]): bilinear from a quad's 4 corners,
/// affine from a triangle's 3, the quadratic through all the nodes (biquadratic on a quad's
/// 3 × 3, the six-node quadratic on a triangle); not below 0.
pub(super) fn at(f: &[([f64; 3], f64)], uv: DVec2) -> [f64; 3] {
    let mut out = [0.0; 3];
    for ((x, _), wt) in f.iter().zip(weights(f.len(), uv)) {
        for c in 0..3 {
            out[c] += wt * x[c];
        }
    }
    out.map(|x| x.max(0.0))
}

/// The variance of [`at`]'s value from independent nodes `f` (their variances σₖ²): Σ wₖ² σₖ².
pub(super) fn var_at(f: &[([f64; 3], f64)], uv: DVec2) -> f64 {
    (f.iter().zip(weights(f.len(), uv)))
        .map(|((_, v), wt)| wt * wt * v)
        .sum()
}

/// The weights of [`at`]'s interpolation from `n` nodes at `uv`.
fn weights(n: usize, uv: DVec2) -> Vec<f64> {
    let (u, v) = (uv.x, uv.y);
    match n {
        3 => vec![1.0 - u - v, u, v],
        4 => vec![(1.0 - u) * (1.0 - v), u * (1.0 - v), u * v, (1.0 - u) * v],
        9 => {
            let l = |t: f64| {
                [
                    2.0 * (t - 0.5) * (t - 1.0),
                    -4.0 * t * (t - 1.0),
                    2.0 * t * (t - 0.5),
                ]
            };
            let (lu, lv) = (l(u), l(v));
            // Node order of `nodes`: (i, j) on the 3 × 3 grid of u, v ∈ {0, ½, 1}.
            let grid = [
                (0, 0),
                (2, 0),
                (2, 2),
                (0, 2),
                (1, 0),
                (2, 1),
                (1, 2),
                (0, 1),
                (1, 1),
            ];
            grid.iter().map(|&(i, j)| lu[i] * lv[j]).collect()
        }
        _ => {
            let (a, b, c) = (1.0 - u - v, u, v);
            vec![
                a * (2.0 * a - 1.0),
                b * (2.0 * b - 1.0),
                c * (2.0 * c - 1.0),
                4.0 * a * b,
                4.0 * b * c,
                4.0 * c * a,
            ]
        }
    }
}

/// A patch whose corners' indirect light differs by more than this fraction of their mean
/// (the difference of the two farthest apart less [`NOISE_Z`] standard deviations of their
/// noise, in quadrature) gathers the rest of its nodes (edge midpoints, a quad's centre) and is interpolated
/// quadratically; below it, bilinearly from its corners (0.05–0.3 measured alike on
/// `scenes/spot.obj`, 0.3 the fewest rays; docs/results/adaptive-elements.md).
pub const SPREAD: f64 = 0.3;

/// Gathers each distinct point that `list` gives the patches `patches` (in increasing order)
/// and `values.indirect` lacks, once ([`gather_new`]).
fn gather_points(
    work: &[PatchWork],
    patches: &[usize],
    list: impl Fn(usize, &PatchWork) -> Vec<(At, DVec3)> + Sync + Send,
    indirect: &(impl Fn(usize, DVec3) -> ([f64; 3], f64, u64) + Sync),
    values: &mut Values,
) {
    let (rays, gathered) = gather_new(
        &mut values.indirect,
        (patches.len(), |k| patches[k]),
        (|i| list(i, &work[i]), |_, p| p, |_| false),
        |_, i, _, x| {
            let (b, var, n) = indirect(i, x);
            ((b, var), n)
        },
        ([0.0; 3], 0.0),
    );
    values.rays += rays;
    values.gathered += gathered;
}

/// Gathers the indirect light at the nodes of the roots of every patch that `near` marks
/// ([`near_patches`]) into `values.indirect` and sets those patches'
/// [`PatchWork::ind_nodes`] (the others' stay empty): first every root's corners (each distinct
/// point once, by the lowest-numbered patch that has it; in parallel), then the other nodes
/// of the patches whose corners' indirect light differs by more than [`SPREAD`] of their
/// mean. `at(patch, work, root, uv)` says where a point's value is kept and where it is
/// gathered; `indirect(patch, x)` gathers the indirect light at `x` as that patch, with the
/// rays it cost.
pub(super) fn gather(
    work: &mut [PatchWork],
    near: &[bool],
    at: impl Fn(usize, &PatchWork, u32, DVec2) -> (At, DVec3) + Sync,
    indirect: impl Fn(usize, DVec3) -> ([f64; 3], f64, u64) + Sync,
    values: &mut Values,
) {
    // Per patch, per root: its nodes, the corners only unless `all`.
    let points = |i: usize, w: &PatchWork, all: bool| -> Vec<Vec<(At, DVec3)>> {
        (w.roots.iter().enumerate())
            .map(|(k, root)| {
                let e = root.element(k as u32);
                let keep = if all { usize::MAX } else { e.count() };
                (nodes(&e).into_iter().take(keep))
                    .map(|uv| at(i, w, k as u32, uv))
                    .collect()
            })
            .collect()
    };
    let near_ones: Vec<usize> = (0..work.len()).filter(|&i| near[i]).collect();
    gather_points(
        work,
        &near_ones,
        |i, w| points(i, w, false).concat(),
        &indirect,
        values,
    );
    let v = &*values;
    let mut all = vec![false; work.len()];
    let spread: Vec<bool> = (near_ones.par_iter())
        .map(|&i| {
            let s: Vec<(f64, f64)> = (points(i, &work[i], false).iter().flatten())
                .map(|(a, _)| (scalar(&v.indirect[a].0), v.indirect[a].1))
                .collect();
            let lo = s.iter().copied().min_by(|a, b| a.0.total_cmp(&b.0));
            let hi = s.iter().copied().max_by(|a, b| a.0.total_cmp(&b.0));
            let (Some(lo), Some(hi)) = (lo, hi) else {
                return false;
            };
            let mean = s.iter().map(|x| x.0).sum::<f64>() / s.len() as f64;
            // The difference less what the two nodes' noise explains (in quadrature, as the
            // refinement's test takes it off: `NOISE_Z`).
            let d2 = (hi.0 - lo.0).powi(2) - NOISE_Z * NOISE_Z * (hi.1 + lo.1);
            d2 > (SPREAD * mean).powi(2)
        })
        .collect();
    for (&i, &wide) in near_ones.iter().zip(&spread) {
        all[i] = wide;
    }
    let wide: Vec<usize> = (0..work.len()).filter(|&i| all[i]).collect();
    gather_points(
        work,
        &wide,
        |i, w| points(i, w, true).concat(),
        &indirect,
        values,
    );
    let v = &*values;
    work.par_iter_mut().enumerate().for_each(|(i, w)| {
        if !near[i] {
            return;
        }
        let pts = points(i, w, all[i]);
        w.ind_nodes = (pts.iter())
            .map(|root| root.iter().map(|(at, _)| v.indirect[at]).collect())
            .collect();
    });
    // Each patch holds its nodes' values now; the maps only served to gather each point once.
    values.indirect = Default::default();
}

/// Hemisphere rays each patch casts from its centre to find how near the geometry it sees is
/// ([`near_patches`]): a 4 × 4 stratified cosine-weighted set.
pub const PROBE_SIDE: usize = 4;

/// Which patches gather the indirect light at their nodes, with the rays it cost to tell
/// (Ward, Rubinstein & Clear, *A ray tracing solution for diffuse interreflection*, SIGGRAPH
/// 1988, Sec. 2.2): the indirect irradiance at a point changes over a distance d by about
/// d/R of itself, R the harmonic mean distance of the surfaces the point sees, so across a
/// patch of size s = √A by about s/R, and what bilinear interpolation between its corners
/// misses (the curvature) by about (s/R)²/8 of the indirect light — of the patch's radiosity
/// B, times the indirect light's share of it, ρ·H_ind / B. A patch where that exceeds
/// `threshold` (the elements' own, `--element-threshold`, which weighs differences against
/// the whole light too) sees geometry near enough to shape a light that shows (a contact, a
/// wall's edge, under a table) and gathers it at its nodes; the others take theirs from the
/// patch solution (the final gather's estimate, averaged to the vertices), at no ray. Beside
/// a lamp, where the direct light is most of B, the indirect light's bend is lost in it; under
/// a table, where it is all of B, it is what shows. R and H_ind are measured from each
/// patch's centre with the same [`PROBE_SIDE`]² cosine-weighted rays (a ray that leaves the
/// model counts as infinitely far; H_ind is the mean of what the solution says the rays see,
/// [`LightAt::seen_light`]), drawn from (seed, [`Stream::Elements`], 2⁶³ + patch).
pub(super) fn near_patches<I: Intersector>(
    mesh: &Mesh,
    light: &LightAt<'_, I>,
    b: &[[f64; 3]],
    seed: u64,
    threshold: f64,
) -> (Vec<bool>, u64) {
    let n = PROBE_SIDE * PROBE_SIDE;
    let got: Vec<(bool, u64)> = (0..mesh.patches.len())
        .into_par_iter()
        .map(|i| {
            let p = &mesh.patches[i];
            let whole = scalar(&b[i]);
            let rho = light.reflectance(i);
            if whole <= 0.0 || scalar(&rho.to_array()) <= 0.0 {
                // Nothing reflected, or nothing shown: no indirect light to shape.
                return (false, 0);
            }
            let s = p.area.sqrt();
            let mut rng = rng_for(seed, Stream::Elements, (1 << 63) | i as u64);
            let frame = Frame::new(p.normal, rng.gen::<f32>() * std::f32::consts::TAU);
            let org = p.centre
                + p.normal
                    * (1e-4 * s as f32).max(f32::EPSILON * p.centre.abs().max_element() * 16.0);
            let (mut inv, mut rays) = (0.0f64, 0u64);
            let mut h = crate::light::Rgb::ZERO;
            for k in 0..n {
                let u1 = ((k / PROBE_SIDE) as f32 + rng.gen::<f32>()) / PROBE_SIDE as f32;
                let u2 = ((k % PROBE_SIDE) as f32 + rng.gen::<f32>()) / PROBE_SIDE as f32;
                let (r, phi) = (u1.sqrt(), std::f32::consts::TAU * u2);
                let d = Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u1).max(0.0).sqrt());
                let dir = frame.to_world(d);
                let seen = light.view(org, dir);
                rays += seen.rays;
                h += light.seen_light(&seen, dir);
                if let Some(hit) = &seen.hit {
                    inv += 1.0 / (hit.point - org).length().max(f32::MIN_POSITIVE) as f64;
                }
            }
            let ratio = s * inv / n as f64;
            let share = (scalar(&(rho * h).to_array()) / n as f64 / whole).min(1.0);
            (ratio * ratio / 8.0 * share > threshold, rays)
        })
        .collect();
    let rays = got.iter().map(|g| g.1).sum();
    (got.into_iter().map(|g| g.0).collect(), rays)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::elements::geometry::Root;
    use glam::Vec3;

    /// A quadratic of the root's parameters is reproduced exactly from its nodes.
    #[test]
    fn the_quadratic_is_exact_on_quadratics() {
        let quad = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        for pts in [&quad[..], &tri[..]] {
            let roots = Root::of_patch(pts);
            let e = roots[0].element(0);
            let f = |uv: DVec2| 1.0 + 2.0 * uv.x - uv.y + 3.0 * uv.x * uv.y + uv.x * uv.x;
            let values: Vec<([f64; 3], f64)> =
                nodes(&e).iter().map(|&uv| ([f(uv); 3], 0.0)).collect();
            for uv in [DVec2::new(0.3, 0.2), DVec2::new(0.125, 0.625)] {
                assert!((at(&values, uv)[1] - f(uv)).abs() < 1e-12);
            }
        }
    }
}
