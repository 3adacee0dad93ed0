//! # radiosity
//!
//! Diffuse global illumination by adaptive progressive refinement, after Airey & Ouh-young,
//! *Two Adaptive Techniques Let Progressive Refinement Outperform the Traditional Radiosity
//! Algorithm* (UNC TR89-020, 1989).
//!
//! The pipeline (DESIGN.md §1): [`scene`] loads OBJ + MTL, [`mesh`] cuts polygons into patches,
//! [`intersect`] builds the ray intersectors, [`solve`] shoots energy with the paper's adaptive
//! polar hemisphere sampler ([`sample`]), and [`render`], [`export`] and [`report`] hand the
//! solution on. The `radiosity` binary is a thin layer over this library.
#![deny(unsafe_code)]

pub mod compare;
pub mod error;
pub mod export;
pub mod false_colour;
pub mod generate;
pub mod glyphs;
pub mod intersect;
pub mod intersect_jobs;
pub mod mesh;
pub mod outputs;
pub mod pipeline;
pub mod progress;
pub mod render;
pub mod report;
pub mod sample;
pub mod scene;
pub mod settings;
pub mod shot_bench;
pub mod solve;
pub mod sweep;

pub use error::Error;
