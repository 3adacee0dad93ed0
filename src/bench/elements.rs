//! `radiosity bench elements`: adaptive elements against uniform meshing (docs/design.md §11;
//! docs/results/adaptive-elements.md).
//!
//! One patch solve; then, on it, a fine *reference* (every patch cut uniformly to half the
//! minimum element size, each corner gathered with many rays), *uniform* element meshes (every
//! patch cut to depth 0, 1, 2, … : 1, 4, 16, … elements per root) and *adaptive* ones (Cohen
//! et al. 1986 Sec. 3, one per threshold), all with the same rays per corner. The error of a
//! mesh is the area-weighted mean relative error of the radiosity it interpolates (bilinear in
//! a quad element, barycentric in a triangle: what its Gouraud picture shows) at the centres of
//! the reference's elements, against the reference's value there, on every patch that reflects
//! and does not emit: Σ A_e·|B(x_e) − B_ref(x_e)|/B_ref(x_e) / Σ A_e, on the scalar (the mean
//! of RGB), leaving out the unlit footprints of objects ([`UNLIT`]); beside it the
//! energy-normalised error Σ A_e·|ΔB| / Σ A_e·B_ref, over all. From the first: the adaptive error against the uniform error at the same element
//! count (uniform interpolated between depths, log–log), and the uniform count that matches
//! the adaptive error.

use crate::elements::{self, CornerLight, Corners, Elements, Rule, Test};
use crate::intersect::select::IntersectorKind;
use crate::light::LightAt;
use crate::model::Model;
use crate::settings::Invalid;
use crate::solve::{scalar, SolveSettings};
use crate::Error;
use serde::Serialize;

/// What to measure.
#[derive(Clone, Debug)]
pub struct ElementBenchJob {
    pub solve: SolveSettings,
    /// Thresholds of the adaptive meshes, each with every one of `tests`.
    pub thresholds: Vec<f64>,
    pub tests: Vec<Test>,
    /// The differences' floor, a fraction of the scene's mean radiosity
    /// ([`elements::FLOOR`]);
    pub floor: f64,
    /// Smallest element edge (metres); `None`: the patch size / 8.
    pub min_size: Option<f32>,
    /// Rays per corner of the uniform and adaptive meshes, and what they gather; the
    /// reference gathers the whole light ([`CornerLight::Full`]) with `reference_rays`.
    pub rays: usize,
    pub light: CornerLight,
    pub reference_rays: usize,
}

impl ElementBenchJob {
    /// What the corners of the uniform and adaptive meshes gather.
    fn corners(&self) -> Corners {
        Corners {
            rays: self.rays,
            light: self.light,
        }
    }

    /// What the reference's corners gather: the whole light at `reference_rays`.
    fn reference_corners(&self) -> Corners {
        Corners {
            rays: self.reference_rays,
            light: CornerLight::Full,
        }
    }
}

/// `radiosity bench elements --thresholds`: the adaptive meshes' thresholds.
pub const DEFAULT_THRESHOLDS: &str = "0.005,0.01,0.02,0.04,0.08";
/// `radiosity bench elements --tests`: what the thresholds apply to, each measured.
pub const DEFAULT_TESTS: &str = "halves,midpoints";
/// `radiosity bench elements --reference-rays`: rays per corner of the reference.
pub const DEFAULT_REFERENCE_RAYS: usize = 2048;

impl ElementBenchJob {
    /// Refuses what `solve` refuses, the element settings `solve --elements` refuses, a
    /// threshold that is no positive fraction and a reference of fewer than 2 rays per corner.
    pub fn check(&self) -> Result<(), Invalid> {
        self.solve.check()?;
        elements::ElementSettings {
            min_size: self.min_size,
            rays: self.rays.max(self.reference_rays.min(2)),
            ..Default::default()
        }
        .check()?;
        if self.thresholds.iter().any(|t| !(*t > 0.0 && t.is_finite())) || self.reference_rays < 2 {
            return Invalid::err(
                "--thresholds must be positive fractions and --reference-rays at least 2",
            );
        }
        Ok(())
    }
}

/// One mesh measured.
#[derive(Clone, Debug, Serialize)]
pub struct ElementBenchRow {
    /// `uniform` or `adaptive`.
    pub kind: &'static str,
    /// What an adaptive mesh's threshold was applied to.
    pub test: Option<Test>,
    /// Depth (uniform) or threshold (adaptive).
    pub param: f64,
    pub elements: u64,
    /// Area-weighted mean relative error (what the bars are on).
    pub error: f64,
    /// Energy-normalised error Σ A·|ΔB| / Σ A·B_ref.
    pub energy_error: f64,
    pub rays: u64,
    pub seconds: f64,
}

/// The measurement.
#[derive(Clone, Debug, Serialize)]
pub struct ElementBenchReport {
    pub scene: String,
    pub patches: usize,
    pub min_size: f64,
    pub rays: usize,
    pub reference_rays: usize,
    pub reference_elements: u64,
    pub rows: Vec<ElementBenchRow>,
    /// Per adaptive mesh: the uniform error at its element count, its error over that
    /// (bar: ≤ 0.5), the uniform count matching its error, and its count over that (bar: ≤ ⅓).
    pub comparisons: Vec<Comparison>,
}

/// An adaptive mesh against the uniform curve.
#[derive(Clone, Debug, Serialize)]
pub struct Comparison {
    pub test: Option<Test>,
    pub threshold: f64,
    pub elements: u64,
    pub error: f64,
    pub uniform_error_at_count: Option<f64>,
    pub error_ratio: Option<f64>,
    pub uniform_count_at_error: Option<f64>,
    pub count_ratio: Option<f64>,
}

/// Reference points darker than this fraction of the scene's mean radiosity are left out of
/// the relative error: they are the unlit footprints of objects standing on a surface (B = 0
/// exactly under a box), hidden from every view, where any interpolation is an infinite
/// relative error.
pub const UNLIT: f64 = 0.01;

/// The errors of `mesh` at the reference's element centres (module docs): the area-weighted
/// mean relative error Σ A·|B − B_ref|/B_ref / Σ A over the points with B_ref ≥ `unlit`, and
/// the energy-normalised one Σ A·|B − B_ref| / Σ A·B_ref over all.
pub fn error_against(
    model: &Model,
    reference: &Elements,
    mesh: &Elements,
    unlit: f64,
) -> (f64, f64) {
    let n = model.mesh.patches.len();
    let first = mesh.first_of_patches(n);
    let mats = &model.scene.materials;
    let (mut rel, mut area, mut num, mut den) = (0.0, 0.0, 0.0, 0.0);
    for (e, el) in reference.params.iter().enumerate() {
        let p = reference.patch[e] as usize;
        let m = &mats[model.mesh.patches[p].material as usize];
        if m.is_emitter() || scalar(&m.rho) <= 0.0 {
            continue;
        }
        let r = scalar(&reference.b[e]);
        let Some(x) = mesh.value_at(&first, p, el.root, el.centre_uv()) else {
            continue;
        };
        let a = reference.mesh.patches[e].area;
        let d = (scalar(&x) - r).abs();
        if r >= unlit && r > 0.0 {
            rel += a * d / r;
            area += a;
        }
        num += a * d;
        den += a * r;
    }
    let q = |a: f64, b: f64| if b > 0.0 { a / b } else { 0.0 };
    (q(rel, area), q(num, den))
}

/// Log–log interpolation of y at x along points sorted by x; `None` outside them.
fn interp(points: &[(f64, f64)], x: f64) -> Option<f64> {
    points.windows(2).find_map(|w| {
        let ((x0, y0), (x1, y1)) = (w[0], w[1]);
        (x >= x0 && x <= x1 && x1 > x0).then(|| {
            let t = (x.ln() - x0.ln()) / (x1.ln() - x0.ln());
            (y0.ln() + t * (y1.ln() - y0.ln())).exp()
        })
    })
}

/// Runs the measurement on `model`.
pub fn run(
    model: &Model,
    job: &ElementBenchJob,
    log: &mut dyn FnMut(&str),
) -> Result<ElementBenchReport, Error> {
    job.check()?;
    let (isect, _) = model.intersector(IntersectorKind::Auto)?;
    let sol = model.solve(Some(&isect), &job.solve, &Default::default(), |_| {})?;
    let m = &model.mesh;
    let gather = LightAt::new(m, &model.scene.materials, &isect, &sol.b, None, None);
    let min_size = elements::ElementSettings {
        min_size: job.min_size,
        ..Default::default()
    }
    .min_size_for(m.patch_size) as f64;
    let depth = (m.patch_size as f64 / min_size).log2().round().max(0.0) as u32;
    // The reference is one level finer than the smallest element, so that every mesh
    // measured, the finest uniform one too, has an error of its own against it.
    let ref_depth = depth + 1;
    let seed = job.solve.seed;
    log(&format!(
        "{}: {} patches; reference: uniform depth {ref_depth}, {} rays per corner",
        model.scene.name,
        m.patches.len(),
        job.reference_rays
    ));
    // Every patch refined by `rule`, its corners gathered as `corners` says.
    let refine = |rule: Rule, corners: Corners| {
        elements::refine_by(
            m,
            &gather,
            &sol.b,
            rule,
            corners,
            usize::MAX,
            seed,
            Default::default(),
        )
    };
    let uniform = |depth: u32, corners: Corners| refine(Rule::Uniform(depth), corners);
    let corners = job.corners();
    let (reference, rs) = uniform(ref_depth, job.reference_corners());
    log(&format!(
        "reference: {} elements, {} rays, {:.1} s",
        rs.count, rs.rays, rs.seconds
    ));
    let floor = job.floor * elements::mean_radiosity(m, &sol.b);
    let unlit = UNLIT * elements::mean_radiosity(m, &sol.b);
    let mut rows = Vec::new();
    for d in 0..=depth {
        let (el, st) = uniform(d, corners);
        let (error, energy_error) = error_against(model, &reference, &el, unlit);
        log(&format!(
            "uniform depth {d}: {} elements, error {:.2} % (energy {:.2} %), {:.2} s",
            st.count,
            100.0 * error,
            100.0 * energy_error,
            st.seconds
        ));
        rows.push(ElementBenchRow {
            kind: "uniform",
            test: None,
            param: d as f64,
            elements: st.count,
            error,
            energy_error,
            rays: st.rays,
            seconds: st.seconds,
        });
    }
    for (test, &threshold) in job
        .tests
        .iter()
        .flat_map(|t| job.thresholds.iter().map(move |x| (*t, x)))
    {
        let rule = Rule::Adaptive {
            threshold,
            floor,
            min_size,
            test,
        };
        let (el, st) = refine(rule, corners);
        let (error, energy_error) = error_against(model, &reference, &el, unlit);
        log(&format!(
            "adaptive {test:?} threshold {threshold}: {} elements, error {:.2} % (energy {:.2} %), {:.2} s",
            st.count,
            100.0 * error,
            100.0 * energy_error,
            st.seconds
        ));
        rows.push(ElementBenchRow {
            kind: "adaptive",
            test: Some(test),
            param: threshold,
            elements: st.count,
            error,
            energy_error,
            rays: st.rays,
            seconds: st.seconds,
        });
    }
    let comparisons = compare_rows(&rows);
    Ok(ElementBenchReport {
        scene: model.scene.name.clone(),
        patches: m.patches.len(),
        min_size,
        rays: job.rays,
        reference_rays: job.reference_rays,
        reference_elements: rs.count,
        rows,
        comparisons,
    })
}

/// Each adaptive row against the uniform meshes: uniform meshing's error at the row's element
/// count, and its count at the row's error, interpolated on the uniform rows' curve.
fn compare_rows(rows: &[ElementBenchRow]) -> Vec<Comparison> {
    let uniform: Vec<(f64, f64)> = rows
        .iter()
        .filter(|r| r.kind == "uniform" && r.error > 0.0)
        .map(|r| (r.elements as f64, r.error))
        .collect();
    // Error falls with the count: for the count at an error, interpolate the reversed curve.
    let mut by_error: Vec<(f64, f64)> = uniform.iter().map(|&(n, e)| (e, n)).collect();
    by_error.sort_by(|a, b| a.0.total_cmp(&b.0));
    rows.iter()
        .filter(|r| r.kind == "adaptive")
        .map(|r| {
            let n = r.elements as f64;
            let ue = interp(&uniform, n);
            let un = interp(&by_error, r.error);
            Comparison {
                test: r.test,
                threshold: r.param,
                elements: r.elements,
                error: r.error,
                uniform_error_at_count: ue,
                error_ratio: ue.map(|u| r.error / u),
                uniform_count_at_error: un,
                count_ratio: un.map(|u| n / u),
            }
        })
        .collect()
}

impl ElementBenchReport {
    /// The report as a Markdown table.
    pub fn markdown(&self) -> String {
        let mut s = format!(
            "{}: {} patches, min element {:.4} m, {} rays per corner; reference {} elements at {} rays per corner\n\n",
            self.scene, self.patches, self.min_size, self.rays, self.reference_elements, self.reference_rays
        );
        s += "| mesh | elements | error | energy error | rays | seconds |\n|---|---|---|---|---|---|\n";
        for r in &self.rows {
            let name = if r.kind == "uniform" {
                format!("uniform depth {}", r.param)
            } else {
                format!(
                    "adaptive {:?} {}",
                    r.test.unwrap_or(Test::Midpoints),
                    r.param
                )
            };
            s += &format!(
                "| {name} | {} | {:.2} % | {:.2} % | {} | {:.2} |\n",
                r.elements,
                100.0 * r.error,
                100.0 * r.energy_error,
                r.rays,
                r.seconds
            );
        }
        s += "\n| test | threshold | elements | error | uniform error at that count | ratio (bar ≤ 0.5) | uniform count at that error | ratio (bar ≤ 0.33) |\n|---|---|---|---|---|---|---|---|\n";
        let f = |v: Option<f64>, k: f64, d: usize| {
            v.map(|x| format!("{:.*}", d, k * x))
                .unwrap_or_else(|| "—".into())
        };
        for c in &self.comparisons {
            s += &format!(
                "| {:?} | {} | {} | {:.2} % | {} % | {} | {} | {} |\n",
                c.test.unwrap_or(Test::Midpoints),
                c.threshold,
                c.elements,
                100.0 * c.error,
                f(c.uniform_error_at_count, 100.0, 2),
                f(c.error_ratio, 1.0, 2),
                f(c.uniform_count_at_error, 1.0, 0),
                f(c.count_ratio, 1.0, 2)
            );
        }
        s
    }
}
