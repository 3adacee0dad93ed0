//! The luminaire schedule: the file a user passes as `--luminaires FILE`, listing which
//! photometric file goes where, aimed how.
//!
//! Two formats, chosen by the extension (`.csv`, `.json`, any case) or, failing that, by the
//! text (JSON if it starts with `{`). Photometric file paths are relative to the schedule's
//! folder (absolute paths are taken as they are); each distinct path is read once and its web
//! shared by every luminaire that uses it.
//!
//! **CSV.** The first line that is neither blank nor a `#` comment is the header, naming the
//! columns in any order (any case); every later such line is one row. Fields are split at
//! commas and trimmed: there is no quoting, so no field may contain a comma. An empty cell
//! counts as an absent value. The columns:
//!
//! | column | meaning | default |
//! |---|---|---|
//! | `file` | photometric file (`.ies`, `.ldt`) | required |
//! | `x`, `y`, `z` | position of the photometric centre, model units | required |
//! | `name` | the luminaire's name | file stem + `-` + row number (`downlight-3`) |
//! | `group` | its group | the name |
//! | `aim_x`, `aim_y`, `aim_z` | a point it aims at (all three or none) | straight down, −zenith |
//! | `spin` | turn about the aim, degrees ([`Frame::new`]: counter-clockwise seen from behind the luminaire, from above a downlight) | 0 |
//! | `count` | identical luminaires this row stands for, whole, 1..=[`MAX_COUNT`] | 1 |
//! | `step_x`, `step_y`, `step_z` | offset between them (each alone may be given) | 0 |
//! | `llf` | light-loss factor, > 0 and ≤ [`MAX_LLF`] | 1 |
//! | `r`, `g`, `b` | colour tint, not negative, not all 0 (all three or none) | 1, 1, 1 |
//!
//! The row number counts rows (not lines) from 1. Unknown and repeated columns are refused.
//!
//! **JSON.** `{"luminaires": [{...}, ...]}`, each entry with `file` (string) and `position`
//! (`[x, y, z]`) and optionally `aim` (`[x, y, z]`, a point), `spin`, `count`, `step`
//! (`[x, y, z]`), `llf`, `colour` (`[r, g, b]`; `color` is accepted too), `name` and `group`,
//! meaning what the CSV columns of the same name mean; the entry number is the row number.
//! Unknown keys are refused.
//!
//! **Count and step.** A row of `count` n with a zero step is one [`Luminaire`] whose scale is
//! llf × n (n fittings in one place, or a fitting whose web is for one lamp of n). With a
//! non-zero step it is n luminaires, the k-th (k = 1..n) at position + (k − 1) × step, named
//! `name#1` … `name#n`, all in the row's group, each with scale llf. All of them are aimed the
//! same way, parallel to the first one's aim (a row of identical fittings), not all at the
//! aim point.
//!
//! **Errors** are one [`ScheduleError`], one line naming the schedule, the 1-based line (for
//! CSV the row's line; for JSON the line where the entry opens, or where serde_json stopped)
//! and what is wrong. No input panics.

use super::{normalise_colour, tilt_factor, Frame, Luminaire};
use crate::photometry::{self, Photometry, PhotometryError};
use glam::DVec3;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The most luminaires one row may stand for: far above any real row, low enough that a
/// garbled count fails at once.
pub const MAX_COUNT: u64 = 10_000;

/// The highest light-loss factor accepted: above 1 allows a maintained-output or
/// over-driven correction, above 2 is a typing error.
pub const MAX_LLF: f64 = 2.0;

/// Why a schedule could not be read: one line naming the schedule file, the 1-based line
/// and what is wrong.
#[derive(Debug, thiserror::Error)]
pub enum ScheduleError {
    /// The schedule could not be read from disk.
    #[error("{file}: cannot read: {source}")]
    Io {
        file: String,
        #[source]
        source: std::io::Error,
    },
    /// A row (or the header, or the JSON) breaks the format or holds a value out of range.
    #[error("{file}:{line}: {message}")]
    Invalid {
        file: String,
        line: usize,
        message: String,
    },
    /// A row's photometric file could not be read; the photometric error names its own file
    /// and line.
    #[error("{file}:{line}: {source}")]
    Photometry {
        file: String,
        line: usize,
        #[source]
        source: PhotometryError,
    },
    /// The schedule lists no luminaire.
    #[error("{file}: no luminaires listed")]
    Empty { file: String },
    /// The zenith given with the schedule is not a direction.
    #[error("{file}: the zenith is not a direction (zero or not finite)")]
    Zenith { file: String },
}

/// One row of either format, its values parsed and not yet checked.
#[derive(Debug)]
struct Row {
    /// 1-based line in the schedule.
    line: usize,
    /// 1-based row (entry) number.
    number: usize,
    file: String,
    position: DVec3,
    /// The point it aims at.
    aim: Option<DVec3>,
    spin: f64,
    count: f64,
    step: DVec3,
    llf: f64,
    colour: [f64; 3],
    name: Option<String>,
    group: Option<String>,
}

/// Reads the schedule at `path` for a model whose up direction is `zenith` (the default aim is
/// −zenith; the IES tilt factor is read from the aim's angle to it). Every photometric file is
/// read, and must carry light. The luminaires come in row order, a row's copies together.
pub fn read_schedule(path: &Path, zenith: DVec3) -> Result<Vec<Luminaire>, ScheduleError> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|source| ScheduleError::Io {
        file: file.clone(),
        source,
    })?;
    if Frame::downward(zenith).is_none() {
        return Err(ScheduleError::Zenith { file });
    }
    let text = decode(&bytes);
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    let json = match ext.as_deref() {
        Some("json") => true,
        Some("csv") => false,
        _ => text.trim_start().starts_with('{'),
    };
    let rows = if text.trim().is_empty() {
        Vec::new()
    } else if json {
        json_rows(text, &file)?
    } else {
        csv_rows(text, &file)?
    };
    if rows.is_empty() {
        return Err(ScheduleError::Empty { file });
    }
    let mut placer = Placer {
        file: &file,
        folder: path.parent().unwrap_or(Path::new("")),
        zenith,
        webs: HashMap::new(),
    };
    let mut out = Vec::new();
    for row in &rows {
        placer.place(row, &mut out)?;
    }
    Ok(out)
}

/// The file's text: UTF-8 as it is, anything else byte by byte as Latin-1 (never fails).
fn decode(bytes: &[u8]) -> String {
    match std::str::from_utf8(bytes) {
        Ok(s) => s.to_string(),
        Err(_) => bytes.iter().map(|&b| char::from(b)).collect(),
    }
}

fn invalid(file: &str, line: usize, message: impl Into<String>) -> ScheduleError {
    ScheduleError::Invalid {
        file: file.to_string(),
        line,
        message: message.into(),
    }
}

/// `(x, y, z)` in messages (of values already checked to be finite).
fn show(v: DVec3) -> String {
    format!("({}, {}, {})", v.x, v.y, v.z)
}

/// The row's numbers checked (finite; llf, count and colour in range) and its colour
/// normalised; or what is wrong.
fn checked_colour(row: &Row) -> Result<[f64; 3], String> {
    let vectors = [
        row.position,
        row.step,
        row.aim.unwrap_or(DVec3::ZERO),
        DVec3::new(row.spin, row.llf, row.count),
        DVec3::from_array(row.colour),
    ];
    if !vectors.iter().all(|v| v.is_finite()) {
        return Err("a number is not finite".into());
    }
    if !(row.llf > 0.0 && row.llf <= MAX_LLF) {
        return Err(format!("llf must be > 0 and ≤ {MAX_LLF}, got {}", row.llf));
    }
    let whole = row.count.fract() == 0.0 && row.count >= 1.0;
    if !(whole && row.count <= MAX_COUNT as f64) {
        let count = row.count;
        return Err(format!(
            "count must be a whole number 1..{MAX_COUNT}, got {count}"
        ));
    }
    let [r, g, b] = row.colour;
    if row.colour.iter().any(|&c| c < 0.0) {
        return Err(format!("colour must not be negative, got ({r}, {g}, {b})"));
    }
    normalise_colour(row.colour)
        .ok_or_else(|| "colour (0, 0, 0) is black: give a tint, not all 0".into())
}

/// Turns checked rows into luminaires, reading each photometric file once.
struct Placer<'a> {
    /// The schedule, as named in messages.
    file: &'a str,
    /// Where relative photometric paths start.
    folder: &'a Path,
    zenith: DVec3,
    /// Every web read so far, by resolved path.
    /// Each photometric file read so far: its web and the web's lumens (integrated once).
    webs: HashMap<PathBuf, (Arc<Photometry>, f64)>,
}

impl Placer<'_> {
    /// Checks `row` and appends its luminaire(s) to `out`.
    fn place(&mut self, row: &Row, out: &mut Vec<Luminaire>) -> Result<(), ScheduleError> {
        let bad = |m: String| invalid(self.file, row.line, m);
        let colour = checked_colour(row).map_err(bad)?;
        let aim = match row.aim {
            Some(point) => point - row.position,
            None => -self.zenith,
        };
        let frame = Frame::new(aim, row.spin, None, self.zenith).ok_or_else(|| {
            let point = row.aim.map(show).unwrap_or_default();
            bad(format!(
                "aim point {point} is the luminaire's position: it gives no direction"
            ))
        })?;
        let (path, photometry, web_lumens) = self.web(row)?;
        let name = row.name.clone().unwrap_or_else(|| default_name(row));
        let group = row.group.clone().unwrap_or_else(|| name.clone());
        let count = row.count as u64;
        let spread = count > 1 && row.step != DVec3::ZERO;
        let tilt_factor = tilt_factor(&photometry, frame.aim, self.zenith);
        let (copies, scale) = if spread {
            (count, row.llf)
        } else {
            (1, row.llf * row.count)
        };
        for k in 0..copies {
            out.push(Luminaire {
                name: if spread {
                    format!("{name}#{}", k + 1)
                } else {
                    name.clone()
                },
                group: group.clone(),
                file: path.clone(),
                photometry: photometry.clone(),
                web_lumens,
                position: row.position + row.step * k as f64,
                frame,
                scale,
                colour,
                tilt_factor,
            });
        }
        Ok(())
    }

    /// The web of `row`'s photometric file and its lumens, read on first use; it must carry
    /// light.
    fn web(&mut self, row: &Row) -> Result<(PathBuf, Arc<Photometry>, f64), ScheduleError> {
        let path = self.folder.join(&row.file);
        if let Some((web, lumens)) = self.webs.get(&path) {
            return Ok((path, web.clone(), *lumens));
        }
        let web = photometry::read(&path).map_err(|source| ScheduleError::Photometry {
            file: self.file.to_string(),
            line: row.line,
            source,
        })?;
        let lumens = web.total_lumens();
        if !lumens.is_finite() || lumens <= 0.0 {
            let m = format!("{}: the web carries no light (0 lm)", path.display());
            return Err(invalid(self.file, row.line, m));
        }
        let web = Arc::new(web);
        self.webs.insert(path.clone(), (web.clone(), lumens));
        Ok((path, web, lumens))
    }
}

/// The name of a row without one: the photometric file's stem, `-`, the row number.
fn default_name(row: &Row) -> String {
    let stem = Path::new(&row.file)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| "luminaire".into());
    format!("{stem}-{}", row.number)
}

/// Every CSV column, required first.
const COLUMNS: [&str; 18] = [
    "file", "x", "y", "z", "name", "group", "aim_x", "aim_y", "aim_z", "spin", "count", "step_x",
    "step_y", "step_z", "llf", "r", "g", "b",
];

/// Columns that must be given together, all or none.
const TRIPLES: [[&str; 3]; 2] = [["aim_x", "aim_y", "aim_z"], ["r", "g", "b"]];

/// The rows of a CSV schedule.
fn csv_rows(text: &str, file: &str) -> Result<Vec<Row>, ScheduleError> {
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let Some((header_line, header)) = lines.next() else {
        return Ok(Vec::new());
    };
    let columns = header_columns(header).map_err(|m| invalid(file, header_line, m))?;
    let mut rows = Vec::new();
    for (number, (line, text)) in lines.enumerate() {
        let cells: Vec<&str> = text.split(',').map(str::trim).collect();
        if cells.len() != columns.len() {
            let m = format!(
                "{} fields, but the header (line {header_line}) names {} columns",
                cells.len(),
                columns.len()
            );
            return Err(invalid(file, line, m));
        }
        let cells = Cells {
            columns: &columns,
            cells,
        };
        let row = cells.row(line, number + 1);
        rows.push(row.map_err(|m| invalid(file, line, m))?);
    }
    Ok(rows)
}

/// The header's column names, lower case, checked: known, not repeated, the required ones
/// and whole triples present.
fn header_columns(header: &str) -> Result<Vec<String>, String> {
    let names: Vec<String> = header
        .split(',')
        .map(|c| c.trim().to_ascii_lowercase())
        .collect();
    for (i, name) in names.iter().enumerate() {
        if !COLUMNS.contains(&name.as_str()) {
            let known = COLUMNS.join(", ");
            return Err(format!("unknown column '{name}' (the columns are {known})"));
        }
        if names[..i].contains(name) {
            return Err(format!("column '{name}' is given twice"));
        }
    }
    let has = |c: &str| names.iter().any(|n| n == c);
    if let Some(missing) = COLUMNS[..4].iter().find(|c| !has(c)) {
        return Err(format!(
            "missing column '{missing}' (file, x, y and z are required)"
        ));
    }
    for triple in TRIPLES {
        let n = triple.iter().filter(|c| has(c)).count();
        if n != 0 && n != 3 {
            return Err(format!("give all of {} or none", triple.join(", ")));
        }
    }
    Ok(names)
}

/// One CSV row's cells under the header's columns.
struct Cells<'a> {
    columns: &'a [String],
    cells: Vec<&'a str>,
}

impl Cells<'_> {
    /// The cell of `column`, `None` if the column is absent or the cell empty.
    fn text(&self, column: &str) -> Option<&str> {
        let i = self.columns.iter().position(|c| c == column)?;
        self.cells.get(i).copied().filter(|t| !t.is_empty())
    }

    /// The number in `column`, `None` if absent or empty.
    fn number(&self, column: &str) -> Result<Option<f64>, String> {
        let Some(text) = self.text(column) else {
            return Ok(None);
        };
        match text.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(Some(v)),
            _ => Err(format!("{column}: '{text}' is not a finite number")),
        }
    }

    /// The number in `column`, which must be there.
    fn required(&self, column: &str) -> Result<f64, String> {
        self.number(column)?
            .ok_or_else(|| format!("{column}: the value is missing"))
    }

    /// The three numbers of a triple of columns: all three or none.
    fn triple(&self, columns: [&str; 3]) -> Result<Option<[f64; 3]>, String> {
        let [a, b, c] = columns.map(|col| self.number(col));
        match (a?, b?, c?) {
            (Some(a), Some(b), Some(c)) => Ok(Some([a, b, c])),
            (None, None, None) => Ok(None),
            _ => Err(format!("give all of {} or none", columns.join(", "))),
        }
    }

    /// The row at 1-based `line`, row `number`.
    fn row(&self, line: usize, number: usize) -> Result<Row, String> {
        let file = self.text("file").ok_or("file: the value is missing")?;
        let step = |c: &str| Ok::<f64, String>(self.number(c)?.unwrap_or(0.0));
        Ok(Row {
            line,
            number,
            file: file.to_string(),
            position: DVec3::new(
                self.required("x")?,
                self.required("y")?,
                self.required("z")?,
            ),
            aim: self.triple(TRIPLES[0])?.map(DVec3::from_array),
            spin: self.number("spin")?.unwrap_or(0.0),
            count: self.number("count")?.unwrap_or(1.0),
            step: DVec3::new(step("step_x")?, step("step_y")?, step("step_z")?),
            llf: self.number("llf")?.unwrap_or(1.0),
            colour: self.triple(TRIPLES[1])?.unwrap_or([1.0; 3]),
            name: self.text("name").map(str::to_string),
            group: self.text("group").map(str::to_string),
        })
    }
}

/// A JSON schedule as written.
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonSchedule {
    luminaires: Vec<JsonEntry>,
}

/// One entry of a JSON schedule as written; the keys mean what the CSV columns mean.
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonEntry {
    file: String,
    position: [f64; 3],
    aim: Option<[f64; 3]>,
    spin: Option<f64>,
    count: Option<f64>,
    step: Option<[f64; 3]>,
    llf: Option<f64>,
    #[serde(alias = "color")]
    colour: Option<[f64; 3]>,
    name: Option<String>,
    group: Option<String>,
}

/// The rows of a JSON schedule.
fn json_rows(text: &str, file: &str) -> Result<Vec<Row>, ScheduleError> {
    let schedule: JsonSchedule = serde_json::from_str(text).map_err(|e| {
        let message = e.to_string();
        let suffix = format!(" at line {} column {}", e.line(), e.column());
        let message = match message.strip_suffix(&suffix) {
            Some(m) => format!("{m} (column {})", e.column()),
            None => message.to_string(),
        };
        invalid(file, e.line().max(1), message.replace('\n', " "))
    })?;
    let lines = entry_lines(text);
    let rows = schedule
        .luminaires
        .into_iter()
        .enumerate()
        .map(|(i, e)| Row {
            line: lines.get(i).copied().unwrap_or(1),
            number: i + 1,
            file: e.file,
            position: DVec3::from_array(e.position),
            aim: e.aim.map(DVec3::from_array),
            spin: e.spin.unwrap_or(0.0),
            count: e.count.unwrap_or(1.0),
            step: e.step.map_or(DVec3::ZERO, DVec3::from_array),
            llf: e.llf.unwrap_or(1.0),
            colour: e.colour.unwrap_or([1.0; 3]),
            name: e.name,
            group: e.group,
        });
    Ok(rows.collect())
}

/// The 1-based line where each entry of the `luminaires` array opens: every `{` met at depth
/// 2 (inside the top object, inside its array). Exact for text serde_json has accepted as a
/// [`JsonSchedule`], whose top object holds that one array and nothing else.
pub(super) fn entry_lines(text: &str) -> Vec<usize> {
    let (mut line, mut depth) = (1, 0usize);
    let (mut in_string, mut escaped) = (false, false);
    let mut out = Vec::new();
    for c in text.chars() {
        if c == '\n' {
            line += 1;
        }
        if in_string {
            if escaped {
                escaped = false;
            } else if c == '\\' {
                escaped = true;
            } else if c == '"' {
                in_string = false;
            }
            continue;
        }
        match c {
            '"' => in_string = true,
            '{' | '[' => {
                if c == '{' && depth == 2 {
                    out.push(line);
                }
                depth += 1;
            }
            '}' | ']' => depth = depth.saturating_sub(1),
            _ => {}
        }
    }
    out
}
