//! Display of a radiosity solution: camera, CPU rasterizer and tone mapping; [`gather`] (the
//! final-gather renderer, `--shading gather`: each pixel gathers its light with rays, the
//! solution as the cache of the indirect light), [`false_colour`] (irradiance on a log scale
//! with a legend) and [`glyphs`] (the legend's digits) beside it.
//!
//! The paper shows its solutions the classic way: radiosity is averaged to the patch vertices
//! and Gouraud-interpolated across each patch. [`render_linear`] does exactly that in software:
//! perspective projection, near-plane (and guard-band) clipping in view space, back-face culling
//! by each patch's front normal, a Z-buffer on 1/z, perspective-correct interpolation of the
//! vertex colours, and s×s supersampling box-filtered down to the output size. [`tone_map`] turns
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
pub mod false_colour;
pub mod gather;
pub mod glyphs;
mod raster;
mod tone;
pub mod view;

pub use camera::Camera;
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

/// Linear radiosity image (W/m² per channel), row-major, width*height, background black.
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
    let planes = view.planes(near_plane(mesh));
    let tris = screen_triangles(mesh, vertex_rgb, &view, &planes);
    draw_bands(&tris, &mut pixels, width, height, s);
    LinearImage {
        width: opts.width,
        height: opts.height,
        pixels,
    }
}

/// The near plane's distance, relative to the size of the mesh's finite vertices: depth is
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
        Camera {
            eye: Vec3::new(0.0, 0.0, d),
            target: Vec3::ZERO,
            up: Vec3::Y,
            fov_y_deg: 40.0,
        }
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
        let cam = Camera {
            eye: Vec3::ZERO,
            target: Vec3::NEG_Z,
            up: Vec3::Y,
            fov_y_deg: 40.0,
        };
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
        assert!(cam.eye.z > 1.0 && cam.fov_y_deg == 40.0);
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
            fov_y_deg: f32::NAN,
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

    /// A closed box room of `n`×`n` quads per wall (2·6·n² triangles), normals inward.
    fn room(n: usize) -> (Mesh, Vec<[f32; 3]>) {
        let mut qs = Vec::new();
        let size = 10.0;
        for axis in 0..3 {
            for side in [0.0f32, 1.0] {
                for i in 0..n {
                    for j in 0..n {
                        let at = |u: usize, v: usize| {
                            let (u, v) = (u as f32 / n as f32 * size, v as f32 / n as f32 * size);
                            let mut p = [0.0; 3];
                            p[axis] = side * size;
                            p[(axis + 1) % 3] = u;
                            p[(axis + 2) % 3] = v;
                            Vec3::from_array(p)
                        };
                        let mut c = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
                        // Counter-clockwise seen from inside the room.
                        if side > 0.5 {
                            c.reverse();
                        }
                        let col = [(i * j % 7) as f32 / 7.0, 0.5, side];
                        qs.push((c, [col; 4]));
                    }
                }
            }
        }
        quads(&qs)
    }

    #[test]
    fn room_is_closed_seen_from_inside() {
        let (mesh, rgb) = room(8);
        let cam = Camera {
            eye: Vec3::new(2.0, 3.0, 4.0),
            target: Vec3::new(9.0, 7.0, 1.0),
            up: Vec3::Y,
            fov_y_deg: 60.0,
        };
        // Every sample hits a wall: no background (crack) pixel anywhere.
        let img = render_linear(&mesh, &rgb, &cam, &opts(97, 61, 3));
        assert!(
            img.pixels.iter().all(|p| p[1] > 0.4999),
            "a crack let the background through"
        );
    }

    #[test]
    #[ignore = "timing; run with --ignored --nocapture"]
    fn time_100k_triangles() {
        let (mesh, rgb) = room(91);
        let tris = 2 * mesh.patches.len();
        let inside = Camera {
            eye: Vec3::new(2.0, 3.0, 4.0),
            target: Vec3::new(9.0, 7.0, 1.0),
            up: Vec3::Y,
            fov_y_deg: 60.0,
        };
        let outside = Camera::fit(Vec3::ZERO, Vec3::splat(10.0), 640.0 / 480.0);
        for (name, cam) in [("inside", inside), ("fitted", outside)] {
            let t = std::time::Instant::now();
            let img = render_linear(&mesh, &rgb, &cam, &RenderOptions::default());
            let dt = t.elapsed();
            let t2 = std::time::Instant::now();
            tone_map(&img, None);
            println!(
                "{tris} triangles, 640x480x9, {name}: render {dt:?}, tone map {:?}",
                t2.elapsed()
            );
        }
    }
}
