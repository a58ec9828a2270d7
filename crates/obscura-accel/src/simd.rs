//! The crate's one module allowed `unsafe` (docs/DESIGN.md): a software prefetch.
//!
//! Safe Rust has no prefetch instruction (`core::hint::prefetch_read` is not stable). A batch
//! query ([`WideBvh::closest_batch`](crate::wide)) asks for the lines of the node a ray will
//! visit next and then works on other rays while they arrive; a plain load in its place
//! would hold up the retirement of everything behind it until the line came, which is what
//! the batch exists to avoid. The path tracer asks ahead in the same way for the environment
//! map's cells a round of paths will read. A prefetch is a hint: it never faults and never
//! changes what a later load returns, so the portable path (no instruction at all) gives the
//! same results.
#![allow(unsafe_code)]

/// Asks for the cache line holding `*item` and the `extra_lines` lines after it, into every
/// cache level. Never changes a result; a no-op on targets without the instruction.
#[inline(always)]
pub fn prefetch<T>(item: &T, extra_lines: usize) {
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
        for line in 0..=extra_lines {
            // SAFETY: `_mm_prefetch` needs SSE, which every x86-64 CPU has and the `x86` arm
            // requires at compile time. It does not dereference its pointer (a prefetch of an
            // unmapped address is dropped, never a fault); the address is computed with
            // `wrapping_add`, so no out-of-bounds pointer arithmetic is asserted either.
            unsafe { _mm_prefetch::<_MM_HINT_T0>(base.wrapping_add(64 * line)) };
        }
    }
    #[cfg(not(any(
        target_arch = "x86_64",
        all(target_arch = "x86", target_feature = "sse")
    )))]
    {
        let _ = (item, extra_lines);
    }
}
