//! The sky's luminance distributions, relative to the zenith, as Radiance's `gensky` and
//! `skybright.cal` define them.
//!
//! θ is the angle from the zenith, μ = cos θ, γ the angle to the sun and Z the sun's zenith
//! angle. Each distribution gives L(θ, γ) / L_z, with L_z the zenith parameter (`gensky -b`):
//!
//! - uniform: L = L_z;
//! - CIE standard overcast (Moon & Spencer 1942, *Illumination from a non-uniform sky*, Illum.
//!   Eng. 37; CIE S 011/E:2003 sky type 1, with b = 2): L = L_z (1 + 2 cos θ) / 3;
//! - CIE clear sky (Kittler 1967; CIE 1973, *Standardization of luminance distribution on clear
//!   skies*, Publ. 22), with its indicatrix φ(γ) = 0.91 + 10 e^(−3γ) + 0.45 cos²γ and gradation
//!   f(θ) = 1 − e^(−0.32 / cos θ):
//!   L = L_z φ(γ) f(θ) / (φ(Z) · 0.274).
//!
//! 0.274 is `gensky`'s rounding of f(0) = 1 − e^(−0.32) = 0.27385, so L_z is `gensky`'s zenith
//! parameter and the clear sky's true zenith luminance is 0.99945 L_z. Below the horizon the
//! sky is the ground (see [`super::Sky`]); the distributions here are for μ > 0 only.
//!
//! The unobstructed horizontal illuminance is E_h = L_z ∫ (L / L_z) cos θ dω over the upper
//! hemisphere, in closed form for two of them:
//!
//! - uniform: E_h = π L_z;
//! - overcast: E_h = (2π / 3) ∫₀¹ (1 + 2μ) μ dμ = (2π / 3)(1/2 + 2/3) = 7π/9 · L_z;
//! - clear: no closed form; integrated numerically over the Tregenza patches
//!   ([`super::tregenza::Band::integrate`]).

use glam::DVec3;

/// Which luminance distribution (the `--sky` flag).
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, clap::ValueEnum,
)]
#[serde(rename_all = "kebab-case")]
pub enum SkyKind {
    /// The CIE standard overcast sky (`gensky -c`).
    #[value(help = crate::settings::NO_HELP)]
    Overcast,
    /// The CIE clear sky, which needs the sun's position (`gensky -s` / `+s`).
    #[value(help = crate::settings::NO_HELP)]
    Clear,
    /// Constant luminance (`gensky -u`).
    #[value(help = crate::settings::NO_HELP)]
    Uniform,
}

impl SkyKind {
    /// Whether the distribution depends on where the sun is.
    pub fn needs_sun_position(self) -> bool {
        self == SkyKind::Clear
    }

    /// E_h / L_z in closed form, where there is one: π (uniform), 7π/9 (overcast).
    pub fn closed_form_ratio(self) -> Option<f64> {
        match self {
            SkyKind::Uniform => Some(std::f64::consts::PI),
            SkyKind::Overcast => Some(7.0 * std::f64::consts::PI / 9.0),
            SkyKind::Clear => None,
        }
    }

    /// L / L_z towards the local direction `d` (unit, z up, μ = d.z > 0), the sun towards
    /// `sun` (unit, local; used by the clear sky only).
    pub fn relative(self, d: DVec3, sun: DVec3) -> f64 {
        match self {
            SkyKind::Uniform => 1.0,
            SkyKind::Overcast => (1.0 + 2.0 * d.z) / 3.0,
            SkyKind::Clear => {
                let cos_gamma = d.dot(sun);
                indicatrix(cos_gamma) * gradation(d.z) / (indicatrix(sun.z) * 0.274)
            }
        }
    }
}

/// The clear sky's indicatrix φ(γ) = 0.91 + 10 e^(−3γ) + 0.45 cos²γ (CIE 1973).
fn indicatrix(cos_gamma: f64) -> f64 {
    let c = cos_gamma.clamp(-1.0, 1.0);
    0.91 + 10.0 * (-3.0 * c.acos()).exp() + 0.45 * c * c
}

/// The clear sky's gradation f(θ) = 1 − e^(−0.32 / cos θ) (CIE 1973); 1 at the horizon.
fn gradation(mu: f64) -> f64 {
    if mu > 0.0 {
        1.0 - (-0.32 / mu).exp()
    } else {
        1.0
    }
}

/// `gensky`'s zenith luminance (cd/m²) when none is given, for the sun at `altitude` degrees:
/// 8.6 sin h + 0.123 kcd/m² for the overcast and uniform skies, (1.376 T − 1.81) tan h + 0.38
/// kcd/m² for the clear sky with turbidity T = [`GENSKY_TURBIDITY`]; never negative.
pub fn gensky_zenith_luminance(kind: SkyKind, altitude: f64) -> f64 {
    let h = altitude.to_radians();
    let kcd = match kind {
        SkyKind::Uniform | SkyKind::Overcast => 8.6 * h.sin() + 0.123,
        // tan h grows without bound; gensky lowers a clear sky's sun to 87° anyway.
        SkyKind::Clear => {
            (1.376 * GENSKY_TURBIDITY - 1.81) * h.min(87f64.to_radians()).tan() + 0.38
        }
    };
    (1000.0 * kcd).max(0.0)
}

/// `gensky`'s default atmospheric turbidity (`-t`).
pub const GENSKY_TURBIDITY: f64 = 2.45;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distributions_are_one_at_the_zenith() {
        let sun = DVec3::new(0.0, -0.6, 0.8);
        assert_eq!(SkyKind::Uniform.relative(DVec3::Z, sun), 1.0);
        assert_eq!(SkyKind::Overcast.relative(DVec3::Z, sun), 1.0);
        // 0.27385 / 0.274: gensky's rounding of f(0).
        let z = SkyKind::Clear.relative(DVec3::Z, sun);
        assert!((z - (1.0 - (-0.32f64).exp()) / 0.274).abs() < 1e-12, "{z}");
    }

    #[test]
    fn overcast_horizon_is_a_third_of_the_zenith() {
        assert!((SkyKind::Overcast.relative(DVec3::X, DVec3::Z) - 1.0 / 3.0).abs() < 1e-15);
    }

    #[test]
    fn clear_sky_is_brightest_near_the_sun() {
        let sun = DVec3::new(0.0, -(0.5f64.sqrt()), 0.5f64.sqrt());
        let at_sun = SkyKind::Clear.relative(sun, sun);
        let away = SkyKind::Clear.relative(DVec3::new(0.0, 0.6, 0.8), sun);
        // φ(0) = 11.36, φ(90°) ≈ 0.92: the circumsolar region is an order brighter.
        assert!(at_sun > 5.0 * away, "{at_sun} {away}");
    }

    #[test]
    fn gensky_default_zenith() {
        // gensky -c at 90°: 8.723 kcd/m²; -s at 45° with T = 2.45: 1.5612 + 0.38 kcd/m².
        assert!((gensky_zenith_luminance(SkyKind::Overcast, 90.0) - 8723.0).abs() < 1e-9);
        let clear = gensky_zenith_luminance(SkyKind::Clear, 45.0);
        assert!((clear - 1941.2).abs() < 1e-9, "{clear}");
        assert_eq!(gensky_zenith_luminance(SkyKind::Clear, -30.0), 0.0);
    }
}
