//! The `radiosity` command: parses flags into the library's settings and jobs, and prints what
//! they return. Every check and all the work are in the library; one module per group of
//! commands:
//!
//! - `solve`: `solve`;
//! - `saved`: `render`, `export`, `relight` (act on a saved solution);
//! - `compare`: `reference`, `compare`;
//! - `bench`: `bench intersect|rays|shots`, `crosscheck`, `sweep`;
//! - `scene`: `info`, `generate`;
//! - `args`: the flag groups they share.
//!
//! The modules name each other through `super::`, never `crate::` (the macros below aside, which
//! `#[macro_export]` puts at the root of whichever crate compiles them): tests/settings_parity.rs
//! compiles this whole command line as a module of its own, to walk clap's own argument list
//! and to parse flags into the jobs without running them.

mod annual;
mod args;
mod bench;
mod compare;
mod saved;
mod scene;
mod sky_args;
mod solve;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// `println!` that ends the process quietly when standard output is closed (`radiosity info |
/// head -1`) instead of panicking on the broken pipe.
#[macro_export]
macro_rules! outln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        if writeln!(std::io::stdout(), $($arg)*).is_err() {
            std::process::exit(0);
        }
    }};
}

/// `print!` likewise.
#[macro_export]
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        if write!(std::io::stdout(), $($arg)*).is_err() {
            std::process::exit(0);
        }
    }};
}

#[derive(Parser)]
#[command(
    name = "radiosity",
    version,
    about = "Adaptive progressive-refinement radiosity (Airey & Ouh-young 1989) for architectural models"
)]
pub(crate) struct Cli {
    #[command(subcommand)]
    pub(crate) command: Command,
    /// Worker threads (default: all cores). Results do not depend on it.
    #[arg(long, global = true, value_parser = args::parse_threads)]
    pub(crate) threads: Option<usize>,
}

#[derive(Subcommand)]
pub(crate) enum Command {
    /// Solve a scene and write patches.csv, render.png and summary.json into --out.
    Solve(Box<solve::SolveArgs>),
    /// A year of daylight at a sensor grid from one solve (daylight coefficients and a weather
    /// file): hourly illuminance and the annual metrics into --out.
    Annual(Box<annual::AnnualArgs>),
    /// Describe a scene: polygons, patches, axis-aligned share, materials, lights, bounds.
    Info(scene::InfoArgs),
    /// Cast the same rays through every intersector the scene supports and compare the hit
    /// patches against the reference (exit code 1 if the bar fails).
    Crosscheck(bench::CrosscheckArgs),
    /// Solve a high-accuracy reference (adaptive rays, two independent halves averaged) and
    /// write DIR/patches.csv and DIR/summary.json with its stated error bound, checked against
    /// the difference of the halves (exit code 1 if they disagree by more than 2×).
    Reference(compare::ReferenceArgs),
    /// Run methods side by side against one reference and write compare.csv, compare.md,
    /// compare.json and the plots (error against time, Fig. 2's decay, Fig. 5's cost per shot).
    Compare(compare::CompareArgs),
    /// The scene-size performance sweep over generated buildings: times, rays per second,
    /// peak memory and the solver's error estimate per size and method; CSV, Markdown with
    /// growth exponents, log-log plots.
    Sweep(bench::SweepArgs),
    /// Benchmarks.
    #[command(subcommand)]
    Bench(bench::BenchCommand),
    /// Generate models.
    #[command(subcommand)]
    Generate(scene::GenerateCommand),
    /// Render a saved solution (from `solve --save`) to PNG, Radiance HDR or OpenEXR.
    Render(saved::RenderArgs),
    /// Export a saved solution as a mesh with per-vertex radiosity: PLY or binary glTF.
    Export(saved::ExportArgs),
    /// Re-weight the lights of a solution saved with --per-light, without solving again, and
    /// render it (.png/.hdr/.exr) or export it (.ply/.glb).
    Relight(saved::RelightArgs),
}

fn run(cli: Cli) -> Result<(), radiosity::Error> {
    match cli.command {
        Command::Solve(a) => solve::run(*a),
        Command::Annual(a) => annual::run(*a),
        Command::Info(a) => scene::info(a),
        Command::Generate(c) => scene::generate(c),
        Command::Render(a) => saved::render(a),
        Command::Export(a) => saved::export(a),
        Command::Relight(a) => saved::relight(a),
        Command::Reference(a) => compare::reference(a),
        Command::Compare(a) => compare::compare(a),
        Command::Crosscheck(a) => bench::crosscheck(a),
        Command::Sweep(a) => bench::sweep(a),
        Command::Bench(c) => bench::bench(c),
    }
}

/// A command-line error of clap's on one line: its message without the usage and help lines
/// (help and version go to stdout as clap prints them).
fn clap_error_line(e: &clap::Error) -> String {
    let text = e.render().to_string();
    let mut parts = Vec::new();
    for line in text.lines() {
        let line = line.trim();
        if line.starts_with("Usage:") || line.starts_with("For more information") {
            break;
        }
        if !line.is_empty() {
            parts.push(line);
        }
    }
    parts.join(" ")
}

/// Ctrl-C asks the solve to stop at its next safe point (writing a checkpoint if asked, then
/// its outputs); a second Ctrl-C ends the process at once.
fn interrupt_flag() -> std::sync::Arc<std::sync::atomic::AtomicBool> {
    use std::sync::atomic::{AtomicBool, Ordering};
    let flag = std::sync::Arc::new(AtomicBool::new(false));
    let f = flag.clone();
    let _ = ctrlc::set_handler(move || {
        if f.swap(true, Ordering::SeqCst) {
            std::process::exit(130);
        }
        eprintln!("\nstopping at the next safe point (Ctrl-C again to quit at once)…");
    });
    flag
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e)
            if !e.use_stderr()
                || e.kind() == clap::error::ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand =>
        {
            let _ = e.print();
            return ExitCode::from(e.exit_code() as u8);
        }
        Err(e) => {
            eprintln!("{}", clap_error_line(&e));
            return ExitCode::from(2);
        }
    };
    let threads = cli.threads.unwrap_or(0);
    if let Err(e) = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .start_handler(|_| radiosity::intersect::embree::set_flush_denormals())
        .build_global()
    {
        eprintln!("Error: cannot start worker threads: {e}");
        return ExitCode::from(1);
    }
    radiosity::intersect::embree::set_flush_denormals();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("Error: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
