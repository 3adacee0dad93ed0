//! Where each sensor is: indoors or outdoors, its storey and its room. The work plane puts
//! sensors on every floor with room above it, the ground of a garden and a terrace among them;
//! this module tells those apart from the rooms, and the rooms from each other.
//!
//! # Indoors
//!
//! A sensor is **indoors** when something covers it: of five rays cast up from it (the zenith
//! and four tilted [`CONE_DEGREES`] towards north-east, north-west, south-west and south-east),
//! at least three meet a surface within [`OUTDOOR_REACH`]. Any surface counts, glazing too: a
//! floor under a roof light (an atrium, a conservatory) is indoors. The majority makes one ray
//! slipping through a crack between two faces, or grazing the edge of an eave, change nothing;
//! the tilts lean across the lattice's lines, so even a crack running along the line of a row
//! or column of sensors (where joins of a modelled grid of roof panels may fall) lets only the
//! zenith ray through. A sensor under an
//! overhang (a porch, a balcony above, a carport) is covered and so counts as indoors.
//!
//! # Storeys
//!
//! As the plan draws them ([`storeys`]): heights along the zenith within
//! [`STOREY_GAP`](super::STOREY_GAP) of each other, step by step, numbered from 0 at the bottom.
//!
//! # Rooms
//!
//! On a work plane, the indoor sensors of one storey are flood-filled over the lattice: two
//! sensors side by side (east–west or north–south neighbours, one spacing apart) are in the
//! same room when the straight line between the points [`ROOM_PROBE`] above their floors meets
//! no surface. At that height the line passes over the furniture of a room (tables, worktops,
//! sofas, low partitions and kitchen counters: a room with furniture is one room) and under any
//! ceiling over a floor (every floor has [`MIN_STOREY_CLEARANCE`](super::MIN_STOREY_CLEARANCE)
//! clear above it), but it meets the wall above a door, whose head is lower: a door joins no
//! two rooms, a wide opening that reaches the ceiling (an arch, an open-plan kitchen) does.
//! Rooms are numbered per storey from 1, in the order of their first sensor in the grid's
//! order (north to south, west to east); 0 is no room (an outdoor sensor, or points from a
//! file, whose floors are not known).

use super::{storeys, Sensor};
use crate::intersect::{Intersector, Ray};
use crate::sky::Compass;
use glam::{DVec3, Vec3};
use rayon::prelude::*;
use std::collections::HashMap;

/// The furthest (metres) a roof or ceiling over a sensor may be and still make it indoors:
/// more than any storey and than the roof light of an atrium five or six storeys high. What is
/// further up (a sky box round the model, a stadium's canopy, a bridge high over a street)
/// covers no room.
pub const OUTDOOR_REACH: f32 = 20.0;

/// How far from the zenith the four tilted rays of the indoor test lean: at 3 m they stand
/// 0.26 m from the vertical one, wider than a crack between two faces, narrower than a roof
/// light or the depth of an eave.
pub const CONE_DEGREES: f32 = 5.0;

/// Height above the floor (metres) at which two neighbouring sensors are tested for a wall
/// between them: above door heads (2.0–2.1 m in houses and offices) and furniture, below the
/// 2.3 m every floor has clear above it.
pub const ROOM_PROBE: f64 = 2.2;

/// What becomes of the sensors found outdoors (`--grid-outdoor`).
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    serde::Serialize,
    serde::Deserialize,
    clap::ValueEnum,
)]
#[serde(rename_all = "kebab-case")]
pub enum Outdoor {
    /// Left out of the grid (the default): the figures are the rooms'.
    #[default]
    Drop,
    /// Kept, and marked `indoor` 0 in `grid.csv`.
    Keep,
}

impl Outdoor {
    /// The flag's value.
    pub fn name(self) -> &'static str {
        match self {
            Outdoor::Drop => "drop",
            Outdoor::Keep => "keep",
        }
    }
}

/// Where one sensor is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Zone {
    /// The storey, from 0 at the bottom.
    pub storey: u32,
    /// The room within the storey, from 1; 0 for none (outdoors, or points from a file).
    pub room: u32,
    /// Whether something covers the sensor (the [module docs](self)).
    pub indoor: bool,
}

/// Whether each sensor is indoors (the rule is in the [module docs](self)).
pub fn indoor<I: Intersector>(isect: &I, compass: &Compass, sensors: &[Sensor]) -> Vec<bool> {
    let eps = eps_of(sensors);
    let up = compass.up();
    let (s, c) = (CONE_DEGREES as f64).to_radians().sin_cos();
    let dirs: Vec<Vec3> = std::iter::once(up)
        .chain(
            [(1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)]
                .map(|(e, n)| (e * compass.east() + n * compass.north()).normalize())
                .map(|h| c * up + s * h),
        )
        .map(|d| d.normalize().as_vec3())
        .collect();
    sensors
        .par_iter()
        .map(|sensor| {
            let covered = dirs
                .iter()
                .filter(|&&dir| {
                    let ray = Ray {
                        org: sensor.position,
                        dir,
                        tnear: eps,
                        tfar: OUTDOOR_REACH,
                    };
                    isect.intersect(&ray).is_some()
                })
                .count();
            2 * covered > dirs.len()
        })
        .collect()
}

/// The step past a sensor's own position: above f32 rounding at the sensors' coordinates,
/// far below any storey.
fn eps_of(sensors: &[Sensor]) -> f32 {
    let far = sensors
        .iter()
        .map(|s| s.position.abs().max_element())
        .fold(0.0f32, f32::max);
    1e-4 + 1e-6 * far
}

/// The storey of each sensor ([`storeys`] of their heights along the zenith).
pub fn storeys_of(compass: &Compass, sensors: &[Sensor]) -> Vec<u32> {
    let heights: Vec<f64> = sensors
        .iter()
        .map(|s| compass.to_local(s.position.as_dvec3()).z)
        .collect();
    storeys(&heights)
}

/// A work plane's lattice, for [`rooms`]: sensors `height` above their floors, `spacing` apart.
#[derive(Clone, Copy, Debug)]
pub struct Plane {
    pub height: f64,
    pub spacing: f64,
}

/// The room of each sensor of a work plane (the rule is in the [module docs](self)): 0 where
/// `indoor` is false, else from 1 per storey (`storey`, one per sensor) in the sensors' order.
///
/// # Panics
/// If `indoor` or `storey` does not hold one value per sensor (a caller's bug).
pub fn rooms<I: Intersector>(
    isect: &I,
    compass: &Compass,
    sensors: &[Sensor],
    indoor: &[bool],
    storey: &[u32],
    plane: Plane,
) -> Vec<u32> {
    assert_eq!(sensors.len(), indoor.len(), "one indoor flag per sensor");
    assert_eq!(sensors.len(), storey.len(), "one storey per sensor");
    let n = sensors.len();
    let local: Vec<DVec3> = sensors
        .iter()
        .map(|s| compass.to_local(s.position.as_dvec3()))
        .collect();
    let Some(origin) = local.iter().map(|p| p.truncate()).reduce(|a, b| a.min(b)) else {
        return Vec::new();
    };
    let cell = |p: DVec3| {
        let c = ((p.truncate() - origin) / plane.spacing).round();
        (c.x as i64, c.y as i64)
    };
    let mut at: HashMap<(u32, i64, i64), Vec<usize>> = HashMap::new();
    for k in (0..n).filter(|&k| indoor[k]) {
        let (i, j) = cell(local[k]);
        at.entry((storey[k], i, j)).or_default().push(k);
    }
    // Each pair of neighbours once: the one east and the one north of each sensor.
    let pairs: Vec<(usize, usize)> = (0..n)
        .filter(|&k| indoor[k])
        .flat_map(|a| {
            let (i, j) = cell(local[a]);
            [(i + 1, j), (i, j + 1)]
                .into_iter()
                .filter_map(|(i, j)| at.get(&(storey[a], i, j)))
                .flatten()
                .map(move |&b| (a, b))
                .collect::<Vec<_>>()
        })
        .collect();
    let probe = |k: usize| local[k] + DVec3::Z * (ROOM_PROBE - plane.height);
    let open: Vec<bool> = pairs
        .par_iter()
        .map(|&(a, b)| {
            let (pa, pb) = (
                compass.to_world(probe(a)).as_vec3(),
                compass.to_world(probe(b)).as_vec3(),
            );
            let d = pb - pa;
            let len = d.length();
            let ray = Ray {
                org: pa,
                dir: d / len,
                tnear: 0.0,
                tfar: len,
            };
            len > 0.0 && isect.intersect(&ray).is_none()
        })
        .collect();
    let mut sets = Sets::new(n);
    for (&(a, b), _) in pairs.iter().zip(&open).filter(|(_, o)| **o) {
        sets.join(a, b);
    }
    number(&mut sets, indoor, storey)
}

/// Room numbers from the sets: per storey from 1, in the sensors' order; 0 outdoors.
fn number(sets: &mut Sets, indoor: &[bool], storey: &[u32]) -> Vec<u32> {
    let mut of_root: HashMap<usize, u32> = HashMap::new();
    let mut next: HashMap<u32, u32> = HashMap::new();
    (0..indoor.len())
        .map(|k| {
            if !indoor[k] {
                return 0;
            }
            let root = sets.root(k);
            *of_root.entry(root).or_insert_with(|| {
                let c = next.entry(storey[k]).or_insert(0);
                *c += 1;
                *c
            })
        })
        .collect()
}

/// Disjoint sets (union by size, path halving).
struct Sets {
    parent: Vec<usize>,
    size: Vec<usize>,
}

impl Sets {
    fn new(n: usize) -> Sets {
        Sets {
            parent: (0..n).collect(),
            size: vec![1; n],
        }
    }

    fn root(&mut self, mut k: usize) -> usize {
        while self.parent[k] != k {
            self.parent[k] = self.parent[self.parent[k]];
            k = self.parent[k];
        }
        k
    }

    fn join(&mut self, a: usize, b: usize) {
        let (mut a, mut b) = (self.root(a), self.root(b));
        if a == b {
            return;
        }
        if self.size[a] < self.size[b] {
            std::mem::swap(&mut a, &mut b);
        }
        self.parent[b] = a;
        self.size[a] += self.size[b];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_zones_sets_join_and_number_in_order_per_storey() {
        let mut s = Sets::new(6);
        s.join(0, 2);
        s.join(3, 5);
        s.join(5, 4);
        let indoor = [true, true, true, true, true, false];
        let storey = [0, 0, 0, 1, 1, 1];
        // 0 and 2 one room, 1 another; on storey 1: 3 and 4 one room, 5 outdoors.
        assert_eq!(number(&mut s, &indoor, &storey), vec![1, 2, 1, 1, 1, 0]);
    }

    #[test]
    fn grid_zones_outdoor_names_its_flag_values() {
        use clap::ValueEnum;
        for o in Outdoor::value_variants() {
            let v = o.to_possible_value().unwrap();
            assert_eq!(v.get_name(), o.name());
        }
        assert_eq!(Outdoor::default(), Outdoor::Drop);
    }
}
