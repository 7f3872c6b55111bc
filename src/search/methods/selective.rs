//! `selective`: the selective look-ahead tree (the paper's section 5) with exact branch and
//! bound; see docs/search.md for the draws.

use super::{HORIZON, Info, Params, Policy};
use crate::mesh::NONE;
use crate::search::Searcher;
use crate::search::policy::{BOUND_SLACK, node_key};
use rand::Rng;

/// The registry's entry.
pub static INFO: Info = Info {
    name: "selective",
    about: "selective look-ahead tree (the paper's drawing rule), horizon h",
    params: &[HORIZON],
    random: true,
    builds_trees: true,
    search: true,
    rank: 3,
    policy: &Selective,
};

#[derive(Debug)]
struct Selective;

impl Policy for Selective {
    fn run(&self, s: &mut Searcher<'_>, p: Params) -> Vec<u32> {
        s.selective(p.horizon.unwrap_or(1).max(1));
        s.state.chosen().to_vec()
    }
}

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
    /// Selective look-ahead tree of horizon `h`.
    fn selective(&mut self, h: u32) {
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
            self.tick_decision(quads);
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
        self.count_node();
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
}
