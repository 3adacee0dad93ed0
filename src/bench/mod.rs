//! Benchmarks and cross-checks, run by hand and reported in the README (never timed
//! assertions in tests):
//!
//! - [`crosscheck`]: every intersector against a reference on the same rays (issue 4);
//! - [`elements`](mod@elements): adaptive elements against uniform meshing (issue 15);
//! - [`intersect`]: the jobs of `radiosity crosscheck` and `radiosity bench intersect`;
//!   [`intersect_table`] their Markdown and CSV;
//! - [`rays`]: raw Embree throughput against the solver's (`radiosity bench rays`);
//! - [`sweep`]: the scene-size performance sweep over generated buildings (`radiosity sweep`);
//! - [`timing`]: hemi-cube shots, the rasteriser and the sensor grid timed (`radiosity bench timing`).

pub mod crosscheck;
pub mod elements;
pub mod intersect;
pub mod intersect_table;
pub mod rays;
pub mod shots;
pub mod sweep;
pub mod timing;
