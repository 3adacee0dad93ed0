//! Annual daylight from one solve (daylight coefficients): what a year at the sensors must
//! equal. An unobstructed plane receives the weather file's horizontal illuminance hour by
//! hour (through the Perez sky); the coefficients summed over a uniform sky equal the
//! uniform-sky solve; one coefficient equals a plain solve under its patch alone.

use radiosity::grid::GridSpec;
use radiosity::pipeline::annual::{self, Annual, AnnualJob};
use radiosity::pipeline::{self, SolveJob};
use radiosity::progress::Progress;
use radiosity::scene::SceneSource;
use radiosity::sky::{
    CoefficientSky, Sampling, SkyKind, SkyLevel, SkyOptions, SkySpec, SkyVectors, SunMode, EFFICACY,
};
use radiosity::weather::Weather;
use std::path::Path;

/// A few hours of Chicago-like weather (`.wea`: month day hour DNI DHI, W/m²): a night hour, a
/// dusk hour, clear mornings and afternoons in summer and winter, an overcast noon.
const WEA: &str = "place Test\nlatitude 41.98\nlongitude 87.92\ntime_zone 90\nsite_elevation 200\nweather_data_file_units 1\n\
3 15 2.5 0 0\n3 15 18.5 5 10\n6 21 8.5 600 120\n6 21 12.5 0 250\n6 21 16.5 750 110\n12 21 10.5 500 60\n12 21 13.5 650 70\n";

/// Writes `files` (name, text) into a fresh temporary folder.
fn folder(files: &[(&str, &str)]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    for (name, text) in files {
        std::fs::write(dir.path().join(name), text).unwrap();
    }
    dir
}

const MTL: &str =
    "newmtl grey\nKd 0.5 0.5 0.5\nnewmtl wall\nKd 0.6 0.6 0.6\nnewmtl floor\nKd 0.3 0.3 0.3\n";

/// A 20 m × 20 m plane at y = 0 (Y up, north −Z).
const PLANE: &str =
    "mtllib m.mtl\nv -10 0 10\nv 10 0 10\nv 10 0 -10\nv -10 0 -10\nusemtl grey\nf 1 2 3 4\n";

/// A 6 × 3 × 4 m room (x 0..6, y 0..3, z −4..0), its south wall (z = 0) with a 4 × 1.5 m
/// opening from 0.8 m up; walls face in.
fn room() -> String {
    let mut v = Vec::new();
    let mut f = Vec::new();
    let mut quad = |m: &str, p: [[f64; 3]; 4]| {
        let k = v.len();
        v.extend(p);
        f.push(format!(
            "usemtl {m}\nf {} {} {} {}",
            k + 1,
            k + 2,
            k + 3,
            k + 4
        ));
    };
    quad(
        "floor",
        [[0., 0., 0.], [6., 0., 0.], [6., 0., -4.], [0., 0., -4.]],
    );
    quad(
        "wall",
        [[0., 3., 0.], [0., 3., -4.], [6., 3., -4.], [6., 3., 0.]],
    );
    quad(
        "wall",
        [[0., 0., -4.], [6., 0., -4.], [6., 3., -4.], [0., 3., -4.]],
    );
    quad(
        "wall",
        [[0., 0., 0.], [0., 0., -4.], [0., 3., -4.], [0., 3., 0.]],
    );
    quad(
        "wall",
        [[6., 0., 0.], [6., 3., 0.], [6., 3., -4.], [6., 0., -4.]],
    );
    // The south wall around the opening (x 1..5, y 0.8..2.3), facing −z.
    quad(
        "wall",
        [[0., 0., 0.], [0., 3., 0.], [1., 3., 0.], [1., 0., 0.]],
    );
    quad(
        "wall",
        [[5., 0., 0.], [5., 3., 0.], [6., 3., 0.], [6., 0., 0.]],
    );
    quad(
        "wall",
        [[1., 0., 0.], [1., 0.8, 0.], [5., 0.8, 0.], [5., 0., 0.]],
    );
    quad(
        "wall",
        [[1., 2.3, 0.], [1., 3., 0.], [5., 3., 0.], [5., 2.3, 0.]],
    );
    let mut s = String::from("mtllib m.mtl\n");
    for p in &v {
        s += &format!("v {} {} {}\n", p[0], p[1], p[2]);
    }
    s + &f.join("\n") + "\n"
}

/// Sensor points (x,y,z,nx,ny,nz) facing up at height 0.8 m.
fn points(xz: &[(f64, f64)], y: f64) -> String {
    let mut s = String::from("x,y,z,nx,ny,nz\n");
    for (x, z) in xz {
        s += &format!("{x},{y},{z},0,1,0\n");
    }
    s
}

fn job(dir: &Path, model: &str, subdivision: u32) -> AnnualJob {
    let mut solve = SolveJob::new(SceneSource::File(dir.join(model)), dir.join("out"));
    solve.grid = Some(GridSpec::Points(dir.join("points.csv")));
    solve.settings.solve.sky = Some(SkySpec::default());
    AnnualJob {
        solve,
        weather: dir.join("t.wea"),
        subdivision,
        patch_rays: annual::DEFAULT_PATCH_RAYS,
        occupancy: Default::default(),
        thresholds: Default::default(),
        csv: false,
        coefficients: None,
        rotate: 0.0,
    }
}

fn run(job: &AnnualJob) -> Annual {
    annual::run(job, &Progress::hidden(), &mut |_| {}).unwrap()
}

#[test]
fn an_unobstructed_plane_receives_the_weather_files_horizontal_illuminance() {
    let pts = points(&[(0.0, 0.0), (3.0, -2.0)], 0.01);
    let dir = folder(&[
        ("p.obj", PLANE),
        ("m.mtl", MTL),
        ("points.csv", &pts),
        ("t.wea", WEA),
    ]);
    for mf in [1, 2] {
        let a = run(&job(dir.path(), "p.obj", mf));
        let weather = Weather::read(dir.path().join("t.wea")).unwrap();
        let hours = weather.sky_hours().unwrap();
        let vectors = SkyVectors::new(SkyOptions {
            subdivision: mf,
            sun: SunMode::Separate,
            sampling: Sampling::Centre,
            ..SkyOptions::default()
        })
        .unwrap();
        assert_eq!(
            a.year.hours,
            vec![1, 2, 3, 4, 5, 6],
            "the night hour is left out"
        );
        for (row, &h) in a.year.hours.iter().enumerate() {
            let v = vectors.hour(&hours[h]).unwrap();
            let alt = hours[h].sun.altitude.to_radians();
            let beam = if v.sun.is_some() {
                v.direct_illuminance * alt.sin().max(0.0)
            } else {
                0.0
            };
            let want = v.diffuse_illuminance + beam;
            for s in 0..2 {
                let got = f64::from(a.year.illuminance[row * 2 + s]);
                let sun = f64::from(a.year.direct_sun[row * 2 + s]);
                eprintln!("MF {mf} hour {h} sensor {s}: {got:.0} lux, the file's sky {want:.0}");
                assert!(
                    (got - want).abs() <= 0.02 * want,
                    "MF {mf} hour {h} sensor {s}: {got} lux, the file's sky {want}"
                );
                assert!(
                    (sun - beam).abs() <= 1e-3 * beam.max(1.0),
                    "MF {mf} hour {h}: direct sun {sun}, want {beam}"
                );
            }
        }
    }
}

/// The room's sensors: a row from the window to the back wall, and one to the side.
fn room_points() -> String {
    points(
        &[
            (3.0, -0.5),
            (3.0, -1.5),
            (3.0, -2.5),
            (3.0, -3.5),
            (1.0, -2.0),
            (5.0, -1.0),
        ],
        0.8,
    )
}

/// `solve` of the room under `spec` (and `coefficients`), its grid's lux at the points.
fn plain_solve(
    dir: &Path,
    spec: SkySpec,
    coefficients: Option<CoefficientSky>,
    rays: usize,
) -> Vec<f64> {
    let out = dir.join(format!(
        "solve-{}",
        coefficients.and_then(|c| c.only).unwrap_or(9999)
    ));
    let mut job = SolveJob::new(SceneSource::File(dir.join("room.obj")), out.clone());
    job.settings.solve.sky = Some(spec);
    job.settings.solve.sky_coefficients = coefficients;
    job.settings.elements.enabled = false;
    job.grid = Some(GridSpec::Points(dir.join("points.csv")));
    job.grid_rays = rays;
    pipeline::run_solve(&job, |_| {}).unwrap();
    let text = std::fs::read_to_string(out.join("grid.csv")).unwrap();
    text.lines()
        .skip(1)
        .map(|l| l.split(',').nth(6).unwrap().parse().unwrap())
        .collect()
}

fn room_dir() -> tempfile::TempDir {
    folder(&[
        ("room.obj", &room()),
        ("m.mtl", MTL),
        ("points.csv", &room_points()),
        ("t.wea", WEA),
    ])
}

/// Sensor s's lux under a sky of radiance `l(column)` W/sr/m², from the coefficients.
fn from_coefficients(a: &Annual, s: usize, l: impl Fn(usize) -> f64) -> f64 {
    let c = &a.coefficients;
    let row = &c.total[s * c.columns..(s + 1) * c.columns];
    EFFICACY
        * row
            .iter()
            .enumerate()
            .map(|(k, &d)| f64::from(d) * l(k))
            .sum::<f64>()
}

/// Mean relative difference of `got` against `want`, area-averaged (sensors stand for equal
/// areas): Σ|got − want| / Σ want.
fn relative(got: &[f64], want: &[f64]) -> f64 {
    let d: f64 = got.iter().zip(want).map(|(g, w)| (g - w).abs()).sum();
    d / want.iter().sum::<f64>()
}

#[test]
fn coefficients_summed_over_a_uniform_sky_equal_the_uniform_sky_solve() {
    let dir = room_dir();
    let a = run(&job(dir.path(), "room.obj", 1));
    let rho_g = radiosity::sky::DEFAULT_GROUND_REFLECTANCE;
    // Radiance 1 W/sr/m² everywhere: E_h = π W/m², the ground ρ_g E_h / π = ρ_g.
    let got: Vec<f64> = (0..6)
        .map(|s| from_coefficients(&a, s, |k| if k == 0 { rho_g } else { 1.0 }))
        .collect();
    let spec = SkySpec {
        kind: SkyKind::Uniform,
        level: SkyLevel::ZenithLuminance(EFFICACY),
        ..SkySpec::default()
    };
    let want = plain_solve(dir.path(), spec, None, 16_384);
    let err = relative(&got, &want);
    eprintln!("uniform sky: {:.2} %", 100.0 * err);
    assert!(
        err < 0.03,
        "coefficients {got:?} against the uniform sky's {want:?}: {:.2} %",
        100.0 * err
    );
}

#[test]
fn one_coefficient_equals_a_plain_solve_under_its_patch_alone() {
    let dir = room_dir();
    let a = run(&job(dir.path(), "room.obj", 1));
    // Patches the window sees: south, low (column 1 + k, k in Tregenza's order: row 0 holds
    // 0..30 from north, so south is k = 15), and one higher up.
    for column in [16, 46] {
        let got: Vec<f64> = (0..6)
            .map(|s| from_coefficients(&a, s, |k| if k == column { 1.0 } else { 0.0 }))
            .collect();
        let only = CoefficientSky {
            subdivision: 1,
            only: Some(column),
        };
        let want = plain_solve(dir.path(), SkySpec::default(), Some(only), 65_536);
        let err = relative(&got, &want);
        eprintln!("column {column}: {:.2} % {got:?} {want:?}", 100.0 * err);
        assert!(want.iter().sum::<f64>() > 0.0);
        assert!(
            err < 0.05,
            "column {column}: coefficients {got:?} against the patch's own solve {want:?}: {:.2} %",
            100.0 * err
        );
    }
}

#[test]
fn the_year_is_the_same_on_any_thread_count() {
    let dir = room_dir();
    let j = job(dir.path(), "room.obj", 1);
    let one = crate::common::on_threads(Some(1), || run(&j));
    let two = crate::common::on_threads(Some(2), || run(&j));
    assert_eq!(one.coefficients, two.coefficients);
    assert_eq!(one.year, two.year);
}

#[test]
fn coefficients_read_back_give_the_same_year_and_a_turned_model_its_own() {
    let dir = room_dir();
    let first = job(dir.path(), "room.obj", 1);
    annual::run_and_write(&first, &Progress::hidden(), &mut |_| {}).unwrap();
    let read = |d: &Path| std::fs::read(d.join("annual/illuminance.npy")).unwrap();
    // The same weather from the coefficients: the same bytes, no solve.
    let again = AnnualJob {
        coefficients: Some(dir.path().join("out")),
        solve: SolveJob {
            out: dir.path().join("again"),
            ..first.solve.clone()
        },
        ..first.clone()
    };
    let a = annual::run(&again, &Progress::hidden(), &mut |_| {}).unwrap();
    assert!(a.solve.is_none(), "no solve with --coefficients");
    annual::run_and_write(&again, &Progress::hidden(), &mut |_| {}).unwrap();
    assert_eq!(
        read(&dir.path().join("out")),
        read(&dir.path().join("again"))
    );
    // Turned 90° clockwise (the window then faces west) from the coefficients, against a
    // solve whose north is where true north then lies in the model (−X).
    let turned = AnnualJob {
        rotate: 90.0,
        ..again.clone()
    };
    let mut west = first.clone();
    west.solve.north = glam::Vec3::NEG_X;
    west.solve.settings.solve.sky = Some(SkySpec {
        north: glam::Vec3::NEG_X,
        ..SkySpec::default()
    });
    let (t, w) = (run(&turned), run(&west));
    assert_eq!(t.year.hours, w.year.hours);
    let (tl, wl): (Vec<f64>, Vec<f64>) = (
        t.year.illuminance.iter().map(|&v| f64::from(v)).collect(),
        w.year.illuminance.iter().map(|&v| f64::from(v)).collect(),
    );
    let err = relative(&tl, &wl);
    eprintln!("turned 90°: {:.2} %", 100.0 * err);
    assert!(
        err < 0.03,
        "turned from the coefficients against solved turned: {:.2} %",
        100.0 * err
    );
    let unturned: f64 = run(&again)
        .year
        .illuminance
        .iter()
        .map(|&v| f64::from(v))
        .sum();
    assert!(
        (unturned - tl.iter().sum::<f64>()).abs() > 0.05 * unturned,
        "turning changes the year"
    );
}
