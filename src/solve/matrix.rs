//! The traditional radiosity algorithm (Cohen & Greenberg 1985), the baseline the paper beats:
//! compute the full form-factor matrix F with a uniform hemi-cube from every patch, then solve
//! B = E + ρ·F·B by Gauss–Seidel iteration: the matrix method (`--method gathering` on the
//! command line and in `summary.json`).
//!
//! Memory is quadratic (n² form factors, f32), so [`solve`] refuses scenes whose matrix would
//! exceed a cap, naming the patch count and the memory it would need. [`FormFactors`] is also
//! what lets a test feed the *same* form factors to the matrix method and to shooting
//! ([`shoot_matrix`]) and check that both reach the same solution.

use super::{scalar, EnergyBalance, Solution, SolveStats, StopReason, TracePoint};
use crate::mesh::Mesh;
use crate::sample::hemicube::{Hemicube, HemicubeBuffer};
use crate::sample::Frame;
use crate::scene::Material;
use rand::{Rng, SeedableRng};
use rayon::prelude::*;
use std::time::Instant;

/// A dense form-factor matrix: row i holds F_ij, the fraction of what leaves i that reaches j.
#[derive(Clone, Debug)]
pub struct FormFactors {
    pub n: usize,
    pub f: Vec<f32>,
}

impl FormFactors {
    /// Bytes an n-patch matrix needs.
    pub fn bytes_for(n: usize) -> u128 {
        (n as u128) * (n as u128) * std::mem::size_of::<f32>() as u128
    }

    #[inline]
    pub fn row(&self, i: usize) -> &[f32] {
        &self.f[i * self.n..(i + 1) * self.n]
    }

    /// Rows by the uniform N×N hemi-cube from every patch centre, in parallel, each turned by a
    /// random angle about its normal (seeded by (seed, row): independent of thread count).
    /// Form factors to back faces are kept out of the matrix (that light is absorbed there).
    pub fn by_hemicube(mesh: &Mesh, n_cube: usize, seed: u64) -> FormFactors {
        let n = mesh.patches.len();
        let cube = Hemicube::uniform(n_cube);
        let mut f = vec![0.0f32; n * n];
        f.par_chunks_mut(n.max(1)).enumerate().for_each_init(
            || (HemicubeBuffer::default(), Vec::new()),
            |(buf, out), (i, row)| {
                let p = &mesh.patches[i];
                let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(
                    seed ^ (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15),
                );
                let frame = Frame::new(p.normal, rng.gen::<f32>() * std::f32::consts::TAU);
                cube.shoot::<rand_pcg::Pcg64Mcg>(mesh, i, p.centre, &frame, None, buf, out);
                for &(j, fij, back) in out.iter() {
                    if !back {
                        row[j as usize] = fij as f32;
                    }
                }
            },
        );
        FormFactors { n, f }
    }
}

/// Why the matrix method was refused (`--method gathering`).
#[derive(Debug, thiserror::Error)]
#[error("gathering needs the full form-factor matrix: {patches} patches need {need_mib} MiB, over the cap of {cap_mib} MiB (--gather-cap-mib); use a shooting method, or a larger patch size")]
pub struct TooLarge {
    pub patches: usize,
    pub need_mib: u128,
    pub cap_mib: u128,
}

/// Checks the matrix fits under `cap_mib`.
pub fn check_size(patches: usize, cap_mib: u64) -> Result<(), TooLarge> {
    let need = FormFactors::bytes_for(patches);
    if need > cap_mib as u128 * (1 << 20) {
        return Err(TooLarge {
            patches,
            need_mib: need.div_ceil(1 << 20),
            cap_mib: cap_mib as u128,
        });
    }
    Ok(())
}

/// Gauss–Seidel on B = E + ρ·F·B, stopping when one sweep changes no patch's radiosity by more
/// than `stop_fraction` of the mean radiosity (the analogue of the shooting criterion, Sec. 3).
/// Returns B and the number of sweeps.
pub fn gauss_seidel(
    ff: &FormFactors,
    e: &[[f64; 3]],
    rho: &[[f64; 3]],
    area: &[f64],
    stop_fraction: f64,
    max_sweeps: usize,
) -> (Vec<[f64; 3]>, usize) {
    gauss_seidel_with(ff, e, rho, area, stop_fraction, max_sweeps, |_, _| {})
}

/// [`gauss_seidel`], calling `on_sweep(B, |change| per patch)` after every sweep.
pub fn gauss_seidel_with(
    ff: &FormFactors,
    e: &[[f64; 3]],
    rho: &[[f64; 3]],
    area: &[f64],
    stop_fraction: f64,
    max_sweeps: usize,
    mut on_sweep: impl FnMut(&[[f64; 3]], &[f64]),
) -> (Vec<[f64; 3]>, usize) {
    let n = ff.n;
    let mut b: Vec<[f64; 3]> = e.to_vec();
    let mut change = vec![0.0f64; n];
    let total_area: f64 = area.iter().sum();
    let mut sweeps = 0;
    while sweeps < max_sweeps {
        sweeps += 1;
        for i in 0..n {
            let row = ff.row(i);
            let mut received = [0.0f64; 3];
            for (j, &fij) in row.iter().enumerate() {
                if fij != 0.0 {
                    for c in 0..3 {
                        received[c] += fij as f64 * b[j][c];
                    }
                }
            }
            let new = [0, 1, 2].map(|c| e[i][c] + rho[i][c] * received[c]);
            change[i] = scalar(&[0, 1, 2].map(|c| (new[c] - b[i][c]).abs()));
            b[i] = new;
        }
        on_sweep(&b, &change);
        let max_change = change.iter().copied().fold(0.0, f64::max);
        let mean: f64 = b.iter().zip(area).map(|(b, a)| scalar(b) * a).sum::<f64>() / total_area;
        if max_change <= stop_fraction * mean {
            break;
        }
    }
    (b, sweeps)
}

/// The matrix method's own error estimate per patch (see [`super::estimate`]), from three parts:
/// - the form factors' error, seen through reciprocity: row i (i's hemi-cube) and column i
///   (A_j·F_ji/A_i, the other hemi-cubes) estimate the same exchange independently, so half
///   their difference, ρ_i·|Σ_j (F_ij − A_j F_ji/A_i)·B_j| / √2, measures what row i gets wrong
///   (point sampling from the patch centre, aliasing);
/// - as a floor, the hemi-cube's Poisson sampling (a cell of mean ΔF = 1/cells:
///   Var B_i ≈ ρ_i² Σ_j F_ij·B_j² / cells);
/// - the convergence still to come: the last sweep's change times q/(1 − q), q the sweep to
///   sweep ratio of the largest change (for the first sweep, the second sweep's change over
///   1 − q); before the first sweep, all of the reflected light.
fn matrix_estimate(
    ff: &FormFactors,
    area: &[f64],
    rho_s: &[f64],
    b_s: &[f64],
    e_s: &[f64],
    cells: usize,
    conv: Option<(&[f64], f64)>,
) -> Vec<f64> {
    let n = ff.n;
    // Column sums Σ_j A_j·B_j·F_ji, by a row-major pass.
    let mut col = vec![0.0f64; n];
    for j in 0..n {
        let w = area[j] * b_s[j];
        for (c, &f) in col.iter_mut().zip(ff.row(j)) {
            *c += w * f as f64;
        }
    }
    let rho_mean: f64 =
        rho_s.iter().zip(area).map(|(r, a)| r * a).sum::<f64>() / area.iter().sum::<f64>();
    let emitted: f64 = e_s.iter().zip(area).map(|(e, a)| e * a).sum();
    let owed_each = emitted * rho_mean / (1.0 - rho_mean.min(0.999)) / area.iter().sum::<f64>();
    (0..n)
        .into_par_iter()
        .map(|i| {
            let (mut direct, mut var) = (0.0, 0.0);
            for (&f, &bj) in ff.row(i).iter().zip(b_s) {
                direct += f as f64 * bj;
                var += f as f64 * bj * bj;
            }
            let var = rho_s[i] * rho_s[i] * var / cells as f64;
            let recip = col[i] / area[i];
            let d = rho_s[i] * (direct - recip).abs() / std::f64::consts::SQRT_2;
            let form = (d * d).max(std::f64::consts::FRAC_2_PI * var);
            let conv = match conv {
                Some((ch, factor)) => ch[i] * factor,
                None => owed_each,
            };
            (conv * conv + form).sqrt()
        })
        .collect()
}

/// Progressive shooting (Southwell iteration, as in Cohen et al. 1988) over the same linear
/// system B = E + ρ·F·B that [`gauss_seidel`] solves: the test twin of the matrix method. Shoots the
/// patch with the most unshot flux ΔB_i·A_i until max unshot radiosity is below `stop_fraction`
/// of the mean; patch j gains ρ_j·F_ji·ΔB_i (column i of F). Hemi-cube form factors are
/// reciprocal (A_i·F_ij = A_j·F_ji) only approximately, so shooting along row i instead, as a
/// hemi-cube shot does, would solve a slightly different system.
pub fn shoot_matrix(
    ff: &FormFactors,
    e: &[[f64; 3]],
    rho: &[[f64; 3]],
    area: &[f64],
    stop_fraction: f64,
) -> Vec<[f64; 3]> {
    let n = ff.n;
    let mut b: Vec<[f64; 3]> = e.to_vec();
    let mut unshot: Vec<[f64; 3]> = e.to_vec();
    let total_area: f64 = area.iter().sum();
    loop {
        let (i, _) = (0..n)
            .map(|k| (k, scalar(&unshot[k]) * area[k]))
            .fold((0, -1.0), |best, x| if x.1 > best.1 { x } else { best });
        let max_b = (0..n).map(|k| scalar(&unshot[k])).fold(0.0, f64::max);
        let mean: f64 = b.iter().zip(area).map(|(b, a)| scalar(b) * a).sum::<f64>() / total_area;
        if max_b <= stop_fraction * mean {
            return b;
        }
        let db = std::mem::replace(&mut unshot[i], [0.0; 3]);
        for j in 0..n {
            let fji = ff.f[j * n + i];
            if fji == 0.0 {
                continue;
            }
            for c in 0..3 {
                let gain = rho[j][c] * fji as f64 * db[c];
                unshot[j][c] += gain;
                b[j][c] += gain;
            }
        }
    }
}

/// The traditional method end to end: matrix by the uniform `n_cube` hemi-cube, then
/// Gauss–Seidel. The energy books are computed from the answer (the matrix method moves no energy
/// explicitly, so they close only as well as the hemi-cube's form factors are consistent).
pub fn solve(
    mesh: &Mesh,
    materials: &[Material],
    cfg: &super::SolveSettings,
    hooks: &super::RunHooks,
    mut on_trace: impl FnMut(&TracePoint),
) -> Solution {
    let (n_cube, seed, stop_fraction) = (cfg.hemicube_n, cfg.seed, cfg.stop_fraction);
    let reference = hooks.reference.as_deref().map(Vec::as_slice);
    let light_groups = hooks.light_groups.as_deref();
    let start = Instant::now();
    let n = mesh.patches.len();
    let ff = FormFactors::by_hemicube(mesh, n_cube, seed);
    let area: Vec<f64> = mesh.patches.iter().map(|p| p.area).collect();
    let e: Vec<[f64; 3]> = mesh
        .patches
        .iter()
        .map(|p| materials[p.material as usize].emission())
        .collect();
    let rho: Vec<[f64; 3]> = mesh
        .patches
        .iter()
        .map(|p| materials[p.material as usize].rho)
        .collect();
    let matrix_s = start.elapsed().as_secs_f64();
    let cells = Hemicube::uniform(n_cube).cell_count();
    let rho_s: Vec<f64> = rho.iter().map(scalar).collect();
    let b_now = |b: &[[f64; 3]]| -> Vec<f64> { b.iter().map(scalar).collect() };
    let mean_of =
        |b: &[f64]| b.iter().zip(&area).map(|(b, a)| b * a).sum::<f64>() / mesh.total_area();
    // Trace points: after the matrix (B = E), then after every sweep.
    let mut trace = Vec::new();
    let e_s: Vec<f64> = e.iter().map(scalar).collect();
    let mut point = |time_s: f64, b: &[[f64; 3]], conv: Option<(&[f64], f64)>| {
        let bs = b_now(b);
        let err = matrix_estimate(&ff, &area, &rho_s, &bs, &e_s, cells, conv);
        // The estimate of the true B: B plus the light still to come.
        let b_est: Vec<f64> = match conv {
            Some((ch, factor)) => bs.iter().zip(ch).map(|(b, c)| b + c * factor).collect(),
            None => bs.iter().zip(&err).map(|(b, e)| b + e).collect(),
        };
        let estimate = super::estimate::from_errors(&area, err.into_iter(), &b_est);
        let error = reference.map(|r| super::estimate::against(&area, b, r));
        let p = TracePoint {
            time_s,
            shots: n as u64,
            rays: 0,
            cells: (n * cells) as u64,
            max_unshot_b: 0.0,
            mean_b: mean_of(&bs),
            unshot_flux: 0.0,
            estimate,
            error,
        };
        on_trace(&p);
        trace.push(p);
    };
    // Before any sweep the whole reflected light is missing: count it as the error.
    point(matrix_s, &e, None);
    // The matrix method has no useful answer before it converges (the paper's point), so its trace is
    // written when it has: the convergence error of sweep k is then known, |B_k − B_last|, plus
    // the last sweep's own geometric tail, Δ_last·q/(1 − q) with q the ratio of the last two
    // sweeps' largest changes.
    let mut sweeps_seen: Vec<(f64, Vec<[f64; 3]>, f64)> = Vec::new();
    let mut last_change = vec![0.0; n];
    let (b, sweeps) =
        gauss_seidel_with(&ff, &e, &rho, &area, stop_fraction, 100_000, |b, change| {
            let max = change.iter().copied().fold(0.0, f64::max);
            sweeps_seen.push((start.elapsed().as_secs_f64(), b.to_vec(), max));
            last_change.copy_from_slice(change);
        });
    let k = sweeps_seen.len();
    let q = if k >= 2 && sweeps_seen[k - 2].2 > 0.0 {
        (sweeps_seen[k - 1].2 / sweeps_seen[k - 2].2).min(0.999)
    } else {
        0.0
    };
    let tail: Vec<f64> = last_change.iter().map(|c| c * q / (1.0 - q)).collect();
    let b_last: Vec<f64> = b.iter().map(scalar).collect();
    for (t, bk, _) in &sweeps_seen {
        let conv: Vec<f64> = bk
            .iter()
            .zip(&b_last)
            .zip(&tail)
            .map(|((x, l), t)| (scalar(x) - l).abs() + t)
            .collect();
        point(*t, bk, Some((&conv, 1.0)));
    }

    let energy = energy_balance(&ff, &b, &e, &rho, &area);
    let seconds = start.elapsed().as_secs_f64();
    let stats = SolveStats {
        shots: n as u64,
        rays: 0,
        hemicube_shots: n as u64,
        hemicube_cells: (n as u64) * Hemicube::uniform(n_cube).cell_count() as u64,
        waves: sweeps as u64,
        seconds,
        energy_per_ray: 0.0,
        stop_reason: Some(StopReason::Converged),
        energy,
        trace,
        ..SolveStats::default()
    };
    // Per-light channels: the same matrix, each light's emission alone (B is linear in E).
    let channels = light_groups
        .map(|g| light_channels(&ff, g, &e, &rho, &area, stop_fraction))
        .unwrap_or_default();
    Solution {
        b,
        unshot: vec![[0.0; 3]; n],
        stats,
        channels,
        shooting: None,
        back: Vec::new(),
    }
}

/// Where the light went, from the answer B: i sends B_i·A_i·F_ij to j.
fn energy_balance(
    ff: &FormFactors,
    b: &[[f64; 3]],
    e: &[[f64; 3]],
    rho: &[[f64; 3]],
    area: &[f64],
) -> EnergyBalance {
    let n = ff.n;
    let mut energy = EnergyBalance::default();
    let mut arrived = vec![[0.0f64; 3]; n];
    for i in 0..n {
        let row = ff.row(i);
        let sum_f: f64 = row.iter().map(|&x| x as f64).sum();
        for c in 0..3 {
            energy.emitted[c] += e[i][c] * area[i];
            energy.escaped[c] += b[i][c] * area[i] * (1.0 - sum_f).max(0.0);
        }
        for (j, &fij) in row.iter().enumerate() {
            if fij != 0.0 {
                for c in 0..3 {
                    arrived[j][c] += b[i][c] * area[i] * fij as f64;
                }
            }
        }
    }
    for j in 0..n {
        for c in 0..3 {
            energy.absorbed[c] += (1.0 - rho[j][c]) * arrived[j][c];
        }
    }
    energy
}

/// Per-light channels: the same matrix, each light group's emission alone (B is linear in E).
fn light_channels(
    ff: &FormFactors,
    g: &super::lights::LightGroups,
    e: &[[f64; 3]],
    rho: &[[f64; 3]],
    area: &[f64],
    stop_fraction: f64,
) -> Vec<super::LightChannel> {
    g.names
        .iter()
        .enumerate()
        .map(|(c, name)| {
            let e_c: Vec<[f64; 3]> = e
                .iter()
                .zip(&g.of_patch)
                .map(|(e, &grp)| if grp as usize == c { *e } else { [0.0; 3] })
                .collect();
            super::LightChannel {
                name: name.clone(),
                b: gauss_seidel(ff, &e_c, rho, area, stop_fraction, 100_000).0,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small random but physically plausible matrix: rows sum to < 1, reciprocity holds.
    type System = (FormFactors, Vec<[f64; 3]>, Vec<[f64; 3]>, Vec<f64>);

    fn random_system(n: usize, seed: u64) -> System {
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
        let area: Vec<f64> = (0..n).map(|_| rng.gen_range(0.5..2.0)).collect();
        // Symmetric "exchange" G_ij = A_i F_ij; F_ij = G_ij / A_i.
        let mut g = vec![0.0f64; n * n];
        for i in 0..n {
            for j in 0..i {
                let x = rng.gen_range(0.0..1.0);
                g[i * n + j] = x;
                g[j * n + i] = x;
            }
        }
        let scale = (0..n)
            .map(|i| (0..n).map(|j| g[i * n + j]).sum::<f64>() / area[i])
            .fold(0.0, f64::max)
            / 0.9;
        let f = (0..n * n)
            .map(|k| (g[k] / scale / area[k / n]) as f32)
            .collect();
        let e = (0..n)
            .map(|i| {
                if i % 7 == 0 {
                    [1.0, 0.5, 0.2]
                } else {
                    [0.0; 3]
                }
            })
            .collect();
        let rho = (0..n).map(|_| [0.7, 0.5, 0.3]).collect();
        (FormFactors { n, f }, e, rho, area)
    }

    /// Fed the same form factors, the matrix method (Gauss–Seidel) and shooting reach the same B:
    /// both converge to the unique solution of B = E + ρFB; with the criterion at 1e-9 of the
    /// mean, they differ by far less than 1e-6 relative.
    #[test]
    fn gauss_seidel_and_shooting_agree_on_the_same_matrix() {
        let (ff, e, rho, area) = random_system(60, 3);
        let (bg, sweeps) = gauss_seidel(&ff, &e, &rho, &area, 1e-10, 10_000);
        assert!(sweeps > 3 && sweeps < 10_000);
        let bs = shoot_matrix(&ff, &e, &rho, &area, 1e-10);
        for (g, s) in bg.iter().zip(&bs) {
            for c in 0..3 {
                assert!(
                    (g[c] - s[c]).abs() <= 1e-6 * g[c].abs().max(1e-3),
                    "{g:?} vs {s:?}"
                );
            }
        }
    }

    #[test]
    fn the_cap_refuses_with_the_numbers() {
        assert!(check_size(1000, 100).is_ok()); // 3.8 MiB
        let e = check_size(100_000, 1024).unwrap_err(); // 37 GiB
        assert_eq!(e.patches, 100_000);
        let msg = e.to_string();
        assert!(
            msg.contains("100000 patches") && msg.contains("38147 MiB"),
            "{msg}"
        );
    }
}
