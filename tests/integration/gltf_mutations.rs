//! The glTF loader on a few thousand broken copies of the corpus's valid models
//! (`tests/corpus/odd-gltf-room.glb`, `odd-gltf-room-data-uri.gltf`): each copy loads to a
//! scene (which then meshes, when small enough) or to a one-line error naming the file, and
//! never panics. The copies are made the same way on every run: seeded byte flips, inserted
//! bytes, cuts every 97 bytes, and each number and string of the JSON replaced by values a
//! reader must survive (1e39, -1, 2^32, "NaN", a newline, ...). In a `.glb` the JSON is
//! replaced inside its chunk, the lengths rewritten, so the copy reaches the loader's own
//! checks rather than failing at the header. `fuzz/fuzz_targets/load_gltf.rs` does the same
//! with coverage guidance, where `cargo fuzz` is installed.

use radiosity::mesh::{self, MeshOptions};
use radiosity::scene::{load_gltf_from_slice, LoadOptions};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

/// Flips and insertions per seed.
const FLIPS: usize = 1500;
const INSERTS: usize = 300;
/// A cut every this many bytes.
const CUT_EVERY: usize = 97;
/// The most patches a loaded copy is meshed with (as the fuzz harness).
const MAX_PATCHES: f64 = 100_000.0;

/// What replaces each JSON number.
const NUMBERS: &[&str] = &[
    "1e39",
    "-1e39",
    "-1",
    "0",
    "-0",
    "1e-45",
    "3.5",
    "65535",
    "4294967295",
    "4294967296",
    "18446744073709551616",
    "\"NaN\"",
    "null",
    "[]",
];

/// What replaces each JSON string.
const STRINGS: &[&str] = &[
    "\"\"",
    "\"a\\nb\"",
    "\"data:\"",
    "\"data:;base64,@@@\"",
    "\"../no\\u0000such.bin\"",
    "7",
];

/// A copy and how it was made (printed when it fails).
struct Mutant {
    how: String,
    bytes: Vec<u8>,
}

/// xorshift64*: the same copies on every run.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

/// Byte ranges (start, end) in a text.
type Spans = Vec<(usize, usize)>;

/// The byte ranges of the numbers and of the strings (quotes included) of a JSON text.
fn tokens(json: &[u8]) -> (Spans, Spans) {
    let (mut numbers, mut strings) = (Vec::new(), Vec::new());
    let mut i = 0;
    while i < json.len() {
        match json[i] {
            b'"' => {
                let start = i;
                i += 1;
                while i < json.len() && json[i] != b'"' {
                    i += if json[i] == b'\\' { 2 } else { 1 };
                }
                i += 1;
                strings.push((start, i.min(json.len())));
            }
            b'-' | b'0'..=b'9' => {
                let start = i;
                while i < json.len()
                    && matches!(json[i], b'-' | b'+' | b'.' | b'e' | b'E' | b'0'..=b'9')
                {
                    i += 1;
                }
                numbers.push((start, i));
            }
            _ => i += 1,
        }
    }
    (numbers, strings)
}

/// A `.glb`'s JSON chunk and binary chunk (the seeds are well formed).
fn split_glb(glb: &[u8]) -> (Vec<u8>, Vec<u8>) {
    let u32_at = |at: usize| u32::from_le_bytes(glb[at..at + 4].try_into().unwrap()) as usize;
    let json_len = u32_at(12);
    let json = glb[20..20 + json_len].to_vec();
    let bin_at = 20 + json_len;
    let bin_len = u32_at(bin_at);
    (json, glb[bin_at + 8..bin_at + 8 + bin_len].to_vec())
}

/// A `.glb` of these chunks, each padded to 4 bytes and every length right.
fn join_glb(json: &[u8], bin: &[u8]) -> Vec<u8> {
    let mut json = json.to_vec();
    json.resize(json.len().next_multiple_of(4), b' ');
    let mut bin = bin.to_vec();
    bin.resize(bin.len().next_multiple_of(4), 0);
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    for n in [2, total] {
        out.extend_from_slice(&(n as u32).to_le_bytes());
    }
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}

/// The byte-level copies of `seed`: flips, insertions, cuts.
fn byte_mutants(seed: &[u8], rng: &mut Rng) -> Vec<Mutant> {
    let mut out = Vec::new();
    for _ in 0..FLIPS {
        let at = rng.below(seed.len());
        let special = [0x00, 0xff, 0x7f, 0x80];
        let (how, byte) = match rng.below(3) {
            0 => {
                let v = special[rng.below(special.len())];
                (format!("byte {at} = {v:#04x}"), v)
            }
            _ => {
                let x = 1u8 << rng.below(8);
                (format!("byte {at} ^= {x:#04x}"), seed[at] ^ x)
            }
        };
        let mut bytes = seed.to_vec();
        bytes[at] = byte;
        out.push(Mutant { how, bytes });
    }
    for _ in 0..INSERTS {
        let at = rng.below(seed.len() + 1);
        let v = rng.next() as u8;
        let mut bytes = seed.to_vec();
        bytes.insert(at, v);
        out.push(Mutant {
            how: format!("{v:#04x} inserted at byte {at}"),
            bytes,
        });
    }
    for at in (0..seed.len()).step_by(CUT_EVERY) {
        out.push(Mutant {
            how: format!("cut at byte {at}"),
            bytes: seed[..at].to_vec(),
        });
    }
    out
}

/// The JSON-level copies of a document: each number and each string replaced in turn;
/// `wrap` makes the file of a changed JSON text.
fn json_mutants(json: &[u8], wrap: &dyn Fn(&[u8]) -> Vec<u8>) -> Vec<Mutant> {
    let (numbers, strings) = tokens(json);
    let mut out = Vec::new();
    let cases = numbers
        .iter()
        .flat_map(|r| NUMBERS.iter().map(move |w| (r, w)))
        .chain(
            strings
                .iter()
                .flat_map(|r| STRINGS.iter().map(move |w| (r, w))),
        );
    for (&(start, end), with) in cases {
        let mut text = json[..start].to_vec();
        text.extend_from_slice(with.as_bytes());
        text.extend_from_slice(&json[end..]);
        let was = String::from_utf8_lossy(&json[start..end]);
        let was: String = was.chars().take(40).collect();
        out.push(Mutant {
            how: format!("JSON bytes {start}..{end} ({was}) replaced by {with}"),
            bytes: wrap(&text),
        });
    }
    out
}

/// What is wrong with loading `m`, if anything: a panic, a multi-line or empty error, an
/// error not naming the file, a scene without polygons or with patches of no finite area.
fn check(name: &str, m: &Mutant) -> Option<String> {
    let outcome = catch_unwind(AssertUnwindSafe(|| {
        match load_gltf_from_slice(name, &m.bytes, None, &LoadOptions::default()) {
            Ok(scene) => {
                if scene.polygons.is_empty() {
                    return Some("a scene without polygons".to_string());
                }
                let opts = MeshOptions::default();
                if mesh::rough_patch_count(&scene, &opts) <= MAX_PATCHES {
                    match mesh::try_build(&scene, &opts) {
                        Ok(mesh) if mesh.patches.iter().all(|p| p.area.is_finite()) => None,
                        Ok(_) => Some("a patch of no finite area".to_string()),
                        Err(e) => Some(format!("under the patch cap, yet not meshed: {e}")),
                    }
                } else {
                    None
                }
            }
            Err(e) => {
                let line = e.to_string();
                if line.contains('\n') || line.contains('\r') {
                    Some(format!("a multi-line error: {line:?}"))
                } else if !line.starts_with(&format!("{name}: ")) || line.len() <= name.len() + 2 {
                    Some(format!("an error not of the form 'FILE: what': {line:?}"))
                } else {
                    None
                }
            }
        }
    }));
    let problem = match outcome {
        Ok(problem) => problem?,
        Err(panic) => {
            let what = panic
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            format!("a panic: {what}")
        }
    };
    Some(format!("{name}, {}: {problem}", m.how))
}

fn corpus_file(name: &str) -> Vec<u8> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/corpus")
        .join(name);
    std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn broken_copies_of_the_valid_gltf_models_load_or_fail_in_one_line() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let glb = corpus_file("odd-gltf-room.glb");
    let gltf = corpus_file("odd-gltf-room-data-uri.gltf");
    let (json, bin) = split_glb(&glb);
    assert_eq!(
        join_glb(&json, &bin),
        glb,
        "the .glb seed is not as join_glb writes it"
    );

    let mut mutants: Vec<(&str, Mutant)> = Vec::new();
    for m in byte_mutants(&glb, &mut rng) {
        mutants.push(("mutant.glb", m));
    }
    for m in json_mutants(&json, &|j| join_glb(j, &bin)) {
        mutants.push(("mutant.glb", m));
    }
    for m in byte_mutants(&gltf, &mut rng) {
        mutants.push(("mutant.gltf", m));
    }
    for m in json_mutants(&gltf, &|j| j.to_vec()) {
        mutants.push(("mutant.gltf", m));
    }
    assert!(mutants.len() > 3000, "only {} copies", mutants.len());

    let failures: Vec<String> = mutants.iter().filter_map(|(n, m)| check(n, m)).collect();
    let shown: Vec<&str> = failures.iter().take(20).map(String::as_str).collect();
    assert!(
        failures.is_empty(),
        "{} of {} copies failed (first 20 shown):\n{}",
        failures.len(),
        mutants.len(),
        shown.join("\n")
    );
}
