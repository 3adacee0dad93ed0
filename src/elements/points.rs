//! The points the refinement gathers (`super::refine`, "Shared points", "Told by the
//! corners"): what a point gathers (its direct light, or all of it), the points a level's tests
//! need with the points each lies between, and their gathers in parallel, the corners first,
//! the points between them handed what the corners' shadow rays told.

use super::refine::{big_enough, test_points, CornerLight, Refiner, Rule};
use super::work::{gather_new, At, Direct, Parents, PatchWork, Values, NO_PARENTS};
use crate::intersect::Intersector;
use crate::light::{LightParts, PartAt, Vis};
use crate::solve::{rng_for, Stream};
use glam::{DVec2, DVec3};
use rustc_hash::FxHashMap as HashMap;

impl<I: Intersector> Refiner<'_, I> {
    /// Gathers at `x`, as patch `patch` (module notes): the direct light, or all of it; the
    /// direct light taking the whole faces `known` tells as told ("Told by the corners").
    fn gather_one(&self, patch: usize, x: DVec3, known: Vis) -> (Direct, u64) {
        let parts = match self.light {
            CornerLight::Full => LightParts::All,
            CornerLight::Direct | CornerLight::Split => LightParts::DirectWhole,
        };
        let (b, got) = self.gather_told(patch, x, (self.rays, parts), known);
        let polygon = self.mesh.patches[patch].polygon;
        let vis = got.vis;
        (Direct { b, vis, polygon }, got.rays)
    }

    /// Gathers `parts` of the light at `x` with `rays` rays, as patch `patch`: its value (0
    /// where not finite), the variance and the rays.
    pub(super) fn gather_part(
        &self,
        patch: usize,
        x: DVec3,
        parts: LightParts,
        rays: usize,
    ) -> ([f64; 3], f64, u64) {
        let (b, got) = self.gather_told(patch, x, (rays, parts), Vis::default());
        (b, got.var, got.rays)
    }

    /// [`Self::gather_part`], the whole faces `known` tells taken as told, with all the gather
    /// found ([`PartAt`]); every point of a polygon draws from the generator seeded alike
    /// ("Common random numbers").
    fn gather_told(
        &self,
        patch: usize,
        x: DVec3,
        ask: (usize, LightParts),
        known: Vis,
    ) -> ([f64; 3], PartAt) {
        let polygon = self.mesh.patches[patch].polygon as u64;
        let mut rng = rng_for(self.seed, Stream::Elements, polygon);
        let got = (self.gather).part_told_at(patch, &[x.as_vec3()], ask, known, &mut rng);
        let b = (got.b)
            .to_array()
            .map(|x| if x.is_finite() { x.max(0.0) } else { 0.0 });
        (b, got)
    }

    /// Gathers the points `want` lists for each patch (the points' parameters, by root, each
    /// with the points it lies between: none for a corner) that `values` does not hold yet:
    /// each new one once, by the lowest-numbered patch asking, in parallel ([`gather_new`]);
    /// first the points that lie between none, then the others, handed what those all told
    /// ("Told by the corners").
    pub(super) fn gather_all(
        &self,
        work: &[PatchWork],
        want: impl Fn(&PatchWork) -> Vec<(u32, DVec2, Parents)> + Sync + Send,
        values: &mut Values,
    ) {
        let list = |i: usize| want(&work[i]);
        let locate =
            |i: usize, (root, uv, _): (u32, DVec2, Parents)| self.at(i, &work[i], root, uv);
        let later = |(_, _, p): (u32, DVec2, Parents)| p.1 > 0;
        let gather =
            |map: &HashMap<At, Direct>, i: usize, (root, _, p): (u32, DVec2, Parents), x| {
                let parents = &p.0[..p.1 as usize];
                let polygon = self.mesh.patches[i].polygon;
                let known = (parents.iter())
                    .map(|&uv| {
                        let at = self.at(i, &work[i], root, uv).0;
                        let d = map.get(&at).filter(|d| d.polygon == polygon);
                        d.map_or(Vis::default(), |d| d.vis)
                    })
                    .reduce(Vis::and)
                    .unwrap_or_default();
                self.gather_one(i, x, known)
            };
        let patches = (work.len(), |k| k);
        let blank = Direct::default();
        let (rays, gathered) = gather_new(
            &mut values.map,
            patches,
            (list, locate, later),
            gather,
            blank,
        );
        values.rays += rays;
        values.gathered += gathered;
    }

    /// The points patch `patch`'s active elements need for `rule`'s decisions, each with the
    /// points it lies between ([`test_points`]).
    pub(super) fn wanted(&self, w: &PatchWork, rule: Rule) -> Vec<(u32, DVec2, Parents)> {
        let Rule::Adaptive { min_size, test, .. } = rule else {
            return Vec::new();
        };
        (w.active.iter())
            .filter(|e| big_enough(e, w, min_size))
            .flat_map(|e| {
                let c = e.corners_uv();
                let n = c.len();
                (test_points(e, test).into_iter().enumerate()).map(move |(k, uv)| {
                    let mut p = NO_PARENTS;
                    if k >= n && k < 2 * n {
                        // The midpoint of edge k − n.
                        p = ([c[k - n], c[(k - n + 1) % n], uv, uv], 2);
                    } else if k >= 2 * n {
                        p.0[..n].copy_from_slice(c);
                        p.1 = n as u8;
                    }
                    (e.root, uv, p)
                })
            })
            .collect()
    }
}
