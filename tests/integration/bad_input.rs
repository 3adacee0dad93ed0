//! Bad input: every malformed file in `tests/corpus/` and every bad flag value or
//! combination gives exactly one error line naming the problem, exit code 2, no panic, and
//! leaves no output behind (no file, no temporary file, no new folder); the odd but valid
//! files (`odd-*`: comments after the data, continued lines, Kd of 1 or more, textures, glTF
//! rooms) load and solve with exactly the warnings they deserve. The glTF files are written by
//! `tests/corpus/make_gltf.py`.
//!
//! The table below is the corpus index: one row per case, `{c}` standing for `tests/corpus`,
//! `{s}` for a shared folder holding a solved solution (`{s}/sol.rad`, `{s}/o/patches.csv`),
//! a regular file `{s}/regular` and the generated large inputs, and `{t}` for a fresh empty
//! folder per case that must still be empty afterwards.

use assert_cmd::Command;
use std::collections::BTreeSet;
use std::path::Path;

/// (what is wrong, the command line, words the error line must hold).
type Case = (&'static str, &'static str, &'static [&'static str]);

/// Malformed files, one per corpus file (the OBJ of an OBJ+MTL pair stands for both, the
/// `.gltf` of a `.gltf`+`.bin` pair too).
#[rustfmt::skip]
const FILES: &[Case] = &[
    ("missing file", "solve -q {c}/no-such-file.obj --out {t}/o", &["no-such-file.obj", "cannot read", "no such file"]),
    ("empty file", "solve -q {c}/empty.obj --out {t}/o", &["empty.obj", "no polygons"]),
    ("comments only", "solve -q {c}/comments-only.obj --out {t}/o", &["comments-only.obj", "no polygons"]),
    ("binary garbage", "solve -q {c}/binary-garbage.obj --out {t}/o", &["binary-garbage.obj", "line 4", "a face with 2 vertices"]),
    ("non-UTF-8 bytes in a vertex", "solve -q {c}/non-utf8-bytes.obj --out {t}/o", &["non-utf8-bytes.obj", "line 4", "cannot read a vertex"]),
    ("face index past the vertex count", "solve -q {c}/face-index-out-of-range.obj --out {t}/o", &["face-index-out-of-range.obj", "line 5", "vertex 9", "has 4 vertices"]),
    ("negative index beyond the vertex count", "solve -q {c}/face-negative-index-beyond-count.obj --out {t}/o", &["face-negative-index-beyond-count.obj", "line 5", "vertex -7"]),
    ("index 0", "solve -q {c}/face-index-zero.obj --out {t}/o", &["face-index-zero.obj", "line 5", "index 0", "start at 1"]),
    ("face of 1 vertex", "solve -q {c}/face-one-vertex.obj --out {t}/o", &["face-one-vertex.obj", "line 6", "a face with 1 vertex", "at least 3"]),
    ("face of 2 vertices", "solve -q {c}/face-two-vertices.obj --out {t}/o", &["face-two-vertices.obj", "line 6", "a face with 2 vertices"]),
    ("face of no vertex", "solve -q {c}/face-no-vertices.obj --out {t}/o", &["face-no-vertices.obj", "line 6", "a face with 0 vertices"]),
    ("face index not a number", "solve -q {c}/face-index-not-a-number.obj --out {t}/o", &["face-index-not-a-number.obj", "line 5", "cannot read a face", "f 1 2 x"]),
    ("texture index out of range", "solve -q {c}/face-texture-index-out-of-range.obj --out {t}/o", &["face-texture-index-out-of-range.obj", "line 7", "texture coordinate 5"]),
    // OBJ readers (tobj too) resolve positive indices at the end: a face before its vertices
    // is read; what is wrong with this file is only that nothing emits.
    ("face before its vertices, no light", "solve -q {c}/face-before-its-vertices-no-light.obj --out {t}/o", &["face-before-its-vertices-no-light.obj", "no light", "--emit"]),
    ("NaN coordinate", "solve -q {c}/vertex-nan.obj --out {t}/o", &["vertex-nan.obj", "vertex 3 (line 3)", "not finite"]),
    ("inf coordinate", "solve -q {c}/vertex-inf.obj --out {t}/o", &["vertex-inf.obj", "vertex 3 (line 3)", "not finite"]),
    ("1e39 overflows f32", "solve -q {c}/vertex-1e39-overflows-f32.obj --out {t}/o", &["vertex-1e39-overflows-f32.obj", "vertex 3", "not finite", "1e39"]),
    ("vertex with 2 numbers", "solve -q {c}/vertex-too-few-numbers.obj --out {t}/o", &["vertex-too-few-numbers.obj", "line 2", "cannot read a vertex", "v 1 0"]),
    ("vertex number does not parse", "solve -q {c}/vertex-not-a-number.obj --out {t}/o", &["vertex-not-a-number.obj", "line 2", "v 1 2 x"]),
    ("vertex w = 0", "solve -q {c}/vertex-w-zero.obj --out {t}/o", &["vertex-w-zero.obj", "line 2", "w"]),
    ("all faces zero-area", "solve -q {c}/all-faces-zero-area.obj --out {t}/o", &["all-faces-zero-area.obj", "all 3 faces have zero area"]),
    ("duplicate vertices only", "solve -q {c}/duplicate-vertices-only.obj --out {t}/o", &["duplicate-vertices-only.obj", "all 2 faces have zero area"]),
    ("vertices but no face", "solve -q {c}/vertices-but-no-faces.obj --out {t}/o", &["vertices-but-no-faces.obj", "no polygons"]),
    ("polylines and points only", "solve -q {c}/lines-and-points-only.obj --out {t}/o", &["lines-and-points-only.obj", "no polygons"]),
    ("usemtl without a name", "solve -q {c}/usemtl-without-name.obj --out {t}/o", &["usemtl-without-name.obj", "line 5", "usemtl"]),
    ("patch-size comment making 10^18 patches", "solve -q {c}/patch-size-hint-far-too-small.obj --out {t}/o", &["patch-size-hint-far-too-small.obj", "patches, over the limit", "--patch-size"]),
    ("bad patch-size comment", "solve -q {c}/bad-patch-size-hint.obj --out {t}/o", &["bad-patch-size-hint.obj", "line 1", "patch-size"]),
    // A missing MTL is only a warning (grey); the error is then that nothing emits.
    ("missing MTL, so no light", "solve -q {c}/missing-mtl-no-light.obj --out {t}/o", &["missing-mtl-no-light.obj", "no light", "--emit"]),
    ("usemtl of an undefined material, so no light", "solve -q {c}/usemtl-undefined-material.obj --out {t}/o", &["usemtl-undefined-material.obj", "no light", "--emit"]),
    ("mtllib escaping with ../ to nothing", "solve -q {c}/mtllib-escapes-with-dotdot.obj --out {t}/o", &["mtllib-escapes-with-dotdot.obj", "no light"]),
    ("mtllib is a folder", "solve -q {c}/mtllib-is-a-folder.obj --out {t}/o", &["mtllib-is-a-folder.obj", "material library '.'", "cannot read"]),
    // Kd of 1 or more is clamped with a warning (see ODD); below 0 or not finite, an error.
    ("Kd negative", "solve -q {c}/mtl-kd-negative.obj --out {t}/o", &["mtl-kd-negative.obj", "'white'", "-0.2", "not a reflectance"]),
    ("Kd NaN", "solve -q {c}/mtl-kd-nan.obj --out {t}/o", &["mtl-kd-nan.obj", "'white'", "NaN", "not a reflectance"]),
    ("Kd of 2 numbers", "solve -q {c}/mtl-kd-two-numbers.obj --out {t}/o", &["mtl-kd-two-numbers.obj", "mtl-kd-two-numbers.mtl", "line 2", "needs 3 numbers"]),
    ("Kd not a number", "solve -q {c}/mtl-kd-not-a-number.obj --out {t}/o", &["mtl-kd-not-a-number.mtl", "line 2", "'grey' is not a number"]),
    ("Kd spectral", "solve -q {c}/mtl-kd-spectral.obj --out {t}/o", &["mtl-kd-spectral.mtl", "line 2", "not supported"]),
    ("Ke negative", "solve -q {c}/mtl-ke-negative.obj --out {t}/o", &["mtl-ke-negative.obj", "'white'", "Ke -1", "not negative"]),
    ("Ke NaN", "solve -q {c}/mtl-ke-nan.obj --out {t}/o", &["mtl-ke-nan.obj", "'white'", "NaN", "finite"]),
    ("Ke inf", "solve -q {c}/mtl-ke-inf.obj --out {t}/o", &["mtl-ke-inf.obj", "'white'", "inf", "finite"]),
    ("Ns not a number", "solve -q {c}/mtl-ns-not-a-number.obj --out {t}/o", &["mtl-ns-not-a-number.mtl", "line 3", "Ns shiny"]),
    ("non-UTF-8 bytes in the MTL", "solve -q {c}/mtl-non-utf8.obj --out {t}/o", &["mtl-non-utf8.mtl", "line 2", "not a number"]),
    // Continued lines and comments after the data: messages name the file's own lines.
    ("bad index after continued lines", "solve -q {c}/continued-lines-then-bad-index.obj --out {t}/o", &["continued-lines-then-bad-index.obj", "line 13", "vertex 99", "has 6 vertices"]),
    ("face of 2 vertices and a comment", "solve -q {c}/trailing-comment-then-bad-face.obj --out {t}/o", &["trailing-comment-then-bad-face.obj", "line 4", "a face with 2 vertices"]),
    ("info reads the same way", "info {c}/face-index-zero.obj", &["face-index-zero.obj", "index 0"]),
    // Luminaire schedules (`--luminaires`) and photometric files.
    ("schedule without a z column", "solve -q {c}/lit.obj --luminaires {c}/schedule-missing-z.csv --out {t}/o", &["schedule-missing-z.csv:1", "missing column 'z'"]),
    ("schedule with a word for a number", "solve -q {c}/lit.obj --luminaires {c}/schedule-bad-number.csv --out {t}/o", &["schedule-bad-number.csv:3", "'x' is not a finite number"]),
    ("schedule naming a missing IES file", "solve -q {c}/lit.obj --luminaires {c}/schedule-missing-ies.csv --out {t}/o", &["schedule-missing-ies.csv:2", "no-such-lamp.ies", "cannot read"]),
    ("schedule naming a garbled IES file", "solve -q {c}/lit.obj --luminaires {c}/schedule-garbage-ies.csv --out {t}/o", &["schedule-garbage-ies.csv:2", "garbage-web.ies:4", "vertical angles"]),
    ("schedule with no luminaire", "solve -q {c}/lit.obj --luminaires {c}/schedule-empty.csv --out {t}/o", &["schedule-empty.csv: no luminaires listed"]),
    ("JSON schedule with an unknown key", "solve -q {c}/lit.obj --luminaires {c}/schedule-unknown-key.json --out {t}/o", &["schedule-unknown-key.json:1", "unknown field `brightness`"]),
    ("info of a garbled IES file", "info {c}/garbage-web.ies", &["garbage-web.ies:4", "vertical angles"]),
    // glTF models, made by tests/corpus/make_gltf.py: the container, then the data, then the
    // document's structure.
    ("glTF: a .glb cut in its binary chunk", "solve -q {c}/gltf-truncated.glb --out {t}/o", &["gltf-truncated.glb", "not a readable .glb file", "cut short"]),
    ("glTF: a .glb whose magic is not glTF", "solve -q {c}/gltf-bad-magic.glb --out {t}/o", &["gltf-bad-magic.glb", "not a .glb file", "does not begin with 'glTF'"]),
    ("glTF: a .glb of version 1", "solve -q {c}/gltf-bad-version.glb --out {t}/o", &["gltf-bad-version.glb", "not a readable .glb file", "version 1; only version 2"]),
    ("glTF: not JSON", "solve -q {c}/gltf-not-json.gltf --out {t}/o", &["gltf-not-json.gltf", "not a readable glTF document", "line 1 column 1"]),
    ("glTF: JSON without an asset", "solve -q {c}/gltf-empty-object.gltf --out {t}/o", &["gltf-empty-object.gltf", "missing field `asset`"]),
    ("glTF: a buffer naming a missing file", "solve -q {c}/gltf-missing-bin.gltf --out {t}/o", &["gltf-missing-bin.gltf", "buffer 0", "no-such-buffer.bin", "no such file"]),
    ("glTF: a buffer shorter than its byteLength", "solve -q {c}/gltf-buffer-short.gltf --out {t}/o", &["gltf-buffer-short.gltf", "buffer 0 holds 180 bytes", "byteLength says 360"]),
    ("glTF: a buffer view past its buffer", "solve -q {c}/gltf-view-past-buffer.gltf --out {t}/o", &["gltf-view-past-buffer.gltf", "buffer view 0", "past the end of buffer 0"]),
    ("glTF: a byteStride shorter than an element", "solve -q {c}/gltf-stride-shorter-than-element.gltf --out {t}/o", &["gltf-stride-shorter-than-element.gltf", "accessor 0", "positions of mesh 0 'tri'", "byteStride", "shorter than an element"]),
    ("glTF: an accessor of count 0", "solve -q {c}/gltf-accessor-count-zero.gltf --out {t}/o", &["gltf-accessor-count-zero.gltf", "accessor 0", "has no elements"]),
    ("glTF: NaN in the positions", "solve -q {c}/gltf-position-nan.glb --out {t}/o", &["gltf-position-nan.glb", "accessor 0", "element 2 holds NaN"]),
    ("glTF: an index past the vertex count", "solve -q {c}/gltf-index-out-of-range.glb --out {t}/o", &["gltf-index-out-of-range.glb", "mesh 0 'tri', primitive 0", "index 7", "its 4 vertices"]),
    ("glTF: lines only", "solve -q {c}/gltf-lines-only.gltf --out {t}/o", &["gltf-lines-only.gltf", "no polygons"]),
    ("glTF: a node cycle", "solve -q {c}/gltf-node-cycle.gltf --out {t}/o", &["gltf-node-cycle.gltf", "node 0 'tri'", "its own ancestor", "cycle"]),
    ("glTF: Draco compression required", "solve -q {c}/gltf-requires-draco.gltf --out {t}/o", &["gltf-requires-draco.gltf", "KHR_draco_mesh_compression", "does not read"]),
    ("glTF: a spot light of negative intensity", "solve -q {c}/gltf-spot-negative-intensity.gltf --out {t}/o", &["gltf-spot-negative-intensity.gltf", "light 0 'downlight'", "intensity -5"]),
    ("glTF: a negative base colour", "solve -q {c}/gltf-base-colour-negative.gltf --out {t}/o", &["gltf-base-colour-negative.gltf", "material 0 'floor'", "base colour -0.5"]),
    ("glTF: no light", "solve -q {c}/gltf-no-light.gltf --out {t}/o", &["gltf-no-light.gltf", "no light", "--emit"]),
    ("info reads glTF the same way", "info {c}/gltf-position-nan.glb", &["gltf-position-nan.glb", "element 2 holds NaN"]),
    // Generated here rather than committed (the repository stays small).
    ("an extremely long line", "solve -q {s}/long-line.obj --out {t}/o", &["long-line.obj", "vertex 3 (line 3)", "not finite"]),
    ("10^6 zero-area faces", "solve -q {s}/million-faces.obj --out {t}/o", &["million-faces.obj", "all 1000000 faces have zero area"]),
];

/// Bad flag values and combinations, on the built-in scene or the corpus's lit scene.
#[rustfmt::skip]
const FLAGS: &[Case] = &[
    ("--emit of an unknown material", "solve -q --out {t}/o --emit lamp=1,1,1", &["cornell-box", "'lamp'", "'white', 'red', 'green', 'light'"]),
    ("--emit negative", "solve -q --out {t}/o --emit light=-1,1,1", &["--emit", "must not be negative"]),
    ("--emit NaN", "solve -q --out {t}/o --emit light=nan,1,1", &["--emit", "'nan' is not a finite number"]),
    ("--emit of 2 numbers", "solve -q --out {t}/o --emit light=1,1", &["--emit", "expected 3 comma-separated numbers"]),
    ("--emit without =", "solve -q --out {t}/o --emit light", &["--emit", "MATERIAL=R,G,B"]),
    ("--patch-size 0", "solve -q --out {t}/o --patch-size 0", &["--patch-size", "positive length"]),
    ("--patch-size -1", "solve -q --out {t}/o --patch-size -1", &["--patch-size", "positive length"]),
    ("--patch-size making 10^13 patches", "solve -q --out {t}/o --patch-size 1e-6", &["cornell-box", "patch size 0.000001 m", "over the limit"]),
    ("info --patch-size making 10^13 patches", "info --patch-size 1e-6", &["cornell-box", "over the limit"]),
    ("--patch-size nan", "solve -q --out {t}/o --patch-size nan", &["--patch-size", "positive length"]),
    ("info --patch-size 0", "info --patch-size 0", &["--patch-size", "positive length"]),
    ("--tolerance 0", "solve -q --out {t}/o --tolerance 0", &["--tolerance", "(0, 1)"]),
    ("--tolerance 1", "solve -q --out {t}/o --tolerance 1", &["--tolerance", "(0, 1)"]),
    ("--tolerance 2", "solve -q --out {t}/o --tolerance 2", &["--tolerance", "(0, 1)"]),
    ("--stop -1", "solve -q --out {t}/o --stop -1", &["--stop", "positive"]),
    ("--max-time -5", "solve -q --out {t}/o --max-time -5", &["--max-time", "positive"]),
    ("--max-rays 0", "solve -q --out {t}/o --max-rays 0", &["--max-rays", "at least 1"]),
    ("--energy-per-ray 0", "solve -q --out {t}/o --energy-per-ray 0", &["--energy-per-ray", "positive"]),
    ("--width 0", "solve -q --out {t}/o --width 0", &["--width", "between 1 and 16384"]),
    ("--height 100000", "solve -q --out {t}/o --height 100000", &["--height", "between 1 and 16384"]),
    ("--fov 180", "solve -q --out {t}/o --fov 180", &["--fov", "(0, 180)"]),
    ("--eye of 2 numbers", "solve -q --out {t}/o --eye 1,2", &["--eye", "expected 3"]),
    ("--eye on --target", "solve -q --out {t}/o --eye 1,1,1 --target 1,1,1", &["--eye", "--target", "same point"]),
    ("--up 0,0,0", "solve -q --out {t}/o --up 0,0,0", &["--up"]),
    ("--up along the line of sight", "solve -q --out {t}/o --eye 0,0,0 --target 0,2,0 --up 0,1,0", &["--up", "line of sight"]),
    ("--exposure nan", "solve -q --out {t}/o --exposure nan", &["--exposure", "positive"]),
    ("--threads 0", "solve -q --out {t}/o --threads 0", &["--threads", "at least 1"]),
    ("--hemicube-n 1", "solve -q --out {t}/o --hemicube-n 1", &["--hemicube-n", "between 2 and 4096"]),
    ("--switch-at without the hybrid", "solve -q --out {t}/o --switch-at 5 --method hemicube", &["--switch-at", "adaptive-hybrid"]),
    ("--gather-cap-mib too small", "solve -q --out {t}/o --method gathering --gather-cap-mib 1", &["cornell-box", "--gather-cap-mib", "15 MiB"]),
    ("--light-groups without --per-light", "solve -q --out {t}/o --light-groups connected", &["--per-light"]),
    ("an unknown flag", "solve -q --out {t}/o --bogus", &["--bogus"]),
    ("--intersector merge on a skew scene", "solve -q --out {t}/o --intersector merge", &["--intersector merge", "skew"]),
    ("--reference of another scene", "solve -q --out {t}/o --reference {s}/o/patches.csv", &["--reference", "patches.csv", "1958"]),
    ("--reference that is no patch table", "solve -q --out {t}/o --reference {c}/lit.obj", &["--reference", "lit.obj", "not a patch table"]),
    ("--out is a regular file", "solve -q --out {s}/regular", &["regular", "is a file, not a folder"]),
    ("--out under a regular file", "solve -q --out {s}/regular/o", &["regular", "is a file, not a folder"]),
    ("--save under a regular file", "solve -q --out {t}/o --save {s}/regular/x.rad", &["--save", "is a file, not a folder"]),
    ("--save in a missing folder", "solve -q --out {t}/o --save {t}/none/x.rad", &["--save", "does not exist"]),
    ("--save is a folder", "solve -q --out {t}/o --save {s}", &["--save", "is a folder"]),
    ("render of a file that is not a solution", "render {c}/not-a-solution.rad --out {t}/x.png", &["not-a-solution.rad", "not a radiosity solution"]),
    ("render of an OBJ", "render {c}/lit.obj --out {t}/x.png", &["lit.obj", "not a radiosity solution"]),
    ("render of a truncated solution", "render {s}/truncated.rad --out {t}/x.png", &["truncated.rad", "truncated"]),
    ("render of a folder", "render {s}/o --out {t}/x.png", &["cannot read"]),
    ("render to an unknown format", "render {s}/sol.rad --out {t}/x.jpg", &["x.jpg", ".png, .hdr or .exr"]),
    ("render under a regular file", "render {s}/sol.rad --out {s}/regular/x.png", &["x.png", "is a file, not a folder"]),
    ("render --width 0", "render {s}/sol.rad --out {t}/x.png --width 0", &["--width"]),
    ("render --false-colour to HDR", "render {s}/sol.rad --out {t}/x.hdr --false-colour", &["--false-colour", ".png"]),
    ("render checked against another scene", "render {s}/sol.rad --scene {c}/mtl-kd-negative.obj --out {t}/x.png", &["mtl-kd-negative.obj", "not a reflectance"]),
    ("export of a file that is not a solution", "export {c}/not-a-solution.rad --out {t}/x.ply", &["not-a-solution.rad", "not a radiosity solution"]),
    ("export to an unknown format", "export {s}/sol.rad --out {t}/x.stl", &["x.stl", ".ply or .glb"]),
    ("relight with a negative weight", "relight {s}/sol.rad --out {t}/x.png --weight lamp=-1", &["--weight", "finite number"]),
    ("relight with a NaN weight", "relight {s}/sol.rad --out {t}/x.png --weight lamp=nan", &["--weight", "finite number"]),
    ("relight with a weight without =", "relight {s}/sol.rad --out {t}/x.png --weight lamp", &["--weight", "LIGHT=WEIGHT"]),
    ("relight of an unknown light", "relight {s}/sol.rad --out {t}/x.png --weight nosuch=2", &["nosuch", "no such light", "lamp"]),
];

/// (what is odd, the command line, words the warnings must hold: none means no warning).
type OddCase = (&'static str, &'static str, &'static [&'static str]);

/// Odd but valid input: each loads and solves (exit code 0, `summary.json` written), with
/// exactly the warnings named (in the summary's `warnings`).
#[rustfmt::skip]
const ODD: &[OddCase] = &[
    ("comments after the data in the OBJ and the MTL", "solve -q {c}/odd-trailing-comments.obj --out {t}/o", &[]),
    ("backslash line continuations", "solve -q {c}/odd-line-continuation.obj --out {t}/o", &[]),
    ("Kd above 1 is clamped", "solve -q {c}/odd-kd-above-one.obj --out {t}/o", &["clamped to 0.98", "'white'"]),
    ("Kd 1 1 1 with a texture, and with a missing one", "solve -q {c}/odd-kd-one-with-texture.obj --out {t}/o",
        &["1 texture(s) not loaded", "'lamp'", "lamp-texture-that-is-not-there.png: no such file", "clamped to 0.98 (a closed room"]),
    // Made by tests/corpus/make_gltf.py: a closed room, its walls a colour times a PNG texture.
    ("glTF room: a point light, the texture in the .glb's binary chunk", "solve -q {c}/odd-gltf-room.glb --out {t}/o", &[]),
    ("glTF room: a point and a spot light, buffer and texture in data URIs", "solve -q {c}/odd-gltf-room-data-uri.gltf --out {t}/o", &[]),
];

fn corpus() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/corpus"))
}

/// Every path under `dir`, relative to it.
fn listing(dir: &Path) -> BTreeSet<String> {
    fn walk(root: &Path, dir: &Path, out: &mut BTreeSet<String>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            out.insert(path.strip_prefix(root).unwrap().display().to_string());
            if path.is_dir() {
                walk(root, &path, out);
            }
        }
    }
    let mut out = BTreeSet::new();
    walk(dir, dir, &mut out);
    out
}

/// The shared folder `{s}`: a solved solution of the corpus's lit scene, a regular file, and
/// the generated large inputs.
fn shared() -> tempfile::TempDir {
    let s = tempfile::tempdir().unwrap();
    let out = Command::cargo_bin("radiosity")
        .unwrap()
        .args(["solve", "-q", "--per-light", "--out"])
        .arg(s.path().join("o"))
        .arg("--save")
        .arg(s.path().join("sol.rad"))
        .arg(corpus().join("lit.obj"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{out:?}");
    let sol = std::fs::read(s.path().join("sol.rad")).unwrap();
    std::fs::write(s.path().join("truncated.rad"), &sol[..sol.len() / 2]).unwrap();
    std::fs::write(s.path().join("regular"), "a regular file\n").unwrap();
    let long = format!(
        "v 0 0 0\nv 1 0 0\nv 0 1{} 0\nf 1 2 3\n",
        "1".repeat(2_000_000)
    );
    std::fs::write(s.path().join("long-line.obj"), long).unwrap();
    let mut million = String::from("v 0 0 0\nv 1 0 0\nv 2 0 0\n");
    million.push_str(&"f 1 2 3\n".repeat(1_000_000));
    std::fs::write(s.path().join("million-faces.obj"), million).unwrap();
    s
}

/// Runs one case; returns what is wrong with its outcome, if anything.
fn check(case: &Case, s: &Path) -> Option<String> {
    let (what, line, needles) = case;
    let t = tempfile::tempdir().unwrap();
    let args: Vec<String> = line
        .split_whitespace()
        .map(|w| {
            w.replace("{c}", &corpus().display().to_string())
                .replace("{s}", &s.display().to_string())
                .replace("{t}", &t.path().display().to_string())
        })
        .collect();
    let out = Command::cargo_bin("radiosity")
        .unwrap()
        .env_remove("RUST_BACKTRACE")
        .args(&args)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    let code = out.status.code();
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    let problem = if code != Some(2) {
        format!("exit code {code:?}, not 2")
    } else if err.contains("panicked") {
        "a panic".to_string()
    } else if lines.len() != 1 {
        format!("{} lines on stderr, not one", lines.len())
    } else if !(lines[0].starts_with("Error: ") || lines[0].starts_with("error: ")) {
        "the line does not start with `Error: `".to_string()
    } else if lines[0].len() > 400 {
        format!("a line of {} characters", lines[0].len())
    } else if let Some(n) = needles
        .iter()
        .find(|n| !lines[0].to_lowercase().contains(&n.to_lowercase()))
    {
        format!("'{n}' is not in the line")
    } else if !listing(t.path()).is_empty() {
        format!("left behind: {:?}", listing(t.path()))
    } else {
        return None;
    };
    Some(format!("{what} (`{line}`): {problem}; stderr: {err}"))
}

fn run_table(table: &[Case]) {
    let s = shared();
    let before = (listing(s.path()), listing(corpus()));
    let failures: Vec<String> = table.iter().filter_map(|c| check(c, s.path())).collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert_eq!(
        (listing(s.path()), listing(corpus())),
        before,
        "a case left a file behind in the shared folder or the corpus"
    );
}

#[test]
fn malformed_files_give_one_error_line_and_exit_2() {
    run_table(FILES);
}

#[test]
fn bad_flags_give_one_error_line_and_exit_2() {
    run_table(FLAGS);
}

#[test]
fn odd_but_valid_input_loads_and_solves() {
    let failures: Vec<String> = ODD
        .iter()
        .filter_map(|(what, line, needles)| {
            let t = tempfile::tempdir().unwrap();
            let args: Vec<String> = line
                .split_whitespace()
                .map(|w| {
                    w.replace("{c}", &corpus().display().to_string())
                        .replace("{t}", &t.path().display().to_string())
                })
                .collect();
            let out = Command::cargo_bin("radiosity")
                .unwrap()
                .args(&args)
                .output()
                .unwrap();
            let err = String::from_utf8_lossy(&out.stderr);
            if !out.status.success() {
                return Some(format!(
                    "{what} (`{line}`): {:?}; stderr: {err}",
                    out.status
                ));
            }
            let Ok(summary) = std::fs::read_to_string(t.path().join("o/summary.json")) else {
                return Some(format!("{what}: no summary.json written"));
            };
            let json: serde_json::Value = serde_json::from_str(&summary).unwrap();
            let warnings: Vec<&str> = json["warnings"]
                .as_array()
                .unwrap()
                .iter()
                .map(|w| w.as_str().unwrap())
                .collect();
            let all = warnings.join("\n");
            if needles.is_empty() && !warnings.is_empty() {
                return Some(format!("{what}: unexpected warnings {warnings:?}"));
            }
            needles
                .iter()
                .find(|n| !all.contains(*n))
                .map(|n| format!("{what}: '{n}' is in no warning: {warnings:?}"))
        })
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn every_corpus_file_is_used() {
    let used: String = FILES.iter().chain(FLAGS).chain(ODD).map(|c| c.1).collect();
    for name in listing(corpus()) {
        if name == "make_gltf.py" {
            // What writes the glTF files, not a case.
            continue;
        }
        let stem = name
            .trim_end_matches(".bin")
            .trim_end_matches(".png")
            .trim_end_matches(".mtl")
            .trim_end_matches(".obj")
            .trim_end_matches(".csv")
            .trim_end_matches(".json")
            .trim_end_matches(".ies");
        assert!(used.contains(stem), "{name} is in no case");
    }
    assert!(FILES.len() >= 30, "the corpus has {} cases", FILES.len());
}
