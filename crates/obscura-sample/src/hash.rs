//! Integer hashing and hash-driven permutations: the only source of randomness in the crate.
//!
//! Everything here is a pure function of its arguments, so every sample value is a pure
//! function of (pixel, sample index, dimension, seed).

/// The golden-ratio increment of splitmix64, used to separate successive keys (odd, so
/// multiplying by it also spreads a counter over a key's bits).
pub(crate) const GOLDEN: u64 = 0x9e37_79b9_7f4a_7c15;

/// The largest `f32` below one: every canonical sample value is at most this.
pub const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// The splitmix64 finaliser: a bijection on `u64` with good avalanche.
#[inline]
pub(crate) fn mix64(mut x: u64) -> u64 {
    x = (x ^ (x >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    x ^ (x >> 31)
}

/// Folds `value` into the running key `key`. For a fixed `key` this is injective in `value`.
#[inline]
pub(crate) fn combine(key: u64, value: u64) -> u64 {
    mix64(key.wrapping_add(GOLDEN) ^ value)
}

/// The key of one pixel under one seed.
#[inline]
pub(crate) fn pixel_key(seed: u64, pixel: [u32; 2]) -> u64 {
    combine(
        mix64(seed ^ 0x6f62_7363_7572_6121),
        u64::from(pixel[0]) | (u64::from(pixel[1]) << 32),
    )
}

/// The top 24 bits of `bits` as a value in `[0, 1)`: exact, never rounds up to one.
#[inline]
pub(crate) fn unit_f32_from_bits(bits: u32) -> f32 {
    (bits >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// The top 53 bits of `bits` as a value in `[0, 1)`.
#[inline]
pub(crate) fn unit_f64_from_bits(bits: u64) -> f64 {
    (bits >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// A pseudo-random permutation of `0..n`, chosen by `key`, applied to `i` (which must be `< n`):
/// [`Permutation::apply`].
#[inline]
pub(crate) fn permute(i: u32, n: u32, key: u64) -> u32 {
    Permutation::new(n).apply(i, key)
}

/// The pseudo-random permutations of `0..n`, one per key, with what depends on `n` alone
/// worked out once (a sampler stream applies one per pair of dimensions).
///
/// A bijection on the smallest power-of-two range holding `n` (xor, odd multiplication and
/// xorshifts, all invertible modulo `2^bits`) is iterated until it lands below `n` ("cycle
/// walking"); the restriction of a permutation to a subset by cycle walking is again a
/// permutation. Expected iterations are below two because `n > 2^bits / 2`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Permutation {
    n: u32,
    mask: u32,
    shift: u32,
    last_shift: u32,
}

impl Permutation {
    /// The permutations of `0..n`.
    #[inline]
    pub(crate) fn new(n: u32) -> Permutation {
        let bits = if n <= 1 {
            0
        } else {
            32 - (n - 1).leading_zeros()
        };
        Permutation {
            n,
            mask: u32::MAX.checked_shr(32 - bits).unwrap_or(0),
            shift: (bits / 2).max(1),
            last_shift: bits.div_ceil(2).max(1),
        }
    }

    /// `n`: how many places are permuted.
    #[inline]
    pub(crate) fn len(self) -> u32 {
        self.n
    }

    /// Where the permutation chosen by `key` takes `i` (which must be `< n`).
    #[inline]
    pub(crate) fn apply(self, i: u32, key: u64) -> u32 {
        let Permutation {
            n,
            mask,
            shift,
            last_shift,
        } = self;
        if n <= 1 {
            return 0;
        }
        let k0 = key as u32;
        let k1 = (key >> 32) as u32;
        let k2 = (key >> 17) as u32;
        let mut x = i & mask;
        loop {
            x ^= k0 & mask;
            x = x.wrapping_mul(k1 | 1) & mask;
            x ^= x >> shift;
            x = x.wrapping_mul(0x2c1b_3c6d | 1) & mask;
            x ^= (x << shift) & mask;
            x = x.wrapping_add(k2) & mask;
            x ^= x >> shift;
            x = x.wrapping_mul(0x297a_2d39) & mask;
            x ^= x >> last_shift;
            if x < n {
                return x;
            }
        }
    }
}

/// A nested uniform (Owen) scramble of the binary fraction held in `v` (bit 31 is the first
/// digit), chosen by `seed`.
///
/// Each digit is flipped or not by a pseudo-random function of the digits before it, which is
/// what Owen scrambling is; it is computed as a hash in bit-reversed order whose output bit
/// `k` is input bit `k` xor a function of the lower bits only (additions, odd multiplications
/// and xor-multiplications by even constants all have that shape), after Burley's "Practical
/// Hash-based Owen Scrambling" (2020). Constants and the sequence of steps are our own.
///
/// The definition the tests check; the samplers call [`owen_hash`] on values they already hold
/// reversed.
#[cfg(test)]
pub(crate) fn owen_scramble(v: u32, seed: u32) -> u32 {
    owen_hash(v.reverse_bits(), seed).reverse_bits()
}

/// The body of `owen_scramble`, on the bit-reversed value and giving the bit-reversed result:
/// `owen_scramble(v, s) == owen_hash(v.reverse_bits(), s).reverse_bits()`. Callers that hold a
/// value already reversed save the two reversals.
#[inline]
pub(crate) fn owen_hash(mut x: u32, seed: u32) -> u32 {
    x = x.wrapping_add(seed);
    x ^= x.wrapping_mul(0x5a3e_16c4);
    x = x.wrapping_mul((seed >> 15) | 1);
    x ^= x.wrapping_mul(0x1d9b_72e8);
    x = x.wrapping_add(seed.rotate_left(13));
    x ^= x.wrapping_mul(0xa7c2_4b1a);
    x ^= x.wrapping_mul(0x36f0_9d54);
    x
}

/// A value in `[0, 1)` that lies in stratum `stratum` of `count` equal strata: in
/// `[stratum / count, (stratum + 1) / count)` exactly, even after rounding to `f32`, with
/// `jitter` in `[0, 1)` placing it inside the stratum.
///
/// `count` must be at most `2^24`, so that every stratum holds at least one `f32` and
/// `x * count` is exact in `f64` for every `f32` `x` (24 + 24 bits < 53).
#[inline]
pub(crate) fn in_stratum(stratum: u32, count: u32, jitter: f64) -> f32 {
    let count_f = f64::from(count);
    let lower = f64::from(stratum);
    let upper = lower + 1.0;
    let mut x = ((lower + jitter) / count_f) as f32;
    x = x.min(ONE_MINUS_EPSILON);
    // Rounding to f32 may have crossed a stratum boundary: step back inside. Each stratum is
    // at least one f32 ulp wide, so a few steps always suffice.
    for _ in 0..4 {
        if f64::from(x) * count_f >= upper {
            x = x.next_down();
        } else if f64::from(x) * count_f < lower {
            x = x.next_up();
        } else {
            break;
        }
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn permute_is_a_permutation_for_many_sizes_and_keys() {
        for n in 1..=70u32 {
            for key in 0..20u64 {
                let key = mix64(key);
                let mut seen = vec![false; n as usize];
                for i in 0..n {
                    let j = permute(i, n, key);
                    assert!(j < n, "permute({i}, {n}) = {j} out of range");
                    assert!(!seen[j as usize], "permute hits {j} twice for n = {n}");
                    seen[j as usize] = true;
                }
            }
        }
    }

    #[test]
    fn permute_depends_on_the_key() {
        // With 16! orderings, 32 keys giving one ordering would mean the key is ignored.
        let orders: std::collections::HashSet<Vec<u32>> = (0..32u64)
            .map(|key| (0..16).map(|i| permute(i, 16, mix64(key))).collect())
            .collect();
        assert!(orders.len() > 24, "only {} distinct orders", orders.len());
    }

    #[test]
    fn owen_scramble_flips_the_first_digit_with_the_seed() {
        // Bit 31 (the first binary digit) is flipped by seed bit 0 alone.
        assert_eq!(owen_scramble(0, 0) >> 31, 0);
        assert_eq!(owen_scramble(0, 1) >> 31, 1);
        assert_eq!(owen_scramble(1 << 31, 1) >> 31, 0);
    }

    #[test]
    fn in_stratum_hand_cases() {
        // Stratum 1 of 3 with jitter 0.5 is the middle: (1 + 0.5) / 3 = 0.5.
        assert_eq!(in_stratum(1, 3, 0.5), 0.5);
        // Jitter just below one in the last stratum must not round to 1.0.
        let x = in_stratum(2, 3, 1.0 - 1e-12);
        assert!(x < 1.0 && f64::from(x) * 3.0 >= 2.0);
        // Stratum 0 of 7 with jitter just below one stays below 1/7.
        let x = in_stratum(0, 7, 1.0 - 1e-12);
        assert!(f64::from(x) * 7.0 < 1.0);
    }

    #[test]
    fn unit_f32_hand_cases() {
        assert_eq!(unit_f32_from_bits(0), 0.0);
        assert_eq!(unit_f32_from_bits(0x8000_0000), 0.5);
        assert_eq!(unit_f32_from_bits(u32::MAX), ONE_MINUS_EPSILON);
    }
}
