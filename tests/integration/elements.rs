//! Adaptive elements (Cohen, Greenberg, Immel & Brock 1986, Sec. 3) —
//! patches shoot, elements receive.

use crate::common;
use crate::scene_builder;

use radiosity::elements::{self, ElementSettings, Elements};
use radiosity::export::solution::SavedSolution;
use radiosity::intersect::embree::EmbreeScene;
use radiosity::light::LightAt;
use radiosity::mesh::Mesh;
use radiosity::scene::Scene;
use radiosity::solve::{self, SolveSettings};
use std::path::Path;

/// Solves `m` and refines its elements with `settings`, on `threads` threads (all when `None`).
fn refined(
    s: &Scene,
    m: &Mesh,
    settings: &ElementSettings,
    threads: Option<usize>,
) -> (Vec<[f64; 3]>, Elements, elements::ElementStats) {
    let isect = EmbreeScene::build(m, |_| true).unwrap();
    let sol = solve::solve(m, &s.materials, &isect, &SolveSettings::default(), |_| {}).unwrap();
    let run = || {
        let gather = LightAt::new(m, &s.materials, &isect, &sol.b, None, None);
        elements::refine(m, &gather, &sol.b, settings, 7)
    };
    let (el, st) = common::on_threads(threads, run);
    (sol.b, el, st)
}

#[test]
fn elements_tile_each_patch_exactly() {
    let (s, m) = scene_builder::project_scene("spot.obj");
    let (_, el, st) = refined(&s, &m, &ElementSettings::default(), None);
    assert!(st.count as usize > m.patches.len(), "{st:?}");
    let mut area = vec![0.0f64; m.patches.len()];
    for (e, &p) in el.patch.iter().enumerate() {
        area[p as usize] += el.mesh.patches[e].area;
        assert_eq!(el.mesh.patches[e].material, m.patches[p as usize].material);
        assert_eq!(el.mesh.patches[e].normal, m.patches[p as usize].normal);
    }
    for (i, p) in m.patches.iter().enumerate() {
        assert!(
            (area[i] - p.area).abs() <= 1e-5 * p.area,
            "patch {i}: elements {} of {}",
            area[i],
            p.area
        );
    }
    // Every value is finite and non-negative; B per element is the mean of its corners.
    assert!(el
        .vertex_b
        .iter()
        .flatten()
        .all(|x| x.is_finite() && *x >= 0.0));
    assert!(el.b.iter().flatten().all(|x| x.is_finite() && *x >= 0.0));
}

/// The furnace: a closed box whose every patch emits and reflects alike is lit uniformly,
/// B = E/(1 − ρ) everywhere, so no element is cut and each equals the patch B within noise.
#[test]
fn a_uniformly_lit_furnace_is_not_subdivided() {
    let (rho, ke) = (0.5, 1.0);
    let s = scene_builder::closed_box(2.0, 2.0, 2.0, scene_builder::material("m", rho, ke));
    let m = scene_builder::mesh_at(&s, Some(0.5));
    let exact = std::f64::consts::PI * ke / (1.0 - rho);
    for light in [elements::CornerLight::Full, elements::CornerLight::Split] {
        // Full gathers everything at every corner: it wants 256 rays (its default before).
        let rays = if light == elements::CornerLight::Full {
            256
        } else {
            elements::DEFAULT_RAYS
        };
        let settings = ElementSettings {
            light,
            rays,
            ..Default::default()
        };
        let (_, el, st) = refined(&s, &m, &settings, None);
        assert_eq!(st.count as usize, m.patches.len(), "{light:?}: {st:?}");
        for b in &el.b {
            for c in b {
                assert!(
                    (c - exact).abs() < 0.03 * exact,
                    "{light:?}: {c} against {exact}"
                );
            }
        }
    }
}

/// The table's shadow on the floor of `spot.obj` (light 0.2 m wide at 3 m, table edge at
/// 0.8 m and 0.6 m from the centre: the shadow's edge 0.818 m from it, its penumbra 7 cm wide)
/// is refined to the smallest elements across its edge (cut in two, the default
/// [`elements::Test::Halves`], they may stay longer along it), and the floor far from any edge
/// is not (at a threshold of 0.01, as `radiosity bench elements` measures it).
#[test]
fn a_sharp_shadow_edge_is_refined_to_the_minimum_size_and_only_there() {
    shadow_edge_refined(elements::CornerLight::Full);
}

/// The same with the direct light at the corners and the indirect interpolated from each
/// patch's corners, or nine nodes where they differ (`--element-light split`, the default):
/// the shadow is the direct light's.
#[test]
fn split_corners_refine_the_shadow_edge_too() {
    shadow_edge_refined(elements::CornerLight::Split);
}

fn shadow_edge_refined(light: elements::CornerLight) {
    let (s, m) = scene_builder::project_scene("spot.obj");
    let settings = ElementSettings {
        threshold: 0.01,
        light,
        ..Default::default()
    };
    let (_, el, _) = refined(&s, &m, &settings, None);
    let min = settings.min_size_for(m.patch_size) as f64;
    let edge = 0.6 * 3.0 / 2.2;
    let (mut along, mut far) = (0.0, 0);
    for (e, p) in el.mesh.patches.iter().enumerate() {
        let c = p.centre;
        if p.normal.y < 0.9 || c.y > 0.01 {
            continue; // the floor only
        }
        let (ax, az) = ((c.x as f64 - 2.0).abs(), (c.z as f64 + 2.0).abs());
        // Along the middle of each side of the shadow's square, within a min size of it.
        let across_x = (ax - edge).abs() < 0.5 * min && az < 0.6;
        let across_z = (az - edge).abs() < 0.5 * min && ax < 0.6;
        if across_x || across_z {
            let (lo, hi) = el.mesh.patch_indices(e).iter().fold(
                (glam::Vec3::splat(f32::MAX), glam::Vec3::splat(f32::MIN)),
                |(l, h), &v| {
                    let q = el.mesh.vertices[v as usize];
                    (l.min(q), h.max(q))
                },
            );
            let width = if across_x { hi.x - lo.x } else { hi.z - lo.z } as f64;
            assert!(
                width <= 1.01 * min,
                "element {e} at {c} is {width} m across the edge"
            );
            along += if across_x { hi.z - lo.z } else { hi.x - lo.x } as f64;
        }
        // A smooth stretch of floor between the shadow and the far corner.
        if c.x > 3.0 && c.x < 3.5 && c.z > -3.5 && c.z < -3.0 {
            far += 1;
            assert!(
                p.area >= 3.99 * min * min,
                "element {e} at {c} is {} m²",
                p.area
            );
        }
    }
    // The four sides' middle 1.2 m each are lined with such elements.
    assert!(along > 0.9 * 4.0 * 1.2 && far > 0, "{along} {far}");
}

/// Ctrl-C (or `--max-time`'s deadline) before the refinement: each patch is kept whole (the spot's patches are quads),
/// with its corners gathered, and the stats say so.
#[test]
fn ctrl_c_keeps_what_is_refined() {
    let (s, m) = scene_builder::project_scene("spot.obj");
    let isect = EmbreeScene::build(&m, |_| true).unwrap();
    let sol = solve::solve(&m, &s.materials, &isect, &SolveSettings::default(), |_| {}).unwrap();
    let gather = LightAt::new(&m, &s.materials, &isect, &sol.b, None, None);
    let stop = std::sync::atomic::AtomicBool::new(true);
    let settings = ElementSettings::default();
    let ctrl_c = elements::Stop {
        flag: Some(&stop),
        deadline: None,
    };
    let (el, st) = elements::refine_until(&m, &gather, &sol.b, &settings, 7, ctrl_c);
    assert!(st.interrupted, "{st:?}");
    assert_eq!(st.count as usize, m.patches.len());
    assert!(el.b.iter().flatten().all(|x| x.is_finite() && *x >= 0.0));
    // A deadline passed (--max-time) does the same.
    let late = elements::Stop {
        flag: None,
        deadline: Some(std::time::Instant::now()),
    };
    let (_, st) = elements::refine_until(&m, &gather, &sol.b, &settings, 7, late);
    assert!(st.out_of_time && !st.interrupted, "{st:?}");
    assert_eq!(st.count as usize, m.patches.len());
    let (_, full) = elements::refine(&m, &gather, &sol.b, &settings, 7);
    assert!(!full.interrupted && full.count > st.count, "{full:?}");
}

#[test]
fn elements_do_not_depend_on_the_thread_count() {
    let (s, m) = scene_builder::project_scene("spot.obj");
    for light in [elements::CornerLight::Full, elements::CornerLight::Split] {
        let settings = ElementSettings {
            light,
            ..Default::default()
        };
        let (_, one, _) = refined(&s, &m, &settings, Some(1));
        let (_, two, _) = refined(&s, &m, &settings, Some(2));
        assert!(
            one == two,
            "{light:?}: the elements differ between 1 and 2 threads"
        );
    }
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// `elements.csv` has exactly the columns of `patches.csv` and the element's patch; the saved
/// solution (format 2) keeps the elements and gives them back to `export` and `render`.
#[test]
fn elements_csv_and_the_saved_solution_carry_the_elements() {
    let dir = tempfile::tempdir().unwrap();
    let spot = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/spot.obj");
    let out = dir.path().join("o");
    let sol_path = dir.path().join("spot.rad");
    let (code, _, err) = common::run(&[
        "solve",
        s(&spot),
        "--quiet",
        "--out",
        s(&out),
        "--save",
        s(&sol_path),
    ]);
    assert_eq!(code, 0, "{err}");
    let patches = std::fs::read_to_string(out.join("patches.csv")).unwrap();
    let elements = std::fs::read_to_string(out.join("elements.csv")).unwrap();
    let header = |t: &str| t.lines().next().unwrap().to_string();
    assert_eq!(header(&elements), format!("{},patch", header(&patches)));
    let sol = SavedSolution::load(&sol_path).unwrap();
    let el = sol
        .elements
        .as_ref()
        .expect("the saved solution keeps its elements");
    assert_eq!(elements.lines().count() - 1, el.mesh.patches.len());
    assert_eq!(patches.lines().count() - 1, sol.mesh.patches.len());
    assert!(el.mesh.patches.len() > sol.mesh.patches.len());
    // The rows' patch ids and values are the saved elements'.
    for (k, line) in elements.lines().skip(1).enumerate() {
        let cells: Vec<&str> = line.split(',').collect();
        assert_eq!(cells.last().unwrap().parse::<u32>().unwrap(), el.patch[k]);
        let b: f64 = cells[14].parse().unwrap();
        assert!(
            (b - el.b[k][0]).abs() <= 1e-6 * b.abs().max(1e-6),
            "{b} {:?}",
            el.b[k]
        );
    }
    // Save → load → save: the same bytes.
    let mut again = Vec::new();
    sol.write(&mut again).unwrap();
    assert_eq!(again, std::fs::read(&sol_path).unwrap());
    // The export draws the elements: one PLY vertex per element vertex.
    let ply = dir.path().join("spot.ply");
    let (code, _, err) = common::run(&["export", s(&sol_path), "--out", s(&ply)]);
    assert_eq!(code, 0, "{err}");
    let text = std::fs::read(&ply).unwrap();
    let head = String::from_utf8_lossy(&text[..text.len().min(2000)]).to_string();
    assert!(
        head.contains(&format!("element vertex {}", el.mesh.vertices.len())),
        "{head}"
    );
    let png = dir.path().join("spot.png");
    let (code, _, err) = common::run(&["render", s(&sol_path), "--out", s(&png)]);
    assert_eq!(code, 0, "{err}");
    // The summary reports them.
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(
        summary["elements"]["count"].as_u64().unwrap() as usize,
        el.mesh.patches.len()
    );
}

/// `--elements auto` (the default) refines meshes up to `AUTO_MAX_PATCHES`; `on`, any.
#[test]
fn elements_auto_stops_at_its_patch_limit() {
    let auto = ElementSettings::default();
    assert!(auto.applies_to(elements::AUTO_MAX_PATCHES as usize));
    assert!(!auto.applies_to(elements::AUTO_MAX_PATCHES as usize + 1));
    let on = ElementSettings {
        auto_limit: None,
        ..Default::default()
    };
    assert!(on.applies_to(usize::MAX));
    let off = ElementSettings {
        enabled: false,
        ..Default::default()
    };
    assert!(!off.applies_to(1));
}

#[test]
fn element_flags_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o");
    for (flag, value, needle) in [
        ("--element-threshold", "0", "--element-threshold"),
        ("--element-min-size", "-1", "--element-min-size"),
        ("--element-rays", "1", "--element-rays"),
        ("--element-max", "0.5", "--element-max"),
    ] {
        common::assert_user_error(
            &["solve", "--quiet", "--out", s(&out), flag, value],
            &[needle],
        );
    }
    let (code, help, _) = common::run(&["solve", "--help"]);
    assert_eq!(code, 0);
    for flag in [
        "--elements",
        "--element-threshold",
        "--element-min-size",
        "--element-rays",
    ] {
        assert!(help.contains(flag), "{flag} not in solve --help");
    }
}

/// A building of 30 closed rooms (3.8 × 3 × 3.8 m, 4 m apart), each lit by its own 0.6 m
/// square lamp facing down 1 cm under its ceiling; 1 m patches.
fn thirty_rooms() -> (Scene, Mesh) {
    use glam::vec3;
    let mut s = scene_builder::scene(
        "rooms",
        vec![
            scene_builder::material("wall", 0.5, 0.0),
            scene_builder::material("lamp", 0.0, 5.0),
        ],
    );
    for (i, j) in (0..6).flat_map(|i| (0..5).map(move |j| (i, j))) {
        let lo = vec3(4.0 * i as f32, 0.0, 4.0 * j as f32);
        let hi = lo + vec3(3.8, 3.0, 3.8);
        let c = (lo + hi) * 0.5;
        let (a, b) = (lo, hi);
        let faces = [
            [
                vec3(a.x, a.y, a.z),
                vec3(b.x, a.y, a.z),
                vec3(b.x, a.y, b.z),
                vec3(a.x, a.y, b.z),
            ],
            [
                vec3(a.x, b.y, a.z),
                vec3(b.x, b.y, a.z),
                vec3(b.x, b.y, b.z),
                vec3(a.x, b.y, b.z),
            ],
            [
                vec3(a.x, a.y, a.z),
                vec3(b.x, a.y, a.z),
                vec3(b.x, b.y, a.z),
                vec3(a.x, b.y, a.z),
            ],
            [
                vec3(a.x, a.y, b.z),
                vec3(b.x, a.y, b.z),
                vec3(b.x, b.y, b.z),
                vec3(a.x, b.y, b.z),
            ],
            [
                vec3(a.x, a.y, a.z),
                vec3(a.x, b.y, a.z),
                vec3(a.x, b.y, b.z),
                vec3(a.x, a.y, b.z),
            ],
            [
                vec3(b.x, a.y, a.z),
                vec3(b.x, b.y, a.z),
                vec3(b.x, b.y, b.z),
                vec3(b.x, a.y, b.z),
            ],
        ];
        for f in faces {
            let centre = (f[0] + f[1] + f[2] + f[3]) * 0.25;
            scene_builder::polygon_facing(&mut s, &f, c - centre, 0);
        }
        let y = hi.y - 0.01;
        let lamp = [
            vec3(c.x - 0.3, y, c.z - 0.3),
            vec3(c.x + 0.3, y, c.z - 0.3),
            vec3(c.x + 0.3, y, c.z + 0.3),
            vec3(c.x - 0.3, y, c.z + 0.3),
        ];
        scene_builder::polygon_facing(&mut s, &lamp, vec3(0.0, -1.0, 0.0), 1);
    }
    let m = scene_builder::mesh_at(&s, Some(1.0));
    (s, m)
}

/// The floor patch of room (2, 2) of [`thirty_rooms`] nearest the point below its lamp, 0.3 m
/// off its centre, and the point 0.1 mm above its centre.
fn room_floor_point(m: &Mesh) -> (usize, [glam::Vec3; 1]) {
    let x = glam::vec3(10.2, 0.0, 9.6);
    let (patch, _) = (m.patches.iter().enumerate())
        .filter(|(_, p)| p.normal.y > 0.9 && p.centre.y < 0.01)
        .map(|(i, p)| (i, p.centre.distance(x)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap();
    (
        patch,
        [m.patches[patch].centre + glam::vec3(0.0, 1e-4, 0.0)],
    )
}

/// Calls `f` with [`thirty_rooms`] solved: its mesh, radiosity, light, and
/// [`room_floor_point`].
fn in_room_floor(
    f: impl FnOnce(&Mesh, &[[f64; 3]], &LightAt<EmbreeScene>, usize, [glam::Vec3; 1]),
) {
    let (s, m) = thirty_rooms();
    let isect = EmbreeScene::build(&m, |_| true).unwrap();
    let sol = solve::solve(&m, &s.materials, &isect, &SolveSettings::default(), |_| {}).unwrap();
    let light = LightAt::new(&m, &s.materials, &isect, &sol.b, None, None);
    let (patch, at) = room_floor_point(&m);
    f(&m, &sol.b, &light, patch, at);
}

/// In a building of 30 closed rooms, each lit by its own lamp, the split corners' direct light
/// at a point draws its light samples from what can light the point's patch — its own room's
/// lamp — not from every lamp by power, which gave the point's own lamp one sample in 30 (of
/// 24: none, or one weighing 30 times): 24-ray estimates at a floor point agree with a
/// 4,096-ray one within 10 % (RMS over 40 seeds).
#[test]
fn split_direct_light_draws_the_rooms_own_lamp() {
    use radiosity::light::LightParts;
    use rand::SeedableRng;
    in_room_floor(|_, _, light, patch, at| {
        let direct = |rays: usize, seed: u64| {
            let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
            let (b, _, _) = light.part_at(patch, &at, rays, LightParts::Direct, &mut rng);
            (b.x + b.y + b.z) / 3.0
        };
        let reference = direct(4096, 1);
        assert!(reference > 0.0, "{reference}");
        let rms = ((0..40u64)
            .map(|k| (direct(24, 100 + k) / reference - 1.0).powi(2))
            .sum::<f64>()
            / 40.0)
            .sqrt();
        assert!(
            rms < 0.1,
            "24-ray direct light off by {rms} (RMS, relative)"
        );
    });
}

/// The split corners' direct light takes the lamps a point's polygon draws most whole: their
/// unoccluded irradiance in closed form times what the shadow rays find unblocked
/// (`light::exact`). At a floor point of one of 30 closed rooms, which sees its lamp whole,
/// every seed's 24-ray estimate is the same value, the lamp's closed form (its neighbours'
/// lamps seen by none of their rays), and it casts at most half its rays (the first stage,
/// a third, agreed; the lamps not taken whole have a few).
#[test]
fn split_direct_light_takes_the_rooms_lamp_whole() {
    use radiosity::light::LightParts;
    use rand::SeedableRng;
    in_room_floor(|m, b, light, patch, at| {
        let direct = |parts, rays: usize, seed: u64| {
            let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
            let (b, _, cast) = light.part_at(patch, &at, rays, parts, &mut rng);
            ((b.x + b.y + b.z) / 3.0, cast)
        };
        // The lamp of room (2, 2), 1 cm under its ceiling, its exitance and the floor's ρ = 0.5.
        let (lamp, _) = (m.patches.iter().enumerate())
            .filter(|(_, p)| p.normal.y < -0.9)
            .map(|(i, p)| (i, p.centre.distance(glam::vec3(9.9, 2.99, 9.9))))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap();
        let corners: Vec<glam::DVec3> = (m.patch_indices(lamp).iter())
            .map(|&v| m.vertices[v as usize].as_dvec3())
            .collect();
        let f =
            radiosity::light::exact::point_to_polygon(at[0].as_dvec3(), glam::DVec3::Y, &corners);
        let reference = 0.5 * b[lamp][0] * f;
        // Light samples alone, by power over the 30 lamps, give most of it (their MIS weight).
        let (sampled, _) = direct(LightParts::Direct, 4096, 1);
        let (whole, cast) = direct(LightParts::DirectWhole, 24, 1);
        assert!(
            (whole / reference - 1.0).abs() < 1e-3 && sampled < whole && sampled > 0.8 * whole,
            "{whole} against {reference} (light samples {sampled})"
        );
        assert!(cast <= 12, "{cast} rays");
        for seed in 2..10 {
            assert_eq!(direct(LightParts::DirectWhole, 24, seed).0, whole);
        }
    });
}

/// A point handed what its own shadow rays told of its polygon's whole lamp faces (its room's
/// lamp seen whole, the others' behind walls hidden) gets the same light with fewer rays, and
/// told its lamp is hidden, none of that lamp's light.
#[test]
fn a_point_told_its_lamps_are_seen_casts_fewer_rays() {
    use radiosity::light::{LightParts, Vis};
    use rand::SeedableRng;
    in_room_floor(|_, _, light, patch, at| {
        let gather = |known: Vis| {
            let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(1);
            let ask = (24, LightParts::DirectWhole);
            light.part_told_at(patch, &at, ask, known, &mut rng)
        };
        let own = gather(Vis::default());
        assert!(own.rays > 0 && own.vis.lit != 0, "{own:?}");
        let told = gather(own.vis);
        let size = own.b.max_element();
        assert!(
            (told.b - own.b).abs().max_element() < 1e-9 * size,
            "{told:?} {own:?}"
        );
        assert!(told.rays < own.rays, "{told:?} {own:?}");
        let hidden = gather(Vis {
            lit: 0,
            dark: own.vis.lit,
        });
        assert!(hidden.b.max_element() < 0.1 * size, "{hidden:?} {own:?}");
    });
}
