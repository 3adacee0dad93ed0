//! Arbitrary bytes through the readers of the two binary files in `radiosity::container`: the
//! saved solution (`solve --save`) and the checkpoint (`solve --checkpoint`). Each must give a
//! value or a one-line error, never a panic; a checkpoint read writes bytes that read again.

#![no_main]

use libfuzzer_sys::fuzz_target;
use radiosity::export::solution::SavedSolution;
use radiosity::solve::checkpoint::Checkpoint;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    if let Err(e) = SavedSolution::from_bytes(Path::new("fuzz.rad"), data) {
        assert!(!e.to_string().contains('\n'), "a multi-line error: {e}");
    }
    match Checkpoint::from_bytes("fuzz.ckpt", data) {
        Ok(c) => {
            let again = c.to_bytes();
            assert!(Checkpoint::from_bytes("fuzz.ckpt", &again).is_ok());
        }
        Err(e) => assert!(!e.contains('\n'), "a multi-line error: {e}"),
    }
});
