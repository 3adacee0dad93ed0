//! Display of a radiosity solution: camera, CPU rasterizer and tone mapping; [`false_colour`]
//! (irradiance on a log scale with a legend) and [`glyphs`] (the legend's digits) beside it.
//!
//! The paper shows its solutions the classic way: radiosity is averaged to the patch vertices
//! and Gouraud-interpolated across each patch. [`render_linear`] does exactly that in software:
//! perspective projection, near-plane (and guard-band) clipping in view space, back-face culling
//! by each patch's front normal, a Z-buffer on 1/z, perspective-correct interpolation of the
//! vertex colours, and s×s supersampling box-filtered down to the output size. [`tone_map`] turns
//! the linear W/m² image into 8-bit sRGB, by a given exposure or one picked from a high
//! percentile of the image's luminance.
//!
//! Back faces are culled because architectural models are closed rooms: a camera outside the
//! building then sees through the near walls into the rooms, as a cut-away.
//!
//! Parallelism: the screen is cut into bands of output rows; triangles are binned by band and
//! each band is rasterized and filtered by one rayon task into its own slice of the image, so no
//! two tasks write the same memory and the result does not depend on scheduling.
//! Rasterization is watertight: each shared edge is evaluated with its endpoints in a canonical
//! order and clipped from its inside endpoint, so neighbouring triangles leave no cracks.

pub mod false_colour;
pub mod glyphs;
pub mod view;

pub use view::{CameraSpec, ViewSettings};

use crate::mesh::Mesh;
use glam::Vec3;
use rayon::prelude::*;

/// A pinhole camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub eye: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    /// Vertical field of view in degrees (clamped to 0.01..179 when used).
    pub fov_y_deg: f32,
}

impl Camera {
    /// Fitted to the scene: looks along -z from the +z side (y up), fov 40°, distance so the whole
    /// bounding box fits in view with a small margin, aimed at the box centre.
    ///
    /// A non-finite or inverted box (such as the bounds of an empty mesh) is replaced by the unit
    /// cube around the origin; a non-positive or non-finite `aspect` (width / height) by 1.
    pub fn fit(lo: Vec3, hi: Vec3, aspect: f32) -> Camera {
        let (lo, hi) = if lo.is_finite() && hi.is_finite() && lo.cmple(hi).all() {
            (lo, hi)
        } else {
            (Vec3::splat(-0.5), Vec3::splat(0.5))
        };
        let aspect = if aspect.is_finite() && aspect > 0.0 {
            aspect
        } else {
            1.0
        };
        let fov_y_deg = 40.0_f32;
        let tan_y = (0.5 * fov_y_deg).to_radians().tan();
        let tan_x = tan_y * aspect;
        // Corners end up at most 1/MARGIN of the way from the image centre to its edge.
        const MARGIN: f32 = 1.1;
        let centre = 0.5 * (lo + hi);
        let h = 0.5 * (hi - lo);
        // With the eye at centre + d·z, a corner at offset (x, y, z) lies at depth d − z and is
        // in view when |x| ≤ (d − z)·tan_x / MARGIN (same for y): solve each for d.
        let mut d: f32 = 0.0;
        for z in [-h.z, h.z] {
            d = d
                .max(z + MARGIN * h.x / tan_x)
                .max(z + MARGIN * h.y / tan_y);
        }
        // Keep the box's near face well in front of the eye even when the box is flat.
        let extent = h.length();
        let gap = if extent > 0.0 { 0.1 * extent } else { 1.0 };
        d = d.max(h.z + gap);
        Camera {
            eye: centre + Vec3::new(0.0, 0.0, d),
            target: centre,
            up: Vec3::Y,
            fov_y_deg,
        }
    }
}

/// Output size and quality of [`render_linear`].
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct RenderOptions {
    pub width: u32,
    pub height: u32,
    /// Samples per pixel along each axis (0 is taken as 1, values above 16 as 16).
    pub supersample: u32,
    /// Exposure for tone mapping; `None` = automatic (see [`tone_map`]).
    pub exposure: Option<f32>,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            width: view::DEFAULT_WIDTH,
            height: view::DEFAULT_HEIGHT,
            supersample: view::DEFAULT_SUPERSAMPLE,
            exposure: None,
        }
    }
}

/// Linear radiosity image (W/m² per channel), row-major, width*height, background black.
#[derive(Clone, Debug, PartialEq)]
pub struct LinearImage {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[f32; 3]>,
}

/// Output rows per rayon task (times the supersampling factor in sample rows).
const BAND_ROWS: usize = 8;
/// Side clip planes sit this factor outside the view, so clipping never shows at the border.
const GUARD: f32 = 1.01;

/// The camera's view transform and projection onto a sample grid.
struct View {
    eye: Vec3,
    right: Vec3,
    up: Vec3,
    fwd: Vec3,
    tan_x: f32,
    tan_y: f32,
    width: f32,
    height: f32,
}

impl View {
    /// Builds an orthonormal basis; a degenerate camera (eye == target, up parallel to the view
    /// direction, non-finite values) falls back to looking along -z and to another up vector.
    fn new(camera: &Camera, width: usize, height: usize) -> View {
        let eye = camera.eye;
        let mut fwd = (camera.target - eye).normalize_or_zero();
        if fwd == Vec3::ZERO {
            fwd = Vec3::NEG_Z;
        }
        let mut right = Vec3::X;
        for up in [camera.up, Vec3::Y, Vec3::Z, Vec3::X] {
            let r = fwd.cross(up.normalize_or_zero());
            // sin of the angle between fwd and up above 1e-3: the basis is well conditioned.
            if r.is_finite() && r.length_squared() > 1e-6 {
                right = r.normalize();
                break;
            }
        }
        let fov = if camera.fov_y_deg.is_finite() {
            camera.fov_y_deg.clamp(0.01, 179.0)
        } else {
            40.0
        };
        let tan_y = (0.5 * fov).to_radians().tan();
        let aspect = if height > 0 {
            width as f32 / height as f32
        } else {
            1.0
        };
        View {
            eye,
            right,
            up: right.cross(fwd),
            fwd,
            tan_x: tan_y * aspect,
            tan_y,
            width: width as f32,
            height: height as f32,
        }
    }

    /// World → view space: x right, y up, z = depth along the view direction.
    fn to_view(&self, p: Vec3) -> Vec3 {
        let d = p - self.eye;
        Vec3::new(d.dot(self.right), d.dot(self.up), d.dot(self.fwd))
    }

    /// View space (z > 0) → sample-grid coordinates, y down, pixel centres at +0.5.
    fn to_screen(&self, v: Vec3) -> [f32; 2] {
        [
            (0.5 + 0.5 * v.x / (v.z * self.tan_x)) * self.width,
            (0.5 - 0.5 * v.y / (v.z * self.tan_y)) * self.height,
        ]
    }

    /// The five clip planes (n, d), inside where n·p + d ≥ 0: near, then the guard band.
    fn planes(&self, near: f32) -> [(Vec3, f32); 5] {
        let (gx, gy) = (GUARD * self.tan_x, GUARD * self.tan_y);
        [
            (Vec3::Z, -near),
            (Vec3::new(1.0, 0.0, gx), 0.0),
            (Vec3::new(-1.0, 0.0, gx), 0.0),
            (Vec3::new(0.0, 1.0, gy), 0.0),
            (Vec3::new(0.0, -1.0, gy), 0.0),
        ]
    }
}

/// A polygon vertex during clipping: view-space position and linear colour.
#[derive(Clone, Copy)]
struct ClipVert {
    p: Vec3,
    c: Vec3,
}

/// A projected triangle: sample-grid positions, 1/z and colour/z per vertex.
#[derive(Clone, Copy)]
struct ScreenTri {
    x: [f32; 3],
    y: [f32; 3],
    w: [f32; 3],
    cw: [Vec3; 3],
}

/// Renders `mesh` with per-vertex radiosity `vertex_rgb` (one entry per `mesh.vertices` element,
/// linear W/m²) into a linear image. Non-finite colours and missing entries count as 0; patches
/// with out-of-range indices or non-finite vertices are skipped. A zero width or height gives an
/// image without pixels.
pub fn render_linear(
    mesh: &Mesh,
    vertex_rgb: &[[f32; 3]],
    camera: &Camera,
    opts: &RenderOptions,
) -> LinearImage {
    let (width, height) = (opts.width as usize, opts.height as usize);
    let mut pixels = vec![[0.0f32; 3]; width.saturating_mul(height)];
    if pixels.is_empty() {
        return LinearImage {
            width: opts.width,
            height: opts.height,
            pixels,
        };
    }
    let s = opts.supersample.clamp(1, 16) as usize;
    let (ws, hs) = (width * s, height * s);
    let view = View::new(camera, ws, hs);

    // Near plane relative to the scene size; depth is tested on 1/z, which keeps its relative
    // precision at any distance, so a small near plane costs nothing.
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for v in mesh.vertices.iter().filter(|v| v.is_finite()) {
        lo = lo.min(*v);
        hi = hi.max(*v);
    }
    let diag = (hi - lo).length();
    let near = if diag.is_finite() && diag > 0.0 {
        (1e-5 * diag).max(1e-7)
    } else {
        1e-4
    };
    let planes = view.planes(near);

    // Cull, clip and project every patch (in parallel, order kept so results are deterministic).
    let tris: Vec<ScreenTri> = mesh
        .patches
        .par_chunks(2048)
        .map(|chunk| {
            let (mut out, mut poly, mut tmp) = (Vec::new(), Vec::new(), Vec::new());
            for patch in chunk {
                let first = patch.first as usize;
                let Some(idx) = first
                    .checked_add(patch.count as usize)
                    .and_then(|end| mesh.patch_vertices.get(first..end))
                else {
                    continue;
                };
                if patch_polygon(mesh, vertex_rgb, idx, patch.normal, &view, &mut poly) {
                    clip_polygon(&mut poly, &mut tmp, &planes);
                    project_fan(&poly, &view, &mut out);
                }
            }
            out
        })
        .flatten_iter()
        .collect();

    // Bin triangles by band of sample rows.
    let band_samples = BAND_ROWS * s;
    let n_bands = height.div_ceil(BAND_ROWS);
    let mut bins: Vec<Vec<u32>> = vec![Vec::new(); n_bands];
    for (i, t) in tris.iter().enumerate() {
        let (r0, r1) = sample_range(t.y, hs);
        if r0 <= r1 {
            for bin in &mut bins[r0 / band_samples..=(r1 / band_samples).min(n_bands - 1)] {
                bin.push(i as u32);
            }
        }
    }

    // Rasterize each band into its own buffers, then box-filter it into its output rows.
    let inv_ss = 1.0 / (s * s) as f32;
    pixels
        .par_chunks_mut(BAND_ROWS * width)
        .zip(bins.par_iter())
        .enumerate()
        .for_each(|(b, (out, bin))| {
            let rows = out.len() / width * s;
            let y0 = b * band_samples;
            let mut colour = vec![Vec3::ZERO; rows * ws];
            let mut depth = vec![0.0f32; rows * ws];
            for &i in bin {
                rasterize(&tris[i as usize], y0, rows, ws, &mut colour, &mut depth);
            }
            for (k, px) in out.iter_mut().enumerate() {
                let (r, c) = (k / width, k % width);
                let mut sum = Vec3::ZERO;
                for sy in r * s..(r + 1) * s {
                    sum += colour[sy * ws + c * s..sy * ws + (c + 1) * s]
                        .iter()
                        .sum::<Vec3>();
                }
                *px = (sum * inv_ss).to_array();
            }
        });
    LinearImage {
        width: opts.width,
        height: opts.height,
        pixels,
    }
}

/// Fills `poly` with the view-space vertices of a front-facing patch; false if the patch is
/// culled (back-facing or edge-on) or invalid.
fn patch_polygon(
    mesh: &Mesh,
    vertex_rgb: &[[f32; 3]],
    idx: &[u32],
    normal: Vec3,
    view: &View,
    poly: &mut Vec<ClipVert>,
) -> bool {
    poly.clear();
    for &i in idx {
        let Some(&p) = mesh.vertices.get(i as usize) else {
            return false;
        };
        if !p.is_finite() {
            return false;
        }
        let c = vertex_rgb.get(i as usize).map_or(Vec3::ZERO, |c| {
            Vec3::from_array(c.map(|x| if x.is_finite() { x } else { 0.0 }))
        });
        poly.push(ClipVert { p, c });
    }
    if poly.len() < 3 {
        return false;
    }
    // The front normal as given, or from the winding (Newell) if that one is unusable.
    let mut n = normal;
    if !(n.is_finite() && n.length_squared() > 0.0) {
        n = Vec3::ZERO;
        for (k, a) in poly.iter().enumerate() {
            n += a.p.cross(poly[(k + 1) % poly.len()].p);
        }
    }
    if n.dot(view.eye - poly[0].p) <= 0.0 {
        return false;
    }
    for v in poly.iter_mut() {
        v.p = view.to_view(v.p);
    }
    true
}

/// Sutherland–Hodgman clipping of `poly` against each plane in turn (`tmp` is scratch).
/// New vertices are interpolated from the inside endpoint, so an edge shared by two patches is
/// cut at bit-identical points in both.
fn clip_polygon(poly: &mut Vec<ClipVert>, tmp: &mut Vec<ClipVert>, planes: &[(Vec3, f32)]) {
    for &(n, d) in planes {
        if poly.len() < 3 {
            poly.clear();
            return;
        }
        tmp.clear();
        for k in 0..poly.len() {
            let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
            let (da, db) = (n.dot(a.p) + d, n.dot(b.p) + d);
            if da >= 0.0 {
                tmp.push(a);
            }
            if (da >= 0.0) != (db >= 0.0) {
                let (inside, outside, di, dout) = if da >= 0.0 {
                    (a, b, da, db)
                } else {
                    (b, a, db, da)
                };
                let t = di / (di - dout);
                tmp.push(ClipVert {
                    p: inside.p.lerp(outside.p, t),
                    c: inside.c.lerp(outside.c, t),
                });
            }
        }
        std::mem::swap(poly, tmp);
    }
}

/// Projects a clipped convex polygon and fan-triangulates it from its first vertex.
fn project_fan(poly: &[ClipVert], view: &View, out: &mut Vec<ScreenTri>) {
    if poly.len() < 3 {
        return;
    }
    let proj = |v: &ClipVert| {
        let [x, y] = view.to_screen(v.p);
        let w = 1.0 / v.p.z;
        (x, y, w, v.c * w)
    };
    let a = proj(&poly[0]);
    for k in 1..poly.len() - 1 {
        let (b, c) = (proj(&poly[k]), proj(&poly[k + 1]));
        let t = ScreenTri {
            x: [a.0, b.0, c.0],
            y: [a.1, b.1, c.1],
            w: [a.2, b.2, c.2],
            cw: [a.3, b.3, c.3],
        };
        let area = (b.0 - a.0) * (c.1 - a.1) - (b.1 - a.1) * (c.0 - a.0);
        let finite = t.x.iter().chain(&t.y).chain(&t.w).all(|v| v.is_finite())
            && t.cw.iter().all(|c| c.is_finite());
        if finite && area != 0.0 {
            out.push(t);
        }
    }
}

/// The inclusive range of sample indices (centres at i + 0.5) in [0, n) within [min, max] of
/// `coords`; empty (first > last) if none.
fn sample_range(coords: [f32; 3], n: usize) -> (usize, usize) {
    let lo = coords[0].min(coords[1]).min(coords[2]);
    let hi = coords[0].max(coords[1]).max(coords[2]);
    let first = (lo - 0.5).ceil().max(0.0);
    let last = (hi - 0.5).floor().min(n as f32 - 1.0);
    if first > last {
        return (1, 0);
    }
    (first as usize, last as usize)
}

/// Z-buffered, perspective-correct rasterization of one triangle into the band of `rows`
/// sample rows starting at sample row `y0`.
fn rasterize(
    t: &ScreenTri,
    y0: usize,
    rows: usize,
    ws: usize,
    colour: &mut [Vec3],
    depth: &mut [f32],
) {
    let (c0, c1) = sample_range(t.x, ws);
    let (r0, r1) = sample_range(t.y, y0 + rows);
    let r0 = r0.max(y0);
    if c0 > c1 || r0 > r1 {
        return;
    }
    // Edge k is opposite vertex k. Its endpoints go in lexicographic order, so a shared edge is
    // evaluated identically by both triangles (up to an exact sign flip): no cracks.
    let mut edges = [(0.0f32, 0.0f32, 0.0f32, 0.0f32, 0.0f32); 3];
    for (k, e) in edges.iter_mut().enumerate() {
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        let (a, b) = if (t.x[i], t.y[i]) < (t.x[j], t.y[j]) {
            (i, j)
        } else {
            (j, i)
        };
        let (ax, ay, dx, dy) = (t.x[a], t.y[a], t.x[b] - t.x[a], t.y[b] - t.y[a]);
        // The sign that makes the opposite vertex (the triangle's inside) non-negative.
        let at_k = dx * (t.y[k] - ay) - dy * (t.x[k] - ax);
        *e = (ax, ay, dx, dy, if at_k < 0.0 { -1.0 } else { 1.0 });
    }
    for sy in r0..=r1 {
        let py = sy as f32 + 0.5;
        let row_terms = edges.map(|(_, ay, dx, _, _)| dx * (py - ay));
        let base = (sy - y0) * ws;
        for sx in c0..=c1 {
            let px = sx as f32 + 0.5;
            let mut e = [0.0f32; 3];
            for k in 0..3 {
                let (ax, _, _, dy, sign) = edges[k];
                e[k] = sign * (row_terms[k] - dy * (px - ax));
            }
            let sum = e[0] + e[1] + e[2];
            if e[0] < 0.0 || e[1] < 0.0 || e[2] < 0.0 || sum <= 0.0 {
                continue;
            }
            let b = [e[0] / sum, e[1] / sum, e[2] / sum];
            let w = b[0] * t.w[0] + b[1] * t.w[1] + b[2] * t.w[2];
            let i = base + sx;
            if w > depth[i] {
                depth[i] = w;
                colour[i] = (b[0] * t.cw[0] + b[1] * t.cw[1] + b[2] * t.cw[2]) / w;
            }
        }
    }
}

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{Patch, PatchClass};

    /// One patch per quad (corners counter-clockwise seen from the front), unwelded vertices.
    fn quads(qs: &[([Vec3; 4], [[f32; 3]; 4])]) -> (Mesh, Vec<[f32; 3]>) {
        let mut mesh = Mesh::default();
        let mut rgb = Vec::new();
        for (corners, colours) in qs {
            let first = mesh.patch_vertices.len() as u32;
            let n = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
            for (p, c) in corners.iter().zip(colours) {
                mesh.patch_vertices.push(mesh.vertices.len() as u32);
                mesh.vertices.push(*p);
                rgb.push(*c);
            }
            mesh.patches.push(Patch {
                first,
                count: 4,
                material: 0,
                polygon: 0,
                area: f64::from(n.length()),
                centre: corners.iter().sum::<Vec3>() / 4.0,
                normal: n.normalize(),
                class: PatchClass::Skew,
            });
        }
        (mesh, rgb)
    }

    /// A quad in the plane z = `z`, facing +z, spanning [-h, h]².
    fn z_quad(z: f32, h: f32) -> [Vec3; 4] {
        [
            Vec3::new(-h, -h, z),
            Vec3::new(h, -h, z),
            Vec3::new(h, h, z),
            Vec3::new(-h, h, z),
        ]
    }

    /// Looking along -z from (0, 0, d) at fov 40°, where the view at z = 0 spans [-1, 1] (square
    /// image).
    fn head_on() -> Camera {
        let d = 1.0 / 20f32.to_radians().tan();
        Camera {
            eye: Vec3::new(0.0, 0.0, d),
            target: Vec3::ZERO,
            up: Vec3::Y,
            fov_y_deg: 40.0,
        }
    }

    fn opts(w: u32, h: u32, s: u32) -> RenderOptions {
        RenderOptions {
            width: w,
            height: h,
            supersample: s,
            exposure: None,
        }
    }

    #[test]
    fn uniform_quad_renders_its_colour_and_tone_maps_to_srgb() {
        let c = [0.05, 0.3, 0.8];
        let (mesh, rgb) = quads(&[(z_quad(0.0, 2.0), [c; 4])]);
        let img = render_linear(&mesh, &rgb, &head_on(), &opts(40, 30, 3));
        assert_eq!(img.pixels.len(), 40 * 30);
        for p in &img.pixels {
            for k in 0..3 {
                // Perspective division and barycentric normalisation cost a few f32 ulps.
                assert!((p[k] - c[k]).abs() < 1e-5, "{p:?} vs {c:?}");
            }
        }
        let (srgb, e) = tone_map(&img, Some(1.0));
        assert_eq!(e, 1.0);
        // sRGB(0.05, 0.3, 0.8) × 255 = (63.19, 148.88, 231.11), computed independently.
        for p in srgb.pixels() {
            assert_eq!(p.0, [63, 149, 231]);
        }
    }

    #[test]
    fn quad_seen_from_behind_is_culled() {
        let (mesh, rgb) = quads(&[(z_quad(0.0, 2.0), [[1.0; 3]; 4])]);
        let mut cam = head_on();
        cam.eye.z = -cam.eye.z;
        let img = render_linear(&mesh, &rgb, &cam, &opts(32, 32, 2));
        assert!(img.pixels.iter().all(|p| *p == [0.0; 3]));
        // The same from the front is drawn: the test can fail.
        let img = render_linear(&mesh, &rgb, &head_on(), &opts(32, 32, 2));
        assert!(img.pixels.iter().all(|p| p[0] > 0.99));
    }

    #[test]
    fn gouraud_gives_a_linear_ramp_along_x() {
        // Colour 0 on the left edge (x = -2), 1 on the right (x = 2): B(x) = (x + 2) / 4.
        let (mesh, rgb) = quads(&[(z_quad(0.0, 2.0), [[0.0; 3], [1.0; 3], [1.0; 3], [0.0; 3]])]);
        let w = 64;
        let img = render_linear(&mesh, &rgb, &head_on(), &opts(w, w, 3));
        for col in [0, 10, 31, 32, 50, 63] {
            // Pixel centre at x = 2(col + 0.5)/w − 1 in the plane z = 0. The box filter averages
            // a linear function over samples placed symmetrically about the pixel centre, so it
            // returns the centre value; what is left is f32 rounding, far below 1e-4.
            let x = 2.0 * (col as f32 + 0.5) / w as f32 - 1.0;
            let expected = (x + 2.0) / 4.0;
            for row in [0, 20, 63] {
                let p = img.pixels[row * w as usize + col];
                assert!(
                    (p[1] - expected).abs() < 1e-4,
                    "col {col}: {} vs {expected}",
                    p[1]
                );
            }
        }
    }

    #[test]
    fn nearer_quad_wins_whatever_the_order() {
        let far = (z_quad(0.0, 2.0), [[1.0, 0.0, 0.0]; 4]);
        let near = (z_quad(0.5, 0.3), [[0.0, 1.0, 0.0]; 4]);
        for order in [[far, near], [near, far]] {
            let (mesh, rgb) = quads(&order);
            let img = render_linear(&mesh, &rgb, &head_on(), &opts(32, 32, 1));
            assert_eq!(img.pixels[16 * 32 + 16], [0.0, 1.0, 0.0]);
            assert_eq!(img.pixels[0], [1.0, 0.0, 0.0]);
        }
    }

    /// A floor at y = -1, facing up, x in [-1000, 1000], z from `z_far` to `z_near`, with colour
    /// `c(z)` at its edges; seen from the origin looking along -z.
    fn floor(z_far: f32, z_near: f32, c_far: f32, c_near: f32) -> (Mesh, Vec<[f32; 3]>, Camera) {
        let h = 1000.0;
        let (mesh, rgb) = quads(&[(
            [
                Vec3::new(-h, -1.0, z_near),
                Vec3::new(h, -1.0, z_near),
                Vec3::new(h, -1.0, z_far),
                Vec3::new(-h, -1.0, z_far),
            ],
            [[c_near; 3], [c_near; 3], [c_far; 3], [c_far; 3]],
        )]);
        let cam = Camera {
            eye: Vec3::ZERO,
            target: Vec3::NEG_Z,
            up: Vec3::Y,
            fov_y_deg: 40.0,
        };
        (mesh, rgb, cam)
    }

    #[test]
    fn floor_crossing_the_near_plane_is_clipped() {
        // The floor reaches 50 m behind the eye. Its far edge (z = -1000) is 0.0028 of the
        // half-height below the image centre, above every sample of row 32 (the first below the
        // centre of 64 rows): rows 32.. are fully covered, rows ..32 empty.
        let (mesh, rgb, cam) = floor(-1000.0, 50.0, 0.5, 0.5);
        let img = render_linear(&mesh, &rgb, &cam, &opts(64, 64, 3));
        for (i, p) in img.pixels.iter().enumerate() {
            if i / 64 >= 32 {
                assert!((p[0] - 0.5).abs() < 1e-4, "pixel {i}: {p:?}");
            } else {
                assert_eq!(*p, [0.0; 3], "pixel {i}");
            }
        }
    }

    #[test]
    fn interpolation_is_perspective_correct_after_clipping() {
        // Colour 0 at z = 10 (behind the eye), 1 at z = -20: c(z) = (10 − z) / 30. The ray
        // through the centre of row r hits the floor at z = −1 / t, t = −ndc_y·tan 20°. One
        // sample per pixel, so the pixel is that ray's value; affine interpolation would be off
        // by > 0.1 here, f32 rounding is below 1e-3.
        let (mesh, rgb, cam) = floor(-20.0, 10.0, 1.0, 0.0);
        let img = render_linear(&mesh, &rgb, &cam, &opts(64, 64, 1));
        for row in [40usize, 50, 63] {
            let ndc_y = 1.0 - 2.0 * (row as f32 + 0.5) / 64.0;
            let t = -ndc_y * 20f32.to_radians().tan();
            let expected = (10.0 + 1.0 / t) / 30.0;
            let p = img.pixels[row * 64 + 20];
            assert!(
                (p[0] - expected).abs() < 1e-3,
                "row {row}: {} vs {expected}",
                p[0]
            );
        }
    }

    #[test]
    fn fitted_camera_sees_all_corners_of_a_unit_box() {
        let cam = Camera::fit(Vec3::ZERO, Vec3::ONE, 640.0 / 480.0);
        assert!(cam.eye.z > 1.0 && cam.fov_y_deg == 40.0);
        let view = View::new(&cam, 640, 480);
        let mut widest: f32 = 0.0;
        for i in 0..8 {
            let corner = Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, (i >> 2) as f32);
            let v = view.to_view(corner);
            assert!(v.z > 0.0);
            let [x, y] = view.to_screen(v);
            assert!(
                (0.0..=640.0).contains(&x) && (0.0..=480.0).contains(&y),
                "{x}, {y}"
            );
            widest = widest
                .max((x / 320.0 - 1.0).abs())
                .max((y / 240.0 - 1.0).abs());
        }
        // A snug fit: the outermost corner lies at 1/1.1 of the way to the border.
        assert!(widest > 0.85 && widest < 0.95, "{widest}");
    }

    #[test]
    fn auto_exposure_is_finite_positive_and_ignores_the_light() {
        let black = LinearImage {
            width: 4,
            height: 4,
            pixels: vec![[0.0; 3]; 16],
        };
        assert_eq!(tone_map(&black, None).1, 1.0);
        // 99 grey pixels at luminance 2 and one light a million times brighter: the 97th
        // percentile is a grey pixel, mapped to 0.9.
        let mut pixels = vec![[2.0f32; 3]; 100];
        pixels[7] = [2e6; 3];
        let img = LinearImage {
            width: 10,
            height: 10,
            pixels,
        };
        let (out, e) = tone_map(&img, None);
        assert!((e - 0.45).abs() < 1e-5, "{e}");
        assert_eq!(out.get_pixel(7, 0).0, [255; 3]);
        assert_eq!(
            out.get_pixel(0, 0).0[0],
            (srgb_encode(0.9) * 255.0).round() as u8
        );
    }

    #[test]
    fn degenerate_inputs_do_not_panic() {
        let (mut mesh, mut rgb) = quads(&[(z_quad(0.0, 2.0), [[1.0; 3]; 4])]);
        let o = opts(16, 16, 2);
        // Empty mesh, zero size, zero supersampling.
        let img = render_linear(&Mesh::default(), &[], &head_on(), &o);
        assert!(img.pixels.iter().all(|p| *p == [0.0; 3]));
        assert!(render_linear(&mesh, &rgb, &head_on(), &opts(0, 16, 3))
            .pixels
            .is_empty());
        assert_eq!(
            tone_map(
                &LinearImage {
                    width: 0,
                    height: 0,
                    pixels: vec![]
                },
                None
            )
            .1,
            1.0
        );
        assert_eq!(
            render_linear(&mesh, &rgb, &head_on(), &opts(4, 4, 0))
                .pixels
                .len(),
            16
        );
        // Degenerate cameras: eye == target, up parallel to the view, NaN everywhere.
        let mut cam = head_on();
        cam.target = cam.eye;
        render_linear(&mesh, &rgb, &cam, &o);
        let cam = Camera {
            up: Vec3::NEG_Z,
            ..head_on()
        };
        let img = render_linear(&mesh, &rgb, &cam, &o);
        assert!(
            img.pixels.iter().all(|p| p[0] > 0.99),
            "a fallback up still sees the quad"
        );
        let nan = Camera {
            eye: Vec3::NAN,
            target: Vec3::NAN,
            up: Vec3::NAN,
            fov_y_deg: f32::NAN,
        };
        render_linear(&mesh, &rgb, &nan, &o);
        // NaN colours count as 0, short colour lists and bad indices are tolerated.
        rgb[0] = [f32::NAN; 3];
        let img = render_linear(&mesh, &rgb, &head_on(), &o);
        assert!(img.pixels.iter().all(|p| p.iter().all(|c| c.is_finite())));
        render_linear(&mesh, &rgb[..2], &head_on(), &o);
        mesh.patch_vertices[3] = 99;
        mesh.patches.push(Patch {
            first: u32::MAX,
            ..mesh.patches[0]
        });
        render_linear(&mesh, &rgb, &head_on(), &o);
        let _ = Camera::fit(Vec3::INFINITY, Vec3::NEG_INFINITY, f32::NAN);
    }

    /// A closed box room of `n`×`n` quads per wall (2·6·n² triangles), normals inward.
    fn room(n: usize) -> (Mesh, Vec<[f32; 3]>) {
        let mut qs = Vec::new();
        let size = 10.0;
        for axis in 0..3 {
            for side in [0.0f32, 1.0] {
                for i in 0..n {
                    for j in 0..n {
                        let at = |u: usize, v: usize| {
                            let (u, v) = (u as f32 / n as f32 * size, v as f32 / n as f32 * size);
                            let mut p = [0.0; 3];
                            p[axis] = side * size;
                            p[(axis + 1) % 3] = u;
                            p[(axis + 2) % 3] = v;
                            Vec3::from_array(p)
                        };
                        let mut c = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
                        // Counter-clockwise seen from inside the room.
                        if side > 0.5 {
                            c.reverse();
                        }
                        let col = [(i * j % 7) as f32 / 7.0, 0.5, side];
                        qs.push((c, [col; 4]));
                    }
                }
            }
        }
        quads(&qs)
    }

    #[test]
    fn room_is_closed_seen_from_inside() {
        let (mesh, rgb) = room(8);
        let cam = Camera {
            eye: Vec3::new(2.0, 3.0, 4.0),
            target: Vec3::new(9.0, 7.0, 1.0),
            up: Vec3::Y,
            fov_y_deg: 60.0,
        };
        // Every sample hits a wall: no background (crack) pixel anywhere.
        let img = render_linear(&mesh, &rgb, &cam, &opts(97, 61, 3));
        assert!(
            img.pixels.iter().all(|p| p[1] > 0.4999),
            "a crack let the background through"
        );
    }

    #[test]
    #[ignore = "timing; run with --ignored --nocapture"]
    fn time_100k_triangles() {
        let (mesh, rgb) = room(91);
        let tris = 2 * mesh.patches.len();
        let inside = Camera {
            eye: Vec3::new(2.0, 3.0, 4.0),
            target: Vec3::new(9.0, 7.0, 1.0),
            up: Vec3::Y,
            fov_y_deg: 60.0,
        };
        let outside = Camera::fit(Vec3::ZERO, Vec3::splat(10.0), 640.0 / 480.0);
        for (name, cam) in [("inside", inside), ("fitted", outside)] {
            let t = std::time::Instant::now();
            let img = render_linear(&mesh, &rgb, &cam, &RenderOptions::default());
            let dt = t.elapsed();
            let t2 = std::time::Instant::now();
            tone_map(&img, None);
            println!(
                "{tris} triangles, 640x480x9, {name}: render {dt:?}, tone map {:?}",
                t2.elapsed()
            );
        }
    }
}
