//! Tests of the equal-flux cells: each checks the sampler against the web through
//! `Photometry::intensity` integrated independently (midpoint rule), never through the table.

use super::super::test_webs::{ies, steps};
use super::super::{parse_ies, parse_ldt, PhotometricType, Photometry};
use super::{CellAngles, FluxCells};
use glam::DVec3;
use rand::{Rng, SeedableRng};
use std::f64::consts::PI;

/// The web of `kind` whose candela at (horizontal h, vertical v) is `f(h, v)`.
fn web(kind: u8, vertical: &[f64], horizontal: &[f64], f: impl Fn(f64, f64) -> f64) -> Photometry {
    let planes: Vec<Vec<f64>> = horizontal
        .iter()
        .map(|&h| vertical.iter().map(|&v| f(h, v)).collect())
        .collect();
    ies(kind, vertical, horizontal, &planes)
}

fn isotropic() -> Photometry {
    web(1, &steps(0.0, 180.0, 10.0), &[0.0], |_, _| 1000.0)
}

fn downlight() -> Photometry {
    web(1, &steps(0.0, 90.0, 5.0), &[0.0], |_, g| {
        1000.0 * g.to_radians().cos()
    })
}

/// Type C, all planes given (0, 90, 180, 270 and 360 = 0): strong in C 0..90, each plane
/// with its own profile in γ, the same value at the poles.
fn asymmetric() -> Photometry {
    let base = |c: f64| match c as u32 {
        90 => 700.0,
        180 => 60.0,
        270 => 250.0,
        _ => 1000.0,
    };
    web(
        1,
        &steps(0.0, 180.0, 10.0),
        &steps(0.0, 360.0, 90.0),
        |c, g| {
            let pole = g == 0.0 || g == 180.0;
            let c = c % 360.0;
            let shape = 0.5 + 0.5 * (g - c / 3.0).to_radians().cos();
            if pole {
                300.0
            } else {
                base(c) * (0.2 + shape)
            }
        },
    )
}

/// Type B floodlight, every plane given: aimed up and to one side, dark at the edges of the
/// front half-sphere.
fn floodlight() -> Photometry {
    web(
        2,
        &steps(-90.0, 90.0, 10.0),
        &steps(-90.0, 90.0, 15.0),
        |h, v| {
            let (h, v) = (h.to_radians(), v.to_radians());
            1000.0 * h.cos() * (1.0 + 0.6 * h.sin()) * v.cos() * (1.0 + 0.5 * v.sin())
        },
    )
}

/// The solid-angle measure of the file's angles (degrees) per square degree, as radians².
fn jacobian(kind: PhotometricType, h: f64, v: f64) -> f64 {
    let per_deg2 = (1.0_f64).to_radians().powi(2);
    match kind {
        PhotometricType::C => v.to_radians().sin() * per_deg2,
        PhotometricType::A | PhotometricType::B => h.to_radians().cos() * per_deg2,
    }
}

/// ∫∫ I dΩ over horizontal `h` × vertical `v` (degrees), midpoint rule on k × k points.
fn flux_over(p: &Photometry, h: [f64; 2], v: [f64; 2], k: usize) -> f64 {
    let (dh, dv) = ((h[1] - h[0]) / k as f64, (v[1] - v[0]) / k as f64);
    let mut sum = 0.0;
    for a in 0..k {
        let hm = h[0] + (a as f64 + 0.5) * dh;
        for b in 0..k {
            let vm = v[0] + (b as f64 + 0.5) * dv;
            sum += p.intensity(hm, vm) * jacobian(p.kind, hm, vm);
        }
    }
    sum * dh * dv
}

fn cell_flux(p: &Photometry, c: CellAngles) -> f64 {
    flux_over(p, c.horizontal, c.vertical, 40)
}

/// One ray per cell per shot, `shots` shots, u and v random; the turn of shot k from `turn`.
fn draws(cells: &FluxCells, shots: usize, seed: u64, turn: impl Fn(usize) -> f64) -> Vec<DVec3> {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let mut out = Vec::with_capacity(shots * cells.len());
    for shot in 0..shots {
        let t = turn(shot);
        for k in 0..cells.len() {
            out.push(cells.sample(k, rng.gen(), rng.gen(), t));
        }
    }
    out
}

/// The file's (horizontal, vertical) angles of a local direction, degrees, by the local-frame
/// convention written out (not through the module's frame).
fn angles(kind: PhotometricType, d: DVec3) -> (f64, f64) {
    match kind {
        PhotometricType::C => (
            d.y.atan2(d.x).to_degrees().rem_euclid(360.0),
            (-d.z).clamp(-1.0, 1.0).acos().to_degrees(),
        ),
        PhotometricType::B => (d.y.asin().to_degrees(), d.x.atan2(-d.z).to_degrees()),
        PhotometricType::A => (d.x.asin().to_degrees(), d.y.atan2(-d.z).to_degrees()),
    }
}

/// The local direction of the file's angles (degrees) by the convention.
fn direction(kind: PhotometricType, h: f64, v: f64) -> DVec3 {
    let (h, v) = (h.to_radians(), v.to_radians());
    match kind {
        PhotometricType::C => DVec3::new(v.sin() * h.cos(), v.sin() * h.sin(), -v.cos()),
        PhotometricType::B => {
            h.sin() * DVec3::Y + h.cos() * v.sin() * DVec3::X - h.cos() * v.cos() * DVec3::Z
        }
        PhotometricType::A => {
            h.sin() * DVec3::X + h.cos() * v.sin() * DVec3::Y - h.cos() * v.cos() * DVec3::Z
        }
    }
}

/// |observed − expected| share within 5 binomial standard deviations (stratification only
/// lowers the spread, so this is conservative).
fn assert_share(observed: usize, n: usize, expected: f64, what: &str) {
    let got = observed as f64 / n as f64;
    let sigma = (expected * (1.0 - expected) / n as f64).sqrt();
    assert!(
        (got - expected).abs() <= 5.0 * sigma + 1e-9,
        "{what}: {got} against {expected} (σ {sigma})"
    );
}

#[test]
fn isotropic_source_is_uniform_on_the_sphere() {
    // One cell (the sampler alone places the rays) and 500 (the strata do most of it).
    for (n, shots) in [(1, 200_000), (500, 400)] {
        let cells = FluxCells::new(&isotropic(), n);
        assert_eq!(cells.len(), n);
        check_uniform(&draws(&cells, shots, 1, |k| (k as f64 * 0.618_034).fract()));
    }
}

/// Moments and octant counts of directions uniform on the sphere, 200 000 of them.
fn check_uniform(d: &[DVec3]) {
    let n = d.len() as f64;
    let mean = d.iter().copied().sum::<DVec3>() / n;
    let z2 = d.iter().map(|v| v.z * v.z).sum::<f64>() / n;
    // Each coordinate of a uniform direction has σ = 1/√3: σ of the mean over 200 000 is
    // 1.3e-3; z² has σ = √(1/5 − 1/9) ≈ 0.30, 6.7e-4 for the mean; 5σ bars.
    assert!(mean.abs().max_element() < 6.5e-3, "mean {mean}");
    assert!((z2 - 1.0 / 3.0).abs() < 3.4e-3, "E[z²] {z2}");
    assert!(d.iter().all(|v| (v.length() - 1.0).abs() < 1e-12));
    let mut octants = [0usize; 8];
    for v in d {
        octants[(v.x > 0.0) as usize + 2 * (v.y > 0.0) as usize + 4 * (v.z > 0.0) as usize] += 1;
    }
    let e = n / 8.0;
    let chi2: f64 = octants.iter().map(|&o| (o as f64 - e).powi(2) / e).sum();
    // χ² with 7 degrees of freedom exceeds 24.3 with probability 0.001.
    assert!(chi2 < 24.3, "octants {octants:?}, χ² {chi2}");
}

#[test]
fn cosine_downlight_has_mean_cosine_two_thirds_and_never_goes_up() {
    for (n, shots) in [(1, 180_000), (300, 600)] {
        let cells = FluxCells::new(&downlight(), n);
        let d = draws(&cells, shots, 2, |_| 0.0);
        assert!(d.iter().all(|v| v.z <= 1e-9), "a ray above the horizon");
        let mean = d.iter().map(|v| -v.z).sum::<f64>() / d.len() as f64;
        // cos γ under a cosine-weighted hemisphere: σ = √(1/2 − 4/9) ≈ 0.236, 5.6e-4 over
        // 180 000 draws; the 5° web's interpolation of cos γ moves the mean by about 1e-4.
        assert!((mean - 2.0 / 3.0).abs() < 3e-3, "N {n}: E[cos γ] {mean}");
    }
}

/// Shares of the samples per C quadrant against the web's flux per quadrant.
fn check_quadrants(p: &Photometry, d: &[DVec3]) {
    let total = p.total_lumens();
    let mut counts = [0usize; 4];
    for v in d {
        let (c, _) = angles(PhotometricType::C, *v);
        counts[((c / 90.0) as usize).min(3)] += 1;
    }
    for (q, &count) in counts.iter().enumerate() {
        let lo = 90.0 * q as f64;
        let expected = flux_over(p, [lo, lo + 90.0], [0.0, 180.0], 360) / total;
        let got = count as f64 / d.len() as f64;
        assert!(
            (got / expected - 1.0).abs() < 0.01,
            "quadrant {q}: {got} against {expected}"
        );
    }
}

#[test]
fn asymmetric_web_shares_its_samples_by_quadrant_flux() {
    let p = asymmetric();
    let cells = FluxCells::new(&p, 2000);
    // The quadrants carry different shares (about 0.4, 0.2, 0.1, 0.3): a sampler that
    // ignored C would put 1/4 in each.
    check_quadrants(&p, &draws(&cells, 200, 3, |_| 0.0));
    let mut rng = rand_pcg::Pcg64::seed_from_u64(4);
    let turns: Vec<f64> = (0..200).map(|_| rng.gen()).collect();
    check_quadrants(&p, &draws(&cells, 200, 5, |k| turns[k]));
}

#[test]
fn type_b_floodlight_stays_in_front_and_follows_the_web() {
    let p = floodlight();
    for (n, shots) in [(1, 300_000), (1000, 300)] {
        let cells = FluxCells::new(&p, n);
        check_flood(
            &p,
            &draws(&cells, shots, 6, |k| (k as f64 * 0.754_877).fract()),
        );
    }
}

/// Directions of `floodlight()`: in front, and shared over 30° bins of (H, V) as its flux.
fn check_flood(p: &Photometry, d: &[DVec3]) {
    assert!(d.iter().all(|v| v.z < 0.0), "a ray behind the floodlight");
    let total = p.total_lumens();
    let mut bins = [[0usize; 6]; 6];
    for v in d {
        let (h, vv) = angles(PhotometricType::B, *v);
        let bin = |a: f64| (((a + 90.0) / 30.0) as usize).min(5);
        bins[bin(h)][bin(vv)] += 1;
    }
    for (a, row) in bins.iter().enumerate() {
        for (b, &count) in row.iter().enumerate() {
            let (h0, v0) = (-90.0 + 30.0 * a as f64, -90.0 + 30.0 * b as f64);
            let expected = flux_over(p, [h0, h0 + 30.0], [v0, v0 + 30.0], 60) / total;
            assert_share(count, d.len(), expected, &format!("bin H{h0} V{v0}"));
        }
    }
}

#[test]
fn every_cell_carries_an_equal_share_of_the_flux() {
    let files = [
        parse_ies(include_str!("testdata/type_b_lateral.ies"), "b.ies").unwrap(),
        parse_ies(include_str!("testdata/iesna91_quadrant.ies"), "q.ies").unwrap(),
        parse_ies(include_str!("testdata/lm63_2002_c90.ies"), "c90.ies").unwrap(),
        parse_ldt(include_str!("testdata/isym2.ldt"), "2.ldt").unwrap(),
    ];
    let webs = [isotropic(), downlight(), asymmetric(), floodlight()];
    for (w, p) in webs.iter().chain(&files).enumerate() {
        for n in [1, 7, 150] {
            let cells = FluxCells::new(p, n);
            assert_eq!(cells.len(), n, "web {w}");
            let lm = p.total_lumens();
            assert!(
                (cells.total_lumens() / lm - 1.0).abs() < 0.005,
                "web {w}: {} against {lm}",
                cells.total_lumens()
            );
            let share = cells.flux_per_cell();
            for k in 0..n {
                let f = cell_flux(p, cells.cell_angles(k).unwrap());
                assert!(
                    (f / share - 1.0).abs() < 0.01,
                    "web {w}, N {n}, cell {k}: {f} against {share}"
                );
            }
        }
    }
}

/// Width over height of each cell of `cells` (Type C), at the middle of its γ range.
fn aspect_ratios(cells: &FluxCells) -> Vec<f64> {
    let mut ratios: Vec<f64> = (0..cells.len())
        .map(|k| {
            let c = cells.cell_angles(k).unwrap();
            let mid = (0.5 * (c.vertical[0] + c.vertical[1])).to_radians().sin();
            mid * (c.horizontal[1] - c.horizontal[0]) / (c.vertical[1] - c.vertical[0])
        })
        .collect();
    ratios.sort_by(f64::total_cmp);
    ratios
}

#[test]
fn cells_are_roughly_square() {
    let ratios = aspect_ratios(&FluxCells::new(&isotropic(), 2000));
    let square = ratios
        .iter()
        .filter(|&&r| (0.75..=1.33).contains(&r))
        .count();
    // All but the polar caps' few cells (a cap's three cells are π/3 wide for 1 high).
    assert!(
        square as f64 > 0.98 * ratios.len() as f64,
        "{square} of {}",
        ratios.len()
    );
    // Lit only in C 0..90: the cells share out the lit quarter of each ring, not all of it.
    let wedge = web(
        1,
        &steps(0.0, 180.0, 15.0),
        &steps(0.0, 360.0, 30.0),
        |c, g| {
            let lit = (30.0..=60.0).contains(&c) && (15.0..=165.0).contains(&g);
            if lit {
                500.0
            } else {
                0.0
            }
        },
    );
    let ratios = aspect_ratios(&FluxCells::new(&wedge, 2000));
    let median = ratios[ratios.len() / 2];
    assert!(
        (0.75..=1.33).contains(&median),
        "median width over height {median}"
    );
}

#[test]
fn turn_moves_rays_but_keeps_the_density() {
    let p = asymmetric();
    let cells = FluxCells::new(&p, 400);
    for k in [0, 57, 399] {
        let d: Vec<DVec3> = [0.0, 0.25, 0.5, 0.75]
            .iter()
            .map(|&t| cells.sample(k, 0.3, 0.6, t))
            .collect();
        for a in 0..d.len() {
            for b in a + 1..d.len() {
                assert!(
                    (d[a] - d[b]).length() > 1e-6,
                    "cell {k}: turns {a}, {b} agree"
                );
            }
        }
    }
    // A fixed turn for every shot, and a fresh one per shot: both still ∝ I.
    let cells = FluxCells::new(&p, 2000);
    check_quadrants(&p, &draws(&cells, 200, 7, |_| 0.37));
    check_quadrants(&p, &draws(&cells, 200, 8, |k| (k as f64 + 0.5) / 200.0));
    // A rotationally symmetric web: the turn is the paper's turn about the polar axis.
    let cells = FluxCells::new(&downlight(), 50);
    let mut rng = rand_pcg::Pcg64::seed_from_u64(9);
    for _ in 0..500 {
        let (k, u, v, t) = (rng.gen_range(0..50), rng.gen(), rng.gen(), rng.gen::<f64>());
        let d = cells.sample(k, u, v, 0.0);
        let (s, c) = (t * 2.0 * PI).sin_cos();
        let turned = DVec3::new(c * d.x - s * d.y, s * d.x + c * d.y, d.z);
        assert!(
            (cells.sample(k, u, v, t) - turned).length() < 1e-9,
            "cell {k} turn {t}"
        );
    }
}

#[test]
fn pdf_is_the_web_over_its_flux_in_the_local_frame() {
    let a = web(
        3,
        &steps(-90.0, 90.0, 15.0),
        &steps(-90.0, 90.0, 10.0),
        |h, v| 500.0 + 3.0 * h + v * v / 20.0,
    );
    for p in [asymmetric(), floodlight(), a] {
        let cells = FluxCells::new(&p, 100);
        let phi = cells.total_lumens();
        let (hs, vs) = match p.kind {
            PhotometricType::C => (steps(0.0, 357.0, 7.0), steps(3.0, 177.0, 6.0)),
            _ => (steps(-87.0, 87.0, 6.0), steps(-89.0, 89.0, 7.0)),
        };
        for &h in &hs {
            for &v in &vs {
                let want = p.intensity(h, v);
                let got = cells.pdf(direction(p.kind, h, v)) * phi;
                assert!(
                    (got - want).abs() < 1e-8 * want.max(1.0),
                    "{:?} ({h}, {v}): {got} against {want}",
                    p.kind
                );
            }
        }
    }
    // Behind a floodlight, above a downlight: no density.
    assert_eq!(
        FluxCells::new(&floodlight(), 10).pdf(DVec3::new(0.1, 0.2, 0.9)),
        0.0
    );
    assert_eq!(FluxCells::new(&downlight(), 10).pdf(DVec3::Z), 0.0);
    // The density integrates to 1 over the sphere (midpoint rule in γ, C).
    let cells = FluxCells::new(&asymmetric(), 10);
    let (n, m) = (360, 180);
    let mut sum = 0.0;
    for a in 0..n {
        for b in 0..m {
            let (c, g) = (
                (a as f64 + 0.5) * 360.0 / n as f64,
                (b as f64 + 0.5) * 180.0 / m as f64,
            );
            sum +=
                cells.pdf(direction(PhotometricType::C, c, g)) * jacobian(PhotometricType::C, c, g);
        }
    }
    assert!((sum - 1.0).abs() < 1e-3, "∫ pdf dΩ = {sum}");
}

#[test]
fn samples_fall_where_the_web_is_lit() {
    // Each web lit only on an open patch of its angles: (h, v) in lo..hi.
    let spot = |h: f64, v: f64, hc: f64, vc: f64| {
        if h == hc && v == vc {
            800.0
        } else {
            0.0
        }
    };
    let cases = [
        (
            web(
                1,
                &steps(0.0, 180.0, 15.0),
                &steps(0.0, 360.0, 30.0),
                |h, v| spot(h, v, 90.0, 45.0),
            ),
            [60.0, 120.0],
            [30.0, 60.0],
        ),
        (
            web(
                2,
                &steps(-90.0, 90.0, 15.0),
                &steps(-90.0, 90.0, 15.0),
                |h, v| spot(h, v, -30.0, 60.0),
            ),
            [-45.0, -15.0],
            [45.0, 75.0],
        ),
        (
            web(
                3,
                &steps(-90.0, 90.0, 15.0),
                &steps(-90.0, 90.0, 15.0),
                |h, v| spot(h, v, 30.0, -15.0),
            ),
            [15.0, 45.0],
            [-30.0, 0.0],
        ),
    ];
    for (p, hr, vr) in &cases {
        let cells = FluxCells::new(p, 64);
        for k in 0..cells.len() {
            let c = cells.cell_angles(k).unwrap();
            let inside = |x: [f64; 2], r: &[f64; 2]| x[0] >= r[0] - 1e-9 && x[1] <= r[1] + 1e-9;
            assert!(
                inside(c.horizontal, hr) && inside(c.vertical, vr),
                "{:?} cell {k}: {c:?}",
                p.kind
            );
        }
        for d in draws(&cells, 50, 10, |k| k as f64 / 50.0) {
            let (h, v) = angles(p.kind, d);
            let ok = h > hr[0] - 1e-6 && h < hr[1] + 1e-6 && v > vr[0] - 1e-6 && v < vr[1] + 1e-6;
            assert!(
                ok,
                "{:?}: ray at ({h}, {v}) outside {hr:?} × {vr:?}",
                p.kind
            );
        }
    }
}

#[test]
fn dark_bands_get_no_cells() {
    // An uplight: dark from the nadir to the horizon.
    let up = web(1, &steps(0.0, 180.0, 15.0), &[0.0], |_, g| {
        if g <= 90.0 {
            0.0
        } else {
            100.0 + g
        }
    });
    let cells = FluxCells::new(&up, 200);
    for k in 0..cells.len() {
        assert!(
            cells.cell_angles(k).unwrap().vertical[0] >= 90.0 - 1e-9,
            "cell {k}"
        );
    }
    // A floodlight dark below its aiming plane (V < 0): no cell reaches below it.
    let half = web(
        2,
        &steps(-90.0, 90.0, 10.0),
        &steps(-90.0, 90.0, 15.0),
        |h, v| {
            if v <= 0.0 {
                0.0
            } else {
                50.0 + h.abs()
            }
        },
    );
    let cells = FluxCells::new(&half, 200);
    for k in 0..cells.len() {
        assert!(
            cells.cell_angles(k).unwrap().vertical[0] >= -1e-9,
            "cell {k}"
        );
    }
}

#[test]
fn webs_without_flux_give_an_empty_table() {
    let dark = web(1, &steps(0.0, 180.0, 45.0), &[0.0, 90.0], |_, _| 0.0);
    let mut no_vertical = isotropic();
    no_vertical.vertical.clear();
    let mut no_horizontal = isotropic();
    no_horizontal.horizontal.clear();
    no_horizontal.candela.clear();
    let mut one_angle = isotropic();
    one_angle.vertical.truncate(1);
    let mut garbage = isotropic();
    for row in &mut garbage.candela {
        for (j, x) in row.iter_mut().enumerate() {
            *x = [f64::NAN, -5.0, f64::INFINITY][j % 3];
        }
    }
    for p in [dark, no_vertical, no_horizontal, one_angle, garbage] {
        let cells = FluxCells::new(&p, 100);
        assert_eq!(
            (cells.len(), cells.total_lumens(), cells.flux_per_cell()),
            (0, 0.0, 0.0)
        );
        assert!(cells.is_empty() && cells.cell_angles(0).is_none());
        assert_eq!(cells.sample(3, 0.5, 0.5, 0.5), DVec3::NEG_Z);
        assert_eq!(cells.pdf(DVec3::NEG_Z), 0.0);
    }
    // A lit web asked for no cells gets one; odd arguments still give unit directions.
    let cells = FluxCells::new(&asymmetric(), 0);
    assert_eq!(cells.len(), 1);
    let cells = FluxCells::new(&asymmetric(), 30);
    for (k, u, v, t) in [
        (31, 0.5, 0.5, 0.0),
        (0, f64::NAN, 2.0, f64::INFINITY),
        (5, -1.0, 1.0, -3.7),
        (29, 1.0, 0.0, 1e300),
    ] {
        let d = cells.sample(k, u, v, t);
        assert!((d.length() - 1.0).abs() < 1e-12, "{d}");
    }
    assert!(cells.pdf(DVec3::ZERO) == 0.0 && cells.pdf(DVec3::NAN) == 0.0);
}

#[test]
fn a_fine_web_cut_into_many_cells_keeps_every_cell_equal() {
    // 5° C-planes by 2.5° γ, asymmetric, 100 000 cells (what a bright luminaire shoots).
    let p = web(
        1,
        &steps(0.0, 180.0, 2.5),
        &steps(0.0, 360.0, 5.0),
        |c, g| {
            let (c, g) = (c.to_radians(), g.to_radians());
            let c = if c >= 2.0 * PI { 0.0 } else { c };
            400.0 * (1.0 + g.cos()) * (1.2 + c.cos() + 0.3 * (3.0 * c).sin()) + 20.0
        },
    );
    let cells = FluxCells::new(&p, 100_000);
    assert_eq!(cells.len(), 100_000);
    assert!((cells.total_lumens() / p.total_lumens() - 1.0).abs() < 0.005);
    let share = cells.flux_per_cell();
    for k in (0..cells.len()).step_by(997) {
        let c = cells.cell_angles(k).unwrap();
        let f = flux_over(&p, c.horizontal, c.vertical, 12);
        assert!(
            (f / share - 1.0).abs() < 0.01,
            "cell {k}: {f} against {share}"
        );
    }
}
