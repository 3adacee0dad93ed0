//! The Reinhart subdivision of the sky (C. F. Reinhart, *Tutorial on the use of Daysim
//! simulations for sustainable design*, 2006; Radiance's `reinhartb.cal` and `gendaymtx`'s
//! `rh_init`): each of Tregenza's seven bands split into MF rows and each row's patches into MF
//! in azimuth, with one cap about the zenith.
//!
//! **Geometry**, exactly `reinhartb.cal`'s: the rows are α = 90° / (7 MF + ½) high, row r
//! (0-based from the horizon) spans altitudes [r α, (r + 1) α] and holds MF × (30, 30, 24, 24,
//! 18, 12, 6)[r / MF] patches; patch j of a row of n is centred at azimuth 360° j / n (east of
//! north: j = 0 is due north, then east) and spans ±180° / n about it. The cap above 90° − α/2
//! is one patch. MF = 1 is Tregenza's 145 ([`super::tregenza`]); MF = 2 gives 577 and MF = 4
//! gives 2,305 sky patches: 144 MF² + 1.
//!
//! **Order**: row by row from the horizon up, each row from north going east, the cap last:
//! `reinhartb.cal`'s `rbin`. `gendaymtx` writes one more row before these, the ground (its
//! patch 0): sky patch k here is its row k + 1.
//!
//! **Centres.** `gendaymtx` evaluates the sky at a patch's centre altitude (r + ½) α (the
//! middle altitude, not the middle sin altitude) and centre azimuth, and the cap at the zenith;
//! [`SkyPatch::dir`] is that direction, and [`SkyPatch::cos`] its sine of altitude, the cosine
//! `gendaymtx` weights a patch by when it normalises the sky.

use super::tregenza::Band;
use crate::settings::Invalid;
use glam::DVec3;
use std::f64::consts::{FRAC_PI_2, TAU};

/// Tregenza's patches per band, from the horizon up (without the cap).
const TREGENZA_ROWS: [usize; 7] = [30, 30, 24, 24, 18, 12, 6];

/// The largest subdivision accepted: MF = 32 is 147,457 patches.
pub const MAX_SUBDIVISION: u32 = 32;

/// One sky patch of the Reinhart subdivision.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SkyPatch {
    /// The patch's extent in μ = sin altitude and azimuth (radians east of north).
    pub band: Band,
    /// `gendaymtx`'s centre altitude, radians: (r + ½) α, or 90° for the cap.
    pub altitude: f64,
    /// `gendaymtx`'s centre azimuth, radians east of north: 2π j / n, or 0 for the cap.
    pub azimuth: f64,
}

impl SkyPatch {
    /// The unit direction of the centre (x east, y north, z up), as `gendaymtx`'s `rh_vector`.
    pub fn dir(&self) -> DVec3 {
        let (sin_alt, cos_alt) = self.altitude.sin_cos();
        let (sin_azi, cos_azi) = self.azimuth.sin_cos();
        DVec3::new(cos_alt * sin_azi, cos_alt * cos_azi, sin_alt)
    }

    /// The sine of the centre's altitude (`gendaymtx`'s `rh_cos`).
    pub fn cos(&self) -> f64 {
        self.altitude.sin()
    }

    /// Solid angle, steradians: 2π (sin a₁ − sin a₀) / n for a row's patch, 2π (1 − cos(α/2))
    /// for the cap (`gendaymtx`'s `rh_dom`).
    pub fn solid_angle(&self) -> f64 {
        self.band.solid_angle()
    }
}

/// The number of sky patches for subdivision `mf`: 144 MF² + 1 (without the ground).
pub fn sky_patch_count(mf: u32) -> usize {
    let mf = mf as usize;
    144 * mf * mf + 1
}

/// Refuses a subdivision outside 1..=[`MAX_SUBDIVISION`].
pub fn check_subdivision(mf: u32) -> Result<(), Invalid> {
    if (1..=MAX_SUBDIVISION).contains(&mf) {
        Ok(())
    } else {
        Invalid::err(format!(
            "the Reinhart sky subdivision MF = {mf} is not within 1..={MAX_SUBDIVISION}"
        ))
    }
}

/// The row height α = (π/2) / (7 MF + ½), radians.
pub fn row_height(mf: u32) -> f64 {
    FRAC_PI_2 / (7.0 * mf as f64 + 0.5)
}

/// Patches in row `r` (0-based from the horizon; row 7 MF is the cap).
fn row_len(mf: u32, r: usize) -> usize {
    let mf = mf as usize;
    TREGENZA_ROWS.get(r / mf).map_or(1, |n| n * mf)
}

/// The sky patches of subdivision `mf`, in `reinhartb.cal`'s order (see the module docs).
pub fn patches(mf: u32) -> Result<Vec<SkyPatch>, Invalid> {
    check_subdivision(mf)?;
    let alpha = row_height(mf);
    let rows = 7 * mf as usize;
    let mut out = Vec::with_capacity(sky_patch_count(mf));
    for r in 0..rows {
        let n = row_len(mf, r);
        let mu = [(alpha * r as f64).sin(), (alpha * (r + 1) as f64).sin()];
        let width = TAU / n as f64;
        for j in 0..n {
            let azimuth = width * j as f64;
            out.push(SkyPatch {
                band: Band {
                    mu,
                    phi: [azimuth - width / 2.0, azimuth + width / 2.0],
                },
                altitude: alpha * (r as f64 + 0.5),
                azimuth,
            });
        }
    }
    out.push(SkyPatch {
        band: Band {
            mu: [(alpha * rows as f64).sin(), 1.0],
            phi: [-TAU / 2.0, TAU / 2.0],
        },
        altitude: FRAC_PI_2,
        azimuth: 0.0,
    });
    Ok(out)
}

/// The sky patch (0-based, [`patches`]' order) holding the local direction `d` (unit, z up),
/// as `reinhartb.cal`'s `rbin`; `None` at or below the horizon (its ground, −1).
pub fn patch_of(mf: u32, d: DVec3) -> Option<usize> {
    if d.z <= 0.0 || !d.is_finite() {
        return None;
    }
    let alpha = row_height(mf);
    let rows = 7 * mf as usize;
    let alt = d.z.min(1.0).asin();
    let row = ((alt / alpha) as usize).min(rows);
    let first: usize = (0..row).map(|r| row_len(mf, r)).sum();
    let n = row_len(mf, row);
    let azi = d.x.atan2(d.y).rem_euclid(TAU);
    let j = ((azi / (TAU / n as f64) + 0.5) as usize) % n;
    Some(first + j)
}
