//! The Perez all-weather sky and the Perez luminous efficacy model, as Radiance's `gendaymtx`
//! computes them from an hour's direct normal and diffuse horizontal irradiance.
//!
//! - R. Perez, P. Ineichen, R. Seals, J. Michalsky, R. Stewart, *Modeling daylight availability
//!   and irradiance components from direct and global irradiance*, Solar Energy 44(5), 1990
//!   ("Perez 1990"): the sky's clearness ε (eq. 1) and brightness Δ (eq. 2), the precipitable
//!   water W from the dew point (eq. 3) and the diffuse and direct luminous efficacies by ε bin
//!   (eq. 7 and 8, table 4).
//! - R. Perez, R. Seals, J. Michalsky, *All-weather model for sky luminance distribution —
//!   preliminary configuration and validation*, Solar Energy 50(3), 1993, with its erratum in
//!   Solar Energy 51(5), 1993 ("Perez 1993"): the relative luminance (eq. 1), its five
//!   parameters a–e from ε's bin, the sun's zenith angle Z and Δ (eq. 6, and for the first bin
//!   eq. 7 and 8), table 1's coefficients.
//!
//! **`gendaymtx`'s choices**, followed here (its functions `ComputeSky`, `CalcPerezParam`):
//! the sun's zenith angle Z is clamped to [3°, 90°] (a sun below the horizon is put on it, one
//! above 87° is lowered to 87° to keep the circumsolar peak off the zenith) for everything: ε,
//! Δ, the efficacies and the distribution; ε is clamped to [1, 11.9] and Δ to [0.01, 0.6]; the
//! parameters of bins 2–5 (1.065 < ε < 2.8) take Δ ≥ 0.2; the air mass is Kasten's (1966) and
//! the extraterrestrial irradiance 1,367 W/m² times Spencer's eccentricity correction of the
//! day of the year; without a dew point it is 11 °C (W = 2.0 cm). A diffuse irradiance of 0
//! with a direct one above it is ε = 11.9 (the limit of eq. 1), not a division by zero.
//!
//! **Units**: irradiance W/m², illuminance lux, angles radians unless a name says degrees.

use crate::settings::Invalid;
use glam::DVec3;
use std::f64::consts::FRAC_PI_2;

/// The solar constant `gendaymtx` uses, W/m².
pub const SOLAR_CONSTANT: f64 = 1367.0;

/// The surface dew point `gendaymtx` assumes when the weather file gives none, °C.
pub const DEFAULT_DEW_POINT: f64 = 11.0;

/// `gendaymtx`'s limits of the clearness ε.
pub const CLEARNESS_LIMITS: [f64; 2] = [1.0, 11.9];

/// `gendaymtx`'s limits of the brightness Δ.
pub const BRIGHTNESS_LIMITS: [f64; 2] = [0.01, 0.6];

/// The lower bounds of the eight ε bins (Perez 1990, table 1; Perez 1993, table 1), overcast
/// to clear. The last bin runs to 12.01 in `gendaymtx`, above the clamp of ε.
pub const CLEARNESS_BINS: [f64; 8] = [1.0, 1.065, 1.23, 1.5, 1.95, 2.8, 4.5, 6.2];

/// Perez 1993, table 1 (with the erratum): for each ε bin, the coefficients (x₁, x₂, x₃, x₄)
/// of a, b, c, d and e, each parameter x = x₁ + x₂ Z + Δ (x₃ + x₄ Z) (eq. 6) except c and d
/// of the first bin (eq. 7, 8). Rows are `[a, b, c, d, e]`.
pub const PEREZ_COEFFICIENTS: [[[f64; 4]; 5]; 8] = [
    [
        [1.3525, -0.2576, -0.2690, -1.4366],
        [-0.7670, 0.0007, 1.2734, -0.1233],
        [2.8000, 0.6004, 1.2375, 1.0000],
        [1.8734, 0.6297, 0.9738, 0.2809],
        [0.0356, -0.1246, -0.5718, 0.9938],
    ],
    [
        [-1.2219, -0.7730, 1.4148, 1.1016],
        [-0.2054, 0.0367, -3.9128, 0.9156],
        [6.9750, 0.1774, 6.4477, -0.1239],
        [-1.5798, -0.5081, -1.7812, 0.1080],
        [0.2624, 0.0672, -0.2190, -0.4285],
    ],
    [
        [-1.1000, -0.2515, 0.8952, 0.0156],
        [0.2782, -0.1812, -4.5000, 1.1766],
        [24.7219, -13.0812, -37.7000, 34.8438],
        [-5.0000, 1.5218, 3.9229, -2.6204],
        [-0.0156, 0.1597, 0.4199, -0.5562],
    ],
    [
        [-0.5484, -0.6654, -0.2672, 0.7117],
        [0.7234, -0.6219, -5.6812, 2.6297],
        [33.3389, -18.3000, -62.2500, 52.0781],
        [-3.5000, 0.0016, 1.1477, 0.1062],
        [0.4659, -0.3296, -0.0876, -0.0329],
    ],
    [
        [-0.6000, -0.3566, -2.5000, 2.3250],
        [0.2937, 0.0496, -5.6812, 1.8415],
        [21.0000, -4.7656, -21.5906, 7.2492],
        [-3.5000, -0.1554, 1.4062, 0.3988],
        [0.0032, 0.0766, -0.0656, -0.1294],
    ],
    [
        [-1.0156, -0.3670, 1.0078, 1.4051],
        [0.2875, -0.5328, -3.8500, 3.3750],
        [14.0000, -0.9999, -7.1406, 7.5469],
        [-3.4000, -0.1078, -1.0750, 1.5702],
        [-0.0672, 0.4016, 0.3017, -0.4844],
    ],
    [
        [-1.0000, 0.0211, 0.5025, -0.5119],
        [-0.3000, 0.1922, 0.7023, -1.6317],
        [19.0000, -5.0000, 1.2438, -1.9094],
        [-4.0000, 0.0250, 0.3844, 0.2656],
        [1.0468, -0.3788, -2.4517, 1.4656],
    ],
    [
        [-1.0500, 0.0289, 0.4260, 0.3590],
        [-0.3250, 0.1156, 0.7781, 0.0025],
        [31.0625, -14.5000, -46.1148, 55.3750],
        [-7.2312, 0.4050, 13.3500, 0.6234],
        [1.5000, -0.6426, 1.8564, 0.5636],
    ],
];

/// Perez 1990, table 4: the diffuse luminous efficacy's (a, b, c, d) per ε bin, lm/W, in
/// K = a + b W + c cos Z + d ln Δ (eq. 7).
pub const DIFFUSE_EFFICACY: [[f64; 4]; 8] = [
    [97.24, -0.46, 12.00, -8.91],
    [107.22, 1.15, 0.59, -3.95],
    [104.97, 2.96, -5.53, -8.77],
    [102.39, 5.59, -13.95, -13.90],
    [100.71, 5.94, -22.75, -23.74],
    [106.42, 3.83, -36.15, -28.83],
    [141.88, 1.90, -53.24, -14.03],
    [152.23, 0.35, -45.27, -7.98],
];

/// Perez 1990, table 4: the direct luminous efficacy's (a, b, c, d) per ε bin, lm/W, in
/// K = a + b W + c e^(5.73 Z − 5) + d Δ (eq. 8).
pub const DIRECT_EFFICACY: [[f64; 4]; 8] = [
    [57.20, -4.55, -2.98, 117.12],
    [98.99, -3.46, -1.21, 12.38],
    [109.83, -4.90, -1.71, -8.81],
    [110.34, -5.84, -1.99, -4.56],
    [106.36, -3.97, -1.75, -6.16],
    [107.19, -1.25, -1.51, -26.73],
    [105.75, 0.77, -1.26, -34.44],
    [101.18, 1.58, -1.10, -8.29],
];

/// The eccentricity correction (r₀ / r)² of the earth's orbit on day `day_of_year` (1 =
/// 1 January), Spencer's Fourier series as `gendaymtx` writes it (after Sen 2008, p. 72): with
/// Γ = 2π (day − 1) / 365, 1.00011 + 0.034221 cos Γ + 0.00128 sin Γ + 0.000719 cos 2Γ +
/// 0.000077 sin 2Γ.
pub fn eccentricity(day_of_year: u32) -> f64 {
    let g = (day_of_year as f64 - 1.0) * std::f64::consts::TAU / 365.0;
    1.00011
        + 0.034221 * g.cos()
        + 0.00128 * g.sin()
        + 0.000719 * (2.0 * g).cos()
        + 0.000077 * (2.0 * g).sin()
}

/// The relative optical air mass at solar zenith angle `zenith` (radians, at most 90°):
/// Kasten (1966), m = 1 / (cos Z + 0.15 (93.885 − Z°)^−1.253), as `gendaymtx`.
pub fn air_mass(zenith: f64) -> f64 {
    let z = zenith.clamp(0.0, FRAC_PI_2);
    1.0 / (z.cos() + 0.15 * (93.885 - z.to_degrees()).powf(-1.253))
}

/// Perez 1990, eq. 3: the atmospheric precipitable water W = e^(0.07 T_d − 0.075), cm, from
/// the surface dew point T_d (°C).
pub fn precipitable_water(dew_point: f64) -> f64 {
    (0.07 * dew_point - 0.075).exp()
}

/// Perez 1990, eq. 1: the sky's clearness ε = ((D + I)/D + κ Z³) / (1 + κ Z³), κ = 1.041, from
/// the diffuse horizontal D and direct normal I irradiance and the zenith angle Z (radians),
/// **before** `gendaymtx`'s clamp; D = 0 gives +∞ (a sky with no diffuse light is clear).
pub fn clearness(dni: f64, dhi: f64, zenith: f64) -> f64 {
    let kz3 = 1.041 * zenith.powi(3);
    if dhi <= 0.0 {
        return f64::INFINITY;
    }
    ((dhi + dni) / dhi + kz3) / (1.0 + kz3)
}

/// Perez 1990, eq. 2: the sky's brightness Δ = D m / I₀, with the air mass m ([`air_mass`])
/// and the extraterrestrial normal irradiance I₀ = 1367 W/m² × [`eccentricity`], before the
/// clamp.
pub fn brightness(dhi: f64, zenith: f64, day_of_year: u32) -> f64 {
    dhi * air_mass(zenith) / (SOLAR_CONSTANT * eccentricity(day_of_year))
}

/// The ε bin (0 = overcast … 7 = clear) of a clearness, [`CLEARNESS_BINS`].
pub fn clearness_bin(epsilon: f64) -> usize {
    CLEARNESS_BINS
        .iter()
        .rposition(|&lo| epsilon >= lo)
        .unwrap_or(0)
}

/// The five parameters a–e of the relative luminance (Perez 1993, eq. 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PerezParameters(pub [f64; 5]);

impl PerezParameters {
    /// Perez 1993, eq. 6: each parameter x = x₁ + x₂ Z + Δ (x₃ + x₄ Z) from bin `bin`'s row
    /// of [`PEREZ_COEFFICIENTS`]; in the first bin, eq. 7: c = e^((Δ (c₁ + c₂ Z))^c₃) − c₄ and
    /// eq. 8: d = −e^(Δ (d₁ + d₂ Z)) + d₃ + Δ d₄. As `gendaymtx`, bins 2–5 (1.065 < ε < 2.8)
    /// use Δ ≥ 0.2. `zenith` in radians.
    pub fn new(bin: usize, epsilon: f64, zenith: f64, delta: f64) -> PerezParameters {
        let x = &PEREZ_COEFFICIENTS[bin.min(7)];
        let delta = if epsilon > 1.065 && epsilon < 2.8 {
            delta.max(0.2)
        } else {
            delta
        };
        let linear = |k: usize| x[k][0] + x[k][1] * zenith + delta * (x[k][2] + x[k][3] * zenith);
        let mut p = [linear(0), linear(1), linear(2), linear(3), linear(4)];
        if bin == 0 {
            // Δ ≥ 0.01 and c₁ + c₂ Z > 0: the power's base is positive.
            p[2] = (delta * (x[2][0] + x[2][1] * zenith))
                .max(0.0)
                .powf(x[2][2])
                .exp()
                - x[2][3];
            p[3] = -(delta * (x[3][0] + x[3][1] * zenith)).exp() + x[3][2] + delta * x[3][3];
        }
        PerezParameters(p)
    }

    /// Perez 1993, eq. 1: the relative luminance
    /// lv(ζ, γ) = (1 + a e^(b / cos ζ)) (1 + c e^(d γ) + e cos² γ) of a sky element at zenith
    /// angle ζ and angle γ from the sun, given as cos ζ and γ (radians). Never negative (`gendaymtx` clamps a negative patch to 0) and
    /// finite: cos ζ is taken ≥ 10⁻³, so the horizon itself is the limit from above.
    pub fn relative_luminance(&self, cos_zeta: f64, gamma: f64) -> f64 {
        let [a, b, c, d, e] = self.0;
        let gradation = 1.0 + a * (b / cos_zeta.max(1e-3)).min(700.0).exp();
        let cos_gamma = gamma.cos();
        let indicatrix = 1.0 + c * (d * gamma).min(700.0).exp() + e * cos_gamma * cos_gamma;
        let lv = gradation * indicatrix;
        if lv.is_finite() {
            lv.max(0.0)
        } else {
            0.0
        }
    }
}

/// One hour's Perez sky: the clamped ε and Δ, the bin, the parameters and the illuminances the
/// efficacy model gives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PerezSky {
    /// The sun's zenith angle as the model uses it, radians: clamped to [3°, 90°].
    pub zenith: f64,
    /// The sun's azimuth, radians east of north.
    pub azimuth: f64,
    /// Clearness ε, clamped to [`CLEARNESS_LIMITS`].
    pub clearness: f64,
    /// Brightness Δ, clamped to [`BRIGHTNESS_LIMITS`].
    pub brightness: f64,
    /// The ε bin, 0–7.
    pub bin: usize,
    pub parameters: PerezParameters,
    /// Diffuse horizontal illuminance, lux: D × the diffuse efficacy (Perez 1990, eq. 7).
    pub diffuse_illuminance: f64,
    /// Direct normal illuminance, lux: I × the direct efficacy (Perez 1990, eq. 8), ≥ 0.
    pub direct_illuminance: f64,
}

/// What one hour's Perez sky is made from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PerezInput {
    /// Day of the year, 1–366 (1 = 1 January).
    pub day_of_year: u32,
    /// The sun's altitude, degrees, in [−90°, 90°].
    pub altitude: f64,
    /// The sun's azimuth, degrees east of north.
    pub azimuth: f64,
    /// Direct normal irradiance, W/m², ≥ 0.
    pub dni: f64,
    /// Diffuse horizontal irradiance, W/m², ≥ 0.
    pub dhi: f64,
    /// Surface dew point, °C ([`DEFAULT_DEW_POINT`] when unknown).
    pub dew_point: f64,
}

impl PerezSky {
    /// The sky of an hour (the module docs give `gendaymtx`'s clamps). Refuses negative or
    /// non-finite irradiances, an altitude outside [−90°, 90°], a day outside 1–366 and a dew
    /// point outside [−100, 60] °C.
    pub fn new(input: &PerezInput) -> Result<PerezSky, Invalid> {
        input.check()?;
        let PerezInput {
            day_of_year,
            altitude,
            azimuth,
            dni,
            dhi,
            dew_point,
        } = *input;
        let zenith = if altitude <= 0.0 {
            90.0
        } else {
            (90.0 - altitude).max(3.0)
        }
        .to_radians();
        let [e0, e1] = CLEARNESS_LIMITS;
        let clearness = clearness(dni, dhi, zenith).clamp(e0, e1);
        let [d0, d1] = BRIGHTNESS_LIMITS;
        let brightness = brightness(dhi, zenith, day_of_year).clamp(d0, d1);
        let bin = clearness_bin(clearness);
        let w = precipitable_water(dew_point);
        let [a, b, c, d] = DIFFUSE_EFFICACY[bin];
        let diffuse = a + b * w + c * zenith.cos() + d * brightness.ln();
        let [a, b, c, d] = DIRECT_EFFICACY[bin];
        let direct = (a + b * w + c * (5.73 * zenith - 5.0).exp() + d * brightness).max(0.0);
        Ok(PerezSky {
            zenith,
            azimuth: azimuth.to_radians(),
            clearness,
            brightness,
            bin,
            parameters: PerezParameters::new(bin, clearness, zenith, brightness),
            diffuse_illuminance: dhi * diffuse,
            direct_illuminance: dni * direct,
        })
    }

    /// The direction of the sun the distribution is centred on (its zenith angle clamped),
    /// unit, x east, y north, z up.
    pub fn sun_dir(&self) -> DVec3 {
        let (sin_z, cos_z) = self.zenith.sin_cos();
        let (sin_a, cos_a) = self.azimuth.sin_cos();
        DVec3::new(sin_z * sin_a, sin_z * cos_a, cos_z)
    }

    /// The relative luminance towards the local unit direction `d` (z up) with the sun towards
    /// `sun` ([`PerezSky::sun_dir`]): Perez 1993, eq. 1 with cos ζ = d_z and γ = ∠(d, sun).
    pub fn relative_luminance(&self, d: DVec3, sun: DVec3) -> f64 {
        let gamma = d.dot(sun).clamp(-1.0, 1.0).acos();
        self.parameters.relative_luminance(d.z, gamma)
    }
}

impl PerezInput {
    fn check(&self) -> Result<(), Invalid> {
        let (altitude, azimuth) = (self.altitude, self.azimuth);
        let (day_of_year, dew_point) = (self.day_of_year, self.dew_point);
        for (what, v) in [
            ("direct normal", self.dni),
            ("diffuse horizontal", self.dhi),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Invalid::err(format!(
                    "the {what} irradiance {v} W/m² is not a finite, non-negative number"
                ));
            }
        }
        if !(altitude.is_finite() && altitude.abs() <= 90.0 && azimuth.is_finite()) {
            return Invalid::err(format!(
            "the solar altitude {altitude}° and azimuth {azimuth}°: the altitude must be within [-90, 90]"
        ));
        }
        if !(1..=366).contains(&day_of_year) {
            return Invalid::err(format!(
                "day of the year {day_of_year} is not within 1..=366"
            ));
        }
        if !(dew_point.is_finite() && (-100.0..=60.0).contains(&dew_point)) {
            return Invalid::err(format!(
                "the dew point {dew_point} °C is not within [-100, 60]"
            ));
        }
        Ok(())
    }
}
