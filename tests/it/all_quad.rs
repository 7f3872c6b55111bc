//! All-quad (`--finish --all-quad`, `src/finish/split_choice.rs`, `all_quad.rs`): on meshes
//! with odd components no triangle is left wherever a boundary split can make a component
//! perfectly matchable, and a clear error names the component where none can. Checked against
//! a brute-force oracle (every boundary side of every odd component split by this file's own
//! code, the exact optimum of each split mesh), and from the written files as meshio reads
//! them (`all_quad_check.py`).

use crate::util::{python, python_module_available, run_in};
use quadrecomb::internals::finish::{FinishConfig, FinishError, Finished, StuckReason, finish};
use quadrecomb::internals::mesh::generate::{GridSpec, grid, lattice};
use quadrecomb::internals::mesh::{Mesh, MeshData};
use quadrecomb::internals::quality::{self, CandidateTable, Rule};
use quadrecomb::internals::search::{Algo, Searcher, optimum};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::{Path, PathBuf};

/// The table of `mesh` under the valid-quad rule.
fn valid_table(mesh: &Mesh) -> CandidateTable {
    CandidateTable::build(mesh).restrict(mesh, Rule::default())
}

/// `mesh` without the triangles `drop` (unused vertices removed).
pub(crate) fn without(mesh: &Mesh, drop: &[u32]) -> Mesh {
    let gone: std::collections::HashSet<u32> = drop.iter().copied().collect();
    let triangles: Vec<[u32; 3]> = (0..mesh.num_triangles() as u32)
        .filter(|t| !gone.contains(t))
        .map(|t| mesh.triangles[t as usize])
        .collect();
    compact(&mesh.vertices, triangles)
}

fn compact(vertices: &[[f64; 3]], triangles: Vec<[u32; 3]>) -> Mesh {
    let mut new_of = vec![u32::MAX; vertices.len()];
    let mut kept = Vec::new();
    let triangles = triangles
        .into_iter()
        .map(|t| {
            t.map(|v| {
                if new_of[v as usize] == u32::MAX {
                    new_of[v as usize] = kept.len() as u32;
                    kept.push(vertices[v as usize]);
                }
                new_of[v as usize]
            })
        })
        .collect();
    Mesh::new(MeshData {
        vertices: kept,
        triangles,
        ..MeshData::default()
    })
    .expect("a valid mesh")
}

/// Sides used by one triangle, as sorted vertex pairs.
fn boundary_sides(mesh: &Mesh) -> std::collections::HashSet<[u32; 2]> {
    let mut count = std::collections::HashMap::new();
    for t in &mesh.triangles {
        for i in 0..3 {
            let mut e = [t[i], t[(i + 1) % 3]];
            e.sort_unstable();
            *count.entry(e).or_insert(0) += 1;
        }
    }
    count
        .into_iter()
        .filter(|&(_, n)| n == 1)
        .map(|(e, _)| e)
        .collect()
}

/// The triangles of the lattice `mesh` with two boundary sides (its corners).
fn corners(mesh: &Mesh) -> Vec<u32> {
    let b = boundary_sides(mesh);
    (0..mesh.num_triangles() as u32)
        .filter(|&t| {
            let tri = mesh.triangles[t as usize];
            (0..3)
                .filter(|&i| {
                    let mut e = [tri[i], tri[(i + 1) % 3]];
                    e.sort_unstable();
                    b.contains(&e)
                })
                .count()
                >= 2
        })
        .collect()
}

/// What the oracle says of one component that keeps triangles.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Verdict {
    /// The component (of the valid-pair dual graph of the unsplit mesh).
    component: u32,
    /// Triangles the exact optimum leaves in it.
    left: usize,
    /// Some single split fixes it: a boundary side of one of its triangles split at its
    /// midpoint (by this function's own code) whose mesh's exact optimum leaves none of the
    /// component's triangles (halves included) and fewer triangles in all.
    fixable: bool,
}

/// The oracle, brute force: every boundary side of every triangle of each component that
/// keeps triangles, split and solved exactly. Returns the components' map and one verdict
/// per component that keeps triangles.
fn oracle(mesh: &Mesh) -> (Vec<u32>, Vec<Verdict>) {
    let table = valid_table(mesh);
    let opt = optimum::solve(mesh, &table);
    let (component, sizes) = CandidateTable::components(&table.dual_graph());
    let paired = |table: &CandidateTable, chosen: &[u32], n: usize| {
        let mut used = vec![false; n];
        for &c in chosen {
            for t in table.pairs[c as usize] {
                used[t as usize] = true;
            }
        }
        used
    };
    let used = paired(&table, &opt.chosen, mesh.num_triangles());
    let mut left = vec![0usize; sizes.len()];
    for t in 0..mesh.num_triangles() {
        if !used[t] {
            left[component[t] as usize] += 1;
        }
    }
    let sides = boundary_sides(mesh);
    let mut verdicts = Vec::new();
    for (c, &left_c) in left.iter().enumerate() {
        if left_c == 0 {
            continue;
        }
        let mut fixable = false;
        'search: for t in 0..mesh.num_triangles() {
            if left_c > 1 || component[t] as usize != c {
                continue;
            }
            let tri = mesh.triangles[t];
            for i in 0..3 {
                let (p, q, s) = (tri[i], tri[(i + 1) % 3], tri[(i + 2) % 3]);
                let mut e = [p, q];
                e.sort_unstable();
                if !sides.contains(&e) {
                    continue;
                }
                let (a, b) = (mesh.vertices[p as usize], mesh.vertices[q as usize]);
                let mut vertices = mesh.vertices.clone();
                let m = vertices.len() as u32;
                vertices.push(std::array::from_fn(|d| 0.5 * (a[d] + b[d])));
                let mut triangles = mesh.triangles.clone();
                triangles[t] = [p, m, s];
                triangles.push([m, q, s]);
                let mut surfaces = mesh.triangle_surface.clone();
                surfaces.push(mesh.triangle_surface[t]);
                let split = Mesh::new(MeshData {
                    vertices,
                    triangles,
                    triangle_surface: surfaces,
                    ..MeshData::default()
                })
                .unwrap();
                // The halves' own quad has a straight angle at the new node: its eta may
                // round above 0, but it is no quad.
                let st = valid_table(&split);
                let keep: Vec<bool> = st
                    .pairs
                    .iter()
                    .map(|&pr| pr != [t as u32, mesh.num_triangles() as u32])
                    .collect();
                let st = st.retain(&keep);
                let so = optimum::solve(&split, &st);
                let u = paired(&st, &so.chosen, split.num_triangles());
                let whole = (0..mesh.num_triangles())
                    .filter(|&x| component[x] as usize == c)
                    .chain([mesh.num_triangles()])
                    .all(|x| u[x]);
                if whole && so.triangles_left < opt.triangles_left {
                    fixable = true;
                    break 'search;
                }
            }
        }
        verdicts.push(Verdict {
            component: c as u32,
            left: left_c,
            fixable,
        });
    }
    (component, verdicts)
}

/// Checks all-quad's outcome on `mesh` against the oracle: it succeeds exactly when every
/// component that keeps triangles is fixable, with one split per such component at most;
/// otherwise it names exactly the components the oracle cannot fix. True if it succeeded.
fn agrees_with_oracle(mesh: &Mesh, seed: u64, what: &str, written: &mut Written) -> bool {
    let (component, verdicts) = oracle(mesh);
    let unfixable: Vec<u32> = verdicts
        .iter()
        .filter(|v| !v.fixable)
        .map(|v| v.component)
        .collect();
    match all_quad_into(mesh, seed, Some(written)) {
        Ok(splits) => {
            assert!(
                unfixable.is_empty(),
                "{what}: succeeded where the oracle says no"
            );
            assert!(splits <= verdicts.len(), "{what}");
            true
        }
        Err(FinishError::NotAllQuad(stuck)) => {
            let mut named: Vec<u32> = stuck
                .iter()
                .map(|s| {
                    let t = mesh
                        .triangle_ids
                        .iter()
                        .position(|&id| id == s.element)
                        .unwrap();
                    component[t]
                })
                .collect();
            named.sort_unstable();
            assert_eq!(named, unfixable, "{what}: {stuck:?} vs {verdicts:?}");
            for s in &stuck {
                let v = verdicts.iter().find(|v| v.left == s.left && !v.fixable);
                assert!(v.is_some(), "{what}: {s:?} vs {verdicts:?}");
            }
            false
        }
        Err(e) => panic!("{what}: {e}"),
    }
}

/// Strict convexity from the corners alone (planar meshes).
fn strictly_convex(p: [[f64; 3]; 4]) -> bool {
    let cross: Vec<f64> = (0..4)
        .map(|i| {
            let (a, b, c) = (p[i], p[(i + 1) % 4], p[(i + 2) % 4]);
            (b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0])
        })
        .collect();
    cross.iter().all(|&x| x > 0.0) || cross.iter().all(|&x| x < 0.0)
}

/// All-quad on `mesh` from a selective run of `seed`: `Ok(splits)` with every check passed
/// (no triangle left, quads strictly convex and a matching, the new mesh valid with one node
/// and one triangle per split, each node the midpoint of its side), or the error.
fn all_quad(mesh: &Mesh, seed: u64) -> Result<usize, FinishError> {
    all_quad_into(mesh, seed, None)
}

/// [`all_quad`], writing the input and the result into `written` when it succeeds.
fn all_quad_into(
    mesh: &Mesh,
    seed: u64,
    written: Option<&mut Written>,
) -> Result<usize, FinishError> {
    let table = valid_table(mesh);
    let run = Searcher::new(mesh, &table).run(Algo::selective(1), seed);
    let config = FinishConfig {
        all_quad: true,
        ..FinishConfig::default()
    };
    let f = finish(mesh, &table, &run.chosen, config)?;
    let (m, t) = (f.mesh(mesh), f.table(&table));
    m.sanity_check().unwrap();
    assert_eq!(m.num_triangles(), mesh.num_triangles() + f.splits.len());
    assert_eq!(m.vertices.len(), mesh.vertices.len() + f.splits.len());
    assert_eq!(2 * f.chosen.len(), m.num_triangles(), "all paired");
    assert_eq!(f.improved.triangles_left, 0);
    let mut used = vec![false; m.num_triangles()];
    for &c in &f.chosen {
        for tri in t.pairs[c as usize] {
            assert!(!used[tri as usize]);
            used[tri as usize] = true;
        }
        let q = t.quads[c as usize].map(|v| m.vertices[v as usize]);
        assert!(strictly_convex(q), "{q:?}");
    }
    for s in &f.splits {
        let at = |tag: u64| m.vertices[m.vertex_ids.iter().position(|&x| x == tag).unwrap()];
        let (a, b, n) = (at(s.side[0]), at(s.side[1]), at(s.node));
        for d in 0..3 {
            assert!((n[d] - 0.5 * (a[d] + b[d])).abs() < 1e-12);
        }
    }
    if let Some(w) = written {
        w.add(mesh, &f, &table);
    }
    Ok(f.splits.len())
}

/// Odd components of the valid-pair dual graph.
fn odd_components(mesh: &Mesh) -> usize {
    let (_, sizes) = CandidateTable::components(&valid_table(mesh).dual_graph());
    sizes.iter().filter(|&&s| s % 2 == 1).count()
}

/// The case docs/finish.md reported as failing: a jittered lattice of 612 triangles without
/// its corner triangle. The leftover walked to the nearest boundary and every side tried
/// there left an imbalance of two; now the split is placed where the rest stays matchable.
#[test]
fn all_quad_pairs_every_triangle_of_the_612_lattice_without_its_corner() {
    let mut written = Written::new();
    for seed in 0..4u64 {
        let full = lattice(612, seed);
        assert_eq!(full.num_triangles(), 612);
        let mesh = without(&full, &[0]);
        assert_eq!(odd_components(&mesh), 1);
        let (_, verdicts) = oracle(&mesh);
        assert_eq!(verdicts.len(), 1);
        assert!(verdicts[0].fixable, "seed {seed}: the oracle finds a split");
        let splits = all_quad_into(&mesh, seed, Some(&mut written))
            .unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        assert_eq!(splits, 1);
    }
    assert!(matches!(written.check(), None | Some(4)));
}

/// Lattices with several corners or inner triangles removed (holes whose sides are
/// boundary): all-quad succeeds exactly where the oracle finds a split for every component
/// that keeps a triangle, and names the others; a single corner removed always succeeds.
#[test]
fn all_quad_on_lattices_with_triangles_removed_agrees_with_the_oracle() {
    let (mut ok, mut cases) = (0, 0);
    let mut written = Written::new();
    for seed in 0..3u64 {
        let full = lattice(400 + 60 * seed as usize, seed);
        let c = corners(&full);
        assert!(c.len() >= 2);
        let inner = (full.num_triangles() / 2) as u32;
        let far = (full.num_triangles() / 3) as u32;
        for drop in [
            vec![c[0]],
            vec![c[c.len() - 1]],
            c.clone(),
            vec![c[c.len() - 1], inner],
            vec![inner],
            vec![inner, far, c[0]],
            vec![inner, inner + 1, inner + 2],
        ] {
            let mesh = without(&full, &drop);
            let what = format!("seed {seed}, drop {drop:?}");
            let done = agrees_with_oracle(&mesh, seed, &what, &mut written);
            if drop.len() == 1 && c.contains(&drop[0]) {
                assert!(done, "seed {seed}: one corner removed");
            }
            ok += done as usize;
            cases += 1;
        }
    }
    assert_eq!(cases, 21);
    assert!(ok >= 8, "{ok} of {cases} succeeded");
    // Every success written and checked by meshio (0: meshio missing outside CI).
    let n = written.check();
    assert!(n.is_none_or(|n| n == ok), "{n:?} checked of {ok}");
}

/// Property over seeds: small jittered lattices and grids with random triangles removed;
/// all-quad agrees with the brute-force oracle on each.
#[test]
fn all_quad_succeeds_exactly_where_a_split_can_fix_every_component() {
    let (mut ok, mut cases) = (0, 0);
    let mut written = Written::new();
    for seed in 0..24u64 {
        let mut rng = ChaCha8Rng::seed_from_u64(crate::util::SEED ^ seed);
        let base = if seed % 2 == 0 {
            lattice(rng.random_range(60..220), seed)
        } else {
            grid(GridSpec {
                triangles: rng.random_range(60..220),
                seed,
                jitter: 0.2,
                ..GridSpec::default()
            })
        };
        let n = base.num_triangles() as u32;
        let k = rng.random_range(1..5);
        let mut drop: Vec<u32> = (0..k).map(|_| rng.random_range(0..n)).collect();
        drop.sort_unstable();
        drop.dedup();
        let mesh = without(&base, &drop);
        ok += agrees_with_oracle(&mesh, seed, &format!("seed {seed}"), &mut written) as usize;
        cases += 1;
    }
    // Both outcomes are exercised (random holes often leave an imbalance no split mends).
    assert!(ok >= 4 && cases - ok >= 4, "{ok} of {cases} succeeded");
    let n = written.check();
    assert!(n.is_none_or(|n| n == ok), "{n:?} checked of {ok}");
}

/// A component no split can fix: a lone triangle (every side boundary) beside a lattice.
/// The error names its element and says why.
#[test]
fn all_quad_names_a_component_no_split_can_fix() {
    let base = lattice(200, 1);
    let mut vertices = base.vertices.clone();
    let mut triangles = base.triangles.clone();
    let v = vertices.len() as u32;
    vertices.extend([[50.0, 0.0, 0.0], [51.0, 0.0, 0.0], [50.5, 0.8, 0.0]]);
    triangles.push([v, v + 1, v + 2]);
    let mesh = compact(&vertices, triangles);
    let lone_id = mesh.triangle_ids[mesh.num_triangles() - 1];
    match all_quad(&mesh, 0) {
        Err(FinishError::NotAllQuad(stuck)) => {
            assert_eq!(stuck.len(), 1, "{stuck:?}");
            assert_eq!(stuck[0].element, lone_id);
            assert_eq!(stuck[0].size, 1);
            assert_eq!(stuck[0].reason, StuckReason::NoSplittableSide);
            let text = FinishError::NotAllQuad(stuck).to_string();
            assert!(
                text.contains(&format!("element {lone_id}")) && text.contains("boundary side"),
                "{text}"
            );
        }
        other => panic!("expected NotAllQuad, got {other:?}"),
    }
}

// ---------------------------------------------------------------- written files

/// Writes `mesh` (triangles only) to `path`.
pub(crate) fn write_input(mesh: &Mesh, path: &Path) {
    let table = valid_table(mesh);
    let rec = quality::recombined(mesh, &table, &[]);
    quadrecomb::internals::mesh::msh::write(path, mesh, &rec).unwrap();
}

/// Runs `all_quad_check.py` on `input` and `output`; asserts what it reports and returns
/// the number of new nodes.
pub(crate) fn check_written(input: &Path, output: &Path) -> usize {
    check_written_all(&[(input.to_path_buf(), output.to_path_buf())])[0]
}

/// [`check_written`] for many pairs, in one Python process.
fn check_written_all(pairs: &[(PathBuf, PathBuf)]) -> Vec<usize> {
    let script = include_str!("all_quad_check.py");
    let args: Vec<&Path> = pairs
        .iter()
        .flat_map(|(a, b)| [a.as_path(), b.as_path()])
        .collect();
    let text = python(script, &args);
    // meshio may print notes of its own (blank lines included): keep the JSON objects.
    let lines: Vec<&str> = text.lines().filter(|l| l.starts_with('{')).collect();
    assert_eq!(lines.len(), pairs.len(), "{text}");
    pairs
        .iter()
        .zip(lines)
        .map(|((_, output), line)| {
            let v: serde_json::Value = serde_json::from_str(line.trim()).unwrap();
            let what = format!("{}: {v}", output.display());
            assert_eq!(v["triangles"], 0, "{what}");
            assert_eq!(v["nonconvex"], 0, "{what}");
            assert_eq!(v["new_nodes_off_boundary_side"], 0, "{what}");
            assert_eq!(v["edges_over_two"], 0, "{what}");
            assert_eq!(v["hanging_edges"], 0, "{what}");
            let new = v["new_nodes"].as_u64().unwrap();
            let (tin, qin, q) = (
                v["input_triangles"].as_u64().unwrap(),
                v["input_quads"].as_u64().unwrap(),
                v["quads"].as_u64().unwrap(),
            );
            assert_eq!(2 * (q - qin), tin + new, "{what}");
            let (a, b) = (
                v["area_in"].as_f64().unwrap(),
                v["area_out"].as_f64().unwrap(),
            );
            // A non-planar quad's (Newell) area is not its two triangles' sum: loose on
            // surfaces.
            let tol = if v["planar"] == true { 1e-9 } else { 1e-3 };
            assert!((a - b).abs() <= tol * a.max(1.0), "{what}");
            new as usize
        })
        .collect()
}

/// The all-quad results of a test written as .msh (input and finished mesh, by our writer),
/// checked by meshio in one go at the end.
struct Written {
    dir: tempfile::TempDir,
    pairs: Vec<(PathBuf, PathBuf)>,
    splits: Vec<usize>,
}

impl Written {
    fn new() -> Written {
        Written {
            dir: tempfile::tempdir().unwrap(),
            pairs: Vec::new(),
            splits: Vec::new(),
        }
    }

    fn add(&mut self, input: &Mesh, f: &Finished, table: &CandidateTable) {
        let k = self.pairs.len();
        let (a, b) = (
            self.dir.path().join(format!("in{k}.msh")),
            self.dir.path().join(format!("out{k}.msh")),
        );
        write_input(input, &a);
        let rec = quality::recombined(f.mesh(input), f.table(table), &f.chosen);
        quadrecomb::internals::mesh::msh::write(&b, f.mesh(input), &rec).unwrap();
        self.pairs.push((a, b));
        self.splits.push(f.splits.len());
    }

    /// Checks every file written; returns how many (`None` without meshio, outside CI).
    fn check(&self) -> Option<usize> {
        if !python_module_available("meshio") {
            return None;
        }
        if self.pairs.is_empty() {
            return Some(0);
        }
        let new = check_written_all(&self.pairs);
        assert_eq!(new, self.splits, "one new node per split");
        Some(new.len())
    }
}

/// `recombine --finish --all-quad -o` on lattices with corners removed writes only strictly
/// convex quads, each new node on an input boundary side, conforming (.msh and .vtu read by
/// meshio); the text names where the nodes are.
#[test]
fn cli_all_quad_files_of_lattices_without_corners_check_out_in_meshio() {
    if !python_module_available("meshio") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (lattice(612, 0), lattice(400, 1));
    let last = *corners(&b).last().unwrap();
    for (name, mesh) in [("one", without(&a, &[0])), ("other", without(&b, &[last]))] {
        let input = dir.path().join(format!("{name}.msh"));
        write_input(&mesh, &input);
        for out in [format!("{name}-aq.msh"), format!("{name}-aq.vtu")] {
            let run = run_in(
                dir.path(),
                &[
                    "recombine",
                    &format!("{name}.msh"),
                    "--algo",
                    "selective",
                    "--finish",
                    "--all-quad",
                    "-o",
                    &out,
                ],
            );
            assert!(
                run.status.success(),
                "{name}: {}",
                String::from_utf8_lossy(&run.stderr)
            );
            let text = String::from_utf8_lossy(&run.stdout);
            assert!(text.contains("on the chord"), "{text}");
            let new = check_written(&input, &dir.path().join(&out));
            assert_eq!(
                new,
                odd_components(&mesh),
                "{name}: one node per odd component"
            );
        }
    }
}

/// The suite's meshes with odd components: where every odd component has a boundary
/// triangle whose split keeps the rest matchable (vase-revolution, many-holes),
/// `recombine --finish --all-quad` leaves no triangle, as meshio reads the file; where one
/// has none (odd-pieces: proven by the oracle below; capped-cylinder and materials: odd
/// components with no boundary side at all, only sides shared with another surface) it
/// fails with exit code 3 and names the components.
#[test]
fn cli_all_quad_on_the_suite_meshes_with_odd_components() {
    if !python_module_available("meshio") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    for (name, works) in [
        ("vase-revolution", true),
        ("many-holes", true),
        ("odd-pieces", false),
        ("capped-cylinder", false),
        ("materials", false),
    ] {
        let input = crate::util::repo_path(&format!("meshes/suite/{name}.msh"));
        let out = dir.path().join(format!("{name}-aq.msh"));
        let run = run_in(
            dir.path(),
            &[
                "recombine",
                input.to_str().unwrap(),
                "--algo",
                "selective",
                "--finish",
                "--all-quad",
                "--no-optimum",
                "--json",
                "-o",
                out.to_str().unwrap(),
            ],
        );
        let err = String::from_utf8_lossy(&run.stderr);
        if !works {
            assert_eq!(run.status.code(), Some(3), "{name}: {err}");
            assert!(
                err.contains("all-quad cannot pair every triangle") && err.contains("element"),
                "{name}: {err}"
            );
            assert!(!out.exists());
            continue;
        }
        assert!(run.status.success(), "{name}: {err}");
        let v: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
        assert_eq!(v["finish"]["triangles_left"], 0, "{name}: {v}");
        let splits = v["finish"]["splits"].as_array().unwrap().len();
        assert!(splits >= 1, "{name}: {v}");
        assert_eq!(v["finish"]["split_place"], "chord");
        assert_eq!(check_written(&input, &out), splits, "{name}");
    }
}

/// odd-pieces: the components all-quad refuses are those where no single boundary split
/// works, by brute force over every boundary side.
#[test]
fn all_quad_refuses_on_odd_pieces_only_what_the_oracle_cannot_fix() {
    let mesh = quadrecomb::internals::mesh::load(
        crate::util::repo_path("meshes/suite/odd-pieces.msh")
            .to_str()
            .unwrap(),
    )
    .unwrap();
    assert!(!agrees_with_oracle(
        &mesh,
        0,
        "odd-pieces",
        &mut Written::new()
    ));
}

/// A mesh no split can fix: the command fails with exit code 3 and names the element.
#[test]
fn cli_all_quad_refuses_a_mesh_no_split_can_fix() {
    let dir = tempfile::tempdir().unwrap();
    let base = lattice(200, 1);
    let mut vertices = base.vertices.clone();
    let mut triangles = base.triangles.clone();
    let v = vertices.len() as u32;
    vertices.extend([[50.0, 0.0, 0.0], [51.0, 0.0, 0.0], [50.5, 0.8, 0.0]]);
    triangles.push([v, v + 1, v + 2]);
    let mesh = compact(&vertices, triangles);
    let id = mesh.triangle_ids[mesh.num_triangles() - 1];
    write_input(&mesh, &dir.path().join("lone.msh"));
    let run = run_in(
        dir.path(),
        &[
            "recombine",
            "lone.msh",
            "--algo",
            "greedy",
            "--finish",
            "--all-quad",
            "-o",
            "x.msh",
        ],
    );
    assert_eq!(run.status.code(), Some(3));
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(
        err.contains("lone.msh") && err.contains(&format!("element {id}")),
        "{err}"
    );
    assert!(!dir.path().join("x.msh").exists());
}
