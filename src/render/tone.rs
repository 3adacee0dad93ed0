//! Tone mapping: linear W/m² to 8-bit sRGB, by a given exposure or one picked from a high
//! percentile of the image's luminance.

use super::LinearImage;

/// Tone mapping: linear radiosity × exposure, then the sRGB transfer curve, clamped to 8 bits.
///
/// `Some(e)` with `e` finite and ≥ 0 is used as given; otherwise the exposure is automatic: the
/// 97th percentile of the luminance of the non-background (non-zero) pixels is mapped to linear
/// 0.9, so a few very bright pixels (the lights) do not darken everything. An image without
/// such pixels gets exposure 1. Returns the image and the exposure used.
pub fn tone_map(img: &LinearImage, exposure: Option<f32>) -> (image::RgbImage, f32) {
    let exposure = match exposure {
        Some(e) if e.is_finite() && e >= 0.0 => e,
        _ => auto_exposure(&img.pixels),
    };
    let (w, h) = (img.width as usize, img.height as usize);
    let mut out = image::RgbImage::new(img.width, img.height);
    if img.pixels.len() == w.saturating_mul(h) {
        for (px, lin) in out.pixels_mut().zip(&img.pixels) {
            px.0 = lin.map(|c| {
                let v = c * exposure;
                let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
                (srgb_encode(v) * 255.0).round() as u8
            });
        }
    }
    (out, exposure)
}

/// The exposure that maps the 97th luminance percentile of the lit pixels to 0.9 (1 if none).
/// Also used for the 8-bit colours of exported meshes.
pub fn auto_exposure(pixels: &[[f32; 3]]) -> f32 {
    let mut lum: Vec<f32> = pixels
        .iter()
        .map(|p| 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2])
        .filter(|l| l.is_finite() && *l > 0.0)
        .collect();
    if lum.is_empty() {
        return 1.0;
    }
    let k = ((lum.len() - 1) as f32 * 0.97).round() as usize;
    let (_, p, _) = lum.select_nth_unstable_by(k, f32::total_cmp);
    let e = 0.9 / *p;
    if e.is_finite() && e > 0.0 {
        e
    } else {
        1.0
    }
}

/// The sRGB transfer curve (IEC 61966-2-1) for v in [0, 1].
pub fn srgb_encode(v: f32) -> f32 {
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}
