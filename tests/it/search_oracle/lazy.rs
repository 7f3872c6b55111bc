//! The state's lazy mode (as greedy uses it: `apply_lazy` marks verdicts that may have
//! changed, queries recheck what they touch, `resolve_all` makes everything exact) against the
//! naive oracle: partial queries after every lazy apply and undo, full comparison at decisions.

use super::meshes::{self, Diagonals, Grid};
use super::naive::Naive;
use super::sample_meshes;
use super::walk::{Subject, compare};

fn buckets(state: &mut State<'_>) -> Option<[Vec<u32>; 3]> {
    Subject::buckets(state)
}
use crate::util::SEED;
use quadrecomb::internals::mesh::{Mesh, NONE};
use quadrecomb::internals::quality::CandidateTable;
use quadrecomb::internals::search::state::State;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Lazy walk: explorations by `apply_lazy` / `undo` with a few lazy queries after each step
/// (random candidates and triangles, and those around the last quad, as the selective tree
/// asks), each checked against the oracle; at every decision `resolve_all` then a full
/// comparison; after each exploration is undone, a full comparison *without* `resolve_all`
/// (the trees read verdicts directly there). Returns the number of lazy queries checked.
fn lazy_walk(name: &str, mesh: &Mesh, seed: u64, max_depth: usize) -> Result<u64, String> {
    let table = CandidateTable::build(mesh);
    let mut state = State::new(mesh, &table);
    let mut oracle = Naive::new(mesh, &table);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let nt = mesh.num_triangles() as u32;
    let nc = table.len() as u32;
    let mut queries = 0u64;
    let ctx = |step: usize, what: &str| {
        format!("mesh {name}, lazy walk seed {seed:#x}, decision {step}, {what}")
    };
    let mut allowed = compare(&mut state, &oracle, &ctx(0, "initial state"))?.allowed_actions();
    let mut step = 0;
    while !allowed.is_empty() {
        for e in 0..rng.random_range(0..=2u32) {
            let before = buckets(&mut state);
            let depth_max = rng.random_range(1..=max_depth);
            let mut depth = 0;
            for op in 0..2 * depth_max {
                let here = oracle.verdicts().allowed_actions();
                let last;
                let what;
                if depth < depth_max && !here.is_empty() && (depth == 0 || rng.random_bool(0.7)) {
                    let c = here[rng.random_range(0..here.len())];
                    state.apply_lazy(c);
                    oracle.apply(c);
                    depth += 1;
                    last = c;
                    what = format!("exploration {e}, op {op}: after apply_lazy({c})");
                } else if depth > 0 {
                    let c = *oracle.path().last().unwrap();
                    state.undo();
                    oracle.undo();
                    depth -= 1;
                    last = c;
                    what = format!("exploration {e}, op {op}: after undo() of {c}");
                } else {
                    break;
                }
                // Lazy queries: random ones and those around the last quad.
                let mut cands: Vec<u32> = (0..4)
                    .filter(|_| nc > 0)
                    .map(|_| rng.random_range(0..nc))
                    .collect();
                let mut tris: Vec<u32> = (0..3).map(|_| rng.random_range(0..nt)).collect();
                for t in table.pairs[last as usize] {
                    for &u in &mesh.topology.neighbours[t as usize] {
                        if u != NONE && rng.random_bool(0.5) {
                            tris.push(u);
                            cands.extend(
                                table.by_triangle[u as usize].iter().filter(|&&d| d != NONE),
                            );
                        }
                    }
                }
                for c in cands {
                    let (got, expected) = (state.is_allowed_lazy(c), oracle.is_allowed(c));
                    queries += 1;
                    if got != expected {
                        return Err(format!(
                            "{}\n  path: {:?}\n  is_allowed_lazy({c}) (triangles {:?}): expected {expected}, got {got} ({:?})",
                            ctx(step, &what),
                            oracle.path(),
                            table.pairs[c as usize],
                            oracle.parts(c)
                        ));
                    }
                }
                for t in tris {
                    let expected = oracle.allowed_count(&table, t);
                    let got = state.allowed_count_lazy(t);
                    queries += 1;
                    if got != expected {
                        return Err(format!(
                            "{}\n  path: {:?}\n  allowed_count_lazy({t}): expected {expected}, got {got}",
                            ctx(step, &what),
                            oracle.path()
                        ));
                    }
                }
            }
            while depth > 0 {
                state.undo();
                oracle.undo();
                depth -= 1;
            }
            compare(
                &mut state,
                &oracle,
                &ctx(step, &format!("exploration {e} undone (no resolve_all)")),
            )?;
            if buckets(&mut state) != before {
                return Err(format!(
                    "{}: P_k bucket order not restored",
                    ctx(step, &format!("exploration {e} undone"))
                ));
            }
        }
        let c = allowed[rng.random_range(0..allowed.len())];
        state.apply_lazy(c);
        oracle.apply(c);
        state.resolve_all();
        step += 1;
        allowed = compare(
            &mut state,
            &oracle,
            &ctx(step, &format!("after apply_lazy({c}) and resolve_all()")),
        )?
        .allowed_actions();
    }
    while !oracle.path().is_empty() {
        let c = *oracle.path().last().unwrap();
        state.undo();
        oracle.undo();
        compare(
            &mut state,
            &oracle,
            &ctx(
                step,
                &format!("undoing the whole walk: after undo() of {c}"),
            ),
        )?;
    }
    Ok(queries)
}

#[test]
fn lazy_state_matches_oracle() {
    let mut queries = 0;
    for n in [5, 6, 9] {
        for s in 0..6 {
            queries += lazy_walk(&format!("strip({n})"), &meshes::strip(n), SEED ^ s, 10)
                .unwrap_or_else(|e| panic!("{e}"));
        }
    }
    for s in 0..6 {
        queries += lazy_walk(
            "grid 4x4 rising",
            &Grid::plain(4, 4).build().unwrap(),
            SEED ^ s,
            10,
        )
        .unwrap_or_else(|e| panic!("{e}"));
    }
    for (name, mesh) in sample_meshes(SEED ^ 0x1A2) {
        queries += lazy_walk(&name, &mesh, SEED, 10).unwrap_or_else(|e| panic!("{e}"));
    }
    let mut spec = Grid::plain(8, 7);
    spec.jitter = 0.2;
    spec.diagonals = Diagonals::Random;
    spec.holes = 0.1;
    spec.drop = 0.03;
    spec.seed = SEED ^ 0x1A3;
    let mesh = spec.build().unwrap();
    for s in 0..2 {
        queries +=
            lazy_walk(&format!("{spec:?}"), &mesh, SEED ^ s, 30).unwrap_or_else(|e| panic!("{e}"));
    }
    assert!(queries > 10_000, "{queries} lazy queries");
}
