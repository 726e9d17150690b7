//! Transparent huge pages for the arrays that hold a value per sphere and
//! are read in no order: `exact`'s bodies, event slots and queue, its cells
//! and neighbour lists.
//!
//! At a million spheres those arrays span hundreds of megabytes, and with
//! 4 KB pages nearly every read an event makes also misses the TLB. Many
//! kernels (Debian's and Ubuntu's among them) back memory with 2 MB pages
//! only where the program asks (`/sys/kernel/mm/transparent_hugepage/enabled`
//! set to `madvise`), and the allocator does not ask. Asking for them made
//! `exact`'s steady rate 5–20 % higher at 1M spheres, and changed nothing
//! at 10k, where no array is that large (docs/perf-log.md, 2026-12-05).
//!
//! One of the crate's two `unsafe` calls is here (the other is the
//! prefetch hint of `prefetch.rs`; the crate denies it everywhere else):
//! `madvise` takes a raw address, though this advice never changes what the
//! memory holds or who may touch it.
#![allow(unsafe_code)]

/// Arrays from this size up are advised: one huge page on x86-64 and on
/// most arm64 kernels. Smaller ones could not use a huge page anyway.
const HUGE_PAGE: usize = 2 << 20;

/// Room for `n` values in `v`, in memory the kernel may back with huge
/// pages when it is that large. Call it before the values are written:
/// pages written first after it are huge from their first touch.
/// A buffer already large enough was advised when it was made here.
pub fn reserve<T>(v: &mut Vec<T>, n: usize) {
    let had = v.capacity();
    v.reserve_exact(n.saturating_sub(v.len()));
    if v.capacity() != had {
        advise(v);
    }
}

/// `v` emptied and refilled with `n` copies of `value`, in huge pages when
/// it is large.
pub fn refill<T: Clone>(v: &mut Vec<T>, n: usize, value: T) {
    v.clear();
    reserve(v, n);
    v.resize(n, value);
}

/// A vector of `n` copies of `value`, in huge pages when it is large.
pub fn filled<T: Clone>(n: usize, value: T) -> Vec<T> {
    let mut v = Vec::new();
    refill(&mut v, n, value);
    v
}

/// Ask for huge pages for the part of `v`'s buffer that can hold them: the
/// whole huge pages inside it. Their bounds are page-aligned whatever the
/// base page size (4, 16 or 64 KB all divide 2 MB), and the range never
/// leaves the buffer.
#[cfg(target_os = "linux")]
fn advise<T>(v: &mut Vec<T>) {
    let bytes = v.capacity() * size_of::<T>();
    let start = v.as_mut_ptr().cast::<u8>();
    let skip = start.addr().next_multiple_of(HUGE_PAGE) - start.addr();
    let len = bytes.saturating_sub(skip) / HUGE_PAGE * HUGE_PAGE;
    if len == 0 {
        return;
    }
    let first = start.wrapping_add(skip).cast::<std::ffi::c_void>();
    // SAFETY: MADV_HUGEPAGE only changes how the kernel backs the pages of
    // the range with physical memory; their contents and whether they may
    // be read or written stay as they were. The range lies inside `v`'s
    // buffer, which `v` holds (so it is mapped), and is aligned as madvise
    // wants. A refusal (no transparent huge pages here) changes nothing.
    let _ = unsafe { rustix::mm::madvise(first, len, rustix::mm::Advice::LinuxHugepage) };
}

#[cfg(not(target_os = "linux"))]
fn advise<T>(_: &mut Vec<T>) {}

#[cfg(test)]
mod tests {
    use super::{HUGE_PAGE, filled, reserve};

    /// The advice changes no value: a large vector reads back as written,
    /// before and after it grows.
    #[test]
    fn advised_vectors_keep_their_values() {
        let n = HUGE_PAGE / 8 * 3;
        let mut v = filled(n, 7_u64);
        assert!(v.len() == n && v.iter().all(|&x| x == 7));
        for (i, x) in v.iter_mut().enumerate() {
            *x = i as u64;
        }
        reserve(&mut v, 2 * n);
        assert!(v.capacity() >= 2 * n);
        v.extend(n as u64..2 * n as u64);
        assert!(v.iter().enumerate().all(|(i, &x)| x == i as u64));
        let small: Vec<u32> = filled(3, 1);
        assert_eq!(small, [1, 1, 1]);
    }

    /// Where the kernel gives huge pages to memory that asks (THP mode
    /// `madvise` or `always`), a large vector is backed by some: the
    /// mappings over its buffer count them in `/proc/self/smaps` (the
    /// advice splits a mapping where its range starts and ends).
    #[cfg(target_os = "linux")]
    #[test]
    fn a_large_vector_gets_huge_pages_where_the_kernel_gives_them() {
        let mode = std::fs::read_to_string("/sys/kernel/mm/transparent_hugepage/enabled")
            .unwrap_or_default();
        let v = filled(3 * HUGE_PAGE / 8, 1_u64);
        let buffer = v.as_ptr().addr()..v.as_ptr().addr() + v.len() * 8;
        let smaps = std::fs::read_to_string("/proc/self/smaps").unwrap();
        let (mut huge_kb, mut over) = (0, false);
        for line in smaps.lines() {
            if let Some((range, _)) = line.split_once(' ')
                && let Some((lo, hi)) = range.split_once('-')
                && let (Ok(lo), Ok(hi)) =
                    (usize::from_str_radix(lo, 16), usize::from_str_radix(hi, 16))
            {
                over = lo < buffer.end && buffer.start < hi;
            } else if over && let Some(kb) = line.strip_prefix("AnonHugePages:") {
                huge_kb += kb.trim().trim_end_matches(" kB").parse::<u64>().unwrap();
            }
        }
        if mode.contains("[madvise]") || mode.contains("[always]") {
            assert!(huge_kb >= 2048, "{huge_kb} kB in huge pages ({mode})");
        }
        assert!(v.iter().all(|&x| x == 1));
    }
}
