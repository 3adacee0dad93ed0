//! Benchmarks and cross-checks: `radiosity bench …`, `radiosity crosscheck`, `radiosity sweep`.

use super::args::{parse_sizes, source, SceneArgs, Sizes, SolverArgs};
use crate::{out, outln};
use clap::{Args, Subcommand};
use radiosity::bench::elements::{
    ElementBenchJob, DEFAULT_REFERENCE_RAYS, DEFAULT_TESTS, DEFAULT_THRESHOLDS,
};
use radiosity::bench::intersect::{self as intersect_jobs, BenchJob, CrossJob, RaysFrom};
use radiosity::bench::intersect::{
    DEFAULT_BENCH_RAYS, DEFAULT_EPS, DEFAULT_GENERATED, DEFAULT_SEED,
};
use radiosity::bench::rays::{RaysJob, DEFAULT_MIN_SECONDS, DEFAULT_RAW_RAYS};
use radiosity::bench::shots::{ShotsJob, DEFAULT_RESOLUTIONS, DEFAULT_SHOOTERS};
use radiosity::bench::{intersect_table, rays, sweep, sweep_e2e};
use radiosity::elements::Test;
use radiosity::export::write_atomic;
use radiosity::generate::BuildingOptions;
use radiosity::scene::SceneSource;
use radiosity::solve::MethodKind;

use std::path::PathBuf;

#[derive(Subcommand)]
pub enum BenchCommand {
    /// Mrays/s of Embree (whole scene), the plane merge, the hybrid and brute force, side by
    /// side on each scene and on generated buildings.
    Intersect {
        /// OBJ files (with their MTL beside them).
        scenes: Vec<PathBuf>,
        #[command(flatten)]
        scene_args: SceneArgs,
        /// Generated buildings of about these many patches (1k = 1000, 1M = 1000000; "none"
        /// for none). 1M takes minutes and a few GB.
        #[arg(long, value_parser = parse_sizes, default_value = DEFAULT_GENERATED)]
        generated: Sizes,
        /// Rays per intersector and scene (brute force casts fewer).
        #[arg(long, default_value_t = DEFAULT_BENCH_RAYS)]
        rays: u64,
        #[arg(long, default_value_t = DEFAULT_SEED)]
        seed: u64,
        /// Which rays: from patch surfaces as the solver casts them, uniform (origin in the
        /// bounds, direction on the sphere), or half of each.
        #[arg(long, value_enum, default_value_t = RaysFrom::default())]
        source: RaysFrom,
        /// Also write the table as CSV to this file.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Raw Embree closest-hit throughput on random rays against the solver's rays per second,
    /// measured in one run.
    Rays {
        scene: Option<PathBuf>,
        #[command(flatten)]
        scene_args: SceneArgs,
        #[command(flatten)]
        solve_args: SolverArgs,
        /// Random rays for the raw measurement (a quarter before each solve).
        #[arg(long, default_value_t = DEFAULT_RAW_RAYS)]
        rays: u64,
        /// Solve again (next seeds) until the solves took this long in all, alternating with
        /// raw measurements, so both see the same machine.
        #[arg(long, default_value_t = DEFAULT_MIN_SECONDS, value_name = "SECONDS")]
        min_seconds: f64,
        /// Also write the figures as JSON to this file.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Cost per shot (Sec. 4): uniform against non-uniform hemi-cubes with the same largest
    /// delta form factor, ray shots per ray, and where adaptive-hybrid switches.
    Shots {
        scene: Option<PathBuf>,
        #[command(flatten)]
        scene_args: SceneArgs,
        #[command(flatten)]
        solve_args: SolverArgs,
        /// Uniform hemi-cube resolutions to compare.
        #[arg(long, value_delimiter = ',', default_value = DEFAULT_RESOLUTIONS)]
        resolutions: Vec<usize>,
        /// Patches to shoot from (spread over the scene), the same for every sampler.
        #[arg(long, default_value_t = DEFAULT_SHOOTERS)]
        shooters: usize,
        /// Also write the figures as JSON to this file.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Adaptive elements (Cohen et al. 1986) against uniform meshing: the error against a
    /// fine reference at equal element counts, and the count uniform meshing needs for the
    /// adaptive error (README, "Adaptive elements").
    Elements {
        scene: Option<PathBuf>,
        #[command(flatten)]
        scene_args: SceneArgs,
        #[command(flatten)]
        solve_args: SolverArgs,
        /// Thresholds of the adaptive meshes (--element-threshold).
        #[arg(long, value_delimiter = ',', default_value = DEFAULT_THRESHOLDS)]
        thresholds: Vec<f64>,
        /// What the thresholds apply to (--element-test), each measured.
        #[arg(long, value_enum, value_delimiter = ',', default_value = DEFAULT_TESTS)]
        tests: Vec<Test>,
        /// Differences below this fraction of the scene's mean radiosity count as if at it.
        #[arg(long, default_value_t = radiosity::elements::FLOOR)]
        floor: f64,
        /// The smallest element edge, metres (the reference's) [default: the patch size / 8].
        #[arg(long, value_name = "METRES")]
        element_min_size: Option<f32>,
        /// Rays per corner of the uniform and adaptive meshes.
        #[arg(long, default_value_t = radiosity::elements::DEFAULT_RAYS)]
        element_rays: usize,
        /// What the corners of the uniform and adaptive meshes gather (--element-light); the
        /// reference's gather the whole light.
        #[arg(long, value_enum, default_value_t = radiosity::elements::CornerLight::default())]
        element_light: radiosity::elements::CornerLight,
        /// Rays per corner of the reference.
        #[arg(long, default_value_t = DEFAULT_REFERENCE_RAYS)]
        reference_rays: usize,
        /// Also write the figures as JSON to this file.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Times no test asserts: a hemi-cube shot by resolution and layout (Sec. 4), the rasteriser
    /// on 100,000 triangles and, with --grid, the sensor grid's placement.
    Timing {
        /// OBJ file (with its MTL beside it) to shoot hemi-cubes in and place the grid on; the
        /// built-in Cornell box if left out.
        scene: Option<PathBuf>,
        #[command(flatten)]
        scene_args: SceneArgs,
        /// Also time the sensor grid (as `solve --grid`): e.g. 0.8,0.004 on scenes/office.obj,
        /// about two million columns.
        #[arg(long, value_name = "HEIGHT,SPACING|FILE")]
        grid: Option<String>,
        /// Also write the figures as JSON to this file.
        #[arg(long)]
        out: Option<PathBuf>,
    },
}

#[derive(Args)]
pub struct CrosscheckArgs {
    /// OBJ file (with its MTL beside it); the built-in Cornell box if left out.
    scene: Option<PathBuf>,
    #[command(flatten)]
    scene_args: SceneArgs,
    /// Rays to cast (half from patch surfaces as the solver casts them, half uniform).
    #[arg(long)]
    rays: u64,
    #[arg(long, default_value_t = DEFAULT_SEED)]
    seed: u64,
    /// Edge distance, relative to the scene's diagonal, within which a disagreement counts as
    /// crossing a patch edge.
    #[arg(long, default_value_t = DEFAULT_EPS, allow_negative_numbers = true)]
    eps: f32,
    /// The scene is open: rays escaping it do not fail the bar (default: judged by the
    /// reference's escapes).
    #[arg(long, conflicts_with = "closed")]
    open: bool,
    /// The scene is closed: any escape fails the bar.
    #[arg(long)]
    closed: bool,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
    /// Also write the report to this file (JSON if it ends in .json, else text).
    #[arg(long)]
    out: Option<PathBuf>,
}

#[derive(Args)]
pub struct SweepArgs {
    /// Building sizes in patches (1k = 1000, 1M = 1000000).
    #[arg(long, value_parser = parse_sizes, default_value = "1k,4k,16k,64k,256k,1M")]
    sizes: Sizes,
    /// Methods to run at every size.
    #[arg(
        long,
        value_enum,
        value_delimiter = ',',
        default_value = "adaptive-hybrid"
    )]
    methods: Vec<MethodKind>,
    #[command(flatten)]
    solve_args: SolverArgs,
    /// Output folder (sweep.csv, sweep.md, time.png, memory.png).
    #[arg(long)]
    out: PathBuf,
    /// Seed of the generated buildings.
    #[arg(long, default_value_t = BuildingOptions::default().seed)]
    building_seed: u64,
    /// Run the whole solve pipeline on each building, as `radiosity solve` does (load, mesh,
    /// build, sides, solve and final gather, elements, picture, files), and report each
    /// stage's time and peak memory (end-to-end.csv, end-to-end.md, end-to-end-time.png,
    /// end-to-end-memory.png); with the first of --methods.
    #[arg(long)]
    end_to_end: bool,
    /// With --end-to-end: keep each size's building and solve outputs in OUT/SIZE.
    #[arg(long, requires = "end_to_end")]
    keep_outputs: bool,
    #[command(flatten)]
    elements: super::solve::ElementArgs,
}

pub fn bench(c: BenchCommand) -> Result<(), radiosity::Error> {
    match c {
        BenchCommand::Intersect {
            scenes,
            scene_args,
            generated,
            rays,
            seed,
            source: rays_from,
            out,
        } => {
            let job = BenchJob {
                scenes: scenes.into_iter().map(SceneSource::File).collect(),
                generated: generated.0,
                load: scene_args.load(),
                mesh: scene_args.mesh(),
                rays,
                seed,
                rays_from,
            };
            let rows = intersect_jobs::bench_intersect(&job, |r| {
                eprintln!(
                    "{}: {} patches, embree {:.2}, hybrid {:.2} Mrays/s",
                    r.scene, r.shape.patches, r.embree.mrays, r.hybrid.mrays
                )
            })?;
            out!("{}", intersect_table::markdown(&rows));
            if let Some(path) = out {
                let text = intersect_table::csv(&rows);
                write_atomic(&path, |w| w.write_all(text.as_bytes()))?;
            }
            Ok(())
        }
        BenchCommand::Rays {
            scene,
            scene_args,
            solve_args,
            rays,
            min_seconds,
            out,
        } => {
            let b = rays::bench_rays(&RaysJob {
                source: source(scene),
                load: scene_args.load(),
                mesh: scene_args.mesh(),
                solve: solve_args.settings(),
                intersector: solve_args.intersector(),
                raw_rays: rays,
                min_seconds,
            })?;
            outln!("{}", b.text());
            if let Some(path) = out {
                write_json(&path, &b)?;
            }
            Ok(())
        }
        BenchCommand::Shots {
            scene,
            scene_args,
            solve_args,
            resolutions,
            shooters,
            out,
        } => {
            let b = radiosity::bench::shots::bench_shots(&ShotsJob {
                source: source(scene),
                load: scene_args.load(),
                mesh: scene_args.mesh(),
                solve: solve_args.settings(),
                resolutions,
                shooters,
            })?;
            out!("{}", b.markdown());
            if let Some(path) = out {
                write_json(&path, &b)?;
            }
            Ok(())
        }
        BenchCommand::Elements {
            scene,
            scene_args,
            solve_args,
            thresholds,
            tests,
            floor,
            element_min_size,
            element_rays,
            element_light,
            reference_rays,
            out,
        } => {
            let job = ElementBenchJob {
                solve: solve_args.settings(),
                thresholds,
                tests,
                floor,
                min_size: element_min_size,
                rays: element_rays,
                light: element_light,
                reference_rays,
            };
            bench_elements(scene, scene_args, job, out)
        }
        BenchCommand::Timing {
            scene,
            scene_args,
            grid,
            out,
        } => bench_timing(scene, scene_args, grid, out),
    }
}

/// `bench timing`: hemi-cube shots, the rasteriser and the sensor grid timed.
fn bench_timing(
    scene: Option<PathBuf>,
    scene_args: SceneArgs,
    grid: Option<String>,
    out: Option<PathBuf>,
) -> Result<(), radiosity::Error> {
    let job = radiosity::bench::timing::TimingJob {
        source: source(scene),
        load: scene_args.load(),
        mesh: scene_args.mesh(),
        grid,
    };
    let r = radiosity::bench::timing::run(&job)?;
    out!("{}", r.text());
    if let Some(path) = out {
        write_json(&path, &r)?;
    }
    Ok(())
}

fn bench_elements(
    scene: Option<PathBuf>,
    scene_args: SceneArgs,
    job: ElementBenchJob,
    out: Option<PathBuf>,
) -> Result<(), radiosity::Error> {
    job.check()?;
    let model =
        radiosity::model::Model::load(&source(scene), &scene_args.load(), &scene_args.mesh())?;
    let r = radiosity::bench::elements::run(&model, &job, &mut |l: &str| eprintln!("{l}"))?;
    out!("{}", r.markdown());
    if let Some(path) = out {
        write_json(&path, &r)?;
    }
    Ok(())
}

fn write_json(path: &std::path::Path, v: &impl serde::Serialize) -> Result<(), radiosity::Error> {
    write_atomic(path, |w| {
        serde_json::to_writer_pretty(&mut *w, v).map_err(std::io::Error::other)?;
        writeln!(w)
    })?;
    Ok(())
}

pub fn sweep(a: SweepArgs) -> Result<(), radiosity::Error> {
    let job = sweep::SweepJob {
        sizes: a.sizes.0.clone(),
        methods: a.methods.clone(),
        // End to end runs `radiosity solve`'s pipeline, so its defaults too (the error target).
        cfg: if a.end_to_end {
            a.solve_args.solve_settings()
        } else {
            a.solve_args.settings()
        },
        intersector: a.solve_args.intersector(),
        out: a.out.clone(),
        seed: a.building_seed,
    };
    let settings = a.elements.settings();
    settings.check()?;
    if a.end_to_end {
        let rows = sweep_e2e::run(&job, &settings, a.keep_outputs, |l| outln!("{l}"))?;
        outln!("{}", sweep_e2e::markdown(&rows));
        outln!("outputs in {}", a.out.display());
        return Ok(());
    }
    let rows = sweep::run(&job, |l| outln!("{l}"))?;
    outln!("{}", sweep::markdown(&rows, &job.methods));
    outln!("outputs in {}", a.out.display());
    Ok(())
}

pub fn crosscheck(a: CrosscheckArgs) -> Result<(), radiosity::Error> {
    let job = CrossJob {
        source: source(a.scene),
        load: a.scene_args.load(),
        mesh: a.scene_args.mesh(),
        rays: a.rays,
        seed: a.seed,
        eps: a.eps,
        closed: match (a.open, a.closed) {
            (true, _) => Some(false),
            (_, true) => Some(true),
            _ => None,
        },
    };
    let c = intersect_jobs::crosscheck(&job)?;
    let json = serde_json::to_string_pretty(&c).unwrap_or_default();
    if a.json {
        outln!("{json}");
    } else {
        out!("{c}");
    }
    if let Some(path) = a.out {
        let text = if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("json"))
        {
            json + "\n"
        } else {
            c.to_string()
        };
        write_atomic(&path, |w| w.write_all(text.as_bytes()))?;
    }
    if c.report.passed {
        Ok(())
    } else {
        Err(radiosity::Error::Failed(format!(
            "{}: the cross-check bar failed: {}",
            c.scene,
            c.report.failures.join("; ")
        )))
    }
}
