//! Corridors and rooms: shells with their doorways and windows, lights, and furniture placed
//! by the seed (some turned, to keep the skew share on target).

use super::*;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// A piece of furniture: footprint w × d, height h.
#[derive(Clone, Copy)]
pub(super) struct Piece {
    pub(super) w: i64,
    pub(super) d: i64,
    pub(super) h: i64,
    pub(super) mat: Mat,
}

pub(super) const fn piece(w: i64, d: i64, h: i64, mat: Mat) -> Piece {
    Piece { w, d, h, mat }
}

/// Desk, table, chair, bookshelf, wardrobe, filing cabinet, sofa.
pub(super) const PIECES: [Piece; 7] = [
    piece(1600, 800, 750, Mat::Wood),
    piece(1200, 800, 720, Mat::Wood),
    piece(520, 520, 900, Mat::Fabric),
    piece(1000, 420, 1900, Mat::Cabinet),
    piece(1100, 620, 2000, Mat::Cabinet),
    piece(520, 620, 1250, Mat::Cabinet),
    piece(1800, 850, 800, Mat::Fabric),
];

impl Gen<'_> {
    pub(super) fn corridor(&mut self, k: i64) -> io::Result<()> {
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
    pub(super) fn wants_skew(&self) -> bool {
        let skew = self.out.skew + self.attic.1;
        let total = self.out.axial + self.out.skew + self.attic.0 + self.attic.1;
        skew < SKEW_TARGET * total
    }

    pub(super) fn room(&mut self, k: i64, r: usize, u: usize) -> io::Result<()> {
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
    pub(super) fn furnish(
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
}
