//! The OBJ text read beside tobj: the pre-pass (faces tobj would drop, the `usemtl` names,
//! polylines hidden from it, the patch-size comment), the scans that turn tobj's errors into
//! messages with a line number, and the helpers that quote input in one-line messages.

use std::collections::HashSet;

/// The author's patch size: a comment line `# radiosity: patch-size METRES`.
pub(super) fn patch_size_hint(text: &str) -> Result<Option<f32>, String> {
    for (i, line) in text.lines().enumerate() {
        let Some(rest) = line.trim().strip_prefix('#') else {
            continue;
        };
        let Some(value) = rest.trim().strip_prefix("radiosity:") else {
            continue;
        };
        let Some(value) = value.trim().strip_prefix("patch-size") else {
            continue;
        };
        return match value.trim().parse::<f32>() {
            Ok(v) if v.is_finite() && v > 0.0 => Ok(Some(v)),
            _ => Err(format!(
                "line {}: `# radiosity: patch-size` needs a positive length in metres: `{}`",
                i + 1,
                snippet(line)
            )),
        };
    }
    Ok(None)
}

/// The text with every `l` (polyline) line emptied, line numbers kept; borrowed if it has none.
pub(super) fn without_lines(text: &str) -> std::borrow::Cow<'_, str> {
    let is_line = |line: &str| line.split_whitespace().next() == Some("l");
    if !text.lines().any(is_line) {
        return text.into();
    }
    let mut out = String::with_capacity(text.len());
    for line in text.lines() {
        if !is_line(line) {
            out.push_str(line);
        }
        out.push('\n');
    }
    out.into()
}

/// One pass over the OBJ text: reject faces of fewer than 3 vertices (tobj drops them
/// silently) and collect the material names `usemtl` asks for.
pub(super) fn prescan(text: &str) -> Result<HashSet<String>, String> {
    let mut requested = HashSet::new();
    for (i, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("f") => {
                let n = words.count();
                if n < 3 {
                    return Err(format!(
                        "line {}: a face with {n} {} (a polygon needs at least 3): `{}`",
                        i + 1,
                        if n == 1 { "vertex" } else { "vertices" },
                        snippet(line)
                    ));
                }
            }
            Some("usemtl") => {
                // As tobj reads the name: everything after the first space, trimmed.
                let name = line.split_once(' ').map_or("", |(_, rest)| rest).trim();
                if !name.is_empty() && !requested.contains(name) {
                    requested.insert(name.to_string());
                }
            }
            _ => {}
        }
    }
    Ok(requested)
}

/// A one-line description of a tobj parse error, with the line when it can be found.
pub(super) fn describe_obj_error(text: &str, e: tobj::LoadError) -> String {
    use tobj::LoadError as E;
    let first_line = |wanted: &dyn Fn(&str, &[&str]) -> bool| {
        text.lines().enumerate().find_map(|(i, line)| {
            let mut words = line.split_whitespace();
            let key = words.next()?;
            let rest: Vec<&str> = words.collect();
            wanted(key, &rest).then(|| (i + 1, snippet(line)))
        })
    };
    let (what, at) = match e {
        E::PositionParseError | E::ScalingByZeroError | E::ColorParseError => (
            format!("cannot read a vertex ({e})"),
            first_line(&|key, rest| key == "v" && !vertex_ok(rest)),
        ),
        E::NormalParseError => (
            format!("cannot read a normal ({e})"),
            first_line(&|key, rest| key == "vn" && !numbers_ok(rest, 3)),
        ),
        E::TexcoordParseError => (
            format!("cannot read a texture coordinate ({e})"),
            first_line(&|key, rest| key == "vt" && !numbers_ok(rest, 2)),
        ),
        E::FaceParseError => (
            format!("cannot read a face ({e})"),
            first_line(&|key, rest| {
                (key == "f" || key == "l") && !rest.iter().all(|w| face_word_ok(w))
            }),
        ),
        E::MaterialParseError => (
            "`usemtl` without a material name".to_string(),
            first_line(&|key, rest| key == "usemtl" && rest.is_empty()),
        ),
        E::FaceVertexOutOfBounds | E::FaceTexCoordOutOfBounds | E::FaceNormalOutOfBounds => {
            match find_bad_index(text) {
                Some(message) => return message,
                None => (format!("{e}"), None),
            }
        }
        _ => (format!("cannot read the OBJ ({e})"), None),
    };
    match at {
        Some((n, line)) => format!("line {n}: {what}: `{line}`"),
        None => what,
    }
}

/// Whether a `v` line's values read as tobj reads them: x y z, then nothing, w ≠ 0, or r g b.
fn vertex_ok(rest: &[&str]) -> bool {
    let number = |s: &&str| s.parse::<f32>().is_ok();
    rest.len() >= 3
        && rest[..3].iter().all(number)
        && match rest.len() {
            3 | 6 => true,
            4 => rest[3].parse::<f32>().is_ok_and(|w| w != 0.0),
            _ => false,
        }
}

fn numbers_ok(rest: &[&str], n: usize) -> bool {
    rest.len() >= n && rest[..n].iter().all(|s| s.parse::<f32>().is_ok())
}

/// `v`, `v/vt`, `v//vn` or `v/vt/vn`, each present part an integer.
fn face_word_ok(word: &str) -> bool {
    let parts: Vec<&str> = word.split('/').collect();
    parts.len() <= 3
        && parts
            .iter()
            .all(|p| p.is_empty() || p.parse::<isize>().is_ok())
}

/// The first face corner that refers to a vertex (or texture coordinate, or normal) that does
/// not exist, as a message; `None` if this scan finds none.
fn find_bad_index(text: &str) -> Option<String> {
    const KINDS: [(&str, &str, &str); 3] = [
        ("v", "vertex", "vertices"),
        ("vt", "texture coordinate", "texture coordinates"),
        ("vn", "normal", "normals"),
    ];
    let mut totals = [0usize; 3];
    for line in text.lines() {
        if let Some(slot) = KINDS
            .iter()
            .position(|(k, _, _)| line.split_whitespace().next() == Some(k))
        {
            totals[slot] += 1;
        }
    }
    let mut so_far = [0usize; 3];
    for (i, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let key = words.next();
        if let Some(slot) = KINDS.iter().position(|(k, _, _)| key == Some(k)) {
            so_far[slot] += 1;
            continue;
        }
        if key != Some("f") {
            continue;
        }
        for word in words {
            for (slot, part) in word.split('/').enumerate().take(3) {
                // tobj ignores texture and normal indices when the file has none of them.
                if part.is_empty() || (slot > 0 && totals[slot] == 0) {
                    continue;
                }
                let Ok(x) = part.parse::<isize>() else {
                    continue;
                };
                let resolved = if x > 0 {
                    Some(x.unsigned_abs() - 1)
                } else if x < 0 {
                    so_far[slot].checked_sub(x.unsigned_abs())
                } else {
                    None
                };
                if resolved.is_none_or(|r| r >= totals[slot]) {
                    let (_, kind, kinds) = KINDS[slot];
                    let have = match totals[slot] {
                        1 => format!("1 {kind}"),
                        n => format!("{n} {kinds}"),
                    };
                    let why = if x == 0 {
                        format!("{kind} index 0 (OBJ indices start at 1)")
                    } else {
                        format!("{kind} {x}, but the file has {have}")
                    };
                    return Some(format!(
                        "line {}: a face refers to {why}: `{}`",
                        i + 1,
                        snippet(line)
                    ));
                }
            }
        }
    }
    None
}

/// Which vertex has a coordinate that is not finite, read as tobj reads it (f32, `/ w`).
pub(super) fn describe_non_finite(text: &str) -> String {
    let mut vertex = 0usize;
    for (i, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        if words.next() != Some("v") {
            continue;
        }
        vertex += 1;
        let values: Vec<f32> = words.take(4).map_while(|w| w.parse().ok()).collect();
        if values.len() < 3 {
            continue;
        }
        let w = if values.len() == 4 { values[3] } else { 1.0 };
        if values[..3].iter().any(|c| !(c / w).is_finite()) {
            return format!(
                "vertex {vertex} (line {}) has a coordinate that is not finite: `{}`",
                i + 1,
                snippet(line)
            );
        }
    }
    "a vertex has a coordinate that is not finite (NaN or infinite)".into()
}

pub(super) fn fmt3(v: &[f64; 3]) -> String {
    format!("{} {} {}", v[0], v[1], v[2])
}

/// `a, b, c`, shortened after 20 names.
pub(super) fn name_list(names: &[&str]) -> String {
    const SHOWN: usize = 20;
    let mut list = names
        .iter()
        .take(SHOWN)
        .map(|n| format!("'{n}'"))
        .collect::<Vec<_>>()
        .join(", ");
    if names.len() > SHOWN {
        list += &format!(" and {} more", names.len() - SHOWN);
    }
    if list.is_empty() {
        list = "none".into();
    }
    list
}

/// A line of input quoted in a message: trimmed, at most 60 characters.
pub(super) fn snippet(line: &str) -> String {
    let line = line.trim();
    if line.chars().count() > 60 {
        line.chars().take(57).collect::<String>() + "..."
    } else {
        line.to_string()
    }
}

pub(in crate::scene) fn one_line(s: &str) -> String {
    if s.contains(['\n', '\r']) {
        s.split(['\n', '\r'])
            .filter(|part| !part.is_empty())
            .collect::<Vec<_>>()
            .join(" ")
    } else {
        s.to_string()
    }
}

pub(in crate::scene) fn io_reason(e: &std::io::Error) -> String {
    match e.kind() {
        std::io::ErrorKind::NotFound => "no such file".into(),
        std::io::ErrorKind::PermissionDenied => "permission denied".into(),
        _ => e.to_string(),
    }
}

/// The OBJ/MTL spellings tobj does not read, rewritten away with every line kept at its
/// original number (so every message names the line of the file):
/// - a `#` comment after the data (`v 0 0 0  # note`, `usemtl wall # x`) is cut off; a whole
///   comment line is left as it is (it may be the patch-size comment);
/// - a line ending in a backslash continues on the next one (the OBJ specification's line
///   continuation, as exporters write long `f` lines): the lines are joined onto the first,
///   the backslash read as a space, and each line taken into it is left empty in its place.
///   A backslash inside a trailing comment is part of the comment, not a continuation.
///
/// Borrowed when there is nothing to rewrite.
pub(super) fn normalize(text: &str) -> std::borrow::Cow<'_, str> {
    if !text.contains(['#', '\\']) {
        return text.into();
    }
    if !text.lines().any(|line| {
        let (data, continues) = statement(line, false);
        continues || data.len() != line.len()
    }) {
        return text.into();
    }
    let mut out = String::with_capacity(text.len());
    // The lines joined so far, and how many lines they took.
    let mut joined = String::new();
    let mut taken = 0usize;
    for line in text.lines() {
        let (data, continues) = statement(line, taken > 0);
        joined.push_str(data);
        taken += 1;
        if continues {
            joined.push(' ');
            continue;
        }
        out.push_str(&joined);
        out.extend(std::iter::repeat_n('\n', taken));
        joined.clear();
        taken = 0;
    }
    // A backslash on the last line continues onto nothing.
    out.push_str(&joined);
    out.extend(std::iter::repeat_n('\n', taken));
    out.into()
}

/// A line's data (without a comment after it and without the continuation backslash), and
/// whether it continues on the next line. A line that is all comment is data as it is (tobj
/// skips it), unless it continues a statement: then it is empty and ends the statement.
fn statement(line: &str, continuing: bool) -> (&str, bool) {
    if line.trim_start().starts_with('#') {
        return (if continuing { "" } else { line }, false);
    }
    let data = strip_comment(line);
    match data.trim_end().strip_suffix('\\') {
        Some(head) => (head, true),
        None => (data, false),
    }
}

/// `line` without a comment after its data. A line that is all comment is returned whole.
/// In a statement that carries a name (`usemtl`, `newmtl`, `mtllib`, `g`, `o`, `map_Kd`, …)
/// only a `#` that begins a word starts a comment (`wall#2` is a name); in any other
/// statement (numbers: `v`, `f`, `Kd`, …) the first `#` does.
fn strip_comment(line: &str) -> &str {
    let trimmed = line.trim_start();
    if trimmed.starts_with('#') || !line.contains('#') {
        return line;
    }
    let key = trimmed.split_whitespace().next().unwrap_or("");
    let names = matches!(
        key,
        "usemtl"
            | "newmtl"
            | "mtllib"
            | "g"
            | "o"
            | "s"
            | "bump"
            | "disp"
            | "decal"
            | "refl"
            | "norm"
    ) || key.starts_with("map_");
    let cut = if names {
        line.char_indices()
            .find(|&(i, c)| c == '#' && line[..i].ends_with(char::is_whitespace))
            .map(|(i, _)| i)
    } else {
        line.find('#')
    };
    match cut {
        Some(i) => line[..i].trim_end(),
        None => line,
    }
}
