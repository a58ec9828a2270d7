//! The public sampler: which generator, how many samples per pixel, which seed, and the
//! per-sample cursor over dimensions.

use std::fmt;
use std::str::FromStr;

use glam::Vec2;

use crate::error::SampleError;
use crate::hash::{Permutation, pixel_key};
use crate::sequences;

/// The largest number of samples per pixel: `2^24`, so that every stratum of every
/// generator still holds an `f32` and stratification survives rounding.
pub const MAX_SAMPLES_PER_PIXEL: u32 = 1 << 24;

/// The dimensions the Sobol sampler stratifies: the camera's five and, in the path
/// integrator's layout, its first two bounces' (up to eight each, with padding). Past them
/// [`SamplerKind::Sobol`] gives independent uniform values, one hash per pair of dimensions:
/// stratifying a path's later bounces measured no less error, at ten times the cost per pair.
pub const SOBOL_DIMENSIONS: u32 = 20;

/// Which values the samplers give: raised whenever some sampler's value for some (pixel,
/// sample index, dimension, seed) changes, as it did when Sobol's index shuffle changed and
/// when Sobol stopped stratifying past [`SOBOL_DIMENSIONS`]. Films from renders with other
/// values are unbiased but not the image this build renders, so the renderer's scene
/// fingerprint includes this number: checkpoints and slices from a build with other values
/// are refused rather than resumed or merged into an image that is not bit for bit the
/// one-process image.
pub const SEQUENCE_VERSION: u32 = 1;

/// The four sample generators of the scene format's `[sampler] type`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SamplerKind {
    /// `"independent"`: uniform random values, no stratification (PCG32 per sample).
    Independent,
    /// `"stratified"`: multi-jittered strata per pair of dimensions, pairs shuffled
    /// independently per pixel.
    Stratified,
    /// `"halton"`: the Halton sequence in prime bases with random digit permutations per
    /// pixel and dimension.
    Halton,
    /// `"sobol"`: padded 2D Sobol (0,2)-sequences with hash-based Owen scrambling for the
    /// first [`SOBOL_DIMENSIONS`], independent values after.
    Sobol,
}

impl SamplerKind {
    /// All kinds, in the order of the scene format.
    pub const ALL: [SamplerKind; 4] = [
        SamplerKind::Independent,
        SamplerKind::Stratified,
        SamplerKind::Halton,
        SamplerKind::Sobol,
    ];

    /// The name used in scene files: `"independent"`, `"stratified"`, `"halton"`, `"sobol"`.
    pub fn name(self) -> &'static str {
        match self {
            SamplerKind::Independent => "independent",
            SamplerKind::Stratified => "stratified",
            SamplerKind::Halton => "halton",
            SamplerKind::Sobol => "sobol",
        }
    }
}

impl fmt::Display for SamplerKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for SamplerKind {
    type Err = SampleError;

    /// Parses exactly the names of [`SamplerKind::name`] (lower case).
    fn from_str(name: &str) -> Result<SamplerKind, SampleError> {
        SamplerKind::ALL
            .into_iter()
            .find(|kind| kind.name() == name)
            .ok_or_else(|| SampleError::UnknownSampler {
                name: name.to_owned(),
            })
    }
}

/// A configured sampler: kind, samples per pixel and seed. Cheap to clone and to share
/// between threads; it holds no mutable state.
///
/// Every value is a pure function of (pixel, sample index, dimension, seed), so a render is
/// the same for any number of threads and any tile order. The kind and the samples per pixel
/// choose the function: a stratified or Sobol sample depends on the spp it belongs to.
/// Dimensions 0-1 are the film offset inside the pixel, 2-3 the lens, 4 the time; shading
/// takes 5 and up through [`SampleStream`]. Dimensions are generated in pairs `(2p, 2p + 1)`:
/// the stratified and Sobol samplers stratify each pair jointly, and every pair is
/// decorrelated from every other pair per pixel.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Sampler {
    kind: SamplerKind,
    samples_per_pixel: u32,
    seed: u64,
    grid: [u32; 2],
    /// Sobol's permutations of a pass's `samples_per_pixel` places, built once.
    sobol_places: Permutation,
}

impl Sampler {
    /// A sampler of `kind` with `samples_per_pixel` samples (1 to
    /// [`MAX_SAMPLES_PER_PIXEL`]) and `seed`.
    pub fn new(
        kind: SamplerKind,
        samples_per_pixel: u32,
        seed: u64,
    ) -> Result<Sampler, SampleError> {
        if samples_per_pixel == 0 {
            return Err(SampleError::ZeroSamplesPerPixel);
        }
        if samples_per_pixel > MAX_SAMPLES_PER_PIXEL {
            return Err(SampleError::TooManySamplesPerPixel {
                spp: samples_per_pixel,
                max: MAX_SAMPLES_PER_PIXEL,
            });
        }
        Ok(Sampler {
            kind,
            samples_per_pixel,
            seed,
            grid: sequences::stratified_grid(samples_per_pixel),
            sobol_places: Permutation::new(samples_per_pixel),
        })
    }

    /// Which generator this is.
    pub fn kind(&self) -> SamplerKind {
        self.kind
    }

    /// Samples per pixel.
    pub fn samples_per_pixel(&self) -> u32 {
        self.samples_per_pixel
    }

    /// The seed.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// The stratified sampler's 2D grid `[nx, ny]` per pair of dimensions: `nx * ny` equals
    /// the samples per pixel, `nx` is its largest divisor not above its square root.
    pub fn stratified_grid(&self) -> [u32; 2] {
        self.grid
    }

    /// The value of `dimension` of sample `index` of `pixel`, in `[0, 1)`.
    ///
    /// Pure function of (pixel, index, dimension, seed). Indices at or beyond
    /// [`Sampler::samples_per_pixel`] are valid: the stratified sampler starts a fresh,
    /// independently shuffled pattern every `samples_per_pixel` indices, Sobol shuffles each
    /// such block of its sequence afresh, and Halton simply continues.
    #[inline]
    pub fn value(&self, pixel: [u32; 2], index: u32, dimension: u32) -> f32 {
        self.value_keyed(self.key(pixel), index, dimension)
    }

    /// The per-pixel key the `*_keyed` functions take (Sobol's is tagged once here).
    #[inline]
    fn key(&self, pixel: [u32; 2]) -> u64 {
        let key = pixel_key(self.seed, pixel);
        match self.kind {
            SamplerKind::Sobol => sequences::sobol_key(key),
            _ => key,
        }
    }

    /// [`Sampler::value`] with the pixel's key from [`Sampler::key`].
    #[inline]
    fn value_keyed(&self, pixel_key: u64, index: u32, dimension: u32) -> f32 {
        match self.kind {
            SamplerKind::Independent => {
                sequences::independent(pixel_key, self.seed, index, dimension)
            }
            SamplerKind::Stratified => sequences::stratified(
                pixel_key,
                self.samples_per_pixel,
                self.grid,
                index,
                dimension,
            ),
            SamplerKind::Halton => sequences::halton(pixel_key, index, dimension),
            SamplerKind::Sobol => sequences::sobol(pixel_key, self.sobol_places, index, dimension),
        }
    }

    /// A cursor over the dimensions of sample `index` of `pixel`. No heap allocation.
    #[inline]
    pub fn stream(&self, pixel: [u32; 2], index: u32) -> SampleStream<'_> {
        SampleStream {
            sampler: self,
            pixel_key: self.key(pixel),
            index,
            sobol_index: sequences::SobolIndex::new(index, self.sobol_places),
            dimension: 0,
            sobol_last: None,
        }
    }
}

/// A cursor over the dimensions of one sample, from [`Sampler::stream`].
///
/// Layout: [`SampleStream::camera`] takes dimensions 0-4 (film 0-1, lens 2-3, time 4); then
/// [`SampleStream::next_1d`] takes the next dimension and [`SampleStream::next_2d`] the next
/// aligned pair `(2p, 2p + 1)`, skipping one dimension if the cursor is odd, so a 2D request
/// always gets a pair that the stratified and Sobol samplers stratify jointly. So after
/// `camera()`, `next_2d()` reads dimensions 6-7, while `next_1d()` would read 5.
#[derive(Debug, Clone)]
pub struct SampleStream<'a> {
    sampler: &'a Sampler,
    pixel_key: u64,
    index: u32,
    /// Where `index` sits in its block of samples, for Sobol's index shuffle of every pair.
    sobol_index: sequences::SobolIndex,
    dimension: u32,
    /// Sobol only: the shared part of the pair last read one dimension at a time, so reading
    /// its other dimension next costs one scramble (the values are the same either way).
    sobol_last: Option<sequences::SobolPair>,
}

impl SampleStream<'_> {
    /// The camera dimensions 0-4 as `(film, lens, time)`: the offset inside the pixel in
    /// `[0, 1)^2` (dimensions 0-1; the raster position is `pixel + film`), the lens sample in
    /// `[0, 1)^2` (dimensions 2-3, to be warped onto the aperture) and the normalised shutter
    /// time in `[0, 1)` (dimension 4, to be mapped by [`crate::shutter_time`]). Meant as the
    /// first call; called later it still returns dimensions 0-4 and moves the cursor to at
    /// least 5.
    #[inline]
    pub fn camera(&mut self) -> (Vec2, Vec2, f32) {
        self.camera_with(true, true)
    }

    /// [`SampleStream::camera`] for a camera that may not read every dimension: the lens pair
    /// is drawn only if `lens`, the time only if `time`; a dimension not drawn is the lens
    /// centre `(0.5, 0.5)` or time 0, as in a pinhole's sample. Dimensions that are drawn have
    /// the same values as from `camera()`, and so do the dimensions after, so skipping is
    /// invisible to a camera that ignores them (a pinhole's lens, an instantaneous shutter's
    /// time) and saves two of a pinhole sample's five draws.
    #[inline]
    pub fn camera_with(&mut self, lens: bool, time: bool) -> (Vec2, Vec2, f32) {
        let dims = (
            self.pair(0),
            if lens { self.pair(2) } else { Vec2::splat(0.5) },
            if time { self.one(4) } else { 0.0 },
        );
        self.dimension = self.dimension.max(5);
        dims
    }

    /// The next dimension, in `[0, 1)`.
    #[inline]
    pub fn next_1d(&mut self) -> f32 {
        let u = self.one(self.dimension);
        self.dimension = self.dimension.saturating_add(1);
        u
    }

    /// Moves past the next dimension without computing it: the dimensions after it are
    /// the same as after [`SampleStream::next_1d`]. For a decision with one outcome (a
    /// material with one lobe, a scene with one light), whose number nothing reads.
    #[inline]
    pub fn skip_1d(&mut self) {
        self.dimension = self.dimension.saturating_add(1);
    }

    /// Dimension `dimension` alone: [`Sampler::value`], reusing the Sobol pair's shared part
    /// when the previous single read was the same pair's other dimension.
    #[inline]
    fn one(&mut self, dimension: u32) -> f32 {
        if self.sampler.kind != SamplerKind::Sobol {
            return self
                .sampler
                .value_keyed(self.pixel_key, self.index, dimension);
        }
        let pair = dimension / 2;
        if pair >= sequences::SOBOL_PAIRS {
            return sequences::tail_pair(self.pixel_key, self.index, pair)
                [(dimension % 2) as usize];
        }
        let prepared = match self.sobol_last {
            Some(last) if last.pair == pair => last,
            _ => {
                let prepared = sequences::sobol_prepare(self.pixel_key, self.sobol_index, pair);
                self.sobol_last = Some(prepared);
                prepared
            }
        };
        sequences::sobol_coordinate(prepared, dimension % 2)
    }

    /// Dimensions `first` and `first + 1` (`first` even), as two [`Sampler::value`] calls
    /// would give them; Sobol computes its per-pair hashes once.
    #[inline]
    fn pair(&self, first: u32) -> Vec2 {
        let (sampler, key, index) = (self.sampler, self.pixel_key, self.index);
        match sampler.kind {
            SamplerKind::Sobol if first.is_multiple_of(2) => {
                Vec2::from(sequences::sobol_pair(key, self.sobol_index, first / 2))
            }
            _ => Vec2::new(
                sampler.value_keyed(key, index, first),
                sampler.value_keyed(key, index, first.saturating_add(1)),
            ),
        }
    }

    /// The value [`SampleStream::next_1d`] would return, without moving the cursor: for a
    /// caller that prepares for a decision before it makes it.
    #[inline]
    pub fn peek_1d(&self) -> f32 {
        self.sampler
            .value_keyed(self.pixel_key, self.index, self.dimension)
    }

    /// The pair [`SampleStream::next_2d`] would return after `skip` calls of
    /// [`SampleStream::skip_1d`], without moving the cursor.
    #[inline]
    pub fn peek_2d(&self, skip: u32) -> Vec2 {
        self.pair(pair_start(self.dimension.saturating_add(skip)))
    }

    /// The next aligned pair of dimensions, in `[0, 1)^2`.
    #[inline]
    pub fn next_2d(&mut self) -> Vec2 {
        let first = pair_start(self.dimension);
        let u2 = self.pair(first);
        self.dimension = first.saturating_add(2);
        u2
    }

    /// Moves past the pair [`SampleStream::next_2d`] would return without computing it (for a
    /// caller that peeked it): the dimensions after are the same as after `next_2d`.
    #[inline]
    pub fn skip_2d(&mut self) {
        self.dimension = pair_start(self.dimension).saturating_add(2);
    }

    /// The dimension the next [`SampleStream::next_1d`] will read.
    pub fn dimension(&self) -> u32 {
        self.dimension
    }

    /// The sample index this stream reads.
    pub fn index(&self) -> u32 {
        self.index
    }
}

/// The first dimension of the aligned pair a 2D read at cursor `dimension` takes: `dimension`
/// itself when even, the next one when odd.
#[inline]
fn pair_start(dimension: u32) -> u32 {
    dimension.saturating_add(dimension % 2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for kind in SamplerKind::ALL {
            assert_eq!(kind.name().parse::<SamplerKind>(), Ok(kind));
        }
        assert_eq!("sobol".parse::<SamplerKind>(), Ok(SamplerKind::Sobol));
        assert!(matches!(
            "Sobol".parse::<SamplerKind>(),
            Err(SampleError::UnknownSampler { name }) if name == "Sobol"
        ));
    }

    #[test]
    fn rejects_bad_sample_counts() {
        assert_eq!(
            Sampler::new(SamplerKind::Sobol, 0, 0),
            Err(SampleError::ZeroSamplesPerPixel)
        );
        assert!(Sampler::new(SamplerKind::Halton, MAX_SAMPLES_PER_PIXEL + 1, 0).is_err());
        assert!(Sampler::new(SamplerKind::Halton, MAX_SAMPLES_PER_PIXEL, 0).is_ok());
    }

    #[test]
    fn pairs_equal_two_single_values_for_every_kind() {
        // The stream's paired path (Sobol hashes each pair once) must give exactly the values
        // of the one-dimension path, which the sequence tests check.
        for kind in SamplerKind::ALL {
            let sampler = Sampler::new(kind, 16, 3).unwrap();
            for (pixel, index) in [([0, 0], 0), ([7, 2], 5), ([1000, 31], 15)] {
                let v = |d| sampler.value(pixel, index, d);
                let mut stream = sampler.stream(pixel, index);
                let (film, lens, time) = stream.camera();
                assert_eq!(film, Vec2::new(v(0), v(1)), "{kind:?}");
                assert_eq!(lens, Vec2::new(v(2), v(3)), "{kind:?}");
                assert_eq!(time, v(4), "{kind:?}");
                for first in [6, 8, 10] {
                    assert_eq!(
                        stream.next_2d(),
                        Vec2::new(v(first), v(first + 1)),
                        "{kind:?}"
                    );
                }
            }
        }
    }

    proptest::proptest! {
        #[test]
        fn peeks_return_the_next_values_and_move_nothing(
            kind_index in 0usize..SamplerKind::ALL.len(),
            steps in proptest::collection::vec(0u8..3, 0..12),
            skip in 0u32..4,
            index in 0u32..64,
        ) {
            // After any mix of reads, a peek gives what the read it stands for would give,
            // and the reads after it are those without the peek.
            let kind = SamplerKind::ALL[kind_index];
            let sampler = Sampler::new(kind, 64, 9).unwrap();
            let mut stream = sampler.stream([5, 11], index);
            stream.camera();
            for step in steps {
                match step {
                    0 => { stream.next_1d(); }
                    1 => stream.skip_1d(),
                    _ => { stream.next_2d(); }
                }
            }
            let (one, two) = (stream.peek_1d(), stream.peek_2d(skip));
            let mut reader = stream.clone();
            proptest::prop_assert_eq!(one.to_bits(), reader.next_1d().to_bits());
            let mut reader = stream.clone();
            for _ in 0..skip {
                reader.skip_1d();
            }
            let expected = reader.next_2d();
            let bits = |v: Vec2| v.to_array().map(f32::to_bits);
            proptest::prop_assert_eq!(bits(two), bits(expected));
            let mut unpeeked = stream.clone();
            proptest::prop_assert_eq!(stream.next_2d(), unpeeked.next_2d());
            // Skipping a pair leaves the stream where drawing it does.
            let (mut skipped, mut drawn) = (stream.clone(), stream.clone());
            skipped.skip_2d();
            drawn.next_2d();
            proptest::prop_assert_eq!(skipped.dimension(), drawn.dimension());
            proptest::prop_assert_eq!(skipped.next_1d().to_bits(), drawn.next_1d().to_bits());
        }
    }

    #[test]
    fn stream_layout_matches_value() {
        let sampler = Sampler::new(SamplerKind::Stratified, 16, 7).unwrap();
        let mut stream = sampler.stream([3, 4], 5);
        let (film, lens, time) = stream.camera();
        let v = |d| sampler.value([3, 4], 5, d);
        assert_eq!(film, Vec2::new(v(0), v(1)));
        assert_eq!(lens, Vec2::new(v(2), v(3)));
        assert_eq!(time, v(4));
        // After the camera, next_2d skips dimension 5 and reads the pair (6, 7).
        assert_eq!(stream.next_2d(), Vec2::new(v(6), v(7)));
        assert_eq!(stream.next_1d(), v(8));
        // Cursor at 9 (odd): next_2d pads to (10, 11).
        assert_eq!(stream.next_2d(), Vec2::new(v(10), v(11)));
        assert_eq!(stream.dimension(), 12);
    }
}
