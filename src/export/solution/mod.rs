//! The saved solution (`radiosity solve --save FILE.rad`, read by `render` and `export`):
//! everything needed to display or export a solve without the OBJ and without solving again.
//!
//! **Layout** (little-endian throughout). A 32-byte header — magic `RADSOL\0\x1a`, format
//! version (u32), reserved flags (u32, 0), payload length (u64), CRC-32 of the payload (u32),
//! reserved (u32, 0): the [`crate::container`] with reserved words — then the payload: a run of
//! sections, each a 4-byte ASCII tag, a u64 length and its bytes:
//!
//! | tag | contents |
//! |---|---|
//! | `META` | JSON [`SolutionMeta`]: tool version, scene name and hash, settings, materials |
//! | `VERT` | welded vertex positions, f32 × 3 each |
//! | `PIDX` | patch vertex indices back to back, u32 each |
//! | `PTCH` | per patch: first, count, material, polygon (u32), area (f64), centre, normal (f32 × 3), class (u8: 0–2 axial x/y/z, 3 skew) |
//! | `BRAD` | radiosity B per patch, f64 × 3 (W/m²) |
//! | `UNSH` | unshot flux ΔΦ per patch, f64 × 3 (W) |
//! | `VRAD` | radiosity at the welded vertices (the area-weighted mean of their patches), f32 × 3 |
//! | `LCHN` | per-light channels: u32 count, then each a u32-length name and f64 × 3 per patch (may be empty) |
//! | `SIDE` | per patch: side (u8: 0 one-sided, 1 front, 2 back twin), the other side's patch id (u32; 0 when one-sided) — format 2 |
//! | `EVRT` | the element mesh's welded vertex positions, f32 × 3 each — format 2 |
//! | `EIDX` | element vertex indices back to back, u32 each — format 2 |
//! | `ELEM` | per element: a record as in `PTCH` (on `EVRT`/`EIDX`) — format 2 |
//! | `EPAT` | per element: the id of its patch, u32 — format 2 |
//! | `EVRD` | radiosity at the element vertices (gathered, [`crate::elements`]), f32 × 3 — format 2 |
//!
//! **Versions.** Format 2 added the element mesh (`EVRT`, `EIDX`, `ELEM`, `EPAT`, `EVRD`: all
//! or none) and the patches' sides (`SIDE`). A format-1 file still reads: its elements are its
//! patches, and its sides are found again by [`Mesh::pair_twins`]. A file newer than
//! [`FORMAT_VERSION`] is refused with one line that says so.
//!
//! **Why hand-written rather than serde + a binary crate.** The file must stay readable by
//! later versions of this tool and by other tools; a layout defined here, in one table, does
//! not change when a dependency's encoding does (bincode 1 and 2 differ on the wire). The bulk
//! is flat arrays of f32/f64 written in one pass, which any language reads with a cast, and
//! the header can be checked (magic, version, length, checksum) before anything is parsed,
//! which is what gives the clear refusals. The flexible part (settings, names) is JSON in
//! `META`, through serde. Unknown section tags are skipped, so a minor addition does not need
//! a new format version; [`FORMAT_VERSION`] rises only when old readers would misread a file.
//!
//! **Scene hash.** [`scene_hash`] (FNV-1a, 64 bits) covers the geometry, the polygons'
//! materials and their reflectances, and the mesh settings (patch size, two-sided): what fixes
//! the patches and their ids. Emission is left out on purpose: relighting changes it without
//! invalidating the patches. A command given both a scene and a solution refuses a solution
//! whose hash differs ([`SavedSolution::check_scene`]).

//!
//! The format's writer is in `write.rs`, its reader (and every check a file must pass) in
//! `read.rs`; this file holds the types and the scene hash.

use crate::container::Container;
use crate::elements::Elements;
use crate::mesh::Mesh;
use crate::scene::Scene;
use serde::{Deserialize, Serialize};
use std::io::{self, Write};
use std::path::{Path, PathBuf};

mod read;
#[cfg(test)]
mod tests;
mod write;

pub use write::write;

/// The first eight bytes of every solution file.
pub const MAGIC: [u8; 8] = *b"RADSOL\0\x1a";
/// The format this build writes, and the newest it reads.
pub const FORMAT_VERSION: u32 = 2;
/// File extension by convention.
pub const EXTENSION: &str = "rad";
/// The header: [`MAGIC`], and the two reserved words (32 bytes).
const CONTAINER: Container = Container {
    magic: MAGIC,
    reserved_words: true,
};

/// A material as saved: enough to compute irradiance (B − E)/ρ without the MTL.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SavedMaterial {
    pub name: String,
    pub rho: [f64; 3],
    /// Emitted radiance, W/sr/m² (E = π·Ke).
    pub ke: [f64; 3],
    /// Glazing: the share of light that goes straight through (`Material::transmittance`), so
    /// that `render --shading gather` sees through panes; 0 in files written before it was
    /// kept (panes then look opaque).
    #[serde(default)]
    pub transmittance: f64,
    /// Tinted glazing's transmittance per channel (`Material::transmittance_rgb`); absent for
    /// grey glazing and in files written before colour was kept (read as grey: `transmittance`
    /// in every channel). Optional in the `META` JSON, so the format's version is unchanged.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transmittance_rgb: Option<[f64; 3]>,
}

impl SavedMaterial {
    /// The material as the solver knew it (what a saved file keeps of it).
    pub fn material(&self) -> crate::scene::Material {
        crate::scene::Material {
            name: self.name.clone(),
            rho: self.rho,
            ke: self.ke,
            rho_source: crate::scene::RhoSource::Kd,
            transmittance: self.transmittance,
            transmittance_rgb: self.transmittance_rgb,
        }
    }
}

/// The settings and provenance of a saved solution (the `META` section, JSON).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SolutionMeta {
    /// Version of the tool that wrote it.
    pub tool_version: String,
    /// The scene's name (its path, or the built-in scene's name).
    pub scene: String,
    /// [`scene_hash`] of the scene and mesh settings solved.
    pub scene_hash: u64,
    pub patch_size: f32,
    pub two_sided: bool,
    pub method: String,
    pub seed: u64,
    pub tolerance: f64,
    /// Energy per ray C the run used (W).
    pub energy_per_ray: f64,
    pub stop_fraction: f64,
    /// Why the solve stopped (`converged`, `max_time`, …), if it did.
    pub stop_reason: Option<String>,
    pub shots: u64,
    pub rays: u64,
    pub materials: Vec<SavedMaterial>,
    /// Every setting that shaped the result (`pipeline::RunSettings` as JSON); null in files
    /// written before it was recorded.
    #[serde(default)]
    pub settings: serde_json::Value,
}

/// One light's share of the radiosity (for relighting): B per patch with only that light on.
pub use crate::solve::LightChannel;

/// A solution as saved and loaded.
#[derive(Clone, Debug, PartialEq)]
pub struct SavedSolution {
    pub meta: SolutionMeta,
    pub mesh: Mesh,
    /// Radiosity per patch, W/m².
    pub b: Vec<[f64; 3]>,
    /// Unshot flux per patch, W.
    pub unshot: Vec<[f64; 3]>,
    /// Radiosity at the welded vertices, W/m² (see [`Mesh::vertex_values`]).
    pub vertex_b: Vec<[f32; 3]>,
    /// Per-light channels; empty when the solve did not keep them.
    pub channels: Vec<LightChannel>,
    /// The adaptive elements (format 2); `None` in a format-1 file: the patches are shown
    /// then. Relighting drops them (their gathered values are the saved lights') and, for an
    /// output that shows them, refines them again under the relit lights
    /// ([`crate::saved::relight::relight_with_elements`]).
    pub elements: Option<Elements>,
}

/// A solution file that cannot be used. Each says which file and what is wrong, in one line.
#[derive(Debug, thiserror::Error)]
pub enum SolutionError {
    #[error("{}: cannot read: {source}", path.display())]
    Read {
        path: PathBuf,
        #[source]
        source: io::Error,
    },
    #[error("{}: not a radiosity solution file (expected one written by `radiosity solve --save`)", path.display())]
    NotASolution { path: PathBuf },
    #[error("{}: solution format {found} is newer than this radiosity reads (up to {FORMAT_VERSION}); use a newer radiosity or solve again", path.display())]
    Newer { path: PathBuf, found: u32 },
    #[error("{}: solution format {found} is not supported", path.display())]
    Unsupported { path: PathBuf, found: u32 },
    #[error("{}: truncated solution file ({have} of {want} bytes); solve again with --save", path.display())]
    Truncated { path: PathBuf, have: u64, want: u64 },
    #[error("{}: damaged solution file ({what}); solve again with --save", path.display())]
    Corrupt { path: PathBuf, what: String },
    #[error("{}: this solution is of another scene or other mesh settings ({saved}, hash {saved_hash:016x}) than {scene} (hash {scene_hash:016x})", path.display())]
    ForeignScene {
        path: PathBuf,
        saved: String,
        saved_hash: u64,
        scene: String,
        scene_hash: u64,
    },
    #[error("{}: its luminaires: {message} (read again on load from the schedule or glTF model the solution names)", path.display())]
    Luminaires { path: PathBuf, message: String },
}

/// FNV-1a, 64 bits: stable across platforms and versions, which is all the hash needs (it
/// tells scenes apart; it is not a defence against forgery).
struct Fnv(u64);

impl Fnv {
    fn new() -> Fnv {
        Fnv(0xcbf2_9ce4_8422_2325)
    }
    fn bytes(&mut self, b: &[u8]) {
        for &x in b {
            self.0 = (self.0 ^ x as u64).wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    fn u64(&mut self, v: u64) {
        self.bytes(&v.to_le_bytes());
    }
}

/// The hash of what fixes a solution's patches: positions, polygons, materials' names and
/// reflectances (not emission: see the module docs), and the mesh settings.
pub fn scene_hash(scene: &Scene, patch_size: f32, two_sided: bool) -> u64 {
    let mut h = Fnv::new();
    h.bytes(b"radiosity scene v1");
    h.u64(scene.positions.len() as u64);
    for p in &scene.positions {
        for c in p.to_array() {
            h.bytes(&c.to_bits().to_le_bytes());
        }
    }
    h.u64(scene.indices.len() as u64);
    for &i in &scene.indices {
        h.bytes(&i.to_le_bytes());
    }
    h.u64(scene.polygons.len() as u64);
    for p in &scene.polygons {
        for v in [p.first, p.len, p.material] {
            h.bytes(&v.to_le_bytes());
        }
    }
    h.u64(scene.materials.len() as u64);
    for m in &scene.materials {
        h.u64(m.name.len() as u64);
        h.bytes(m.name.as_bytes());
        for r in m.rho {
            h.u64(r.to_bits());
        }
    }
    h.bytes(&patch_size.to_bits().to_le_bytes());
    h.bytes(&[two_sided as u8]);
    h.0
}

impl SavedSolution {
    /// What is shown and exported: the element mesh and its vertex radiosities, else the
    /// patches and theirs.
    pub fn display(&self) -> (&Mesh, &[[f32; 3]]) {
        match &self.elements {
            Some(e) => (&e.mesh, &e.vertex_b),
            None => (&self.mesh, &self.vertex_b),
        }
    }

    /// Irradiance per patch (W/m²), `None` where the material reflects nothing.
    pub fn irradiance(&self) -> Vec<Option<f64>> {
        let sol = self;
        use super::patches::LUMA;
        (0..sol.mesh.patches.len())
            .map(|i| {
                let mat = &sol.meta.materials[sol.mesh.patches[i].material as usize];
                let e = sol.emission(i);
                let (mut sum, mut w) = (0.0, 0.0);
                for c in 0..3 {
                    if mat.rho[c] > 0.0 {
                        sum += LUMA[c] * (sol.b[i][c] - e[c]) / mat.rho[c];
                        w += LUMA[c];
                    }
                }
                (w > 0.0)
                    .then(|| (sum / w).max(0.0))
                    .filter(|h| h.is_finite())
            })
            .collect()
    }

    /// Emitted radiosity E = π·Ke (W/m²) of patch `i`'s material.
    pub fn emission(&self, i: usize) -> [f64; 3] {
        let m = &self.meta.materials[self.mesh.patches[i].material as usize];
        m.ke.map(|k| std::f64::consts::PI * k)
    }

    /// Refuses the solution unless it was solved on a scene with hash `scene_hash`.
    pub fn check_scene(
        &self,
        path: &Path,
        scene_name: &str,
        scene_hash: u64,
    ) -> Result<(), SolutionError> {
        if self.meta.scene_hash == scene_hash {
            return Ok(());
        }
        Err(SolutionError::ForeignScene {
            path: path.to_path_buf(),
            saved: self.meta.scene.clone(),
            saved_hash: self.meta.scene_hash,
            scene: scene_name.to_string(),
            scene_hash,
        })
    }

    /// Writes the file (use with [`crate::export::write_atomic`]).
    pub fn write(&self, w: &mut dyn Write) -> io::Result<()> {
        write(
            w,
            &self.meta,
            &self.mesh,
            &self.b,
            &self.unshot,
            &self.vertex_b,
            &self.channels,
            self.elements.as_ref(),
        )
    }

    /// Reads and checks a solution file.
    pub fn load(path: &Path) -> Result<SavedSolution, SolutionError> {
        let bytes = std::fs::read(path).map_err(|source| SolutionError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        let mut sol = Self::from_bytes(path, &bytes)?;
        sol.mesh.luminaires = sol.luminaires(path)?;
        Ok(sol)
    }

    /// The luminaires the solve placed (`--luminaires`): the file keeps their schedule's path,
    /// as given to the solve, and the zenith that aimed them; both are read again here. None
    /// when the solve had none.
    fn luminaires(&self, path: &Path) -> Result<Vec<crate::luminaire::Luminaire>, SolutionError> {
        let load = self.meta.settings.get("load");
        // A glTF model's own lights come with the model: it is read again, as it was read
        // for the solve (its schedule too).
        let model = Path::new(&self.meta.scene);
        if crate::scene::is_gltf(model) {
            let opts: crate::scene::LoadOptions = load
                .and_then(|l| serde_json::from_value(l.clone()).ok())
                .unwrap_or_default();
            let source = crate::scene::SceneSource::File(model.to_path_buf());
            return source.load(&opts).map(|s| s.luminaires).map_err(|e| {
                SolutionError::Luminaires {
                    path: path.to_path_buf(),
                    message: e.to_string(),
                }
            });
        }
        let Some(schedule) = load
            .and_then(|l| l.get("luminaires"))
            .and_then(|v| v.as_str())
        else {
            return Ok(Vec::new());
        };
        let zenith = (load.and_then(|l| l.get("zenith")))
            .and_then(|z| serde_json::from_value::<[f32; 3]>(z.clone()).ok())
            .unwrap_or(crate::sky::DEFAULT_ZENITH.to_array());
        let zenith = glam::Vec3::from(zenith).as_dvec3();
        crate::luminaire::read_schedule(Path::new(schedule), zenith).map_err(|e| {
            SolutionError::Luminaires {
                path: path.to_path_buf(),
                message: e.to_string(),
            }
        })
    }

    /// Parses a solution file's bytes; `path` only names it in errors.
    pub fn from_bytes(path: &Path, bytes: &[u8]) -> Result<SavedSolution, SolutionError> {
        read::from_bytes(path, bytes)
    }
}
