//! The generator's building blocks: the header, axis planes with holes, blocks, doorway and
//! window reveals, light panels.

use super::*;

impl Gen<'_> {
    pub(super) fn header(&mut self, opts: &BuildingOptions, mtl_name: &str) -> io::Result<()> {
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
    // Seven: the plane (axis, offset, facing) and its outline (rectangle, holes, fills) are
    // what every caller names; the generator's call sites read as the building's plan.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn plane(
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
    pub(super) fn block(
        &mut self,
        mat: Mat,
        x: (i64, i64),
        y: (i64, i64),
        z: (i64, i64),
    ) -> io::Result<()> {
        self.plane(mat, Axis::Y, y.1, 1, r2(x.0, x.1, z.0, z.1), &[], &[])?;
        self.plane(mat, Axis::X, x.0, -1, r2(z.0, z.1, y.0, y.1), &[], &[])?;
        self.plane(mat, Axis::X, x.1, 1, r2(z.0, z.1, y.0, y.1), &[], &[])?;
        self.plane(mat, Axis::Z, z.0, -1, r2(x.0, x.1, y.0, y.1), &[], &[])?;
        self.plane(mat, Axis::Z, z.1, 1, r2(x.0, x.1, y.0, y.1), &[], &[])
    }

    /// A block turned about y, standing on y0: four (skew) sides and the top.
    pub(super) fn turned_block(
        &mut self,
        mat: Mat,
        foot: &[[i64; 2]; 4],
        y: (i64, i64),
    ) -> io::Result<()> {
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
    pub(super) fn opening_z(
        &mut self,
        x: (i64, i64),
        y: (i64, i64),
        za: i64,
        zb: i64,
    ) -> io::Result<()> {
        let (z0, z1) = (za.min(zb), za.max(zb));
        self.plane(Mat::Wall, Axis::Y, y.0, 1, r2(x.0, x.1, z0, z1), &[], &[])?;
        self.plane(Mat::Wall, Axis::Y, y.1, -1, r2(x.0, x.1, z0, z1), &[], &[])?;
        self.plane(Mat::Wall, Axis::X, x.0, 1, r2(z0, z1, y.0, y.1), &[], &[])?;
        self.plane(Mat::Wall, Axis::X, x.1, -1, r2(z0, z1, y.0, y.1), &[], &[])
    }

    /// The same through a wall normal to x, between `xa` and `xb`: z range `z`.
    pub(super) fn opening_x(
        &mut self,
        z: (i64, i64),
        y: (i64, i64),
        xa: i64,
        xb: i64,
    ) -> io::Result<()> {
        let (x0, x1) = (xa.min(xb), xa.max(xb));
        self.plane(Mat::Wall, Axis::Y, y.0, 1, r2(x0, x1, z.0, z.1), &[], &[])?;
        self.plane(Mat::Wall, Axis::Y, y.1, -1, r2(x0, x1, z.0, z.1), &[], &[])?;
        self.plane(Mat::Wall, Axis::Z, z.0, 1, r2(x0, x1, y.0, y.1), &[], &[])?;
        self.plane(Mat::Wall, Axis::Z, z.1, -1, r2(x0, x1, y.0, y.1), &[], &[])
    }

    /// A ceiling light panel flush in its hole, facing down.
    pub(super) fn light(&mut self, y: i64, r: R2) -> io::Result<()> {
        self.plane(Mat::Light, Axis::Y, y, -1, r, &[], &[])
    }

    /// Windows of an outside wall normal to z: x ranges, evenly along [x0, x1].
    pub(super) fn windows_along(x0: i64, x1: i64) -> Vec<(i64, i64)> {
        let n = ((x1 - x0) / 2200).max(1);
        (0..n)
            .map(|i| {
                let c = x0 + (2 * i + 1) * (x1 - x0) / (2 * n);
                (c - WIN_W / 2, c + WIN_W / 2)
            })
            .collect()
    }
}
