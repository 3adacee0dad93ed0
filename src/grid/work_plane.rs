//! The work plane: sensors at a height above each floor, on a square lattice (`--grid
//! HEIGHT,SPACING`), as daylighting standards lay out their reference plane (e.g. 0.85 m above
//! the floor, points about half a metre apart).
//!
//! # The rule
//!
//! - **Lattice.** Columns on a square lattice of SPACING aligned with east and north ([`Compass`]),
//!   offset half a spacing from the model's plan bounds (the bounds of all its vertices seen
//!   from above): the first column is half a spacing east and north of the south-west corner,
//!   and columns stand strictly inside the bounds.
//! - **Floors.** A ray is cast straight down each column from above the model through its whole
//!   height, stepping past each hit, so every storey of a building is met. A hit is a *floor*
//!   when the side of the surface it meets exists ([`Mesh::receiver`]: the front, or the back
//!   twin of a two-sided surface) and faces up (normal · zenith ≥ [`FLOOR_COS`]), and a ray cast
//!   up from it meets nothing within [`MIN_STOREY_CLEARANCE`].
//! - **Sensors.** One per floor met, HEIGHT above it (the floor's own plane, exactly), facing the
//!   zenith, kept only if the ray up from the floor also meets nothing up to the sensor: the
//!   sensor is in the room's air, not inside a desk, a beam or the slab above.
//! - **Order.** By storey ([`storeys`] of the floor heights) from the bottom, then by rows from
//!   north to south, then from west to east (the reading order of the plan), then by height.
//!
//! # Why, and the limits
//!
//! The clearance is what tells a storey from furniture: a desk top 0.75 m high in a 3 m room has
//! 2.25 m above it and is no floor. A ray cannot tell a desk from a low ceiling, so the floor
//! *under* a desk, a table or a bed has no clearance either: **furniture leaves holes in the
//! grid**, whatever its height, as does anything lower than 2.3 m over a floor (a mezzanine, a
//! duct, the flight of a stair above). Any up-facing surface with the clearance is a floor:
//! stair treads and ramps get their sensors (as many storeys as the gap rule makes of them), and
//! so does every surface open to the sky: a courtyard (Sponza's), a terrace, a flat roof, the
//! ground modelled around a building. A solve then leaves those out as outdoors unless asked
//! to keep them ([`GridSpec::place`](super::GridSpec::place), `--grid-outdoor keep`). A
//! column that runs exactly in the plane of a wall may see it as an obstacle and lose its
//! sensor. A one-sided floor seen from below is no floor (its back does not exist); a floor modelled as two coincident opposite faces is merged
//! into one two-sided surface when the model is loaded, and its up-facing side counts.
//!
//! Where that rule does not fit (furnished rooms read at desk height, sloping floors, sensors
//! that are not horizontal), give the points in a CSV file
//! (`--grid POINTS.csv`, [`read_points`](super::read_points)).
//!
//! # Cost
//!
//! Two or three rays per floor met per column; columns run in parallel (rayon) and the result
//! is sorted, so it does not depend on scheduling. A few million columns take seconds.

use super::{check_plane, storeys, GridError, Sensor};
use crate::intersect::{Hit, Intersector, Ray};
use crate::mesh::Mesh;
use crate::sky::Compass;
use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// Clear height (metres) an up-facing surface needs above it to be a floor. Storeys of rooms
/// people use are rarely lower than 2.3 m clear; the 2.25 m left above a 0.75 m desk in a 3 m
/// room is just below it, so desks and worktops are not floors.
pub const MIN_STOREY_CLEARANCE: f32 = 2.3;

/// A floor faces up within about 8° (cos 8° ≈ 0.99): level floors modelled with a little slope
/// or noise count; ramps steeper than 1 in 7 do not.
pub const FLOOR_COS: f32 = 0.99;

/// The most lattice columns a work plane may have: 5 × 10⁷ is a 700 m square at 10 cm, far more
/// than any study needs; more is taken for a mistake (a wrong unit, a typo) rather than run for
/// hours and fill the memory.
pub const MAX_COLUMNS: f64 = 5e7;

/// Sensors HEIGHT above each floor of `mesh` on a lattice of SPACING (the rule is in the
/// [module docs](self)), facing the zenith of `compass`, in storey, row, column order.
///
/// Refuses a height or spacing that is not a positive length, a lattice of more than
/// [`MAX_COLUMNS`] columns, and a model where no sensor can be placed.
pub fn work_plane<I: Intersector>(
    mesh: &Mesh,
    isect: &I,
    compass: &Compass,
    height: f32,
    spacing: f32,
) -> Result<Vec<Sensor>, GridError> {
    check_plane(height, spacing)?;
    let lattice = Lattice::new(mesh, compass, spacing as f64);
    let columns = lattice.nx as f64 * lattice.ny as f64;
    if columns > MAX_COLUMNS {
        return Err(GridError::TooMany {
            height,
            spacing,
            columns,
        });
    }
    let column = Column {
        mesh,
        isect,
        lattice: &lattice,
        reach: MIN_STOREY_CLEARANCE.max(height),
    };
    let mut found: Vec<Found> = (0..lattice.nx * lattice.ny)
        .into_par_iter()
        .flat_map_iter(|k| column.floors(k % lattice.nx, k / lattice.nx))
        .collect();
    if found.is_empty() {
        return Err(GridError::NoFloor { height, spacing });
    }
    order(&mut found);
    Ok(found
        .iter()
        .map(|f| lattice.sensor(f, height as f64))
        .collect())
}

/// A floor met by a column, with room for a sensor above it.
#[derive(Clone, Copy, Debug)]
struct Found {
    /// Column index, east.
    i: usize,
    /// Row index, north.
    j: usize,
    /// The floor's height along the zenith.
    u: f64,
}

/// Sorts by storey (bottom up), row (north first), column (west first), height.
fn order(found: &mut [Found]) {
    let heights: Vec<f64> = found.iter().map(|f| f.u).collect();
    let storey = storeys(&heights);
    let mut keyed: Vec<(u32, Found)> = storey.into_iter().zip(found.iter().copied()).collect();
    keyed.sort_unstable_by(|(sa, a), (sb, b)| {
        sa.cmp(sb)
            .then(b.j.cmp(&a.j))
            .then(a.i.cmp(&b.i))
            .then(a.u.total_cmp(&b.u))
    });
    for (dst, (_, f)) in found.iter_mut().zip(keyed) {
        *dst = f;
    }
}

/// The lattice over the model's plan, in the compass's local coordinates (east, north, up).
struct Lattice {
    compass: Compass,
    /// South-west corner of the plan bounds (east, north).
    e0: f64,
    n0: f64,
    spacing: f64,
    nx: usize,
    ny: usize,
    /// Where the downward rays start (above the model) and how far they reach.
    top: f64,
    depth: f64,
    /// The step past a hit: well above f32 rounding at the model's coordinates, far below any
    /// slab's thickness.
    eps: f64,
}

impl Lattice {
    fn new(mesh: &Mesh, compass: &Compass, spacing: f64) -> Lattice {
        let (lo, hi) = local_bounds(mesh, compass);
        let span = (hi - lo).max_element().max(0.0);
        let far = lo.abs().max(hi.abs()).max_element();
        // Columns strictly inside the bounds: e0 + (i + ½)s < e1.
        let count = |extent: f64| (extent / spacing - 0.5).ceil().max(0.0) as usize;
        let margin = 1.0 + 0.01 * span;
        Lattice {
            compass: *compass,
            e0: lo.x,
            n0: lo.y,
            spacing,
            nx: count(hi.x - lo.x),
            ny: count(hi.y - lo.y),
            top: hi.z + margin,
            depth: span + 2.0 * margin,
            eps: 1e-5 * (1.0 + span) + 5e-7 * far,
        }
    }

    /// The lattice point (i, j) at height `u`, local coordinates.
    fn local(&self, i: usize, j: usize, u: f64) -> DVec3 {
        DVec3::new(
            self.e0 + (i as f64 + 0.5) * self.spacing,
            self.n0 + (j as f64 + 0.5) * self.spacing,
            u,
        )
    }

    fn sensor(&self, f: &Found, height: f64) -> Sensor {
        Sensor {
            position: self
                .compass
                .to_world(self.local(f.i, f.j, f.u + height))
                .as_vec3(),
            normal: self.compass.up().as_vec3(),
        }
    }
}

/// The bounds of the mesh's vertices in local coordinates (east, north, up); zero when empty.
fn local_bounds(mesh: &Mesh, compass: &Compass) -> (DVec3, DVec3) {
    let mut it = mesh.vertices.iter().map(|v| compass.to_local(v.as_dvec3()));
    let Some(first) = it.next() else {
        return (DVec3::ZERO, DVec3::ZERO);
    };
    it.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p)))
}

/// What one column needs: the model, the rays, the lattice, and how far up a floor must be
/// free (the storey clearance, or the sensor's height if higher).
struct Column<'a, I> {
    mesh: &'a Mesh,
    isect: &'a I,
    lattice: &'a Lattice,
    reach: f32,
}

impl<I: Intersector> Column<'_, I> {
    /// The floors of column (i, j) with a sensor's room above them, top down.
    fn floors(&self, i: usize, j: usize) -> Vec<Found> {
        let l = self.lattice;
        let down = -l.compass.up().as_vec3();
        let mut ray = Ray {
            org: l.compass.to_world(l.local(i, j, l.top)).as_vec3(),
            dir: down,
            tnear: 0.0,
            tfar: l.depth as f32,
        };
        let mut out = Vec::new();
        while let Some(hit) = self.isect.intersect(&ray) {
            if let Some(u) = self.floor_height(i, j, hit) {
                if self.is_clear(i, j, u) {
                    out.push(Found { i, j, u });
                }
            }
            ray.tnear = hit.t + l.eps as f32;
        }
        out
    }

    /// The height of the surface `hit` meets in column (i, j), if the side met exists and
    /// faces up: where the column crosses the patch's plane, in f64 (exact for a level floor,
    /// whatever Embree's rounding of t).
    fn floor_height(&self, i: usize, j: usize, hit: Hit) -> Option<f64> {
        let side = self.mesh.receiver(hit.patch, hit.back)?;
        let p = &self.mesh.patches[side as usize];
        let f = &self.lattice.compass;
        let n = f.to_local(p.normal.as_dvec3());
        if n.z < FLOOR_COS as f64 {
            return None;
        }
        let c = f.to_local(p.centre.as_dvec3());
        let at = self.lattice.local(i, j, 0.0);
        Some(c.z - ((at.x - c.x) * n.x + (at.y - c.y) * n.y) / n.z)
    }

    /// Whether nothing is within `reach` straight above the floor at height `u`.
    fn is_clear(&self, i: usize, j: usize, u: f64) -> bool {
        let l = self.lattice;
        let up: Vec3 = l.compass.up().as_vec3();
        let ray = Ray {
            org: l.compass.to_world(l.local(i, j, u)).as_vec3(),
            dir: up,
            tnear: l.eps as f32,
            tfar: self.reach,
        };
        self.isect.intersect(&ray).is_none()
    }
}
