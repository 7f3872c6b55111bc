//! All-quad (`--finish --all-quad`, `src/finish/split_choice.rs`, `all_quad.rs`): on meshes
//! with odd components no triangle is left wherever a boundary split can make a component
//! perfectly matchable, and a clear error names the component where none can. Checked against
//! a brute-force oracle (every boundary side of every odd component split by this file's own
//! code, the exact optimum of each split mesh), and from the written files as meshio reads
//! them (`all_quad_check.py`).

use crate::util::{python, python_module_available, repo_path, run_in, run_ok};
use quadrecomb::internals::finish::{
    FinishConfig, FinishError, Finished, SheetError, SheetStats, finish,
};
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

pub(crate) fn compact(vertices: &[[f64; 3]], triangles: Vec<[u32; 3]>) -> Mesh {
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

/// Checks all-quad's outcome on `mesh` against the oracle: it always leaves no triangle;
/// single splits alone (one per component that keeps triangles at most) exactly when every
/// such component is fixable, sheet refinement otherwise. True if it needed sheets.
fn agrees_with_oracle(mesh: &Mesh, seed: u64, what: &str, written: &mut Written) -> bool {
    let (_, verdicts) = oracle(mesh);
    let unfixable = verdicts.iter().filter(|v| !v.fixable).count();
    let f = all_quad_into(mesh, seed, Some(written)).unwrap_or_else(|e| panic!("{what}: {e}"));
    assert!(f.splits.len() <= verdicts.len(), "{what}");
    assert_eq!(
        f.sheets.sheets > 0,
        unfixable > 0,
        "{what}: sheets {:?} vs {verdicts:?}",
        f.sheets
    );
    if unfixable > 0 {
        // At least the unfixable components' leftovers were refined: 3 quads each.
        assert!(
            f.sheets.sheets >= 3 && f.sheets.triangles_replaced >= 1,
            "{what}"
        );
    }
    f.sheets.sheets > 0
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

/// All-quad on `mesh` from a selective run of `seed`: `Ok(finished)` with every check passed
/// (no triangle left, quads strictly convex and a matching, the new mesh valid with one node
/// and one triangle per split and the sheets' nodes and triangles, each split's node the
/// midpoint of its side), or the error; the input and the result written into `written`
/// when it succeeds.
fn all_quad_into(
    mesh: &Mesh,
    seed: u64,
    written: Option<&mut Written>,
) -> Result<Finished, FinishError> {
    let table = valid_table(mesh);
    let run = Searcher::new(mesh, &table).run(Algo::selective(1), seed);
    let config = FinishConfig {
        all_quad: true,
        ..FinishConfig::default()
    };
    let f = finish(mesh, &table, &run.chosen, config)?;
    let (m, t) = (f.mesh(mesh), f.table(&table));
    m.sanity_check().unwrap();
    let added = f.splits.len() + f.sheets.triangles_added;
    assert_eq!(m.num_triangles(), mesh.num_triangles() + added);
    assert_eq!(
        m.vertices.len(),
        mesh.vertices.len() + f.splits.len() + f.sheets.nodes
    );
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
    Ok(f)
}

/// What the written file of `f` must show: one node and one triangle per split, and the
/// sheets' nodes and triangles (at least the splits' nodes on the boundary).
fn expected(f: &Finished) -> Checked {
    let splits = f.splits.len();
    Checked {
        new_nodes: splits + f.sheets.nodes,
        new_boundary_nodes: splits,
        triangles_added: splits + f.sheets.triangles_added,
    }
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
        let f = all_quad_into(&mesh, seed, Some(&mut written))
            .unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        assert_eq!(f.splits.len(), 1);
        assert_eq!(f.sheets.sheets, 0, "seed {seed}: one split suffices");
    }
    assert!(matches!(written.check(), None | Some(4)));
}

/// Lattices with several corners or inner triangles removed (holes whose sides are
/// boundary): all-quad always leaves no triangle, by single splits exactly where the oracle
/// finds a split for every component that keeps a triangle, with sheets otherwise; a single
/// corner removed never needs sheets.
#[test]
fn all_quad_on_lattices_with_triangles_removed_agrees_with_the_oracle() {
    let (mut sheets, mut cases) = (0, 0);
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
            let used_sheets = agrees_with_oracle(&mesh, seed, &what, &mut written);
            if drop.len() == 1 && c.contains(&drop[0]) {
                assert!(!used_sheets, "seed {seed}: one corner removed");
            }
            sheets += used_sheets as usize;
            cases += 1;
        }
    }
    assert_eq!(cases, 21);
    // Both ways are exercised (docs/finish.md: 2 of the 21 need sheets).
    assert!(
        sheets >= 1 && cases - sheets >= 8,
        "{sheets} of {cases} needed sheets"
    );
    // Every result written and checked by meshio (None: meshio missing outside CI).
    let n = written.check();
    assert!(n.is_none_or(|n| n == cases), "{n:?} checked of {cases}");
}

/// Property over seeds: small jittered lattices and grids with random triangles removed;
/// all-quad leaves no triangle on each (checked from the written files), with sheets exactly
/// where the brute-force oracle finds no single split for some component.
#[test]
fn all_quad_leaves_no_triangle_on_random_meshes_with_sheets_where_no_split_fixes() {
    let (mut sheets, mut cases) = (0, 0);
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
        sheets += agrees_with_oracle(&mesh, seed, &format!("seed {seed}"), &mut written) as usize;
        cases += 1;
    }
    // Both ways are exercised (random holes often leave an imbalance no split mends: 19 of
    // the 24 were refused before sheet refinement).
    assert!(
        sheets >= 4 && cases - sheets >= 4,
        "{sheets} of {cases} needed sheets"
    );
    let n = written.check();
    assert!(n.is_none_or(|n| n == cases), "{n:?} checked of {cases}");
}

/// A component no split can fix: a lone triangle (every side boundary) beside a lattice.
/// Sheet refinement makes it 3 quads (3 sheets, each to the boundary at once: 3 midpoints and
/// the centroid); the lattice is untouched.
#[test]
fn all_quad_refines_a_lone_triangle_into_three_quads() {
    let base = lattice(200, 1);
    let mut vertices = base.vertices.clone();
    let mut triangles = base.triangles.clone();
    let v = vertices.len() as u32;
    vertices.extend([[50.0, 0.0, 0.0], [51.0, 0.0, 0.0], [50.5, 0.8, 0.0]]);
    triangles.push([v, v + 1, v + 2]);
    let mesh = compact(&vertices, triangles);
    let mut written = Written::new();
    let f = all_quad_into(&mesh, 0, Some(&mut written)).unwrap();
    assert!(f.splits.is_empty());
    assert_eq!(
        f.sheets,
        SheetStats {
            sheets: 3,
            nodes: 4,
            triangles_replaced: 1,
            triangles_added: 5,
        }
    );
    let m = f.mesh(&mesh);
    // The centroid, and the three midpoints.
    let at = |p: [f64; 3]| {
        m.vertices
            .iter()
            .any(|q| (0..3).all(|d| (q[d] - p[d]).abs() < 1e-12))
    };
    assert!(at([50.5, 0.8 / 3.0, 0.0]));
    assert!(at([50.5, 0.0, 0.0]) && at([50.75, 0.4, 0.0]) && at([50.25, 0.4, 0.0]));
    assert!(matches!(written.check(), None | Some(1)));
}

/// `recombine INPUT --algo selective --finish --all-quad --json -o out.msh` in `dir`: its
/// JSON object (the command must succeed).
fn cli_all_quad(dir: &Path, input: &Path) -> serde_json::Value {
    let mut args = vec!["recombine", input.to_str().unwrap()];
    args.extend(["--algo", "selective", "--finish", "--all-quad", "--json"]);
    args.extend(["-o", "out.msh"]);
    serde_json::from_slice(&run_ok(dir, &args).stdout).unwrap()
}

/// Sheets cross edges where three surfaces meet (a box's faces and a wall across it, shells
/// with odd surfaces that no split fixes, a Gmsh mesh): every surface on such an edge gets
/// its midpoint, so the output conforms (checked by meshio: no hanging edge, every edge used
/// by one, two, or as many elements as the input edge it lies on). Refused before, at the
/// first such edge a sheet reached.
#[test]
fn cli_all_quad_sheets_cross_edges_where_three_surfaces_meet() {
    if !python_module_available("meshio") {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let input = repo_path("tests/data/box_wall_41_ascii.msh");
    let v = cli_all_quad(tmp.path(), &input);
    assert!(v["finish"]["sheets"]["sheets"].as_u64().unwrap() > 0, "{v}");
    let script = include_str!("all_quad_check.py");
    let text = python(script, &[input.as_path(), &tmp.path().join("out.msh")]);
    let line = text.lines().find(|l| l.starts_with('{')).unwrap();
    let c: serde_json::Value = serde_json::from_str(line).unwrap();
    assert!(c["input_junction_edges"].as_u64().unwrap() > 10, "{c}");
    check_written(&input, &tmp.path().join("out.msh"));
}

/// A Gmsh file with input quads (one square recombined by Gmsh, the other of 73 triangles):
/// the split's new triangle gets a tag no element has. The input quads were renumbered from
/// the triangle count up, onto the triangles' own tags (a Gmsh file's point and line
/// elements come first), and every such all-quad failed: "element tag 75 is given to two
/// elements".
#[test]
fn cli_all_quad_on_a_gmsh_file_with_input_quads() {
    if !python_module_available("meshio") {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let input = repo_path("tests/data/mixed_odd_41_ascii.msh");
    let v = cli_all_quad(tmp.path(), &input);
    assert_eq!(v["finish"]["triangles_left"], 0, "{v}");
    let c = check_written(&input, &tmp.path().join("out.msh"));
    assert!(c.new_nodes > 0, "{c:?}");
}

/// A sheet that reaches a side shared with an input quad cannot go on conformingly: a clear
/// error naming the element and the side, nothing half made.
#[test]
fn all_quad_sheet_stops_with_an_error_at_an_input_quad() {
    let mesh = Mesh::new(MeshData {
        vertices: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.5, 0.8, 0.0],
            [0.0, -1.0, 0.0],
            [1.0, -1.0, 0.0],
        ],
        triangles: vec![[0, 1, 2]],
        quads: vec![[0, 3, 4, 1]],
        ..MeshData::default()
    })
    .unwrap();
    let tri_id = mesh.triangle_ids[0];
    let table = valid_table(&mesh);
    let config = FinishConfig {
        all_quad: true,
        ..FinishConfig::default()
    };
    match finish(&mesh, &table, &[], config) {
        Err(e @ FinishError::Sheet(SheetError::Blocked { .. })) => {
            let text = e.to_string();
            assert!(
                text.contains(&format!("element {tri_id}")) && text.contains("input quad"),
                "{text}"
            );
        }
        other => panic!("expected a blocked sheet, got {other:?}"),
    }
}

// ---------------------------------------------------------------- written files

/// Writes `mesh` (triangles only) to `path`.
pub(crate) fn write_input(mesh: &Mesh, path: &Path) {
    let table = valid_table(mesh);
    let rec = quality::recombined(mesh, &table, &[]);
    quadrecomb::internals::mesh::msh::write(path, mesh, &rec).unwrap();
}

/// What `all_quad_check.py` found in one written file, beside what it asserts always (no
/// triangle, every quad strictly convex, conforming, every new node on the boundary inside an
/// input boundary side, area kept).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Checked {
    /// Nodes not in the input.
    pub new_nodes: usize,
    /// Of those, the ones on the output's boundary (each inside an input boundary side).
    pub new_boundary_nodes: usize,
    /// Triangles the output's quads stand for beyond the input's: `2 x quads - input
    /// triangles` (input quads aside): one per split, and the sheets' added triangles.
    pub triangles_added: usize,
}

impl Checked {
    /// What a finish that only split boundary sides writes: one node per split, on an input
    /// boundary side, one triangle more per split.
    pub fn of_splits(splits: usize) -> Checked {
        Checked {
            new_nodes: splits,
            new_boundary_nodes: splits,
            triangles_added: splits,
        }
    }
}

/// Runs `all_quad_check.py` on `input` and `output`; asserts what it always must hold and
/// returns the rest.
pub(crate) fn check_written(input: &Path, output: &Path) -> Checked {
    check_written_all(&[(input.to_path_buf(), output.to_path_buf())])[0]
}

/// [`check_written`] for many pairs, in one Python process.
fn check_written_all(pairs: &[(PathBuf, PathBuf)]) -> Vec<Checked> {
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
            assert_eq!(v["new_boundary_nodes_off_boundary_side"], 0, "{what}");
            assert_eq!(v["edges_over_two"], 0, "{what}");
            assert_eq!(v["hanging_edges"], 0, "{what}");
            let new = v["new_nodes"].as_u64().unwrap();
            let new_boundary = v["new_boundary_nodes"].as_u64().unwrap();
            // Inner new nodes are exactly those off every input boundary side.
            assert_eq!(
                v["new_nodes_off_boundary_side"].as_u64().unwrap(),
                new - new_boundary,
                "{what}"
            );
            let (tin, qin, q) = (
                v["input_triangles"].as_u64().unwrap(),
                v["input_quads"].as_u64().unwrap(),
                v["quads"].as_u64().unwrap(),
            );
            let (a, b) = (
                v["area_in"].as_f64().unwrap(),
                v["area_out"].as_f64().unwrap(),
            );
            // A non-planar quad's (Newell) area is not its two triangles' sum: loose on
            // surfaces.
            let tol = if v["planar"] == true { 1e-9 } else { 1e-3 };
            assert!((a - b).abs() <= tol * a.max(1.0), "{what}");
            Checked {
                new_nodes: new as usize,
                new_boundary_nodes: new_boundary as usize,
                triangles_added: (2 * (q - qin) - tin) as usize,
            }
        })
        .collect()
}

/// The all-quad results of a test written as .msh (input and finished mesh, by our writer),
/// checked by meshio in one go at the end.
struct Written {
    dir: tempfile::TempDir,
    pairs: Vec<(PathBuf, PathBuf)>,
    expected: Vec<Checked>,
}

impl Written {
    fn new() -> Written {
        Written {
            dir: tempfile::tempdir().unwrap(),
            pairs: Vec::new(),
            expected: Vec::new(),
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
        self.expected.push(expected(f));
    }

    /// Checks every file written; returns how many (`None` without meshio, outside CI).
    fn check(&self) -> Option<usize> {
        if !python_module_available("meshio") {
            return None;
        }
        if self.pairs.is_empty() {
            return Some(0);
        }
        let found = check_written_all(&self.pairs);
        assert_eq!(found.len(), self.expected.len());
        for (f, e) in found.iter().zip(&self.expected) {
            assert_eq!(
                f.new_nodes, e.new_nodes,
                "one node per split, the sheets' nodes"
            );
            assert_eq!(f.triangles_added, e.triangles_added);
            // Splits only: every new node on the boundary. With sheets, the splits' nodes
            // and the ends of sheets that reach the boundary.
            if e.new_nodes == e.new_boundary_nodes {
                assert_eq!(f.new_boundary_nodes, e.new_boundary_nodes, "splits only");
            } else {
                assert!(
                    f.new_boundary_nodes >= e.new_boundary_nodes,
                    "{f:?} vs {e:?}"
                );
            }
        }
        Some(found.len())
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
            let found = check_written(&input, &dir.path().join(&out));
            assert_eq!(
                found,
                Checked::of_splits(odd_components(&mesh)),
                "{name}: one node per odd component"
            );
        }
    }
}

/// The suite's meshes with odd components: `recombine --finish --all-quad` leaves no
/// triangle on each, as meshio reads the file (strictly convex, conforming, new boundary nodes
/// on input boundary sides, area kept). Where every odd component has a boundary triangle
/// whose split keeps the rest matchable (vase-revolution, many-holes) by single splits only;
/// where one has none (odd-pieces: proven by the oracle below; capped-cylinder and materials:
/// odd components with no boundary side at all, only sides shared with another surface) by
/// sheet refinement there (these three were refused with exit code 3 before).
#[test]
fn cli_all_quad_on_the_suite_meshes_with_odd_components() {
    if !python_module_available("meshio") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    for (name, needs_sheets) in [
        ("vase-revolution", false),
        ("many-holes", false),
        ("odd-pieces", true),
        ("capped-cylinder", true),
        ("materials", true),
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
        assert!(run.status.success(), "{name}: {err}");
        let v: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
        let f = &v["finish"];
        assert_eq!(f["triangles_left"], 0, "{name}: {v}");
        let splits = f["splits"].as_array().unwrap().len();
        let found = check_written(&input, &out);
        if !needs_sheets {
            assert!(splits >= 1, "{name}: {v}");
            assert_eq!(f["split_place"], "chord");
            assert!(f["sheets"].is_null(), "{name}: {v}");
            assert_eq!(found, Checked::of_splits(splits), "{name}");
            continue;
        }
        let s = &f["sheets"];
        assert!(s["sheets"].as_u64().unwrap() >= 1, "{name}: {v}");
        let (nodes, added) = (
            s["nodes_added"].as_u64().unwrap() as usize,
            s["triangles_added"].as_u64().unwrap() as usize,
        );
        assert_eq!(found.new_nodes, splits + nodes, "{name}: {v}");
        assert_eq!(found.triangles_added, splits + added, "{name}: {v}");
        assert!(found.new_boundary_nodes >= splits, "{name}: {v}");
    }
}

/// odd-pieces: all-quad needs sheets there, because the oracle proves some component has no
/// single boundary split that works (brute force over every boundary side); the result leaves
/// no triangle, checked from the written file.
#[test]
fn all_quad_needs_sheets_on_odd_pieces_where_the_oracle_finds_no_split() {
    let mesh = quadrecomb::internals::mesh::load(
        crate::util::repo_path("meshes/suite/odd-pieces.msh")
            .to_str()
            .unwrap(),
    )
    .unwrap();
    let mut written = Written::new();
    assert!(agrees_with_oracle(&mesh, 0, "odd-pieces", &mut written));
    assert!(matches!(written.check(), None | Some(1)));
}

/// A mesh no split can fix (a lone triangle beside a lattice): the command refines it by
/// sheets and writes only quads, as meshio reads the file.
#[test]
fn cli_all_quad_refines_a_mesh_no_split_can_fix() {
    let dir = tempfile::tempdir().unwrap();
    let base = lattice(200, 1);
    let mut vertices = base.vertices.clone();
    let mut triangles = base.triangles.clone();
    let v = vertices.len() as u32;
    vertices.extend([[50.0, 0.0, 0.0], [51.0, 0.0, 0.0], [50.5, 0.8, 0.0]]);
    triangles.push([v, v + 1, v + 2]);
    let mesh = compact(&vertices, triangles);
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
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{err}");
    let text = String::from_utf8_lossy(&run.stdout);
    assert!(
        text.contains("sheets        3 sheets") && text.contains("4 nodes added"),
        "{text}"
    );
    if python_module_available("meshio") {
        let found = check_written(&dir.path().join("lone.msh"), &dir.path().join("x.msh"));
        assert_eq!(found.new_nodes, 4);
        assert_eq!(found.new_boundary_nodes, 3);
        assert_eq!(found.triangles_added, 5);
    }
}

/// A refined mesh's quality is still given as a % of the input's optimum, which it can
/// exceed (odd-pieces: 115 %): the text says so where all-quad added triangles, and only there.
#[test]
fn cli_all_quad_says_its_percentages_are_of_the_input() {
    let dir = tempfile::tempdir().unwrap();
    let input = crate::util::repo_path("meshes/suite/odd-pieces.msh");
    let text = |extra: &[&str]| {
        let mut args = vec![input.to_str().unwrap(), "--algo", "greedy", "--finish"];
        args.extend_from_slice(extra);
        args.insert(0, "recombine");
        let run = run_in(dir.path(), &args);
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        String::from_utf8_lossy(&run.stdout).into_owned()
    };
    let note = "% above are of the input mesh's optimum";
    let refined = text(&["--all-quad"]);
    assert!(
        refined.contains("note          all-quad added"),
        "{refined}"
    );
    assert!(refined.contains(note), "{refined}");
    let plain = text(&[]);
    assert!(!plain.contains(note), "{plain}");
}
