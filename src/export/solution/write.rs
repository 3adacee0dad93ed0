//! The saved solution's writer: the checks a solution must pass to be saved, and its sections
//! in the order the format's table (in `mod.rs`) lists them.

use super::{LightChannel, SolutionMeta, CONTAINER, FORMAT_VERSION};
use crate::container::Put;
use crate::elements::Elements;
use crate::mesh::{Axis, Mesh, Patch, PatchClass, Side};
use std::io::{self, Write};

/// Writes a solution from its parts (so a solve need not copy its mesh to save it).
///
/// Eight parameters: they are the parts of a [`super::SavedSolution`] borrowed from wherever a
/// solve keeps them (a struct of them would be a second `SavedSolution` of references).
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
    check(mesh, b, unshot, vertex_b, channels, elements)?;
    let mut p = Vec::new();
    let json = serde_json::to_vec(meta).map_err(io::Error::other)?;
    section(&mut p, b"META", |s| s.extend_from_slice(&json));
    section(&mut p, b"VERT", |s| {
        for v in &mesh.vertices {
            s.put_f32s(&v.to_array());
        }
    });
    section(&mut p, b"PIDX", |s| {
        mesh.patch_vertices.iter().for_each(|&i| s.put_u32(i))
    });
    section(&mut p, b"PTCH", |s| put_records(s, &mesh.patches));
    section(&mut p, b"BRAD", |s| s.put_f64x3s(b));
    section(&mut p, b"UNSH", |s| s.put_f64x3s(unshot));
    section(&mut p, b"VRAD", |s| {
        vertex_b.iter().for_each(|v| s.put_f32s(v))
    });
    section(&mut p, b"LCHN", |s| {
        s.put_u32(channels.len() as u32);
        for c in channels {
            s.put_u32(c.name.len() as u32);
            s.extend_from_slice(c.name.as_bytes());
            s.put_f64x3s(&c.b);
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
            s.put_u32(other);
        }
    });
    if let Some(e) = elements {
        section(&mut p, b"EVRT", |s| {
            for v in &e.mesh.vertices {
                s.put_f32s(&v.to_array());
            }
        });
        section(&mut p, b"EIDX", |s| {
            e.mesh.patch_vertices.iter().for_each(|&i| s.put_u32(i))
        });
        section(&mut p, b"ELEM", |s| put_records(s, &e.mesh.patches));
        section(&mut p, b"EPAT", |s| {
            e.patch.iter().for_each(|&i| s.put_u32(i))
        });
        section(&mut p, b"EVRD", |s| {
            e.vertex_b.iter().for_each(|v| s.put_f32s(v))
        });
    }
    w.write_all(&CONTAINER.wrap(FORMAT_VERSION, &p))
}

/// What the reader would refuse is not written: arrays that do not match the mesh (an
/// internal error), values that are not finite.
fn check(
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
    Ok(())
}

/// Patch (or element) records as the `PTCH` section keeps them.
fn put_records(s: &mut Vec<u8>, patches: &[Patch]) {
    for q in patches {
        for v in [q.first, q.count, q.material, q.polygon] {
            s.put_u32(v);
        }
        s.put_f64s(&[q.area]);
        s.put_f32s(&q.centre.to_array());
        s.put_f32s(&q.normal.to_array());
        s.push(match q.class {
            PatchClass::Axial(Axis::X) => 0,
            PatchClass::Axial(Axis::Y) => 1,
            PatchClass::Axial(Axis::Z) => 2,
            PatchClass::Skew => 3,
        });
    }
}

/// A section: its tag, its length (u64) and what `fill` writes.
pub(super) fn section(out: &mut Vec<u8>, tag: &[u8; 4], fill: impl FnOnce(&mut Vec<u8>)) {
    out.extend_from_slice(tag);
    let at = out.len();
    out.put_u64(0);
    fill(out);
    let len = (out.len() - at - 8) as u64;
    out[at..at + 8].copy_from_slice(&len.to_le_bytes());
}
