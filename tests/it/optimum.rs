//! The exact optimum: brute force on small graphs, the `mwmatching` oracle on random sparse
//! graphs and generated meshes, the dual certificate, the CLI, and the reference values.

use crate::util::{SEED, run_in};
use quadrecomb::internals::mesh::{Mesh, MeshData};
use quadrecomb::internals::quality::CandidateTable;
use quadrecomb::internals::search::optimum::{self, blossom};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// (cardinality, weight) of the best matching: most pairs, then most weight.
fn brute_force(n: usize, edges: &[(u32, u32, i64)]) -> (usize, i64) {
    let mut adj = vec![Vec::new(); n];
    for &(u, v, w) in edges {
        adj[u as usize].push((v as usize, w));
        adj[v as usize].push((u as usize, w));
    }
    fn go(v: usize, used: &mut Vec<bool>, adj: &[Vec<(usize, i64)>]) -> (usize, i64) {
        let n = used.len();
        let mut v = v;
        while v < n && used[v] {
            v += 1;
        }
        if v == n {
            return (0, 0);
        }
        used[v] = true;
        let mut best = go(v + 1, used, adj);
        for &(w, wt) in &adj[v] {
            if !used[w] {
                used[w] = true;
                let (c, s) = go(v + 1, used, adj);
                best = best.max((c + 1, s + wt));
                used[w] = false;
            }
        }
        used[v] = false;
        best
    }
    go(0, &mut vec![false; n], &adj)
}

/// Random simple graph: `n` vertices, each edge kept with probability `p`, degree at most
/// `maxdeg`, weights drawn from `0..=wmax`.
fn random_graph(
    rng: &mut ChaCha8Rng,
    n: usize,
    p: f64,
    maxdeg: usize,
    wmax: i64,
) -> Vec<(u32, u32, i64)> {
    let mut deg = vec![0; n];
    let mut edges = Vec::new();
    for u in 0..n {
        for v in u + 1..n {
            if deg[u] < maxdeg && deg[v] < maxdeg && rng.random_bool(p) {
                deg[u] += 1;
                deg[v] += 1;
                edges.push((u as u32, v as u32, rng.random_range(0..=wmax)));
            }
        }
    }
    edges
}

fn solve_checked(
    n: usize,
    edges: &[(u32, u32, i64)],
) -> (usize, i64, blossom::Matching, blossom::Graph) {
    let g = blossom::Graph::from_edges(n, edges.iter().copied());
    let m = blossom::solve(&g);
    if let Err(e) = m.check(&g) {
        panic!("certificate failed: {e}\nn = {n}, edges = {edges:?}");
    }
    let pairs: Vec<(u32, u32)> = m.pairs().collect();
    let mut used = vec![false; n];
    for &(u, v) in &pairs {
        assert!(!used[u as usize] && !used[v as usize], "vertex used twice");
        used[u as usize] = true;
        used[v as usize] = true;
    }
    let w = m.weight(&g);
    (pairs.len(), w, m, g)
}

#[test]
fn brute_force_small_graphs() {
    let mut rng = ChaCha8Rng::seed_from_u64(SEED);
    let mut deficient = 0;
    let mut odd = 0;
    for case in 0..6000 {
        let n = rng.random_range(1..=16usize);
        let p = [0.15, 0.3, 0.5, 0.9][case % 4];
        // Dense graphs only where enumerating every matching stays cheap.
        let maxdeg = if case % 3 == 0 && n <= 11 { 16 } else { 3 };
        let wmax = [1, 3, 10, 1 << 24][case % 4 / 2 + case % 2 * 2];
        let edges = random_graph(&mut rng, n, p, maxdeg, wmax);
        let (card, w, m, _) = solve_checked(n, &edges);
        let want = brute_force(n, &edges);
        assert_eq!(
            (card, w),
            want,
            "case {case} (seed {SEED:#x}): n = {n}, edges = {edges:?}, stats = {:?}",
            m.stats
        );
        if n % 2 == 1 {
            odd += 1;
        }
        if n % 2 == 0 && 2 * card < n {
            deficient += 1;
        }
    }
    assert!(
        odd > 100 && deficient > 100,
        "coverage: {odd} odd, {deficient} deficient"
    );
}

/// Cardinality and weight from `mwmatching`'s maximum-cardinality mode.
fn oracle(edges: &[(u32, u32, i64)]) -> (usize, i64) {
    let e: Vec<(usize, usize, i32)> = edges
        .iter()
        .map(|&(u, v, w)| (u as usize, v as usize, w as i32))
        .collect();
    if e.is_empty() {
        return (0, 0);
    }
    let mate = mwmatching::Matching::new(e).max_cardinality().solve();
    let mut card = 0;
    let mut w = 0;
    for &(u, v, wt) in edges {
        if mate.get(u as usize) == Some(&(v as usize)) {
            card += 1;
            w += wt;
        }
    }
    (card, w)
}

#[test]
fn agrees_with_oracle_on_random_sparse_graphs() {
    let mut rng = ChaCha8Rng::seed_from_u64(SEED ^ 1);
    for case in 0..60 {
        let n = rng.random_range(20..=400usize);
        // Mean degree about 2.5: many components, odd and deficient ones among them.
        let p = 2.5 / n as f64;
        let wmax = [3, 100, 1 << 24][case % 3];
        let edges = random_graph(&mut rng, n, p, 3, wmax);
        let (card, w, _, _) = solve_checked(n, &edges);
        assert_eq!((card, w), oracle(&edges), "case {case}: n = {n}");
    }
}

/// A jittered grid of `nx * ny` squares split into two triangles each (diagonals at random),
/// with a fraction `hole` of the triangles removed (making odd and deficient components).
pub fn jittered_grid(nx: usize, ny: usize, hole: f64, seed: u64) -> Mesh {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut vertices = Vec::new();
    for j in 0..=ny {
        for i in 0..=nx {
            let jit = |r: &mut ChaCha8Rng, k: usize, nk: usize| {
                if k == 0 || k == nk {
                    0.0
                } else {
                    r.random_range(-0.3..0.3)
                }
            };
            let x = i as f64 + jit(&mut rng, i, nx);
            let y = j as f64 + jit(&mut rng, j, ny);
            vertices.push([x, y, 0.0]);
        }
    }
    let id = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
    let mut triangles = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            let pair = if rng.random_bool(0.5) {
                [[a, b, c], [a, c, d]]
            } else {
                [[a, b, d], [b, c, d]]
            };
            for t in pair {
                if !rng.random_bool(hole) {
                    triangles.push(t);
                }
            }
        }
    }
    // Drop vertices no triangle uses.
    let mut used = vec![u32::MAX; vertices.len()];
    let mut kept = Vec::new();
    for t in &mut triangles {
        for v in t.iter_mut() {
            if used[*v as usize] == u32::MAX {
                used[*v as usize] = kept.len() as u32;
                kept.push(vertices[*v as usize]);
            }
            *v = used[*v as usize];
        }
    }
    Mesh::new(MeshData {
        vertices: kept,
        triangles,
        ..MeshData::default()
    })
    .expect("valid grid")
}

fn mesh_edges(table: &CandidateTable) -> Vec<(u32, u32, i64)> {
    table
        .pairs
        .iter()
        .zip(&table.eta)
        .map(|(&[a, b], &eta)| (a, b, optimum::weight(eta)))
        .collect()
}

#[test]
fn agrees_with_oracle_on_meshes() {
    for (k, &(nx, ny, hole)) in [(32, 32, 0.0), (40, 30, 0.02), (45, 50, 0.0), (50, 50, 0.08)]
        .iter()
        .enumerate()
    {
        let mesh = jittered_grid(nx, ny, hole, SEED + k as u64);
        let nt = mesh.num_triangles();
        assert!((2000..=5000).contains(&nt), "{nt} triangles");
        let table = CandidateTable::build(&mesh);
        let (opt, report) = optimum::solve_certified(&mesh, &table, true);
        report.expect("checked").expect("certificate");
        let edges = mesh_edges(&table);
        let w: i64 = opt
            .chosen
            .iter()
            .map(|&c| optimum::weight(table.eta[c as usize]))
            .sum();
        assert_eq!((opt.quads, w), oracle(&edges), "grid {nx}x{ny} hole {hole}");
        assert_eq!(opt.triangles_left, nt - 2 * opt.quads);
        let q: f64 = opt.chosen.iter().map(|&c| table.eta[c as usize]).sum();
        assert_eq!(opt.quality, q);
        if hole == 0.0 {
            assert_eq!(opt.triangles_left, 0, "a full grid has a perfect matching");
        }
    }
}

#[test]
fn certificate_rejects_a_wrong_matching() {
    // The check must be able to fail: tamper with a weight so that the returned matching is
    // no longer optimal for the graph being checked.
    let edges = [(0, 1, 5), (1, 2, 5), (2, 3, 5)];
    let g = blossom::Graph::from_edges(4, edges.iter().copied());
    let m = blossom::solve(&g);
    assert_eq!(m.pairs().collect::<Vec<_>>(), vec![(0, 1), (2, 3)]);
    m.check(&g).expect("valid");
    let other = blossom::Graph::from_edges(4, [(0, 1, 5), (1, 2, 50), (2, 3, 5)].into_iter());
    assert!(m.check(&other).is_err());
}

#[test]
fn large_grid_is_perfect_and_certified() {
    let mesh = jittered_grid(150, 100, 0.0, SEED);
    let table = CandidateTable::build(&mesh);
    let (opt, report) = optimum::solve_certified(&mesh, &table, true);
    report.expect("checked").expect("certificate");
    assert_eq!(opt.triangles_left, 0);
}

/// The reference values of the issue, on the built-in meshes (once they are loadable).
#[test]
fn builtin_reference_values() {
    for (name, want_q, want_tri) in [
        ("sphere", 678.81, None),
        ("borouchaki", 13183.64, Some(34456)),
    ] {
        let mesh = match quadrecomb::internals::mesh::load(name) {
            Ok(m) => m,
            Err(e) => {
                eprintln!(
                    "NOTE: built-in mesh {name} not loadable here ({e}); reference value not checked"
                );
                continue;
            }
        };
        let table = CandidateTable::build(&mesh);
        let (opt, report) = optimum::solve_certified(&mesh, &table, true);
        report.expect("checked").expect("certificate");
        assert!(
            (opt.quality - want_q).abs() < 0.005,
            "{name}: quality {}",
            opt.quality
        );
        if let Some(nt) = want_tri {
            assert_eq!(mesh.num_triangles(), nt);
            assert_eq!(opt.triangles_left, 0, "{name}: all triangles recombined");
        }
    }
}

#[test]
fn cli_optimum_json() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mesh = jittered_grid(10, 8, 0.0, SEED);
    let path = dir.path().join("grid.msh");
    std::fs::write(&path, msh22(&mesh)).expect("write mesh");
    let out = run_in(dir.path(), &["optimum", "grid.msh", "--json", "--check"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() && stderr.contains("unknown mesh format") {
        // Loading files arrives with the io work; until then `load` refuses every path.
        eprintln!("NOTE: mesh loading not available in this branch: {stderr}");
        return;
    }
    assert!(out.status.success(), "{stderr}");
    let v: serde_json::Value =
        serde_json::from_slice(&out.stdout).expect("one JSON object on stdout");
    assert_eq!(v["algo"], "optimum");
    assert_eq!(v["triangles"], 160);
    assert_eq!(v["quads"], 80);
    assert_eq!(v["triangles_left"], 0);
    assert!(v["horizon"].is_null() && v["seed"].is_null() && v["nodes_expanded"].is_null());
    assert!(v["trees"].is_null());
    let table = CandidateTable::build(&mesh);
    let opt = optimum::solve(&mesh, &table);
    let q = v["quality"].as_f64().expect("quality");
    assert!((q - opt.quality).abs() < 1e-6, "{q} vs {}", opt.quality);
}

#[test]
fn cli_rejects_missing_mesh() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = run_in(dir.path(), &["optimum", "no-such-mesh.msh"]);
    assert_eq!(out.status.code(), Some(3));
}

/// MSH 2.2 ASCII text of a triangle mesh (enough for the CLI test).
fn msh22(mesh: &Mesh) -> String {
    let mut s = String::from("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n");
    s += &format!("{}\n", mesh.vertices.len());
    for (i, p) in mesh.vertices.iter().enumerate() {
        s += &format!("{} {} {} {}\n", i + 1, p[0], p[1], p[2]);
    }
    s += &format!("$EndNodes\n$Elements\n{}\n", mesh.triangles.len());
    for (i, t) in mesh.triangles.iter().enumerate() {
        s += &format!("{} 2 2 1 1 {} {} {}\n", i + 1, t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s += "$EndElements\n";
    s
}

/// Ad-hoc: the optimum of a mesh given as a text dump (`n`, then `n` lines `x y z`, `m`, then
/// `m` lines `a b c surface`, 0-based) named by `QUADRECOMB_OPTIMUM_DUMP`; for checking the
/// reference values where `.msh` loading is not available. Prints what it finds.
#[test]
#[ignore = "needs QUADRECOMB_OPTIMUM_DUMP"]
fn optimum_of_text_dump() {
    // `cargo test -- --ignored` runs every ignored test: without a dump there is nothing to
    // do here, which is not a failure.
    let Ok(path) = std::env::var("QUADRECOMB_OPTIMUM_DUMP") else {
        eprintln!("optimum_of_text_dump: skipped (set QUADRECOMB_OPTIMUM_DUMP to a dump file)");
        return;
    };
    let text = std::fs::read_to_string(&path).expect("read dump");
    let mut it = text.split_ascii_whitespace();
    let mut next = || it.next().expect("more numbers");
    let n: usize = next().parse().expect("n");
    let mut data = MeshData::default();
    for _ in 0..n {
        let p = [(); 3].map(|_| next().parse::<f64>().expect("coordinate"));
        data.vertices.push(p);
    }
    let m: usize = next().parse().expect("m");
    for _ in 0..m {
        let t = [(); 3].map(|_| next().parse::<u32>().expect("node"));
        data.triangles.push(t);
        data.triangle_surface.push(next().parse().expect("surface"));
    }
    let mesh = Mesh::new(data).expect("valid mesh");
    let table = CandidateTable::build(&mesh);
    // On-CPU time of this thread (ns), from the scheduler: robust to a loaded machine.
    let cpu_ns = || -> Option<u64> {
        std::fs::read_to_string("/proc/thread-self/schedstat")
            .ok()?
            .split_whitespace()
            .next()?
            .parse()
            .ok()
    };
    let mut best = f64::INFINITY;
    let c0 = cpu_ns();
    for _ in 0..20 {
        best = best.min(optimum::solve(&mesh, &table).time_s);
    }
    if let (Some(a), Some(b)) = (c0, cpu_ns()) {
        println!("mean on-CPU time per solve: {:.4} s", (b - a) as f64 / 20e9);
    }
    let (opt, report) = optimum::solve_certified(&mesh, &table, true);
    let g = optimum::graph(&mesh, &table);
    let stats = blossom::solve(&g).stats;
    println!(
        "{path}: {} triangles, {} quads, {} left, quality {:.4}, best of 20 {:.4} s, check {:?}, {stats:?}",
        mesh.num_triangles(),
        opt.quads,
        opt.triangles_left,
        opt.quality,
        best,
        report.expect("checked")
    );
}

#[test]
fn cli_writes_the_optimal_quad_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let out = crate::util::run_in(dir.path(), &["optimum", "sphere", "-o", "opt.msh"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let path = dir.path().join("opt.msh");
    let file =
        quadrecomb::internals::mesh::msh::parse(&path, &std::fs::read(&path).unwrap()).unwrap();
    // All 2,104 triangles of the built-in sphere pair up: 1,052 quads, no triangle left.
    assert_eq!(
        (file.data.quads.len(), file.data.triangles.len()),
        (1052, 0),
        "read back"
    );
    let bad = crate::util::run_in(dir.path(), &["optimum", "sphere", "-o", "opt.txt"]);
    assert_eq!(bad.status.code(), Some(2));
}
