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
//! The results go to `grid.csv` ([`write_csv`]: `x,y,z,nx,ny,nz,lux,df`), `summary.json`
//! ([`GridStats`]: mean, minimum, uniformity U0 = min/mean, …) and a false-colour plan
//! ([`plan_image`]: one top view per storey, a legend in lux, north up).
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

pub use csv::{read_points, write_csv, CSV_HEADER};
pub use plan::plan_image;
pub use stats::{stats, GridStats};
pub use work_plane::{work_plane, MAX_COLUMNS, MIN_STOREY_CLEARANCE};

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
