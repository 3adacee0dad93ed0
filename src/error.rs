//! The library's error: one enum over the areas' own errors, each displayed as one line that
//! names the file and what is wrong. [`Error::exit_code`] says whose fault it is.

use crate::export::solution::SolutionError;
use crate::export::WriteError;
use crate::intersect::embree::EmbreeError;
use crate::intersect::select::SelectError;
use crate::photometry::PhotometryError;
use crate::scene::SceneError;
use crate::solve::SolveError;

#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error("{scene}: {source}")]
    Solve {
        scene: String,
        #[source]
        source: SolveError,
    },
    #[error(transparent)]
    Write(#[from] WriteError),
    #[error(transparent)]
    Embree(#[from] EmbreeError),
    /// The intersector asked for does not suit the scene, or could not be built.
    #[error(transparent)]
    Select(SelectError),
    /// A saved solution that cannot be used (`render`, `export`).
    #[error(transparent)]
    Solution(#[from] SolutionError),
    /// A luminaire file (IES, EULUMDAT) that cannot be read.
    #[error(transparent)]
    Photometry(#[from] PhotometryError),
    /// A bad setting (flag value, combination).
    #[error("{0}")]
    Invalid(String),
    /// A check ran and its bar failed (`radiosity crosscheck`): exit code 1.
    #[error("{0}")]
    Failed(String),
    /// A plot could not be drawn (`radiosity compare`): exit code 1.
    #[error("cannot draw a plot: {0}")]
    Plot(String),
    /// Ctrl-C stopped a run whose outputs would mislead if written from the part done
    /// (`radiosity annual`): exit code 130, as a shell reports SIGINT.
    #[error("{0}")]
    Interrupted(String),
}

/// Annual metrics: a non-finite illuminance is the solver's fault (exit 1); a bad setting or
/// an unwritable file the user's.
impl From<crate::annual::AnnualError> for Error {
    fn from(e: crate::annual::AnnualError) -> Error {
        match e {
            crate::annual::AnnualError::NotFinite { .. } => Error::Failed(e.to_string()),
            _ => Error::Invalid(e.to_string()),
        }
    }
}

impl Error {
    /// 2 for what the user can fix (input, flags, output folder), 1 for internal failures,
    /// 130 for Ctrl-C.
    pub fn exit_code(&self) -> u8 {
        match self {
            Error::Embree(_) | Error::Failed(_) | Error::Plot(_) => 1,
            Error::Interrupted(_) => 130,
            _ => 2,
        }
    }
}

impl From<crate::settings::Invalid> for Error {
    fn from(e: crate::settings::Invalid) -> Error {
        Error::Invalid(e.0)
    }
}

impl From<SelectError> for Error {
    fn from(e: SelectError) -> Error {
        match e {
            SelectError::Embree(e) => Error::Embree(e),
            e => Error::Select(e),
        }
    }
}
