//! Adaptive elements (docs/design.md §11; Cohen, Greenberg, Immel & Brock 1986, *An efficient
//! radiosity approach for realistic image synthesis*, IEEE CG&A 6(3), Sec. 3 "substructuring"):
//! patches shoot, elements receive.
//!
//! The solve runs on the patches. Afterwards each patch is cut into *elements* in its own
//! parametric domain ([`geometry`]: quads into four at their edge midpoints, triangles into
//! four similar ones, n-gons fan-triangulated first), and an element is cut again while the
//! radiosity at its corners differs by more than a threshold — shadow boundaries, corners,
//! beside lights — down to a minimum size ([`refine`](mod@refine)). The corners' radiosity is gathered at
//! the corner itself, with the patch solution as the cache of the indirect light
//! ([`crate::light::LightAt`], in place of Cohen 1986's vertex hemi-cubes).
//! Unshot energy stays on the patches: the elements move no energy, and the energy books are
//! the patches'. The elements are what is shown and exported ([`display`]): Gouraud shading on
//! the elements' vertex radiosities is exactly Cohen 1986's display. So the light is smooth
//! where the patches are large and sharp where the elements are small — a better picture for
//! fewer patches than uniform meshing (README, "Adaptive elements", measures it;
//! docs/design.md §11).
//!
//! Outputs: `elements.csv` (the columns of `patches.csv` and the element's `patch`; an
//! element's B is the mean of its corners' radiosities, which for a quad is its bilinear
//! value at the centre), `render.png` and the exports drawn from the elements, and the
//! element mesh in the saved solution (format 2).

pub mod display;
pub mod geometry;
mod indirect;
mod points;
pub mod refine;
mod work;

use crate::intersect::Intersector;
use crate::light::LightAt;
use crate::mesh::Mesh;
use crate::solve::scalar;
use geometry::Elem;
use glam::DVec2;
use serde::{Deserialize, Serialize};
use std::time::Instant;

pub use refine::{CornerLight, Rule, Stop, Test};

/// Default `--element-threshold` ([`Test::Halves`]): an element is cut while the error of
/// its interpolation, relative to its mean and weighed by its share of its patch, exceeds
/// this (README, "Adaptive elements": on `scenes/spot.obj` 0.47 of uniform meshing's error at
/// the same count, with [`DEFAULT_RAYS`]-ray corners against a 2,048-ray reference).
pub const DEFAULT_THRESHOLD: f64 = 0.02;
/// Default smallest element, as a fraction of the patch size.
pub const DEFAULT_MIN_FRACTION: f32 = 1.0 / 8.0;
/// Default `--element-rays`: with the default [`CornerLight::Split`], the rays of each
/// indirect node's gather, 3/8 as many for each corner's direct light. With the patches
/// setting the level (`display`'s notes) 64 reach about the error [`CornerLight::Full`] had
/// at 256 on `scenes/spot.obj` (docs/results/adaptive-elements.md); [`CornerLight::Full`]
/// wants 256 (at 128 the corners' own noise is a floor the meshing cannot go under).
pub const DEFAULT_RAYS: usize = 64;
/// Default cap on the elements, as a multiple of the patches.
pub const DEFAULT_MAX_FACTOR: f64 = 8.0;
/// `--elements auto` (the default) refines the elements of meshes up to this many patches
/// and skips them, with a line, above: with the split corners on the patches that see
/// geometry nearby their rays stay under the solve's (the office 0.98, the furnished office
/// 0.27, a generated 100 k-patch building 0.63 of the solve's and final gather's rays;
/// docs/results/adaptive-elements.md), but their elements' memory grows with the model.
pub const AUTO_MAX_PATCHES: u64 = 1_000_000;
/// Below this fraction of the scene's mean radiosity, differences count as if at it (dark
/// corners are not refined for noise).
pub const FLOOR: f64 = 1e-3;

/// The test takes this many standard deviations of the indirect nodes' noise
/// (`refine::Refiner::test_noise`) off a difference (in quadrature: √(d² − z²σ²)) before it weighs
/// it against the threshold: in a uniformly lit room the differences are that noise alone,
/// and a threshold on the light cannot tell them from a shadow's. Measured on a closed box
/// whose every patch emits (the furnace test; seeds 1–20, split corners at 64 rays): 8
/// elements cut in all with nothing taken off, 2 with one σ, none with 1.5, 2 or 3; on
/// `bench elements scenes/spot.obj --tests halves` at 0.02: 1.19 % error with nothing taken
/// off, 1.22 % with 1.5, 1.23 % with 2 (ratio 0.49 to uniform meshing). A bare cut-off (cut
/// only above 3σ) left one cut in the 20 and 1.27 % (docs/results/adaptive-elements.md).
const NOISE_Z: f64 = 2.0;

/// How the patches are cut into elements (`radiosity solve --elements …`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ElementSettings {
    /// Refine adaptive elements after the solve (`--elements auto|on|off`); off, the elements
    /// are the patches.
    pub enabled: bool,
    /// `--elements auto`: refine only meshes of at most this many patches (`None`: any).
    pub auto_limit: Option<u64>,
    /// `--element-threshold`: cut an element while the difference [`Test`] measures exceeds
    /// this fraction of its corners' mean (Cohen 1986 Sec. 3).
    pub threshold: f64,
    /// `--element-min-size`: the smallest element edge (metres); `None`: the patch size / 8.
    pub min_size: Option<f32>,
    /// `--element-rays`: rays of each corner's gather.
    pub rays: usize,
    /// At most this many times as many elements as patches (`--element-max`); the largest
    /// differences are cut first when the cap is met.
    pub max_factor: f64,
    /// What the threshold is applied to (`--element-test`).
    pub test: Test,
    /// What is gathered at the corners (`--element-light`).
    pub light: CornerLight,
}

impl Default for ElementSettings {
    fn default() -> Self {
        ElementSettings {
            enabled: true,
            auto_limit: Some(AUTO_MAX_PATCHES),
            threshold: DEFAULT_THRESHOLD,
            min_size: None,
            rays: DEFAULT_RAYS,
            max_factor: DEFAULT_MAX_FACTOR,
            test: Test::Halves,
            light: CornerLight::Split,
        }
    }
}

impl ElementSettings {
    /// Checks what a user can get wrong (one line naming the flag).
    pub fn check(&self) -> Result<(), crate::settings::Invalid> {
        use crate::settings::Invalid;
        if !(self.threshold > 0.0 && self.threshold.is_finite()) {
            return Invalid::err(format!(
                "--element-threshold must be a positive fraction such as 0.1, got {}",
                self.threshold
            ));
        }
        if let Some(s) = self.min_size {
            if !(s > 0.0 && s.is_finite()) {
                return Invalid::err(format!(
                    "--element-min-size must be a positive length in metres, got {s}"
                ));
            }
        }
        if !(2..=1_000_000).contains(&self.rays) {
            return Invalid::err(format!(
                "--element-rays must be between 2 and 1000000, got {}",
                self.rays
            ));
        }
        if !(self.max_factor >= 1.0 && self.max_factor <= 4096.0) {
            return Invalid::err(format!(
                "--element-max must be between 1 and 4096 (elements per patch), got {}",
                self.max_factor
            ));
        }
        Ok(())
    }

    /// Whether to refine the elements of a mesh of `patches` patches.
    pub fn applies_to(&self, patches: usize) -> bool {
        self.enabled && self.auto_limit.is_none_or(|n| patches as u64 <= n)
    }

    /// The smallest element edge for patches of size `patch_size`.
    pub fn min_size_for(&self, patch_size: f32) -> f32 {
        self.min_size.unwrap_or(patch_size * DEFAULT_MIN_FRACTION)
    }
}

/// What the refinement did (`summary.json`: `elements`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ElementStats {
    /// Elements kept.
    pub count: u64,
    /// Patches they were cut from.
    pub patches: u64,
    /// Welded element vertices.
    pub vertices: u64,
    /// Points gathered: the corners and the points the test reads, each once for all the
    /// patches that have it (and, split, the indirect light's nodes).
    pub gathered: u64,
    /// Rays cast by the corners' gathers.
    pub rays: u64,
    /// Wall-clock seconds.
    pub seconds: f64,
    /// The threshold and the smallest element edge used (metres).
    pub threshold: f64,
    pub min_size: f64,
    /// Rays per corner.
    pub rays_per_corner: u64,
    /// Whether the cap on the elements stopped the refinement.
    pub capped: bool,
    /// `--element-light split`: the patches that gathered their indirect light at nodes (the
    /// others' is the patch solution's).
    #[serde(default)]
    pub indirect_patches: u64,
    /// Whether Ctrl-C stopped it (the elements refined by then are kept).
    #[serde(default)]
    pub interrupted: bool,
    /// Whether `--max-time` stopped it (likewise).
    #[serde(default)]
    pub out_of_time: bool,
}

/// The element mesh of a solution: what is shown and exported.
#[derive(Clone, Debug, PartialEq)]
pub struct Elements {
    /// The elements as mesh records (material, polygon, normal, area, centre of their patch's
    /// surface) on welded vertices; all one-sided (the sides are the patches').
    pub mesh: Mesh,
    /// The patch each element was cut from.
    pub patch: Vec<u32>,
    /// Radiosity at the element mesh's vertices (W/m², RGB): the gathered values, made to
    /// conform across T-junctions ([`display`]).
    pub vertex_b: Vec<[f32; 3]>,
    /// Radiosity per element: the mean of its corners' `vertex_b`.
    pub b: Vec<[f64; 3]>,
    /// Each element in its patch's parameters (empty for elements read from a file).
    pub params: Vec<Elem>,
}

impl Elements {
    /// Elements from their mesh, patch ids and vertex values (B per element derived).
    pub fn new(mesh: Mesh, patch: Vec<u32>, vertex_b: Vec<[f32; 3]>) -> Elements {
        let b = (0..mesh.patches.len())
            .map(|e| {
                let ids = mesh.patch_indices(e);
                let mut s = [0.0f64; 3];
                for &v in ids {
                    for c in 0..3 {
                        s[c] += vertex_b[v as usize][c] as f64;
                    }
                }
                s.map(|x| x / ids.len().max(1) as f64)
            })
            .collect();
        Elements {
            mesh,
            patch,
            vertex_b,
            b,
            params: Vec::new(),
        }
    }

    /// The patches themselves as elements (`--elements off`, and solutions saved before
    /// elements): the patch radiosities averaged to the welded vertices, B per patch as solved.
    pub fn of_patches(mesh: &Mesh, b: &[[f64; 3]]) -> Elements {
        Elements {
            mesh: mesh.clone(),
            patch: (0..mesh.patches.len() as u32).collect(),
            vertex_b: mesh.vertex_values(b),
            b: b.to_vec(),
            params: Vec::new(),
        }
    }

    /// Whether these elements are the patches of `mesh` with radiosity `b` themselves (what
    /// [`Elements::of_patches`] makes): one element per patch, in patch order, with the
    /// patch's material, centre, normal, area and radiosity — every column of its row in
    /// `elements.csv` but the last is then its patch's in `patches.csv`.
    pub fn are_the_patches(&self, mesh: &Mesh, b: &[[f64; 3]]) -> bool {
        let same = |(e, p): (&crate::mesh::Patch, &crate::mesh::Patch)| {
            (e.material, e.area, e.centre, e.normal) == (p.material, p.area, p.centre, p.normal)
        };
        self.mesh.patches.len() == mesh.patches.len()
            && self.b == b
            && (self.patch.iter().enumerate()).all(|(k, &p)| p as usize == k)
            && (self.mesh.patches.iter().zip(&mesh.patches)).all(same)
    }

    /// The radiosity the elements interpolate at parameters `uv` of root `root` of patch
    /// `patch` (bilinear in a quad element, barycentric in a triangle; what Gouraud shading
    /// shows up to the triangulation of quads), when an element there is known.
    pub fn value_at(
        &self,
        first: &[usize],
        patch: usize,
        root: u32,
        uv: DVec2,
    ) -> Option<[f64; 3]> {
        let (lo, hi) = (*first.get(patch)?, *first.get(patch + 1)?);
        for e in lo..hi {
            let el = self.params.get(e)?;
            if el.root != root {
                continue;
            }
            if let Some(w) = el.weights(uv) {
                let ids = self.mesh.patch_indices(e);
                let mut v = [0.0; 3];
                for (k, &id) in ids.iter().enumerate() {
                    for (x, &b) in v.iter_mut().zip(&self.vertex_b[id as usize]) {
                        *x += w[k] * b as f64;
                    }
                }
                return Some(v);
            }
        }
        None
    }

    /// Where each patch's elements start (elements are kept in patch order), with the end last.
    pub fn first_of_patches(&self, patches: usize) -> Vec<usize> {
        let mut first = vec![self.patch.len(); patches + 1];
        for (e, &p) in self.patch.iter().enumerate().rev() {
            first[p as usize] = e;
        }
        for p in (0..patches).rev() {
            first[p] = first[p].min(first[p + 1]);
        }
        first
    }
}

/// The area-weighted mean scalar radiosity of a patch solution.
pub fn mean_radiosity(mesh: &Mesh, b: &[[f64; 3]]) -> f64 {
    let (mut s, mut a) = (0.0, 0.0);
    for (p, v) in mesh.patches.iter().zip(b) {
        s += scalar(v) * p.area;
        a += p.area;
    }
    if a > 0.0 {
        s / a
    } else {
        0.0
    }
}

/// Cohen 1986 Sec. 3: refines the elements of the patch solution `b` of `mesh` as `settings`
/// say, each corner gathered through `gather` (built over `mesh` and `b`) with random numbers
/// from `seed`.
pub fn refine<I: Intersector>(
    mesh: &Mesh,
    gather: &LightAt<'_, I>,
    b: &[[f64; 3]],
    settings: &ElementSettings,
    seed: u64,
) -> (Elements, ElementStats) {
    refine_until(mesh, gather, b, settings, seed, Stop::default())
}

/// [`refine()`], stopping early (keeping what is refined) on Ctrl-C or at a deadline.
pub fn refine_until<I: Intersector>(
    mesh: &Mesh,
    gather: &LightAt<'_, I>,
    b: &[[f64; 3]],
    settings: &ElementSettings,
    seed: u64,
    stop: Stop<'_>,
) -> (Elements, ElementStats) {
    let min_size = settings.min_size_for(mesh.patch_size) as f64;
    let rule = Rule::Adaptive {
        threshold: settings.threshold,
        floor: FLOOR * mean_radiosity(mesh, b),
        min_size,
        test: settings.test,
    };
    let cap = (settings.max_factor * mesh.patches.len() as f64).ceil() as usize;
    let corners = Corners {
        rays: settings.rays,
        light: settings.light,
    };
    let (el, mut stats) = refine_by(mesh, gather, b, rule, corners, cap, seed, stop);
    stats.threshold = settings.threshold;
    stats.min_size = min_size;
    (el, stats)
}

/// What each corner gathers: `rays` rays of `light`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Corners {
    pub rays: usize,
    pub light: CornerLight,
}

/// [`refine()`] by any [`Rule`] (the uniform meshing it is measured against), with `corners`
/// gathered as it says and at most `cap` elements, stopping early as `stop` says.
// Eight: the mesh, its light and its solution, and the five choices of a refinement (what is
// cut, what is gathered, the cap, the seed, what stops it), each of which the bench varies.
#[allow(clippy::too_many_arguments)]
pub fn refine_by<I: Intersector>(
    mesh: &Mesh,
    gather: &LightAt<'_, I>,
    b: &[[f64; 3]],
    rule: Rule,
    corners: Corners,
    cap: usize,
    seed: u64,
    stop: Stop<'_>,
) -> (Elements, ElementStats) {
    let Corners { rays, light } = corners;
    let t = Instant::now();
    let (lo, hi) = mesh.vertices.iter().fold(
        (glam::Vec3::splat(f32::MAX), glam::Vec3::splat(f32::MIN)),
        |(l, h), v| (l.min(*v), h.max(*v)),
    );
    let diagonal = (hi - lo).length().max(f32::MIN_POSITIVE) as f64;
    let threshold = match rule {
        Rule::Adaptive { threshold, .. } => threshold,
        Rule::Uniform(_) => DEFAULT_THRESHOLD,
    };
    // Split: which patches see geometry near enough to gather their indirect light at nodes.
    let (near, probe_rays) = match light {
        CornerLight::Split => indirect::near_patches(mesh, gather, b, seed, threshold),
        _ => (Vec::new(), 0),
    };
    let indirect_patches = near.iter().filter(|&&n| n).count() as u64;
    let r = refine::Refiner {
        mesh,
        gather,
        b,
        seed,
        // Split: 3/8 of the rays to each corner's direct light, all of them to each node of
        // the indirect light (docs/results/adaptive-elements.md: a quarter, 16 at the default,
        // left a stretch of spot.obj's table shadow unrefined; half cost the office 1.3 times
        // the rays).
        rays: if light == CornerLight::Split {
            (rays * 3 / 8).max(2)
        } else {
            rays
        },
        light,
        indirect_rays: rays,
        near,
        quantum: diagonal * 1e-6,
        inner: refine::inner_edges(mesh),
        stop,
    };
    let (work, values, capped) = refine::run(&r, rule, cap.max(mesh.patches.len()));
    let gathered = values.gathered;
    let built = display::build(&r, work, values.rays + probe_rays);
    let vertex_b: Vec<[f32; 3]> = built.vertex_b.iter().map(|v| v.map(|x| x as f32)).collect();
    let mut el = Elements::new(built.mesh, built.patch, vertex_b);
    el.params = built.elems;
    let stats = ElementStats {
        count: el.mesh.patches.len() as u64,
        patches: mesh.patches.len() as u64,
        vertices: el.mesh.vertices.len() as u64,
        gathered,
        rays: built.rays,
        seconds: t.elapsed().as_secs_f64(),
        threshold: 0.0,
        min_size: 0.0,
        rays_per_corner: rays as u64,
        capped,
        indirect_patches,
        interrupted: stop.interrupted(),
        out_of_time: stop.out_of_time(),
    };
    (el, stats)
}
