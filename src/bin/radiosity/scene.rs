//! `radiosity info` (describe a scene) and `radiosity generate` (write a model).

use super::args::{source, SceneArgs};
use crate::{out, outln};
use clap::{Args, Subcommand};
use radiosity::generate::{self, BuildingOptions, BUILDING_PATCH_SIZE};
use radiosity::photometry::{self, summary};
use std::path::PathBuf;

#[derive(Args)]
pub struct InfoArgs {
    /// OBJ file (with its MTL beside it); the built-in Cornell box if left out. A luminaire
    /// file (`.ies`, `.ldt`) gets its photometry summed up: the web, its flux against the
    /// lamps', the peak intensity, the opening.
    scene: Option<PathBuf>,
    #[command(flatten)]
    scene_args: SceneArgs,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
}

#[derive(Subcommand)]
pub enum GenerateCommand {
    /// A multi-storey building (OBJ, with its MTL beside it under the same stem).
    Building {
        /// The OBJ file to write.
        #[arg(long)]
        out: PathBuf,
        #[arg(long, default_value_t = BuildingOptions::default().floors)]
        floors: u32,
        /// Rooms per floor.
        #[arg(long, default_value_t = BuildingOptions::default().rooms_per_floor)]
        rooms: u32,
        /// Aim at about this many patches (overrides --floors and --rooms).
        #[arg(long)]
        patches: Option<usize>,
        #[arg(long, default_value_t = BuildingOptions::default().seed)]
        seed: u64,
    },
}

pub fn info(a: InfoArgs) -> Result<(), radiosity::Error> {
    if let Some(path) = a.scene.as_ref().filter(|p| summary::is_photometric_file(p)) {
        let s = summary::summarize(&photometry::read(path)?, &path.display().to_string());
        if a.json {
            outln!("{}", serde_json::to_string_pretty(&s).unwrap_or_default());
        } else {
            out!("{s}");
        }
        return Ok(());
    }
    let info =
        radiosity::pipeline::info(&source(a.scene), &a.scene_args.load(), &a.scene_args.mesh())?;
    if a.json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&info).unwrap_or_default()
        );
    } else {
        out!("{info}");
    }
    Ok(())
}

pub fn generate(c: GenerateCommand) -> Result<(), radiosity::Error> {
    let GenerateCommand::Building {
        out,
        floors,
        rooms,
        patches,
        seed,
    } = c;
    let opts = match patches {
        Some(n) => BuildingOptions::for_patches(n, seed),
        None => BuildingOptions {
            floors,
            rooms_per_floor: rooms,
            seed,
            ..Default::default()
        },
    };
    let st = generate::write_building_files(&out, &opts)?;
    outln!(
        "{}: {} floors × {} rooms, {} polygons, about {} patches at {} m, {} lights",
        out.display(),
        opts.floors,
        opts.rooms_per_floor,
        st.polygons,
        st.estimated_patches,
        BUILDING_PATCH_SIZE,
        st.lights
    );
    Ok(())
}
