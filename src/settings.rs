//! Settings a user gives, and the one error a bad one makes.
//!
//! Each concern has one plain, serialisable settings type beside the code it steers:
//! [`crate::scene::LoadOptions`] (how a model is read), [`crate::mesh::MeshOptions`] (how it is
//! cut into patches), [`crate::solve::SolveSettings`] (how it is solved),
//! [`crate::render::ViewSettings`] (camera and picture). Each checks itself, once, in the
//! library, with a message that names the flag; the commands call those checks and add none of
//! their own, so every command refuses what `solve` refuses, in the same words. The daylight
//! flags are [`crate::sky::SkySettings`], checked before any model is read; the benchmarks'
//! jobs check themselves likewise (see [`crate::bench`]).
//!
//! The library's enums are the flags' values: `clap::ValueEnum` is derived on them (method,
//! intersector, switch rule, element test, light groups, sky kind, bench ray kinds; the
//! shading's is written out below), so the command line keeps no mirror of them, and the
//! defaults `--help` shows are the library's. tests/settings_parity.rs walks clap's argument
//! list and checks that every `solve` flag reaches the recorded settings
//! ([`crate::pipeline::RunSettings`]) or is listed with the reason it does not.

/// A setting a user got wrong: one line naming the flag and the value.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct Invalid(pub String);

impl Invalid {
    /// `Err(Invalid(message))`.
    pub fn err<T>(message: impl Into<String>) -> Result<T, Invalid> {
        Err(Invalid(message.into()))
    }
}

/// No description of a flag's value in `--help` (the flag's own help says what its values
/// mean): for the library enums whose variant docs are written for the code, not the user.
/// `#[value(help = NO_HELP)]` on a `clap::ValueEnum` variant.
pub const NO_HELP: Option<&str> = None;
