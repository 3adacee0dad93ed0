//! The final-gather renderer (`--shading gather`, `render::gather`): a furnace renders flat at
//! its analytic radiosity, the picture is the same for a seed on any thread count, a small
//! light's umbra is dark where the Gouraud picture blurs it, and the commands take the flags.

use crate::common::*;
use crate::scene_builder::*;
use glam::{vec3, Vec3};
use radiosity::intersect::embree::EmbreeScene;
use radiosity::light::LightAt;
use radiosity::mesh::Mesh;
use radiosity::progress::Counter;
use radiosity::render::{
    render_gather, render_linear, Camera, LinearImage, RenderOptions, Shading, ShadingSettings,
};
use radiosity::scene::Scene;
use radiosity::solve::{MethodKind, SolveSettings};
use std::path::Path;

fn opts(width: u32, height: u32, supersample: u32) -> RenderOptions {
    RenderOptions {
        width,
        height,
        supersample,
        exposure: None,
    }
}

fn gather_settings(rays: usize, seed: u64) -> ShadingSettings {
    ShadingSettings {
        shading: Shading::Gather,
        rays,
        seed,
        ..Default::default()
    }
}

/// The gathered picture of `b` on `m`.
fn gathered(
    scene: &Scene,
    m: &Mesh,
    b: &[[f64; 3]],
    cam: &Camera,
    o: &RenderOptions,
    s: &ShadingSettings,
) -> LinearImage {
    let isect = EmbreeScene::build(m, |_| true).unwrap();
    let g = LightAt::new(m, &scene.materials, &isect, b, None, None);
    render_gather(&g, cam, o, s, &Counter::hidden()).0
}

fn luminance(p: &[f32; 3]) -> f64 {
    0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2])
}

/// The furnace (closed box, uniform E and ρ): with the analytic solution as the cache, every
/// pixel is B = E/(1 − ρ) within the gather's noise, and the image's mean within a fraction of
/// it (what pbrt's furnace tests check of an integrator).
#[test]
fn a_furnace_renders_flat_at_its_analytic_radiosity() {
    let (rho, ke) = (0.6, 1.0 / std::f64::consts::PI); // E = 1 W/m²
    let scene = closed_box(2.0, 1.5, 3.0, material("glow", rho, ke));
    let m = mesh_at(&scene, Some(0.5));
    let exact = 1.0 / (1.0 - rho);
    let b = vec![[exact; 3]; m.patches.len()];
    let cam = Camera::perspective(
        vec3(0.4, 0.3, 2.7),
        vec3(1.7, 1.2, 0.2),
        Vec3::Y,
        80.0,
        48.0 / 36.0,
    );
    let img = gathered(
        &scene,
        &m,
        &b,
        &cam,
        &opts(48, 36, 2),
        &gather_settings(16, 3),
    );
    let rel: Vec<f64> = img
        .pixels
        .iter()
        .map(|p| luminance(p) / exact - 1.0)
        .collect();
    let mean = rel.iter().sum::<f64>() / rel.len() as f64;
    let worst = rel.iter().fold(0.0f64, |w, r| w.max(r.abs()));
    eprintln!("furnace: mean {mean:+.4}, worst {worst:.4}");
    assert!(mean.abs() < 0.005, "mean relative error {mean}");
    assert!(worst < 0.1, "worst pixel {worst}");
    assert!(img.pixels.iter().flatten().all(|c| c.is_finite()));
}

/// A solved room's picture is the same for one seed on one thread and on three, and differs
/// for another seed (so the test can fail).
#[test]
fn the_picture_depends_on_the_seed_only() {
    let (scene, m, b) = shadow_room();
    let cam = room_camera(40.0 / 30.0);
    let o = opts(40, 30, 2);
    let on = |threads: usize, seed: u64| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| gathered(&scene, &m, &b, &cam, &o, &gather_settings(8, seed)))
    };
    let one = on(1, 7);
    assert_eq!(one, on(3, 7), "the thread count changed the picture");
    assert_ne!(one, on(3, 8), "another seed gave the same picture");
}

/// The indirect light gathered at nodes every 4 pixels and interpolated (the default) against
/// gathered at every sample (`--indirect-spacing 0`), both with 16 rays per sample, and a
/// reference of 512 rays per sample: the two agree on the mean (the direct and indirect
/// parts add up to the whole, nothing counted twice or lost) and the nodes' picture is
/// nearer the reference per pixel (its indirect light gathered with more rays).
#[test]
fn indirect_nodes_keep_the_mean_and_lower_the_noise() {
    let (scene, m, b) = shadow_room();
    let cam = room_camera(64.0 / 48.0);
    let o = opts(64, 48, 2);
    let at = |rays: usize, spacing: usize| {
        let s = ShadingSettings {
            indirect_spacing: spacing,
            ..gather_settings(rays, 5)
        };
        gathered(&scene, &m, &b, &cam, &o, &s)
    };
    let reference = at(512, 0);
    let stats = |img: &LinearImage| {
        let (mut err, mut n, mut sum, mut sum_ref) = (0.0, 0.0, 0.0, 0.0);
        for (p, r) in img.pixels.iter().zip(&reference.pixels) {
            let (l, lr) = (luminance(p), luminance(r));
            sum += l;
            sum_ref += lr;
            if lr > 0.0 {
                err += (l - lr).abs() / lr;
                n += 1.0;
            }
        }
        (sum / sum_ref - 1.0, err / n)
    };
    let (bias_nodes, err_nodes) = stats(&at(16, 4));
    let (bias_each, err_each) = stats(&at(16, 0));
    eprintln!(
        "nodes: mean {bias_nodes:+.4}, error {err_nodes:.4}; each sample: mean {bias_each:+.4}, error {err_each:.4}"
    );
    assert!(bias_nodes.abs() < 0.01 && bias_each.abs() < 0.01);
    assert!(err_nodes < err_each, "{err_nodes} against {err_each}");
}

/// The aft clipping plane (`-va`, [`Camera::far`]): what lies beyond it is black in the
/// gathered picture, as in the Gouraud one and in `rpict`'s, and what lies before it is drawn.
#[test]
fn the_aft_plane_clips_the_gathered_picture() {
    let (scene, m, b) = shadow_room();
    // From the middle of one wall towards the opposite one, 4 m away; the aft plane at 3 m.
    let mut cam = Camera::perspective(vec3(2.0, 1.5, 0.1), vec3(2.0, 1.5, 4.0), Vec3::Y, 60.0, 1.0);
    cam.far = Some(3.0);
    let o = opts(24, 24, 1);
    let img = gathered(&scene, &m, &b, &cam, &o, &gather_settings(8, 1));
    let flat = render_linear(&m, &m.vertex_values(&b), &cam, &o);
    // The centre sees the far wall (3.9 m on): clipped; a corner sees the floor near the eye.
    let centre = luminance(&img.pixels[12 * 24 + 12]);
    let corner = luminance(&img.pixels[23 * 24]);
    assert_eq!(centre, 0.0);
    assert_eq!(luminance(&flat.pixels[12 * 24 + 12]), 0.0);
    assert!(corner > 0.0, "{corner}");
    cam.far = None;
    let open = gathered(&scene, &m, &b, &cam, &o, &gather_settings(8, 1));
    assert!(luminance(&open.pixels[12 * 24 + 12]) > 0.0);
}

/// A view of [`shadow_room`] from high in one corner, of aspect `aspect`.
fn room_camera(aspect: f32) -> Camera {
    Camera::perspective(
        vec3(0.3, 2.5, 0.3),
        vec3(2.5, 0.0, 2.5),
        Vec3::Y,
        70.0,
        aspect,
    )
}

/// A 4 × 3 × 4 m room (ρ 0.5, 1 m patches) lit by a 0.2 m lamp in the middle of the ceiling,
/// with a 0.8 m square occluder 1 m above the floor under it (two-sided); solved.
fn shadow_room() -> (Scene, Mesh, Vec<[f64; 3]>) {
    let mut s = closed_box(4.0, 3.0, 4.0, material("wall", 0.5, 0.0));
    s.materials.push(material("lamp", 0.0, 100.0));
    s.materials.push(material("board", 0.5, 0.0));
    let (a, y) = (0.1, 2.99);
    quad(
        &mut s,
        [
            vec3(2.0 - a, y, 2.0 - a),
            vec3(2.0 + a, y, 2.0 - a),
            vec3(2.0 + a, y, 2.0 + a),
            vec3(2.0 - a, y, 2.0 + a),
        ],
        1,
    );
    let c = 0.4;
    quad(
        &mut s,
        [
            vec3(2.0 - c, 1.0, 2.0 - c),
            vec3(2.0 + c, 1.0, 2.0 - c),
            vec3(2.0 + c, 1.0, 2.0 + c),
            vec3(2.0 - c, 1.0, 2.0 + c),
        ],
        2,
    );
    s.polygons.last_mut().unwrap().back_material = Some(2);
    let m = mesh_at(&s, Some(1.0));
    let sol = solve_mesh(
        &s,
        &m,
        &SolveSettings {
            method: MethodKind::AdaptiveRays,
            tolerance: 0.03,
            ..SolveSettings::default()
        },
    );
    (s, m, sol.b)
}

/// The floor point (x, z) seen through the centre of pixel (px, py) of a camera at `eye`
/// looking straight down with +z up in the image, fov 90°, square image of `n` pixels (the
/// renderer's pinhole: right = forward × up).
fn floor_point(eye: Vec3, n: usize, px: usize, py: usize) -> (f32, f32) {
    let fwd = Vec3::NEG_Y;
    let right = fwd.cross(Vec3::Z).normalize();
    let up = right.cross(fwd);
    let sx = 2.0 * (px as f32 + 0.5) / n as f32 - 1.0;
    let sy = 1.0 - 2.0 * (py as f32 + 0.5) / n as f32;
    let d = fwd + right * sx + up * sy; // tan 45° = 1
    let t = eye.y / -d.y;
    let p = eye + d * t;
    (p.x, p.z)
}

/// A sharp shadow: under the occluder the analytic umbra (every point of the lamp hidden) is
/// |x − 2|, |z − 2| ≤ (c − a·s)/(1 − s) = 0.55 m and the penumbra ends at (c + a·s)/(1 − s) =
/// 0.65 m (s = 1/2.99 the occluder's height over the lamp's). The gathered picture is dark in
/// the umbra — the indirect light alone — and lit beyond the penumbra by ρ times the lamp's
/// direct irradiance, which is computed here in closed form; the Gouraud picture of the same
/// solution, whose 1 m floor patches straddle the shadow's edge, is far brighter in the umbra.
#[test]
fn a_small_light_casts_a_sharp_umbra() {
    let (scene, m, b) = shadow_room();
    let n = 64;
    let eye = vec3(2.0, 0.9, 2.0);
    let cam = Camera::perspective(eye, vec3(2.0, 0.0, 2.0), Vec3::Z, 90.0, 1.0);
    let o = opts(n as u32, n as u32, 2);
    let img = gathered(&scene, &m, &b, &cam, &o, &gather_settings(32, 1));
    let gouraud = render_linear(&m, &m.vertex_values(&b), &cam, &o);

    let (a, c, s) = (0.1f32, 0.4f32, 1.0f32 / 2.99);
    let umbra = (c - a * s) / (1.0 - s);
    let lit_from = (c + a * s) / (1.0 - s);
    assert!((umbra - 0.55).abs() < 0.01 && (lit_from - 0.65).abs() < 0.01);
    // The lamp's direct irradiance at a floor point (a 0.2 m source 3 m away: the point-source
    // form is exact to 0.2 %): L·A·cos θ·cos θ' / r².
    let direct = |x: f32, z: f32| {
        let d = vec3(2.0 - x, 2.99, 2.0 - z);
        let r2 = d.length_squared();
        let cos = 2.99 / r2.sqrt();
        100.0 * 0.04 * f64::from(cos * cos / r2)
    };
    let (mut dark, mut dark_g) = (Vec::new(), Vec::new());
    let mut lit_excess = Vec::new();
    for py in 0..n {
        for px in 0..n {
            let (x, z) = floor_point(eye, n, px, py);
            let r = (x - 2.0).abs().max((z - 2.0).abs());
            let v = luminance(&img.pixels[py * n + px]);
            if r < umbra - 0.05 {
                dark.push(v);
                dark_g.push(luminance(&gouraud.pixels[py * n + px]));
            } else if r > lit_from + 0.05 {
                lit_excess.push((v, 0.5 * direct(x, z)));
            }
        }
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let indirect = mean(&dark);
    let worst_dark = dark.iter().fold(0.0f64, |w, &v| w.max(v));
    // Beyond the penumbra: B = ρ·(direct + indirect), the indirect about the umbra's level.
    let ratio = mean(
        &lit_excess
            .iter()
            .map(|(v, _)| v - indirect)
            .collect::<Vec<_>>(),
    ) / mean(&lit_excess.iter().map(|(_, d)| *d).collect::<Vec<_>>());
    eprintln!(
        "umbra: gather {indirect:.4} (worst {worst_dark:.4}), gouraud {:.4}; lit: (B − umbra) / ρE_direct = {ratio:.3} over {} pixels",
        mean(&dark_g),
        lit_excess.len()
    );
    assert!(dark.len() > 500 && lit_excess.len() > 300);
    // Sharp: no pixel of the umbra sees the lamp; the indirect light is ~1/4 of the lit level.
    assert!(
        worst_dark < 0.5 * mean(&lit_excess.iter().map(|(v, _)| *v).collect::<Vec<_>>()),
        "a lit pixel in the umbra: {worst_dark}"
    );
    assert!(
        (ratio - 1.0).abs() < 0.15,
        "lit pixels hold {ratio} of the analytic direct light"
    );
    // Blurred: the Gouraud umbra holds the average of lit and shadowed floor.
    assert!(
        indirect < 0.7 * mean(&dark_g),
        "gather umbra {indirect} against Gouraud's {}",
        mean(&dark_g)
    );
}

/// The furnace of tests/outputs.rs: the inside of a unit cube, ρ = 0.5, Ke = 1 (B = 2π).
const FURNACE_OBJ: &str = "mtllib f.mtl\n\
v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
usemtl glow\n\
f 1 5 6 2\nf 4 3 7 8\nf 1 2 3 4\nf 5 8 7 6\nf 1 4 8 5\nf 2 6 7 3\n";
const FURNACE_MTL: &str = "newmtl glow\nKd 0.5 0.5 0.5\nKe 1 1 1\n";

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// `solve --shading gather` and `render --shading gather` write their pictures; a bad value of
/// either flag is refused in one line naming it.
#[test]
fn the_commands_take_the_shading_flags() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("f.mtl"), FURNACE_MTL).unwrap();
    let obj = d.join("furnace.obj");
    std::fs::write(&obj, FURNACE_OBJ).unwrap();
    let sol = d.join("s.rad");
    let small = ["--width", "48", "--height", "36", "--pixel-rays", "8"];
    let (code, _, err) = run(&[
        &[
            "solve",
            s(&obj),
            "--out",
            s(&d.join("o")),
            "--save",
            s(&sol),
        ],
        &["--shading", "gather", "--quiet"][..],
        &small[..],
    ]
    .concat());
    assert_eq!(code, 0, "{err}");
    let png = image::open(d.join("o/render.png")).unwrap().to_rgb8();
    assert_eq!(png.dimensions(), (48, 36));
    for ext in ["png", "hdr"] {
        let out = d.join(format!("g.{ext}"));
        let (code, stdout, err) = run(&[
            &["render", s(&sol), "--out", s(&out), "--shading", "gather"][..],
            &["--eye", "0.5,0.5,0.5", "--target", "0.5,0.5,0"],
            &small[..],
        ]
        .concat());
        assert_eq!(code, 0, "{err}");
        assert!(stdout.contains("final gather"), "{stdout}");
        let img = image::open(&out).unwrap().to_rgb32f();
        assert_eq!(img.dimensions(), (48, 36));
        assert!(img
            .pixels()
            .all(|p| p.0.iter().all(|v| v.is_finite() && *v > 0.0)));
    }
    // The Gouraud preview still renders.
    let (code, stdout, _) = run(&[
        &[
            "render",
            s(&sol),
            "--out",
            s(&d.join("p.png")),
            "--shading",
            "gouraud",
        ][..],
        &small[..],
    ]
    .concat());
    assert_eq!(code, 0);
    assert!(stdout.contains("gouraud shading"), "{stdout}");
    assert_user_error(
        &[
            "render",
            s(&sol),
            "--out",
            s(&d.join("x.png")),
            "--shading",
            "phong",
        ],
        &["--shading", "phong", "gather", "gouraud"],
    );
    assert_user_error(
        &[
            "solve",
            s(&obj),
            "--out",
            s(&d.join("o2")),
            "--shading",
            "flat",
        ],
        &["--shading", "flat"],
    );
    assert_user_error(
        &[
            "render",
            s(&sol),
            "--out",
            s(&d.join("x.png")),
            "--pixel-rays",
            "0",
        ],
        &["--pixel-rays", "between 1 and"],
    );
    assert_user_error(
        &[
            "render",
            s(&sol),
            "--out",
            s(&d.join("x.png")),
            "--indirect-spacing",
            "65",
        ],
        &["--indirect-spacing", "between 0 and 64"],
    );
}

/// `relight --shading gather` gathers the relit lights: the furnace's light at weight 2 gives
/// exactly twice the picture of weight 1 (radiosity is linear in the emission, and the same
/// seed draws the same samples), at weight 0 a black one.
#[test]
fn relight_gathers_the_reweighted_lights() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("f.mtl"), FURNACE_MTL).unwrap();
    let obj = d.join("furnace.obj");
    std::fs::write(&obj, FURNACE_OBJ).unwrap();
    let sol = d.join("s.rad");
    let (code, _, err) = run(&[
        "solve",
        s(&obj),
        "--out",
        s(&d.join("o")),
        "--save",
        s(&sol),
        "--per-light",
        "--quiet",
    ]);
    assert_eq!(code, 0, "{err}");
    let picture = |weight: &str| {
        let out = d.join(format!("r{weight}.exr"));
        let (code, _, err) = run(&[
            "relight",
            s(&sol),
            "--weight",
            &format!("glow={weight}"),
            "--out",
            s(&out),
            "--width",
            "32",
            "--height",
            "24",
            "--pixel-rays",
            "8",
        ]);
        assert_eq!(code, 0, "{err}");
        image::open(&out).unwrap().to_rgb32f()
    };
    let (one, two, zero) = (picture("1"), picture("2"), picture("0"));
    let mut lit = 0;
    for ((a, b), z) in one.pixels().zip(two.pixels()).zip(zero.pixels()) {
        for q in 0..3 {
            // The background (the fitted camera looks in from outside) stays black.
            if a.0[q] > 0.0 {
                lit += 1;
                assert!(
                    (b.0[q] / a.0[q] - 2.0).abs() < 1e-4,
                    "{} vs {}",
                    b.0[q],
                    a.0[q]
                );
            } else {
                assert_eq!(b.0[q], 0.0);
            }
            assert_eq!(z.0[q], 0.0);
        }
    }
    assert!(lit > 32 * 24, "{lit} lit channels");
}

/// A daylit solve's sky is rebuilt from the settings its saved file keeps: the gathered
/// picture of a roofless room under a uniform sky shows the sky, uniform, where it looks out,
/// and says nothing about a sky it could not rebuild.
#[test]
fn a_saved_daylit_solve_renders_with_its_sky() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let sol = solved_court(d, 0.5, &["--sky", "uniform"]);
    let out = d.join("up.exr");
    let (code, stdout, err) = run(&[
        "render",
        s(&sol),
        "--out",
        s(&out),
        "--eye",
        "1,0.2,1",
        "--target",
        "1,1,1.01",
        "--fov",
        "120",
        "--width",
        "40",
        "--height",
        "40",
        "--pixel-rays",
        "8",
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("warning"), "{err}");
    let report: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(report["shading"], "gather");
    assert!(report.get("warnings").is_none(), "{report}");
    // The centre looks straight up at the open sky.
    let img = image::open(&out).unwrap().to_rgb32f();
    let sky = img.get_pixel(20, 20).0;
    assert!(sky[1] > 0.0);
    for (x, y) in [(18, 18), (22, 21), (19, 23)] {
        let p = img.get_pixel(x, y).0;
        assert!((p[1] / sky[1] - 1.0).abs() < 1e-3, "{p:?} against {sky:?}");
    }
}

/// Under a sky with a sun (no lamp), the indirect light gathered at nodes (the default) and at
/// every sample (`--indirect-spacing 0`) give the same picture on average: the nodes' part is
/// the hemisphere's (sky and bounced light), the samples' the sun's.
#[test]
fn a_sunlit_court_renders_alike_with_and_without_nodes() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let sol = solved_court(d, 0.6, &["--sky", "clear", "--sun", "40,20"]);
    let mean = |spacing: &str| {
        let out = d.join(format!("v{spacing}.exr"));
        let (code, _, err) = run(&[
            "render",
            s(&sol),
            "--out",
            s(&out),
            "--eye",
            "1,0.8,1.9",
            "--target",
            "1,0.2,0",
            "--fov",
            "80",
            "--width",
            "48",
            "--height",
            "36",
            "--indirect-spacing",
            spacing,
        ]);
        assert_eq!(code, 0, "{err}");
        let img = image::open(&out).unwrap().to_rgb32f();
        img.pixels().map(|p| f64::from(p.0[1])).sum::<f64>() / img.pixels().len() as f64
    };
    let (nodes, each) = (mean("4"), mean("0"));
    eprintln!("court: nodes {nodes}, every sample {each}");
    assert!(
        each > 0.0 && (nodes / each - 1.0).abs() < 0.03,
        "{nodes} against {each}"
    );
}

/// A 2 × 1 × 2 m room without a roof (faces wound to look in) of reflectance `kd`, in `d`,
/// solved under the sky `sky` and saved: the solution's path.
fn solved_court(d: &Path, kd: f64, sky: &[&str]) -> std::path::PathBuf {
    let obj = d.join("court.obj");
    std::fs::write(
        &obj,
        "mtllib c.mtl\nv 0 0 0\nv 2 0 0\nv 2 1 0\nv 0 1 0\nv 0 0 2\nv 2 0 2\nv 2 1 2\nv 0 1 2\n\
         usemtl stone\nf 1 5 6 2\nf 1 2 3 4\nf 5 8 7 6\nf 1 4 8 5\nf 2 6 7 3\n",
    )
    .unwrap();
    std::fs::write(
        d.join("c.mtl"),
        format!("newmtl stone\nKd {kd} {kd} {kd}\n"),
    )
    .unwrap();
    let sol = d.join("s.rad");
    let (o, out) = (d.join("o"), s(&sol).to_string());
    let mut args = vec!["solve", s(&obj)];
    args.extend_from_slice(sky);
    args.extend_from_slice(&["--out", s(&o), "--save", &out, "--quiet"]);
    let (code, _, err) = run(&args);
    assert_eq!(code, 0, "{err}");
    sol
}
