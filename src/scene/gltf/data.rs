//! The bytes behind a glTF document: its buffers (the `.glb`'s binary chunk, files beside the
//! model, `data:` URIs) and what its accessors hold, read here rather than through the `gltf`
//! crate's reader, whose arithmetic trusts the file (a count of 0, a stride shorter than an
//! element or an offset past the end panic or wrap there). Every fault is one line naming the
//! buffer or accessor.

use base64::Engine;
use gltf::accessor::{DataType, Dimensions};
use std::path::Path;

/// The most values a sparse accessor without a buffer view (all zeros but its substitutions)
/// may declare: 60 M (20 M points of three), the tool's patch limit in vertices.
const MAX_SPARSE_VALUES: usize = 60_000_000;

/// The bytes of every buffer, in the document's order.
pub struct Buffers(Vec<Vec<u8>>);

impl Buffers {
    /// Reads every buffer: the binary chunk of a `.glb` (`blob`), a `data:` URI, or a file
    /// relative to `dir` (`None`: no file may be read, as for bytes given without a folder).
    /// A buffer shorter than its `byteLength` is an error; a longer one is cut to it.
    pub fn load(
        doc: &gltf::Document,
        mut blob: Option<Vec<u8>>,
        dir: Option<&Path>,
    ) -> Result<Buffers, String> {
        let mut out = Vec::new();
        for b in doc.buffers() {
            let what = describe("buffer", b.index(), b.name());
            let mut bytes = match b.source() {
                gltf::buffer::Source::Bin => blob
                    .take()
                    .ok_or_else(|| format!("{what} is the binary chunk, which the file has not"))?,
                gltf::buffer::Source::Uri(uri) => {
                    read_uri(uri, dir).map_err(|e| format!("{what}: {e}"))?
                }
            };
            if bytes.len() < b.length() {
                return Err(format!(
                    "{what} holds {} bytes, its byteLength says {}: the file is cut short",
                    bytes.len(),
                    b.length()
                ));
            }
            bytes.truncate(b.length());
            out.push(bytes);
        }
        Ok(Buffers(out))
    }

    /// The bytes of a buffer view.
    pub fn view<'a>(&'a self, view: &gltf::buffer::View) -> Result<&'a [u8], String> {
        let buffer = &self.0[view.buffer().index()];
        view.offset()
            .checked_add(view.length())
            .and_then(|end| buffer.get(view.offset()..end))
            .ok_or_else(|| {
                format!(
                    "{} reaches past the end of buffer {} ({} bytes)",
                    describe("buffer view", view.index(), view.name()),
                    view.buffer().index(),
                    buffer.len()
                )
            })
    }
}

/// `kind N 'name'` (or `kind N` without a name), as messages name a part of the document.
pub fn describe(kind: &str, index: usize, name: Option<&str>) -> String {
    match name {
        Some(n) if !n.is_empty() => format!("{kind} {index} '{}'", crate::scene::obj::one_line(n)),
        _ => format!("{kind} {index}"),
    }
}

/// The bytes a URI names: a `data:` URI decoded (base64), or a file relative to `dir`, its
/// `%xx` escapes undone.
pub fn read_uri(uri: &str, dir: Option<&Path>) -> Result<Vec<u8>, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let Some((_, data)) = rest.split_once(";base64,") else {
            return Err("a data URI that is not base64".into());
        };
        return base64::engine::general_purpose::STANDARD
            .decode(data.trim())
            .map_err(|e| format!("its data URI is not valid base64 ({e})"));
    }
    if uri.contains("://") {
        return Err(format!(
            "'{uri}' is not a file beside the model (only files and data URIs are read)"
        ));
    }
    let Some(dir) = dir else {
        return Err(format!("'{uri}' cannot be read (no folder to find it in)"));
    };
    let path = dir.join(percent_decode(uri));
    std::fs::read(&path).map_err(|e| {
        format!(
            "cannot read '{}': {}",
            path.display(),
            crate::scene::obj::io_reason(&e)
        )
    })
}

/// `%20` and the like undone (glTF URIs are URI-encoded); a malformed escape is kept as written.
fn percent_decode(s: &str) -> String {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = |b: u8| (b as char).to_digit(16);
        if bytes[i] == b'%' && i + 2 < bytes.len() {
            if let (Some(h), Some(l)) = (hex(bytes[i + 1]), hex(bytes[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(bytes[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// One component of an accessor's element as f64, by its type; `normalized` integers mapped
/// to [0, 1] or [−1, 1] as glTF defines.
fn component(bytes: &[u8], ty: DataType, normalized: bool) -> f64 {
    let b = |n: usize| -> [u8; 4] {
        let mut a = [0u8; 4];
        a[..n].copy_from_slice(&bytes[..n]);
        a
    };
    let (v, max) = match ty {
        DataType::I8 => (f64::from(bytes[0] as i8), 127.0),
        DataType::U8 => (f64::from(bytes[0]), 255.0),
        DataType::I16 => (f64::from(i16::from_le_bytes([bytes[0], bytes[1]])), 32767.0),
        DataType::U16 => (f64::from(u16::from_le_bytes([bytes[0], bytes[1]])), 65535.0),
        DataType::U32 => (f64::from(u32::from_le_bytes(b(4))), 4_294_967_295.0),
        DataType::F32 => return f64::from(f32::from_le_bytes(b(4))),
    };
    if normalized {
        (v / max).max(-1.0)
    } else {
        v
    }
}

/// How many components an element of these dimensions has.
fn width(d: Dimensions) -> usize {
    match d {
        Dimensions::Scalar => 1,
        Dimensions::Vec2 => 2,
        Dimensions::Vec3 => 3,
        Dimensions::Vec4 | Dimensions::Mat2 => 4,
        Dimensions::Mat3 => 9,
        Dimensions::Mat4 => 16,
    }
}

/// Reads `count` elements of `n` components of type `ty` from `bytes` at `offset`, `stride`
/// bytes apart (0: packed), into `out` (appended), each component checked to be in `bytes`.
fn read_elements(
    bytes: &[u8],
    offset: usize,
    stride: usize,
    count: usize,
    (ty, n, normalized): (DataType, usize, bool),
    out: &mut Vec<f64>,
) -> Option<()> {
    let size = ty.size();
    let element = size * n;
    let stride = if stride == 0 { element } else { stride };
    if stride < element {
        return None;
    }
    let last = count
        .checked_sub(1)?
        .checked_mul(stride)?
        .checked_add(offset)?;
    bytes.get(last..last.checked_add(element)?)?;
    out.reserve(count * n);
    for i in 0..count {
        let at = offset + i * stride;
        for c in 0..n {
            out.push(component(&bytes[at + c * size..], ty, normalized));
        }
    }
    Some(())
}

/// What an accessor holds, as f64, `n` components per element (its dimensions' width),
/// sparse substitutions applied. `what` names the accessor's use in messages. A count of 0,
/// data outside its buffer view, or a sparse index past the count is an error.
pub fn read_accessor(
    acc: &gltf::Accessor,
    buffers: &Buffers,
    what: &str,
) -> Result<(Vec<f64>, usize), String> {
    let name = format!("{} ({what})", describe("accessor", acc.index(), acc.name()));
    let (ty, n, count) = (acc.data_type(), width(acc.dimensions()), acc.count());
    if count == 0 {
        return Err(format!("{name} has no elements"));
    }
    let outside = || format!("{name} reaches outside its buffer view");
    let mut values = Vec::new();
    match acc.view() {
        Some(view) => {
            let bytes = buffers.view(&view)?;
            let stride = view.stride().unwrap_or(0);
            let element = ty.size() * n;
            if stride != 0 && stride < element {
                return Err(format!(
                    "{name}: its buffer view's byteStride {stride} is shorter than an element \
                     ({element} bytes)"
                ));
            }
            read_elements(
                bytes,
                acc.offset(),
                stride,
                count,
                (ty, n, acc.normalized()),
                &mut values,
            )
            .ok_or_else(outside)?;
        }
        // No view: zeros, for the sparse values to fill.
        None => {
            let total = count
                .checked_mul(n)
                .filter(|t| *t <= MAX_SPARSE_VALUES)
                .ok_or_else(|| {
                    format!("{name} declares {count} elements, more than it can hold")
                })?;
            values.resize(total, 0.0)
        }
    }
    if let Some(sparse) = acc.sparse() {
        let k = sparse.count();
        let (idx, vals) = (sparse.indices(), sparse.values());
        let idx_ty = match idx.index_type() {
            gltf::accessor::sparse::IndexType::U8 => DataType::U8,
            gltf::accessor::sparse::IndexType::U16 => DataType::U16,
            gltf::accessor::sparse::IndexType::U32 => DataType::U32,
        };
        let mut at = Vec::new();
        let mut with = Vec::new();
        read_elements(
            buffers.view(&idx.view())?,
            idx.offset(),
            0,
            k,
            (idx_ty, 1, false),
            &mut at,
        )
        .ok_or_else(|| format!("{name}: its sparse indices reach outside their buffer view"))?;
        read_elements(
            buffers.view(&vals.view())?,
            vals.offset(),
            0,
            k,
            (ty, n, acc.normalized()),
            &mut with,
        )
        .ok_or_else(|| format!("{name}: its sparse values reach outside their buffer view"))?;
        for (j, &i) in at.iter().enumerate() {
            let i = i as usize;
            if i >= count {
                return Err(format!(
                    "{name}: sparse index {i} is past its {count} elements"
                ));
            }
            values[i * n..(i + 1) * n].copy_from_slice(&with[j * n..(j + 1) * n]);
        }
    }
    if let Some(bad) = values.iter().position(|v| !v.is_finite()) {
        return Err(format!(
            "{name}: element {} holds {}, not a finite number",
            bad / n,
            values[bad]
        ));
    }
    Ok((values, n))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percent_escapes_are_undone_and_bad_ones_kept() {
        assert_eq!(percent_decode("a%20b.bin"), "a b.bin");
        assert_eq!(percent_decode("100%"), "100%");
        assert_eq!(percent_decode("%zz%4"), "%zz%4");
    }

    #[test]
    fn elements_outside_their_bytes_are_refused_not_read() {
        let bytes = [0u8; 12];
        let mut out = Vec::new();
        let f = (DataType::F32, 3, false);
        assert!(read_elements(&bytes, 0, 0, 1, f, &mut out).is_some());
        assert!(read_elements(&bytes, 4, 0, 1, f, &mut out).is_none());
        assert!(read_elements(&bytes, 0, 0, 2, f, &mut out).is_none());
        assert!(
            read_elements(&bytes, 0, 4, 1, f, &mut out).is_none(),
            "stride below an element"
        );
        assert!(read_elements(&bytes, usize::MAX, 0, 1, f, &mut out).is_none());
        assert!(read_elements(&bytes, 0, 0, 0, f, &mut out).is_none());
    }

    #[test]
    fn normalized_integers_map_to_unit_range() {
        assert_eq!(component(&[255], DataType::U8, true), 1.0);
        assert_eq!(component(&[0x80], DataType::I8, true), -1.0);
        assert_eq!(component(&[0xff, 0x7f], DataType::I16, true), 1.0);
        assert_eq!(component(&[7, 0, 0, 0], DataType::U32, false), 7.0);
    }
}
