//! The policies: greedy without and with the criterion, the uniform look-ahead tree with
//! exact branch and bound, and the selective look-ahead tree. All explore by apply / undo.

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
fn pick_with(x: u64, n: usize) -> usize {
    ((x as u128 * n as u128) >> 64) as usize
}

/// The random number of the selective tree's node reached from the node keyed `parent` by
/// action `c`: SplitMix64's finaliser of `parent ^ (c + 1) * golden ratio`. Each node's draw
/// depends on its path alone, not on what the search explored before it, so pruning and
/// the order children are visited in cannot change any draw (or the decision).
fn node_key(parent: u64, c: u32) -> u64 {
    let mut z = parent ^ (u64::from(c) + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Slack added to branch-and-bound upper bounds so that rounding never prunes a sequence
/// whose value could tie or beat the best (keeps the result identical to exhaustive search).
const BOUND_SLACK: f64 = 1e-9;

/// Branch and bound of one selective tree: the best leaf value found so far (rewards summed
/// from the root, in path order). Rewards are at most 1, so a node at depth `d` whose path
/// sums to `partial` has no leaf above `partial + (h - d)`; when that is below the best
/// (by more than `BOUND_SLACK`, which covers the rounding of sums taken in another order),
/// nothing below it can be the best, nor tie with it.
struct Bound {
    h: u32,
    best: f64,
}

impl Bound {
    fn new(h: u32) -> Bound {
        Bound {
            h,
            best: f64::NEG_INFINITY,
        }
    }

    fn leaf(&mut self, value: f64) {
        if value > self.best {
            self.best = value;
        }
    }

    fn prunes(&self, partial: f64, d: u32) -> bool {
        partial + f64::from(self.h - d) + BOUND_SLACK < self.best
    }
}

impl Searcher<'_> {
    /// Uniform pick in `0..n` (n > 0) from the run's ChaCha8 stream, portable.
    fn pick(&mut self, n: usize) -> usize {
        pick_from(&mut self.rng, n)
    }

    /// Moves the cursor past candidates that are no longer live (permanent on the main
    /// trajectory).
    fn advance_cursor(&mut self) {
        while self.cursor < self.order.len() && !self.state.is_live(self.order[self.cursor]) {
            self.cursor += 1;
        }
    }

    /// Decreasing eta, no criterion.
    pub(super) fn greedy_nocrit(&mut self) -> Vec<u32> {
        let table = self.state.table;
        self.used.iter_mut().for_each(|u| *u = false);
        let mut chosen = Vec::new();
        for &c in &self.order {
            let [a, b] = table.pairs[c as usize];
            if !self.used[a as usize] && !self.used[b as usize] {
                self.used[a as usize] = true;
                self.used[b as usize] = true;
                chosen.push(c);
            }
        }
        chosen
    }

    /// Decreasing eta among allowed actions. The cursor passes used and forbidden actions
    /// for good; an action behind it is looked at again only when an action marked its
    /// verdict stale, so each step costs what changed, not a rescan.
    pub(super) fn greedy(&mut self) {
        self.revisit.clear();
        let mut seen = self.state.dirty_since(0).len();
        loop {
            let mut next = NONE;
            while let Some(&std::cmp::Reverse(r)) = self.revisit.peek() {
                self.revisit.pop();
                let c = self.order[r as usize];
                if self.state.is_allowed_lazy(c) {
                    next = c;
                    break;
                }
            }
            if next == NONE {
                while self.cursor < self.order.len() {
                    let c = self.order[self.cursor];
                    self.cursor += 1;
                    if self.state.is_allowed_lazy(c) {
                        next = c;
                        break;
                    }
                }
            } else {
                // A revisited action wins only if it comes before everything ahead.
                debug_assert!((self.rank[next as usize] as usize) < self.cursor);
            }
            if next == NONE {
                break;
            }
            self.state.apply_lazy(next);
            let quads = self.state.quads();
            if quads % 4096 == 0 {
                self.tick(quads);
            }
            let fresh = self.state.dirty_since(seen);
            seen += fresh.len();
            for &c in fresh {
                let r = self.rank[c as usize];
                if (r as usize) < self.cursor {
                    self.revisit.push(std::cmp::Reverse(r));
                }
            }
        }
    }

    /// Uniform look-ahead tree of horizon `h` with exact branch and bound.
    pub(super) fn uniform(&mut self, h: u32) {
        if h == 1 {
            // The best sequence of one action is the best allowed action: greedy, which
            // keeps the base state lazy (the tree would resolve every verdict each step).
            self.greedy();
            self.nodes += self.state.quads() as u64;
            return;
        }
        loop {
            self.advance_cursor();
            if self.cursor == self.order.len() {
                break;
            }
            // Rewards only fall as triangles are used: the best live eta bounds every step.
            let top = self.state.table().eta[self.order[self.cursor] as usize];
            let mut best = f64::NEG_INFINITY;
            let mut first = NONE;
            self.state.tree_begin();
            self.allowed_ranks.clear();
            self.allowed_scan = self.cursor;
            self.uniform_dfs(0, h, 0.0, top, NONE, &mut best, &mut first);
            if first == NONE {
                break;
            }
            self.state.apply(first);
            let quads = self.state.quads();
            self.tick(quads);
        }
    }

    /// The rank of the `i`-th action allowed at the root of the current uniform tree (from
    /// the cursor), or `u32::MAX` past the last; found lazily (the root's verdicts stay
    /// readable inside the tree).
    fn allowed_rank(&mut self, i: usize) -> u32 {
        while self.allowed_ranks.len() <= i {
            if self.allowed_scan >= self.order.len() {
                return u32::MAX;
            }
            let r = self.allowed_scan;
            self.allowed_scan += 1;
            if self.state.is_allowed(self.order[r]) {
                self.allowed_ranks.push(r as u32);
            }
        }
        self.allowed_ranks[i]
    }

    /// Explores the node at depth `d` (partial reward `partial`, first action `root`);
    /// children in decreasing eta, pruned when even `top` per remaining step cannot beat
    /// `best` (strictly).
    #[allow(clippy::too_many_arguments)]
    fn uniform_dfs(
        &mut self,
        d: u32,
        h: u32,
        partial: f64,
        top: f64,
        root: u32,
        best: &mut f64,
        first: &mut u32,
    ) {
        let table = self.state.table();
        let rest = (h - d - 1) as f64 * top;
        let mut any = false;
        let mut cut = false;
        let mut expanded = false;
        // Ranks to look at, in order: the actions allowed at the root and, below it, the
        // actions forbidden at the root that the path may have allowed (every other action
        // reads as at the root: `tree_affected`).
        let du = d as usize;
        if self.extra.len() <= du {
            self.extra.resize_with(du + 1, Vec::new);
        }
        let mut extra = std::mem::take(&mut self.extra[du]);
        extra.clear();
        if d > 0 {
            self.state.tree_affected(&mut extra);
            let (state, rank, cursor) = (&self.state, &self.rank, self.cursor);
            // An action whose reward cannot beat `best` now never will (`best` only grows,
            // and the loop below stops at the first such action in eta order): leave it out
            // before sorting.
            let floor = *best - partial - rest - BOUND_SLACK;
            extra.retain(|&c| {
                table.eta[c as usize] > floor
                    && !state.is_allowed(c)
                    && rank[c as usize] as usize >= cursor
            });
            extra.iter_mut().for_each(|c| *c = rank[*c as usize]);
            extra.sort_unstable();
            extra.dedup();
        }
        let (mut i, mut j) = (0, 0);
        loop {
            let a = self.allowed_rank(i);
            let b = extra.get(j).copied().unwrap_or(u32::MAX);
            if a == u32::MAX && b == u32::MAX {
                break;
            }
            let r = if a < b {
                i += 1;
                a
            } else {
                j += 1;
                b
            };
            let c = self.order[r as usize];
            let eta = table.eta[c as usize];
            // In eta order: once the bound fails it fails for every later action, allowed
            // or not, so no verdict is needed to stop.
            if partial + eta + rest + BOUND_SLACK <= *best {
                cut = true;
                break;
            }
            if !self.state.tree_allowed(c) {
                continue;
            }
            any = true;
            if !expanded {
                expanded = true;
                self.nodes += 1;
                if self.nodes & 0xFFFF == 0 {
                    let quads = self.state.quads();
                    self.tick(quads);
                }
            }
            let r = if d == 0 { c } else { root };
            if d + 1 == h {
                let v = partial + eta;
                if v > *best {
                    *best = v;
                    *first = r;
                }
            } else {
                self.state.tree_push(c);
                self.uniform_dfs(d + 1, h, partial + eta, top, r, best, first);
                self.state.tree_pop();
            }
        }
        self.extra[du] = extra;
        if !any && !cut && d > 0 && partial > *best {
            // No action left: a shorter sequence is a leaf.
            *best = partial;
            *first = root;
        }
    }

    /// Selective look-ahead tree of horizon `h`.
    pub(super) fn selective(&mut self, h: u32) {
        let table = self.state.table();
        while let Some(k) = self.state.min_k() {
            let n = self.state.bucket_len(k);
            let i = self.pick(n);
            let t = self.state.bucket_nth(k, i);
            if k == 1 {
                // One allowed action: no tree can change the decision, so none is built.
                let c = self
                    .state
                    .candidates_of(t)
                    .into_iter()
                    .find(|&c| c != NONE && self.state.is_allowed(c))
                    .expect("a triangle of P_1 has an allowed action");
                self.state.apply(c);
                continue;
            }
            self.nodes += 1;
            self.trees += 1;
            let quads = self.state.quads();
            self.tick(quads);
            self.state.tree_begin();
            let key = self.rng.next_u64();
            // Children in decreasing reward, so good leaves come first and bound the rest;
            // ties between the root's children still go to the first in `by_triangle`.
            let mut kids = [(-1.0, 0, NONE); 3];
            for (slot, c) in self.state.candidates_of(t).into_iter().enumerate() {
                if c != NONE && self.state.is_allowed(c) {
                    kids[slot] = (table.eta[c as usize], slot, c);
                }
            }
            kids.sort_by(|a, b| b.0.total_cmp(&a.0));
            let mut bound = Bound::new(h);
            let (mut best, mut first, mut first_slot) = (f64::NEG_INFINITY, NONE, usize::MAX);
            for (eta, slot, c) in kids {
                if c == NONE {
                    break;
                }
                let v = eta + self.selective_child(c, key, 1, eta, &mut bound);
                if v > best || (v == best && slot < first_slot) {
                    (best, first, first_slot) = (v, c, slot);
                }
            }
            debug_assert!(first != NONE, "a triangle of P_min has an allowed action");
            self.state.apply(first);
        }
    }

    /// Value of the best leaf below the child reached by action `c` at depth `d` (the reward
    /// of `c` excluded), or minus infinity when `bound` proves that no leaf there can reach
    /// the best leaf found so far. `parent` is the key of the node `c` leaves, `partial` the
    /// rewards from the root down to `c` included.
    fn selective_child(
        &mut self,
        c: u32,
        parent: u64,
        d: u32,
        partial: f64,
        bound: &mut Bound,
    ) -> f64 {
        if d == bound.h {
            bound.leaf(partial);
            return 0.0;
        }
        if bound.prunes(partial, d) {
            return f64::NEG_INFINITY;
        }
        self.state.tree_push(c);
        let v = self.selective_node(node_key(parent, c), d, partial, bound);
        self.state.tree_pop();
        v
    }

    /// Best summed reward below the current node at depth `d < h`, keyed `key`.
    fn selective_node(&mut self, key: u64, d: u32, partial: f64, bound: &mut Bound) -> f64 {
        let table = self.state.table();
        let Some((t, allowed)) = self.choose_triangle(key) else {
            bound.leaf(partial);
            return 0.0;
        };
        self.nodes += 1;
        if self.nodes & 0xFFFF == 0 {
            let quads = self.state.quads();
            self.tick(quads);
        }
        let mut kids = [(-1.0, NONE); 3];
        for (i, c) in self.state.candidates_of(t).into_iter().enumerate() {
            if allowed & (1 << i) != 0 {
                kids[i] = (table.eta[c as usize], c);
            }
        }
        kids.sort_by(|a, b| b.0.total_cmp(&a.0));
        let mut best = f64::NEG_INFINITY;
        for (eta, c) in kids {
            if c == NONE {
                break;
            }
            let v = eta + self.selective_child(c, key, d + 1, partial + eta, bound);
            if v > best {
                best = v;
            }
        }
        best
    }

    /// The triangle to branch on below the root, with its allowed actions (bit i:
    /// `by_triangle[t][i]`): uniformly from the first non-empty `P_k ∩ N` (N: recombinable
    /// triangles across an edge of a quad of the path, in path then side order), else from
    /// `P_min` (in increasing id).
    fn choose_triangle(&mut self, key: u64) -> Option<(u32, u8)> {
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
}
