//! Arbitrary bytes through the loading path: everything before the first NUL byte is the OBJ,
//! everything after it the MTL its `mtllib` line names. A scene that loads is then cut into
//! patches. Loading must give a scene or a one-line error, never a panic; no Embree is used.

#![no_main]

use libfuzzer_sys::fuzz_target;
use radiosity::mesh::{self, MeshOptions};
use radiosity::scene::{load_obj_from_strs, LoadOptions};

/// The most patches the harness meshes (each run should take milliseconds).
const FUZZ_MAX_PATCHES: f64 = 100_000.0;

fuzz_target!(|data: &[u8]| {
    let (obj, mtl) = match data.iter().position(|&b| b == 0) {
        Some(at) => (&data[..at], &data[at + 1..]),
        None => (data, &[][..]),
    };
    // As `load_obj` reads a file: bytes that are not UTF-8 become U+FFFD.
    let obj = String::from_utf8_lossy(obj);
    let mtl = String::from_utf8_lossy(mtl);
    match load_obj_from_strs("fuzz.obj", &obj, &mtl, &LoadOptions::default()) {
        Ok(scene) => {
            assert!(!scene.polygons.is_empty());
            // What the pipeline does: refuse absurd patch counts, else cut into patches. The
            // tool allows 20M patches; a sliver triangle 800 m long already makes millions
            // (its longest edge sets the subdivision), which is slow, not wrong: the harness
            // meshes only what it can mesh quickly.
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
