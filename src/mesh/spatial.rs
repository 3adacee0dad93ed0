//! Patches in space order: by facing, then along the Morton curve of their centres in their
//! bounding box, so that a stretch of the order is a compact group of patches facing one way
//! (the emitters' tree, `crate::light::emitters`; the final gather's learning runs,
//! `crate::solve::final_gather`).

use super::Mesh;
use glam::Vec3;

/// The six axis facings, and 6 for any other.
pub fn facing_class(n: Vec3) -> u8 {
    let a = n.abs();
    let (axis, v) = if a.x >= a.y && a.x >= a.z {
        (0, n.x)
    } else if a.y >= a.z {
        (1, n.y)
    } else {
        (2, n.z)
    };
    if a.max_element() < 1.0 - 1e-4 {
        6
    } else {
        axis * 2 + u8::from(v < 0.0)
    }
}

/// Positions into `patches` (patch ids of `mesh`) sorted by facing ([`facing_class`]), then
/// along the Morton curve of the centres in their bounding box (10 bits an axis), then by
/// position.
pub fn space_order(mesh: &Mesh, patches: &[usize]) -> Vec<u32> {
    let mut order: Vec<u32> = (0..patches.len() as u32).collect();
    let centre = |e: u32| mesh.patches[patches[e as usize]].centre;
    let (lo, hi) = order.iter().fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(lo, hi), &e| (lo.min(centre(e)), hi.max(centre(e))),
    );
    let size = (hi - lo).max(Vec3::splat(1e-6));
    let key = |e: u32| {
        let q = ((centre(e) - lo) / size * 1023.0).clamp(Vec3::ZERO, Vec3::splat(1023.0));
        let m = morton(q.x as u32) | (morton(q.y as u32) << 1) | (morton(q.z as u32) << 2);
        (facing_class(mesh.patches[patches[e as usize]].normal), m, e)
    };
    order.sort_by_cached_key(|&e| key(e));
    order
}

/// The bits of a 10-bit `v` spread to every third bit.
fn morton(v: u32) -> u32 {
    let mut x = v & 0x3ff;
    x = (x | (x << 16)) & 0x0300_00ff;
    x = (x | (x << 8)) & 0x0300_f00f;
    x = (x | (x << 4)) & 0x030c_30c3;
    x = (x | (x << 2)) & 0x0924_9249;
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn morton_interleaves_bits() {
        assert_eq!(morton(0b1), 0b1);
        assert_eq!(morton(0b11), 0b1001);
        assert_eq!(morton(0x3ff), 0x0924_9249);
    }

    #[test]
    fn facings_are_classed_by_axis_and_sign() {
        assert_eq!(facing_class(Vec3::X), 0);
        assert_eq!(facing_class(-Vec3::Y), 3);
        assert_eq!(facing_class(Vec3::new(0.6, 0.8, 0.0)), 6);
    }
}
