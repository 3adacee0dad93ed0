//! The luminaire's own frame, the photometric file's angles in it, and the frame's place in
//! the world.
//!
//! **The local frame.** Every placed luminaire, and everything that turns a photometric web
//! into directions, uses one frame fixed to the luminaire:
//!
//! - −Z is the nadir, the aiming direction: γ = 0 of a Type C file, H = V = 0 of Types A and B;
//! - +X is the luminaire's length and its C0 plane (LM-63's 0° plane);
//! - +Y is its width and its C90 plane;
//! - right-handed (X × Y = Z), so that seen from behind the luminaire looking along its aim
//!   (from above a downlight) the C angle counts counter-clockwise from C0 to C90, as LM-63
//!   and EN 13032-1 count it.
//!
//! **The file's angles as local directions** ([`local_direction`], inverted by
//! [`file_angles`]):
//!
//! - Type C: (C, γ) ↦ (sin γ cos C, sin γ sin C, −cos γ): γ from the nadir, C about the
//!   vertical axis from +X toward +Y.
//! - Type B, polar axis along the width (+Y): (H, V) ↦ sin H·(+Y) + cos H sin V·(+X) +
//!   cos H cos V·(−Z): V turns the aim about the polar axis toward +X, H leans out of that
//!   plane toward +Y.
//! - Type A, polar axis along the length (+X): (H, V) ↦ sin H·(+X) + cos H sin V·(+Y) +
//!   cos H cos V·(−Z).
//!
//! For Types A and B the web covers H and V in −90..90, the half-space in front of the
//! luminaire (local z ≤ 0). A direction behind it has |V| > 90 by [`file_angles`] (V runs
//! −180..180 there), outside any Type A or B web, where [`Photometry::intensity`] gives 0.
//!
//! **In the world** a [`Frame`] holds the world directions of the local axes: `aim` (local
//! −Z), `c0` (local +X) and `c90` (local +Y). [`Frame::new`] says how C0 is chosen and how
//! the spin turns it.
//!
//! [`Photometry::intensity`]: crate::photometry::Photometry::intensity

use crate::photometry::PhotometricType;
use glam::DVec3;

/// Below this length, out of 1, what is left of a unit vector once its part along another is
/// removed counts as nothing: the two are taken as (anti)parallel (about 0.00006° apart).
const PARALLEL: f64 = 1e-6;

/// The local direction (unit vector) of the file's angles `h_deg` (horizontal: C for Type C,
/// H for Types A and B) and `v_deg` (vertical: γ for Type C, V for Types A and B), degrees,
/// by the formulas of the module doc. Quarter turns are exact: (C90, γ90) is exactly +Y.
pub fn local_direction(kind: PhotometricType, h_deg: f64, v_deg: f64) -> DVec3 {
    let (sin_h, cos_h) = sin_cos_deg(h_deg);
    let (sin_v, cos_v) = sin_cos_deg(v_deg);
    match kind {
        PhotometricType::C => DVec3::new(sin_v * cos_h, sin_v * sin_h, -cos_v),
        PhotometricType::B => DVec3::new(cos_h * sin_v, sin_h, -cos_h * cos_v),
        PhotometricType::A => DVec3::new(sin_h, cos_h * sin_v, -cos_h * cos_v),
    }
}

/// The file's angles `(h_deg, v_deg)` of local direction `d` (any length), the pair to give
/// [`Photometry::intensity`](crate::photometry::Photometry::intensity):
///
/// - Type C: h = C in 0..360 (0 at the poles, where C is undefined), v = γ in 0..180;
/// - Types A and B: h = H in −90..90, v = V in −180..180: |V| ≤ 90 in front of the luminaire,
///   |V| > 90 behind it (local z > 0), outside any web, so the intensity there is 0. At the
///   poles of the polar axis (H = ±90) V is undefined and given as 0.
///
/// A zero or non-finite `d` gives NaN angles, for which `Photometry::intensity` is 0.
pub fn file_angles(kind: PhotometricType, d: DVec3) -> (f64, f64) {
    let Some(d) = unit(d) else {
        return (f64::NAN, f64::NAN);
    };
    match kind {
        PhotometricType::C => {
            // atan2 rather than acos: as exact near the poles as anywhere.
            let gamma = d.x.hypot(d.y).atan2(-d.z).to_degrees();
            let c = if d.x == 0.0 && d.y == 0.0 {
                0.0
            } else {
                d.y.atan2(d.x).to_degrees().rem_euclid(360.0)
            };
            // rem_euclid of a tiny negative angle rounds up to 360 itself.
            (if c >= 360.0 { 0.0 } else { c }, gamma)
        }
        PhotometricType::B => polar_angles(d.y, d.x, d.z),
        PhotometricType::A => polar_angles(d.x, d.y, d.z),
    }
}

/// (H, V) of a unit direction whose component along the polar axis is `along`, across it (in
/// the plane of H = 0) `across`, and local z `z`.
fn polar_angles(along: f64, across: f64, z: f64) -> (f64, f64) {
    // atan2 rather than asin: as exact near the poles as anywhere.
    let h = along.atan2(across.hypot(z)).to_degrees();
    // At the pole atan2(±0, ±0) could be ±180 (behind): V is undefined there, take 0.
    let v = if across == 0.0 && z == 0.0 {
        0.0
    } else {
        across.atan2(-z).to_degrees()
    };
    (h, v)
}

/// `(sin, cos)` of an angle in degrees, exact at whole quarter turns.
fn sin_cos_deg(deg: f64) -> (f64, f64) {
    let r = deg.rem_euclid(360.0);
    if r == 0.0 {
        (0.0, 1.0)
    } else if r == 90.0 {
        (1.0, 0.0)
    } else if r == 180.0 {
        (0.0, -1.0)
    } else if r == 270.0 {
        (-1.0, 0.0)
    } else {
        deg.to_radians().sin_cos()
    }
}

/// `v` scaled to length 1, or `None` if it is zero or not finite. Scaled by its largest
/// component first, so that no finite vector overflows.
fn unit(v: DVec3) -> Option<DVec3> {
    let big = v.abs().max_element();
    if !(big.is_finite() && big > 0.0) {
        return None;
    }
    let v = v / big;
    Some(v / v.length())
}

/// The unit part of unit vector `v` perpendicular to unit vector `axis`, or `None` if the two
/// are (anti)parallel. Exact when `v` is already perpendicular to `axis` with an exact zero
/// dot product (axis-aligned vectors).
fn perpendicular(v: DVec3, axis: DVec3) -> Option<DVec3> {
    let p = v - v.dot(axis) * axis;
    let len = p.length();
    (len >= PARALLEL).then(|| p / len)
}

/// The default reference for C0 in a model with unit zenith `up`: the model's +X made
/// perpendicular to the zenith, or +Z if +X is the zenith (or its opposite).
fn horizontal_reference(up: DVec3) -> DVec3 {
    perpendicular(DVec3::X, up)
        .or_else(|| perpendicular(DVec3::Z, up))
        .unwrap_or(DVec3::Z)
}

/// A luminaire's frame in world space: the world directions of its local axes (orthonormal,
/// right-handed: `c0 × c90 = −aim`, as local X × Y = Z = −(−Z)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// World direction of local −Z: where the luminaire aims (γ = 0; H = V = 0).
    pub aim: DVec3,
    /// World direction of local +X: the luminaire's length, its C0 plane.
    pub c0: DVec3,
    /// World direction of local +Y: the luminaire's width, its C90 plane.
    pub c90: DVec3,
}

impl Frame {
    /// The frame of a luminaire aimed along `aim` (any length) in a model whose up direction
    /// is `zenith` (any length), its C0 axis chosen as follows and then turned by `spin_deg`.
    ///
    /// **C0 before the spin.** The reference direction is `c0_hint` if given, else the
    /// model's horizontal reference: +X made perpendicular to the zenith (+Z instead if +X is
    /// the zenith or its opposite). C0 is the reference made perpendicular to the aim; if the
    /// aim is (anti)parallel to the reference, the zenith made perpendicular to the aim
    /// instead (a luminaire aimed along +X has C0 up), and failing that (a hint along a
    /// vertical aim) the horizontal reference. So a downlight in a Y-up or Z-up model has C0
    /// along +X; C90 is then −Z (Y-up) or +Y (Z-up).
    ///
    /// **Spin.** `spin_deg` turns C0 and C90 about the aim: positive is counter-clockwise
    /// seen from behind the luminaire looking along its aim (from above a downlight, as in a
    /// plan), the right-hand turn about −aim, i.e. the direction in which the C angle grows.
    /// At spin 90° C0 lies where C90 was: the file's C-plane c appears where the unspun
    /// frame's plane c + spin was.
    ///
    /// `None` if `aim` or `zenith` is zero or not finite, `spin_deg` is not finite, or
    /// `c0_hint` is given and zero or not finite.
    pub fn new(aim: DVec3, spin_deg: f64, c0_hint: Option<DVec3>, zenith: DVec3) -> Option<Frame> {
        let aim = unit(aim)?;
        let up = unit(zenith)?;
        if !spin_deg.is_finite() {
            return None;
        }
        let horizontal = horizontal_reference(up);
        let reference = match c0_hint {
            Some(hint) => unit(hint)?,
            None => horizontal,
        };
        let c0 = perpendicular(reference, aim)
            .or_else(|| perpendicular(up, aim))
            .or_else(|| perpendicular(horizontal, aim))?;
        let back = -aim;
        let c90 = back.cross(c0);
        let (sin, cos) = sin_cos_deg(spin_deg);
        let c0 = c0 * cos + c90 * sin;
        Some(Frame {
            aim,
            c0,
            c90: back.cross(c0),
        })
    }

    /// The frame of a luminaire aimed straight down (−zenith), C0 by the horizontal reference,
    /// no spin; `None` if `zenith` is zero or not finite.
    pub fn downward(zenith: DVec3) -> Option<Frame> {
        Frame::new(-zenith, 0.0, None, zenith)
    }

    /// A world vector in the local frame: (along C0, along C90, against the aim).
    pub fn to_local(&self, world: DVec3) -> DVec3 {
        DVec3::new(
            world.dot(self.c0),
            world.dot(self.c90),
            -world.dot(self.aim),
        )
    }

    /// A local vector in world space (the inverse of [`Frame::to_local`]).
    pub fn to_world(&self, local: DVec3) -> DVec3 {
        self.c0 * local.x + self.c90 * local.y - self.aim * local.z
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use PhotometricType::{A, B, C};

    fn close(a: DVec3, b: DVec3) -> bool {
        (a - b).length() < 1e-12
    }

    /// A grid of angles, degrees, `lo..=hi` in `n` steps.
    fn grid(lo: f64, hi: f64, n: usize) -> Vec<f64> {
        (0..=n)
            .map(|k| lo + (hi - lo) * k as f64 / n as f64)
            .collect()
    }

    #[test]
    fn type_c_angles_follow_the_convention_and_round_trip() {
        assert_eq!(local_direction(C, 0.0, 0.0), DVec3::NEG_Z);
        assert_eq!(local_direction(C, 0.0, 90.0), DVec3::X);
        assert_eq!(local_direction(C, 90.0, 90.0), DVec3::Y);
        assert_eq!(local_direction(C, 270.0, 90.0), DVec3::NEG_Y);
        assert_eq!(local_direction(C, 123.0, 180.0).z, 1.0);
        for c in grid(0.0, 350.0, 35) {
            for g in grid(5.0, 175.0, 17) {
                let (c2, g2) = file_angles(C, local_direction(C, c, g));
                // Angles from acos and atan2 of rounded components: a few ulps of a degree.
                assert!((c2 - c).abs() < 1e-9 && (g2 - g).abs() < 1e-9, "C{c} γ{g}");
            }
        }
        // Any length.
        let (c, g) = file_angles(C, DVec3::new(0.0, 3.0, -3.0));
        assert!((c - 90.0).abs() < 1e-12 && (g - 45.0).abs() < 1e-12);
    }

    #[test]
    fn type_c_poles_have_c_zero() {
        assert_eq!(file_angles(C, DVec3::NEG_Z), (0.0, 0.0));
        assert_eq!(file_angles(C, DVec3::Z), (0.0, 180.0));
        // Signed zeros must not turn the pole into C180.
        assert_eq!(file_angles(C, DVec3::new(-0.0, 0.0, -1.0)), (0.0, 0.0));
        assert_eq!(file_angles(C, DVec3::new(-0.0, -0.0, 2.0)), (0.0, 180.0));
        // Just below C360: in 0..360.
        let (c, _) = file_angles(C, DVec3::new(1.0, -1e-20, -1.0));
        assert!((0.0..360.0).contains(&c), "{c}");
    }

    #[test]
    fn type_a_and_b_angles_follow_the_convention_and_round_trip() {
        assert_eq!(local_direction(B, 0.0, 0.0), DVec3::NEG_Z);
        assert_eq!(local_direction(B, 90.0, 0.0), DVec3::Y);
        assert_eq!(local_direction(B, 0.0, 90.0), DVec3::X);
        assert_eq!(local_direction(A, 90.0, 0.0), DVec3::X);
        assert_eq!(local_direction(A, 0.0, 90.0), DVec3::Y);
        assert_eq!(local_direction(A, 0.0, -90.0), DVec3::NEG_Y);
        for kind in [A, B] {
            for h in grid(-85.0, 85.0, 17) {
                for v in grid(-175.0, 175.0, 35) {
                    let (h2, v2) = file_angles(kind, local_direction(kind, h, v));
                    assert!(
                        (h2 - h).abs() < 1e-9 && (v2 - v).abs() < 1e-9,
                        "{kind:?} H{h} V{v}"
                    );
                }
            }
        }
    }

    #[test]
    fn type_a_and_b_poles_and_the_back_half() {
        assert_eq!(file_angles(B, DVec3::Y), (90.0, 0.0));
        assert_eq!(file_angles(B, DVec3::new(-0.0, -1.0, -0.0)), (-90.0, 0.0));
        assert_eq!(file_angles(A, DVec3::new(1.0, 0.0, -0.0)), (90.0, 0.0));
        for kind in [A, B] {
            // Straight back, and anything with local z > 0: |V| > 90.
            assert_eq!(file_angles(kind, DVec3::Z).1.abs(), 180.0);
            for d in [
                DVec3::new(0.3, 0.2, 0.1),
                DVec3::new(-0.9, 0.1, 1e-3),
                DVec3::new(0.1, -0.9, 1e-3),
            ] {
                let (h, v) = file_angles(kind, d);
                assert!(v.abs() > 90.0 && h.abs() < 90.0, "{kind:?} {d}: {h} {v}");
            }
            // In front: |V| ≤ 90.
            let (_, v) = file_angles(kind, DVec3::new(0.5, 0.5, -1e-3));
            assert!(v.abs() <= 90.0);
        }
    }

    #[test]
    fn degenerate_directions_give_nan_angles() {
        for kind in [A, B, C] {
            for d in [DVec3::ZERO, DVec3::new(f64::NAN, 0.0, 1.0), DVec3::INFINITY] {
                let (h, v) = file_angles(kind, d);
                assert!(h.is_nan() && v.is_nan());
            }
        }
        // Huge but finite: fine.
        let (_, g) = file_angles(C, DVec3::new(0.0, 0.0, -1e308));
        assert_eq!(g, 0.0);
    }

    #[test]
    fn frames_of_downlights_in_y_up_and_z_up_models() {
        let f = Frame::downward(DVec3::Y).unwrap();
        assert_eq!((f.aim, f.c0, f.c90), (DVec3::NEG_Y, DVec3::X, DVec3::NEG_Z));
        let f = Frame::downward(DVec3::new(0.0, 0.0, 2.0)).unwrap();
        assert_eq!((f.aim, f.c0, f.c90), (DVec3::NEG_Z, DVec3::X, DVec3::Y));
        // An X-up model: the reference is +Z.
        let f = Frame::downward(DVec3::X).unwrap();
        assert_eq!((f.aim, f.c0), (DVec3::NEG_X, DVec3::Z));
    }

    #[test]
    fn frames_are_orthonormal_and_right_handed() {
        let zeniths = [DVec3::Y, DVec3::Z, DVec3::new(0.3, 1.0, -0.2)];
        let aims = [
            DVec3::new(1.0, -1.0, 0.5),
            DVec3::X,
            DVec3::NEG_X,
            DVec3::new(0.0, 0.2, -1.0),
        ];
        for zenith in zeniths {
            for aim in aims {
                for spin in [0.0, 30.0, -90.0, 400.0] {
                    let f = Frame::new(aim, spin, None, zenith).unwrap();
                    assert!(close(f.aim, aim.normalize()));
                    for (a, b) in [(f.aim, f.c0), (f.aim, f.c90), (f.c0, f.c90)] {
                        assert!(a.dot(b).abs() < 1e-12 && (b.length() - 1.0).abs() < 1e-12);
                    }
                    assert!(close(f.c0.cross(f.c90), -f.aim));
                    let w = DVec3::new(0.3, -2.0, 1.5);
                    assert!(close(f.to_world(f.to_local(w)), w));
                    assert!(close(f.to_world(DVec3::NEG_Z), f.aim));
                    assert!(close(f.to_local(f.c90), DVec3::Y));
                }
            }
        }
    }

    #[test]
    fn c0_reference_falls_back_to_the_zenith_and_takes_a_hint() {
        // Aimed along +X in a Z-up model: C0 is up.
        let f = Frame::new(DVec3::X, 0.0, None, DVec3::Z).unwrap();
        assert_eq!(f.c0, DVec3::Z);
        // Aimed down at 45° toward +X: C0 is +X made perpendicular to the aim (tilted up).
        let f = Frame::new(DVec3::new(1.0, 0.0, -1.0), 0.0, None, DVec3::Z).unwrap();
        assert!(close(f.c0, DVec3::new(1.0, 0.0, 1.0).normalize()));
        // A hint turns C0; a hint along the aim falls back to the zenith.
        let f = Frame::new(DVec3::NEG_Z, 0.0, Some(DVec3::Y), DVec3::Z).unwrap();
        assert_eq!((f.c0, f.c90), (DVec3::Y, DVec3::NEG_X));
        let f = Frame::new(DVec3::X, 0.0, Some(DVec3::NEG_X), DVec3::Z).unwrap();
        assert_eq!(f.c0, DVec3::Z);
        // Hint and zenith both along a vertical aim: the horizontal reference.
        let f = Frame::new(DVec3::NEG_Z, 0.0, Some(DVec3::Z), DVec3::Z).unwrap();
        assert_eq!(f.c0, DVec3::X);
    }

    #[test]
    fn spin_turns_c0_toward_c90() {
        let f0 = Frame::downward(DVec3::Z).unwrap();
        let f = Frame::new(DVec3::NEG_Z, 90.0, None, DVec3::Z).unwrap();
        // Counter-clockwise seen from above: +X goes to +Y.
        assert_eq!((f.c0, f.c90), (f0.c90, -f0.c0));
        let f = Frame::new(DVec3::NEG_Z, 30.0, None, DVec3::Z).unwrap();
        assert!(close(f.c0, local_direction(C, 30.0, 90.0)));
        // A turn of 360° changes nothing.
        assert_eq!(Frame::new(DVec3::NEG_Z, 360.0, None, DVec3::Z), Some(f0));
    }

    #[test]
    fn degenerate_input_gives_no_frame() {
        let z = DVec3::Z;
        assert_eq!(Frame::new(DVec3::ZERO, 0.0, None, z), None);
        assert_eq!(Frame::new(DVec3::NEG_Z, 0.0, None, DVec3::ZERO), None);
        assert_eq!(Frame::new(DVec3::NEG_Z, f64::NAN, None, z), None);
        assert_eq!(Frame::new(DVec3::NEG_Z, 0.0, Some(DVec3::ZERO), z), None);
        assert_eq!(Frame::new(DVec3::splat(f64::INFINITY), 0.0, None, z), None);
        assert_eq!(Frame::downward(DVec3::new(f64::NAN, 1.0, 0.0)), None);
    }
}
