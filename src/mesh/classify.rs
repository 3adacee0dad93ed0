//! Patch classes (Sec. 2): axial patches, lying in a plane x, y or z = const, go to the paper's
//! plane-merge intersector; skew ones elsewhere (docs/design.md §1, "Patches").

use super::{Axis, PatchClass};
use glam::Vec3;

/// Sec. 2: a patch is axial when it lies in a plane x, y or z = const (all its vertices share
/// that coordinate), so the plane-merge intersector can take it; otherwise skew.
pub(super) fn classify(pts: &[Vec3], n: Vec3) -> PatchClass {
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
