//! The hemi-cube's cell layouts (Sec. 2): the faces and their cell axes with the look-up
//! tables, the uniform and non-uniform constructors, the diagonal and side-face recurrences
//! and the exact ΔF per cell.

use super::Hemicube;
use std::f64::consts::PI;

/// One face: how frame-local (x, y, z) maps onto it, and its cells.
#[derive(Clone, Debug)]
pub(super) struct Face {
    /// Local coordinate (index, sign) giving w (along the face's axis), then u, then v.
    pub(super) axes: [(usize, f32); 3],
    /// Lower end of v: −1 on the top face, 0 (the base plane) on a side.
    pub(super) v_lo: f32,
    pub(super) u: CellAxis,
    pub(super) v: CellAxis,
    /// Index of the face's first cell.
    pub(super) first: usize,
}

impl Face {
    /// Frame-local point → (w, u·w, v·w).
    #[inline]
    pub(super) fn map(&self, p: [f32; 3]) -> [f32; 3] {
        let [(a, sa), (b, sb), (c, sc)] = self.axes;
        [p[a] * sa, p[b] * sb, p[c] * sc]
    }

    /// Signed distances to the face's frustum (w ± u·w ≥ 0, w − v·w ≥ 0, v·w − v_lo·w ≥ 0);
    /// its four planes pass through the eye, so clipping stays linear in (w, u·w, v·w).
    #[inline]
    pub(super) fn plane(&self, k: usize, q: [f32; 3]) -> f32 {
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
pub(super) struct CellAxis {
    pub(super) bounds: Vec<f32>,
    pub(super) centres: Vec<f32>,
    pub(super) bound_lut: Lut,
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

    pub(super) fn len(&self) -> usize {
        self.centres.len()
    }

    /// The first cell whose centre is ≥ x.
    #[inline]
    pub(super) fn first_centre(&self, x: f32) -> usize {
        self.centre_lut.first_ge(&self.centres, x)
    }

    /// The cells whose intervals meet [x0, x1].
    #[inline]
    pub(super) fn cells_meeting(&self, x0: f32, x1: f32) -> std::ops::Range<usize> {
        let a = self.bound_lut.first_ge(&self.bounds, x0).saturating_sub(1);
        let b = self.bound_lut.first_ge(&self.bounds, x1).min(self.len());
        a..b
    }
}

/// Sec. 2's look-up table from a regular grid onto a sorted array: bin k holds the first index
/// whose value is ≥ the bin's start.
#[derive(Clone, Debug)]
pub(super) struct Lut {
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
    pub(super) fn first_ge(&self, values: &[f32], x: f32) -> usize {
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
pub(super) fn top_corner_ff(x: f64, y: f64) -> f64 {
    let a = (1.0 + x * x).sqrt();
    let b = (1.0 + y * y).sqrt();
    (x / a * (y / a).atan() + y / b * (x / b).atan()) / (2.0 * PI)
}

/// An antiderivative in (y, z) of the side density z/(π(y²+z²+1)²) on the plane x = 1:
/// ∂²/∂y∂z of −atan(y/√(1+z²)) / (2π√(1+z²)).
pub(super) fn side_corner_ff(y: f64, z: f64) -> f64 {
    let s = (1.0 + z * z).sqrt();
    -(y / s).atan() / (2.0 * PI * s)
}
