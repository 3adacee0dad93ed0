//! The element mesh for display and export: the kept elements as [`Mesh`] records on welded
//! vertices, each vertex with the radiosity gathered there (Cohen, Greenberg, Immel & Brock
//! 1986, Sec. 3: the elements' vertex radiosities, Gouraud-interpolated, are the picture).
//!
//! **Welding.** Vertices are welded as the patch mesh welds them (`mesh::Builder`): where
//! position, facing and material agree. A vertex that several patches gathered (a corner
//! shared by neighbouring patches) takes the mean of their values.
//!
//! **Level.** The solve's final gather has already measured each patch's mean radiosity
//! B, with more rays than any one vertex gets: the vertices give the light's shape within
//! the patch, the patch its level. So each patch's elements are scaled (per channel) until
//! their area-weighted mean is the patch's B, the factor averaged over the elements around
//! each vertex so that it stays one value per vertex, continuous across patches. A vertex's
//! own noise at low rays then shows as a ripple within a patch, not as a blotch over
//! several (Cohen, Greenberg, Immel & Brock 1986, Sec. 3: the patches' radiosities are the
//! solution, the elements' the detail within them). Measured in
//! docs/results/adaptive-elements.md: on `scenes/spot.obj` it lowers the error of every mesh.
//!
//! **T-junctions.** Where an element meets two or more smaller ones along one edge, the
//! smaller ones' corners on that edge ("hanging" vertices) are not corners of the larger one,
//! and Gouraud shading would crack there. As Cohen et al. 1986 and later adaptive meshers do,
//! the mesh is made to conform by *interpolation*: a hanging vertex takes the value the larger
//! element's edge interpolates there (the mean of the edge's ends, recursively for vertices at
//! a quarter, an eighth, …), the longest edges first, so the shading is continuous. The larger
//! element was left whole because its corners agree within the threshold, so what this
//! changes is within it too.

use super::geometry::Elem;
use super::refine::{facing, key, PatchWork, Refiner};
use crate::intersect::Intersector;
use crate::mesh::{newell, Mesh, Patch, Side};
use glam::{DVec3, Vec3};
use rustc_hash::{FxHashMap as HashMap, FxHashSet as HashSet};

/// The element mesh and what it holds per element and per vertex.
pub(super) struct Built {
    pub mesh: Mesh,
    pub patch: Vec<u32>,
    /// Gathered (then conformed) radiosity per welded vertex, RGB W/m².
    pub vertex_b: Vec<[f64; 3]>,
    /// Each element's parameters (for point look-ups).
    pub elems: Vec<Elem>,
    pub rays: u64,
}

type WeldKey = ([i64; 3], [i32; 3], u32);

/// Welds the kept elements' corners (their values gathered by [`super::refine::finish`]) and
/// builds the mesh.
pub(super) fn build<I: Intersector>(r: &Refiner<'_, I>, work: Vec<PatchWork>, rays: u64) -> Built {
    let mesh = r.mesh;
    let mut out = Mesh {
        patch_size: mesh.patch_size,
        ..Mesh::default()
    };
    let mut weld: HashMap<WeldKey, u32> = HashMap::default();
    let mut sum: Vec<[f64; 3]> = Vec::new();
    let mut count: Vec<u32> = Vec::new();
    let mut patch_of = Vec::new();
    let mut elems = Vec::new();
    for (i, w) in work.iter().enumerate() {
        let p = &mesh.patches[i];
        let facing = facing(p.normal);
        let mut counted = HashSet::default();
        let mut values = w.corner_b.iter();
        for e in &w.done {
            let pts = e.corners(&w.roots);
            let mut ids = Vec::with_capacity(pts.len());
            for &q in &pts {
                let k = (key(q, r.quantum), facing, p.material);
                let next = out.vertices.len() as u32;
                let id = *weld.entry(k).or_insert(next);
                if id == next {
                    out.vertices.push(q.as_vec3());
                    sum.push([0.0; 3]);
                    count.push(0);
                }
                // A corner gathered by several patches takes the mean of their values.
                let v = values.next().copied().unwrap_or([0.0; 3]);
                if counted.insert(id) {
                    for c in 0..3 {
                        sum[id as usize][c] += v[c];
                    }
                    count[id as usize] += 1;
                }
                ids.push(id);
            }
            push_element(&mut out, &ids, &pts, p);
            patch_of.push(i as u32);
            elems.push(*e);
        }
    }
    let mut vertex_b: Vec<[f64; 3]> = sum
        .iter()
        .zip(&count)
        .map(|(s, &n)| s.map(|x| x / n.max(1) as f64))
        .collect();
    let floor = super::FLOOR * super::mean_radiosity(mesh, r.b);
    to_patch_level(&out, &patch_of, r.b, floor, &mut vertex_b);
    conform(&out, &weld, r.quantum, &mut vertex_b);
    Built {
        mesh: out,
        patch: patch_of,
        vertex_b,
        elems,
        rays,
    }
}

/// The most a patch's level may scale its elements' gathered light (the module notes, "Level").
pub const MAX_LEVEL: f64 = 4.0;

/// Puts the gathered light at the patch solution's level (module notes, "Level"): per patch
/// and channel, k = B / (its elements' area-weighted mean), at most [`MAX_LEVEL`] (1 where
/// that mean is under `floor`), and each vertex of `m` (the element mesh, elements in
/// `patch_of`'s patches) times the area-weighted mean k of the elements around it.
fn to_patch_level(m: &Mesh, patch_of: &[u32], b: &[[f64; 3]], floor: f64, vb: &mut [[f64; 3]]) {
    let mut sum = vec![[0.0f64; 3]; b.len()];
    let mut area = vec![0.0f64; b.len()];
    for (e, &p) in patch_of.iter().enumerate() {
        let ids = m.patch_indices(e);
        let a = m.patches[e].area;
        for &v in ids {
            for c in 0..3 {
                sum[p as usize][c] += a * vb[v as usize][c] / ids.len() as f64;
            }
        }
        area[p as usize] += a;
    }
    let k: Vec<[f64; 3]> = (sum.iter().zip(&area).zip(b))
        .map(|((s, &a), bp)| {
            [0, 1, 2].map(|c| {
                let mean = if a > 0.0 { s[c] / a } else { 0.0 };
                if mean > floor && bp[c].is_finite() {
                    (bp[c].max(0.0) / mean).min(MAX_LEVEL)
                } else {
                    1.0
                }
            })
        })
        .collect();
    let mut ks = vec![[0.0f64; 3]; vb.len()];
    let mut weight = vec![0.0f64; vb.len()];
    for (e, &p) in patch_of.iter().enumerate() {
        let a = m.patches[e].area;
        for &v in m.patch_indices(e) {
            for c in 0..3 {
                ks[v as usize][c] += a * k[p as usize][c];
            }
            weight[v as usize] += a;
        }
    }
    for ((x, kv), &w) in vb.iter_mut().zip(&ks).zip(&weight) {
        if w > 0.0 {
            for c in 0..3 {
                x[c] *= kv[c] / w;
            }
        }
    }
}

/// Appends one element record (the patch's material, polygon, normal, class; one-sided: the
/// element mesh is for display, the sides are the patches').
fn push_element(out: &mut Mesh, ids: &[u32], pts: &[DVec3], p: &Patch) {
    let v: Vec<Vec3> = pts.iter().map(|q| q.as_vec3()).collect();
    let area = newell(&v).length() as f64 * 0.5;
    let mut c = DVec3::ZERO;
    let mut a_sum = 0.0;
    for k in 1..pts.len() - 1 {
        let ak = (pts[k] - pts[0]).cross(pts[k + 1] - pts[0]).length() * 0.5;
        c += (pts[0] + pts[k] + pts[k + 1]) / 3.0 * ak;
        a_sum += ak;
    }
    let centre = if a_sum > 0.0 {
        (c / a_sum).as_vec3()
    } else {
        v[0]
    };
    let first = out.patch_vertices.len() as u32;
    out.patch_vertices.extend_from_slice(ids);
    out.patches.push(Patch {
        first,
        count: ids.len() as u32,
        material: p.material,
        polygon: p.polygon,
        area,
        centre,
        normal: p.normal,
        class: p.class,
        side: Side::One,
    });
}

/// Makes the shading conform across T-junctions (module docs): every element edge, longest
/// first, gives each welded vertex at its midpoint (recursively) the mean of its ends.
fn conform(m: &Mesh, weld: &HashMap<WeldKey, u32>, quantum: f64, vb: &mut [[f64; 3]]) {
    let mut edges: Vec<(f64, u32, u32, usize)> = Vec::new();
    for e in 0..m.patches.len() {
        let ids = m.patch_indices(e);
        for k in 0..ids.len() {
            let (a, b) = (ids[k], ids[(k + 1) % ids.len()]);
            let len =
                (m.vertices[a as usize].as_dvec3() - m.vertices[b as usize].as_dvec3()).length();
            edges.push((len, a.min(b), a.max(b), e));
        }
    }
    edges.sort_by(|x, y| {
        y.0.total_cmp(&x.0)
            .then(x.1.cmp(&y.1))
            .then(x.2.cmp(&y.2))
            .then(x.3.cmp(&y.3))
    });
    edges.dedup_by(|x, y| x.1 == y.1 && x.2 == y.2);
    for &(_, a, b, e) in &edges {
        let p = &m.patches[e];
        let facing = facing(p.normal);
        let mut stack = vec![(a, b, 0u32)];
        while let Some((a, b, depth)) = stack.pop() {
            if depth > 12 {
                continue;
            }
            let mid = (m.vertices[a as usize].as_dvec3() + m.vertices[b as usize].as_dvec3()) * 0.5;
            let Some(&h) = weld.get(&(key(mid, quantum), facing, p.material)) else {
                continue;
            };
            if h == a || h == b {
                continue;
            }
            let (va, vb_) = (vb[a as usize], vb[b as usize]);
            vb[h as usize] = [0, 1, 2].map(|c| 0.5 * (va[c] + vb_[c]));
            stack.push((a, h, depth + 1));
            stack.push((h, b, depth + 1));
        }
    }
}
