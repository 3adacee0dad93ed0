//! The solver's error estimates (Sec. 3): the error against a reference, and the solver's
//! own estimate of its error when there is none. (Not the crate's Rust errors: those are
//! `crate::error`.)
//!
//! **The paper's metrics** (Sec. 3, on scalar radiosity, the mean of RGB):
//! - average energy error = Σ_i |Φ_i − Φ_i^ref| / Σ_i Φ_i^ref, with Φ = B·A;
//! - average weighted percent error = (1/n) Σ_i |B_i − B_i^ref| / B_i^ref;
//! - and the RMS relative error sqrt((1/n) Σ_i ((B_i − B_i^ref)/B_i^ref)²).
//!
//! Patches whose reference radiosity is zero (black, unlit), or a numerical zero
//! ([`BLACK_SHARE`]), carry no relative error and are left out of n.
//!
//! **The estimate** ([`Estimator`]) adds, per patch, the two things a progressive solve gets
//! wrong, and puts the sum through the same metrics:
//! - *sampling noise.* Every sample a shooter sends carries about the same energy e (Sec. 2:
//!   rays X = ΔΦ/C each carry C; a hemi-cube cell carries ΔΦ/cells on average), so the flux a
//!   patch has kept, G_j = ρ_j·(samples that hit it)·e, is a Poisson count and
//!   Var(G_j) = Σ ρ_j·e·(what each shot left), accumulated as it is deposited (for rays, with
//!   e = C, from G_j itself at no cost). σ(B_j) = sqrt(Var G_j)/A_j, and E|noise| = σ·sqrt(2/π).
//! - *light not yet shot.* Each unit of flux shot so far came back as r = (kept)/(shot) units to
//!   shoot again, so the unshot flux U still owes U·r/(1 − r) of kept flux; it is spread like the
//!   reflected light so far: patch j misses (B_j − E_j)·(owed / kept so far).
//!
//! Noise that a shooter passes on in its own unshot flux (correlated between its receivers) is
//! not counted; the tests check on scenes with references that the estimate stays within a
//! factor of 2 of the measured error over whole runs.

use super::scalar;
use crate::mesh::Mesh;
use crate::scene::Material;

/// The paper's two metrics and the RMS relative error, as fractions (0.01 = 1 %).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ErrorMetrics {
    /// Average energy error Σ|Φ − Φref| / ΣΦref.
    pub energy: f64,
    /// Average weighted percent error (1/n) Σ |B − Bref| / Bref.
    pub weighted_percent: f64,
    /// RMS relative error.
    pub rms_relative: f64,
}

/// A patch whose radiosity is at most this share of the area-weighted mean is black for the
/// relative metrics (as a zero is): forty stops below the mean no meter or display reads it,
/// and a solve's "nearly nothing" there (1e-35 W/m² on a face no light reaches, what a
/// combination of weights leaves) is a numerical zero whose relative error means nothing.
pub const BLACK_SHARE: f64 = 1e-12;

/// The radiosity at or below which a patch of `b` (scalar, W/m²) counts as black
/// ([`BLACK_SHARE`] of the area-weighted mean).
pub fn black_floor(area: &[f64], b: &[f64]) -> f64 {
    let (sum, total) = (area.iter().zip(b)).fold((0.0, 0.0), |(s, t), (&a, &r)| (s + r * a, t + a));
    if total > 0.0 {
        BLACK_SHARE * sum / total
    } else {
        0.0
    }
}

/// Metrics from per-patch absolute errors `err` (scalar W/m²) against radiosities `b_ref`.
pub fn from_errors(area: &[f64], err: impl Iterator<Item = f64>, b_ref: &[f64]) -> ErrorMetrics {
    let (mut energy, mut total, mut pct, mut sq, mut n) = (0.0, 0.0, 0.0, 0.0, 0usize);
    let black = black_floor(area, b_ref);
    for ((&a, e), &r) in area.iter().zip(err).zip(b_ref) {
        energy += e * a;
        total += r * a;
        if r > black {
            let rel = e / r;
            pct += rel;
            sq += rel * rel;
            n += 1;
        }
    }
    let n = n.max(1) as f64;
    ErrorMetrics {
        energy: if total > 0.0 { energy / total } else { 0.0 },
        weighted_percent: pct / n,
        rms_relative: (sq / n).sqrt(),
    }
}

/// The metrics of `b` against a reference `b_ref` (both RGB, W/m²).
pub fn against(area: &[f64], b: &[[f64; 3]], b_ref: &[[f64; 3]]) -> ErrorMetrics {
    let r: Vec<f64> = b_ref.iter().map(scalar).collect();
    from_errors(
        area,
        b.iter().zip(&r).map(|(b, r)| (scalar(b) - r).abs()),
        &r,
    )
}

/// Per-patch inputs of the estimate (scalar).
pub struct Estimator<'a> {
    pub area: &'a [f64],
    /// Emitted radiosity E_j.
    pub emission: &'a [f64],
    /// Mean reflectance ρ_j.
    pub rho: &'a [f64],
    /// Energy per ray C (scalar W; Sec. 2).
    pub energy_per_ray: f64,
    /// Area-weighted mean reflectance: the share of shot light kept before anything is known.
    pub rho_mean: f64,
    /// Per patch: the other side of its two-sided surface (docs/design.md §7), `u32::MAX` for a
    /// one-sided patch; empty when no patch has one. A side that has received at most
    /// [`DARK_SIDE`] of what its other side has is presumed to face the void or the inside of an
    /// object (what reaches it leaks through cracks where parts touch): it is owed nothing and
    /// its relative error is not counted. One-sided patches are always owed their share.
    pub other_side: &'a [u32],
    /// Per patch: its own side is hidden (`crate::mesh::Hidden`: inside a closed solid); empty
    /// when none is. A hidden side that has received nothing is dark: owed nothing, not counted.
    pub hidden: &'a [bool],
}

/// A side of a two-sided surface that has received at most this share of what its other side
/// has is dark (see [`Estimator::other_side`]; the final gather skips it too).
pub const DARK_SIDE: f64 = 0.01;

/// The estimate's parts per patch (scalar W/m²): see [`Estimator::parts`].
#[derive(Clone, Debug)]
pub struct Parts {
    /// Light the unshot flux still owes the patch.
    pub missing: Vec<f64>,
    /// σ of the patch's sampling noise.
    pub sigma: Vec<f64>,
    /// The estimate of the true B: what was kept plus what is still owed.
    pub b: Vec<f64>,
}

/// Expected |error| of a patch from its owed light and its noise σ: E|noise| = σ·sqrt(2/π).
pub fn combine(missing: f64, sigma: f64) -> f64 {
    (missing * missing + std::f64::consts::FRAC_2_PI * sigma * sigma).sqrt()
}

/// What the solver knows at a trace point, per patch and in total (scalar).
pub struct Books<'a> {
    /// Flux kept so far, G_j (W).
    pub gathered: &'a [f64],
    /// Of G_j, what hemi-cube shots left, and their variance Σ ρ·e·kept (W²); empty if none.
    pub cube_gathered: &'a [f64],
    pub cube_var: &'a [f64],
    /// Σ_j G_j, Σ unshot, and the flux shot so far.
    pub kept: f64,
    pub unshot: f64,
    pub shot: f64,
}

impl Estimator<'_> {
    /// Expected |B_j − B_j^true| per patch, and B_j, from the books.
    pub fn per_patch(&self, books: &Books) -> (Vec<f64>, Vec<f64>) {
        let parts = self.parts(books);
        let err = parts
            .missing
            .iter()
            .zip(&parts.sigma)
            .map(|(m, s)| combine(*m, *s))
            .collect();
        (err, parts.b)
    }

    /// The two parts of the estimate per patch, apart: light still owed and sampling noise
    /// (the final gather replaces the noise of the patches it re-estimates; see
    /// `solve::final_gather`).
    pub fn parts(&self, books: &Books) -> Parts {
        // Light not yet shot: what it will still leave behind, spread like the light so far
        // (before any light was kept: evenly over the area, at the mean reflectance).
        let r = if books.shot > 0.0 {
            books.kept / books.shot
        } else {
            self.rho_mean
        }
        .min(0.999_999);
        let owed = books.unshot * r / (1.0 - r);
        // Spread like light arriving evenly per unit area (the light still owed has bounced at
        // least once, and bounced light is far more even than direct light), kept at ρ_j.
        let n = self.area.len();
        let dark = |j: usize| {
            let o = self.other_side.get(j).copied().unwrap_or(u32::MAX);
            let hidden = self.hidden.get(j).copied().unwrap_or(false);
            self.emission[j] <= 0.0
                && ((o != u32::MAX && books.gathered[j] <= DARK_SIDE * books.gathered[o as usize])
                    || (hidden && books.gathered[j] <= 0.0))
        };
        let rho_area: f64 = (0..n)
            .filter(|&j| !dark(j))
            .map(|j| self.rho[j] * self.area[j])
            .sum::<f64>()
            .max(f64::MIN_POSITIVE);
        let mut parts = Parts {
            missing: Vec::with_capacity(n),
            sigma: Vec::with_capacity(n),
            b: Vec::with_capacity(n),
        };
        for j in 0..n {
            let g = books.gathered[j].max(0.0);
            let (gc, vc) = if books.cube_gathered.is_empty() {
                (0.0, 0.0)
            } else {
                (books.cube_gathered[j], books.cube_var[j])
            };
            let var = self.rho[j] * self.energy_per_ray * (g - gc).max(0.0) + vc;
            let sigma = var.sqrt() / self.area[j];
            let bj = self.emission[j] + g / self.area[j];
            if dark(j) {
                // Presumed dark: no error counted, left out of the relative metrics (B = 0).
                parts.missing.push(0.0);
                parts.sigma.push(0.0);
                parts.b.push(0.0);
                continue;
            }
            let missing = self.rho[j] * owed / rho_area;
            parts.missing.push(missing);
            parts.sigma.push(sigma);
            // The estimate of the true B includes what is still owed.
            parts.b.push(bj + missing);
        }
        parts
    }

    /// The estimated metrics.
    pub fn metrics(&self, books: &Books) -> ErrorMetrics {
        let (err, b) = self.per_patch(books);
        from_errors(self.area, err.into_iter(), &b)
    }
}

/// Per-patch scalars of the solver's error estimate.
pub(super) struct PatchScalars {
    pub(super) area: Vec<f64>,
    pub(super) emission: Vec<f64>,
    pub(super) rho: Vec<f64>,
    rho_mean: f64,
    /// Sides of two-sided surfaces (empty if the mesh has none).
    other_side: Vec<u32>,
    /// Hidden sides (empty if none is: `crate::mesh::Hidden`).
    hidden: Vec<bool>,
}

impl PatchScalars {
    pub(super) fn new(mesh: &Mesh, materials: &[Material]) -> PatchScalars {
        let material = |p: &crate::mesh::Patch| &materials[p.material as usize];
        let area: Vec<f64> = mesh.patches.iter().map(|p| p.area).collect();
        let rho: Vec<f64> = mesh
            .patches
            .iter()
            .map(|p| scalar(&material(p).rho))
            .collect();
        let other_side = if mesh.back_twins() > 0 {
            let other = |i: usize| mesh.other_side(i).map_or(u32::MAX, |o| o as u32);
            (0..mesh.patches.len()).map(other).collect()
        } else {
            Vec::new()
        };
        let hidden = if mesh.hidden.count(mesh).0 > 0 {
            (0..mesh.patches.len())
                .map(|i| mesh.hidden.side(mesh, i))
                .collect()
        } else {
            Vec::new()
        };
        PatchScalars {
            other_side,
            hidden,
            emission: mesh
                .patches
                .iter()
                .map(|p| scalar(&material(p).emission()))
                .collect(),
            rho_mean: rho.iter().zip(&area).map(|(r, a)| r * a).sum::<f64>() / mesh.total_area(),
            area,
            rho,
        }
    }

    pub(super) fn estimator(&self, energy_per_ray: f64) -> Estimator<'_> {
        Estimator {
            area: &self.area,
            emission: &self.emission,
            rho: &self.rho,
            energy_per_ray,
            rho_mean: self.rho_mean,
            other_side: &self.other_side,
            hidden: &self.hidden,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn metrics_follow_the_papers_definitions() {
        let area = [1.0, 3.0];
        let b_ref = [[2.0; 3], [1.0; 3]];
        let b = [[3.0; 3], [0.5; 3]];
        let m = against(&area, &b, &b_ref);
        // Energy: (|3−2|·1 + |0.5−1|·3) / (2·1 + 1·3) = 2.5 / 5.
        assert!((m.energy - 0.5).abs() < 1e-12);
        // Weighted percent: (0.5 + 0.5) / 2.
        assert!((m.weighted_percent - 0.5).abs() < 1e-12);
        assert!((m.rms_relative - 0.5).abs() < 1e-12);
        assert_eq!(against(&area, &b_ref, &b_ref), ErrorMetrics::default());
    }

    #[test]
    fn black_patches_are_left_out_of_the_relative_metrics() {
        let m = against(&[1.0, 1.0], &[[1.1; 3], [0.2; 3]], &[[1.0; 3], [0.0; 3]]);
        assert!((m.weighted_percent - 0.1).abs() < 1e-9);
        // A numerical zero (1e-35 W/m² beside 1 W/m²) is black too, whatever its error.
        let m = from_errors(&[1.0, 1.0], [0.1, 1e-17].into_iter(), &[1.0, 1e-35]);
        assert!((m.weighted_percent - 0.1).abs() < 1e-9, "{m:?}");
        // Faint but real light (1e-9 of the mean) is counted.
        let m = from_errors(&[1.0, 1.0], [0.1, 1e-10].into_iter(), &[1.0, 1e-9]);
        assert!((m.weighted_percent - 0.1).abs() < 1e-9, "{m:?}");
    }

    #[test]
    fn estimate_counts_noise_and_owed_light() {
        let est = Estimator {
            area: &[1.0],
            emission: &[0.0],
            rho: &[0.5],
            energy_per_ray: 0.01,
            rho_mean: 0.5,
            other_side: &[],
            hidden: &[],
        };
        // 100 hits of 0.01 W kept at ρ = 0.5: G = 0.5, Var = 0.5·0.01·0.5, σ/B = 0.1.
        let books = Books {
            gathered: &[0.5],
            cube_gathered: &[],
            cube_var: &[],
            kept: 0.5,
            unshot: 0.0,
            shot: 1.0,
        };
        let m = est.metrics(&books);
        let expected = 0.1 * std::f64::consts::FRAC_2_PI.sqrt();
        assert!((m.weighted_percent - expected).abs() < 1e-12, "{m:?}");
        // Owed light only: r = 0.5, U = 1 → owed 1 = twice what was kept: B misses 2/3 of
        // its final value.
        let est = Estimator {
            energy_per_ray: 0.0,
            ..est
        };
        let m = est.metrics(&Books {
            unshot: 1.0,
            ..books
        });
        assert!((m.weighted_percent - 2.0 / 3.0).abs() < 1e-12, "{m:?}");
    }

    #[test]
    fn an_unlit_side_of_a_two_sided_surface_is_owed_nothing() {
        // Patch 1 is the unlit back of patch 0: it takes no share of the owed light, so the
        // estimate is patch 0's alone (as if the back were not there).
        let est = Estimator {
            area: &[1.0, 1.0],
            emission: &[0.0, 0.0],
            rho: &[0.5, 0.5],
            energy_per_ray: 0.0,
            rho_mean: 0.5,
            other_side: &[1, 0],
            hidden: &[],
        };
        let books = Books {
            gathered: &[0.5, 0.0],
            cube_gathered: &[],
            cube_var: &[],
            kept: 0.5,
            unshot: 1.0,
            shot: 1.0,
        };
        let m = est.metrics(&books);
        assert!((m.weighted_percent - 2.0 / 3.0).abs() < 1e-12, "{m:?}");
        let (_, b) = est.per_patch(&books);
        assert_eq!(b[1], 0.0);
        // One-sided, the unlit patch is owed half the light.
        let m = Estimator {
            other_side: &[],
            hidden: &[],
            ..est
        }
        .metrics(&books);
        assert!(m.weighted_percent > 0.7, "{m:?}");
    }
}
