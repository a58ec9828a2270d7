//! The crate's one module allowed `unsafe` (docs/DESIGN.md): a software prefetch, and the
//! branch-free SSE2 steps of a spawned ray's origin.
//!
//! Safe Rust has no prefetch instruction (`core::hint::prefetch_read` is not stable). A batch
//! query ([`WideBvh::closest_batch`](crate::wide)) asks for the lines of the node a ray will
//! visit next and then works on other rays while they arrive, and a one-ray query asks for
//! the lines of each child it stacks and, on a large tree, for a node's leaf packets and
//! first child as soon as it reaches the node; a plain load in their place would hold up the
//! retirement of everything behind it until the line came. The path tracer asks ahead in the
//! same way for the environment map's cells a round of paths will read. A prefetch is a hint:
//! it never faults and never changes what a later load returns, so the portable path (no
//! instruction at all) gives the same results.
//!
//! On x86-64 CPUs with AVX2, the one-ray and batch queries of the wide BVH run compiled for
//! AVX2 ([`Avx2::run`]), and test a node's eight boxes in one eight-lane register
//! ([`Avx2::slabs8`]) where the portable path takes two four-lane halves. The CPU is asked at
//! run time ([`Avx2::detect`]); without AVX2 the portable path runs. Both do the same
//! operations in the same order on each lane, with no fused multiply-add, so they give the
//! same bits (`wide/tests.rs` compares them).
#![allow(unsafe_code)]

use glam::Vec4;
#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::{
    __m128, __m256, _CMP_LE_OQ, _mm256_add_ps, _mm256_andnot_ps, _mm256_broadcast_ps,
    _mm256_cmp_ps, _mm256_max_ps, _mm256_min_ps, _mm256_movemask_ps, _mm256_mul_ps, _mm256_set1_ps,
    _mm256_sub_ps,
};

/// Proof that the CPU runs AVX2: made only by [`Avx2::detect`], so the code it unlocks never
/// runs on a CPU without the instructions.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Avx2(());

impl Avx2 {
    /// `Some` when this CPU has AVX2 (std asks the CPU once and keeps the answer).
    #[inline(always)]
    pub(crate) fn detect() -> Option<Avx2> {
        #[cfg(target_arch = "x86_64")]
        {
            if std::is_x86_feature_detected!("avx2") {
                return Some(Avx2(()));
            }
        }
        None
    }

    /// Runs `work` inside a function compiled with AVX2 enabled, where [`slabs8`](Avx2::slabs8)
    /// inlines.
    #[inline(always)]
    pub(crate) fn run<W: WithAvx2>(self, work: W) -> W::Output {
        #[cfg(target_arch = "x86_64")]
        {
            // SAFETY: `self` exists only if `detect` found AVX2 on this CPU, which is all a
            // function compiled with `target_feature(enable = "avx2")` requires of its caller.
            unsafe { run_avx2(self, work) }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            work.with_avx2(self)
        }
    }

    /// The slab test of a node's eight boxes, `bounds` as the node stores them (min x, max x,
    /// min y, max y, min z, max z; four lanes to a `Vec4`), for a ray with splatted origin
    /// `o`, near-plane reciprocals `inv`, far-plane reciprocals `far` and near-plane choice
    /// `near` (1 where the direction is negative). Returns each lane's entry distance and the
    /// mask of the lanes entered within `[t_min, t_max]`; `SLACK` widens each far distance by
    /// `t + |t| * slack` first. The portable test's steps exactly
    /// (`wide::ray::Prepared::slabs`), one register for all eight lanes.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(crate) fn slabs8<const SLACK: bool>(
        self,
        bounds: &[[Vec4; 2]; 6],
        o: &[Vec4; 3],
        inv: &[Vec4; 3],
        far: &[Vec4; 3],
        near: [usize; 3],
        range: [f32; 2],
        slack: f32,
    ) -> ([f32; 8], u32) {
        #[cfg(target_arch = "x86_64")]
        {
            // SAFETY: as in `run`: `self` proves the CPU has AVX2.
            unsafe { slabs8_avx2::<SLACK>(bounds, o, inv, far, near, range, slack) }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            let _ = (bounds, o, inv, far, near, range, slack);
            unreachable!("Avx2 is never made off x86-64")
        }
    }
}

/// Work that [`Avx2::run`] compiles for AVX2. Only what is inlined into the AVX2 function is
/// AVX2 code; a call left out of line runs baseline code. So `with_avx2` and everything it
/// calls are `#[inline(always)]` functions, which are always inlined, and not closures, which
/// are inlined only when the optimiser finds them small enough.
pub(crate) trait WithAvx2 {
    /// What the work returns.
    type Output;
    /// The work, given the token.
    fn with_avx2(self, avx2: Avx2) -> Self::Output;
}

/// [`Avx2::run`]'s body, compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
fn run_avx2<W: WithAvx2>(avx2: Avx2, work: W) -> W::Output {
    work.with_avx2(avx2)
}

/// [`Avx2::slabs8`], compiled for AVX2 (its intrinsics are safe to call here; it reads memory
/// only through references, by value).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
fn slabs8_avx2<const SLACK: bool>(
    bounds: &[[Vec4; 2]; 6],
    o: &[Vec4; 3],
    inv: &[Vec4; 3],
    far: &[Vec4; 3],
    near: [usize; 3],
    [t_min, t_max]: [f32; 2],
    slack: f32,
) -> ([f32; 8], u32) {
    let plane = |i: usize| bytemuck::cast::<[Vec4; 2], __m256>(bounds[i]);
    let splat = |v: &Vec4| _mm256_broadcast_ps(&__m128::from(*v));
    let (nx, ny, nz) = (near[0] & 1, near[1] & 1, near[2] & 1);
    let (ox, oy, oz) = (splat(&o[0]), splat(&o[1]), splat(&o[2]));
    let tnx = _mm256_mul_ps(_mm256_sub_ps(plane(nx), ox), splat(&inv[0]));
    let tfx = _mm256_mul_ps(_mm256_sub_ps(plane(nx ^ 1), ox), splat(&far[0]));
    let tny = _mm256_mul_ps(_mm256_sub_ps(plane(2 + ny), oy), splat(&inv[1]));
    let tfy = _mm256_mul_ps(_mm256_sub_ps(plane(2 + (ny ^ 1)), oy), splat(&far[1]));
    let tnz = _mm256_mul_ps(_mm256_sub_ps(plane(4 + nz), oz), splat(&inv[2]));
    let tfz = _mm256_mul_ps(_mm256_sub_ps(plane(4 + (nz ^ 1)), oz), splat(&far[2]));
    let entry = _mm256_max_ps(
        _mm256_max_ps(tnx, tny),
        _mm256_max_ps(tnz, _mm256_set1_ps(t_min)),
    );
    let t = _mm256_min_ps(_mm256_min_ps(tfx, tfy), tfz);
    let t = if SLACK {
        // |t|: the sign bit cleared, as the portable `abs` does.
        let abs = _mm256_andnot_ps(_mm256_set1_ps(-0.0), t);
        _mm256_add_ps(t, _mm256_mul_ps(abs, _mm256_set1_ps(slack)))
    } else {
        t
    };
    let exit = _mm256_min_ps(_mm256_set1_ps(t_max), t);
    let mask = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(entry, exit)) as u32;
    (bytemuck::cast::<__m256, [f32; 8]>(entry), mask)
}

/// Asks for the cache line holding `*item` and the `extra_lines` lines after it, into every
/// cache level. Never changes a result; a no-op on targets without the instruction.
#[inline(always)]
pub fn prefetch<T>(item: &T, extra_lines: usize) {
    for line in 0..=extra_lines {
        prefetch_line(item, line);
    }
}

/// Asks for the lines of `count` items side by side from `*item` (at most `MAX`), each
/// `LINES` cache lines long, into every cache level: [`prefetch`] unrolled, with one branch
/// per item where a loop over the lines would take one per line.
#[inline(always)]
pub(crate) fn prefetch_items<T, const LINES: usize, const MAX: usize>(item: &T, count: usize) {
    for k in 0..MAX {
        if k < count {
            for line in 0..LINES {
                prefetch_line(item, k * LINES + line);
            }
        }
    }
}

/// Asks for the `line`th cache line from `*item`'s; a no-op on targets without the
/// instruction.
#[inline(always)]
fn prefetch_line<T>(item: &T, line: usize) {
    #[cfg(any(
        target_arch = "x86_64",
        all(target_arch = "x86", target_feature = "sse")
    ))]
    {
        #[cfg(target_arch = "x86")]
        use std::arch::x86::{_MM_HINT_T0, _mm_prefetch};
        #[cfg(target_arch = "x86_64")]
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        let base = std::ptr::from_ref(item).cast::<i8>();
        // SAFETY: `_mm_prefetch` needs SSE, which every x86-64 CPU has and the `x86` arm
        // requires at compile time. It does not dereference its pointer (a prefetch of an
        // unmapped address is dropped, never a fault); the address is computed with
        // `wrapping_add`, so no out-of-bounds pointer arithmetic is asserted either.
        unsafe { _mm_prefetch::<_MM_HINT_T0>(base.wrapping_add(64 * line)) };
    }
    #[cfg(not(any(
        target_arch = "x86_64",
        all(target_arch = "x86", target_feature = "sse")
    )))]
    {
        let _ = (item, line);
    }
}

/// The last steps of [`offset_ray_origin`](crate::geom::offset_ray_origin): `p` moved by `d`
/// along the normal `n` turned to the side of the ray (`-n` when `w_dot_n < 0`), then each
/// coordinate one float further the same way: the next float up where the turned normal's
/// coordinate is positive, the next float down where negative, unchanged where it is zero or
/// NaN.
///
/// On x86-64 it is one branch-free run of SSE2, working on the floats' bits for the steps:
/// which way a spawned ray leaves and the normal's signs are close to random from one hit to
/// the next, so branches on them were mispredicted about once a spawn. Elsewhere it is the
/// scalar steps; a test checks both give the same bits.
#[inline]
pub(crate) fn offset_point(p: glam::Vec3A, n: glam::Vec3A, d: f32, w_dot_n: f32) -> glam::Vec3A {
    #[cfg(target_arch = "x86_64")]
    {
        offset_point_sse2(p, n, d, w_dot_n)
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        offset_point_portable(p, n, d, w_dot_n)
    }
}

/// [`offset_point`] with a branch per decision, through the scalar steps.
#[cfg(any(test, not(target_arch = "x86_64")))]
#[inline]
pub(crate) fn offset_point_portable(
    p: glam::Vec3A,
    n: glam::Vec3A,
    d: f32,
    w_dot_n: f32,
) -> glam::Vec3A {
    use crate::geom::{next_float_down, next_float_up};
    let side = if w_dot_n < 0.0 { -n } else { n };
    let mut out = p + side * d;
    for i in 0..3 {
        if side[i] > 0.0 {
            out[i] = next_float_up(out[i]);
        } else if side[i] < 0.0 {
            out[i] = next_float_down(out[i]);
        }
    }
    out
}

/// [`offset_point`] on x86-64. The normal is turned by flipping its sign bits. For the steps,
/// with `m` the bits of a coordinate's magnitude: moving away from zero (the signs agree, or
/// the coordinate is a zero) gives magnitude `m + 1` with the side's sign, which also turns a
/// zero into the smallest subnormal of that sign; moving towards zero is the bits minus one.
/// NaNs, and infinities moving outwards, stay as they are.
#[cfg(target_arch = "x86_64")]
#[inline]
pub(crate) fn offset_point_sse2(
    p: glam::Vec3A,
    n: glam::Vec3A,
    d: f32,
    w_dot_n: f32,
) -> glam::Vec3A {
    use std::arch::x86_64::{
        __m128, _mm_add_epi32, _mm_add_ps, _mm_and_ps, _mm_and_si128, _mm_andnot_si128,
        _mm_castps_si128, _mm_castsi128_ps, _mm_cmpeq_epi32, _mm_cmpgt_epi32, _mm_cmpgt_ps,
        _mm_cmplt_ps, _mm_mul_ps, _mm_or_ps, _mm_or_si128, _mm_set1_epi32, _mm_set1_ps,
        _mm_setzero_ps, _mm_setzero_si128, _mm_sub_epi32, _mm_xor_ps,
    };
    let (p, n) = (__m128::from(p), __m128::from(n));
    // SAFETY: SSE2 is part of the x86-64 baseline, so every x86-64 CPU runs these; they work on
    // registers only and read or write no memory.
    let out = unsafe {
        let zero = _mm_setzero_ps();
        let sign = _mm_set1_epi32(i32::MIN);
        let flip = _mm_and_ps(
            _mm_cmplt_ps(_mm_set1_ps(w_dot_n), zero),
            _mm_castsi128_ps(sign),
        );
        let side = _mm_xor_ps(n, flip);
        let moved = _mm_add_ps(p, _mm_mul_ps(side, _mm_set1_ps(d)));

        let bits = _mm_castps_si128(moved);
        let one = _mm_set1_epi32(1);
        let infinity = _mm_set1_epi32(0x7f80_0000);
        let magnitude = _mm_andnot_si128(sign, bits);
        let side_sign = _mm_and_si128(_mm_castps_si128(side), sign);
        // Ordered comparisons: false for a zero or NaN side, which leave the coordinate alone.
        let steps = _mm_castps_si128(_mm_or_ps(
            _mm_cmpgt_ps(side, zero),
            _mm_cmplt_ps(side, zero),
        ));
        let outwards = _mm_or_si128(
            _mm_cmpeq_epi32(_mm_and_si128(bits, sign), side_sign),
            _mm_cmpeq_epi32(magnitude, _mm_setzero_si128()),
        );
        // The magnitude is below 2^31, so the signed comparison orders it.
        let stays = _mm_or_si128(
            _mm_cmpgt_epi32(magnitude, infinity),
            _mm_and_si128(_mm_cmpeq_epi32(magnitude, infinity), outwards),
        );
        let away = _mm_or_si128(_mm_add_epi32(magnitude, one), side_sign);
        let towards = _mm_sub_epi32(bits, one);
        let stepped = _mm_or_si128(
            _mm_and_si128(outwards, away),
            _mm_andnot_si128(outwards, towards),
        );
        let change = _mm_andnot_si128(stays, steps);
        _mm_castsi128_ps(_mm_or_si128(
            _mm_and_si128(change, stepped),
            _mm_andnot_si128(change, bits),
        ))
    };
    glam::Vec3A::from(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(4096))]

        /// The SSE2 run gives the scalar steps' bits, for every bit pattern of the point, the
        /// normal, the distance and the dot product (NaNs, infinities, zeros and subnormals
        /// included).
        #[test]
        #[cfg(target_arch = "x86_64")]
        fn offset_point_sse2_matches_the_portable_steps(
            p: [u32; 3],
            n: [u32; 3],
            d: u32,
            w_dot_n: u32,
            pick in 0usize..12,
        ) {
            // Half the cases put a coordinate of the point or the normal on an edge where the
            // steps differ: zeros, infinities, the largest finite float, a subnormal, a NaN.
            const EDGES: [u32; 7] =
                [0, 0x8000_0000, 0x7f80_0000, 0xff80_0000, 0x7f7f_ffff, 1, 0x7fc0_0000];
            let (mut p, mut n) = (p, n);
            if pick < 3 {
                p[pick] = EDGES[(p[pick] % 7) as usize];
            } else if pick < 6 {
                n[pick - 3] = EDGES[(n[pick - 3] % 7) as usize];
            }
            let v = |b: [u32; 3]| glam::Vec3A::from_array(b.map(f32::from_bits));
            let (d, w_dot_n) = (f32::from_bits(d), f32::from_bits(w_dot_n));
            // A NaN's payload is not defined across the two (Rust leaves which NaN an
            // operation returns open), only that it is a NaN.
            let bits = |v: glam::Vec3A| v.to_array().map(|x| if x.is_nan() { u32::MAX } else { x.to_bits() });
            let fast = bits(offset_point_sse2(v(p), v(n), d, w_dot_n));
            let portable = bits(offset_point_portable(v(p), v(n), d, w_dot_n));
            proptest::prop_assert_eq!(fast, portable);
        }
    }

    #[test]
    fn offset_point_hand_cases() {
        let n = glam::Vec3A::new(1.0, -1.0, 0.0);
        let p = glam::Vec3A::ONE;
        // d = 0: only the steps, one ulp up in x, down in y, none in z.
        let out = offset_point(p, n, 0.0, 1.0);
        assert_eq!(
            out.to_array(),
            [1.0 + f32::EPSILON, 1.0 - f32::EPSILON / 2.0, 1.0]
        );
        // The ray leaves on the other side: the normal turns, and so do the steps.
        let out = offset_point(p, n, 0.0, -1.0);
        assert_eq!(
            out.to_array(),
            [1.0 - f32::EPSILON / 2.0, 1.0 + f32::EPSILON, 1.0]
        );
        // Zeros step to the smallest subnormal of the side's sign; an infinity moving outwards
        // stays.
        let zeros = offset_point(glam::Vec3A::new(0.0, -0.0, f32::INFINITY), n, 0.0, 1.0);
        assert_eq!(zeros.x.to_bits(), 1);
        assert_eq!(zeros.y.to_bits(), 0x8000_0001);
        assert_eq!(zeros.z, f32::INFINITY);
        // Moved by d = 0.5 along the turned normal, then stepped.
        let out = offset_point(glam::Vec3A::ZERO, n, 0.5, -1.0);
        assert_eq!(
            out.to_array(),
            [-0.5 - f32::EPSILON / 2.0, 0.5 + f32::EPSILON / 2.0, 0.0]
        );
    }
}
