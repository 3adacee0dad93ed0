//! The stair room (a flight per floor through a hole in the slab above) and the attic under
//! the pitched roof.

use super::*;

impl Gen<'_> {
    /// The flight of floor `k`: lane, direction (+1: climbs towards +z), and the z where it
    /// starts and where it meets the slab above.
    pub(super) fn flight(&self, k: i64, sz0: i64) -> (usize, i64, i64, i64) {
        let lane = (k % 2) as usize;
        let run = STEPS * TREAD;
        if lane == 0 {
            (lane, 1, sz0 + FLIGHT_OFFSET, sz0 + FLIGHT_OFFSET + run)
        } else {
            (lane, -1, sz0 + FLIGHT_OFFSET + run, sz0 + FLIGHT_OFFSET)
        }
    }

    /// The hole in the slab above floor `k`'s flight (x and z ranges, as a plan rectangle).
    pub(super) fn slab_hole(&self, k: i64, sx0: i64, sz0: i64) -> R2 {
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
    pub(super) fn stair_room(&mut self, k: i64, row: &Row, unit: &Unit) -> io::Result<()> {
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

    pub(super) fn attic(&mut self) -> io::Result<()> {
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
