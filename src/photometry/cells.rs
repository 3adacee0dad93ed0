//! Cells of equal flux over a luminaire's directions, and the importance sampler over them.
//!
//! Airey & Ouh-young (1989), Sec. 2, shoot a patch's unshot energy as X rays that all carry
//! the same energy, ΔΦ/X, through X cells of equal form factor. A luminaire is shot the same
//! way: its flux Φ as N rays of Φ/N each. A ray stands for the flux of the directions it
//! represents, so for every ray to carry the same energy every cell must hold the same flux,
//! ∫∫_cell I dΩ = Φ/N; one ray is cast through each cell, and inside its cell the ray's
//! direction is drawn with density ∝ I. Over all cells the directions' density is then exactly
//! I(d)/Φ: importance sampling of the web, stratified by the cells.
//!
//! # One polar system for the three types
//!
//! Every direction is written about a pole P with an azimuth basis (E0, E90):
//!
//!   d = cos θ·P + sin θ·(cos φ·E0 + sin φ·E90),   dΩ = sin θ dθ dφ.
//!
//! - Type C: θ = γ, φ = C, P = −Z (the nadir), E0 = +X, E90 = +Y: dΩ = sin γ dγ dC, and d is
//!   (sin γ cos C, sin γ sin C, −cos γ).
//! - Type B: θ = 90° + H, φ = V, P = −Y, E0 = −Z, E90 = +X: dΩ = cos H dH dV (sin θ = cos H),
//!   and d = sin H·(+Y) + cos H sin V·(+X) + cos H cos V·(−Z).
//! - Type A: θ = 90° + H, φ = V, P = −X, E0 = −Z, E90 = +Y: dΩ = cos H dH dV, and
//!   d = sin H·(+X) + cos H sin V·(+Y) + cos H cos V·(−Z).
//!
//! # The table is the web itself
//!
//! [`Photometry::intensity`] is bilinear in the file's angles between the nodes of the web,
//! once its symmetry is expanded. The table takes as nodes the file's angles and all their
//! mirror images under the declared symmetry, and the intensity there: between these nodes it
//! is bilinear in (φ, θ), so the table *is* `intensity` (no resampling), and the bilinear web
//! times sin θ integrates in closed form over a θ interval of width w:
//!
//!   ∫₀ʷ (a + b s) sin(θ_j + s) ds = sin θ_j [a sin w + b (w sin w − 2 sin²(w/2))]
//!                                 + cos θ_j [2a sin²(w/2) + b (sin w − w cos w)].
//!
//! From it: Q_i(θ) = ∫_{θ₀}^{θ} I(φ_i, θ') sin θ' dθ' at each azimuth node i, and, since I is
//! a sum of hat functions in φ, the flux from the first polar node to θ,
//! M(θ) = Σ_i w_i Q_i(θ) (w_i the integral of node i's hat); Φ = M(θ_last).
//!
//! # The cells: rings in θ, sectors in φ
//!
//! Like the paper's polar grid: rings about the pole, each cut into sectors. Ring k holds n_k
//! cells and so the flux n_k·Φ/N; its bounds solve M(θ) = (cells before it)·Φ/N. The counts
//! are chosen ring by ring from the pole so that the cells come out nearest square in solid
//! angle, sin θ_mid·L/n_k ≈ Δθ (the paper's "theta divisions = 2 × radius divisions" makes
//! its cells square on the Nusselt disc; a web is no disc, so the rule is applied to the sphere
//! ring by ring). In a ring [θa, θb] the flux per unit φ is
//! g(φ) = Σ_i hat_i(φ)·(Q_i(θb) − Q_i(θa)), and L = (∫g dφ)²/∫g² dφ is the azimuth span g
//! would fill if it were even: the whole circle for an even ring, the beam for a beam, while
//! faint tails hardly count (a plain "where g > 0" would let a trace of stray light make the
//! beam's cells slivers). g is piecewise linear: its integral is piecewise
//! quadratic, and the n_k sectors of equal flux are found by solving one quadratic each. Every
//! cell holds exactly Φ/N of the web (rounding aside), and N is exactly the count asked for.
//! Bounds are drawn tight around the light: a ring starts at the last angle its flux has not
//! yet begun and ends at the first where it is complete, and the same for sectors, so a dark
//! region (I = 0) lies in no cell, except a dark gap inside a ring's lit azimuths, which one
//! sector may straddle (its rays never go there: their density is I).
//!
//! # Sampling
//!
//! In cell (ring k, sector s): u places the ray along the ring, φ solving
//! ∫_{φ₀}^{φ} g = (s + u)/n_k·(ring flux) (a quadratic); v places it across the ring, θ
//! solving Q(φ, θ) − Q(φ, θa) = v·(Q(φ, θb) − Q(φ, θa)) with Q(φ, ·) the hat-weighted Q_i
//! (the closed form above, inverted by Newton's method kept inside a bisection bracket). That
//! is the inverse of the cell's exact CDF, so the density is I·sin θ, ∝ I per solid angle.
//! Cost per sample: binary searches over the rings, the azimuth nodes and the polar nodes, and a
//! few Newton steps: O(log n), never a scan.

use super::{PhotometricType, Photometry, Symmetry};
use glam::DVec3;

/// Nodes closer than this, degrees, are one node: far below any file's precision, far above
/// the rounding of the mirror images (360 − h and the like).
const SAME_NODE_DEG: f64 = 1e-9;

/// Below this interval width, radians, `sin w − w cos w` comes from its series (the direct
/// difference loses digits to cancellation).
const SERIES_BELOW: f64 = 0.1;

/// Newton steps at most in one inversion (bisection keeps it bracketed; 64 halvings reach the
/// last bit of any interval).
const MAX_STEPS: usize = 64;

/// A luminaire's directions cut into cells of equal flux, with a sampler that draws a
/// direction inside a cell with density ∝ intensity (see the module documentation).
#[derive(Clone, Debug)]
pub struct FluxCells {
    /// The tabulated web; `None` when it carries no flux (then there are no cells).
    web: Option<Web>,
    /// The rings, in order from the pole, each with the index of its first cell.
    rings: Vec<Ring>,
    /// Per ring and azimuth node (`ring * np + i`): Q_i(θa), the flux per unit φ before the
    /// ring.
    before: Vec<f64>,
    /// Per ring and azimuth node: G_i = Q_i(θb) − Q_i(θa), the ring's flux per unit φ.
    across: Vec<f64>,
    /// Per ring and azimuth node: ∫ g from the first azimuth node to node i.
    along: Vec<f64>,
    /// Each cell's azimuth bounds, radians.
    sectors: Vec<[f64; 2]>,
}

/// One ring of cells: its polar bounds, radians, its cells and its flux.
#[derive(Clone, Copy, Debug)]
struct Ring {
    theta: [f64; 2],
    first: usize,
    count: usize,
    flux: f64,
}

/// A cell's bounds in the file's own angles, degrees: `horizontal` is C (Type C) or H (Types
/// A and B), `vertical` is γ (Type C) or V (Types A and B). A cell is exactly the directions
/// with both angles inside its bounds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CellAngles {
    pub horizontal: [f64; 2],
    pub vertical: [f64; 2],
}

/// The local frame of a photometric type: the pole and the azimuth basis.
#[derive(Clone, Copy, Debug)]
struct Frame {
    pole: DVec3,
    e0: DVec3,
    e90: DVec3,
}

impl Frame {
    fn of(kind: PhotometricType) -> Frame {
        let (pole, e0, e90) = match kind {
            PhotometricType::C => (DVec3::NEG_Z, DVec3::X, DVec3::Y),
            PhotometricType::B => (DVec3::NEG_Y, DVec3::NEG_Z, DVec3::X),
            PhotometricType::A => (DVec3::NEG_X, DVec3::NEG_Z, DVec3::Y),
        };
        Frame { pole, e0, e90 }
    }

    fn direction(&self, theta: f64, phi: f64) -> DVec3 {
        let (st, ct) = theta.sin_cos();
        let (sp, cp) = phi.sin_cos();
        ct * self.pole + st * (cp * self.e0 + sp * self.e90)
    }
}

/// The web on its nodes with its integrals over θ.
#[derive(Clone, Debug)]
struct Web {
    kind: PhotometricType,
    frame: Frame,
    /// Polar nodes, radians, increasing (at least 2), with their (sin, cos).
    theta: Vec<f64>,
    sin_cos: Vec<(f64, f64)>,
    /// Azimuth nodes, radians, increasing (at least 2).
    phi: Vec<f64>,
    /// I(φ_i, θ_j) at `i * nt + j`, candela, finite and ≥ 0.
    value: Vec<f64>,
    /// Q_i(θ_j) at `i * nt + j`.
    cum: Vec<f64>,
    /// Σ_i w_i I(φ_i, θ_j): the web integrated over φ at each polar node.
    bar: Vec<f64>,
    /// M(θ_j).
    marginal: Vec<f64>,
    /// Φ = M(θ_last), lumens, finite and > 0.
    total: f64,
}

impl FluxCells {
    /// The cells of `p`: `cells` of them (a request below 1 counts as 1), each of equal flux,
    /// or none when the web carries no flux (all candela 0, fewer than two angles on an axis).
    /// Intensities that are negative or not finite (impossible from the readers) count as 0.
    pub fn new(p: &Photometry, cells: usize) -> FluxCells {
        let mut out = FluxCells {
            web: None,
            rings: Vec::new(),
            before: Vec::new(),
            across: Vec::new(),
            along: Vec::new(),
            sectors: Vec::new(),
        };
        if let Some(web) = Web::new(p) {
            out.lay_rings(&web, cells.max(1));
            out.web = Some(web);
        }
        out
    }

    /// Number of cells: the count asked for, or 0 for a web without flux.
    pub fn len(&self) -> usize {
        self.sectors.len()
    }

    /// Whether there are no cells (the web carries no flux).
    pub fn is_empty(&self) -> bool {
        self.sectors.is_empty()
    }

    /// The flux the table integrates, lumens: the exact integral of the bilinear web over the
    /// sphere (what [`Photometry::total_lumens`] approximates by the trapezoid rule).
    pub fn total_lumens(&self) -> f64 {
        self.web.as_ref().map_or(0.0, |w| w.total)
    }

    /// The flux of each cell, and so the energy each ray carries, lumens: Φ/N (0 if empty).
    pub fn flux_per_cell(&self) -> f64 {
        match self.len() {
            0 => 0.0,
            n => self.total_lumens() / n as f64,
        }
    }

    /// Cell `cell`'s bounds in the file's angles, degrees; `None` past the last cell.
    pub fn cell_angles(&self, cell: usize) -> Option<CellAngles> {
        let web = self.web.as_ref()?;
        let sector = self.sectors.get(cell)?;
        let ring = self.rings.get(self.ring_of(cell))?;
        let polar = ring.theta.map(|t| t.to_degrees() - web.polar_offset_deg());
        let azimuth = sector.map(f64::to_degrees);
        Some(match web.kind {
            PhotometricType::C => CellAngles {
                horizontal: azimuth,
                vertical: polar,
            },
            PhotometricType::A | PhotometricType::B => CellAngles {
                horizontal: polar,
                vertical: azimuth,
            },
        })
    }

    /// A unit direction in the luminaire's local frame inside cell `cell` (taken modulo
    /// [`len`](Self::len)), for `u`, `v` uniform in [0, 1) (clamped to [0, 1]; NaN reads as 0):
    /// over cells drawn equally often the directions have density I(d)/Φ per steradian.
    ///
    /// `turn` (taken modulo 1) turns the cell pattern for one shot, as the paper turns its
    /// polar grid by a random angle per shot: the ray's place along its ring, (s + u)/n_k, is
    /// shifted by `turn` cyclically, and the ray drawn at the shifted place (which may lie in
    /// another cell of the ring). For a rotationally symmetric Type C web, whose rings carry
    /// their flux evenly in C, that is exactly the turn by `turn`·360° about the polar axis.
    /// For any other web a geometric turn would carry the pattern's rays into directions of
    /// other intensity and so change their density; the shift is the same turn measured in flux
    /// rather than in angle, a measure-preserving map of each ring onto itself, so the density
    /// stays exactly I(d)/Φ for every `turn` while the cell boundaries move from shot to shot.
    /// One ray per cell with a shared `turn` still puts one ray in each cell of the shifted
    /// pattern, so the stratification is kept. (A Cranley–Patterson shift of u alone would
    /// keep the density too, but would leave the boundaries where they are.) An empty table
    /// gives the nadir, −Z.
    pub fn sample(&self, cell: usize, u: f64, v: f64, turn: f64) -> DVec3 {
        let Some(web) = &self.web else {
            return DVec3::NEG_Z;
        };
        if self.is_empty() {
            return DVec3::NEG_Z;
        }
        let cell = cell % self.len();
        let r = self.ring_of(cell);
        let ring = self.rings[r];
        let n = ring.count as f64;
        let turn = if turn.is_finite() {
            turn.rem_euclid(1.0)
        } else {
            0.0
        };
        let place = (((cell - ring.first) as f64 + unit(u)) / n + turn).fract();
        let s = ((place * n) as usize).min(ring.count - 1);
        let [lo, hi] = self.sectors[ring.first + s];
        let phi = self
            .azimuth_at(web, r, place * ring.flux, false)
            .clamp(lo, hi);
        let theta = self.polar_at(web, r, phi, unit(v));
        web.frame.direction(theta, phi)
    }

    /// The sampler's density at local direction `d` (any length but 0), per steradian:
    /// I(d)/Φ, 0 where the web is dark or the table empty.
    pub fn pdf(&self, d: DVec3) -> f64 {
        let Some(web) = &self.web else {
            return 0.0;
        };
        let d = d.normalize_or_zero();
        if d == DVec3::ZERO {
            return 0.0;
        }
        let f = web.frame;
        let theta = d.dot(f.pole).clamp(-1.0, 1.0).acos();
        let mut phi = d.dot(f.e90).atan2(d.dot(f.e0));
        if web.kind == PhotometricType::C {
            phi = phi.rem_euclid(std::f64::consts::TAU);
        }
        web.intensity(phi, theta) / web.total
    }

    /// The ring holding `cell` (< len).
    fn ring_of(&self, cell: usize) -> usize {
        self.rings
            .partition_point(|r| r.first <= cell)
            .saturating_sub(1)
    }

    /// Rings from the pole, each with the cell count that makes its cells nearest square,
    /// until `n` cells hold the whole flux.
    fn lay_rings(&mut self, web: &Web, n: usize) {
        let per_cell = web.total / n as f64;
        let flux_at = |cells: usize| {
            if cells >= n {
                web.total
            } else {
                cells as f64 * per_cell
            }
        };
        let mut done = 0;
        let mut theta_a = web.polar_at_flux(0.0, false);
        while done < n {
            let left = n - done;
            let end = |count: usize| web.polar_at_flux(flux_at(done + count), true);
            let aspect = |count: usize| web.aspect(theta_a, end(count), count);
            let count = nearest_square(left, aspect);
            let theta_b = end(count).max(theta_a);
            self.add_ring(web, [theta_a, theta_b], done, count);
            done += count;
            // sup{M ≤ target} ≥ inf{M ≥ target}: the next ring starts where this one ends or,
            // past a dark band, where the light resumes.
            theta_a = web.polar_at_flux(flux_at(done), false).max(theta_b);
        }
    }

    /// Appends the ring `theta` of `count` cells starting at cell `first`: its tables along φ
    /// and its sectors of equal flux.
    fn add_ring(&mut self, web: &Web, theta: [f64; 2], first: usize, count: usize) {
        let np = web.phi.len();
        let r = self.rings.len();
        for i in 0..np {
            let qa = web.q(i, theta[0]);
            self.before.push(qa);
            self.across.push((web.q(i, theta[1]) - qa).max(0.0));
        }
        let g = &self.across[r * np..];
        self.along.push(0.0);
        for i in 0..np - 1 {
            let w = web.phi[i + 1] - web.phi[i];
            let last = self.along[r * np + i];
            self.along.push(last + 0.5 * w * (g[i] + g[i + 1]));
        }
        let flux = self.along[r * np + np - 1];
        self.rings.push(Ring {
            theta,
            first,
            count,
            flux,
        });
        for s in 0..count {
            let at = |k: usize| {
                if k >= count {
                    flux
                } else {
                    flux * k as f64 / count as f64
                }
            };
            let lo = self.azimuth_at(web, r, at(s), false);
            let hi = self.azimuth_at(web, r, at(s + 1), true).max(lo);
            self.sectors.push([lo, hi]);
        }
    }

    /// In ring `r`, the azimuth where the flux along the ring reaches `target`: the least such
    /// (`upper`) or the greatest that has not passed it.
    fn azimuth_at(&self, web: &Web, r: usize, target: f64, upper: bool) -> f64 {
        let np = web.phi.len();
        let along = &self.along[r * np..(r + 1) * np];
        let g = &self.across[r * np..(r + 1) * np];
        let i = crossing(np, |i| along[i], target, upper);
        let w = web.phi[i + 1] - web.phi[i];
        let slope = (g[i + 1] - g[i]) / w;
        web.phi[i] + invert_linear(g[i], slope, w, target - along[i])
    }

    /// In ring `r` at azimuth `phi`, the polar angle that leaves the share `v` of the ring's
    /// flux along that azimuth before it.
    fn polar_at(&self, web: &Web, r: usize, phi: f64, v: f64) -> f64 {
        let ring = self.rings[r];
        let (nt, np) = (web.theta.len(), web.phi.len());
        let m = interval(&web.phi, phi);
        let t = ((phi - web.phi[m]) / (web.phi[m + 1] - web.phi[m])).clamp(0.0, 1.0);
        let lerp = |a: f64, b: f64| a + t * (b - a);
        let at = |table: &[f64], k: usize| lerp(table[m * nt + k], table[(m + 1) * nt + k]);
        let before = lerp(self.before[r * np + m], self.before[r * np + m + 1]);
        let across = lerp(self.across[r * np + m], self.across[r * np + m + 1]);
        let target = before + v * across;
        let j = crossing(nt, |k| at(&web.cum, k), target, false);
        let (a0, a1) = (at(&web.value, j), at(&web.value, j + 1));
        let w = web.theta[j + 1] - web.theta[j];
        let s = invert_sin(
            web.sin_cos[j],
            a0,
            (a1 - a0) / w,
            w,
            target - at(&web.cum, j),
        );
        (web.theta[j] + s).clamp(ring.theta[0], ring.theta[1])
    }
}

/// `x` as a place in [0, 1]: clamped, NaN as 0.
fn unit(x: f64) -> f64 {
    if x.is_nan() {
        0.0
    } else {
        x.clamp(0.0, 1.0)
    }
}

/// The count in 1..=left whose ring has cells nearest square: the aspect (width over height)
/// falls as the count grows, so the count where it crosses 1 is found by bisection, and the
/// nearer of it and the count before it on a log scale is taken.
fn nearest_square(left: usize, aspect: impl Fn(usize) -> f64) -> usize {
    let (mut lo, mut hi) = (1, left);
    if aspect(hi) > 1.0 {
        return left;
    }
    // Invariant: aspect(hi) <= 1; the answer's crossing lies in lo..=hi.
    while lo < hi {
        let mid = lo + (hi - lo) / 2;
        if aspect(mid) <= 1.0 {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    if hi > 1 && aspect(hi - 1).ln().abs() < aspect(hi).ln().abs() {
        hi - 1
    } else {
        hi
    }
}

/// Index `j` in 0..=n−2 such that `x` lies in nodes[j]..nodes[j+1] (clamped at the ends).
fn interval(nodes: &[f64], x: f64) -> usize {
    nodes
        .partition_point(|&n| n <= x)
        .saturating_sub(1)
        .min(nodes.len().saturating_sub(2))
}

/// The interval `j` in 0..=n−2 where the nondecreasing `cum(0..n)` crosses `target`: the one
/// ending at the first node with cum ≥ target (`upper`: for the least angle that reaches it)
/// or cum > target (for the greatest angle that has not passed it).
fn crossing(n: usize, cum: impl Fn(usize) -> f64, target: f64, upper: bool) -> usize {
    let (mut lo, mut hi) = (0, n);
    while lo < hi {
        let mid = lo + (hi - lo) / 2;
        let c = cum(mid);
        if (upper && c < target) || (!upper && c <= target) {
            lo = mid + 1;
        } else {
            hi = mid;
        }
    }
    lo.saturating_sub(1).min(n.saturating_sub(2))
}

/// ∫₀ʷ (a + b s) sin(θ₀ + s) ds for `sin_cos` = (sin θ₀, cos θ₀): the module documentation's
/// closed form, never negative.
fn integral_sin(sin_cos: (f64, f64), a: f64, b: f64, w: f64) -> f64 {
    let (sin0, cos0) = sin_cos;
    let (sw, cw) = w.sin_cos();
    let half = (0.5 * w).sin();
    let one_minus_cos = 2.0 * half * half;
    let s_cos = w * sw - one_minus_cos; // ∫₀ʷ s cos s ds
    let s_sin = if w < SERIES_BELOW {
        // ∫₀ʷ s sin s ds = w³/3 − w⁵/30 + w⁷/840 − w⁹/45360 + …
        let w2 = w * w;
        w * w2 * (1.0 / 3.0 - w2 * (1.0 / 30.0 - w2 * (1.0 / 840.0 - w2 / 45360.0)))
    } else {
        sw - w * cw
    };
    (sin0 * (a * sw + b * s_cos) + cos0 * (a * one_minus_cos + b * s_sin)).max(0.0)
}

/// The s in 0..=w where [`integral_sin`] reaches `target`: Newton's method on the closed
/// form, every step kept inside a shrinking bisection bracket.
fn invert_sin(sin_cos: (f64, f64), a: f64, b: f64, w: f64, target: f64) -> f64 {
    let total = integral_sin(sin_cos, a, b, w);
    if target.is_nan() || target <= 0.0 {
        return 0.0;
    }
    if total.is_nan() || target >= total {
        return w;
    }
    let (mut lo, mut hi) = (0.0, w);
    let mut s = w * (target / total);
    for _ in 0..MAX_STEPS {
        let f = integral_sin(sin_cos, a, b, s) - target;
        if f == 0.0 {
            return s;
        }
        if f > 0.0 {
            hi = s;
        } else {
            lo = s;
        }
        let (ss, cs) = s.sin_cos();
        let density = (a + b * s) * (sin_cos.0 * cs + sin_cos.1 * ss);
        let newton = s - f / density;
        let next = if density > 0.0 && newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
        let converged = (next - s).abs() <= 1e-14 * w;
        s = next;
        if converged {
            break;
        }
    }
    s.clamp(0.0, w)
}

/// The x in 0..=w where ∫₀ˣ (a + b s) ds = a x + b x²/2 reaches `target`, for a ≥ 0 and
/// a + b w ≥ 0 (the root written so that it does not cancel).
fn invert_linear(a: f64, b: f64, w: f64, target: f64) -> f64 {
    if target.is_nan() || target <= 0.0 {
        return 0.0;
    }
    let total = w * (a + 0.5 * b * w);
    if total.is_nan() || target >= total {
        return w;
    }
    let root = (a * a + 2.0 * b * target).max(0.0).sqrt();
    let x = 2.0 * target / (a + root);
    if x.is_finite() {
        x.clamp(0.0, w)
    } else {
        w
    }
}

impl Web {
    /// The web of `p` on its nodes, or `None` if it carries no flux.
    fn new(p: &Photometry) -> Option<Web> {
        let (polar_deg, azimuth_deg) = nodes(p)?;
        let (nt, np) = (polar_deg.len(), azimuth_deg.len());
        let mut value = Vec::with_capacity(nt * np);
        for &f in &azimuth_deg {
            for &t in &polar_deg {
                let i = match p.kind {
                    // C360 as the limit from below (the file's last plane), not as C0 again.
                    PhotometricType::C => p.intensity(f.min(360.0 - SAME_NODE_DEG), t),
                    PhotometricType::A | PhotometricType::B => p.intensity(t, f),
                };
                value.push(if i.is_finite() && i > 0.0 { i } else { 0.0 });
            }
        }
        let offset = polar_offset_deg(p.kind);
        let theta: Vec<f64> = polar_deg
            .iter()
            .map(|t| (t + offset).to_radians())
            .collect();
        let phi: Vec<f64> = azimuth_deg.iter().map(|f| f.to_radians()).collect();
        let sin_cos: Vec<(f64, f64)> = theta.iter().map(|t| t.sin_cos()).collect();
        let mut cum = vec![0.0; nt * np];
        for i in 0..np {
            for j in 0..nt - 1 {
                let (a0, a1) = (value[i * nt + j], value[i * nt + j + 1]);
                let w = theta[j + 1] - theta[j];
                cum[i * nt + j + 1] =
                    cum[i * nt + j] + integral_sin(sin_cos[j], a0, (a1 - a0) / w, w);
            }
        }
        let hat: Vec<f64> = (0..np)
            .map(|i| {
                let left = if i > 0 { phi[i] - phi[i - 1] } else { 0.0 };
                let right = if i + 1 < np { phi[i + 1] - phi[i] } else { 0.0 };
                0.5 * (left + right)
            })
            .collect();
        let weighted =
            |table: &[f64], j: usize| -> f64 { (0..np).map(|i| hat[i] * table[i * nt + j]).sum() };
        let bar: Vec<f64> = (0..nt).map(|j| weighted(&value, j)).collect();
        let marginal: Vec<f64> = (0..nt).map(|j| weighted(&cum, j)).collect();
        let total = marginal[nt - 1];
        (total > 0.0 && total.is_finite()).then_some(Web {
            kind: p.kind,
            frame: Frame::of(p.kind),
            theta,
            sin_cos,
            phi,
            value,
            cum,
            bar,
            marginal,
            total,
        })
    }

    fn polar_offset_deg(&self) -> f64 {
        polar_offset_deg(self.kind)
    }

    /// Q_i(θ): ∫ I(φ_i, θ') sin θ' dθ' from the first polar node to `theta`.
    fn q(&self, i: usize, theta: f64) -> f64 {
        let nt = self.theta.len();
        let j = interval(&self.theta, theta);
        let (a0, a1) = (self.value[i * nt + j], self.value[i * nt + j + 1]);
        let w = self.theta[j + 1] - self.theta[j];
        let s = (theta - self.theta[j]).clamp(0.0, w);
        self.cum[i * nt + j] + integral_sin(self.sin_cos[j], a0, (a1 - a0) / w, s)
    }

    /// The polar angle where M reaches `target`: the least such (`upper`) or the greatest
    /// that has not passed it.
    fn polar_at_flux(&self, target: f64, upper: bool) -> f64 {
        let j = crossing(self.theta.len(), |k| self.marginal[k], target, upper);
        let (a0, a1) = (self.bar[j], self.bar[j + 1]);
        let w = self.theta[j + 1] - self.theta[j];
        let partial = target - self.marginal[j];
        self.theta[j] + invert_sin(self.sin_cos[j], a0, (a1 - a0) / w, w, partial)
    }

    /// Width over height of the cells of a ring `theta_a..theta_b` cut into `count`: the arc
    /// of the ring's effective azimuth span L = (∫g)²/∫g² at its middle, shared out, against
    /// its polar extent.
    fn aspect(&self, theta_a: f64, theta_b: f64, count: usize) -> f64 {
        let height = theta_b - theta_a;
        if height.is_nan() || height <= 0.0 {
            return f64::INFINITY;
        }
        let g = |i: usize| (self.q(i, theta_b) - self.q(i, theta_a)).max(0.0);
        let (mut flux, mut square) = (0.0, 0.0);
        let mut before = g(0);
        for i in 1..self.phi.len() {
            let (here, w) = (g(i), self.phi[i] - self.phi[i - 1]);
            // g linear from `before` to `here`: exact integrals of g and g².
            flux += 0.5 * w * (before + here);
            square += w * (before * before + before * here + here * here) / 3.0;
            before = here;
        }
        let span = if square > 0.0 {
            flux * flux / square
        } else {
            0.0
        };
        (0.5 * (theta_a + theta_b)).sin() * span / (count as f64 * height)
    }

    /// The bilinear web at (φ, θ), radians; 0 outside the nodes.
    fn intensity(&self, phi: f64, theta: f64) -> f64 {
        let inside = |nodes: &[f64], x: f64| {
            nodes
                .first()
                .zip(nodes.last())
                .is_some_and(|(&a, &b)| x >= a && x <= b)
        };
        if !(inside(&self.phi, phi) && inside(&self.theta, theta)) {
            return 0.0;
        }
        let nt = self.theta.len();
        let (i, j) = (interval(&self.phi, phi), interval(&self.theta, theta));
        let s = ((phi - self.phi[i]) / (self.phi[i + 1] - self.phi[i])).clamp(0.0, 1.0);
        let t = ((theta - self.theta[j]) / (self.theta[j + 1] - self.theta[j])).clamp(0.0, 1.0);
        let along = |i: usize| {
            let (a, b) = (self.value[i * nt + j], self.value[i * nt + j + 1]);
            a + t * (b - a)
        };
        let (a, b) = (along(i), along(i + 1));
        a + s * (b - a)
    }
}

/// θ minus the file's polar angle, degrees: 0 for Type C (θ = γ), 90 for A and B (θ = 90° + H).
fn polar_offset_deg(kind: PhotometricType) -> f64 {
    match kind {
        PhotometricType::C => 0.0,
        PhotometricType::A | PhotometricType::B => 90.0,
    }
}

/// The web's nodes in the file's angles, degrees, as (polar, azimuth): (γ, C) for Type C,
/// (H, V) for Types A and B; every angle where `intensity` may bend, i.e. the file's angles
/// and their mirror images under the symmetry, within the range the polar system covers.
/// `None` if an axis has fewer than two.
fn nodes(p: &Photometry) -> Option<(Vec<f64>, Vec<f64>)> {
    match p.kind {
        PhotometricType::C => {
            let polar = clipped(p.vertical.iter().copied(), 0.0, 180.0)?;
            // The folds of `Photometry::intensity`: C, 180 − C, 180 + C, 360 − C, 540 − C (and
            // whole turns), and the mirror planes themselves.
            let images = p.horizontal.iter().flat_map(|&h| {
                [
                    h,
                    180.0 - h,
                    180.0 + h,
                    360.0 - h,
                    540.0 - h,
                    h - 360.0,
                    h + 360.0,
                ]
            });
            let planes = [0.0, 90.0, 180.0, 270.0, 360.0];
            let azimuth = clipped(images.chain(planes), 0.0, 360.0)?;
            Some((polar, azimuth))
        }
        PhotometricType::A | PhotometricType::B => {
            let mirror = p.symmetry == Symmetry::Lateral;
            let h = p
                .horizontal
                .iter()
                .flat_map(|&h| [h, if mirror { -h } else { h }]);
            let polar = clipped(h, -90.0, 90.0)?;
            let azimuth = clipped(p.vertical.iter().copied(), -180.0, 180.0)?;
            Some((polar, azimuth))
        }
    }
}

/// The finite `values` within `lo..=hi`, with `lo` and `hi` added where values reach past
/// them, snapped to the ends, sorted, without near duplicates; `None` if fewer than two.
fn clipped(values: impl Iterator<Item = f64>, lo: f64, hi: f64) -> Option<Vec<f64>> {
    let all: Vec<f64> = values.filter(|x| x.is_finite()).collect();
    let below = all.iter().any(|&x| x < lo);
    let above = all.iter().any(|&x| x > hi);
    let snap = |x: f64| {
        if (x - lo).abs() <= SAME_NODE_DEG {
            lo
        } else if (x - hi).abs() <= SAME_NODE_DEG {
            hi
        } else {
            x
        }
    };
    let mut v: Vec<f64> = all
        .into_iter()
        .map(snap)
        .filter(|&x| x >= lo && x <= hi)
        .collect();
    if below {
        v.push(lo);
    }
    if above {
        v.push(hi);
    }
    v.sort_by(f64::total_cmp);
    v.dedup_by(|b, a| (*b - *a).abs() <= SAME_NODE_DEG);
    (v.len() >= 2).then_some(v)
}

#[cfg(test)]
#[path = "cells_tests.rs"]
mod tests;
