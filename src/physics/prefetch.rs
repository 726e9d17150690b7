//! Asking the processor to start loading a line the event loop will read
//! soon. At a million spheres every record an event reads is a cache miss,
//! and the loop knows the next event's sphere before it is done with the
//! current one: loading its records meanwhile takes their misses off the
//! path (docs/perf-log.md, 2026-12-05).
//!
//! The crate's other `unsafe` call besides `madvise` (the crate denies it
//! elsewhere): a prefetch is an intrinsic the compiler will only call from
//! code that names its target feature, though a prefetch never faults and
//! never changes memory.
#![allow(unsafe_code)]

/// Start loading the line that holds `x` into every cache level.
#[inline(always)]
pub fn line<T>(x: &T) {
    at(std::ptr::from_ref(x).cast::<i8>());
}

/// Start loading both lines of a record that may straddle two (the
/// packed event slots and list centres): its first byte's and its last's.
#[inline(always)]
pub fn record<T>(x: &T) {
    let first = std::ptr::from_ref(x).cast::<i8>();
    at(first);
    at(first.wrapping_add(size_of::<T>().saturating_sub(1)));
}

/// Start loading the line of address `p`.
#[inline(always)]
fn at(p: *const i8) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: `prefetch_t0` needs SSE, which every x86-64 processor has
    // (it is in the target's baseline). A prefetch is a hint: it reads
    // nothing into the program, never faults whatever the address, and
    // writes nothing.
    unsafe {
        prefetch_t0(p);
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = p;
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "sse")]
#[inline]
fn prefetch_t0(p: *const i8) {
    use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
    _mm_prefetch::<_MM_HINT_T0>(p);
}
