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

/// Weighs patch `i`'s gather `g` (of area `area`) against the shooting's estimate in `b`.
pub(super) fn weigh(
    shooting: &Shooting,
    b: &[[f64; 3]],
    (e, rho): (&[Rgb], &[Rgb]),
    area: f64,
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
    // Neither the shooting nor the gather's rays found light here (a face against a wall, the
    // underside of a box on the floor): the light still owed, which arrives like the indirect
    // light the gather saw none of, is not owed here either.
    let missing = if x_s <= 0.0 && x_g <= 0.0 {
        0.0
    } else {
        shooting.parts.missing[i]
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
