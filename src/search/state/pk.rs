//! The sets `P_1`, `P_2`, `P_3` (remaining triangles with exactly k allowed actions) as
//! bitmaps over triangle ids with a counting Fenwick tree over blocks of 512 ids: O(1)
//! membership changes plus an O(log(n / 512)) walk over a tree small enough to stay in
//! cache, and rank and select in O(log(n / 512) + 8 words). A uniform draw takes the i-th
//! member in increasing id order. The order is canonical: a draw depends on the current
//! state only, not on the path of applies and undos that reached it.
//!
//! (A Fenwick tree over the ids themselves, the first version, touched about log2(n) cache
//! lines per change: on meshes of a million triangles, most of them misses.)

/// Ids per block: one cache line of bitmap words.
const BLOCK_BITS: usize = 512;
const WORDS_PER_BLOCK: usize = BLOCK_BITS / 64;

/// `P_1..P_3` over triangles `0..n`.
#[derive(Debug, Clone)]
pub(super) struct OrderedSets {
    /// `bits[k]`: membership in `P_k`, bit `t % 64` of word `t / 64`; `bits[0]` unused.
    bits: [Vec<u64>; 4],
    /// `blocks[k]`: Fenwick tree (1-based) of the members per block of `BLOCK_BITS` ids.
    blocks: [Vec<u32>; 4],
    len: [u32; 4],
    /// Highest power of two not above the number of blocks (select's first step).
    top: usize,
}

impl OrderedSets {
    /// Empty sets over triangles `0..n`.
    pub(super) fn new(n: usize) -> OrderedSets {
        let words = n.div_ceil(64);
        let nblocks = n.div_ceil(BLOCK_BITS);
        let top = if nblocks == 0 {
            0
        } else {
            1 << nblocks.ilog2()
        };
        let bits = || vec![0u64; words];
        let blocks = || vec![0u32; nblocks + 1];
        OrderedSets {
            bits: [Vec::new(), bits(), bits(), bits()],
            blocks: [Vec::new(), blocks(), blocks(), blocks()],
            len: [0; 4],
            top,
        }
    }

    /// Size of `P_k` (k in 1..=3).
    #[inline]
    pub(super) fn len(&self, k: usize) -> usize {
        self.len[k] as usize
    }

    /// Adds triangle `t` to `P_k` (it must not be there).
    #[inline]
    pub(super) fn insert(&mut self, k: usize, t: u32) {
        let t = t as usize;
        debug_assert!(
            self.bits[k][t / 64] & 1 << (t % 64) == 0,
            "{t} already in P_{k}"
        );
        self.bits[k][t / 64] |= 1 << (t % 64);
        self.len[k] += 1;
        let f = &mut self.blocks[k];
        let mut i = t / BLOCK_BITS + 1;
        while i < f.len() {
            f[i] += 1;
            i += i & i.wrapping_neg();
        }
    }

    /// Removes triangle `t` from `P_k` (it must be there).
    #[inline]
    pub(super) fn remove(&mut self, k: usize, t: u32) {
        let t = t as usize;
        debug_assert!(
            self.bits[k][t / 64] & 1 << (t % 64) != 0,
            "{t} not in P_{k}"
        );
        self.bits[k][t / 64] &= !(1 << (t % 64));
        self.len[k] -= 1;
        let f = &mut self.blocks[k];
        let mut i = t / BLOCK_BITS + 1;
        while i < f.len() {
            f[i] -= 1;
            i += i & i.wrapping_neg();
        }
    }

    /// Number of members of `P_k` with id below `t`.
    pub(super) fn rank(&self, k: usize, t: u32) -> usize {
        let words = &self.bits[k];
        let t = (t as usize).min(64 * words.len());
        // Whole blocks below t's block.
        let f = &self.blocks[k];
        let mut i = t / BLOCK_BITS;
        let mut s = 0;
        while i > 0 {
            s += f[i] as usize;
            i &= i - 1;
        }
        // Whole words of t's block below t's word, then t's word below t.
        let (w, b) = (t / 64, t % 64);
        for &x in &words[(t / BLOCK_BITS) * WORDS_PER_BLOCK..w] {
            s += x.count_ones() as usize;
        }
        if b > 0 {
            s += (words[w] & ((1u64 << b) - 1)).count_ones() as usize;
        }
        s
    }

    /// The member of `P_k` with exactly `i` members below it (`i < len(k)`).
    pub(super) fn select(&self, k: usize, i: usize) -> u32 {
        debug_assert!(i < self.len(k));
        // The block: Fenwick descent.
        let f = &self.blocks[k];
        let (mut pos, mut rest) = (0usize, i as u32);
        let mut step = self.top;
        while step > 0 {
            let next = pos + step;
            if next < f.len() && f[next] <= rest {
                pos = next;
                rest -= f[next];
            }
            step >>= 1;
        }
        // The word within block `pos`, then the bit within the word.
        let words = &self.bits[k];
        let mut w = pos * WORDS_PER_BLOCK;
        loop {
            let c = words[w].count_ones();
            if rest < c {
                break;
            }
            rest -= c;
            w += 1;
        }
        let mut x = words[w];
        for _ in 0..rest {
            x &= x - 1;
        }
        (64 * w + x.trailing_zeros() as usize) as u32
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Random inserts and removes against a sorted vector: len, rank and select agree (sizes
    /// across several blocks and a partial last block; the large ones checked now and then).
    #[test]
    fn matches_a_sorted_vector() {
        for n in [1usize, 2, 7, 64, 100, 1000, 1537, 5000] {
            let mut rng = ChaCha8Rng::seed_from_u64(n as u64);
            let mut sets = OrderedSets::new(n);
            let mut naive: [Vec<u32>; 4] = Default::default();
            for _ in 0..4 * n {
                let k = 1 + (rng.next_u32() % 3) as usize;
                let t = rng.next_u32() % n as u32;
                match naive[k].binary_search(&t) {
                    Ok(p) => {
                        naive[k].remove(p);
                        sets.remove(k, t);
                    }
                    Err(p) => {
                        naive[k].insert(p, t);
                        sets.insert(k, t);
                    }
                }
                if n > 1000 && rng.next_u32() % 64 != 0 {
                    continue;
                }
                for k in 1..4 {
                    assert_eq!(sets.len(k), naive[k].len());
                    for (i, &x) in naive[k].iter().enumerate() {
                        assert_eq!(sets.select(k, i), x);
                        assert_eq!(sets.rank(k, x), i);
                    }
                    assert_eq!(sets.rank(k, n as u32), naive[k].len());
                }
            }
        }
    }
}
