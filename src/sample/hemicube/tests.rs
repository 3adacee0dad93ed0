//! Unit tests of the hemi-cube: layouts, ΔF sums and spreads, the look-up tables, form
//! factors against closed forms, occlusion, culling, buffers and thread independence.

use super::grid::{side_corner_ff, top_corner_ff};
use super::*;
use crate::mesh::{newell, Patch, PatchClass, Side};
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;
use std::f64::consts::PI;

/// Quads with centre c and half-edge vectors e1, e2, facing e1 × e2.
fn quad_mesh(quads: &[(Vec3, Vec3, Vec3)]) -> Mesh {
    let mut mesh = Mesh::default();
    for (k, &(c, e1, e2)) in quads.iter().enumerate() {
        let pts = [c - e1 - e2, c + e1 - e2, c + e1 + e2, c - e1 + e2];
        let first = mesh.patch_vertices.len() as u32;
        for p in pts {
            mesh.patch_vertices.push(mesh.vertices.len() as u32);
            mesh.vertices.push(p);
        }
        let n = newell(&pts);
        mesh.patches.push(Patch {
            first,
            count: 4,
            material: 0,
            polygon: k as u32,
            area: n.length() as f64 * 0.5,
            centre: c,
            normal: n.normalize(),
            class: PatchClass::Skew,
            side: Side::One,
        });
    }
    mesh
}

/// Unit square at the origin facing +z (the shooter) and `others`.
fn scene(others: &[(Vec3, Vec3, Vec3)]) -> Mesh {
    let mut quads = vec![(Vec3::ZERO, Vec3::X * 0.5, Vec3::Y * 0.5)];
    quads.extend_from_slice(others);
    quad_mesh(&quads)
}

fn parallel_receiver() -> (Vec3, Vec3, Vec3) {
    // At z = 1 facing down (−z) towards the shooter.
    (Vec3::Z, Vec3::Y * 0.5, Vec3::X * 0.5)
}

/// Point on the axis at distance 1 from a unit square: 4 corner rectangles of 0.5 × 0.5.
fn parallel_exact() -> f64 {
    4.0 * top_corner_ff(0.5, 0.5)
}

/// Sharing the shooter's edge x = 0.5, standing up to z = 1, facing −x.
fn perpendicular_receiver() -> (Vec3, Vec3, Vec3) {
    (Vec3::new(0.5, 0.0, 0.5), Vec3::Z * 0.5, Vec3::Y * 0.5)
}

/// Point to a perpendicular rectangle at distance c = 0.5, y ∈ [−0.5, 0.5], z ∈ [0, 1]:
/// scaled by 1/c, y ∈ [−1, 1], z ∈ [0, 2] on the plane x = 1.
fn perpendicular_exact() -> f64 {
    2.0 * (side_corner_ff(1.0, 2.0) - side_corner_ff(1.0, 0.0))
}

fn shoot_once(cube: &Hemicube, mesh: &Mesh, angle: f32) -> Vec<(u32, f64, bool)> {
    let mut buf = HemicubeBuffer::default();
    let mut out = Vec::new();
    let frame = Frame::new(mesh.patches[0].normal, angle);
    cube.shoot::<Pcg64Mcg>(
        mesh,
        0,
        mesh.patches[0].centre,
        &frame,
        None,
        &mut buf,
        &mut out,
    );
    out
}

fn f_of(out: &[(u32, f64, bool)], j: u32) -> f64 {
    out.iter().find(|o| o.0 == j).map_or(0.0, |o| o.1)
}

#[test]
fn closed_forms_agree_with_textbook_values() {
    // Parallel unit squares at distance 1: 0.1998 between the squares (Howell's C-11);
    // from the centre point it is larger, 0.2394. Perpendicular, from the centre point of
    // the shared-edge square: 0.25 − atan(1/√5)/(π√5) = 0.1901.
    assert!(
        (parallel_exact() - 0.239_45).abs() < 1e-4,
        "{}",
        parallel_exact()
    );
    assert!((perpendicular_exact() - 0.190_14).abs() < 1e-4);
}

#[test]
fn delta_ff_sums_to_one() {
    // Uniform: normalised by construction; non-uniform: exact integrals, no normalising —
    // either way only f64 rounding over ≤ 30k terms remains (~1e-13); 1e-6 is the spec.
    for n in [10, 50, 100] {
        let c = Hemicube::uniform(n);
        assert_eq!(c.cell_count(), 3 * n * n);
        assert!((c.delta_ff_sum() - 1.0).abs() < 1e-6, "uniform {n}");
    }
    for n in [5, 21, 51, 101] {
        let c = Hemicube::non_uniform(n);
        assert!((c.delta_ff_sum() - 1.0).abs() < 1e-6, "non-uniform {n}");
        let raw: f64 = c.delta_ffs().iter().sum();
        assert!((raw - 1.0).abs() < 1e-12, "non-uniform {n}: {raw}");
    }
}

#[test]
fn uniform_max_is_the_top_centre_cell() {
    for n in [10, 50, 100] {
        let c = Hemicube::uniform(n);
        let target = 4.0 / (PI * (n * n) as f64);
        // The centre cells sit at (±1/N, ±1/N): (1 + 2/N²)^−2 ≈ 1 − 4/N², and the
        // normalisation moves the sum by O(1/N²) too; 10/N² covers both.
        let tol = 10.0 / (n * n) as f64;
        assert!((c.max_delta_ff() / target - 1.0).abs() < tol, "{n}");
        let argmax = (0..c.cell_count())
            .max_by(|&a, &b| c.delta_ff[a].total_cmp(&c.delta_ff[b]))
            .unwrap();
        let (r, i) = (argmax / n, argmax % n);
        assert!(argmax < n * n && (r == n / 2 || r == n / 2 - 1) && (i == n / 2 || i == n / 2 - 1));
    }
}

#[test]
fn non_uniform_layout_is_symmetric_and_odd() {
    let c = Hemicube::non_uniform(20);
    assert_eq!(c.resolution(), 21);
    let b = &c.faces[0].u.bounds;
    let k = b.len() - 1;
    assert!(k % 2 == 1, "odd cell count across");
    assert!((b[k / 2] + 1.0 / 21.0).abs() < 1e-7 && (b[k / 2 + 1] - 1.0 / 21.0).abs() < 1e-7);
    for i in 0..=k {
        assert!((b[i] + b[k - i]).abs() < 1e-7);
    }
    assert_eq!(c.faces[1].v.bounds[0], 0.0);
    assert_eq!(*c.faces[1].v.bounds.last().unwrap(), 1.0);
}

/// The target 4/(πN²) (the top face's centre cell) and the non-uniform ΔF per cell over it.
fn ratios(c: &Hemicube) -> (f64, Vec<f64>) {
    let target = 4.0 / (PI * (c.n * c.n) as f64);
    (target, c.delta_ffs().iter().map(|f| f / target).collect())
}

/// Spread of the non-uniform ΔF over every odd N from 21 to 301, measured: max/target ≤
/// 1.0135 (N = 67; the side faces' central column, which is the full 2/N wide while the
/// lowered top step is narrower), min/target ≥ 0.669 (off-diagonal cells: (2a+1)(2b+1)/
/// (a+b+1)² ≥ 3/4 at a = x², b = y² ≤ 1, times the lowered step's (t/s)²). The top face's
/// diagonal cells agree among themselves within 0.83 % and carry 0.823–1.0014 of the
/// target (N = 51: 0.967–0.969; N = 101: 0.977–0.978).
#[test]
fn non_uniform_spread_is_bounded() {
    for n in (21..=301).step_by(2) {
        let c = Hemicube::non_uniform(n);
        let (_, r) = ratios(&c);
        let (lo, hi) = r
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(a, b), &x| (a.min(x), b.max(x)));
        // No cell above the centre's 4/(πN²) but for the central column's ≤ 1.4 %.
        assert!(hi < 1.02, "{n}: max {hi}");
        // ≥ 3/4 · (t/s)² with (t/s)² ≥ 0.82, less the midpoint rule's O(Δ²): 0.6.
        assert!(lo > 0.6, "{n}: min {lo}");
        // The diagonal cells of the top face (beyond the centre): all the same s²/π up to
        // the midpoint rule's O(Δ²) (≤ 0.83 % measured; 1.5 % allowed), ≤ the target.
        let k = c.faces[0].u.len();
        let diag: Vec<f64> = (k / 2 + 1..k).map(|d| r[d * k + d]).collect();
        let (dlo, dhi) = diag
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(a, b), &x| (a.min(x), b.max(x)));
        assert!(
            dhi / dlo < 1.015 && dhi < 1.005 && dlo > 0.8,
            "{n}: diagonal {dlo}..{dhi}"
        );
        if n == 51 || n == 101 {
            // Lowering s fills the axis with whole steps: by (k/(k+1))² at worst, here
            // within 4 % (measured 3.3 % and 2.3 %).
            assert!(dlo > 0.96, "{n}: diagonal {dlo}");
        }
    }
}

/// Sec. 1: cells of equal ΔF = 4/(πN²) would need π/12 of the uniform 3N². Measured: the
/// non-uniform cube has 1.079× (N = 51), 1.077× (N = 101) and at most 1.187× (odd N from
/// 21 to 301) that count; its largest cell is the uniform cube's.
#[test]
fn non_uniform_cell_count_is_near_pi_over_12() {
    for n in (21..=301).step_by(2) {
        let c = Hemicube::non_uniform(n);
        let ideal = PI / 12.0 * (3 * n * n) as f64;
        let ratio = c.cell_count() as f64 / ideal;
        // Never below 1/max (no cell carries more than max ΔF ≤ 1.0135 × target); cells
        // average 0.84–0.93 of the target (the off-diagonal ones carry less): ≤ 1.2.
        assert!(ratio > 0.98 && ratio < 1.2, "{n}: {ratio}");
        if n == 51 || n == 101 {
            assert!(ratio < 1.1, "{n}: {ratio}");
        }
    }
    // The same largest ΔF as the uniform cube of the same N (its centre cells sit at
    // ±1/N, (1 + 2/N²)^−2 below 4/(πN²)): within 1 % at N = 101.
    let (nu, un) = (Hemicube::non_uniform(101), Hemicube::uniform(100));
    let (t, _) = ratios(&nu);
    assert!((nu.max_delta_ff() / t - 1.0).abs() < 0.01);
    assert!((un.max_delta_ff() / (4.0 / (PI * 1e4)) - 1.0).abs() < 0.01);
}

#[test]
fn lut_matches_binary_search() {
    let mut rng = Pcg64Mcg::seed_from_u64(3);
    for c in [
        Hemicube::uniform(100),
        Hemicube::non_uniform(51),
        Hemicube::non_uniform(5),
    ] {
        for face in &c.faces {
            for axis in [&face.u, &face.v] {
                for _ in 0..2000 {
                    let x = rng.gen_range(-1.2f32..1.2);
                    assert_eq!(
                        axis.first_centre(x),
                        axis.centres.partition_point(|&c| c < x)
                    );
                    let b = axis.bound_lut.first_ge(&axis.bounds, x);
                    assert_eq!(b, axis.bounds.partition_point(|&c| c < x));
                }
                // Exactly on every value, too.
                for (k, &x) in axis.centres.iter().enumerate() {
                    assert_eq!(axis.first_centre(x), k);
                }
            }
        }
    }
}

/// Single shots at angles away from the grid's axes and diagonals, and the average over
/// the rotation (what the solvers' random turn per shot gives).
///
/// Measured over 200 angles (parallel / perpendicular): uniform 100: median |error|
/// 6.0e-5 / 1.7e-5, 90th percentile 3.1e-4 / 7.7e-5, worst 1.5e-3 / 7.6e-4; non-uniform
/// 51: median 9.0e-4 / 2.2e-4, 90th percentile 4.1e-3 / 1.0e-3, worst 9.5e-3 / 5.1e-3;
/// non-uniform 101: median 3.9e-4 / 9.7e-5, worst 5.8e-3 / 2.1e-3. The worst cases are
/// angles where the square's edges run along the cells' rows (or, for the uniform cube,
/// diagonals), or exactly through a column of cell centres: then a whole column is in or
/// out together, up to half of its ΔF. Averaged over the 200 angles: 4.0e-5 / 9.2e-6
/// (uniform 100), 5.2e-5 / 1.5e-4 (non-uniform 51).
#[test]
fn form_factors_match_closed_forms() {
    let par = scene(&[parallel_receiver()]);
    let perp = scene(&[perpendicular_receiver()]);
    let cases = [(&par, parallel_exact()), (&perp, perpendicular_exact())];
    // Edge aliasing at a generic angle: each cell the outline cuts counts whole or not at
    // all, ± up to half its ΔF with varying sign; ~200 such cells of 1.3e-4 (uniform 100)
    // or ~70 of ≤ 4.9e-4 (non-uniform 51) give a few 1e-4 to 3e-3 (the 90th
    // percentiles above); the tolerances sit above those.
    for (cube, tol, mean_tol) in [
        (Hemicube::uniform(100), 1.0e-3, 2.0e-4),
        (Hemicube::non_uniform(51), 5.0e-3, 5.0e-4),
    ] {
        for (k, &(mesh, exact)) in cases.iter().enumerate() {
            for angle in [0.3f32, 1.9, 4.4, 5.2] {
                let f = f_of(&shoot_once(&cube, mesh, angle), 1);
                assert!(
                    (f - exact).abs() < tol,
                    "case {k} N={} {angle}: {f} vs {exact}",
                    cube.n
                );
            }
            // Over the rotation the in/out errors cancel: what is left is the ΔF table's
            // own error (uniform: the centre-value table, O(1/N²)) and residual aliasing.
            let shots = 64;
            let mean = (0..shots)
                .map(|a| {
                    let angle = (a as f32 + 0.5) / shots as f32 * std::f32::consts::TAU;
                    f_of(&shoot_once(&cube, mesh, angle), 1)
                })
                .sum::<f64>()
                / shots as f64;
            assert!(
                (mean - exact).abs() < mean_tol,
                "case {k} N={} mean {mean} vs {exact}",
                cube.n
            );
        }
    }
}

/// The paper's jittered hemi-cube (Table 1: 100×100, each sample uniform in its cell),
/// averaged over 200 shots with random turns about the normal. Measured over 2,000 shots:
/// uniform 100: mean error −3.6e-5, single-shot sd 4.2e-4; non-uniform 51: −2.1e-4, sd
/// 1.8e-3. Uniform-in-cell jitter has an O(Δ²) bias: a cell the outline cuts is counted
/// with its mean density, while its covered part lies nearer the centre where the density
/// is higher (non-uniform 15: −2.9e-3, 14 standard errors).
#[test]
fn jittered_average_matches_closed_form() {
    let mesh = scene(&[parallel_receiver()]);
    let exact = parallel_exact();
    let mut rng = Pcg64Mcg::seed_from_u64(11);
    let mut buf = HemicubeBuffer::default();
    let mut out = Vec::new();
    for (cube, bias) in [
        (Hemicube::uniform(100), 1e-4),
        (Hemicube::non_uniform(51), 5e-4),
    ] {
        let shots = 200;
        let (mut sum, mut sum2) = (0.0, 0.0);
        for _ in 0..shots {
            let frame = Frame::new(Vec3::Z, rng.gen::<f32>() * std::f32::consts::TAU);
            let mut jit = Pcg64Mcg::seed_from_u64(rng.gen());
            cube.shoot(
                &mesh,
                0,
                Vec3::ZERO,
                &frame,
                Some(&mut jit),
                &mut buf,
                &mut out,
            );
            let f = f_of(&out, 1);
            sum += f;
            sum2 += f * f;
        }
        let mean = sum / shots as f64;
        let sd = (sum2 / shots as f64 - mean * mean).max(0.0).sqrt();
        // 5 standard errors of the mean plus the bias allowance (≥ 2× the measured bias).
        let tol = 5.0 * sd / (shots as f64).sqrt() + bias;
        assert!(
            (mean - exact).abs() < tol,
            "N={}: {mean} vs {exact} (sd {sd})",
            cube.n
        );
        assert!(sd > 0.0, "jitter changes the answer from shot to shot");
    }
}

#[test]
fn blocker_takes_the_receivers_share() {
    // Receiver at z = 1; a 2×2 blocker at z = 0.5 covers its whole cone from the centre.
    let receiver = parallel_receiver();
    let blocker = (Vec3::Z * 0.5, Vec3::Y, Vec3::X);
    let both = scene(&[receiver, blocker]);
    let alone = scene(&[blocker]);
    for cube in [Hemicube::uniform(100), Hemicube::non_uniform(51)] {
        let out = shoot_once(&cube, &both, 0.7);
        assert_eq!(f_of(&out, 1), 0.0, "receiver hidden");
        assert_eq!(out.len(), 1);
        // The blocker gets exactly what it gets alone (the receiver wins no cell of it).
        let f = f_of(&out, 2);
        assert_eq!(f, f_of(&shoot_once(&cube, &alone, 0.7), 1));
        // Half-sides 1 at distance 0.5 = half-sides 2 at distance 1: F = 0.831. Its
        // outline runs over the side faces at v = 0.5, where non-uniform 51 cells carry
        // up to 4.9e-4 each, ~70 of them: up to 1e-2 (measured 4.9e-3 at this angle; uniform
        // 100: 2.3e-4).
        let exact = 4.0 * top_corner_ff(2.0, 2.0);
        assert!((f - exact).abs() < 1e-2, "N={}: {f} vs {exact}", cube.n);
    }
}

#[test]
fn receiver_facing_away_is_seen_from_back() {
    // At z = 1 facing +z: its back faces the shooter.
    let mesh = scene(&[
        (Vec3::Z, Vec3::X * 0.5, Vec3::Y * 0.5),
        perpendicular_receiver(),
    ]);
    let out = shoot_once(&Hemicube::non_uniform(51), &mesh, 0.2);
    assert_eq!(out.len(), 2);
    assert_eq!(out[0].0, 1);
    assert!(out[0].2, "back");
    assert!(
        (out[0].1 - parallel_exact()).abs() < 3e-3,
        "a back face still counts"
    );
    assert!(!out[1].2, "front");
}

#[test]
fn patches_in_the_base_plane_are_not_drawn() {
    // A neighbour in the shooter's plane, facing up too: nothing but the far receiver.
    let mesh = scene(&[(Vec3::X, Vec3::X * 0.5, Vec3::Y * 0.5), parallel_receiver()]);
    let out = shoot_once(&Hemicube::uniform(50), &mesh, 0.4);
    assert_eq!(out.iter().map(|o| o.0).collect::<Vec<_>>(), vec![2]);
}

/// A closed 1×1×1 box of 2×2 patches per wall, all facing in (the vertices of neighbouring
/// patches computed apart, so shared edges differ by rounding), and a tilted blocker inside.
fn box_mesh() -> Mesh {
    let h = 0.25;
    let mut quads = Vec::new();
    for (c, e1, e2) in [
        (Vec3::ZERO, Vec3::X, Vec3::Y),
        (Vec3::Z, Vec3::Y, Vec3::X),
        (Vec3::new(0.5, 0.0, 0.5), Vec3::Z, Vec3::Y),
        (Vec3::new(-0.5, 0.0, 0.5), Vec3::Y, Vec3::Z),
        (Vec3::new(0.0, 0.5, 0.5), Vec3::X, Vec3::Z),
        (Vec3::new(0.0, -0.5, 0.5), Vec3::Z, Vec3::X),
    ] {
        for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
            quads.push((c + (e1 * a + e2 * b) * h, e1 * h, e2 * h));
        }
    }
    quads.push((
        Vec3::new(0.1, 0.0, 0.4),
        Vec3::new(0.2, 0.0, 0.1),
        Vec3::Y * 0.2,
    ));
    quad_mesh(&quads)
}

/// Inside a closed box every shot sees its whole hemisphere: the form factors sum to
/// Σ ΔF = 1 (to f64 rounding over ≤ 30k cells), with and without jitter, also when the
/// frame is square to the walls and cell centres fall exactly on edges patches share
/// (the blocker's normal ray hits the ceiling's middle edge).
#[test]
fn closed_box_sums_to_one() {
    let mesh = box_mesh();
    let mut rng = Pcg64Mcg::seed_from_u64(9);
    let mut buf = HemicubeBuffer::default();
    let mut out = Vec::new();
    for cube in [
        Hemicube::uniform(30),
        Hemicube::non_uniform(31),
        Hemicube::non_uniform(101),
    ] {
        for angle in [
            0.0f32,
            std::f32::consts::FRAC_PI_4,
            std::f32::consts::FRAC_PI_2,
            0.5,
            2.0,
        ] {
            for (i, p) in mesh.patches.iter().enumerate() {
                let frame = Frame::new(p.normal, angle);
                for jitter in [false, true] {
                    let jit = jitter.then_some(&mut rng);
                    cube.shoot(&mesh, i, p.centre, &frame, jit, &mut buf, &mut out);
                    let total: f64 = out.iter().map(|o| o.1).sum();
                    let msg = format!("N={} angle {angle} shooter {i} jitter {jitter}", cube.n);
                    assert!((total - 1.0).abs() < 1e-9, "{msg}: {total}");
                    // The walls face in; only the blocker can be seen from behind.
                    assert!(out.iter().all(|o| !o.2 || o.0 == 24), "{msg}");
                }
            }
        }
    }
}

#[test]
fn buffers_carry_nothing_between_shots() {
    let mesh = scene(&[parallel_receiver(), perpendicular_receiver()]);
    let cube = Hemicube::non_uniform(31);
    let mut buf = HemicubeBuffer::default();
    let (mut a, mut b, mut c) = (Vec::new(), Vec::new(), Vec::new());
    let f0 = Frame::new(Vec3::Z, 0.3);
    let p1 = &mesh.patches[1];
    let f1 = Frame::new(p1.normal, 1.1);
    let none = None::<&mut Pcg64Mcg>;
    cube.shoot(&mesh, 0, Vec3::ZERO, &f0, none, &mut buf, &mut a);
    cube.shoot::<Pcg64Mcg>(&mesh, 1, p1.centre, &f1, None, &mut buf, &mut b);
    cube.shoot::<Pcg64Mcg>(&mesh, 0, Vec3::ZERO, &f0, None, &mut buf, &mut c);
    assert_eq!(a, c);
    assert!(!b.is_empty() && b.iter().all(|o| o.0 != 1));
}

/// Shots run in parallel, one buffer per thread and the RNG seeded per shot (as the solvers
/// do): the same answers with 1 and 2 threads, bit for bit.
#[test]
fn same_answers_with_one_and_two_threads() {
    use rayon::prelude::*;
    let mesh = box_mesh();
    let cube = Hemicube::non_uniform(31);
    let run = |threads: usize, jitter: bool| -> Vec<Vec<(u32, f64, bool)>> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            (0..mesh.patches.len())
                .into_par_iter()
                .map_init(HemicubeBuffer::default, |buf, i| {
                    let mut rng = Pcg64Mcg::seed_from_u64(1000 + i as u64);
                    let p = &mesh.patches[i];
                    let frame = Frame::new(p.normal, rng.gen::<f32>() * std::f32::consts::TAU);
                    let mut out = Vec::new();
                    let jit = jitter.then_some(&mut rng);
                    cube.shoot(&mesh, i, p.centre, &frame, jit, buf, &mut out);
                    out
                })
                .collect()
        })
    };
    for jitter in [false, true] {
        let one = run(1, jitter);
        assert_eq!(one, run(2, jitter), "jitter {jitter}");
        assert!(one.iter().all(|out| out.len() > 5));
    }
}
