//! Finds Embree 4 for linking (docs/design.md §3), in order: `$EMBREE_DIR`, `pkg-config embree4`,
//! the system library folders, then the repo-local `.embree/lib` that `setup.sh` fills.
//! `embree4-sys` asks for `-lembree4`; this script only says where it is, and sets an rpath so
//! the binaries find it at run time without `LD_LIBRARY_PATH`.

use std::path::{Path, PathBuf};
use std::process::Command;

fn main() {
    println!("cargo:rerun-if-env-changed=EMBREE_DIR");
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=.embree/lib");

    let dir = find_embree();
    match dir {
        Some(Found::Dir(dir)) => {
            println!("cargo:rustc-link-search=native={}", dir.display());
            println!("cargo:rustc-link-arg=-Wl,-rpath,{}", dir.display());
        }
        Some(Found::System) => {}
        None => {
            println!(
                "cargo:warning=Embree 4 not found: run ./setup.sh (or set EMBREE_DIR to the folder holding libembree4.so)"
            );
            panic!("Embree 4 not found: run ./setup.sh (or set EMBREE_DIR to the folder holding libembree4.so)");
        }
    }
}

enum Found {
    Dir(PathBuf),
    System,
}

fn has_lib(dir: &Path) -> bool {
    dir.join("libembree4.so").exists()
}

fn find_embree() -> Option<Found> {
    // 1. An explicit folder (either the lib folder or an install prefix).
    if let Ok(d) = std::env::var("EMBREE_DIR") {
        let d = PathBuf::from(d);
        for cand in [d.clone(), d.join("lib"), d.join("lib64")] {
            if has_lib(&cand) {
                return Some(Found::Dir(cand));
            }
        }
    }
    // 2. pkg-config.
    if let Ok(out) = Command::new("pkg-config")
        .args(["--variable=libdir", "embree4"])
        .output()
    {
        if out.status.success() {
            let d = PathBuf::from(String::from_utf8_lossy(&out.stdout).trim());
            if has_lib(&d) {
                return Some(Found::Dir(d));
            }
        }
    }
    // 3. The system library folders (found by the linker with no help).
    for d in [
        "/usr/lib/x86_64-linux-gnu",
        "/usr/lib/aarch64-linux-gnu",
        "/usr/lib64",
        "/usr/lib",
        "/usr/local/lib",
    ] {
        if has_lib(Path::new(d)) {
            return Some(if d == "/usr/local/lib" {
                Found::Dir(d.into())
            } else {
                Found::System
            });
        }
    }
    // 4. The folder setup.sh fills.
    let local = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").unwrap_or_default())
        .join(".embree")
        .join("lib");
    if has_lib(&local) {
        return Some(Found::Dir(local));
    }
    None
}
