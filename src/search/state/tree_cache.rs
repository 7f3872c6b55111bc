//! The look-ahead tree's verdicts by candidate: a small open-addressing map sized to what
//! the current tree touched (a dense array over every candidate cost 24 bytes per
//! candidate for trees that touch few), emptied at each `tree_begin` in time proportional
//! to what the tree stored.

use crate::mesh::NONE;

/// One slot: a candidate (NONE: empty) and its entry.
#[derive(Debug, Clone, Copy)]
struct Slot<T> {
    c: u32,
    e: T,
}

/// Map from candidate to `T`; an absent candidate reads as `T::default()`. No removal:
/// entries are overwritten, and all dropped at once by [`CandMap::clear`].
#[derive(Debug, Clone)]
pub(super) struct CandMap<T> {
    slots: Vec<Slot<T>>,
    /// Indices of the occupied slots (what `clear` empties).
    used: Vec<u32>,
}

/// Slots of a new map (a power of two).
const FIRST: usize = 256;

impl<T: Copy + Default> CandMap<T> {
    pub(super) fn new() -> CandMap<T> {
        CandMap {
            slots: Vec::new(),
            used: Vec::new(),
        }
    }

    /// Home slot of `c` (Fibonacci hashing; `slots.len()` is a power of two).
    #[inline(always)]
    fn home(&self, c: u32) -> usize {
        let bits = self.slots.len().trailing_zeros();
        ((c as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) >> (64 - bits)) as usize
    }

    /// The entry of `c`, or `T::default()`.
    #[inline]
    pub(super) fn get(&self, c: u32) -> T {
        if self.slots.is_empty() {
            return T::default();
        }
        let mask = self.slots.len() - 1;
        let mut i = self.home(c);
        loop {
            let s = &self.slots[i];
            if s.c == c {
                return s.e;
            }
            if s.c == NONE {
                return T::default();
            }
            i = (i + 1) & mask;
        }
    }

    /// Sets the entry of `c`.
    #[inline]
    pub(super) fn set(&mut self, c: u32, e: T) {
        if 2 * (self.used.len() + 1) > self.slots.len() {
            self.grow();
        }
        let mask = self.slots.len() - 1;
        let mut i = self.home(c);
        loop {
            let s = &mut self.slots[i];
            if s.c == c {
                s.e = e;
                return;
            }
            if s.c == NONE {
                *s = Slot { c, e };
                self.used.push(i as u32);
                return;
            }
            i = (i + 1) & mask;
        }
    }

    /// Doubles the slots (at most half of them used) and puts the entries back.
    #[cold]
    fn grow(&mut self) {
        let n = (2 * self.slots.len()).max(FIRST);
        let empty = Slot {
            c: NONE,
            e: T::default(),
        };
        let old = std::mem::replace(&mut self.slots, vec![empty; n]);
        let used = std::mem::take(&mut self.used);
        for &i in &used {
            let s = old[i as usize];
            self.set(s.c, s.e);
        }
    }

    /// Drops every entry, in time proportional to their number.
    pub(super) fn clear(&mut self) {
        for &i in &self.used {
            self.slots[i as usize].c = NONE;
        }
        self.used.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use std::collections::HashMap;

    /// Against a `HashMap` oracle, through growth and clears.
    #[test]
    fn reads_what_was_set() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut m: CandMap<u64> = CandMap::new();
        let mut oracle = HashMap::new();
        for round in 0..6 {
            for _ in 0..(50 << round) {
                let c = rng.random_range(0..5000u32);
                if rng.random_bool(0.6) {
                    let v = rng.random::<u64>();
                    m.set(c, v);
                    oracle.insert(c, v);
                }
                assert_eq!(m.get(c), oracle.get(&c).copied().unwrap_or_default());
            }
            for c in 0..5000 {
                assert_eq!(m.get(c), oracle.get(&c).copied().unwrap_or_default());
            }
            m.clear();
            oracle.clear();
            assert!((0..5000).all(|c| m.get(c) == 0));
        }
    }
}
