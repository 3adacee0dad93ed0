//! Image files (docs/design.md §5), the format chosen by the output's extension: PNG (8-bit sRGB,
//! tone-mapped), Radiance `.hdr` (RGBE) and OpenEXR `.exr` (32-bit float), both holding the
//! linear radiosity in W/m² untouched by exposure — what a lighting tool or a compositor
//! wants. All through the `image` crate; non-finite values never reach a file (written as 0).

use crate::render::LinearImage;
use std::io::{self, Write};
use std::path::Path;

/// An image format `radiosity render --out` writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageKind {
    Png,
    Hdr,
    Exr,
}

impl ImageKind {
    /// From the file name's extension (case-insensitive); `None` for anything else.
    pub fn from_path(path: &Path) -> Option<ImageKind> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "png" => Some(ImageKind::Png),
            "hdr" => Some(ImageKind::Hdr),
            "exr" => Some(ImageKind::Exr),
            _ => None,
        }
    }

    /// True for the formats that hold linear radiosity.
    pub fn is_linear(self) -> bool {
        self != ImageKind::Png
    }
}

/// Writes an 8-bit image as PNG.
pub fn write_png(w: &mut dyn Write, img: &image::RgbImage) -> io::Result<()> {
    let mut buf = io::Cursor::new(Vec::new());
    img.write_to(&mut buf, image::ImageFormat::Png)
        .map_err(io::Error::other)?;
    w.write_all(buf.get_ref())
}

/// Linear pixels with non-finite or negative values replaced by 0.
fn clean(img: &LinearImage) -> Vec<[f32; 3]> {
    img.pixels
        .iter()
        .map(|p| p.map(|c| if c.is_finite() && c > 0.0 { c } else { 0.0 }))
        .collect()
}

/// Writes linear radiosity as Radiance RGBE (`.hdr`).
pub fn write_hdr(w: &mut dyn Write, img: &LinearImage) -> io::Result<()> {
    let px: Vec<image::Rgb<f32>> = clean(img).into_iter().map(image::Rgb).collect();
    let mut buf = Vec::new();
    image::codecs::hdr::HdrEncoder::new(&mut buf)
        .encode(&px, img.width as usize, img.height as usize)
        .map_err(io::Error::other)?;
    w.write_all(&buf)
}

/// Writes linear radiosity as OpenEXR, 32-bit float RGB.
pub fn write_exr(w: &mut dyn Write, img: &LinearImage) -> io::Result<()> {
    let flat: Vec<f32> = clean(img).into_iter().flatten().collect();
    let buf = image::Rgb32FImage::from_raw(img.width, img.height, flat)
        .ok_or_else(|| io::Error::other("image size does not match its pixels"))?;
    let mut out = io::Cursor::new(Vec::new());
    image::DynamicImage::ImageRgb32F(buf)
        .write_to(&mut out, image::ImageFormat::OpenExr)
        .map_err(io::Error::other)?;
    w.write_all(out.get_ref())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kinds_by_extension() {
        assert_eq!(
            ImageKind::from_path(Path::new("a.PNG")),
            Some(ImageKind::Png)
        );
        assert_eq!(
            ImageKind::from_path(Path::new("a.hdr")),
            Some(ImageKind::Hdr)
        );
        assert_eq!(
            ImageKind::from_path(Path::new("a.exr")),
            Some(ImageKind::Exr)
        );
        assert_eq!(ImageKind::from_path(Path::new("a.jpg")), None);
        assert_eq!(ImageKind::from_path(Path::new("a")), None);
    }

    #[test]
    fn linear_formats_keep_the_values() {
        let img = LinearImage {
            width: 2,
            height: 1,
            pixels: vec![[1.5, 20.0, 300.0], [f32::NAN, -1.0, 0.25]],
        };
        let mut exr = Vec::new();
        write_exr(&mut exr, &img).unwrap();
        let back = image::load_from_memory(&exr).unwrap().to_rgb32f();
        assert_eq!(back.get_pixel(0, 0).0, [1.5, 20.0, 300.0]);
        assert_eq!(back.get_pixel(1, 0).0, [0.0, 0.0, 0.25]);
        let mut hdr = Vec::new();
        write_hdr(&mut hdr, &img).unwrap();
        let back = image::load_from_memory(&hdr).unwrap().to_rgb32f();
        // RGBE keeps 8 bits of mantissa per channel relative to the largest: ~1 % of it.
        for (a, b) in back.get_pixel(0, 0).0.iter().zip([1.5, 20.0, 300.0]) {
            assert!((a - b).abs() <= 0.01 * 300.0, "{a} vs {b}");
        }
    }
}
