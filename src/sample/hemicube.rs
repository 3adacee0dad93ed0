//! The software hemi-cube (Cohen & Greenberg 1985) and the paper's non-uniform, adaptive
//! hemi-cube (Airey & Ouh-young 1989, Sec. 1 and 2).
//!
//! A hemi-cube around the shooter's centre has a top face (z = 1, u = x, v = y in [-1, 1]) and
//! four half side faces (e.g. x = 1: u = y in [-1, 1], v = z in [0, 1]). Every other patch is
//! projected onto the faces and z-buffered; each cell then holds the nearest patch seen through
//! its sample point, and the form factor F_ij is the sum of the delta form factors ΔF of the
//! cells patch j holds (Nusselt's analog: ΔF is the cell's share of the projected hemisphere).
//! `i` shoots, `j` receives.
//!
//! **Uniform** (Cohen & Greenberg): an N×N top face and N×N/2 side faces, ΔA = 4/N², with the
//! closed-form table ΔF = ΔA/(π(x²+y²+1)²) on the top and z·ΔA/(π(y²+z²+1)²) on a side, at the
//! cell centres, normalised so the 3N² cells sum to exactly 1.
//!
//! **Non-uniform** (Sec. 2): the largest uniform ΔF is the top face's centre cell, 4/(πN²); if
//! every cell carried that much, πN²/4 cells would do instead of 3N² (π/12 as many). The cells
//! grow away from the centre: along the top face's diagonal the recurrence
//! (x_{i+1} − x_i)² / (2((x_i + x_{i+1})/2)² + 1)² = 4/N², x_0 = 1/N, puts the boundaries (a
//! quadratic in the step, solved exactly); they are used on both axes of the top face and along
//! u of the side faces, so the cells of the side faces line up with those of the top. Off the
//! diagonal a top cell carries (2a+1)(2b+1)/(a+b+1)² ∈ [3/4, 1] of a diagonal one (a = x²,
//! b = y²). The side faces' heights follow the "similar recurrence" the paper leaves to the
//! reader, taken along the side face's own diagonal u = v: there a cell of width (2/N)(2m² + 1)
//! (the top's step at m) and height Δv carries Δu·Δv·m/(π(2m²+1)²), set to 4/(πN²). For a fixed
//! height, density times u-width peaks exactly on that diagonal, so no side cell exceeds the
//! top's centre cell (fixing the side's middle column at 4/(πN²) instead would put 4/3 of it
//! into the cells at the top corners: max ΔF 1.30× the centre's at N = 101).
//!
//! The recurrence rarely lands on an edge. Merging a last partial interval into its neighbour
//! when it is shorter than half of it (and keeping it otherwise) leaves, depending on N, cells
//! from 0.08× to 2.2× the target (measured over odd N ≤ 301: the merged column crosses the
//! merged row in a corner cell of up to 1.5² its share). Here the remainder becomes a step of
//! its own and the step constant is lowered, by bisection, until the whole steps end exactly on
//! the edge: every diagonal cell then carries the same, a little less than 4/(πN²), the central
//! cell stays the largest, and over odd N from 21 to 301 every cell lies within 0.67–1.014 of
//! 4/(πN²) with 1.06–1.19× the ideal πN²/4 cells. The second pass of Sec. 2 gives every cell
//! its *exact* ΔF, the closed-form integral of the differential form factor over the cell (the
//! point-to-rectangle form factor: one antiderivative per face type, at the cell's corners), so
//! the cells sum to 1 to rounding without normalising.
//!
//! **Scan conversion** follows Sec. 2: a convex polygon is scan-converted one cell row at a time
//! at the row's sample height, and the span's ends are mapped onto the non-uniform cells through
//! a look-up table: a regular grid over the face axis, each bin holding the first cell whose
//! sample point lies at or after the bin's start. The bins are no wider than the smallest gap
//! between sample points, so at most one comparison corrects the table's answer: O(1) per span
//! end, against the ~7 steps of a binary search over 70–100 boundaries. For the uniform cube the
//! table is the identity. With jitter (the paper's Table 1 "jittered hemi-cube") every cell has
//! its own random sample point, so the table gives the cells the polygon's extent over the row
//! band can touch, and each candidate's own point is tested against the polygon's edge
//! functions. Spans and inside tests are widened by a rounding tolerance (`EDGE_TOL`), so a sample
//! exactly on an edge two patches share is claimed by both rather than lost between them.
//! Depth is 1/w, w the distance along the face's axis, which is affine in the face coordinates
//! (u, v) for a planar patch; nearest wins, and ties keep the lower patch id (patches are drawn
//! in id order and only a strictly nearer one replaces a cell).
//!
//! One shot is single-threaded: the solvers run shots in parallel with one [`HemicubeBuffer`]
//! per thread, so the result never depends on the thread count.

use super::Frame;
use crate::mesh::Mesh;
use glam::Vec3;
use rand::Rng;
use std::f64::consts::PI;

/// No patch in this cell.
const EMPTY: u32 = u32::MAX;

/// Cell layout and delta form factors of one hemi-cube: top face (z = 1, u, v in [-1, 1]) and
/// four half side faces (e.g. x = 1: u = y in [-1, 1], v = z in [0, 1]).
#[derive(Clone, Debug)]
pub struct Hemicube {
    n: usize,
    uniform: bool,
    /// Top, +x, −x, +y, −y.
    faces: [Face; 5],
    /// ΔF per cell, faces back to back, each row-major (v rows of u cells).
    delta_ff: Vec<f64>,
    min_ff: f64,
    max_ff: f64,
    sum_ff: f64,
}

/// One face: how frame-local (x, y, z) maps onto it, and its cells.
#[derive(Clone, Debug)]
struct Face {
    /// Local coordinate (index, sign) giving w (along the face's axis), then u, then v.
    axes: [(usize, f32); 3],
    /// Lower end of v: −1 on the top face, 0 (the base plane) on a side.
    v_lo: f32,
    u: CellAxis,
    v: CellAxis,
    /// Index of the face's first cell.
    first: usize,
}

impl Face {
    /// Frame-local point → (w, u·w, v·w).
    #[inline]
    fn map(&self, p: [f32; 3]) -> [f32; 3] {
        let [(a, sa), (b, sb), (c, sc)] = self.axes;
        [p[a] * sa, p[b] * sb, p[c] * sc]
    }

    /// Signed distances to the face's frustum (w ± u·w ≥ 0, w − v·w ≥ 0, v·w − v_lo·w ≥ 0);
    /// its four planes pass through the eye, so clipping stays linear in (w, u·w, v·w).
    #[inline]
    fn plane(&self, k: usize, q: [f32; 3]) -> f32 {
        match k {
            0 => q[0] - q[1],
            1 => q[0] + q[1],
            2 => q[0] - q[2],
            _ => q[2] - self.v_lo * q[0],
        }
    }

    fn cells(&self) -> usize {
        self.u.len() * self.v.len()
    }
}

/// Cells along one axis of a face: boundaries, sample points (the cells' centres) and the
/// look-up tables that map a coordinate onto them.
#[derive(Clone, Debug)]
struct CellAxis {
    bounds: Vec<f32>,
    centres: Vec<f32>,
    bound_lut: Lut,
    centre_lut: Lut,
}

impl CellAxis {
    fn new(bounds: &[f64]) -> CellAxis {
        let bounds: Vec<f32> = bounds.iter().map(|&b| b as f32).collect();
        let centres: Vec<f32> = bounds.windows(2).map(|w| 0.5 * (w[0] + w[1])).collect();
        let (lo, hi) = (bounds[0], bounds[bounds.len() - 1]);
        CellAxis {
            bound_lut: Lut::new(&bounds, lo, hi),
            centre_lut: Lut::new(&centres, lo, hi),
            bounds,
            centres,
        }
    }

    fn len(&self) -> usize {
        self.centres.len()
    }

    /// The first cell whose centre is ≥ x.
    #[inline]
    fn first_centre(&self, x: f32) -> usize {
        self.centre_lut.first_ge(&self.centres, x)
    }

    /// The cells whose intervals meet [x0, x1].
    #[inline]
    fn cells_meeting(&self, x0: f32, x1: f32) -> std::ops::Range<usize> {
        let a = self.bound_lut.first_ge(&self.bounds, x0).saturating_sub(1);
        let b = self.bound_lut.first_ge(&self.bounds, x1).min(self.len());
        a..b
    }
}

/// Sec. 2's look-up table from a regular grid onto a sorted array: bin k holds the first index
/// whose value is ≥ the bin's start.
#[derive(Clone, Debug)]
struct Lut {
    lo: f32,
    scale: f32,
    first: Vec<u32>,
}

impl Lut {
    fn new(values: &[f32], lo: f32, hi: f32) -> Lut {
        let span = (hi - lo).max(f32::MIN_POSITIVE);
        // Bins no wider than the smallest gap hold at most one value each: one correction step.
        let gap = values
            .windows(2)
            .map(|w| w[1] - w[0])
            .fold(span, f32::min)
            .max(span / 65_536.0);
        let bins = ((span / gap).ceil() as usize).max(1);
        let scale = bins as f32 / span;
        let first = (0..bins)
            .map(|k| values.partition_point(|&x| x < lo + k as f32 / scale) as u32)
            .collect();
        Lut { lo, scale, first }
    }

    /// The first index i with values[i] ≥ x (values.len() if none).
    #[inline]
    fn first_ge(&self, values: &[f32], x: f32) -> usize {
        let k = (((x - self.lo) * self.scale) as isize).clamp(0, self.first.len() as isize - 1);
        let mut i = self.first[k as usize] as usize;
        // Rounding of the bin's start can leave the table one step off either way.
        while i < values.len() && values[i] < x {
            i += 1;
        }
        while i > 0 && values[i - 1] >= x {
            i -= 1;
        }
        i
    }
}

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
    fn reset(&mut self, cells: usize, patches: usize) {
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
    /// The uniform N×N hemi-cube (Cohen & Greenberg 1985): top N×N, sides N×N/2 (N even; an odd
    /// N is rounded up), ΔF from the closed-form table at the cell centres, normalised so they
    /// sum to exactly 1.
    pub fn uniform(n: usize) -> Hemicube {
        let n = (n.max(2) + 1) & !1;
        let h = 2.0 / n as f64;
        let across: Vec<f64> = (0..=n).map(|k| -1.0 + k as f64 * h).collect();
        let up: Vec<f64> = (0..=n / 2).map(|k| k as f64 * h).collect();
        let da = h * h;
        let centres =
            |b: &[f64]| -> Vec<f64> { b.windows(2).map(|w| 0.5 * (w[0] + w[1])).collect() };
        let (cx, cz) = (centres(&across), centres(&up));
        let top = cx
            .iter()
            .flat_map(|&y| {
                cx.iter()
                    .map(move |&x| da / (PI * (x * x + y * y + 1.0).powi(2)))
            })
            .collect();
        let side = cz
            .iter()
            .flat_map(|&z| {
                cx.iter()
                    .map(move |&y| z * da / (PI * (y * y + z * z + 1.0).powi(2)))
            })
            .collect();
        Hemicube::build(n, true, &across, &up, top, side, true)
    }

    /// The paper's non-uniform hemi-cube for resolution N (N odd, ≥ 3; an even N is rounded
    /// up): the central cell is the uniform N×N cube's, [-1/N, 1/N]², with ΔF ≈ 4/(πN²), and
    /// the other cells grow so each carries about as much but no more (Sec. 2; the module docs
    /// give the recurrences and the edge rule). Each cell's ΔF is its exact integral, so they
    /// sum to 1 without normalising.
    pub fn non_uniform(n: usize) -> Hemicube {
        let n = n.max(3) | 1;
        let (half, s_top) = diagonal_bounds(n);
        let across: Vec<f64> = half
            .iter()
            .rev()
            .map(|&x| -x)
            .chain(half.iter().copied())
            .collect();
        // The side's cells ask s_top·s_side/π = 4/(πN²) of the top's lowered s_top before
        // their own bisection (only the central column, 2/N wide, can pass it: by ≤ 1.4 %).
        let s = 2.0 / n as f64;
        let up = side_bounds(s * s / s_top);
        let top = integrated(&across, &across, top_corner_ff);
        let side = integrated(&across, &up, side_corner_ff);
        Hemicube::build(n, false, &across, &up, top, side, false)
    }

    /// Lays out the five faces on the given boundaries (`across`: u of every face and v of the
    /// top, from −1 to 1; `up`: v of the sides, from 0 to 1) with ΔF per cell of the top face
    /// and of one side face (the four are alike), each row-major.
    fn build(
        n: usize,
        uniform: bool,
        across: &[f64],
        up: &[f64],
        top: Vec<f64>,
        side: Vec<f64>,
        normalise: bool,
    ) -> Hemicube {
        // (w, u, v) per face as (local axis, sign): top (z, x, y); sides (±x, y, z), (±y, x, z).
        let axes: [[(usize, f32); 3]; 5] = [
            [(2, 1.0), (0, 1.0), (1, 1.0)],
            [(0, 1.0), (1, 1.0), (2, 1.0)],
            [(0, -1.0), (1, 1.0), (2, 1.0)],
            [(1, 1.0), (0, 1.0), (2, 1.0)],
            [(1, -1.0), (0, 1.0), (2, 1.0)],
        ];
        let mut first = 0;
        let faces = axes.map(|axes| {
            let top = axes[0].0 == 2;
            let face = Face {
                axes,
                v_lo: if top { -1.0 } else { 0.0 },
                u: CellAxis::new(across),
                v: CellAxis::new(if top { across } else { up }),
                first,
            };
            first += face.cells();
            face
        });
        let mut delta_ff = top;
        for _ in 1..5 {
            delta_ff.extend_from_slice(&side);
        }
        debug_assert_eq!(delta_ff.len(), first);
        if normalise {
            let sum: f64 = delta_ff.iter().sum();
            delta_ff.iter_mut().for_each(|d| *d /= sum);
        }
        let min_ff = delta_ff.iter().copied().fold(f64::INFINITY, f64::min);
        let max_ff = delta_ff.iter().copied().fold(0.0, f64::max);
        let sum_ff = delta_ff.iter().sum();
        Hemicube {
            n,
            uniform,
            faces,
            delta_ff,
            min_ff,
            max_ff,
            sum_ff,
        }
    }

    /// N: the top face's resolution (uniform: N×N cells; non-uniform: central cell 2/N wide).
    pub fn resolution(&self) -> usize {
        self.n
    }

    /// Whether this is the uniform (Cohen & Greenberg) cube.
    pub fn is_uniform(&self) -> bool {
        self.uniform
    }

    pub fn cell_count(&self) -> usize {
        self.delta_ff.len()
    }

    /// ΔF per cell (top face, then +x, −x, +y, −y; each row-major, v rows of u cells).
    pub fn delta_ffs(&self) -> &[f64] {
        &self.delta_ff
    }

    pub fn max_delta_ff(&self) -> f64 {
        self.max_ff
    }

    pub fn delta_ff_sum(&self) -> f64 {
        self.sum_ff
    }

    /// Min and max ΔF over cells (for the spread bound).
    pub fn delta_ff_range(&self) -> (f64, f64) {
        (self.min_ff, self.max_ff)
    }

    /// Renders every patch of `mesh` except `shooter` as seen from `eye` in `frame` (frame.n =
    /// the shooter's normal; the top face looks along n, the sides along ±t, ±b) into a z-buffer
    /// holding the nearest patch id per cell, and writes
    /// into `out` (cleared first), sorted by patch id, (patch id, F = Σ ΔF of its cells,
    /// seen_from_back) for every patch with F > 0. Returns the work it did, counted (the
    /// hybrid's cost model weighs these counts, Sec. 4).
    ///
    /// With `jitter`, every cell's sample point is drawn uniformly inside its cell (the paper's
    /// "jittered hemi-cube", Table 1) instead of its centre. Patches wholly within a tiny
    /// epsilon of the base plane (the shooter's own plane) are culled, the others clipped
    /// against it (z ≥ 0 in the frame) and against each face's frustum before scan conversion.
    /// Back faces are drawn too (they occlude); the caller learns they were seen from behind.
    ///
    /// The steps: size and clear the buffers; draw the jittered sample points; per patch, into
    /// the frame ([`to_frame`]) and onto the faces ([`Hemicube::draw_patch`]); read the cells
    /// back ([`Hemicube::read_back`]).
    #[allow(clippy::too_many_arguments)]
    pub fn shoot<R: Rng>(
        &self,
        mesh: &Mesh,
        shooter: usize,
        eye: Vec3,
        frame: &Frame,
        jitter: Option<&mut R>,
        buf: &mut HemicubeBuffer,
        out: &mut Vec<(u32, f64, bool)>,
    ) -> ShotWork {
        out.clear();
        buf.reset(self.cell_count(), mesh.patches.len());
        let mut work = ShotWork {
            cells: self.cell_count() as u64,
            ..ShotWork::default()
        };
        let jittered = match jitter {
            Some(rng) => {
                self.draw_sample_points(rng, buf);
                true
            }
            None => false,
        };
        // Patches in the shooter's own plane (z ≈ 0 up to f32 rounding of coordinates of this
        // size) and edge-on ones must not be drawn.
        let eps = 1e-5 * (1.0 + eye.abs().max_element());
        for j in 0..mesh.patches.len() {
            if j == shooter {
                continue;
            }
            work.patches += 1;
            if let Some(plane) = to_frame(mesh, j, eye, frame, eps, buf) {
                self.draw_patch(j as u32, plane, jittered, buf, &mut work);
            }
        }
        self.read_back(mesh, eye, buf, out);
        work
    }

    /// Jitter: one random point per cell, drawn in cell order before any drawing.
    fn draw_sample_points<R: Rng>(&self, rng: &mut R, buf: &mut HemicubeBuffer) {
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
    fn draw_patch(
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
    fn read_back(
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
                out.push((j, f, p.normal.dot(eye - p.centre) < 0.0));
            }
        }
    }
}

/// A patch's plane in the shooter's frame: n·p = d (d < 0: its front faces the eye).
#[derive(Clone, Copy)]
struct FramePlane {
    normal: [f32; 3],
    d: f32,
}

/// Patch `j` into the frame, relative to the eye, into `buf.local`, clipped to the base plane
/// z ≥ 0; `None` when it is wholly under the base plane (within `eps`), edge-on, or clipped
/// away.
fn to_frame(
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

/// Sec. 2: the positive cell boundaries along the top face's diagonal, x_0 = 1/N, …, 1, and
/// the step constant they were made with (see [`fill_axis`] for how the edge is met).
fn diagonal_bounds(n: usize) -> (Vec<f64>, f64) {
    fill_axis(1.0 / n as f64, 1.0, 2.0 / n as f64, diagonal_step)
}

/// Cell boundaries up a side face, 0 … 1, made from the top edge down with step constant s
/// (see [`side_step`]).
fn side_bounds(s: f64) -> Vec<f64> {
    let mut b = fill_axis(1.0, 0.0, s, side_step).0;
    b.reverse();
    b
}

/// Steps from `start` towards `edge` by `step(position, t)`, ending exactly on the edge, and
/// the t used.
///
/// The recurrence at the asked t = s rarely lands on the edge: k whole steps fit and a
/// remainder is left. Merging a short remainder into its neighbour (or keeping it) would leave
/// one column of cells up to 1.5× (and its corner 2.25×) or down to ~0 of the target,
/// depending on N. Instead the remainder becomes a step of its own and t is lowered, by
/// bisection, until k + 1 steps end exactly on the edge: every step's cell on the diagonal then
/// carries the same t·s/π ≤ s²/π. A step that cannot be taken (the rest of the axis carries
/// less than one cell's worth) counts as passing the edge.
fn fill_axis(start: f64, edge: f64, s: f64, step: fn(f64, f64) -> Option<f64>) -> (Vec<f64>, f64) {
    let dir = (edge - start).signum();
    // How far past the edge `steps` steps at t end (None: a step failed, i.e. passed).
    let past = |t: f64, steps: usize| -> Option<f64> {
        let mut p = start;
        for _ in 0..steps {
            p += dir * step(p, t)?;
        }
        Some((p - edge) * dir)
    };
    // Whole steps at s until one reaches or passes the edge.
    let mut steps = 1;
    let mut p = start;
    while let Some(d) = step(p, s) {
        p += dir * d;
        if (p - edge) * dir >= -1e-12 {
            break;
        }
        steps += 1;
    }
    // The largest t ≤ s whose steps do not pass the edge; steps grow with t.
    let t = if past(s, steps).is_some_and(|e| e.abs() <= 1e-12) {
        s
    } else {
        let (mut lo, mut hi) = (0.0, s);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            match past(mid, steps) {
                Some(e) if e <= 0.0 => lo = mid,
                _ => hi = mid,
            }
        }
        lo
    };
    let mut b = vec![start];
    for _ in 0..steps {
        let p = b[b.len() - 1];
        match step(p, t) {
            Some(d) => b.push(p + dir * d),
            None => break,
        }
    }
    // The last step ends on the edge to rounding (or, for tiny N where no t fits, short of it).
    if b.len() > steps {
        *b.last_mut().unwrap() = edge;
    } else {
        b.push(edge);
    }
    (b, t)
}

/// One step of the top face's diagonal recurrence from x:
/// (x_{i+1} − x_i)² / (2((x_i + x_{i+1})/2)² + 1)² = s² (the paper's s = 2/N). With Δ the
/// step and m = x + Δ/2, Δ = s(2m² + 1) is the quadratic (s/2)Δ² + (2sx − 1)Δ + s(2x² + 1) = 0,
/// whose smaller root is the step; None if no cell this far out carries s²/π.
fn diagonal_step(x: f64, s: f64) -> Option<f64> {
    let p = 1.0 - 2.0 * s * x;
    let disc = p * p - 2.0 * s * s * (2.0 * x * x + 1.0);
    (p > 0.0 && disc >= 0.0).then(|| (p - disc.sqrt()) / s)
}

/// One step down a side face from height v. The cell on the side face's own diagonal u = v = m
/// has the top face's width there, Δu = s_top(2m² + 1), and carries ≈ Δu·Δv·m/(π(2m²+1)²);
/// asking s_top·s/π of it gives Δv·m = s(2m² + 1), with m = v − Δv/2 the quadratic
/// 2(1 + s)m² − 2v·m + s = 0, whose larger root is the step's midpoint. None if even the cell
/// down to the base carries less.
fn side_step(v: f64, s: f64) -> Option<f64> {
    let disc = v * v - 2.0 * s * (1.0 + s);
    (disc >= 0.0).then(|| 2.0 * (v - (v + disc.sqrt()) / (2.0 * (1.0 + s))))
}

/// ΔF per cell (row-major, v rows of u cells) from an antiderivative `f` of the face's
/// density, evaluated once per grid corner: ∫∫ over [u0, u1]×[v0, v1] = f(u1, v1) − f(u0, v1)
/// − f(u1, v0) + f(u0, v0).
fn integrated(u: &[f64], v: &[f64], f: impl Fn(f64, f64) -> f64) -> Vec<f64> {
    let corners: Vec<f64> = v
        .iter()
        .flat_map(|&y| u.iter().map(move |&x| (x, y)))
        .map(|(x, y)| f(x, y))
        .collect();
    let w = u.len();
    let mut out = Vec::with_capacity((u.len() - 1) * (v.len() - 1));
    for r in 0..v.len() - 1 {
        for i in 0..w - 1 {
            let (a, b) = (r * w + i, (r + 1) * w + i);
            out.push(corners[b + 1] - corners[b] - corners[a + 1] + corners[a]);
        }
    }
    out
}

/// Form factor from a differential area at the origin (normal z) to the rectangle
/// [0, x]×[0, y] of the plane z = 1 (odd in x and in y, so signed corners sum any cell).
fn top_corner_ff(x: f64, y: f64) -> f64 {
    let a = (1.0 + x * x).sqrt();
    let b = (1.0 + y * y).sqrt();
    (x / a * (y / a).atan() + y / b * (x / b).atan()) / (2.0 * PI)
}

/// An antiderivative in (y, z) of the side density z/(π(y²+z²+1)²) on the plane x = 1:
/// ∂²/∂y∂z of −atan(y/√(1+z²)) / (2π√(1+z²)).
fn side_corner_ff(y: f64, z: f64) -> f64 {
    let s = (1.0 + z * z).sqrt();
    -(y / s).atan() / (2.0 * PI * s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{newell, Patch, PatchClass};
    use rand::SeedableRng;
    use rand_pcg::Pcg64Mcg;

    /// Quads with centre c and half-edge vectors e1, e2, facing e1 × e2.
    fn quad_mesh(quads: &[(Vec3, Vec3, Vec3)]) -> Mesh {
        let mut mesh = Mesh::default();
        for (k, &(c, e1, e2)) in quads.iter().enumerate() {
            let pts = [c - e1 - e2, c + e1 - e2, c + e1 + e2, c - e1 + e2];
            let first = mesh.patch_vertices.len() as u32;
            for p in pts {
                mesh.patch_vertices.push(mesh.vertices.len() as u32);
                mesh.vertices.push(p);
            }
            let n = newell(&pts);
            mesh.patches.push(Patch {
                first,
                count: 4,
                material: 0,
                polygon: k as u32,
                area: n.length() as f64 * 0.5,
                centre: c,
                normal: n.normalize(),
                class: PatchClass::Skew,
            });
        }
        mesh
    }

    /// Unit square at the origin facing +z (the shooter) and `others`.
    fn scene(others: &[(Vec3, Vec3, Vec3)]) -> Mesh {
        let mut quads = vec![(Vec3::ZERO, Vec3::X * 0.5, Vec3::Y * 0.5)];
        quads.extend_from_slice(others);
        quad_mesh(&quads)
    }

    fn parallel_receiver() -> (Vec3, Vec3, Vec3) {
        // At z = 1 facing down (−z) towards the shooter.
        (Vec3::Z, Vec3::Y * 0.5, Vec3::X * 0.5)
    }

    /// Point on the axis at distance 1 from a unit square: 4 corner rectangles of 0.5 × 0.5.
    fn parallel_exact() -> f64 {
        4.0 * top_corner_ff(0.5, 0.5)
    }

    /// Sharing the shooter's edge x = 0.5, standing up to z = 1, facing −x.
    fn perpendicular_receiver() -> (Vec3, Vec3, Vec3) {
        (Vec3::new(0.5, 0.0, 0.5), Vec3::Z * 0.5, Vec3::Y * 0.5)
    }

    /// Point to a perpendicular rectangle at distance c = 0.5, y ∈ [−0.5, 0.5], z ∈ [0, 1]:
    /// scaled by 1/c, y ∈ [−1, 1], z ∈ [0, 2] on the plane x = 1.
    fn perpendicular_exact() -> f64 {
        2.0 * (side_corner_ff(1.0, 2.0) - side_corner_ff(1.0, 0.0))
    }

    fn shoot_once(cube: &Hemicube, mesh: &Mesh, angle: f32) -> Vec<(u32, f64, bool)> {
        let mut buf = HemicubeBuffer::default();
        let mut out = Vec::new();
        let frame = Frame::new(mesh.patches[0].normal, angle);
        cube.shoot::<Pcg64Mcg>(
            mesh,
            0,
            mesh.patches[0].centre,
            &frame,
            None,
            &mut buf,
            &mut out,
        );
        out
    }

    fn f_of(out: &[(u32, f64, bool)], j: u32) -> f64 {
        out.iter().find(|o| o.0 == j).map_or(0.0, |o| o.1)
    }

    #[test]
    fn closed_forms_agree_with_textbook_values() {
        // Parallel unit squares at distance 1: 0.1998 between the squares (Howell's C-11);
        // from the centre point it is larger, 0.2394. Perpendicular, from the centre point of
        // the shared-edge square: 0.25 − atan(1/√5)/(π√5) = 0.1901.
        assert!(
            (parallel_exact() - 0.239_45).abs() < 1e-4,
            "{}",
            parallel_exact()
        );
        assert!((perpendicular_exact() - 0.190_14).abs() < 1e-4);
    }

    #[test]
    fn delta_ff_sums_to_one() {
        // Uniform: normalised by construction; non-uniform: exact integrals, no normalising —
        // either way only f64 rounding over ≤ 30k terms remains (~1e-13); 1e-6 is the spec.
        for n in [10, 50, 100] {
            let c = Hemicube::uniform(n);
            assert_eq!(c.cell_count(), 3 * n * n);
            assert!((c.delta_ff_sum() - 1.0).abs() < 1e-6, "uniform {n}");
        }
        for n in [5, 21, 51, 101] {
            let c = Hemicube::non_uniform(n);
            assert!((c.delta_ff_sum() - 1.0).abs() < 1e-6, "non-uniform {n}");
            let raw: f64 = c.delta_ffs().iter().sum();
            assert!((raw - 1.0).abs() < 1e-12, "non-uniform {n}: {raw}");
        }
    }

    #[test]
    fn uniform_max_is_the_top_centre_cell() {
        for n in [10, 50, 100] {
            let c = Hemicube::uniform(n);
            let target = 4.0 / (PI * (n * n) as f64);
            // The centre cells sit at (±1/N, ±1/N): (1 + 2/N²)^−2 ≈ 1 − 4/N², and the
            // normalisation moves the sum by O(1/N²) too; 10/N² covers both.
            let tol = 10.0 / (n * n) as f64;
            assert!((c.max_delta_ff() / target - 1.0).abs() < tol, "{n}");
            let argmax = (0..c.cell_count())
                .max_by(|&a, &b| c.delta_ff[a].total_cmp(&c.delta_ff[b]))
                .unwrap();
            let (r, i) = (argmax / n, argmax % n);
            assert!(
                argmax < n * n && (r == n / 2 || r == n / 2 - 1) && (i == n / 2 || i == n / 2 - 1)
            );
        }
    }

    #[test]
    fn non_uniform_layout_is_symmetric_and_odd() {
        let c = Hemicube::non_uniform(20);
        assert_eq!(c.resolution(), 21);
        let b = &c.faces[0].u.bounds;
        let k = b.len() - 1;
        assert!(k % 2 == 1, "odd cell count across");
        assert!((b[k / 2] + 1.0 / 21.0).abs() < 1e-7 && (b[k / 2 + 1] - 1.0 / 21.0).abs() < 1e-7);
        for i in 0..=k {
            assert!((b[i] + b[k - i]).abs() < 1e-7);
        }
        assert_eq!(c.faces[1].v.bounds[0], 0.0);
        assert_eq!(*c.faces[1].v.bounds.last().unwrap(), 1.0);
    }

    /// The target 4/(πN²) (the top face's centre cell) and the non-uniform ΔF per cell over it.
    fn ratios(c: &Hemicube) -> (f64, Vec<f64>) {
        let target = 4.0 / (PI * (c.n * c.n) as f64);
        (target, c.delta_ffs().iter().map(|f| f / target).collect())
    }

    /// Spread of the non-uniform ΔF over every odd N from 21 to 301, measured: max/target ≤
    /// 1.0135 (N = 67; the side faces' central column, which is the full 2/N wide while the
    /// lowered top step is narrower), min/target ≥ 0.669 (off-diagonal cells: (2a+1)(2b+1)/
    /// (a+b+1)² ≥ 3/4 at a = x², b = y² ≤ 1, times the lowered step's (t/s)²). The top face's
    /// diagonal cells agree among themselves within 0.83 % and carry 0.823–1.0014 of the
    /// target (N = 51: 0.967–0.969; N = 101: 0.977–0.978).
    #[test]
    fn non_uniform_spread_is_bounded() {
        for n in (21..=301).step_by(2) {
            let c = Hemicube::non_uniform(n);
            let (_, r) = ratios(&c);
            let (lo, hi) = r
                .iter()
                .fold((f64::INFINITY, 0.0f64), |(a, b), &x| (a.min(x), b.max(x)));
            // No cell above the centre's 4/(πN²) but for the central column's ≤ 1.4 %.
            assert!(hi < 1.02, "{n}: max {hi}");
            // ≥ 3/4 · (t/s)² with (t/s)² ≥ 0.82, less the midpoint rule's O(Δ²): 0.6.
            assert!(lo > 0.6, "{n}: min {lo}");
            // The diagonal cells of the top face (beyond the centre): all the same s²/π up to
            // the midpoint rule's O(Δ²) (≤ 0.83 % measured; 1.5 % allowed), ≤ the target.
            let k = c.faces[0].u.len();
            let diag: Vec<f64> = (k / 2 + 1..k).map(|d| r[d * k + d]).collect();
            let (dlo, dhi) = diag
                .iter()
                .fold((f64::INFINITY, 0.0f64), |(a, b), &x| (a.min(x), b.max(x)));
            assert!(
                dhi / dlo < 1.015 && dhi < 1.005 && dlo > 0.8,
                "{n}: diagonal {dlo}..{dhi}"
            );
            if n == 51 || n == 101 {
                // Lowering s fills the axis with whole steps: by (k/(k+1))² at worst, here
                // within 4 % (measured 3.3 % and 2.3 %).
                assert!(dlo > 0.96, "{n}: diagonal {dlo}");
            }
        }
    }

    /// Sec. 1: cells of equal ΔF = 4/(πN²) would need π/12 of the uniform 3N². Measured: the
    /// non-uniform cube has 1.079× (N = 51), 1.077× (N = 101) and at most 1.187× (odd N from
    /// 21 to 301) that count; its largest cell is the uniform cube's.
    #[test]
    fn non_uniform_cell_count_is_near_pi_over_12() {
        for n in (21..=301).step_by(2) {
            let c = Hemicube::non_uniform(n);
            let ideal = PI / 12.0 * (3 * n * n) as f64;
            let ratio = c.cell_count() as f64 / ideal;
            // Never below 1/max (no cell carries more than max ΔF ≤ 1.0135 × target); cells
            // average 0.84–0.93 of the target (the off-diagonal ones carry less): ≤ 1.2.
            assert!(ratio > 0.98 && ratio < 1.2, "{n}: {ratio}");
            if n == 51 || n == 101 {
                assert!(ratio < 1.1, "{n}: {ratio}");
            }
        }
        // The same largest ΔF as the uniform cube of the same N (its centre cells sit at
        // ±1/N, (1 + 2/N²)^−2 below 4/(πN²)): within 1 % at N = 101.
        let (nu, un) = (Hemicube::non_uniform(101), Hemicube::uniform(100));
        let (t, _) = ratios(&nu);
        assert!((nu.max_delta_ff() / t - 1.0).abs() < 0.01);
        assert!((un.max_delta_ff() / (4.0 / (PI * 1e4)) - 1.0).abs() < 0.01);
    }

    #[test]
    fn lut_matches_binary_search() {
        let mut rng = Pcg64Mcg::seed_from_u64(3);
        for c in [
            Hemicube::uniform(100),
            Hemicube::non_uniform(51),
            Hemicube::non_uniform(5),
        ] {
            for face in &c.faces {
                for axis in [&face.u, &face.v] {
                    for _ in 0..2000 {
                        let x = rng.gen_range(-1.2f32..1.2);
                        assert_eq!(
                            axis.first_centre(x),
                            axis.centres.partition_point(|&c| c < x)
                        );
                        let b = axis.bound_lut.first_ge(&axis.bounds, x);
                        assert_eq!(b, axis.bounds.partition_point(|&c| c < x));
                    }
                    // Exactly on every value, too.
                    for (k, &x) in axis.centres.iter().enumerate() {
                        assert_eq!(axis.first_centre(x), k);
                    }
                }
            }
        }
    }

    /// Single shots at angles away from the grid's axes and diagonals, and the average over
    /// the rotation (what the solvers' random turn per shot gives).
    ///
    /// Measured over 200 angles (parallel / perpendicular): uniform 100: median |error|
    /// 6.0e-5 / 1.7e-5, 90th percentile 3.1e-4 / 7.7e-5, worst 1.5e-3 / 7.6e-4; non-uniform
    /// 51: median 9.0e-4 / 2.2e-4, 90th percentile 4.1e-3 / 1.0e-3, worst 9.5e-3 / 5.1e-3;
    /// non-uniform 101: median 3.9e-4 / 9.7e-5, worst 5.8e-3 / 2.1e-3. The worst cases are
    /// angles where the square's edges run along the cells' rows (or, for the uniform cube,
    /// diagonals), or exactly through a column of cell centres: then a whole column is in or
    /// out together, up to half of its ΔF. Averaged over the 200 angles: 4.0e-5 / 9.2e-6
    /// (uniform 100), 5.2e-5 / 1.5e-4 (non-uniform 51).
    #[test]
    fn form_factors_match_closed_forms() {
        let par = scene(&[parallel_receiver()]);
        let perp = scene(&[perpendicular_receiver()]);
        let cases = [(&par, parallel_exact()), (&perp, perpendicular_exact())];
        // Edge aliasing at a generic angle: each cell the outline cuts counts whole or not at
        // all, ± up to half its ΔF with varying sign; ~200 such cells of 1.3e-4 (uniform 100)
        // or ~70 of ≤ 4.9e-4 (non-uniform 51) give a few 1e-4 to 3e-3 (the 90th
        // percentiles above); the tolerances sit above those.
        for (cube, tol, mean_tol) in [
            (Hemicube::uniform(100), 1.0e-3, 2.0e-4),
            (Hemicube::non_uniform(51), 5.0e-3, 5.0e-4),
        ] {
            for (k, &(mesh, exact)) in cases.iter().enumerate() {
                for angle in [0.3f32, 1.9, 4.4, 5.2] {
                    let f = f_of(&shoot_once(&cube, mesh, angle), 1);
                    assert!(
                        (f - exact).abs() < tol,
                        "case {k} N={} {angle}: {f} vs {exact}",
                        cube.n
                    );
                }
                // Over the rotation the in/out errors cancel: what is left is the ΔF table's
                // own error (uniform: the centre-value table, O(1/N²)) and residual aliasing.
                let shots = 64;
                let mean = (0..shots)
                    .map(|a| {
                        let angle = (a as f32 + 0.5) / shots as f32 * std::f32::consts::TAU;
                        f_of(&shoot_once(&cube, mesh, angle), 1)
                    })
                    .sum::<f64>()
                    / shots as f64;
                assert!(
                    (mean - exact).abs() < mean_tol,
                    "case {k} N={} mean {mean} vs {exact}",
                    cube.n
                );
            }
        }
    }

    /// The paper's jittered hemi-cube (Table 1: 100×100, each sample uniform in its cell),
    /// averaged over 200 shots with random turns about the normal. Measured over 2,000 shots:
    /// uniform 100: mean error −3.6e-5, single-shot sd 4.2e-4; non-uniform 51: −2.1e-4, sd
    /// 1.8e-3. Uniform-in-cell jitter has an O(Δ²) bias: a cell the outline cuts is counted
    /// with its mean density, while its covered part lies nearer the centre where the density
    /// is higher (non-uniform 15: −2.9e-3, 14 standard errors).
    #[test]
    fn jittered_average_matches_closed_form() {
        let mesh = scene(&[parallel_receiver()]);
        let exact = parallel_exact();
        let mut rng = Pcg64Mcg::seed_from_u64(11);
        let mut buf = HemicubeBuffer::default();
        let mut out = Vec::new();
        for (cube, bias) in [
            (Hemicube::uniform(100), 1e-4),
            (Hemicube::non_uniform(51), 5e-4),
        ] {
            let shots = 200;
            let (mut sum, mut sum2) = (0.0, 0.0);
            for _ in 0..shots {
                let frame = Frame::new(Vec3::Z, rng.gen::<f32>() * std::f32::consts::TAU);
                let mut jit = Pcg64Mcg::seed_from_u64(rng.gen());
                cube.shoot(
                    &mesh,
                    0,
                    Vec3::ZERO,
                    &frame,
                    Some(&mut jit),
                    &mut buf,
                    &mut out,
                );
                let f = f_of(&out, 1);
                sum += f;
                sum2 += f * f;
            }
            let mean = sum / shots as f64;
            let sd = (sum2 / shots as f64 - mean * mean).max(0.0).sqrt();
            // 5 standard errors of the mean plus the bias allowance (≥ 2× the measured bias).
            let tol = 5.0 * sd / (shots as f64).sqrt() + bias;
            assert!(
                (mean - exact).abs() < tol,
                "N={}: {mean} vs {exact} (sd {sd})",
                cube.n
            );
            assert!(sd > 0.0, "jitter changes the answer from shot to shot");
        }
    }

    #[test]
    fn blocker_takes_the_receivers_share() {
        // Receiver at z = 1; a 2×2 blocker at z = 0.5 covers its whole cone from the centre.
        let receiver = parallel_receiver();
        let blocker = (Vec3::Z * 0.5, Vec3::Y, Vec3::X);
        let both = scene(&[receiver, blocker]);
        let alone = scene(&[blocker]);
        for cube in [Hemicube::uniform(100), Hemicube::non_uniform(51)] {
            let out = shoot_once(&cube, &both, 0.7);
            assert_eq!(f_of(&out, 1), 0.0, "receiver hidden");
            assert_eq!(out.len(), 1);
            // The blocker gets exactly what it gets alone (the receiver wins no cell of it).
            let f = f_of(&out, 2);
            assert_eq!(f, f_of(&shoot_once(&cube, &alone, 0.7), 1));
            // Half-sides 1 at distance 0.5 = half-sides 2 at distance 1: F = 0.831. Its
            // outline runs over the side faces at v = 0.5, where non-uniform 51 cells carry
            // up to 4.9e-4 each, ~70 of them: up to 1e-2 (measured 4.9e-3 at this angle; uniform
            // 100: 2.3e-4).
            let exact = 4.0 * top_corner_ff(2.0, 2.0);
            assert!((f - exact).abs() < 1e-2, "N={}: {f} vs {exact}", cube.n);
        }
    }

    #[test]
    fn receiver_facing_away_is_seen_from_back() {
        // At z = 1 facing +z: its back faces the shooter.
        let mesh = scene(&[
            (Vec3::Z, Vec3::X * 0.5, Vec3::Y * 0.5),
            perpendicular_receiver(),
        ]);
        let out = shoot_once(&Hemicube::non_uniform(51), &mesh, 0.2);
        assert_eq!(out.len(), 2);
        assert_eq!(out[0].0, 1);
        assert!(out[0].2, "back");
        assert!(
            (out[0].1 - parallel_exact()).abs() < 3e-3,
            "a back face still counts"
        );
        assert!(!out[1].2, "front");
    }

    #[test]
    fn patches_in_the_base_plane_are_not_drawn() {
        // A neighbour in the shooter's plane, facing up too: nothing but the far receiver.
        let mesh = scene(&[(Vec3::X, Vec3::X * 0.5, Vec3::Y * 0.5), parallel_receiver()]);
        let out = shoot_once(&Hemicube::uniform(50), &mesh, 0.4);
        assert_eq!(out.iter().map(|o| o.0).collect::<Vec<_>>(), vec![2]);
    }

    /// A closed 1×1×1 box of 2×2 patches per wall, all facing in (the vertices of neighbouring
    /// patches computed apart, so shared edges differ by rounding), and a tilted blocker inside.
    fn box_mesh() -> Mesh {
        let h = 0.25;
        let mut quads = Vec::new();
        for (c, e1, e2) in [
            (Vec3::ZERO, Vec3::X, Vec3::Y),
            (Vec3::Z, Vec3::Y, Vec3::X),
            (Vec3::new(0.5, 0.0, 0.5), Vec3::Z, Vec3::Y),
            (Vec3::new(-0.5, 0.0, 0.5), Vec3::Y, Vec3::Z),
            (Vec3::new(0.0, 0.5, 0.5), Vec3::X, Vec3::Z),
            (Vec3::new(0.0, -0.5, 0.5), Vec3::Z, Vec3::X),
        ] {
            for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
                quads.push((c + (e1 * a + e2 * b) * h, e1 * h, e2 * h));
            }
        }
        quads.push((
            Vec3::new(0.1, 0.0, 0.4),
            Vec3::new(0.2, 0.0, 0.1),
            Vec3::Y * 0.2,
        ));
        quad_mesh(&quads)
    }

    /// Inside a closed box every shot sees its whole hemisphere: the form factors sum to
    /// Σ ΔF = 1 (to f64 rounding over ≤ 30k cells), with and without jitter, also when the
    /// frame is square to the walls and cell centres fall exactly on edges patches share
    /// (the blocker's normal ray hits the ceiling's middle edge).
    #[test]
    fn closed_box_sums_to_one() {
        let mesh = box_mesh();
        let mut rng = Pcg64Mcg::seed_from_u64(9);
        let mut buf = HemicubeBuffer::default();
        let mut out = Vec::new();
        for cube in [
            Hemicube::uniform(30),
            Hemicube::non_uniform(31),
            Hemicube::non_uniform(101),
        ] {
            for angle in [
                0.0f32,
                std::f32::consts::FRAC_PI_4,
                std::f32::consts::FRAC_PI_2,
                0.5,
                2.0,
            ] {
                for (i, p) in mesh.patches.iter().enumerate() {
                    let frame = Frame::new(p.normal, angle);
                    for jitter in [false, true] {
                        let jit = jitter.then_some(&mut rng);
                        cube.shoot(&mesh, i, p.centre, &frame, jit, &mut buf, &mut out);
                        let total: f64 = out.iter().map(|o| o.1).sum();
                        let msg = format!("N={} angle {angle} shooter {i} jitter {jitter}", cube.n);
                        assert!((total - 1.0).abs() < 1e-9, "{msg}: {total}");
                        // The walls face in; only the blocker can be seen from behind.
                        assert!(out.iter().all(|o| !o.2 || o.0 == 24), "{msg}");
                    }
                }
            }
        }
    }

    #[test]
    fn buffers_carry_nothing_between_shots() {
        let mesh = scene(&[parallel_receiver(), perpendicular_receiver()]);
        let cube = Hemicube::non_uniform(31);
        let mut buf = HemicubeBuffer::default();
        let (mut a, mut b, mut c) = (Vec::new(), Vec::new(), Vec::new());
        let f0 = Frame::new(Vec3::Z, 0.3);
        let p1 = &mesh.patches[1];
        let f1 = Frame::new(p1.normal, 1.1);
        let none = None::<&mut Pcg64Mcg>;
        cube.shoot(&mesh, 0, Vec3::ZERO, &f0, none, &mut buf, &mut a);
        cube.shoot::<Pcg64Mcg>(&mesh, 1, p1.centre, &f1, None, &mut buf, &mut b);
        cube.shoot::<Pcg64Mcg>(&mesh, 0, Vec3::ZERO, &f0, None, &mut buf, &mut c);
        assert_eq!(a, c);
        assert!(!b.is_empty() && b.iter().all(|o| o.0 != 1));
    }

    /// Shots run in parallel, one buffer per thread and the RNG seeded per shot (as the solvers
    /// do): the same answers with 1 and 2 threads, bit for bit.
    #[test]
    fn same_answers_with_one_and_two_threads() {
        use rayon::prelude::*;
        let mesh = box_mesh();
        let cube = Hemicube::non_uniform(31);
        let run = |threads: usize, jitter: bool| -> Vec<Vec<(u32, f64, bool)>> {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                (0..mesh.patches.len())
                    .into_par_iter()
                    .map_init(HemicubeBuffer::default, |buf, i| {
                        let mut rng = Pcg64Mcg::seed_from_u64(1000 + i as u64);
                        let p = &mesh.patches[i];
                        let frame = Frame::new(p.normal, rng.gen::<f32>() * std::f32::consts::TAU);
                        let mut out = Vec::new();
                        let jit = jitter.then_some(&mut rng);
                        cube.shoot(&mesh, i, p.centre, &frame, jit, buf, &mut out);
                        out
                    })
                    .collect()
            })
        };
        for jitter in [false, true] {
            let one = run(1, jitter);
            assert_eq!(one, run(2, jitter), "jitter {jitter}");
            assert!(one.iter().all(|out| out.len() > 5));
        }
    }

    /// Time per shot on the default Cornell box, single-threaded, best of 5 rounds of 200 shots
    /// from patches spread over the mesh (run with `--ignored --nocapture`).
    #[test]
    #[ignore]
    fn time_per_shot_on_the_cornell_box() {
        let scene = crate::scene::default_scene(&Default::default()).unwrap();
        let mesh = crate::mesh::build(&scene, &Default::default());
        let mut rng = Pcg64Mcg::seed_from_u64(5);
        for (name, n, uniform, jitter) in [
            ("uniform 100", 100, true, false),
            ("uniform 100 jittered", 100, true, true),
            ("non-uniform 101", 101, false, false),
            ("non-uniform 51", 51, false, false),
            ("non-uniform 21", 21, false, false),
        ] {
            let t = std::time::Instant::now();
            let cube = if uniform {
                Hemicube::uniform(n)
            } else {
                Hemicube::non_uniform(n)
            };
            let build = t.elapsed().as_secs_f64();
            let mut buf = HemicubeBuffer::default();
            let mut out = Vec::new();
            let (shots, mut best, mut seen) = (200, f64::INFINITY, 0);
            for _ in 0..5 {
                let t = std::time::Instant::now();
                for s in 0..shots {
                    let i = (s * 7919) % mesh.patches.len();
                    let p = &mesh.patches[i];
                    let frame = Frame::new(p.normal, rng.gen::<f32>() * std::f32::consts::TAU);
                    let jit = jitter.then_some(&mut rng);
                    cube.shoot(&mesh, i, p.centre, &frame, jit, &mut buf, &mut out);
                    seen += out.len();
                }
                best = best.min(t.elapsed().as_secs_f64() / shots as f64);
            }
            println!(
                "{name}: {} patches, {} cells (built {:.3} ms), {:.3} ms/shot, {:.0} seen",
                mesh.patches.len(),
                cube.cell_count(),
                build * 1e3,
                best * 1e3,
                seen as f64 / (5 * shots) as f64
            );
        }
    }
}
