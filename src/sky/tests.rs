//! The sky's invariants: closed-form illuminances, the pieces' power sums, sampling, errors.

use super::*;
use std::f64::consts::TAU;

fn spec(kind: SkyKind, level: SkyLevel) -> SkySpec {
    SkySpec {
        kind,
        level,
        sun_position: Some(SolarAngles::new(35.0, -40.0).unwrap()),
        ..SkySpec::default()
    }
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// Σ radiance × projected solid angle over the pieces of `kind`.
fn horizontal_sum(sky: &Sky, kind: PieceKind) -> f64 {
    sky.pieces()
        .iter()
        .filter(|p| p.kind == kind)
        .map(|p| p.radiance[0] * p.projected_solid_angle)
        .sum()
}

/// E_h / L_z of the clear sky by a plain midpoint rule on an n × 4n (θ, φ) grid (θ from the
/// zenith, dω = sin θ dθ dφ): independent of the Tregenza cut and its Gauss–Legendre cells,
/// and, unlike a grid in cos θ, smooth at the zenith where a high sun puts its cusp.
fn clear_ratio_reference(sun: DVec3, n: usize) -> f64 {
    let (dt, dphi) = (PI / 2.0 / n as f64, TAU / (4 * n) as f64);
    let mut sum = 0.0;
    for i in 0..n {
        let (s, mu) = ((i as f64 + 0.5) * dt).sin_cos();
        for j in 0..4 * n {
            let (sin, cos) = ((j as f64 + 0.5) * dphi).sin_cos();
            sum += mu * s * SkyKind::Clear.relative(DVec3::new(s * sin, s * cos, mu), sun);
        }
    }
    sum * dt * dphi
}

#[test]
fn uniform_sky_gives_pi_l() {
    let sky = Sky::new(&spec(SkyKind::Uniform, SkyLevel::ZenithLuminance(1000.0))).unwrap();
    // Gauss–Legendre is exact on a constant: only rounding over 145 patches remains.
    assert!(rel(sky.horizontal_illuminance().0, PI * 1000.0) < 1e-12);
    for p in sky.pieces().iter().filter(|p| p.kind == PieceKind::Sky) {
        assert!(rel(p.radiance[0], 1000.0 / EFFICACY) < 1e-12);
    }
}

#[test]
fn overcast_sky_gives_seven_ninths_pi_lz() {
    let sky = Sky::new(&spec(SkyKind::Overcast, SkyLevel::ZenithLuminance(3000.0))).unwrap();
    // (1 + 2μ)μ is a quadratic in μ: exact under 4-point Gauss–Legendre.
    let e = sky.horizontal_illuminance().0;
    assert!(rel(e, 7.0 * PI / 9.0 * 3000.0) < 1e-12, "{e}");
    // And back: 10 klux of overcast sky has L_z = 9 · 10⁴ / 7π cd/m².
    let sky = Sky::new(&SkySpec::default()).unwrap();
    assert!(rel(sky.zenith_luminance(), 90_000.0 / (7.0 * PI)) < 1e-12);
    assert!(rel(sky.horizontal_illuminance().0, 10_000.0) < 1e-12);
}

#[test]
fn clear_sky_illuminance_matches_an_independent_quadrature() {
    for altitude in [2.0, 20.0, 45.0, 70.0, 89.0] {
        let angles = SolarAngles::new(altitude, 30.0).unwrap();
        let s = SkySpec {
            sun_position: Some(angles),
            ..spec(SkyKind::Clear, SkyLevel::ZenithLuminance(EFFICACY))
        };
        let ratio = Sky::new(&s).unwrap().horizontal_irradiance().0;
        // The midpoint rule is O(h²): Richardson's step from n = 300 and 600 leaves ~1e-8.
        let (coarse, fine) = (
            clear_ratio_reference(angles.local_dir(), 300),
            clear_ratio_reference(angles.local_dir(), 600),
        );
        let reference = fine + (fine - coarse) / 3.0;
        // 8² Gauss–Legendre cells per patch measured within 3e-6 of 64² (worst with the sun
        // at 85°, its cusp in the cap); 1e-5 leaves room, and is ten times the 1e-4 asked for.
        assert!(
            rel(ratio, reference) < 1e-5,
            "{altitude}°: {ratio} vs {reference}"
        );
    }
}

/// `gensky`'s own normalisation is a quartic fit in the sun's altitude (`normsc`): the
/// integral here should agree with it to the fit's accuracy.
#[test]
fn clear_sky_agrees_with_gensky_normalisation_fit() {
    const NFC: [f64; 5] = [2.766521, 0.547665, -0.369832, 0.009237, 0.059229];
    for altitude in [10.0, 30.0, 50.0, 70.0, 85.0] {
        let h: f64 = f64::to_radians(altitude);
        let x = (h - PI / 4.0) / (PI / 4.0);
        let normsc = NFC.iter().rev().fold(0.0, |acc, c| acc * x + c);
        let f2 = 0.274 * (0.91 + 10.0 * (-3.0 * (PI / 2.0 - h)).exp() + 0.45 * h.sin().powi(2));
        let s = SkySpec {
            sun_position: Some(SolarAngles::new(altitude, 0.0).unwrap()),
            ..spec(SkyKind::Clear, SkyLevel::ZenithLuminance(EFFICACY))
        };
        let ratio = Sky::new(&s).unwrap().horizontal_irradiance().0;
        let gensky = normsc / f2;
        // The fit's residual, measured: 0.25 % at 10°, under 0.1 % from 50° up.
        assert!(
            rel(ratio, gensky) < 5e-3,
            "{altitude}°: {ratio} vs gensky {gensky}"
        );
    }
}

#[test]
fn pieces_carry_the_horizontal_illuminance_for_every_sky() {
    let sun = Some(SunLevel::Gensky);
    for kind in [SkyKind::Uniform, SkyKind::Overcast, SkyKind::Clear] {
        let sky = Sky::new(&SkySpec {
            sun,
            ground_reflectance: 0.3,
            ..spec(kind, SkyLevel::HorizontalIlluminance(12_345.0))
        })
        .unwrap();
        let (e_sky, e_sun) = sky.horizontal_irradiance();
        assert!(rel(e_sky * EFFICACY, 12_345.0) < 1e-12);
        // Each a sum of the same numbers in another order: rounding only.
        assert!(
            rel(horizontal_sum(&sky, PieceKind::Sky), e_sky) < 1e-12,
            "{kind:?}"
        );
        assert!(
            rel(horizontal_sum(&sky, PieceKind::Sun), e_sun) < 1e-12,
            "{kind:?}"
        );
        let ground = horizontal_sum(&sky, PieceKind::Ground);
        assert!(rel(ground, 0.3 * (e_sky + e_sun)) < 1e-12, "{kind:?}");
    }
}

/// With cos θ taken at each piece's `dir`: exact for the 144 band patches; the cap's `dir` is
/// the zenith, where cos θ · Ω exceeds its projected solid angle by L_cap (Ω − P).
#[test]
fn beams_along_dir_carry_the_horizontal_illuminance_but_for_the_cap() {
    let sky = Sky::new(&spec(
        SkyKind::Clear,
        SkyLevel::HorizontalIlluminance(9000.0),
    ))
    .unwrap();
    let up = sky.compass().up();
    let sky_pieces = sky.pieces().iter().filter(|p| p.kind == PieceKind::Sky);
    let beams: f64 = sky_pieces
        .map(|p| p.radiance[0] * p.solid_angle * p.dir.as_dvec3().dot(up))
        .sum();
    let cap = sky.pieces()[144];
    let excess = cap.radiance[0] * (cap.solid_angle - cap.projected_solid_angle);
    let e_sky = sky.horizontal_irradiance().0;
    // f32 directions: cos θ good to ~1e-7.
    assert!(
        rel(beams - excess, e_sky) < 1e-6,
        "{beams} {excess} {e_sky}"
    );
    assert!(
        excess / e_sky < 1e-4,
        "the cap's share stays small: {}",
        excess / e_sky
    );
}

#[test]
fn solid_angles_cover_the_sphere() {
    let sky = Sky::new(&SkySpec::default()).unwrap();
    for kind in [PieceKind::Sky, PieceKind::Ground] {
        let pieces = sky.pieces().iter().filter(|p| p.kind == kind);
        let omega: f64 = pieces.map(|p| p.solid_angle).sum();
        assert!((omega - TAU).abs() < 1e-9, "{kind:?} {omega}");
    }
    assert_eq!(sky.pieces().len(), 2 * tregenza::PATCHES);
}

/// Directions sampled on a midpoint grid of (u, v): μ is linear in u, so their mean cos θ is
/// each band's exactly, and the sampled beams carry E_h (the cap included).
#[test]
fn sampled_directions_carry_the_horizontal_illuminance() {
    let sky = Sky::new(&SkySpec {
        sun: Some(SunLevel::NormalIlluminance(70_000.0)),
        ..spec(SkyKind::Clear, SkyLevel::HorizontalIlluminance(9000.0))
    })
    .unwrap();
    let up = sky.compass().up().as_vec3();
    let n = 16;
    let mut sum = 0.0;
    for p in sky.pieces().iter().filter(|p| p.kind != PieceKind::Ground) {
        let mut mean_cos = 0.0;
        for a in 0..n {
            for b in 0..n {
                let (u, v) = ((a as f64 + 0.5) / n as f64, (b as f64 + 0.5) / n as f64);
                let d = p.sample(u, v);
                assert!((d.length() - 1.0).abs() < 1e-6);
                assert!(p.kind != PieceKind::Sky || d.dot(up) >= 0.0);
                mean_cos += d.dot(up) as f64 / (n * n) as f64;
            }
        }
        sum += p.radiance[0] * p.solid_angle * mean_cos;
    }
    let (e_sky, e_sun) = sky.horizontal_irradiance();
    // f32 directions (1e-7) and the sun's disc, whose grid mean of cos is exact only to O(α²).
    assert!(rel(sum, e_sky + e_sun) < 1e-6, "{sum} vs {}", e_sky + e_sun);
}

#[test]
fn radiance_of_escaping_rays() {
    let sky = Sky::new(&SkySpec {
        sun: Some(SunLevel::Gensky),
        ..spec(SkyKind::Clear, SkyLevel::Gensky)
    })
    .unwrap();
    let sun = sky.sun().unwrap();
    // Towards the sun: the circumsolar sky, not the disc (the sun is sampled on its own).
    let at_sun = sky.radiance(sun.dir)[0];
    assert!(
        at_sun > 0.0 && at_sun < 1e-3 * sun.radiance()[0],
        "{at_sun}"
    );
    let expect =
        sky.zenith_luminance() / EFFICACY * SkyKind::Clear.relative(DVec3::Z, sky.sun_local);
    assert!(rel(sky.radiance(Vec3::Y * 3.0)[0], expect) < 1e-12);
    assert_eq!(sky.radiance(-Vec3::Y)[0], sky.ground_radiance());
    assert_eq!(sky.radiance(Vec3::ZERO)[0], sky.ground_radiance());
    let (e_sky, e_sun) = sky.horizontal_irradiance();
    assert!(rel(sky.ground_radiance(), 0.2 * (e_sky + e_sun) / PI) < 1e-12);
}

#[test]
fn sun_below_the_horizon_gives_no_sun_piece() {
    let sky = Sky::new(&SkySpec {
        sun: Some(SunLevel::Gensky),
        sun_position: Some(SolarAngles::new(-5.0, 100.0).unwrap()),
        ..SkySpec::default()
    })
    .unwrap();
    assert!(sky.sun().is_none() && sky.sun_below_horizon());
    assert!(sky.pieces().iter().all(|p| p.kind != PieceKind::Sun));
    assert_eq!(sky.horizontal_illuminance().1, 0.0);
    let up = Sky::new(&SkySpec {
        sun: Some(SunLevel::Gensky),
        ..spec(SkyKind::Overcast, SkyLevel::HorizontalIlluminance(1.0))
    })
    .unwrap();
    assert!(!up.sun_below_horizon());
    assert_eq!(up.pieces().last().unwrap().kind, PieceKind::Sun);
}

#[test]
fn orientation_follows_zenith_and_north() {
    // gensky's own axes: Z up, Y north. The sun due south at 45°: (0, −1, 1)/√2.
    let sky = Sky::new(&SkySpec {
        zenith: Vec3::Z,
        north: Vec3::Y,
        sun: Some(SunLevel::Gensky),
        sun_position: Some(SolarAngles::new(45.0, 0.0).unwrap()),
        ..SkySpec::default()
    })
    .unwrap();
    let d = sky.sun().unwrap().dir;
    assert!(
        (d - Vec3::new(0.0, -1.0, 1.0).normalize()).length() < 1e-6,
        "{d}"
    );
    // Tregenza patch 1 is due north on the horizon band; patch 145 the zenith.
    assert!(sky.pieces()[0].dir.y > 0.99 && sky.pieces()[144].dir == Vec3::Z);
    assert!(sky.pieces()[145].dir.z < 0.0, "ground pieces point down");
}

#[test]
fn bad_specs_are_refused() {
    let clear = SkySpec {
        kind: SkyKind::Clear,
        ..SkySpec::default()
    };
    assert_eq!(
        Sky::new(&clear).unwrap_err().0,
        "--sky: the clear sky needs the sun's position (altitude and azimuth, or a site and a time)"
    );
    let cases = [
        SkySpec {
            ground_reflectance: 1.5,
            ..SkySpec::default()
        },
        SkySpec {
            level: SkyLevel::HorizontalIlluminance(f64::NAN),
            ..SkySpec::default()
        },
        SkySpec {
            level: SkyLevel::ZenithLuminance(-1.0),
            ..SkySpec::default()
        },
        SkySpec {
            sun: Some(SunLevel::Gensky),
            ..SkySpec::default()
        },
        SkySpec {
            level: SkyLevel::Gensky,
            ..SkySpec::default()
        },
        SkySpec {
            north: Vec3::Y,
            ..SkySpec::default()
        },
    ];
    for s in cases {
        let e = Sky::new(&s).unwrap_err();
        assert!(e.0.starts_with("--"), "names no flag: {e}");
        assert_eq!(s.check().unwrap_err(), e);
    }
}
