//! `uniform`: the first action of the best `horizon`-action sequence (the paper's section 4),
//! found by exact branch and bound.

use super::{HORIZON, Info, Params, Policy};
use crate::mesh::NONE;
use crate::search::Searcher;

/// The registry's entry.
pub static INFO: Info = Info {
    name: "uniform",
    about: "uniform look-ahead tree (exact branch and bound): first action of the best h-action sequence",
    params: &[HORIZON],
    random: false,
    builds_trees: true,
    search: true,
    rank: 2,
    policy: &Uniform,
};

#[derive(Debug)]
struct Uniform;

impl Policy for Uniform {
    fn run(&self, s: &mut Searcher<'_>, p: Params) -> Vec<u32> {
        s.uniform(p.horizon.unwrap_or(1).max(1));
        s.trees = s.state.quads() as u64;
        s.state.chosen().to_vec()
    }

    fn reads_eta_order(&self) -> bool {
        true
    }
}

impl Searcher<'_> {
    /// Uniform look-ahead tree of horizon `h` with exact branch and bound.
    fn uniform(&mut self, h: u32) {
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
            self.state.tree_begin();
            self.allowed_ranks.clear();
            self.allowed_scan = self.cursor;
            // Along allowed actions a forbidden action stays forbidden (docs/search.md,
            // "Forbidden stays forbidden"): every action of the tree is allowed at its root,
            // and the best of them bounds every step.
            let r = self.allowed_rank(0);
            if r == u32::MAX {
                break;
            }
            let top = self.state.table().eta[self.order[r as usize] as usize];
            // Rewards are never negative (eta lies in [0, 1]): a shorter sequence is worth
            // no more than the bound, and a node cut before its first child hides no leaf.
            debug_assert!(top >= 0.0, "a negative reward {top}");
            let mut best = f64::NEG_INFINITY;
            let mut first = NONE;
            self.uniform_dfs(0, h, 0.0, top, NONE, &mut best, &mut first);
            if first == NONE {
                break;
            }
            self.state.apply(first);
            // One tree per quad (the run's count, set again when it ends).
            self.trees += 1;
            let quads = self.state.quads();
            self.tick_decision(quads);
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

    /// Explores the node at depth `d` (partial reward `partial`, first action `root`):
    /// the root's allowed actions that are still allowed here, in decreasing eta, pruned when
    /// even `top` per remaining step cannot beat `best` (strictly: a sequence that only ties
    /// it would not replace it).
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
        let mut any = false;
        let mut cut = false;
        let mut expanded = false;
        let mut i = 0;
        loop {
            let r = self.allowed_rank(i);
            if r == u32::MAX {
                break;
            }
            i += 1;
            let c = self.order[r as usize];
            let eta = table.eta[c as usize];
            // In eta order: once the bound fails it fails for every later action, so no
            // verdict is needed to stop.
            if bound_below(partial + eta, h - d - 1, top) <= *best {
                cut = true;
                break;
            }
            if !self.state.tree_allowed(c) {
                continue;
            }
            any = true;
            if !expanded {
                expanded = true;
                self.count_node();
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
        if !any && !cut && d > 0 && partial > *best {
            // No action left: a shorter sequence is a leaf.
            *best = partial;
            *first = root;
        }
    }
}

/// The most that `steps` more rewards, each at most `top`, can add to `sum`, added one after
/// another as the tree adds them. Rounded addition is monotone in both operands, so no
/// sequence below comes out above it, not even by a rounding: a subtree whose bound is at
/// most `best` cannot improve on it (improvement is strict) and is cut, ties included. With
/// rewards of at least 0, a sequence that stops early is within the bound too.
fn bound_below(mut sum: f64, steps: u32, top: f64) -> f64 {
    for _ in 0..steps {
        sum += top;
    }
    sum
}
