//! False-colour rendering of irradiance, the picture lighting designers read: how much light
//! arrives on each surface, whatever its colour, on a logarithmic colour scale with a legend.
//!
//! Irradiance (W/m², incident flux density) is what a surface receives: H = (B − E)/ρ per
//! channel (docs/design.md §5), reduced to one number by the luminance weights of the channels with
//! ρ > 0. A surface with ρ = 0 in every channel reflects nothing, so its irradiance is unknown
//! from B: it is drawn grey. The values are interpolated over the welded vertices like the
//! radiosity in [`crate::render`], and mapped through viridis (perceptually uniform, readable
//! in grey and by most colour-blind readers) on a log10 axis spanning at most four decades,
//! ends rounded to 1–2–5 steps. The legend is a panel of [`LEGEND_WIDTH`] pixels appended on
//! the right, so it never hides the scene.

use crate::mesh::Mesh;
use crate::render::glyphs;
use crate::render::{self, Camera, RenderOptions};

/// Width of the legend panel to the right of the picture, pixels.
pub const LEGEND_WIDTH: u32 = 110;
/// Background of the picture where no surface is, and of the legend panel.
pub const BACKGROUND: [u8; 3] = [24, 24, 24];
/// Surfaces whose irradiance is unknown (ρ = 0).
pub const NO_DATA: [u8; 3] = [128, 128, 128];
/// The widest range shown, in decades.
pub const MAX_DECADES: f64 = 4.0;

/// Viridis at nine even stops (sRGB), linearly interpolated between them.
const VIRIDIS: [[u8; 3]; 9] = [
    [68, 1, 84],
    [71, 44, 122],
    [59, 81, 139],
    [44, 113, 142],
    [33, 144, 141],
    [39, 173, 129],
    [92, 200, 99],
    [170, 220, 50],
    [253, 231, 37],
];

/// The colour at `t` in [0, 1] along the scale.
pub fn colour_at(t: f64) -> [u8; 3] {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = t * (VIRIDIS.len() - 1) as f64;
    let k = (x.floor() as usize).min(VIRIDIS.len() - 2);
    let f = x - k as f64;
    let (a, b) = (VIRIDIS[k], VIRIDIS[k + 1]);
    [0, 1, 2].map(|c| (a[c] as f64 + f * (b[c] as f64 - a[c] as f64)).round() as u8)
}

/// A log scale from `lo` to `hi` (W/m², both > 0).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Scale {
    pub lo: f64,
    pub hi: f64,
}

impl Scale {
    /// Position of `v` along the scale, clamped to [0, 1].
    pub fn t(&self, v: f64) -> f64 {
        let t = (v.max(f64::MIN_POSITIVE).log10() - self.lo.log10())
            / (self.hi.log10() - self.lo.log10());
        if t.is_finite() {
            t.clamp(0.0, 1.0)
        } else {
            0.0
        }
    }

    /// From the values seen: the 99th percentile rounded up to a 1–2–5 step, down to the
    /// 1st percentile rounded down, but no more than [`MAX_DECADES`] below the top and at
    /// least one decade (so a nearly uniform picture does not exaggerate small differences).
    pub fn fit(values: &mut Vec<f64>) -> Scale {
        values.retain(|v| v.is_finite() && *v > 0.0);
        if values.is_empty() {
            return Scale { lo: 0.1, hi: 100.0 };
        }
        values.sort_by(f64::total_cmp);
        let q = |p: f64| values[((values.len() - 1) as f64 * p).round() as usize];
        let hi = nice(q(0.99), true);
        let lo = nice(q(0.01), false).max(hi / 10f64.powf(MAX_DECADES));
        Scale {
            lo: lo.min(hi / 10.0),
            hi,
        }
    }

    /// The 1–2–5 values inside the scale, for the legend's ticks (at most about a dozen).
    pub fn ticks(&self) -> Vec<f64> {
        let mut out = Vec::new();
        let mut e = self.lo.log10().floor() as i32 - 1;
        while 10f64.powi(e) <= self.hi * 1.0001 {
            for m in [1.0, 2.0, 5.0] {
                let v = m * 10f64.powi(e);
                if v >= self.lo * 0.9999 && v <= self.hi * 1.0001 {
                    out.push(v);
                }
            }
            e += 1;
        }
        if out.len() > 12 {
            out.retain(|v| {
                let m = v / 10f64.powf(v.log10().floor());
                (m - 1.0).abs() < 1e-6
            });
        }
        out
    }
}

/// `v` rounded up (or down) to the next 1, 2 or 5 × 10^k.
fn nice(v: f64, up: bool) -> f64 {
    let e = v.log10().floor();
    let base = 10f64.powf(e);
    let steps = [1.0, 2.0, 5.0, 10.0];
    let m = v / base;
    let pick = if up {
        steps.iter().copied().find(|s| *s >= m * (1.0 - 1e-9))
    } else {
        steps.iter().rev().copied().find(|s| *s <= m * (1.0 + 1e-9))
    };
    pick.unwrap_or(1.0) * base
}

/// A label for a tick: "0.05", "2", "500", "2k", "10k".
pub fn label(v: f64) -> String {
    if v >= 1000.0 {
        format!("{}k", trim(v / 1000.0))
    } else {
        trim(v)
    }
}

fn trim(v: f64) -> String {
    let s = format!("{v:.3}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    s.to_string()
}

/// The false-colour picture (with its legend panel) and the scale used.
/// `irradiance` holds one value per patch of `mesh` (W/m²; `None` where it is unknown, as on
/// a material that reflects nothing).
pub fn render(
    mesh: &Mesh,
    irradiance: &[Option<f64>],
    cam: &Camera,
    opts: &RenderOptions,
) -> (image::RgbImage, Scale) {
    let h = irradiance;
    // Three channels interpolate together: irradiance × known, coverage (1), known. Their
    // ratios per pixel give the mean irradiance of the known surfaces, the share of the pixel
    // covered (anti-aliased edges) and the share whose irradiance is known.
    let per_patch: Vec<[f64; 3]> = h
        .iter()
        .map(|v| match v {
            Some(x) => [*x, 1.0, 1.0],
            None => [0.0, 1.0, 0.0],
        })
        .collect();
    let vertex = mesh.vertex_values(&per_patch);
    let lin = render::render_linear(mesh, &vertex, cam, opts);
    let value = |p: &[f32; 3]| (p[2] > 0.5 * p[1] && p[1] > 1e-6).then(|| (p[0] / p[2]) as f64);
    let mut seen: Vec<f64> = lin.pixels.iter().filter_map(value).collect();
    let scale = Scale::fit(&mut seen);

    let (w, ht) = (lin.width, lin.height);
    let mut img = image::RgbImage::from_pixel(w + LEGEND_WIDTH, ht, image::Rgb(BACKGROUND));
    for (k, p) in lin.pixels.iter().enumerate() {
        let cov = p[1].clamp(0.0, 1.0) as f64;
        if cov <= 1e-6 {
            continue;
        }
        let c = match value(p) {
            Some(v) => colour_at(scale.t(v)),
            None => NO_DATA,
        };
        let px = [0, 1, 2].map(|i| {
            (BACKGROUND[i] as f64 + cov * (c[i] as f64 - BACKGROUND[i] as f64)).round() as u8
        });
        img.put_pixel(k as u32 % w, k as u32 / w, image::Rgb(px));
    }
    draw_legend(&mut img, w, &scale, "W/m2");
    (img, scale)
}

/// The legend: a vertical colour bar, its 1–2–5 ticks labelled, and the unit on top, in a panel
/// of [`LEGEND_WIDTH`] from column `x0` (the grid's plan draws it too, in lux).
pub(crate) fn draw_legend(img: &mut image::RgbImage, x0: u32, scale: &Scale, unit: &str) {
    let ticks: Vec<(f64, String)> = (scale.ticks().into_iter())
        .map(|v| (scale.t(v), label(v)))
        .collect();
    draw_legend_ticks(img, x0, unit, &ticks);
}

/// A legend of any scale: the colour bar from 0 (bottom) to 1 (top), a tick at each
/// (position along the bar in [0, 1], label) of `ticks`, and the unit on top, in a panel of
/// [`LEGEND_WIDTH`] from column `x0`.
pub(crate) fn draw_legend_ticks(
    img: &mut image::RgbImage,
    x0: u32,
    unit: &str,
    ticks: &[(f64, String)],
) {
    let ht = img.height() as i64;
    let font = if ht >= 240 { 2 } else { 1 };
    let ink = [230, 230, 230];
    let fh = (glyphs::HEIGHT * font) as i64;
    let top = 8 + fh + 8;
    let bottom = ht - 8 - fh / 2;
    glyphs::draw(img, x0 as i64 + 10, 8, font, unit, ink);
    if bottom - top < 8 {
        return;
    }
    let (bx0, bx1) = (x0 as i64 + 10, x0 as i64 + 30);
    for y in top..=bottom {
        let t = (bottom - y) as f64 / (bottom - top) as f64;
        let c = colour_at(t);
        for x in bx0..bx1 {
            if (x as u32) < img.width() {
                img.put_pixel(x as u32, y as u32, image::Rgb(c));
            }
        }
    }
    for (t, text) in ticks {
        let y = bottom - (t * (bottom - top) as f64).round() as i64;
        for x in bx1..bx1 + 4 {
            if (x as u32) < img.width() {
                img.put_pixel(x as u32, y as u32, image::Rgb(ink));
            }
        }
        glyphs::draw(img, bx1 + 7, y - fh / 2, font, text, ink);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scale_fits_nice_ends_and_ticks() {
        let mut v: Vec<f64> = (1..=1000).map(|k| k as f64 * 0.37).collect();
        let s = Scale::fit(&mut v);
        // 99th percentile 366 → 500; 1st percentile 4.07 → 2.
        assert_eq!(s.hi, 500.0);
        assert_eq!(s.lo, 2.0);
        assert_eq!(s.t(2.0), 0.0);
        assert_eq!(s.t(500.0), 1.0);
        let t = s.ticks();
        assert_eq!(t.first(), Some(&2.0));
        assert_eq!(t.last(), Some(&500.0));
        // Four decades at most.
        let mut wide = vec![1e-6, 1.0, 1e6];
        let s = Scale::fit(&mut wide);
        assert!(s.hi / s.lo <= 1e4 * 1.0001, "{s:?}");
        assert_eq!(
            Scale::fit(&mut vec![f64::NAN]),
            Scale { lo: 0.1, hi: 100.0 }
        );
    }

    #[test]
    fn labels_are_short() {
        assert_eq!(label(0.05), "0.05");
        assert_eq!(label(2.0), "2");
        assert_eq!(label(500.0), "500");
        assert_eq!(label(2000.0), "2k");
        assert_eq!(label(10000.0), "10k");
    }

    #[test]
    fn colours_run_from_dark_to_light() {
        assert_eq!(colour_at(0.0), VIRIDIS[0]);
        assert_eq!(colour_at(1.0), VIRIDIS[8]);
        assert_eq!(colour_at(f64::NAN), VIRIDIS[0]);
        let lum = |c: [u8; 3]| c[0] as u32 * 2 + c[1] as u32 * 7 + c[2] as u32;
        assert!(lum(colour_at(0.25)) < lum(colour_at(0.75)));
    }
}
