//! Placed luminaires: a photometric web put somewhere in the model, turned some way, and the
//! light it sends toward any world direction.
//!
//! A [`Luminaire`] is one photometric file ([`crate::photometry`]) at a position with a
//! [`Frame`]: where its nadir aims and where its C0 plane lies. [`frame`] fixes the luminaire's
//! local frame (−Z the aim, +X the length and C0, +Y the width and C90) and how the file's
//! angles (Types C, B and A) map to local directions; [`schedule`] reads the list of
//! luminaires a user gives (`--luminaires FILE`, CSV or JSON).
//!
//! **Units.** The solver's light is in watts (RGB, f64). A web's candela become a radiant
//! intensity in W/sr and its lumens watts by [`EFFICACY`], 179 lm/W (Radiance's convention for
//! white light): I W/sr = I cd / 179.
//!
//! **Colour.** A luminaire's RGB tint is normalised so that its luminance weights (Rec. 709,
//! 0.2126 R + 0.7152 G + 0.0722 B) sum to 1 ([`normalise_colour`]): tinting moves watts
//! between the channels but keeps the lumens, as Radiance's `ies2rad -c` does. A white
//! luminaire has colour (1, 1, 1).
//!
//! **Scale.** [`Luminaire::scale`] multiplies the whole web: the light-loss factor times the
//! number of identical luminaires the one stands for.
//!
//! **Tilt.** An IES file's tilt table (`TILT=INCLUDE`) gives the lamp's output against the
//! luminaire's tilt from its design orientation. It is applied as one constant factor, read at
//! the angle between the aim and the nadir (−zenith): a simplification that takes the design
//! orientation to be aimed straight down and ignores which way the luminaire is tilted (LM-63's
//! lamp-to-luminaire geometries 1–3 are not told apart). See [`tilt_factor`].

pub mod frame;
pub mod schedule;

pub use frame::{file_angles, local_direction, Frame};
pub use schedule::{read_schedule, ScheduleError};

use crate::photometry::Photometry;
use crate::sky::EFFICACY;
use glam::DVec3;
use std::path::PathBuf;
use std::sync::Arc;

/// Rec. 709 luminance weights of R, G and B: a colour's luminance is their weighted sum.
pub const LUMINANCE_WEIGHTS: [f64; 3] = [0.2126, 0.7152, 0.0722];

/// A luminaire placed in the model.
#[derive(Clone, Debug, PartialEq)]
pub struct Luminaire {
    /// Its name, unique within a schedule unless the user repeats one.
    pub name: String,
    /// The group it belongs to (switched or reported together); by default its name.
    pub group: String,
    /// The photometric file it was read from, as the schedule's folder and the schedule's
    /// path make it.
    pub file: PathBuf,
    /// The web, shared by every luminaire of the same file.
    pub photometry: Arc<Photometry>,
    /// The web's own lumens (`Photometry::total_lumens`, integrated once when it was read).
    pub web_lumens: f64,
    /// Where it is: the photometric centre, model coordinates.
    pub position: DVec3,
    /// How it is turned.
    pub frame: Frame,
    /// What the whole web is multiplied by: light-loss factor × the number of identical
    /// luminaires this one stands for. Dimensionless.
    pub scale: f64,
    /// RGB tint, normalised so that 0.2126 R + 0.7152 G + 0.0722 B = 1 ([`normalise_colour`]).
    pub colour: [f64; 3],
    /// The IES tilt factor at this luminaire's aim ([`tilt_factor`]); 1 without a tilt table.
    pub tilt_factor: f64,
}

impl Luminaire {
    /// Radiant intensity toward world direction `world_dir` (any length) from the luminaire,
    /// W/sr per RGB channel: the web's candela in that direction / [`EFFICACY`] × scale ×
    /// tilt factor × colour. 0 for a zero or non-finite direction and where the web gives no
    /// light (outside its angles, behind a Type A or B luminaire).
    pub fn intensity_toward(&self, world_dir: DVec3) -> [f64; 3] {
        let (h, v) = file_angles(self.photometry.kind, self.frame.to_local(world_dir));
        let candela = self.photometry.intensity(h, v);
        let watts = candela / EFFICACY * self.scale * self.tilt_factor;
        self.colour.map(|c| watts * c)
    }

    /// The luminaire's luminous flux, lumens: the web's total lumens × scale × tilt factor.
    pub fn flux_lumens(&self) -> f64 {
        self.web_lumens * self.scale * self.tilt_factor
    }

    /// The luminaire's radiant flux per RGB channel, W: [`Luminaire::flux_lumens`] /
    /// [`EFFICACY`] × colour (whose luminance is the lumens again, by the colour's
    /// normalisation).
    pub fn flux_watts(&self) -> [f64; 3] {
        let watts = self.flux_lumens() / EFFICACY;
        self.colour.map(|c| watts * c)
    }
}

impl Luminaire {
    /// Whether its file gives a luminous opening with an area (LM-63's width, length or
    /// height; EULUMDAT's luminous area): its direct light is then taken from points spread
    /// over the opening ([`Luminaire::opening_point`]) rather than from its centre.
    pub fn has_opening(&self) -> bool {
        let o = &self.photometry.luminous_opening;
        [o.width, o.length, o.height]
            .iter()
            .filter(|x| **x > 0.0)
            .count()
            >= 2
    }

    /// A point of the luminous opening for `(a, b)` uniform in [0, 1)² (the photometric
    /// centre without an opening): a rectangle (LM-63's flat rectangle and box, at the
    /// centre's height) of its length along C0 and width along C90, or for the round shapes an
    /// ellipse over the first two of length (C0), width (C90) and height (up) it has. Uniform
    /// over the area, so that the far-field intensity spread evenly over it gives its light
    /// near by as Radiance's `ies2rad` sources do: E = mean over the opening of I(ω)·cos θ/r².
    pub fn opening_point(&self, a: f64, b: f64) -> DVec3 {
        use crate::photometry::OpeningShape as S;
        if !self.has_opening() {
            return self.position;
        }
        let o = &self.photometry.luminous_opening;
        let f = &self.frame;
        let axes = [(o.length, f.c0), (o.width, f.c90), (o.height, -f.aim)];
        let mut it = axes.iter().filter(|(x, _)| *x > 0.0);
        let (Some(&(l1, u1)), Some(&(l2, u2))) = (it.next(), it.next()) else {
            return self.position;
        };
        let (x, y) = match o.shape {
            S::Rectangle | S::Box => (a - 0.5, b - 0.5),
            _ => {
                let (r, phi) = (a.sqrt() / 2.0, std::f64::consts::TAU * b);
                (r * phi.cos(), r * phi.sin())
            }
        };
        self.position + u1 * (x * l1) + u2 * (y * l2)
    }
}

/// The IES tilt factor of `photometry` for a luminaire aimed along `aim` in a model whose up
/// direction is `zenith`: the tilt table's factor at the angle between the aim and the nadir
/// (−zenith), degrees (0 aimed straight down, 90 aimed at the horizon), or 1 without a table.
/// A zero or non-finite aim or zenith reads the table at its first angle.
pub fn tilt_factor(photometry: &Photometry, aim: DVec3, zenith: DVec3) -> f64 {
    let Some(tilt) = &photometry.tilt else {
        return 1.0;
    };
    let (aim, up) = (aim.normalize_or_zero(), zenith.normalize_or_zero());
    // Tilt::factor reads a NaN angle at the table's first angle.
    let angle = if aim == DVec3::ZERO || up == DVec3::ZERO {
        f64::NAN
    } else {
        aim.dot(-up).clamp(-1.0, 1.0).acos().to_degrees()
    };
    tilt.factor(angle)
}

/// An RGB tint scaled so that its luminance (0.2126 R + 0.7152 G + 0.0722 B) is 1, or `None`
/// if a channel is negative or not finite, or all are 0.
pub fn normalise_colour(rgb: [f64; 3]) -> Option<[f64; 3]> {
    if rgb.iter().any(|c| !(c.is_finite() && *c >= 0.0)) {
        return None;
    }
    let luminance: f64 = rgb.iter().zip(LUMINANCE_WEIGHTS).map(|(c, w)| c * w).sum();
    (luminance > 0.0 && luminance.is_finite()).then(|| rgb.map(|c| c / luminance))
}

#[cfg(test)]
mod tests;
