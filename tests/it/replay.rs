//! `quadrecomb replay` (issue 27 items 4 and 5): a record of a sweep re-run from its seed with
//! the record's mesh, eta and rule gives the recorded result, on the CPU twin and on the
//! default backend; the exported mesh is read by Gmsh and meshio; what cannot be reproduced
//! is refused with a message and writes nothing.

use crate::util::{SEED, gmsh_available, python, run_in};
use quadrecomb::internals::experiment::record::RunRecord;
use quadrecomb::internals::experiment::store;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Output;

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A small sweep of `mesh` (greedy and selective h = 1, 2; 3 runs) into `dir/name`.
fn sweep(dir: &Path, mesh: &str, name: &str, extra: &[&str]) -> PathBuf {
    let seed = SEED.to_string();
    let mut args = vec![
        "sweep",
        "--mesh",
        mesh,
        "--algo",
        "greedy",
        "selective",
        "--horizons",
        "1,2",
        "--runs",
        "3",
        "--seed",
        &seed,
        "--no-report",
        "-q",
        "--out",
        name,
    ];
    args.extend_from_slice(extra);
    let o = run_in(dir, &args);
    assert!(o.status.success(), "sweep: {}", stderr(&o));
    dir.join(name)
}

fn records(dir: &Path) -> Vec<RunRecord> {
    store::read(&dir.join("runs.jsonl")).unwrap().records
}

/// `quadrecomb replay DIR RUN --algo A [--horizon H] --json [extra]` for `r`, in `cwd`.
fn replay(cwd: &Path, dir: &Path, run: &str, r: &RunRecord, extra: &[&str]) -> Output {
    let h = r.horizon.map(|h| h.to_string());
    let mut args = vec![
        "replay",
        dir.to_str().unwrap(),
        run,
        "--algo",
        &r.algo,
        "--json",
    ];
    if let Some(h) = &h {
        args.extend(["--horizon", h]);
    }
    args.extend_from_slice(extra);
    run_in(cwd, &args)
}

/// Asserts that `o` failed with exit code `code` and a message that contains `text`.
fn refused(o: &Output, code: i32, text: &str) {
    assert_eq!(o.status.code(), Some(code), "{}", stderr(o));
    assert!(stderr(o).contains(text), "{}", stderr(o));
}

fn json(o: &Output) -> Value {
    assert!(o.status.success(), "replay: {}", stderr(o));
    serde_json::from_slice(&o.stdout).expect("one JSON object on stdout")
}

/// Every record of a sweep replays to its quads and quality (bit for bit: the same f64
/// prints the same), with eta from the recorded evaluator, whose table hashes as the
/// manifest's.
fn every_record_reproduces(tmp: &Path, dir: &Path) {
    let recs = records(dir);
    assert_eq!(recs.len(), 7, "1 greedy + 2 x 3 selective runs");
    for r in &recs {
        let v = json(&replay(tmp, dir, &r.run.to_string(), r, &[]));
        let what = format!("{}: {v}", r.key());
        assert_eq!(v["run"], r.run, "{what}");
        assert_eq!(v["quads"], r.quads, "{what}");
        assert_eq!(v["triangles_left"], r.triangles_left, "{what}");
        assert_eq!(v["quality"].as_f64(), Some(r.quality), "{what}");
        assert_eq!(v["mean_eta"].as_f64(), r.mean_eta, "{what}");
        assert_eq!(v["reproduced"], true, "{what}");
        assert_eq!(v["eta_hash_matches"], true, "{what}");
        assert_eq!(v["backend"], r.backend.as_str(), "{what}");
        let eta = v["eta"].as_str().unwrap();
        assert!(eta.ends_with("(as recorded)"), "{what}");
    }
}

#[test]
fn replay_reproduces_every_record_on_the_cpu_twin() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = sweep(tmp.path(), "sphere", "cpu", &["--backend", "cpu"]);
    assert!(records(&dir).iter().all(|r| r.backend == "cpu-twin"));
    every_record_reproduces(tmp.path(), &dir);
}

#[test]
fn replay_reproduces_every_record_on_the_auto_backend() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = sweep(tmp.path(), "sphere", "auto", &[]);
    every_record_reproduces(tmp.path(), &dir);
}

#[test]
fn typical_is_the_default_and_is_the_median_run() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = sweep(tmp.path(), "sphere", "r", &["--backend", "cpu"]);
    let recs = records(&dir);
    // Without RUN and --algo: the typical run of the first configuration (greedy here).
    let v = json(&run_in(
        tmp.path(),
        &["replay", dir.to_str().unwrap(), "--json"],
    ));
    assert_eq!(
        (v["algo"].as_str(), v["typical"].as_bool()),
        (Some("greedy"), Some(true))
    );
    // selective h=2: the median of its three runs by quality.
    let mut sel: Vec<&RunRecord> = (recs.iter())
        .filter(|r| r.algo == "selective" && r.horizon == Some(2))
        .collect();
    sel.sort_by(|a, b| a.quality.total_cmp(&b.quality).then(a.run.cmp(&b.run)));
    let v = json(&replay(tmp.path(), &dir, "typical", sel[1], &[]));
    assert_eq!(v["run"], sel[1].run, "{v}");
    assert_eq!(v["quads"], sel[1].quads, "{v}");
}

/// `quadrecomb generate grid` of 200 triangles from `seed` into `dir/m.msh`.
fn generate_grid(dir: &Path, seed: &str) {
    let args = [
        "generate",
        "grid",
        "--triangles",
        "200",
        "--seed",
        seed,
        "-o",
        "m.msh",
    ];
    let o = run_in(dir, &args);
    assert!(o.status.success(), "generate: {}", stderr(&o));
}

/// Element counts (triangles, quads) of a mesh file as Gmsh reads it.
fn gmsh_counts(path: &Path) -> (usize, usize) {
    let script = r#"
import sys, gmsh
gmsh.initialize(["-noenv"])
gmsh.option.setNumber("General.Terminal", 0)
gmsh.open(sys.argv[1])
print(len(gmsh.model.mesh.getElementsByType(2)[0]), len(gmsh.model.mesh.getElementsByType(3)[0]))
gmsh.finalize()
"#;
    let s = python(script, &[path]);
    let v: Vec<usize> = s.split_whitespace().map(|x| x.parse().unwrap()).collect();
    (v[0], v[1])
}

#[test]
fn replay_exports_the_run_as_msh_and_vtu() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = sweep(tmp.path(), "sphere", "r", &["--backend", "cpu"]);
    let r = records(&dir)
        .into_iter()
        .find(|r| r.algo == "selective" && r.horizon == Some(2) && r.run == 1)
        .unwrap();
    let msh = tmp.path().join("run.msh");
    let v = json(&replay(
        tmp.path(),
        &dir,
        "1",
        &r,
        &["-o", msh.to_str().unwrap()],
    ));
    assert_eq!(v["output"], msh.to_str().unwrap());
    let vtu = tmp.path().join("run.vtu");
    json(&replay(
        tmp.path(),
        &dir,
        "1",
        &r,
        &["-o", vtu.to_str().unwrap()],
    ));
    let cells = python(
        "import sys, meshio\nm = meshio.read(sys.argv[1])\n\
         print(sum(len(c.data) for c in m.cells if c.type == 'triangle'), \
         sum(len(c.data) for c in m.cells if c.type == 'quad'))",
        &[&vtu],
    );
    assert_eq!(
        cells.trim(),
        format!("{} {}", r.triangles_left, r.quads),
        "meshio's triangles and quads of the .vtu"
    );
    if gmsh_available() {
        assert_eq!(
            gmsh_counts(&msh),
            (r.triangles_left, r.quads),
            "Gmsh's count"
        );
    }
}

#[test]
fn replay_refuses_what_it_cannot_reproduce() {
    let tmp = tempfile::tempdir().unwrap();
    let t = tmp.path();
    generate_grid(t, "7");
    let dir = sweep(t, "m.msh", "r", &["--backend", "cpu"]);
    let r = records(&dir)
        .into_iter()
        .find(|r| r.algo == "selective" && r.horizon == Some(1) && r.run == 0)
        .unwrap();
    json(&replay(t, &dir, "0", &r, &[]));

    // The output may not be the input mesh.
    let o = replay(t, &dir, "0", &r, &["-o", "m.msh"]);
    refused(&o, 2, "is the input mesh");
    // Nor a file of the results directory, even through a link (the manifest was replaced
    // by mesh data).
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(dir.join("manifest.json"), t.join("link.msh")).unwrap();
        let manifest = std::fs::read(dir.join("manifest.json")).unwrap();
        let o = replay(t, &dir, "0", &r, &["-o", "link.msh"]);
        refused(&o, 2, "is manifest.json of the results directory");
        assert_eq!(std::fs::read(dir.join("manifest.json")).unwrap(), manifest);
    }
    // Nor a file of another kind; and RUN must be an index of the configuration.
    let o = replay(t, &dir, "0", &r, &["-o", "out.stl"]);
    refused(&o, 2, "expected a .msh or .vtu file name");
    let o = replay(t, &dir, "7", &r, &[]);
    refused(
        &o,
        2,
        "has no run 7 (its runs: 0 to 2); no configuration here has a run 7",
    );
    // Without --algo, the first configuration is the baseline of one run; the message names
    // the configurations that hold the run asked for.
    let o = run_in(t, &["replay", dir.to_str().unwrap(), "2"]);
    refused(
        &o,
        2,
        "m greedy has no run 2 (its runs: 0); choose one with --mesh, --algo, --horizon or \
         --budget; run 2 is in m selective h=1; m selective h=2",
    );
    let o = replay(t, &dir, "first", &r, &[]);
    refused(&o, 2, "bad RUN \"first\"");

    // A record the replay does not give (its quality lowered by hand): exit 1, a message
    // with both results, nothing written.
    let runs = dir.join("runs.jsonl");
    let text = std::fs::read_to_string(&runs).unwrap();
    let line = r.to_json_line();
    let mut edited = r.clone();
    edited.quality -= 0.25;
    edited.quality_pct = r.quality_pct.map(|p| p * edited.quality / r.quality);
    edited.mean_eta = r.mean_eta.map(|_| edited.quality / edited.quads as f64);
    std::fs::write(&runs, text.replace(&line, &edited.to_json_line())).unwrap();
    let o = replay(t, &dir, "0", &r, &["-o", "out.msh"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(err.contains("not reproduced"), "{err}");
    assert!(err.contains(&format!("{:.6}", edited.quality)), "{err}");
    assert!(err.contains("nothing written"), "{err}");
    assert!(!t.join("out.msh").exists());
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["reproduced"], false, "{v}");
    std::fs::write(&runs, text).unwrap();

    // The mesh changed since the sweep: refused, naming it.
    generate_grid(t, "8");
    let o = replay(t, &dir, "0", &r, &["-o", "out.msh"]);
    refused(&o, 3, "mesh m.msh has changed since the sweep");
    assert!(!t.join("out.msh").exists());
}

/// A results directory that keeps its mesh file inside it (as the committed results do) and
/// was moved, with the sweep's absolute path gone from its manifest: the mesh is found by its
/// file name inside the directory, from any working directory.
#[test]
fn replay_finds_a_mesh_kept_inside_a_moved_results_directory() {
    let tmp = tempfile::tempdir().unwrap();
    let work = tmp.path().join("work");
    std::fs::create_dir_all(work.join("data")).unwrap();
    generate_grid(&work.join("data"), "5");
    let dir = sweep(&work, "data/m.msh", "res", &["--backend", "cpu"]);
    std::fs::rename(work.join("data/m.msh"), dir.join("m.msh")).unwrap();
    let manifest = dir.join("manifest.json");
    let mut v: Value = serde_json::from_str(&std::fs::read_to_string(&manifest).unwrap()).unwrap();
    v["spec"]["meshes"][0]
        .as_object_mut()
        .unwrap()
        .remove("path");
    std::fs::write(&manifest, serde_json::to_string_pretty(&v).unwrap()).unwrap();
    let moved = tmp.path().join("elsewhere");
    std::fs::rename(&dir, &moved).unwrap();
    let r = records(&moved)
        .into_iter()
        .find(|r| r.algo == "selective")
        .unwrap();
    let v = json(&replay(tmp.path(), &moved, &r.run.to_string(), &r, &[]));
    assert_eq!(v["reproduced"], true, "{v}");
    assert_eq!(v["quads"], r.quads, "{v}");
}
