//! Checkpoints of a shooting solve (`--checkpoint FILE`, `--resume FILE`): the file that holds
//! a run's saved state. This module only lays the state out; each part of the solver saves and
//! restores its own: the driver ([`driver::Saved`]: counters and trace), the books
//! ([`books::Saved`]) and the hybrid's switch policy ([`switch::Saved`]).
//!
//! A shooting solve passes a *safe point* every [`driver::SYNC_WAVES`] waves (and before its
//! first): the wave in flight is applied there, so the books hold everything and nothing is
//! cast. Safe points come at the same waves whether or not anyone checkpoints, so a run resumed
//! from one continues exactly as the uninterrupted run did: same shooters in the same order,
//! same random numbers (they depend on the seed and the shot number only), same result. This
//! holds for `adaptive-hybrid` too: its switch is decided from counted work (the work counted
//! so far is in the header); only with `--switch-by measured` does it depend on times no run
//! repeats.
//!
//! The file: the [`crate::container`] without reserved words — an 8-byte magic, a format
//! version (u32), the payload's length (u64) and its CRC-32 (u32) — then the payload: a JSON
//! header (`Header`: settings key, counters, trace) behind its length (u64), then the
//! per-patch arrays as little-endian f64: unshot and kept flux (× 3 per patch), the hemi-cube
//! share of the kept flux and its variance (`cube_len` each), the light channels' unshot and
//! kept flux (× 3, `channels` per patch). A file from another scene or other settings (the key
//! differs), a newer version, a wrong magic, a short or damaged file are refused with one line
//! naming the file.

use super::{books, driver, switch, EnergyBalance, SwitchInfo, TracePoint};
use crate::container::{Container, Cursor, Put, Refusal};
use serde::{Deserialize, Serialize};

const CONTAINER: Container = Container {
    magic: *b"RADCKPT\0",
    reserved_words: false,
};
pub const VERSION: u32 = 1;

/// A checkpoint: a run's saved state, and the key a run resuming from it must match.
#[derive(Clone, Debug, Default)]
pub struct Checkpoint {
    /// What the run must match to resume: the scene and the settings that shape the result.
    pub key: String,
    pub run: driver::Saved,
}

/// The JSON header: the counters and small state of the parts, in the file's order (the field
/// names and their order are the format; the parts' own types are not).
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
struct Header {
    key: String,
    patches: usize,
    elapsed: f64,
    energy: EnergyBalance,
    b_flux: [f64; 3],
    rays: u64,
    cells: u64,
    shot_flux: f64,
    shots: u64,
    waves: u64,
    hemicube_shots: u64,
    hemicube_cells: u64,
    energy_per_ray: f64,
    switch: Option<SwitchInfo>,
    cubes_active: bool,
    cube_cost: [f64; 5],
    ray_cost: Option<f64>,
    /// Absent in files written before the counted switch.
    #[serde(default)]
    cube_work: WorkTally,
    trace: Vec<TracePoint>,
    /// Lengths of the arrays that follow.
    cube_len: usize,
    channels: usize,
}

/// [`switch::WorkTally`] as the header keeps it.
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize)]
struct WorkTally {
    shots: u64,
    faces: u64,
    cells: u64,
    tested: u64,
}

/// The file's bytes for `run`, with `key` (a [`Checkpoint`]'s, without building one).
pub fn to_bytes(key: &str, run: &driver::Saved) -> Vec<u8> {
    let (b, s) = (&run.books, &run.switch);
    let t = s.tally;
    let header = Header {
        key: key.to_string(),
        patches: b.unshot.len(),
        elapsed: run.elapsed,
        energy: b.energy,
        b_flux: b.b_flux,
        rays: b.rays,
        cells: b.cells,
        shot_flux: b.shot_flux,
        shots: run.shots,
        waves: run.waves,
        hemicube_shots: run.hemicube_shots,
        hemicube_cells: run.hemicube_cells,
        energy_per_ray: run.energy_per_ray,
        switch: run.switched,
        cubes_active: run.cubes_active,
        cube_cost: s.cube_cost,
        ray_cost: s.ray_cost,
        cube_work: WorkTally {
            shots: t.shots,
            faces: t.faces,
            cells: t.cells,
            tested: t.tested,
        },
        trace: run.trace.clone(),
        cube_len: b.cube_kept.len(),
        channels: b.channels,
    };
    let json = serde_json::to_vec(&header).expect("plain data serialises");
    let mut payload = Vec::new();
    payload.put_u64(json.len() as u64);
    payload.extend_from_slice(&json);
    payload.put_f64x3s(&b.unshot);
    payload.put_f64x3s(&b.kept);
    payload.put_f64s(&b.cube_kept);
    payload.put_f64s(&b.cube_var);
    payload.put_f64x3s(&b.ch_unshot);
    payload.put_f64x3s(&b.ch_kept);
    CONTAINER.wrap(VERSION, &payload)
}

impl Checkpoint {
    /// The file's bytes.
    pub fn to_bytes(&self) -> Vec<u8> {
        to_bytes(&self.key, &self.run)
    }

    /// Reads a checkpoint; `what` names the file in messages.
    pub fn from_bytes(what: &str, bytes: &[u8]) -> Result<Checkpoint, String> {
        let bad = |m: &str| format!("{what}: {m}");
        let refused = |r: Refusal| match r {
            Refusal::Foreign => bad("not a radiosity checkpoint"),
            Refusal::ShortHeader { .. } => bad("truncated checkpoint (shorter than its header)"),
            Refusal::Truncated { have, want } => {
                bad(&format!("truncated checkpoint ({have} of {want} bytes)"))
            }
            Refusal::Checksum => bad("damaged checkpoint (checksum mismatch)"),
        };
        let header = CONTAINER.header(bytes).map_err(refused)?;
        if header.version != VERSION {
            return Err(bad(&format!(
                "checkpoint format version {}; this radiosity reads version {VERSION}",
                header.version
            )));
        }
        let (payload, _) = CONTAINER.payload(bytes, &header).map_err(refused)?;
        let overrun = |_| bad("damaged checkpoint (sections overrun)");
        let mut c = Cursor::new(payload);
        let json_len = c.u64().map_err(overrun)?;
        let json = c
            .take(usize::try_from(json_len).unwrap_or(usize::MAX))
            .map_err(overrun)?;
        let h: Header = serde_json::from_slice(json)
            .map_err(|e| bad(&format!("damaged checkpoint header ({e})")))?;
        let n = h.patches;
        let unshot = c.f64x3s(n).map_err(overrun)?;
        let kept = c.f64x3s(n).map_err(overrun)?;
        let (cl, ch) = (h.cube_len, h.channels.checked_mul(n));
        let rest = ch.and_then(|ch| {
            let f64s = cl.checked_mul(2)?.checked_add(ch.checked_mul(6)?)?;
            f64s.checked_mul(8)
        });
        let disagree = || bad("damaged checkpoint (array lengths disagree)");
        if rest != Some(c.rest().len()) {
            return Err(disagree());
        }
        let ch = ch.unwrap_or_default();
        let books = books::Saved {
            energy: h.energy,
            b_flux: h.b_flux,
            rays: h.rays,
            cells: h.cells,
            shot_flux: h.shot_flux,
            cube_kept: c.f64s(cl).map_err(|_| disagree())?,
            cube_var: c.f64s(cl).map_err(|_| disagree())?,
            channels: h.channels,
            ch_unshot: c.f64x3s(ch).map_err(|_| disagree())?,
            ch_kept: c.f64x3s(ch).map_err(|_| disagree())?,
            unshot,
            kept,
        };
        if books
            .unshot
            .iter()
            .chain(&books.kept)
            .flatten()
            .any(|x| !x.is_finite())
        {
            return Err(bad("damaged checkpoint (a value is not finite)"));
        }
        let t = h.cube_work;
        let switch = switch::Saved {
            tally: switch::WorkTally {
                shots: t.shots,
                faces: t.faces,
                cells: t.cells,
                tested: t.tested,
            },
            cube_cost: h.cube_cost,
            ray_cost: h.ray_cost,
        };
        let run = driver::Saved {
            elapsed: h.elapsed,
            energy_per_ray: h.energy_per_ray,
            shots: h.shots,
            waves: h.waves,
            hemicube_shots: h.hemicube_shots,
            hemicube_cells: h.hemicube_cells,
            switched: h.switch,
            cubes_active: h.cubes_active,
            trace: h.trace,
            books,
            switch,
        };
        Ok(Checkpoint { key: h.key, run })
    }

    /// Refuses a checkpoint written for another scene or other settings.
    pub fn check_key(&self, what: &str, key: &str) -> Result<(), String> {
        if self.key != key {
            return Err(format!(
                "{what}: this checkpoint was written by another run (scene or settings differ: it has {}, this run has {key}); resume with the same scene, --patch-size, --method, --seed and sampling flags",
                self.key
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The state `testdata/sample-v1.ckpt` was written from (before the checkpoint moved into
    /// [`crate::container`] and its parts into their owners).
    fn sample() -> Checkpoint {
        Checkpoint {
            key: "k".into(),
            run: driver::Saved {
                shots: 7,
                trace: vec![TracePoint::default()],
                switched: Some(SwitchInfo {
                    shot: 3,
                    rays: 9,
                    ..SwitchInfo::default()
                }),
                books: books::Saved {
                    unshot: vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]],
                    kept: vec![[0.5; 3], [0.25; 3]],
                    cube_kept: vec![1.0, 2.0],
                    cube_var: vec![3.0, 4.0],
                    channels: 1,
                    ch_unshot: vec![[1.0; 3], [2.0; 3]],
                    ch_kept: vec![[3.0; 3], [4.0; 3]],
                    ..books::Saved::default()
                },
                switch: switch::Saved {
                    tally: switch::WorkTally {
                        shots: 1,
                        faces: 2,
                        cells: 3,
                        tested: 4,
                    },
                    cube_cost: [1.0, 2.0, 3.0, 4.0, 5.0],
                    ray_cost: Some(0.5),
                },
                ..driver::Saved::default()
            },
        }
    }

    #[test]
    fn round_trips() {
        let s = sample();
        let b = s.to_bytes();
        let r = Checkpoint::from_bytes("x", &b).unwrap();
        assert_eq!(r.to_bytes(), b);
        assert_eq!(r.run.books.unshot, s.run.books.unshot);
        assert_eq!(r.run.books.ch_kept, s.run.books.ch_kept);
        assert_eq!(r.run.switch, s.run.switch);
        assert_eq!(r.run.shots, 7);
    }

    /// A file written before reads, and the same state writes the same bytes.
    #[test]
    fn a_file_written_before_reads_and_writes_the_same() {
        let old: &[u8] = include_bytes!("testdata/sample-v1.ckpt");
        assert_eq!(sample().to_bytes(), old);
        let r = Checkpoint::from_bytes("old.ckpt", old).unwrap();
        assert_eq!(r.key, "k");
        assert_eq!(r.run.switch, sample().run.switch);
        assert_eq!(r.run.books.kept, sample().run.books.kept);
        assert_eq!(r.to_bytes(), old);
    }

    #[test]
    fn refuses_bad_files() {
        let b = sample().to_bytes();
        let msg = |bytes: &[u8]| Checkpoint::from_bytes("f.ckpt", bytes).unwrap_err();
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
        for k in 0..b.len() {
            assert!(
                Checkpoint::from_bytes("f.ckpt", &b[..k]).is_err(),
                "cut at {k}"
            );
        }
        let s = Checkpoint::from_bytes("f.ckpt", &b).unwrap();
        assert!(s
            .check_key("f.ckpt", "other")
            .unwrap_err()
            .contains("another run"));
    }
}
