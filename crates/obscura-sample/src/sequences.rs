//! The four sample generators, each a pure function of (pixel key, sample index, dimension)
//! for a given number of samples per pixel.
//!
//! The pixel key is [`crate::hash::pixel_key`] of (seed, pixel); everything else that varies
//! per pixel, per dimension or per pair of dimensions is hashed from it here.

use rand_core::Rng;
use rand_pcg::Pcg32;

use crate::hash::{
    GOLDEN, Permutation, combine, in_stratum, mix64, owen_hash, permute, unit_f32_from_bits,
    unit_f64_from_bits,
};

/// Tags that keep the hash streams of the samplers and of their parts apart.
const TAG_STRATIFIED: u64 = 0x5354_5241_5449_4659;
const TAG_HALTON: u64 = 0x4841_4c54_4f4e_0001;
const TAG_HALTON_JITTER: u64 = 0x4841_4c54_4f4e_0002;
const TAG_SOBOL: u64 = 0x534f_424f_4c00_0001;
const TAG_TAIL: u64 = 0x534f_424f_4c00_0002;

/// The finest strata a value is placed in: `2^24`, one `f32` ulp just below one.
const MAX_STRATA: u32 = 1 << 24;

// ---------------------------------------------------------------------------------------
// Independent

/// Independent uniform values: a PCG32 generator seeded per (pixel, index, seed), advanced
/// by `dimension` steps (PCG jumps ahead in logarithmic time), so the value does not depend
/// on which dimensions were asked for before.
#[inline]
pub(crate) fn independent(pixel_key: u64, seed: u64, index: u32, dimension: u32) -> f32 {
    let state = combine(pixel_key, u64::from(index));
    let stream = mix64(seed ^ 0x1d8e_4e27_c47d_124f);
    let mut rng = Pcg32::new(state, stream);
    rng.advance(u64::from(dimension));
    unit_f32_from_bits(rng.next_u32())
}

// ---------------------------------------------------------------------------------------
// Stratified

/// The 2D grid `[nx, ny]` used for `spp` samples: the factorisation `nx * ny = spp` with `nx`
/// the largest divisor of `spp` not above its square root (so `nx <= ny`; a prime `spp` gives
/// `1 x spp`).
pub(crate) fn stratified_grid(spp: u32) -> [u32; 2] {
    let mut nx = spp.isqrt().max(1);
    while !spp.is_multiple_of(nx) {
        nx -= 1;
    }
    [nx, spp / nx]
}

/// Multi-jittered stratified sampling (Chiu, Shirley and Wang 1994) per pair of dimensions.
///
/// The samples `pass * spp .. (pass + 1) * spp` of a pixel form one pattern. For pair `p`
/// (dimensions `2p`, `2p + 1`), sample `index` first takes a shuffled 2D cell
/// `s = permute(index % spp)`, with a permutation drawn per (pixel, pair, pass): that shuffle
/// is what decorrelates the lens and time strata from the film strata. Cell `s` is column
/// `i = s % nx`, row `j = s / nx`. The x value then sits in the fine stratum
/// `i * ny + perm_i(j)` of `spp`, the y value in `j * nx + perm_j(i)`, with fresh
/// permutations per column and row, and a jitter inside. So every pattern is jittered on the
/// `nx x ny` grid AND each dimension alone is stratified into `spp` equal intervals
/// (Latin hypercube), whatever `spp` is.
#[inline]
pub(crate) fn stratified(
    pixel_key: u64,
    spp: u32,
    grid: [u32; 2],
    index: u32,
    dimension: u32,
) -> f32 {
    let [nx, ny] = grid;
    let pass = index / spp;
    let pair = dimension / 2;
    let pattern_key = combine(
        combine(combine(pixel_key, TAG_STRATIFIED), u64::from(pair)),
        u64::from(pass),
    );
    // Shuffle the cells per pair: the pair's stratum does not follow the film's.
    let s = permute(index % spp, spp, pattern_key);
    let i = s % nx;
    let j = s / nx;
    // Fine stratum within the column (x) or row (y), and a jitter inside it.
    let (fine, component_key) = if dimension.is_multiple_of(2) {
        let key = combine(pattern_key, 2 * u64::from(i));
        (i * ny + permute(j, ny, key), key)
    } else {
        let key = combine(pattern_key, 2 * u64::from(j) + 1);
        (j * nx + permute(i, nx, key), key)
    };
    let jitter = unit_f64_from_bits(combine(component_key, u64::from(s) | (1 << 40)));
    in_stratum(fine, spp, jitter)
}

// ---------------------------------------------------------------------------------------
// Halton

/// How many dimensions get their own prime base; dimension `d` uses `PRIMES[d % NUM_PRIMES]`
/// (beyond that the bases repeat, with independent scrambles).
pub(crate) const NUM_PRIMES: usize = 1024;

/// The first [`NUM_PRIMES`] primes, found at compile time by trial division.
pub(crate) static PRIMES: [u32; NUM_PRIMES] = first_primes();

const fn first_primes() -> [u32; NUM_PRIMES] {
    let mut primes = [0u32; NUM_PRIMES];
    let mut count = 0;
    let mut candidate = 2u32;
    while count < NUM_PRIMES {
        let mut is_prime = true;
        let mut k = 0;
        while k < count && primes[k] * primes[k] <= candidate {
            if candidate.is_multiple_of(primes[k]) {
                is_prime = false;
                break;
            }
            k += 1;
        }
        if is_prime {
            primes[count] = candidate;
            count += 1;
        }
        candidate += 1;
    }
    primes
}

/// The scrambled radical inverse of `index` in the prime base of `dimension`.
///
/// The first `K` base-`b` digits (with `b^K <= 2^24`) are each sent through a random
/// permutation of `0..b` drawn per (seed, pixel, dimension, digit position) (random digit
/// permutation scrambling; in base 2 a random xor). The permuted digits name one of `b^K`
/// fine strata and a hashed jitter places the value inside it (standing in for the infinite
/// tail of scrambled digits). Digit-wise bijections map the set of `k`-digit prefixes of
/// indices `0..b^k` onto itself, so the scrambled points keep the stratification of the
/// Halton sequence: the first `b^k` indices fill each interval `[m / b^k, (m + 1) / b^k)`
/// once, and pairs of dimensions fill `b1^k1 x b2^k2` grids.
#[inline]
pub(crate) fn halton(pixel_key: u64, index: u32, dimension: u32) -> f32 {
    let base = PRIMES[dimension as usize % NUM_PRIMES];
    let key = combine(combine(pixel_key, TAG_HALTON), u64::from(dimension));
    let (stratum, count) = if base == 2 {
        // All 24 binary digits at once: bit reversal, then xor with random bits.
        let digits = index.reverse_bits() >> 8;
        (digits ^ ((key as u32) >> 8), MAX_STRATA)
    } else {
        let mut stratum = 0u32;
        let mut count = 1u32;
        let mut rest = index;
        let mut position = 0u64;
        while count <= MAX_STRATA / base {
            let digit = rest % base;
            rest /= base;
            stratum = stratum * base + permute(digit, base, combine(key, position));
            count *= base;
            position += 1;
        }
        (stratum, count)
    };
    let jitter = unit_f64_from_bits(combine(combine(key, TAG_HALTON_JITTER), u64::from(index)));
    in_stratum(stratum, count, jitter)
}

// ---------------------------------------------------------------------------------------
// Sobol

/// The second dimension of the Sobol sequence as a 32-bit binary fraction: its generator
/// matrix is Pascal's triangle modulo 2, whose successive columns `v` are obtained by
/// `v ^= v >> 1` from `v = 1 << 31`. Read from [`raw_pair`]'s tables, as the sampler reads it.
#[cfg(test)]
pub(crate) fn sobol_second(index: u32) -> u32 {
    raw_pair(index)[1].reverse_bits()
}

/// Both raw coordinates of a pair's (0,2)-sequence point at (shuffled) index `shuffled`,
/// bit-reversed as the Owen scramble consumes them: the van der Corput value reversed, which
/// is `shuffled` itself, and [`sobol_second_bitwise`]`(shuffled)` reversed.
///
/// The second is linear over XOR in the index bits (bit reversal distributes over XOR), so it
/// is read from four tables of 256 entries, one per byte of the index: the bit-by-bit product
/// (the reference) mispredicted a branch per set bit.
#[inline]
pub(crate) fn raw_pair(shuffled: u32) -> [u32; 2] {
    let [b0, b1, b2, b3] = shuffled.to_le_bytes();
    let second = SECOND_REVERSED[0][b0 as usize]
        ^ SECOND_REVERSED[1][b1 as usize]
        ^ SECOND_REVERSED[2][b2 as usize]
        ^ SECOND_REVERSED[3][b3 as usize];
    [shuffled, second]
}

/// `SECOND_REVERSED[k][b]`: the second Sobol dimension, bit-reversed, of byte `b` placed at
/// bits `8k..8k + 8` of the index, computed at compile time from the bitwise reference.
static SECOND_REVERSED: [[u32; 256]; 4] = {
    let mut table = [[0u32; 256]; 4];
    let mut k = 0;
    while k < 4 {
        let mut b = 0;
        while b < 256 {
            table[k][b] = sobol_second_bitwise((b as u32) << (8 * k)).reverse_bits();
            b += 1;
        }
        k += 1;
    }
    table
};

/// The second Sobol dimension one index bit at a time: the definition the tables are built
/// from.
pub(crate) const fn sobol_second_bitwise(mut index: u32) -> u32 {
    let mut result = 0u32;
    let mut column = 1u32 << 31;
    while index != 0 {
        if index & 1 != 0 {
            result ^= column;
        }
        index >>= 1;
        column ^= column >> 1;
    }
    result
}

/// Padded, Owen-scrambled Sobol: each pair of dimensions `(2p, 2p + 1)` is the 2D
/// (0,2)-sequence (van der Corput, second Sobol dimension), its sample index shuffled per
/// (pixel, pair, pass) and each coordinate Owen-scrambled per (pixel, pair, coordinate).
///
/// The index shuffle is a pseudo-random permutation ([`permute`]) of each block of `spp`
/// consecutive indices (a pass over the pixel's samples) onto itself, drawn per (pixel, pair,
/// block), as pbrt-v4's padded Sobol sampler and Mitsuba 3's `ldsampler` do; the film pair
/// (`p = 0`) is not shuffled, so every other pair is paired with the film by one permutation
/// of the hash family, which renders measured better than a uniformly random pairing (and
/// than a composition of two). Each block holds the same points as before its shuffle, so
/// when `spp = 2^m` every pair of every block is a (0,m,2)-net (one point in each elementary
/// interval of area `2^-m`; Owen scrambling keeps nets), and the film's first `2^k` samples
/// are nets too.
///
/// Only the first [`SOBOL_PAIRS`] pairs are Sobol's: the dimensions past them (a path's third
/// bounce on) are independent values from [`tail_pair`], at a tenth of a scrambled pair's
/// cost. Stratifying them measured no less error (docs/performance.md, "Sobol for the first
/// two bounces").
///
/// Not a nested scramble of the index bits, although that would keep every pair's first `2^k`
/// samples nets as well: it pairs the strata of different pairs with a structure of its own,
/// which renders measured noisier (docs/performance.md, "The Sobol sampler's index shuffle").
///
/// `key` is the pixel's key tagged for Sobol by [`sobol_key`] (once per pixel, not per value);
/// `places` is [`Permutation::new`] of the samples per pixel, which the sampler builds once.
#[inline]
pub(crate) fn sobol(key: u64, places: Permutation, index: u32, dimension: u32) -> f32 {
    if dimension / 2 >= SOBOL_PAIRS {
        return tail_pair(key, index, dimension / 2)[(dimension % 2) as usize];
    }
    let prepared = sobol_prepare(key, SobolIndex::new(index, places), dimension / 2);
    sobol_coordinate(prepared, dimension % 2)
}

/// The pairs of dimensions the Sobol sampler stratifies: [`crate::SOBOL_DIMENSIONS`] / 2.
pub(crate) const SOBOL_PAIRS: u32 = crate::SOBOL_DIMENSIONS / 2;

/// Both values of a pair past [`SOBOL_PAIRS`]: the two halves of one hash of (pixel, sample
/// index, pair), independent uniform values. `key` is the Sobol-tagged pixel key; `TAG_TAIL`
/// keeps these hashes apart from the pairs' keys, which hash (pixel, pair) from the same key.
#[inline]
pub(crate) fn tail_pair(key: u64, index: u32, pair: u32) -> [f32; 2] {
    let bits = combine(key ^ TAG_TAIL, u64::from(index) << 32 | u64::from(pair));
    [
        unit_f32_from_bits(bits as u32),
        unit_f32_from_bits((bits >> 32) as u32),
    ]
}

/// Where a sample index sits for Sobol's index shuffle: its block of `spp` indices and its
/// place in it. A stream computes it once for all the pairs it reads.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SobolIndex {
    /// The first index of its block: `index - index % spp`.
    start: u32,
    /// `index % spp`.
    local: u32,
    /// The permutations of a block's `spp` places.
    permutation: Permutation,
    /// The block's number, spread over a key's bits (zero for the first block).
    block_key: u64,
}

impl SobolIndex {
    /// Sample `index` of a pixel sampled `permutation.len()` (at least one) times a pass;
    /// `permutation` permutes a pass's places.
    #[inline]
    pub(crate) fn new(index: u32, permutation: Permutation) -> SobolIndex {
        let spp = permutation.len().max(1);
        let block = index / spp;
        SobolIndex {
            start: block * spp,
            local: index % spp,
            permutation,
            block_key: u64::from(block).wrapping_mul(GOLDEN),
        }
    }

    /// The index pair `pair`'s point is taken at: the sample index for the film pair, else
    /// its place in the block permuted by the pair's key.
    #[inline]
    fn shuffled(self, pair: u32, pair_key: u64) -> u32 {
        if pair == 0 {
            self.start + self.local
        } else {
            // Wrapping: only a last, partial block just below 2^32 can reach past it.
            self.start.wrapping_add(
                self.permutation
                    .apply(self.local, pair_key ^ self.block_key),
            )
        }
    }
}

/// What both coordinates of pair `pair` share: the pair's key and the shuffled sample index.
/// A stream keeps it, so the second coordinate of a pair read one dimension at a time costs
/// one scramble, not a shuffle and two scrambles.
#[inline]
pub(crate) fn sobol_prepare(key: u64, at: SobolIndex, pair: u32) -> SobolPair {
    let pair_key = combine(key, u64::from(pair));
    SobolPair {
        pair,
        pair_key,
        shuffled: at.shuffled(pair, pair_key),
    }
}

/// The shared part of one Sobol pair, from [`sobol_prepare`].
#[derive(Debug, Clone, Copy)]
pub(crate) struct SobolPair {
    /// Which pair (dimensions `2 pair` and `2 pair + 1`).
    pub pair: u32,
    pair_key: u64,
    /// The shuffled sample index.
    shuffled: u32,
}

impl SobolPair {
    /// The Owen scramble seed of coordinate `which` (0 or 1).
    #[inline]
    fn scramble_seed(&self, which: u32) -> u32 {
        combine(self.pair_key, u64::from(which) + 1) as u32
    }
}

/// The key [`sobol`] and [`sobol_pair`] take: the pixel's key tagged for this sampler.
#[inline]
pub(crate) fn sobol_key(pixel_key: u64) -> u64 {
    combine(pixel_key, TAG_SOBOL)
}

/// Both coordinates of pair `pair` (dimensions `2 pair` and `2 pair + 1`) of the sample at
/// `at`: the same values as two [`sobol`] calls, with the pair's key, index shuffle and raw
/// coordinates computed once, and the two scrambled coordinates reversed together in one
/// 64-bit reversal (hashing and bit reversal are most of the sampler's cost; see
/// docs/performance.md).
#[inline]
pub(crate) fn sobol_pair(key: u64, at: SobolIndex, pair: u32) -> [f32; 2] {
    if pair >= SOBOL_PAIRS {
        return tail_pair(key, at.start.wrapping_add(at.local), pair);
    }
    let prepared = sobol_prepare(key, at, pair);
    let [raw0, raw1] = raw_pair(prepared.shuffled);
    let h0 = owen_hash(raw0, prepared.scramble_seed(0));
    let h1 = owen_hash(raw1, prepared.scramble_seed(1));
    // Reversing h1:h0 as one 64-bit word puts h0 reversed in the high half, h1 reversed in
    // the low.
    let both = (u64::from(h1) << 32 | u64::from(h0)).reverse_bits();
    [
        unit_f32_from_bits((both >> 32) as u32),
        unit_f32_from_bits(both as u32),
    ]
}

/// Coordinate `which` (0 or 1) of the pair's (0,2)-sequence point at the shuffled index,
/// Owen-scrambled.
///
/// The raw coordinates are the van der Corput radical inverse (the index's bits reversed) and
/// the second Sobol dimension; the scramble works on reversed bits, so both are formed
/// reversed ([`raw_pair`]) and [`owen_hash`] reverses once: the same value as
/// `owen_scramble(raw, seed)` with two bit reversals fewer.
#[inline]
pub(crate) fn sobol_coordinate(prepared: SobolPair, which: u32) -> f32 {
    let raw_reversed = raw_pair(prepared.shuffled)[(which & 1) as usize];
    let scrambled = owen_hash(raw_reversed, prepared.scramble_seed(which));
    unit_f32_from_bits(scrambled.reverse_bits())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hash::owen_scramble;

    #[test]
    fn primes_start_right_and_are_prime() {
        assert_eq!(&PRIMES[..10], &[2, 3, 5, 7, 11, 13, 17, 19, 23, 29]);
        // The 1024th prime is 8161.
        assert_eq!(PRIMES[NUM_PRIMES - 1], 8161);
        for &p in &PRIMES {
            assert!((2..p).take_while(|d| d * d <= p).all(|d| p % d != 0), "{p}");
        }
    }

    #[test]
    fn grid_hand_cases() {
        assert_eq!(stratified_grid(1), [1, 1]);
        assert_eq!(stratified_grid(16), [4, 4]);
        assert_eq!(stratified_grid(12), [3, 4]);
        assert_eq!(stratified_grid(8), [2, 4]);
        assert_eq!(stratified_grid(7), [1, 7]);
    }

    #[test]
    fn sobol_second_tables_match_the_bitwise_definition() {
        // Every single bit, and a spread of full 32-bit indices (an odd-multiplier walk).
        for bit in 0..32 {
            assert_eq!(sobol_second(1 << bit), sobol_second_bitwise(1 << bit));
        }
        let mut i = 0u32;
        for _ in 0..100_000 {
            i = i.wrapping_mul(0x9e37_79b9).wrapping_add(0x7f4a_7c15);
            assert_eq!(sobol_second(i), sobol_second_bitwise(i), "index {i:#x}");
            assert_eq!(raw_pair(i)[0], i, "index {i:#x}");
        }
    }

    /// Sobol's values from their definition, one step at a time. A stratified pair: the
    /// index's block of `spp` and its place in it, that place permuted per pair and block (not
    /// for the film pair), the raw coordinate (van der Corput or the second Sobol dimension,
    /// bit by bit), then its own Owen scramble. A later pair: one hash, split in two.
    fn sobol_definition(key: u64, spp: u32, index: u32, dimension: u32) -> f32 {
        let pair = dimension / 2;
        if pair >= crate::SOBOL_DIMENSIONS / 2 {
            // Past the stratified pairs: one hash of (pixel, index, pair), low half first.
            let bits = combine(key ^ TAG_TAIL, (u64::from(index) << 32) + u64::from(pair));
            return unit_f32_from_bits((bits >> (32 * (dimension % 2))) as u32);
        }
        let pair_key = combine(key, u64::from(pair));
        let block = index / spp;
        let shuffled = if pair == 0 {
            index
        } else {
            let block_key = u64::from(block).wrapping_mul(0x9e37_79b9_7f4a_7c15);
            (block * spp).wrapping_add(permute(index % spp, spp, pair_key ^ block_key))
        };
        let raw = if dimension.is_multiple_of(2) {
            shuffled.reverse_bits()
        } else {
            sobol_second_bitwise(shuffled)
        };
        let seed = combine(pair_key, u64::from(dimension % 2) + 1) as u32;
        unit_f32_from_bits(owen_scramble(raw, seed))
    }

    proptest::proptest! {
        #[test]
        fn sobol_values_and_pairs_equal_the_definition(
            key: u64,
            spp in 1u32..5000,
            index: u32,
            pair in 0u32..1000,
        ) {
            // The film pair, which is not shuffled, every time; a stratified pair and any pair
            // (mostly past the stratified ones) at random.
            for pair in [0, pair % SOBOL_PAIRS, pair] {
                let expected = [
                    sobol_definition(key, spp, index, 2 * pair),
                    sobol_definition(key, spp, index, 2 * pair + 1),
                ];
                proptest::prop_assert_eq!(
                    [
                        sobol(key, Permutation::new(spp), index, 2 * pair),
                        sobol(key, Permutation::new(spp), index, 2 * pair + 1),
                    ],
                    expected
                );
                proptest::prop_assert_eq!(
                    sobol_pair(key, SobolIndex::new(index, Permutation::new(spp)), pair),
                    expected
                );
            }
        }

        #[test]
        fn raw_pair_tables_equal_the_bitwise_definition(shuffled: u32) {
            proptest::prop_assert_eq!(
                raw_pair(shuffled),
                [shuffled, sobol_second_bitwise(shuffled).reverse_bits()]
            );
        }

        #[test]
        fn sobol_shuffles_each_block_onto_itself(key: u64, spp in 1u32..300, block in 0u32..4, pair in 0u32..20) {
            // The pair's points of one block are the block's own indices, each once.
            let at = |i| SobolIndex::new(block * spp + i, Permutation::new(spp));
            let mut seen = vec![false; spp as usize];
            for i in 0..spp {
                let shuffled = sobol_prepare(key, at(i), pair).shuffled;
                proptest::prop_assert!((block * spp..(block + 1) * spp).contains(&shuffled));
                let slot = &mut seen[(shuffled - block * spp) as usize];
                proptest::prop_assert!(!*slot, "index {} twice", shuffled);
                *slot = true;
            }
        }
    }

    #[test]
    fn sobol_second_first_points() {
        // Index 1: column 0 = 1000... -> 0.5. Index 2: column 1 = 1100... -> 0.75.
        // Index 3: 1000... ^ 1100... = 0100... -> 0.25. Index 4: column 2 = 1010... -> 0.625.
        let as_fraction = |i| f64::from(sobol_second(i)) / 2f64.powi(32);
        assert_eq!(as_fraction(0), 0.0);
        assert_eq!(as_fraction(1), 0.5);
        assert_eq!(as_fraction(2), 0.75);
        assert_eq!(as_fraction(3), 0.25);
        assert_eq!(as_fraction(4), 0.625);
    }

    /// The first `count` binary digits of a 32-bit fraction.
    fn top_bits(v: u32, count: u32) -> u32 {
        if count == 0 { 0 } else { v >> (32 - count) }
    }

    #[test]
    fn unscrambled_sobol_pair_is_a_02_sequence() {
        // Every elementary interval of area 2^-m holds one of the first 2^m points.
        for m in 0..=10u32 {
            for a in 0..=m {
                let mut seen = vec![false; 1 << m];
                for i in 0..(1u32 << m) {
                    let x = top_bits(i.reverse_bits(), a);
                    let y = top_bits(sobol_second(i), m - a);
                    let cell = ((x << (m - a)) | y) as usize;
                    assert!(!seen[cell], "m = {m}, a = {a}: cell {cell} twice");
                    seen[cell] = true;
                }
            }
        }
    }
}
