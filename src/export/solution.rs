//! The saved solution (`radiosity solve --save FILE.rad`, read by `render` and `export`):
//! everything needed to display or export a solve without the OBJ and without solving again.
//!
//! **Layout** (little-endian throughout). A 32-byte header — magic `RADSOL\0\x1a`, format
//! version (u32), reserved flags (u32, 0), payload length (u64), CRC-32 of the payload (u32),
//! reserved (u32, 0) — then the payload: a run of sections, each a 4-byte ASCII tag, a u64
//! length and its bytes:
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

use crate::elements::Elements;
use crate::mesh::{Axis, Mesh, Patch, PatchClass, Side};
use crate::scene::Scene;
use glam::Vec3;
use serde::{Deserialize, Serialize};
use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// The first eight bytes of every solution file.
pub const MAGIC: [u8; 8] = *b"RADSOL\0\x1a";
/// The format this build writes, and the newest it reads.
pub const FORMAT_VERSION: u32 = 2;
/// File extension by convention.
pub const EXTENSION: &str = "rad";
const HEADER_LEN: usize = 32;
/// Bytes per record of the `PTCH` section.
const PATCH_RECORD: usize = 4 * 4 + 8 + 6 * 4 + 1;

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
        Self::from_bytes(path, &bytes)
    }

    /// Parses a solution file's bytes; `path` only names it in errors.
    pub fn from_bytes(path: &Path, bytes: &[u8]) -> Result<SavedSolution, SolutionError> {
        let corrupt = |what: &str| SolutionError::Corrupt {
            path: path.to_path_buf(),
            what: what.to_string(),
        };
        // Header: magic first, so a foreign file is named as such even when short.
        let n = bytes.len().min(MAGIC.len());
        if bytes[..n] != MAGIC[..n] || bytes.is_empty() {
            return Err(SolutionError::NotASolution {
                path: path.to_path_buf(),
            });
        }
        if bytes.len() < HEADER_LEN {
            return Err(SolutionError::Truncated {
                path: path.to_path_buf(),
                have: bytes.len() as u64,
                want: HEADER_LEN as u64,
            });
        }
        let mut hdr = Cursor::new(&bytes[8..HEADER_LEN]);
        let version = hdr.u32().ok_or_else(|| corrupt("header"))?;
        if version > FORMAT_VERSION {
            return Err(SolutionError::Newer {
                path: path.to_path_buf(),
                found: version,
            });
        }
        if version == 0 {
            return Err(SolutionError::Unsupported {
                path: path.to_path_buf(),
                found: version,
            });
        }
        let _flags = hdr.u32().ok_or_else(|| corrupt("header"))?;
        let len = hdr.u64().ok_or_else(|| corrupt("header"))?;
        let crc = hdr.u32().ok_or_else(|| corrupt("header"))?;
        let have = (bytes.len() - HEADER_LEN) as u64;
        if have < len {
            return Err(SolutionError::Truncated {
                path: path.to_path_buf(),
                have: bytes.len() as u64,
                want: len.saturating_add(HEADER_LEN as u64),
            });
        }
        if have > len {
            return Err(corrupt("trailing bytes after the payload"));
        }
        let payload = &bytes[HEADER_LEN..];
        if crc32fast::hash(payload) != crc {
            return Err(corrupt("checksum mismatch"));
        }
        parse_payload(payload).map_err(|what| corrupt(&what))
    }
}

/// Writes a solution from its parts (so a solve need not copy its mesh to save it).
#[allow(clippy::too_many_arguments)]
pub fn write(
    w: &mut dyn Write,
    meta: &SolutionMeta,
    mesh: &Mesh,
    b: &[[f64; 3]],
    unshot: &[[f64; 3]],
    vertex_b: &[[f32; 3]],
    channels: &[LightChannel],
    elements: Option<&Elements>,
) -> io::Result<()> {
    if let Some(e) = elements {
        if e.patch.len() != e.mesh.patches.len()
            || e.vertex_b.len() != e.mesh.vertices.len()
            || e.patch.iter().any(|&p| p as usize >= mesh.patches.len())
        {
            return Err(io::Error::other(
                "the elements do not match their mesh (internal error)",
            ));
        }
        if !e.vertex_b.iter().flatten().all(|x| x.is_finite()) {
            return Err(io::Error::other("the elements have a non-finite value"));
        }
    }
    let n = mesh.patches.len();
    if b.len() != n || unshot.len() != n || vertex_b.len() != mesh.vertices.len() {
        return Err(io::Error::other(
            "solution arrays do not match the mesh (internal error)",
        ));
    }
    if channels.iter().any(|c| c.b.len() != n) {
        return Err(io::Error::other(
            "a light channel does not match the mesh (internal error)",
        ));
    }
    let finite = |v: &[f64; 3]| v.iter().all(|x| x.is_finite());
    if !b.iter().all(finite)
        || !unshot.iter().all(finite)
        || !vertex_b.iter().flatten().all(|x| x.is_finite())
        || !channels.iter().all(|c| c.b.iter().all(finite))
    {
        return Err(io::Error::other("the solution has a non-finite value"));
    }
    let mut p = Vec::new();
    let json = serde_json::to_vec(meta).map_err(io::Error::other)?;
    section(&mut p, b"META", |s| s.extend_from_slice(&json));
    section(&mut p, b"VERT", |s| {
        for v in &mesh.vertices {
            put_f32s(s, &v.to_array());
        }
    });
    section(&mut p, b"PIDX", |s| {
        for &i in &mesh.patch_vertices {
            s.extend_from_slice(&i.to_le_bytes());
        }
    });
    section(&mut p, b"PTCH", |s| put_records(s, &mesh.patches));
    section(&mut p, b"BRAD", |s| b.iter().for_each(|v| put_f64s(s, v)));
    section(&mut p, b"UNSH", |s| {
        unshot.iter().for_each(|v| put_f64s(s, v))
    });
    section(&mut p, b"VRAD", |s| {
        vertex_b.iter().for_each(|v| put_f32s(s, v))
    });
    section(&mut p, b"LCHN", |s| {
        s.extend_from_slice(&(channels.len() as u32).to_le_bytes());
        for c in channels {
            s.extend_from_slice(&(c.name.len() as u32).to_le_bytes());
            s.extend_from_slice(c.name.as_bytes());
            c.b.iter().for_each(|v| put_f64s(s, v));
        }
    });
    section(&mut p, b"SIDE", |s| {
        for q in &mesh.patches {
            let (kind, other) = match q.side {
                Side::One => (0u8, 0u32),
                Side::Front { back } => (1, back),
                Side::Back { front } => (2, front),
            };
            s.push(kind);
            s.extend_from_slice(&other.to_le_bytes());
        }
    });
    if let Some(e) = elements {
        section(&mut p, b"EVRT", |s| {
            for v in &e.mesh.vertices {
                put_f32s(s, &v.to_array());
            }
        });
        section(&mut p, b"EIDX", |s| {
            for &i in &e.mesh.patch_vertices {
                s.extend_from_slice(&i.to_le_bytes());
            }
        });
        section(&mut p, b"ELEM", |s| put_records(s, &e.mesh.patches));
        section(&mut p, b"EPAT", |s| {
            for &i in &e.patch {
                s.extend_from_slice(&i.to_le_bytes());
            }
        });
        section(&mut p, b"EVRD", |s| {
            e.vertex_b.iter().for_each(|v| put_f32s(s, v))
        });
    }

    let mut hdr = Vec::with_capacity(HEADER_LEN);
    hdr.extend_from_slice(&MAGIC);
    hdr.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    hdr.extend_from_slice(&0u32.to_le_bytes());
    hdr.extend_from_slice(&(p.len() as u64).to_le_bytes());
    hdr.extend_from_slice(&crc32fast::hash(&p).to_le_bytes());
    hdr.extend_from_slice(&0u32.to_le_bytes());
    w.write_all(&hdr)?;
    w.write_all(&p)
}

/// Patch (or element) records as the `PTCH` section keeps them.
fn put_records(s: &mut Vec<u8>, patches: &[Patch]) {
    for q in patches {
        for v in [q.first, q.count, q.material, q.polygon] {
            s.extend_from_slice(&v.to_le_bytes());
        }
        s.extend_from_slice(&q.area.to_le_bytes());
        put_f32s(s, &q.centre.to_array());
        put_f32s(s, &q.normal.to_array());
        s.push(match q.class {
            PatchClass::Axial(Axis::X) => 0,
            PatchClass::Axial(Axis::Y) => 1,
            PatchClass::Axial(Axis::Z) => 2,
            PatchClass::Skew => 3,
        });
    }
}

/// Reads records written by [`put_records`] (one-sided).
fn read_records(s: &[u8], tag: &str) -> Result<Vec<Patch>, String> {
    records(s, PATCH_RECORD, tag, |c| {
        Some(Patch {
            first: c.u32()?,
            count: c.u32()?,
            material: c.u32()?,
            polygon: c.u32()?,
            area: c.f64()?,
            centre: Vec3::from_array(c.f32x3()?),
            normal: Vec3::from_array(c.f32x3()?),
            class: match c.u8()? {
                0 => PatchClass::Axial(Axis::X),
                1 => PatchClass::Axial(Axis::Y),
                2 => PatchClass::Axial(Axis::Z),
                3 => PatchClass::Skew,
                _ => return None,
            },
            side: Side::One,
        })
    })
}

fn section(out: &mut Vec<u8>, tag: &[u8; 4], fill: impl FnOnce(&mut Vec<u8>)) {
    out.extend_from_slice(tag);
    let at = out.len();
    out.extend_from_slice(&0u64.to_le_bytes());
    fill(out);
    let len = (out.len() - at - 8) as u64;
    out[at..at + 8].copy_from_slice(&len.to_le_bytes());
}

fn put_f32s(s: &mut Vec<u8>, v: &[f32]) {
    v.iter().for_each(|x| s.extend_from_slice(&x.to_le_bytes()));
}

fn put_f64s(s: &mut Vec<u8>, v: &[f64]) {
    v.iter().for_each(|x| s.extend_from_slice(&x.to_le_bytes()));
}

/// A bounds-checked little-endian reader: every read past the end gives `None`.
struct Cursor<'a> {
    b: &'a [u8],
}

impl<'a> Cursor<'a> {
    fn new(b: &'a [u8]) -> Self {
        Cursor { b }
    }
    fn take(&mut self, n: usize) -> Option<&'a [u8]> {
        if n > self.b.len() {
            return None;
        }
        let (a, rest) = self.b.split_at(n);
        self.b = rest;
        Some(a)
    }
    fn arr<const N: usize>(&mut self) -> Option<[u8; N]> {
        self.take(N).and_then(|s| s.try_into().ok())
    }
    fn u8(&mut self) -> Option<u8> {
        self.arr::<1>().map(|a| a[0])
    }
    fn u32(&mut self) -> Option<u32> {
        self.arr().map(u32::from_le_bytes)
    }
    fn u64(&mut self) -> Option<u64> {
        self.arr().map(u64::from_le_bytes)
    }
    fn f32(&mut self) -> Option<f32> {
        self.arr().map(f32::from_le_bytes)
    }
    fn f64(&mut self) -> Option<f64> {
        self.arr().map(f64::from_le_bytes)
    }
    fn f32x3(&mut self) -> Option<[f32; 3]> {
        Some([self.f32()?, self.f32()?, self.f32()?])
    }
    fn f64x3(&mut self) -> Option<[f64; 3]> {
        Some([self.f64()?, self.f64()?, self.f64()?])
    }
}

/// A section's bytes as a list of fixed-size records.
fn records<T>(
    s: &[u8],
    size: usize,
    tag: &str,
    read: impl Fn(&mut Cursor) -> Option<T>,
) -> Result<Vec<T>, String> {
    if !s.len().is_multiple_of(size) {
        return Err(format!("section {tag} has a partial record"));
    }
    let mut c = Cursor::new(s);
    (0..s.len() / size)
        .map(|_| read(&mut c).ok_or_else(|| format!("section {tag} is short")))
        .collect()
}

fn parse_payload(payload: &[u8]) -> Result<SavedSolution, String> {
    // Sections by tag; unknown ones are skipped (see the module docs).
    let mut sections: std::collections::HashMap<[u8; 4], &[u8]> = Default::default();
    let mut c = Cursor::new(payload);
    while !c.b.is_empty() {
        let tag = c.arr::<4>().ok_or("a section header is cut short")?;
        let len = c.u64().ok_or("a section header is cut short")?;
        let len = usize::try_from(len).map_err(|_| "a section is too long")?;
        let body = c.take(len).ok_or("a section runs past the end")?;
        sections.insert(tag, body);
    }
    let get = |tag: &[u8; 4]| {
        sections.get(tag).copied().ok_or_else(|| {
            format!(
                "section {} is missing",
                String::from_utf8_lossy(tag).into_owned()
            )
        })
    };
    let meta: SolutionMeta =
        serde_json::from_slice(get(b"META")?).map_err(|e| format!("section META: {e}"))?;
    let vertices = records(get(b"VERT")?, 12, "VERT", |c| {
        c.f32x3().map(Vec3::from_array)
    })?;
    let patch_vertices = records(get(b"PIDX")?, 4, "PIDX", |c| c.u32())?;
    // Without a SIDE section (format 1) every patch reads one-sided; `Mesh::pair_twins`
    // finds the twins again for a picture that casts rays into the solution.
    let mut patches = read_records(get(b"PTCH")?, "PTCH")?;
    if let Some(sides) = sections.get(b"SIDE") {
        let sides = records(sides, 5, "SIDE", |c| Some((c.u8()?, c.u32()?)))?;
        if sides.len() != patches.len() {
            return Err("section SIDE does not match the patches".into());
        }
        for (i, &(kind, other)) in sides.iter().enumerate() {
            let twin = |want: u8| {
                sides
                    .get(other as usize)
                    .is_some_and(|&(k, o)| k == want && o as usize == i)
            };
            patches[i].side = match kind {
                0 => Side::One,
                1 if twin(2) => Side::Front { back: other },
                2 if twin(1) => Side::Back { front: other },
                _ => return Err("section SIDE has a bad side".into()),
            };
        }
    }
    let b = records(get(b"BRAD")?, 24, "BRAD", |c| c.f64x3())?;
    let unshot = records(get(b"UNSH")?, 24, "UNSH", |c| c.f64x3())?;
    let vertex_b = records(get(b"VRAD")?, 12, "VRAD", |c| c.f32x3())?;
    let channels = match sections.get(b"LCHN") {
        None => Vec::new(),
        Some(s) => parse_channels(s, patches.len())?,
    };
    let mesh = Mesh {
        vertices,
        patch_vertices,
        patches,
        patch_size: meta.patch_size,
    };
    let elements = match sections.get(b"ELEM") {
        None => None,
        Some(el) => {
            let emesh = Mesh {
                vertices: records(get(b"EVRT")?, 12, "EVRT", |c| {
                    c.f32x3().map(Vec3::from_array)
                })?,
                patch_vertices: records(get(b"EIDX")?, 4, "EIDX", |c| c.u32())?,
                patches: read_records(el, "ELEM")?,
                patch_size: meta.patch_size,
            };
            let patch = records(get(b"EPAT")?, 4, "EPAT", |c| c.u32())?;
            let vb = records(get(b"EVRD")?, 12, "EVRD", |c| c.f32x3())?;
            check_elements(
                &emesh,
                &patch,
                &vb,
                mesh.patches.len(),
                meta.materials.len(),
            )?;
            Some(Elements::new(emesh, patch, vb))
        }
    };
    let sol = SavedSolution {
        meta,
        mesh,
        b,
        unshot,
        vertex_b,
        channels,
        elements,
    };
    check_consistent(&sol)?;
    Ok(sol)
}

fn parse_channels(s: &[u8], patches: usize) -> Result<Vec<LightChannel>, String> {
    let short = || "section LCHN is short".to_string();
    let mut c = Cursor::new(s);
    let k = c.u32().ok_or_else(short)?;
    let mut out = Vec::new();
    for _ in 0..k {
        let len = c.u32().ok_or_else(short)? as usize;
        let name = String::from_utf8(c.take(len).ok_or_else(short)?.to_vec())
            .map_err(|_| "section LCHN: a light name is not UTF-8")?;
        let body = c
            .take(patches.checked_mul(24).ok_or_else(short)?)
            .ok_or_else(short)?;
        let b = records(body, 24, "LCHN", |c| c.f64x3())?;
        out.push(LightChannel { name, b });
    }
    Ok(out)
}

/// The element sections agree with each other and with the patches.
fn check_elements(
    m: &Mesh,
    patch: &[u32],
    vb: &[[f32; 3]],
    patches: usize,
    materials: usize,
) -> Result<(), String> {
    if patch.len() != m.patches.len() || vb.len() != m.vertices.len() {
        return Err("element counts differ".into());
    }
    if patch.iter().any(|&p| p as usize >= patches) {
        return Err("an element's patch is out of range".into());
    }
    for p in &m.patches {
        let end = p.first as u64 + p.count as u64;
        if p.count < 3 || end > m.patch_vertices.len() as u64 || p.material as usize >= materials {
            return Err("an element record is out of range".into());
        }
    }
    if m.patch_vertices
        .iter()
        .any(|&i| i as usize >= m.vertices.len())
    {
        return Err("an element vertex index is out of range".into());
    }
    if !vb.iter().flatten().all(|x| x.is_finite()) || !m.vertices.iter().all(|v| v.is_finite()) {
        return Err("an element value is not finite".into());
    }
    Ok(())
}

/// Counts agree, indices are in range, numbers are finite: what the renderer and exporters
/// rely on, so a damaged file is refused here rather than misdrawn later.
fn check_consistent(s: &SavedSolution) -> Result<(), String> {
    let m = &s.mesh;
    let n = m.patches.len();
    if s.b.len() != n || s.unshot.len() != n {
        return Err("radiosity and patch counts differ".into());
    }
    if s.vertex_b.len() != m.vertices.len() {
        return Err("vertex radiosity and vertex counts differ".into());
    }
    for p in &m.patches {
        let end = p.first as u64 + p.count as u64;
        if p.count < 3 || end > m.patch_vertices.len() as u64 {
            return Err("a patch's vertex run is out of range".into());
        }
        if p.material as usize >= s.meta.materials.len() {
            return Err("a patch's material is out of range".into());
        }
    }
    if m.patch_vertices
        .iter()
        .any(|&i| i as usize >= m.vertices.len())
    {
        return Err("a vertex index is out of range".into());
    }
    let finite = |v: &[f64; 3]| v.iter().all(|x| x.is_finite());
    if !s.b.iter().all(finite)
        || !s.unshot.iter().all(finite)
        || !s.vertex_b.iter().flatten().all(|x| x.is_finite())
        || !m.vertices.iter().all(|v| v.is_finite())
    {
        return Err("a value is not finite".into());
    }
    // Glazing passes rays with probability T and tints them by T_c / T: both must be shares.
    let share = |t: f64| (0.0..=1.0).contains(&t);
    for mat in &s.meta.materials {
        if !share(mat.transmittance)
            || !mat
                .transmittance_rgb
                .is_none_or(|c| c.into_iter().all(share))
        {
            return Err(format!(
                "material '{}': a transmittance is not within [0, 1]",
                mat.name
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> SavedSolution {
        let mut mesh = Mesh {
            vertices: vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
            patch_vertices: vec![0, 1, 2, 3],
            patches: Vec::new(),
            patch_size: 1.0,
        };
        mesh.patches.push(Patch {
            first: 0,
            count: 4,
            material: 0,
            polygon: 0,
            area: 1.0,
            centre: Vec3::new(0.5, 0.5, 0.0),
            normal: Vec3::Z,
            class: PatchClass::Axial(Axis::Z),
            side: Side::One,
        });
        SavedSolution {
            meta: SolutionMeta {
                tool_version: "0.1.0".into(),
                scene: "unit".into(),
                scene_hash: 42,
                patch_size: 1.0,
                two_sided: false,
                method: "adaptive-rays".into(),
                seed: 1,
                tolerance: 0.05,
                energy_per_ray: 0.1,
                stop_fraction: 0.0006,
                stop_reason: Some("converged".into()),
                shots: 3,
                rays: 100,
                materials: vec![SavedMaterial {
                    name: "m".into(),
                    rho: [0.5; 3],
                    ke: [1.0; 3],
                    transmittance: 0.0,
                    transmittance_rgb: None,
                }],
                settings: serde_json::Value::Null,
            },
            mesh,
            b: vec![[1.0, 2.0, 3.0]],
            unshot: vec![[0.0, 0.1, 0.2]],
            vertex_b: vec![[1.0, 2.0, 3.0]; 4],
            channels: vec![LightChannel {
                name: "m".into(),
                b: vec![[1.0, 2.0, 3.0]],
            }],
            elements: None,
        }
    }

    fn bytes(s: &SavedSolution) -> Vec<u8> {
        let mut v = Vec::new();
        s.write(&mut v).unwrap();
        v
    }

    #[test]
    fn round_trip_is_identical() {
        let s = sample();
        let back = SavedSolution::from_bytes(Path::new("x.rad"), &bytes(&s)).unwrap();
        assert_eq!(back, s);
    }

    #[test]
    fn every_truncation_is_refused_without_panic() {
        let b = bytes(&sample());
        for k in 0..b.len() {
            let e = SavedSolution::from_bytes(Path::new("x.rad"), &b[..k]).unwrap_err();
            assert!(
                matches!(
                    e,
                    SolutionError::Truncated { .. } | SolutionError::NotASolution { .. }
                ),
                "{k}: {e}"
            );
        }
    }

    #[test]
    fn every_flipped_byte_is_refused_without_panic() {
        let b = bytes(&sample());
        for k in 0..b.len() {
            let mut c = b.clone();
            c[k] ^= 0x5a;
            // Flipping a reserved header byte is harmless; anything else must be caught.
            if let Ok(s) = SavedSolution::from_bytes(Path::new("x.rad"), &c) {
                assert!((12..16).contains(&k) || (28..32).contains(&k), "{k}");
                assert_eq!(s, sample());
            }
        }
    }

    /// The bytes of `sol` as format 1 wrote them: no `SIDE` and no element sections.
    fn as_format_1(sol: &SavedSolution) -> Vec<u8> {
        let b = bytes(sol);
        let mut c = Cursor::new(&b[HEADER_LEN..]);
        let mut payload = Vec::new();
        while !c.b.is_empty() {
            let tag = c.arr::<4>().unwrap();
            let len = c.u64().unwrap() as usize;
            let body = c.take(len).unwrap();
            if !matches!(
                &tag,
                b"SIDE" | b"EVRT" | b"EIDX" | b"ELEM" | b"EPAT" | b"EVRD"
            ) {
                section(&mut payload, &tag, |s| s.extend_from_slice(body));
            }
        }
        let mut out = b[..HEADER_LEN].to_vec();
        out[8..12].copy_from_slice(&1u32.to_le_bytes());
        out[16..24].copy_from_slice(&(payload.len() as u64).to_le_bytes());
        out[24..28].copy_from_slice(&crc32fast::hash(&payload).to_le_bytes());
        out.extend_from_slice(&payload);
        out
    }

    /// Format 2 keeps the sides and the elements; format 1 files still read (elements none,
    /// every patch one-sided until `Mesh::pair_twins`).
    #[test]
    fn format_2_keeps_sides_and_elements_and_format_1_still_reads() {
        let mut s = sample();
        // A back twin for the patch, and elements: the patch cut in two triangles.
        let mut twin = s.mesh.patches[0];
        twin.normal = -twin.normal;
        twin.side = Side::Back { front: 0 };
        s.mesh.patches[0].side = Side::Front { back: 1 };
        s.mesh.patches.push(twin);
        s.b.push([0.5; 3]);
        s.unshot.push([0.0; 3]);
        s.channels[0].b.push([0.5; 3]);
        let mut em = s.mesh.clone();
        em.patches.truncate(1);
        em.patches[0].side = Side::One;
        em.patches[0].count = 3;
        em.patch_vertices = vec![0, 1, 2, 0, 2, 3];
        let mut second = em.patches[0];
        second.first = 3;
        em.patches.push(second);
        s.elements = Some(Elements::new(em, vec![0, 0], vec![[1.0, 2.0, 3.0]; 4]));
        let back = SavedSolution::from_bytes(Path::new("x.rad"), &bytes(&s)).unwrap();
        assert_eq!(back, s);
        assert_eq!(back.display().0.patches.len(), 2);
        // As format 1: no sides, no elements, the rest the same.
        let old = SavedSolution::from_bytes(Path::new("x.rad"), &as_format_1(&s)).unwrap();
        assert!(old.elements.is_none());
        assert!(old.mesh.patches.iter().all(|p| p.side == Side::One));
        assert_eq!(old.b, s.b);
        let mut paired = old.mesh.clone();
        assert_eq!(paired.pair_twins(), 1);
        assert_eq!(paired.patches, s.mesh.patches);
        assert_eq!(old.display().0.patches.len(), 2);
    }

    #[test]
    fn newer_version_and_foreign_scene() {
        let mut b = bytes(&sample());
        b[8..12].copy_from_slice(&(FORMAT_VERSION + 1).to_le_bytes());
        let e = SavedSolution::from_bytes(Path::new("x.rad"), &b).unwrap_err();
        assert!(e.to_string().contains("newer"), "{e}");
        let s = sample();
        assert!(s.check_scene(Path::new("x.rad"), "unit", 42).is_ok());
        let e = s.check_scene(Path::new("x.rad"), "other", 43).unwrap_err();
        assert!(e.to_string().contains("another scene"), "{e}");
    }

    /// A material saved before glazing kept its colour (no `transmittance_rgb` in the META
    /// JSON) reads as grey glazing; tinted glazing's colour round-trips, and grey glazing
    /// writes no colour (so its files are as before).
    #[test]
    fn glazing_colour_is_optional_and_old_files_read_as_grey() {
        let old = r#"{"name":"glass","rho":[0.1,0.1,0.1],"ke":[0,0,0],"transmittance":0.6}"#;
        let m: SavedMaterial = serde_json::from_str(old).unwrap();
        assert_eq!(m.transmittance_rgb, None);
        let mat = m.material();
        assert_eq!(mat.transmittance_rgb(), [0.6; 3]);
        assert_eq!(mat.tint(), [1.0; 3]);
        assert!(!serde_json::to_string(&m)
            .unwrap()
            .contains("transmittance_rgb"));

        let mut s = sample();
        s.meta.materials[0].transmittance = 0.4;
        s.meta.materials[0].transmittance_rgb = Some([0.2, 0.6, 0.4]);
        let back = SavedSolution::from_bytes(Path::new("x.rad"), &bytes(&s)).unwrap();
        assert_eq!(back, s);
        let mat = back.meta.materials[0].material();
        assert_eq!(mat.transmittance_rgb(), [0.2, 0.6, 0.4]);
        assert!(mat.is_tinted());

        // A damaged colour is refused, not drawn.
        s.meta.materials[0].transmittance_rgb = Some([0.2, 1.6, 0.4]);
        let e = SavedSolution::from_bytes(Path::new("x.rad"), &bytes(&s)).unwrap_err();
        assert!(e.to_string().contains("transmittance"), "{e}");
    }
}
