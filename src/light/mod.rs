//! The light at a point: the light-transport kernel every per-point estimate shares — the
//! solver's final gather (`solve::final_gather`), the gathered pictures (`render::gather`),
//! the adaptive elements' corners (`elements`), relit and re-rendered saved solutions
//! (`saved`) and the daylight sensors (`--grid`). The radiosity solution is its cache of the
//! indirect light, as in two-pass methods (Chen, Rushmeier, Miller & Turner, *A Progressive
//! Multi-Pass Method for Global Illumination*, SIGGRAPH 1991, Sec. 4; Lischinski, Tampieri &
//! Greenberg, *Combining Hierarchical Radiosity and Discontinuity Meshing*, SIGGRAPH 1993).
//!
//! The irradiance H at a point x facing n ([`gather`]) is the sum of three estimates:
//!
//! - **Direct light** by sampling the emitters explicitly ([`emitters`], [`direct`]): an
//!   emitting patch j drawn with probability P_j — by an estimate of the irradiance its
//!   cluster of emitters gives the receiver, mixed with a share by power E_j·A_j (a CDF,
//!   stratified; none where no emitter can light the receiver; in the final gather weighed by
//!   which emitters the neighbouring patches gathered before it saw, `emitters::Learned`) — a
//!   point y uniform on it, a shadow ray from x. The ray must reach
//!   j's emitting side (a one-sided emitter emits from its front only; a back twin from the
//!   back of its surface, `Mesh::receiver`) with nothing before it; the sample is
//!   E_j·cosθ_i·cosθ_j/(π r²) / p(y), p(y) = P_j / A_j.
//! - **The sun** ([`sun`]): directions over its disc, shadow rays that must leave the model;
//!   rays that leave it otherwise see the sky's radiance (an exitance π·L, the unit of B).
//! - **Indirect light** by cosine-weighted rays ([`hemisphere`]; the stratified polar grid of
//!   the paper's Sec. 2, turned by a random angle) returning the solved B_k − E_k of the *side*
//!   they meet (`Mesh::receiver(hit, back)`; the back of a one-sided patch, or the void, gives
//!   0), through glazing (each pane passes on its transmittance T_c per channel and adds what
//!   its side reflects: docs/design.md §9). With cosine-weighted directions the irradiance is
//!   the plain mean of what the rays return.
//!
//! **Multiple importance sampling** (the power heuristic, Veach & Guibas 1995): a hemisphere
//! ray that meets an emitter's emitting side also counts its E at its MIS weight, and a light
//! sample counts at its own, so a point beside a big emitter (where 1/r² makes light samples
//! heavy-tailed) takes that light from its hemisphere rays, and a small bright lamp far away
//! from its light samples. Points (on a patch, or one pixel's) are stratified (Latin hypercube
//! over an area-preserving map of the unit square), paired with the cells or emitter draws in
//! random order; the variance of the mean is that of stratified samples (collapsed pairs).
//!
//! **Near hits** ([`NEAR`], [`NEAR_DEPTH`]): a hemisphere ray that meets a side closer than
//! that side's size does not take its B (constant over the patch: right seen from afar,
//! wrong from beside it — the 0.5 m wall patch behind a shelf 5 cm in front of it is lit on
//! its exposed part and dark behind the shelf). It takes the light at the point it met, from
//! one light sample and one cosine ray there, followed the same way through the gap. The
//! followed point's light sample comes from the gathering point's own cut of the emitters
//! mixed with a share by power ([`hemisphere::FOLLOWED_NEAR`]): the point lies within a patch's
//! size of it, in the same room.
//!
//! **The point query** ([`LightAt`]): what a camera ray sees, the radiosity B = E + ρ·H
//! leaving a side at some points of it (or its direct or indirect part, [`LightParts`]), the
//! irradiance at sensors. RGB triples are [`Rgb`] (f64 per channel) throughout.
//!
//! **Reproducible**: every estimate draws from the generator its caller gives it, seeded by
//! (seed, `solve::Stream`, item) — a patch, a sensor, a pixel, a polygon — so results do not
//! depend on the thread count.

pub mod coefficients;
pub mod direct;
pub mod emitters;
pub mod exact;
pub mod gather;
pub mod hemisphere;
pub mod light_at;
pub mod luminaires;
pub mod sun;

pub use gather::LightParts;
pub use hemisphere::{NEAR, NEAR_DEPTH};
pub use light_at::{LightAt, PartAt, Relit, ViewHit, ViewSeen, Vis};

use crate::mesh::Mesh;
use crate::scene::Material;
use crate::sky::Sky;
use emitters::Emitters;
use glam::Vec3;
use std::borrow::Cow;
use sun::SkyLight;

/// A radiometric triple: one value per colour channel (R, G, B), f64.
pub type Rgb = glam::DVec3;

/// One light group's radiosity per patch (W/m², RGB): a *light* channel (`--per-light`), as
/// opposed to the R, G, B colour channels every radiosity has.
#[derive(Clone, Debug, PartialEq)]
pub struct LightChannel {
    pub name: String,
    pub b: Vec<[f64; 3]>,
}

/// The per-light channel of the sky and its ground glow (`--per-light` with `--sky`).
pub const SKY_CHANNEL: &str = "(sky)";
/// The per-light channel of the sun.
pub const SUN_CHANNEL: &str = "(sun)";
/// Daylight coefficients ([`crate::sky::Sky::coefficients`]): the ground's channel, each sky
/// patch's following it in the patches' order ([`sky_patch_channel`]).
pub const GROUND_CHANNEL: &str = "(ground)";

/// The channel name of daylight-coefficient sky patch `k` (0-based): `(sky k+1)`, numbered as
/// the rows of Radiance's sky matrices, the ground being 0.
pub fn sky_patch_channel(k: usize) -> String {
    format!("(sky {})", k + 1)
}

/// The scalar the solver ranks and stops by: the mean of the three channels
/// (`solve::scalar`'s, in that order).
#[inline]
pub fn scalar(v: Rgb) -> f64 {
    (v.x + v.y + v.z) / 3.0
}

/// The "patch" a sensor's rays leave: none (a point in the air).
pub const NO_PATCH: usize = usize::MAX;

/// Where a light sample's ray leaves: the point `x` facing `n`, `eps` off the surface of
/// patch `patch` ([`NO_PATCH`] for a sensor in the air).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Origin {
    pub patch: usize,
    pub x: Vec3,
    pub n: Vec3,
    pub eps: f32,
}

/// The solution the kernel reads: emission, reflectance and radiosity per patch, and per light
/// channel.
pub(crate) struct Solved<'a> {
    /// Emitted radiosity and reflectance per patch: borrowed by the solver's gather, owned by a
    /// [`LightAt`] (which derives them from the materials itself).
    pub e: Cow<'a, [Rgb]>,
    pub rho: Cow<'a, [Rgb]>,
    /// The shooting's radiosity, and per light channel.
    pub b: &'a [[f64; 3]],
    pub channels: &'a [LightChannel],
    /// Light group per patch (`u32::MAX` for none), when there are channels.
    pub group: Option<&'a [u32]>,
}

impl Solved<'_> {
    /// What side `r` reflects: B_r − E_r, never below 0.
    fn reflected(&self, r: usize) -> Rgb {
        (Rgb::from_array(self.b[r]) - self.e[r]).max(Rgb::ZERO)
    }

    /// Whether patch `r` emits into light channel `c`.
    fn own(&self, r: usize, c: usize) -> bool {
        self.group.is_some_and(|g| g[r] as usize == c)
    }
}

/// Everything the kernel reads, shared by all threads: the mesh and its intersector, the
/// solution, the emitters, the sky and the glazing.
pub(crate) struct Kernel<'a, I> {
    pub mesh: &'a Mesh,
    pub isect: &'a I,
    pub sol: Solved<'a>,
    pub emitters: Emitters,
    pub sky: SkyLight<'a>,
    /// Straight-through transmittance per patch and channel T_c (glazing, tinted or grey:
    /// docs/design.md §9); empty when nothing transmits.
    pub glazing: Vec<Rgb>,
    /// The smallest offset off a surface, from the model's extent (f32 rounding).
    pub eps_floor: f32,
    /// Each luminaire's light channel (`--per-light`, by its group's name), if it has one.
    pub luminaire_channels: Vec<Option<usize>>,
    /// The luminaires' cumulative shares of their flux (`luminaires::flux_cdf`).
    pub luminaire_flux_cdf: Vec<f64>,
    /// This kernel among all made in the process (the key of `gather`'s per-thread draw of
    /// the last polygon gathered in parts).
    pub id: u64,
    /// Per polygon of the model, the centre and radius of its patches' bounding box (made
    /// when a gather in parts first asks: `Kernel::polygon_draw`).
    pub polygons: std::sync::OnceLock<Vec<(Vec3, f32)>>,
}

/// The next [`Kernel::id`].
static KERNELS: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

impl<'a, I> Kernel<'a, I> {
    /// The kernel over `mesh` and `isect` reading the solution `sol`, lit by `sky` when there
    /// is one (its light and its sun's at weight 1).
    pub fn new(
        mesh: &'a Mesh,
        materials: &[Material],
        isect: &'a I,
        sol: Solved<'a>,
        sky: Option<&'a Sky>,
    ) -> Self {
        let reach = mesh
            .vertices
            .iter()
            .fold(0.0f32, |m, v| m.max(v.abs().max_element()));
        let t = |p: &crate::mesh::Patch| {
            Rgb::from_array(materials[p.material as usize].transmittance_rgb())
        };
        let luminaire_channels = (mesh.luminaires.iter())
            .map(|l| sol.channels.iter().position(|c| c.name == l.group))
            .collect();
        Kernel {
            mesh,
            isect,
            emitters: Emitters::new(mesh, &sol.e),
            sky: SkyLight::new(sky, sol.channels),
            sol,
            glazing: if materials.iter().any(|m| m.transmittance > 0.0) {
                mesh.patches.iter().map(t).collect()
            } else {
                Vec::new()
            },
            eps_floor: reach * 5e-7,
            luminaire_channels,
            luminaire_flux_cdf: luminaires::flux_cdf(&mesh.luminaires),
            id: KERNELS.fetch_add(1, std::sync::atomic::Ordering::Relaxed),
            polygons: std::sync::OnceLock::new(),
        }
    }

    /// How far rays leave patch `i`'s surface: 10⁻⁴ of its size, at least the floor.
    pub fn eps_of(&self, i: usize) -> f32 {
        (1e-4 * (self.mesh.patches[i].area as f32).sqrt()).max(self.eps_floor)
    }
}

/// Each patch's emission E and reflectance ρ (RGB), from its material.
pub(crate) fn emission_and_reflectance(
    mesh: &Mesh,
    materials: &[Material],
) -> (Vec<Rgb>, Vec<Rgb>) {
    let mat = |p: &crate::mesh::Patch| &materials[p.material as usize];
    mesh.patches
        .iter()
        .map(|p| {
            (
                Rgb::from_array(mat(p).emission()),
                Rgb::from_array(mat(p).rho),
            )
        })
        .unzip()
}

/// Adds `w`·`v` per colour to light channel `c` of `ch`, when there is one (`w`: a weight per
/// colour, as tinted glazing's transmittance).
fn add_to(ch: &mut [Rgb], c: Option<usize>, v: Rgb, w: Rgb) {
    if let Some(x) = c.and_then(|c| ch.get_mut(c)) {
        *x += w * v;
    }
}
