//! `optimum`: the exact maximum-weight matching (`search::optimum`), a method that is not a
//! search: exact, it runs once per mesh (sweeps solve it once and take it from their cache).

use super::{Info, Params, Policy};
use crate::search::Searcher;

/// The registry's entry.
pub static INFO: Info = Info {
    name: "optimum",
    about: "the exact optimum (maximum-weight matching with an LP certificate), solved once per mesh",
    params: &[],
    random: false,
    builds_trees: false,
    search: false,
    rank: 9,
    policy: &Optimum,
};

#[derive(Debug)]
struct Optimum;

impl Policy for Optimum {
    fn run(&self, s: &mut Searcher<'_>, _: Params) -> Vec<u32> {
        let opt = crate::search::optimum::solve(s.state.mesh, s.state.table);
        (s.nodes, s.trees) = (0, 0);
        opt.chosen
    }
}
