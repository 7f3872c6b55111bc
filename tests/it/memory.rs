//! Memory: runs in child processes under an address-space limit (`ulimit -v`), so that a
//! run needing more fails instead of taking the machine's memory.

use crate::util::bin;
use std::path::Path;
use std::process::{Command, Output};

/// Runs `quadrecomb args...` in `dir` under `ulimit -v kib`.
fn limited(dir: &Path, kib: u64, args: &[&str]) -> Output {
    let mut script = format!("ulimit -v {kib} && exec \"$0\"");
    for i in 1..=args.len() {
        script += &format!(" \"${i}\"");
    }
    Command::new("sh")
        .arg("-c")
        .arg(script)
        .arg(bin())
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run sh")
}

fn generate(dir: &Path, what: &[&str]) {
    let out = Command::new(bin())
        .arg("generate")
        .args(what)
        .current_dir(dir)
        .output()
        .expect("run quadrecomb");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// One-cell-wide corridors of 10^5 triangles recombine in 200 MB of address space with
/// every policy (about 65 MB resident). Certificates used to list every part a split
/// leaves, quadratic on these shapes: a strip of 20,000 triangles needed 4.3 GB, one of
/// 50,000 aborted, and the initial verdicts took `n^2 / 4` search steps.
#[test]
fn long_corridors_recombine_in_bounded_memory() {
    let dir = tempfile::tempdir().unwrap();
    for shape in ["strip", "spiral", "maze"] {
        let file = format!("{shape}.msh");
        generate(dir.path(), &[shape, "--triangles", "100000", "-o", &file]);
        for algo in [
            &["--algo", "greedy-nocrit"][..],
            &["--algo", "greedy"],
            &["--algo", "selective", "--horizon", "3"],
        ] {
            let mut args = vec!["recombine", &file, "--no-optimum", "--json"];
            args.extend_from_slice(algo);
            let out = limited(dir.path(), 200_000, &args);
            assert!(
                out.status.success(),
                "{shape} {algo:?}: {} {}",
                out.status,
                String::from_utf8_lossy(&out.stderr)
            );
            let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
            // A path of an even number of triangles pairs up completely under the
            // criterion (every allowed action leaves even parts).
            let left = v["triangles_left"].as_u64().unwrap();
            if shape != "maze" && algo[1] != "greedy-nocrit" {
                assert_eq!(left, 0, "{shape} {algo:?}");
            }
        }
    }
}

/// Out of memory is exit code 5 with a message naming what was being done and how much
/// could not be had, not an abort (exit 134, "memory allocation of N bytes failed").
#[test]
fn out_of_memory_is_an_error_not_an_abort() {
    let dir = tempfile::tempdir().unwrap();
    generate(
        dir.path(),
        &["grid", "--triangles", "400000", "-o", "grid.msh"],
    );
    for (cmd, doing) in [
        (&["info", "grid.msh"][..], ""),
        (&["recombine", "grid.msh", "--algo", "greedy"], ""),
        (&["optimum", "grid.msh"], ""),
        (
            &[
                "sweep", "--mesh", "grid.msh", "--algo", "greedy", "--out", "sw",
            ],
            "while running the sweep",
        ),
        (
            &[
                "generate",
                "grid",
                "--triangles",
                "3000000",
                "-o",
                "big.msh",
            ],
            "while generating the mesh",
        ),
    ] {
        // About 90 MB resident for `info`, more for the others: 60 MB cannot do.
        let out = limited(dir.path(), 60_000, cmd);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(5), "{cmd:?}: {} {err}", out.status);
        assert!(
            err.contains("error: out of memory while") && err.contains("could not allocate"),
            "{cmd:?}: {err}"
        );
        // What was being done: a mesh command names the mesh's size or the reading, the
        // others their own phase (they said "while starting").
        if doing.is_empty() {
            assert!(
                err.contains("triangles") || err.contains("reading"),
                "{err}"
            );
        } else {
            assert!(err.contains(doing), "{cmd:?}: {err}");
        }
        assert!(!err.contains("while starting"), "{cmd:?}: {err}");
    }
}
