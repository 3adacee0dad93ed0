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

mod grid;
mod raster;
#[cfg(test)]
mod tests;

use grid::Face;
use raster::to_frame;
pub use raster::{HemicubeBuffer, ShotWork};

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

impl Hemicube {
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

    /// Renders every surface patch of `mesh` except `shooter`'s surface as seen from `eye` in
    /// `frame` (frame.n = the shooter's normal; the top face looks along n, the sides along ±t,
    /// ±b) into a z-buffer holding the nearest patch id per cell, and writes into `out`
    /// (cleared first) (receiver, F = Σ ΔF of its cells, lost_on_back) for every surface with
    /// F > 0, in surface id order. The receiver is the side the eye sees ([`Mesh::receiver`]):
    /// the surface, its back twin, or for the back of a one-sided surface the surface itself
    /// with `lost_on_back` set. Returns the work it did, counted (the
    /// hybrid's cost model weighs these counts, Sec. 4).
    ///
    /// With `jitter`, every cell's sample point is drawn uniformly inside its cell (the paper's
    /// "jittered hemi-cube", Table 1) instead of its centre. Patches wholly within a tiny
    /// epsilon of the base plane (the shooter's own plane) are culled, the others clipped
    /// against it (z ≥ 0 in the frame) and against each face's frustum before scan conversion.
    /// Back faces are drawn too (they occlude); the caller learns they were seen from behind.
    ///
    /// The steps: size and clear the buffers; draw the jittered sample points; per patch, into
    /// the frame (`to_frame`) and onto the faces (`Hemicube::draw_patch`); read the cells
    /// back (`Hemicube::read_back`).
    // Eight: the shot (shooter, eye, frame, jitter) and the per-thread scratch (`buf`, `out`),
    // kept apart so that rayon's `for_each_init` owns the scratch and the shot is per call.
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
        // Surfaces only: a back twin is drawn as its front patch (docs/design.md §7).
        let own = mesh.surface_of(shooter);
        for j in 0..mesh.patches.len() {
            if j == own || !mesh.is_surface(j) {
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
}
