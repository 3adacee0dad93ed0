//! Cross-validation and speed of the intersectors: the library side of `radiosity crosscheck`
//! and `radiosity bench intersect`.
//!
//! The same rays go through every intersector: half cast as the solver casts them (a patch
//! picked by area, a uniform point on it, a cosine-distributed direction about its normal, the
//! origin offset along the normal, hits on the shooter itself skipped), half uniformly random
//! (origin uniform in the scene's bounds, direction uniform on the sphere). Each disagreement
//! on the hit patch is classified against the oracle (brute force in f64 when the scene is
//! small enough, else pairwise):
//!
//! - **edge**: the crossing point of either answer lies within `eps` (relative to the scene's
//!   diagonal) of an edge of the patch it hit — the two intersectors split a shared edge
//!   differently, or one took a crack-sealing tolerance;
//! - **grazing**: the ray is within 1e-4 (in cosine) of either hit patch's plane, where the
//!   crossing point is ill-conditioned;
//! - **coincident**: both hit parallel patches at the same distance — coplanar overlapping
//!   patches (a two-sided surface), where each intersector picks one by its own rule;
//! - **real**: anything else. The bar is zero.
//!
//! Rays from patch surfaces that hit nothing are escapes: a closed scene must have none.
//! Everything runs in parallel over chunks of rays whose random numbers come from (seed,
//! chunk), and the chunks' results are combined in order, so a report depends on the seed only.

use crate::intersect::brute::BruteForce;
use crate::intersect::embree::{set_flush_denormals, EmbreeError, EmbreeScene};
use crate::intersect::hybrid::Hybrid;
use crate::intersect::plane_merge::PlaneMerge;
use crate::intersect::select::AnyIntersector;
use crate::intersect::{Hit, Intersector, Ray};
use crate::mesh::{Mesh, PatchClass};
use crate::sample::Frame;
use glam::{DVec3, Vec3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use rayon::prelude::*;

/// Brute force (the oracle) runs only on scenes of at most this many patches.
pub const BRUTE_MAX_PATCHES: usize = 2000;
/// Rays per parallel task.
const CHUNK: u64 = 4096;
/// Real disagreements kept as examples, per pair.
const MAX_EXAMPLES: usize = 10;
/// |cos| between a ray and a plane below which a crossing is grazing.
const GRAZING_COS: f64 = 1e-4;

/// How a test ray was made.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum RaySource {
    /// From a patch surface, cosine distributed, as the solver casts.
    Surface,
    /// Origin uniform in the bounds, direction uniform on the sphere.
    Uniform,
}

/// One test ray.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct TestRay {
    pub org: [f32; 3],
    pub dir: [f32; 3],
    pub source: RaySource,
    /// The patch a surface ray leaves (its hits are skipped, as the solver does).
    pub shooter: Option<u32>,
    /// The solver's step past a hit on the shooter.
    #[serde(skip)]
    pub eps: f32,
}

impl TestRay {
    pub fn ray(&self) -> Ray {
        Ray {
            org: Vec3::from(self.org),
            dir: Vec3::from(self.dir),
            tnear: 0.0,
            tfar: f32::INFINITY,
        }
    }
}

/// The rays the solver casts and uniform ones, reproducible from a seed.
pub struct RayGen<'a> {
    mesh: &'a Mesh,
    /// Cumulative patch areas.
    cdf: Vec<f64>,
    lo: Vec3,
    hi: Vec3,
    eps_floor: f32,
}

impl<'a> RayGen<'a> {
    pub fn new(mesh: &'a Mesh) -> RayGen<'a> {
        let mut total = 0.0;
        let cdf = mesh
            .patches
            .iter()
            .map(|p| {
                total += p.area;
                total
            })
            .collect();
        let (lo, hi) = bounds(mesh);
        // The solver's floor on the origin offset: a few ulps of the largest coordinate.
        let eps_floor = lo.abs().max(hi.abs()).max_element() * 5e-7;
        RayGen {
            mesh,
            cdf,
            lo,
            hi,
            eps_floor,
        }
    }

    /// The `count` rays of chunk `chunk` of the stream for `seed` (each chunk of 4096 has its
    /// own generator, so chunks can be made in parallel): even positions from surfaces, odd
    /// ones uniform.
    fn chunk(&self, seed: u64, chunk: u64, count: u64, out: &mut Vec<TestRay>) {
        out.clear();
        let mut rng = Pcg64Mcg::seed_from_u64(mix(mix(seed) ^ chunk));
        for k in 0..count {
            let surface = k % 2 == 0 && !self.mesh.patches.is_empty();
            out.push(if surface {
                self.surface_ray(&mut rng)
            } else {
                self.uniform_ray(&mut rng)
            });
        }
    }

    /// `n` rays for `seed` (half from surfaces, half uniform).
    pub fn rays(&self, n: u64, seed: u64) -> Vec<TestRay> {
        let chunks = n.div_ceil(CHUNK);
        let mut out: Vec<TestRay> = (0..chunks)
            .into_par_iter()
            .flat_map_iter(|c| {
                let mut v = Vec::with_capacity(CHUNK as usize);
                self.chunk(seed, c, CHUNK.min(n - c * CHUNK), &mut v);
                v
            })
            .collect();
        out.truncate(n as usize);
        out
    }

    fn surface_ray(&self, rng: &mut Pcg64Mcg) -> TestRay {
        let total = *self.cdf.last().expect("non-empty");
        let u = rng.gen::<f64>() * total;
        let i = self
            .cdf
            .partition_point(|&c| c <= u)
            .min(self.cdf.len() - 1);
        let patch = &self.mesh.patches[i];
        // A uniform point: a fan triangle by area, then uniform in it.
        let ids = self.mesh.patch_indices(i);
        let v = |k: usize| self.mesh.vertices[ids[k] as usize];
        let fan_area = |k: usize| (v(k) - v(0)).cross(v(k + 1) - v(0)).length();
        let sum: f32 = (1..ids.len() - 1).map(fan_area).sum();
        let mut x = rng.gen::<f32>() * sum;
        let mut k = 1;
        while k < ids.len() - 2 && x >= fan_area(k) {
            x -= fan_area(k);
            k += 1;
        }
        let (r1, r2) = (rng.gen::<f32>().sqrt(), rng.gen::<f32>());
        let p = v(0) * (1.0 - r1) + v(k) * (r1 * (1.0 - r2)) + v(k + 1) * (r1 * r2);
        // Cosine-distributed about the normal (Nusselt: a uniform point on the disc, lifted).
        let (r, phi) = (
            rng.gen::<f32>().sqrt(),
            rng.gen::<f32>() * std::f32::consts::TAU,
        );
        let local = Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - r * r).max(0.0).sqrt());
        let dir = Frame::new(patch.normal, 0.0).to_world(local).normalize();
        let eps = (1e-4 * (patch.area as f32).sqrt()).max(self.eps_floor);
        TestRay {
            org: (p + patch.normal * eps).to_array(),
            dir: dir.to_array(),
            source: RaySource::Surface,
            shooter: Some(i as u32),
            eps,
        }
    }

    fn uniform_ray(&self, rng: &mut Pcg64Mcg) -> TestRay {
        let org = self.lo + (self.hi - self.lo) * Vec3::new(rng.gen(), rng.gen(), rng.gen());
        let z: f32 = rng.gen::<f32>() * 2.0 - 1.0;
        let phi: f32 = rng.gen::<f32>() * std::f32::consts::TAU;
        let r = (1.0 - z * z).max(0.0).sqrt();
        TestRay {
            org: org.to_array(),
            dir: [r * phi.cos(), r * phi.sin(), z],
            source: RaySource::Uniform,
            shooter: None,
            eps: 0.0,
        }
    }
}

/// splitmix64: decorrelates (seed, chunk) into independent RNG seeds.
fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

fn bounds(mesh: &Mesh) -> (Vec3, Vec3) {
    if mesh.vertices.is_empty() {
        return (Vec3::ZERO, Vec3::ZERO);
    }
    mesh.vertices.iter().fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(l, h), v| (l.min(*v), h.max(*v)),
    )
}

/// Casts `r` as the solver does: a hit on the shooter is stepped past (at most 3 times).
pub fn trace<I: Intersector>(isect: &I, r: &TestRay) -> Option<Hit> {
    let mut ray = r.ray();
    for _ in 0..3 {
        match isect.intersect(&ray) {
            Some(h) if Some(h.patch) == r.shooter => ray.tnear = h.t + r.eps,
            other => return other,
        }
    }
    None
}

/// How two answers for one ray differ (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Class {
    Edge,
    Grazing,
    Coincident,
    Real,
}

/// One answer, as reported.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct Answer {
    pub patch: u32,
    pub t: f32,
    pub back: bool,
}

impl From<Hit> for Answer {
    fn from(h: Hit) -> Answer {
        Answer {
            patch: h.patch,
            t: h.t,
            back: h.back,
        }
    }
}

/// A real disagreement kept as an example.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Disagreement {
    pub ray: TestRay,
    pub a: Option<Answer>,
    pub b: Option<Answer>,
}

/// How one intersector compares with another (`b` is the oracle when there is one).
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct PairReport {
    pub a: String,
    pub b: String,
    pub rays: u64,
    /// Rays on which both report the same patch, or both no hit.
    pub agreed: u64,
    /// agreed / rays.
    pub agreement: f64,
    pub edge: u64,
    pub grazing: u64,
    pub coincident: u64,
    pub real: u64,
    /// Up to 10 real disagreements, in ray order.
    pub examples: Vec<Disagreement>,
}

impl PairReport {
    fn add(&mut self, o: PairReport) {
        self.rays += o.rays;
        self.agreed += o.agreed;
        self.edge += o.edge;
        self.grazing += o.grazing;
        self.coincident += o.coincident;
        self.real += o.real;
        let room = MAX_EXAMPLES.saturating_sub(self.examples.len());
        self.examples.extend(o.examples.into_iter().take(room));
    }
}

/// One intersector's misses.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct IntersectorReport {
    pub name: String,
    /// Rays cast from patch surfaces, and how many of them hit nothing (0 in a closed scene).
    pub surface_rays: u64,
    pub escapes: u64,
    /// Uniform rays that hit nothing (expected in an open scene, or from origins outside it).
    pub uniform_misses: u64,
}

/// What `radiosity crosscheck` found.
#[derive(Clone, Debug, serde::Serialize)]
pub struct CrossReport {
    pub patches: usize,
    pub axial_patches: usize,
    pub skew_patches: usize,
    pub rays: u64,
    pub seed: u64,
    /// Edge distance below which a disagreement is "edge", relative to `scene_size`.
    pub eps: f32,
    /// The scene's bounding-box diagonal.
    pub scene_size: f64,
    /// The oracle's name when brute force ran (scenes of ≤ 2000 patches).
    pub oracle: Option<String>,
    /// The reference every other intersector is compared with: the oracle, else Embree.
    pub reference: String,
    pub intersectors: Vec<IntersectorReport>,
    pub pairs: Vec<PairReport>,
    /// Whether the scene is taken as closed (escapes then fail the bar), and why.
    pub closed: bool,
    pub closed_reason: String,
    /// The bar: ≥ [`BAR_AGREEMENT`] agreement on every pair, no real disagreement, no
    /// escape from a closed scene.
    pub passed: bool,
    /// What failed the bar, one line each.
    pub failures: Vec<String>,
}

/// The bar on the agreement rate of every pair (99.999 %).
pub const BAR_AGREEMENT: f64 = 0.99999;
/// Share of the reference's surface rays that may escape before the scene is taken as open:
/// a closed scene leaks none through a correct intersector, a leaky one a few per million,
/// while an open one (the Cornell box without its front wall) loses a sizeable share.
const OPEN_ESCAPES: f64 = 1e-3;

impl CrossReport {
    /// Decides closure (`Some` forces it; `None` judges by the reference's escapes) and
    /// checks the bar.
    pub fn apply_bar(&mut self, closed: Option<bool>) {
        let reference = self
            .intersectors
            .iter()
            .find(|i| i.name == self.reference)
            .cloned()
            .unwrap_or_default();
        let share = reference.escapes as f64 / reference.surface_rays.max(1) as f64;
        (self.closed, self.closed_reason) = match closed {
            Some(true) => (true, "declared closed (--closed)".into()),
            Some(false) => (false, "declared open (--open)".into()),
            None if share < OPEN_ESCAPES => (
                true,
                format!(
                    "{} of the reference's {} surface rays escaped (< {} %): taken as closed",
                    reference.escapes,
                    reference.surface_rays,
                    100.0 * OPEN_ESCAPES
                ),
            ),
            None => (
                false,
                format!(
                    "{:.2} % of the reference's surface rays escaped: taken as open",
                    100.0 * share
                ),
            ),
        };
        let mut failures = Vec::new();
        for p in &self.pairs {
            if p.agreement < BAR_AGREEMENT {
                failures.push(format!(
                    "{} vs {}: agreement {:.5} % < {:.3} %",
                    p.a,
                    p.b,
                    100.0 * p.agreement,
                    100.0 * BAR_AGREEMENT
                ));
            }
            if p.real > 0 {
                failures.push(format!("{} vs {}: {} real disagreements", p.a, p.b, p.real));
            }
        }
        if self.closed {
            for i in self.intersectors.iter().filter(|i| i.escapes > 0) {
                failures.push(format!(
                    "{}: {} rays escaped from a closed scene",
                    i.name, i.escapes
                ));
            }
        }
        self.passed = failures.is_empty();
        self.failures = failures;
    }
}

impl std::fmt::Display for CrossReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "{} patches ({} axis-aligned, {} skew); {} rays (half from patch surfaces, half \
             uniform), seed {}; edge ε {:.1e} of the scene size {:.3} m",
            self.patches,
            self.axial_patches,
            self.skew_patches,
            self.rays,
            self.seed,
            self.eps,
            self.scene_size
        )?;
        writeln!(f, "reference: {}", self.reference)?;
        writeln!(
            f,
            "{:<18} {:>12} {:>8} {:>8} {:>8} {:>10} {:>6}",
            "pair", "agreement %", "edge", "grazing", "coinc.", "real", ""
        )?;
        for p in &self.pairs {
            writeln!(
                f,
                "{:<18} {:>12.5} {:>8} {:>8} {:>8} {:>10}",
                format!("{} vs {}", p.a, p.b),
                100.0 * p.agreement,
                p.edge,
                p.grazing,
                p.coincident,
                p.real
            )?;
        }
        writeln!(
            f,
            "scene {} ({})",
            if self.closed { "closed" } else { "open" },
            self.closed_reason
        )?;
        for i in &self.intersectors {
            writeln!(
                f,
                "  {:<8} escapes {} of {} surface rays; uniform rays missing everything: {}",
                i.name, i.escapes, i.surface_rays, i.uniform_misses
            )?;
        }
        for p in self.pairs.iter().filter(|p| !p.examples.is_empty()) {
            writeln!(
                f,
                "real disagreements, {} vs {} (first {}):",
                p.a,
                p.b,
                p.examples.len()
            )?;
            for d in &p.examples {
                writeln!(
                    f,
                    "  org {:?} dir {:?} ({:?}): {:?} vs {:?}",
                    d.ray.org, d.ray.dir, d.ray.source, d.a, d.b
                )?;
            }
        }
        if self.passed {
            writeln!(
                f,
                "bar passed: ≥ {:.3} % agreement, no real disagreement{}",
                100.0 * BAR_AGREEMENT,
                if self.closed { ", no escape" } else { "" }
            )
        } else {
            writeln!(f, "bar FAILED:")?;
            for x in &self.failures {
                writeln!(f, "  {x}")?;
            }
            Ok(())
        }
    }
}

/// Classifies disagreements for one mesh (see the module docs for the classes).
pub struct Judge<'a> {
    mesh: &'a Mesh,
    /// Absolute edge distance.
    eps: f64,
}

impl<'a> Judge<'a> {
    /// `eps` is relative to the scene's bounding-box diagonal.
    pub fn new(mesh: &'a Mesh, eps: f32) -> Judge<'a> {
        let (lo, hi) = bounds(mesh);
        Judge {
            mesh,
            eps: eps as f64 * (hi - lo).as_dvec3().length(),
        }
    }

    /// The class of a disagreement between answers `a` and `b` for ray `r`.
    pub fn classify(&self, r: &TestRay, a: Option<Hit>, b: Option<Hit>) -> Class {
        let org = Vec3::from(r.org).as_dvec3();
        let dir = Vec3::from(r.dir).as_dvec3();
        let hits = [a, b];
        let hits = hits.iter().flatten();
        if hits
            .clone()
            .any(|h| self.edge_distance(h.patch, org + dir * h.t as f64) <= self.eps)
        {
            return Class::Edge;
        }
        let normal = |h: &Hit| self.mesh.patches[h.patch as usize].normal.as_dvec3();
        if hits
            .clone()
            .any(|h| (dir.dot(normal(h)) / dir.length()).abs() < GRAZING_COS)
        {
            return Class::Grazing;
        }
        if let (Some(ha), Some(hb)) = (a, b) {
            let same_t = ((ha.t - hb.t) as f64 * dir.length()).abs() <= self.eps;
            if same_t && normal(&ha).dot(normal(&hb)).abs() > 1.0 - 1e-6 {
                return Class::Coincident;
            }
        }
        Class::Real
    }

    /// Distance from `p` to the boundary of patch `i` (f64).
    pub fn edge_distance(&self, i: u32, p: DVec3) -> f64 {
        let ids = self.mesh.patch_indices(i as usize);
        let v = |k: usize| self.mesh.vertices[ids[k % ids.len()] as usize].as_dvec3();
        (0..ids.len())
            .map(|k| {
                let (a, b) = (v(k), v(k + 1));
                let ab = b - a;
                let s = ((p - a).dot(ab) / ab.length_squared().max(1e-300)).clamp(0.0, 1.0);
                (a + ab * s - p).length()
            })
            .fold(f64::INFINITY, f64::min)
    }
}

/// One chunk's tallies.
#[derive(Default)]
struct Tally {
    casters: Vec<IntersectorReport>,
    pairs: Vec<PairReport>,
}

impl Tally {
    /// Zero counts for every intersector in `names` and every pair in `pairs`.
    fn empty(names: &[&str], pairs: &[(usize, usize)]) -> Tally {
        Tally {
            casters: names
                .iter()
                .map(|n| IntersectorReport {
                    name: n.to_string(),
                    ..Default::default()
                })
                .collect(),
            pairs: pairs
                .iter()
                .map(|&(a, b)| PairReport {
                    a: names[a].to_string(),
                    b: names[b].to_string(),
                    ..Default::default()
                })
                .collect(),
        }
    }

    /// Counts one ray's `answers` (one per intersector): misses, then agreement of each pair.
    fn record(
        &mut self,
        r: &TestRay,
        answers: &[Option<Hit>],
        pairs: &[(usize, usize)],
        judge: &Judge<'_>,
    ) {
        for (k, rep) in self.casters.iter_mut().enumerate() {
            let missed = answers[k].is_none() as u64;
            if r.source == RaySource::Surface {
                rep.surface_rays += 1;
                rep.escapes += missed;
            } else {
                rep.uniform_misses += missed;
            }
        }
        for (p, &(ia, ib)) in self.pairs.iter_mut().zip(pairs) {
            let (a, b) = (answers[ia], answers[ib]);
            p.rays += 1;
            if a.map(|h| h.patch) == b.map(|h| h.patch) {
                p.agreed += 1;
                continue;
            }
            match judge.classify(r, a, b) {
                Class::Edge => p.edge += 1,
                Class::Grazing => p.grazing += 1,
                Class::Coincident => p.coincident += 1,
                Class::Real => {
                    p.real += 1;
                    if p.examples.len() < MAX_EXAMPLES {
                        p.examples.push(Disagreement {
                            ray: *r,
                            a: a.map(Answer::from),
                            b: b.map(Answer::from),
                        });
                    }
                }
            }
        }
    }

    /// Adds a later chunk's tallies to these (examples kept in chunk order).
    fn add(&mut self, t: Tally) {
        for (x, y) in self.casters.iter_mut().zip(t.casters) {
            x.surface_rays += y.surface_rays;
            x.escapes += y.escapes;
            x.uniform_misses += y.uniform_misses;
        }
        for (x, y) in self.pairs.iter_mut().zip(t.pairs) {
            x.add(y);
        }
    }
}

/// The intersectors to compare, Embree first and brute force (when it runs) last; `skew` is
/// the number of skew patches. Also says whether brute force runs.
fn build_casters(mesh: &Mesh, skew: usize) -> Result<(Vec<AnyIntersector>, bool), EmbreeError> {
    let mut casters = vec![AnyIntersector::Embree(EmbreeScene::build(mesh, |_| true)?)];
    if skew == 0 && !mesh.patches.is_empty() {
        casters.push(AnyIntersector::Merge(PlaneMerge::build(mesh)));
    }
    casters.push(AnyIntersector::Hybrid(Hybrid::build(mesh)?));
    let brute = mesh.patches.len() <= BRUTE_MAX_PATCHES;
    if brute {
        casters.push(AnyIntersector::Brute(BruteForce::new(mesh)));
    }
    Ok((casters, brute))
}

/// Pairs (a, b) of indices into `names`, b the reference: each against the reference, and the
/// hybrid against Embree (index 0) when the reference is brute force.
fn compared_pairs(names: &[&str], reference: usize, brute: bool) -> Vec<(usize, usize)> {
    let mut pairs: Vec<(usize, usize)> = (0..names.len())
        .filter(|&k| k != reference)
        .map(|k| (k, reference))
        .collect();
    let hybrid = names
        .iter()
        .position(|n| *n == "hybrid")
        .expect("always built");
    if brute {
        pairs.push((hybrid, 0));
    }
    pairs
}

/// Casts through every intersector all `rays` rays, in parallel chunks, and combines the
/// chunks' tallies in chunk order (deterministic examples); sets each pair's agreement.
fn cast_all(
    casters: &[AnyIntersector],
    names: &[&str],
    pairs: &[(usize, usize)],
    gen: &RayGen<'_>,
    judge: &Judge<'_>,
    rays: u64,
    seed: u64,
) -> Tally {
    let tallies: Vec<Tally> = (0..rays.div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            set_flush_denormals();
            let mut batch = Vec::with_capacity(CHUNK as usize);
            gen.chunk(seed, c, CHUNK.min(rays - c * CHUNK), &mut batch);
            let mut t = Tally::empty(names, pairs);
            let mut answers = vec![None; casters.len()];
            for r in &batch {
                for (a, c) in answers.iter_mut().zip(casters) {
                    *a = trace(c, r);
                }
                t.record(r, &answers, pairs, judge);
            }
            t
        })
        .collect();
    let mut total = Tally::empty(names, pairs);
    for t in tallies {
        total.add(t);
    }
    for p in &mut total.pairs {
        p.agreement = p.agreed as f64 / (p.rays.max(1)) as f64;
    }
    total
}

/// Casts `rays` test rays through every intersector the scene supports — Embree over the whole
/// scene, the plane merge alone when every patch is axis-aligned, the hybrid (plane merge +
/// Embree over the skew patches) and, on scenes of ≤ [`BRUTE_MAX_PATCHES`] patches, brute force
/// — compares each with the reference (brute force when it ran, else Embree; and the hybrid
/// with Embree) on the hit patch, classifies the disagreements and applies the bar, judging
/// closure by the reference's escapes ([`CrossReport::apply_bar`] to override). `eps` is
/// relative to the scene's diagonal (1e-5 is a good default).
pub fn crosscheck(mesh: &Mesh, rays: u64, seed: u64, eps: f32) -> Result<CrossReport, EmbreeError> {
    let skew = mesh
        .patches
        .iter()
        .filter(|p| p.class == PatchClass::Skew)
        .count();
    let (casters, brute) = build_casters(mesh, skew)?;
    let names: Vec<&str> = casters.iter().map(|c| c.name()).collect();
    // Brute force is last when it ran; Embree is first.
    let reference = if brute { names.len() - 1 } else { 0 };
    let pairs = compared_pairs(&names, reference, brute);
    let (lo, hi) = bounds(mesh);
    let scene_size = (hi - lo).as_dvec3().length();
    let judge = Judge::new(mesh, eps);
    let gen = RayGen::new(mesh);
    let total = cast_all(&casters, &names, &pairs, &gen, &judge, rays, seed);
    let mut report = CrossReport {
        patches: mesh.patches.len(),
        axial_patches: mesh.patches.len() - skew,
        skew_patches: skew,
        rays,
        seed,
        eps,
        scene_size,
        oracle: brute.then(|| "brute".to_string()),
        reference: names[reference].to_string(),
        intersectors: total.casters,
        pairs: total.pairs,
        closed: false,
        closed_reason: String::new(),
        passed: false,
        failures: Vec::new(),
    };
    report.apply_bar(None);
    Ok(report)
}
