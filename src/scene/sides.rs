//! Coincident faces (docs/design.md §7): exporters write a thin or "two-sided" surface as two
//! polygons on the same vertices, once each way round (SketchUp, many CAD exporters, MGF
//! `sides 2`). Solved as written, the two race in every intersector and light lands on the wrong
//! twin. At load time such a pair becomes one polygon with a back material
//! ([`Polygon::back_material`](super::Polygon::back_material)), which the mesh turns into a front patch and its back twin. A
//! polygon repeated with the *same* winding is kept once (reported with a count).
//!
//! Two polygons are coincident when they have the same vertex positions (to a millionth of the
//! model's size) in the same cyclic order, forwards or backwards. Overlapping faces that do not
//! share their vertices are not detected.

use super::Scene;
use std::collections::HashMap;

/// What [`merge_coincident`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct Merged {
    /// Pairs wound opposite ways, now one two-sided polygon each.
    pub two_sided: usize,
    /// Repeats of a polygon with the same winding (or a third copy), dropped.
    pub repeated: usize,
}

/// Turns every polygon round (reverses its winding), for `--flip`.
pub fn flip(scene: &mut Scene) {
    for p in &scene.polygons {
        scene.indices[p.first as usize..(p.first + p.len) as usize].reverse();
    }
}

/// A polygon's vertex positions, quantized, in its cyclic order starting at the smallest.
fn canonical(keys: &[[i64; 3]]) -> Vec<[i64; 3]> {
    let start = (0..keys.len()).min_by_key(|&k| keys[k]).unwrap_or(0);
    (0..keys.len())
        .map(|k| keys[(start + k) % keys.len()])
        .collect()
}

/// Merges coincident polygons of `scene` (see the module notes), keeping the first of each
/// set in file order as the front. Adds one warning when polygons were repeated.
pub fn merge_coincident(scene: &mut Scene) -> Merged {
    let (lo, hi) = scene.bounds();
    let quantum = ((hi - lo).length() * 1e-6).max(f32::MIN_POSITIVE);
    let key_of = |i: u32| {
        let p = scene.positions[i as usize];
        [p.x, p.y, p.z].map(|x| (x / quantum).round() as i64)
    };
    let mut first_of: HashMap<Vec<[i64; 3]>, usize> = HashMap::new();
    let mut keep = vec![true; scene.polygons.len()];
    let mut merged = Merged::default();
    // The back material each front polygon was given (at most one).
    let mut back_of: HashMap<usize, u32> = HashMap::new();
    for (pi, poly) in scene.polygons.iter().enumerate() {
        let keys: Vec<[i64; 3]> = scene
            .polygon_indices(poly)
            .iter()
            .map(|&i| key_of(i))
            .collect();
        let forward = canonical(&keys);
        let reversed: Vec<[i64; 3]> = keys.iter().rev().copied().collect();
        let backward = canonical(&reversed);
        if first_of.contains_key(&forward) {
            keep[pi] = false;
            merged.repeated += 1;
        } else if let Some(&front) = first_of.get(&backward) {
            keep[pi] = false;
            if let std::collections::hash_map::Entry::Vacant(e) = back_of.entry(front) {
                e.insert(poly.material);
                merged.two_sided += 1;
            } else {
                merged.repeated += 1;
            }
        } else {
            first_of.insert(forward, pi);
        }
    }
    for (front, material) in back_of {
        scene.polygons[front].back_material = Some(material);
    }
    if merged.repeated > 0 {
        scene.warnings.push(format!(
            "{} polygon(s) repeated on the vertices of another with the same winding: kept once",
            merged.repeated
        ));
    }
    let mut k = 0;
    scene.polygons.retain(|_| {
        k += 1;
        keep[k - 1]
    });
    merged
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Material, Polygon};
    use glam::{vec3, Vec3};

    fn scene_of(faces: &[(&[Vec3], u32)]) -> Scene {
        let mut s = Scene {
            materials: vec![Material::default(), Material::default()],
            ..Scene::default()
        };
        for (f, m) in faces {
            let base = s.positions.len() as u32;
            s.positions.extend_from_slice(f);
            s.indices.extend(base..base + f.len() as u32);
            s.polygons.push(Polygon {
                first: s.indices.len() as u32 - f.len() as u32,
                len: f.len() as u32,
                material: *m,
                back_material: None,
            });
        }
        s
    }

    const Q: [Vec3; 4] = [
        vec3(0.0, 0.0, 0.0),
        vec3(1.0, 0.0, 0.0),
        vec3(1.0, 1.0, 0.0),
        vec3(0.0, 1.0, 0.0),
    ];

    #[test]
    fn opposite_winding_pair_becomes_one_two_sided_polygon() {
        // The twin starts at another vertex and runs the other way round, on its own vertices.
        let twin = [Q[2], Q[1], Q[0], Q[3]];
        let mut s = scene_of(&[(&Q, 0), (&twin, 1)]);
        let m = merge_coincident(&mut s);
        assert_eq!(
            m,
            Merged {
                two_sided: 1,
                repeated: 0
            }
        );
        assert_eq!(s.polygons.len(), 1);
        assert_eq!(s.polygons[0].material, 0);
        assert_eq!(s.polygons[0].back_material, Some(1));
        assert!(s.warnings.is_empty());
    }

    #[test]
    fn same_winding_repeats_are_kept_once_with_one_warning() {
        let shifted = [Q[1], Q[2], Q[3], Q[0]];
        let twin = [Q[3], Q[2], Q[1], Q[0]];
        let mut s = scene_of(&[(&Q, 0), (&shifted, 0), (&Q, 1), (&twin, 1), (&twin, 0)]);
        let m = merge_coincident(&mut s);
        assert_eq!(
            m,
            Merged {
                two_sided: 1,
                repeated: 3
            }
        );
        assert_eq!(s.polygons.len(), 1);
        assert_eq!(s.warnings.len(), 1, "{:?}", s.warnings);
        assert!(s.warnings[0].starts_with("3 polygon(s) repeated"));
    }

    #[test]
    fn neighbours_sharing_an_edge_are_not_coincident() {
        let next = [Q[1], vec3(2.0, 0.0, 0.0), vec3(2.0, 1.0, 0.0), Q[2]];
        let tri = [Q[0], Q[1], Q[2]];
        let mut s = scene_of(&[(&Q, 0), (&next, 0), (&tri, 0)]);
        assert_eq!(merge_coincident(&mut s), Merged::default());
        assert_eq!(s.polygons.len(), 3);
    }
}
