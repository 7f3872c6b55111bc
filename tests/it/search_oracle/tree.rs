//! The look-ahead tree layer (`tree_begin`, `tree_push`, `tree_pop` and the queries the trees
//! make: `tree_allowed`, `tree_count`, `tree_near`, `tree_pick_pmin`) against the naive
//! oracle, after every push and pop of random explorations from every decision of random
//! walks; the base state must be untouched after each exploration.

use super::meshes::{self, Diagonals, Grid};
use super::naive::Naive;
use super::sample_meshes;
use super::walk::compare;
use crate::util::SEED;
use quadrecomb::internals::mesh::{Mesh, NONE};
use quadrecomb::internals::quality::{CandidateTable, Rule};
use quadrecomb::internals::search::state::State;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Allowed actions of `t` by the oracle (0 when used).
fn naive_count(oracle: &Naive, table: &CandidateTable, t: u32) -> u32 {
    if !oracle.is_remaining(t) {
        return 0;
    }
    table.by_triangle[t as usize]
        .iter()
        .filter(|&&c| c != NONE && oracle.is_allowed(c))
        .count() as u32
}

/// Bit i: action `by_triangle[t][i]` allowed, by the oracle.
fn naive_mask(oracle: &Naive, table: &CandidateTable, t: u32) -> u8 {
    let mut bits = 0;
    for (i, &c) in table.by_triangle[t as usize].iter().enumerate() {
        if c != NONE && oracle.is_remaining(t) && oracle.is_allowed(c) {
            bits |= 1 << i;
        }
    }
    bits
}

/// `P_min` by the oracle, in increasing id; `None` when no action is allowed.
fn naive_pmin(oracle: &Naive, table: &CandidateTable, nt: u32) -> Option<Vec<u32>> {
    let counts: Vec<u32> = (0..nt).map(|t| naive_count(oracle, table, t)).collect();
    let k = counts.iter().copied().filter(|&k| k > 0).min()?;
    Some((0..nt).filter(|&t| counts[t as usize] == k).collect())
}

/// Checks every tree query at the current node against the oracle.
pub(super) fn check_node(
    state: &mut State<'_>,
    oracle: &Naive,
    mesh: &Mesh,
    table: &CandidateTable,
    rng: &mut ChaCha8Rng,
    base_len: usize,
    context: &dyn Fn() -> String,
) -> Result<u64, String> {
    let tree_path = &oracle.path()[base_len..];
    let (nt, nc) = (mesh.num_triangles() as u32, table.len() as u32);
    let mut queries = 0;
    // Random candidates and triangles, and everything around the path's quads.
    let mut cands: Vec<u32> = (0..4).map(|_| rng.random_range(0..nc)).collect();
    let mut tris: Vec<u32> = (0..3).map(|_| rng.random_range(0..nt)).collect();
    for &c in tree_path {
        for n in state.quad_neighbours(c) {
            if n != NONE {
                tris.push(n);
                cands.extend(table.by_triangle[n as usize].iter().filter(|&&d| d != NONE));
            }
        }
    }
    // Ask in a random order: answers must not depend on what was asked before.
    for i in (1..cands.len()).rev() {
        cands.swap(i, rng.random_range(0..=i));
    }
    for c in cands {
        let (got, expected) = (state.tree_allowed(c), oracle.is_allowed(c));
        queries += 1;
        if got != expected {
            return Err(format!(
                "{}\n  tree_allowed({c}) (triangles {:?}): expected {expected}, got {got} ({:?})",
                context(),
                table.pairs[c as usize],
                oracle.parts(c)
            ));
        }
    }
    for t in tris {
        let got = (state.tree_count(t), state.tree_allowed_mask(t));
        let expected = (naive_count(oracle, table, t), naive_mask(oracle, table, t));
        queries += 2;
        if got != expected {
            return Err(format!(
                "{}\n  (tree_count({t}), tree_allowed_mask({t})): expected {expected:?}, got {got:?}",
                context()
            ));
        }
    }
    let slots = state.tree_near().to_vec();
    let expected: Vec<(u32, u8)> = tree_path
        .iter()
        .flat_map(|&c| state.quad_neighbours(c))
        .filter(|&n| n != NONE && oracle.is_remaining(n))
        .map(|n| (n, naive_count(oracle, table, n) as u8))
        .collect();
    let got: Vec<(u32, u8)> = slots.iter().map(|s| (s.t, s.k)).collect();
    for s in &slots {
        let expected = naive_mask(oracle, table, s.t);
        queries += 1;
        if s.allowed != expected {
            return Err(format!(
                "{}\n  tree_near(): triangle {} allowed actions {:#b}, expected {expected:#b}",
                context(),
                s.t,
                s.allowed
            ));
        }
    }
    queries += 1;
    if got != expected {
        return Err(format!(
            "{}\n  tree_near(): expected {expected:?}, got {got:?}",
            context()
        ));
    }
    if rng.random_bool(0.3) {
        let pmin = naive_pmin(oracle, table, nt);
        let mut asked = None;
        let mut draw = |n: usize| {
            let i = (n as u64 * 7919 % 977) as usize % n.max(1);
            asked = Some((n, i));
            i
        };
        let got = state.tree_pick_pmin(&mut draw);
        queries += 1;
        let expected = pmin.as_ref().map(|p| {
            let i = (p.len() as u64 * 7919 % 977) as usize % p.len();
            (p.len(), p[i])
        });
        let got = got.map(|t| (asked.expect("pick called").0, t));
        if got != expected {
            return Err(format!(
                "{}\n  tree_pick_pmin(): expected (|P_min|, triangle) {expected:?}, got {got:?}; P_min {pmin:?}",
                context()
            ));
        }
    }
    Ok(queries)
}

/// Random walk over decisions; at each, a few explorations by `tree_push` / `tree_pop`
/// (allowed actions, as the trees push) with every query checked after each step, then a
/// full comparison of the base state (which the tree must leave exact and untouched).
fn tree_walk(name: &str, mesh: &Mesh, seed: u64, max_depth: usize) -> Result<u64, String> {
    tree_walk_on(name, mesh, &CandidateTable::build(mesh), seed, max_depth)
}

/// [`tree_walk`] with the candidates of `table` (a restricted one: fewer pairs).
pub(super) fn tree_walk_on(
    name: &str,
    mesh: &Mesh,
    table: &CandidateTable,
    seed: u64,
    max_depth: usize,
) -> Result<u64, String> {
    let table = table.clone();
    let mut state = State::new(mesh, &table);
    let mut oracle = Naive::new(mesh, &table);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut queries = 0u64;
    let mut allowed = compare(&mut state, &oracle, "initial state")?.allowed_actions();
    let mut step = 0;
    while !allowed.is_empty() {
        state.tree_begin();
        let base_len = oracle.path().len();
        for e in 0..rng.random_range(1..=3u32) {
            let depth_max = rng.random_range(1..=max_depth);
            let mut depth = 0;
            for op in 0..2 * depth_max {
                let here = oracle.verdicts().allowed_actions();
                let what;
                if depth < depth_max && !here.is_empty() && (depth == 0 || rng.random_bool(0.7)) {
                    let c = here[rng.random_range(0..here.len())];
                    state.tree_push(c);
                    oracle.apply(c);
                    depth += 1;
                    what = format!("push({c})");
                } else if depth > 0 {
                    state.tree_pop();
                    let c = *oracle.path().last().unwrap();
                    oracle.undo();
                    depth -= 1;
                    what = format!("pop() of {c}");
                } else {
                    break;
                }
                let context = || {
                    format!(
                        "mesh {name}, tree walk seed {seed:#x}, decision {step}, exploration {e}, op {op}: after {what}\n  path: {:?}",
                        oracle.path()
                    )
                };
                queries += check_node(
                    &mut state, &oracle, mesh, &table, &mut rng, base_len, &context,
                )?;
            }
            while depth > 0 {
                state.tree_pop();
                oracle.undo();
                depth -= 1;
            }
        }
        let c = allowed[rng.random_range(0..allowed.len())];
        state.apply(c);
        oracle.apply(c);
        step += 1;
        allowed = compare(
            &mut state,
            &oracle,
            &format!("mesh {name}, tree walk seed {seed:#x}, decision {step}: after apply({c})"),
        )?
        .allowed_actions();
    }
    Ok(queries)
}

#[test]
fn tree_layer_matches_oracle() {
    let mut queries = 0;
    for n in [5, 6, 9] {
        for s in 0..4 {
            queries += tree_walk(&format!("strip({n})"), &meshes::strip(n), SEED ^ s, 6)
                .unwrap_or_else(|e| panic!("{e}"));
        }
    }
    for (name, mesh) in sample_meshes(SEED ^ 0x7E3) {
        for s in 0..2 {
            queries += tree_walk(&name, &mesh, SEED ^ s, 8).unwrap_or_else(|e| panic!("{e}"));
        }
    }
    let mut spec = Grid::plain(8, 7);
    spec.jitter = 0.2;
    spec.diagonals = Diagonals::Random;
    spec.holes = 0.1;
    spec.drop = 0.03;
    spec.seed = SEED ^ 0x7E4;
    let mesh = spec.build().unwrap();
    for s in 0..2 {
        queries +=
            tree_walk(&format!("{spec:?}"), &mesh, SEED ^ s, 12).unwrap_or_else(|e| panic!("{e}"));
    }
    assert!(queries > 10_000, "{queries} tree queries");
}

#[test]
fn tree_layer_matches_oracle_on_restricted_candidates() {
    // Polders under the valid-quad rule: the dual graph less the pairs dropped.
    let mut queries = 0;
    for (name, mesh) in sample_meshes(SEED ^ 0x7E5) {
        let table = CandidateTable::build(&mesh).restrict(&mesh, Rule::Valid { min_eta: 0.6 });
        queries += tree_walk_on(&format!("{name}, eta >= 0.6"), &mesh, &table, SEED, 8)
            .unwrap_or_else(|e| panic!("{e}"));
    }
    assert!(queries > 5_000, "{queries} tree queries");
}
