//! The point query, the crate's "light at a point" service: [`LightAt`] over a solved model
//! answers what a camera ray sees ([`LightAt::view`]), the radiosity leaving a side at some of
//! its points ([`LightAt::radiosity_at`], [`LightAt::part_at`]) and the irradiance at sensors
//! ([`LightAt::sensor_irradiance`]). The final-gather pictures (docs/design.md §10, after
//! Reichert, *A Two-Pass Radiosity Method Driven by Lights and Viewer Position*, MSc thesis,
//! Cornell 1992, and Lischinski, Tampieri & Greenberg, SIGGRAPH 1993), the adaptive
//! elements' corners (§11), relit solutions and the daylight grid (§9) all ask it.
//!
//! It is the solver's final gather applied to other points: the same light sampling, multiple
//! importance sampling, sky, sun, glazing and near-hit rule ([`super::NEAR`]), so shadows are
//! as sharp as the geometry makes them, not as the mesh does, and corners and narrow gaps are
//! not blotchy with the constant B of the patches beside them.

pub use super::gather::Vis;
use super::gather::{Ask, Spot};
use super::hemisphere::MAX_STEPS;
use super::{emission_and_reflectance, scalar, Kernel, LightParts, Rgb, Solved, NO_PATCH};
use crate::intersect::{Intersector, Ray};
use crate::mesh::Mesh;
use crate::random::{rng_for, Stream};
use crate::scene::Material;
use crate::sky::Sky;
use glam::Vec3;
use rand::Rng;
use rayon::prelude::*;
use std::borrow::Cow;
use std::sync::OnceLock;

/// The light at points of a solved model (see the module notes). Built once per image, grid or
/// refinement; shared by every thread.
pub struct LightAt<'a, I> {
    kernel: Kernel<'a, I>,
    /// Per patch, once asked: whether any emitter faces it ([`LightAt::radiosity_at`]).
    facing: Vec<OnceLock<bool>>,
}

/// What a ray from the camera met ([`LightAt::view`]).
#[derive(Clone, Copy, Debug)]
pub struct ViewHit {
    /// The side seen: the patch, or the back twin of a two-sided surface.
    pub patch: usize,
    /// Where the ray met it.
    pub point: Vec3,
}

/// What a camera ray sees: the first side that faces it (backs of one-sided patches are passed
/// through, as the Gouraud rasterizer culls them), the transmittance per channel of the glazing
/// before it (tinted glazing colours what is seen through it: docs/design.md §9) and what the
/// panes' sides reflect towards the camera (W/m², already weighed).
#[derive(Clone, Copy, Debug)]
pub struct ViewSeen {
    pub hit: Option<ViewHit>,
    pub through: Rgb,
    pub panes: Rgb,
    /// Rays cast.
    pub rays: u64,
}

/// What [`LightAt::part_told_at`] gathered: the value, the variance of the scalar ρ·H it
/// gathered (of its mean), the rays cast and what the rays told of the whole faces ([`Vis`];
/// nothing but for `DirectWhole`).
#[derive(Clone, Copy, Debug)]
pub struct PartAt {
    pub b: Rgb,
    pub var: f64,
    pub rays: u64,
    pub vis: Vis,
}

/// The lights of a relit solution (`radiosity relight`): each patch's emitted radiosity E
/// times its light's weight, and the weights of the sky and the sun.
#[derive(Clone, Debug, PartialEq)]
pub struct Relit {
    pub emission: Vec<[f64; 3]>,
    pub sky: f64,
    pub sun: f64,
}

impl<'a, I: Intersector> LightAt<'a, I> {
    /// The light of the solution `b` (W/m² per patch of `mesh`) through `isect` (built over
    /// `mesh`, whose sides say which patch a back hit goes to), lit by `sky` when it has one;
    /// with `relit`, by the re-weighted lights that made `b`, so that the direct light, the
    /// emitters seen and the B − E of the sides met all agree with it.
    pub fn new(
        mesh: &'a Mesh,
        materials: &[Material],
        isect: &'a I,
        b: &'a [[f64; 3]],
        sky: Option<&'a Sky>,
        relit: Option<Relit>,
    ) -> Self {
        let (own, rho) = emission_and_reflectance(mesh, materials);
        let (e, sky_weight, sun_weight) = match relit {
            Some(r) if r.emission.len() == mesh.patches.len() => (
                r.emission.into_iter().map(Rgb::from_array).collect(),
                r.sky,
                r.sun,
            ),
            _ => (own, 1.0, 1.0),
        };
        let sol = Solved {
            e: Cow::Owned(e),
            rho: Cow::Owned(rho),
            b,
            channels: &[],
            group: None,
        };
        let mut kernel = Kernel::new(mesh, materials, isect, sol, sky);
        kernel.sky.sky_weight = sky_weight;
        kernel.sky.sun_weight = sun_weight;
        LightAt::over(kernel)
    }

    /// The point query over `kernel`, no patch yet asked whether an emitter faces it.
    fn over(kernel: Kernel<'a, I>) -> Self {
        let facing = (0..kernel.mesh.patches.len())
            .map(|_| OnceLock::new())
            .collect();
        LightAt { kernel, facing }
    }

    /// The light of a daylight-coefficient solve ([`crate::sky::Sky::coefficients`]): `b` and
    /// its light `channels` (the ground's, then each sky patch's), for
    /// [`LightAt::sensor_coefficients`]. The gathers' own rays that leave the model count in
    /// no channel there: the sensors sample their direct view of each patch themselves.
    pub fn for_coefficients(
        mesh: &'a Mesh,
        materials: &[Material],
        isect: &'a I,
        b: &'a [[f64; 3]],
        channels: &'a [super::LightChannel],
        sky: &'a Sky,
    ) -> Self {
        let (e, rho) = emission_and_reflectance(mesh, materials);
        let sol = Solved {
            e: Cow::Owned(e),
            rho: Cow::Owned(rho),
            b,
            channels,
            group: None,
        };
        let mut kernel = Kernel::new(mesh, materials, isect, sol, Some(sky));
        kernel.sky.first_escapes = false;
        LightAt::over(kernel)
    }

    /// The daylight coefficients of sensors `(point, facing)`
    /// ([`super::coefficients`]): a gather of `rays` rays each over the solution's channels,
    /// and `rays_per_patch` rays at each sky patch (and ground patch) the sensor faces; sensor k
    /// draws from (seed, [`Stream::Sensors`], k). Built by [`LightAt::for_coefficients`].
    pub fn sensor_coefficients(
        &self,
        sensors: &[(Vec3, Vec3)],
        rays: usize,
        rays_per_patch: usize,
        seed: u64,
    ) -> Vec<super::coefficients::SensorCoefficients> {
        self.kernel
            .sensor_coefficients(sensors, rays, rays_per_patch, seed)
    }

    /// The direct sun at each sensor for each direction of `dirs` ([`super::coefficients`]):
    /// cos θ × the glazing's `luma`-weighted transmittance, 0 in shadow; rows by direction.
    pub fn sun_view(&self, sensors: &[(Vec3, Vec3)], dirs: &[Vec3], luma: Rgb) -> Vec<f32> {
        self.kernel.sun_view(sensors, dirs, luma)
    }

    /// Whether some emitter could light `patch`: the emitters' own test, a cluster with a
    /// part in front of the patch's plane while the patch is not wholly behind it
    /// (`Emitters::draw_for`). When none can — a ceiling beside its flush lamps — light samples
    /// could only miss, so the gather's rays all go over the hemisphere instead: half the noise
    /// variance where the picture is lit indirectly alone.
    fn lit_by_an_emitter(&self, patch: usize) -> bool {
        let k = &self.kernel;
        k.emitters.draw_for(&k.patch_receiver(patch)).is_some()
    }

    /// What the ray from `org` along `dir` sees. The backs of one-sided patches are passed
    /// through (a camera outside a closed room sees into it, as in the Gouraud image); glazing
    /// is seen and seen through as by the gather's rays.
    pub fn view(&self, org: Vec3, dir: Vec3) -> ViewSeen {
        let k = &self.kernel;
        let mut ray = Ray {
            org,
            dir,
            tnear: 0.0,
            tfar: f32::INFINITY,
        };
        let mut out = ViewSeen {
            hit: None,
            through: Rgb::ONE,
            panes: Rgb::ZERO,
            rays: 0,
        };
        for _ in 0..MAX_STEPS {
            let seen = k.cast(NO_PATCH, ray, k.eps_floor);
            out.rays += 1;
            out.panes += out.through * seen.panes;
            out.through *= seen.through;
            let Some(h) = seen.hit else {
                return out;
            };
            if let Some(r) = k.mesh.receiver(h.patch, h.back) {
                out.hit = Some(ViewHit {
                    patch: r as usize,
                    point: org + dir * h.t,
                });
                return out;
            }
            ray.tnear = h.t + (h.t * 1e-5).max(k.eps_floor);
        }
        out.through = Rgb::ZERO;
        out
    }

    /// The radiosity B = E + ρ·H (RGB, W/m²) leaving `patch` at the points `points` (on it,
    /// seen through one pixel), H their mean irradiance gathered with about `rays` rays in
    /// all: half shadow rays to the emitters, a quarter to the sun when there is one, the rest
    /// cosine-weighted over the hemisphere (points, light samples and directions stratified
    /// together, so the points of one pixel share one stratified gather). Returns B and the
    /// rays cast. A side that reflects nothing is its emission alone, without a ray.
    pub fn radiosity_at<R: Rng>(
        &self,
        patch: usize,
        points: &[Vec3],
        rays: usize,
        rng: &mut R,
    ) -> (Rgb, u64) {
        let (b, _, rays) = self.part_at(patch, points, rays, LightParts::All, rng);
        (b, rays)
    }

    /// [`Self::radiosity_at`]'s `parts` of the light: `All` is B = E + ρ·H; `Direct` is
    /// E + ρ·H_direct (the emitters and the sun by shadow rays, all `rays` theirs); `Indirect`
    /// is ρ·H_indirect (the hemisphere, the emitters' light left out). `Direct` and `Indirect`
    /// add up to `All`'s B in expectation (`IndirectOnce` is `Indirect` with near hits
    /// followed one step, not three). Returns the value, the variance of the scalar ρ·H
    /// it gathered (of its mean; 0 where nothing was gathered) and the rays cast.
    pub fn part_at<R: Rng>(
        &self,
        patch: usize,
        points: &[Vec3],
        rays: usize,
        parts: LightParts,
        rng: &mut R,
    ) -> (Rgb, f64, u64) {
        let p = self.part_told_at(patch, points, (rays, parts), Vis::default(), rng);
        (p.b, p.var, p.rays)
    }

    /// [`Self::part_at`], the whole faces `known` as the points around said
    /// (`Ask::known`), with what its rays told of the whole faces
    /// (`DirectWhole`).
    pub fn part_told_at<R: Rng>(
        &self,
        patch: usize,
        points: &[Vec3],
        (rays, parts): (usize, LightParts),
        known: Vis,
        rng: &mut R,
    ) -> PartAt {
        let k = &self.kernel;
        let (e, rho) = (k.sol.e[patch], k.sol.rho[patch]);
        let e = if parts.direct() { e } else { Rgb::ZERO };
        if points.is_empty() || scalar(rho) <= 0.0 {
            return PartAt {
                b: e,
                var: 0.0,
                rays: 0,
                vis: Vis::default(),
            };
        }
        let m = points.len();
        let at = |u: f32, _: f32| points[((u * m as f32) as usize).min(m - 1)];
        let spot = Spot {
            patch,
            at: &at,
            n: k.mesh.patches[patch].normal,
            eps: k.eps_of(patch),
            rho,
        };
        let ask = Ask {
            rays: rays.max(2),
            lights: *self.facing[patch].get_or_init(|| self.lit_by_an_emitter(patch)),
            parts,
            known,
        };
        let g = k.gather_at(&spot, ask, rng);
        let b = (e + rho * g.h)
            .to_array()
            .map(|v| if v.is_finite() { v.max(0.0) } else { 0.0 });
        let var = if g.var.is_finite() { g.var } else { 0.0 };
        PartAt {
            b: Rgb::from_array(b),
            var,
            rays: g.rays,
            vis: g.vis,
        }
    }

    /// Irradiance (RGB, W/m²) at sensors (point, facing direction) from the solved radiosity
    /// (the daylight grid, docs/design.md §9): each sensor gathers as a patch does (light
    /// samples of the emitters and the sun, hemisphere rays that see the solution, the sky and
    /// through glazing, near hits followed), `rays` rays each (at least 4), sensor k drawing
    /// from (seed, [`Stream::Sensors`], k).
    pub fn sensor_irradiance(
        &self,
        sensors: &[(Vec3, Vec3)],
        rays: usize,
        seed: u64,
    ) -> Vec<[f64; 3]> {
        let k = &self.kernel;
        let rays = rays.max(4);
        sensors
            .par_iter()
            .enumerate()
            .map(|(i, &(x, n))| {
                let mut rng = rng_for(seed, Stream::Sensors, i as u64);
                let at = |_: f32, _: f32| x;
                let spot = Spot {
                    patch: NO_PATCH,
                    at: &at,
                    n: n.normalize_or_zero(),
                    eps: k.eps_floor,
                    rho: Rgb::ONE,
                };
                let ask = Ask {
                    rays,
                    lights: true,
                    parts: LightParts::All,
                    known: Default::default(),
                };
                k.gather_at(&spot, ask, &mut rng).h.to_array()
            })
            .collect()
    }

    /// What a camera ray that leaves the model sees: the sky's radiance as an exitance, π·L
    /// (the unit of B), black without a sky; the sun's disc is left out.
    pub fn sky_exitance(&self, dir: Vec3) -> Rgb {
        self.kernel.sky.exitance(dir)
    }

    /// What the light a ray brings from what it saw (`seen`, along `dir`) is worth as
    /// irradiance from a cosine-weighted direction: the B − E of the side it met or the sky's
    /// exitance where it left, through the glazing it passed, and the panes' own (RGB, W/m²;
    /// the mean over cosine-weighted rays is the irradiance from the solution and the sky).
    pub fn seen_light(&self, seen: &ViewSeen, dir: Vec3) -> Rgb {
        let k = &self.kernel;
        let far = match &seen.hit {
            Some(h) => k.sol.reflected(h.patch),
            None => k.sky.exitance(dir),
        };
        seen.panes + seen.through * far
    }

    /// The reflectance ρ of patch `patch` (RGB).
    pub fn reflectance(&self, patch: usize) -> Rgb {
        self.kernel.sol.rho[patch]
    }

    /// The mesh the light is gathered in.
    pub fn mesh(&self) -> &Mesh {
        self.kernel.mesh
    }
}
