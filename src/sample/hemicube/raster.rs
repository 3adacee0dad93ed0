//! One z-buffer shot of the hemi-cube: the per-thread buffers and their reset, the patch into
//! the shooter's frame, clipping to each face's frustum, scan conversion (at the cell centres
//! or jittered) and the read-back of ΔF per patch, with the work counted as [`ShotWork`].

use super::grid::Face;
use super::{Frame, Hemicube};
use crate::mesh::Mesh;
use glam::Vec3;
use rand::Rng;

/// No patch in this cell.
const EMPTY: u32 = u32::MAX;

/// Per-thread scratch: z-buffer and id buffer for all cells, reused across shots (no allocation
/// per shot once sized).
#[derive(Default)]
pub struct HemicubeBuffer {
    /// 1/w of the nearest patch per cell (0: nothing, i.e. infinitely far).
    depth: Vec<f32>,
    id: Vec<u32>,
    /// Jittered sample points per cell.
    sample_u: Vec<f32>,
    sample_v: Vec<f32>,
    /// Per patch: F accumulated this shot (0 outside `touched`).
    acc: Vec<f64>,
    touched: Vec<u32>,
    /// The patch in the frame, clipped to the base plane.
    local: Vec<[f32; 3]>,
    clip_a: Vec<[f32; 3]>,
    clip_b: Vec<[f32; 3]>,
    proj: Vec<[f32; 2]>,
    edges: Vec<[f32; 3]>,
}

impl HemicubeBuffer {
    /// Sized for `cells` cells and `patches` patches, the z-buffer cleared.
    pub(super) fn reset(&mut self, cells: usize, patches: usize) {
        self.depth.clear();
        self.depth.resize(cells, 0.0);
        self.id.clear();
        self.id.resize(cells, EMPTY);
        if self.acc.len() < patches {
            self.acc.resize(patches, 0.0);
        }
    }
}

/// The work one shot did, counted: what the hybrid's cost model (Sec. 4, `solve::switch`)
/// weighs. A function of the scene, the cube and the shot's rotation only (never of the clock
/// or the thread count).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ShotWork {
    /// Patches transformed into the shooter's frame (every patch but the shooter).
    pub patches: u64,
    /// (patch, face) pairs mapped onto a face and clipped to its frustum.
    pub faces: u64,
    /// Cells of the cube (cleared before the shot, read back after it).
    pub cells: u64,
    /// Cells the scan conversion depth-tested (overdraw counted).
    pub tested: u64,
}

impl Hemicube {
    /// Jitter: one random point per cell, drawn in cell order before any drawing.
    pub(super) fn draw_sample_points<R: Rng>(&self, rng: &mut R, buf: &mut HemicubeBuffer) {
        buf.sample_u.clear();
        buf.sample_v.clear();
        for face in &self.faces {
            for v in face.v.bounds.windows(2) {
                for u in face.u.bounds.windows(2) {
                    buf.sample_u.push(u[0] + rng.gen::<f32>() * (u[1] - u[0]));
                    buf.sample_v.push(v[0] + rng.gen::<f32>() * (v[1] - v[0]));
                }
            }
        }
    }

    /// Draws patch `j`, already in the frame (`buf.local`, its plane `plane`), onto every face
    /// that can see it: mapped into the face's coordinates, clipped to its frustum, projected
    /// and scan-converted.
    pub(super) fn draw_patch(
        &self,
        j: u32,
        plane: FramePlane,
        jittered: bool,
        buf: &mut HemicubeBuffer,
        work: &mut ShotWork,
    ) {
        let HemicubeBuffer {
            depth,
            id,
            sample_u,
            sample_v,
            local,
            clip_a,
            clip_b,
            proj,
            edges,
            ..
        } = buf;
        // A face sees only points ahead of it (w > 0): a face none of the (clipped) polygon's
        // vertices is ahead of cannot see any of it, and is skipped before the mapping and the
        // frustum tests (most patches reach one to three faces, not five).
        let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for q in local.iter() {
            for k in 0..3 {
                lo[k] = lo[k].min(q[k]);
                hi[k] = hi[k].max(q[k]);
            }
        }
        for face in &self.faces {
            let (w_axis, w_sign) = face.axes[0];
            let ahead = if w_sign > 0.0 {
                hi[w_axis] > 0.0
            } else {
                lo[w_axis] < 0.0
            };
            if !ahead {
                continue;
            }
            work.faces += 1;
            if !clip_to_frustum(face, local, clip_a, clip_b) {
                continue;
            }
            proj.clear();
            // w > 0 inside the frustum but at the eye itself, which only a patch whose plane
            // holds the eye (skipped in `to_frame`) could reach: guard against 0/0 anyway.
            proj.extend(clip_a.iter().map(|q| {
                let w = q[0].max(f32::MIN_POSITIVE);
                [
                    (q[1] / w).clamp(-1.0, 1.0),
                    (q[2] / w).clamp(face.v_lo, 1.0),
                ]
            }));
            // 1/w = n·(1, u, v)/d in the face's coordinates: affine in (u, v).
            let nf = face.map(plane.normal);
            let z = [nf[0] / plane.d, nf[1] / plane.d, nf[2] / plane.d];
            work.tested += if jittered {
                raster_jittered(face, proj, z, j, depth, id, sample_u, sample_v, edges)
            } else {
                raster_centres(face, proj, z, j, depth, id)
            };
        }
    }

    /// Σ ΔF per patch, in cell order (deterministic), into `out` sorted by patch id.
    pub(super) fn read_back(
        &self,
        mesh: &Mesh,
        eye: Vec3,
        buf: &mut HemicubeBuffer,
        out: &mut Vec<(u32, f64, bool)>,
    ) {
        let HemicubeBuffer {
            id, acc, touched, ..
        } = buf;
        touched.clear();
        for (c, &j) in id.iter().enumerate() {
            if j != EMPTY {
                let a = &mut acc[j as usize];
                if *a == 0.0 {
                    touched.push(j);
                }
                *a += self.delta_ff[c];
            }
        }
        touched.sort_unstable();
        for &j in touched.iter() {
            let f = std::mem::take(&mut acc[j as usize]);
            let p = &mesh.patches[j as usize];
            if f > 0.0 {
                // The side the eye sees decides the receiver: a back twin, or (one-sided) lost
                // on the back face (docs/design.md §7).
                let back = p.normal.dot(eye - p.centre) < 0.0;
                out.push(match mesh.receiver(j, back) {
                    Some(r) => (r, f, false),
                    None => (j, f, true),
                });
            }
        }
    }
}

/// A patch's plane in the shooter's frame: n·p = d (d < 0: its front faces the eye).
#[derive(Clone, Copy)]
pub(super) struct FramePlane {
    normal: [f32; 3],
    d: f32,
}

/// Patch `j` into the frame, relative to the eye, into `buf.local`, clipped to the base plane
/// z ≥ 0; `None` when it is wholly under the base plane (within `eps`), edge-on, or clipped
/// away.
pub(super) fn to_frame(
    mesh: &Mesh,
    j: usize,
    eye: Vec3,
    frame: &Frame,
    eps: f32,
    buf: &mut HemicubeBuffer,
) -> Option<FramePlane> {
    let patch = &mesh.patches[j];
    let (local, clip_a) = (&mut buf.local, &mut buf.clip_a);
    local.clear();
    let (mut zmin, mut zmax) = (f32::INFINITY, f32::NEG_INFINITY);
    for &vi in mesh.patch_indices(j) {
        let p = mesh.vertices[vi as usize] - eye;
        let q = [p.dot(frame.t), p.dot(frame.b), p.dot(frame.n)];
        zmin = zmin.min(q[2]);
        zmax = zmax.max(q[2]);
        local.push(q);
    }
    if zmax <= eps || local.len() < 3 {
        return None;
    }
    // d ≈ 0 is edge-on.
    let d = patch.normal.dot(patch.centre - eye);
    if d.abs() <= eps {
        return None;
    }
    // Clipped at z = 0 itself, not at eps: a jittered sample may sit just above the base.
    if zmin < 0.0 {
        clip(local, clip_a, |q| q[2]);
        std::mem::swap(local, clip_a);
        if local.len() < 3 {
            return None;
        }
    }
    Some(FramePlane {
        normal: [
            patch.normal.dot(frame.t),
            patch.normal.dot(frame.b),
            patch.normal.dot(frame.n),
        ],
        d,
    })
}

/// `local` into the face's (w, u·w, v·w), into `clip_a`, clipped to the face's frustum
/// (`clip_b` is scratch). False when nothing of it is inside.
fn clip_to_frustum(
    face: &Face,
    local: &[[f32; 3]],
    clip_a: &mut Vec<[f32; 3]>,
    clip_b: &mut Vec<[f32; 3]>,
) -> bool {
    clip_a.clear();
    clip_a.extend(local.iter().map(|&q| face.map(q)));
    for k in 0..4 {
        let (mut inside, mut outside) = (false, false);
        for &q in clip_a.iter() {
            if face.plane(k, q) >= 0.0 {
                inside = true;
            } else {
                outside = true;
            }
        }
        if !inside {
            return false;
        }
        if outside {
            clip(clip_a, clip_b, |q| face.plane(k, q));
            std::mem::swap(clip_a, clip_b);
            if clip_a.len() < 3 {
                return false;
            }
        }
    }
    true
}

/// Sutherland–Hodgman: the part of convex polygon `src` where `dist ≥ 0`, into `dst`.
#[inline]
fn clip(src: &[[f32; 3]], dst: &mut Vec<[f32; 3]>, dist: impl Fn([f32; 3]) -> f32) {
    dst.clear();
    let m = src.len();
    for k in 0..m {
        let (a, b) = (src[k], src[(k + 1) % m]);
        let (da, db) = (dist(a), dist(b));
        if da >= 0.0 {
            dst.push(a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            let t = da / (da - db);
            dst.push([
                a[0] + t * (b[0] - a[0]),
                a[1] + t * (b[1] - a[1]),
                a[2] + t * (b[2] - a[2]),
            ]);
        }
    }
}

/// Face units by which spans and inside tests are widened: the same shared edge, projected and
/// clipped as part of two polygons, can land a few ulps apart, and a sample exactly on it (as
/// on axis-aligned architecture seen square-on) must not fall between them. Both claim it and
/// the z-test picks one; the bias, 2e-6 against a cell ≥ 2e-3 wide (N ≤ 1000), is ≤ 1e-3 of an
/// outline cell's ΔF.
const EDGE_TOL: f32 = 2e-6;

/// The u-range a convex polygon covers on the line v = const (clamped into its v-range, so a
/// row within [`EDGE_TOL`] of a vertex still gets the vertex's span).
#[inline]
fn span_at(poly: &[[f32; 2]], v: f32, (vmin, vmax): (f32, f32)) -> Option<(f32, f32)> {
    let v = v.clamp(vmin, vmax);
    let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
    let m = poly.len();
    for k in 0..m {
        let (a, b) = (poly[k], poly[(k + 1) % m]);
        if (a[1] <= v && v <= b[1]) || (b[1] <= v && v <= a[1]) {
            if a[1] == b[1] {
                lo = lo.min(a[0].min(b[0]));
                hi = hi.max(a[0].max(b[0]));
            } else {
                let u = a[0] + (v - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
                lo = lo.min(u);
                hi = hi.max(u);
            }
        }
    }
    (lo <= hi).then_some((lo, hi))
}

fn v_range(poly: &[[f32; 2]]) -> (f32, f32) {
    poly.iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p[1]), hi.max(p[1]))
        })
}

/// Sec. 2's scan conversion: per cell row at its centre height, the span's ends (widened by
/// [`EDGE_TOL`]) mapped through the look-up table onto the cells whose centres it covers.
/// Returns the cells it depth-tested.
fn raster_centres(
    face: &Face,
    poly: &[[f32; 2]],
    plane: [f32; 3],
    j: u32,
    depth: &mut [f32],
    id: &mut [u32],
) -> u64 {
    let (vmin, vmax) = v_range(poly);
    let rows = face.v.first_centre(vmin - EDGE_TOL)..face.v.first_centre(vmax + EDGE_TOL);
    let nu = face.u.len();
    let mut tested = 0;
    for r in rows {
        let v = face.v.centres[r];
        let Some((u0, u1)) = span_at(poly, v, (vmin, vmax)) else {
            continue;
        };
        let row = face.first + r * nu;
        let z_row = plane[0] + plane[2] * v;
        let span = face.u.first_centre(u0 - EDGE_TOL)..face.u.first_centre(u1 + EDGE_TOL);
        tested += span.len() as u64;
        for i in span {
            let z = z_row + plane[1] * face.u.centres[i];
            let c = row + i;
            if z > depth[c] {
                depth[c] = z;
                id[c] = j;
            }
        }
    }
    tested
}

/// Jittered: per row band, the cells the polygon's extent over the band can touch, each tested
/// at its own sample point against the polygon's edge functions. Returns the cells it tested.
// Nine: the innermost rasteriser; the face's depth and id buffers and the sample points are
// borrowed as separate slices (disjoint borrows of one face), as `raster_centres` takes them.
#[allow(clippy::too_many_arguments)]
fn raster_jittered(
    face: &Face,
    poly: &[[f32; 2]],
    plane: [f32; 3],
    j: u32,
    depth: &mut [f32],
    id: &mut [u32],
    sample_u: &[f32],
    sample_v: &[f32],
    edges: &mut Vec<[f32; 3]>,
) -> u64 {
    let m = poly.len();
    let area2: f32 = (0..m)
        .map(|k| {
            let (a, b) = (poly[k], poly[(k + 1) % m]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum();
    if area2 == 0.0 {
        return 0;
    }
    // Inside: a·u + b·v + c ≥ −EDGE_TOL for every edge, (a, b) the edge's unit inward normal (signs
    // follow the projected winding); a clipped-away zero-length edge tests nothing.
    let s = area2.signum();
    edges.clear();
    edges.extend((0..m).map(|k| {
        let (p, q) = (poly[k], poly[(k + 1) % m]);
        let (du, dv) = (q[0] - p[0], q[1] - p[1]);
        let len = (du * du + dv * dv).sqrt();
        if len == 0.0 {
            return [0.0; 3];
        }
        let s = s / len;
        [-dv * s, du * s, (dv * p[0] - du * p[1]) * s]
    }));
    let (vmin, vmax) = v_range(poly);
    let nu = face.u.len();
    let mut tested = 0;
    for r in face.v.cells_meeting(vmin - EDGE_TOL, vmax + EDGE_TOL) {
        let lo = face.v.bounds[r].clamp(vmin, vmax);
        let hi = face.v.bounds[r + 1].clamp(vmin, vmax);
        // The polygon's u-extent over the band: its crossings of the band's edges and the
        // vertices inside the band.
        let (mut u0, mut u1) = (f32::INFINITY, f32::NEG_INFINITY);
        for v in [lo, hi] {
            if let Some((a, b)) = span_at(poly, v, (vmin, vmax)) {
                u0 = u0.min(a);
                u1 = u1.max(b);
            }
        }
        for p in poly.iter().filter(|p| lo <= p[1] && p[1] <= hi) {
            u0 = u0.min(p[0]);
            u1 = u1.max(p[0]);
        }
        if u0 > u1 {
            continue;
        }
        let row = face.first + r * nu;
        let span = face.u.cells_meeting(u0 - EDGE_TOL, u1 + EDGE_TOL);
        tested += span.len() as u64;
        for i in span {
            let c = row + i;
            let (u, v) = (sample_u[c], sample_v[c]);
            if edges
                .iter()
                .all(|e| e[0] * u + e[1] * v + e[2] >= -EDGE_TOL)
            {
                let z = plane[0] + plane[1] * u + plane[2] * v;
                if z > depth[c] {
                    depth[c] = z;
                    id[c] = j;
                }
            }
        }
    }
    tested
}
