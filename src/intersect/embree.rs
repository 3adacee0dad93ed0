//! Closest-hit queries through Intel Embree 4 (docs/design.md §3).
//!
//! The only module allowed `unsafe`: it calls `embree4-sys` directly. `embree4-rs` 0.0.16 was
//! tried and dropped: it polls `rtcGetDeviceError` after every ray, hides the scene handle that
//! `rtcIntersect1` needs, and — measured here — its `intersect_1` is unsound against Embree
//! 4.3+: the library writes `instPrimID` (4 bytes, seen as 0xffffffff) past the end of the
//! `RTCRayHit` laid out from the 4.2 headers, i.e. past its stack variable. `RayHitSlack`
//! gives that write somewhere to land. Its `Device` cannot be used on its own either: the
//! handle is crate-private (so no scene of ours can be made on it), the type is `!Send`, and
//! `Device::try_new` hands `rtcNewDevice` a Rust `&str` that is not NUL-terminated.
//!
//! A piece cut into a regular grid of patches goes in whole, as its quad's two triangles
//! (`crate::mesh::grids`: the patch is found from the hit's coordinates); every other patch as
//! its fan triangles; `prims` maps Embree's primitive ids back (docs/design.md §3, "Grids").
//! The scene is built with `RTC_SCENE_FLAG_ROBUST` so rays do not slip through shared edges of a
//! closed room (measured: without it, a few rays per million escape a closed box).
#![allow(unsafe_code)]

use super::{Hit, Intersector, Ray};
use crate::mesh::grids::Cells;
use crate::mesh::Mesh;
use embree4_sys as sys;
use glam::Vec3;
use std::ffi::CString;

/// Why Embree could not be used.
#[derive(Debug, thiserror::Error)]
pub enum EmbreeError {
    #[error("Embree: could not create a device ({0:?})")]
    Device(sys::RTCError),
    #[error("Embree: {what} failed ({code:?})")]
    Call {
        what: &'static str,
        code: sys::RTCError,
    },
    #[error("Embree: the scene has {0} triangles, more than Embree's 32-bit ids hold")]
    TooLarge(usize),
}

/// A committed Embree scene over (a subset of) the mesh's patches: the pieces cut into regular
/// grids whole (`crate::mesh::grids`: two triangles each, the patch found from the hit's
/// coordinates), every other patch as its fan triangles.
pub struct EmbreeScene {
    device: sys::RTCDevice,
    scene: sys::RTCScene,
    /// Per triangle: its patch, or its grid's layout as its half of the grid's quad reads it.
    prims: Vec<Cells>,
    /// How many grids went in whole.
    grids: usize,
}

// Embree documents committed scenes as safe to query from any number of threads at once, and
// nothing here mutates the scene after `build`.
unsafe impl Send for EmbreeScene {}
unsafe impl Sync for EmbreeScene {}

/// `RTCRayHit` followed by slack: Embree 4.3+ built with instance arrays appends
/// `instPrimID` to `RTCHit`, which the 4.2 headers `embree4-sys` was generated from lack.
#[repr(C, align(16))]
struct RayHitSlack {
    rh: sys::RTCRayHit,
    _slack: [u32; 8],
}

fn check(device: sys::RTCDevice, what: &'static str) -> Result<(), EmbreeError> {
    let code = unsafe { sys::rtcGetDeviceError(device) };
    if code == sys::RTCError::NONE {
        Ok(())
    } else {
        Err(EmbreeError::Call { what, code })
    }
}

/// Sets flush-to-zero and denormals-are-zero in the calling thread's MXCSR. Embree asks for it
/// (it warns of a severe slowdown otherwise); call it in every thread that casts rays.
pub fn set_flush_denormals() {
    #[cfg(target_arch = "x86_64")]
    #[allow(deprecated)]
    unsafe {
        use std::arch::x86_64::{_mm_getcsr, _mm_setcsr};
        // FTZ is bit 15, DAZ bit 6.
        _mm_setcsr(_mm_getcsr() | (1 << 15) | (1 << 6));
    }
}

impl EmbreeScene {
    /// Builds a scene from the surface patches (never a back twin, docs/design.md §7) for
    /// which `keep(patch index)` holds: a grid whose patches are all kept as its quad (two
    /// triangles), the others as their fan triangles.
    pub fn build(mesh: &Mesh, keep: impl Fn(usize) -> bool) -> Result<EmbreeScene, EmbreeError> {
        set_flush_denormals();
        let config = CString::new("verbose=0").expect("no NUL");
        let device = unsafe { sys::rtcNewDevice(config.as_ptr()) };
        if device.is_null() {
            return Err(EmbreeError::Device(unsafe {
                sys::rtcGetDeviceError(std::ptr::null_mut())
            }));
        }
        let mut me = EmbreeScene {
            device,
            scene: std::ptr::null_mut(),
            prims: Vec::new(),
            grids: 0,
        };
        let mut index: Vec<u32> = Vec::new();
        let mut in_grid = vec![false; mesh.patches.len()];
        for g in &mesh.grids {
            let r = g.patches();
            if r.end <= mesh.patches.len() && r.clone().all(|p| mesh.is_surface(p) && keep(p)) {
                in_grid[r].fill(true);
                // Two triangles, (0, 1, 3) and (2, 3, 1), as Embree splits a quad; a
                // triangle's grid only the first.
                let c = g.corners;
                index.extend_from_slice(&[c[0], c[1], c[3]]);
                me.prims.push(g.cells);
                if !g.is_triangle() {
                    index.extend_from_slice(&[c[2], c[3], c[1]]);
                    me.prims.push(g.second_half());
                }
                me.grids += 1;
            }
        }
        for (tri, patch) in mesh.surface_triangles() {
            if keep(patch as usize) && !in_grid[patch as usize] {
                index.extend_from_slice(&tri);
                me.prims.push(Cells::single(patch));
            }
        }
        if me.prims.len() >= u32::MAX as usize {
            return Err(EmbreeError::TooLarge(me.prims.len()));
        }
        unsafe {
            me.scene = sys::rtcNewScene(device);
            check(device, "rtcNewScene")?;
            sys::rtcSetSceneFlags(me.scene, sys::RTCSceneFlags::ROBUST);
            sys::rtcSetSceneBuildQuality(me.scene, sys::RTCBuildQuality::MEDIUM);
            if !me.prims.is_empty() {
                me.attach_triangles(&mesh.vertices, &index)?;
            }
            sys::rtcCommitScene(me.scene);
            check(device, "rtcCommitScene")?;
        }
        Ok(me)
    }

    /// Attaches the triangles `index` (vertex indices, three a triangle) over `vertices`.
    ///
    /// # Safety
    /// `self.scene` is a live, uncommitted scene of `self.device`.
    unsafe fn attach_triangles(&self, vertices: &[Vec3], index: &[u32]) -> Result<(), EmbreeError> {
        let device = self.device;
        let geom = sys::rtcNewGeometry(device, sys::RTCGeometryType::TRIANGLE);
        check(device, "rtcNewGeometry")?;
        let nv = vertices.len();
        // Embree reads vertex buffers 16 bytes at a time: one spare float at the end.
        let vb = sys::rtcSetNewGeometryBuffer(
            geom,
            sys::RTCBufferType::VERTEX,
            0,
            sys::RTCFormat::FLOAT3,
            12,
            nv + 1,
        ) as *mut f32;
        check(device, "vertex buffer")?;
        let vbs = std::slice::from_raw_parts_mut(vb, 3 * (nv + 1));
        for (k, v) in vertices.iter().enumerate() {
            vbs[3 * k..3 * k + 3].copy_from_slice(&v.to_array());
        }
        vbs[3 * nv..].fill(0.0);
        let ib = sys::rtcSetNewGeometryBuffer(
            geom,
            sys::RTCBufferType::INDEX,
            0,
            sys::RTCFormat::UINT3,
            12,
            index.len() / 3,
        ) as *mut u32;
        check(device, "index buffer")?;
        std::slice::from_raw_parts_mut(ib, index.len()).copy_from_slice(index);
        sys::rtcCommitGeometry(geom);
        sys::rtcAttachGeometry(self.scene, geom);
        sys::rtcReleaseGeometry(geom);
        check(device, "geometry")
    }

    /// Number of triangles in the scene: the patches' and the grids'.
    pub fn triangle_count(&self) -> usize {
        self.prims.len()
    }

    /// How many grids the scene takes whole.
    pub fn grid_count(&self) -> usize {
        self.grids
    }
}

impl Intersector for EmbreeScene {
    #[inline]
    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let mut rh = RayHitSlack {
            rh: sys::RTCRayHit {
                ray: sys::RTCRay {
                    org_x: ray.org.x,
                    org_y: ray.org.y,
                    org_z: ray.org.z,
                    tnear: ray.tnear,
                    dir_x: ray.dir.x,
                    dir_y: ray.dir.y,
                    dir_z: ray.dir.z,
                    time: 0.0,
                    tfar: ray.tfar,
                    mask: u32::MAX,
                    id: 0,
                    flags: 0,
                },
                hit: sys::RTCHit {
                    Ng_x: 0.0,
                    Ng_y: 0.0,
                    Ng_z: 0.0,
                    u: 0.0,
                    v: 0.0,
                    primID: sys::RTC_INVALID_GEOMETRY_ID,
                    geomID: sys::RTC_INVALID_GEOMETRY_ID,
                    instID: [sys::RTC_INVALID_GEOMETRY_ID],
                },
            },
            _slack: [0; 8],
        };
        // SAFETY: the scene is committed and alive for `self`'s lifetime; `rh` is a valid,
        // 16-byte aligned RTCRayHit with room for the fields newer Embree versions append.
        unsafe { sys::rtcIntersect1(self.scene, &mut rh.rh, std::ptr::null_mut()) };
        if rh.rh.hit.geomID == sys::RTC_INVALID_GEOMETRY_ID {
            return None;
        }
        let h = &rh.rh.hit;
        // Embree's geometric normal points like the counter-clockwise front normal (checked by
        // the tests below), so a back hit has Ng·dir > 0. Reading the side from Ng saves a
        // cache miss on the patch array per ray.
        let ng_dot_dir = h.Ng_x * ray.dir.x + h.Ng_y * ray.dir.y + h.Ng_z * ray.dir.z;
        let patch = self.prims[h.primID as usize].patch_at(h.u, h.v);
        Some(Hit {
            patch,
            t: rh.rh.ray.tfar,
            back: ng_dot_dir > 0.0,
        })
    }

    fn name(&self) -> &'static str {
        "embree"
    }
}

impl Drop for EmbreeScene {
    fn drop(&mut self) {
        unsafe {
            if !self.scene.is_null() {
                sys::rtcReleaseScene(self.scene);
            }
            sys::rtcReleaseDevice(self.device);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::intersect::brute::BruteForce;
    use crate::mesh::{Patch, PatchClass, Side};
    use glam::{vec3, Vec3};

    /// One unit quad in z = 0, counter-clockwise seen from +z (its front).
    fn quad_mesh() -> Mesh {
        Mesh {
            vertices: vec![
                vec3(0., 0., 0.),
                vec3(1., 0., 0.),
                vec3(1., 1., 0.),
                vec3(0., 1., 0.),
            ],
            patch_vertices: vec![0, 1, 2, 3],
            patches: vec![Patch {
                first: 0,
                count: 4,
                material: 0,
                polygon: 0,
                area: 1.0,
                centre: vec3(0.5, 0.5, 0.0),
                normal: Vec3::Z,
                class: PatchClass::Skew,
                side: Side::One,
            }],
            patch_size: 1.0,
            ..Mesh::default()
        }
    }

    #[test]
    fn hits_report_distance_and_side_like_the_oracle() {
        let m = quad_mesh();
        let e = EmbreeScene::build(&m, |_| true).unwrap();
        let b = BruteForce::new(&m);
        for (org, dir, back) in [
            (vec3(0.3, 0.6, 5.0), vec3(0., 0., -1.), false),
            (vec3(0.3, 0.6, -2.0), vec3(0., 0., 1.), true),
            (vec3(0.7, 0.2, 1.0), vec3(0.1, 0.1, -1.0).normalize(), false),
        ] {
            let ray = Ray {
                org,
                dir,
                tnear: 0.0,
                tfar: f32::INFINITY,
            };
            let he = e.intersect(&ray).unwrap();
            let hb = b.intersect(&ray).unwrap();
            assert_eq!(he.patch, 0);
            assert_eq!(he.back, back, "embree side for {org}");
            assert_eq!(hb.back, back, "oracle side for {org}");
            assert!((he.t - hb.t).abs() < 1e-5);
        }
        let miss = Ray {
            org: vec3(2., 2., 1.),
            dir: vec3(0., 0., -1.),
            tnear: 0.0,
            tfar: f32::INFINITY,
        };
        assert!(e.intersect(&miss).is_none());
        let short = Ray {
            org: vec3(0.5, 0.5, 1.),
            dir: vec3(0., 0., -1.),
            tnear: 0.0,
            tfar: 0.5,
        };
        assert!(e.intersect(&short).is_none(), "tfar bounds the search");
    }

    #[test]
    fn a_scene_with_no_patches_misses_everything() {
        let m = quad_mesh();
        let e = EmbreeScene::build(&m, |_| false).unwrap();
        assert_eq!(e.triangle_count(), 0);
        let ray = Ray {
            org: vec3(0.5, 0.5, 1.),
            dir: vec3(0., 0., -1.),
            tnear: 0.0,
            tfar: f32::INFINITY,
        };
        assert!(e.intersect(&ray).is_none());
    }
}
