//! The random-number streams: every random number the tool draws comes from a generator
//! seeded by (seed, stream, chunk) only — a shot's chunk of rays, a gathered patch, a sensor, a
//! pixel — so results depend on the seed alone, never on the thread count or on which thread
//! draws (docs/design.md §6). [`Stream`] names what draws; [`rng_for`] makes the generator.

/// splitmix64: decorrelates (seed, shot, chunk) into independent RNG seeds (and a generated
/// building's rooms' seeds from their place, independent of the order they are written in).
pub(crate) fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The random-number streams: what draws, as the "shot number" [`rng_for`] mixes in. Shots
/// count up from 0; every other stream counts down from `u64::MAX`, so none meets a shot's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stream {
    /// Shot k of the shooting (also the light-facing probe of `solve::lights`, as shot 0).
    Shot(u64),
    /// The final gather's patches (`u64::MAX − 1`): round 0 of [`Stream::Regather`].
    Gather,
    /// The final gather's round k (`solve --error`, `solve::final_gather::Gathers::plan`):
    /// `u64::MAX − 1 − k·2³²`, far from every other stream.
    Regather(u64),
    /// The sky's and the sun's shots (`u64::MAX − 2`, `solve::sky_shots`).
    Sky,
    /// The sky's pilot rays, which measure the share of its flux the model receives
    /// (`u64::MAX − 3`, the value [`Stream::Sensors`] has too: they never mix).
    SkyPilot,
    /// The sensors' gathers (`--grid`, `u64::MAX − 3`).
    Sensors,
    /// The pictures' pixels and indirect nodes (`--shading gather`, `u64::MAX − 4`).
    Picture,
    /// The adaptive elements' corner gathers (`u64::MAX − 5`).
    Elements,
    /// The probes that find the hidden sides of surfaces (`u64::MAX − 6`,
    /// `intersect::hidden`).
    Hidden,
    /// The luminaires' shots (`u64::MAX − 7`, `solve::luminaire_shots`).
    Luminaires,
    /// The emitters' sight rays before a gather (`u64::MAX − 8`, `light::emitters`).
    Sight,
    /// The rays the first final gather adds to the patches its pilot gathered
    /// (`u64::MAX − 9`, `solve::final_gather`).
    TopUp,
}

/// Regather round k draws under `Stream::Gather`'s number less k times this.
const REGATHER_STRIDE: u64 = 1 << 32;

impl Stream {
    /// The stream's number, as [`rng_for`] mixes it in.
    pub fn id(self) -> u64 {
        match self {
            Stream::Shot(k) => k,
            Stream::Gather => u64::MAX - 1,
            Stream::Regather(k) => Stream::Gather.id().wrapping_sub(REGATHER_STRIDE * k),
            Stream::Sky => u64::MAX - 2,
            Stream::SkyPilot => u64::MAX - 3,
            Stream::Sensors => u64::MAX - 3,
            Stream::Picture => u64::MAX - 4,
            Stream::Elements => u64::MAX - 5,
            Stream::Hidden => u64::MAX - 6,
            Stream::Luminaires => u64::MAX - 7,
            Stream::Sight => u64::MAX - 8,
            Stream::TopUp => u64::MAX - 9,
        }
    }
}

/// The random numbers of one stream's chunk of samples (a shot's chunk, a gathered patch, a
/// pixel): a function of (seed, stream, chunk) only, so results do not depend on which thread
/// draws them.
pub fn rng_for(seed: u64, stream: Stream, chunk: u64) -> rand_pcg::Pcg64Mcg {
    use rand::SeedableRng;
    rand_pcg::Pcg64Mcg::seed_from_u64(mix(mix(mix(seed) ^ stream.id()) ^ chunk))
}

#[cfg(test)]
mod tests {
    use super::Stream;

    /// The streams' numbers are part of every result (they seed the random numbers): they
    /// must never change.
    #[test]
    fn the_streams_keep_their_numbers() {
        assert_eq!(Stream::Shot(7).id(), 7);
        assert_eq!(Stream::Gather.id(), u64::MAX - 1);
        assert_eq!(Stream::Regather(0).id(), Stream::Gather.id());
        assert_eq!(Stream::Regather(2).id(), u64::MAX - 1 - 2 * (1 << 32));
        assert_eq!(Stream::Sky.id(), u64::MAX - 2);
        assert_eq!(Stream::SkyPilot.id(), u64::MAX - 3);
        assert_eq!(Stream::Sensors.id(), u64::MAX - 3);
        assert_eq!(Stream::Picture.id(), u64::MAX - 4);
        assert_eq!(Stream::Elements.id(), u64::MAX - 5);
        assert_eq!(Stream::Hidden.id(), u64::MAX - 6);
        assert_eq!(Stream::Luminaires.id(), u64::MAX - 7);
        assert_eq!(Stream::Sight.id(), u64::MAX - 8);
        assert_eq!(Stream::TopUp.id(), u64::MAX - 9);
    }
}
