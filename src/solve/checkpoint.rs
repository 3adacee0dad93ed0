//! Checkpoints of a shooting solve (`--checkpoint FILE`, `--resume FILE`).
//!
//! A shooting solve passes a *safe point* every [`SYNC_WAVES`] waves (and before its first):
//! the wave in flight is applied there, so the books hold everything and nothing is cast. Safe
//! points come at the same waves whether or not anyone checkpoints, so a run resumed from one
//! continues exactly as the uninterrupted run did: same shooters in the same order, same random
//! numbers (they depend on the seed and the shot number only), same result. This holds for
//! `adaptive-hybrid` too: its switch is decided from counted work (the work counted so far is
//! in the header); only with `--switch-by measured` does it depend on times no run repeats.
//!
//! The file: an 8-byte magic, a format version (u32), the payload's length (u64) and its CRC-32
//! (u32), then the payload: a JSON header (settings key, counters, trace) behind its length,
//! then the per-patch arrays as little-endian f64. A file from another scene or other settings
//! (the key differs), a newer version, a wrong magic, a short or damaged file are refused with
//! one line naming the file.

use super::{EnergyBalance, SwitchInfo, TracePoint};
use serde::{Deserialize, Serialize};
use std::sync::Arc;
use std::time::Duration;

/// Waves between safe points.
pub const SYNC_WAVES: u64 = 8;
const MAGIC: &[u8; 8] = b"RADCKPT\0";
pub const VERSION: u32 = 1;

/// Writes one snapshot somewhere; an error is one line.
pub type WriteFn = dyn Fn(&Snapshot) -> Result<(), String> + Send + Sync;

/// Where checkpoints go: a writer called with each snapshot (the pipeline writes the file
/// atomically), and how often.
#[derive(Clone)]
pub struct Sink {
    pub every: Duration,
    /// What a resumed run must match (the scene and the settings); stored in every snapshot.
    pub key: String,
    pub write: Arc<WriteFn>,
}

impl std::fmt::Debug for Sink {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Sink {{ every: {:?} }}", self.every)
    }
}

/// Counters and small state, stored as JSON.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Header {
    /// What the run must match to resume: the scene and the settings that shape the result.
    pub key: String,
    pub patches: usize,
    pub elapsed: f64,
    pub energy: EnergyBalance,
    pub b_flux: [f64; 3],
    pub rays: u64,
    pub cells: u64,
    pub shot_flux: f64,
    pub shots: u64,
    pub waves: u64,
    pub hemicube_shots: u64,
    pub hemicube_cells: u64,
    pub energy_per_ray: f64,
    pub switch: Option<SwitchInfo>,
    /// Hemi-cube shots still to come (the hemi-cube methods, or the hybrid before switching).
    pub cubes_active: bool,
    /// `--switch-by measured`: the sums of the fit of hemi-cube shot times, and the measured
    /// seconds per ray (see [`super::switch`]).
    pub cube_cost: [f64; 5],
    pub ray_cost: Option<f64>,
    /// `adaptive-hybrid`: the hemi-cube shots' counted work so far (see [`super::switch`]).
    #[serde(default)]
    pub cube_work: super::switch::WorkTally,
    pub trace: Vec<TracePoint>,
    /// Lengths of the arrays that follow.
    pub cube_len: usize,
    pub channels: usize,
}

/// Everything a solve needs to continue.
#[derive(Clone, Debug, Default)]
pub struct Snapshot {
    pub header: Header,
    pub unshot: Vec<[f64; 3]>,
    pub gathered: Vec<[f64; 3]>,
    pub cube_gathered: Vec<f64>,
    pub cube_var: Vec<f64>,
    /// Per-light channels, `channels` per patch side by side.
    pub ch_unshot: Vec<[f64; 3]>,
    pub ch_gathered: Vec<[f64; 3]>,
}

fn put3(out: &mut Vec<u8>, v: &[[f64; 3]]) {
    for x in v.iter().flatten() {
        out.extend_from_slice(&x.to_le_bytes());
    }
}

fn put1(out: &mut Vec<u8>, v: &[f64]) {
    for x in v {
        out.extend_from_slice(&x.to_le_bytes());
    }
}

impl Snapshot {
    /// The file's bytes.
    pub fn to_bytes(&self) -> Vec<u8> {
        let json = serde_json::to_vec(&self.header).expect("plain data serialises");
        let mut payload = Vec::new();
        payload.extend_from_slice(&(json.len() as u64).to_le_bytes());
        payload.extend_from_slice(&json);
        put3(&mut payload, &self.unshot);
        put3(&mut payload, &self.gathered);
        put1(&mut payload, &self.cube_gathered);
        put1(&mut payload, &self.cube_var);
        put3(&mut payload, &self.ch_unshot);
        put3(&mut payload, &self.ch_gathered);
        let mut out = Vec::with_capacity(payload.len() + 24);
        out.extend_from_slice(MAGIC);
        out.extend_from_slice(&VERSION.to_le_bytes());
        out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
        out.extend_from_slice(&crc32fast::hash(&payload).to_le_bytes());
        out.extend_from_slice(&payload);
        out
    }

    /// Reads a checkpoint; `what` names the file in messages.
    pub fn from_bytes(what: &str, bytes: &[u8]) -> Result<Snapshot, String> {
        let bad = |m: &str| format!("{what}: {m}");
        if bytes.len() < 24 || &bytes[..8] != MAGIC {
            return Err(
                if bytes.starts_with(&MAGIC[..bytes.len().min(8)]) && bytes.len() < 24 {
                    bad("truncated checkpoint (shorter than its header)")
                } else {
                    bad("not a radiosity checkpoint")
                },
            );
        }
        let version = u32::from_le_bytes(bytes[8..12].try_into().expect("4 bytes"));
        if version != VERSION {
            return Err(bad(&format!(
                "checkpoint format version {version}; this radiosity reads version {VERSION}"
            )));
        }
        let len = u64::from_le_bytes(bytes[12..20].try_into().expect("8 bytes")) as usize;
        let crc = u32::from_le_bytes(bytes[20..24].try_into().expect("4 bytes"));
        let payload = &bytes[24..];
        if payload.len() < len {
            return Err(bad(&format!(
                "truncated checkpoint ({} of {len} bytes)",
                payload.len()
            )));
        }
        let payload = &payload[..len];
        if crc32fast::hash(payload) != crc {
            return Err(bad("damaged checkpoint (checksum mismatch)"));
        }
        let mut at = 0usize;
        let mut take = |n: usize| -> Result<&[u8], String> {
            let s = payload
                .get(at..at + n)
                .ok_or_else(|| bad("damaged checkpoint (sections overrun)"))?;
            at += n;
            Ok(s)
        };
        let jl = u64::from_le_bytes(take(8)?.try_into().expect("8 bytes")) as usize;
        let header: Header = serde_json::from_slice(take(jl)?)
            .map_err(|e| bad(&format!("damaged checkpoint header ({e})")))?;
        let f64s = |b: &[u8]| -> Vec<f64> {
            b.chunks_exact(8)
                .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
                .collect()
        };
        let mut take3 = |count: usize| -> Result<Vec<[f64; 3]>, String> {
            let v = f64s(take(count * 24)?);
            Ok(v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
        };
        let n = header.patches;
        let unshot = take3(n)?;
        let gathered = take3(n)?;
        let mut snap = Snapshot {
            unshot,
            gathered,
            ..Snapshot::default()
        };
        let rest = &payload[at..];
        let (cl, ch) = (header.cube_len, header.channels * n);
        if rest.len() != (2 * cl + 6 * ch) * 8 {
            return Err(bad("damaged checkpoint (array lengths disagree)"));
        }
        let all = f64s(rest);
        snap.cube_gathered = all[..cl].to_vec();
        snap.cube_var = all[cl..2 * cl].to_vec();
        let three = |v: &[f64]| v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        snap.ch_unshot = three(&all[2 * cl..2 * cl + 3 * ch]);
        snap.ch_gathered = three(&all[2 * cl + 3 * ch..]);
        if snap
            .unshot
            .iter()
            .chain(&snap.gathered)
            .flatten()
            .any(|x| !x.is_finite())
        {
            return Err(bad("damaged checkpoint (a value is not finite)"));
        }
        snap.header = header;
        Ok(snap)
    }

    /// Refuses a checkpoint written for another scene or other settings.
    pub fn check_key(&self, what: &str, key: &str) -> Result<(), String> {
        if self.header.key != key {
            return Err(format!(
                "{what}: this checkpoint was written by another run (scene or settings differ: it has {}, this run has {key}); resume with the same scene, --patch-size, --method, --seed and sampling flags",
                self.header.key
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Snapshot {
        Snapshot {
            header: Header {
                key: "k".into(),
                patches: 2,
                shots: 7,
                cube_len: 2,
                channels: 1,
                trace: vec![TracePoint::default()],
                ..Header::default()
            },
            unshot: vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]],
            gathered: vec![[0.5; 3], [0.25; 3]],
            cube_gathered: vec![1.0, 2.0],
            cube_var: vec![3.0, 4.0],
            ch_unshot: vec![[1.0; 3], [2.0; 3]],
            ch_gathered: vec![[3.0; 3], [4.0; 3]],
        }
    }

    #[test]
    fn round_trips() {
        let s = sample();
        let b = s.to_bytes();
        let r = Snapshot::from_bytes("x", &b).unwrap();
        assert_eq!(r.to_bytes(), b);
        assert_eq!(r.unshot, s.unshot);
        assert_eq!(r.ch_gathered, s.ch_gathered);
        assert_eq!(r.header.shots, 7);
    }

    #[test]
    fn refuses_bad_files() {
        let b = sample().to_bytes();
        let msg = |bytes: &[u8]| Snapshot::from_bytes("f.ckpt", bytes).unwrap_err();
        assert!(msg(&b[..b.len() - 5]).contains("truncated"));
        assert!(msg(&b[..10]).contains("truncated"));
        assert!(msg(b"hello world, not a checkpoint").contains("not a radiosity checkpoint"));
        let mut flipped = b.clone();
        let last = flipped.len() - 1;
        flipped[last] ^= 1;
        assert!(msg(&flipped).contains("damaged"));
        let mut newer = b.clone();
        newer[8] = 9;
        assert!(msg(&newer).contains("version 9"));
        let s = Snapshot::from_bytes("f.ckpt", &b).unwrap();
        assert!(s
            .check_key("f.ckpt", "other")
            .unwrap_err()
            .contains("another run"));
    }
}
