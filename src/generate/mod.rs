//! `radiosity generate building`: a multi-storey building as OBJ + MTL, written as it is made.
//!
//! The sweep and the scale tests need architecture of any size, from a thousand patches to
//! millions, that is *closed* (a shooter's rays never leave it), lit in every room, and about
//! 85 % axis-aligned by area like the real models the paper's plane-merge intersector is meant
//! for (Sec. 2; docs/design.md §4: real models are 56–85 % axial, the paper says 90 %).
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
//! into ⌈u/s⌉·⌈v/s⌉ cells, a triangle into k² with k = ⌈longest edge/s⌉, lengths in `f32`);
//! the mesher's finer cuts near lights are measured on two storeys ([`near_light_factor`]).

mod faces;
mod geom;
mod materials;
mod out;
mod plan;
mod rooms;
mod stairs;

use crate::random::mix;
use geom::*;
use materials::*;
use out::*;
use plan::*;
use rand::SeedableRng;
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
    /// Room widths in per cent of the widths drawn from the seed (100: as drawn; no room
    /// narrower than 2.1 m). [`BuildingOptions::for_patches`] stretches or shrinks small
    /// buildings with it, where a whole room more or less is too coarse a step.
    pub width_percent: u32,
}

/// What was written.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BuildingStats {
    pub polygons: u64,
    /// Patches at [`BUILDING_PATCH_SIZE`] as the mesher cuts them: [`Self::uniform_patches`]
    /// times the share the cuts near lights add, measured on two storeys
    /// ([`near_light_factor`]).
    pub estimated_patches: u64,
    /// Patches at [`BUILDING_PATCH_SIZE`] before the mesher cuts any finer near a light,
    /// counted exactly as it cuts them.
    pub uniform_patches: u64,
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
            width_percent: 100,
        }
    }
}

impl BuildingOptions {
    /// A building of about `target` patches at [`BUILDING_PATCH_SIZE`]: floors grow as the
    /// square root of the target, rooms per floor are then found by counting (secant steps on
    /// dry runs, which write nothing). A room is about 1,000 patches, so below a few thousand
    /// whole rooms are too coarse a step (one room: ~1,100, two: ~2,200): when the nearest
    /// count misses by more than [`FIT_TOLERANCE`], the room widths are stretched or shrunk
    /// ([`BuildingOptions::width_percent`], bisection on dry runs) for that number of rooms
    /// and the one below. The count is the uniform cut's; the share the mesher adds near
    /// lights is then measured on two storeys ([`near_light_factor`]) and the building fitted
    /// again to the target over it. Every target from 1,000 to 2,000,000 lands within a few
    /// per cent.
    pub fn for_patches(target: usize, seed: u64) -> BuildingOptions {
        let first = Self::fit_uniform(target as f64, seed);
        let factor = near_light_factor(&first);
        if (factor - 1.0).abs() <= FIT_TOLERANCE {
            return first;
        }
        Self::fit_uniform(target as f64 / factor, seed)
    }

    /// The building whose uniform patch count is nearest `target` (see [`Self::for_patches`]).
    fn fit_uniform(target: f64, seed: u64) -> BuildingOptions {
        let floors = ((target / 2500.0).sqrt().round() as u32).clamp(1, 40);
        let opts = |rooms: u32, width_percent: u32| BuildingOptions {
            floors,
            rooms_per_floor: rooms.max(1),
            seed,
            width_percent,
        };
        let count = |o: &BuildingOptions| -> f64 {
            build(None, None, "", o).map_or(f64::INFINITY, |s| s.uniform_patches as f64)
        };
        let rooms = nearest_rooms(target, |r| count(&opts(r, 100)));
        let mut best = (opts(rooms, 100), (count(&opts(rooms, 100)) - target).abs());
        if best.1 <= FIT_TOLERANCE * target {
            return best.0;
        }
        // Patches grow with the room widths (floors, ceilings, walls and corridor all get
        // longer): bisect on the width for this many rooms, and for one room fewer.
        for r in [rooms, rooms.saturating_sub(1)] {
            if r == 0 {
                continue;
            }
            let (mut lo, mut hi) = (MIN_WIDTH_PERCENT, MAX_WIDTH_PERCENT);
            while hi - lo > 1 {
                let mid = (lo + hi) / 2;
                let o = opts(r, mid);
                let c = count(&o);
                if (c - target).abs() < best.1 {
                    best = (o, (c - target).abs());
                }
                if c < target {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            if best.1 <= FIT_TOLERANCE * target {
                break;
            }
        }
        best.0
    }
}

/// How close to its target [`BuildingOptions::for_patches`] is content to land by rooms
/// alone before it adjusts the room widths.
pub const FIT_TOLERANCE: f64 = 0.03;
/// The room widths [`BuildingOptions::for_patches`] may choose, per cent of the drawn ones:
/// from narrow rooms to long halls, a range over which one room's count spans more than the
/// step from one room to two.
const MIN_WIDTH_PERCENT: u32 = 50;
const MAX_WIDTH_PERCENT: u32 = 300;

/// The number of rooms per floor whose count (by `count`) is nearest `target`: secant steps,
/// since patches grow about linearly with rooms.
fn nearest_rooms(target: f64, count: impl Fn(u32) -> f64) -> u32 {
    let (mut r0, mut c0) = (1u32, count(1));
    let mut best = (r0, (c0 - target).abs());
    if c0 >= target {
        return 1;
    }
    let mut r1 = ((target / c0).round() as u32).max(2);
    for _ in 0..6 {
        let c1 = count(r1);
        if (c1 - target).abs() < best.1 {
            best = (r1, (c1 - target).abs());
        }
        if (c1 - target).abs() <= FIT_TOLERANCE * target || c1 == c0 {
            break;
        }
        let slope = (c1 - c0) / (r1 as f64 - r0 as f64);
        let next = (r1 as f64 + (target - c1) / slope).round().max(1.0) as u32;
        if next == r1 {
            break;
        }
        (r0, c0, r1) = (r1, c1, next);
    }
    best.0
}

/// Streams the OBJ into `obj` (with a `mtllib MTL_NAME` line and the patch-size comment) and
/// the MTL into `mtl`.
pub fn write_building(
    obj: &mut dyn Write,
    mtl: &mut dyn Write,
    mtl_name: &str,
    opts: &BuildingOptions,
) -> io::Result<BuildingStats> {
    let mut stats = build(Some(obj), Some(mtl), mtl_name, opts)?;
    stats.estimated_patches =
        (stats.uniform_patches as f64 * near_light_factor(opts)).round() as u64;
    Ok(stats)
}

/// How many times the uniform cut's patches the mesher makes of this building, with its cuts
/// near lights (`mesh::near_lights`): measured by meshing at most two storeys of it (the same
/// rooms, widths and seed; two, so the stair room is in) in memory. Every storey above the first
/// has the same plan and lights, so the share is the building's to about a per cent; 1 when the
/// storeys cannot be made.
pub fn near_light_factor(opts: &BuildingOptions) -> f64 {
    let storey = BuildingOptions {
        floors: opts.floors.min(2),
        ..opts.clone()
    };
    let (mut obj, mut mtl) = (Vec::new(), Vec::new());
    let Ok(stats) = build(Some(&mut obj), Some(&mut mtl), "building.mtl", &storey) else {
        return 1.0;
    };
    let (Ok(obj), Ok(mtl)) = (String::from_utf8(obj), String::from_utf8(mtl)) else {
        return 1.0;
    };
    let load = crate::scene::LoadOptions::default();
    let Ok(scene) = crate::scene::load_obj_from_strs("building.obj", &obj, &mtl, &load) else {
        return 1.0;
    };
    let mesh = crate::mesh::build(
        &scene,
        &crate::mesh::MeshOptions {
            patch_size: Some(BUILDING_PATCH_SIZE),
            ..Default::default()
        },
    );
    mesh.patches.len() as f64 / stats.uniform_patches.max(1) as f64
}

/// Writes the building to the file `out` and its MTL beside it (same stem, `.mtl`), each
/// atomically; refuses a building of no floor or no room.
pub fn write_building_files(
    out: &std::path::Path,
    opts: &BuildingOptions,
) -> Result<BuildingStats, crate::Error> {
    use crate::export::write_atomic;
    if opts.floors == 0 || opts.rooms_per_floor == 0 {
        return Err(crate::Error::Invalid(
            "--floors and --rooms must be at least 1".into(),
        ));
    }
    let mtl_path = out.with_extension("mtl");
    let mtl_name = mtl_path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "building.mtl".into());
    let mut mtl_text = Vec::new();
    let mut stats = None;
    write_atomic(out, |w| {
        stats = Some(write_building(w, &mut mtl_text, &mtl_name, opts)?);
        Ok(())
    })?;
    write_atomic(&mtl_path, |w| w.write_all(&mtl_text))?;
    stats.ok_or_else(|| crate::Error::Invalid("the generator wrote nothing".into()))
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

// ---- the generator -------------------------------------------------------------------------

struct Gen<'w> {
    out: Out<'w>,
    plan: Plan,
    seed: u64,
    /// Area the attic will add at the end (axial, skew), m²: known from the plan, counted in
    /// the skew balance from the start.
    attic: (f64, f64),
}

fn build(
    obj: Option<&mut dyn Write>,
    mtl: Option<&mut dyn Write>,
    mtl_name: &str,
    opts: &BuildingOptions,
) -> io::Result<BuildingStats> {
    if opts.floors == 0 || opts.rooms_per_floor == 0 || opts.width_percent == 0 {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            "a building needs at least one floor, one room per floor and a room width above 0 %",
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
        uniform_patches: out.patches,
        lights: out.lights,
        axial_fraction: out.axial / (out.axial + out.skew).max(f64::MIN_POSITIVE),
    })
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
            ..BuildingOptions::default()
        };
        let (mut obj, mut mtl) = (Vec::new(), Vec::new());
        let written = write_building(&mut obj, &mut mtl, "b.mtl", &opts).unwrap();
        let counted = build(None, None, "", &opts).unwrap();
        // A dry run counts the uniform cut; the file's stats add the cuts near lights.
        assert_eq!(
            BuildingStats {
                estimated_patches: written.uniform_patches,
                ..written.clone()
            },
            counted
        );
        assert!(written.estimated_patches > written.uniform_patches);
        let text = String::from_utf8(obj).unwrap();
        assert_eq!(
            text.lines().filter(|l| l.starts_with("f ")).count() as u64,
            written.polygons
        );
        assert!(text.contains("# radiosity: patch-size 0.5\n"));
    }
}
