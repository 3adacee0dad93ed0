//! The photometric web once read: which symmetry its angles declare, the intensity in any
//! direction (the symmetry applied, then bilinear interpolation) and the flux it carries.
//!
//! The symmetry rules are LM-63's (ANSI/IES LM-63-19, the horizontal angles' first and last
//! values); EULUMDAT's Isym codes are turned into the same angle ranges by its reader.

use super::{PhotometricType, Photometry, Symmetry, Tilt};

/// Step of the integration grid, degrees: 1° puts the trapezoid rule's own error near 1e-5
/// relative for smooth webs, far below what the measurement carries.
const STEP_DEG: f64 = 1.0;

/// How close an angle must be to LM-63's 0, 90, 180, 270 or 360 to count as it, degrees
/// (files write these exactly; this only forgives printing noise).
const SNAP_DEG: f64 = 1e-6;

/// Which angle list an [`AngleError`] points into.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Axis {
    Vertical,
    Horizontal,
}

/// Angles that break the rules of their photometric type: the list, the index of the angle
/// to blame (for its line) and what is wrong.
#[derive(Debug)]
pub(super) struct AngleError {
    pub axis: Axis,
    pub index: usize,
    pub message: String,
}

fn near(a: f64, b: f64) -> bool {
    (a - b).abs() <= SNAP_DEG
}

/// The symmetry that strictly increasing `vertical` and `horizontal` angles declare under
/// LM-63's rules for `kind`, or the angle that breaks them.
pub(super) fn classify(
    kind: PhotometricType,
    vertical: &[f64],
    horizontal: &[f64],
) -> Result<Symmetry, AngleError> {
    let (vlo, vhi, name) = match kind {
        PhotometricType::C => (0.0, 180.0, "C"),
        PhotometricType::B => (-90.0, 90.0, "B"),
        PhotometricType::A => (-90.0, 90.0, "A"),
    };
    if let Some(i) = vertical
        .iter()
        .position(|&v| v < vlo - SNAP_DEG || v > vhi + SNAP_DEG)
    {
        return Err(AngleError {
            axis: Axis::Vertical,
            index: i,
            message: format!(
                "Type {name} vertical angles must lie in {vlo}..{vhi}, got {}",
                vertical.get(i).copied().unwrap_or(f64::NAN)
            ),
        });
    }
    let (Some(&first), Some(&last)) = (horizontal.first(), horizontal.last()) else {
        return Err(AngleError {
            axis: Axis::Horizontal,
            index: 0,
            message: "no horizontal angles".into(),
        });
    };
    let symmetry = match kind {
        PhotometricType::C if horizontal.len() == 1 => Some(Symmetry::Rotational),
        PhotometricType::C => match (first, last) {
            (f, l) if near(f, 0.0) && near(l, 90.0) => Some(Symmetry::Quadrant),
            (f, l) if near(f, 0.0) && near(l, 180.0) => Some(Symmetry::BilateralC0),
            (f, l) if near(f, 90.0) && near(l, 270.0) => Some(Symmetry::BilateralC90),
            (f, l) if near(f, 0.0) && near(l, 360.0) => Some(Symmetry::Asymmetric),
            _ => None,
        },
        PhotometricType::A | PhotometricType::B => match (first, last) {
            (f, l) if near(f, 0.0) && near(l, 90.0) => Some(Symmetry::Lateral),
            (f, l) if near(f, -90.0) && near(l, 90.0) => Some(Symmetry::Asymmetric),
            _ => None,
        },
    };
    let allowed = match kind {
        PhotometricType::C => "0–90, 0–180, 90–270 or 0–360, or be one angle",
        _ => "−90–90, or 0–90 for a laterally symmetric luminaire",
    };
    symmetry.ok_or_else(|| AngleError {
        axis: Axis::Horizontal,
        index: if near(first, 0.0) || near(first, 90.0) || near(first, -90.0) {
            horizontal.len() - 1
        } else {
            0
        },
        message: format!("Type {name} horizontal angles must run {allowed}; got {first}–{last}"),
    })
}

/// Whether a Type C web of horizontal angles `0..last` with `180 < last < 360` gives every
/// plane but stops short of 360, as LM-63-1995 allows ("greater than 180 and less than 360").
pub(super) fn stops_short_of_360(horizontal: &[f64]) -> bool {
    match (horizontal.first(), horizontal.last()) {
        (Some(&f), Some(&l)) => horizontal.len() > 1 && near(f, 0.0) && l > 180.0 && l < 360.0,
        _ => false,
    }
}

/// Closes a full circle of planes at 360 by repeating the first plane there (C360 is C0), so
/// that interpolation between the last plane and C0 needs no wrap-around. `lines` (the lines of
/// the angles, for errors) gets the last angle's line again.
pub(super) fn close_circle(
    horizontal: &mut Vec<f64>,
    lines: &mut Vec<usize>,
    candela: &mut Vec<Vec<f64>>,
) {
    if let (Some(first), Some(&line)) = (candela.first().cloned(), lines.last()) {
        horizontal.push(360.0);
        lines.push(line);
        candela.push(first);
    }
}

/// `(i, t)` with `x = (1 − t)·a[i] + t·a[i+1]`, `t` in 0..=1, or `None` outside `a`'s range.
/// At a node `t` is exactly 0 (or 1 at the last), so the web's values come back exactly.
fn locate(a: &[f64], x: f64) -> Option<(usize, f64)> {
    let (&first, &last) = (a.first()?, a.last()?);
    if !(x >= first && x <= last) {
        return None;
    }
    if a.len() < 2 {
        return Some((0, 0.0));
    }
    let i = a
        .partition_point(|&v| v <= x)
        .saturating_sub(1)
        .min(a.len() - 2);
    let (x0, x1) = (a.get(i)?, a.get(i + 1)?);
    Some((i, (x - x0) / (x1 - x0)))
}

/// `(1 − t)·a + t·b`, exact at `t` = 0 and 1; `b` is not read at `t` = 0.
fn lerp(t: f64, a: f64, b: impl FnOnce() -> f64) -> f64 {
    if t == 0.0 {
        a
    } else {
        (1.0 - t) * a + t * b()
    }
}

impl Photometry {
    /// Intensity, absolute candela, toward horizontal angle `c_deg` and vertical angle
    /// `gamma_deg` (degrees), in the file's own convention:
    ///
    /// - Type C: `c_deg` is the C-plane (any value, taken modulo 360), `gamma_deg` the angle
    ///   from the nadir (0 down, 90 horizontal, 180 up); a γ outside 0..180 is reflected
    ///   through the pole into the opposite plane. The declared symmetry fills the planes the
    ///   file leaves out: quadrant (0–90) mirrors into all four quadrants, bilateral 0–180
    ///   mirrors about the C0–C180 plane (I(C) = I(360 − C)), bilateral 90–270 about the
    ///   C90–C270 plane (I(C) = I(180 − C)), one plane is rotationally symmetric.
    /// - Types B and A: the polar axis is horizontal (Type B: along the luminaire's width,
    ///   Type A: along its length). `gamma_deg` is the vertical angle V of the plane about
    ///   that axis, −90..90 from the aiming direction, and `c_deg` the horizontal angle H
    ///   within the plane, −90..90 toward either end of the axis. A laterally symmetric file
    ///   (H 0..90) is mirrored: I(−H, V) = I(H, V).
    ///
    /// Between the web's angles the value is bilinear in (horizontal, vertical) angle, and
    /// exactly the file's value at its nodes. Outside the vertical angles the file gives
    /// (e.g. above 90° for a 0–90 downlight) and outside the horizontal range of Types A and B
    /// the intensity is 0. Non-finite angles give 0.
    pub fn intensity(&self, c_deg: f64, gamma_deg: f64) -> f64 {
        if !(c_deg.is_finite() && gamma_deg.is_finite()) {
            return 0.0;
        }
        let (h, v) = match self.kind {
            PhotometricType::C => self.fold_c(c_deg, gamma_deg),
            PhotometricType::A | PhotometricType::B => match self.symmetry {
                Symmetry::Lateral => (c_deg.abs(), gamma_deg),
                _ => (c_deg, gamma_deg),
            },
        };
        self.bilinear(h, v)
    }

    /// A Type C direction as the (horizontal, vertical) pair the stored planes cover.
    fn fold_c(&self, c_deg: f64, gamma_deg: f64) -> (f64, f64) {
        let mut gamma = gamma_deg.rem_euclid(360.0);
        let mut c = c_deg;
        if gamma > 180.0 {
            gamma = 360.0 - gamma;
            c += 180.0;
        }
        let mut c = c.rem_euclid(360.0);
        match self.symmetry {
            Symmetry::Rotational => c = self.horizontal.first().copied().unwrap_or(0.0),
            Symmetry::Quadrant => {
                if c > 180.0 {
                    c = 360.0 - c;
                }
                if c > 90.0 {
                    c = 180.0 - c;
                }
            }
            Symmetry::BilateralC0 if c > 180.0 => c = 360.0 - c,
            Symmetry::BilateralC90 if c < 90.0 => c = 180.0 - c,
            Symmetry::BilateralC90 if c > 270.0 => c = 540.0 - c,
            _ => {}
        }
        if let (Some(&lo), Some(&hi)) = (self.horizontal.first(), self.horizontal.last()) {
            // max/min, not clamp: never panics, even on a web built by hand.
            c = c.max(lo).min(hi);
        }
        (c, gamma)
    }

    /// The web's value at (h, v), bilinear between nodes; 0 outside the angles given.
    fn bilinear(&self, h: f64, v: f64) -> f64 {
        let (Some((i, s)), Some((j, t))) = (locate(&self.horizontal, h), locate(&self.vertical, v))
        else {
            return 0.0;
        };
        let at = |i: usize, j: usize| {
            self.candela
                .get(i)
                .and_then(|row| row.get(j))
                .copied()
                .unwrap_or(0.0)
        };
        let along = |i: usize| lerp(t, at(i, j), || at(i, j + 1));
        lerp(s, along(i), || along(i + 1))
    }

    /// The luminous flux of the web, lumens: the intensity integrated over the directions it
    /// covers, by the trapezoid rule on a 1° grid of the interpolated (symmetry-expanded)
    /// intensity. Type C: ∫∫ I(C, γ) sin γ dγ dC over C 0..360 and the file's γ range. Types A
    /// and B: ∫∫ I(H, V) cos H dH dV over the file's H range (mirrored if laterally symmetric)
    /// and V range, the half-sphere in front of the luminaire at most.
    pub fn total_lumens(&self) -> f64 {
        let (Some(&vlo), Some(&vhi)) = (self.vertical.first(), self.vertical.last()) else {
            return 0.0;
        };
        match self.kind {
            PhotometricType::C => trapezoid(0.0, 360.0, |c| {
                trapezoid(vlo, vhi, |g| self.intensity(c, g) * g.to_radians().sin())
            }),
            PhotometricType::A | PhotometricType::B => {
                let (Some(&hlo), Some(&hhi)) = (self.horizontal.first(), self.horizontal.last())
                else {
                    return 0.0;
                };
                let hlo = if self.symmetry == Symmetry::Lateral {
                    -hhi
                } else {
                    hlo
                };
                trapezoid(vlo, vhi, |v| {
                    trapezoid(hlo, hhi, |h| self.intensity(h, v) * h.to_radians().cos())
                })
            }
        }
    }
}

/// ∫ f over `lo..=hi` (degrees, the integral per radian) by the trapezoid rule, in steps of
/// at most [`STEP_DEG`] that end exactly on `lo` and `hi`.
fn trapezoid(lo: f64, hi: f64, f: impl Fn(f64) -> f64) -> f64 {
    // The angles are finite (the readers see to it), so this is every empty range.
    if hi <= lo {
        return 0.0;
    }
    let n = ((hi - lo) / STEP_DEG).ceil().max(1.0) as usize;
    let step = (hi - lo) / n as f64;
    let inner: f64 = (1..n).map(|k| f(lo + step * k as f64)).sum();
    (inner + 0.5 * (f(lo) + f(hi))) * step.to_radians()
}

impl Tilt {
    /// The multiplying factor at tilt `angle_deg`, degrees: linear between the table's
    /// angles, the end values beyond them.
    pub fn factor(&self, angle_deg: f64) -> f64 {
        let (Some(&lo), Some(&hi)) = (self.angles.first(), self.angles.last()) else {
            return 1.0;
        };
        let x = if angle_deg.is_nan() {
            lo
        } else {
            angle_deg.max(lo).min(hi)
        };
        let get = |i: usize| self.factors.get(i).copied().unwrap_or(1.0);
        match locate(&self.angles, x) {
            Some((i, t)) => lerp(t, get(i), || get(i + 1)),
            None => get(0),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_webs::{ies, steps};
    use super::*;
    use std::f64::consts::PI;

    /// A quadrant web: C 0, 45, 90; γ 0, 45, 90; distinct values everywhere.
    fn quadrant() -> Photometry {
        let planes = vec![
            vec![100.0, 80.0, 10.0],
            vec![120.0, 60.0, 20.0],
            vec![140.0, 40.0, 0.0],
        ];
        ies(1, &[0.0, 45.0, 90.0], &[0.0, 45.0, 90.0], &planes)
    }

    #[test]
    fn nodes_come_back_exactly() {
        let w = quadrant();
        for (i, &c) in w.horizontal.iter().enumerate() {
            for (j, &g) in w.vertical.iter().enumerate() {
                assert_eq!(w.intensity(c, g), w.candela[i][j], "C{c} γ{g}");
            }
        }
    }

    #[test]
    fn between_nodes_the_value_is_bilinear() {
        let w = quadrant();
        // C 22.5 is halfway between C0 and C45, γ 15 a third of the way from 0 to 45.
        let expected =
            0.5 * (100.0 * 2.0 / 3.0 + 80.0 / 3.0) + 0.5 * (120.0 * 2.0 / 3.0 + 60.0 / 3.0);
        // Four roundings of a few ulps each: 1e-12 relative is far above them, far below any error.
        assert!((w.intensity(22.5, 15.0) - expected).abs() < 1e-12 * expected);
        // Outside the 0–90 vertical range: dark.
        assert_eq!(w.intensity(10.0, 90.5), 0.0);
        assert_eq!(w.intensity(10.0, 135.0), 0.0);
    }

    #[test]
    fn quadrant_symmetry_mirrors_into_all_four_quadrants() {
        let w = quadrant();
        let i = w.intensity(30.0, 20.0);
        for c in [150.0, 210.0, 330.0, -30.0, 390.0] {
            // The folds (180 − C, 360 − C) are exact for these whole angles.
            assert_eq!(w.intensity(c, 20.0), i, "C{c}");
        }
        // γ below 0 is the opposite plane: (C30, −20) is (C210, 20).
        assert_eq!(w.intensity(30.0, -20.0), w.intensity(210.0, 20.0));
    }

    #[test]
    fn bilateral_symmetries_mirror_about_their_plane() {
        let v = [0.0, 90.0, 180.0];
        let rows = |n: usize| {
            (0..n)
                .map(|k| vec![10.0 + k as f64, 5.0 * k as f64, 1.0])
                .collect::<Vec<_>>()
        };
        let c0 = ies(1, &v, &[0.0, 60.0, 120.0, 180.0], &rows(4));
        assert_eq!(c0.symmetry, Symmetry::BilateralC0);
        assert_eq!(c0.intensity(300.0, 45.0), c0.intensity(60.0, 45.0));
        assert_eq!(c0.intensity(200.0, 45.0), c0.intensity(160.0, 45.0));
        let c90 = ies(1, &v, &[90.0, 150.0, 210.0, 270.0], &rows(4));
        assert_eq!(c90.symmetry, Symmetry::BilateralC90);
        // I(C) = I(180 − C): C30 ↔ C150, C330 ↔ C210, C0 ↔ C180.
        assert_eq!(c90.intensity(30.0, 45.0), c90.intensity(150.0, 45.0));
        assert_eq!(c90.intensity(330.0, 45.0), c90.intensity(210.0, 45.0));
        assert_eq!(c90.intensity(0.0, 45.0), c90.intensity(180.0, 45.0));
    }

    #[test]
    fn isotropic_web_carries_four_pi_times_its_intensity() {
        for horizontal in [vec![0.0], steps(0.0, 90.0, 30.0), steps(0.0, 360.0, 45.0)] {
            let v = steps(0.0, 180.0, 10.0);
            let planes = vec![vec![1000.0; v.len()]; horizontal.len()];
            let w = ies(1, &v, &horizontal, &planes);
            let lm = w.total_lumens();
            // The brief's bar: 0.5 %. A constant's trapezoid error is only that of sin γ at 1°
            // steps (2.5e-5 relative), so this holds with a wide margin.
            assert!(
                (lm / (4.0 * PI * 1000.0) - 1.0).abs() < 0.005,
                "{lm} for {horizontal:?}"
            );
        }
    }

    #[test]
    fn lambertian_web_carries_pi_times_its_peak() {
        let v = steps(0.0, 90.0, 5.0);
        let plane: Vec<f64> = v.iter().map(|g| 500.0 * g.to_radians().cos()).collect();
        let w = ies(1, &v, &[0.0], &[plane]);
        let lm = w.total_lumens();
        // 0.5 % (the brief's bar): linear interpolation of cos γ between 5° nodes
        // underestimates it by at most h²/8 ≈ 1e-3 of I0 at a node gap, and by less on
        // average; the integral comes out 0.07 % low.
        assert!((lm / (PI * 500.0) - 1.0).abs() < 0.005, "{lm}");
    }

    #[test]
    fn type_b_lateral_web_mirrors_and_integrates_over_the_front_half() {
        let v = steps(-90.0, 90.0, 15.0);
        let h = steps(0.0, 90.0, 15.0);
        let planes: Vec<Vec<f64>> = h.iter().map(|&x| vec![200.0 - x; v.len()]).collect();
        let w = ies(2, &v, &h, &planes);
        assert_eq!(
            (w.kind, w.symmetry),
            (PhotometricType::B, Symmetry::Lateral)
        );
        assert_eq!(w.intensity(-30.0, 10.0), w.intensity(30.0, 10.0));
        assert_eq!(w.intensity(30.0, 15.0), 170.0);
        assert_eq!(w.intensity(95.0, 0.0), 0.0);
        let flat = ies(2, &v, &h, &vec![vec![100.0; v.len()]; h.len()]);
        // Isotropic over the front half-sphere: 2π·I; same trapezoid margin as above.
        let lm = flat.total_lumens();
        assert!((lm / (2.0 * PI * 100.0) - 1.0).abs() < 0.005, "{lm}");
    }

    #[test]
    fn classify_names_the_angle_that_breaks_the_rules() {
        let e = classify(PhotometricType::C, &[0.0, 90.0], &[0.0, 45.0]).unwrap_err();
        assert_eq!((e.axis, e.index), (Axis::Horizontal, 1));
        assert!(e.message.contains("0–45"), "{}", e.message);
        let e = classify(PhotometricType::C, &[0.0, 190.0], &[0.0]).unwrap_err();
        assert_eq!((e.axis, e.index), (Axis::Vertical, 1));
        let e = classify(PhotometricType::B, &[0.0, 90.0], &[-45.0, 90.0]).unwrap_err();
        assert_eq!((e.axis, e.index), (Axis::Horizontal, 0));
        assert!(stops_short_of_360(&[0.0, 120.0, 240.0]));
        assert!(!stops_short_of_360(&[0.0, 90.0, 180.0]));
    }

    #[test]
    fn tilt_factor_is_linear_and_clamped() {
        let t = Tilt {
            geometry: 1,
            angles: vec![0.0, 30.0, 90.0],
            factors: vec![1.0, 0.9, 0.6],
        };
        assert_eq!(t.factor(30.0), 0.9);
        // Halfway between 0.9 and 0.6; a few ulps of rounding at most.
        assert!((t.factor(60.0) - 0.75).abs() < 1e-12);
        assert_eq!((t.factor(-5.0), t.factor(120.0)), (1.0, 0.6));
    }
}
