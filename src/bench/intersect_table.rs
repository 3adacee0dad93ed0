//! Speed of the intersectors side by side: the library side of `radiosity bench intersect`.
//!
//! Every intersector the scene supports casts the same rays (half from patch surfaces as the
//! solver casts them, half uniform: [`RayGen`]) in one process, one after the other, each on
//! all threads (rayon) after a short warm-up. Mrays/s counts closest-hit queries; building the
//! structures is timed apart. A benchmark, not a test: nothing asserts on its figures.

use super::crosscheck::{RayGen, RaySource, TestRay, BRUTE_MAX_PATCHES};
use crate::intersect::brute::BruteForce;
use crate::intersect::embree::{set_flush_denormals, EmbreeError, EmbreeScene};
use crate::intersect::hybrid::Hybrid;
use crate::intersect::plane_merge::PlaneMerge;
use crate::intersect::select::SceneShape;
use crate::intersect::{Intersector, Ray};
use crate::mesh::Mesh;
use rayon::prelude::*;
use std::fmt::Write as _;
use std::time::Instant;

/// Measurement rounds per intersector (the best counts).
const ROUNDS: usize = 3;
/// Rays per parallel task.
const CHUNK: usize = 4096;
/// Brute force costs O(triangles) per ray: its ray count is capped at this many ray–triangle
/// tests.
const BRUTE_WORK: usize = 200_000_000;

/// One intersector's speed on one scene.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Rate {
    /// Closest-hit queries per second, millions.
    pub mrays: f64,
    /// Build time, seconds.
    pub build_seconds: f64,
    /// Rays cast for the measurement.
    pub rays: u64,
}

/// One scene's row.
#[derive(Clone, Debug, serde::Serialize)]
pub struct BenchRow {
    pub scene: String,
    #[serde(flatten)]
    pub shape: SceneShape,
    pub threads: usize,
    /// Which rays: "surface", "uniform" or "both" (half of each).
    pub rays_from: &'static str,
    pub embree: Rate,
    /// The plane merge; over the axial patches only when the scene also has skew ones
    /// (`merge_subset`), where it cannot be used alone and misses every skew hit.
    pub merge: Option<Rate>,
    pub merge_subset: bool,
    pub hybrid: Rate,
    /// Brute force, on scenes of ≤ [`BRUTE_MAX_PATCHES`] patches.
    pub brute: Option<Rate>,
    /// The fastest of those that can serve the scene alone (the subset merge cannot).
    pub fastest: String,
    /// Hybrid Mrays/s over Embree's.
    pub hybrid_over_embree: f64,
    /// Where the merge's time goes (over up to 100 k of the rays): planes whose crossing was
    /// tested, and point locations inside a plane's bounds, per ray.
    pub merge_planes_per_ray: Option<f64>,
    pub merge_locates_per_ray: Option<f64>,
}

/// Mrays/s of `isect` over `rays`, all threads, after a warm-up over a tenth of them.
fn rate<I: Intersector>(isect: &I, rays: &[Ray], build_seconds: f64) -> Rate {
    let run = |rays: &[Ray]| -> u64 {
        rays.par_chunks(CHUNK)
            .map(|c| {
                set_flush_denormals();
                c.iter().filter(|r| isect.intersect(r).is_some()).count() as u64
            })
            .sum()
    };
    std::hint::black_box(run(&rays[..rays.len() / 10 + 1]));
    let t = Instant::now();
    std::hint::black_box(run(rays));
    Rate {
        mrays: rays.len() as f64 / t.elapsed().as_secs_f64().max(1e-9) / 1e6,
        build_seconds,
        rays: rays.len() as u64,
    }
}

/// Builds with `f`, timing it.
fn timed<T, E>(f: impl FnOnce() -> Result<T, E>) -> Result<(T, f64), E> {
    let t = Instant::now();
    let x = f()?;
    Ok((x, t.elapsed().as_secs_f64()))
}

/// Measures every applicable intersector on `mesh` over the same `rays` rays of `seed` (only
/// those from `source`, if given).
pub fn bench_mesh(
    name: &str,
    mesh: &Mesh,
    rays: u64,
    seed: u64,
    source: Option<RaySource>,
) -> Result<BenchRow, EmbreeError> {
    let shape = SceneShape::of(mesh);
    // With one source, twice the rays are made and half kept.
    let made = if source.is_some() { 2 * rays } else { rays };
    let test: Vec<Ray> = RayGen::new(mesh)
        .rays(made.max(1), seed)
        .iter()
        .filter(|r| source.is_none_or(|s| r.source == s))
        .map(TestRay::ray)
        .collect();
    // Build everything, then measure in ROUNDS alternating rounds and keep each one's best:
    // other load on the machine then hits all of them alike, and a burst of it costs only one
    // round.
    let (e, e_s) = timed(|| EmbreeScene::build(mesh, |_| true))?;
    let m = if shape.axial > 0 {
        Some(timed(|| Ok::<_, EmbreeError>(PlaneMerge::build(mesh)))?)
    } else {
        None
    };
    let (h, h_s) = timed(|| Hybrid::build(mesh))?;
    let b = if shape.patches <= BRUTE_MAX_PATCHES && shape.patches > 0 {
        Some(timed(|| Ok::<_, EmbreeError>(BruteForce::new(mesh)))?)
    } else {
        None
    };
    // Brute force over fewer rays: at most BRUTE_WORK ray–triangle tests.
    let n_brute = (BRUTE_WORK / mesh.triangles().count().max(1)).clamp(1000, test.len());
    let best = |old: Option<Rate>, new: Rate| match old {
        Some(o) if o.mrays >= new.mrays => Some(o),
        _ => Some(new),
    };
    let (mut embree, mut merge, mut hybrid, mut brute) = (None, None, None, None);
    for _ in 0..ROUNDS {
        embree = best(embree, rate(&e, &test, e_s));
        if let Some((m, s)) = &m {
            merge = best(merge, rate(m, &test, *s));
        }
        hybrid = best(hybrid, rate(&h, &test, h_s));
        if let Some((b, s)) = &b {
            brute = best(brute, rate(b, &test[..n_brute], *s));
        }
    }
    let (embree, hybrid) = (embree.expect("measured"), hybrid.expect("measured"));
    let walk = m.as_ref().map(|(m, _)| {
        let sample = &test[..test.len().min(100_000)];
        let mut c = crate::intersect::plane_merge::WalkCount::default();
        for r in sample {
            std::hint::black_box(m.intersect_counted(r, &mut c));
        }
        let n = sample.len().max(1) as f64;
        (c.planes as f64 / n, c.locates as f64 / n)
    });
    let merge_subset = shape.skew > 0;
    let mut fastest = ("embree", embree.mrays);
    for (n, r) in [
        ("merge", merge.as_ref().filter(|_| !merge_subset)),
        ("hybrid", Some(&hybrid)),
        ("brute", brute.as_ref()),
    ] {
        if let Some(r) = r {
            if r.mrays > fastest.1 {
                fastest = (n, r.mrays);
            }
        }
    }
    Ok(BenchRow {
        scene: name.to_string(),
        shape,
        threads: rayon::current_num_threads(),
        rays_from: match source {
            None => "both",
            Some(RaySource::Surface) => "surface",
            Some(RaySource::Uniform) => "uniform",
        },
        hybrid_over_embree: hybrid.mrays / embree.mrays.max(1e-12),
        merge_planes_per_ray: walk.map(|w| w.0),
        merge_locates_per_ray: walk.map(|w| w.1),
        embree,
        merge,
        merge_subset,
        hybrid,
        brute,
        fastest: fastest.0.to_string(),
    })
}

fn cell(r: Option<&Rate>, star: bool) -> String {
    match r {
        Some(r) => format!("{:.2}{}", r.mrays, if star { "*" } else { "" }),
        None => "—".into(),
    }
}

/// The rows as a Markdown table (Mrays/s), with a footnote for subset merges.
pub fn markdown(rows: &[BenchRow]) -> String {
    let mut s = String::new();
    let threads = rows.first().map_or(0, |r| r.threads);
    let rays = match rows.first().map_or("both", |r| r.rays_from) {
        "surface" => "from patch surfaces, cosine distributed, as the solver casts them",
        "uniform" => "origins uniform in the bounds, directions uniform on the sphere",
        _ => "half from patch surfaces, cosine distributed, half uniform",
    };
    let _ = writeln!(
        s,
        "| scene | patches | skew | rays | Embree | merge | hybrid | brute | hybrid / Embree | fastest |"
    );
    let _ = writeln!(s, "|---|---:|---:|---:|---:|---:|---:|---:|---:|---|");
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {:.2} | {} | {:.2} | {} | {:.2} | {} |",
            r.scene,
            r.shape.patches,
            r.shape.skew,
            r.embree.rays,
            r.embree.mrays,
            cell(r.merge.as_ref(), r.merge_subset),
            r.hybrid.mrays,
            cell(r.brute.as_ref(), false),
            r.hybrid_over_embree,
            r.fastest
        );
    }
    let _ = writeln!(
        s,
        "\nMrays/s of closest-hit queries, {threads} threads, best of {ROUNDS} alternating rounds, \
         the same rays for each intersector ({rays}). \
         *: the merge over the axial patches only (the scene has skew ones, which it misses), \
         not usable alone; not counted for \"fastest\"."
    );
    let walks: Vec<String> = rows
        .iter()
        .filter_map(|r| {
            Some(format!(
                "{} {:.1} / {:.1}",
                r.scene, r.merge_planes_per_ray?, r.merge_locates_per_ray?
            ))
        })
        .collect();
    if !walks.is_empty() {
        let _ = writeln!(
            s,
            "\nThe merge's work per ray (planes whose crossing was tested / point locations inside \
             a plane's bounds): {}.",
            walks.join("; ")
        );
    }
    s
}

/// The rows as CSV.
pub fn csv(rows: &[BenchRow]) -> String {
    let mut s = String::from(
        "scene,patches,axial,skew,threads,rays_from,rays,embree_mrays,embree_build_s,merge_mrays,merge_build_s,merge_subset,hybrid_mrays,hybrid_build_s,brute_mrays,brute_rays,hybrid_over_embree,fastest\n",
    );
    let opt = |r: Option<&Rate>, f: fn(&Rate) -> String| r.map_or(String::new(), f);
    for r in rows {
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{:.4},{:.4},{},{},{},{:.4},{:.4},{},{},{:.4},{}",
            r.scene.replace(',', ";"),
            r.shape.patches,
            r.shape.axial,
            r.shape.skew,
            r.threads,
            r.rays_from,
            r.embree.rays,
            r.embree.mrays,
            r.embree.build_seconds,
            opt(r.merge.as_ref(), |m| format!("{:.4}", m.mrays)),
            opt(r.merge.as_ref(), |m| format!("{:.4}", m.build_seconds)),
            r.merge_subset,
            r.hybrid.mrays,
            r.hybrid.build_seconds,
            opt(r.brute.as_ref(), |b| format!("{:.4}", b.mrays)),
            opt(r.brute.as_ref(), |b| b.rays.to_string()),
            r.hybrid_over_embree,
            r.fastest
        );
    }
    s
}
