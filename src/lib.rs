//! # radiosity
//!
//! Diffuse global illumination by adaptive progressive refinement, after Airey & Ouh-young,
//! *Two Adaptive Techniques Let Progressive Refinement Outperform the Traditional Radiosity
//! Algorithm* (UNC TR89-020, 1989).
//!
//! The core, in pipeline order (docs/design.md §1); each layer uses only those above it:
//!
//! - [`scene`] loads OBJ + MTL (materials ρ, emission, lights);
//! - [`mesh`] cuts polygons into patches; [`model`] is a loaded scene with its mesh and the
//!   intersector a command asks for, built once;
//! - [`intersect`] casts rays (Embree 4, the paper's three-way plane merge, their hybrid);
//! - [`sample`] holds the paper's samplers: the adaptive polar hemisphere and the uniform and
//!   non-uniform hemi-cubes (Sec. 2);
//! - [`solve`] shoots (or gathers) energy: the driver, ray shots, hemi-cube shots, the hybrid's
//!   switch (Sec. 4), the stopping rule (Sec. 3) and the energy books;
//! - [`light`] is the light at a point: emitters sampled by what they give each receiver, direct light and the sun
//!   with their MIS weights, hemisphere rays with the near-hit rule, and the point query
//!   ([`light::LightAt`]) the final gather, the pictures, the elements and the sensors share
//!   (it reads the solution's types from [`solve`], whose final gather calls it).
//!
//! Around it: [`settings`] (the settings types and their one error), [`pipeline`] (what
//! `radiosity solve` and `info` do), [`saved`] (commands on a saved solution: render, export,
//! relight), [`compare`] (reference and methods side by side), [`bench`](mod@bench) (benchmarks,
//! cross-checks and the scene-size sweep), [`render`] (rasteriser, false colour, glyphs),
//! [`export`] (file formats), [`container`] (the binary container of the saved solution and
//! the checkpoint), [`report`] (summaries, traces, plots), [`generate`] (generated
//! buildings), [`grid`] (the sensor grid of a daylight study: placement, CSV, figures, plan),
//! [`photometry`] (luminaire files: IES LM-63 and EULUMDAT), [`luminaire`] (placed
//! luminaires: position, aiming frame, intensity toward a direction, the `--luminaires`
//! schedule), [`weather`] (weather files, EPW and Radiance's `.wea`: an hourly series of
//! irradiance at a place, for annual daylight), [`annual`] (a year of daylight at the grid's sensors:
//! the hourly product of the sensors' daylight coefficients and the weather's skies, and its
//! metrics DA, sDA, ASE, UDI, EN 17037, their files and plans; `radiosity annual` runs it
//! through [`pipeline`]).
//! The `radiosity` binary (`src/bin/radiosity/`) only parses flags and prints.
#![deny(unsafe_code)]

pub mod annual;
pub mod bench;
pub mod compare;
pub mod container;
pub mod elements;
pub mod error;
pub mod export;
pub mod generate;
pub mod grid;
pub mod intersect;
pub mod light;
pub mod luminaire;
pub mod mesh;
pub mod model;
pub mod photometry;
pub mod pipeline;
pub mod progress;
pub mod random;
pub mod render;
pub mod report;
pub mod sample;
pub mod saved;
pub mod scene;
pub mod settings;
pub mod sky;
pub mod solve;
pub mod text;
pub mod weather;

pub use error::Error;
