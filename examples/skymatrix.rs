//! The tool's sky vectors for a few hours, for `scripts/radiance/skymatrix.py` to compare with
//! Radiance's `gendaymtx`. Not part of the tool.
//!
//! ```text
//! cargo run --release --example skymatrix -- LAT LON_EAST UTC_OFFSET MF [separate] [integrated] [noaa]
//! ```
//!
//! reads `month day hour dni dhi` lines (a `.wea` file's data lines) on stdin and writes one
//! line per hour: the radiances (W/sr/m², ground first) separated by spaces. `separate` keeps
//! the sun out of the patches (its direct normal illuminance, lux, then ends the line),
//! `integrated` integrates the Perez sky over each patch, `noaa` places the sun by the tool's
//! NOAA algorithm instead of `gendaymtx`'s formulas.

use radiosity::sky::matrix::{Hour, Sampling, SkyOptions, SkyVectors, SunMode};
use radiosity::sky::{DateTime, Site};
use std::io::BufRead;

fn main() {
    if let Err(e) = run() {
        eprintln!("skymatrix: {e}");
        std::process::exit(2);
    }
}

fn run() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let num = |i: usize| -> Result<f64, String> {
        let a = args
            .get(i)
            .ok_or("usage: LAT LON_EAST UTC_OFFSET MF [separate] [integrated] [noaa]")?;
        a.parse().map_err(|_| format!("not a number: {a}"))
    };
    let site = Site::new(num(0)?, num(1)?).map_err(|e| e.0)?;
    let utc_offset = num(2)?;
    let flag = |f: &str| args.iter().skip(4).any(|a| a == f);
    let options = SkyOptions {
        subdivision: num(3)? as u32,
        sun: if flag("separate") {
            SunMode::Separate
        } else {
            SunMode::InPatches
        },
        sampling: if flag("integrated") {
            Sampling::Integrated
        } else {
            Sampling::Centre
        },
        ..SkyOptions::default()
    };
    let vectors = SkyVectors::new(options).map_err(|e| e.0)?;
    for line in std::io::stdin().lock().lines() {
        let line = line.map_err(|e| e.to_string())?;
        let f: Vec<f64> = line
            .split_whitespace()
            .filter_map(|x| x.parse().ok())
            .collect();
        let [month, day, hour, dni, dhi] = f[..] else {
            continue;
        };
        let (month, day) = (month as u32, day as u32);
        let h = if flag("noaa") {
            let minutes = (hour * 60.0).round() as u32;
            let time = DateTime {
                year: 2026,
                month,
                day,
                hour: minutes / 60,
                minute: minutes % 60,
                second: 0.0,
                utc_offset,
            };
            Hour::at(&site, &time, dni, dhi)
        } else {
            Hour::gendaymtx(&site, utc_offset, month, day, hour, dni, dhi)
        }
        .map_err(|e| e.0)?;
        let v = vectors.hour(&h).map_err(|e| e.0)?;
        let mut out: Vec<String> = v.radiance.iter().map(|x| format!("{x:e}")).collect();
        if options.sun == SunMode::Separate {
            out.push(format!("{:e}", v.sun.map_or(0.0, |s| s.normal_illuminance)));
        }
        println!("{}", out.join(" "));
    }
    Ok(())
}
