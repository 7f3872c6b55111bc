//! Forward mode as the policies run it — lazy applies (`apply_lazy`), lazy queries
//! (greedy's), look-ahead trees over the forward base (selective's) — on restricted tables,
//! against the naive oracle: where verdicts are kept or found again without a new version
//! (`keep_distinct`, `reinstall_distinct`) and their certificates rewritten in place.

use super::meshes::{Diagonals, Grid};
use super::naive::Naive;
use super::tree::check_node;
use super::walk::compare;
use crate::util::SEED;
use quadrecomb::internals::mesh::{Mesh, NONE};
use quadrecomb::internals::quality::{CandidateTable, Rule};
use quadrecomb::internals::search::state::State;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn walk(
    name: &str,
    mesh: &Mesh,
    table: &CandidateTable,
    state: &mut State<'_>,
    seed: u64,
) -> Result<u64, String> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut oracle = Naive::new(mesh, table);
    let (nt, nc) = (mesh.num_triangles() as u32, table.len() as u32);
    let mut queries = 0;
    let mut step = 0;
    compare(state, &oracle, &format!("{name} seed {seed:#x}: start"))?;
    loop {
        let allowed = oracle.verdicts().allowed_actions();
        if allowed.is_empty() {
            break;
        }
        let c = allowed[rng.random_range(0..allowed.len())];
        state.apply_lazy(c);
        oracle.apply(c);
        step += 1;
        let ctx = |what: &str| format!("{name} seed {seed:#x} step {step} apply_lazy({c}): {what}");
        // Lazy queries: a few random, and around the last quad (as greedy asks).
        let mut cands: Vec<u32> = (0..3).map(|_| rng.random_range(0..nc)).collect();
        for t in table.pairs[c as usize] {
            for &u in &mesh.topology.neighbours[t as usize] {
                if u != NONE && rng.random_bool(0.5) {
                    cands.extend(table.by_triangle[u as usize].iter().filter(|&&d| d != NONE));
                }
            }
        }
        for d in cands {
            let (got, exp) = (state.is_allowed_lazy(d), oracle.is_allowed(d));
            queries += 1;
            if got != exp {
                return Err(ctx(&format!("is_allowed_lazy({d}) {got}, expected {exp}")));
            }
        }
        let t = rng.random_range(0..nt);
        let exp = oracle.allowed_count(table, t);
        let got = state.allowed_count_lazy(t);
        if got != exp {
            return Err(ctx(&format!(
                "allowed_count_lazy({t}) {got}, expected {exp}"
            )));
        }
        if rng.random_bool(0.25) {
            state.tree_begin();
            compare(state, &oracle, &ctx("after tree_begin"))?;
            let base_len = oracle.path().len();
            for e in 0..rng.random_range(1..=2u32) {
                let depth_max = rng.random_range(1..=6);
                let mut depth = 0;
                for op in 0..2 * depth_max {
                    let here = oracle.verdicts().allowed_actions();
                    if depth < depth_max && !here.is_empty() && (depth == 0 || rng.random_bool(0.7))
                    {
                        let p = here[rng.random_range(0..here.len())];
                        state.tree_push(p);
                        oracle.apply(p);
                        depth += 1;
                    } else if depth > 0 {
                        state.tree_pop();
                        oracle.undo();
                        depth -= 1;
                    } else {
                        break;
                    }
                    let context = || {
                        ctx(&format!(
                            "tree exploration {e} op {op}, path {:?}",
                            oracle.path()
                        ))
                    };
                    queries +=
                        check_node(state, &oracle, mesh, table, &mut rng, base_len, &context)?;
                }
                while depth > 0 {
                    state.tree_pop();
                    oracle.undo();
                    depth -= 1;
                }
            }
        } else if rng.random_bool(0.2) {
            state.resolve_all();
            compare(state, &oracle, &ctx("after resolve_all"))?;
        }
    }
    state.resolve_all();
    compare(state, &oracle, &format!("{name} seed {seed:#x}: end"))?;
    Ok(queries)
}

#[test]
fn forward_lazy_applies_and_trees_match_oracle_on_restricted_tables() {
    // Jittered grids under the valid-quad rule at eta >= 0.5 and random cuts, three walks
    // from resets of one state and one without a copy of the initial state. Fails when a
    // reinstalled distinct verdict does not watch its new roots.
    let mut queries = 0;
    let mut rekept = 0;
    let mut kept = 0;
    for i in 0..3u64 {
        let mut spec = Grid::plain(16, 12);
        spec.jitter = 0.3;
        spec.diagonals = Diagonals::Random;
        spec.holes = 0.03 * i as f64;
        spec.seed = SEED ^ (0x16D1 + i);
        let mesh = spec.build().unwrap();
        let full = CandidateTable::build(&mesh);
        let mut rng = ChaCha8Rng::seed_from_u64(SEED ^ (0x16D5 + i));
        let keep: Vec<bool> = (0..full.len()).map(|_| rng.random_bool(0.8)).collect();
        let tables = [
            (
                "eta >= 0.5",
                full.clone().restrict(&mesh, Rule::Valid { min_eta: 0.5 }),
            ),
            ("80 %", full.retain(&keep)),
        ];
        for (what, table) in &tables {
            let name = format!("{spec:?}, {what}");
            let mut state = State::new(&mesh, table);
            state.set_forward(true);
            for s in 0..3u64 {
                state.reset();
                queries += walk(&name, &mesh, table, &mut state, SEED ^ 0x16E0 ^ s)
                    .unwrap_or_else(|e| panic!("{e}"));
            }
            rekept += state.distinct_rekept;
            kept += state.distinct_kept;
            let mut state = State::new(&mesh, table);
            state.set_forward_uncopied();
            queries += walk(&name, &mesh, table, &mut state, SEED ^ 0x16EF)
                .unwrap_or_else(|e| panic!("{e}"));
            rekept += state.distinct_rekept;
            kept += state.distinct_kept;
        }
    }
    eprintln!("forward lazy walks: {queries} queries, {kept} kept, {rekept} found again");
    assert!(
        rekept > 50 && queries > 1000,
        "the walks must exercise reinstalled verdicts: {rekept} of them, {queries} queries"
    );
}
