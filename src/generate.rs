//! `radiosity generate building`: a multi-storey building as OBJ + MTL, written as it is made.
//!
//! The sweep and the scale tests need architecture of any size, from a thousand patches to
//! millions, that is *closed* (a shooter's rays never leave it), lit in every room, and about
//! 85 % axis-aligned by area like the real models the paper's plane-merge intersector is meant
//! for (Sec. 2; DESIGN.md §4: real models are 56–90 % axial).
//!
//! **Plan.** Every floor has the same plan: a corridor along x between a south row of rooms and
//! a north row (which also holds the stair room when there is more than one floor). Walls are
//! 0.2 m thick and slabs 0.3 m, so every space is a closed box of faces looking into its air;
//! neighbouring spaces meet only through real openings — doorways cut through the walls (four
//! reveal faces per hole), windows closed by a dark pane at the outer face, and in the stair
//! room a hole through the slab above each flight. Flights alternate between two lanes and two
//! directions from floor to floor, so a flight never stands on the hole of the one below; the
//! top flight leads into the attic, closed by a pitched roof of two skew planes on knee walls
//! and two gables. No corner is acute (a ray leaving a patch beside an acute corner could start
//! beyond the other face). Furniture are blocks standing free on the floor, which is cut around
//! them (a turned block's bounding box is filled around its footprint by four triangles), so no
//! face is hidden behind another and no patch sees a back face.
//!
//! **Axial share.** The roof is skew; what else is skew is furniture turned about the vertical.
//! A running balance decides, piece by piece, whether to turn the next one, aiming at
//! [`SKEW_TARGET`] of the final area (the attic's share is known from the plan in advance).
//!
//! **Streaming.** Coordinates are whole millimetres (`i64`), so shared edges and planes are
//! exact and the text is short; every polygon writes its own vertices and an `f` line with
//! absolute indices from a running counter. Nothing but the plan (O(rooms per floor)) is kept.
//! The same code runs without a writer to count patches, which is how
//! [`BuildingOptions::for_patches`] picks a size: the count mimics [`crate::mesh`] (a quad cut
//! into ⌈u/s⌉·⌈v/s⌉ cells, a triangle into k² with k = ⌈longest edge/s⌉, lengths in `f32`).

use glam::Vec3;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use std::io::{self, BufWriter, Write};

/// The patch size (metres) the generator designs for and writes into the OBJ's
/// `# radiosity: patch-size` line; [`BuildingOptions::for_patches`] counts patches at it.
pub const BUILDING_PATCH_SIZE: f32 = 0.5;

/// The share of the area the generator aims to make skew (turned furniture and the roof).
pub const SKEW_TARGET: f64 = 0.15;

/// What to build.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BuildingOptions {
    /// Storeys (≥ 1); with two or more, a stair room connects them.
    pub floors: u32,
    /// Rooms on each floor besides the stair room (≥ 1), split between the two rows.
    pub rooms_per_floor: u32,
    /// Seed of every random choice (room widths, doors, furniture): same seed, same bytes.
    pub seed: u64,
}

/// What was written.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BuildingStats {
    pub polygons: u64,
    /// Patches at [`BUILDING_PATCH_SIZE`], counted as the mesher cuts them.
    pub estimated_patches: u64,
    /// Light fixtures (each one emitting polygon).
    pub lights: u64,
    /// Axis-aligned share of the area.
    pub axial_fraction: f64,
}

impl Default for BuildingOptions {
    /// Three floors of eight rooms (about 25,000 patches), seed 1.
    fn default() -> Self {
        BuildingOptions {
            floors: 3,
            rooms_per_floor: 8,
            seed: 1,
        }
    }
}

impl BuildingOptions {
    /// A building of about `target` patches at [`BUILDING_PATCH_SIZE`]: floors grow as the
    /// square root of the target, rooms per floor are then found by counting (secant steps on
    /// dry runs, which write nothing). From about 2,000 patches up the result is within a few
    /// per cent; below, a building grows by whole rooms of about 900 patches (one room: about
    /// 1,000), so the nearest is returned.
    pub fn for_patches(target: usize, seed: u64) -> BuildingOptions {
        let floors = ((target as f64 / 2500.0).sqrt().round() as u32).clamp(1, 40);
        let opts = |rooms: u32| BuildingOptions {
            floors,
            rooms_per_floor: rooms.max(1),
            seed,
        };
        let count = |rooms: u32| -> f64 {
            build(None, None, "", &opts(rooms))
                .map_or(f64::INFINITY, |s| s.estimated_patches as f64)
        };
        let target = target as f64;
        let (mut r0, mut c0) = (1u32, count(1));
        let mut best = (r0, (c0 - target).abs());
        if c0 >= target {
            return opts(1);
        }
        // Patches grow about linearly with rooms: secant steps from a first guess.
        let mut r1 = ((target / c0).round() as u32).max(2);
        for _ in 0..6 {
            let c1 = count(r1);
            if (c1 - target).abs() < best.1 {
                best = (r1, (c1 - target).abs());
            }
            if (c1 - target).abs() <= 0.03 * target || c1 == c0 {
                break;
            }
            let slope = (c1 - c0) / (r1 as f64 - r0 as f64);
            let next = (r1 as f64 + (target - c1) / slope).round().max(1.0) as u32;
            if next == r1 {
                break;
            }
            (r0, c0, r1) = (r1, c1, next);
        }
        opts(best.0)
    }
}

/// Streams the OBJ into `obj` (with a `mtllib MTL_NAME` line and the patch-size comment) and
/// the MTL into `mtl`.
pub fn write_building(
    obj: &mut dyn Write,
    mtl: &mut dyn Write,
    mtl_name: &str,
    opts: &BuildingOptions,
) -> io::Result<BuildingStats> {
    build(Some(obj), Some(mtl), mtl_name, opts)
}

// ---- dimensions, millimetres ------------------------------------------------------------

const WALL: i64 = 200;
const STOREY: i64 = 2800;
const SLAB: i64 = 300;
/// Floor to ceiling.
const CLEAR: i64 = STOREY - SLAB;
const CORRIDOR: i64 = 1800;
const DOOR_W: i64 = 900;
const DOOR_H: i64 = 2100;
const WIN_W: i64 = 1200;
const SILL: i64 = 900;
const HEAD: i64 = 2200;
/// Stairs: `STEPS` treads of `TREAD`, `STEPS + 1` risers of `RISER` (the last is the slab's
/// edge), so one flight climbs one storey.
const RISER: i64 = 200;
const TREAD: i64 = 280;
const STEPS: i64 = STOREY / RISER - 1;
/// The flight's first `FREE_STEPS` steps are under the ceiling (head room ≥ 2.1 m); the slab
/// is open above the rest.
const FREE_STEPS: i64 = 2;
const STAIR_ROOM_W: i64 = 3400;
/// Flight lanes (x offsets in the stair room) and the slab holes around them (15 cm wider on
/// each side, so a flight's sides never lie in a hole's reveals).
const LANES: [(i64, i64); 2] = [(350, 1450), (1950, 3050)];
const HOLE_MARGIN: i64 = 150;
/// Flights start (or end) this far from the corridor wall: room for the doorway.
const FLIGHT_OFFSET: i64 = 800;
/// Roof pitch rise/run = 3/5 (31°): with the attic's half width a multiple of 5 mm the ridge
/// is at a whole millimetre, so gables and roof planes share their corners exactly.
const ROOF_RISE: i64 = 3;
const ROOF_RUN: i64 = 5;
/// The attic's knee walls: the roof rests on them, so no corner of the attic is acute (a ray
/// leaving a floor patch next to an acute eave could start outside the roof).
const KNEE: i64 = 600;

fn mm_to_m(v: i64) -> f32 {
    (v as f64 / 1000.0) as f32
}

// ---- materials ----------------------------------------------------------------------------

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Mat {
    Wall,
    Floor,
    CorridorFloor,
    Ceiling,
    Light,
    Glass,
    Wood,
    Fabric,
    Cabinet,
    Stair,
    Roof,
    AtticFloor,
}

impl Mat {
    const ALL: [Mat; 12] = [
        Mat::Wall,
        Mat::Floor,
        Mat::CorridorFloor,
        Mat::Ceiling,
        Mat::Light,
        Mat::Glass,
        Mat::Wood,
        Mat::Fabric,
        Mat::Cabinet,
        Mat::Stair,
        Mat::Roof,
        Mat::AtticFloor,
    ];

    /// (name, comment, Kd, Ke).
    fn spec(self) -> (&'static str, &'static str, [f32; 3], Option<[f32; 3]>) {
        match self {
            Mat::Wall => ("wall", "walls and reveals", [0.72, 0.7, 0.65], None),
            Mat::Floor => ("floor", "room floors", [0.35, 0.33, 0.3], None),
            Mat::CorridorFloor => ("corridor_floor", "", [0.45, 0.45, 0.42], None),
            Mat::Ceiling => ("ceiling", "", [0.8, 0.8, 0.8], None),
            Mat::Light => (
                "light",
                "ceiling panels and lanterns: E = pi * Ke = 31.4 W/m2",
                [0.8, 0.8, 0.8],
                Some([10.0, 10.0, 10.0]),
            ),
            Mat::Glass => (
                "glass",
                "window panes: low reflectance, no emission (night outside)",
                [0.04, 0.04, 0.05],
                None,
            ),
            Mat::Wood => ("wood", "desks and tables", [0.55, 0.38, 0.22], None),
            Mat::Fabric => ("fabric", "chairs and sofas", [0.25, 0.28, 0.4], None),
            Mat::Cabinet => (
                "cabinet",
                "shelves, cabinets, lantern bodies",
                [0.5, 0.5, 0.52],
                None,
            ),
            Mat::Stair => ("stair", "flights and slab edges", [0.6, 0.58, 0.55], None),
            Mat::Roof => ("roof", "underside of the roof", [0.5, 0.38, 0.25], None),
            Mat::AtticFloor => ("attic_floor", "", [0.45, 0.4, 0.35], None),
        }
    }
}

fn write_mtl(mtl: &mut dyn Write) -> io::Result<()> {
    writeln!(
        mtl,
        "# Materials of a building written by `radiosity generate building`."
    )?;
    writeln!(
        mtl,
        "# Kd: diffuse reflectance; Ke: emitted radiance, W/sr/m²."
    )?;
    for m in Mat::ALL {
        let (name, comment, kd, ke) = m.spec();
        writeln!(mtl)?;
        if !comment.is_empty() {
            writeln!(mtl, "# {comment}")?;
        }
        writeln!(mtl, "newmtl {name}")?;
        writeln!(mtl, "Kd {} {} {}", kd[0], kd[1], kd[2])?;
        if let Some(ke) = ke {
            writeln!(mtl, "Ke {} {} {}", ke[0], ke[1], ke[2])?;
        }
    }
    Ok(())
}

// ---- output: polygons, counting -----------------------------------------------------------

type P3 = [i64; 3];

/// Where polygons go: formatted into the OBJ (when there is one) and counted always.
struct Out<'w> {
    obj: Option<BufWriter<&'w mut dyn Write>>,
    line: Vec<u8>,
    mat: Option<Mat>,
    vertices: u64,
    polygons: u64,
    patches: u64,
    lights: u64,
    /// Areas so far, m².
    axial: f64,
    skew: f64,
    size: f32,
}

impl Out<'_> {
    fn raw(&mut self, text: &str) -> io::Result<()> {
        match &mut self.obj {
            Some(w) => w.write_all(text.as_bytes()),
            None => Ok(()),
        }
    }

    /// Starts a named object (and forgets the material, so the next face names it again).
    fn object(&mut self, name: &str) -> io::Result<()> {
        self.mat = None;
        if self.obj.is_some() {
            self.raw(&format!("\no {name}\n"))?;
        }
        Ok(())
    }

    /// One planar convex polygon, wound so that its front faces `toward`.
    fn poly(&mut self, mat: Mat, pts: &[P3], toward: [f64; 3]) -> io::Result<()> {
        // Newell's normal (exact in f64 for millimetre coordinates of this size).
        let mut n = [0.0f64; 3];
        for k in 0..pts.len() {
            let (a, b) = (pts[k], pts[(k + 1) % pts.len()]);
            let (a, b) = (a.map(|c| c as f64), b.map(|c| c as f64));
            n[0] += (a[1] - b[1]) * (a[2] + b[2]);
            n[1] += (a[2] - b[2]) * (a[0] + b[0]);
            n[2] += (a[0] - b[0]) * (a[1] + b[1]);
        }
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        if len == 0.0 {
            return Ok(());
        }
        let flip = n[0] * toward[0] + n[1] * toward[1] + n[2] * toward[2] < 0.0;
        let mut buf = [[0i64; 3]; 4];
        let pts: &[P3] = if flip {
            for (k, p) in pts.iter().rev().enumerate() {
                buf[k] = *p;
            }
            &buf[..pts.len()]
        } else {
            pts
        };
        let area = len * 0.5 * 1e-6;
        let axial = (0..3).any(|a| pts.iter().all(|p| p[a] == pts[0][a]));
        if axial {
            self.axial += area;
        } else {
            self.skew += area;
        }
        self.polygons += 1;
        self.patches += estimate_patches(pts, self.size);
        if mat == Mat::Light {
            self.lights += 1;
        }
        if let Some(w) = &mut self.obj {
            let line = &mut self.line;
            line.clear();
            if self.mat != Some(mat) {
                line.extend_from_slice(b"usemtl ");
                line.extend_from_slice(mat.spec().0.as_bytes());
                line.push(b'\n');
            }
            for p in pts {
                line.push(b'v');
                for &c in p {
                    line.push(b' ');
                    push_mm(line, c);
                }
                line.push(b'\n');
            }
            line.push(b'f');
            for k in 0..pts.len() as u64 {
                line.push(b' ');
                push_uint(line, self.vertices + k + 1);
            }
            line.push(b'\n');
            w.write_all(line)?;
        }
        self.mat = Some(mat);
        self.vertices += pts.len() as u64;
        Ok(())
    }
}

fn push_uint(buf: &mut Vec<u8>, mut v: u64) {
    let mut digits = [0u8; 20];
    let mut k = digits.len();
    loop {
        k -= 1;
        digits[k] = b'0' + (v % 10) as u8;
        v /= 10;
        if v == 0 {
            break;
        }
    }
    buf.extend_from_slice(&digits[k..]);
}

/// Millimetres as metres, shortest form: 12345 → "12.345", -200 → "-0.2", 3000 → "3".
fn push_mm(buf: &mut Vec<u8>, v: i64) {
    if v < 0 {
        buf.push(b'-');
    }
    let a = v.unsigned_abs();
    push_uint(buf, a / 1000);
    let mut frac = a % 1000;
    if frac != 0 {
        buf.push(b'.');
        let mut div = 100;
        while frac != 0 {
            buf.push(b'0' + (frac / div) as u8);
            frac %= div;
            div /= 10;
        }
    }
}

/// Patches the mesher cuts this polygon into (see the module docs), lengths in f32 as there.
fn estimate_patches(pts: &[P3], size: f32) -> u64 {
    let v = |k: usize| Vec3::new(mm_to_m(pts[k][0]), mm_to_m(pts[k][1]), mm_to_m(pts[k][2]));
    let div = |len: f32| ((len / size).ceil() as u64).max(1);
    match pts.len() {
        3 => {
            let longest = (0..3)
                .map(|k| (v((k + 1) % 3) - v(k)).length())
                .fold(0.0, f32::max);
            div(longest).pow(2)
        }
        _ => {
            let u = (v(1) - v(0)).length().max((v(2) - v(3)).length());
            let w = (v(3) - v(0)).length().max((v(2) - v(1)).length());
            div(u) * div(w)
        }
    }
}

// ---- planes with holes ----------------------------------------------------------------------

/// A rectangle in a plane's (u, v) coordinates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct R2 {
    u0: i64,
    u1: i64,
    v0: i64,
    v1: i64,
}

const fn r2(u0: i64, u1: i64, v0: i64, v1: i64) -> R2 {
    R2 { u0, u1, v0, v1 }
}

impl R2 {
    fn overlaps(&self, o: &R2) -> bool {
        self.u0 < o.u1 && o.u0 < self.u1 && self.v0 < o.v1 && o.v0 < self.v1
    }
    fn grown(&self, d: i64) -> R2 {
        r2(self.u0 - d, self.u1 + d, self.v0 - d, self.v1 + d)
    }
    fn transposed(&self) -> R2 {
        r2(self.v0, self.v1, self.u0, self.u1)
    }
}

/// An interval [a, b).
type Span = (i64, i64);

/// `r` minus the `holes`, as rectangles: slabs between the holes' u-edges, the free
/// v-intervals of each, neighbouring slabs with the same free intervals merged.
fn cut(r: R2, holes: &[R2]) -> Vec<R2> {
    let hs: Vec<R2> = holes
        .iter()
        .map(|h| {
            r2(
                h.u0.max(r.u0),
                h.u1.min(r.u1),
                h.v0.max(r.v0),
                h.v1.min(r.v1),
            )
        })
        .filter(|h| h.u1 > h.u0 && h.v1 > h.v0)
        .collect();
    let mut br: Vec<i64> = vec![r.u0, r.u1];
    br.extend(hs.iter().flat_map(|h| [h.u0, h.u1]));
    br.sort_unstable();
    br.dedup();
    // (u0, u1, free v-intervals) of each slab.
    let mut slabs: Vec<(i64, i64, Vec<Span>)> = Vec::new();
    for w in br.windows(2) {
        let (a, b) = (w[0], w[1]);
        let mut cov: Vec<(i64, i64)> = hs
            .iter()
            .filter(|h| h.u0 <= a && h.u1 >= b)
            .map(|h| (h.v0, h.v1))
            .collect();
        cov.sort_unstable();
        let mut free = Vec::new();
        let mut cur = r.v0;
        for (c0, c1) in cov {
            if c0 > cur {
                free.push((cur, c0));
            }
            cur = cur.max(c1);
        }
        if r.v1 > cur {
            free.push((cur, r.v1));
        }
        match slabs.last_mut() {
            Some(last) if last.2 == free => last.1 = b,
            _ => slabs.push((a, b, free)),
        }
    }
    slabs
        .into_iter()
        .flat_map(|(a, b, free)| free.into_iter().map(move |(f0, f1)| r2(a, b, f0, f1)))
        .collect()
}

/// An axis-aligned plane: normal along `axis`; (u, v) = (x, z) for y, (z, y) for x, (x, y) for z.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Axis {
    X,
    Y,
    Z,
}

fn to3(axis: Axis, c: i64, u: i64, v: i64) -> P3 {
    match axis {
        Axis::X => [c, v, u],
        Axis::Y => [u, c, v],
        Axis::Z => [u, v, c],
    }
}

fn axis_dir(axis: Axis, sign: i64) -> [f64; 3] {
    let s = sign as f64;
    match axis {
        Axis::X => [s, 0.0, 0.0],
        Axis::Y => [0.0, s, 0.0],
        Axis::Z => [0.0, 0.0, s],
    }
}

/// A triangle in a plane's (u, v) coordinates.
type T2 = [[i64; 2]; 3];

// ---- plan ----------------------------------------------------------------------------------

/// A room (or the stair room) in a row: x extent and its doorways.
#[derive(Clone, Debug)]
struct Unit {
    x0: i64,
    x1: i64,
    stair: bool,
    /// Doorway to the corridor: x range.
    door: (i64, i64),
    /// Doorway to the next unit of the row (through the wall at x1): z range.
    next_door: Option<(i64, i64)>,
}

#[derive(Clone, Debug)]
struct Row {
    /// Interior z range.
    z0: i64,
    z1: i64,
    /// South row: the corridor is at z1 and the outside at z0; north row: the other way.
    south: bool,
    units: Vec<Unit>,
}

impl Row {
    fn corridor_z(&self) -> i64 {
        if self.south {
            self.z1
        } else {
            self.z0
        }
    }
    fn outside_z(&self) -> i64 {
        if self.south {
            self.z0
        } else {
            self.z1
        }
    }
    /// Direction from the row into the corridor (+1: +z).
    fn to_corridor(&self) -> i64 {
        if self.south {
            1
        } else {
            -1
        }
    }
}

struct Plan {
    floors: i64,
    /// Outer extent: x in [0, lx], z in [0, lz].
    lx: i64,
    lz: i64,
    rows: Vec<Row>,
    /// Corridor interior z range (x runs from WALL to lx − WALL).
    cz: (i64, i64),
    /// Attic: half width (eave to ridge, horizontally) and rise.
    half: i64,
    rise: i64,
}

fn plan(opts: &BuildingOptions, rng: &mut Pcg64Mcg) -> Plan {
    let floors = opts.floors as i64;
    let rooms = opts.rooms_per_floor as i64;
    let has_stair = floors >= 2;
    // Room depth: a multiple of 10 mm so the attic's half width is a multiple of 5 mm; deep
    // enough for a flight and its landings when there are stairs.
    let depth = if has_stair {
        5150 + 100 * rng.gen_range(0..10i64)
    } else {
        3850 + 100 * rng.gen_range(0..9i64)
    };
    // Units (rooms and the stair room) split evenly between the rows, the stair room first in
    // the north row; both rows are then fitted to their mean length (room widths scaled, the
    // stair room kept), so the building grows by about one room per room asked for.
    let units = rooms + has_stair as i64;
    let south_n = units - units / 2;
    let north_n = units / 2 - has_stair as i64;
    let widths = |n: i64, rng: &mut Pcg64Mcg| -> Vec<i64> {
        (0..n)
            .map(|_| 2850 + 100 * rng.gen_range(0..17i64))
            .collect()
    };
    let mut south_w = widths(south_n, rng);
    let mut north_w = widths(north_n, rng);
    let stair_w = if has_stair { STAIR_ROOM_W + WALL } else { 0 };
    let row_len = |w: &[i64], fixed: i64| {
        if w.is_empty() {
            (fixed - WALL).max(0)
        } else {
            w.iter().sum::<i64>() + WALL * (w.len() as i64 - 1) + fixed
        }
    };
    let south_len = row_len(&south_w, 0);
    let north_len = row_len(&north_w, stair_w);
    let mut inner = if north_len == 0 {
        south_len
    } else {
        (south_len + north_len) / 2
    };
    // No room narrower than 2.1 m, and the stair room at least as wide as it is designed.
    inner = inner
        .max(row_len(&vec![2100; south_w.len()], 0))
        .max(row_len(&vec![2100; north_w.len()], stair_w));
    let fit = |w: &mut Vec<i64>, fixed: i64| {
        if w.is_empty() {
            return;
        }
        let target = inner - fixed - WALL * (w.len() as i64 - 1);
        let sum: i64 = w.iter().sum();
        for x in w.iter_mut() {
            *x = *x * target / sum;
        }
        let rest = target - w.iter().sum::<i64>();
        if let Some(last) = w.last_mut() {
            *last += rest;
        }
    };
    fit(&mut south_w, 0);
    fit(&mut north_w, stair_w);
    if has_stair {
        // The stair room leads its row; alone, it takes the whole row.
        let w = if north_w.is_empty() {
            inner
        } else {
            STAIR_ROOM_W
        };
        north_w.insert(0, w);
    }
    let lx = inner + 2 * WALL;

    let south_z = (WALL, WALL + depth);
    let cz = (south_z.1 + WALL, south_z.1 + WALL + CORRIDOR);
    let north_z = (cz.1 + WALL, cz.1 + WALL + depth);
    let lz = if north_w.is_empty() {
        cz.1 + WALL
    } else {
        north_z.1 + WALL
    };
    let mut rows = Vec::new();
    for (ws, (z0, z1), south) in [(south_w, south_z, true), (north_w, north_z, false)] {
        if ws.is_empty() {
            continue;
        }
        let mut units = Vec::new();
        let mut x = WALL;
        for (k, &w) in ws.iter().enumerate() {
            let stair = has_stair && !south && k == 0;
            let door = if stair {
                let c = x + (LANES[0].1 + LANES[1].0) / 2;
                (c - DOOR_W / 2, c + DOOR_W / 2)
            } else {
                let d0 = x + 300 + rng.gen_range(0..=(w - 1200 - 300));
                (d0, d0 + DOOR_W)
            };
            units.push(Unit {
                x0: x,
                x1: x + w,
                stair,
                door,
                next_door: None,
            });
            x += w + WALL;
        }
        // Doorways between neighbouring rooms (never into the stair room).
        for k in 0..units.len().saturating_sub(1) {
            if !units[k].stair && !units[k + 1].stair && rng.gen_bool(0.35) {
                let d0 = z0 + 300 + rng.gen_range(0..=(depth - 1200 - 300));
                units[k].next_door = Some((d0, d0 + DOOR_W));
            }
        }
        rows.push(Row {
            z0,
            z1,
            south,
            units,
        });
    }
    let half = (lz - 2 * WALL) / 2;
    debug_assert_eq!(half % ROOF_RUN, 0);
    Plan {
        floors,
        lx,
        lz,
        rows,
        cz,
        half,
        rise: half / ROOF_RUN * ROOF_RISE,
    }
}

// ---- the generator -------------------------------------------------------------------------

struct Gen<'w> {
    out: Out<'w>,
    plan: Plan,
    seed: u64,
    /// Area the attic will add at the end (axial, skew), m²: known from the plan, counted in
    /// the skew balance from the start.
    attic: (f64, f64),
}

/// A seed for one room's random choices, independent of the order rooms are written in.
fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

fn build(
    obj: Option<&mut dyn Write>,
    mtl: Option<&mut dyn Write>,
    mtl_name: &str,
    opts: &BuildingOptions,
) -> io::Result<BuildingStats> {
    if opts.floors == 0 || opts.rooms_per_floor == 0 {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            "a building needs at least one floor and one room per floor",
        ));
    }
    if let Some(mtl) = mtl {
        write_mtl(mtl)?;
    }
    let mut rng = Pcg64Mcg::seed_from_u64(mix(opts.seed));
    let plan = plan(opts, &mut rng);
    let roof_len = ((plan.half as f64).powi(2) + (plan.rise as f64).powi(2)).sqrt();
    let inner_x = (plan.lx - 2 * WALL) as f64;
    let attic = (
        (inner_x * (plan.lz - 2 * WALL + 2 * KNEE) as f64
            + ((plan.half * plan.rise) as f64 + (4 * plan.half * KNEE) as f64) * 2.0)
            * 1e-6,
        2.0 * inner_x * roof_len * 1e-6,
    );
    let mut g = Gen {
        out: Out {
            obj: obj.map(|w| BufWriter::with_capacity(1 << 16, w)),
            line: Vec::with_capacity(256),
            mat: None,
            vertices: 0,
            polygons: 0,
            patches: 0,
            lights: 0,
            axial: 0.0,
            skew: 0.0,
            size: BUILDING_PATCH_SIZE,
        },
        plan,
        seed: opts.seed,
        attic,
    };
    g.header(opts, mtl_name)?;
    for k in 0..g.plan.floors {
        g.corridor(k)?;
        for r in 0..g.plan.rows.len() {
            for u in 0..g.plan.rows[r].units.len() {
                g.room(k, r, u)?;
            }
        }
    }
    g.attic()?;
    let out = &mut g.out;
    if let Some(w) = &mut out.obj {
        w.flush()?;
    }
    Ok(BuildingStats {
        polygons: out.polygons,
        estimated_patches: out.patches,
        lights: out.lights,
        axial_fraction: out.axial / (out.axial + out.skew).max(f64::MIN_POSITIVE),
    })
}

/// A piece of furniture: footprint w × d, height h.
#[derive(Clone, Copy)]
struct Piece {
    w: i64,
    d: i64,
    h: i64,
    mat: Mat,
}

const fn piece(w: i64, d: i64, h: i64, mat: Mat) -> Piece {
    Piece { w, d, h, mat }
}

/// Desk, table, chair, bookshelf, wardrobe, filing cabinet, sofa.
const PIECES: [Piece; 7] = [
    piece(1600, 800, 750, Mat::Wood),
    piece(1200, 800, 720, Mat::Wood),
    piece(520, 520, 900, Mat::Fabric),
    piece(1000, 420, 1900, Mat::Cabinet),
    piece(1100, 620, 2000, Mat::Cabinet),
    piece(520, 620, 1250, Mat::Cabinet),
    piece(1800, 850, 800, Mat::Fabric),
];

/// What stands on a floor: its footprint's bounding box and, for a turned block, the four
/// triangles that fill the box around the footprint.
struct Footprint {
    bbox: R2,
    fills: Vec<T2>,
}

impl Gen<'_> {
    fn header(&mut self, opts: &BuildingOptions, mtl_name: &str) -> io::Result<()> {
        let p = &self.plan;
        let text = format!(
            "# A building written by `radiosity generate building` (radiosity {}):\n\
             # {} floor(s), {} room(s) per floor, seed {}; {:.1} m x {:.1} m, storeys of {} m.\n\
             # Closed: rooms, corridor, stair room and attic are boxes of faces looking into\n\
             # their air, joined by doorways and slab holes; windows are dark panes.\n\
             # Units: metres. Faces are counter-clockwise seen from the air they face.\n\
             #\n\
             # radiosity: patch-size {}\n\n\
             mtllib {}\n",
            env!("CARGO_PKG_VERSION"),
            opts.floors,
            opts.rooms_per_floor,
            opts.seed,
            p.lx as f64 / 1000.0,
            p.lz as f64 / 1000.0,
            STOREY as f64 / 1000.0,
            BUILDING_PATCH_SIZE,
            mtl_name
        );
        self.out.raw(&text)
    }

    /// An axis plane at `c` facing `sign` along `axis`: the rectangle `r` minus `holes`, plus
    /// the triangles `fills`. The cut that gives fewer patches wins (strips along u or v).
    #[allow(clippy::too_many_arguments)]
    fn plane(
        &mut self,
        mat: Mat,
        axis: Axis,
        c: i64,
        sign: i64,
        r: R2,
        holes: &[R2],
        fills: &[T2],
    ) -> io::Result<()> {
        let toward = axis_dir(axis, sign);
        let along_u = cut(r, holes);
        let rects = if holes.is_empty() {
            along_u
        } else {
            let t: Vec<R2> = holes.iter().map(R2::transposed).collect();
            let along_v: Vec<R2> = cut(r.transposed(), &t).iter().map(R2::transposed).collect();
            let cost = |rs: &[R2]| -> (u64, usize) {
                let s = 1000.0 * self.out.size as f64;
                let n = rs
                    .iter()
                    .map(|q| {
                        (((q.u1 - q.u0) as f64 / s).ceil() * ((q.v1 - q.v0) as f64 / s).ceil())
                            as u64
                    })
                    .sum();
                (n, rs.len())
            };
            if cost(&along_v) < cost(&along_u) {
                along_v
            } else {
                along_u
            }
        };
        for q in rects {
            let pts = [
                to3(axis, c, q.u0, q.v0),
                to3(axis, c, q.u1, q.v0),
                to3(axis, c, q.u1, q.v1),
                to3(axis, c, q.u0, q.v1),
            ];
            self.out.poly(mat, &pts, toward)?;
        }
        for t in fills {
            let pts = t.map(|[u, v]| to3(axis, c, u, v));
            self.out.poly(mat, &pts, toward)?;
        }
        Ok(())
    }

    /// A block standing on y0: top and four sides (the floor under it is cut away).
    fn block(&mut self, mat: Mat, x: (i64, i64), y: (i64, i64), z: (i64, i64)) -> io::Result<()> {
        self.plane(mat, Axis::Y, y.1, 1, r2(x.0, x.1, z.0, z.1), &[], &[])?;
        self.plane(mat, Axis::X, x.0, -1, r2(z.0, z.1, y.0, y.1), &[], &[])?;
        self.plane(mat, Axis::X, x.1, 1, r2(z.0, z.1, y.0, y.1), &[], &[])?;
        self.plane(mat, Axis::Z, z.0, -1, r2(x.0, x.1, y.0, y.1), &[], &[])?;
        self.plane(mat, Axis::Z, z.1, 1, r2(x.0, x.1, y.0, y.1), &[], &[])
    }

    /// A block turned about y, standing on y0: four (skew) sides and the top.
    fn turned_block(&mut self, mat: Mat, foot: &[[i64; 2]; 4], y: (i64, i64)) -> io::Result<()> {
        let cx = foot.iter().map(|p| p[0] as f64).sum::<f64>() / 4.0;
        let cz = foot.iter().map(|p| p[1] as f64).sum::<f64>() / 4.0;
        for k in 0..4 {
            let (a, b) = (foot[k], foot[(k + 1) % 4]);
            let out = [
                (a[0] + b[0]) as f64 / 2.0 - cx,
                0.0,
                (a[1] + b[1]) as f64 / 2.0 - cz,
            ];
            let pts = [
                [a[0], y.0, a[1]],
                [b[0], y.0, b[1]],
                [b[0], y.1, b[1]],
                [a[0], y.1, a[1]],
            ];
            self.out.poly(mat, &pts, out)?;
        }
        let top = foot.map(|p| [p[0], y.1, p[1]]);
        self.out.poly(mat, &top, [0.0, 1.0, 0.0])
    }

    /// The four reveals of an opening through a wall normal to z, between planes `za` and
    /// `zb`: x range `x`, heights `y`.
    fn opening_z(&mut self, x: (i64, i64), y: (i64, i64), za: i64, zb: i64) -> io::Result<()> {
        let (z0, z1) = (za.min(zb), za.max(zb));
        self.plane(Mat::Wall, Axis::Y, y.0, 1, r2(x.0, x.1, z0, z1), &[], &[])?;
        self.plane(Mat::Wall, Axis::Y, y.1, -1, r2(x.0, x.1, z0, z1), &[], &[])?;
        self.plane(Mat::Wall, Axis::X, x.0, 1, r2(z0, z1, y.0, y.1), &[], &[])?;
        self.plane(Mat::Wall, Axis::X, x.1, -1, r2(z0, z1, y.0, y.1), &[], &[])
    }

    /// The same through a wall normal to x, between `xa` and `xb`: z range `z`.
    fn opening_x(&mut self, z: (i64, i64), y: (i64, i64), xa: i64, xb: i64) -> io::Result<()> {
        let (x0, x1) = (xa.min(xb), xa.max(xb));
        self.plane(Mat::Wall, Axis::Y, y.0, 1, r2(x0, x1, z.0, z.1), &[], &[])?;
        self.plane(Mat::Wall, Axis::Y, y.1, -1, r2(x0, x1, z.0, z.1), &[], &[])?;
        self.plane(Mat::Wall, Axis::Z, z.0, 1, r2(x0, x1, y.0, y.1), &[], &[])?;
        self.plane(Mat::Wall, Axis::Z, z.1, -1, r2(x0, x1, y.0, y.1), &[], &[])
    }

    /// A ceiling light panel flush in its hole, facing down.
    fn light(&mut self, y: i64, r: R2) -> io::Result<()> {
        self.plane(Mat::Light, Axis::Y, y, -1, r, &[], &[])
    }

    /// Windows of an outside wall normal to z: x ranges, evenly along [x0, x1].
    fn windows_along(x0: i64, x1: i64) -> Vec<(i64, i64)> {
        let n = ((x1 - x0) / 2200).max(1);
        (0..n)
            .map(|i| {
                let c = x0 + (2 * i + 1) * (x1 - x0) / (2 * n);
                (c - WIN_W / 2, c + WIN_W / 2)
            })
            .collect()
    }

    fn corridor(&mut self, k: i64) -> io::Result<()> {
        let p = &self.plan;
        let (x0, x1) = (WALL, p.lx - WALL);
        let (z0, z1) = p.cz;
        let y0 = k * STOREY;
        let y1 = y0 + CLEAR;
        let lx = p.lx;
        let mut south_doors = Vec::new();
        let mut north_doors = Vec::new();
        for row in &p.rows {
            let doors: Vec<R2> = row
                .units
                .iter()
                .map(|u| r2(u.door.0, u.door.1, y0, y0 + DOOR_H))
                .collect();
            if row.south {
                south_doors = doors;
            } else {
                north_doors = doors;
            }
        }
        let north_outside = p.rows.iter().all(|r| r.south);
        let lights: Vec<R2> = {
            let n = ((x1 - x0) / 4000).max(1);
            let zc = (z0 + z1) / 2;
            (0..n)
                .map(|i| {
                    let c = x0 + (2 * i + 1) * (x1 - x0) / (2 * n);
                    r2(c - 600, c + 600, zc - 300, zc + 300)
                })
                .collect()
        };
        let end_win = {
            let c = (z0 + z1) / 2;
            r2(c - WIN_W / 2, c + WIN_W / 2, y0 + SILL, y0 + HEAD)
        };
        self.out.object(&format!("floor{k}_corridor"))?;
        let span = r2(x0, x1, z0, z1);
        self.plane(Mat::CorridorFloor, Axis::Y, y0, 1, span, &[], &[])?;
        self.plane(Mat::Ceiling, Axis::Y, y1, -1, span, &lights, &[])?;
        for l in &lights {
            self.light(y1, *l)?;
        }
        self.plane(
            Mat::Wall,
            Axis::Z,
            z0,
            1,
            r2(x0, x1, y0, y1),
            &south_doors,
            &[],
        )?;
        if north_outside {
            let wins: Vec<R2> = Self::windows_along(x0, x1)
                .into_iter()
                .map(|(a, b)| r2(a, b, y0 + SILL, y0 + HEAD))
                .collect();
            self.plane(Mat::Wall, Axis::Z, z1, -1, r2(x0, x1, y0, y1), &wins, &[])?;
            for w in &wins {
                self.opening_z((w.u0, w.u1), (w.v0, w.v1), z1, z1 + WALL)?;
                self.plane(Mat::Glass, Axis::Z, z1 + WALL, -1, *w, &[], &[])?;
            }
        } else {
            self.plane(
                Mat::Wall,
                Axis::Z,
                z1,
                -1,
                r2(x0, x1, y0, y1),
                &north_doors,
                &[],
            )?;
        }
        // End walls with a window each.
        for (x, sign, outer) in [(x0, 1, 0), (x1, -1, lx)] {
            let wall = r2(z0, z1, y0, y1);
            self.plane(Mat::Wall, Axis::X, x, sign, wall, &[end_win], &[])?;
            self.opening_x((end_win.u0, end_win.u1), (end_win.v0, end_win.v1), x, outer)?;
            self.plane(Mat::Glass, Axis::X, outer, sign, end_win, &[], &[])?;
        }
        Ok(())
    }

    /// Is the running skew share (counting the attic to come) below the target?
    fn wants_skew(&self) -> bool {
        let skew = self.out.skew + self.attic.1;
        let total = self.out.axial + self.out.skew + self.attic.0 + self.attic.1;
        skew < SKEW_TARGET * total
    }

    fn room(&mut self, k: i64, r: usize, u: usize) -> io::Result<()> {
        let row_ref = &self.plan.rows[r];
        let unit = row_ref.units[u].clone();
        let prev_door = if u > 0 {
            row_ref.units[u - 1].next_door
        } else {
            None
        };
        // The row without its units (copying them for every room would cost O(rooms²)).
        let row = Row {
            z0: row_ref.z0,
            z1: row_ref.z1,
            south: row_ref.south,
            units: Vec::new(),
        };
        let (x0, x1, z0, z1) = (unit.x0, unit.x1, row.z0, row.z1);
        let y0 = k * STOREY;
        let y1 = y0 + CLEAR;
        let zc = row.corridor_z();
        let zo = row.outside_z();
        let into_corridor = row.to_corridor();
        let mut rng = Pcg64Mcg::seed_from_u64(mix(
            self.seed ^ mix((k as u64) << 32 | (r as u64) << 24 | u as u64)
        ));
        let name = if unit.stair {
            format!("floor{k}_stairs")
        } else {
            format!("floor{k}_{}{u}", if row.south { "south" } else { "north" })
        };
        self.out.object(&name)?;

        // Walls and their openings: doorway to the corridor, windows, doorways to neighbours.
        let door = r2(unit.door.0, unit.door.1, y0, y0 + DOOR_H);
        self.plane(
            Mat::Wall,
            Axis::Z,
            zc,
            -into_corridor,
            r2(x0, x1, y0, y1),
            &[door],
            &[],
        )?;
        self.opening_z(unit.door, (y0, y0 + DOOR_H), zc, zc + into_corridor * WALL)?;
        let wins: Vec<R2> = Self::windows_along(x0, x1)
            .into_iter()
            .map(|(a, b)| r2(a, b, y0 + SILL, y0 + HEAD))
            .collect();
        self.plane(
            Mat::Wall,
            Axis::Z,
            zo,
            into_corridor,
            r2(x0, x1, y0, y1),
            &wins,
            &[],
        )?;
        let outer = zo - into_corridor * WALL;
        for w in &wins {
            self.opening_z((w.u0, w.u1), (w.v0, w.v1), zo, outer)?;
            self.plane(Mat::Glass, Axis::Z, outer, into_corridor, *w, &[], &[])?;
        }
        let side_hole = |d: Option<(i64, i64)>| d.map(|(a, b)| r2(a, b, y0, y0 + DOOR_H));
        let west: Vec<R2> = side_hole(prev_door).into_iter().collect();
        let east: Vec<R2> = side_hole(unit.next_door).into_iter().collect();
        self.plane(Mat::Wall, Axis::X, x0, 1, r2(z0, z1, y0, y1), &west, &[])?;
        self.plane(Mat::Wall, Axis::X, x1, -1, r2(z0, z1, y0, y1), &east, &[])?;
        if let Some(d) = unit.next_door {
            self.opening_x(d, (y0, y0 + DOOR_H), x1, x1 + WALL)?;
        }

        if unit.stair {
            return self.stair_room(k, &row, &unit);
        }

        // Ceiling lights: one, or two in a deep or wide room.
        let (xm, zm) = ((x0 + x1) / 2, (z0 + z1) / 2);
        let two = (x1 - x0) * (z1 - z0) > 18_000_000;
        let lights: Vec<R2> = if two {
            let dz = (z1 - z0) / 6;
            vec![
                r2(xm - 600, xm + 600, zm - dz - 300, zm - dz + 300),
                r2(xm - 600, xm + 600, zm + dz - 300, zm + dz + 300),
            ]
        } else {
            vec![r2(xm - 600, xm + 600, zm - 300, zm + 300)]
        };
        self.plane(
            Mat::Ceiling,
            Axis::Y,
            y1,
            -1,
            r2(x0, x1, z0, z1),
            &lights,
            &[],
        )?;
        for l in &lights {
            self.light(y1, *l)?;
        }

        // Furniture: free-standing blocks, clear of the doorways; turned while the building
        // needs skew area.
        let mut keep_out = vec![r2(
            unit.door.0 - 200,
            unit.door.1 + 200,
            zc.min(zc - into_corridor * 1100),
            zc.max(zc - into_corridor * 1100),
        )];
        if let Some((a, b)) = prev_door {
            keep_out.push(r2(x0, x0 + 1100, a - 200, b + 200));
        }
        if let Some((a, b)) = unit.next_door {
            keep_out.push(r2(x1 - 1100, x1, a - 200, b + 200));
        }
        let placed = self.furnish(&mut rng, r2(x0, x1, z0, z1), &keep_out, y0)?;
        let (holes, fills) = floor_cuts(&placed);
        let room = r2(x0, x1, z0, z1);
        self.plane(Mat::Floor, Axis::Y, y0, 1, room, &holes, &fills)
    }

    /// Furniture on the floor at `y0` of `area`: free-standing blocks 15 cm off its edges,
    /// clear of `keep_out` and of each other, turned while the building needs skew area (then
    /// up to three more pieces, all turned). Returns what was placed, to cut the floor around.
    fn furnish(
        &mut self,
        rng: &mut Pcg64Mcg,
        area: R2,
        keep_out: &[R2],
        y0: i64,
    ) -> io::Result<Vec<Footprint>> {
        let inside = area.grown(-150);
        let area_m2 = ((area.u1 - area.u0) * (area.v1 - area.v0)) as f64 * 1e-6;
        let count = 3 + (area_m2 / 4.0) as usize;
        let mut placed: Vec<Footprint> = Vec::new();
        for n in 0..count + 3 {
            let turn = self.wants_skew();
            if n >= count && !turn {
                break;
            }
            let piece = PIECES[rng.gen_range(0..PIECES.len())];
            for _try in 0..12 {
                let cx = rng.gen_range(inside.u0..inside.u1);
                let cz = rng.gen_range(inside.v0..inside.v1);
                let deg = if turn {
                    rng.gen_range(15.0..75.0f64)
                } else if rng.gen_bool(0.5) {
                    0.0
                } else {
                    90.0
                };
                let foot = footprint(cx, cz, piece.w, piece.d, deg);
                let bb = bbox(&foot);
                let fits = bb.u0 >= inside.u0
                    && bb.u1 <= inside.u1
                    && bb.v0 >= inside.v0
                    && bb.v1 <= inside.v1
                    && !keep_out.iter().any(|o| o.overlaps(&bb))
                    && !placed.iter().any(|f| f.bbox.grown(100).overlaps(&bb));
                if !fits {
                    continue;
                }
                let y = (y0, y0 + piece.h);
                let fills = if turn {
                    self.turned_block(piece.mat, &foot, y)?;
                    corner_fills(&foot, &bb)
                } else {
                    self.block(piece.mat, (bb.u0, bb.u1), y, (bb.v0, bb.v1))?;
                    Vec::new()
                };
                placed.push(Footprint { bbox: bb, fills });
                break;
            }
        }
        Ok(placed)
    }

    /// The flight of floor `k`: lane, direction (+1: climbs towards +z), and the z where it
    /// starts and where it meets the slab above.
    fn flight(&self, k: i64, sz0: i64) -> (usize, i64, i64, i64) {
        let lane = (k % 2) as usize;
        let run = STEPS * TREAD;
        if lane == 0 {
            (lane, 1, sz0 + FLIGHT_OFFSET, sz0 + FLIGHT_OFFSET + run)
        } else {
            (lane, -1, sz0 + FLIGHT_OFFSET + run, sz0 + FLIGHT_OFFSET)
        }
    }

    /// The hole in the slab above floor `k`'s flight (x and z ranges, as a plan rectangle).
    fn slab_hole(&self, k: i64, sx0: i64, sz0: i64) -> R2 {
        let (lane, dir, _, top) = self.flight(k, sz0);
        let (hx0, hx1) = (
            sx0 + LANES[lane].0 - HOLE_MARGIN,
            sx0 + LANES[lane].1 + HOLE_MARGIN,
        );
        let len = (STEPS - FREE_STEPS) * TREAD;
        if dir > 0 {
            r2(hx0, hx1, top - len, top)
        } else {
            r2(hx0, hx1, top, top + len)
        }
    }

    /// Stair room contents: floor (around this flight and the hole of the one below),
    /// ceiling (around this flight's hole), the flight, the hole's reveals, a light.
    fn stair_room(&mut self, k: i64, row: &Row, unit: &Unit) -> io::Result<()> {
        let (sx0, sx1, sz0, sz1) = (unit.x0, unit.x1, row.z0, row.z1);
        debug_assert!(!row.south);
        let y0 = k * STOREY;
        let y1 = y0 + CLEAR;
        let (lane, dir, start, top) = self.flight(k, sz0);
        let (fx0, fx1) = (sx0 + LANES[lane].0, sx0 + LANES[lane].1);
        let hole = self.slab_hole(k, sx0, sz0);
        // Light over the other lane, mid-room.
        let other = LANES[1 - lane];
        let lc = sx0 + (other.0 + other.1) / 2;
        let zm = (sz0 + sz1) / 2;
        let light = r2(lc - 300, lc + 300, zm - 600, zm + 600);
        let room = r2(sx0, sx1, sz0, sz1);
        self.plane(Mat::Ceiling, Axis::Y, y1, -1, room, &[hole, light], &[])?;
        self.light(y1, light)?;
        let foot = r2(fx0, fx1, start.min(top), start.max(top));
        let mut holes = vec![foot];
        if k > 0 {
            holes.push(self.slab_hole(k - 1, sx0, sz0));
        }
        // A stair room wider than its stairs (alone in its row) is furnished beyond them.
        let mut fills = Vec::new();
        let spare = r2(sx0 + STAIR_ROOM_W, sx1, sz0, sz1);
        if spare.u1 - spare.u0 >= 1500 {
            let mut rng = Pcg64Mcg::seed_from_u64(mix(self.seed ^ mix(k as u64 + 0x5EED)));
            let door_zone = r2(unit.door.0 - 200, unit.door.1 + 200, sz0, sz0 + 1100);
            let placed = self.furnish(&mut rng, spare, &[door_zone], y0)?;
            let (h, f) = floor_cuts(&placed);
            holes.extend(h);
            fills = f;
        }
        self.plane(Mat::Floor, Axis::Y, y0, 1, room, &holes, &fills)?;

        // The flight: treads, risers, stepped sides, and its top end below the slab.
        let m = Mat::Stair;
        for i in 0..STEPS {
            let (za, zb) = (start + dir * i * TREAD, start + dir * (i + 1) * TREAD);
            let (z_lo, z_hi) = (za.min(zb), za.max(zb));
            let yt = y0 + (i + 1) * RISER;
            self.plane(m, Axis::Y, yt, 1, r2(fx0, fx1, z_lo, z_hi), &[], &[])?;
            self.plane(m, Axis::Z, za, -dir, r2(fx0, fx1, yt - RISER, yt), &[], &[])?;
            self.plane(m, Axis::X, fx0, -1, r2(z_lo, z_hi, y0, yt), &[], &[])?;
            self.plane(m, Axis::X, fx1, 1, r2(z_lo, z_hi, y0, yt), &[], &[])?;
        }
        self.plane(m, Axis::Z, top, dir, r2(fx0, fx1, y0, y1), &[], &[])?;
        // The hole's reveals (the slab's edges). At the flight's top the top step and the
        // slab are one solid up to the top tread; above it the last riser is the slab's edge.
        let (ya, yb) = (y1, y0 + STOREY);
        let far = if dir > 0 { hole.v0 } else { hole.v1 };
        self.plane(
            m,
            Axis::X,
            hole.u0,
            1,
            r2(hole.v0, hole.v1, ya, yb),
            &[],
            &[],
        )?;
        self.plane(
            m,
            Axis::X,
            hole.u1,
            -1,
            r2(hole.v0, hole.v1, ya, yb),
            &[],
            &[],
        )?;
        self.plane(m, Axis::Z, far, dir, r2(hole.u0, hole.u1, ya, yb), &[], &[])?;
        let fused = r2(fx0, fx1, ya, yb - RISER);
        self.plane(
            m,
            Axis::Z,
            top,
            -dir,
            r2(hole.u0, hole.u1, ya, yb),
            &[fused],
            &[],
        )
    }

    fn attic(&mut self) -> io::Result<()> {
        let p = &self.plan;
        let (x0, x1) = (WALL, p.lx - WALL);
        let (z0, z1) = (WALL, p.lz - WALL);
        let (half, rise) = (p.half, p.rise);
        let zr = z0 + half;
        let y0 = p.floors * STOREY;
        let ye = y0 + KNEE;
        let yr = ye + rise;
        let holes: Vec<R2> = p
            .rows
            .iter()
            .find_map(|r| r.units.iter().find(|u| u.stair).map(|u| (u.x0, r.z0)))
            .map(|(sx0, sz0)| self.slab_hole(p.floors - 1, sx0, sz0))
            .into_iter()
            .collect();
        self.out.object("attic")?;
        self.plane(
            Mat::AtticFloor,
            Axis::Y,
            y0,
            1,
            r2(x0, x1, z0, z1),
            &holes,
            &[],
        )?;
        // Knee walls along the eaves, then the roof: two skew planes up to the ridge, facing
        // down into the attic.
        self.plane(Mat::Wall, Axis::Z, z0, 1, r2(x0, x1, y0, ye), &[], &[])?;
        self.plane(Mat::Wall, Axis::Z, z1, -1, r2(x0, x1, y0, ye), &[], &[])?;
        let (h, r) = (half as f64, rise as f64);
        let south = [[x0, ye, z0], [x1, ye, z0], [x1, yr, zr], [x0, yr, zr]];
        self.out.poly(Mat::Roof, &south, [0.0, -h, r])?;
        let north = [[x0, ye, z1], [x1, ye, z1], [x1, yr, zr], [x0, yr, zr]];
        self.out.poly(Mat::Roof, &north, [0.0, -h, -r])?;
        // Gables: one quad per half (knee wall, ridge, roof line, floor), so the two halves
        // share their whole ridge edge and no coplanar T-junction can open a crack.
        for (x, sign) in [(x0, 1), (x1, -1)] {
            let toward = [sign as f64, 0.0, 0.0];
            for ze in [z0, z1] {
                let pts = [[x, y0, ze], [x, y0, zr], [x, yr, zr], [x, ye, ze]];
                self.out.poly(Mat::Wall, &pts, toward)?;
            }
        }
        // Lanterns under the ridge, every 8 m: boxes whose bottoms emit.
        let count = ((x1 - x0) / 8000).max(1);
        for i in 0..count {
            let c = x0 + (2 * i + 1) * (x1 - x0) / (2 * count);
            let (lx, lz, ly) = (
                (c - 250, c + 250),
                (zr - 250, zr + 250),
                (yr - 900, yr - 600),
            );
            self.block(Mat::Cabinet, lx, ly, lz)?;
            self.plane(
                Mat::Light,
                Axis::Y,
                ly.0,
                -1,
                r2(lx.0, lx.1, lz.0, lz.1),
                &[],
                &[],
            )?;
        }
        Ok(())
    }
}

/// Holes and fills that cut a floor around the furniture standing on it.
fn floor_cuts(placed: &[Footprint]) -> (Vec<R2>, Vec<T2>) {
    let holes = placed.iter().map(|f| f.bbox).collect();
    let fills = placed
        .iter()
        .flat_map(|f| f.fills.iter().copied())
        .collect();
    (holes, fills)
}

/// Corners of a w × d rectangle centred at (cx, cz) turned by `deg` about y, in whole mm.
fn footprint(cx: i64, cz: i64, w: i64, d: i64, deg: f64) -> [[i64; 2]; 4] {
    let (s, c) = deg.to_radians().sin_cos();
    let (hw, hd) = (w as f64 / 2.0, d as f64 / 2.0);
    [(-hw, -hd), (hw, -hd), (hw, hd), (-hw, hd)].map(|(u, v)| {
        [
            cx + (u * c - v * s).round() as i64,
            cz + (u * s + v * c).round() as i64,
        ]
    })
}

fn bbox(foot: &[[i64; 2]; 4]) -> R2 {
    let xs = foot.map(|p| p[0]);
    let zs = foot.map(|p| p[1]);
    r2(
        *xs.iter().min().unwrap_or(&0),
        *xs.iter().max().unwrap_or(&0),
        *zs.iter().min().unwrap_or(&0),
        *zs.iter().max().unwrap_or(&0),
    )
}

/// The bounding box of a turned footprint minus the footprint: one triangle per edge, between
/// the edge and the box corner outside it.
fn corner_fills(foot: &[[i64; 2]; 4], bb: &R2) -> Vec<T2> {
    let centre = [
        foot.iter().map(|p| p[0] as f64).sum::<f64>() / 4.0,
        foot.iter().map(|p| p[1] as f64).sum::<f64>() / 4.0,
    ];
    let side = |a: [i64; 2], b: [i64; 2], p: [f64; 2]| {
        (b[0] - a[0]) as f64 * (p[1] - a[1] as f64) - (b[1] - a[1]) as f64 * (p[0] - a[0] as f64)
    };
    let mut out = Vec::with_capacity(4);
    for k in 0..4 {
        let (a, b) = (foot[k], foot[(k + 1) % 4]);
        let inner = side(a, b, centre);
        for corner in [[a[0], b[1]], [b[0], a[1]]] {
            let on_box = (corner[0] == bb.u0 || corner[0] == bb.u1)
                && (corner[1] == bb.v0 || corner[1] == bb.v1);
            let s = side(a, b, [corner[0] as f64, corner[1] as f64]);
            if on_box && s * inner < 0.0 {
                out.push([a, b, corner]);
                break;
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area(r: &R2) -> i64 {
        (r.u1 - r.u0) * (r.v1 - r.v0)
    }

    #[test]
    fn cut_keeps_the_area_outside_the_holes() {
        let r = r2(0, 1000, 0, 800);
        let holes = [
            r2(100, 300, 0, 200),
            r2(250, 400, 100, 500),
            r2(900, 1200, 700, 900),
        ];
        let pieces = cut(r, &holes);
        // Holes overlap each other: area of their union inside r, by counting on a grid.
        let mut covered = 0;
        for u in (0..1000).step_by(10) {
            for v in (0..800).step_by(10) {
                if holes
                    .iter()
                    .any(|h| u >= h.u0 && u < h.u1 && v >= h.v0 && v < h.v1)
                {
                    covered += 100;
                }
            }
        }
        assert_eq!(pieces.iter().map(area).sum::<i64>(), area(&r) - covered);
        for (i, a) in pieces.iter().enumerate() {
            assert!(holes.iter().all(|h| !h.overlaps(a)));
            assert!(pieces[i + 1..].iter().all(|b| !b.overlaps(a)));
        }
    }

    #[test]
    fn millimetres_print_as_short_metres() {
        let s = |v| {
            let mut b = Vec::new();
            push_mm(&mut b, v);
            String::from_utf8(b).unwrap()
        };
        assert_eq!(s(0), "0");
        assert_eq!(s(3000), "3");
        assert_eq!(s(12345), "12.345");
        assert_eq!(s(-200), "-0.2");
        assert_eq!(s(1050), "1.05");
        assert_eq!(s(-7), "-0.007");
    }

    #[test]
    fn turned_footprint_and_fills_tile_its_bounding_box() {
        for deg in [15.0, 33.0, 60.0, 75.0] {
            let foot = footprint(5000, -3000, 1600, 800, deg);
            let bb = bbox(&foot);
            let fills = corner_fills(&foot, &bb);
            assert_eq!(fills.len(), 4, "{deg}");
            let tri = |t: &T2| {
                let (a, b, c) = (t[0], t[1], t[2]);
                ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])).abs()
            };
            let quad = tri(&[foot[0], foot[1], foot[2]]) + tri(&[foot[0], foot[2], foot[3]]);
            let sum: i64 = fills.iter().map(tri).sum::<i64>() + quad;
            assert_eq!(sum, 2 * area(&bb), "{deg}");
        }
    }

    #[test]
    fn counting_and_writing_agree() {
        let opts = BuildingOptions {
            floors: 2,
            rooms_per_floor: 3,
            seed: 9,
        };
        let (mut obj, mut mtl) = (Vec::new(), Vec::new());
        let written = write_building(&mut obj, &mut mtl, "b.mtl", &opts).unwrap();
        let counted = build(None, None, "", &opts).unwrap();
        assert_eq!(written, counted);
        let text = String::from_utf8(obj).unwrap();
        assert_eq!(
            text.lines().filter(|l| l.starts_with("f ")).count() as u64,
            written.polygons
        );
        assert!(text.contains("# radiosity: patch-size 0.5\n"));
    }
}
