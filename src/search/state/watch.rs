//! The watch lists (per triangle and per dead-component root: the verdicts `(candidate,
//! version)` whose certificate holds that element) in one slab: every list's entries lie
//! contiguous in a block of a power-of-two size, and a list costs an 8-byte head (its
//! block's address, length and size class). A list that outgrows its block moves to one of
//! the next class; a freed block goes on a free list of its class, linked through the block
//! itself, and a block of a class with no free one is cut from a larger free block when
//! there is one. A heap block per list (`ThinVec`: a 16-byte header and malloc's 8 bytes
//! beside the entries, 32 bytes at least) cost about 20 bytes per triangle of a grid more
//! (#26). The triangles' and the roots' lists share the slab: the roots' lists grow and
//! are freed as dead components merge, and their blocks serve the triangles' lists.
//!
//! The slab is a list of fixed pages, never moved: one `Vec` doubling by `realloc` copied
//! itself at each doubling when glibc had not mapped it apart (its mmap threshold grows
//! with the large buffers freed before), and the copy and the hole it left in the heap
//! raised the peak resident memory of selective on a 10^6-triangle grid by 13 bytes per
//! triangle instead of lowering it.

use crate::mesh::NONE;

/// A watch entry: a candidate and the version of its verdict when the entry was made.
pub(super) type Entry = (u32, u32);

/// A head's length bits; the size class sits above them.
const LEN_BITS: u32 = 27;
const LEN_MASK: u32 = (1 << LEN_BITS) - 1;
/// Size classes: 0 is no block, `k` a block of `2^(k - 1)` entries; the largest block,
/// class 27, holds 2^26 entries (a list's length stays below its bits' limit).
const CLASSES: usize = 28;
/// Entries per page (64 KiB: below glibc's mmap threshold, so pages pack in the heap). A
/// block lies within one page; a larger block gets a page of its size, followed by empty
/// pages that keep its addresses.
const PAGE_BITS: u32 = 13;
const PAGE: usize = 1 << PAGE_BITS;
const IN_PAGE: u32 = PAGE as u32 - 1;
/// Pages the 32-bit addresses reach, less one: no block's address is `NONE`, which ends a
/// free list.
const MAX_PAGES: usize = (1 << (32 - PAGE_BITS)) - 1;

/// One list: its block's address in the slab (page `off >> PAGE_BITS`, entry `off &
/// IN_PAGE`) and `class << LEN_BITS | length`.
#[derive(Debug, Clone, Copy, Default)]
struct Head {
    off: u32,
    len: u32,
}

impl Head {
    #[inline]
    fn len(self) -> usize {
        (self.len & LEN_MASK) as usize
    }

    #[inline]
    fn class(self) -> usize {
        (self.len >> LEN_BITS) as usize
    }

    /// Entries the block holds.
    #[inline]
    fn capacity(self) -> usize {
        capacity(self.class())
    }
}

/// Entries in a block of class `k`.
#[inline]
fn capacity(k: usize) -> usize {
    if k == 0 { 0 } else { 1 << (k - 1) }
}

/// The smallest class whose block holds `n` entries.
#[inline]
fn class_for(n: usize) -> usize {
    if n == 0 {
        0
    } else {
        n.next_power_of_two().trailing_zeros() as usize + 1
    }
}

/// The page and the entry within it of address `off`.
#[inline]
fn split(off: u32) -> (usize, usize) {
    ((off >> PAGE_BITS) as usize, (off & IN_PAGE) as usize)
}

/// Numbered watch lists in one slab (see the module docs): first one per triangle, then one
/// per vertex (a dead-component root's, [`WatchLists::root`]).
#[derive(Debug, Clone)]
pub(super) struct WatchLists {
    heads: Vec<Head>,
    /// The first root's list.
    roots: u32,
    pages: Vec<Box<[Entry]>>,
    /// The part of the last page of single pages not yet given to a block (addresses; empty
    /// when there is none).
    next: usize,
    end: usize,
    /// Per class, the first free block (its first entry's `.0` links to the next), or NONE.
    free: [u32; CLASSES],
    /// Bit k: class k has a free block.
    has_free: u32,
}

impl WatchLists {
    /// Empty lists for `triangles` triangles and `roots` vertices (nothing allocated beyond
    /// their heads). Their sum stays below 2^32 (both are below 2^31).
    pub(super) fn new(triangles: usize, roots: usize) -> WatchLists {
        let n = triangles + roots;
        assert!(n < NONE as usize, "{n} watch lists");
        WatchLists {
            heads: vec![Head::default(); n],
            roots: triangles as u32,
            pages: Vec::new(),
            next: 0,
            end: 0,
            free: [NONE; CLASSES],
            has_free: 0,
        }
    }

    /// The list of dead-component root `v`.
    #[inline]
    pub(super) fn root(&self, v: u32) -> u32 {
        self.roots + v
    }

    /// Number of entries of list `i`.
    #[inline]
    pub(super) fn len(&self, i: u32) -> usize {
        self.heads[i as usize].len()
    }

    /// Entry `j` of list `i` (`j < len(i)`).
    #[inline]
    pub(super) fn get(&self, i: u32, j: usize) -> Entry {
        let h = self.heads[i as usize];
        debug_assert!(j < h.len());
        let (p, e) = split(h.off);
        self.pages[p][e + j]
    }

    /// The entries of list `i`. A loop that pushes onto other lists while it reads one reads
    /// by index ([`WatchLists::get`]) instead.
    #[inline]
    pub(super) fn slice(&self, i: u32) -> &[Entry] {
        let h = self.heads[i as usize];
        if h.class() == 0 {
            return &[];
        }
        let (p, e) = split(h.off);
        &self.pages[p][e..e + h.len()]
    }

    /// The lengths of every list, in order.
    pub(super) fn lens(&self) -> impl Iterator<Item = u32> + '_ {
        self.heads.iter().map(|h| h.len() as u32)
    }

    /// Appends `e` to list `i`. A list without a block gets one of `first` entries (a power
    /// of two); a full one moves to a block of four entries, then to one twice its size.
    #[inline]
    pub(super) fn push(&mut self, i: u32, e: Entry, first: usize) {
        let h = self.heads[i as usize];
        let n = h.len();
        if n == h.capacity() {
            self.grow(i, first);
        }
        let h = &mut self.heads[i as usize];
        let (p, at) = split(h.off);
        self.pages[p][at + n] = e;
        h.len += 1;
    }

    /// Moves full list `i` to a larger block.
    #[cold]
    fn grow(&mut self, i: u32, first: usize) {
        let h = self.heads[i as usize];
        let (n, k) = (h.len(), h.class());
        let new_k = if k == 0 {
            class_for(first.max(1))
        } else {
            (k + 1).max(class_for(4))
        };
        assert!(
            new_k < CLASSES,
            "a watch list of {n} entries: over the limit"
        );
        let off = self.alloc(new_k);
        if n > 0 {
            let ((pf, f), (pt, t)) = (split(h.off), split(off));
            if pf == pt {
                self.pages[pf].copy_within(f..f + n, t);
            } else {
                let (lo, hi) = self.pages.split_at_mut(pf.max(pt));
                let (src, dst) = if pf < pt {
                    (&lo[pf], &mut hi[0])
                } else {
                    (&hi[0], &mut lo[pt])
                };
                dst[t..t + n].copy_from_slice(&src[f..f + n]);
            }
        }
        if k != 0 {
            self.release(h.off, k);
        }
        self.heads[i as usize] = Head {
            off,
            len: (new_k as u32) << LEN_BITS | n as u32,
        };
    }

    /// A block of class `k`: the first free one, else the first part of the smallest free
    /// larger one within a page (the rest goes to the free lists), else a new one.
    fn alloc(&mut self, k: usize) -> u32 {
        let size = capacity(k);
        let larger = self.has_free >> k;
        if larger != 0 {
            let j = k + larger.trailing_zeros() as usize;
            if j == k || capacity(j) <= PAGE {
                let b = self.take(j);
                // The rest of the block: blocks of `size`, `2 size`, ... half of it.
                for c in k..j {
                    self.release(b + capacity(c) as u32, c);
                }
                return b;
            }
        }
        if size > PAGE {
            // Pages of its own.
            let p = self.new_pages(size / PAGE);
            self.pages[p] = vec![(0, 0); size].into_boxed_slice();
            return (p << PAGE_BITS) as u32;
        }
        if self.end - self.next < size {
            // What the last page has left goes to the free lists, in blocks of powers of
            // two (none straddles a page).
            while self.next < self.end {
                let s = 1 << (self.end - self.next).ilog2();
                self.release(self.next as u32, class_for(s));
                self.next += s;
            }
            let p = self.new_pages(1);
            self.pages[p] = vec![(0, 0); PAGE].into_boxed_slice();
            self.next = p << PAGE_BITS;
            self.end = self.next + PAGE;
        }
        let off = self.next;
        self.next += size;
        off as u32
    }

    /// Appends `n` empty pages; returns the first's index.
    fn new_pages(&mut self, n: usize) -> usize {
        let p = self.pages.len();
        assert!(
            p + n <= MAX_PAGES,
            "the watch lists' slab is over 2^32 entries"
        );
        self.pages.resize_with(p + n, Default::default);
        p
    }

    /// The first free block of class `k` (there is one), off its free list.
    #[inline]
    fn take(&mut self, k: usize) -> u32 {
        let b = self.free[k];
        let (p, e) = split(b);
        self.free[k] = self.pages[p][e].0;
        if self.free[k] == NONE {
            self.has_free &= !(1 << k);
        }
        b
    }

    /// Puts block `off` of class `k` on its free list.
    #[inline]
    fn release(&mut self, off: u32, k: usize) {
        let (p, e) = split(off);
        self.pages[p][e].0 = self.free[k];
        self.free[k] = off;
        self.has_free |= 1 << k;
    }

    /// Removes the last entry of list `i` (its block stays).
    #[inline]
    pub(super) fn pop(&mut self, i: u32) {
        let h = &mut self.heads[i as usize];
        debug_assert!(h.len() > 0, "pop of an empty watch list");
        h.len -= 1;
    }

    /// Cuts list `i` to its first `n` entries (its block stays).
    #[inline]
    pub(super) fn truncate(&mut self, i: u32, n: usize) {
        let h = &mut self.heads[i as usize];
        if n < h.len() {
            h.len = h.len & !LEN_MASK | n as u32;
        }
    }

    /// Empties list `i` and gives its block back for other lists.
    pub(super) fn free(&mut self, i: u32) {
        let h = std::mem::take(&mut self.heads[i as usize]);
        if h.class() != 0 {
            self.release(h.off, h.class());
        }
    }

    /// Keeps the first `keep` entries of list `i` and, of the others, those `live` accepts,
    /// in their order.
    #[inline]
    pub(super) fn retain_from(&mut self, i: u32, keep: usize, live: impl Fn(Entry) -> bool) {
        let h = self.heads[i as usize];
        let n = h.len();
        if n <= keep {
            return;
        }
        let (p, e) = split(h.off);
        let list = &mut self.pages[p][e..e + n];
        let mut w = keep;
        for r in keep..n {
            let x = list[r];
            if live(x) {
                list[w] = x;
                w += 1;
            }
        }
        self.truncate(i, w);
    }

    /// Entries the slab's pages hold (for tests).
    #[cfg(test)]
    fn slab_len(&self) -> usize {
        self.pages.iter().map(|p| p.len()).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `Vec` per list as the oracle: pushes, pops, truncations, frees and retains in a
    /// seeded random order give the same lists, and freed blocks are reused.
    #[test]
    fn the_slab_holds_what_a_vec_per_list_holds() {
        let n = 37;
        let mut lists = WatchLists::new(30, n - 30);
        let mut oracle: Vec<Vec<Entry>> = vec![Vec::new(); n];
        let mut x: u64 = 0x2545_f491_4f6c_dd1d;
        let mut next = |m: u64| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x % m
        };
        for step in 0..200_000u32 {
            let i = next(n as u64) as u32;
            let o = &mut oracle[i as usize];
            match next(10) {
                0..=5 => {
                    let e = (step, next(1000) as u32);
                    lists.push(i, e, if step % 2 == 0 { 1 } else { 4 });
                    o.push(e);
                }
                6 => {
                    if !o.is_empty() {
                        lists.pop(i);
                        o.pop();
                    }
                }
                7 => {
                    let k = next(o.len() as u64 + 1) as usize;
                    lists.truncate(i, k);
                    o.truncate(k);
                }
                8 => {
                    if next(8) == 0 {
                        lists.free(i);
                        o.clear();
                    }
                }
                _ => {
                    let keep = next(o.len() as u64 + 1) as usize;
                    let live = |e: Entry| !e.1.is_multiple_of(3);
                    lists.retain_from(i, keep, live);
                    let mut k = 0;
                    o.retain(|&e| {
                        k += 1;
                        k <= keep || live(e)
                    });
                }
            }
            assert_eq!(lists.slice(i), &o[..], "list {i} after step {step}");
        }
        for i in 0..n as u32 {
            assert_eq!(lists.slice(i), &oracle[i as usize][..]);
            assert_eq!(lists.len(i), oracle[i as usize].len());
            for j in 0..lists.len(i) {
                assert_eq!(lists.get(i, j), oracle[i as usize][j]);
            }
        }
        // Without reuse the slab would hold every block ever made.
        let live: usize = (0..n as u32)
            .map(|i| lists.heads[i as usize].capacity())
            .sum();
        assert!(
            lists.slab_len() < 4 * live + 2 * PAGE,
            "slab {} for {live} entries of blocks",
            lists.slab_len()
        );
    }

    #[test]
    fn blocks_grow_one_four_then_double() {
        let mut lists = WatchLists::new(1, 1);
        lists.push(0, (1, 1), 1);
        assert_eq!(lists.heads[0].capacity(), 1);
        lists.push(0, (2, 2), 1);
        assert_eq!(lists.heads[0].capacity(), 4);
        for k in 0..3 {
            lists.push(0, (k, k), 1);
        }
        assert_eq!(lists.heads[0].capacity(), 8);
        assert_eq!(lists.root(0), 1);
        lists.push(1, (9, 9), 4);
        assert_eq!(lists.heads[1].capacity(), 4);
        // A freed block is taken by the next list that needs one of its class.
        lists.free(1);
        let before = lists.slab_len();
        lists.push(1, (3, 3), 4);
        assert_eq!(lists.slab_len(), before, "list 1's freed block reused");
        assert_eq!(lists.slice(0), &[(1, 1), (2, 2), (0, 0), (1, 1), (2, 2)]);
    }

    /// A list longer than a page moves to pages of its own and back to reused blocks;
    /// the small lists around it keep their entries.
    #[test]
    fn a_list_longer_than_a_page() {
        let mut lists = WatchLists::new(3, 0);
        let n = 3 * PAGE + 5;
        for j in 0..n as u32 {
            lists.push(0, (j, 0), 1);
            if j % 1000 == 0 {
                lists.push(1, (j, 1), 4);
            }
        }
        assert_eq!(lists.heads[0].capacity(), 4 * PAGE);
        assert_eq!(lists.len(0), n);
        assert!((0..n).all(|j| lists.get(0, j) == (j as u32, 0)));
        assert_eq!(lists.len(1), n.div_ceil(1000));
        lists.retain_from(0, 2, |(c, _)| c % 2 == 1);
        assert_eq!(lists.len(0), 2 + (n - 2) / 2);
        assert_eq!(&lists.slice(0)[..4], &[(0, 0), (1, 0), (3, 0), (5, 0)]);
        // Its block, freed, is taken by the next list that grows to its class.
        let pages = lists.pages.len();
        lists.free(0);
        for j in 0..(2 * PAGE + 1) as u32 {
            lists.push(2, (j, 2), 4);
        }
        assert_eq!(lists.pages.len(), pages);
        assert!((0..lists.len(2)).all(|j| lists.get(2, j) == (j as u32, 2)));
        assert_eq!(lists.slice(1)[3], (3000, 1));
    }

    /// A block of a class with no free block is cut from a larger free one.
    #[test]
    fn a_larger_free_block_is_cut() {
        let mut lists = WatchLists::new(4, 0);
        for j in 0..9 {
            lists.push(0, (j, 0), 4);
        }
        assert_eq!(lists.heads[0].capacity(), 16);
        let used = lists.next;
        // List 0's blocks of 4 and 8 are free; freeing its 16 and taking four blocks of 4
        // and one of 8 takes no new room.
        lists.free(0);
        for i in 1..4 {
            for j in 0..5 {
                lists.push(i, (i, j), 4);
            }
        }
        lists.push(0, (7, 7), 4);
        assert_eq!(lists.next, used);
        assert_eq!(lists.slice(2), &[(2, 0), (2, 1), (2, 2), (2, 3), (2, 4)]);
        assert_eq!(lists.slice(0), &[(7, 7)]);
    }
}
