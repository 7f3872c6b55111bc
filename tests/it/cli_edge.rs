//! The command line's edge: one exit code per kind of error (README, "Exit codes"), library
//! errors worded with the flags that fix them, and a library that prints nothing and knows
//! no command-line parser.

use std::path::Path;

use crate::util::run_in;

fn stderr(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Runs `quadrecomb args...` in `dir`, checks its exit code and that its one-line error says
/// `expect`; returns the error.
fn fails_with(dir: &Path, args: &[&str], code: i32, expect: &str) -> String {
    let o = run_in(dir, args);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(code), "{args:?}: {err}");
    assert!(err.starts_with("error: "), "{args:?}: {err}");
    assert!(err.contains(expect), "{args:?}: {err}");
    err
}

/// A small sweep of `sphere` into `out` (greedy only: a few runs).
fn sweep_args(out: &str) -> Vec<&str> {
    vec![
        "sweep",
        "--mesh",
        "sphere",
        "--algo",
        "greedy",
        "--backend",
        "cpu",
        "--no-report",
        "-q",
        "--out",
        out,
    ]
}

/// 1: a failure that is neither the arguments nor the input (here the system refuses to
/// create the results directory).
#[cfg(target_os = "linux")]
#[test]
fn exit_1_other_failure() {
    let tmp = tempfile::tempdir().unwrap();
    // /proc takes no new directory, even for root.
    fails_with(
        tmp.path(),
        &sweep_args("/proc/quadrecomb-test-results"),
        1,
        "/proc/quadrecomb-test-results",
    );
}

/// 2: usage errors, clap's own and the values it cannot check, the library's value named by
/// its flag.
#[test]
fn exit_2_usage_error() {
    let tmp = tempfile::tempdir().unwrap();
    fails_with(
        tmp.path(),
        &["sweep", "--no-such-flag"],
        2,
        "--no-such-flag",
    );
    let mut args = sweep_args("a");
    args.extend(["--algo", "selective", "--horizons", "1", "--runs", "0"]);
    // The last --algo wins: selective with zero runs.
    fails_with(tmp.path(), &args, 2, "--runs must be at least 1");
    let mut args = sweep_args("a");
    args.extend(["--threads", "0"]);
    fails_with(tmp.path(), &args, 2, "--threads must be at least 1");
    assert!(!tmp.path().join("a").exists(), "refused before any work");
}

/// 3: bad input, a mesh file that is not one, and a results directory whose files are not a
/// sweep's.
#[test]
fn exit_3_bad_input() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("bad.msh"), "$MeshFormat\nnonsense\n").unwrap();
    fails_with(tmp.path(), &["info", "bad.msh"], 3, "bad.msh");
    std::fs::create_dir(tmp.path().join("r")).unwrap();
    std::fs::write(tmp.path().join("r/runs.jsonl"), "").unwrap();
    fails_with(
        tmp.path(),
        &["report", "r"],
        3,
        "r/runs.jsonl: no runs recorded",
    );
}

/// 4: the results directory cannot be used as asked: it holds another sweep's runs, or it is
/// a file.
#[test]
fn exit_4_results_directory() {
    let tmp = tempfile::tempdir().unwrap();
    let first = run_in(tmp.path(), &sweep_args("d"));
    assert!(first.status.success(), "{}", stderr(&first));
    let err = fails_with(tmp.path(), &sweep_args("d"), 4, "already holds");
    assert!(
        err.contains("pass --resume to continue that sweep, --overwrite to replace it"),
        "{err}"
    );
    std::fs::write(tmp.path().join("f"), "").unwrap();
    fails_with(
        tmp.path(),
        &sweep_args("f"),
        4,
        "--out f: is a regular file, not a directory",
    );
}

/// The library's notices reach stderr through the command: the backend `auto` picked, once,
/// and the resume; `-q` keeps the backend line (as before) but not the progress or resume.
#[test]
fn notices_reach_stderr_through_the_command() {
    let tmp = tempfile::tempdir().unwrap();
    let mut args = sweep_args("d");
    args.retain(|a| !["--backend", "cpu", "-q"].contains(a));
    args.push("--plain");
    let first = run_in(tmp.path(), &args);
    let err = stderr(&first);
    assert!(first.status.success(), "{err}");
    let backend: Vec<&str> = (err.lines())
        .filter(|l| l.starts_with("quality backend: "))
        .collect();
    assert_eq!(backend.len(), 1, "{err}");
    assert!(err.contains("sweep: 1/1 runs (100.0%)"), "{err}");
    args.push("--resume");
    let resumed = stderr(&run_in(tmp.path(), &args));
    assert!(
        resumed.contains("sweep: resuming: 1 of 1 runs already recorded\n"),
        "{resumed}"
    );
    args.push("-q");
    args.retain(|a| *a != "--plain");
    let quiet = stderr(&run_in(tmp.path(), &args));
    assert!(quiet.starts_with("quality backend: "), "{quiet}");
    assert!(
        !quiet.contains("resuming") && !quiet.contains("1/1 runs"),
        "{quiet}"
    );
}

// 5 (out of memory) is checked by `memory::out_of_memory_is_an_error_not_an_abort`, and 130
// (Ctrl-C) by the runner's interrupt test.

/// The library (everything but `src/cli` and `src/main.rs`) writes nothing to stdout or
/// stderr and does not import clap: notices, progress and flags are the command line's.
#[test]
fn library_prints_nothing_and_knows_no_clap() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    library_files(&src, &src, &mut files);
    assert!(files.len() > 20, "{files:?}");
    let mut offenders = Vec::new();
    for path in files {
        let text = std::fs::read_to_string(&path).unwrap();
        // Comments (doc examples included) may say anything.
        let code = text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.trim_start().starts_with("//"));
        for (i, line) in code {
            let prints = ["println!", "eprintln!", "print!(", "eprint!(", "dbg!("]
                .iter()
                .any(|m| line.contains(m));
            if prints || line.contains("clap::") || line.trim_start().starts_with("use clap") {
                offenders.push(format!("{}:{}: {}", path.display(), i + 1, line.trim()));
            }
        }
    }
    assert!(offenders.is_empty(), "{}", offenders.join("\n"));
}

/// The `.rs` files under `dir` that are the library's: not `src/cli/`, not `src/main.rs`.
fn library_files(src: &Path, dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path == src.join("cli") || path == src.join("main.rs") {
            continue;
        }
        if path.is_dir() {
            library_files(src, &path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}
