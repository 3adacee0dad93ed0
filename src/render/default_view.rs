//! The default view: the camera a picture is drawn with when none is given (no `--eye`,
//! `--target`, `--up`, `--fov`, `--near` or `--view`), for `solve`'s `render.png` and for
//! `render` and `relight` of a saved solution.
//!
//! **Fitted, the zenith up.** The camera looks horizontally, along the model's default north
//! (−z for the default zenith +y; +y for a Z-up model, `--zenith 0,0,1`: north turned by the
//! shortest rotation from +y to the zenith, [`Compass::default_north`]), from the south, with
//! the zenith up the picture, far enough back that the whole bounding box fits in view
//! ([`Camera::fit_along`]). For a Y-up model this is the camera every version before took;
//! a Z-up model now gets the same view of itself rather than its roof from above. Back faces
//! are culled, so the rooms of a model made of one-sided faces looking into the rooms (the
//! scenes of `scenes/`) are seen through the near wall, and an open box (a Cornell box)
//! through its open side.
//!
//! **A building's plan.** A model whose walls and roof are closed solids (a CAD or IFC export:
//! every wall, slab and roof a box, its faces looking out) shows nothing but its outside to
//! that camera. So the fitted view is probed first ([`outside_share`]): a ray through each of
//! [`PROBE_COLS`] × [`PROBE_ROWS`] pixel centres sees the *outside* of the model when the first
//! face it shows (the first it meets from the front, as the picture culls backs) is met before
//! any back face — nothing is seen through a wall — and the ray, going on past that face, next
//! meets the back of a face: what it shows is the outer skin of something closed (or it shows
//! the back patch of a two-sided surface, a wall seen from behind its front). A ray that
//! shows open ground (a face looking up, met directly, nothing behind it: a site, a garden, a
//! Cornell box's floor) is not counted, so a garden around a house does not outweigh it. When
//! more than [`OUTSIDE_SHARE`] of the counted rays see the outside, the model is taken for a
//! building seen from outside, and the default view becomes a plan of its top storey:
//!
//! - vertical rays down through a [`PLAN_RAYS`] × [`PLAN_RAYS`] lattice over the bounding box
//!   find, on each, the first *indoor floor* from the top: a face looking up (its normal within
//!   45° of the zenith: [`FLOOR_COS`]) met below a face looking down (a ceiling or the
//!   underside of a roof) and more than [`MIN_ROOM_SHARE`] of the model's height under it,
//!   with the lowest such cover above it (its storey's ceiling);
//! - the top storey's floor is the median of those floors' heights, its height the median of
//!   their floor-to-ceiling heights, and the plan is cut at its mid-height (a plan's usual cut,
//!   about 1.3 m above a floor in a 2.6 m storey): the roof, the ceiling and everything else
//!   above the cut are clipped (the camera's near plane, as `--near` clips by hand, and a
//!   Radiance view's `-vo` writes), and the top storey is seen from above, its walls cut;
//! - the camera looks straight down the zenith, north up the picture and east to the right,
//!   fitted to the part of the bounding box below the cut and over the lattice cells whose rays
//!   found an indoor floor (so a garden around the house is left out), perspective, 40° as the
//!   fitted view.
//!
//! A model with no indoor floor under any ray keeps the fitted view. Open boxes seen from
//! their open side (a Cornell box) and rooms seen through their near wall keep it too: their
//! rays see the inside (measured: 17 % of the Cornell box's fitted view sees an outside, its
//! two blocks; 0 % of every other scene's; 90–100 % of a two-storey house of solids, Y or Z
//! up, with or without a garden: `tests/integration/views.rs`). The rule reads the geometry only along fixed rays, so it is
//! deterministic, and a model rotated from Y up to Z up (with `--zenith` saying so) gets the
//! same view of itself.

use super::camera::Camera;
use crate::intersect::{Hit, Intersector, Ray};
use crate::mesh::{Mesh, Side};
use crate::sky::Compass;
use glam::Vec3;

/// Columns of the lattice of probe rays through the fitted view.
pub const PROBE_COLS: usize = 40;
/// Rows of the lattice of probe rays through the fitted view.
pub const PROBE_ROWS: usize = 30;
/// The fitted view is given up for a plan when more than this share of the probe rays that
/// show anything see the model's outside.
pub const OUTSIDE_SHARE: f64 = 0.5;
/// Vertical rays down a side of the lattice that finds the top storey.
pub const PLAN_RAYS: usize = 32;
/// A floor looks up: the cosine of its normal's angle to the zenith is at least this (45°).
pub const FLOOR_COS: f32 = 0.7;
/// An indoor floor has its cover at least this share of the model's height (along the zenith)
/// above it: a face looking up that touches the one looking down above it (a roof solid
/// standing on a slab) is no floor.
pub const MIN_ROOM_SHARE: f32 = 0.02;
/// At most this many faces are met along one probe ray.
const MAX_HITS: usize = 256;

/// The view the default camera took ([`default_camera`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DefaultView {
    /// Fitted to the bounding box, looking horizontally along the model's north, zenith up.
    Fitted,
    /// A plan of the top storey from above, cut at mid-height: the floor's height and the
    /// cut's (along the zenith, in scene units), and the share of the fitted view's probe
    /// rays that saw the outside.
    Plan { floor: f32, cut: f32, outside: f64 },
}

impl DefaultView {
    /// What a user should hear of the view taken: the plan and why (none for the fitted view).
    pub fn describe(&self) -> Option<String> {
        match *self {
            DefaultView::Fitted => None,
            DefaultView::Plan {
                floor,
                cut,
                outside,
            } => Some(format!(
                "{:.0} % of the fitted view is the model's outside, so the default view is a plan of its top storey from above (floor at height {floor:.2}, cut at {cut:.2} along the zenith; --eye, --near or --view for another)",
                100.0 * outside
            )),
        }
    }
}

/// What the default camera is fitted to: the model's bounds and zenith, and (to tell a
/// building seen from outside) its patches with an intersector over them.
pub struct ModelView<'a, I> {
    pub lo: Vec3,
    pub hi: Vec3,
    /// The model's up (`--zenith`); a zero or non-finite one is taken as +y.
    pub zenith: Vec3,
    /// The patches and an intersector over them; without them the fitted view is taken.
    pub probe: Option<(&'a Mesh, &'a I)>,
}

/// The model's up (unit) and default north (unit, horizontal).
pub fn orientation(zenith: Vec3) -> (Vec3, Vec3) {
    let up = zenith.normalize_or_zero();
    let up = if up.is_finite() && up != Vec3::ZERO {
        up
    } else {
        Vec3::Y
    };
    (up, Compass::default_north(up))
}

/// The fitted camera with the zenith up, looking along the model's default north.
pub fn fitted(lo: Vec3, hi: Vec3, aspect: f32, zenith: Vec3) -> Camera {
    let (up, north) = orientation(zenith);
    Camera::fit_along(lo, hi, aspect, north, up)
}

/// The default camera of a model and a picture of `aspect` (width / height): fitted, or the
/// plan of a building seen from outside (see the [module docs](self)).
pub fn default_camera<I: Intersector>(m: &ModelView<'_, I>, aspect: f32) -> (Camera, DefaultView) {
    let cam = fitted(m.lo, m.hi, aspect, m.zenith);
    let Some(outside) = outside_share(m, aspect) else {
        return (cam, DefaultView::Fitted);
    };
    if outside <= OUTSIDE_SHARE {
        return (cam, DefaultView::Fitted);
    }
    let Some((mesh, isect)) = m.probe else {
        return (cam, DefaultView::Fitted);
    };
    match top_storey(&Probe::new(mesh, isect, m.lo, m.hi), m) {
        Some(storey) => (
            plan(m, aspect, &storey),
            DefaultView::Plan {
                floor: storey.floor,
                cut: storey.cut,
                outside,
            },
        ),
        None => (cam, DefaultView::Fitted),
    }
}

/// The share of the fitted view's counted probe rays (those that show anything but open
/// ground) that see the model's outside ([module docs](self)); `None` without a probe, 0 when
/// no ray counts.
pub fn outside_share<I: Intersector>(m: &ModelView<'_, I>, aspect: f32) -> Option<f64> {
    let (mesh, isect) = m.probe?;
    let probe = Probe::new(mesh, isect, m.lo, m.hi);
    let cam = fitted(m.lo, m.hi, aspect, m.zenith);
    let (up, _) = orientation(m.zenith);
    let (mut counted, mut outside) = (0usize, 0usize);
    for row in 0..PROBE_ROWS {
        for col in 0..PROBE_COLS {
            let u = (col as f32 + 0.5) / PROBE_COLS as f32;
            let v = (row as f32 + 0.5) / PROBE_ROWS as f32;
            let (org, dir) = cam.ray(u, v);
            match probe.seen(org, dir, up) {
                None | Some(Seen::Ground) => {}
                Some(seen) => {
                    counted += 1;
                    outside += usize::from(seen == Seen::Outside);
                }
            }
        }
    }
    Some(if counted == 0 {
        0.0
    } else {
        outside as f64 / counted as f64
    })
}

/// What a probe ray through the fitted view shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Seen {
    /// The outer skin of something closed: met directly, and past it the ray meets a back.
    Outside,
    /// Open ground: a face looking up, met directly, with nothing behind it (not counted).
    Ground,
    /// Anything else: seen through a wall's back, or an open box's inside.
    Other,
}

/// The patches and an intersector, with the step past a face met.
struct Probe<'a, I> {
    mesh: &'a Mesh,
    isect: &'a I,
    /// A ray goes on this far past a face it met (relative to the model's size).
    step: f32,
}

impl<'a, I: Intersector> Probe<'a, I> {
    fn new(mesh: &'a Mesh, isect: &'a I, lo: Vec3, hi: Vec3) -> Probe<'a, I> {
        let size = (hi - lo).length();
        let step = if size.is_finite() && size > 0.0 {
            1e-5 * size
        } else {
            1e-5
        };
        Probe { mesh, isect, step }
    }

    /// The first face along the ray from `org` past distance `t`.
    fn next(&self, org: Vec3, dir: Vec3, t: f32) -> Option<Hit> {
        self.isect.intersect(&Ray {
            org,
            dir,
            tnear: t,
            tfar: f32::INFINITY,
        })
    }

    /// Whether the picture shows the face as the ray met it: its front, or the back of a
    /// two-sided surface (whose back patch looks that way).
    fn shows(&self, h: &Hit) -> bool {
        !h.back
            || matches!(
                self.mesh.patches.get(h.patch as usize).map(|p| p.side),
                Some(Side::Front { .. })
            )
    }

    /// What the ray shows: `None` if nothing, else what (see the [module docs](self)).
    fn seen(&self, org: Vec3, dir: Vec3, up: Vec3) -> Option<Seen> {
        let mut t = 0.0;
        let mut through_a_back = false;
        for _ in 0..MAX_HITS {
            let h = self.next(org, dir, t)?;
            if self.shows(&h) {
                if through_a_back {
                    return Some(Seen::Other);
                }
                if h.back {
                    // The back patch of a two-sided surface: a wall or roof seen from behind
                    // its front, from outside.
                    return Some(Seen::Outside);
                }
                return Some(match self.next(org, dir, h.t + self.step) {
                    Some(b) if b.back => Seen::Outside,
                    Some(_) => Seen::Other,
                    None => {
                        let n = self.mesh.patches[h.patch as usize].normal;
                        let n = if h.back { -n } else { n };
                        if n.dot(up) >= FLOOR_COS {
                            Seen::Ground
                        } else {
                            Seen::Other
                        }
                    }
                });
            }
            through_a_back = true;
            t = h.t + self.step;
        }
        None
    }
}

/// The top storey a plan shows ([`top_storey`]).
struct Storey {
    /// Its floor's height and the cut's, along the zenith.
    floor: f32,
    cut: f32,
    /// The part of the bounding box over its floors, in fractions of the box's half-extents
    /// east and north of its centre (−1 to 1): the lattice cells whose rays found one.
    east: (f32, f32),
    north: (f32, f32),
}

/// The top storey (see the [module docs](self)), from vertical rays down through the
/// bounding box; `None` when no ray finds an indoor floor.
fn top_storey<I: Intersector>(probe: &Probe<'_, I>, m: &ModelView<'_, I>) -> Option<Storey> {
    let (up, north) = orientation(m.zenith);
    let east = north.cross(up);
    let centre = 0.5 * (m.lo + m.hi);
    let h = 0.5 * (m.hi - m.lo);
    let along = |a: Vec3| a.abs().dot(h);
    let (he, hn, hu) = (along(east), along(north), along(up));
    // Start above the top, so the first face met is the highest.
    let above = centre + (hu + 0.01 * (hu + he + hn) + probe.step) * up;
    let (mut floors, mut rooms) = (Vec::new(), Vec::new());
    let cell = 1.0 / PLAN_RAYS as f32;
    let (mut ea, mut na) = ((1.0f32, -1.0f32), (1.0f32, -1.0f32));
    for i in 0..PLAN_RAYS {
        for j in 0..PLAN_RAYS {
            let a = 2.0 * (i as f32 + 0.5) * cell - 1.0;
            let b = 2.0 * (j as f32 + 0.5) * cell - 1.0;
            let org = above + a * he * east + b * hn * north;
            let min_room = MIN_ROOM_SHARE * 2.0 * hu;
            if let Some((floor, ceiling)) = indoor_floor(probe, org, up, min_room) {
                floors.push(floor);
                rooms.push(ceiling - floor);
                ea = (ea.0.min(a - cell), ea.1.max(a + cell));
                na = (na.0.min(b - cell), na.1.max(b + cell));
            }
        }
    }
    let floor = median(&mut floors)?;
    let room = median(&mut rooms)?;
    Some(Storey {
        floor,
        cut: floor + 0.5 * room,
        east: ea,
        north: na,
    })
}

/// Along the ray down from `org`: the height (along `up`) of the first face looking up that
/// lies more than `min_room` under a face looking down, and of the lowest such cover above it.
fn indoor_floor<I: Intersector>(
    probe: &Probe<'_, I>,
    org: Vec3,
    up: Vec3,
    min_room: f32,
) -> Option<(f32, f32)> {
    let dir = -up;
    let mut cover: Option<f32> = None;
    let mut t = 0.0;
    for _ in 0..MAX_HITS {
        let h = probe.next(org, dir, t)?;
        let height = (org + h.t * dir).dot(up);
        let patch = &probe.mesh.patches[h.patch as usize];
        let two_sided = matches!(patch.side, Side::Front { .. });
        // Met from the front by a ray going down, a face looks up.
        let looks_up = !h.back || two_sided;
        let looks_down = h.back || two_sided;
        if looks_up && patch.normal.dot(up).abs() >= FLOOR_COS {
            if let Some(c) = cover.filter(|c| c - height > min_room) {
                return Some((height, c));
            }
        }
        if looks_down {
            cover = Some(height);
        }
        t = h.t + probe.step;
    }
    None
}

/// The median of finite values (the lower of the middle two for an even count); `None` for
/// none.
fn median(v: &mut Vec<f32>) -> Option<f32> {
    v.retain(|x| x.is_finite());
    if v.is_empty() {
        return None;
    }
    v.sort_by(f32::total_cmp);
    Some(v[(v.len() - 1) / 2])
}

/// The plan camera: straight down the zenith, north up the picture, fitted to the part of the
/// bounding box over the storey's floors and below its cut, its near plane at the cut.
fn plan<I>(m: &ModelView<'_, I>, aspect: f32, storey: &Storey) -> Camera {
    let (up, north) = orientation(m.zenith);
    let east = north.cross(up);
    let (lo, hi) = (m.lo, m.hi);
    let frame = Camera::perspective(Vec3::ZERO, -up, north, 40.0, 1.0).frame();
    let h = 0.5 * (hi - lo);
    let mut half = frame.half_extent(h);
    // Across: the storey's part of the box (the frame's right is east, its up north).
    let (he, hn) = (east.abs().dot(h), north.abs().dot(h));
    let (e, n) = (storey.east, storey.north);
    let mut centre =
        0.5 * (lo + hi) + (0.5 * (e.0 + e.1) * he) * east + (0.5 * (n.0 + n.1) * hn) * north;
    half.x *= 0.5 * (e.1 - e.0);
    half.y *= 0.5 * (n.1 - n.0);
    // Along the zenith (the frame's backward axis): from the bottom to the cut.
    let mid = centre.dot(up);
    let (bottom, top) = (mid - half.z, (mid + half.z).min(storey.cut));
    half.z = 0.5 * (top - bottom).max(0.0);
    centre += (0.5 * (bottom + top) - mid) * up;
    let mut cam = Camera::fit_frame(centre, half, h.length(), &frame, aspect);
    cam.near = (cam.eye.dot(up) - storey.cut).max(0.0);
    cam
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fitted_view_follows_the_zenith() {
        let (lo, hi) = (Vec3::new(-1.0, 0.0, -2.0), Vec3::new(3.0, 2.5, 4.0));
        // Y up: exactly the camera of every version before.
        assert_eq!(
            fitted(lo, hi, 4.0 / 3.0, Vec3::Y),
            Camera::fit(lo, hi, 4.0 / 3.0)
        );
        // Z up: the same box turned (x, y, z) -> (x, -z, y) gives the same camera, turned.
        let turn = |p: Vec3| Vec3::new(p.x, -p.z, p.y);
        let (zlo, zhi) = (turn(lo).min(turn(hi)), turn(lo).max(turn(hi)));
        let y = fitted(lo, hi, 4.0 / 3.0, Vec3::Y);
        let z = fitted(zlo, zhi, 4.0 / 3.0, Vec3::Z);
        assert!((z.eye - turn(y.eye)).length() < 1e-5, "{z:?} {y:?}");
        assert!((z.target - turn(y.target)).length() < 1e-5);
        assert_eq!(z.up, Vec3::Z);
        let f = z.frame();
        assert!(f.fwd.dot(Vec3::Z).abs() < 1e-6, "horizontal: {f:?}");
        assert!(f.fwd.dot(Vec3::Y) > 0.999, "looks north (+y): {f:?}");
        // A zenith that is no direction is taken as +y.
        assert_eq!(
            fitted(lo, hi, 1.0, Vec3::ZERO),
            fitted(lo, hi, 1.0, Vec3::Y)
        );
    }

    #[test]
    fn median_takes_the_lower_middle_and_skips_nan() {
        assert_eq!(median(&mut vec![]), None);
        assert_eq!(median(&mut vec![3.0, f32::NAN, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&mut vec![4.0, 1.0, 3.0, 2.0]), Some(2.0));
    }
}
