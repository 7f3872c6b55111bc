//! The budgeted policies (optimistic, mcts, beam) against exhaustive search over the same
//! branching, and against the naive criterion.
//!
//! Exhaustive search over the selective tree's branching is the selective tree itself: its
//! branch and bound is exact and `selective.rs` replays it node by node on the naive oracle.
//! With a budget that covers the whole tree to depth h, each budgeted policy must find the
//! same best leaf at every decision and so make the same run as selective h for the same seed
//! (same root draws, same tree keys; ties to the first root action in side order). With small
//! budgets, every action a run applies must be allowed, at its turn, by the naive criterion,
//! and a seed must give the same run again.

use super::naive::Naive;
use super::sample_meshes;
use crate::util::SEED;
use quadrecomb::internals::quality::CandidateTable;
use quadrecomb::internals::search::{Algo, Params, Searcher};

const BUDGETED: [&str; 3] = ["optimistic", "mcts", "beam"];

fn algo(name: &str, h: u32, b: u32) -> Algo {
    Algo::new(
        name,
        Params {
            horizon: Some(h),
            budget: Some(b),
        },
    )
    .expect("a registered method")
}

#[test]
fn a_covering_budget_finds_what_exhaustive_search_finds() {
    let mut decisions = 0;
    for (name, mesh) in sample_meshes(SEED) {
        let table = CandidateTable::build(&mesh);
        let mut s = Searcher::new(&mesh, &table);
        for h in [1u32, 2, 3] {
            for seed in 0..4u64 {
                let want = s.run(Algo::selective(h), seed);
                decisions += want.decisions;
                for p in BUDGETED {
                    // Beam's width is budget / h: 3^h children per level fit.
                    let got = s.run(algo(p, h, 1 << 20), seed);
                    assert_eq!(
                        got.chosen, want.chosen,
                        "{name}: {p} h={h} seed {seed} with a covering budget against selective h={h}"
                    );
                }
            }
        }
    }
    assert!(decisions > 100, "the meshes made decisions ({decisions})");
}

#[test]
fn small_budgets_apply_only_what_the_naive_criterion_allows_and_repeat() {
    for (name, mesh) in sample_meshes(SEED ^ 7) {
        let table = CandidateTable::build(&mesh);
        let mut s = Searcher::new(&mesh, &table);
        for p in BUDGETED {
            for (h, b) in [(3u32, 2u32), (5, 7), (10, 20)] {
                for seed in 0..3u64 {
                    let out = s.run(algo(p, h, b), seed);
                    let mut naive = Naive::new(&mesh, &table);
                    for &c in &out.chosen {
                        assert!(
                            naive.is_allowed(c),
                            "{name}: {p} h={h} b={b} seed {seed} applied {c}, forbidden by the naive criterion"
                        );
                        naive.apply(c);
                    }
                    let left = (0..table.len() as u32).any(|c| {
                        let [a, b] = table.pairs[c as usize];
                        naive.is_remaining(a) && naive.is_remaining(b) && naive.is_allowed(c)
                    });
                    assert!(!left, "{name}: {p} stopped with an allowed action left");
                    let again = s.run(algo(p, h, b), seed);
                    assert_eq!(again.chosen, out.chosen, "{name}: {p} seed {seed} repeats");
                }
            }
        }
    }
}
