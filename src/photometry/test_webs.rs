//! Webs the photometry tests build: an LM-63-2002 text of given angles and candela, read back.

use super::{parse_ies, Photometry};

/// An LM-63-2002 file of photometric type `kind` (1 = C, 2 = B, 3 = A) with the given angles
/// and candela planes (one per horizontal angle), read back.
pub(super) fn ies(
    kind: u8,
    vertical: &[f64],
    horizontal: &[f64],
    planes: &[Vec<f64>],
) -> Photometry {
    let join = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{x}"))
            .collect::<Vec<_>>()
            .join(" ")
    };
    let mut text = format!(
        "IESNA:LM-63-2002\n[TEST] web\nTILT=NONE\n1 -1 1 {} {} {kind} 2 0 0 0\n1 1 0\n{}\n{}\n",
        vertical.len(),
        horizontal.len(),
        join(vertical),
        join(horizontal)
    );
    for p in planes {
        text.push_str(&join(p));
        text.push('\n');
    }
    parse_ies(&text, "web.ies").unwrap()
}

/// `lo, lo + step, …, hi`.
pub(super) fn steps(lo: f64, hi: f64, step: f64) -> Vec<f64> {
    let n = ((hi - lo) / step).round() as usize;
    (0..=n).map(|k| lo + step * k as f64).collect()
}
