//! What `radiosity crosscheck` and `radiosity bench intersect` run: load or generate the
//! scenes, mesh them, and hand them to [`crate::bench::crosscheck`] and
//! [`crate::bench::intersect_table`]. The binary only fills the jobs and prints.

use super::crosscheck::{self, CrossReport, RaySource};
use super::intersect_table::{self as bench, BenchRow};
use crate::generate::{self, BuildingOptions};
use crate::mesh::MeshOptions;
use crate::model::Model;
use crate::scene::SceneSource;
use crate::scene::{self, LoadOptions, Scene};
use crate::settings::Invalid;
use crate::Error;

/// Seed of the rays of `radiosity crosscheck` and `radiosity bench intersect` (`--seed`).
pub const DEFAULT_SEED: u64 = 1;
/// `radiosity crosscheck --eps`: the edge distance, relative to the scene's diagonal.
pub const DEFAULT_EPS: f32 = 1e-5;
/// `radiosity bench intersect --rays`: rays per intersector and scene.
pub const DEFAULT_BENCH_RAYS: u64 = 1_000_000;
/// `radiosity bench intersect --generated`: the generated buildings' sizes, in patches.
pub const DEFAULT_GENERATED: &str = "1k,10k,100k";

/// Everything `radiosity crosscheck` does.
#[derive(Clone, Debug)]
pub struct CrossJob {
    pub source: SceneSource,
    pub load: LoadOptions,
    pub mesh: MeshOptions,
    pub rays: u64,
    pub seed: u64,
    /// Edge distance for the "edge" class, relative to the scene's diagonal.
    pub eps: f32,
    /// `Some` declares the scene closed or open; `None` judges by the reference's escapes.
    pub closed: Option<bool>,
}

/// `radiosity crosscheck`'s result: the scene and the report.
#[derive(Clone, Debug, serde::Serialize)]
pub struct CrossCheck {
    pub scene: String,
    pub patch_size: f32,
    #[serde(flatten)]
    pub report: CrossReport,
}

impl std::fmt::Display for CrossCheck {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(f, "{} at patch size {} m", self.scene, self.patch_size)?;
        write!(f, "{}", self.report)
    }
}

impl CrossJob {
    /// Refuses a bad patch size, no rays or an edge distance outside (0, 1).
    pub fn check(&self) -> Result<(), Invalid> {
        self.mesh.check()?;
        if self.rays == 0 {
            return Invalid::err("--rays must be at least 1");
        }
        if !(self.eps > 0.0 && self.eps < 1.0) {
            return Invalid::err(format!("--eps must be in (0, 1), got {}", self.eps));
        }
        Ok(())
    }
}

/// Runs the cross-check; the bar's verdict is in the report (`passed`), not an error.
pub fn crosscheck(job: &CrossJob) -> Result<CrossCheck, Error> {
    job.check()?;
    let Model { scene, mesh: m } = Model::load(&job.source, &job.load, &job.mesh)?;
    if m.patches.is_empty() {
        return Err(Error::Invalid(format!(
            "{}: no patches to cast at",
            scene.name
        )));
    }
    let mut report = crosscheck::crosscheck(&m, job.rays, job.seed, job.eps)?;
    if job.closed.is_some() {
        report.apply_bar(job.closed);
    }
    Ok(CrossCheck {
        scene: scene.name.clone(),
        patch_size: m.patch_size,
        report,
    })
}

/// A generated building of about `patches` patches (seed 1), made in memory.
pub fn generated_building(patches: usize) -> Result<Scene, Error> {
    let opts = BuildingOptions::for_patches(patches, 1);
    let (mut obj, mut mtl) = (Vec::new(), Vec::new());
    generate::write_building(&mut obj, &mut mtl, "building.mtl", &opts)
        .map_err(|e| Error::Invalid(format!("generating a building: {e}")))?;
    let text = |b: Vec<u8>| String::from_utf8(b).unwrap_or_default();
    Ok(scene::load_obj_from_strs(
        &format!("building-{}", short(patches)),
        &text(obj),
        &text(mtl),
        &LoadOptions::default(),
    )?)
}

/// 1000 → "1k", 1000000 → "1M".
fn short(n: usize) -> String {
    match n {
        n if n >= 1_000_000 && n % 1_000_000 == 0 => format!("{}M", n / 1_000_000),
        n if n >= 1000 && n % 1000 == 0 => format!("{}k", n / 1000),
        n => n.to_string(),
    }
}

/// Everything `radiosity bench intersect` does.
#[derive(Clone, Debug)]
pub struct BenchJob {
    /// Scenes, meshed with `mesh`.
    pub scenes: Vec<SceneSource>,
    /// Generated buildings of about these many patches (at the generator's patch size).
    pub generated: Vec<usize>,
    pub load: LoadOptions,
    pub mesh: MeshOptions,
    /// Rays per intersector and scene.
    pub rays: u64,
    pub seed: u64,
    /// Which rays are cast (`--source`).
    pub rays_from: RaysFrom,
}

/// Which test rays `radiosity bench intersect` casts (`--source`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum RaysFrom {
    /// Half of each kind. The default.
    #[default]
    #[value(help = crate::settings::NO_HELP)]
    Both,
    /// From patch surfaces, as the solver casts them.
    #[value(help = crate::settings::NO_HELP)]
    Surface,
    /// Origin in the bounds, direction on the sphere.
    #[value(help = crate::settings::NO_HELP)]
    Uniform,
}

impl RaysFrom {
    /// The one kind cast, or `None` for both.
    pub fn only(self) -> Option<RaySource> {
        match self {
            RaysFrom::Both => None,
            RaysFrom::Surface => Some(RaySource::Surface),
            RaysFrom::Uniform => Some(RaySource::Uniform),
        }
    }
}

impl BenchJob {
    /// Refuses a bad patch size, no rays or a generated size out of range.
    pub fn check(&self) -> Result<(), Invalid> {
        self.mesh.check()?;
        if self.rays == 0 {
            return Invalid::err("--rays must be at least 1");
        }
        if let Some(&n) = self
            .generated
            .iter()
            .find(|&&n| !(1..=10_000_000).contains(&n))
        {
            return Invalid::err(format!(
                "--generated sizes must be between 1 and 10000000 patches, got {n}"
            ));
        }
        Ok(())
    }
}

/// `radiosity bench intersect`: each scene, then each generated building, through every
/// applicable intersector. `log` hears each row as it is measured.
pub fn bench_intersect(
    job: &BenchJob,
    mut log: impl FnMut(&BenchRow),
) -> Result<Vec<BenchRow>, Error> {
    job.check()?;
    let (rays, seed, from) = (job.rays, job.seed, job.rays_from.only());
    let mut rows = Vec::new();
    for source in &job.scenes {
        let model = Model::load(source, &job.load, &job.mesh)?;
        let row = bench::bench_mesh(&model.scene.name, &model.mesh, rays, seed, from)?;
        log(&row);
        rows.push(row);
    }
    for &n in &job.generated {
        let m = Model::from_scene(generated_building(n)?, &MeshOptions::default())?.mesh;
        let row = bench::bench_mesh(&format!("building-{}", short(n)), &m, rays, seed, from)?;
        log(&row);
        rows.push(row);
    }
    Ok(rows)
}
