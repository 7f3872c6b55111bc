//! Finishing (`src/finish/`, `recombine --finish`, `sweep --finish`) and `generate lattice`.

use crate::util::{gmsh_available, python, run_in};
use quadrecomb::internals::mesh::Mesh;
use quadrecomb::internals::mesh::generate::lattice;

/// `generate lattice` writes the lattice `bench optimum` times: same nodes, same triangles,
/// read back by the library and by Gmsh with the same counts; bad sizes are usage errors.
#[test]
fn cli_generate_lattice_writes_the_benchmark_lattice() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_in(
        dir.path(),
        &[
            "generate",
            "lattice",
            "--triangles",
            "1000",
            "--seed",
            "3",
            "-o",
            "l.msh",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let want = lattice(1000, 3);
    assert_eq!(want.num_triangles(), 2 * 22 * 23);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains(&format!("{} triangles", want.num_triangles())),
        "{stdout}"
    );
    let back: Mesh = quadrecomb::internals::mesh::msh::read(&dir.path().join("l.msh")).unwrap();
    assert_eq!(
        back.vertices, want.vertices,
        "coordinates round-trip exactly"
    );
    assert_eq!(back.triangles.len(), want.triangles.len());
    let key = |m: &Mesh| {
        let mut v: Vec<[u32; 3]> = m
            .triangles
            .iter()
            .map(|t| {
                let mut k = *t;
                k.sort_unstable();
                k
            })
            .collect();
        v.sort_unstable();
        v
    };
    assert_eq!(key(&back), key(&want));
    // A different seed moves the interior vertices only.
    let other = lattice(1000, 4);
    assert_ne!(other.vertices, want.vertices);
    assert_eq!(key(&other), key(&want));
    for bad in ["0", "1"] {
        let out = run_in(
            dir.path(),
            &["generate", "lattice", "--triangles", bad, "-o", "x.msh"],
        );
        assert_eq!(out.status.code(), Some(2), "--triangles {bad}");
        assert!(String::from_utf8_lossy(&out.stderr).contains("--triangles"));
    }
    if gmsh_available() {
        let script = "import gmsh, sys\n\
            gmsh.initialize(readConfigFiles=False)\n\
            gmsh.option.setNumber('General.Terminal', 0)\n\
            gmsh.open(sys.argv[1])\n\
            types, tags, _ = gmsh.model.mesh.getElements(2)\n\
            print(len(gmsh.model.mesh.getNodes()[0]), sum(len(t) for t in tags))\n";
        let line = python(script, &[&dir.path().join("l.msh")]);
        assert_eq!(
            line.trim(),
            format!("{} {}", want.vertices.len(), want.num_triangles())
        );
    }
}

// ---------------------------------------------------------------- the library's finish

use quadrecomb::internals::finish::{FinishConfig, Finished, finish};
use quadrecomb::internals::mesh::generate::{GridSpec, grid};
use quadrecomb::internals::quality::{CandidateTable, Rule};
use quadrecomb::internals::search::{Algo, Searcher, optimum};

/// The table of `mesh` under the valid-quad rule.
fn valid_table(mesh: &Mesh) -> CandidateTable {
    CandidateTable::build(mesh).restrict(mesh, Rule::default())
}

/// Strict convexity of a planar quad computed here, from its corners alone: the four
/// cross products of consecutive sides are non-zero and of one sign.
fn strictly_convex(p: [[f64; 3]; 4]) -> bool {
    let cross: Vec<f64> = (0..4)
        .map(|i| {
            let (a, b, c) = (p[i], p[(i + 1) % 4], p[(i + 2) % 4]);
            (b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0])
        })
        .collect();
    cross.iter().all(|&x| x > 0.0) || cross.iter().all(|&x| x < 0.0)
}

/// Checks a finished pairing: a matching of the (possibly split) mesh, every quad strictly
/// convex, the figures what the pairing gives; returns (quads, triangles left, quality).
fn check_finished(mesh: &Mesh, table: &CandidateTable, f: &Finished) -> (usize, usize, f64) {
    let (m, t) = (f.mesh(mesh), f.table(table));
    let mut used = vec![false; m.num_triangles()];
    for &c in &f.chosen {
        for tri in t.pairs[c as usize] {
            assert!(!used[tri as usize], "triangle {tri} in two quads");
            used[tri as usize] = true;
        }
        let q = t.quads[c as usize].map(|v| m.vertices[v as usize]);
        assert!(strictly_convex(q), "quad {c} is not strictly convex: {q:?}");
    }
    let quality = t.quality_of(&f.chosen);
    let left = m.num_triangles() - 2 * f.chosen.len();
    assert_eq!(f.improved.quads, f.chosen.len());
    assert_eq!(f.improved.triangles_left, left);
    assert!((f.improved.quality - quality).abs() < 1e-9);
    (f.chosen.len(), left, quality)
}

/// On small jittered meshes, from greedy and selective runs: elimination leaves only what
/// the optimum leaves, improvement never lowers eta, no quad is invalid, and with a window
/// that covers the whole mesh the finish reaches the exact optimum.
#[test]
fn finish_never_lowers_eta_and_reaches_the_optimum_with_a_whole_window() {
    let mut checked = 0;
    for seed in 0..6u64 {
        for mesh in [
            lattice(300 + 40 * seed as usize, seed),
            grid(GridSpec {
                triangles: 300,
                seed,
                jitter: 0.24,
                ..GridSpec::default()
            }),
        ] {
            let table = valid_table(&mesh);
            let opt = optimum::solve(&mesh, &table);
            let mut searcher = Searcher::new(&mesh, &table);
            for algo in [Algo::greedy(), Algo::selective(2)] {
                let run = searcher.run(algo, seed);
                for window in [1, 3] {
                    let config = FinishConfig {
                        window,
                        ..FinishConfig::default()
                    };
                    let f = finish(&mesh, &table, &run.chosen, config).unwrap();
                    let (quads, left, quality) = check_finished(&mesh, &table, &f);
                    assert!(quads >= run.quads);
                    assert_eq!(
                        left, opt.triangles_left,
                        "elimination leaves what the optimum does"
                    );
                    assert_eq!(f.eliminated.triangles_left, opt.triangles_left);
                    assert!(
                        quality >= f.eliminated.quality - 1e-9,
                        "improvement lowered eta"
                    );
                    assert!(quality <= opt.quality + 1e-9);
                    if f.eliminated.quads == run.quads {
                        assert!(f.eliminated.quality >= run.quality - 1e-9);
                    }
                }
                // A window covering the whole mesh is one exact solve: the optimum.
                let whole = FinishConfig {
                    window: mesh.num_triangles() as u32,
                    ..FinishConfig::default()
                };
                let f = finish(&mesh, &table, &run.chosen, whole).unwrap();
                let (_, left, quality) = check_finished(&mesh, &table, &f);
                assert_eq!(left, opt.triangles_left);
                assert!(
                    (quality - opt.quality).abs() < 1e-6,
                    "{quality} vs optimum {}",
                    opt.quality
                );
                checked += 1;
            }
        }
    }
    assert_eq!(checked, 24);
}

/// Finishing the optimum changes nothing (no window can raise it), and finishing nothing
/// (every triangle left) still pairs all the optimum pairs.
#[test]
fn finish_of_the_optimum_is_the_optimum_and_of_nothing_is_maximal() {
    let mesh = lattice(2000, 5);
    let table = valid_table(&mesh);
    let opt = optimum::solve(&mesh, &table);
    let f = finish(&mesh, &table, &opt.chosen, FinishConfig::default()).unwrap();
    assert_eq!(f.chosen, opt.chosen);
    let f = finish(&mesh, &table, &[], FinishConfig::default()).unwrap();
    let (_, left, quality) = check_finished(&mesh, &table, &f);
    assert_eq!(left, opt.triangles_left);
    assert!(quality > 0.97 * opt.quality, "{quality} vs {}", opt.quality);
}

/// Grids with dropped triangles have odd components: without all-quad one triangle stays in
/// each; with it none stays, every quad is strictly convex (recomputed here from the new
/// mesh), the new mesh is valid and has one more node and triangle per split.
#[test]
fn all_quad_leaves_no_triangle_in_odd_components() {
    let grids = [(1u64, 1usize, 1u32), (2, 3, 1)].map(|(seed, drop, surfaces)| {
        grid(GridSpec {
            triangles: 800,
            seed,
            drop_triangles: drop,
            surfaces,
            ..GridSpec::default()
        })
    });
    for (seed, mesh) in grids.into_iter().enumerate() {
        let seed = seed as u64;
        let table = valid_table(&mesh);
        let (_, sizes) = CandidateTable::components(&table.dual_graph());
        let odd = sizes.iter().filter(|&&s| s % 2 == 1).count();
        assert!(odd > 0, "seed {seed}: the mesh has odd components");
        let run = Searcher::new(&mesh, &table).run(Algo::selective(1), seed);
        let plain = finish(&mesh, &table, &run.chosen, FinishConfig::default()).unwrap();
        let (_, left, _) = check_finished(&mesh, &table, &plain);
        assert_eq!(left, optimum::solve(&mesh, &table).triangles_left);
        assert!(left >= odd);
        let config = FinishConfig {
            all_quad: true,
            ..FinishConfig::default()
        };
        let f = finish(&mesh, &table, &run.chosen, config).unwrap();
        let (quads, left, _) = check_finished(&mesh, &table, &f);
        assert_eq!(left, 0, "seed {seed}: all-quad left {left} triangles");
        let m = f.mesh(&mesh);
        m.sanity_check().unwrap();
        assert_eq!(m.num_triangles(), mesh.num_triangles() + f.splits.len());
        assert_eq!(m.vertices.len(), mesh.vertices.len() + f.splits.len());
        assert_eq!(2 * quads, m.num_triangles());
        assert!(f.splits.len() >= odd);
        // The new nodes are the midpoints of the sides they split.
        for s in &f.splits {
            let at = |tag: u64| m.vertices[m.vertex_ids.iter().position(|&x| x == tag).unwrap()];
            let (a, b, n) = (at(s.side[0]), at(s.side[1]), at(s.node));
            for d in 0..3 {
                assert!((n[d] - 0.5 * (a[d] + b[d])).abs() < 1e-12);
            }
        }
    }
}

// ---------------------------------------------------------------- the command line

/// `recombine --finish --all-quad` on a grid with odd components writes a mesh of quads
/// only (.msh and .vtu), every quad strictly convex as meshio reads it, and reports the
/// steps in text and JSON.
#[test]
fn cli_recombine_finish_all_quad_writes_only_convex_quads() {
    let dir = tempfile::tempdir().unwrap();
    let made = run_in(
        dir.path(),
        &[
            "generate",
            "grid",
            "--triangles",
            "800",
            "--seed",
            "1",
            "--drop-triangles",
            "1",
            "-o",
            "g.msh",
        ],
    );
    assert!(made.status.success());
    let plain = run_in(
        dir.path(),
        &[
            "recombine",
            "g.msh",
            "--algo",
            "selective",
            "--horizon",
            "2",
            "--finish",
            "--json",
        ],
    );
    assert!(
        plain.status.success(),
        "{}",
        String::from_utf8_lossy(&plain.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&plain.stdout).unwrap();
    assert_eq!(
        v["finish"]["triangles_left"], 1,
        "one per odd component: {v}"
    );
    assert!(v["finish"]["all_quad"].is_null());
    for out in ["f.msh", "f.vtu"] {
        let run = run_in(
            dir.path(),
            &[
                "recombine",
                "g.msh",
                "--algo",
                "selective",
                "--horizon",
                "2",
                "--finish",
                "--all-quad",
                "-o",
                out,
            ],
        );
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        let text = String::from_utf8_lossy(&run.stdout);
        assert!(text.contains("all-quad"), "{text}");
        assert!(text.contains("on the chord"), "{text}");
        assert!(text.contains("improve"), "{text}");
        if !crate::util::python_module_available("meshio") {
            continue;
        }
        let script = "import meshio, sys\n\
            m = meshio.read(sys.argv[1])\n\
            tri = sum(len(c.data) for c in m.cells if c.type == 'triangle')\n\
            bad = 0\n\
            quads = [c.data for c in m.cells if c.type == 'quad']\n\
            n = 0\n\
            for block in quads:\n\
            \x20   for q in block:\n\
            \x20       n += 1\n\
            \x20       p = m.points[q][:, :2]\n\
            \x20       s = [(p[(i+1)%4][0]-p[i][0])*(p[(i+2)%4][1]-p[(i+1)%4][1]) - (p[(i+1)%4][1]-p[i][1])*(p[(i+2)%4][0]-p[(i+1)%4][0]) for i in range(4)]\n\
            \x20       bad += not (all(x > 0 for x in s) or all(x < 0 for x in s))\n\
            print(tri, n, bad)\n";
        let line = python(script, &[&dir.path().join(out)]);
        let f: Vec<usize> = line
            .split_whitespace()
            .map(|x| x.parse().unwrap())
            .collect();
        assert_eq!(f[0], 0, "{out}: triangles left in the file");
        assert!(f[1] >= 400, "{out}: {line}");
        assert_eq!(f[2], 0, "{out}: non-convex quads");
    }
    // --all-quad needs --finish.
    let bad = run_in(
        dir.path(),
        &["recombine", "g.msh", "--algo", "greedy", "--all-quad"],
    );
    assert_eq!(bad.status.code(), Some(2));
}
