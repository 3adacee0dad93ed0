//! The final-gather renderer (`--shading gather`, docs/design.md §10): each pixel's visible points
//! gather their light with rays, the radiosity solution serving as the cache of the indirect
//! light — the two-pass "radiosity as a cache" pictures of Reichert (*A Two-Pass Radiosity
//! Method Driven by Lights and Viewer Position*, MSc thesis, Cornell 1992) and Lischinski,
//! Tampieri & Greenberg (*Combining Hierarchical Radiosity and Discontinuity Meshing*,
//! SIGGRAPH 1993, Sec. 5).
//!
//! **Why.** The Gouraud image ([`super::render_linear`]) shows the solution as it is: one B per
//! patch, averaged to the vertices and interpolated. A shadow is then as sharp as the mesh — a
//! 0.5 m patch half in shadow is grey over its whole extent — and the light's edge bleeds
//! along every patch boundary. Here the mesh only supplies the light that has bounced:
//!
//! - **Visible point**: a ray through the pixel (the backs of one-sided patches passed through,
//!   as the rasterizer culls them; glazing seen and seen through).
//! - **Direct light** from each emitter and the sun, sampled explicitly with shadow rays *at
//!   that point* ([`LightAt::radiosity_at`], the solver's own light sampling and MIS): shadows
//!   as sharp as the geometry makes them, whatever the patch size.
//! - **Indirect light**: cosine-weighted rays that take the solved B − E of the side they meet,
//!   or follow it on when it is nearer than that side's size (the near-hit rule of the
//!   solver's gather, [`crate::light::NEAR`]), so corners are not blotchy.
//! - B = E + ρ·H per channel, in f64; an emitter seen shows its emission. Rays that leave the
//!   model see the sky (as an exitance π·L, the unit of B) when the solve had one, else black.
//!
//! **Anti-aliasing**: s×s jittered samples per pixel (`--supersample`, stratified over the
//! pixel). The samples that meet the same side are gathered together: their points share one
//! stratified gather of s²·`--pixel-rays` rays (points, light samples and hemisphere cells
//! paired in random order), which is less noisy than s² independent gathers of the same rays.
//!
//! **Indirect cache** (`--indirect-spacing`): the indirect part of the light is gathered at
//! the nodes of an `IndirectCache`, every few pixels, and interpolated between them over one
//! surface; the direct part stays per sample.
//!
//! **Deterministic for a seed**: a pixel's random numbers come from (seed,
//! [`Stream::Picture`], pixel index) alone; rows are shaded in parallel, each into its own
//! slice, so the image does not depend on the thread count or the scheduling.
//!
//! The image is the same linear radiosity (W/m² per channel) as the Gouraud path's, so
//! exposure, tone mapping and the image writers treat the two alike.

use super::{Camera, LinearImage, RenderOptions};
use crate::elements::refine::INSET;
use crate::intersect::Intersector;
use crate::light::{self, LightAt, LightParts, Rgb};
use crate::mesh::Mesh;
use crate::progress::Counter;
use crate::settings::Invalid;
use crate::solve::{rng_for, Stream};
use glam::Vec3;
use rand::Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// Rays gathered per anti-aliasing sample by default (`--pixel-rays`): with the default 3×3
/// samples, 144 per pixel (README, "Final-gather pictures", for the measurements behind it).
pub const DEFAULT_PIXEL_RAYS: usize = 16;

/// Default `--indirect-spacing`: pixels between the points where the indirect light is
/// gathered and interpolated from (0: at every sample).
pub const DEFAULT_INDIRECT_SPACING: usize = 4;

/// Most `--indirect-spacing`.
pub const MAX_INDIRECT_SPACING: usize = 64;

/// A node gathers this many times the hemisphere rays of one pixel's samples.
pub const NODE_GAIN: usize = 4;

/// A node whose gather's relative standard error exceeds this gathers more rays, up to
/// [`NODE_MORE`] times its first (as many as its measured variance says would bring it here).
pub const NODE_ERROR: f64 = 0.02;

/// At most this many times a node's first rays in all.
pub const NODE_MORE: usize = 4;

/// Most rays per sample `--pixel-rays` takes.
pub const MAX_PIXEL_RAYS: usize = 65_536;

/// How a picture is shaded (`--shading`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Shading {
    /// The solution's B per patch, averaged to the welded vertices and Gouraud-interpolated
    /// ([`super::render_linear`]): the fast preview, as the paper shows its images; the
    /// library's default and `solve`'s (its picture is a by-product of the solve).
    #[default]
    Gouraud,
    /// A final gather per pixel ([`render_gather`]): `render`'s and `relight`'s default.
    Gather,
}

/// `--shading gather|gouraud`, written out so that `--help` lists `gather` first and each
/// value's spelling is [`Shading::name`].
impl clap::ValueEnum for Shading {
    fn value_variants<'a>() -> &'a [Self] {
        &[Shading::Gather, Shading::Gouraud]
    }

    fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
        Some(clap::builder::PossibleValue::new(self.name()))
    }
}

impl Shading {
    /// The flag's spelling.
    pub fn name(self) -> &'static str {
        match self {
            Shading::Gouraud => "gouraud",
            Shading::Gather => "gather",
        }
    }
}

/// How a picture is shaded, and with how many rays.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ShadingSettings {
    pub shading: Shading,
    /// Rays gathered per anti-aliasing sample (`--pixel-rays`): half to the lights, a quarter
    /// to the sun when there is one, the rest over the hemisphere.
    pub rays: usize,
    /// Seed of the pixels' random numbers.
    pub seed: u64,
    /// Pixels between the nodes where the indirect light is gathered, to be interpolated
    /// between them over one surface (`--indirect-spacing`; 0: gathered at every sample).
    pub indirect_spacing: usize,
}

impl Default for ShadingSettings {
    fn default() -> Self {
        ShadingSettings {
            shading: Shading::default(),
            rays: DEFAULT_PIXEL_RAYS,
            seed: 1,
            indirect_spacing: DEFAULT_INDIRECT_SPACING,
        }
    }
}

impl ShadingSettings {
    /// Refuses a ray count the renderer cannot use (one line naming the flag).
    pub fn check(&self) -> Result<(), Invalid> {
        if !(1..=MAX_PIXEL_RAYS).contains(&self.rays) {
            return Invalid::err(format!(
                "--pixel-rays must be between 1 and {MAX_PIXEL_RAYS}, got {}",
                self.rays
            ));
        }
        if self.indirect_spacing > MAX_INDIRECT_SPACING {
            return Invalid::err(format!(
                "--indirect-spacing must be between 0 and {MAX_INDIRECT_SPACING} pixels, got {}",
                self.indirect_spacing
            ));
        }
        Ok(())
    }
}

/// What a gathered picture cost.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct GatherStats {
    /// Anti-aliasing samples (camera rays) in all.
    pub samples: u64,
    /// Rays cast in all: camera rays, shadow rays, hemisphere rays and near hits followed.
    pub rays: u64,
    /// Rays per pixel, on average.
    pub rays_per_pixel: f64,
    /// Wall-clock seconds.
    pub seconds: f64,
}

/// The primary ray through the image point (x, y), in pixels from the top left corner of a
/// `width`×`height` picture: [`Camera::ray`], the rasterizer's own projection (perspective or
/// parallel, shifted, from the fore clipping plane), so the gathered and the Gouraud pictures
/// of one camera line up pixel for pixel; `None` for a camera that is not finite.
fn primary_ray(camera: &Camera, x: f32, y: f32, width: f32, height: f32) -> Option<(Vec3, Vec3)> {
    let (org, dir) = camera.ray(x / width, y / height);
    (org.is_finite() && dir.is_finite() && dir != Vec3::ZERO).then_some((org, dir))
}

/// The samples of one pixel that met one side: its points and their weight per channel (the
/// glazing's transmittance before them, summed).
struct Group {
    patch: usize,
    points: Vec<Vec3>,
    weight: Rgb,
    /// The points whose indirect light no nodes interpolate, and their weight.
    alone: Vec<Vec3>,
    alone_weight: Rgb,
}

/// Where the light of a point seen on `patch` is gathered: moved [`INSET`] of the way towards
/// the patch's centre, so that a point seen in a room's edge (where float rounding may put it
/// a hair inside the wall beside it) casts no ray out of the room — at a node, such a ray
/// would darken the 8 pixels around it.
fn inset(mesh: &Mesh, patch: usize, point: Vec3) -> Vec3 {
    point + (mesh.patches[patch].centre - point) * INSET as f32
}

/// The indirect light gathered at one node of the image: ρ·H_indirect of the side seen
/// there, and which surface (polygon and facing) that side is.
#[derive(Clone, Copy)]
struct Node {
    polygon: u32,
    material: u32,
    normal: Vec3,
    point: Vec3,
    value: Rgb,
}

/// The picture's indirect cache: the indirect light at every `spacing`-th pixel corner (its
/// nodes, in rows of `cols`), interpolated between them over one surface.
struct IndirectCache {
    spacing: f32,
    cols: usize,
    rows: usize,
    at: Vec<Option<Node>>,
}

impl IndirectCache {
    /// Gathers the nodes of a `width`×`height` picture, `rays` hemisphere rays each; returns
    /// them and the rays cast.
    fn gather<I: Intersector>(
        light: &LightAt<I>,
        camera: &Camera,
        (width, height): (usize, usize),
        spacing: usize,
        rays: usize,
        seed: u64,
    ) -> (IndirectCache, u64) {
        let cols = width.div_ceil(spacing) + 1;
        let rows = height.div_ceil(spacing) + 1;
        let size = (width as f32, height as f32);
        let per_row: Vec<(Vec<Option<Node>>, u64)> = (0..rows)
            .into_par_iter()
            .map(|j| {
                let mut cast = 0;
                let row = (0..cols)
                    .map(|i| {
                        let index = (j * cols + i) as u64;
                        let at = ((i * spacing) as f32, (j * spacing) as f32);
                        Self::node(light, camera, at, size, rays, (seed, index), &mut cast)
                    })
                    .collect();
                (row, cast)
            })
            .collect();
        let cast = per_row.iter().map(|r| r.1).sum();
        let at = per_row.into_iter().flat_map(|r| r.0).collect();
        (
            IndirectCache {
                spacing: spacing as f32,
                cols,
                rows,
                at,
            },
            cast,
        )
    }

    /// The node at image point `(x, y)` of a picture of `size` pixels: what the camera ray
    /// there sees, and the indirect light gathered there with `rays` hemisphere rays (more
    /// where that is noisy), drawn from (seed, [`Stream::Picture`], 2⁶³ + `index`); `None`
    /// where the ray sees no side. Adds the rays cast to `cast`.
    fn node<I: Intersector>(
        light: &LightAt<I>,
        camera: &Camera,
        (x, y): (f32, f32),
        (fw, fh): (f32, f32),
        rays: usize,
        (seed, index): (u64, u64),
        cast: &mut u64,
    ) -> Option<Node> {
        let mesh = light.mesh();
        // A stream of its own: pixel indices stay far below 2^63.
        let mut rng = rng_for(seed, Stream::Picture, (1 << 63) | index);
        let (org, dir) = primary_ray(camera, x, y, fw, fh)?;
        let seen = light.view(org, dir);
        *cast += seen.rays;
        let h = seen.hit?;
        let x = inset(mesh, h.patch, h.point);
        let (mut value, var, n) =
            light.part_at(h.patch, &[x], rays, LightParts::Indirect, &mut rng);
        *cast += n;
        // A noisy node (daylight through a window: a bright patch of sky few hemisphere rays
        // find) gathers more, pooled by rays.
        let rel = var.sqrt() / light::scalar(value).max(f64::MIN_POSITIVE);
        let more = ((rel / NODE_ERROR).powi(2) - 1.0).min(NODE_MORE as f64 - 1.0);
        let extra = (more * rays as f64).round() as usize;
        if extra >= 2 {
            let (v, _, n) = light.part_at(h.patch, &[x], extra, LightParts::Indirect, &mut rng);
            *cast += n;
            let w = extra as f64 / (rays + extra) as f64;
            value = value * (1.0 - w) + v * w;
        }
        let p = &mesh.patches[h.patch];
        Some(Node {
            polygon: p.polygon,
            material: p.material,
            normal: p.normal,
            point: h.point,
            value,
        })
    }

    /// The indirect light at image point (x, y), the point `at` on `patch`, interpolated
    /// bilinearly from those of the four nodes around it that saw the sample's surface — the
    /// same material facing alike in the same plane (a polygon, or coplanar neighbours such
    /// as a ceiling's tiles) — their weights renormalised; `None` when none did (an object's
    /// edge seen against another): gathered there instead.
    fn interpolate(&self, mesh: &Mesh, patch: usize, at: Vec3, x: f32, y: f32) -> Option<Rgb> {
        let (gx, gy) = (x / self.spacing, y / self.spacing);
        let (i, j) = (gx.floor() as usize, gy.floor() as usize);
        if i + 1 >= self.cols || j + 1 >= self.rows {
            return None;
        }
        let (tx, ty) = (f64::from(gx - i as f32), f64::from(gy - j as f32));
        let p = &mesh.patches[patch];
        let (mut v, mut total) = (Rgb::ZERO, 0.0);
        for (di, dj, w) in [
            (0, 0, (1.0 - tx) * (1.0 - ty)),
            (1, 0, tx * (1.0 - ty)),
            (0, 1, (1.0 - tx) * ty),
            (1, 1, tx * ty),
        ] {
            let Some(n) = self.at[(j + dj) * self.cols + i + di] else {
                continue;
            };
            let same = n.polygon == p.polygon
                || (n.material == p.material && {
                    let d = n.point - at;
                    p.normal.dot(d).abs() <= 1e-3 * d.length() + 1e-6
                });
            if !same || n.normal.dot(p.normal) < 0.999 {
                continue;
            }
            // Never a zero weight for a node that counts (a sample exactly on a node line).
            let w = w + 1e-9;
            total += w;
            v += w * n.value;
        }
        (total > 0.0).then(|| v / total)
    }
}

/// What every pixel of one picture is shaded with: the light, the camera, the indirect cache
/// (with nodes), s×s samples per pixel and the rays of each.
struct Shader<'s, I> {
    light: &'s LightAt<'s, I>,
    camera: &'s Camera,
    cache: Option<&'s IndirectCache>,
    /// The picture's size in pixels, s, and the aft plane's distance when there is one.
    size: (f32, f32),
    s: usize,
    far: Option<f32>,
    /// Rays per sample, and the half of them the direct light takes with nodes.
    rays: usize,
    half: usize,
    seed: u64,
}

impl<I: Intersector> Shader<'_, I> {
    /// Pixel (x, y) of a picture `width` pixels wide: its linear radiosity and the rays cast.
    fn pixel(
        &self,
        (x, y): (usize, usize),
        width: usize,
        groups: &mut Vec<Group>,
    ) -> ([f32; 3], u64) {
        let index = (y * width + x) as u64;
        let mut rng = rng_for(self.seed, Stream::Picture, index);
        groups.clear();
        let (mut sum, mut cast) = self.samples((x, y), groups, &mut rng);
        cast += self.gather_groups(groups, &mut sum, &mut rng);
        let s = self.s;
        let px = sum.to_array().map(|v| {
            let v = (v / (s * s) as f64) as f32;
            if v.is_finite() {
                v.max(0.0)
            } else {
                0.0
            }
        });
        (px, cast)
    }

    /// The s×s jittered samples of pixel (x, y): what each sees (the panes, the sky, the
    /// indirect light the cache interpolates) summed, the sides they met in `groups`; and the
    /// rays cast.
    fn samples<R: Rng>(
        &self,
        (x, y): (usize, usize),
        groups: &mut Vec<Group>,
        rng: &mut R,
    ) -> (Rgb, u64) {
        let (s, (fw, fh)) = (self.s, self.size);
        let mesh = self.light.mesh();
        let (mut sum, mut cast) = (Rgb::ZERO, 0u64);
        for k in 0..s * s {
            let (a, b) = ((k % s) as f32, (k / s) as f32);
            let (ja, jb) = (rng.gen::<f32>(), rng.gen::<f32>());
            let fx = x as f32 + (a + ja) / s as f32;
            let fy = y as f32 + (b + jb) / s as f32;
            let Some((org, dir)) = primary_ray(self.camera, fx, fy, fw, fh) else {
                continue;
            };
            let seen = self.light.view(org, dir);
            cast += seen.rays;
            // Beyond the aft plane (`-va`) nothing is seen, the sky neither, as the Gouraud
            // picture and rpict draw it.
            let beyond = |f: f32| {
                seen.hit
                    .is_none_or(|h| self.camera.project(h.point).is_none_or(|(_, z)| z > f))
            };
            if self.far.is_some_and(beyond) {
                continue;
            }
            sum += Rgb::ONE * seen.panes;
            let Some(h) = seen.hit else {
                sum += seen.through * self.light.sky_exitance(dir);
                continue;
            };
            let at = match groups.iter().position(|g| g.patch == h.patch) {
                Some(at) => at,
                None => {
                    groups.push(Group {
                        patch: h.patch,
                        points: Vec::new(),
                        weight: Rgb::ZERO,
                        alone: Vec::new(),
                        alone_weight: Rgb::ZERO,
                    });
                    groups.len() - 1
                }
            };
            let g = &mut groups[at];
            let x = inset(mesh, h.patch, h.point);
            g.points.push(x);
            g.weight += seen.through;
            let ind = self
                .cache
                .and_then(|c| c.interpolate(mesh, h.patch, h.point, fx, fy));
            match ind {
                Some(v) => sum += seen.through * v,
                None => {
                    g.alone.push(x);
                    g.alone_weight += seen.through;
                }
            }
        }
        (sum, cast)
    }

    /// The light of the sides a pixel's samples met, gathered at their points and added to
    /// `sum` by their weights: all of it without nodes; with nodes, the direct part, and the
    /// indirect part of the points no nodes interpolate. Returns the rays cast.
    fn gather_groups<R: Rng>(&self, groups: &[Group], sum: &mut Rgb, rng: &mut R) -> u64 {
        let mut cast = 0;
        for g in groups {
            let n = g.points.len();
            if self.cache.is_none() {
                let (b, c) = self
                    .light
                    .radiosity_at(g.patch, &g.points, self.rays * n, rng);
                cast += c;
                *sum += g.weight * b;
                continue;
            }
            let (b, _, c) =
                self.light
                    .part_at(g.patch, &g.points, self.half * n, LightParts::Direct, rng);
            cast += c;
            *sum += g.weight * b;
            if !g.alone.is_empty() {
                let rays = self.half * g.alone.len();
                let (b, _, c) =
                    self.light
                        .part_at(g.patch, &g.alone, rays, LightParts::Indirect, rng);
                cast += c;
                *sum += g.alone_weight * b;
            }
        }
        cast
    }
}

/// Renders the view of `camera` by a final gather per pixel through `light` (see the module
/// notes): `opts.supersample`² jittered samples per pixel, `settings.rays` rays gathered per
/// sample, reproducible for `settings.seed`. `rows` moves on by one per finished row. A zero
/// width or height gives an image without pixels.
pub fn render_gather<I: Intersector>(
    light: &LightAt<I>,
    camera: &Camera,
    opts: &RenderOptions,
    settings: &ShadingSettings,
    rows: &Counter,
) -> (LinearImage, GatherStats) {
    let t0 = Instant::now();
    let (width, height) = (opts.width as usize, opts.height as usize);
    let mut pixels = vec![[0.0f32; 3]; width.saturating_mul(height)];
    let mut stats = GatherStats::default();
    let image = |pixels| LinearImage {
        width: opts.width,
        height: opts.height,
        pixels,
    };
    if pixels.is_empty() {
        return (image(pixels), stats);
    }
    let s = opts.supersample.clamp(1, 16) as usize;
    let rays = settings.rays.clamp(1, MAX_PIXEL_RAYS);
    // With nodes, half a sample's rays go to the lights at the sample and the hemisphere's
    // half is gathered at the nodes, NODE_GAIN pixels' worth each.
    let spacing = settings.indirect_spacing.min(MAX_INDIRECT_SPACING);
    let half = (rays / 2).max(1);
    let cache = (spacing > 0).then(|| {
        IndirectCache::gather(
            light,
            camera,
            (width, height),
            spacing,
            half * s * s * NODE_GAIN,
            settings.seed,
        )
    });
    let shader = Shader {
        light,
        camera,
        cache: cache.as_ref().map(|c| &c.0),
        size: (opts.width as f32, opts.height as f32),
        s,
        far: camera.far_distance(),
        rays,
        half,
        seed: settings.seed,
    };
    let counts: Vec<u64> = pixels
        .par_chunks_mut(width)
        .enumerate()
        .map(|(y, row)| {
            let mut groups: Vec<Group> = Vec::new();
            let mut cast = 0u64;
            for (x, px) in row.iter_mut().enumerate() {
                let (v, c) = shader.pixel((x, y), width, &mut groups);
                *px = v;
                cast += c;
            }
            rows.inc(1);
            cast
        })
        .collect();
    stats.samples = (width * height * s * s) as u64;
    stats.rays = counts.iter().sum::<u64>() + cache.as_ref().map_or(0, |n| n.1);
    stats.rays_per_pixel = stats.rays as f64 / (width * height) as f64;
    stats.seconds = t0.elapsed().as_secs_f64();
    (image(pixels), stats)
}
