//! Weighing one gathered patch's estimate against the shooting's: inverse-variance weights,
//! the shooting left out where it is biased (`super`'s module notes, "Combining").

use super::{reflected, Gathered, PatchModel, Shooting, BIAS_Z};
use crate::light::{self, Rgb};

/// One gathered patch's estimate weighed against the shooting's (module notes): the shooting's
/// weight, the combined B and σ, and the patch's error model.
pub(super) struct Weighed {
    pub a: f64,
    pub b: Rgb,
    pub sigma: f64,
    pub model: PatchModel,
}

/// The light still owed to gathered patches, per unit of the reflected light their gathers
/// found (`super`'s module notes, "The light still owed"): Σ owed_i·A_i / Σ ρ_i·R_i·A_i over
/// `gathered` (patch, gather) pairs, owed_i the shooting's even share ([`Shooting`]'s parts),
/// R_i the irradiance the gather's hemisphere rays found reflected. `None` when they found no
/// reflected light at all: the even shares then stand.
pub(super) fn owed_per_reflected<'g>(
    shooting: &Shooting,
    rho: &[Rgb],
    area: impl Fn(usize) -> f64,
    gathered: impl Iterator<Item = (usize, &'g Gathered)>,
) -> Option<f64> {
    let (mut owed, mut reflected) = (0.0, 0.0);
    for (i, g) in gathered {
        let a = area(i);
        owed += shooting.parts.missing[i] * a;
        reflected += light::scalar(rho[i] * g.reflected) * a;
    }
    (reflected > 0.0).then(|| owed / reflected)
}

/// Weighs patch `i`'s gather `g` (of area `area`) against the shooting's estimate in `b`;
/// `owed` is [`owed_per_reflected`] of the patches gathered with it.
pub(super) fn weigh(
    shooting: &Shooting,
    b: &[[f64; 3]],
    (e, rho): (&[Rgb], &[Rgb]),
    (area, owed): (f64, Option<f64>),
    (i, g): (usize, &Gathered),
) -> Weighed {
    let x_s = reflected(b, e, i).max(0.0);
    let x_g = light::scalar(rho[i] * g.h);
    let mu = 0.5 * (x_s + x_g);
    // The shooting's Poisson variance at the pooled mean: Var(G) = ρ·C_eff·E[G].
    let var_s = if x_s > 0.0 && shooting.parts.sigma[i] > 0.0 {
        shooting.parts.sigma[i].powi(2) * mu / x_s
    } else {
        light::scalar(rho[i]) * shooting.energy_per_ray * mu / area
    };
    let floor = 1e-24 * mu * mu + f64::MIN_POSITIVE;
    let (w_s, w_g) = (1.0 / (var_s + floor), 1.0 / (g.var + floor));
    let a = w_s / (w_s + w_g);
    let a = if a.is_finite() { a } else { 0.5 };
    let biased = (x_s - x_g).powi(2) > BIAS_Z * BIAS_Z * (var_s + g.var);
    let a = if biased { 0.0 } else { a };
    // The light still owed arrives as light reflected by other surfaces, in proportion to
    // what the gather found of it (module notes); none where neither the shooting nor the
    // gather's rays found any light (a face against a wall, the underside of a box).
    let missing = match owed {
        Some(k) => k * light::scalar(rho[i] * g.reflected),
        None if x_s <= 0.0 && x_g <= 0.0 => 0.0,
        None => shooting.parts.missing[i],
    };
    let sigma = if biased {
        g.var.sqrt()
    } else {
        (1.0 / (w_s + w_g)).sqrt()
    };
    let b = e[i] + a * (Rgb::from_array(b[i]) - e[i]) + (1.0 - a) * (rho[i] * g.h);
    Weighed {
        a,
        b,
        sigma,
        model: PatchModel {
            var_s,
            var_g: g.var,
            biased,
            missing,
            b_true: light::scalar(b) + missing,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solve::estimate::Parts;

    fn gathered(h: f64, reflected: f64) -> Gathered {
        Gathered {
            h: Rgb::splat(h),
            ch: vec![Rgb::splat(h)],
            var: 1e-4 * h * h,
            rays: 64,
            reflected: Rgb::splat(reflected),
            vis: Default::default(),
        }
    }

    #[test]
    fn the_owed_light_follows_the_reflected_light_the_gathers_found() {
        // Three patches the shooting owes the same even share (0.01 W/m² each, 1 m² each): a
        // lit one whose gather found 1 W/m² reflected, a dark one that found 0.01, one in the
        // void that found none.
        let shooting = Shooting {
            parts: Parts {
                missing: vec![0.01; 3],
                sigma: vec![0.0; 3],
                b: vec![0.5, 0.005, 0.0],
            },
            energy_per_ray: 1e-3,
        };
        let rho = [Rgb::splat(0.5); 3];
        let e = [Rgb::ZERO; 3];
        let b = [[0.5; 3], [0.005; 3], [0.0; 3]];
        let gs = [gathered(1.0, 1.0), gathered(0.01, 0.01), gathered(0.0, 0.0)];
        let k = owed_per_reflected(&shooting, &rho, |_| 1.0, gs.iter().enumerate());
        let k = k.expect("reflected light was found");
        let missing: Vec<f64> = (0..3)
            .map(|i| {
                weigh(&shooting, &b, (&e, &rho), (1.0, Some(k)), (i, &gs[i]))
                    .model
                    .missing
            })
            .collect();
        // The owed flux (0.03 W) is all handed out, in proportion to ρ·R: 100 to 1 to 0.
        assert!(
            (missing.iter().sum::<f64>() - 0.03).abs() < 1e-12,
            "{missing:?}"
        );
        assert!(
            (missing[0] / missing[1] - 100.0).abs() < 1e-9,
            "{missing:?}"
        );
        assert_eq!(missing[2], 0.0);
        // The dark patch is owed 6 % of its B, where the even share said twice its B.
        let dark = weigh(&shooting, &b, (&e, &rho), (1.0, Some(k)), (1, &gs[1])).model;
        let owed = dark.missing / (dark.b_true - dark.missing);
        assert!((owed - 0.0594).abs() < 1e-3, "{owed}");
        // Gathers that found no reflected light leave the even shares as they were.
        let none = [gathered(1.0, 0.0)];
        assert_eq!(
            owed_per_reflected(&shooting, &rho, |_| 1.0, none.iter().enumerate()),
            None
        );
    }
}
