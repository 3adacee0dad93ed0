//! The Reinhart patches, the Perez model and the hour's sky vector: counts, order, tables,
//! normalisation, symmetry and extreme inputs.

use super::*;
use crate::sky::perez::{self, PerezParameters};
use crate::sky::tregenza;
use std::f64::consts::TAU;

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

fn angles(altitude: f64, azimuth: f64) -> SolarAngles {
    SolarAngles::new(altitude, azimuth).unwrap()
}

fn vectors(mf: u32, sun: SunMode, sampling: Sampling) -> SkyVectors {
    SkyVectors::new(SkyOptions {
        subdivision: mf,
        sun,
        sampling,
        ..SkyOptions::default()
    })
    .unwrap()
}

/// Σ L_k × exact projected solid angle over the sky patches (ground excluded), W/m².
fn horizontal(v: &SkyVectors, radiance: &[f64]) -> f64 {
    let sky = &radiance[1..];
    v.patches()
        .iter()
        .zip(sky)
        .map(|(p, l)| l * p.band.projected_solid_angle())
        .sum()
}

#[test]
fn patch_counts_and_solid_angles() {
    for (mf, n) in [(1, 145), (2, 577), (4, 2305)] {
        let p = reinhart::patches(mf).unwrap();
        assert_eq!(p.len(), n);
        assert_eq!(reinhart::sky_patch_count(mf), n);
        assert_eq!(
            vectors(mf, SunMode::InPatches, Sampling::Centre).len(),
            n + 1
        );
        let omega: f64 = p.iter().map(SkyPatch::solid_angle).sum();
        assert!((omega - TAU).abs() < 1e-9, "MF {mf}: {omega}");
        let projected: f64 = p.iter().map(|q| q.band.projected_solid_angle()).sum();
        assert!((projected - PI).abs() < 1e-9, "MF {mf}: {projected}");
        // gendaymtx's own weights, sin(centre altitude) × Ω, within 0.6 % of π (the cap,
        // weighted as if all of it faced the zenith, gives most of it).
        let centred: f64 = p.iter().map(|q| q.cos() * q.solid_angle()).sum();
        assert!(rel(centred, PI) < 6e-3, "MF {mf}: {centred}");
    }
    assert!(reinhart::patches(0).is_err());
    assert!(reinhart::patches(reinhart::MAX_SUBDIVISION + 1).is_err());
}

#[test]
fn tregenza_is_the_first_subdivision() {
    let r = reinhart::patches(1).unwrap();
    for (a, b) in r.iter().zip(tregenza::patches()) {
        assert!((a.band.mu[0] - b.mu[0]).abs() < 1e-12 && (a.band.mu[1] - b.mu[1]).abs() < 1e-12);
        assert!(a.band.is_cap() == b.is_cap());
        if !a.band.is_cap() {
            assert!((a.band.phi[0] - b.phi[0]).abs() < 1e-12);
        }
    }
}

#[test]
fn order_starts_north_on_the_lowest_row_going_east() {
    for mf in [1, 2, 4] {
        let p = reinhart::patches(mf).unwrap();
        let alpha = reinhart::row_height(mf);
        let d0 = p[0].dir();
        assert!(d0.x.abs() < 1e-12 && d0.y > 0.99, "MF {mf}: {d0}");
        assert!((p[0].altitude - alpha / 2.0).abs() < 1e-12);
        assert!(p[1].dir().x > 0.0, "the second patch is east of north");
        let first_row = 30 * mf as usize;
        assert!((p[first_row].altitude - 1.5 * alpha).abs() < 1e-12);
        assert!((p.last().unwrap().dir() - DVec3::Z).length() < 1e-15);
        for (k, q) in p.iter().enumerate() {
            assert_eq!(reinhart::patch_of(mf, q.dir()), Some(k), "MF {mf}");
            assert_eq!(
                reinhart::patch_of(mf, q.band.local_dir(0.02, 0.98)),
                Some(k)
            );
        }
        assert_eq!(reinhart::patch_of(mf, DVec3::new(0.0, 0.6, -0.8)), None);
    }
    // MF 2: rows 6.2069° high, 60 patches in each of the first two.
    let p = reinhart::patches(2).unwrap();
    assert!((reinhart::row_height(2).to_degrees() - 90.0 / 14.5).abs() < 1e-12);
    assert_eq!(p[59].altitude, p[0].altitude);
    assert!(p[60].altitude > p[59].altitude);
}

#[test]
fn coefficient_tables_match_the_papers() {
    let c = &perez::PEREZ_COEFFICIENTS;
    // Perez 1993, table 1: a₁ of bin 1, c₁..c₄ of bin 3, e₄ of bin 8 (erratum values).
    assert_eq!(c[0][0][0], 1.3525);
    assert_eq!(c[2][2], [24.7219, -13.0812, -37.7000, 34.8438]);
    assert_eq!(c[7][4][3], 0.5636);
    assert_eq!(c[0][3], [1.8734, 0.6297, 0.9738, 0.2809]);
    // Perez 1990, table 4.
    assert_eq!(perez::DIFFUSE_EFFICACY[0], [97.24, -0.46, 12.00, -8.91]);
    assert_eq!(perez::DIRECT_EFFICACY[7], [101.18, 1.58, -1.10, -8.29]);
    assert_eq!(perez::clearness_bin(1.0), 0);
    assert_eq!(perez::clearness_bin(1.065), 1);
    assert_eq!(perez::clearness_bin(6.3), 7);
    assert_eq!(perez::clearness_bin(11.9), 7);
}

#[test]
fn clearness_brightness_and_efficacy_by_hand() {
    let z = 30f64.to_radians();
    let kz3 = 1.041 * z.powi(3);
    let eps = perez::clearness(600.0, 100.0, z);
    assert!(rel(eps, (7.0 + kz3) / (1.0 + kz3)) < 1e-12);
    assert_eq!(perez::clearness(0.0, 100.0, z), 1.0);
    assert_eq!(perez::clearness(800.0, 0.0, z), f64::INFINITY);
    // Kasten: m(0) = 1 / (1 + 0.15 · 93.885^−1.253) ≈ 0.99949.
    assert!((perez::air_mass(0.0) - 0.999_49).abs() < 1e-5);
    assert!((perez::precipitable_water(11.0) - 0.695f64.exp()).abs() < 1e-12);
    // Day 1: 1.00011 + 0.034221 + 0.000719.
    assert!((perez::eccentricity(1) - 1.035_05).abs() < 1e-12);
    let sky = PerezSky::new(&perez::PerezInput {
        day_of_year: 172,
        altitude: 60.0,
        azimuth: 180.0,
        dni: 600.0,
        dhi: 100.0,
        dew_point: 11.0,
    })
    .unwrap();
    assert_eq!(sky.bin, 7);
    let delta = 100.0 * perez::air_mass(z) / (1367.0 * perez::eccentricity(172));
    assert!(rel(sky.brightness, delta) < 1e-12);
    let [a, b, c, d] = perez::DIFFUSE_EFFICACY[7];
    let k = a + b * perez::precipitable_water(11.0) + c * z.cos() + d * delta.ln();
    assert!(rel(sky.diffuse_illuminance, 100.0 * k) < 1e-12);
    assert!(sky.direct_illuminance > 600.0 * 80.0 && sky.direct_illuminance < 600.0 * 110.0);
}

#[test]
fn relative_luminance_is_equation_one() {
    let p = PerezParameters::new(3, 1.7, 0.6, 0.25);
    let [a, b, c, d, e] = p.0;
    let (zeta, gamma) = (0.4f64, 0.9f64);
    let lv = (1.0 + a * (b / zeta.cos()).exp())
        * (1.0 + c * (d * gamma).exp() + e * gamma.cos().powi(2));
    assert!(rel(p.relative_luminance(zeta.cos(), gamma), lv) < 1e-14);
    // Eq. 6 for a: a₁ + a₂ Z + Δ (a₃ + a₄ Z).
    let x = perez::PEREZ_COEFFICIENTS[3][0];
    assert!(rel(a, x[0] + x[1] * 0.6 + 0.25 * (x[2] + x[3] * 0.6)) < 1e-14);
    // Bins 2–5 take Δ ≥ 0.2.
    assert_eq!(
        PerezParameters::new(2, 1.3, 0.6, 0.05),
        PerezParameters::new(2, 1.3, 0.6, 0.2)
    );
}

#[test]
fn overcast_hour_carries_the_diffuse_illuminance() {
    let hour = Hour::new(80, angles(35.0, -20.0), 5.0, 180.0);
    for mf in [1, 2, 4] {
        let v = vectors(mf, SunMode::Separate, Sampling::Centre);
        let s = v.hour(&hour).unwrap();
        let e = s.diffuse_illuminance / EFFICACY;
        assert!(e > 0.0);
        assert!(rel(horizontal(&v, &s.radiance), e) < 0.01, "MF {mf}");
        let centred: f64 = v
            .patches()
            .iter()
            .zip(&s.radiance[1..])
            .map(|(p, l)| l * p.cos() * p.solid_angle())
            .sum();
        assert!(rel(centred, e) < 1e-12, "gendaymtx's own sum, MF {mf}");
        let v = vectors(mf, SunMode::Separate, Sampling::Integrated);
        let s = v.hour(&hour).unwrap();
        assert!(rel(horizontal(&v, &s.radiance), e) < 1e-12, "MF {mf}");
    }
}

#[test]
fn ground_and_sun_follow_gendaymtx() {
    let hour = Hour::new(172, angles(50.0, 30.0), 700.0, 120.0);
    let apart = vectors(2, SunMode::Separate, Sampling::Centre)
        .hour(&hour)
        .unwrap();
    let v = vectors(2, SunMode::InPatches, Sampling::Centre);
    let inside = v.hour(&hour).unwrap();
    let sun = apart.sun.unwrap();
    assert!(rel(sun.normal_illuminance, inside.direct_illuminance) < 1e-15);
    let e_h = inside.diffuse_illuminance + sun.normal_illuminance * 50f64.to_radians().sin();
    assert!(rel(inside.radiance[0], 0.2 * e_h / PI / EFFICACY) < 1e-12);
    assert_eq!(inside.radiance[0], apart.radiance[0]);
    // The sun's patches carry its normal irradiance: Σ ΔL Ω = E_s / 179, in 4 patches.
    let added: Vec<(usize, f64)> = (1..v.len())
        .map(|k| (k, inside.radiance[k] - apart.radiance[k]))
        .filter(|&(_, d)| d > 0.0)
        .collect();
    assert_eq!(added.len(), SUN_PATCHES);
    let flux: f64 = added
        .iter()
        .map(|&(k, d)| d * v.patches()[k - 1].solid_angle())
        .sum();
    assert!(rel(flux, sun.normal_irradiance()) < 1e-12);
    let nearest = reinhart::patch_of(2, sun.dir).unwrap();
    assert!(added.iter().any(|&(k, _)| k == nearest + 1));
}

#[test]
fn a_sun_due_south_makes_a_mirror_symmetric_sky() {
    let hour = Hour::new(200, angles(40.0, 0.0), 400.0, 150.0);
    for mf in [1, 2] {
        for sampling in [Sampling::Centre, Sampling::Integrated] {
            let v = vectors(mf, SunMode::Separate, sampling);
            let s = v.hour(&hour).unwrap();
            let p = v.patches();
            let mut checked = 0;
            for (k, a) in p.iter().enumerate() {
                // The mirror of azimuth φ about the north–south line is −φ.
                let mirror = DVec3::new(-a.dir().x, a.dir().y, a.dir().z);
                let m = reinhart::patch_of(mf, mirror).unwrap();
                assert!(rel(s.radiance[k + 1], s.radiance[m + 1]) < 1e-9, "{k} {m}");
                checked += usize::from(m != k);
            }
            assert!(checked > p.len() / 2);
        }
    }
}

#[test]
fn extreme_inputs_stay_finite() {
    let cases = [
        (0.0, 0.0, 300.0, 50.0),   // sun on the horizon
        (-3.0, 10.0, 0.0, 20.0),   // twilight: sky only
        (-3.0, 10.0, 30.0, 20.0),  // a direct value below the horizon
        (60.0, 0.0, 1e6, 50.0),    // DNI huge
        (45.0, 90.0, 800.0, 0.0),  // no diffuse light
        (45.0, 90.0, 800.0, 1e-9), // almost none
        (89.9, 0.0, 900.0, 80.0),  // the sun at the zenith
        (30.0, 0.0, 0.0, 1e5),     // DHI huge
    ];
    for mf in [1, 2] {
        for mode in [SunMode::InPatches, SunMode::Separate] {
            let v = vectors(mf, mode, Sampling::Centre);
            for (alt, azi, dni, dhi) in cases {
                let s = v.hour(&Hour::new(355, angles(alt, azi), dni, dhi)).unwrap();
                assert!(
                    s.radiance.iter().all(|x| x.is_finite() && *x >= 0.0),
                    "{alt} {azi} {dni} {dhi}"
                );
            }
        }
    }
    let v = vectors(1, SunMode::Separate, Sampling::Centre);
    let dark = v
        .hour(&Hour::new(10, angles(-20.0, 0.0), 0.0, 0.0))
        .unwrap();
    assert!(dark.radiance.iter().all(|&x| x == 0.0) && dark.sun.is_none());
    let low = v
        .hour(&Hour::new(10, angles(-3.0, 0.0), 30.0, 20.0))
        .unwrap();
    assert!(
        low.sun.is_none(),
        "a sun below its disc's radius is not in the sky"
    );
    for (dni, dhi) in [
        (-1.0, 10.0),
        (10.0, -0.5),
        (f64::NAN, 10.0),
        (10.0, f64::INFINITY),
    ] {
        assert!(v.hour(&Hour::new(10, angles(20.0, 0.0), dni, dhi)).is_err());
    }
    assert!(v.hour(&Hour::new(0, angles(20.0, 0.0), 1.0, 1.0)).is_err());
    assert!(SkyVectors::new(SkyOptions {
        ground_reflectance: 1.5,
        ..SkyOptions::default()
    })
    .is_err());
}

#[test]
fn gendaymtx_sun_is_near_noaa() {
    // Chicago, 21 June 2026 at 12:30 CST (UTC−6).
    let site = Site::new(41.98, -87.92).unwrap();
    let g = Hour::gendaymtx(&site, -6.0, 6, 21, 12.5, 500.0, 100.0).unwrap();
    assert_eq!(g.day_of_year, 172);
    let t: DateTime = "2026-06-21T12:30-06:00".parse().unwrap();
    let n = Hour::at(&site, &t, 500.0, 100.0).unwrap();
    assert_eq!(n.day_of_year, 172);
    assert!(
        (g.sun.altitude - n.sun.altitude).abs() < 1.0,
        "{:?} {:?}",
        g.sun,
        n.sun
    );
    assert!(
        (g.sun.azimuth - n.sun.azimuth).abs() < 2.0,
        "{:?} {:?}",
        g.sun,
        n.sun
    );
    assert!(Hour::gendaymtx(&site, -6.0, 2, 30, 12.0, 1.0, 1.0).is_err());
    assert!(Hour::gendaymtx(&site, -6.0, 2, 1, 25.0, 1.0, 1.0).is_err());
}

#[test]
fn matrix_rows_are_the_hours_vectors() {
    let hours = [
        Hour::new(172, angles(50.0, 30.0), 700.0, 120.0),
        Hour::new(172, angles(-30.0, 150.0), 0.0, 0.0),
        Hour::new(80, angles(20.0, -60.0), 0.0, 200.0),
    ];
    let options = SkyOptions {
        subdivision: 2,
        sun: SunMode::Separate,
        ..SkyOptions::default()
    };
    let m = SkyMatrix::build(&hours, options).unwrap();
    assert_eq!((m.hours(), m.columns()), (3, 578));
    let v = SkyVectors::new(options).unwrap().hour(&hours[0]).unwrap();
    let row = m.row(0).unwrap();
    assert!(row.iter().zip(&v.radiance).all(|(a, b)| *a == *b as f32));
    assert!(m.row(1).unwrap().iter().all(|&x| x == 0.0));
    assert!(m.sun(0).is_some() && m.sun(1).is_none() && m.sun(2).is_none());
    assert!(m.row(3).is_none());
    let bad = [Hour::new(80, angles(20.0, 0.0), -5.0, 10.0)];
    let err = SkyMatrix::build(&bad, options).unwrap_err();
    assert!(err.0.starts_with("hour 1:"), "{err}");
}
