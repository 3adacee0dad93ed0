//! Patches finer where a light is close: a receiver is cut again, up to [`NEAR_LIGHT_CUTS`]
//! times, while a near light's direct irradiance bends across it by more than the scene's mean:
//! E_l · (L / d_l)² > Φ / A, with E_l the light's unoccluded irradiance at the patch's centre
//! (Lambert's closed form), L the patch's longest edge, d_l the light's distance, Φ the power of
//! all lights and A the area of all faces.
//!
//! A patch carries one radiosity, its average. Light from a source at distance d changes over
//! lengths of about d; a change linear across the patch averages out, so what a constant patch
//! misrepresents is the bend, of order E · (L / d)². A patch larger than about d / 2 averages a
//! hot spot it cannot show — and where the brightest part of the spot is the part others do not
//! see (the ceiling right above a hung panel, hidden from the room by the panel itself), the
//! average sends the room light that really goes back to the panel. Cutting such patches by the
//! light's distance, as Radiance cuts its sources by `-ds`, is decided from the geometry and the
//! emission alone, before any light is shot: no patch far from a light changes, and a scene
//! whose lights are far from everything meshes exactly as before.

use super::{newell, polygon_points};
use crate::scene::Scene;
use glam::Vec3;
use std::collections::HashMap;

/// Only lights nearer than `NEAR_LIGHT` × a patch's longest edge are looked at.
pub const NEAR_LIGHT: f32 = 4.0;
/// At most this many cuts (each halving the edges): patches near a light end at ≥ 1/8 of the
/// patch size.
pub const NEAR_LIGHT_CUTS: u32 = 3;

/// One emitting face: its points, unit front normal and exitance (W/m², the channels' mean).
struct Light {
    pts: Vec<Vec3>,
    normal: Vec3,
    exitance: f64,
}

/// The emitting faces of a scene, bucketed on a grid so a patch looks only at those near it.
pub(super) struct NearLights {
    lights: Vec<Light>,
    cell: f32,
    grid: HashMap<[i32; 3], Vec<u32>>,
    /// Φ / A: the lights' power over the area of every face (W/m²).
    mean: f64,
}

impl NearLights {
    /// The scene's emitting faces, or `None` when it has none (nothing to refine by).
    pub(super) fn new(scene: &Scene, patch_size: f32) -> Option<Self> {
        let lights: Vec<Light> = (scene.polygons.iter())
            .filter(|p| scene.materials[p.material as usize].is_emitter())
            .filter_map(|p| {
                let pts = polygon_points(scene, p);
                let normal = newell(&pts).normalize_or_zero();
                let e = scene.materials[p.material as usize].emission();
                let exitance = (e[0] + e[1] + e[2]) / 3.0;
                (normal != Vec3::ZERO).then_some(Light {
                    pts,
                    normal,
                    exitance,
                })
            })
            .collect();
        let area = |pts: &[Vec3]| newell(pts).length() as f64 * 0.5;
        let power: f64 = lights.iter().map(|l| l.exitance * area(&l.pts)).sum();
        let total: f64 = (scene.polygons.iter())
            .map(|p| area(&polygon_points(scene, p)))
            .sum();
        if lights.is_empty() || !(power > 0.0 && total > 0.0) {
            return None;
        }
        // A patch asks about lights within NEAR_LIGHT × its edge ≤ NEAR_LIGHT × the patch size.
        let cell = NEAR_LIGHT * patch_size;
        let key = |v: Vec3| (v / cell).floor().as_ivec3().to_array();
        let mut grid: HashMap<[i32; 3], Vec<u32>> = HashMap::new();
        for (i, l) in lights.iter().enumerate() {
            let (lo, hi) =
                (l.pts.iter()).fold((l.pts[0], l.pts[0]), |(a, b), &v| (a.min(v), b.max(v)));
            let (a, b) = (key(lo - Vec3::splat(cell)), key(hi + Vec3::splat(cell)));
            for x in a[0]..=b[0] {
                for y in a[1]..=b[1] {
                    for z in a[2]..=b[2] {
                        grid.entry([x, y, z]).or_default().push(i as u32);
                    }
                }
            }
        }
        Some(NearLights {
            lights,
            cell,
            grid,
            mean: power / total,
        })
    }

    /// Whether a patch with these points, facing `n`, is to be cut again: some light faces it,
    /// lies in front of it, is nearer its centre than [`NEAR_LIGHT`] × its longest edge, and
    /// bends its light by more than the scene's mean irradiance (the module's rule).
    pub(super) fn too_near(&self, pts: &[Vec3], n: Vec3) -> bool {
        let longest = (0..pts.len())
            .map(|k| (pts[(k + 1) % pts.len()] - pts[k]).length())
            .fold(0.0, f32::max);
        let c = pts.iter().copied().sum::<Vec3>() / pts.len() as f32;
        let reach = NEAR_LIGHT * longest;
        let key = (c / self.cell).floor().as_ivec3().to_array();
        let Some(near) = self.grid.get(&key) else {
            return false;
        };
        near.iter().any(|&i| {
            let l = &self.lights[i as usize];
            // The light in front of the patch and the patch in front of the light (strictly:
            // a light in the patch's own plane, beside it, sends it nothing).
            let tol = 1e-4 * longest;
            if !(l.pts.iter().any(|&v| (v - c).dot(n) > tol)
                && pts.iter().any(|&p| (p - l.pts[0]).dot(l.normal) > tol))
            {
                return false;
            }
            let d = distance_to_polygon(c, &l.pts, l.normal);
            let ratio = (longest / d.max(1e-6 * longest)) as f64;
            d < reach && l.exitance * form_factor(c, n, &l.pts) * ratio * ratio > self.mean
        })
    }
}

/// The form factor from a point at `p` facing `n` to a polygon wholly in front of it (Lambert's
/// contour integral; the part behind the point's plane is not clipped, so it overestimates a
/// light the plane cuts).
fn form_factor(p: Vec3, n: Vec3, pts: &[Vec3]) -> f64 {
    let mut s = 0.0f64;
    for k in 0..pts.len() {
        let a = (pts[k] - p).as_dvec3().normalize_or_zero();
        let b = (pts[(k + 1) % pts.len()] - p)
            .as_dvec3()
            .normalize_or_zero();
        let g = a.cross(b);
        let ng = g.length();
        if ng > 1e-15 {
            s += ng.atan2(a.dot(b)) * n.as_dvec3().dot(g / ng);
        }
    }
    (s.abs() / (2.0 * std::f64::consts::PI)).min(1.0)
}

/// Distance from `p` to a planar convex polygon with unit normal `n`.
fn distance_to_polygon(p: Vec3, pts: &[Vec3], n: Vec3) -> f32 {
    let h = (p - pts[0]).dot(n);
    let q = p - n * h;
    let inside = (0..pts.len()).all(|k| {
        let (a, b) = (pts[k], pts[(k + 1) % pts.len()]);
        (b - a).cross(q - a).dot(n) >= 0.0
    });
    if inside {
        return h.abs();
    }
    (0..pts.len())
        .map(|k| {
            let (a, b) = (pts[k], pts[(k + 1) % pts.len()]);
            let ab = b - a;
            let t = ((p - a).dot(ab) / ab.length_squared().max(f32::MIN_POSITIVE)).clamp(0.0, 1.0);
            (p - (a + ab * t)).length()
        })
        .fold(f32::MAX, f32::min)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distance_to_a_square_inside_beside_and_off_a_corner() {
        let sq = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        let n = Vec3::Z;
        assert!((distance_to_polygon(Vec3::new(0.5, 0.5, 0.3), &sq, n) - 0.3).abs() < 1e-6);
        assert!((distance_to_polygon(Vec3::new(1.5, 0.5, 0.0), &sq, n) - 0.5).abs() < 1e-6);
        let d = distance_to_polygon(Vec3::new(2.0, 2.0, 1.0), &sq, n);
        assert!((d - 3f32.sqrt()).abs() < 1e-6);
    }

    #[test]
    fn form_factor_of_a_square_above_its_centre_is_the_closed_form() {
        // A square of side 2 centred 1 above the point: four corner rectangles 1 × 1 at height
        // 1, each (1/2π)·2·x·atan(x) with x = 1/√2 (the parallel-rectangle corner formula).
        let sq = |s: f32, h: f32| {
            [
                Vec3::new(-s, -s, h),
                Vec3::new(s, -s, h),
                Vec3::new(s, s, h),
                Vec3::new(-s, s, h),
            ]
        };
        let f = form_factor(Vec3::ZERO, Vec3::Z, &sq(1.0, 1.0));
        let x = 1.0f64 / 2f64.sqrt();
        let exact = 4.0 / (2.0 * std::f64::consts::PI) * 2.0 * x * x.atan();
        assert!((f - exact).abs() < 1e-6, "{f} against {exact}");
        assert!(form_factor(Vec3::ZERO, Vec3::Z, &sq(1e3, 1.0)) > 0.999);
    }
}
