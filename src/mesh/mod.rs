//! Polygons → patches: subdivision to the patch size, area, centre, normal, class (axis-aligned
//! or skew), and welded vertices for display.
//!
//! Quads stay quads (split into an m×n grid of sub-quads), triangles into k² sub-triangles,
//! convex n-gons stay whole when small enough; non-planar or non-convex faces are triangulated
//! first. A patch faces its winding's normal (counter-clockwise seen from the front).
//!
//! Vertices are welded across polygons only where position, facing *and* material agree, so
//! Gouraud interpolation smooths over a wall's own patches but never across a crease, and a
//! light's radiosity never bleeds into the ceiling around it.
//!
//! | file           | what it owns                                   |
//! |----------------|------------------------------------------------|
//! | `mod.rs`       | the types, the patch size, [`build`]           |
//! | `pieces.rs`    | faces → planar convex pieces (ear clipping)    |
//! | `subdivide.rs` | pieces → patches no longer than the patch size |
//! | `classify.rs`  | axial or skew (Sec. 2)                         |
//! | `weld.rs`      | welded display vertices, per-vertex values     |
//! | `sides.rs`     | sides and back twins (docs/design.md §7)       |
//! | `hidden.rs`    | the sides no light can reach (what was found)  |
//! | `contact.rs`   | faces lying on faces that face them            |
//! | `near_lights.rs` | patches cut finer where a light is close     |
//! | `spatial.rs`   | patches in space order (facing, Morton curve)  |
//! | `grids.rs`     | pieces cut into regular grids of patches       |

mod contact;
pub mod grids;
mod hidden;
mod near_lights;
pub use contact::Contacts;
pub use hidden::Hidden;
mod classify;
mod pieces;
mod sides;
pub mod spatial;
mod subdivide;
#[cfg(test)]
mod tests;
mod weld;

use crate::scene::Scene;
use glam::Vec3;
use pieces::planar_convex_pieces;
use subdivide::Builder;

/// Which coordinate axis an axis-aligned patch is normal to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
pub enum Axis {
    X = 0,
    Y = 1,
    Z = 2,
}

/// Axis-aligned patches go to the paper's plane-merge intersector (Sec. 2), skew ones elsewhere.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PatchClass {
    Axial(Axis),
    Skew,
}

/// One radiosity element: a planar convex polygon of `count` vertices starting at `first` in
/// [`Mesh::patch_vertices`], counter-clockwise seen from the front (the side `normal` points to).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Patch {
    pub first: u32,
    pub count: u32,
    pub material: u32,
    /// The scene polygon this patch was cut from.
    pub polygon: u32,
    pub area: f64,
    pub centre: Vec3,
    pub normal: Vec3,
    pub class: PatchClass,
    /// Which side of its surface this patch is (docs/design.md §7).
    pub side: Side,
}

/// Sides (docs/design.md §7). Every geometric surface goes to the intersectors and the hemi-cube
/// once, as its front patch; a two-sided surface also has a back patch, its *twin*: the same
/// polygon wound the other way, with a material of its own, which no intersector sees. Which
/// side a ray meets decides which of the two receives it ([`Mesh::receiver`]), so light is never
/// lost to the wrong twin, and two coincident triangles never race in a BVH or a Z-buffer.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Side {
    /// One-sided: light meeting its back is absorbed there (books: "absorbed on back faces").
    #[default]
    One,
    /// The front of a two-sided surface; `back` is its twin.
    Front { back: u32 },
    /// The back of a two-sided surface; `front` is the patch the intersectors see.
    Back { front: u32 },
}

/// The patches of a scene and their welded display vertices.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Welded vertex positions (shared by patches of one facing).
    pub vertices: Vec<Vec3>,
    /// Vertex indices of all patches, back to back.
    pub patch_vertices: Vec<u32>,
    pub patches: Vec<Patch>,
    /// The patch size used (metres): no patch edge is longer.
    pub patch_size: f32,
    /// The sides no light can reach (`intersect::hidden`), found once rays can be cast; empty
    /// until then (no side hidden).
    pub hidden: Hidden,
    /// Where faces lie on faces facing them (`Mesh::find_contacts`); empty until found.
    pub contacts: Contacts,
    /// The scene's luminaires (`Scene::luminaires`): lights with no patch, which shoot first
    /// and are gathered by shadow rays (`solve::luminaire_shots`, `light::luminaires`).
    pub luminaires: Vec<crate::luminaire::Luminaire>,
    /// The pieces cut into regular grids of patches, which Embree takes whole ([`grids`]);
    /// empty for a mesh not made by [`build`] (every patch is then its own primitive).
    pub grids: Vec<grids::Grid>,
}

impl Mesh {
    /// Whether patch `i` is a surface the intersectors and the hemi-cube see (not a back twin).
    pub fn is_surface(&self, i: usize) -> bool {
        !matches!(self.patches[i].side, Side::Back { .. })
    }

    /// The box around the mesh's vertices (lowest, highest corner).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        (self.vertices.iter()).fold(
            (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
            |(lo, hi), &v| (lo.min(v), hi.max(v)),
        )
    }

    /// Smallest offset of a ray's origin off its patch: a few ulps of the largest coordinate
    /// (what the shooting and the hidden-side probes step by).
    pub fn ray_offset_floor(&self) -> f32 {
        let reach = (self.vertices.iter()).fold(0.0f32, |m, v| m.max(v.abs().max_element()));
        reach * 5e-7
    }

    /// The vertex indices of patch `i`.
    pub fn patch_indices(&self, i: usize) -> &[u32] {
        let p = &self.patches[i];
        &self.patch_vertices[p.first as usize..(p.first + p.count) as usize]
    }
}

/// How to cut the scene into patches.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct MeshOptions {
    /// Longest patch edge (metres); `None` takes the scene's own hint
    /// ([`Scene::patch_size_hint`]) or derives one from the scene ([`default_patch_size`]).
    pub patch_size: Option<f32>,
    /// Give every polygon a back patch of its own (thin surfaces seen from both sides).
    pub two_sided: bool,
    /// Keep light that meets the back of a one-sided face absorbed there, as a model's winding
    /// says, instead of giving the faces lit from behind back patches of their own
    /// (`pipeline::stages::lit_backs`, the default).
    pub one_sided: bool,
    /// Cut every patch to the patch size only, not finer near lights (`near_lights.rs`): for
    /// tests and studies that want one patch per face.
    pub uniform_patches: bool,
}

impl MeshOptions {
    /// Checks what a user can get wrong (one line naming the flag).
    pub fn check(&self) -> Result<(), crate::settings::Invalid> {
        match self.patch_size {
            Some(ps) if !(ps > 0.0 && ps.is_finite()) => crate::settings::Invalid::err(format!(
                "--patch-size must be a positive length in metres, got {ps}"
            )),
            _ => Ok(()),
        }
    }
}

/// Patch count the derived default patch size aims at: enough to show soft shadows in a room,
/// few enough that the default solve takes seconds.
const DEFAULT_PATCH_TARGET: f64 = 1500.0;

/// A patch size derived from the scene: the "nice" length (1, 1.5, 2, 2.5, 3, 4, 5, 6, 8 × 10^k)
/// closest to sqrt(total area / 1500), so a room comes out at roughly 1–2 thousand patches.
pub fn default_patch_size(scene: &Scene) -> f32 {
    let total: f64 = scene
        .polygons
        .iter()
        .map(|p| newell(&polygon_points(scene, p)).length() as f64 * 0.5)
        .sum();
    if total <= 0.0 || !total.is_finite() {
        return 1.0;
    }
    nice_length((total / DEFAULT_PATCH_TARGET).sqrt())
}

fn nice_length(x: f64) -> f32 {
    let exp = x.log10().floor();
    let base = 10f64.powf(exp);
    let m = x / base;
    let steps: [f64; 10] = [1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0];
    let best = steps
        .iter()
        .copied()
        .min_by(|a, b| (a.ln() - m.ln()).abs().total_cmp(&(b.ln() - m.ln()).abs()))
        .unwrap_or(1.0);
    (best * base) as f32
}

fn polygon_points(scene: &Scene, p: &crate::scene::Polygon) -> Vec<Vec3> {
    scene
        .polygon_indices(p)
        .iter()
        .map(|&i| scene.positions[i as usize])
        .collect()
}

/// Newell's normal of a polygon: its direction is the front normal, its length twice the area.
/// Computed in f64 about the first vertex so large coordinates keep their precision.
pub fn newell(pts: &[Vec3]) -> Vec3 {
    let o = pts[0].as_dvec3();
    let mut n = glam::DVec3::ZERO;
    for k in 0..pts.len() {
        let a = pts[k].as_dvec3() - o;
        let b = pts[(k + 1) % pts.len()].as_dvec3() - o;
        n += a.cross(b);
    }
    n.as_vec3()
}

/// The most patches a mesh may have: a patch size that would make more is taken for a mistake
/// (a typo in `--patch-size`, a wrong unit) rather than run out of memory.
pub const MAX_PATCHES: f64 = 20e6;

/// The patch size [`build`] uses: the option, else the scene's own, else derived.
pub fn patch_size(scene: &Scene, opts: &MeshOptions) -> f32 {
    opts.patch_size
        .or(scene.patch_size_hint)
        .filter(|s| s.is_finite() && *s > 0.0)
        .unwrap_or_else(|| default_patch_size(scene))
}

/// How many patches [`build`] makes before the cuts near lights (which add a few per cent
/// where lights hang close to surfaces): the same pieces and divisions, counted, not made.
/// Cheap: no patch is made, no vertex welded.
pub fn rough_patch_count(scene: &Scene, opts: &MeshOptions) -> f64 {
    rough_count(scene, opts, true)
}

/// [`rough_patch_count`] of the surface patches alone (no back twins).
pub fn rough_surface_patch_count(scene: &Scene, opts: &MeshOptions) -> f64 {
    rough_count(scene, opts, false)
}

/// The patches [`build`] makes before the cuts near lights, back twins counted or not.
fn rough_count(scene: &Scene, opts: &MeshOptions, twins: bool) -> f64 {
    let size = patch_size(scene, opts);
    let per_polygon = |p: &crate::scene::Polygon| {
        let sides = if twins && back_material(scene, p, opts).is_some() {
            2.0
        } else {
            1.0
        };
        let pts = polygon_points(scene, p);
        let base: f64 = (planar_convex_pieces(&pts).iter())
            .map(|piece| subdivide::patches_of_piece(piece, size))
            .sum();
        sides * base
    };
    scene.polygons.iter().map(per_polygon).sum::<f64>()
}

/// [`build`], refusing (one line, for a [`crate::scene::SceneError`]) a patch size that
/// would make more than [`MAX_PATCHES`] patches.
pub fn try_build(scene: &Scene, opts: &MeshOptions) -> Result<Mesh, String> {
    let n = rough_patch_count(scene, opts);
    if n.is_nan() || n > MAX_PATCHES {
        return Err(format!(
            "patch size {} m would make about {n:.1e} patches, over the limit of {MAX_PATCHES:.0e}: \
             use a larger --patch-size",
            patch_size(scene, opts)
        ));
    }
    Ok(build(scene, opts))
}

/// Builds the patches of `scene`.
pub fn build(scene: &Scene, opts: &MeshOptions) -> Mesh {
    let size = patch_size(scene, opts);
    let (lo, hi) = scene.bounds();
    let mut b = Builder::new(size, (hi - lo).length().max(f32::MIN_POSITIVE));
    if !opts.uniform_patches {
        b.near = near_lights::NearLights::new(scene, size);
    }
    for (pi, poly) in scene.polygons.iter().enumerate() {
        let pts = polygon_points(scene, poly);
        b.refine_near = !scene.materials[poly.material as usize].is_emitter();
        let back = back_material(scene, poly, opts);
        for piece in planar_convex_pieces(&pts) {
            let start = b.mesh.patches.len();
            b.add_polygon(&piece, poly.material, pi as u32);
            if let Some(m) = back {
                b.add_back_twins(start, m);
            }
        }
    }
    b.mesh.luminaires = scene.luminaires.clone();
    b.mesh
}

/// The material of a polygon's back side, if it has one (docs/design.md §7): its own (a
/// doubled face merged at load time), else with `--two-sided` its front material — except for
/// an emitter, whose light leaves its front only (as Radiance's `light`): a lamp stays one-sided.
/// Glazing (a material that transmits) is always two-sided: a pane is met from both sides.
pub fn back_material(
    scene: &Scene,
    poly: &crate::scene::Polygon,
    opts: &MeshOptions,
) -> Option<u32> {
    let m = &scene.materials[poly.material as usize];
    poly.back_material.or_else(|| {
        ((opts.two_sided && !m.is_emitter()) || m.transmittance > 0.0).then_some(poly.material)
    })
}

impl Mesh {
    /// Total patch area.
    pub fn total_area(&self) -> f64 {
        self.patches.iter().map(|p| p.area).sum()
    }

    /// Fan triangles of every patch, as (vertex indices, patch id): what exports draw.
    pub fn triangles(&self) -> impl Iterator<Item = ([u32; 3], u32)> + '_ {
        self.triangles_of(0..self.patches.len())
    }

    /// Fan triangles of the surface patches only ([`Mesh::is_surface`]): what intersectors
    /// are built from.
    pub fn surface_triangles(&self) -> impl Iterator<Item = ([u32; 3], u32)> + '_ {
        self.triangles_of((0..self.patches.len()).filter(move |&i| self.is_surface(i)))
    }

    fn triangles_of<'a>(
        &'a self,
        patches: impl Iterator<Item = usize> + 'a,
    ) -> impl Iterator<Item = ([u32; 3], u32)> + 'a {
        patches.flat_map(move |i| {
            let ids = self.patch_indices(i);
            (1..ids.len() - 1).map(move |k| ([ids[0], ids[k], ids[k + 1]], i as u32))
        })
    }
}
