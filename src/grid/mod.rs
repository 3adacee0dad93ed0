//! The sensor grid of a daylight study: where the illuminance is read, how sensors are
//! read from and written to CSV, the figures daylighting standards quote, and the plan picture.
//!
//! This module places sensors and reports values it is given; it computes no illuminance (the
//! solver gathers the solution at each [`Sensor`]). Two ways to place them (`--grid`,
//! [`GridSpec`]):
//!
//! - **A work plane above each floor** (`--grid HEIGHT,SPACING`, [`work_plane()`]): sensors at
//!   HEIGHT above every floor on a square lattice of SPACING, facing the zenith. The rule, its
//!   reasons and its limits are in [`work_plane()`](mod@work_plane)'s documentation.
//! - **Points from a CSV file** (`--grid POINTS.csv`, [`read_points`]): any positions and facing
//!   directions, for whatever the work-plane rule does not fit (a sloping auditorium, vertical
//!   sensors on a façade, a standard's own reference points).
//!
//! **Indoors, storeys and rooms** ([`GridSpec::place`], the rules in [`zones`]): a work-plane
//! sensor with nothing over it (a garden, a terrace) is outdoors and left out unless
//! `--grid-outdoor keep`; every sensor gets its storey, and the indoor sensors of a work plane
//! their room (floor regions bounded by walls, doors included).
//!
//! The results go to `grid.csv` ([`write_csv`]: `x,y,z,nx,ny,nz,lux,df,storey,room,indoor`),
//! `summary.json` ([`GridReport`]: mean, minimum, uniformity U0 = min/mean, …, of the grid and
//! of each storey and room) and a false-colour plan ([`plan_image`]: one top view per storey,
//! a legend in lux, north up).
//!
//! **Orientation.** Plans are laid out in the sky's compass ([`Compass`]: east = north × zenith),
//! so the grid and the sky can never disagree about which way is north. Coordinates are model
//! units, taken to be metres (as the patch size and the sky are).
//!
//! **Storeys.** Sensors whose heights (along the zenith) are within [`STOREY_GAP`] of each other,
//! step by step, make one storey ([`storeys`]); the work plane is ordered by storey and the plan
//! draws one panel per storey.

mod csv;
mod plan;
mod spacing;
mod stats;
pub mod work_plane;
pub mod zones;

pub use csv::{read_points, write_csv, CSV_HEADER};
pub use plan::{plan_image, plan_image_scaled, PlanScale};
pub use stats::{stats, GridReport, GridStats, RoomStats, StoreyStats};
pub use work_plane::{work_plane, MAX_COLUMNS, MIN_STOREY_CLEARANCE};
pub use zones::{Outdoor, Zone};

use crate::intersect::Intersector;
use crate::mesh::Mesh;
use crate::sky::Compass;
use glam::Vec3;
use std::path::{Path, PathBuf};

/// One sensor: where the illuminance is read and which way the sensor faces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sensor {
    /// Model coordinates.
    pub position: Vec3,
    /// Unit normal: the illuminance is that on a small plane facing this way.
    pub normal: Vec3,
}

/// The sensors a grid keeps and where each is ([`GridSpec::place`]).
#[derive(Clone, Debug)]
pub struct Placed {
    pub sensors: Vec<Sensor>,
    /// One per sensor.
    pub zones: Vec<Zone>,
    /// Each sensor's height along the zenith, metres.
    pub heights: Vec<f64>,
    /// The floor area one sensor stands for, m²: the lattice's cell, or for points from a file
    /// the square of their typical spacing (0 if they have none).
    pub cell_area: f64,
    /// `--grid-outdoor`.
    pub rule: Outdoor,
    /// Sensors found outdoors, dropped or kept.
    pub outdoor_points: u64,
    /// Of those, how many were left out.
    pub dropped_points: u64,
    /// One line to warn of: every sensor of a work plane outdoors, so all kept.
    pub warning: Option<String>,
}

impl Placed {
    /// Classifies `sensors` (of a work plane when `plane` is given) and keeps those `rule`
    /// keeps (see [`GridSpec::place`]).
    fn new<I: Intersector>(
        sensors: Vec<Sensor>,
        plane: Option<zones::Plane>,
        isect: &I,
        compass: &Compass,
        rule: Outdoor,
    ) -> Placed {
        let inside = zones::indoor(isect, compass, &sensors);
        let n = sensors.len();
        let outdoor_points = inside.iter().filter(|i| !**i).count();
        let none_indoor = n > 0 && outdoor_points == n;
        let dropping = plane.is_some() && rule == Outdoor::Drop;
        let warning = (dropping && none_indoor).then(|| {
            format!(
                "grid: none of the {n} sensors has a roof or ceiling over it (a model without \
                 one?), so all are kept and marked outdoor (--grid-outdoor keep keeps them \
                 without this warning)"
            )
        });
        let drop = dropping && !none_indoor;
        let (sensors, inside): (Vec<Sensor>, Vec<bool>) = sensors
            .into_iter()
            .zip(inside)
            .filter(|(_, i)| *i || !drop)
            .unzip();
        let storey = zones::storeys_of(compass, &sensors);
        let room = match plane {
            Some(p) => zones::rooms(isect, compass, &sensors, &inside, &storey, p),
            None => vec![0; sensors.len()],
        };
        let local: Vec<glam::DVec3> = sensors
            .iter()
            .map(|s| compass.to_local(s.position.as_dvec3()))
            .collect();
        let cell_area = match plane {
            Some(p) => p.spacing * p.spacing,
            None => {
                let plan: Vec<glam::DVec2> = local.iter().map(|p| p.truncate()).collect();
                spacing::estimate(&plan, &storey).map_or(0.0, |s| s * s)
            }
        };
        let zones = (0..sensors.len())
            .map(|k| Zone {
                storey: storey[k],
                room: room[k],
                indoor: inside[k],
            })
            .collect();
        Placed {
            dropped_points: (n - sensors.len()) as u64,
            sensors,
            zones,
            heights: local.iter().map(|p| p.z).collect(),
            cell_area,
            rule,
            outdoor_points: outdoor_points as u64,
            warning,
        }
    }
}

/// Sensors whose heights differ by no more than this (metres) step by step are one storey:
/// floors of one storey differ by a few steps at most, storeys by 2.5 m or more.
pub const STOREY_GAP: f64 = 1.0;

/// What `--grid` asks for.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum GridSpec {
    /// Sensors `height` metres above each floor, `spacing` metres apart ([`work_plane()`]).
    WorkPlane { height: f32, spacing: f32 },
    /// Sensors read from a CSV file ([`read_points`]).
    Points(PathBuf),
}

impl GridSpec {
    /// The sensors this spec asks for in `mesh`, oriented by `compass`.
    pub fn sensors<I: Intersector>(
        &self,
        mesh: &Mesh,
        isect: &I,
        compass: &Compass,
    ) -> Result<Vec<Sensor>, GridError> {
        match self {
            GridSpec::WorkPlane { height, spacing } => {
                work_plane(mesh, isect, compass, *height, *spacing)
            }
            GridSpec::Points(path) => read_points(path),
        }
    }

    /// The sensors this spec asks for in `mesh` ([`GridSpec::sensors`]), each with its storey,
    /// room and whether it is indoors ([`zones`]); outdoor sensors of a work plane are left out
    /// by [`Outdoor::Drop`], unless none is indoors (a model without a roof: then all are kept,
    /// with a [`Placed::warning`], rather than an empty grid). Points from a file are all kept,
    /// whatever `rule` says: the user chose them.
    pub fn place<I: Intersector>(
        &self,
        mesh: &Mesh,
        isect: &I,
        compass: &Compass,
        rule: Outdoor,
    ) -> Result<Placed, GridError> {
        let sensors = self.sensors(mesh, isect, compass)?;
        let plane = match self {
            GridSpec::WorkPlane { height, spacing } => Some(zones::Plane {
                height: *height as f64,
                spacing: *spacing as f64,
            }),
            GridSpec::Points(_) => None,
        };
        Ok(Placed::new(sensors, plane, isect, compass, rule))
    }

    /// The cell size [`plan_image`] should draw: the lattice spacing, or 0 (estimate it) for
    /// points from a file.
    pub fn spacing_hint(&self) -> f32 {
        match self {
            GridSpec::WorkPlane { spacing, .. } => *spacing,
            GridSpec::Points(_) => 0.0,
        }
    }
}

/// `HEIGHT,SPACING` (two positive numbers of metres, e.g. `0.8,0.5`) is a work plane; anything
/// else is the path of a CSV file. A value made only of numbers and commas that is not two
/// positive numbers (`0.8`, `0.8,0`, `1,2,3`) is refused rather than taken for a file name.
impl std::str::FromStr for GridSpec {
    type Err = GridError;

    fn from_str(s: &str) -> Result<GridSpec, GridError> {
        let t = s.trim();
        let numeric = !t.is_empty()
            && t.chars()
                .all(|c| c.is_ascii_digit() || ".,+-eE ".contains(c));
        if !numeric {
            return Ok(GridSpec::Points(PathBuf::from(s)));
        }
        let bad = |why: &str| GridError::Spec(format!("{why}, got {s:?}"));
        let parts: Vec<&str> = t.split(',').map(str::trim).collect();
        let [h, sp] = parts[..] else {
            return Err(bad("two numbers are needed"));
        };
        let height: f32 = h.parse().map_err(|_| bad("the height is not a number"))?;
        let spacing: f32 = sp.parse().map_err(|_| bad("the spacing is not a number"))?;
        check_plane(height, spacing)?;
        Ok(GridSpec::WorkPlane { height, spacing })
    }
}

impl std::fmt::Display for GridSpec {
    /// The flag's value that gives this spec back.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            GridSpec::WorkPlane { height, spacing } => write!(f, "{height},{spacing}"),
            GridSpec::Points(p) => write!(f, "{}", p.display()),
        }
    }
}

/// Refuses a work plane whose height or spacing is not a positive, finite length.
fn check_plane(height: f32, spacing: f32) -> Result<(), GridError> {
    for (what, v) in [("height", height), ("spacing", spacing)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(GridError::Spec(format!(
                "the {what} must be a positive length in metres, got {v}"
            )));
        }
    }
    Ok(())
}

/// Why no grid could be made. Each displays as one line naming the flag or the file.
#[derive(Debug, thiserror::Error)]
pub enum GridError {
    /// A bad `--grid` value.
    #[error("--grid expects HEIGHT,SPACING in metres (e.g. 0.8,0.5) or a CSV file of points: {0}")]
    Spec(String),
    /// The points file could not be read.
    #[error("--grid: cannot read {path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// A line of the points file is wrong (lines count from 1, the header is line 1).
    #[error("--grid: {path}:{line}: {message}")]
    Csv {
        path: PathBuf,
        line: usize,
        message: String,
    },
    /// The points file has a header but no points.
    #[error("--grid: {0} holds no points")]
    NoPoints(PathBuf),
    /// The work plane found no floor anywhere.
    #[error(
        "--grid {height},{spacing}: no sensor could be placed: no floor (an up-facing surface \
         with {MIN_STOREY_CLEARANCE} m clear above it) has the height free above it at any \
         lattice point; give points in a CSV file instead"
    )]
    NoFloor { height: f32, spacing: f32 },
    /// The lattice would be larger than [`MAX_COLUMNS`].
    #[error(
        "--grid {height},{spacing}: a spacing of {spacing} m makes {columns:.1e} lattice \
         points over the model's plan, over the limit of {MAX_COLUMNS:.0e}: use a larger spacing"
    )]
    TooMany {
        height: f32,
        spacing: f32,
        columns: f64,
    },
}

impl GridError {
    /// A [`GridError::Csv`] about `line` of `path`.
    fn csv(path: &Path, line: usize, message: impl Into<String>) -> GridError {
        GridError::Csv {
            path: path.to_path_buf(),
            line,
            message: message.into(),
        }
    }
}

/// The storey of each height (metres along the zenith), numbered from 0 at the bottom: sorted,
/// heights more than [`STOREY_GAP`] above the one below start a new storey.
pub fn storeys(heights: &[f64]) -> Vec<u32> {
    let mut order: Vec<usize> = (0..heights.len()).collect();
    order.sort_by(|&a, &b| heights[a].total_cmp(&heights[b]));
    let mut out = vec![0; heights.len()];
    let mut storey = 0;
    for k in 1..order.len() {
        if heights[order[k]] - heights[order[k - 1]] > STOREY_GAP {
            storey += 1;
        }
        out[order[k]] = storey;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_spec_parses_a_plane_or_a_path() {
        let plane: GridSpec = "0.8,0.5".parse().unwrap();
        assert_eq!(
            plane,
            GridSpec::WorkPlane {
                height: 0.8,
                spacing: 0.5
            }
        );
        assert_eq!(plane.to_string().parse::<GridSpec>().unwrap(), plane);
        assert_eq!(plane.spacing_hint(), 0.5);
        assert_eq!(
            " 0.85 , 1 ".parse::<GridSpec>().unwrap(),
            GridSpec::WorkPlane {
                height: 0.85,
                spacing: 1.0
            }
        );
        let pts: GridSpec = "rooms/points.csv".parse().unwrap();
        assert_eq!(pts, GridSpec::Points("rooms/points.csv".into()));
        assert_eq!(pts.spacing_hint(), 0.0);
    }

    #[test]
    fn grid_spec_refuses_bad_planes_naming_the_flag() {
        for bad in [
            "0.8", "0.8,0", "0.8,-1", "1,2,3", "0.8,,", "1e40,1", "0,0.5",
        ] {
            let e = bad.parse::<GridSpec>().unwrap_err().to_string();
            assert!(e.starts_with("--grid expects HEIGHT,SPACING"), "{bad}: {e}");
            assert!(!e.contains('\n'), "{e}");
        }
    }

    #[test]
    fn storeys_split_where_heights_jump_more_than_the_gap() {
        let h = [3.8, 0.8, 0.8, 1.3, 7.0, 3.9, 2.4];
        // 0.8, 0.8, 1.3 | 2.4 (1.1 above 1.3) | 3.8, 3.9 | 7.0
        assert_eq!(storeys(&h), vec![2, 0, 0, 0, 3, 2, 1]);
        assert!(storeys(&[]).is_empty());
    }
}
