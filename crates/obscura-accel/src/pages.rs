//! Large read-only arrays kept on transparent huge pages.
//!
//! A ray through a BVH over a million triangles visits about ten nodes and leaf packets spread
//! over 120 MB. With 4 KiB pages, nearly every one of those visits also misses the TLB, and on
//! a virtual machine the page walk that follows is itself a chain of memory reads (nested
//! paging).
//! Linux backs memory with 2 MiB pages where the mapping asks for them (`madvise` with
//! `MADV_HUGEPAGE`; Embree asks for its BVH too), but the allocator behind `Vec` does not ask.
//! [`Pages`] moves a finished array into an anonymous mapping that does (the gain on the
//! benchmark meshes is in docs/performance.md).
//!
//! Arrays under [`Pages::MIN_BYTES`], and every array on systems other than Linux, or where the
//! mapping fails, stay in their `Vec`: the pages are a speed-up, never a requirement.
//!
//! Public, for the other large tables read at random by every ray (obscura-shade keeps an
//! environment map's sampling grid in one).

use bytemuck::Pod;
use std::fmt;
use std::marker::PhantomData;
use std::ops::Deref;

/// A read-only array, on huge pages where the system gives them (Linux's transparent huge
/// pages, asked for with `madvise`); read it as a slice.
///
/// ```
/// use obscura_accel::Pages;
///
/// let table = Pages::new(vec![0u32; 1 << 20]); // 4 MiB: mapped on Linux
/// assert_eq!(table.len(), 1 << 20);
/// assert_eq!(table[12345], 0);
/// ```
pub struct Pages<T: Pod> {
    store: Store<T>,
}

enum Store<T> {
    Heap(Vec<T>),
    /// An anonymous mapping of exactly the elements' bytes.
    #[cfg_attr(not(target_os = "linux"), allow(dead_code))]
    Mapped(memmap2::MmapMut, PhantomData<T>),
}

impl<T: Pod> Pages<T> {
    /// The smallest array worth a mapping: one huge page.
    pub const MIN_BYTES: usize = 2 << 20;

    /// `items`, moved into a mapping advised for huge pages when it is at least
    /// [`Pages::MIN_BYTES`] and the system allows; otherwise the vector itself, trimmed.
    pub fn new(mut items: Vec<T>) -> Pages<T> {
        if size_of_val(items.as_slice()) >= Self::MIN_BYTES
            && let Some(store) = mapped(&items)
        {
            return Pages { store };
        }
        items.shrink_to_fit();
        Pages {
            store: Store::Heap(items),
        }
    }

    /// Whether the array lives in a huge-page mapping (for tests and reports).
    pub fn is_mapped(&self) -> bool {
        matches!(self.store, Store::Mapped(..))
    }

    /// Bytes held, mapping or vector.
    pub fn bytes(&self) -> usize {
        match &self.store {
            Store::Heap(v) => v.capacity() * size_of::<T>(),
            Store::Mapped(map, _) => map.len(),
        }
    }
}

/// A mapping advised for huge pages holding a copy of `items`; `None` where there is no such
/// thing (not Linux) or the system refuses.
#[cfg(target_os = "linux")]
fn mapped<T: Pod>(items: &[T]) -> Option<Store<T>> {
    let bytes: &[u8] = bytemuck::cast_slice(items);
    let mut map = memmap2::MmapMut::map_anon(bytes.len()).ok()?;
    // Anonymous mappings start at a page boundary, far beyond any element's alignment; check
    // rather than assume (before copying anything), and keep the vector if not.
    bytemuck::try_cast_slice::<u8, T>(&map).ok()?;
    // Advise before the first write: the pages are faulted in by the copy below, and only
    // faults in an advised range are served with huge pages. If the kernel has transparent
    // huge pages disabled the advice fails and ordinary pages serve the mapping.
    let _ = map.advise(memmap2::Advice::HugePage);
    map.copy_from_slice(bytes);
    Some(Store::Mapped(map, PhantomData))
}

#[cfg(not(target_os = "linux"))]
fn mapped<T: Pod>(_items: &[T]) -> Option<Store<T>> {
    None
}

impl<T: Pod> Deref for Pages<T> {
    type Target = [T];

    #[inline(always)]
    fn deref(&self) -> &[T] {
        match &self.store {
            Store::Heap(v) => v,
            // The cast was checked when the mapping was made, so it cannot panic here.
            Store::Mapped(map, _) => bytemuck::cast_slice(map),
        }
    }
}

impl<T: Pod> Clone for Pages<T> {
    fn clone(&self) -> Self {
        Pages::new(self.to_vec())
    }
}

impl<T: Pod + PartialEq> PartialEq for Pages<T> {
    fn eq(&self, other: &Self) -> bool {
        **self == **other
    }
}

impl<T: Pod> fmt::Debug for Pages<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Pages")
            .field("len", &self.len())
            .field("mapped", &self.is_mapped())
            .finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_small_array_stays_in_its_vector() {
        let pages = Pages::new(vec![1u32, 2, 3]);
        assert!(!pages.is_mapped());
        assert_eq!(&*pages, &[1, 2, 3]);
        assert_eq!(pages.bytes(), 12);
    }

    #[test]
    fn a_large_array_reads_back_the_same_and_clones() {
        let n = Pages::<u64>::MIN_BYTES / 8 + 1000;
        let items: Vec<u64> = (0..n as u64).map(|i| i * 2654435761).collect();
        let pages = Pages::new(items.clone());
        if cfg!(target_os = "linux") {
            assert!(pages.is_mapped(), "a {n}-element array is mapped on Linux");
            assert!(pages.bytes() >= n * 8);
        }
        assert_eq!(&*pages, items.as_slice());
        let copy = pages.clone();
        assert_eq!(copy.is_mapped(), pages.is_mapped());
        assert_eq!(&*copy, items.as_slice());
    }

    #[test]
    fn an_empty_array_is_empty() {
        let pages = Pages::<u32>::new(Vec::new());
        assert!(pages.is_empty());
        assert!(!pages.is_mapped());
    }
}
