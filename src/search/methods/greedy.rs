//! `greedy`: the best allowed action each step (a uniform tree of horizon 1).

use super::{Info, Params, Policy};
use crate::mesh::NONE;
use crate::search::Searcher;

/// The registry's entry.
pub static INFO: Info = Info {
    name: "greedy",
    about: "decreasing eta among the allowed actions (a uniform tree of horizon 1)",
    params: &[],
    random: false,
    builds_trees: true,
    search: true,
    rank: 1,
    policy: &Greedy,
};

#[derive(Debug)]
struct Greedy;

impl Policy for Greedy {
    fn run(&self, s: &mut Searcher<'_>, _: Params) -> Vec<u32> {
        s.greedy();
        let quads = s.state.quads() as u64;
        (s.nodes, s.trees) = (quads, quads);
        s.state.chosen().to_vec()
    }

    fn reads_eta_order(&self) -> bool {
        true
    }
}

impl Searcher<'_> {
    /// Decreasing eta among allowed actions. The cursor passes used and forbidden actions
    /// for good; an action behind it is looked at again only when an action marked its
    /// verdict stale, so each step costs what changed, not a rescan.
    pub(in crate::internals::search) fn greedy(&mut self) {
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
            if quads.is_multiple_of(4096) {
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
}
