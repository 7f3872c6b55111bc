//! Search core: the state and its criterion (hand-checked cases, random apply/undo sequences
//! against the naive criterion), the policies (reproducibility, exhaustive-search equality of
//! the uniform tree), and the `recombine` CLI.

use crate::util::SEED;
use quadrecomb::internals::mesh::{Mesh, MeshData, NONE};
use quadrecomb::internals::quality::{CandidateTable, Rule};
use quadrecomb::internals::search::state::{State, naive_allowed};
use quadrecomb::internals::search::{self, Algo, Searcher};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A strip of `n` triangles 0-1-...-(n-1), each sharing one edge with the next.
fn strip(n: usize) -> Mesh {
    let mut d = MeshData::default();
    let cols = n / 2 + 2;
    for i in 0..cols {
        d.vertices.push([i as f64, 0.0, 0.0]);
        d.vertices.push([i as f64 + 0.5, 1.0, 0.0]);
    }
    let (b, u) = (|i: usize| 2 * i as u32, |i: usize| 2 * i as u32 + 1);
    for k in 0..n {
        let i = k / 2;
        d.triangles.push(if k % 2 == 0 {
            [b(i), b(i + 1), u(i)]
        } else {
            [b(i + 1), u(i + 1), u(i)]
        });
    }
    Mesh::new(d).expect("strip")
}

/// An `nx` x `ny` grid of unit squares, each split along the same diagonal, with optional
/// jitter, triangles listed in `keep` order only where `keep(t)`, surfaces from `surface`.
fn grid(
    nx: usize,
    ny: usize,
    jitter: f64,
    seed: u64,
    keep: impl Fn(usize, usize) -> bool,
    surface: impl Fn(usize, usize) -> i32,
) -> Mesh {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut d = MeshData::default();
    for j in 0..=ny {
        for i in 0..=nx {
            let mut jit = || (rng.next_u64() as f64 / u64::MAX as f64 - 0.5) * jitter;
            let inner = i > 0 && j > 0 && i < nx && j < ny;
            let (dx, dy) = if inner { (jit(), jit()) } else { (0.0, 0.0) };
            d.vertices.push([i as f64 + dx, j as f64 + dy, 0.0]);
        }
    }
    let v = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
    for j in 0..ny {
        for i in 0..nx {
            if !keep(i, j) {
                continue;
            }
            // Diagonal (i+1, j) - (i, j+1): the corner (0,0) is an ear.
            d.triangles.push([v(i, j), v(i + 1, j), v(i, j + 1)]);
            d.triangles
                .push([v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)]);
            d.triangle_surface.push(surface(i, j));
            d.triangle_surface.push(surface(i, j));
        }
    }
    Mesh::new(d).expect("grid")
}

fn pair_of(table: &CandidateTable, a: u32, b: u32) -> u32 {
    (0..table.len() as u32)
        .find(|&c| table.pairs[c as usize] == [a.min(b), a.max(b)])
        .expect("neighbours")
}

#[test]
fn strip_of_six_allows_only_even_splits() {
    let mesh = strip(6);
    let table = CandidateTable::build(&mesh);
    let state = State::new(&mesh, &table);
    for (a, b, ok) in [
        (0, 1, true),
        (1, 2, false),
        (2, 3, true),
        (3, 4, false),
        (4, 5, true),
    ] {
        assert_eq!(state.is_allowed(pair_of(&table, a, b)), ok, "({a},{b})");
    }
    assert_eq!(state.allowed_count(0), 1);
    assert_eq!(state.allowed_count(1), 1);
    assert_eq!(state.allowed_count(2), 1);
    state.sanity_check().unwrap();
}

#[test]
fn strip_of_five_allows_everything() {
    let mesh = strip(5);
    let table = CandidateTable::build(&mesh);
    let mut state = State::new(&mesh, &table);
    assert_eq!(state.allowed_actions().len(), 4);
    for t in 0..5 {
        assert_eq!(state.allowed_count(t), if t == 0 || t == 4 { 1 } else { 2 });
    }
    // (1,2) leaves {0} and {3,4}: one odd part, allowed; then only (3,4) remains.
    state.apply(pair_of(&table, 1, 2));
    state.sanity_check().unwrap();
    assert_eq!(state.allowed_actions(), vec![pair_of(&table, 3, 4)]);
    assert_eq!(state.allowed_count(0), 0);
    assert!(!state.is_remaining(1));
    state.undo();
    assert_eq!(state.allowed_actions().len(), 4);
    state.sanity_check().unwrap();
}

#[test]
fn grid_forbids_exactly_the_actions_isolating_an_ear() {
    let mesh = grid(4, 4, 0.0, 0, |_, _| true, |_, _| 1);
    assert_eq!(mesh.num_triangles(), 32);
    let table = CandidateTable::build(&mesh);
    let state = State::new(&mesh, &table);
    state.sanity_check().unwrap();
    // Ears: triangles with two boundary sides, and the pair of actions that cut them off.
    let nb = &mesh.topology.neighbours;
    let mut expect = Vec::new();
    for t in 0..32u32 {
        let inner: Vec<u32> = nb[t as usize]
            .iter()
            .copied()
            .filter(|&u| u != NONE)
            .collect();
        if inner.len() == 1 {
            let b = inner[0];
            for &x in &nb[b as usize] {
                if x != NONE && x != t {
                    expect.push(pair_of(&table, b, x));
                }
            }
        }
    }
    expect.sort_unstable();
    assert_eq!(
        expect.len(),
        4,
        "two ears (corners (0,0) and (4,4)), two cutting actions each"
    );
    let forbidden: Vec<u32> = (0..table.len() as u32)
        .filter(|&c| !state.is_allowed(c))
        .collect();
    assert_eq!(forbidden, expect);
}

/// Random apply / undo sequences, checking every verdict against the naive criterion.
fn random_walks(mesh: &Mesh, walks: usize, seed: u64) {
    let table = CandidateTable::build(mesh);
    let mut state = State::new(mesh, &table);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let initial = state.allowed_actions();
    for _ in 0..walks {
        loop {
            let actions = state.allowed_actions();
            if actions.is_empty() {
                break;
            }
            // Mostly forward, sometimes back a step (tree-like exploration).
            if state.depth() > 0 && rng.next_u64() % 5 == 0 {
                state.undo();
            } else {
                let c = actions[(rng.next_u64() % actions.len() as u64) as usize];
                state.apply(c);
            }
            state.sanity_check().unwrap();
        }
        let left = state.triangles_left();
        assert_eq!(left + 2 * state.quads(), mesh.num_triangles());
        state.reset();
        assert_eq!(state.allowed_actions(), initial);
    }
}

#[test]
fn random_walks_match_the_naive_criterion_on_a_jittered_grid() {
    random_walks(&grid(8, 7, 0.4, SEED, |_, _| true, |_, _| 1), 6, SEED);
}

#[test]
fn random_walks_match_on_holes_surfaces_and_odd_components() {
    // Holes (missing squares), two surfaces, and an odd component (a lone triangle is made
    // by removing one triangle of a square: here a whole odd surface strip).
    let holes = grid(
        9,
        8,
        0.3,
        SEED + 1,
        |i, j| !(((3..5).contains(&i) && (3..5).contains(&j)) || (i == 7 && j == 1)),
        |i, _| if i < 5 { 1 } else { 2 },
    );
    random_walks(&holes, 5, SEED + 1);
    // Odd components: a strip of 5 and a strip of 7 side by side with a grid.
    let mut d = MeshData::default();
    for (k, m) in [
        strip(5),
        strip(7),
        grid(5, 4, 0.3, SEED, |_, _| true, |_, _| 1),
    ]
    .iter()
    .enumerate()
    {
        let base = d.vertices.len() as u32;
        for p in &m.vertices {
            d.vertices.push([p[0], p[1] + 10.0 * k as f64, 0.0]);
        }
        for t in &m.triangles {
            d.triangles.push(t.map(|v| v + base));
        }
    }
    let odd = Mesh::new(d).unwrap();
    assert!(odd.topology.component_sizes.iter().any(|s| s % 2 == 1));
    random_walks(&odd, 8, SEED + 2);
}

#[test]
fn naive_criterion_agrees_with_the_hand_checked_strip() {
    let mesh = strip(6);
    let table = CandidateTable::build(&mesh);
    let ok = naive_allowed(&mesh, &table, &[true; 6]);
    assert_eq!(ok, vec![true, false, true, false, true]);
}

/// Plain exhaustive uniform tree: best value of `h`-action sequences, first action, with the
/// same order (decreasing eta, then index) and strict improvement.
fn exhaustive(
    state: &mut State<'_>,
    order: &[u32],
    h: u32,
    partial: f64,
    best: &mut (f64, u32),
    root: u32,
) {
    let eta = &state.table().eta;
    let mut any = false;
    for &c in order {
        if !state.is_allowed(c) {
            continue;
        }
        any = true;
        let r = if root == NONE { c } else { root };
        let v = partial + eta[c as usize];
        if h == 1 {
            if v > best.0 {
                *best = (v, r);
            }
        } else {
            state.apply(c);
            exhaustive(state, order, h - 1, v, best, r);
            state.undo();
        }
    }
    if !any && root != NONE && partial > best.0 {
        *best = (partial, root);
    }
}

#[test]
fn uniform_tree_equals_exhaustive_search() {
    for (mesh, h) in [
        (grid(4, 3, 0.45, SEED, |_, _| true, |_, _| 1), 3),
        (grid(3, 3, 0.3, SEED + 5, |i, j| i + j != 2, |_, _| 1), 4),
        (strip(9), 3),
        // Many equal rewards (a regular grid): ties decide the first action.
        (grid(4, 4, 0.0, SEED, |_, _| true, |_, _| 1), 3),
        (grid(5, 3, 0.0, SEED, |i, j| i + j != 3, |_, _| 1), 4),
        (grid(6, 5, 0.2, SEED + 9, |_, _| true, |_, _| 1), 3),
    ] {
        let table = CandidateTable::build(&mesh);
        let mut order: Vec<u32> = (0..table.len() as u32).collect();
        order.sort_by(|&a, &b| {
            table.eta[b as usize]
                .total_cmp(&table.eta[a as usize])
                .then(a.cmp(&b))
        });
        // Replay the uniform run and check each decision against exhaustive search.
        let out = search::run(&mesh, &table, Algo::uniform(h), SEED);
        let mut state = State::new(&mesh, &table);
        for &c in &out.chosen {
            let mut best = (f64::NEG_INFINITY, NONE);
            exhaustive(&mut state, &order, h, 0.0, &mut best, NONE);
            assert_eq!(best.1, c, "uniform h={h} chose {c}, exhaustive {}", best.1);
            state.apply(c);
        }
        assert!(
            state.allowed_actions().is_empty(),
            "the run stops only when stuck"
        );
    }
}

#[test]
fn runs_are_reproducible_and_searchers_reusable() {
    let mesh = grid(12, 10, 0.4, SEED, |_, _| true, |_, _| 1);
    let table = CandidateTable::build(&mesh);
    let mut s = Searcher::new(&mesh, &table);
    for algo in [
        Algo::greedy_nocrit(),
        Algo::greedy(),
        Algo::uniform(2),
        Algo::selective(1),
        Algo::selective(4),
    ] {
        let w0 = s.criterion_work();
        let a = s.run(algo, SEED);
        let w1 = s.criterion_work();
        let b = s.run(algo, SEED);
        let w2 = s.criterion_work();
        // The first run's state keeps no copy of its initial position (the second builds it
        // again with one); the third resets by copying.
        let b2 = s.run(algo, SEED);
        let c = search::run(&mesh, &table, algo, SEED);
        assert_eq!(a.chosen, b.chosen, "{algo}");
        assert_eq!(a.chosen, b2.chosen, "{algo}");
        // The work counters are as reproducible as the run (the benchmarks report them).
        let work = |x: (u64, u64), y: (u64, u64)| (y.0 - x.0, y.1 - x.1);
        assert_eq!(work(w0, w1), work(w1, w2), "{algo}");
        if algo == Algo::greedy_nocrit() {
            assert_eq!(work(w0, w1), (0, 0), "no criterion, no search");
        } else {
            assert!(work(w0, w1).0 > 0 && work(w0, w1).1 > 0, "{algo}");
        }
        assert_eq!(a.chosen, c.chosen, "{algo}");
        assert_eq!(a.quads + a.triangles_left / 2, mesh.num_triangles() / 2);
        let q: f64 = a.chosen.iter().map(|&c| table.eta[c as usize]).sum();
        assert!((q - a.quality).abs() < 1e-9);
        // A matching: no triangle twice.
        let mut used = vec![false; mesh.num_triangles()];
        for &c in &a.chosen {
            for t in table.pairs[c as usize] {
                assert!(!used[t as usize]);
                used[t as usize] = true;
            }
        }
    }
    // Different seeds explore differently on the selective tree.
    let runs: Vec<_> = (0..6)
        .map(|k| s.run(Algo::selective(2), k).chosen)
        .collect();
    assert!(runs.iter().any(|r| r != &runs[0]));
}

#[test]
fn policies_respect_the_criterion_and_recombine_a_grid_fully() {
    let mesh = grid(10, 10, 0.2, SEED, |_, _| true, |_, _| 1);
    let table = CandidateTable::build(&mesh);
    let mut s = Searcher::new(&mesh, &table);
    for algo in [Algo::greedy(), Algo::selective(3), Algo::uniform(2)] {
        let out = s.run(algo, SEED);
        // Replaying: every action was allowed when taken.
        let mut state = State::new(&mesh, &table);
        for &c in &out.chosen {
            assert!(state.is_allowed(c), "{algo}: action {c} was forbidden");
            state.apply(c);
        }
        assert!(state.allowed_actions().is_empty());
        // The criterion keeps every polder even: an even grid ends fully recombined.
        assert_eq!(out.triangles_left, 0, "{algo}");
        // Every tree expands its root; only selective skips trees (forced decisions: on
        // this grid, where some triangle always has a single option, all of them).
        assert!(out.nodes_expanded >= out.trees, "{algo}");
        if algo.name() == "selective" {
            assert!(out.trees <= out.decisions);
        } else {
            assert_eq!(out.trees, out.decisions);
        }
    }
    // Without the criterion, greedy strands triangles on this mesh.
    let nocrit = s.run(Algo::greedy_nocrit(), SEED);
    assert!(nocrit.quads > 0);
}

#[test]
fn algo_names_parse() {
    assert_eq!(
        "greedy-nocrit".parse::<Algo>().unwrap(),
        Algo::greedy_nocrit()
    );
    assert_eq!("selective:5".parse::<Algo>().unwrap(), Algo::selective(5));
    assert_eq!(Algo::uniform(2).to_string(), "uniform");
    assert!("blossom".parse::<Algo>().is_err());
    assert!("uniform:0".parse::<Algo>().is_err());
}

#[test]
fn recombine_cli_prints_json_and_writes_meshes() {
    let dir = tempfile::tempdir().unwrap();
    let out = crate::util::run_in(
        dir.path(),
        &[
            "recombine",
            "sphere",
            "--algo",
            "selective",
            "--horizon",
            "2",
            "--seed",
            "7",
            "--json",
            "-o",
            "out.msh",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for key in [
        "mesh",
        "triangles",
        "algo",
        "horizon",
        "seed",
        "quads",
        "triangles_left",
        "recombined_pct",
        "quality",
        "time_s",
        "nodes_expanded",
        "trees",
        "decisions",
        "quality_pct",
    ] {
        assert!(v.get(key).is_some(), "missing {key} in {v}");
    }
    assert_eq!(v["algo"], "selective");
    assert_eq!(v["horizon"], 2);
    assert_eq!(v["seed"], 7);
    let (quads, left, nt) = (
        v["quads"].as_u64().unwrap(),
        v["triangles_left"].as_u64().unwrap(),
        v["triangles"].as_u64().unwrap(),
    );
    assert_eq!(2 * quads + left, nt);
    let pct = v["quality_pct"].as_f64().unwrap();
    assert!(pct > 90.0 && pct <= 100.0 + 1e-9, "{pct}");
    // Same seed, same run, through the library.
    let mesh = quadrecomb::internals::mesh::load("sphere").unwrap();
    let table = CandidateTable::build(&mesh).restrict(&mesh, Rule::default());
    let lib = search::run(&mesh, &table, Algo::selective(2), 7);
    assert_eq!(lib.quads as u64, quads);
    assert!((lib.quality - v["quality"].as_f64().unwrap()).abs() < 1e-9);
    // The written mesh holds the quads and the leftover triangles, and `info` on it reads the
    // quads by their corner angles: on the sphere's slightly non-planar quads that is within
    // a fraction of a percent of the run's quality (whose quads sum their two triangles' 3D
    // angles at the diagonal), on a planar mesh the same to rounding.
    let info_sum = |file: &str| {
        let info = crate::util::run_in(dir.path(), &["info", "--json", file]);
        assert_eq!(info.status.code(), Some(0));
        let back: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
        let n = back["quads"].as_u64().unwrap();
        (
            n,
            back["triangles"].as_u64().unwrap(),
            back["quad_eta"]["mean"].as_f64().unwrap() * n as f64,
        )
    };
    let (n, tris, sum) = info_sum("out.msh");
    assert_eq!((n, tris), (quads, left));
    let quality = v["quality"].as_f64().unwrap();
    assert!((sum - quality).abs() < 5e-3 * quality, "{sum} vs {quality}");
    let out = crate::util::run_in(
        dir.path(),
        &[
            "recombine",
            "borouchaki",
            "--algo",
            "greedy",
            "-o",
            "flat.msh",
            "--json",
            "--no-optimum",
        ],
    );
    let flat: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let quality = flat["quality"].as_f64().unwrap();
    let (_, _, sum) = info_sum("flat.msh");
    assert!((sum - quality).abs() < 1e-9 * quality, "{sum} vs {quality}");
    let write_to = |o: &str| {
        let out = crate::util::run_in(
            dir.path(),
            &[
                "recombine",
                "sphere",
                "--algo",
                "greedy",
                "-o",
                o,
                "--no-optimum",
            ],
        );
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{o}: {err}");
    };
    write_to("out.vtu");
    assert!(dir.path().join("out.vtu").exists());
    // Bad input: zero horizon, unknown output format.
    for args in [
        &[
            "recombine",
            "sphere",
            "--algo",
            "selective",
            "--horizon",
            "0",
        ][..],
        &["recombine", "sphere", "--algo", "greedy", "-o", "out.obj"][..],
    ] {
        let bad = crate::util::run_in(dir.path(), args);
        assert_eq!(bad.status.code(), Some(2), "{args:?}");
    }
    // Output paths it could not write are refused by the check made before the search (its
    // messages; a failed write after the search would say "cannot write output").
    std::fs::create_dir(dir.path().join("adir.msh")).unwrap();
    std::fs::write(dir.path().join("afile"), "").unwrap();
    for (o, why) in [
        ("no/such/dir/x.msh", "directory no/such/dir does not exist"),
        ("adir.msh", "names a directory"),
        ("x.msh/", "names a directory"),
        ("afile/x.vtu", "afile is not a directory"),
    ] {
        for cmd in [
            &["recombine", "sphere", "--algo", "greedy"][..],
            &["optimum", "sphere"],
        ] {
            let mut args = cmd.to_vec();
            args.extend(["-o", o]);
            let bad = crate::util::run_in(dir.path(), &args);
            let err = String::from_utf8_lossy(&bad.stderr);
            assert_eq!(bad.status.code(), Some(2), "{args:?}: {err}");
            assert!(
                err.starts_with(&format!("error: output {o}: {why}")),
                "{args:?}: {err}"
            );
        }
    }
    // Extensions in any case; the write goes through a temporary file renamed into place.
    write_to("UP.MSH");
    let names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(names.iter().any(|n| n == "UP.MSH"), "{names:?}");
    assert!(!names.iter().any(|n| n.contains(".tmp")), "{names:?}");
    // Through a symbolic link, the file it points to is replaced, keeping its permissions.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let target = dir.path().join("target.vtu");
        std::fs::write(&target, "").unwrap();
        std::fs::set_permissions(&target, std::fs::Permissions::from_mode(0o640)).unwrap();
        std::os::unix::fs::symlink("target.vtu", dir.path().join("link.vtu")).unwrap();
        write_to("link.vtu");
        let link = std::fs::symlink_metadata(dir.path().join("link.vtu")).unwrap();
        assert!(link.file_type().is_symlink());
        let meta = std::fs::metadata(&target).unwrap();
        assert!(meta.len() > 1000);
        assert_eq!(meta.permissions().mode() & 0o777, 0o640);
        // A link that leads to no file yet: the file it names is created, as by a shell's
        // `>` (it replaced the link before), through a chain of relative links too.
        std::fs::create_dir(dir.path().join("sub")).unwrap();
        std::os::unix::fs::symlink("new.vtu", dir.path().join("dangling.vtu")).unwrap();
        std::os::unix::fs::symlink("sub/end.msh", dir.path().join("chain2.msh")).unwrap();
        std::os::unix::fs::symlink("chain2.msh", dir.path().join("chain1.msh")).unwrap();
        for (link, made) in [("dangling.vtu", "new.vtu"), ("chain1.msh", "sub/end.msh")] {
            write_to(link);
            let meta = std::fs::symlink_metadata(dir.path().join(link)).unwrap();
            assert!(meta.file_type().is_symlink(), "{link} replaced");
            assert!(std::fs::metadata(dir.path().join(made)).unwrap().len() > 1000);
        }
        // One into a directory that does not exist, or a loop: refused before the search.
        std::os::unix::fs::symlink("nowhere/x.msh", dir.path().join("lost.msh")).unwrap();
        std::os::unix::fs::symlink("loop.msh", dir.path().join("loop.msh")).unwrap();
        for (o, why) in [
            (
                "lost.msh",
                "directory nowhere does not exist (the symbolic link leads to nowhere/x.msh)",
            ),
            ("loop.msh", "cannot be written: "),
        ] {
            let bad = crate::util::run_in(
                dir.path(),
                &["recombine", "sphere", "--algo", "greedy", "-o", o],
            );
            let err = String::from_utf8_lossy(&bad.stderr);
            assert_eq!(bad.status.code(), Some(2), "{o}: {err}");
            assert!(
                err.starts_with(&format!("error: output {o}: {why}")),
                "{o}: {err}"
            );
        }
    }
}

/// `recombine --backend cpu` (the CPU twin's f32 eta) repeats a committed sweep's run from its
/// recorded seed: same quads, same quality to the bit; the default f64 eta need not (ties
/// fall otherwise on `sphere`: greedy makes 860 quads with it against the sweep's 881).
#[test]
fn recombine_backend_cpu_repeats_a_committed_sweep_run() {
    let runs = std::fs::read_to_string(crate::util::repo_path("results/sphere/runs.jsonl"))
        .expect("committed results/sphere");
    let recs: Vec<serde_json::Value> = runs
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let pick = |algo: &str, h: Option<u64>| {
        recs.iter()
            .find(|r| r["algo"] == algo && r["horizon"].as_u64() == h && r["backend"] == "cpu-twin")
            .unwrap_or_else(|| panic!("no {algo} {h:?} record"))
    };
    let dir = tempfile::tempdir().unwrap();
    for (algo, h) in [("greedy", None), ("selective", Some(3))] {
        let rec = pick(algo, h);
        let seed = rec["seed"].as_u64().unwrap().to_string();
        let mut args = vec!["recombine", "sphere", "--algo", algo, "--seed", &seed];
        let hs = h.map(|h| h.to_string());
        if let Some(hs) = &hs {
            args.extend(["--horizon", hs]);
        }
        args.extend(["--backend", "cpu", "--json", "--no-optimum"]);
        // The record's rule (records made before the rule existed allowed every pair).
        if rec.get("allow_invalid").is_none_or(|a| a == true) {
            args.push("--allow-invalid");
        }
        let out = crate::util::run_in(dir.path(), &args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["backend"], "cpu-twin");
        assert_eq!(v["quads"], rec["quads"], "{algo} {h:?}");
        assert_eq!(
            v["quality"].as_f64().unwrap().to_bits(),
            rec["quality"].as_f64().unwrap().to_bits(),
            "{algo} {h:?}"
        );
    }
    let exact = crate::util::run_in(
        dir.path(),
        &[
            "recombine",
            "sphere",
            "--algo",
            "greedy",
            "--json",
            "--no-optimum",
        ],
    );
    let v: serde_json::Value = serde_json::from_slice(&exact.stdout).unwrap();
    assert_eq!(v["backend"], "exact");
}

/// `bench memory` prints one row per working-set size (1, 2, 4 MiB up to `--max-mib`) with
/// positive latencies, and refuses sizes or load counts of zero.
#[test]
fn bench_memory_prints_one_row_per_size() {
    let dir = tempfile::tempdir().unwrap();
    let out = crate::util::run_in(
        dir.path(),
        &["bench", "memory", "--max-mib", "4", "--loads", "20000"],
    );
    let s = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{s}");
    let rows: Vec<Vec<f64>> = s
        .lines()
        .filter_map(|l| {
            let v: Vec<f64> = l
                .split_whitespace()
                .filter_map(|w| w.parse().ok())
                .collect();
            (v.len() == 4).then_some(v)
        })
        .collect();
    let sizes: Vec<f64> = rows.iter().map(|r| r[0]).collect();
    assert_eq!(sizes, [1.0, 2.0, 4.0], "{s}");
    for r in &rows {
        assert!(r[1] > 0.0 && r[2] > 0.0 && r[3] > 0.0, "{s}");
    }
    for bad in [["--max-mib", "0"], ["--loads", "0"]] {
        let out = crate::util::run_in(dir.path(), &["bench", "memory", bad[0], bad[1]]);
        assert_eq!(out.status.code(), Some(2), "{bad:?}");
    }
}

/// A table of another mesh is refused with a message naming both (a library user's review:
/// index out of bounds in the searches, "bad edge 458-2290" in the optimum, and, the other
/// way round, the sphere's optimum returned for borouchaki without a word); `recombined`
/// refuses candidates that share a triangle (it wrote overlapping quads).
#[test]
fn a_table_of_another_mesh_and_overlapping_quads_are_refused() {
    let boro = quadrecomb::load("borouchaki").unwrap();
    let sphere = quadrecomb::load("sphere").unwrap();
    let (tb, ts) = (CandidateTable::build(&boro), CandidateTable::build(&sphere));
    assert!(tb.fits(&boro) && ts.fits(&sphere));
    assert!(!tb.fits(&sphere) && !ts.fits(&boro));
    let message = |f: &dyn Fn()| {
        let err = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).unwrap_err();
        err.downcast_ref::<String>().cloned().unwrap_or_default()
    };
    type Call<'a> = (&'static str, Box<dyn Fn() + 'a>);
    let calls: [Call<'_>; 7] = [
        (
            "run",
            Box::new(|| drop(search::run(&boro, &ts, Algo::greedy(), 0))),
        ),
        ("searcher", Box::new(|| drop(Searcher::new(&sphere, &tb)))),
        ("state", Box::new(|| drop(State::new(&sphere, &tb)))),
        (
            "optimum",
            Box::new(|| drop(quadrecomb::optimum(&boro, &ts))),
        ),
        (
            "optimum'",
            Box::new(|| drop(quadrecomb::optimum(&sphere, &tb))),
        ),
        (
            "recombined",
            Box::new(|| drop(quadrecomb::recombined(&boro, &ts, &[]))),
        ),
        (
            "restrict",
            Box::new(|| drop(ts.clone().restrict(&boro, Rule::default()))),
        ),
    ];
    for (what, f) in calls {
        let m = message(&*f);
        assert!(m.contains("was not built for this mesh"), "{what}: {m}");
    }
    let m = message(&|| drop(quadrecomb::recombined(&sphere, &ts, &[0, 0])));
    assert!(m.contains("not a matching"), "{m}");
    let m = message(&|| drop(quadrecomb::recombined(&sphere, &ts, &[u32::MAX - 1])));
    assert!(m.contains("does not exist"), "{m}");
}

/// On a torus, lockstep searches meet round the handle (a quad touching one dead component
/// twice need not cut there). Their verdicts are certified by the paths that join them
/// (`join_paths`), not by everything they visited, so an action on what they visited no
/// longer sends each back to a search round the handle: uniform h = 2 on the suite's torus
/// took 1.4 s for that. Its criterion's searches visited 5,004 triangles per triangle of the
/// mesh before, 471 now (the same run: 17,878 searches then, 9,778 now).
#[test]
fn searches_that_met_are_certified_by_their_joining_paths() {
    use quadrecomb::internals::mesh::{load, suite};
    let member = suite::member("torus").expect("a suite member");
    let mesh = load(&suite::spec(member)).expect("the torus loads");
    let table = CandidateTable::build(&mesh).restrict(&mesh, Rule::default());
    let mut searcher = Searcher::new(&mesh, &table);
    let out = searcher.run(Algo::uniform(2), 0);
    assert!(out.quads > 0);
    let (_, searched) = searcher.criterion_work();
    let per = searched as f64 / mesh.num_triangles() as f64;
    assert!(per < 1000.0, "{per:.1} triangles searched per triangle");
}
