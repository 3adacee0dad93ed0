//! `map_Kd` textures as exporters write them: the file name after the map options, found
//! relative to the MTL file's folder, decoded through `image`, reduced to its mean colour in
//! linear light (the reflectance a patch sees averaged over its area, as a radiosity patch
//! has one colour).

use super::text::io_reason;
use rayon::prelude::*;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// The file name of a `map_…` statement's value: the options before it skipped
/// (`-s 1 1 1`, `-bm 1`, `-clamp on`, `-mm 0 1`, …; an unknown `-option` with the numbers
/// after it). A name with spaces is kept whole.
pub(super) fn map_file(value: &str) -> &str {
    let mut rest = value.trim();
    // The last option if it took no argument: the name after all when nothing follows it
    // (`-tex.png`).
    let mut bare_option = "";
    loop {
        let Some((word, after)) = next_word(rest) else {
            return bare_option;
        };
        if !word.starts_with('-') || word.parse::<f64>().is_ok() {
            return rest;
        }
        // (words that follow, at most this many numbers that follow).
        let (words, numbers) = match word {
            "-blendu" | "-blendv" | "-cc" | "-clamp" | "-imfchan" | "-type" | "-colorspace" => {
                (1, 0)
            }
            "-bm" | "-boost" | "-texres" => (0, 1),
            "-mm" => (0, 2),
            _ => (0, 3), // -o, -s, -t and unknown options
        };
        rest = after;
        bare_option = word;
        for _ in 0..words {
            if let Some((_, after)) = next_word(rest) {
                (rest, bare_option) = (after, "");
            }
        }
        for _ in 0..numbers {
            match next_word(rest) {
                Some((w, after)) if w.parse::<f64>().is_ok() => (rest, bare_option) = (after, ""),
                _ => break,
            }
        }
    }
}

/// The first word of `s` and what follows it (trimmed), or `None` if `s` is blank.
fn next_word(s: &str) -> Option<(&str, &str)> {
    let s = s.trim_start();
    if s.is_empty() {
        return None;
    }
    let end = s.find(char::is_whitespace).unwrap_or(s.len());
    Some((&s[..end], s[end..].trim_start()))
}

/// Where the texture `file` (as an MTL in `folder` names it) is: as written if that exists,
/// else with Windows separators (`textures\brick.jpg`) read as `/`, else the one file of the
/// same name in another letter case (exporters on Windows write names that differ in case from
/// the files). The path as written when none exists.
pub(super) fn resolve(folder: &Path, file: &str) -> PathBuf {
    let written = folder.join(file);
    if written.is_file() {
        return written;
    }
    let slashed = folder.join(file.replace('\\', "/"));
    if slashed.is_file() {
        return slashed;
    }
    let (Some(parent), Some(name)) = (slashed.parent(), slashed.file_name()) else {
        return written;
    };
    let wanted = name.to_string_lossy().to_lowercase();
    let found = std::fs::read_dir(parent).ok().and_then(|entries| {
        entries.filter_map(Result::ok).map(|e| e.path()).find(|p| {
            p.is_file()
                && p.file_name()
                    .is_some_and(|n| n.to_string_lossy().to_lowercase() == wanted)
        })
    });
    found.unwrap_or(written)
}

/// The mean colour of each texture, decoded in parallel, each file once: `Ok(rgb)` in linear
/// light, or `Err(why it did not load)`.
pub(super) fn mean_colours(paths: &[PathBuf]) -> HashMap<PathBuf, Result<[f64; 3], String>> {
    let mut unique: Vec<&PathBuf> = paths.iter().collect();
    unique.sort();
    unique.dedup();
    unique
        .into_par_iter()
        .map(|p| (p.clone(), mean_colour(p)))
        .collect()
}

/// The mean colour of one texture file in linear light; alpha is ignored.
pub(super) fn mean_colour(path: &Path) -> Result<[f64; 3], String> {
    let reader = image::ImageReader::open(path).map_err(|e| io_reason(&e))?;
    let reader = reader.with_guessed_format().map_err(|e| io_reason(&e))?;
    mean_of(reader)
}

/// The mean colour of an image file's bytes (a glTF's embedded image) in linear light.
pub(in crate::scene) fn mean_colour_of_bytes(bytes: &[u8]) -> Result<[f64; 3], String> {
    let reader = image::ImageReader::new(std::io::Cursor::new(bytes));
    mean_of(reader.with_guessed_format().map_err(|e| io_reason(&e))?)
}

/// The mean colour of what `reader` decodes, in linear light.
fn mean_of<R: std::io::BufRead + std::io::Seek>(
    reader: image::ImageReader<R>,
) -> Result<[f64; 3], String> {
    let image = reader
        .decode()
        .map_err(|e| format!("cannot decode it ({e})"))?;
    if image.width() == 0 || image.height() == 0 {
        return Err("it has no pixels".into());
    }
    let mean = mean_linear(&image);
    if mean.iter().any(|c| !c.is_finite() || *c < 0.0) {
        return Err(format!(
            "its mean colour {} {} {} is not a reflectance",
            mean[0], mean[1], mean[2]
        ));
    }
    Ok(mean)
}

/// sRGB-encoded value in [0, 1] to linear light (IEC 61966-2-1).
pub(super) fn srgb_to_linear(v: f64) -> f64 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// The mean texel in linear light: integer texels are sRGB-encoded (8-bit and 16-bit PNG,
/// JPEG, TGA, BMP), floating-point ones (HDR, EXR) linear already.
fn mean_linear(image: &image::DynamicImage) -> [f64; 3] {
    use image::DynamicImage as D;
    let lut: [f64; 256] = std::array::from_fn(|i| srgb_to_linear(i as f64 / 255.0));
    let b8 = |c: u8| lut[c as usize];
    let b16 = |c: u16| srgb_to_linear(f64::from(c) / 65535.0);
    match image {
        D::ImageLuma8(b) => mean(b.pixels().map(|p| [b8(p[0]); 3])),
        D::ImageLumaA8(b) => mean(b.pixels().map(|p| [b8(p[0]); 3])),
        D::ImageRgb8(b) => mean(b.pixels().map(|p| [b8(p[0]), b8(p[1]), b8(p[2])])),
        D::ImageRgba8(b) => mean(b.pixels().map(|p| [b8(p[0]), b8(p[1]), b8(p[2])])),
        D::ImageLuma16(b) => mean(b.pixels().map(|p| [b16(p[0]); 3])),
        D::ImageLumaA16(b) => mean(b.pixels().map(|p| [b16(p[0]); 3])),
        D::ImageRgb16(b) => mean(b.pixels().map(|p| [b16(p[0]), b16(p[1]), b16(p[2])])),
        D::ImageRgba16(b) => mean(b.pixels().map(|p| [b16(p[0]), b16(p[1]), b16(p[2])])),
        D::ImageRgb32F(b) => mean(b.pixels().map(|p| p.0.map(f64::from))),
        D::ImageRgba32F(b) => mean(b.pixels().map(|p| [p[0], p[1], p[2]].map(f64::from))),
        // A layout added to `image` later: as 16-bit sRGB.
        other => mean(
            other
                .to_rgb16()
                .pixels()
                .map(|p| [b16(p[0]), b16(p[1]), b16(p[2])]),
        ),
    }
}

fn mean(texels: impl Iterator<Item = [f64; 3]>) -> [f64; 3] {
    let (mut sum, mut n) = ([0.0; 3], 0usize);
    for t in texels {
        for c in 0..3 {
            sum[c] += t[c];
        }
        n += 1;
    }
    sum.map(|s| s / n.max(1) as f64)
}
