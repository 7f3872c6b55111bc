//! `greedy-nocrit`: candidates in decreasing eta, taken when both triangles are free; the
//! criterion is ignored (the paper's "naive greedy").

use super::{Info, Params, Policy};
use crate::search::Searcher;

/// The registry's entry.
pub static INFO: Info = Info {
    name: "greedy-nocrit",
    about: "decreasing eta, no criterion (the paper's naive greedy)",
    params: &[],
    random: false,
    builds_trees: false,
    search: true,
    rank: 0,
    policy: &GreedyNocrit,
};

#[derive(Debug)]
struct GreedyNocrit;

impl Policy for GreedyNocrit {
    fn run(&self, s: &mut Searcher<'_>, _: Params) -> Vec<u32> {
        let chosen = s.greedy_nocrit();
        s.nodes = chosen.len() as u64;
        s.trees = chosen.len() as u64;
        chosen
    }

    fn reads_eta_order(&self) -> bool {
        true
    }
}

impl Searcher<'_> {
    /// Decreasing eta, no criterion.
    fn greedy_nocrit(&mut self) -> Vec<u32> {
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
}
