//! Daylight: the sky, ground glow and sun as distant emitters that shoot first, and
//! glazing. Furnaces: an unobstructed horizontal plane under a sky receives exactly the sky's
//! horizontal illuminance; a closed box receives nothing; a pane of transmittance T passes T.

use glam::{vec3, Vec3};
use radiosity::scene::{Material, Scene};
use radiosity::sky::{SkyKind, SkyLevel, SkySpec, SunLevel, EFFICACY};
use radiosity::solve::{Solution, SolveSettings};

use crate::common;
use crate::common::solve_mesh;
use crate::scene_builder::{closed_box, material, mesh_at, quad, scene};

fn sky(kind: SkyKind, sun: Option<(f64, f64)>) -> SkySpec {
    SkySpec {
        kind,
        level: SkyLevel::HorizontalIlluminance(10_000.0),
        sun_position: sun.map(|(alt, azi)| radiosity::sky::SolarAngles::new(alt, azi).unwrap()),
        sun: sun.map(|_| SunLevel::NormalIlluminance(60_000.0)),
        ..SkySpec::default()
    }
}

fn solve(scene: &Scene, spec: SkySpec) -> (radiosity::mesh::Mesh, Solution) {
    let m = mesh_at(scene, Some(0.5));
    let cfg = SolveSettings {
        sky: Some(spec),
        ..SolveSettings::default()
    };
    let sol = solve_mesh(scene, &m, &cfg);
    let e = &sol.stats.energy;
    assert!(e.relative_residual() < 1e-9, "{e:?}");
    (m, sol)
}

/// Area-weighted mean illuminance (lux, green channel) over the patches `keep` picks.
fn lux(
    m: &radiosity::mesh::Mesh,
    sol: &Solution,
    rho: f64,
    keep: impl Fn(Vec3, Vec3) -> bool,
) -> f64 {
    let (mut sum, mut area) = (0.0, 0.0);
    for (p, b) in m.patches.iter().zip(&sol.b) {
        if keep(p.centre, p.normal) {
            sum += b[1] / rho * p.area;
            area += p.area;
        }
    }
    assert!(area > 0.0);
    EFFICACY * sum / area
}

/// A 10 m × 10 m horizontal plane facing up (Y), ρ = 0.5.
fn plane() -> Scene {
    let mut s = scene("", vec![material("grey", 0.5, 0.0)]);
    let p = |x, z| vec3(x, 0.0, z);
    quad(&mut s, [p(-5., 5.), p(5., 5.), p(5., -5.), p(-5., -5.)], 0);
    s
}

#[test]
fn an_unobstructed_plane_receives_the_skys_horizontal_illuminance() {
    let s = plane();
    for kind in [SkyKind::Uniform, SkyKind::Overcast] {
        let (m, sol) = solve(&s, sky(kind, None));
        let e = lux(&m, &sol, 0.5, |_, _| true);
        assert!((e - 10_000.0).abs() < 50.0, "{kind:?}: {e} lux");
    }
    // With a sun 40° up: the sky plus 60,000·sin 40° lux.
    let (m, sol) = solve(&s, sky(SkyKind::Overcast, Some((40.0, 10.0))));
    let e = lux(&m, &sol, 0.5, |_, _| true);
    let want = 10_000.0 + 60_000.0 * 40f64.to_radians().sin();
    assert!((e - want).abs() < 0.01 * want, "{e} lux, want {want}");
}

#[test]
fn a_closed_box_under_a_sky_and_sun_receives_nothing() {
    let s = closed_box(4.0, 3.0, 4.0, material("wall", 0.6, 0.0));
    let (_, sol) = solve(&s, sky(SkyKind::Clear, Some((30.0, 20.0))));
    assert!(sol.b.iter().all(|b| *b == [0.0; 3]));
    let e = &sol.stats.energy;
    assert!(e.back_fraction() == 0.0, "{e:?}");
}

/// The closed box with its roof (y = 3) replaced: open, or a pane of transmittance 0.7.
fn roofed(glass: bool) -> Scene {
    roofed_with(glass.then(|| Material {
        name: "glass".into(),
        transmittance: 0.7,
        ..Material::default()
    }))
}

/// The closed box with its roof (y = 3) replaced by a pane of `glass`, or open (`None`).
fn roofed_with(glass: Option<Material>) -> Scene {
    let mut s = closed_box(4.0, 3.0, 4.0, material("wall", 0.6, 0.0));
    let roof = s
        .polygons
        .iter()
        .position(|p| {
            let idx = &s.indices[p.first as usize..(p.first + p.len) as usize];
            idx.iter().all(|&i| s.positions[i as usize].y == 3.0)
        })
        .unwrap();
    if let Some(glass) = glass {
        s.materials.push(glass);
        s.polygons[roof].material = 1;
    } else {
        s.polygons.remove(roof);
    }
    s
}

#[test]
fn glazing_passes_its_transmittance_and_the_books_close() {
    let floor = |c: Vec3, n: Vec3| c.y < 1e-3 && n.y > 0.9;
    let (mo, open) = solve(&roofed(false), sky(SkyKind::Uniform, None));
    let (mg, glazed) = solve(&roofed(true), sky(SkyKind::Uniform, None));
    let (eo, eg) = (lux(&mo, &open, 0.6, floor), lux(&mg, &glazed, 0.6, floor));
    // A black pane (ρ = 0) of T = 0.7: every path into the box crosses it once.
    assert!((eg / eo - 0.7).abs() < 0.02, "glazed {eg} / open {eo}");
    // The pane is two-sided: light from outside is not lost on its back.
    assert!(glazed.stats.energy.back_fraction() < 1e-9);
}

/// A black pane (ρ = 0) of tinted glass: T_c = 0.2 0.6 0.3, T = their mean.
fn tinted_glass() -> Material {
    let rgb = [0.2, 0.6, 0.3];
    Material {
        name: "glass".into(),
        transmittance: (rgb[0] + rgb[1] + rgb[2]) / 3.0,
        transmittance_rgb: Some(rgb),
        ..Material::default()
    }
}

/// Area-weighted mean irradiance per channel (W/m²) over the floor's patches.
fn floor_irradiance(m: &radiosity::mesh::Mesh, sol: &Solution, rho: f64) -> [f64; 3] {
    let (mut sum, mut area) = ([0.0; 3], 0.0);
    for (p, b) in m.patches.iter().zip(&sol.b) {
        if p.centre.y < 1e-3 && p.normal.y > 0.9 {
            for q in 0..3 {
                sum[q] += b[q] / rho * p.area;
            }
            area += p.area;
        }
    }
    sum.map(|s| s / area)
}

/// Docs/design.md §9, "Tinted glazing": rays go through a pane with probability T (the mean)
/// and carry T_c / T per channel on. Every path into the box crosses the black pane once, so
/// each channel of the floor's irradiance is T_c of the open box's, within the noise; the
/// books close per channel; per-light channels still sum to B.
#[test]
fn tinted_glazing_passes_each_channel_its_own_transmittance() {
    use radiosity::solve::lights::{LightGroups, SKY_CHANNEL, SUN_CHANNEL};
    let rgb = tinted_glass().transmittance_rgb.unwrap();
    let specs = [
        sky(SkyKind::Uniform, None),
        sky(SkyKind::Clear, Some((50.0, 20.0))),
    ];
    // Shooting alone, and with the final gather (which sees through panes by T_c).
    for (spec, final_gather) in specs.iter().flat_map(|s| [(s, false), (s, true)]) {
        let cfg = SolveSettings {
            sky: Some(*spec),
            final_gather,
            ..SolveSettings::default()
        };
        let open_scene = roofed(false);
        let mo = mesh_at(&open_scene, Some(0.5));
        let open = solve_mesh(&open_scene, &mo, &cfg);
        let s = roofed_with(Some(tinted_glass()));
        let m = mesh_at(&s, Some(0.5));
        let hooks = radiosity::solve::RunHooks {
            light_groups: Some(std::sync::Arc::new(LightGroups {
                names: vec![SKY_CHANNEL.into(), SUN_CHANNEL.into()],
                of_patch: vec![u32::MAX; m.patches.len()],
            })),
            ..Default::default()
        };
        let tinted = common::solve_mesh_with(&s, &m, &cfg, &hooks);
        let e = &tinted.stats.energy;
        assert!(e.relative_residual() < 1e-9, "{e:?}");
        let (eo, eg) = (
            floor_irradiance(&mo, &open, 0.6),
            floor_irradiance(&m, &tinted, 0.6),
        );
        // Shooting alone scatters about 1.6 % over seeds here (12 seeds: mean 0.998 of the
        // tint); the gather about a third of that.
        let tol = if final_gather { 0.03 } else { 0.06 };
        for q in 0..3 {
            let ratio = eg[q] / eo[q];
            assert!(
                (ratio / rgb[q] - 1.0).abs() < tol,
                "{:?}: channel {q}: tinted {} / open {} = {ratio}, want {}",
                spec.kind,
                eg[q],
                eo[q],
                rgb[q]
            );
        }
        // Behind a black pane every path carries the same T_c / T, so the channels differ by
        // the tint alone: to rounding, not to noise.
        let per = [0, 1, 2].map(|q| eg[q] / eo[q] / rgb[q]);
        assert!(
            (per[0] / per[1] - 1.0).abs() < 1e-9 && (per[2] / per[1] - 1.0).abs() < 1e-9,
            "{per:?}"
        );
        // The sky's and the sun's channels still sum to B through tinted glass.
        for (j, b) in tinted.b.iter().enumerate() {
            for (q, bq) in b.iter().enumerate() {
                let sum: f64 = tinted.channels.iter().map(|c| c.b[j][q]).sum();
                assert!(
                    (sum - bq).abs() <= 1e-9 * bq.max(1e-12),
                    "patch {j}: {sum} vs {bq}"
                );
            }
        }
    }
}

/// A tinted pane that reflects more of a channel than the mean T leaves to land (ρ_b = 0.9 >
/// 1 − T = 0.38: its rays that land keep ρ_b / (1 − T) > 1 of that channel, unclamped) still
/// reflects ρ_c of the sky's light in each channel, shooting alone, and the books close.
#[test]
fn a_tinted_pane_reflects_rho_per_channel_even_where_rho_exceeds_one_minus_t() {
    let mut s = plane();
    s.materials[0] = Material {
        name: "glass".into(),
        rho: [0.05, 0.05, 0.9],
        transmittance: (0.9 + 0.9 + 0.05) / 3.0,
        transmittance_rgb: Some([0.9, 0.9, 0.05]),
        ..Material::default()
    };
    let spec = sky(SkyKind::Uniform, None);
    let m = mesh_at(&s, Some(0.5));
    let cfg = SolveSettings {
        sky: Some(spec),
        final_gather: false,
        ..SolveSettings::default()
    };
    let sol = solve_mesh(&s, &m, &cfg);
    let e = &sol.stats.energy;
    assert!(e.relative_residual() < 1e-9, "{e:?}");
    let horizontal = 10_000.0 / EFFICACY;
    let (mut b, mut area) = ([0.0; 3], 0.0);
    for (p, bj) in m.patches.iter().zip(&sol.b) {
        if p.normal.y > 0.9 {
            for q in 0..3 {
                b[q] += bj[q] * p.area;
            }
            area += p.area;
        }
    }
    for (q, (bq, rho)) in b.iter().zip(s.materials[0].rho).enumerate() {
        let want = rho * horizontal;
        let got = bq / area;
        assert!(
            (got / want - 1.0).abs() < 0.02,
            "channel {q}: B {got}, want {want}"
        );
    }
}

/// Grey glazing whose colour is given (T_c = T in every channel) solves exactly as grey
/// glazing without one: its tint factor is 1 and is never applied.
#[test]
fn grey_glazing_with_a_colour_solves_bit_for_bit_as_without() {
    let grey = |rgb: Option<[f64; 3]>| Material {
        name: "glass".into(),
        transmittance: 0.5,
        transmittance_rgb: rgb,
        rho: [0.1; 3],
        ..Material::default()
    };
    let spec = sky(SkyKind::Clear, Some((50.0, 20.0)));
    let (_, a) = solve(&roofed_with(Some(grey(None))), spec);
    let (_, b) = solve(&roofed_with(Some(grey(Some([0.5; 3])))), spec);
    assert_eq!(a.b, b.b);
    assert_eq!(a.stats.energy.absorbed, b.stats.energy.absorbed);
}

/// The sensors (`--grid`) and the gathered picture see through tinted glass per channel: a
/// camera ray through the pane carries T_c, and sensors on the floor of the glazed box read
/// T_c of the open box's irradiance per channel.
#[test]
fn sensors_and_the_gathered_picture_see_the_tint() {
    use radiosity::intersect::embree::EmbreeScene;
    use radiosity::light::LightAt;
    let spec = sky(SkyKind::Uniform, None);
    let skyl = radiosity::sky::Sky::new(&spec).unwrap();
    let rgb = tinted_glass().transmittance_rgb.unwrap();
    let sensors: Vec<(Vec3, Vec3)> = [(1.0, 1.0), (2.0, 2.0), (3.0, 1.5), (1.5, 3.0)]
        .iter()
        .map(|&(x, z)| (vec3(x, 0.8, z), Vec3::Y))
        .collect();
    let mut h = Vec::new();
    for glass in [None, Some(tinted_glass())] {
        let s = roofed_with(glass);
        let (m, sol) = solve(&s, spec);
        let isect = EmbreeScene::build(&m, |_| true).unwrap();
        let e = LightAt::new(&m, &s.materials, &isect, &sol.b, Some(&skyl), None)
            .sensor_irradiance(&sensors, 4096, 7);
        let mean = [0, 1, 2].map(|q| e.iter().map(|v| v[q]).sum::<f64>() / e.len() as f64);
        h.push(mean);
        if s.materials.len() > 1 {
            let g = LightAt::new(&m, &s.materials, &isect, &sol.b, Some(&skyl), None);
            let seen = g.view(vec3(2.0, 10.0, 2.0), vec3(0.0, -1.0, 0.0));
            assert!(seen.hit.is_some());
            let off = (0..3).map(|q| (seen.through[q] - rgb[q]).abs());
            assert!(off.fold(0.0, f64::max) < 1e-12, "{:?}", seen.through);
        }
    }
    let per = [0, 1, 2].map(|q| h[1][q] / h[0][q] / rgb[q]);
    for q in 0..3 {
        assert!(
            (per[q] - 1.0).abs() < 0.04,
            "channel {q}: {per:?} of the tint"
        );
        assert!(
            (per[q] / per[1] - 1.0).abs() < 1e-9,
            "channels differ by more than the tint: {per:?}"
        );
    }
}

#[test]
fn sky_flags_a_user_gets_wrong_are_one_line_and_exit_2() {
    common::assert_user_error(
        &["solve", "--sky", "clear", "--out", "/tmp/x"],
        &["--sky", "sun"],
    );
    common::assert_user_error(
        &["solve", "--sun", "30,20", "--out", "/tmp/x"],
        &["--sun", "--sky"],
    );
    common::assert_user_error(
        &[
            "solve",
            "--sky",
            "overcast",
            "--sun",
            "2026-06-21T12:00+02:00",
            "--out",
            "/tmp/x",
        ],
        &["--site"],
    );
    common::assert_user_error(&["solve", "--grid", "0.8", "--out", "/tmp/x"], &["--grid"]);
    common::assert_user_error(
        &[
            "solve", "--sky", "overcast", "--method", "hemicube", "--out", "/tmp/x",
        ],
        &["--sky"],
    );
}

#[test]
fn a_daylit_solve_writes_the_grid_and_the_sky() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("room.obj");
    // A 4 × 3 × 4 m room open at the top (no roof), the sky lighting its floor.
    std::fs::write(
        &obj,
        "mtllib room.mtl\nusemtl wall\n\
         v 0 0 0\nv 4 0 0\nv 4 0 4\nv 0 0 4\nv 0 3 0\nv 4 3 0\nv 4 3 4\nv 0 3 4\n\
         f 1 4 3 2\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n",
    )
    .unwrap();
    std::fs::write(dir.path().join("room.mtl"), "newmtl wall\nKd 0.5 0.5 0.5\n").unwrap();
    let out = dir.path().join("o");
    let grid = "0.8,1.0";
    let (code, _, err) = common::run(&[
        "solve",
        obj.to_str().unwrap(),
        "--sky",
        "overcast",
        "--grid",
        grid,
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let csv = std::fs::read_to_string(out.join("grid.csv")).unwrap();
    let mut lines = csv.lines();
    // The columns of old first, in their order; where each sensor is after them.
    assert_eq!(
        lines.next(),
        Some("x,y,z,nx,ny,nz,lux,df,storey,room,indoor")
    );
    let lux: Vec<f64> = lines
        .map(|l| l.split(',').nth(6).unwrap().parse().unwrap())
        .collect();
    assert_eq!(lux.len(), 16, "a 4 × 4 lattice at 1 m over the floor");
    // Open above, walls 3 m high: less than the unobstructed 10,000 lux, far more than 0.
    assert!(lux.iter().all(|l| *l > 1000.0 && *l < 10_000.0), "{lux:?}");
    assert!(image::open(out.join("grid.png")).is_ok());
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(s["sky"]["kind"], "overcast");
    assert!((s["sky"]["sky_illuminance"].as_f64().unwrap() - 10_000.0).abs() < 1e-6);
    assert_eq!(s["grid"]["points"], 16);
    // CPU seconds beside the wall's: the solve and the grid did work, within the process's.
    let cpu = |k: &str| s["cpu_seconds"][k].as_f64().unwrap();
    assert!(
        cpu("solve") > 0.0 && cpu("grid") > 0.0,
        "{}",
        s["cpu_seconds"]
    );
    assert!(
        cpu("total") >= cpu("solve") + cpu("grid"),
        "{}",
        s["cpu_seconds"]
    );
    let patches = std::fs::read_to_string(out.join("patches.csv")).unwrap();
    assert!(patches.lines().next().unwrap().ends_with(",lux,df"));
    assert!(!patches.contains("NaN") && !csv.contains("NaN"));
}

#[test]
fn per_light_channels_keep_the_sky_and_the_sun_apart_and_sum_to_b() {
    use radiosity::solve::lights::{LightGroups, SKY_CHANNEL, SUN_CHANNEL};
    let s = roofed(false);
    let m = mesh_at(&s, Some(0.5));
    let cfg = SolveSettings {
        sky: Some(sky(SkyKind::Clear, Some((50.0, 20.0)))),
        ..SolveSettings::default()
    };
    let hooks = radiosity::solve::RunHooks {
        light_groups: Some(std::sync::Arc::new(LightGroups {
            names: vec![SKY_CHANNEL.into(), SUN_CHANNEL.into()],
            of_patch: vec![u32::MAX; m.patches.len()],
        })),
        ..Default::default()
    };
    let sol = common::solve_mesh_with(&s, &m, &cfg, &hooks);
    assert_eq!(sol.channels.len(), 2);
    let (mut sky_sum, mut sun_sum) = (0.0, 0.0);
    for (j, b) in sol.b.iter().enumerate() {
        for (q, bq) in b.iter().enumerate() {
            let sum = sol.channels[0].b[j][q] + sol.channels[1].b[j][q];
            assert!(
                (sum - bq).abs() <= 1e-9 * bq.max(1e-12),
                "patch {j}: {sum} vs {bq}"
            );
        }
        sky_sum += sol.channels[0].b[j][1] * m.patches[j].area;
        sun_sum += sol.channels[1].b[j][1] * m.patches[j].area;
    }
    assert!(sky_sum > 0.0 && sun_sum > 0.0, "{sky_sum} {sun_sum}");
}

/// From the command line: a daylit `solve --per-light --save` keeps `(sky)` and `(sun)` in the
/// saved file, their channels sum to B there too, and `relight` rescales them without solving
/// again: the sun off leaves the sky's picture, both off a black one.
#[test]
fn relight_a_day_from_the_saved_sky_and_sun_channels() {
    use radiosity::export::solution::SavedSolution;
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).display().to_string();
    std::fs::write(
        p("room.obj"),
        "mtllib room.mtl\nusemtl wall\n\
         v 0 0 0\nv 4 0 0\nv 4 0 4\nv 0 0 4\nv 0 3 0\nv 4 3 0\nv 4 3 4\nv 0 3 4\n\
         f 1 4 3 2\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n",
    )
    .unwrap();
    std::fs::write(p("room.mtl"), "newmtl wall\nKd 0.5 0.5 0.5\n").unwrap();
    let (code, _, err) = common::run(&[
        "solve",
        &p("room.obj"),
        "--sky",
        "clear",
        "--sun",
        "50,20",
        "--per-light",
        "--save",
        &p("s.rad"),
        "--out",
        &p("o"),
        "--quiet",
    ]);
    assert_eq!(code, 0, "{err}");
    let saved = SavedSolution::load(std::path::Path::new(&p("s.rad"))).unwrap();
    let names: Vec<&str> = saved.channels.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["(sky)", "(sun)"]);
    for (j, b) in saved.b.iter().enumerate() {
        for (q, bq) in b.iter().enumerate() {
            let sum = saved.channels[0].b[j][q] + saved.channels[1].b[j][q];
            assert!((sum - bq).abs() <= 1e-9 * bq.max(1e-12), "patch {j}");
        }
    }
    // Mean pixel of a relit picture (linear .exr: what relight's weights scale).
    let mean = |weights: &[&str], name: &str| {
        let mut args = vec!["relight".to_string(), p("s.rad")];
        for w in weights {
            args.extend(["--weight".to_string(), w.to_string()]);
        }
        args.extend(["--out".to_string(), p(name)]);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let (code, _, err) = common::run(&args);
        assert_eq!(code, 0, "{err}");
        let img = image::open(p(name)).unwrap().to_rgb32f();
        img.pixels().map(|px| f64::from(px[1])).sum::<f64>() / img.pixels().len() as f64
    };
    let day = mean(&[], "day.exr");
    let sky_only = mean(&["(sun)=0"], "sky.exr");
    let dark = mean(&["(sun)=0", "(sky)=0"], "dark.exr");
    let doubled = mean(&["(sun)=2", "(sky)=2"], "doubled.exr");
    assert!(
        day > 0.0 && sky_only > 0.0 && sky_only < day,
        "{day} {sky_only}"
    );
    assert_eq!(dark, 0.0);
    assert!((doubled / day - 2.0).abs() < 1e-4, "{doubled} / {day}");
}

/// `--zenith` decides which way is up for the work plane even without a sky (a Z-up model lit
/// by its own lamp): the sensors stand 0.8 m off the wall that faces +Z, facing +Z.
#[test]
fn the_work_plane_follows_zenith_without_a_sky() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).display().to_string();
    std::fs::write(
        p("room.obj"),
        "mtllib room.mtl\n\
         v 0 0 0\nv 4 0 0\nv 4 0 4\nv 0 0 4\nv 0 3 0\nv 4 3 0\nv 4 3 4\nv 0 3 4\n\
         usemtl lamp\nf 1 4 3 2\nusemtl wall\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\nf 5 6 7 8\n",
    )
    .unwrap();
    std::fs::write(
        p("room.mtl"),
        "newmtl wall\nKd 0.5 0.5 0.5\nnewmtl lamp\nKd 0.5 0.5 0.5\nKe 1 1 1\n",
    )
    .unwrap();
    let (code, _, err) = common::run(&[
        "solve",
        &p("room.obj"),
        "--grid",
        "0.8,1",
        "--zenith",
        "0,0,1",
        "--north",
        "0,1,0",
        "--out",
        &p("o"),
        "--quiet",
    ]);
    assert_eq!(code, 0, "{err}");
    let csv = std::fs::read_to_string(dir.path().join("o/grid.csv")).unwrap();
    let rows: Vec<Vec<f64>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert!(!rows.is_empty());
    for r in &rows {
        assert!((r[2] - 0.8).abs() < 1e-4 && r[5] == 1.0, "{r:?}");
        assert!(r[6] > 0.0, "{r:?}");
    }
    // A zenith that is no direction is refused before any work.
    let (code, _, err) = common::run(&[
        "solve",
        &p("room.obj"),
        "--grid",
        "0.8,1",
        "--zenith",
        "0,0,0",
        "--out",
        &p("o2"),
        "--quiet",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--zenith"), "{err}");
}
