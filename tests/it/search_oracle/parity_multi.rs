//! Parity by the boundary with more than two parts (docs/search.md "Parity by the
//! boundary"): a quad that one dead component touches three or four times splits its polder
//! into one part per run of neighbours between those arcs, and each part's parity is read
//! off the edge weights of its own curve. Generated jittered grids under the valid-quad rule
//! (which drops pairs, leaving dead sides all over the grid: where such quads are common),
//! walked against the naive oracle in every mode; the counters say that the three- and
//! four-part verdicts were read off parities, not searched.

use super::meshes::{Diagonals, Grid};
use super::parity::forbidden_walks;
use super::tree::tree_walk_on;
use super::walk::{WalkConfig, walk};
use crate::util::SEED;
use quadrecomb::internals::mesh::Mesh;
use quadrecomb::internals::mesh::generate::{self, GridSpec};
use quadrecomb::internals::quality::{CandidateTable, Rule};
use quadrecomb::internals::search::state::State;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Jittered grids as `generate grid` makes them (one with holes), and the tests' own with
/// random diagonals.
fn grids() -> Vec<(String, Mesh)> {
    let mut out = Vec::new();
    for (k, holes) in [false, false, true].into_iter().enumerate() {
        let spec = GridSpec {
            triangles: 240,
            seed: SEED ^ (0x3A + k as u64),
            holes,
            ..GridSpec::default()
        };
        out.push((format!("{spec:?}"), generate::grid(spec)));
    }
    let spec = Grid {
        jitter: 0.24,
        diagonals: Diagonals::Random,
        seed: SEED ^ 0x3F,
        ..Grid::plain(11, 10)
    };
    out.push((format!("{spec:?}"), spec.build().expect("a grid")));
    out
}

/// The valid-quad rule (what `recombine` uses), a stricter threshold, and the rule with a
/// random cut on top.
fn tables(mesh: &Mesh, seed: u64) -> Vec<(String, CandidateTable)> {
    let full = CandidateTable::build(mesh);
    let valid = full.clone().restrict(mesh, Rule::Valid { min_eta: 0.0 });
    let mut rng = ChaCha8Rng::seed_from_u64(SEED ^ seed);
    let keep: Vec<bool> = (0..valid.len()).map(|_| !rng.random_bool(0.1)).collect();
    vec![
        ("valid quads".into(), valid.clone()),
        (
            "eta >= 0.4".into(),
            full.restrict(mesh, Rule::Valid { min_eta: 0.4 }),
        ),
        ("valid quads, 10 % cut".into(), valid.retain(&keep)),
    ]
}

#[test]
fn parity_reads_every_part_when_one_component_touches_a_quad_three_or_four_times() {
    let (mut multi, mut searches, mut parity) = ([0u64; 2], 0, 0);
    for (k, (name, mesh)) in grids().iter().enumerate() {
        for (tname, table) in tables(mesh, 0x60 + k as u64) {
            let name = format!("{name}, {tname}");
            // Apply/undo walks, as the trees make them, every answer compared with the
            // oracle after every step.
            let mut state = State::new(mesh, &table);
            walk(
                &name,
                mesh,
                &table,
                &mut state,
                SEED ^ 0x6C,
                WalkConfig::default(),
            )
            .unwrap_or_else(|e| panic!("{e}"));
            multi[0] += state.parity_multi[0];
            multi[1] += state.parity_multi[1];
            parity += state.parity_splits;
            searches += state.searches;
            // Forward mode (what the runs use), and actions the criterion forbids.
            let mut state = State::new(mesh, &table);
            state.set_forward(true);
            let forward = WalkConfig {
                explorations: 0,
                max_depth: 1,
                unwind: false,
            };
            for s in 0..2 {
                state.reset();
                walk(&name, mesh, &table, &mut state, SEED ^ 0x6E ^ s, forward)
                    .unwrap_or_else(|e| panic!("{e}"));
            }
            multi[0] += state.parity_multi[0];
            multi[1] += state.parity_multi[1];
            forbidden_walks(&name, mesh, &table, 1);
            tree_walk_on(&name, mesh, &table, SEED ^ 0x6F, 6).unwrap_or_else(|e| panic!("{e}"));
        }
    }
    // Each counter moves only on its own path: skipping the new reading (or reading the
    // parts of three or four only when two would do) leaves them at 0.
    assert!(multi[0] > 200, "only {} three-part splits read", multi[0]);
    assert!(multi[1] > 20, "only {} four-part splits read", multi[1]);
    assert!(parity > multi[0] + multi[1], "two-part splits read as well");
    assert!(
        searches < parity,
        "{searches} searches against {parity} splits read off parities"
    );
}
