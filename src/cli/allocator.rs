//! The binary's memory allocator: the system's, asking Linux for transparent huge pages on
//! large blocks.
//!
//! A BVH build over a million triangles writes over 100 MB of fresh memory (primitive boxes,
//! the binary tree's nodes, leaf blocks). With 4 KiB pages that measured some 26,000 page
//! faults a build; with 2 MiB pages, about 2,300.
//! Linux's default (`/sys/kernel/mm/transparent_hugepage/enabled` set to `madvise`) gives huge
//! pages only to memory that asks for them, which this allocator does for every block of at
//! least [`HUGE_MIN`] bytes as soon as the C allocator returns it. For a fresh block that is
//! before the program writes it; a block served from memory freed earlier (the C allocator
//! keeps some) has its pages already, which the kernel may collapse into huge ones later.
//! Elsewhere, or when the kernel declines, the advice changes nothing: it never changes what the
//! memory holds.

use std::alloc::{GlobalAlloc, Layout, System};

/// Blocks at least this large (4 MiB) are advised to use huge pages: two huge pages or more,
/// so that the rounding to 2 MiB boundaries leaves most of the block covered.
pub const HUGE_MIN: usize = 4 << 20;

/// The largest alignment `System` serves with `calloc` (the C allocator's own alignment on
/// 64-bit targets): above it, `System` zeroes a block by writing it.
const CALLOC_ALIGN: usize = 16;

/// [`System`], with huge pages advised for large blocks (see the module).
pub struct HugePages;

// SAFETY: every call is forwarded to `System` with the same arguments; `advise` only gives
// advice on pages inside the block `System` just returned.
unsafe impl GlobalAlloc for HugePages {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: the caller's contract, forwarded.
        let p = unsafe { System.alloc(layout) };
        advise(p, layout.size());
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if layout.size() >= HUGE_MIN && layout.align() > CALLOC_ALIGN {
            // `System` would zero such a block by writing it, which maps its pages before the
            // advice: advise first, then zero.
            // SAFETY: the caller's contract, forwarded; the write stays within the block.
            unsafe {
                let p = System.alloc(layout);
                advise(p, layout.size());
                if !p.is_null() {
                    std::ptr::write_bytes(p, 0, layout.size());
                }
                return p;
            }
        }
        // SAFETY: the caller's contract, forwarded. Zeroed by `calloc`, which leaves fresh
        // pages untouched (they are zero already) until the program writes them.
        let p = unsafe { System.alloc_zeroed(layout) };
        advise(p, layout.size());
        p
    }

    unsafe fn dealloc(&self, p: *mut u8, layout: Layout) {
        // SAFETY: the caller's contract, forwarded.
        unsafe { System.dealloc(p, layout) }
    }

    unsafe fn realloc(&self, p: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: the caller's contract, forwarded.
        let q = unsafe { System.realloc(p, layout, new_size) };
        advise(q, new_size);
        q
    }
}

/// The system's page size, asked once (0 if the system does not say).
#[cfg(target_os = "linux")]
fn page_size() -> usize {
    use std::sync::atomic::{AtomicUsize, Ordering};
    // usize::MAX: not asked yet.
    static PAGE: AtomicUsize = AtomicUsize::new(usize::MAX);
    let mut page = PAGE.load(Ordering::Relaxed);
    if page == usize::MAX {
        // SAFETY: sysconf has no preconditions.
        page = usize::try_from(unsafe { libc::sysconf(libc::_SC_PAGESIZE) }).unwrap_or(0);
        PAGE.store(page, Ordering::Relaxed);
    }
    page
}

/// Advise huge pages for the whole pages inside the block of `size` bytes at `p`, if it is at
/// least [`HUGE_MIN`] bytes (Linux only; a refusal is ignored, as advice may be).
#[inline]
fn advise(p: *mut u8, size: usize) {
    #[cfg(target_os = "linux")]
    if !p.is_null() && size >= HUGE_MIN {
        let page = page_size();
        if page == 0 {
            return;
        }
        let start = (p as usize).next_multiple_of(page);
        let end = (p as usize + size) / page * page;
        if end > start {
            // SAFETY: the range lies within the block just allocated and is page-aligned;
            // MADV_HUGEPAGE changes how the pages are backed, never what they hold.
            unsafe {
                libc::madvise(start as *mut libc::c_void, end - start, libc::MADV_HUGEPAGE);
            }
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = (p, size);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A large block keeps its contents through growth and comes back zeroed when asked; on
    /// Linux with transparent huge pages not switched off, its pages are huge ones. Both ways
    /// of zeroing: `calloc` (alignment 8) and writing after the advice (alignment 64).
    #[test]
    fn large_blocks_are_whole_and_huge() {
        for align in [8, 64] {
            large_block(align);
        }
    }

    fn large_block(align: usize) {
        let a = HugePages;
        let size = 16 << 20;
        let layout = Layout::from_size_align(size, align).unwrap();
        // SAFETY: a non-zero size; every access stays within the block's current size, and
        // the block is freed once with its last layout.
        unsafe {
            let p = a.alloc_zeroed(layout);
            assert!(!p.is_null());
            let block = std::slice::from_raw_parts_mut(p, size);
            // Zeroed: checked on the first and last MiB only, away from the middle whose pages
            // are measured below (reading a fresh page maps the shared zero page, which some
            // kernels split into small pages at the first write).
            let mib = 1 << 20;
            assert!(block[..mib].iter().all(|&b| b == 0));
            assert!(block[size - mib..].iter().all(|&b| b == 0));
            for (i, b) in block.iter_mut().enumerate() {
                *b = (i % 251) as u8;
            }
            #[cfg(target_os = "linux")]
            {
                let thp = std::fs::read_to_string("/sys/kernel/mm/transparent_hugepage/enabled")
                    .unwrap_or_default();
                if !thp.is_empty() && !thp.contains("[never]") {
                    // The middle of the block: its first page, which holds part of the C allocator's
                    // header, lies outside the advised range.
                    let huge = anon_huge_kib(p as usize + size / 2);
                    assert!(
                        huge >= 2048,
                        "align {align}: {huge} KiB of huge pages in the block ({thp})"
                    );
                }
            }
            let q = a.realloc(p, layout, 2 * size);
            assert!(!q.is_null());
            let grown = std::slice::from_raw_parts(q, size);
            assert!(grown.iter().enumerate().all(|(i, &b)| b == (i % 251) as u8));
            a.dealloc(q, Layout::from_size_align(2 * size, align).unwrap());
        }
    }

    /// `AnonHugePages` of the mapping that holds address `at`, in KiB, from `/proc/self/smaps`.
    #[cfg(target_os = "linux")]
    fn anon_huge_kib(at: usize) -> u64 {
        let smaps = std::fs::read_to_string("/proc/self/smaps").unwrap();
        let mut inside = false;
        for line in smaps.lines() {
            let first = line.split_whitespace().next().unwrap_or("");
            if let Some((lo, hi)) = first.split_once('-')
                && let (Ok(lo), Ok(hi)) =
                    (usize::from_str_radix(lo, 16), usize::from_str_radix(hi, 16))
            {
                inside = (lo..hi).contains(&at);
            } else if inside && let Some(v) = line.strip_prefix("AnonHugePages:") {
                return v.trim().trim_end_matches("kB").trim().parse().unwrap_or(0);
            }
        }
        0
    }
}
