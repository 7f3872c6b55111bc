//! The benchmark suite (issue 24): its embedded files against `meshes/suite/` and
//! `scripts/make_suite.py`, the registry's counts against the loaded meshes, `suite list`,
//! `suite:NAME` errors and `sweep --suite` end to end.

use crate::util::{gmsh_available, repo_path, run_in};
use quadrecomb::internals::mesh::suite::{self, MEMBERS, Origin};
use std::collections::BTreeMap;

/// Every member but the generated 10^6 grid loads by its spec into a valid mesh with the
/// registry's triangle and odd-component counts, and the embedded files are the committed ones.
#[test]
fn members_load_with_their_registered_counts() {
    for m in MEMBERS {
        if let Origin::Grid(spec) = m.origin {
            // Generating and parsing 10^6 triangles is left to `sweep --suite full`; the
            // count is the generator's own.
            assert_eq!(spec.triangle_count(), m.triangles, "{}", m.name);
            continue;
        }
        if let Origin::File(bytes) = m.origin {
            let on_disk =
                std::fs::read(repo_path(&format!("meshes/suite/{}.msh", m.name))).unwrap();
            assert!(
                bytes == on_disk.as_slice(),
                "{}: embedded bytes differ",
                m.name
            );
        }
        let mesh = quadrecomb::internals::mesh::load(&suite::spec(m)).expect(m.name);
        mesh.sanity_check().expect(m.name);
        assert_eq!(mesh.num_triangles(), m.triangles, "{}", m.name);
        let odd = (mesh.topology.component_sizes.iter())
            .filter(|&&s| s % 2 == 1)
            .count();
        assert_eq!(odd, m.odd_components, "{}", m.name);
    }
}

/// The committed files are what `scripts/make_suite.py` makes (when Python has gmsh 4.15.2):
/// the script checks counts and reruns itself; bytes are compared and differences reported,
/// as for the built-in meshes (floating-point paths may differ on other CPUs).
#[test]
fn suite_files_are_reproducible_with_gmsh() {
    if !gmsh_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let out = std::process::Command::new("python3")
        .arg(repo_path("scripts/make_suite.py"))
        .arg("--out")
        .arg(dir.path())
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut files = 0;
    for m in MEMBERS {
        if let Origin::File(committed) = m.origin {
            let made = std::fs::read(dir.path().join(format!("{}.msh", m.name))).unwrap();
            let mesh = quadrecomb::internals::mesh::msh::read_bytes(m.name, &made).unwrap();
            assert_eq!(mesh.num_triangles(), m.triangles, "{}\n{text}", m.name);
            if made != committed {
                eprintln!("note: {}: regenerated file has other bytes\n{text}", m.name);
            }
            files += 1;
        }
    }
    assert_eq!(files, 12);
}

#[test]
fn suite_list_json_is_the_registry() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_in(dir.path(), &["suite", "list", "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let members = v["members"].as_array().unwrap();
    assert_eq!(members.len(), MEMBERS.len());
    for (j, m) in members.iter().zip(MEMBERS) {
        assert_eq!(j["name"], m.name);
        assert_eq!(j["spec"], format!("suite:{}", m.name));
        assert_eq!(j["triangles"], m.triangles);
        assert!(!j["tests"].as_str().unwrap().is_empty());
    }
    let suites: Vec<&str> = (v["suites"].as_array().unwrap().iter())
        .map(|s| s["name"].as_str().unwrap())
        .collect();
    assert_eq!(suites, ["default", "small", "full"]);
    // The text listing names every member.
    let out = run_in(dir.path(), &["suite", "list"]);
    let text = String::from_utf8_lossy(&out.stdout);
    for m in MEMBERS {
        assert!(text.contains(m.name), "{text}");
    }
    let out = run_in(dir.path(), &["suite", "list", "--suite", "small"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("odd-pieces") && !text.contains("torus "),
        "{text}"
    );
}

#[test]
fn unknown_suite_names_are_errors_that_list_the_names() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_in(dir.path(), &["info", "suite:tours"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{err}");
    assert!(
        err.contains("no suite mesh is named \"tours\"") && err.contains("torus, capped-cylinder"),
        "{err}"
    );
    // A suite member's plain name that is no file points to its spec.
    let out = run_in(dir.path(), &["info", "torus"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{err}");
    assert!(
        err.contains("torus: no such file; the benchmark suite's mesh of that name is suite:torus"),
        "{err}"
    );
    // Built-in members still load by their plain names.
    let out = run_in(dir.path(), &["info", "sphere"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = run_in(dir.path(), &["sweep", "--suite", "huge"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("default, small, full"), "{err}");
    let out = run_in(dir.path(), &["suite", "list", "--suite", "huge"]);
    assert_eq!(out.status.code(), Some(2));
    // --suite and --mesh exclude each other.
    let out = run_in(
        dir.path(),
        &["sweep", "--suite", "small", "--mesh", "sphere"],
    );
    assert_eq!(out.status.code(), Some(2));
}

/// `sweep --suite small` runs the suite's methods on each of its meshes, names the meshes as
/// the registry does, reports its phase times, and resumes like any sweep.
#[test]
fn sweep_suite_small_end_to_end() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "sweep",
        "--suite",
        "small",
        "--runs",
        "2",
        "--out",
        "s",
        "--json",
        "--quiet",
        "--no-report",
    ];
    let out = run_in(dir.path(), &args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let small = suite::suite("small").unwrap();
    // Per mesh: greedy once, selective h = 1, 3, 5 twice each, the optimum once.
    assert_eq!(v["runs"], small.len() * (1 + 3 * 2 + 1));
    for phase in ["load_s", "eta_s", "optimum_s", "searches_s", "overhead_pct"] {
        assert!(v["phases"][phase].as_f64().is_some_and(|x| x >= 0.0), "{v}");
    }
    let runs = std::fs::read_to_string(dir.path().join("s/runs.jsonl")).unwrap();
    let mut per_mesh: BTreeMap<String, BTreeMap<String, usize>> = BTreeMap::new();
    for line in runs.lines() {
        let r: serde_json::Value = serde_json::from_str(line).unwrap();
        let algo = match r["horizon"].as_u64() {
            Some(h) => format!("{}-h{h}", r["algo"].as_str().unwrap()),
            None => r["algo"].as_str().unwrap().to_string(),
        };
        *(per_mesh
            .entry(r["mesh"].as_str().unwrap().into())
            .or_default())
        .entry(algo)
        .or_default() += 1;
    }
    let names: Vec<&str> = per_mesh.keys().map(String::as_str).collect();
    let mut expected: Vec<&str> = small.iter().map(|m| m.name).collect();
    expected.sort();
    assert_eq!(names, expected);
    for (mesh, algos) in &per_mesh {
        let got: Vec<(&str, usize)> = algos.iter().map(|(a, n)| (a.as_str(), *n)).collect();
        assert_eq!(
            got,
            [
                ("greedy", 1),
                ("optimum", 1),
                ("selective-h1", 2),
                ("selective-h3", 2),
                ("selective-h5", 2)
            ],
            "{mesh}"
        );
    }
    let manifest = std::fs::read_to_string(dir.path().join("s/manifest.json")).unwrap();
    assert!(manifest.contains("\"suite:odd-pieces\""), "{manifest}");
    // Resumable like any sweep: nothing left to do.
    let mut again = args.to_vec();
    again.push("--resume");
    let out = run_in(dir.path(), &again);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["new"], 0);
}

/// `suite:grid-1m` is the file `quadrecomb generate` writes for the documented command, byte
/// for byte (so its mesh hash, and records, are the same whichever way it was made).
#[test]
fn grid_1m_is_what_generate_writes() {
    let m = suite::member("grid-1m").unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = run_in(
        dir.path(),
        &[
            "generate",
            "grid",
            "--triangles",
            "1000000",
            "--seed",
            "24",
            "-o",
            "g.msh",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let file = std::fs::read(dir.path().join("g.msh")).unwrap();
    assert!(
        m.bytes().as_ref() == file.as_slice(),
        "grid-1m differs from generate's file"
    );
}
