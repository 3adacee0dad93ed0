//! The sky cut into directional pieces, each a distant emitter a shooter can fire parallel
//! rays from: 145 Tregenza patches of sky, the same 145 mirrored for the ground, and the sun.
//!
//! A piece's radiance is constant over it: the cos-weighted mean ∫ L cos θ dω / ∫ cos θ dω of
//! the sky over the patch (θ from the zenith), so that Σ radiance × projected solid angle is
//! the unobstructed horizontal irradiance exactly, and a direction drawn uniformly within the
//! piece ([`SkyPiece::sample`]) delivers it without bias.
//!
//! The ground is the mirrored Tregenza table rather than fewer, larger pieces: the ground is
//! uniform so any cut carries its power exactly, but windows see it at grazing angles where
//! 12° bands keep the directions as fine as the sky's, one code path serves both, and with equal
//! energy per ray the extra pieces cost shots, not rays.

use super::compass::Compass;
use super::sun::Sun;
use super::tregenza::Band;
use glam::Vec3;

/// What a piece is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PieceKind {
    /// A Tregenza patch of the sky (upper hemisphere).
    Sky,
    /// A mirrored Tregenza patch of the ground glow (lower hemisphere).
    Ground,
    /// The solar disc.
    Sun,
}

/// The directions a piece covers.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Region {
    /// A Tregenza patch, local coordinates.
    Band(Band),
    /// The solar disc.
    Sun(Sun),
}

/// One distant emitter.
///
/// `dir` points **from the scene towards the piece** (as a gather's escaping ray would); its
/// light travels along −`dir` ([`SkyPiece::travel`]). Its power through a unit area facing it
/// is about radiance × solid angle; exactly, through a unit horizontal area, radiance ×
/// projected solid angle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SkyPiece {
    /// Unit vector from the scene towards the piece's centre, model coordinates. For a band, the
    /// middle azimuth at the middle cos θ; for a cap, the zenith (nadir); for the sun, its centre.
    pub dir: Vec3,
    /// Steradians.
    pub solid_angle: f64,
    /// ∫ |cos θ| dω over the piece, θ from the zenith: the weight that turns radiance into
    /// horizontal irradiance. Equals solid_angle × |cos θ(dir)| but for the two caps (there
    /// 0.27 % less) and the sun (5 × 10⁻⁶ less).
    pub projected_solid_angle: f64,
    /// The sky's cos-weighted mean radiance over the piece (module docs), W/sr/m² per RGB
    /// channel (white: equal channels).
    pub radiance: [f64; 3],
    pub kind: PieceKind,
    /// The Tregenza patch, 0–144 in `tregenza.cal`'s order minus one (sky and ground); 0 for
    /// the sun.
    pub index: usize,
    region: Region,
    compass: Compass,
}

impl SkyPiece {
    /// A sky or ground patch of radiance `radiance`.
    pub(crate) fn band(
        kind: PieceKind,
        index: usize,
        band: Band,
        radiance: f64,
        compass: Compass,
    ) -> SkyPiece {
        SkyPiece {
            dir: compass.to_world(band.centre()).as_vec3(),
            solid_angle: band.solid_angle(),
            projected_solid_angle: band.projected_solid_angle(),
            radiance: [radiance; 3],
            kind,
            index,
            region: Region::Band(band),
            compass,
        }
    }

    /// The solar disc.
    pub(crate) fn sun(sun: &Sun, compass: Compass) -> SkyPiece {
        SkyPiece {
            dir: sun.dir,
            solid_angle: Sun::solid_angle(),
            projected_solid_angle: sun.projected_solid_angle(),
            radiance: sun.radiance(),
            kind: PieceKind::Sun,
            index: 0,
            region: Region::Sun(*sun),
            compass,
        }
    }

    /// The direction the piece's light travels: −`dir`.
    pub fn travel(&self) -> Vec3 {
        -self.dir
    }

    /// A unit direction towards the piece (like `dir`) at (u, v) ∈ [0, 1]², uniform in solid
    /// angle over it; the map is continuous, so stratified (u, v) give stratified directions.
    pub fn sample(&self, u: f64, v: f64) -> Vec3 {
        match self.region {
            Region::Band(b) => self.compass.to_world(b.local_dir(u, v)).as_vec3(),
            Region::Sun(sun) => sun.sample(u, v),
        }
    }
}
