//! Benchmarks and cross-checks, run by hand and reported in the README (never timed
//! assertions in tests):
//!
//! - [`crosscheck`]: every intersector against a reference on the same rays;
//! - [`elements`](mod@elements): adaptive elements against uniform meshing;
//! - [`intersect`]: the jobs of `radiosity crosscheck` and `radiosity bench intersect`;
//!   [`intersect_table`] their Markdown and CSV;
//! - [`rays`]: raw Embree throughput against the solver's (`radiosity bench rays`);
//! - [`shots`]: the cost per shot and the hybrid's switch (`radiosity bench shots`);
//! - [`sweep`]: the scene-size performance sweep over generated buildings (`radiosity sweep`);
//! - [`timing`]: hemi-cube shots, the rasteriser and the sensor grid timed (`radiosity bench
//!   timing`).
//!
//! Each command's job is a plain type here (`CrossJob`, `BenchJob`, `RaysJob`, `ShotsJob`,
//! `ElementBenchJob`, `SweepJob`) whose `check()` refuses a bad flag before any work, with the
//! one [`crate::settings::Invalid`] error; the binary only fills the jobs.

pub mod crosscheck;
pub mod elements;
pub mod intersect;
pub mod intersect_table;
pub mod rays;
pub mod shots;
pub mod sweep;
pub mod sweep_e2e;
pub mod timing;
