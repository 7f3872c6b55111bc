//! `sweep --finish --all-quad` and `replay -o` of finished runs: records keep the finish
//! object plus what all-quad did (splits, nodes added, counted on the split mesh), replay
//! rebuilds the split mesh from the record and `-o` writes the finished mesh, as meshio reads
//! it; other all-quad settings are refused on resume.

use crate::all_quad::{Checked, check_written, without, write_input};
use crate::runner::{records, stderr, sweep};
use crate::util::{SEED, python, python_module_available, run_in};
use quadrecomb::internals::experiment::manifest::Manifest;
use quadrecomb::internals::mesh::generate::lattice;

fn args(out: &str, finish: &[&str]) -> Vec<String> {
    args_of("selective", out, finish)
}

fn args_of(algo: &str, out: &str, finish: &[&str]) -> Vec<String> {
    let mut a: Vec<String> = [
        "sweep",
        "--mesh",
        "one.msh",
        "--algo",
        algo,
        "optimum",
        "--horizons",
        "1",
        "--runs",
        "2",
        "--seed",
        &SEED.to_string(),
        "--backend",
        "cpu",
        "--threads",
        "2",
        "--out",
        out,
        "-q",
    ]
    .map(String::from)
    .to_vec();
    a.extend(finish.iter().map(|s| s.to_string()));
    a
}

/// Triangles in a written mesh, as meshio reads it.
fn triangles_in(path: &std::path::Path) -> usize {
    let script = "import meshio, sys\n\
        m = meshio.read(sys.argv[1])\n\
        print(sum(len(c.data) for c in m.cells if c.type == 'triangle'))\n";
    python(script, &[path]).trim().parse().unwrap()
}

#[test]
fn sweep_finish_all_quad_records_splits_and_replay_writes_the_finished_mesh() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    // 611 triangles, one odd component: the optimum leaves one triangle.
    let mesh = without(&lattice(612, 0), &[0]);
    write_input(&mesh, &dir.join("one.msh"));
    let out = sweep(dir, &args("aq", &["--finish", "--all-quad"]), &[]);
    assert!(out.status.success(), "{}", stderr(&out));
    let manifest = Manifest::read(&dir.join("aq")).unwrap();
    let settings = manifest.spec.finish.unwrap();
    assert!(settings.all_quad);
    assert_eq!(manifest.optimum[0].triangles_left, 1);
    let recs = records(&dir.join("aq"));
    assert_eq!(recs.len(), 3);
    for r in &recs {
        if r.algo == "optimum" {
            assert!(r.finish.is_none());
            continue;
        }
        let f = r.finish.as_ref().unwrap();
        let a = f.all_quad.expect("all-quad figures in the record");
        assert_eq!((a.splits, a.nodes_added), (1, 1), "{}", r.key());
        assert_eq!(f.triangles_left, 0);
        assert_eq!(2 * f.quads, r.triangles + 1);
        assert_eq!(f.recombined_pct, 100.0);
        assert!((f.time_s - f.eliminate_s - a.time_s - f.improve_s).abs() < 1e-12);
    }
    let text = std::fs::read_to_string(dir.join("aq/runs.jsonl")).unwrap();
    assert!(
        text.contains("\"all_quad\":{\"splits\":1,\"nodes_added\":1,"),
        "{text}"
    );
    let report = std::fs::read_to_string(dir.join("aq/report.md")).unwrap();
    // A split mesh can hold one more quad than the input: its quality % is marked.
    assert!(
        report.contains(" † |") && report.contains("† Some runs were refined by --all-quad"),
        "{report}"
    );
    assert!(
        report.contains("| selective + finish | 1 | 2 | "),
        "{report}"
    );

    // Replay rebuilds the split mesh and writes the finished mesh.
    let out = run_in(
        dir,
        &[
            "replay",
            "aq",
            "1",
            "--algo",
            "selective",
            "--json",
            "-o",
            "r.msh",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["reproduced"], true);
    assert_eq!(v["finish"]["all_quad"]["splits"], 1);
    assert_eq!(v["finish"]["quads"], v["recorded"]["finish"]["quads"]);
    if python_module_available("meshio") {
        assert_eq!(
            check_written(&dir.join("one.msh"), &dir.join("r.msh")),
            Checked::of_splits(1)
        );
    }

    // Without --all-quad the settings differ: resume refuses.
    let out = sweep(dir, &args("aq", &["--finish"]), &["--resume"]);
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("finish rings 2 window 8 vs finish rings 2 window 8 all-quad"),
        "{}",
        stderr(&out)
    );
    assert!(
        Manifest::read(&dir.join("aq"))
            .unwrap()
            .spec
            .finish
            .unwrap()
            .all_quad
    );

    // A plain --finish sweep of greedy runs: replay -o writes the finished pairing (one
    // triangle left, the odd component's), not the search's.
    let out = sweep(dir, &args_of("greedy", "fin", &["--finish"]), &[]);
    assert!(out.status.success(), "{}", stderr(&out));
    let fin_text = std::fs::read_to_string(dir.join("fin/runs.jsonl")).unwrap();
    assert!(!fin_text.contains("all_quad"), "{fin_text}");
    let recs = records(&dir.join("fin"));
    let r = recs.iter().find(|r| r.algo == "greedy").unwrap();
    let f = r.finish.as_ref().unwrap();
    assert_eq!(f.triangles_left, 1);
    assert!(
        r.triangles_left > 1,
        "the search leaves more: nothing tested"
    );
    let out = run_in(
        dir,
        &["replay", "fin", "0", "--algo", "greedy", "-o", "f.vtu"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    if python_module_available("meshio") {
        assert_eq!(triangles_in(&dir.join("f.vtu")), 1);
    }
}

/// A mesh no single split fixes (a lone triangle beside a lattice): `sweep --finish
/// --all-quad` finishes every run by sheet refinement, the records say so additively
/// (`sheets`, `sheet_nodes`, ... within `finish.all_quad`), and replay reproduces the run and
/// writes the refined mesh, as meshio reads it.
#[test]
fn sweep_finish_all_quad_with_sheets_records_them_and_replay_reproduces() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let base = lattice(200, 1);
    let mut vertices = base.vertices.clone();
    let mut triangles = base.triangles.clone();
    let v = vertices.len() as u32;
    vertices.extend([[50.0, 0.0, 0.0], [51.0, 0.0, 0.0], [50.5, 0.8, 0.0]]);
    triangles.push([v, v + 1, v + 2]);
    let mesh = crate::all_quad::compact(&vertices, triangles);
    write_input(&mesh, &dir.join("one.msh"));
    let out = sweep(dir, &args("aq", &["--finish", "--all-quad"]), &[]);
    assert!(out.status.success(), "{}", stderr(&out));
    let recs = records(&dir.join("aq"));
    let mut finished = 0;
    for r in &recs {
        if r.algo == "optimum" {
            continue;
        }
        let f = r.finish.as_ref().unwrap();
        let a = f.all_quad.expect("all-quad figures in the record");
        assert_eq!(a.splits, 0, "{}", r.key());
        assert_eq!((a.sheets, a.sheet_nodes, a.nodes_added), (3, 4, 4));
        assert_eq!(
            (a.sheet_triangles_replaced, a.sheet_triangles_added),
            (1, 5)
        );
        assert_eq!(f.triangles_left, 0);
        assert_eq!(2 * f.quads, r.triangles + 5);
        finished += 1;
    }
    assert_eq!(finished, 2);
    // The refined mesh has more quads than the input allows: the report marks its quality %
    // (not comparable to the input's optimum) and says why.
    let report = std::fs::read_to_string(dir.join("aq/report.md")).unwrap();
    assert!(
        report.contains("| selective + finish | 1 | 2 |") && report.contains(" † |"),
        "{report}"
    );
    assert!(
        report.contains("† Some runs were refined by --all-quad"),
        "{report}"
    );
    let text = std::fs::read_to_string(dir.join("aq/runs.jsonl")).unwrap();
    assert!(
        text.contains("\"sheets\":3,\"sheet_nodes\":4,\"sheet_triangles_replaced\":1,\"sheet_triangles_added\":5"),
        "{text}"
    );
    let out = run_in(
        dir,
        &[
            "replay",
            "aq",
            "1",
            "--algo",
            "selective",
            "--json",
            "-o",
            "r.msh",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["reproduced"], true, "{v}");
    assert_eq!(v["finish"]["all_quad"]["sheets"], 3, "{v}");
    if python_module_available("meshio") {
        let found = check_written(&dir.join("one.msh"), &dir.join("r.msh"));
        assert_eq!((found.new_nodes, found.triangles_added), (4, 5));
    }
}
