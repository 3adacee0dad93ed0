//! The floor plan every storey shares: two rows of rooms (and the stair room) along a
//! corridor, room widths and doorways drawn from the seed.

use super::*;
use rand::Rng;
use rand_pcg::Pcg64Mcg;

/// A room (or the stair room) in a row: x extent and its doorways.
#[derive(Clone, Debug)]
pub(super) struct Unit {
    pub(super) x0: i64,
    pub(super) x1: i64,
    pub(super) stair: bool,
    /// Doorway to the corridor: x range.
    pub(super) door: (i64, i64),
    /// Doorway to the next unit of the row (through the wall at x1): z range.
    pub(super) next_door: Option<(i64, i64)>,
}

#[derive(Clone, Debug)]
pub(super) struct Row {
    /// Interior z range.
    pub(super) z0: i64,
    pub(super) z1: i64,
    /// South row: the corridor is at z1 and the outside at z0; north row: the other way.
    pub(super) south: bool,
    pub(super) units: Vec<Unit>,
}

impl Row {
    pub(super) fn corridor_z(&self) -> i64 {
        if self.south {
            self.z1
        } else {
            self.z0
        }
    }
    pub(super) fn outside_z(&self) -> i64 {
        if self.south {
            self.z0
        } else {
            self.z1
        }
    }
    /// Direction from the row into the corridor (+1: +z).
    pub(super) fn to_corridor(&self) -> i64 {
        if self.south {
            1
        } else {
            -1
        }
    }
}

pub(super) struct Plan {
    pub(super) floors: i64,
    /// Outer extent: x in [0, lx], z in [0, lz].
    pub(super) lx: i64,
    pub(super) lz: i64,
    pub(super) rows: Vec<Row>,
    /// Corridor interior z range (x runs from WALL to lx − WALL).
    pub(super) cz: (i64, i64),
    /// Attic: half width (eave to ridge, horizontally) and rise.
    pub(super) half: i64,
    pub(super) rise: i64,
}

/// Draws the storey's layout: the room depth, the room widths of both rows, then each row's
/// doorways (the random draws in that order).
pub(super) fn plan(opts: &BuildingOptions, rng: &mut Pcg64Mcg) -> Plan {
    let floors = opts.floors as i64;
    let has_stair = floors >= 2;
    // Room depth: a multiple of 10 mm so the attic's half width is a multiple of 5 mm; deep
    // enough for a flight and its landings when there are stairs.
    let depth = if has_stair {
        5150 + 100 * rng.gen_range(0..10i64)
    } else {
        3850 + 100 * rng.gen_range(0..9i64)
    };
    let (south_w, north_w, inner) = row_widths(opts, has_stair, rng);
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
    for (ws, z, south) in [(south_w, south_z, true), (north_w, north_z, false)] {
        if ws.is_empty() {
            continue;
        }
        rows.push(row(&ws, z, south, has_stair, depth, rng));
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

/// The unit widths of the south and north rows (the stair room first in the north row) and
/// the rows' common interior length.
fn row_widths(
    opts: &BuildingOptions,
    has_stair: bool,
    rng: &mut Pcg64Mcg,
) -> (Vec<i64>, Vec<i64>, i64) {
    let rooms = opts.rooms_per_floor as i64;
    // Units (rooms and the stair room) split evenly between the rows, the stair room first in
    // the north row; both rows are then fitted to their mean length (room widths scaled, the
    // stair room kept), so the building grows by about one room per room asked for.
    let units = rooms + has_stair as i64;
    let south_n = units - units / 2;
    let north_n = units / 2 - has_stair as i64;
    let widths = |n: i64, rng: &mut Pcg64Mcg| -> Vec<i64> {
        (0..n)
            .map(|_| (2850 + 100 * rng.gen_range(0..17i64)) * opts.width_percent as i64 / 100)
            .collect()
    };
    let mut south_w = widths(south_n, rng);
    let mut north_w = widths(north_n, rng);
    let stair_w = if has_stair { STAIR_ROOM_W + WALL } else { 0 };
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
    fit(&mut south_w, 0, inner);
    fit(&mut north_w, stair_w, inner);
    if has_stair {
        // The stair room leads its row; alone, it takes the whole row.
        let w = if north_w.is_empty() {
            inner
        } else {
            STAIR_ROOM_W
        };
        north_w.insert(0, w);
    }
    (south_w, north_w, inner)
}

/// Interior length of a row of rooms of widths `w` with walls between them, plus `fixed`.
fn row_len(w: &[i64], fixed: i64) -> i64 {
    if w.is_empty() {
        (fixed - WALL).max(0)
    } else {
        w.iter().sum::<i64>() + WALL * (w.len() as i64 - 1) + fixed
    }
}

/// Scales the widths `w` so that the row (plus `fixed`) is `inner` long, the last room taking
/// the rounding.
fn fit(w: &mut [i64], fixed: i64, inner: i64) {
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
}

/// One row of units of widths `ws` from x = WALL: the stair room's doorway between the lanes,
/// each room's at random; then doorways between neighbouring rooms, at random.
fn row(
    ws: &[i64],
    (z0, z1): (i64, i64),
    south: bool,
    has_stair: bool,
    depth: i64,
    rng: &mut Pcg64Mcg,
) -> Row {
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
    Row {
        z0,
        z1,
        south,
        units,
    }
}
