//! The saved solution's reader: the container's header checked first (see
//! [`crate::container`]), then the sections, then everything a file must be to be used —
//! counts that agree, indices in range, finite numbers — so a damaged file is refused here,
//! with one line, rather than misdrawn later.

use super::{LightChannel, SavedSolution, SolutionError, SolutionMeta, CONTAINER, FORMAT_VERSION};
use crate::container::{Cursor, Refusal, Short};
use crate::elements::Elements;
use crate::mesh::{Axis, Mesh, Patch, PatchClass, Side};
use glam::Vec3;
use std::path::Path;

/// Bytes per record of the `PTCH` section.
const PATCH_RECORD: usize = 4 * 4 + 8 + 6 * 4 + 1;

/// Parses a solution file's bytes; `path` only names it in errors.
pub(super) fn from_bytes(path: &Path, bytes: &[u8]) -> Result<SavedSolution, SolutionError> {
    let path_buf = || path.to_path_buf();
    let corrupt = |what: &str| SolutionError::Corrupt {
        path: path_buf(),
        what: what.to_string(),
    };
    let header_len = CONTAINER.header_len() as u64;
    let refused = |r: Refusal| match r {
        // An empty file is no solution at all, rather than a short one.
        Refusal::Foreign | Refusal::ShortHeader { have: 0 } => {
            SolutionError::NotASolution { path: path_buf() }
        }
        Refusal::ShortHeader { have } => SolutionError::Truncated {
            path: path_buf(),
            have: have as u64,
            want: header_len,
        },
        Refusal::Truncated { have, want } => SolutionError::Truncated {
            path: path_buf(),
            have: have + header_len,
            want: want.saturating_add(header_len),
        },
        Refusal::Checksum => corrupt("checksum mismatch"),
    };
    let header = CONTAINER.header(bytes).map_err(refused)?;
    if header.version > FORMAT_VERSION {
        return Err(SolutionError::Newer {
            path: path_buf(),
            found: header.version,
        });
    }
    if header.version == 0 {
        return Err(SolutionError::Unsupported {
            path: path_buf(),
            found: header.version,
        });
    }
    let (payload, trailing) = CONTAINER.payload(bytes, &header).map_err(refused)?;
    if !trailing.is_empty() {
        return Err(corrupt("trailing bytes after the payload"));
    }
    parse_payload(payload).map_err(|what| corrupt(&what))
}

/// Reads records written by [`put_records`] (one-sided).
fn read_records(s: &[u8], tag: &str) -> Result<Vec<Patch>, String> {
    records(s, PATCH_RECORD, tag, |c| {
        Ok(Patch {
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
                _ => return Err(Short),
            },
            side: Side::One,
        })
    })
}

/// A section's bytes as a list of fixed-size records.
fn records<T>(
    s: &[u8],
    size: usize,
    tag: &str,
    read: impl Fn(&mut Cursor) -> Result<T, Short>,
) -> Result<Vec<T>, String> {
    if !s.len().is_multiple_of(size) {
        return Err(format!("section {tag} has a partial record"));
    }
    let mut c = Cursor::new(s);
    (0..s.len() / size)
        .map(|_| read(&mut c).map_err(|_| format!("section {tag} is short")))
        .collect()
}
fn parse_payload(payload: &[u8]) -> Result<SavedSolution, String> {
    // Sections by tag; unknown ones are skipped (see the module docs).
    let mut sections: std::collections::HashMap<[u8; 4], &[u8]> = Default::default();
    let mut c = Cursor::new(payload);
    while !c.is_empty() {
        let tag = c.arr::<4>().map_err(|_| "a section header is cut short")?;
        let len = c.u64().map_err(|_| "a section header is cut short")?;
        let len = usize::try_from(len).map_err(|_| "a section is too long")?;
        let body = c.take(len).map_err(|_| "a section runs past the end")?;
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
        let sides = records(sides, 5, "SIDE", |c| Ok((c.u8()?, c.u32()?)))?;
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
        ..Mesh::default()
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
                ..Mesh::default()
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
    let k = c.u32().map_err(|_| short())?;
    let mut out = Vec::new();
    for _ in 0..k {
        let len = c.u32().map_err(|_| short())? as usize;
        let name = String::from_utf8(c.take(len).map_err(|_| short())?.to_vec())
            .map_err(|_| "section LCHN: a light name is not UTF-8")?;
        let body = c
            .take(patches.checked_mul(24).ok_or_else(short)?)
            .map_err(|_| short())?;
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
