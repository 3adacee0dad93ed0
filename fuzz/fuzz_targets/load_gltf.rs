//! Arbitrary bytes through the glTF loader, as a `.glb` or a `.gltf` (the loader tells them
//! apart by the bytes, not the name) with no folder beside it, so only embedded buffers and
//! images (the binary chunk, `data:` URIs) are read. A scene that loads is then cut into
//! patches. Loading must give a scene or a one-line error, never a panic; no Embree is used.
//!
//! Seeds: the valid models of the corpus, `tests/corpus/odd-gltf-room.glb` and
//! `tests/corpus/odd-gltf-room-data-uri.gltf`, e.g. `cargo fuzz run load_gltf
//! fuzz/corpus/load_gltf tests/corpus` (new inputs are written to the first folder only).

#![no_main]

use libfuzzer_sys::fuzz_target;
use radiosity::mesh::{self, MeshOptions};
use radiosity::scene::{load_gltf_from_slice, LoadOptions};

/// The most patches the harness meshes (each run should take milliseconds).
const FUZZ_MAX_PATCHES: f64 = 100_000.0;

fuzz_target!(|data: &[u8]| {
    match load_gltf_from_slice("fuzz.glb", data, None, &LoadOptions::default()) {
        Ok(scene) => {
            assert!(!scene.polygons.is_empty());
            // As load_obj's harness: the tool refuses absurd patch counts and meshes the
            // rest; a huge model is slow, not wrong, so only what meshes quickly is meshed.
            let opts = MeshOptions::default();
            if mesh::rough_patch_count(&scene, &opts) <= FUZZ_MAX_PATCHES {
                let m = mesh::try_build(&scene, &opts).expect("under the limit");
                assert!(m.patches.iter().all(|p| p.area.is_finite()));
            }
        }
        Err(e) => {
            let line = e.to_string();
            assert!(!line.contains('\n'), "a multi-line error: {line}");
        }
    }
});
