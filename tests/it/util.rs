//! Test utilities: fixed seeds, running the CLI in a temporary directory.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The seed every randomized test starts from.
pub const SEED: u64 = 0x5EED_2026;

/// The built `quadrecomb` binary, or the one `QUADRECOMB_TEST_BIN` names (to check that a
/// regression test fails on an older build).
pub fn bin() -> PathBuf {
    std::env::var_os("QUADRECOMB_TEST_BIN").map_or_else(
        || PathBuf::from(env!("CARGO_BIN_EXE_quadrecomb")),
        PathBuf::from,
    )
}

/// Runs `quadrecomb args...` in `dir` and returns its output.
pub fn run_in(dir: &Path, args: &[&str]) -> Output {
    Command::new(bin())
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run quadrecomb")
}

/// [`run_in`], asserting that the command succeeded (its stderr in the message).
pub fn run_ok(dir: &Path, args: &[&str]) -> Output {
    let out = run_in(dir, args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Whether `python3` can import `gmsh` 4.15.2 (the version the test meshes and expected
/// figures come from). Outside CI a test without it skips with a message; in CI (`CI` set)
/// it must be there, so that no Gmsh check is skipped silently.
pub fn gmsh_available() -> bool {
    let ok = Command::new("python3")
        .args(["-c", "import gmsh; assert gmsh.__version__ == '4.15.2'"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !ok && std::env::var_os("CI").is_some() {
        panic!("the gmsh Python module 4.15.2 is required in CI (pip install gmsh==4.15.2)");
    }
    if !ok {
        eprintln!("skipping a Gmsh check: python3 cannot import gmsh 4.15.2");
    }
    ok
}

/// Whether python3 can import `module` (a reader we check our files with, e.g. `vtk` or
/// `meshio`). In CI it must be there (scripts/test-all.sh installs it), so that no check is
/// skipped silently; elsewhere a missing module skips the check with a message.
pub fn python_module_available(module: &str) -> bool {
    let ok = Command::new("python3")
        .args(["-c", &format!("import {module}")])
        .output()
        .is_ok_and(|o| o.status.success());
    if !ok && std::env::var_os("CI").is_some() {
        panic!("the Python module {module} is required in CI (pip install {module})");
    }
    if !ok {
        eprintln!("skipping a check: python3 cannot import {module}");
    }
    ok
}

/// Runs `python3 -c script args...` and returns its standard output; panics with its
/// standard error if it fails.
pub fn python(script: &str, args: &[&Path]) -> String {
    let out = Command::new("python3")
        .args(["-c", script])
        .args(args)
        .output()
        .expect("run python3");
    assert!(
        out.status.success(),
        "python3 failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("UTF-8 output")
}

/// Path of a file in the repository.
pub fn repo_path(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}
