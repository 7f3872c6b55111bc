//! What the policies share (the context a [`super::methods::Policy`] runs in, beside the
//! state's own tree layer): the run's draws, the selective rule's triangle below the root
//! and its node keys, node counting with the progress tick, and the decision loop of the
//! policies that branch like the selective tree.

use super::Searcher;
use crate::mesh::NONE;
use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// Uniform pick in `0..n` (n > 0) from a ChaCha8 stream: the top 64 bits of `u64 * n`,
/// portable and the same on every platform.
fn pick_from(rng: &mut ChaCha8Rng, n: usize) -> usize {
    pick_with(rng.next_u64(), n)
}

/// Uniform pick in `0..n` (n > 0) from the 64-bit number `x`: the top 64 bits of `x * n`.
pub(super) fn pick_with(x: u64, n: usize) -> usize {
    ((x as u128 * n as u128) >> 64) as usize
}

/// The random number of the selective tree's node reached from the node keyed `parent` by
/// action `c`: SplitMix64's finaliser of `parent ^ (c + 1) * golden ratio`. Each node's draw
/// depends on its path alone, not on what the search explored before it, so pruning and
/// the order children are visited in cannot change any draw (or the decision).
pub(super) fn node_key(parent: u64, c: u32) -> u64 {
    let mut z = parent ^ (u64::from(c) + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Slack added to branch-and-bound upper bounds so that rounding never prunes a sequence
/// whose value could tie or beat the best (keeps the result identical to exhaustive search).
pub(super) const BOUND_SLACK: f64 = 1e-9;

impl Searcher<'_> {
    /// Uniform pick in `0..n` (n > 0) from the run's ChaCha8 stream, portable.
    pub(super) fn pick(&mut self, n: usize) -> usize {
        pick_from(&mut self.rng, n)
    }

    /// Moves the cursor past candidates that are no longer live (permanent on the main
    /// trajectory).
    pub(super) fn advance_cursor(&mut self) {
        while self.cursor < self.order.len() && !self.state.is_live(self.order[self.cursor]) {
            self.cursor += 1;
        }
    }

    /// The triangle to branch on below the root, with its allowed actions (bit i:
    /// `by_triangle[t][i]`): uniformly from the first non-empty `P_k ∩ N` (N: recombinable
    /// triangles across an edge of a quad of the path, in path then side order), else from
    /// `P_min` (in increasing id).
    pub(super) fn choose_triangle(&mut self, key: u64) -> Option<(u32, u8)> {
        self.near.clear();
        let mut kmin = u8::MAX;
        for slot in self.state.tree_near() {
            if slot.k == 0 || slot.k > kmin {
                continue;
            }
            if slot.k < kmin {
                kmin = slot.k;
                self.near.clear();
            }
            if !self.near.iter().any(|s| s.t == slot.t) {
                self.near.push(*slot);
            }
        }
        if !self.near.is_empty() {
            let i = pick_with(key, self.near.len());
            return Some((self.near[i].t, self.near[i].allowed));
        }
        let t = self.state.tree_pick_pmin(|n| pick_with(key, n))?;
        Some((t, self.state.tree_allowed_mask(t)))
    }

    /// Counts one node expanded (children generated) and reports progress every 2^8 nodes:
    /// often enough for deep trees, whose nodes cost more (uniform on `sphere`: about
    /// 0.5 ms a node at h = 20, 11 ms at h = 40), to be reported within a few seconds; a
    /// report without a callback is one branch.
    #[inline]
    pub(super) fn count_node(&mut self) {
        self.nodes += 1;
        if self.nodes & 0xFF == 0 {
            let quads = self.state.quads();
            self.tick(quads);
        }
    }

    /// The children of the current tree node keyed `key` by the selective rule (the
    /// triangle of [`Searcher::choose_triangle`], its allowed actions in side order) into
    /// `out` as `(action, eta)`; false (and `out` empty) when no action is allowed.
    pub(super) fn selective_children(&mut self, key: u64, out: &mut Vec<(u32, f64)>) -> bool {
        out.clear();
        let Some((t, allowed)) = self.choose_triangle(key) else {
            return false;
        };
        let table = self.state.table();
        for (i, c) in self.state.candidates_of(t).into_iter().enumerate() {
            if allowed & (1 << i) != 0 {
                out.push((c, table.eta[c as usize]));
            }
        }
        !out.is_empty()
    }

    /// Rebuilds in `path` the actions from the root to node `i` of an explicit tree
    /// (`link(j)`: node `j`'s action and parent, `u32::MAX` above the root's children) and
    /// pushes them onto the state's tree.
    pub(super) fn push_path_to(
        &mut self,
        path: &mut Vec<u32>,
        i: u32,
        link: impl Fn(u32) -> (u32, u32),
    ) {
        path.clear();
        let mut j = i;
        while j != u32::MAX {
            let (action, parent) = link(j);
            path.push(action);
            j = parent;
        }
        path.reverse();
        for &c in path.iter() {
            self.state.tree_push(c);
        }
    }

    /// Pops `n` actions off the state's tree.
    pub(super) fn pop_n(&mut self, n: usize) {
        for _ in 0..n {
            self.state.tree_pop();
        }
    }

    /// The decision loop of the policies that branch like the selective tree: each decision
    /// draws its root triangle uniformly from `P_min` with the run's stream; a triangle with
    /// a single allowed action gets it (no tree could change it); otherwise the tree's key
    /// is drawn, a tree begins, and `decide(searcher, key, children)` (the root's allowed
    /// actions with their eta, in side order) returns the action applied.
    pub(super) fn decide_each(
        &mut self,
        mut decide: impl FnMut(&mut Self, u64, &[(u32, f64)]) -> u32,
    ) {
        let table = self.state.table();
        let mut kids = Vec::with_capacity(3);
        while let Some(k) = self.state.min_k() {
            let n = self.state.bucket_len(k);
            let i = self.pick(n);
            let t = self.state.bucket_nth(k, i);
            kids.clear();
            for c in self.state.candidates_of(t) {
                if c != NONE && self.state.is_allowed(c) {
                    kids.push((c, table.eta[c as usize]));
                }
            }
            debug_assert!(
                !kids.is_empty(),
                "a triangle of P_min has an allowed action"
            );
            if kids.len() == 1 {
                self.state.apply(kids[0].0);
                continue;
            }
            self.nodes += 1;
            self.trees += 1;
            let quads = self.state.quads();
            self.tick_decision(quads);
            self.state.tree_begin();
            let key = self.rng.next_u64();
            let c = decide(self, key, &kids);
            debug_assert!(self.state.tree_allowed(c));
            self.state.apply(c);
        }
    }
}
