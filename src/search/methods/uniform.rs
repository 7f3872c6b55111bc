//! `uniform`: the first action of the best `horizon`-action sequence (the paper's section 4),
//! found by exact branch and bound.

use super::{HORIZON, Info, Params, Policy};
use crate::mesh::NONE;
use crate::search::Searcher;
use crate::search::policy::BOUND_SLACK;

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
            // One tree per quad (the run's count, set again when it ends).
            self.trees += 1;
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
        self.extra[du] = extra;
        if !any && !cut && d > 0 && partial > *best {
            // No action left: a shorter sequence is a leaf.
            *best = partial;
            *first = root;
        }
    }
}
