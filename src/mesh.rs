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

use glam::Vec3;

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
}

impl Mesh {
    /// Whether patch `i` is a surface the intersectors and the hemi-cube see (not a back twin).
    pub fn is_surface(&self, i: usize) -> bool {
        !matches!(self.patches[i].side, Side::Back { .. })
    }

    /// The patch that receives light meeting surface patch `patch` on its front (`back` false)
    /// or its back: the patch itself, its back twin, or `None` for the back of a one-sided
    /// patch (that light is absorbed there).
    pub fn receiver(&self, patch: u32, back: bool) -> Option<u32> {
        match (back, self.patches[patch as usize].side) {
            (false, _) => Some(patch),
            (true, Side::Front { back }) => Some(back),
            (true, _) => None,
        }
    }

    /// The surface patch `i` is a side of: itself, or the front patch of a back twin.
    pub fn surface_of(&self, i: usize) -> usize {
        match self.patches[i].side {
            Side::Back { front } => front as usize,
            _ => i,
        }
    }

    /// The other side of a two-sided surface's patch `i` (its twin, or its front), if any.
    pub fn other_side(&self, i: usize) -> Option<usize> {
        match self.patches[i].side {
            Side::Front { back } => Some(back as usize),
            Side::Back { front } => Some(front as usize),
            Side::One => None,
        }
    }

    /// How many patches are back twins.
    pub fn back_twins(&self) -> usize {
        (0..self.patches.len())
            .filter(|&i| !self.is_surface(i))
            .count()
    }

    /// The vertex indices of patch `i`.
    pub fn patch_indices(&self, i: usize) -> &[u32] {
        let p = &self.patches[i];
        &self.patch_vertices[p.first as usize..(p.first + p.count) as usize]
    }

    /// Pairs the back twins of a mesh that lost its sides (a saved solution keeps none,
    /// docs/design.md §7) again, so that rays cast into it meet each surface once and a back
    /// hit goes to the twin: a one-sided patch of the same polygon, centre and area as an
    /// earlier one, and the exactly opposite normal, is that one's twin (the builder copies
    /// them from the front; a twin always comes after its front). Returns the pairs made.
    pub fn pair_twins(&mut self) -> usize {
        type Key = (u32, [u32; 3], u64);
        let key = |p: &Patch| -> Key {
            (
                p.polygon,
                p.centre.to_array().map(f32::to_bits),
                p.area.to_bits(),
            )
        };
        let mut open: HashMap<Key, Vec<usize>> = HashMap::new();
        let mut pairs = 0;
        for i in 0..self.patches.len() {
            let p = self.patches[i];
            if p.side != Side::One {
                continue;
            }
            let k = key(&p);
            let list = open.entry(k).or_default();
            let front = list
                .iter()
                .position(|&j| self.patches[j].normal == -p.normal && p.normal != Vec3::ZERO);
            match front {
                Some(at) => {
                    let j = list.swap_remove(at);
                    self.patches[j].side = Side::Front { back: i as u32 };
                    self.patches[i].side = Side::Back { front: j as u32 };
                    pairs += 1;
                }
                None => list.push(i),
            }
        }
        pairs
    }
}

use crate::scene::Scene;
use std::collections::HashMap;

/// How to cut the scene into patches.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct MeshOptions {
    /// Longest patch edge (metres); `None` takes the scene's own hint
    /// ([`Scene::patch_size_hint`]) or derives one from the scene ([`default_patch_size`]).
    pub patch_size: Option<f32>,
    /// Give every polygon a back patch of its own (thin surfaces seen from both sides).
    pub two_sided: bool,
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

/// An upper estimate of how many patches [`build`] makes: per polygon, (its extent over the
/// patch size)² cells for each of its n − 2 triangles. Cheap: no polygon is cut.
pub fn rough_patch_count(scene: &Scene, opts: &MeshOptions) -> f64 {
    let size = patch_size(scene, opts) as f64;
    let per_polygon = |p: &crate::scene::Polygon| {
        let sides = if back_material(scene, p, opts).is_some() {
            2.0
        } else {
            1.0
        };
        let pts = polygon_points(scene, p);
        let (lo, hi) = pts
            .iter()
            .fold((pts[0], pts[0]), |(l, h), v| (l.min(*v), h.max(*v)));
        let k = ((hi - lo).length() as f64 / size).ceil().max(1.0);
        sides * k * k * (pts.len().max(3) - 2) as f64
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
    for (pi, poly) in scene.polygons.iter().enumerate() {
        let pts = polygon_points(scene, poly);
        let back = back_material(scene, poly, opts);
        for piece in planar_convex_pieces(&pts) {
            let start = b.mesh.patches.len();
            b.add_polygon(&piece, poly.material, pi as u32);
            if let Some(m) = back {
                b.add_back_twins(start, m);
            }
        }
    }
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

/// Splits a face into planar convex pieces: itself when it already is one, else triangles
/// (ear clipping in the plane of its Newell normal).
fn planar_convex_pieces(pts: &[Vec3]) -> Vec<Vec<Vec3>> {
    let n = newell(pts);
    if pts.len() == 3 || (is_planar(pts, n) && is_convex(pts, n)) {
        return vec![pts.to_vec()];
    }
    ear_clip(pts, n)
}

fn is_planar(pts: &[Vec3], n: Vec3) -> bool {
    let n = n.normalize_or_zero();
    let c = pts.iter().copied().sum::<Vec3>() / pts.len() as f32;
    let diam = pts.iter().map(|p| (*p - c).length()).fold(0.0f32, f32::max);
    pts.iter()
        .all(|p| (*p - c).dot(n).abs() <= 1e-4 * diam.max(f32::MIN_POSITIVE))
}

fn is_convex(pts: &[Vec3], n: Vec3) -> bool {
    let m = pts.len();
    (0..m).all(|k| {
        let a = pts[k];
        let b = pts[(k + 1) % m];
        let c = pts[(k + 2) % m];
        (b - a).cross(c - b).dot(n) >= -1e-9 * n.length_squared()
    })
}

/// Ear clipping of a simple polygon, projected onto the plane of its normal `n`.
fn ear_clip(pts: &[Vec3], n: Vec3) -> Vec<Vec<Vec3>> {
    let n = n.normalize_or_zero();
    let u = n.any_orthonormal_vector();
    let v = n.cross(u);
    let p2: Vec<glam::DVec2> = pts
        .iter()
        .map(|p| glam::dvec2(p.dot(u) as f64, p.dot(v) as f64))
        .collect();
    let cross = |a: glam::DVec2, b: glam::DVec2, c: glam::DVec2| (b - a).perp_dot(c - a);
    let mut idx: Vec<usize> = (0..pts.len()).collect();
    let mut out = Vec::new();
    let mut guard = 0;
    while idx.len() > 3 && guard < 10 * pts.len() {
        guard += 1;
        let m = idx.len();
        let mut clipped = false;
        for k in 0..m {
            let (ia, ib, ic) = (idx[(k + m - 1) % m], idx[k], idx[(k + 1) % m]);
            let (a, b, c) = (p2[ia], p2[ib], p2[ic]);
            if cross(a, b, c) <= 0.0 {
                continue; // reflex corner
            }
            let inside = idx.iter().any(|&j| {
                j != ia
                    && j != ib
                    && j != ic
                    && cross(a, b, p2[j]) >= 0.0
                    && cross(b, c, p2[j]) >= 0.0
                    && cross(c, a, p2[j]) >= 0.0
            });
            if !inside {
                out.push(vec![pts[ia], pts[ib], pts[ic]]);
                idx.remove(k);
                clipped = true;
                break;
            }
        }
        if !clipped {
            break;
        }
    }
    if idx.len() >= 3 {
        // What is left (a triangle, or a degenerate remainder): fan it.
        for k in 1..idx.len() - 1 {
            out.push(vec![pts[idx[0]], pts[idx[k]], pts[idx[k + 1]]]);
        }
    }
    out
}

/// Accumulates patches and welds their vertices by (position, facing).
struct Builder {
    mesh: Mesh,
    size: f32,
    /// Weld grid cell size: positions closer than this (and facing the same way) are one vertex.
    quantum: f32,
    weld: HashMap<([i64; 3], [i32; 3], u32), u32>,
}

impl Builder {
    fn new(size: f32, diagonal: f32) -> Self {
        Builder {
            mesh: Mesh {
                patch_size: size,
                ..Mesh::default()
            },
            size,
            quantum: diagonal * 1e-6,
            weld: HashMap::new(),
        }
    }

    fn vertex(&mut self, p: Vec3, n: Vec3, material: u32) -> u32 {
        let q = |x: f32| (x / self.quantum).round() as i64;
        let qn = |x: f32| (x * 1000.0).round() as i32;
        let key = (
            [q(p.x), q(p.y), q(p.z)],
            [qn(n.x), qn(n.y), qn(n.z)],
            material,
        );
        let next = self.mesh.vertices.len() as u32;
        let id = *self.weld.entry(key).or_insert(next);
        if id == next {
            self.mesh.vertices.push(p);
        }
        id
    }

    /// Cuts one planar convex polygon into patches no longer than the patch size.
    fn add_polygon(&mut self, pts: &[Vec3], material: u32, polygon: u32) {
        let n = newell(pts).normalize_or_zero();
        if n == Vec3::ZERO {
            return;
        }
        let s = self.size;
        let div = |len: f32| ((len / s).ceil() as usize).max(1);
        match pts.len() {
            3 => {
                let longest = (0..3)
                    .map(|k| (pts[(k + 1) % 3] - pts[k]).length())
                    .fold(0.0, f32::max);
                let k = div(longest);
                self.add_subdivided_triangle(pts, k, n, material, polygon);
            }
            4 => {
                let along_u = (pts[1] - pts[0]).length().max((pts[2] - pts[3]).length());
                let along_v = (pts[3] - pts[0]).length().max((pts[2] - pts[1]).length());
                let (m, k) = (div(along_u), div(along_v));
                // Bilinear grid: iso-u and iso-v lines of a planar convex quad are straight,
                // so every cell is a planar convex quad with edges ≤ the patch size.
                let at = |i: usize, j: usize| {
                    let (u, v) = (i as f32 / m as f32, j as f32 / k as f32);
                    let a = pts[0].lerp(pts[1], u);
                    let b = pts[3].lerp(pts[2], u);
                    a.lerp(b, v)
                };
                let grid: Vec<u32> = (0..=k)
                    .flat_map(|j| (0..=m).map(move |i| (i, j)))
                    .map(|(i, j)| at(i, j))
                    .collect::<Vec<_>>()
                    .into_iter()
                    .map(|p| self.vertex(p, n, material))
                    .collect();
                let g = |i: usize, j: usize| grid[j * (m + 1) + i];
                for j in 0..k {
                    for i in 0..m {
                        let ids = [g(i, j), g(i + 1, j), g(i + 1, j + 1), g(i, j + 1)];
                        self.push_patch(&ids, n, material, polygon);
                    }
                }
            }
            count => {
                let longest = (0..count)
                    .map(|k| (pts[(k + 1) % count] - pts[k]).length())
                    .fold(0.0, f32::max);
                let c = pts.iter().copied().sum::<Vec3>() / count as f32;
                let radius = pts.iter().map(|p| (*p - c).length()).fold(0.0, f32::max);
                if longest <= s && radius <= s {
                    let ids: Vec<u32> = pts.iter().map(|&p| self.vertex(p, n, material)).collect();
                    self.push_patch(&ids, n, material, polygon);
                } else {
                    // A large n-gon: fan from its centroid, then cut each triangle.
                    for e in 0..count {
                        let tri = [c, pts[e], pts[(e + 1) % count]];
                        let longest = (0..3)
                            .map(|q| (tri[(q + 1) % 3] - tri[q]).length())
                            .fold(0.0, f32::max);
                        self.add_subdivided_triangle(&tri, div(longest), n, material, polygon);
                    }
                }
            }
        }
    }

    /// Cuts a triangle into k² similar triangles on a barycentric grid (edges = original / k).
    fn add_subdivided_triangle(
        &mut self,
        t: &[Vec3],
        k: usize,
        n: Vec3,
        material: u32,
        polygon: u32,
    ) {
        let at = |i: usize, j: usize| {
            // Point i steps along t0→t1 and j steps along t0→t2.
            t[0] + (t[1] - t[0]) * (i as f32 / k as f32) + (t[2] - t[0]) * (j as f32 / k as f32)
        };
        let mut row_start = Vec::with_capacity(k + 1);
        let mut ids = Vec::new();
        for j in 0..=k {
            row_start.push(ids.len());
            for i in 0..=(k - j) {
                let p = if i + j == k && j == 0 {
                    t[1]
                } else if i == 0 && j == k {
                    t[2]
                } else {
                    at(i, j)
                };
                ids.push(self.vertex(p, n, material));
            }
        }
        let g = |i: usize, j: usize| ids[row_start[j] + i];
        for j in 0..k {
            for i in 0..(k - j) {
                self.push_patch(&[g(i, j), g(i + 1, j), g(i, j + 1)], n, material, polygon);
                if i + j + 1 < k {
                    self.push_patch(
                        &[g(i + 1, j), g(i + 1, j + 1), g(i, j + 1)],
                        n,
                        material,
                        polygon,
                    );
                }
            }
        }
    }

    /// Gives each patch from `start` on a back twin of `material` (docs/design.md §7): the same
    /// polygon wound the other way, on vertices of its own (welded with the back's facing).
    fn add_back_twins(&mut self, start: usize, material: u32) {
        for k in start..self.mesh.patches.len() {
            let front = self.mesh.patches[k];
            let ring: Vec<Vec3> = self
                .mesh
                .patch_indices(k)
                .iter()
                .rev()
                .map(|&v| self.mesh.vertices[v as usize])
                .collect();
            let ids: Vec<u32> = ring
                .iter()
                .map(|&p| self.vertex(p, -front.normal, material))
                .collect();
            let twin = self.mesh.patches.len() as u32;
            let first = self.mesh.patch_vertices.len() as u32;
            self.mesh.patch_vertices.extend_from_slice(&ids);
            self.mesh.patches.push(Patch {
                first,
                material,
                normal: -front.normal,
                side: Side::Back { front: k as u32 },
                ..front
            });
            self.mesh.patches[k].side = Side::Front { back: twin };
        }
    }

    fn push_patch(&mut self, ids: &[u32], n: Vec3, material: u32, polygon: u32) {
        let pts: Vec<Vec3> = ids
            .iter()
            .map(|&i| self.mesh.vertices[i as usize])
            .collect();
        let nn = newell(&pts);
        let area = nn.length() as f64 * 0.5;
        if area <= 0.0 {
            return;
        }
        // The centroid of the polygon's area (not of its vertices), from its fan triangles.
        let mut c = glam::DVec3::ZERO;
        let mut a_sum = 0.0;
        for k in 1..pts.len() - 1 {
            let (a, b, d) = (pts[0].as_dvec3(), pts[k].as_dvec3(), pts[k + 1].as_dvec3());
            let ak = (b - a).cross(d - a).length() * 0.5;
            c += (a + b + d) / 3.0 * ak;
            a_sum += ak;
        }
        let centre = if a_sum > 0.0 {
            (c / a_sum).as_vec3()
        } else {
            pts[0]
        };
        let first = self.mesh.patch_vertices.len() as u32;
        self.mesh.patch_vertices.extend_from_slice(ids);
        self.mesh.patches.push(Patch {
            first,
            count: ids.len() as u32,
            material,
            polygon,
            area,
            centre,
            normal: n,
            class: classify(&pts, n),
            side: Side::One,
        });
    }
}

/// Sec. 2: a patch is axial when it lies in a plane x, y or z = const (all its vertices share
/// that coordinate), so the plane-merge intersector can take it; otherwise skew.
fn classify(pts: &[Vec3], n: Vec3) -> PatchClass {
    let a = n.abs();
    let axis = if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    };
    if n.abs()[axis] < 1.0 - 1e-6 {
        return PatchClass::Skew;
    }
    let c = pts[0][axis];
    let tol = 1e-6 * c.abs().max(1.0);
    if pts.iter().all(|p| (p[axis] - c).abs() <= tol) {
        PatchClass::Axial([Axis::X, Axis::Y, Axis::Z][axis])
    } else {
        PatchClass::Skew
    }
}

impl Mesh {
    /// Total patch area.
    pub fn total_area(&self) -> f64 {
        self.patches.iter().map(|p| p.area).sum()
    }

    /// Per-vertex values for display: the area-weighted mean of the patches sharing the vertex
    /// (vertices are welded only within one facing, so creases stay sharp).
    pub fn vertex_values(&self, patch_values: &[[f64; 3]]) -> Vec<[f32; 3]> {
        let mut sum = vec![[0.0f64; 3]; self.vertices.len()];
        let mut w = vec![0.0f64; self.vertices.len()];
        for (i, p) in self.patches.iter().enumerate() {
            for &v in self.patch_indices(i) {
                for c in 0..3 {
                    sum[v as usize][c] += patch_values[i][c] * p.area;
                }
                w[v as usize] += p.area;
            }
        }
        sum.iter()
            .zip(&w)
            .map(|(s, &w)| {
                if w > 0.0 {
                    s.map(|x| (x / w) as f32)
                } else {
                    [0.0; 3]
                }
            })
            .collect()
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Material, Polygon};
    use glam::vec3;

    /// The unit square in z = 0, facing +z.
    const UNIT_QUAD: [Vec3; 4] = [
        vec3(0., 0., 0.),
        vec3(1., 0., 0.),
        vec3(1., 1., 0.),
        vec3(0., 1., 0.),
    ];

    fn scene_of(faces: &[&[Vec3]]) -> Scene {
        let mut s = Scene {
            materials: vec![Material {
                name: "m".into(),
                rho: [0.5; 3],
                ke: [0.0; 3],
                ..Material::default()
            }],
            ..Scene::default()
        };
        for f in faces {
            let base = s.positions.len() as u32;
            s.positions.extend_from_slice(f);
            let first = s.indices.len() as u32;
            s.indices.extend(base..base + f.len() as u32);
            s.polygons.push(Polygon {
                first,
                len: f.len() as u32,
                material: 0,
                back_material: None,
            });
        }
        s
    }

    fn opts(size: f32) -> MeshOptions {
        MeshOptions {
            patch_size: Some(size),
            two_sided: false,
        }
    }

    fn longest_edge(m: &Mesh) -> f32 {
        (0..m.patches.len())
            .flat_map(|i| {
                let ids = m.patch_indices(i);
                (0..ids.len()).map(move |k| {
                    (m.vertices[ids[(k + 1) % ids.len()] as usize] - m.vertices[ids[k] as usize])
                        .length()
                })
            })
            .fold(0.0, f32::max)
    }

    #[test]
    fn quad_is_cut_into_a_welded_grid_keeping_area() {
        let quad = [
            vec3(0., 0., 0.),
            vec3(2., 0., 0.),
            vec3(2., 0., -1.),
            vec3(0., 0., -1.),
        ];
        let m = build(&scene_of(&[&quad]), &opts(0.5));
        assert_eq!(m.patches.len(), 4 * 2);
        assert_eq!(m.vertices.len(), 5 * 3, "grid vertices are shared");
        assert!((m.total_area() - 2.0).abs() < 1e-6);
        assert!(longest_edge(&m) <= 0.5 + 1e-6);
        for p in &m.patches {
            assert_eq!(p.count, 4, "quads stay quads");
            assert!((p.normal - Vec3::Y).length() < 1e-6);
            assert_eq!(p.class, PatchClass::Axial(Axis::Y));
        }
    }

    #[test]
    fn triangle_and_large_ngon_keep_their_area() {
        let tri = [vec3(0., 0., 0.), vec3(1., 0., 1.), vec3(0., 1., 0.3)];
        let hexagon: Vec<Vec3> = (0..6)
            .map(|k| {
                let a = k as f32 * std::f32::consts::TAU / 6.0;
                vec3(a.cos(), a.sin(), 0.0)
            })
            .collect();
        let s = scene_of(&[&tri, &hexagon]);
        let m = build(&s, &opts(0.3));
        let tri_area = 0.5 * newell(&tri).length() as f64;
        let hex_area = 3.0 * 3f64.sqrt() / 2.0;
        assert!((m.total_area() - tri_area - hex_area).abs() < 1e-5);
        assert!(longest_edge(&m) <= 0.3 + 1e-5);
        let skew = m
            .patches
            .iter()
            .filter(|p| p.class == PatchClass::Skew)
            .count();
        assert!(skew > 0 && skew < m.patches.len());
    }

    #[test]
    fn non_convex_and_non_planar_faces_are_triangulated() {
        // An L-shape (non-convex) and a twisted quad (non-planar).
        let l = [
            vec3(0., 0., 0.),
            vec3(2., 0., 0.),
            vec3(2., 1., 0.),
            vec3(1., 1., 0.),
            vec3(1., 2., 0.),
            vec3(0., 2., 0.),
        ];
        let twisted = [
            vec3(0., 0., 5.),
            vec3(1., 0., 5.),
            vec3(1., 1., 5.3),
            vec3(0., 1., 5.),
        ];
        let m = build(&scene_of(&[&l, &twisted]), &opts(10.0));
        let l_patches: Vec<_> = m.patches.iter().filter(|p| p.polygon == 0).collect();
        assert_eq!(l_patches.len(), 4, "a hexagonal L needs 4 triangles");
        assert!(l_patches.iter().all(|p| p.count == 3));
        let l_area: f64 = l_patches.iter().map(|p| p.area).sum();
        assert!((l_area - 3.0).abs() < 1e-6);
        assert!(m
            .patches
            .iter()
            .filter(|p| p.polygon == 1)
            .all(|p| p.count == 3));
    }

    #[test]
    fn two_sided_adds_opposite_patches_with_their_own_vertices() {
        let quad = UNIT_QUAD;
        let m = build(
            &scene_of(&[&quad]),
            &MeshOptions {
                patch_size: Some(0.5),
                two_sided: true,
            },
        );
        assert_eq!(m.patches.len(), 8);
        let back = m.patches.iter().filter(|p| p.normal.z < 0.0).count();
        assert_eq!(back, 4);
        assert_eq!(m.vertices.len(), 18, "front and back never share a vertex");
        // Each front patch and its twin name each other, and only fronts are surfaces.
        for (i, p) in m.patches.iter().enumerate() {
            match p.side {
                Side::Front { back } => {
                    let t = &m.patches[back as usize];
                    assert_eq!(t.side, Side::Back { front: i as u32 });
                    assert_eq!((t.area, t.centre, t.normal), (p.area, p.centre, -p.normal));
                    assert!(m.is_surface(i) && !m.is_surface(back as usize));
                    assert_eq!(m.receiver(i as u32, true), Some(back));
                    assert_eq!(m.surface_of(back as usize), i);
                }
                Side::Back { .. } => {}
                Side::One => panic!("patch {i} has no twin"),
            }
        }
        assert_eq!(
            m.surface_triangles().count(),
            8,
            "4 quads, 2 triangles each"
        );
        assert_eq!(m.triangles().count(), 16);
    }

    #[test]
    fn twins_lost_by_a_saved_solution_are_paired_again() {
        let quad = UNIT_QUAD;
        let mut s = scene_of(&[&quad, &quad.map(|v| v + Vec3::Z)]);
        s.polygons[1].back_material = Some(0);
        // Polygon 0 one-sided, polygon 1 two-sided (a merged doubled face), 4 patches each side.
        let m = build(&s, &opts(0.5));
        assert_eq!(m.back_twins(), 4);
        let mut lost = m.clone();
        lost.patches.iter_mut().for_each(|p| p.side = Side::One);
        assert_eq!(lost.pair_twins(), 4);
        assert_eq!(lost, m);
        // Pairing again finds nothing more.
        assert_eq!(lost.pair_twins(), 0);
    }

    #[test]
    fn an_emitter_stays_one_sided_and_a_merged_back_material_is_used() {
        let quad = UNIT_QUAD;
        let mut s = scene_of(&[&quad, &quad.map(|v| v + Vec3::Z)]);
        s.materials.push(Material {
            name: "lamp".into(),
            ke: [1.0; 3],
            ..Material::default()
        });
        s.polygons[0].material = 1;
        s.polygons[1].back_material = Some(1);
        let two = MeshOptions {
            patch_size: Some(1.0),
            two_sided: true,
        };
        let m = build(&s, &two);
        assert_eq!(m.patches.len(), 3, "lamp one-sided, the other two-sided");
        assert_eq!(m.patches[0].side, Side::One);
        assert_eq!(m.patches[2].material, 1, "the merged back material");
        assert_eq!(
            build(&s, &opts(1.0)).back_twins(),
            1,
            "merged faces need no flag"
        );
    }

    #[test]
    fn crease_vertices_are_not_welded_but_coplanar_ones_are() {
        let floor_a = [
            vec3(0., 0., 0.),
            vec3(0., 0., 1.),
            vec3(1., 0., 1.),
            vec3(1., 0., 0.),
        ];
        let floor_b = [
            vec3(1., 0., 0.),
            vec3(1., 0., 1.),
            vec3(2., 0., 1.),
            vec3(2., 0., 0.),
        ];
        let wall = [
            vec3(0., 0., 0.),
            vec3(1., 0., 0.),
            vec3(1., 1., 0.),
            vec3(0., 1., 0.),
        ];
        let m = build(&scene_of(&[&floor_a, &floor_b, &wall]), &opts(5.0));
        // floors share 2 vertices (6 in all); the wall shares none with them (4 more).
        assert_eq!(m.vertices.len(), 10);
        let vals = m.vertex_values(&[[1.0; 3], [3.0; 3], [7.0; 3]]);
        let shared = m.patch_indices(1)[0] as usize; // (1,0,0) on floor_b
        assert_eq!(vals[shared], [2.0; 3]);
    }

    #[test]
    fn rough_patch_count_bounds_the_mesh_and_try_build_refuses_far_too_many() {
        // A quad with one corner typed 800 m away (found by fuzzing: a mutated hallway): not
        // convex, so ear-clipped into two slivers whose longest edge sets the subdivision.
        let dart = [
            vec3(0.9, 2.8, -18.9),
            vec3(1.5, 2.8, -819.0),
            vec3(1.5, 2.8, -17.1),
            vec3(0.9, 2.8, -17.1),
        ];
        let square = [
            vec3(0.0, 0.0, 0.0),
            vec3(1.0, 0.0, 0.0),
            vec3(1.0, 1.0, 0.0),
            vec3(0.0, 1.0, 0.0),
        ];
        let scene = scene_of(&[&dart, &square]);
        let m = build(&scene, &opts(5.0));
        assert!(rough_patch_count(&scene, &opts(5.0)) >= m.patches.len() as f64);
        let e = try_build(&scene, &opts(1e-3)).unwrap_err();
        assert!(e.contains("over the limit") && !e.contains('\n'), "{e}");
        assert_eq!(try_build(&scene, &opts(5.0)).unwrap(), m);
    }

    #[test]
    fn default_patch_size_is_a_nice_length() {
        assert_eq!(nice_length(0.0356), 0.04);
        assert_eq!(nice_length(0.6), 0.6);
        assert_eq!(nice_length(13.0), 15.0);
    }
}
