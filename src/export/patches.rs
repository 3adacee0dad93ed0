//! The patch table (docs/design.md §5): one CSV row per patch, stable ids in mesh order,
//! `id, cx, cy, cz, nx, ny, nz, area, rho_r, rho_g, rho_b, e_r, e_g, e_b, b_r, b_g, b_b`
//! (B = radiosity in W/m²; irradiance = (B − E)/ρ), then the daylight columns (docs/design.md
//! §9) `lux, df`: the illuminance in lux (179 lm/W × the luminance-weighted irradiance, over
//! the channels with ρ > 0; empty where the material reflects nothing, so its irradiance is
//! unknown from B) and the daylight factor in % (lux over the sky's unobstructed horizontal
//! illuminance, sun included; empty without a sky).

use crate::mesh::Mesh;
use crate::scene::Material;
use std::io::{self, BufRead, Write};

/// The header's first 17 columns, exactly as other tools script against them.
pub const HEADER: &str = "id,cx,cy,cz,nx,ny,nz,area,rho_r,rho_g,rho_b,e_r,e_g,e_b,b_r,b_g,b_b";
/// The daylight columns added after them (docs/design.md §9).
pub const DAYLIGHT_COLUMNS: &str = "lux,df";

/// Luminance weights of the RGB channels (Rec. 709), for illuminance from RGB irradiance.
pub const LUMA: [f64; 3] = [0.2126, 0.7152, 0.0722];

/// Illuminance in lux of a patch of material `m` and radiosity `b`: 179 lm/W × the
/// luminance-weighted irradiance (B − E)/ρ over the channels with ρ > 0; `None` when no
/// channel reflects.
pub fn lux(m: &Material, b: &[f64; 3]) -> Option<f64> {
    let e = m.emission();
    let (mut sum, mut w) = (0.0, 0.0);
    for c in 0..3 {
        if m.rho[c] > 0.0 {
            sum += LUMA[c] * (b[c] - e[c]) / m.rho[c];
            w += LUMA[c];
        }
    }
    (w > 0.0)
        .then(|| crate::sky::EFFICACY * (sum / w).max(0.0))
        .filter(|h| h.is_finite())
}

/// The column [`write_elements`] adds: the id of the element's patch.
pub const PATCH_COLUMN: &str = "patch";

/// Writes the table. `sky_lux` is the sky's unobstructed horizontal illuminance (sun
/// included) when there is a sky, for the daylight factor. Non-finite values never reach the
/// file: they are an error.
pub fn write(
    w: &mut dyn Write,
    mesh: &Mesh,
    materials: &[Material],
    b: &[[f64; 3]],
    sky_lux: Option<f64>,
) -> io::Result<()> {
    write_rows(w, mesh, materials, b, sky_lux, None)
}

/// The element table `elements.csv` ([`crate::elements`]): the columns of the patch table,
/// one row per element of the element mesh `mesh`, and last [`PATCH_COLUMN`], the id of the
/// patch (a row of `patches.csv`) the element was cut from.
pub fn write_elements(
    w: &mut dyn Write,
    mesh: &Mesh,
    materials: &[Material],
    b: &[[f64; 3]],
    sky_lux: Option<f64>,
    patch: &[u32],
) -> io::Result<()> {
    if patch.len() != mesh.patches.len() || b.len() != mesh.patches.len() {
        return Err(io::Error::other(
            "element arrays do not match the element mesh (internal error)",
        ));
    }
    write_rows(w, mesh, materials, b, sky_lux, Some(patch))
}

fn write_rows(
    w: &mut dyn Write,
    mesh: &Mesh,
    materials: &[Material],
    b: &[[f64; 3]],
    sky_lux: Option<f64>,
    parent: Option<&[u32]>,
) -> io::Result<()> {
    match parent {
        Some(_) => writeln!(w, "{HEADER},{DAYLIGHT_COLUMNS},{PATCH_COLUMN}")?,
        None => writeln!(w, "{HEADER},{DAYLIGHT_COLUMNS}")?,
    }
    // Rows formatted in parallel, chunk by chunk, and written in order: the same bytes as one
    // row after another (formatting the numbers is most of the time on a large model).
    use rayon::prelude::*;
    let table = Table {
        mesh,
        materials,
        b,
        sky_lux,
        parent,
    };
    let n = mesh.patches.len();
    // At most CHUNKS_HELD chunks are held at once, so the memory stays bounded on any model.
    let chunks: Vec<usize> = (0..n).step_by(ROWS_PER_CHUNK).collect();
    for held in chunks.chunks(CHUNKS_HELD) {
        let formatted: Vec<io::Result<Vec<u8>>> = held
            .par_iter()
            .map(|&first| {
                let mut out = Vec::new();
                for i in first..(first + ROWS_PER_CHUNK).min(n) {
                    table.row(&mut out, i)?;
                }
                Ok(out)
            })
            .collect();
        for chunk in formatted {
            w.write_all(&chunk?)?;
        }
    }
    Ok(())
}

/// The element table of elements that are the patches themselves (the elements off or
/// skipped, `crate::elements::Elements::are_the_patches`), made from the patch table `r` as
/// written: each row as it stands there, then its own id as [`PATCH_COLUMN`] — the bytes
/// [`write_elements`] would write, each number formatted once (on a million patches the
/// formatting is most of the time the two tables take).
pub fn elements_of_patch_table(r: &mut impl BufRead, w: &mut dyn Write) -> io::Result<()> {
    let mut line = Vec::with_capacity(256);
    let mut id = 0u64;
    let mut header = true;
    loop {
        line.clear();
        if r.read_until(b'\n', &mut line)? == 0 {
            return Ok(());
        }
        let row = line.strip_suffix(b"\n").ok_or_else(|| {
            io::Error::new(io::ErrorKind::InvalidData, "the patch table ends mid-row")
        })?;
        w.write_all(row)?;
        if header {
            header = false;
            writeln!(w, ",{PATCH_COLUMN}")?;
        } else {
            writeln!(w, ",{id}")?;
            id += 1;
        }
    }
}

/// Rows of a table formatted together by one thread ([`write_rows`]) ...
const ROWS_PER_CHUNK: usize = 16_384;
/// ... and chunks formatted before they are written (about 50 MB of text).
const CHUNKS_HELD: usize = 16;

/// What the rows of the patch or element table are made of ([`write_rows`]).
struct Table<'a> {
    mesh: &'a Mesh,
    materials: &'a [Material],
    b: &'a [[f64; 3]],
    sky_lux: Option<f64>,
    parent: Option<&'a [u32]>,
}

impl Table<'_> {
    /// Row `i`.
    fn row(&self, w: &mut Vec<u8>, i: usize) -> io::Result<()> {
        let Table {
            mesh,
            materials,
            b,
            sky_lux,
            parent,
        } = *self;
        let p = &mesh.patches[i];
        let m = &materials[p.material as usize];
        let e = m.emission();
        let vals = [
            p.centre.x as f64,
            p.centre.y as f64,
            p.centre.z as f64,
            p.normal.x as f64,
            p.normal.y as f64,
            p.normal.z as f64,
            p.area,
            m.rho[0],
            m.rho[1],
            m.rho[2],
            e[0],
            e[1],
            e[2],
            b[i][0],
            b[i][1],
            b[i][2],
        ];
        if vals.iter().any(|v| !v.is_finite()) {
            return Err(io::Error::other(format!(
                "patch {i} has a non-finite value"
            )));
        }
        write!(w, "{i}")?;
        for v in vals {
            write!(w, ",{v}")?;
        }
        let lx = lux(m, &b[i]);
        let df = lx
            .zip(sky_lux.filter(|s| *s > 0.0))
            .map(|(l, s)| 100.0 * l / s);
        let opt = |v: Option<f64>| v.map(|v| v.to_string()).unwrap_or_default();
        write!(w, ",{},{}", opt(lx), opt(df))?;
        match parent {
            Some(pa) => writeln!(w, ",{}", pa[i]),
            None => writeln!(w),
        }
    }
}

/// One row read back.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub id: usize,
    pub values: [f64; 16],
}

impl Row {
    pub fn area(&self) -> f64 {
        self.values[6]
    }
    pub fn b(&self) -> [f64; 3] {
        [self.values[13], self.values[14], self.values[15]]
    }
}

/// Reads a patch table written by [`write`](fn@write) (for references and comparisons).
pub fn read(r: impl BufRead) -> io::Result<Vec<Row>> {
    let bad = |line: usize, what: &str| {
        io::Error::new(io::ErrorKind::InvalidData, format!("line {line}: {what}"))
    };
    let mut rows = Vec::new();
    for (k, line) in r.lines().enumerate() {
        let line = line?;
        if k == 0 {
            // Tables written before the daylight columns end at HEADER.
            if !line.trim().starts_with(HEADER) {
                return Err(bad(1, "not a patch table (unexpected header)"));
            }
            continue;
        }
        if line.trim().is_empty() {
            continue;
        }
        let mut it = line.split(',');
        let id = it
            .next()
            .and_then(|s| s.trim().parse().ok())
            .ok_or_else(|| bad(k + 1, "bad id"))?;
        let mut values = [0.0; 16];
        for v in values.iter_mut() {
            *v = it
                .next()
                .and_then(|s| s.trim().parse().ok())
                .ok_or_else(|| bad(k + 1, "missing or bad number"))?;
        }
        rows.push(Row { id, values });
    }
    Ok(rows)
}

/// Reads a reference patch table and checks it belongs to this mesh (same patch count, and
/// every patch's centre where this mesh has it). Returns its radiosity per patch.
pub fn read_reference(
    path: &std::path::Path,
    m: &crate::mesh::Mesh,
) -> Result<Vec<[f64; 3]>, crate::settings::Invalid> {
    let bad =
        |what: String| crate::settings::Invalid(format!("--reference {}: {what}", path.display()));
    let file = std::fs::File::open(path).map_err(|e| bad(format!("cannot read it ({e})")))?;
    let rows = read(std::io::BufReader::new(file)).map_err(|e| bad(e.to_string()))?;
    if rows.len() != m.patches.len() {
        return Err(bad(format!(
            "it has {} patches but this mesh has {}: solve the reference with the same scene and --patch-size",
            rows.len(),
            m.patches.len()
        )));
    }
    let (lo, hi) = m.vertices.iter().fold(
        (glam::Vec3::splat(f32::MAX), glam::Vec3::splat(f32::MIN)),
        |(l, h), v| (l.min(*v), h.max(*v)),
    );
    let tol = 1e-4 * (hi - lo).max_element().max(f32::MIN_POSITIVE) as f64 + 1e-6;
    for (k, (row, p)) in rows.iter().zip(&m.patches).enumerate() {
        let c = [row.values[0], row.values[1], row.values[2]];
        let far = (0..3).any(|a| (c[a] - p.centre[a] as f64).abs() > tol);
        if row.id != k || far {
            return Err(bad(format!(
                "patch {k} is not where this mesh has it: the reference comes from another scene or patch size"
            )));
        }
        if row.b().iter().any(|x| !x.is_finite() || *x < 0.0) {
            return Err(bad(format!(
                "patch {k} has a radiosity that is not a finite non-negative number"
            )));
        }
    }
    Ok(rows.iter().map(|r| r.b()).collect())
}
