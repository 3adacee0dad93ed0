//! The solver on scenes with known answers.
mod common;

use common::*;
use radiosity::intersect::embree::EmbreeScene;
use radiosity::mesh::{self, MeshOptions};
use radiosity::solve::{self, SolveConfig, StopReason};

#[test]
fn closed_box_reaches_e_over_one_minus_rho() {
    let (rho, ke) = (0.5, 1.0 / std::f64::consts::PI); // E = 1 W/m²
    let scene = closed_box(1.0, 1.0, 1.0, material("wall", rho, ke));
    let m = mesh::build(
        &scene,
        &MeshOptions {
            patch_size: Some(0.25),
            two_sided: false,
        },
    );
    assert_eq!(m.patches.len(), 96);
    let isect = EmbreeScene::build(&m, |_| true).unwrap();
    let cfg = SolveConfig::default();
    let sol = solve::solve(&m, &scene.materials, &isect, &cfg, |_| {}).unwrap();
    let exact = 1.0 / (1.0 - rho);
    let errs: Vec<f64> = sol.b.iter().map(|b| (b[0] - exact).abs() / exact).collect();
    let rms = (errs.iter().map(|e| e * e).sum::<f64>() / errs.len() as f64).sqrt();
    let max = errs.iter().cloned().fold(0.0, f64::max);
    eprintln!("stats {:?} rms {rms} max {max}", sol.stats.stop_reason);
    eprintln!(
        "rays {} shots {} waves {}",
        sol.stats.rays, sol.stats.shots, sol.stats.waves
    );
    assert_eq!(sol.stats.stop_reason, Some(StopReason::Converged));
    assert!(rms < 0.05, "rms {rms}");
    assert!(sol.stats.energy.relative_residual() < 1e-9);
    assert_eq!(sol.stats.energy.escaped, [0.0; 3]);
}
