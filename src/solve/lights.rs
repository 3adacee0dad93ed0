//! Light groups for per-light channels (`--per-light`, `--light-groups`; the paper's Images
//! 1a/1b, where two ceiling lights were re-weighted in real time without solving again).
//!
//! A group is either every patch of one emitting material, or one connected emitting surface
//! (emitting polygons that share a vertex position), so two fixtures of the same material can
//! be dimmed apart.

use crate::mesh::Mesh;
use crate::scene::Scene;

/// How lights are grouped into channels.
#[derive(
    Clone,
    Copy,
    Debug,
    PartialEq,
    Eq,
    Default,
    serde::Serialize,
    serde::Deserialize,
    clap::ValueEnum,
)]
#[serde(rename_all = "kebab-case")]
pub enum GroupBy {
    /// One channel per emitting material (named after it).
    #[default]
    #[value(help = "One channel per emitting material")]
    Material,
    /// One channel per connected emitting surface (named `material#k`).
    #[value(help = "One channel per connected emitting surface (fixtures of one material apart)")]
    Connected,
}

pub use crate::light::{sky_patch_channel, GROUND_CHANNEL, SKY_CHANNEL, SUN_CHANNEL};

/// The light group of every patch.
#[derive(Clone, Debug, PartialEq)]
pub struct LightGroups {
    pub names: Vec<String>,
    /// Group per patch, `u32::MAX` for patches that do not emit.
    pub of_patch: Vec<u32>,
}

impl LightGroups {
    pub fn len(&self) -> usize {
        self.names.len()
    }

    /// The channel of `name` (the sky's, the sun's), if there is one.
    pub fn channel(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }
}

/// Groups the emitting patches of `mesh` (built from `scene`).
pub fn groups(scene: &Scene, mesh: &Mesh, by: GroupBy) -> LightGroups {
    let emits = |material: u32| scene.materials[material as usize].is_emitter();
    // Group per polygon first.
    let npoly = scene.polygons.len();
    let mut poly_group = vec![u32::MAX; npoly];
    let mut names = Vec::new();
    match by {
        GroupBy::Material => {
            let mut of_material = vec![u32::MAX; scene.materials.len()];
            for (k, poly) in scene.polygons.iter().enumerate() {
                if emits(poly.material) {
                    let m = poly.material as usize;
                    if of_material[m] == u32::MAX {
                        of_material[m] = names.len() as u32;
                        names.push(scene.materials[m].name.clone());
                    }
                    poly_group[k] = of_material[m];
                }
            }
        }
        GroupBy::Connected => {
            // Union-find over emitting polygons of one material sharing a vertex position.
            let mut parent: Vec<usize> = (0..npoly).collect();
            fn find(parent: &mut [usize], mut x: usize) -> usize {
                while parent[x] != x {
                    parent[x] = parent[parent[x]];
                    x = parent[x];
                }
                x
            }
            let mut at: std::collections::HashMap<([u32; 3], u32), usize> =
                std::collections::HashMap::new();
            for (k, poly) in scene.polygons.iter().enumerate() {
                if !emits(poly.material) {
                    continue;
                }
                let idx = &scene.indices[poly.first as usize..(poly.first + poly.len) as usize];
                for &v in idx {
                    let p = scene.positions[v as usize];
                    let key = ([p.x.to_bits(), p.y.to_bits(), p.z.to_bits()], poly.material);
                    match at.get(&key) {
                        Some(&other) => {
                            let (a, b) = (find(&mut parent, k), find(&mut parent, other));
                            if a != b {
                                parent[a.max(b)] = a.min(b);
                            }
                        }
                        None => {
                            at.insert(key, k);
                        }
                    }
                }
            }
            let mut of_root = std::collections::HashMap::new();
            let mut count_of_material = vec![0usize; scene.materials.len()];
            for (k, poly) in scene.polygons.iter().enumerate() {
                if !emits(poly.material) {
                    continue;
                }
                let root = find(&mut parent, k);
                let g = *of_root.entry(root).or_insert_with(|| {
                    let m = poly.material as usize;
                    count_of_material[m] += 1;
                    names.push(format!(
                        "{}#{}",
                        scene.materials[m].name, count_of_material[m]
                    ));
                    names.len() as u32 - 1
                });
                poly_group[k] = g;
            }
        }
    }
    let of_patch = mesh
        .patches
        .iter()
        .map(|p| {
            if emits(p.material) {
                poly_group
                    .get(p.polygon as usize)
                    .copied()
                    .unwrap_or(u32::MAX)
            } else {
                u32::MAX
            }
        })
        .collect();
    LightGroups { names, of_patch }
}

/// Of rays leaving the lights' *backs* (up to [`FACING_PATCHES`] emitting surface patches, 16
/// rays each on the polar grid, about each patch's centre), the share that meets any surface.
/// docs/design.md §7: when most of the emitted light escapes a model, this tells lights turned
/// out of a closed model (their backs see the rooms: most such rays meet something) from an
/// open model lit on purpose (their backs see the sky). 0 when nothing emits.
pub fn backs_meeting_surfaces<I: crate::intersect::Intersector>(
    mesh: &Mesh,
    materials: &[crate::scene::Material],
    isect: &I,
) -> f64 {
    use crate::intersect::Ray;
    use crate::sample::{polar::PolarGrid, Frame};
    let lights: Vec<usize> = (0..mesh.patches.len())
        .filter(|&i| {
            mesh.is_surface(i) && materials[mesh.patches[i].material as usize].is_emitter()
        })
        .collect();
    if lights.is_empty() {
        return 0.0;
    }
    let step = lights.len().div_ceil(FACING_PATCHES);
    let grid = PolarGrid::for_samples(16.0);
    let mut rng = super::rng_for(0, super::Stream::Shot(0), 0);
    let (mut met, mut cast) = (0usize, 0usize);
    for &i in lights.iter().step_by(step) {
        let p = &mesh.patches[i];
        let frame = Frame::new(-p.normal, 0.0);
        let eps = 1e-4 * (p.area as f32).sqrt().max(1e-3);
        for k in 0..grid.len() {
            let ray = Ray {
                org: p.centre - p.normal * eps,
                dir: frame.to_world(grid.direction(k, 0.0, false, &mut rng)),
                tnear: 0.0,
                tfar: f32::INFINITY,
            };
            cast += 1;
            met += usize::from(matches!(isect.intersect(&ray), Some(h) if h.patch as usize != i));
        }
    }
    met as f64 / cast as f64
}

/// How many light patches [`backs_meeting_surfaces`] samples at most.
pub const FACING_PATCHES: usize = 256;
