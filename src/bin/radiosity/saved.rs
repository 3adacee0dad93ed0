//! The commands that act on a saved solution (`solve --save`): `render`, `export`, `relight`.

use super::args::{parse_weight, CheckArgs, ShadingArgs, ViewArgs, Xyz};
use crate::outln;
use clap::Args;
use radiosity::progress::Progress;
use radiosity::render::Shading;
use radiosity::saved::{self, ExportJob, OutputReport, RelightJob, RenderJob};
use std::path::PathBuf;

#[derive(Args)]
pub struct RenderArgs {
    /// The saved solution (`radiosity solve --save FILE.rad`).
    solution: PathBuf,
    /// Image to write: .png (tone-mapped sRGB), .hdr or .exr (linear radiance, W/sr/m²: the
    /// radiosity over π, as Radiance's rpict writes).
    #[arg(long)]
    out: PathBuf,
    #[command(flatten)]
    check: CheckArgs,
    #[command(flatten)]
    view: ViewArgs,
    #[command(flatten)]
    shading: ShadingArgs,
    /// Seed of the gathered picture's random numbers; the same seed gives the same image on
    /// any thread count.
    #[arg(long, default_value_t = radiosity::solve::settings::DEFAULT_SEED)]
    seed: u64,
    /// Irradiance in false colour on a log scale, with a legend in W/m² (PNG only).
    #[arg(long, alias = "false-color")]
    false_colour: bool,
    /// The model's up direction X,Y,Z, for the default view (no camera flag: the zenith up,
    /// or a building's plan) [default: the zenith of the sky the solution was solved under,
    /// else 0,1,0].
    #[arg(long, value_parser = Xyz::parse, allow_hyphen_values = true)]
    zenith: Option<Xyz>,
    /// Print the report as JSON on stdout.
    #[arg(long)]
    json: bool,
    /// Print nothing but errors.
    #[arg(long, short)]
    quiet: bool,
}

impl RenderArgs {
    fn job(&self) -> Result<RenderJob, radiosity::Error> {
        Ok(RenderJob {
            solution: self.solution.clone(),
            check: self.check.check(),
            out: self.out.clone(),
            view: self.view.settings()?,
            false_colour: self.false_colour,
            shading: self.shading.settings(self.seed, Shading::Gather),
            zenith: self.zenith.map(|z| z.0),
        })
    }
}

#[derive(Args)]
pub struct ExportArgs {
    /// The saved solution (`radiosity solve --save FILE.rad`).
    solution: PathBuf,
    /// Mesh to write: .ply or .glb.
    #[arg(long)]
    out: PathBuf,
    #[command(flatten)]
    check: CheckArgs,
    /// Exposure of the display colours (default: automatic, as for images).
    #[arg(long, allow_negative_numbers = true)]
    exposure: Option<f32>,
    /// Print the report as JSON on stdout.
    #[arg(long)]
    json: bool,
    /// Print nothing but errors.
    #[arg(long, short)]
    quiet: bool,
}

#[derive(Args)]
pub struct RelightArgs {
    /// LIGHT=WEIGHT (repeatable): scale that light's channel (its name as `solve --per-light`
    /// printed it); lights not named keep weight 1.
    #[arg(long = "weight", value_name = "LIGHT=W", value_parser = parse_weight)]
    weights: Vec<(String, f64)>,
    #[command(flatten)]
    render: RenderArgs,
}

pub fn render(a: RenderArgs) -> Result<(), radiosity::Error> {
    let progress = Progress::for_terminal(a.quiet || a.json);
    let r = saved::run_render_with(&a.job()?, &progress)?;
    drop(progress);
    print_report(&r, a.json, a.quiet);
    Ok(())
}

pub fn relight(a: RelightArgs) -> Result<(), radiosity::Error> {
    let job = RelightJob {
        render: a.render.job()?,
        weights: a.weights,
    };
    let progress = Progress::for_terminal(a.render.quiet || a.render.json);
    let r = saved::run_relight_with(&job, &progress)?;
    drop(progress);
    print_report(&r, a.render.json, a.render.quiet);
    Ok(())
}

pub fn export(a: ExportArgs) -> Result<(), radiosity::Error> {
    let job = ExportJob {
        solution: a.solution,
        check: a.check.check(),
        out: a.out,
        exposure: a.exposure,
    };
    let r = saved::run_export(&job)?;
    print_report(&r, a.json, a.quiet);
    Ok(())
}

/// The one-line report of `render`, `export` and `relight`, or its JSON.
fn print_report(r: &OutputReport, json: bool, quiet: bool) {
    for w in &r.warnings {
        eprintln!("warning: {w}");
    }
    if let Some(v) = r.view.as_ref().filter(|_| !quiet && !json) {
        eprintln!("note: {v}");
    }
    if json {
        outln!("{}", serde_json::to_string_pretty(r).unwrap_or_default());
    } else if !quiet {
        let extra = match (&r.scale, r.exposure) {
            (Some(s), _) => format!(", irradiance {}–{} W/m² on a log scale", s.lo, s.hi),
            (None, Some(e)) => format!(", exposure {e:.4}"),
            (None, None) => ", radiance in W/sr/m² (radiosity/π)".to_string(),
        };
        let extra = match (&r.shading, &r.gather) {
            (_, Some(g)) => format!(
                "{extra}; final gather, {:.0} rays per pixel, {:.2} s",
                g.rays_per_pixel, g.seconds
            ),
            (Some(s), None) => format!("{extra}; {s} shading"),
            _ => extra,
        };
        let elements = r
            .elements
            .map_or(String::new(), |n| format!(", {n} elements"));
        outln!(
            "{}: {} of {} ({} patches{elements}, {} vertices){extra}",
            r.out,
            r.format,
            r.scene,
            r.patches,
            r.vertices
        );
    }
}
