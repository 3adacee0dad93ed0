//! The CPU rasterizer: the view transform and projection (perspective or parallel, with
//! Radiance's shift and lift), culling and near-, far- and guard-band clipping in view space,
//! fan triangulation, the band scheduler, and Z-buffered, perspective-correct, watertight
//! rasterization of each triangle.

use super::Camera;
use crate::mesh::Mesh;
use glam::{Vec2, Vec3};
use rayon::prelude::*;

/// Output rows per rayon task (times the supersampling factor in sample rows).
const BAND_ROWS: usize = 8;
/// Side clip planes sit this factor outside the view, so clipping never shows at the border.
const GUARD: f32 = 1.01;

/// The camera's view transform and projection onto a sample grid.
pub(super) struct View {
    pub(super) eye: Vec3,
    right: Vec3,
    up: Vec3,
    pub(super) fwd: Vec3,
    /// Parallel projection: image-plane coordinates are view-space x, y (not x/z, y/z).
    pub(super) parallel: bool,
    /// Half the picture's size on the image plane ([`crate::render::Projection::half_extent`]).
    half: Vec2,
    /// The picture's shift and lift (fractions of its width and height).
    shift: Vec2,
    width: f32,
    height: f32,
}

impl View {
    /// The camera's frame ([`Camera::frame`], degenerate cameras fall back) and projection on
    /// a `width`×`height` sample grid.
    pub(super) fn new(camera: &Camera, width: usize, height: usize) -> View {
        let f = camera.frame();
        View {
            eye: camera.eye_or_origin(),
            right: f.right,
            up: f.up,
            fwd: f.fwd,
            parallel: camera.projection.is_parallel(),
            half: camera.projection.half_extent(),
            shift: camera.shift_or_zero(),
            width: width as f32,
            height: height as f32,
        }
    }

    /// World → view space: x right, y up, z = depth along the view direction.
    pub(super) fn to_view(&self, p: Vec3) -> Vec3 {
        let d = p - self.eye;
        Vec3::new(d.dot(self.right), d.dot(self.up), d.dot(self.fwd))
    }

    /// View space (z > 0 for a perspective view) → sample-grid coordinates, y down, pixel
    /// centres at +0.5: [`Camera::project`]'s (u, v) times the grid's size.
    pub(super) fn to_screen(&self, v: Vec3) -> [f32; 2] {
        let (px, py) = if self.parallel {
            (v.x, v.y)
        } else {
            (v.x / v.z, v.y / v.z)
        };
        [
            (0.5 + 0.5 * px / self.half.x - self.shift.x) * self.width,
            (0.5 - 0.5 * py / self.half.y + self.shift.y) * self.height,
        ]
    }

    /// The clip planes (n, d), inside where n·p + d ≥ 0: near, the guard band (left, right,
    /// bottom, top), then far if there is one.
    pub(super) fn planes(&self, near: f32, far: Option<f32>) -> Vec<(Vec3, f32)> {
        // The picture spans centre ± half on the image plane; the band GUARD times as wide.
        let centre = 2.0 * self.half * self.shift;
        let (lo, hi) = (centre - GUARD * self.half, centre + GUARD * self.half);
        let mut planes = vec![(Vec3::Z, -near)];
        if self.parallel {
            // x ≥ lo.x: n = +x, d = −lo.x; and so on.
            planes.extend([
                (Vec3::X, -lo.x),
                (Vec3::NEG_X, hi.x),
                (Vec3::Y, -lo.y),
                (Vec3::NEG_Y, hi.y),
            ]);
        } else {
            // x/z ≥ lo.x ⇔ x − lo.x·z ≥ 0 (z > 0 past the near plane); and so on.
            planes.extend([
                (Vec3::new(1.0, 0.0, -lo.x), 0.0),
                (Vec3::new(-1.0, 0.0, hi.x), 0.0),
                (Vec3::new(0.0, 1.0, -lo.y), 0.0),
                (Vec3::new(0.0, -1.0, hi.y), 0.0),
            ]);
        }
        if let Some(far) = far {
            planes.push((Vec3::NEG_Z, far));
        }
        planes
    }
}

/// A polygon vertex during clipping: view-space position and linear colour.
#[derive(Clone, Copy)]
struct ClipVert {
    p: Vec3,
    c: Vec3,
}

/// A projected triangle: sample-grid positions, the perspective weight w (1/z; 1 for a
/// parallel view, whose interpolation is affine on the screen), colour·w, and the depth key
/// (larger is nearer: 1/z, or −z for a parallel view; both are affine on the screen).
#[derive(Clone, Copy)]
pub(super) struct ScreenTri {
    x: [f32; 3],
    y: [f32; 3],
    w: [f32; 3],
    cw: [Vec3; 3],
    key: [f32; 3],
}

/// Culls, clips and projects every patch (in parallel, order kept so results are
/// deterministic) into triangles on the sample grid.
pub(super) fn screen_triangles(
    mesh: &Mesh,
    vertex_rgb: &[[f32; 3]],
    view: &View,
    planes: &[(Vec3, f32)],
) -> Vec<ScreenTri> {
    mesh.patches
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
                if patch_polygon(mesh, vertex_rgb, idx, patch.normal, view, &mut poly) {
                    clip_polygon(&mut poly, &mut tmp, planes);
                    project_fan(&poly, view, &mut out);
                }
            }
            out
        })
        .flatten_iter()
        .collect()
}

/// The band scheduler: bins the triangles by band of output rows, then rasterizes each band
/// into its own buffers (one rayon task each) and box-filters it into its rows of `pixels`
/// (`width` wide, `s`×`s` samples per pixel).
pub(super) fn draw_bands(
    tris: &[ScreenTri],
    pixels: &mut [[f32; 3]],
    width: usize,
    height: usize,
    s: usize,
) {
    let (ws, hs) = (width * s, height * s);
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
            let mut depth = vec![f32::NEG_INFINITY; rows * ws];
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
    // Seen from the front: towards the eye, or against the direction of a parallel view.
    let towards_viewer = if view.parallel {
        -view.fwd
    } else {
        view.eye - poly[0].p
    };
    if n.dot(towards_viewer) <= 0.0 {
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
        let (w, key) = if view.parallel {
            (1.0, -v.p.z)
        } else {
            (1.0 / v.p.z, 1.0 / v.p.z)
        };
        (x, y, w, v.c * w, key)
    };
    let a = proj(&poly[0]);
    for k in 1..poly.len() - 1 {
        let (b, c) = (proj(&poly[k]), proj(&poly[k + 1]));
        let t = ScreenTri {
            x: [a.0, b.0, c.0],
            y: [a.1, b.1, c.1],
            w: [a.2, b.2, c.2],
            cw: [a.3, b.3, c.3],
            key: [a.4, b.4, c.4],
        };
        let area = (b.0 - a.0) * (c.1 - a.1) - (b.1 - a.1) * (c.0 - a.0);
        let finite =
            t.x.iter()
                .chain(&t.y)
                .chain(&t.w)
                .chain(&t.key)
                .all(|v| v.is_finite())
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
            let key = b[0] * t.key[0] + b[1] * t.key[1] + b[2] * t.key[2];
            let i = base + sx;
            if key > depth[i] {
                depth[i] = key;
                let w = b[0] * t.w[0] + b[1] * t.w[1] + b[2] * t.w[2];
                colour[i] = (b[0] * t.cw[0] + b[1] * t.cw[1] + b[2] * t.cw[2]) / w;
            }
        }
    }
}
