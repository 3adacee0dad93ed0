//! Files other tools read (docs/design.md §5). Every file is written whole or not at all: into a
//! temporary name beside the target, then renamed, so no partial file is left behind.

pub mod glb;
pub mod image;
pub mod patches;
pub mod ply;
pub mod solution;

use std::io::Write;
use std::path::{Path, PathBuf};

/// A file that could not be written.
#[derive(Debug, thiserror::Error)]
#[error("{}: cannot write: {source}", path.display())]
pub struct WriteError {
    pub path: PathBuf,
    #[source]
    pub source: std::io::Error,
}

/// Writes `path` atomically: `fill` writes into `path.tmp`, which is then renamed over `path`.
pub fn write_atomic(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<(), WriteError> {
    let err = |source| WriteError {
        path: path.to_path_buf(),
        source,
    };
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    let tmp = PathBuf::from(tmp);
    let result = (|| {
        let f = std::fs::File::create(&tmp)?;
        let mut w = std::io::BufWriter::new(f);
        fill(&mut w)?;
        w.into_inner().map_err(|e| e.into_error())?.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result.map_err(|e| err(file_in_the_way(path).unwrap_or(e)))
}

/// A regular file where a folder of `path` should be, as an error that names it.
fn file_in_the_way(path: &Path) -> Option<std::io::Error> {
    let file = path.ancestors().skip(1).find(|a| a.is_file())?;
    Some(std::io::Error::other(format!(
        "{} is a file, not a folder",
        file.display()
    )))
}

/// Makes sure `dir` exists and is writable, before any work is spent on what goes into it.
/// Returns the folders it created, deepest first, for [`remove_made_dirs`] if the work fails.
pub fn prepare_dir(dir: &Path) -> Result<Vec<PathBuf>, WriteError> {
    let err = |source| WriteError {
        path: dir.to_path_buf(),
        source,
    };
    // A regular file where a folder should be: say so rather than "File exists".
    if let Some(e) = file_in_the_way(&dir.join("x")) {
        return Err(err(e));
    }
    let made: Vec<PathBuf> = dir
        .ancestors()
        .take_while(|a| !a.as_os_str().is_empty() && !a.exists())
        .map(Path::to_path_buf)
        .collect();
    let probe = dir.join(".radiosity-write-test");
    let result = std::fs::create_dir_all(dir)
        .and_then(|()| std::fs::write(&probe, b""))
        .and_then(|()| std::fs::remove_file(&probe));
    if let Err(e) = result {
        remove_made_dirs(&made);
        return Err(err(e));
    }
    Ok(made)
}

/// Removes the folders [`prepare_dir`] created, deepest first, as far as they are empty.
pub fn remove_made_dirs(made: &[PathBuf]) {
    for dir in made {
        if std::fs::remove_dir(dir).is_err() {
            break;
        }
    }
}

/// The exposure for display colours of per-vertex radiosity: `Some(e)` (finite, ≥ 0) as given,
/// else automatic as for images ([`crate::render::auto_exposure`]).
pub fn vertex_exposure(vertex_b: &[[f32; 3]], exposure: Option<f32>) -> f32 {
    match exposure {
        Some(e) if e.is_finite() && e >= 0.0 => e,
        _ => crate::render::auto_exposure(vertex_b),
    }
}

/// Linear radiosity × exposure, clamped to [0, 1] (0 for non-finite values).
pub fn exposed(rgb: [f32; 3], exposure: f32) -> [f32; 3] {
    rgb.map(|c| {
        let v = c * exposure;
        if v.is_finite() {
            v.clamp(0.0, 1.0)
        } else {
            0.0
        }
    })
}

/// Tone-mapped 8-bit sRGB of a linear radiosity (as the PNG renders show it).
pub fn srgb8(rgb: [f32; 3], exposure: f32) -> [u8; 3] {
    exposed(rgb, exposure).map(|v| (crate::render::srgb_encode(v) * 255.0).round() as u8)
}
