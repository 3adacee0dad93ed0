//! `radiosity bench timing`: the timings the tests do not make (a test asserts what holds on any
//! machine; a time is a figure to print): the hemi-cube's time per shot by resolution and layout
//! (Sec. 4, Fig. 5's curve C), the rasteriser on a room of 100,000 triangles, and, with
//! `--grid`, the sensor grid's work plane (`radiosity bench timing scenes/office.obj --grid
//! 0.8,0.004`: the office at 4 mm, about two million columns).

use crate::grid::GridSpec;
use crate::intersect::embree::EmbreeScene;
use crate::mesh::{Mesh, MeshOptions, Patch, PatchClass, Side};
use crate::model::Model;
use crate::render::{render_linear, tone_map, Camera, RenderOptions};
use crate::sample::hemicube::{Hemicube, HemicubeBuffer};
use crate::sample::Frame;
use crate::scene::{LoadOptions, SceneSource};
use crate::Error;
use glam::Vec3;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use serde::Serialize;
use std::fmt::Write as _;
use std::time::Instant;

/// Shots per round of [`hemicube_shots`]; the best of [`ROUNDS`] rounds is kept.
pub const SHOTS: usize = 200;
/// Rounds of [`SHOTS`] shots each.
pub const ROUNDS: usize = 5;
/// Quads per wall edge of the room [`render_room`] draws: 6 · 91² quads, 99,372 triangles.
pub const ROOM_QUADS: usize = 91;

/// What `radiosity bench timing` measures.
#[derive(Clone, Debug)]
pub struct TimingJob {
    pub source: SceneSource,
    pub load: LoadOptions,
    pub mesh: MeshOptions,
    /// The grid to time (`--grid`), none when `None`.
    pub grid: Option<String>,
}

/// What `radiosity bench timing` measured.
#[derive(Clone, Debug, Serialize)]
pub struct TimingReport {
    pub scene: String,
    pub patches: usize,
    pub hemicube: Vec<ShotTiming>,
    pub render: Vec<RenderTiming>,
    pub grid: Option<GridTiming>,
}

/// One hemi-cube layout's time per shot, single-threaded.
#[derive(Clone, Debug, Serialize)]
pub struct ShotTiming {
    pub name: String,
    pub resolution: usize,
    pub uniform: bool,
    pub jittered: bool,
    pub cells: usize,
    /// Building the cube's layout and delta form factors.
    pub build_ms: f64,
    /// The best round's mean time per shot.
    pub ms_per_shot: f64,
    /// Patches seen per shot, on average over all rounds.
    pub seen_per_shot: f64,
}

/// One view of the room, rendered and tone-mapped.
#[derive(Clone, Debug, Serialize)]
pub struct RenderTiming {
    pub view: String,
    pub triangles: usize,
    pub width: u32,
    pub height: u32,
    pub supersample: u32,
    pub render_ms: f64,
    pub tone_map_ms: f64,
}

/// The sensor grid's placement (Embree, all threads).
#[derive(Clone, Debug, Serialize)]
pub struct GridTiming {
    pub grid: String,
    pub sensors: usize,
    pub seconds: f64,
}

/// Loads the scene and runs the three timings (the grid only when asked for, and first).
pub fn run(job: &TimingJob) -> Result<TimingReport, Error> {
    let grid = job
        .grid
        .as_deref()
        .map(|g| {
            g.parse::<GridSpec>()
                .map(|spec| (g, spec))
                .map_err(|e| Error::Invalid(e.to_string()))
        })
        .transpose()?;
    let model = Model::load(&job.source, &job.load, &job.mesh)?;
    // The grid first: a model it does not suit is refused before the other timings run.
    let grid = match grid {
        Some((text, spec)) => {
            let embree = EmbreeScene::build(&model.mesh, |_| true)?;
            let t = Instant::now();
            let sensors = spec
                .sensors(&model.mesh, &embree, &crate::sky::Compass::default())
                .map_err(|e| Error::Invalid(e.to_string()))?;
            Some(GridTiming {
                grid: text.to_string(),
                sensors: sensors.len(),
                seconds: t.elapsed().as_secs_f64(),
            })
        }
        None => None,
    };
    let hemicube = hemicube_shots(&model.mesh);
    let render = render_room();
    Ok(TimingReport {
        scene: model.scene.name.clone(),
        patches: model.mesh.patches.len(),
        hemicube,
        render,
        grid,
    })
}

/// Time per shot of five hemi-cubes, single-threaded: the best of [`ROUNDS`] rounds of
/// [`SHOTS`] shots from patches spread over the mesh, each turned by a random angle.
pub fn hemicube_shots(mesh: &Mesh) -> Vec<ShotTiming> {
    let mut rng = Pcg64Mcg::seed_from_u64(5);
    let mut rows = Vec::new();
    if mesh.patches.is_empty() {
        return rows;
    }
    for (name, n, uniform, jitter) in [
        ("uniform 100", 100, true, false),
        ("uniform 100 jittered", 100, true, true),
        ("non-uniform 101", 101, false, false),
        ("non-uniform 51", 51, false, false),
        ("non-uniform 21", 21, false, false),
    ] {
        let t = Instant::now();
        let cube = if uniform {
            Hemicube::uniform(n)
        } else {
            Hemicube::non_uniform(n)
        };
        let build = t.elapsed().as_secs_f64();
        let mut buf = HemicubeBuffer::default();
        let mut out = Vec::new();
        let (mut best, mut seen) = (f64::INFINITY, 0);
        for _ in 0..ROUNDS {
            let t = Instant::now();
            for s in 0..SHOTS {
                let i = (s * 7919) % mesh.patches.len();
                let p = &mesh.patches[i];
                let frame = Frame::new(p.normal, rng.gen::<f32>() * std::f32::consts::TAU);
                let jit = jitter.then_some(&mut rng);
                cube.shoot(mesh, i, p.centre, &frame, jit, &mut buf, &mut out);
                seen += out.len();
            }
            best = best.min(t.elapsed().as_secs_f64() / SHOTS as f64);
        }
        rows.push(ShotTiming {
            name: name.into(),
            resolution: n,
            uniform,
            jittered: jitter,
            cells: cube.cell_count(),
            build_ms: build * 1e3,
            ms_per_shot: best * 1e3,
            seen_per_shot: seen as f64 / (ROUNDS * SHOTS) as f64,
        });
    }
    rows
}

/// The rasteriser on a closed 10 m room of 6 · [`ROOM_QUADS`]² quads, at the default picture
/// size and supersampling, from inside and from a camera fitted around it; then tone mapping.
pub fn render_room() -> Vec<RenderTiming> {
    let (mesh, rgb) = room(ROOM_QUADS);
    let triangles = 2 * mesh.patches.len();
    let opts = RenderOptions::default();
    let aspect = opts.width as f32 / opts.height as f32;
    let inside = Camera::perspective(
        Vec3::new(2.0, 3.0, 4.0),
        Vec3::new(9.0, 7.0, 1.0),
        Vec3::Y,
        60.0,
        aspect,
    );
    let fitted = Camera::fit(Vec3::ZERO, Vec3::splat(10.0), aspect);
    [("inside", inside), ("fitted", fitted)]
        .into_iter()
        .map(|(view, cam)| {
            let t = Instant::now();
            let img = render_linear(&mesh, &rgb, &cam, &opts);
            let render_ms = t.elapsed().as_secs_f64() * 1e3;
            let t = Instant::now();
            tone_map(&img, None);
            RenderTiming {
                view: view.into(),
                triangles,
                width: opts.width,
                height: opts.height,
                supersample: opts.supersample,
                render_ms,
                tone_map_ms: t.elapsed().as_secs_f64() * 1e3,
            }
        })
        .collect()
}

/// A closed box room 10 m wide of `n`×`n` quads per wall (2·6·n² triangles), normals inward,
/// with a colour per vertex (also the renderer's tests' room).
pub(crate) fn room(n: usize) -> (Mesh, Vec<[f32; 3]>) {
    let size = 10.0;
    let mut mesh = Mesh::default();
    let mut rgb = Vec::new();
    for axis in 0..3 {
        for side in [0.0f32, 1.0] {
            for i in 0..n {
                for j in 0..n {
                    let at = |u: usize, v: usize| {
                        let (u, v) = (u as f32 / n as f32 * size, v as f32 / n as f32 * size);
                        let mut p = [0.0; 3];
                        p[axis] = side * size;
                        p[(axis + 1) % 3] = u;
                        p[(axis + 2) % 3] = v;
                        Vec3::from_array(p)
                    };
                    let mut c = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
                    // Counter-clockwise seen from inside the room.
                    if side > 0.5 {
                        c.reverse();
                    }
                    let colour = [(i * j % 7) as f32 / 7.0, 0.5, side];
                    push_quad(&mut mesh, &c);
                    rgb.extend([colour; 4]);
                }
            }
        }
    }
    (mesh, rgb)
}

/// Appends the quad `corners` as one patch with vertices of its own.
fn push_quad(mesh: &mut Mesh, corners: &[Vec3; 4]) {
    let first = mesh.patch_vertices.len() as u32;
    let n = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
    for p in corners {
        mesh.patch_vertices.push(mesh.vertices.len() as u32);
        mesh.vertices.push(*p);
    }
    mesh.patches.push(Patch {
        first,
        count: 4,
        material: 0,
        polygon: 0,
        area: f64::from(n.length()),
        centre: corners.iter().sum::<Vec3>() / 4.0,
        normal: n.normalize(),
        class: PatchClass::Skew,
        side: Side::One,
    });
}

impl ShotTiming {
    fn line(&self, patches: usize) -> String {
        format!(
            "hemi-cube {}: {patches} patches, {} cells (built {:.3} ms), {:.3} ms/shot, {:.0} seen",
            self.name, self.cells, self.build_ms, self.ms_per_shot, self.seen_per_shot
        )
    }
}

impl RenderTiming {
    fn line(&self) -> String {
        format!(
            "render {}: {} triangles, {}x{}x{}, render {:.1} ms, tone map {:.1} ms",
            self.view,
            self.triangles,
            self.width,
            self.height,
            self.supersample * self.supersample,
            self.render_ms,
            self.tone_map_ms
        )
    }
}

impl GridTiming {
    fn line(&self) -> String {
        format!(
            "grid {}: {} sensors in {:.2} s",
            self.grid, self.sensors, self.seconds
        )
    }
}

impl TimingReport {
    /// The figures as the lines `radiosity bench timing` prints.
    pub fn text(&self) -> String {
        let mut s = format!("{}: {} patches\n", self.scene, self.patches);
        for t in &self.hemicube {
            let _ = writeln!(s, "  {}", t.line(self.patches));
        }
        for t in &self.render {
            let _ = writeln!(s, "  {}", t.line());
        }
        if let Some(g) = &self.grid {
            let _ = writeln!(s, "  {}", g.line());
        }
        s
    }
}
