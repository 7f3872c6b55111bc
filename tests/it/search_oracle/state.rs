//! The fast `search::state::State` against the naive oracle, on every mesh family.

use super::meshes::{self, Diagonals, Grid, Surfaces};
use super::sample_meshes;
use super::walk::{Subject, WalkConfig, WalkStats, walk};
use crate::util::SEED;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};
use quadrecomb::mesh::Mesh;
use quadrecomb::quality::CandidateTable;
use quadrecomb::search::state::State;

impl Subject for State<'_> {
    fn apply(&mut self, c: u32) {
        State::apply(self, c);
    }
    fn undo(&mut self) {
        State::undo(self);
    }
    fn is_allowed(&mut self, c: u32) -> bool {
        State::is_allowed(self, c)
    }
    fn allowed_count(&mut self, t: u32) -> u32 {
        State::allowed_count(self, t)
    }
    fn is_remaining(&mut self, t: u32) -> bool {
        State::is_remaining(self, t)
    }
    fn allowed_actions(&mut self) -> Vec<u32> {
        State::allowed_actions(self)
    }
    fn buckets(&mut self) -> Option<[Vec<u32>; 3]> {
        Some([1, 2, 3].map(|k| self.bucket(k).to_vec()))
    }
    fn min_k(&mut self) -> Option<Option<u32>> {
        Some(State::min_k(self))
    }
}

/// Walks a fresh state on `mesh` with each seed; panics with the oracle's report on the first
/// difference.
fn check_mesh(
    name: &str,
    mesh: &Mesh,
    seeds: std::ops::Range<u64>,
    config: WalkConfig,
) -> WalkStats {
    let table = CandidateTable::build(mesh);
    let mut total = WalkStats::default();
    for s in seeds {
        let seed = SEED ^ s;
        let mut state = State::new(mesh, &table);
        let stats =
            walk(name, mesh, &table, &mut state, seed, config).unwrap_or_else(|e| panic!("{e}"));
        if !table.is_empty() {
            assert!(stats.applies > 0, "{name}: the walk applied nothing");
        }
        total.checks += stats.checks;
        total.applies += stats.applies;
        total.undos += stats.undos;
    }
    total
}

#[test]
fn state_matches_oracle_on_hand_checked_cases() {
    for n in 1..=9 {
        check_mesh(
            &format!("strip({n})"),
            &meshes::strip(n),
            0..8,
            WalkConfig::default(),
        );
    }
    for surfaces in [
        &[1, 1, 1, 2, 2, 2][..],
        &[1, 2, 1, 1, 2, 2, 2, 1],
        &[1, 1, 2, 2, 2, 2, 2, 3, 3],
    ] {
        let mesh = meshes::strip_with_surfaces(surfaces);
        check_mesh(
            &format!("strip with surfaces {surfaces:?}"),
            &mesh,
            0..8,
            WalkConfig::default(),
        );
    }
    let mut flipped = Grid::plain(4, 4);
    flipped.flip = vec![(0, 3)];
    let mut alternating = Grid::plain(4, 4);
    alternating.diagonals = Diagonals::Alternating;
    for (name, spec) in [
        ("grid 4x4 rising", Grid::plain(4, 4)),
        ("grid 4x4 rising, cell (0, 3) flipped", flipped),
        ("grid 4x4 alternating", alternating),
    ] {
        check_mesh(name, &spec.build().unwrap(), 0..12, WalkConfig::default());
    }
}

#[test]
fn state_matches_oracle_on_sample_meshes() {
    // Grids with random diagonals, holes, dropped triangles, input quads, several surfaces;
    // an icosphere; random triangulations.
    let mut total = WalkStats::default();
    for (name, mesh) in sample_meshes(SEED) {
        let stats = check_mesh(&name, &mesh, 0..1, WalkConfig::default());
        total.checks += stats.checks;
    }
    assert!(total.checks > 1000, "{total:?}");
}

#[test]
fn state_matches_oracle_on_closed_icospheres() {
    check_mesh(
        "icosphere(0)",
        &meshes::icosphere(0),
        0..16,
        WalkConfig::default(),
    );
    check_mesh(
        "icosphere(1)",
        &meshes::icosphere(1),
        0..6,
        WalkConfig::default(),
    );
    check_mesh(
        "icosphere(2)",
        &meshes::icosphere(2),
        0..2,
        WalkConfig {
            explorations: 1,
            max_depth: 10,
        },
    );
}

#[test]
fn state_matches_oracle_deep_explorations() {
    // Explorations down to 30 actions, as a long horizon does.
    let mut spec = Grid::plain(8, 7);
    spec.jitter = 0.2;
    spec.diagonals = Diagonals::Random;
    spec.holes = 0.1;
    spec.drop = 0.03;
    spec.seed = SEED;
    check_mesh(
        &format!("{spec:?}"),
        &spec.build().unwrap(),
        0..3,
        WalkConfig {
            explorations: 3,
            max_depth: 30,
        },
    );
}

fn surfaces() -> impl Strategy<Value = Surfaces> {
    prop_oneof![
        Just(Surfaces::One),
        Just(Surfaces::Quadrants),
        (1..4usize).prop_map(Surfaces::Bands),
        (2..4i32).prop_map(Surfaces::RandomCells),
        (2..3i32).prop_map(Surfaces::RandomTriangles),
    ]
}

fn grids() -> impl Strategy<Value = Grid> {
    (
        1..9usize,
        1..9usize,
        prop_oneof![
            Just(Diagonals::Rising),
            Just(Diagonals::Alternating),
            Just(Diagonals::Random)
        ],
        prop_oneof![Just(0.0), 0.0..0.3f64],
        prop_oneof![Just(0.0), 0.0..0.15f64],
        prop_oneof![Just(0.0), 0.0..0.1f64],
        surfaces(),
        any::<u64>(),
    )
        .prop_map(
            |(nx, ny, diagonals, holes, drop, quads, surfaces, seed)| Grid {
                nx,
                ny,
                jitter: 0.2,
                diagonals,
                holes,
                drop,
                quads,
                surfaces,
                flip: Vec::new(),
                seed,
            },
        )
}

proptest! {
    #![proptest_config(Config {
        cases: 64,
        rng_seed: RngSeed::Fixed(SEED),
        failure_persistence: None,
        ..Config::default()
    })]

    #[test]
    fn state_matches_oracle_on_random_grids(spec in grids(), walk_seed in any::<u64>()) {
        if let Some(mesh) = spec.build() {
            let table = CandidateTable::build(&mesh);
            let mut state = State::new(&mesh, &table);
            let result = walk(&format!("{spec:?}"), &mesh, &table, &mut state, walk_seed, WalkConfig::default());
            prop_assert!(result.is_ok(), "{}", result.unwrap_err());
        }
    }

    #[test]
    fn state_matches_oracle_on_random_triangulations(
        points in 0..45usize,
        flips in 0..80usize,
        drop in prop_oneof![Just(0.0), 0.0..0.15f64],
        surfaces in 1..3i32,
        seed in any::<u64>(),
        walk_seed in any::<u64>(),
    ) {
        if let Some(mesh) = meshes::random_triangulation(points, flips, drop, surfaces, seed) {
            let name = format!("random_triangulation(points {points}, flips {flips}, drop {drop}, surfaces {surfaces}, seed {seed:#x})");
            let table = CandidateTable::build(&mesh);
            let mut state = State::new(&mesh, &table);
            let result = walk(&name, &mesh, &table, &mut state, walk_seed, WalkConfig::default());
            prop_assert!(result.is_ok(), "{}", result.unwrap_err());
        }
    }
}
