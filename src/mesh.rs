//! Polygons → patches: subdivision to the patch size, area, centre, normal, class (axis-aligned
//! or skew), and welded vertices for display.
//!
//! Quads stay quads (split into an m×n grid of sub-quads), triangles into k² sub-triangles,
//! convex n-gons stay whole when small enough; non-planar or non-convex faces are triangulated
//! first. A patch faces its winding's normal (counter-clockwise seen from the front).
//!
//! Vertices are welded across polygons only where position *and* facing agree, so Gouraud
//! interpolation smooths over a wall's own patches but never across a crease.

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
#[derive(Clone, Copy, Debug)]
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
}

/// The patches of a scene and their welded display vertices.
#[derive(Clone, Debug, Default)]
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
    /// The vertex indices of patch `i`.
    pub fn patch_indices(&self, i: usize) -> &[u32] {
        let p = &self.patches[i];
        &self.patch_vertices[p.first as usize..(p.first + p.count) as usize]
    }
}
