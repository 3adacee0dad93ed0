//! Where polygons go: formatted into the OBJ when there is one, and counted always (patches
//! as the mesher cuts them, areas axial and skew, lights).

use super::materials::Mat;
use super::mm_to_m;
use glam::Vec3;
use std::io::{self, BufWriter, Write};

pub(super) type P3 = [i64; 3];

/// Where polygons go: formatted into the OBJ (when there is one) and counted always.
pub(super) struct Out<'w> {
    pub(super) obj: Option<BufWriter<&'w mut dyn Write>>,
    pub(super) line: Vec<u8>,
    pub(super) mat: Option<Mat>,
    pub(super) vertices: u64,
    pub(super) polygons: u64,
    pub(super) patches: u64,
    pub(super) lights: u64,
    /// Areas so far, m².
    pub(super) axial: f64,
    pub(super) skew: f64,
    pub(super) size: f32,
}

impl Out<'_> {
    pub(super) fn raw(&mut self, text: &str) -> io::Result<()> {
        match &mut self.obj {
            Some(w) => w.write_all(text.as_bytes()),
            None => Ok(()),
        }
    }

    /// Starts a named object (and forgets the material, so the next face names it again).
    pub(super) fn object(&mut self, name: &str) -> io::Result<()> {
        self.mat = None;
        if self.obj.is_some() {
            self.raw(&format!("\no {name}\n"))?;
        }
        Ok(())
    }

    /// One planar convex polygon, wound so that its front faces `toward`.
    pub(super) fn poly(&mut self, mat: Mat, pts: &[P3], toward: [f64; 3]) -> io::Result<()> {
        // Newell's normal (exact in f64 for millimetre coordinates of this size).
        let mut n = [0.0f64; 3];
        for k in 0..pts.len() {
            let (a, b) = (pts[k], pts[(k + 1) % pts.len()]);
            let (a, b) = (a.map(|c| c as f64), b.map(|c| c as f64));
            n[0] += (a[1] - b[1]) * (a[2] + b[2]);
            n[1] += (a[2] - b[2]) * (a[0] + b[0]);
            n[2] += (a[0] - b[0]) * (a[1] + b[1]);
        }
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        if len == 0.0 {
            return Ok(());
        }
        let flip = n[0] * toward[0] + n[1] * toward[1] + n[2] * toward[2] < 0.0;
        let mut buf = [[0i64; 3]; 4];
        let pts: &[P3] = if flip {
            for (k, p) in pts.iter().rev().enumerate() {
                buf[k] = *p;
            }
            &buf[..pts.len()]
        } else {
            pts
        };
        let area = len * 0.5 * 1e-6;
        let axial = (0..3).any(|a| pts.iter().all(|p| p[a] == pts[0][a]));
        if axial {
            self.axial += area;
        } else {
            self.skew += area;
        }
        self.polygons += 1;
        self.patches += estimate_patches(pts, self.size);
        if mat == Mat::Light {
            self.lights += 1;
        }
        if let Some(w) = &mut self.obj {
            let line = &mut self.line;
            line.clear();
            if self.mat != Some(mat) {
                line.extend_from_slice(b"usemtl ");
                line.extend_from_slice(mat.spec().0.as_bytes());
                line.push(b'\n');
            }
            for p in pts {
                line.push(b'v');
                for &c in p {
                    line.push(b' ');
                    push_mm(line, c);
                }
                line.push(b'\n');
            }
            line.push(b'f');
            for k in 0..pts.len() as u64 {
                line.push(b' ');
                push_uint(line, self.vertices + k + 1);
            }
            line.push(b'\n');
            w.write_all(line)?;
        }
        self.mat = Some(mat);
        self.vertices += pts.len() as u64;
        Ok(())
    }
}

pub(super) fn push_uint(buf: &mut Vec<u8>, mut v: u64) {
    let mut digits = [0u8; 20];
    let mut k = digits.len();
    loop {
        k -= 1;
        digits[k] = b'0' + (v % 10) as u8;
        v /= 10;
        if v == 0 {
            break;
        }
    }
    buf.extend_from_slice(&digits[k..]);
}

/// Millimetres as metres, shortest form: 12345 → "12.345", -200 → "-0.2", 3000 → "3".
pub(super) fn push_mm(buf: &mut Vec<u8>, v: i64) {
    if v < 0 {
        buf.push(b'-');
    }
    let a = v.unsigned_abs();
    push_uint(buf, a / 1000);
    let mut frac = a % 1000;
    if frac != 0 {
        buf.push(b'.');
        let mut div = 100;
        while frac != 0 {
            buf.push(b'0' + (frac / div) as u8);
            frac %= div;
            div /= 10;
        }
    }
}

/// Patches the mesher cuts this polygon into (see the module docs), lengths in f32 as there.
pub(super) fn estimate_patches(pts: &[P3], size: f32) -> u64 {
    let v = |k: usize| Vec3::new(mm_to_m(pts[k][0]), mm_to_m(pts[k][1]), mm_to_m(pts[k][2]));
    let div = |len: f32| ((len / size).ceil() as u64).max(1);
    match pts.len() {
        3 => {
            let longest = (0..3)
                .map(|k| (v((k + 1) % 3) - v(k)).length())
                .fold(0.0, f32::max);
            div(longest).pow(2)
        }
        _ => {
            let u = (v(1) - v(0)).length().max((v(2) - v(3)).length());
            let w = (v(3) - v(0)).length().max((v(2) - v(1)).length());
            div(u) * div(w)
        }
    }
}
