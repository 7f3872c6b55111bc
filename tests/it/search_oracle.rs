//! Oracle test of the search state: a naive implementation of the recombination criterion
//! (full BFS per action, [`naive`]) checked against the fast `search::state::State` after every
//! apply and every undo of many random apply/undo walks, on strips, grids with random
//! diagonals, holes, dropped triangles, input quads and several surfaces, icospheres and
//! random triangulations. The naive oracle itself is checked on hand-made cases and against a
//! second, global statement of the same rule.

mod audit;
mod budgeted;
mod forward_lazy;
mod lazy;
mod meshes;
mod naive;
mod parity;
mod parity_multi;
mod selective;
mod state;
mod tree;
mod walk;

use meshes::{Diagonals, Fin, Grid, Surfaces};
use naive::Naive;
use quadrecomb::internals::mesh::generate::{self, Corridor};
use quadrecomb::internals::mesh::{Mesh, MeshData, NONE};
use quadrecomb::internals::quality::CandidateTable;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use walk::{Subject, WalkConfig, walk};

use crate::util::SEED;

/// The candidate joining triangles `a` and `b`.
fn candidate(table: &CandidateTable, a: u32, b: u32) -> u32 {
    let key = [a.min(b), a.max(b)];
    table
        .pairs
        .iter()
        .position(|&p| p == key)
        .unwrap_or_else(|| panic!("no candidate joins {a} and {b}")) as u32
}

/// The forbidden actions (both triangles remaining, criterion says no), as triangle pairs.
fn forbidden_pairs(oracle: &Naive) -> Vec<[u32; 2]> {
    (0..oracle.num_candidates() as u32)
        .filter(|&c| {
            let [a, b] = oracle.pair(c);
            oracle.is_remaining(a) && oracle.is_remaining(b) && !oracle.is_allowed(c)
        })
        .map(|c| oracle.pair(c))
        .collect()
}

// ---------------------------------------------------------------------------------------------
// The oracle on its own: hand-checked cases.

#[test]
fn oracle_strip_of_six() {
    let mesh = meshes::strip(6);
    let table = CandidateTable::build(&mesh);
    assert_eq!(table.len(), 5);
    let oracle = Naive::new(&mesh, &table);
    for (a, b, allowed) in [
        (0, 1, true),
        (1, 2, false),
        (2, 3, true),
        (3, 4, false),
        (4, 5, true),
    ] {
        let c = candidate(&table, a, b);
        assert_eq!(
            oracle.is_allowed(c),
            allowed,
            "strip of 6, action ({a}, {b})"
        );
    }
    // Every triangle is in exactly one allowed action: all of them in P_1.
    assert_eq!(oracle.verdicts().count, vec![1; 6]);
}

#[test]
fn oracle_strip_of_five() {
    let mesh = meshes::strip(5);
    let table = CandidateTable::build(&mesh);
    let mut oracle = Naive::new(&mesh, &table);
    for c in 0..table.len() as u32 {
        assert!(
            oracle.is_allowed(c),
            "strip of 5, action {:?}",
            table.pairs[c as usize]
        );
    }
    assert_eq!(oracle.verdicts().count, vec![1, 2, 2, 2, 1]);
    // After (0, 1), the polder {2, 3, 4} is odd: both of its actions leave one odd part.
    oracle.apply(candidate(&table, 0, 1));
    let v = oracle.verdicts();
    assert_eq!(v.count, vec![0, 0, 1, 2, 1]);
    assert_eq!(
        v.allowed_actions(),
        vec![candidate(&table, 2, 3), candidate(&table, 3, 4)]
    );
    // After (1, 2) instead, {0} and {3, 4} are separate: only (3, 4) is an action.
    oracle.undo();
    oracle.apply(candidate(&table, 1, 2));
    assert_eq!(
        oracle.verdicts().allowed_actions(),
        vec![candidate(&table, 3, 4)]
    );
    assert_eq!(oracle.verdicts().count, vec![0, 0, 0, 1, 1]);
}

#[test]
fn oracle_surfaces_cut_the_dual_graph() {
    // Two surfaces of three triangles each: two odd polders, every action allowed, and no
    // candidate across the surface boundary.
    let mesh = meshes::strip_with_surfaces(&[1, 1, 1, 2, 2, 2]);
    let table = CandidateTable::build(&mesh);
    assert_eq!(table.len(), 4);
    assert!(!table.pairs.contains(&[2, 3]));
    let oracle = Naive::new(&mesh, &table);
    assert_eq!(oracle.odd_polders(), 2);
    assert_eq!(oracle.verdicts().allowed_actions().len(), 4);
    assert_eq!(oracle.verdicts().count, vec![1, 2, 1, 1, 2, 1]);
}

#[test]
fn oracle_single_triangles_have_no_action() {
    let mesh = meshes::strip_with_surfaces(&[1, 2, 3]);
    let table = CandidateTable::build(&mesh);
    assert!(table.is_empty());
    let oracle = Naive::new(&mesh, &table);
    assert_eq!(oracle.odd_polders(), 3);
    assert_eq!(oracle.verdicts().count, vec![0; 3]);
}

/// In the 4x4 grid of squares, the triangles with a single neighbour (corner triangles whose
/// two other sides lie on the boundary) and the actions that would isolate them.
fn isolating_actions(mesh: &Mesh, table: &CandidateTable) -> Vec<[u32; 2]> {
    let degree = |t: u32| {
        mesh.topology.neighbours[t as usize]
            .iter()
            .filter(|&&u| u != NONE)
            .count()
    };
    let mut out = Vec::new();
    for x in 0..mesh.num_triangles() as u32 {
        if degree(x) != 1 {
            continue;
        }
        let y = *mesh.topology.neighbours[x as usize]
            .iter()
            .find(|&&u| u != NONE)
            .unwrap();
        for &z in &mesh.topology.neighbours[y as usize] {
            if z != NONE && z != x {
                out.push(table.pairs[candidate(table, y, z) as usize]);
            }
        }
    }
    out.sort_unstable();
    out
}

#[test]
fn oracle_four_by_four_grid() {
    // Rising diagonals everywhere: the lower-right corner cell and the upper-left corner cell
    // each have a triangle with a single neighbour, so four actions isolate a corner triangle.
    let mesh = Grid::plain(4, 4).build().unwrap();
    assert_eq!(mesh.num_triangles(), 32);
    let table = CandidateTable::build(&mesh);
    let oracle = Naive::new(&mesh, &table);
    let mut forbidden = forbidden_pairs(&oracle);
    forbidden.sort_unstable();
    let expected = isolating_actions(&mesh, &table);
    assert_eq!(expected.len(), 4);
    assert_eq!(forbidden, expected);

    // Flip the upper-left corner cell: one corner triangle with a single neighbour is left,
    // and exactly the two actions that isolate it are forbidden.
    let mut spec = Grid::plain(4, 4);
    spec.flip = vec![(0, 3)];
    let mesh = spec.build().unwrap();
    let table = CandidateTable::build(&mesh);
    let oracle = Naive::new(&mesh, &table);
    let mut forbidden = forbidden_pairs(&oracle);
    forbidden.sort_unstable();
    let expected = isolating_actions(&mesh, &table);
    assert_eq!(expected.len(), 2);
    assert_eq!(forbidden, expected);

    // Alternating diagonals: no triangle with a single neighbour, every action allowed.
    let mut spec = Grid::plain(4, 4);
    spec.diagonals = Diagonals::Alternating;
    let mesh = spec.build().unwrap();
    let table = CandidateTable::build(&mesh);
    let oracle = Naive::new(&mesh, &table);
    assert!(isolating_actions(&mesh, &table).is_empty());
    assert!(forbidden_pairs(&oracle).is_empty());
}

#[test]
fn oracle_icosphere_is_closed_and_all_allowed_at_start() {
    let mesh = meshes::icosphere(1);
    assert_eq!(mesh.num_triangles(), 80);
    assert!(
        mesh.topology
            .neighbours
            .iter()
            .all(|n| n.iter().all(|&u| u != NONE))
    );
    let table = CandidateTable::build(&mesh);
    assert_eq!(table.len(), 120);
    // Removing two adjacent triangles of a closed 3-regular dual graph never disconnects it.
    let oracle = Naive::new(&mesh, &table);
    assert!(forbidden_pairs(&oracle).is_empty());
    assert_eq!(oracle.verdicts().count, vec![3; 80]);
}

/// The polder rule equals the global one ("the number of odd components of the whole remaining
/// graph does not increase") at every step of random walks on varied meshes.
#[test]
fn oracle_polder_rule_equals_global_rule() {
    let mut rng = ChaCha8Rng::seed_from_u64(SEED);
    for (name, mesh) in sample_meshes(SEED).into_iter().take(8) {
        let table = CandidateTable::build(&mesh);
        let mut oracle = Naive::new(&mesh, &table);
        let mut steps = 0;
        loop {
            let mut allowed = Vec::new();
            for c in 0..table.len() as u32 {
                let polder = oracle.is_allowed(c);
                assert_eq!(
                    polder,
                    oracle.is_allowed_globally(c),
                    "{name}: candidate {c} after {:?}",
                    oracle.path()
                );
                if polder {
                    allowed.push(c);
                }
            }
            if allowed.is_empty() || steps == 40 {
                break;
            }
            let before = oracle.odd_polders();
            oracle.apply(allowed[rng.random_range(0..allowed.len())]);
            assert_eq!(oracle.odd_polders(), before, "{name}: odd polders changed");
            steps += 1;
        }
    }
}

/// What the uniform tree's bound rests on: along allowed actions, a forbidden action stays
/// forbidden (proof in docs/search.md, "Forbidden stays forbidden"), in even and odd polders
/// alike. Random walks to the end on every sample mesh, each verdict from the naive oracle.
#[test]
fn oracle_forbidden_actions_stay_forbidden() {
    let mut rng = ChaCha8Rng::seed_from_u64(SEED ^ 0xF0);
    // Live forbidden actions seen, in even and in odd polders: the claim was put to the test.
    let (mut even, mut odd) = (0usize, 0usize);
    for (name, mesh) in sample_meshes(SEED) {
        let table = CandidateTable::build(&mesh);
        for _ in 0..3 {
            let mut oracle = Naive::new(&mesh, &table);
            let mut before = oracle.verdicts().allowed;
            loop {
                for c in 0..table.len() as u32 {
                    let [a, b] = oracle.pair(c);
                    if oracle.is_remaining(a) && oracle.is_remaining(b) && !before[c as usize] {
                        match oracle.polder(a).len() % 2 {
                            0 => even += 1,
                            _ => odd += 1,
                        }
                    }
                }
                let actions: Vec<u32> = (0..table.len() as u32)
                    .filter(|&c| before[c as usize])
                    .collect();
                if actions.is_empty() {
                    break;
                }
                oracle.apply(actions[rng.random_range(0..actions.len())]);
                let now = oracle.verdicts().allowed;
                for c in 0..table.len() {
                    assert!(
                        before[c] || !now[c],
                        "{name}: candidate {c} forbidden before {:?}, allowed after",
                        oracle.path()
                    );
                }
                before = now;
            }
        }
    }
    assert!(
        even > 1000 && odd > 100,
        "forbidden seen: {even} even, {odd} odd"
    );
}

#[test]
fn oracle_sample_meshes_cover_the_cases() {
    let all = sample_meshes(SEED);
    let odd = |m: &Mesh| Naive::new(m, &CandidateTable::build(m)).odd_polders();
    assert!(
        all.iter().any(|(_, m)| odd(m) > 0),
        "a mesh with odd components"
    );
    assert!(
        all.iter().any(|(_, m)| m.surfaces().len() > 1),
        "a mesh with several surfaces"
    );
    assert!(
        all.iter().any(|(_, m)| !m.quads.is_empty()),
        "a mesh with input quads"
    );
    assert!(
        all.iter()
            .any(|(_, m)| m.topology.component_sizes.len() > 3),
        "a mesh in pieces"
    );
    // Elements on each edge, counted apart from the library's topology.
    let most_on_an_edge = |m: &Mesh| {
        let mut on: std::collections::HashMap<(u32, u32), usize> = Default::default();
        for t in &m.triangles {
            for i in 0..3 {
                let (a, b) = (t[i], t[(i + 1) % 3]);
                *on.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
        on.into_values().max().unwrap_or(0)
    };
    assert!(
        all.iter().any(|(_, m)| most_on_an_edge(m) == 3),
        "a mesh with three surfaces' triangles on an edge"
    );
    assert!(
        all.iter().any(|(_, m)| most_on_an_edge(m) == 4),
        "a mesh with two surfaces' two triangles each on an edge"
    );
    assert!(
        all.iter().any(|(_, m)| m.num_triangles() >= 180),
        "a mesh of a couple of hundred triangles"
    );
    for (name, mesh) in &all {
        mesh.sanity_check()
            .unwrap_or_else(|e| panic!("{name}: {e}"));
    }
}

// ---------------------------------------------------------------------------------------------
// The harness catches wrong states: two plausible mistakes must be reported.

/// The old Definition 2: forbid every split that leaves an odd part, even in an odd polder.
#[derive(Debug)]
struct Strict(Naive);

impl Strict {
    fn allowed(&self, c: u32) -> bool {
        matches!(self.0.parts(c), Some((_, parts)) if parts.iter().all(|p| p % 2 == 0))
    }
}

impl Subject for Strict {
    fn apply(&mut self, c: u32) {
        self.0.apply(c);
    }
    fn undo(&mut self) {
        self.0.undo();
    }
    fn is_allowed(&mut self, c: u32) -> bool {
        self.allowed(c)
    }
    fn allowed_count(&mut self, t: u32) -> u32 {
        (0..self.0.num_candidates() as u32)
            .filter(|&c| self.0.pair(c).contains(&t) && self.allowed(c))
            .count() as u32
    }
    fn is_remaining(&mut self, t: u32) -> bool {
        self.0.is_remaining(t)
    }
    fn allowed_actions(&mut self) -> Vec<u32> {
        (0..self.0.num_candidates() as u32)
            .filter(|&c| self.allowed(c))
            .collect()
    }
}

/// Rechecks after an apply only the candidates within two dual steps of the quad: misses
/// verdicts that change far away (a split elsewhere in the polder).
#[derive(Debug)]
struct Local<'m> {
    mesh: &'m Mesh,
    table: &'m CandidateTable,
    naive: Naive,
    allowed: Vec<bool>,
    saved: Vec<Vec<bool>>,
}

impl<'m> Local<'m> {
    fn new(mesh: &'m Mesh, table: &'m CandidateTable) -> Self {
        let naive = Naive::new(mesh, table);
        let allowed = naive.verdicts().allowed;
        Local {
            mesh,
            table,
            naive,
            allowed,
            saved: Vec::new(),
        }
    }
}

impl Subject for Local<'_> {
    fn apply(&mut self, c: u32) {
        self.saved.push(self.allowed.clone());
        self.naive.apply(c);
        let mut near: Vec<u32> = self.table.pairs[c as usize].to_vec();
        for _ in 0..2 {
            let ring: Vec<u32> = near
                .iter()
                .flat_map(|&t| self.mesh.topology.neighbours[t as usize])
                .filter(|&u| u != NONE)
                .collect();
            near.extend(ring);
        }
        for t in near {
            for d in self.table.by_triangle[t as usize] {
                if d != NONE {
                    self.allowed[d as usize] = self.naive.is_allowed(d);
                }
            }
        }
    }
    fn undo(&mut self) {
        self.naive.undo();
        self.allowed = self.saved.pop().unwrap();
    }
    fn is_allowed(&mut self, c: u32) -> bool {
        self.allowed[c as usize]
    }
    fn allowed_count(&mut self, t: u32) -> u32 {
        self.table.by_triangle[t as usize]
            .iter()
            .filter(|&&d| d != NONE && self.allowed[d as usize])
            .count() as u32
    }
    fn is_remaining(&mut self, t: u32) -> bool {
        self.naive.is_remaining(t)
    }
    fn allowed_actions(&mut self) -> Vec<u32> {
        (0..self.allowed.len() as u32)
            .filter(|&c| self.allowed[c as usize])
            .collect()
    }
}

#[test]
fn harness_reports_the_old_strict_criterion() {
    let mesh = meshes::strip(5);
    let table = CandidateTable::build(&mesh);
    let err = walk(
        "strip(5)",
        &mesh,
        &table,
        &mut Strict(Naive::new(&mesh, &table)),
        SEED,
        WalkConfig::default(),
    )
    .expect_err("strict criterion must differ on an odd strip");
    assert!(
        err.contains("initial state") && err.contains("is_allowed(0)"),
        "{err}"
    );
}

#[test]
fn harness_reports_verdicts_changed_far_away() {
    // Verdicts change far from the last action when it splits a polder elsewhere (a part's
    // parity decides what is allowed in it): the walks must find such cases.
    let (mut caught, all) = (0, sample_meshes(SEED));
    for (name, mesh) in &all {
        let table = CandidateTable::build(mesh);
        let mut local = Local::new(mesh, &table);
        if walk(
            name,
            mesh,
            &table,
            &mut local,
            SEED,
            WalkConfig {
                explorations: 0,
                max_depth: 1,
                ..WalkConfig::default()
            },
        )
        .is_err()
        {
            caught += 1;
        }
    }
    assert!(
        2 * caught > all.len(),
        "a local-only recheck went unnoticed on most meshes ({caught} of {} caught)",
        all.len()
    );
}

// ---------------------------------------------------------------------------------------------
// Meshes for the comparison.

/// A varied set of meshes of up to about two hundred triangles, named by how to rebuild them.
fn sample_meshes(seed: u64) -> Vec<(String, Mesh)> {
    let mut out: Vec<(String, Mesh)> = vec![
        ("strip(6)".into(), meshes::strip(6)),
        ("strip(5)".into(), meshes::strip(5)),
        ("grid 4x4 rising".into(), Grid::plain(4, 4).build().unwrap()),
    ];
    let grid = |nx, ny, s: u64| Grid {
        jitter: 0.2,
        diagonals: Diagonals::Random,
        seed: seed ^ s,
        ..Grid::plain(nx, ny)
    };
    let specs = [
        grid(10, 9, 1),
        Grid {
            holes: 0.12,
            ..grid(12, 8, 2)
        },
        Grid {
            drop: 0.03,
            ..grid(10, 9, 3)
        },
        Grid {
            holes: 0.05,
            drop: 0.02,
            surfaces: Surfaces::Quadrants,
            ..grid(12, 9, 4)
        },
        Grid {
            drop: 0.02,
            diagonals: Diagonals::Alternating,
            surfaces: Surfaces::Bands(4),
            ..grid(12, 8, 5)
        },
        Grid {
            holes: 0.05,
            surfaces: Surfaces::RandomCells(3),
            ..grid(10, 10, 6)
        },
        Grid {
            surfaces: Surfaces::RandomTriangles(2),
            ..grid(8, 8, 7)
        },
        Grid {
            holes: 0.08,
            drop: 0.02,
            quads: 0.08,
            ..grid(10, 10, 8)
        },
        Grid {
            holes: 0.3,
            drop: 0.05,
            ..grid(20, 8, 9)
        },
    ];
    for spec in specs {
        if let Some(mesh) = spec.build() {
            out.push((format!("{spec:?}"), mesh));
        }
    }
    // Surfaces meeting three or more at an edge: a wall standing on a one-surface grid (two
    // grid triangles and one of the wall's on each edge of the line), on the line between
    // two quadrants (one of each surface), and through a grid (two of each).
    let fin = |j, i0, i1, levels, surface, through| Fin {
        j,
        i0,
        i1,
        levels,
        surface,
        through,
    };
    let finned = [
        Grid {
            fins: vec![fin(4, 1, 8, 2, 7, false)],
            ..grid(10, 8, 10)
        },
        Grid {
            holes: 0.05,
            surfaces: Surfaces::Quadrants,
            fins: vec![fin(4, 0, 10, 1, 9, false), fin(1, 2, 6, 3, 8, false)],
            ..grid(10, 8, 11)
        },
        Grid {
            drop: 0.02,
            fins: vec![fin(3, 2, 7, 2, 5, true)],
            ..grid(9, 7, 12)
        },
    ];
    for spec in finned {
        let mesh = spec.build().expect("a finned grid");
        out.push((format!("{spec:?}"), mesh));
    }
    out.push(("icosphere(1)".into(), meshes::icosphere(1)));
    // Long thin polders (one-cell corridors): splits with parts over LONG_PART triangles,
    // whose certificates list only their seeds; one odd (a triangle short).
    for (shape, n) in [
        (Corridor::Strip, 150),
        (Corridor::Spiral, 160),
        (Corridor::Maze, 220),
    ] {
        let name = format!("corridor({shape:?}, {n}, seed {seed})");
        out.push((name, generate::corridor(shape, n, seed)));
    }
    let spiral = generate::corridor(Corridor::Spiral, 162, seed);
    let odd = MeshData {
        vertices: spiral.vertices.clone(),
        triangles: spiral.triangles[..spiral.triangles.len() - 1].to_vec(),
        ..MeshData::default()
    };
    out.push((
        format!("corridor(Spiral, 162, seed {seed}) less its last triangle"),
        Mesh::new(odd).unwrap(),
    ));
    for (k, (points, flips, drop, surfaces)) in
        [(90, 120, 0.0, 1), (100, 120, 0.06, 1), (120, 100, 0.02, 2)]
            .into_iter()
            .enumerate()
    {
        let s = seed ^ (100 + k as u64);
        if let Some(mesh) = meshes::random_triangulation(points, flips, drop, surfaces, s) {
            out.push((
                format!("random_triangulation(points {points}, flips {flips}, drop {drop}, surfaces {surfaces}, seed {s:#x})"),
                mesh,
            ));
        }
    }
    out
}
