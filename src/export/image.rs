//! Image files (docs/design.md §5), the format chosen by the output's extension: PNG (8-bit sRGB,
//! tone-mapped from the radiosity), Radiance `.hdr` (RGBE) and OpenEXR `.exr` (32-bit float).
//!
//! The two linear formats hold **radiance in W/sr/m²**, untouched by exposure: what Radiance's
//! `rpict` writes and what its tools assume (`pvalue`, `pcomb`, `falsecolor`, `findglare`, and
//! 179 lm/W to turn a pixel into cd/m²). A diffuse surface of radiosity B (W/m², what the solver
//! and [`LinearImage`] hold) has radiance L = B/π in every direction, so the writers divide by
//! π. Each file says so in its header: the Radiance header carries `SOFTWARE=`, a comment line
//! naming the unit, `VIEW=` (the camera, as `rpict` writes it, so `getinfo`, `rvu -vf`,
//! `pinterp` and `findglare` know the view), `EXPOSURE=1` and `FORMAT=`; the EXR header the
//! standard attributes `software`, `comments` (the unit) and `whiteLuminance` = 179 (the
//! luminance in cd/m² of RGB (1, 1, 1)), the field of view and clipping planes, and the view in
//! a text attribute `radianceView`. Non-finite or negative values never reach a file (written
//! as 0).

use crate::render::view_file::view_options;
use crate::render::{Camera, LinearImage, Projection};
use std::io::{self, Write};
use std::path::Path;

/// Luminous efficacy of Radiance's white, lm/W: a pixel of the linear formats times this is
/// luminance in cd/m² (`crate::sky::EFFICACY`).
pub const EFFICACY: f64 = crate::sky::EFFICACY;

/// The unit of the linear formats' pixels, as their headers state it.
pub const PIXEL_UNIT: &str =
    "pixels: radiance in W/sr/m2 (radiosity B/pi on diffuse surfaces); x 179 lm/W = cd/m2";

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

    /// True for the formats that hold linear radiance.
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

/// The pixels as radiance (B/π), non-finite or negative values replaced by 0.
fn radiance(img: &LinearImage) -> Vec<[f32; 3]> {
    let to_l = 1.0 / std::f32::consts::PI;
    img.pixels
        .iter()
        .map(|p| {
            p.map(|c| {
                if c.is_finite() && c > 0.0 {
                    c * to_l
                } else {
                    0.0
                }
            })
        })
        .collect()
}

/// Writes a radiosity image (W/m²) as a Radiance picture of radiance (W/sr/m², B/π), drawn
/// with camera `cam`: the header (see the module's documentation), the resolution line
/// `-Y height +X width` (rows top first) and run-length encoded RGBE scanlines, as `rpict`
/// writes them (Radiance's src/common/color.c: `setcolr`, `fwritecolrs`).
pub fn write_hdr(w: &mut dyn Write, img: &LinearImage, cam: &Camera) -> io::Result<()> {
    let (width, height) = (img.width as usize, img.height as usize);
    let px = radiance(img);
    if px.len() != width * height {
        return Err(io::Error::other("image size does not match its pixels"));
    }
    let mut out = Vec::with_capacity(256 + 4 * px.len());
    write!(
        out,
        "#?RADIANCE\n# {PIXEL_UNIT}\nSOFTWARE= radiosity {}\nVIEW= {}\nEXPOSURE=1\nFORMAT=32-bit_rle_rgbe\n\n-Y {height} +X {width}\n",
        env!("CARGO_PKG_VERSION"),
        view_options(cam)
    )?;
    let mut line = vec![[0u8; 4]; width];
    for row in px.chunks(width.max(1)).take(height) {
        for (c, p) in line.iter_mut().zip(row) {
            *c = rgbe(*p);
        }
        write_scanline(&mut out, &line);
    }
    w.write_all(&out)
}

/// Radiance's `setcolr`: the largest component's mantissa in 128..=255 with a shared exponent
/// (biased by 128); each component truncated, as Radiance's readers add half a step back.
/// Below 1e-32 is black; beyond RGBE's range is clamped to its largest value.
fn rgbe(c: [f32; 3]) -> [u8; 4] {
    let d = c[0].max(c[1]).max(c[2]);
    // The pixels are cleaned (finite, ≥ 0) before they get here.
    if d <= 1e-32 {
        return [0; 4];
    }
    // d = m·2^e with m in [0.5, 1): the exponent from the bits (d is a normal f32 here).
    let e = ((d.to_bits() >> 23) & 0xff) as i32 - 126;
    if e > 127 {
        return [255, 255, 255, 255];
    }
    let scale = 2f64.powi(8 - e);
    let m = |x: f32| (f64::from(x) * scale).clamp(0.0, 255.0) as u8;
    [m(c[0]), m(c[1]), m(c[2]), (e + 128) as u8]
}

/// One scanline: the new run-length encoding (each component apart, runs of 4 or more coded)
/// for widths 8..=0x7fff, flat pixels otherwise (as Radiance's `fwritecolrs`).
fn write_scanline(out: &mut Vec<u8>, line: &[[u8; 4]]) {
    let n = line.len();
    if !(8..=0x7fff).contains(&n) {
        out.extend(line.iter().flatten());
        return;
    }
    out.extend([2, 2, (n >> 8) as u8, (n & 0xff) as u8]);
    let mut comp = vec![0u8; n];
    for k in 0..4 {
        for (c, p) in comp.iter_mut().zip(line) {
            *c = p[k];
        }
        rle(&comp, out);
    }
}

/// Run-length codes one component: a run of 4 to 127 equal bytes as (128 + count, byte), the
/// bytes between runs as (count ≤ 128, bytes…).
fn rle(bytes: &[u8], out: &mut Vec<u8>) {
    let literal = |out: &mut Vec<u8>, lit: &[u8]| {
        for chunk in lit.chunks(128) {
            out.push(chunk.len() as u8);
            out.extend_from_slice(chunk);
        }
    };
    let (mut i, mut start) = (0, 0);
    while i < bytes.len() {
        let run = bytes[i..]
            .iter()
            .take(127)
            .take_while(|&&b| b == bytes[i])
            .count();
        if run >= 4 {
            literal(out, &bytes[start..i]);
            out.extend([128 + run as u8, bytes[i]]);
            i += run;
            start = i;
        } else {
            i += 1;
        }
    }
    literal(out, &bytes[start..]);
}

/// Writes a radiosity image (W/m²) as OpenEXR of radiance (W/sr/m², B/π), 32-bit float RGB,
/// with the unit, the software and the view in its header (see the module's documentation).
pub fn write_exr(w: &mut dyn Write, img: &LinearImage, cam: &Camera) -> io::Result<()> {
    use exr::prelude::*;
    let (width, height) = (img.width as usize, img.height as usize);
    let px = radiance(img);
    if px.len() != width * height || px.is_empty() {
        return Err(io::Error::other(
            "an EXR image needs pixels matching its size",
        ));
    }
    let text = |s: &str| Text::new_or_none(s).unwrap_or_default();
    let mut attributes = LayerAttributes {
        software_name: Some(text(&format!("radiosity {}", env!("CARGO_PKG_VERSION")))),
        comments: Some(text(PIXEL_UNIT)),
        white_luminance: Some(EFFICACY as f32),
        near_clip_plane: Some(cam.near_distance()),
        far_clip_plane: cam.far_distance(),
        ..LayerAttributes::default()
    };
    if let Projection::Perspective {
        fov_x_deg,
        fov_y_deg,
    } = cam.projection.as_drawn()
    {
        attributes.horizontal_field_of_view = Some(fov_x_deg);
        attributes.vertical_field_of_view = Some(fov_y_deg);
    }
    attributes.other.insert(
        text("radianceView"),
        AttributeValue::Text(text(&view_options(cam))),
    );
    let layer = Layer::new(
        (width, height),
        attributes,
        Encoding::FAST_LOSSLESS,
        SpecificChannels::rgb(|p: Vec2<usize>| {
            let [r, g, b] = px[p.y() * width + p.x()];
            (r, g, b)
        }),
    );
    let mut out = io::Cursor::new(Vec::new());
    Image::from_layer(layer)
        .write()
        .to_buffered(&mut out)
        .map_err(io::Error::other)?;
    w.write_all(out.get_ref())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use std::f32::consts::PI;

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

    fn cam() -> Camera {
        Camera::perspective(
            Vec3::new(1.0, 2.0, 3.0),
            Vec3::new(1.0, 2.0, 2.0),
            Vec3::Y,
            40.0,
            2.0,
        )
    }

    fn img(width: u32, height: u32) -> LinearImage {
        let pixels = (0..width * height)
            .map(|i| {
                let x = i as f32;
                [
                    x * 0.37 + 1.0,
                    (x * 1.3).sin().abs() * 100.0,
                    1e-3 * (i % 5) as f32,
                ]
            })
            .collect();
        LinearImage {
            width,
            height,
            pixels,
        }
    }

    #[test]
    fn exr_holds_radiance_and_says_so() {
        let mut img = img(3, 2);
        img.pixels[1] = [f32::NAN, -1.0, 0.25];
        let mut exr = Vec::new();
        write_exr(&mut exr, &img, &cam()).unwrap();
        let back = image::load_from_memory(&exr).unwrap().to_rgb32f();
        assert_eq!(back.dimensions(), (3, 2));
        for (k, p) in img.pixels.iter().enumerate() {
            let want = p.map(|c| {
                if c.is_finite() && c > 0.0 {
                    c * (1.0 / PI)
                } else {
                    0.0
                }
            });
            assert_eq!(
                back.get_pixel(k as u32 % 3, k as u32 / 3).0,
                want,
                "pixel {k}"
            );
        }
        let meta = exr::meta::MetaData::read_from_buffered(io::Cursor::new(&exr), false).unwrap();
        let a = &meta.headers[0].own_attributes;
        assert_eq!(a.white_luminance, Some(179.0));
        assert!(a.comments.as_ref().unwrap().to_string().contains("W/sr/m2"));
        assert!(a
            .software_name
            .as_ref()
            .unwrap()
            .to_string()
            .starts_with("radiosity "));
        let view = a
            .other
            .get(&exr::meta::attribute::Text::from("radianceView"))
            .unwrap();
        assert!(
            format!("{view:?}").contains("-vtv -vp 1 2 3 -vd 0 0 -1 -vu 0 1 0"),
            "{view:?}"
        );
    }

    /// The header's text lines and the byte offset of the pixels.
    fn header(bytes: &[u8]) -> (Vec<String>, usize) {
        let end = bytes.windows(2).position(|w| w == b"\n\n").unwrap() + 2;
        let res = end + bytes[end..].iter().position(|&b| b == b'\n').unwrap() + 1;
        let text = String::from_utf8(bytes[..res].to_vec()).unwrap();
        (text.lines().map(str::to_string).collect(), res)
    }

    #[test]
    fn hdr_round_trips_radiance_with_its_header() {
        // Widths on both sides of the run-length threshold (8) and one with long runs.
        for (w, h) in [(3, 2), (40, 3), (300, 2)] {
            let mut im = img(w, h);
            im.pixels[0] = [f32::NAN, -1.0, 0.0];
            for p in im.pixels.iter_mut().skip(10).take(200) {
                *p = [5.0, 5.0, 5.0];
            }
            let mut hdr = Vec::new();
            write_hdr(&mut hdr, &im, &cam()).unwrap();
            let (lines, _) = header(&hdr);
            assert_eq!(lines[0], "#?RADIANCE");
            assert!(lines.contains(&format!("# {PIXEL_UNIT}")));
            assert!(lines.contains(&format!(
                "SOFTWARE= radiosity {}",
                env!("CARGO_PKG_VERSION")
            )));
            assert!(lines.contains(&"EXPOSURE=1".to_string()));
            assert!(lines.contains(&"FORMAT=32-bit_rle_rgbe".to_string()));
            assert!(lines.contains(&format!("-Y {h} +X {w}")));
            let view = lines.iter().find(|l| l.starts_with("VIEW= ")).unwrap();
            // The view reads back (as Radiance would) to the camera drawn with.
            let back = crate::render::view_file::RadianceView::parse(view, true).unwrap();
            assert_eq!(back.camera().eye, cam().eye);
            assert!((back.aspect() - 2.0).abs() < 1e-5);

            let dec = image::load_from_memory(&hdr).unwrap().to_rgb32f();
            assert_eq!(dec.dimensions(), (w, h));
            for (k, p) in im.pixels.iter().enumerate() {
                let want = p.map(|c| {
                    if c.is_finite() && c > 0.0 {
                        c * (1.0 / PI)
                    } else {
                        0.0
                    }
                });
                let got = dec.get_pixel(k as u32 % w, k as u32 / w).0;
                let max = want[0].max(want[1]).max(want[2]);
                for c in 0..3 {
                    // RGBE: 8 bits of mantissa relative to the largest component, truncated
                    // (`image` does not add Radiance's half step back): within 1/128 of it.
                    assert!(
                        got[c] <= want[c] + 1e-6 && want[c] - got[c] <= max / 128.0,
                        "{w}x{h} pixel {k}: {got:?} vs {want:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn rgbe_matches_radiance() {
        // Radiance's setcolr(1, 0.5, 0.25): frexp(1) = 0.5·2^1, so 128, 64, 32, 129.
        assert_eq!(rgbe([1.0, 0.5, 0.25]), [128, 64, 32, 129]);
        assert_eq!(rgbe([0.0; 3]), [0; 4]);
        assert_eq!(rgbe([1e-40; 3]), [0; 4]);
        assert_eq!(rgbe([3.0e38, 0.0, 0.0]), [255; 4]);
        // 179 W/sr/m²·π… any value: mantissa of the largest in 128..=255.
        let c = rgbe([57.0, 3.0, 0.1]);
        assert!(c[0] >= 128);
        let v = (c[0] as f64 + 0.5) * 2f64.powi(c[3] as i32 - 136);
        assert!((v - 57.0).abs() < 57.0 / 256.0, "{v}");
    }

    #[test]
    fn run_length_coding_decodes_back() {
        let data: Vec<u8> = [
            vec![7u8; 300],
            (0..=255).collect(),
            vec![1, 1, 1, 2, 2, 2, 2, 3],
        ]
        .concat();
        let mut out = Vec::new();
        rle(&data, &mut out);
        let mut back = Vec::new();
        let mut i = 0;
        while i < out.len() {
            let c = out[i] as usize;
            if c > 128 {
                back.extend(std::iter::repeat_n(out[i + 1], c - 128));
                i += 2;
            } else {
                assert!(c > 0);
                back.extend_from_slice(&out[i + 1..i + 1 + c]);
                i += 1 + c;
            }
        }
        assert_eq!(back, data);
        assert!(out.len() < data.len());
    }
}
