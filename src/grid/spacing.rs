//! How far apart points from a file are: the median distance from a point to its nearest
//! neighbour on the same storey, seen from above. The plan draws each such point as a cell of
//! that size, so points on a lattice tile the plan as a work plane does.

use glam::DVec2;
use std::collections::HashMap;

/// Points whose nearest neighbour is looked for, at most (evenly strided): the median of a few
/// thousand distances is steady, and the cost stays small for millions of points.
const SAMPLE: usize = 4096;

/// The median nearest-neighbour distance in the plan between points of the same storey, or
/// `None` if no point has a distinct neighbour on its storey.
pub(super) fn estimate(plan: &[DVec2], storey: &[u32]) -> Option<f64> {
    let index = Buckets::new(plan)?;
    let stride = plan.len().div_ceil(SAMPLE).max(1);
    let mut d: Vec<f64> = (0..plan.len())
        .step_by(stride)
        .filter_map(|k| index.nearest(plan, storey, k))
        .collect();
    if d.is_empty() {
        return None;
    }
    d.sort_by(f64::total_cmp);
    Some(d[d.len() / 2])
}

/// The points binned in square buckets of about one point each.
struct Buckets {
    lo: DVec2,
    size: f64,
    /// Buckets along the longer side: no ring search goes further.
    across: i64,
    /// Distances at or below this are the same place (duplicates, not neighbours).
    same: f64,
    cells: HashMap<(i64, i64), Vec<u32>>,
}

impl Buckets {
    fn new(plan: &[DVec2]) -> Option<Buckets> {
        let first = *plan.first()?;
        let (lo, hi) = plan
            .iter()
            .fold((first, first), |(l, h), p| (l.min(*p), h.max(*p)));
        let extent = (hi - lo).max_element();
        if !(extent > 0.0 && extent.is_finite()) {
            return None;
        }
        let size = extent / (plan.len() as f64).sqrt();
        let mut b = Buckets {
            lo,
            size,
            across: (extent / size).ceil() as i64 + 1,
            same: 1e-9 * extent,
            cells: HashMap::new(),
        };
        for (k, p) in plan.iter().enumerate() {
            b.cells.entry(b.key(*p)).or_default().push(k as u32);
        }
        Some(b)
    }

    fn key(&self, p: DVec2) -> (i64, i64) {
        let c = ((p - self.lo) / self.size).floor();
        (c.x as i64, c.y as i64)
    }

    /// Distance from point `k` to its nearest distinct neighbour on the same storey: rings of
    /// buckets outwards until the best found is nearer than any bucket further out.
    fn nearest(&self, plan: &[DVec2], storey: &[u32], k: usize) -> Option<f64> {
        let (ci, cj) = self.key(plan[k]);
        let mut best = f64::INFINITY;
        for r in 0..=self.across {
            if best <= (r - 1).max(0) as f64 * self.size {
                break;
            }
            for key in ring(ci, cj, r) {
                for &m in self.cells.get(&key).into_iter().flatten() {
                    let m = m as usize;
                    let d = plan[m].distance(plan[k]);
                    if storey[m] == storey[k] && d > self.same {
                        best = best.min(d);
                    }
                }
            }
        }
        best.is_finite().then_some(best)
    }
}

/// The buckets at Chebyshev distance `r` from (i, j).
fn ring(i: i64, j: i64, r: i64) -> impl Iterator<Item = (i64, i64)> {
    (-r..=r).flat_map(move |di| {
        (-r..=r)
            .filter(move |dj| di.abs() == r || dj.abs() == r)
            .map(move |dj| (i + di, j + dj))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_spacing_of_a_lattice_is_its_pitch() {
        let plan: Vec<DVec2> = (0..40)
            .flat_map(|i| (0..25).map(move |j| DVec2::new(i as f64 * 0.6, j as f64 * 0.6 - 3.0)))
            .collect();
        let one = vec![0; plan.len()];
        let s = estimate(&plan, &one).unwrap();
        assert!((s - 0.6).abs() < 1e-9, "{s}");
        // The same lattice twice, one storey above the other: the storeys do not mix.
        let twice: Vec<DVec2> = plan.iter().chain(&plan).copied().collect();
        let storeys: Vec<u32> = (0..twice.len()).map(|k| (k >= plan.len()) as u32).collect();
        assert!((estimate(&twice, &storeys).unwrap() - 0.6).abs() < 1e-9);
    }

    #[test]
    fn grid_spacing_needs_two_distinct_points() {
        assert_eq!(estimate(&[], &[]), None);
        assert_eq!(estimate(&[DVec2::ONE; 3], &[0; 3]), None);
        let two = [DVec2::ZERO, DVec2::new(3.0, 4.0)];
        assert_eq!(estimate(&two, &[0, 1]), None);
        assert_eq!(estimate(&two, &[0, 0]), Some(5.0));
    }
}
