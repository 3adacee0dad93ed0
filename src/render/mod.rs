//! Display of a radiosity solution: camera, CPU rasterizer and tone mapping; [`gather`] (the
//! final-gather renderer, `--shading gather`: each pixel gathers its light with rays, the
//! solution as the cache of the indirect light), [`false_colour`] (irradiance on a log scale
//! with a legend) and [`glyphs`] (the legend's digits) beside it.
//!
//! The paper shows its solutions the classic way: radiosity is averaged to the patch vertices
//! and Gouraud-interpolated across each patch. [`render_linear`] does exactly that in software:
//! perspective or parallel projection ([`Camera`], Radiance's view conventions; a view can be
//! read from a Radiance view file by [`view_file`]), near-, far- and guard-band clipping in view
//! space, back-face culling by each patch's front normal, a Z-buffer on 1/z (−z for a parallel
//! view), perspective-correct interpolation of the vertex colours, and s×s supersampling
//! box-filtered down to the output size. [`tone_map`] turns
//! the linear W/m² image into 8-bit sRGB, by a given exposure or one picked from a high
//! percentile of the image's luminance.
//!
//! Back faces are culled because architectural models are closed rooms: a camera outside the
//! building then sees through the near walls into the rooms, as a cut-away.
//!
//! Parallelism: the screen is cut into bands of output rows; triangles are binned by band and
//! each band is rasterized and filtered by one rayon task into its own slice of the image, so no
//! two tasks write the same memory and the result does not depend on scheduling.
//! Rasterization is watertight: each shared edge is evaluated with its endpoints in a canonical
//! order and clipped from its inside endpoint, so neighbouring triangles leave no cracks.

mod camera;
pub mod default_view;
pub mod false_colour;
pub mod gather;
pub mod glyphs;
mod raster;
mod tone;
pub mod view;
pub mod view_file;

pub use camera::{Camera, CameraFrame, Projection};
pub use gather::{render_gather, Shading, ShadingSettings};
pub use tone::{auto_exposure, srgb_encode, tone_map};
pub use view::{CameraSpec, ViewSettings};

use crate::mesh::Mesh;
use glam::Vec3;
use raster::{draw_bands, screen_triangles, View};

/// Output size and quality of [`render_linear`].
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct RenderOptions {
    pub width: u32,
    pub height: u32,
    /// Samples per pixel along each axis (0 is taken as 1, values above 16 as 16).
    pub supersample: u32,
    /// Exposure for tone mapping; `None` = automatic (see [`tone_map`]).
    pub exposure: Option<f32>,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            width: view::DEFAULT_WIDTH,
            height: view::DEFAULT_HEIGHT,
            supersample: view::DEFAULT_SUPERSAMPLE,
            exposure: None,
        }
    }
}

/// Linear radiosity image (W/m² per channel), row-major, width*height, background black (the
/// `.hdr`/`.exr` writers of [`crate::export::image`] store it as radiance, B/π).
#[derive(Clone, Debug, PartialEq)]
pub struct LinearImage {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[f32; 3]>,
}

/// Renders `mesh` with per-vertex radiosity `vertex_rgb` (one entry per `mesh.vertices` element,
/// linear W/m²) into a linear image. Non-finite colours and missing entries count as 0; patches
/// with out-of-range indices or non-finite vertices are skipped. A zero width or height gives an
/// image without pixels.
pub fn render_linear(
    mesh: &Mesh,
    vertex_rgb: &[[f32; 3]],
    camera: &Camera,
    opts: &RenderOptions,
) -> LinearImage {
    let (width, height) = (opts.width as usize, opts.height as usize);
    let mut pixels = vec![[0.0f32; 3]; width.saturating_mul(height)];
    if pixels.is_empty() {
        return LinearImage {
            width: opts.width,
            height: opts.height,
            pixels,
        };
    }
    let s = opts.supersample.clamp(1, 16) as usize;
    let view = View::new(camera, width * s, height * s);
    // A perspective view divides by depth, so it keeps a near plane in front of the eye; a
    // parallel one clips at the plane through the eye (Radiance's -vtl with -vo 0).
    let near = if camera.projection.is_parallel() {
        camera.near_distance()
    } else {
        camera.near_distance().max(near_plane(mesh))
    };
    let planes = view.planes(near, camera.far_distance());
    let tris = screen_triangles(mesh, vertex_rgb, &view, &planes);
    draw_bands(&tris, &mut pixels, width, height, s);
    LinearImage {
        width: opts.width,
        height: opts.height,
        pixels,
    }
}

/// The least near plane's distance of a perspective view, relative to the size of the mesh's finite vertices: depth is
/// tested on 1/z, which keeps its relative precision at any distance, so a small near plane
/// costs nothing.
fn near_plane(mesh: &Mesh) -> f32 {
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for v in mesh.vertices.iter().filter(|v| v.is_finite()) {
        lo = lo.min(*v);
        hi = hi.max(*v);
    }
    let diag = (hi - lo).length();
    if diag.is_finite() && diag > 0.0 {
        (1e-5 * diag).max(1e-7)
    } else {
        1e-4
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{Patch, PatchClass, Side};

    /// One patch per quad (corners counter-clockwise seen from the front), unwelded vertices.
    fn quads(qs: &[([Vec3; 4], [[f32; 3]; 4])]) -> (Mesh, Vec<[f32; 3]>) {
        let mut mesh = Mesh::default();
        let mut rgb = Vec::new();
        for (corners, colours) in qs {
            let first = mesh.patch_vertices.len() as u32;
            let n = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
            for (p, c) in corners.iter().zip(colours) {
                mesh.patch_vertices.push(mesh.vertices.len() as u32);
                mesh.vertices.push(*p);
                rgb.push(*c);
            }
            mesh.patches.push(Patch {
                first,
                count: 4,
                material: 0,
                polygon: 0,
                area: f64::from(n.length()),
                centre: corners.iter().sum::<Vec3>() / 4.0,
                normal: n.normalize(),
                class: PatchClass::Skew,
                side: Side::One,
            });
        }
        (mesh, rgb)
    }

    /// A quad in the plane z = `z`, facing +z, spanning [-h, h]².
    fn z_quad(z: f32, h: f32) -> [Vec3; 4] {
        [
            Vec3::new(-h, -h, z),
            Vec3::new(h, -h, z),
            Vec3::new(h, h, z),
            Vec3::new(-h, h, z),
        ]
    }

    /// Looking along -z from (0, 0, d) at fov 40°, where the view at z = 0 spans [-1, 1] (square
    /// image).
    fn head_on() -> Camera {
        let d = 1.0 / 20f32.to_radians().tan();
        Camera::perspective(Vec3::new(0.0, 0.0, d), Vec3::ZERO, Vec3::Y, 40.0, 1.0)
    }

    fn opts(w: u32, h: u32, s: u32) -> RenderOptions {
        RenderOptions {
            width: w,
            height: h,
            supersample: s,
            exposure: None,
        }
    }

    #[test]
    fn uniform_quad_renders_its_colour_and_tone_maps_to_srgb() {
        let c = [0.05, 0.3, 0.8];
        let (mesh, rgb) = quads(&[(z_quad(0.0, 2.0), [c; 4])]);
        let img = render_linear(&mesh, &rgb, &head_on(), &opts(40, 30, 3));
        assert_eq!(img.pixels.len(), 40 * 30);
        for p in &img.pixels {
            for k in 0..3 {
                // Perspective division and barycentric normalisation cost a few f32 ulps.
                assert!((p[k] - c[k]).abs() < 1e-5, "{p:?} vs {c:?}");
            }
        }
        let (srgb, e) = tone_map(&img, Some(1.0));
        assert_eq!(e, 1.0);
        // sRGB(0.05, 0.3, 0.8) × 255 = (63.19, 148.88, 231.11), computed independently.
        for p in srgb.pixels() {
            assert_eq!(p.0, [63, 149, 231]);
        }
    }

    #[test]
    fn quad_seen_from_behind_is_culled() {
        let (mesh, rgb) = quads(&[(z_quad(0.0, 2.0), [[1.0; 3]; 4])]);
        let mut cam = head_on();
        cam.eye.z = -cam.eye.z;
        let img = render_linear(&mesh, &rgb, &cam, &opts(32, 32, 2));
        assert!(img.pixels.iter().all(|p| *p == [0.0; 3]));
        // The same from the front is drawn: the test can fail.
        let img = render_linear(&mesh, &rgb, &head_on(), &opts(32, 32, 2));
        assert!(img.pixels.iter().all(|p| p[0] > 0.99));
    }

    #[test]
    fn gouraud_gives_a_linear_ramp_along_x() {
        // Colour 0 on the left edge (x = -2), 1 on the right (x = 2): B(x) = (x + 2) / 4.
        let (mesh, rgb) = quads(&[(z_quad(0.0, 2.0), [[0.0; 3], [1.0; 3], [1.0; 3], [0.0; 3]])]);
        let w = 64;
        let img = render_linear(&mesh, &rgb, &head_on(), &opts(w, w, 3));
        for col in [0, 10, 31, 32, 50, 63] {
            // Pixel centre at x = 2(col + 0.5)/w − 1 in the plane z = 0. The box filter averages
            // a linear function over samples placed symmetrically about the pixel centre, so it
            // returns the centre value; what is left is f32 rounding, far below 1e-4.
            let x = 2.0 * (col as f32 + 0.5) / w as f32 - 1.0;
            let expected = (x + 2.0) / 4.0;
            for row in [0, 20, 63] {
                let p = img.pixels[row * w as usize + col];
                assert!(
                    (p[1] - expected).abs() < 1e-4,
                    "col {col}: {} vs {expected}",
                    p[1]
                );
            }
        }
    }

    #[test]
    fn nearer_quad_wins_whatever_the_order() {
        let far = (z_quad(0.0, 2.0), [[1.0, 0.0, 0.0]; 4]);
        let near = (z_quad(0.5, 0.3), [[0.0, 1.0, 0.0]; 4]);
        for order in [[far, near], [near, far]] {
            let (mesh, rgb) = quads(&order);
            let img = render_linear(&mesh, &rgb, &head_on(), &opts(32, 32, 1));
            assert_eq!(img.pixels[16 * 32 + 16], [0.0, 1.0, 0.0]);
            assert_eq!(img.pixels[0], [1.0, 0.0, 0.0]);
        }
    }

    /// A floor at y = -1, facing up, x in [-1000, 1000], z from `z_far` to `z_near`, with colour
    /// `c(z)` at its edges; seen from the origin looking along -z.
    fn floor(z_far: f32, z_near: f32, c_far: f32, c_near: f32) -> (Mesh, Vec<[f32; 3]>, Camera) {
        let h = 1000.0;
        let (mesh, rgb) = quads(&[(
            [
                Vec3::new(-h, -1.0, z_near),
                Vec3::new(h, -1.0, z_near),
                Vec3::new(h, -1.0, z_far),
                Vec3::new(-h, -1.0, z_far),
            ],
            [[c_near; 3], [c_near; 3], [c_far; 3], [c_far; 3]],
        )]);
        let cam = Camera::perspective(Vec3::ZERO, Vec3::NEG_Z, Vec3::Y, 40.0, 1.0);
        (mesh, rgb, cam)
    }

    #[test]
    fn floor_crossing_the_near_plane_is_clipped() {
        // The floor reaches 50 m behind the eye. Its far edge (z = -1000) is 0.0028 of the
        // half-height below the image centre, above every sample of row 32 (the first below the
        // centre of 64 rows): rows 32.. are fully covered, rows ..32 empty.
        let (mesh, rgb, cam) = floor(-1000.0, 50.0, 0.5, 0.5);
        let img = render_linear(&mesh, &rgb, &cam, &opts(64, 64, 3));
        for (i, p) in img.pixels.iter().enumerate() {
            if i / 64 >= 32 {
                assert!((p[0] - 0.5).abs() < 1e-4, "pixel {i}: {p:?}");
            } else {
                assert_eq!(*p, [0.0; 3], "pixel {i}");
            }
        }
    }

    #[test]
    fn interpolation_is_perspective_correct_after_clipping() {
        // Colour 0 at z = 10 (behind the eye), 1 at z = -20: c(z) = (10 − z) / 30. The ray
        // through the centre of row r hits the floor at z = −1 / t, t = −ndc_y·tan 20°. One
        // sample per pixel, so the pixel is that ray's value; affine interpolation would be off
        // by > 0.1 here, f32 rounding is below 1e-3.
        let (mesh, rgb, cam) = floor(-20.0, 10.0, 1.0, 0.0);
        let img = render_linear(&mesh, &rgb, &cam, &opts(64, 64, 1));
        for row in [40usize, 50, 63] {
            let ndc_y = 1.0 - 2.0 * (row as f32 + 0.5) / 64.0;
            let t = -ndc_y * 20f32.to_radians().tan();
            let expected = (10.0 + 1.0 / t) / 30.0;
            let p = img.pixels[row * 64 + 20];
            assert!(
                (p[0] - expected).abs() < 1e-3,
                "row {row}: {} vs {expected}",
                p[0]
            );
        }
    }

    #[test]
    fn fitted_camera_sees_all_corners_of_a_unit_box() {
        let cam = Camera::fit(Vec3::ZERO, Vec3::ONE, 640.0 / 480.0);
        assert!(cam.eye.z > 1.0);
        assert!(
            matches!(cam.projection, Projection::Perspective { fov_y_deg, .. } if fov_y_deg == 40.0)
        );
        let view = View::new(&cam, 640, 480);
        let mut widest: f32 = 0.0;
        for i in 0..8 {
            let corner = Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, (i >> 2) as f32);
            let v = view.to_view(corner);
            assert!(v.z > 0.0);
            let [x, y] = view.to_screen(v);
            assert!(
                (0.0..=640.0).contains(&x) && (0.0..=480.0).contains(&y),
                "{x}, {y}"
            );
            widest = widest
                .max((x / 320.0 - 1.0).abs())
                .max((y / 240.0 - 1.0).abs());
        }
        // A snug fit: the outermost corner lies at 1/1.1 of the way to the border.
        assert!(widest > 0.85 && widest < 0.95, "{widest}");
    }

    #[test]
    fn auto_exposure_is_finite_positive_and_ignores_the_light() {
        let black = LinearImage {
            width: 4,
            height: 4,
            pixels: vec![[0.0; 3]; 16],
        };
        assert_eq!(tone_map(&black, None).1, 1.0);
        // 99 grey pixels at luminance 2 and one light a million times brighter: the 97th
        // percentile is a grey pixel, mapped to 0.9.
        let mut pixels = vec![[2.0f32; 3]; 100];
        pixels[7] = [2e6; 3];
        let img = LinearImage {
            width: 10,
            height: 10,
            pixels,
        };
        let (out, e) = tone_map(&img, None);
        assert!((e - 0.45).abs() < 1e-5, "{e}");
        assert_eq!(out.get_pixel(7, 0).0, [255; 3]);
        assert_eq!(
            out.get_pixel(0, 0).0[0],
            (srgb_encode(0.9) * 255.0).round() as u8
        );
    }

    #[test]
    fn degenerate_inputs_do_not_panic() {
        let (mut mesh, mut rgb) = quads(&[(z_quad(0.0, 2.0), [[1.0; 3]; 4])]);
        let o = opts(16, 16, 2);
        // Empty mesh, zero size, zero supersampling.
        let img = render_linear(&Mesh::default(), &[], &head_on(), &o);
        assert!(img.pixels.iter().all(|p| *p == [0.0; 3]));
        assert!(render_linear(&mesh, &rgb, &head_on(), &opts(0, 16, 3))
            .pixels
            .is_empty());
        assert_eq!(
            tone_map(
                &LinearImage {
                    width: 0,
                    height: 0,
                    pixels: vec![]
                },
                None
            )
            .1,
            1.0
        );
        assert_eq!(
            render_linear(&mesh, &rgb, &head_on(), &opts(4, 4, 0))
                .pixels
                .len(),
            16
        );
        // Degenerate cameras: eye == target, up parallel to the view, NaN everywhere.
        let mut cam = head_on();
        cam.target = cam.eye;
        render_linear(&mesh, &rgb, &cam, &o);
        let cam = Camera {
            up: Vec3::NEG_Z,
            ..head_on()
        };
        let img = render_linear(&mesh, &rgb, &cam, &o);
        assert!(
            img.pixels.iter().all(|p| p[0] > 0.99),
            "a fallback up still sees the quad"
        );
        let nan = Camera {
            eye: Vec3::NAN,
            target: Vec3::NAN,
            up: Vec3::NAN,
            projection: Projection::Perspective {
                fov_x_deg: f32::NAN,
                fov_y_deg: f32::NAN,
            },
            near: f32::NAN,
            far: Some(f32::NAN),
            shift: glam::Vec2::NAN,
        };
        render_linear(&mesh, &rgb, &nan, &o);
        let nan = Camera {
            projection: Projection::Parallel {
                width: f32::NAN,
                height: -1.0,
            },
            ..nan
        };
        render_linear(&mesh, &rgb, &nan, &o);
        // NaN colours count as 0, short colour lists and bad indices are tolerated.
        rgb[0] = [f32::NAN; 3];
        let img = render_linear(&mesh, &rgb, &head_on(), &o);
        assert!(img.pixels.iter().all(|p| p.iter().all(|c| c.is_finite())));
        render_linear(&mesh, &rgb[..2], &head_on(), &o);
        mesh.patch_vertices[3] = 99;
        mesh.patches.push(Patch {
            first: u32::MAX,
            ..mesh.patches[0]
        });
        render_linear(&mesh, &rgb, &head_on(), &o);
        let _ = Camera::fit(Vec3::INFINITY, Vec3::NEG_INFINITY, f32::NAN);
    }

    /// Cameras of every kind: perspective and parallel, shifted and lifted, clipped, aimed
    /// off the axes.
    fn cameras() -> Vec<Camera> {
        let base = Camera::perspective(
            Vec3::new(1.0, -2.0, 3.0),
            Vec3::new(4.0, 0.5, -1.0),
            Vec3::new(0.1, 1.0, 0.2),
            50.0,
            1.6,
        );
        vec![
            base,
            Camera {
                shift: glam::Vec2::new(0.3, -0.45),
                near: 0.7,
                ..base
            },
            Camera {
                projection: Projection::Parallel {
                    width: 6.0,
                    height: 2.5,
                },
                ..base
            },
            Camera {
                projection: Projection::Parallel {
                    width: 6.0,
                    height: 2.5,
                },
                shift: glam::Vec2::new(-0.2, 1.5),
                near: 2.0,
                ..base
            },
        ]
    }

    #[test]
    fn camera_rays_and_the_rasterizer_projection_agree() {
        let (w, h) = (320usize, 200usize);
        for cam in cameras() {
            let view = View::new(&cam, w, h);
            for (u, v) in [
                (0.5, 0.5),
                (0.0, 0.0),
                (1.0, 1.0),
                (0.13, 0.87),
                (0.91, 0.07),
            ] {
                let (o, d) = cam.ray(u, v);
                assert!((d.length() - 1.0).abs() < 1e-5);
                // The origin lies on the fore clipping plane.
                let f = cam.frame();
                assert!(
                    ((o - cam.eye).dot(f.fwd) - cam.near).abs() < 1e-4,
                    "{cam:?}"
                );
                for t in [0.5f32, 3.0, 40.0] {
                    let p = o + t * d;
                    let (uv, z) = cam.project(p).unwrap();
                    assert!(
                        (uv.x - u).abs() < 1e-4 && (uv.y - v).abs() < 1e-4,
                        "{uv} vs {u},{v}"
                    );
                    assert!(z > 0.0);
                    let [sx, sy] = view.to_screen(view.to_view(p));
                    assert!(
                        (sx / w as f32 - u).abs() < 1e-4 && (sy / h as f32 - v).abs() < 1e-4,
                        "rasterizer {sx},{sy} vs ray {u},{v} for {cam:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn a_speck_on_a_pixels_ray_lights_that_pixel_only() {
        let (w, h) = (40u32, 24u32);
        for cam in cameras() {
            for (col, row) in [(0u32, 0u32), (17, 9), (39, 23)] {
                let (u, v) = ((col as f32 + 0.5) / w as f32, (row as f32 + 0.5) / h as f32);
                let (o, d) = cam.ray(u, v);
                // A speck square to the ray, far smaller than the pixel's footprint, facing
                // the camera.
                let p = o + 6.0 * d;
                let f = cam.frame();
                let r = 0.002;
                let (a, b) = (f.right * r, f.up * r);
                let (mesh, rgb) =
                    quads(&[([p - a - b, p + a - b, p + a + b, p - a + b], [[1.0; 3]; 4])]);
                let img = render_linear(&mesh, &rgb, &cam, &opts(w, h, 1));
                for (k, px) in img.pixels.iter().enumerate() {
                    let lit = k == (row * w + col) as usize;
                    assert_eq!(px[0] > 0.5, lit, "pixel {k}, speck at {col},{row}, {cam:?}");
                }
            }
        }
    }

    #[test]
    fn perspective_fills_exactly_its_angles_of_view() {
        // -vh 90 -vv 53.13: tan 45° = 1, tan 26.57° = 0.5, so at distance 1 the view spans
        // x in [-1, 1], y in [-0.5, 0.5], a 2:1 picture.
        let fov_y = 2.0 * 0.5f32.atan().to_degrees();
        let cam = Camera {
            projection: Projection::Perspective {
                fov_x_deg: 90.0,
                fov_y_deg: fov_y,
            },
            ..Camera::perspective(Vec3::new(0.0, 0.0, 1.0), Vec3::ZERO, Vec3::Y, 1.0, 1.0)
        };
        assert!((cam.projection.aspect() - 2.0).abs() < 1e-5);
        let rect = |s: f32| {
            [
                Vec3::new(-s, -0.5 * s, 0.0),
                Vec3::new(s, -0.5 * s, 0.0),
                Vec3::new(s, 0.5 * s, 0.0),
                Vec3::new(-s, 0.5 * s, 0.0),
            ]
        };
        // Just bigger than the view: every pixel covered; just smaller: the border empty.
        let (mesh, rgb) = quads(&[(rect(1.001), [[1.0; 3]; 4])]);
        let img = render_linear(&mesh, &rgb, &cam, &opts(64, 32, 1));
        assert!(img.pixels.iter().all(|p| p[0] > 0.99));
        let (mesh, rgb) = quads(&[(rect(0.96), [[1.0; 3]; 4])]);
        let img = render_linear(&mesh, &rgb, &cam, &opts(64, 32, 1));
        for (k, p) in img.pixels.iter().enumerate() {
            let (c, r) = (k % 64, k / 64);
            let border = c == 0 || c == 63 || r == 0 || r == 31;
            assert_eq!(p[0] > 0.5, !border, "pixel {c},{r}");
        }
    }

    #[test]
    fn parallel_view_draws_sizes_independent_of_distance() {
        // A 4 × 2 parallel view from z = 5 down -z: the view spans x in [-2, 2], y in [-1, 1].
        let cam = Camera {
            projection: Projection::Parallel {
                width: 4.0,
                height: 2.0,
            },
            ..Camera::perspective(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 1.0, 1.0)
        };
        for z in [0.0, -100.0] {
            // A quad x in [-1, 1] covers the middle half of the columns at any distance.
            let (mesh, rgb) = quads(&[(z_quad(z, 1.0), [[1.0; 3]; 4])]);
            let img = render_linear(&mesh, &rgb, &cam, &opts(64, 32, 1));
            for (k, p) in img.pixels.iter().enumerate() {
                let c = k % 64;
                assert_eq!(p[0] > 0.5, (16..48).contains(&c), "z {z}: pixel {k}");
            }
        }
        // Depth still decides: the nearer quad wins in either order; what is behind the eye's
        // plane is not drawn.
        let far = (z_quad(-3.0, 3.0), [[1.0, 0.0, 0.0]; 4]);
        let near = (z_quad(1.0, 0.5), [[0.0, 1.0, 0.0]; 4]);
        let behind = (z_quad(6.0, 0.2), [[0.0, 0.0, 1.0]; 4]);
        for order in [[far, near, behind], [behind, near, far]] {
            let (mesh, rgb) = quads(&order);
            let img = render_linear(&mesh, &rgb, &cam, &opts(64, 32, 1));
            assert_eq!(img.pixels[16 * 64 + 32], [0.0, 1.0, 0.0]);
            assert_eq!(img.pixels[0], [1.0, 0.0, 0.0]);
        }
        // Back faces are culled by the view direction, not by the eye's position.
        let (mesh, rgb) = quads(&[(z_quad(-3.0, 3.0), [[1.0; 3]; 4])]);
        let back = Camera {
            eye: Vec3::new(0.0, 0.0, -5.0),
            target: Vec3::new(0.0, 0.0, -6.0),
            ..cam
        };
        let img = render_linear(&mesh, &rgb, &back, &opts(16, 8, 1));
        assert!(img.pixels.iter().all(|p| *p == [0.0; 3]));
    }

    #[test]
    fn near_clipping_sees_past_the_wall_in_front_of_the_eye() {
        // The eye 0.2 behind a wall's face (z = 0.1, facing it); the next room's far wall at
        // z = -3, large enough to fill the view.
        let wall = (z_quad(0.1, 50.0), [[1.0, 0.0, 0.0]; 4]);
        let far_wall = (z_quad(-3.0, 50.0), [[0.0, 1.0, 0.0]; 4]);
        let (mesh, rgb) = quads(&[wall, far_wall]);
        let mut cam = Camera::perspective(Vec3::new(0.0, 0.0, 0.3), Vec3::ZERO, Vec3::Y, 60.0, 1.5);
        let img = render_linear(&mesh, &rgb, &cam, &opts(30, 20, 2));
        assert!(img.pixels.iter().all(|p| *p == [1.0, 0.0, 0.0]), "the wall");
        cam.near = 0.25;
        let img = render_linear(&mesh, &rgb, &cam, &opts(30, 20, 2));
        assert!(
            img.pixels.iter().all(|p| *p == [0.0, 1.0, 0.0]),
            "past the wall"
        );
        // The aft plane: nothing beyond 2 is drawn.
        cam.far = Some(2.0);
        let img = render_linear(&mesh, &rgb, &cam, &opts(30, 20, 2));
        assert!(img.pixels.iter().all(|p| *p == [0.0; 3]), "beyond -va");
    }

    #[test]
    fn room_is_closed_seen_from_inside() {
        let (mesh, rgb) = crate::bench::timing::room(8);
        let cam = Camera::perspective(
            Vec3::new(2.0, 3.0, 4.0),
            Vec3::new(9.0, 7.0, 1.0),
            Vec3::Y,
            60.0,
            97.0 / 61.0,
        );
        // Every sample hits a wall: no background (crack) pixel anywhere.
        let img = render_linear(&mesh, &rgb, &cam, &opts(97, 61, 3));
        assert!(
            img.pixels.iter().all(|p| p[1] > 0.4999),
            "a crack let the background through"
        );
    }
}
