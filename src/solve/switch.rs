//! Sec. 4 of Airey & Ouh-young (1989): when `adaptive-hybrid` stops shooting hemi-cubes and
//! starts casting rays, and the cost model it decides by. Everything about the switch is here.
//!
//! The paper's Figure 5: a hemi-cube shot costs about the same whatever energy it carries
//! (transforming and clipping every patch dominates below N ≈ 50; curve C falls only slowly as
//! the adaptive resolution drops), while a ray shot costs in proportion to its energy (X = ΔΦ/C
//! rays; curve D falls exponentially with the unshot energy). "The optimal hybrid algorithm
//! can be determined by using the method whose curve has least cost at any given iteration":
//! before each hemi-cube shot the hybrid asks whether that shot would be cheaper by rays, and
//! from the first one that would, it casts rays only.
//!
//! Three ways to decide ([`SwitchBy`], `--switch-at`):
//! - **Counted** (the default; [`counted_costs`]): the costs are *predicted from counted work*
//!   weighed by constants the code keeps ([`KEPT`]). A hemi-cube shot costs
//!   `patch·P + face·F + cell·N_c + tested·T` (P patches transformed into the shooter's frame,
//!   F patch-face pairs clipped, N_c cells cleared and read back, T cells depth-tested; see
//!   [`ShotWork`]), with F per shot and T per cell taken from the hemi-cube shots so far
//!   ([`WorkTally`]); a ray shot costs `ray·log₂(patches)·X` (X rays, each descending a
//!   bounding-volume hierarchy about log₂(patches) deep). Counts depend only on the scene, the seed and
//!   the shots so far, so the switch shot, and the result, are the same on every run and
//!   every thread count.
//! - **Measured** ([`CubeCost`], `probe`): the costs are times measured during the run (a
//!   least-squares fit of hemi-cube shot time against cells, and a timed probe of a few
//!   thousand rays). Adapts to the machine; the switch shot varies from run to run.
//! - **Forced** (`--switch-at SHOT`): the switch at a given shot (an exact replay of a recorded
//!   switch), the costs still computed and recorded by the chosen model.
//!
//! The constants are thread seconds on one core, measured by `radiosity bench shots`, which
//! times hemi-cube shots of several resolutions and ray shots of several sizes from shooters
//! spread over a scene, fits the constants by least squares with non-negative coefficients
//! ([`fit_cube`], [`fit_rays`]), and prints them beside the kept ones with the shot at which
//! the hybrid switches under each.

use super::cube_shots::CubeHits;
use super::ray_shots::{tasks_of, RayCaster, RayShot, CHUNK};
use super::{SolveSettings, SwitchBy, SwitchInfo};
use crate::intersect::Intersector;
use crate::sample::hemicube::ShotWork;
use crate::sample::polar::PolarGrid;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// Kept cost constants (thread seconds on one core), all five measured together on the
/// development machine class: a 2-core Intel Xeon VM (x86-64, `--release`, shared with another
/// job), 2026-11-30, by `radiosity bench shots scenes/S.obj --out bench-S.json`, twice for
/// S = blocks, office, hallway, church and once for cornell-box, then fitted to the nine runs'
/// timed shots together (their `cube_samples` and `ray_samples`, 6,912 hemi-cube and 1,728 ray
/// shots; [`crate::bench::shots::pooled_fit`], the fit `bench shots` prints per scene). Seconds
/// per patch transformed into a hemi-cube's frame.
pub const PATCH_SECONDS: f64 = 2.0e-8;
/// Seconds per (patch, face) pair mapped onto a hemi-cube face and clipped to its frustum
/// (measured with [`PATCH_SECONDS`]).
pub const FACE_SECONDS: f64 = 4.7e-8;
/// Seconds per hemi-cube cell cleared and read back (measured with [`PATCH_SECONDS`]).
pub const CELL_SECONDS: f64 = 1.4e-9;
/// Seconds per cell depth-tested by scan conversion (measured with [`PATCH_SECONDS`]).
pub const TESTED_SECONDS: f64 = 5.2e-9;
/// Seconds per ray of a ray shot and per log₂ of the scene's patch count (the depth of the
/// intersector's hierarchy), cast (applying the hits adds a few percent; measured with
/// [`PATCH_SECONDS`]). Per ray alone the scenes (232 to 5,267 patches) spread 1.3× (1.1–1.7e-7
/// s, the smallest scene cheapest); per ray and log₂(patches), a little less (1.1–1.6e-8 s).
pub const RAY_LOG2_SECONDS: f64 = 1.3e-8;

/// The kept constants as a model.
pub const KEPT: CostModel = CostModel {
    patch: PATCH_SECONDS,
    face: FACE_SECONDS,
    cell: CELL_SECONDS,
    tested: TESTED_SECONDS,
    ray: RAY_LOG2_SECONDS,
};

/// Predicted thread seconds of a shot from its counted work.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CostModel {
    /// Per patch transformed into the frame.
    pub patch: f64,
    /// Per (patch, face) pair clipped.
    pub face: f64,
    /// Per cell of the cube.
    pub cell: f64,
    /// Per cell depth-tested.
    pub tested: f64,
    /// Per ray and per log₂(patches).
    pub ray: f64,
}

/// A hemi-cube shot's counts as reals (a prediction may be fractional).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CubeWork {
    pub patches: f64,
    pub faces: f64,
    pub cells: f64,
    pub tested: f64,
}

impl From<ShotWork> for CubeWork {
    fn from(w: ShotWork) -> CubeWork {
        CubeWork {
            patches: w.patches as f64,
            faces: w.faces as f64,
            cells: w.cells as f64,
            tested: w.tested as f64,
        }
    }
}

impl CubeWork {
    /// The counts in the order of [`CostModel::cube_coefficients`].
    pub fn terms(&self) -> [f64; 4] {
        [self.patches, self.faces, self.cells, self.tested]
    }
}

impl CostModel {
    /// The hemi-cube coefficients, in the order of [`CubeWork::terms`].
    pub fn cube_coefficients(&self) -> [f64; 4] {
        [self.patch, self.face, self.cell, self.tested]
    }

    /// Predicted seconds of a hemi-cube shot doing `w`.
    pub fn cube_seconds(&self, w: &CubeWork) -> f64 {
        let c = self.cube_coefficients();
        w.terms().iter().zip(c).map(|(x, k)| x * k).sum()
    }

    /// Predicted seconds per ray in a scene of `patches` patches.
    pub fn seconds_per_ray(&self, patches: usize) -> f64 {
        self.ray * log2_patches(patches)
    }

    /// Predicted seconds of a ray shot of `rays` rays in a scene of `patches` patches.
    pub fn ray_seconds(&self, rays: u64, patches: usize) -> f64 {
        rays as f64 * self.seconds_per_ray(patches)
    }
}

/// Running totals of the hemi-cube shots' counted work so far, from which the next shot's
/// work is predicted. Saved in checkpoints ([`Saved`]), so a resumed run predicts the same.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WorkTally {
    pub shots: u64,
    pub faces: u64,
    pub cells: u64,
    pub tested: u64,
}

impl WorkTally {
    pub fn add(&mut self, w: &ShotWork) {
        self.shots += 1;
        self.faces += w.faces;
        self.cells += w.cells;
        self.tested += w.tested;
    }

    /// The work of a shot with `cells` cells in a scene of `patches` patches: one transform per
    /// patch but the shooter, the faces clipped per shot so far (they do not depend on the
    /// resolution), the cells tested per cell so far (the overdraw) times `cells`.
    pub fn predict(&self, patches: usize, cells: usize) -> CubeWork {
        let per = |x: u64, by: u64| if by == 0 { 0.0 } else { x as f64 / by as f64 };
        CubeWork {
            patches: patches.saturating_sub(1) as f64,
            faces: per(self.faces, self.shots),
            cells: cells as f64,
            tested: per(self.tested, self.cells) * cells as f64,
        }
    }
}

/// The counted rule: (hemi-cube work, its seconds, ray seconds) of the next shot, by `model`.
/// A pure function of counts: no clock, no thread count.
pub fn counted_costs(
    model: &CostModel,
    tally: &WorkTally,
    patches: usize,
    cells: usize,
    rays: u64,
) -> (CubeWork, f64, f64) {
    let work = tally.predict(patches, cells);
    (
        work,
        model.cube_seconds(&work),
        model.ray_seconds(rays, patches),
    )
}

/// Least squares y ≈ Σ_k c_k·x_k with every c_k ≥ 0 (no intercept), exactly: every subset of
/// the columns is solved by the normal equations and the best fit whose coefficients are all
/// non-negative kept (2^k − 1 small systems; k ≤ 4 here). `None` without data.
pub fn nonneg_least_squares<const K: usize>(rows: &[([f64; K], f64)]) -> Option<[f64; K]> {
    if rows.is_empty() {
        return None;
    }
    // Columns scaled to unit RMS, so the systems are well conditioned whatever the units.
    let scale: [f64; K] = std::array::from_fn(|k| {
        (rows.iter().map(|r| r.0[k] * r.0[k]).sum::<f64>() / rows.len() as f64).sqrt()
    });
    let mut best: Option<(f64, [f64; K])> = None;
    for mask in 1u32..(1 << K) {
        let cols: Vec<usize> = (0..K)
            .filter(|&k| mask & (1 << k) != 0 && scale[k] > 0.0)
            .collect();
        if cols.len() != mask.count_ones() as usize {
            continue;
        }
        let m = cols.len();
        let x = |r: &([f64; K], f64), a: usize| r.0[cols[a]] / scale[cols[a]];
        // Normal equations A c = b, A = XᵀX, b = Xᵀy.
        let mut a = vec![vec![0.0; m + 1]; m];
        for r in rows {
            for (p, row) in a.iter_mut().enumerate() {
                let xp = x(r, p);
                for (q, v) in row[..m].iter_mut().enumerate() {
                    *v += xp * x(r, q);
                }
                row[m] += xp * r.1;
            }
        }
        let Some(c) = solve_linear(a) else {
            continue;
        };
        if c.iter().any(|&v| v < 0.0) {
            continue;
        }
        let mut coef = [0.0; K];
        for (a, &k) in cols.iter().enumerate() {
            coef[k] = c[a] / scale[k];
        }
        let sse: f64 = rows
            .iter()
            .map(|r| {
                let p: f64 = (0..K).map(|k| coef[k] * r.0[k]).sum();
                (p - r.1) * (p - r.1)
            })
            .sum();
        if best.as_ref().is_none_or(|b| sse < b.0) {
            best = Some((sse, coef));
        }
    }
    best.map(|b| b.1)
}

/// Gaussian elimination with partial pivoting on the augmented matrix `a` (m rows of m + 1);
/// `None` when singular.
fn solve_linear(mut a: Vec<Vec<f64>>) -> Option<Vec<f64>> {
    let m = a.len();
    let big = a
        .iter()
        .enumerate()
        .map(|(i, r)| r[i].abs())
        .fold(0.0, f64::max);
    for col in 0..m {
        let piv = (col..m).max_by(|&p, &q| a[p][col].abs().total_cmp(&a[q][col].abs()))?;
        if a[piv][col].abs() <= 1e-12 * big.max(f64::MIN_POSITIVE) {
            return None;
        }
        a.swap(col, piv);
        let (top, rest) = a.split_at_mut(col + 1);
        let pivot = &top[col];
        for row in rest {
            let f = row[col] / pivot[col];
            for (v, p) in row[col..].iter_mut().zip(&pivot[col..]) {
                *v -= f * p;
            }
        }
    }
    let mut x = vec![0.0; m];
    for r in (0..m).rev() {
        let s: f64 = (r + 1..m).map(|c| a[r][c] * x[c]).sum();
        x[r] = (a[r][m] - s) / a[r][r];
    }
    Some(x)
}

/// Fits the hemi-cube constants (patch, face, cell, tested) to timed shots, minimising the
/// *relative* error (each shot weighted by 1/its time), so the small shots the hybrid decides
/// on count as much as the big ones.
pub fn fit_cube(shots: &[(ShotWork, f64)]) -> Option<[f64; 4]> {
    let rows: Vec<([f64; 4], f64)> = shots
        .iter()
        .filter(|s| s.1 > 0.0)
        .map(|(w, t)| (CubeWork::from(*w).terms().map(|x| x / t), 1.0))
        .collect();
    nonneg_least_squares(&rows)
}

/// The scene measure a ray's cost grows with: log₂ of the patch count (at least 1).
pub fn log2_patches(patches: usize) -> f64 {
    (patches.max(2) as f64).log2()
}

/// Fits the seconds per ray and log₂(patches) to timed ray shots (rays, patches of the
/// scene, seconds), on the relative error.
pub fn fit_rays(shots: &[(u64, usize, f64)]) -> Option<f64> {
    let rows: Vec<([f64; 1], f64)> = shots
        .iter()
        .filter(|s| s.2 > 0.0)
        .map(|&(x, n, t)| ([x as f64 * log2_patches(n) / t], 1.0))
        .collect();
    nonneg_least_squares(&rows).map(|c| c[0])
}

/// `--switch-by measured`: the measured cost of a hemi-cube shot, fitted as t = a + b·cells by
/// least squares over the shots so far (a: transforming and clipping every patch, b: scan
/// conversion and reading the cells back). Thread time, so it compares with the rays' thread
/// time per ray.
#[derive(Clone, Copy, Debug, Default)]
pub struct CubeCost {
    n: f64,
    sx: f64,
    sy: f64,
    sxx: f64,
    sxy: f64,
}

impl CubeCost {
    /// The running sums (for checkpoints).
    pub fn sums(&self) -> [f64; 5] {
        [self.n, self.sx, self.sy, self.sxx, self.sxy]
    }

    pub fn from_sums(s: [f64; 5]) -> CubeCost {
        CubeCost {
            n: s[0],
            sx: s[1],
            sy: s[2],
            sxx: s[3],
            sxy: s[4],
        }
    }

    pub fn add(&mut self, cells: usize, seconds: f64) {
        let x = cells as f64;
        self.n += 1.0;
        self.sx += x;
        self.sy += seconds;
        self.sxx += x * x;
        self.sxy += x * seconds;
    }

    pub fn samples(&self) -> usize {
        self.n as usize
    }

    /// Predicted seconds of a shot with `cells` cells (the mean when all shots had the same
    /// size, or the fit would give a negative slope or intercept).
    pub fn predict(&self, cells: usize) -> f64 {
        if self.n == 0.0 {
            return 0.0;
        }
        let mean_y = self.sy / self.n;
        let var = self.sxx - self.sx * self.sx / self.n;
        if var <= 1e-9 * self.sxx.max(1.0) {
            return mean_y;
        }
        let b = (self.sxy - self.sx * self.sy / self.n) / var;
        let a = mean_y - b * self.sx / self.n;
        if b < 0.0 || a < 0.0 {
            return mean_y;
        }
        a + b * cells as f64
    }
}

/// `--switch-by measured`: thread time per ray (s) of a few thousand rays from `patch`, cast
/// like a shot's but not applied. Twice, keeping the second (the first warms the caches up).
pub(super) fn probe<I: Intersector>(caster: &RayCaster<I>, patch: usize) -> f64 {
    let shot = RayShot {
        patch,
        index: u64::MAX - 1,
        phi: [0.0; 3],
        ch: Vec::new(),
        grid: PolarGrid::for_samples((2 * CHUNK) as f64),
    };
    let tasks = tasks_of(std::slice::from_ref(&shot));
    let mut per_ray = 0.0;
    for _ in 0..2 {
        let (secs, rays) = tasks
            .par_iter()
            .map(|t| {
                let t0 = Instant::now();
                let n = caster.cast(&shot, t.chunk, t.first, t.count).codes.len();
                (t0.elapsed().as_secs_f64(), n)
            })
            .reduce(|| (0.0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
        per_ray = secs / rays.max(1) as f64;
    }
    per_ray
}

/// What a checkpoint keeps of the switch policy (`SwitchPolicy::save`): what it has learnt
/// so far, so a resumed run decides as the uninterrupted one. [`super::checkpoint`] lays it
/// out in the file.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Saved {
    /// `adaptive-hybrid`: the hemi-cube shots' counted work so far.
    pub tally: WorkTally,
    /// `--switch-by measured`: the sums of the fit of hemi-cube shot times
    /// ([`CubeCost::sums`]), and the measured seconds per ray.
    pub cube_cost: [f64; 5],
    pub ray_cost: Option<f64>,
}

/// The hybrid's switch policy during one solve: what it has learnt so far (counted work, or
/// measured times) and the rule it applies.
pub(super) struct SwitchPolicy {
    by: SwitchBy,
    switch_at: Option<u64>,
    model: CostModel,
    /// Patches in the scene (each hemi-cube shot transforms all but its shooter).
    patches: usize,
    tally: WorkTally,
    cube_cost: CubeCost,
    ray_cost: Option<f64>,
}

impl SwitchPolicy {
    pub fn new(cfg: &SolveSettings, model: CostModel, patches: usize) -> SwitchPolicy {
        SwitchPolicy {
            by: cfg.switch_by,
            switch_at: cfg.switch_at,
            model,
            patches,
            tally: WorkTally::default(),
            cube_cost: CubeCost::default(),
            ray_cost: None,
        }
    }

    /// Carries on from a checkpoint.
    pub fn restore(&mut self, s: &Saved) {
        self.tally = s.tally;
        self.cube_cost = CubeCost::from_sums(s.cube_cost);
        self.ray_cost = s.ray_cost;
    }

    /// What a checkpoint keeps of it.
    pub fn save(&self) -> Saved {
        Saved {
            tally: self.tally,
            cube_cost: self.cube_cost.sums(),
            ray_cost: self.ray_cost,
        }
    }

    /// Books a hemi-cube shot of `cells` cells that did `hits.work` in `hits.seconds`.
    pub fn record(&mut self, cells: usize, hits: &CubeHits) {
        self.tally.add(&hits.work);
        if self.by == SwitchBy::Measured {
            self.cube_cost.add(cells, hits.seconds);
        }
    }

    /// Whether `rays` rays cost less by the counted model than the least a hemi-cube shot of
    /// `cells` cells can cost (no face clipped, no cell tested).
    fn rays_beat_any_cube(&self, rays: u64, cells: usize) -> bool {
        let (_, least, by_rays) = counted_costs(
            &self.model,
            &WorkTally::default(),
            self.patches,
            cells,
            rays,
        );
        by_rays < least
    }

    /// Before hemi-cube shot number `shot` with a cube of `cells` cells: `Some` (the costs it
    /// compared) when this shot and all after it are to be cast by `rays` rays instead.
    /// `probe` measures the seconds per ray (`--switch-by measured` only; called once).
    pub fn consider(
        &mut self,
        shot: u64,
        rays: u64,
        cells: usize,
        probe: impl FnOnce() -> f64,
    ) -> Option<SwitchInfo> {
        let forced = self.switch_at.is_some_and(|k| shot >= k);
        let ready = match self.by {
            // Before any hemi-cube shot the counted rule knows the work every shot does
            // (transforming the patches, clearing the cells), not yet the clipping and depth
            // tests: a lower bound of a hemi-cube shot's cost. Rays cheaper than that are
            // cheaper than any hemi-cube shot (a million-patch model: 20 ms to transform its
            // patches against 3 ms for a lamp's rays), and the hybrid casts rays from the first.
            SwitchBy::Counted => self.tally.shots >= 1 || self.rays_beat_any_cube(rays, cells),
            SwitchBy::Measured => self.cube_cost.samples() >= 2,
        };
        if !forced && (self.switch_at.is_some() || !ready) {
            return None;
        }
        let mut info = SwitchInfo {
            shot,
            rays,
            hemicube_cells: cells as u64,
            forced,
            by: self.by,
            ..SwitchInfo::default()
        };
        match self.by {
            SwitchBy::Counted => {
                let (work, by_cube, by_rays) =
                    counted_costs(&self.model, &self.tally, self.patches, cells, rays);
                info.seconds_per_ray = self.model.seconds_per_ray(self.patches);
                info.hemicube_shot_seconds = by_cube;
                info.ray_shot_seconds = by_rays;
                info.hemicube_faces = work.faces;
                info.hemicube_tested = work.tested;
            }
            SwitchBy::Measured => {
                let per_ray = *self.ray_cost.get_or_insert_with(probe);
                info.seconds_per_ray = per_ray;
                info.hemicube_shot_seconds = self.cube_cost.predict(cells);
                info.ray_shot_seconds = rays as f64 * per_ray;
            }
        }
        (forced || info.ray_shot_seconds < info.hemicube_shot_seconds).then_some(info)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn work(faces: u64, cells: u64, tested: u64) -> ShotWork {
        ShotWork {
            patches: 231,
            faces,
            cells,
            tested,
        }
    }

    /// Before any hemi-cube shot, the counted rule switches only when rays beat the least a
    /// hemi-cube shot can cost: at once on a million patches (a lamp's 10,368 rays against
    /// transforming every patch), never on a small scene, which learns its shots' work first.
    #[test]
    fn rays_from_the_first_shot_only_when_cheaper_than_any_cube() {
        let cfg = SolveSettings {
            switch_by: SwitchBy::Counted,
            ..SolveSettings::default()
        };
        let no_probe = || panic!("the counted rule never times rays");
        let mut big = SwitchPolicy::new(&cfg, KEPT, 1_000_000);
        let info = big
            .consider(0, 10_368, 12_296, no_probe)
            .expect("rays at once");
        assert!(info.ray_shot_seconds < info.hemicube_shot_seconds);
        assert_eq!(info.shot, 0);
        let mut small = SwitchPolicy::new(&cfg, KEPT, 5_000);
        assert!(small.consider(0, 50_000, 12_296, no_probe).is_none());
        // A big scene's lamp whose rays would cost more than transforming it waits as before.
        assert!(big.consider(0, 10_000_000, 12_296, no_probe).is_none());
    }

    #[test]
    fn measured_fit_recovers_a_line() {
        let mut c = CubeCost::default();
        for cells in [100, 400, 1600, 6400] {
            c.add(cells, 1e-4 + 2e-8 * cells as f64);
        }
        let p = c.predict(10_000);
        assert!((p - (1e-4 + 2e-4)).abs() < 1e-9, "{p}");
        let mut same = CubeCost::default();
        same.add(500, 1.0);
        same.add(500, 3.0);
        assert_eq!(same.predict(10), 2.0);
    }

    #[test]
    fn counted_fit_recovers_synthetic_constants() {
        let truth = CostModel {
            patch: 4e-8,
            face: 1.5e-7,
            cell: 2e-9,
            tested: 5e-9,
            ray: 1.3e-8,
        };
        let mut shots = Vec::new();
        for (k, cells) in [300u64, 3_000, 30_000, 300_000].into_iter().enumerate() {
            for f in [40u64, 90, 150] {
                let w = work(f + k as u64, cells, cells * (f % 7 + 1) / 2);
                shots.push((w, truth.cube_seconds(&w.into())));
            }
        }
        let fit = fit_cube(&shots).unwrap();
        for (got, want) in fit.iter().zip(truth.cube_coefficients()) {
            assert!((got - want).abs() < 1e-6 * want, "{fit:?}");
        }
        let rays: Vec<(u64, usize, f64)> = [(256u64, 232), (1024, 2092), (4096, 5267)]
            .iter()
            .map(|&(x, n)| (x, n, truth.ray_seconds(x, n)))
            .collect();
        let r = fit_rays(&rays).unwrap();
        assert!((r - truth.ray).abs() < 1e-9 * truth.ray, "{r}");
    }

    #[test]
    fn nonnegative_fit_drops_a_column_rather_than_go_negative() {
        // y = 2·x0 exactly, x1 noise that a free fit would give a negative weight.
        let rows = [
            ([1.0, 1.0], 2.0),
            ([2.0, 0.0], 4.1),
            ([3.0, 2.0], 5.9),
            ([4.0, 0.5], 8.0),
        ];
        let c = nonneg_least_squares(&rows).unwrap();
        assert!(c.iter().all(|&x| x >= 0.0), "{c:?}");
        assert!((c[0] - 2.0).abs() < 0.1, "{c:?}");
        assert!(nonneg_least_squares::<2>(&[]).is_none());
    }

    #[test]
    fn counted_switch_is_a_pure_function_of_counts() {
        let mut tally = WorkTally::default();
        tally.add(&work(120, 30_000, 60_000));
        tally.add(&work(80, 10_000, 20_000));
        // Faces: 100 per shot; tested: 2 per cell.
        let (w, cube, rays) = counted_costs(&KEPT, &tally, 232, 5_000, 600);
        assert_eq!(w.patches, 231.0);
        assert_eq!(w.faces, 100.0);
        assert_eq!(w.tested, 10_000.0);
        assert_eq!(
            cube,
            231.0 * KEPT.patch + 100.0 * KEPT.face + 5_000.0 * KEPT.cell + 10_000.0 * KEPT.tested
        );
        assert_eq!(rays, 600.0 * KEPT.ray * 232f64.log2());
        // The same counts give the same answer, bit for bit, every time.
        assert_eq!(
            (w, cube, rays),
            counted_costs(&KEPT, &tally, 232, 5_000, 600)
        );

        // The policy: before the first shot, only the least a hemi-cube shot can cost to go by
        // (transforming the patches, clearing the cells); then rays once they are cheaper.
        let cfg = SolveSettings::default();
        let mut p = SwitchPolicy::new(&cfg, KEPT, 232);
        let no_probe = || panic!("counted never measures");
        let least = 231.0 * KEPT.patch + 5_000.0 * KEPT.cell;
        let above_least = (2.0 * least / KEPT.seconds_per_ray(232)) as u64;
        assert!(p.consider(0, above_least, 5_000, no_probe).is_none());
        assert!(p.consider(0, 1, 5_000, no_probe).is_some());
        let hits = CubeHits {
            work: work(100, 5_000, 10_000),
            ..CubeHits::default()
        };
        p.record(5_000, &hits);
        let cheap_rays = (cube / KEPT.seconds_per_ray(232)) as u64 / 2;
        let s = p
            .consider(8, cheap_rays, 5_000, no_probe)
            .expect("rays cheaper");
        assert_eq!(
            (s.shot, s.rays, s.forced, s.by),
            (8, cheap_rays, false, SwitchBy::Counted)
        );
        // Four times the rays cost twice the hemi-cube's shot: no switch.
        assert!(p.consider(8, cheap_rays * 4, 5_000, no_probe).is_none());

        // Forced: at the shot asked for, whatever the costs.
        let forced = SolveSettings {
            switch_at: Some(3),
            ..cfg
        };
        let mut p = SwitchPolicy::new(&forced, KEPT, 232);
        assert!(p.consider(2, 1, 5_000, no_probe).is_none());
        let s = p.consider(3, 1 << 30, 5_000, no_probe).expect("forced");
        assert!(s.forced);
    }
}
