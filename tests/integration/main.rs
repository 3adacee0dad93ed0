//! The integration tests as one crate (one binary, so the crate and Embree link once): each
//! module is the tests of one feature, on the library's public API or on the `radiosity`
//! binary. `common` runs the binary and solves; `scene_builder` builds the little scenes the
//! tests solve. The malformed inputs of `bad_input` are in `tests/corpus/`.

mod common;
mod scene_builder;

mod annual;
mod bad_input;
mod checkpoint;
mod cli;
mod compare;
mod converted;
mod daylight;
mod elements;
mod error_target;
mod final_gather;
mod gather_render;
mod gltf;
mod gltf_mutations;
mod grid_rooms;
mod grid_work_plane;
mod house_rules;
mod intersect;
mod luminaires;
mod outputs;
mod relight;
mod reproducible;
mod scenes;
mod settings_parity;
mod sides;
mod solve_analytic;
mod solve_methods;
mod stiff;
mod view;
mod views;
