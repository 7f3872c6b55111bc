//! The sets `P_1`, `P_2`, `P_3` (remaining triangles with exactly k allowed actions) as
//! counting Fenwick trees over triangle ids: O(log n) insert, remove, rank and select, so a
//! uniform draw takes the i-th member in increasing id order. The order is canonical: a draw
//! depends on the current state only, not on the path of applies and undos that reached it.

/// `P_1..P_3` over triangles `0..n`.
#[derive(Debug, Clone)]
pub(super) struct OrderedSets {
    /// `tree[k]`: Fenwick tree (1-based) of membership in `P_k`; `tree[0]` unused.
    tree: [Vec<u32>; 4],
    len: [u32; 4],
    /// Highest power of two not above `n` (select's first step).
    top: usize,
}

impl OrderedSets {
    /// Empty sets over triangles `0..n`.
    pub(super) fn new(n: usize) -> OrderedSets {
        let top = if n == 0 { 0 } else { 1 << n.ilog2() };
        OrderedSets {
            tree: [Vec::new(), vec![0; n + 1], vec![0; n + 1], vec![0; n + 1]],
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
        self.len[k] += 1;
        let f = &mut self.tree[k];
        let mut i = t as usize + 1;
        while i < f.len() {
            f[i] += 1;
            i += i & i.wrapping_neg();
        }
    }

    /// Removes triangle `t` from `P_k` (it must be there).
    #[inline]
    pub(super) fn remove(&mut self, k: usize, t: u32) {
        self.len[k] -= 1;
        let f = &mut self.tree[k];
        let mut i = t as usize + 1;
        while i < f.len() {
            f[i] -= 1;
            i += i & i.wrapping_neg();
        }
    }

    /// Number of members of `P_k` with id below `t`.
    pub(super) fn rank(&self, k: usize, t: u32) -> usize {
        let f = &self.tree[k];
        let mut i = (t as usize).min(f.len() - 1);
        let mut s = 0;
        while i > 0 {
            s += f[i] as usize;
            i &= i - 1;
        }
        s
    }

    /// The member of `P_k` with exactly `i` members below it (`i < len(k)`).
    pub(super) fn select(&self, k: usize, i: usize) -> u32 {
        debug_assert!(i < self.len(k));
        let f = &self.tree[k];
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
        pos as u32
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Random inserts and removes against a sorted vector: len, rank and select agree.
    #[test]
    fn matches_a_sorted_vector() {
        for n in [1usize, 2, 7, 64, 100, 1000] {
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
