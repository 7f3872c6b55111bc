//! The command line's edge: one exit code per kind of error (README, "Exit codes"), library
//! errors worded with the flags that fix them, and a library that prints nothing and knows
//! no command-line parser.

use std::path::Path;
use std::process::{Command, Stdio};

use crate::util::{bin, run_in};

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
    // An -o name longer than the file system takes is refused before the work (it failed
    // at the rename, after it: exit 1).
    let long = format!("{}.msh", "a".repeat(300));
    fails_with(
        tmp.path(),
        &["recombine", "sphere", "--algo", "greedy", "-o", &long],
        2,
        "the file name is too long for the file system",
    );
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
    // Also when no method given reads it.
    let mut args = sweep_args("a");
    args.extend(["--algo", "greedy", "--runs", "0"]);
    fails_with(tmp.path(), &args, 2, "--runs must be at least 1");
    let mut args = sweep_args("a");
    args.extend(["--threads", "0"]);
    fails_with(tmp.path(), &args, 2, "--threads must be at least 1");
    // A negative number is a value out of range, not an unknown flag (clap's "unexpected
    // argument '-1'"), in every command and nested command.
    for (args, message) in [
        (
            &["sweep", "--runs", "-1"][..],
            "invalid value '-1' for '--runs",
        ),
        (
            &["sweep", "--horizons", "-1"],
            "invalid value '-1' for '--horizons",
        ),
        (
            &[
                "recombine",
                "sphere",
                "--algo",
                "selective",
                "--horizon",
                "-2",
            ],
            "invalid value '-2' for '--horizon",
        ),
        (
            &["generate", "grid", "--triangles", "-5", "-o", "g.msh"],
            "invalid value '-5' for '--triangles",
        ),
        (
            &["bench", "search", "--runs", "-3"],
            "invalid value '-3' for '--runs",
        ),
        // Numbers clap does not know as numbers: an exponent's sign, no leading digit.
        (
            &[
                "recombine",
                "sphere",
                "--algo",
                "greedy",
                "--min-eta",
                "-1e-300",
            ],
            "--min-eta: the lowest eta must lie in [0, 1], not -1e-300",
        ),
        (
            &["optimum", "sphere", "--min-eta", "-.5"],
            "--min-eta: the lowest eta must lie in [0, 1], not -0.5",
        ),
        (
            &["sweep", "--algo", "selective", "--horizons", "-1e-3"],
            "invalid value '-1e-3' for '--horizons",
        ),
        // A flag where a value was due is still a missing value.
        (
            &["recombine", "sphere", "--algo", "greedy", "-o", "--json"],
            "a value is required for '--output",
        ),
    ] {
        fails_with(tmp.path(), args, 2, message);
    }
    assert!(!tmp.path().join("a").exists(), "refused before any work");
    // An argument that is not UTF-8 is named (clap's message named none).
    {
        use std::os::unix::ffi::OsStrExt;
        let name = std::ffi::OsStr::from_bytes(b"m\xff.msh");
        std::fs::write(tmp.path().join(name), "").unwrap();
        let o = Command::new(bin())
            .arg("info")
            .arg(name)
            .current_dir(tmp.path())
            .output()
            .unwrap();
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(
            err.starts_with("error: the argument \"m\\xFF.msh\" is not valid UTF-8"),
            "{err}"
        );
    }
    // A method's parameter out of range names the flag that carried it.
    fails_with(
        tmp.path(),
        &["recombine", "sphere", "--algo", "mcts", "--budget", "0"],
        2,
        "--budget: mcts: budget 0 is out of range 1..=",
    );
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

/// A directory that no sweep made keeps its files: a sweep or a merge pointed at one that
/// holds a report, a summary or figures of the user's own is refused (exit 4) before
/// anything is written there, naming them; they were replaced without a word.
#[test]
fn a_users_own_report_and_summary_are_not_written_over() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let notes = dir.join("paper");
    std::fs::create_dir(&notes).unwrap();
    std::fs::write(notes.join("report.md"), "# My paper notes\n").unwrap();
    std::fs::write(notes.join("summary.csv"), "a,b\n").unwrap();
    std::fs::write(notes.join("data.txt"), "mine\n").unwrap();
    let err = fails_with(dir, &sweep_args("paper"), 4, "summary.csv, report.md");
    assert!(err.contains("not a sweep's results"), "{err}");
    let mut over = sweep_args("paper");
    over.push("--overwrite");
    fails_with(dir, &over, 4, "summary.csv, report.md");
    let names: Vec<String> = std::fs::read_dir(&notes)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(
        names.len(),
        3,
        "the sweep wrote into the directory: {names:?}"
    );
    assert_eq!(
        std::fs::read_to_string(notes.join("report.md")).unwrap(),
        "# My paper notes\n"
    );
    // Figures alone are in the way too; other files are not.
    std::fs::remove_file(notes.join("report.md")).unwrap();
    std::fs::remove_file(notes.join("summary.csv")).unwrap();
    std::fs::create_dir(notes.join("figures")).unwrap();
    std::fs::write(notes.join("figures").join("plot.svg"), "<svg/>").unwrap();
    fails_with(dir, &sweep_args("paper"), 4, "figures/");
    std::fs::remove_dir_all(notes.join("figures")).unwrap();
    let ok = run_in(dir, &sweep_args("paper"));
    assert!(ok.status.success(), "{}", stderr(&ok));
    assert_eq!(
        std::fs::read_to_string(notes.join("data.txt")).unwrap(),
        "mine\n"
    );
    // merge: shards into a directory holding the user's report.
    for (k, shard) in ["1/2", "2/2"].iter().enumerate() {
        let name = format!("s{k}");
        let mut args = sweep_args(&name);
        args.extend(["--shard", shard]);
        let out = run_in(dir, &args);
        assert!(out.status.success(), "{}", stderr(&out));
    }
    let target = dir.join("merged");
    std::fs::create_dir(&target).unwrap();
    std::fs::write(target.join("report.md"), "# My notes\n").unwrap();
    fails_with(
        dir,
        &["merge", "s0", "s1", "--out", "merged"],
        4,
        "report.md",
    );
    assert_eq!(
        std::fs::read_to_string(target.join("report.md")).unwrap(),
        "# My notes\n"
    );
}

/// Writing `-o` failing after the work (here a file-size limit, as a full disk) is a failure
/// of the system, exit 1, not a usage error (exit 2, as it was), and leaves no file; the
/// run's figures are printed all the same (text and `--json`), without a "wrote" line. The
/// limit's signal (SIGXFSZ, whose default action kills) is ignored by the binary itself.
#[test]
fn a_failed_write_after_the_work_exits_1() {
    for (cmd, json) in [
        ("recombine sphere --algo greedy", false),
        ("recombine sphere --algo greedy", true),
        ("optimum sphere", false),
        ("optimum sphere", true),
    ] {
        let tmp = tempfile::tempdir().unwrap();
        let flag = if json { " --json" } else { "" };
        let o = std::process::Command::new("sh")
            .arg("-c")
            .arg(format!("ulimit -f 1; exec \"$0\" {cmd}{flag} -o out.msh"))
            .arg(crate::util::bin())
            .current_dir(tmp.path())
            .output()
            .unwrap();
        let (err, out) = (stderr(&o), String::from_utf8_lossy(&o.stdout));
        assert_eq!(o.status.code(), Some(1), "{cmd}{flag}: {err}");
        assert!(err.contains("cannot write output out.msh"), "{err}");
        let left: Vec<_> = std::fs::read_dir(tmp.path()).unwrap().collect();
        assert!(left.is_empty(), "{left:?}");
        if json {
            let v: serde_json::Value = serde_json::from_str(&out).unwrap();
            assert!(v["quads"].as_u64().unwrap() > 800, "{cmd}: {out}");
        } else {
            assert!(out.contains("quality "), "{cmd}: {out}");
            assert!(!out.contains("wrote"), "{cmd}: {out}");
        }
    }
}

/// The library's notices reach stderr through the command: the backend `--backend auto` picked, once,
/// and the resume; `-q` keeps only warnings: the backend line where it is a fallback (no GPU
/// here: lavapipe or the CPU twin), not the progress, the resume or the summary.
#[test]
fn notices_reach_stderr_through_the_command() {
    let tmp = tempfile::tempdir().unwrap();
    let mut args = sweep_args("d");
    args.retain(|a| !["--backend", "cpu", "-q"].contains(a));
    args.extend(["--backend", "auto", "--plain"]);
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
    let gpu = backend[0].starts_with("quality backend: using the GPU");
    assert_eq!(quiet.starts_with("quality backend: "), !gpu, "{quiet}");
    assert!(
        quiet.lines().all(|l| l.starts_with("quality backend: ")),
        "-q: warnings only: {quiet}"
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

/// Sizes too small to mean anything are refused before any work, with the limit: `bench
/// optimum --sizes 0` panicked (exit 101), `--lattice-sizes 2` timed a 2-triangle lattice,
/// `bench search --max-grid 1` printed an empty table, `generate icosphere --triangles 0`
/// wrote 20 triangles without a word.
#[test]
fn sizes_too_small_are_refused_with_the_limit() {
    let tmp = tempfile::tempdir().unwrap();
    let no_work = |args: &[&str], expect: &str| {
        let o = run_in(tmp.path(), args);
        assert!(o.stdout.is_empty(), "{args:?}: refused before any work");
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.starts_with("error: ") && err.contains(expect), "{err}");
    };
    let bench = ["bench", "optimum", "--no-rss", "--repeat", "1"];
    no_work(&[&bench[..], &["--sizes", "0"]].concat(), "--sizes 0");
    no_work(
        &[&bench[..], &["--sizes", "1000", "--lattice-sizes", "2"]].concat(),
        "--lattice-sizes 2: sizes must be between 100 triangles",
    );
    no_work(
        &["bench", "search", "--max-grid", "1"],
        "--max-grid 1: the grid rows start at 10000 triangles",
    );
    let ico = ["generate", "icosphere", "-o", "s.msh", "--triangles"];
    no_work(&[&ico[..], &["0"]].concat(), "at least 20 triangles");
    assert!(!tmp.path().join("s.msh").exists());
    // A target that is not a level's count: the closest level, and the line says so.
    let o = run_in(tmp.path(), &[&ico[..], &["30"]].concat());
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        out.contains("20 triangles")
            && out.contains("20 * 4^0 is the closest count to --triangles 30"),
        "{out}"
    );
}

/// `bench optimum` solves under the rule every other command uses and names it (it solved
/// the paper-literal problem whatever the flags, a review's finding: borouchaki 13183.64
/// against `optimum`'s 13170.04, without a word).
#[test]
fn bench_optimum_takes_and_names_the_rule() {
    let tmp = tempfile::tempdir().unwrap();
    let row = |extra: &[&str]| {
        let mut args = vec![
            "bench",
            "optimum",
            "--no-rss",
            "--repeat",
            "1",
            "--sizes",
            "100",
            "--lattice-sizes",
            "100",
            "--meshes",
            "borouchaki",
        ];
        args.extend_from_slice(extra);
        let o = run_in(tmp.path(), &args);
        assert!(o.status.success(), "{}", stderr(&o));
        let out = String::from_utf8_lossy(&o.stdout).to_string();
        let rule = out.lines().next().unwrap().to_string();
        let line = out.lines().find(|l| l.starts_with("borouchaki")).unwrap();
        let quality: f64 = line.split_whitespace().nth(4).unwrap().parse().unwrap();
        (rule, quality)
    };
    let (rule, q) = row(&[]);
    assert_eq!(rule, "Rule: valid quads (eta > 0).");
    assert_eq!(format!("{q:.4}"), "13170.0382");
    let (rule, q) = row(&["--allow-invalid"]);
    assert!(rule.contains("paper-literal"), "{rule}");
    assert_eq!(format!("{q:.4}"), "13183.6406");
    let (rule, q) = row(&["--min-eta", "0.3"]);
    assert_eq!(rule, "Rule: valid quads, eta >= 0.3.");
    assert!(q < 13000.0, "{q}");
}

/// An output directory that takes no new file is refused before the search (it ran, then
/// failed writing), for every command with `-o`.
#[cfg(target_os = "linux")]
#[test]
fn unwritable_output_directory_is_refused_before_the_work() {
    let tmp = tempfile::tempdir().unwrap();
    // /proc takes no new file, even for root.
    for args in [
        &[
            "recombine",
            "sphere",
            "--algo",
            "greedy",
            "-o",
            "/proc/q.msh",
        ][..],
        &["optimum", "sphere", "-o", "/proc/q.vtu"],
        &[
            "generate",
            "grid",
            "--triangles",
            "100",
            "-o",
            "/proc/q.msh",
        ],
    ] {
        let o = run_in(tmp.path(), args);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(o.stdout.is_empty(), "{args:?}: no work done");
        assert!(
            err.contains("directory /proc does not take a new file"),
            "{args:?}: {err}"
        );
    }
}

/// `sweep --out` under a regular file names the user's path and the file in the way (it
/// named the internal `f/sub/optimum-cache`), before any work; so does `merge --out`.
#[test]
fn results_directory_under_a_file_names_the_users_path() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("f"), "").unwrap();
    let err = fails_with(
        tmp.path(),
        &sweep_args("f/sub/deeper"),
        4,
        "--out f/sub/deeper: f is a regular file, not a directory",
    );
    assert!(!err.contains("optimum-cache"), "{err}");
    fails_with(
        tmp.path(),
        &["merge", "a", "b", "--out", "f/m"],
        4,
        "--out f/m: f is a regular file",
    );
}

/// `-q` means errors and warnings only: a sweep that succeeds with an explicit backend prints
/// nothing (it printed the "runs done" and report lines).
#[test]
fn quiet_sweep_prints_nothing_on_success() {
    let tmp = tempfile::tempdir().unwrap();
    let mut args = sweep_args("d");
    args.retain(|a| *a != "--no-report");
    let o = run_in(tmp.path(), &args);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(stderr(&o), "");
    assert!(o.stdout.is_empty());
    assert!(tmp.path().join("d/report.md").is_file());
}

/// `optimum -o` says what it wrote, as `recombine` does.
#[test]
fn optimum_output_prints_a_wrote_line() {
    let tmp = tempfile::tempdir().unwrap();
    let o = run_in(tmp.path(), &["optimum", "sphere", "-o", "o.msh"]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(tmp.path().join("o.msh").is_file());
    assert!(out.lines().any(|l| l == "wrote           o.msh"), "{out}");
}

/// `info`'s time line lists the steps, each with its own time, and the wall total
/// separately, never less than their sum (it read "parse X ms (read, topology, candidates)"
/// as though the parts made up the parse time, which they exceeded).
#[test]
fn info_time_line_parts_fit_in_the_total() {
    let tmp = tempfile::tempdir().unwrap();
    let o = run_in(tmp.path(), &["info", "borouchaki"]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", stderr(&o));
    let line = out
        .lines()
        .find(|l| l.starts_with("time:"))
        .expect("a time line");
    let num = |after: &str| -> f64 {
        let rest = &line[line
            .find(after)
            .unwrap_or_else(|| panic!("{after}: {line}"))
            + after.len()..];
        rest.trim_start()
            .split(' ')
            .next()
            .unwrap()
            .parse()
            .unwrap()
    };
    let parts: f64 = ["read", "parse", "topology", "candidates"]
        .iter()
        .map(|s| num(s))
        .sum();
    let total = num(";");
    assert!(line.ends_with("ms in all (wall)"), "{line}");
    assert!(parts <= total + 0.02, "{line}");
    let o = run_in(tmp.path(), &["info", "borouchaki", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let t = &v["time_ms"];
    let sum: f64 = ["read", "parse", "topology", "candidates"]
        .iter()
        .map(|k| t[k].as_f64().unwrap())
        .sum();
    assert!(sum <= t["total"].as_f64().unwrap(), "{t}");
}

/// `completions SHELL` prints a script the shell takes: bash completes the subcommands and a
/// subcommand's flags through it; zsh's and fish's name the command and its subcommands.
#[test]
fn completions_complete_subcommands_and_flags() {
    let tmp = tempfile::tempdir().unwrap();
    let script = |shell: &str| {
        let o = run_in(tmp.path(), &["completions", shell]);
        assert!(o.status.success(), "{shell}: {}", stderr(&o));
        String::from_utf8(o.stdout).unwrap()
    };
    let bash = script("bash");
    std::fs::write(tmp.path().join("q.bash"), &bash).unwrap();
    // What bash offers after `quadrecomb sw` and `quadrecomb sweep --ba`.
    let complete = |words: &str| {
        let line = format!(
            "source ./q.bash; COMP_WORDS=({words}); COMP_CWORD=$((${{#COMP_WORDS[@]}} - 1)); \
             COMP_LINE=\"{words}\"; COMP_POINT=${{#COMP_LINE}}; \
             $(complete -p quadrecomb | sed 's/.*-F \\([^ ]*\\).*/\\1/') quadrecomb \
             \"${{COMP_WORDS[COMP_CWORD]}}\" \"${{COMP_WORDS[COMP_CWORD-1]}}\"; \
             printf '%s\\n' \"${{COMPREPLY[@]}}\""
        );
        let o = std::process::Command::new("bash")
            .args(["-c", &line])
            .current_dir(tmp.path())
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", stderr(&o));
        String::from_utf8(o.stdout).unwrap()
    };
    assert_eq!(complete("quadrecomb sw").trim(), "sweep");
    let flags = complete("quadrecomb sweep --ba");
    assert!(flags.lines().any(|l| l == "--backend"), "{flags}");
    assert!(flags.lines().any(|l| l == "--baseline-runs"), "{flags}");
    let zsh = script("zsh");
    assert!(zsh.starts_with("#compdef quadrecomb"), "{zsh}");
    let fish = script("fish");
    assert!(fish.contains("complete -c quadrecomb"), "{fish}");
    assert!(fish.contains("-a \"sweep\""), "{fish}");
    for s in [&zsh, &fish] {
        assert!(s.contains("completions") && s.contains("replay"));
    }
    fails_with(tmp.path(), &["completions", "tcsh"], 2, "tcsh");
}

/// Parses `o`'s stdout as exactly one JSON object (a single line), after a success.
fn one_object(o: &std::process::Output) -> serde_json::Value {
    assert!(o.status.success(), "{}", stderr(o));
    let out = String::from_utf8(o.stdout.clone()).unwrap();
    assert_eq!(out.lines().count(), 1, "one line on stdout: {out}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert!(v.is_object(), "{v}");
    v
}

/// `--json` on `sweep`, `merge`, `report` and `generate`: one object on stdout saying what
/// was written (paths that exist), counts and time; progress and notes stay on stderr, so
/// `sweep ... --json | jq .` works (`sweep` wrote nothing to stdout).
#[test]
fn json_results_on_stdout_notes_on_stderr() {
    let tmp = tempfile::tempdir().unwrap();
    let exists = |v: &serde_json::Value| {
        let p = tmp.path().join(v.as_str().unwrap_or_else(|| panic!("{v}")));
        assert!(p.is_file(), "{}", p.display());
    };
    let g = one_object(&run_in(
        tmp.path(),
        &[
            "generate",
            "grid",
            "--triangles",
            "200",
            "-o",
            "g.msh",
            "--json",
        ],
    ));
    assert_eq!(g["output"], "g.msh");
    exists(&g["output"]);
    assert!(g["triangles"].as_u64().unwrap() > 100 && g["vertices"].as_u64().is_some());
    assert!(g["generate_s"].is_f64() && g["write_s"].is_f64(), "{g}");

    let mut args = sweep_args("d");
    args.retain(|a| *a != "-q" && *a != "--no-report");
    args.extend(["--plain", "--json"]);
    let o = run_in(tmp.path(), &args);
    assert!(stderr(&o).contains("sweep: 1/1 runs"), "{}", stderr(&o));
    let s = one_object(&o);
    assert_eq!(
        (s["out"].as_str(), s["runs"].as_u64()),
        (Some("d"), Some(1))
    );
    assert_eq!(
        (s["new"].as_u64(), s["cancelled"].as_bool()),
        (Some(1), Some(false))
    );
    for f in ["runs", "manifest", "summary_json", "summary_csv"] {
        exists(&s["files"][f]);
    }
    exists(&s["report"]["markdown"]);
    exists(&s["report"]["html"]);
    s["report"]["figures"]
        .as_array()
        .unwrap()
        .iter()
        .for_each(exists);
    assert!(s["time_s"].is_f64());
    // The same through jq, as a user pipes it (where jq is installed).
    let jq = std::process::Command::new("jq").arg("--version").output();
    if jq.is_ok_and(|o| o.status.success()) {
        let pipe = format!(
            "{} report d --no-pictures --json | jq -r .markdown",
            crate::util::bin().display()
        );
        let o = std::process::Command::new("sh")
            .args(["-c", &pipe])
            .current_dir(tmp.path())
            .output()
            .unwrap();
        assert_eq!(String::from_utf8_lossy(&o.stdout).trim(), "d/report.md");
    } else {
        eprintln!("skipping the jq pipe: no jq here");
    }
    let r = one_object(&run_in(
        tmp.path(),
        &["report", "d", "--no-pictures", "--json"],
    ));
    assert_eq!(r["dir"], "d");
    exists(&r["html"]);

    let mut shard = sweep_args("p1");
    shard.extend(["--shard", "1/1"]);
    assert!(run_in(tmp.path(), &shard).status.success());
    let o = run_in(tmp.path(), &["merge", "p1", "--out", "m", "--json"]);
    assert!(
        stderr(&o).contains("merge: 1 runs from 1 directories"),
        "{}",
        stderr(&o)
    );
    let m = one_object(&o);
    assert_eq!(
        (m["out"].as_str(), m["runs"].as_u64()),
        (Some("m"), Some(1))
    );
    assert_eq!(m["parts"], serde_json::json!(["p1"]));
    exists(&m["files"]["runs"]);
    exists(&m["report"]["markdown"]);
}

/// Records and `--json` agree on "not applicable": greedy-nocrit and the optimum build no
/// tree, so their `nodes_expanded` and `trees` are null in the sweep's records, in
/// `recombine --json` and in `optimum --json` (greedy-nocrit counted its decisions as trees,
/// the optimum's record had 0 where `optimum --json` had null); greedy's one-node trees and
/// selective's trees are counted. Committed records with the old numbers still read.
#[test]
fn no_tree_is_null_in_records_and_json() {
    let tmp = tempfile::tempdir().unwrap();
    let mut args = sweep_args("d");
    // Every algorithm but uniform (greedy is there already).
    args.extend(["--algo", "greedy-nocrit", "selective", "optimum"]);
    args.extend(["--horizons", "2", "--runs", "1"]);
    let o = run_in(tmp.path(), &args);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(tmp.path().join("d/runs.jsonl")).unwrap();
    let records: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(records.len(), 4);
    for r in &records {
        let none = ["greedy-nocrit", "optimum"].contains(&r["algo"].as_str().unwrap());
        for f in ["nodes_expanded", "trees"] {
            assert_eq!(r[f].is_null(), none, "{f}: {r}");
            assert!(none || r[f].as_u64().unwrap() > 0, "{f}: {r}");
        }
    }
    let json = |args: &[&str]| -> serde_json::Value {
        let o = run_in(tmp.path(), args);
        assert!(o.status.success(), "{}", stderr(&o));
        serde_json::from_slice(&o.stdout).unwrap()
    };
    let nocrit = json(&["recombine", "sphere", "--algo", "greedy-nocrit", "--json"]);
    let optimum = json(&["optimum", "sphere", "--json"]);
    let greedy = json(&["recombine", "sphere", "--algo", "greedy", "--json"]);
    for f in ["nodes_expanded", "trees"] {
        assert!(nocrit[f].is_null() && optimum[f].is_null(), "{f}");
        assert_eq!(
            greedy[f], greedy["decisions"],
            "{f}: greedy's one-node trees"
        );
    }
    // The committed records hold null; records written before (0 for the optimum) still read,
    // as they are.
    let committed = crate::util::repo_path("results/sphere/runs.jsonl");
    let now = quadrecomb::internals::experiment::store::read(&committed)
        .unwrap()
        .records;
    let opt = now.iter().find(|r| r.algo == "optimum").unwrap();
    assert_eq!((opt.nodes_expanded, opt.trees), (None, None));
    let mut old: serde_json::Value = serde_json::to_value(opt).unwrap();
    old["nodes_expanded"] = 0.into();
    old["trees"] = 0.into();
    let old: quadrecomb::internals::experiment::record::RunRecord =
        serde_json::from_value(old).unwrap();
    assert_eq!((old.nodes_expanded, old.trees), (Some(0), Some(0)));
}

/// `bench search --mesh` (#27 item 11) compares greedy with selective h = 1 on the meshes
/// named, after `borouchaki`, and `--greedy-only` stops there; a mesh that cannot be read
/// is bad input named before any timing.
#[test]
fn bench_search_compares_greedy_on_named_meshes() {
    let tmp = tempfile::tempdir().unwrap();
    let args = ["bench", "search", "--greedy-only", "--runs", "1"];
    let o = run_in(tmp.path(), &[&args[..], &["--mesh", "sphere"]].concat());
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", stderr(&o));
    let rows: Vec<&str> = out.lines().filter(|l| l.starts_with("| ")).collect();
    assert_eq!(rows.len(), 3, "header, borouchaki and sphere only: {out}");
    assert!(rows[1].starts_with("| borouchaki | 34456 |"), "{out}");
    assert!(rows[2].starts_with("| sphere |"), "{out}");
    // Ratio and work columns are numbers.
    let cells: Vec<&str> = rows[2].split('|').map(str::trim).collect();
    assert!(cells[6].parse::<f64>().unwrap() > 0.0, "{out}");
    assert!(cells[7].contains(" / "), "{out}");
    let o = run_in(
        tmp.path(),
        &[&args[..], &["--mesh", "missing.msh"]].concat(),
    );
    assert!(o.stdout.is_empty(), "nothing timed");
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    assert!(stderr(&o).contains("missing.msh"), "{}", stderr(&o));
}

/// A reader that stops early (`quadrecomb sweep ... 2>&1 | head -1`) must not turn the sweep
/// into a panic (exit 101) that leaves no report: notes and results to a closed pipe are
/// dropped, the work finishes.
#[test]
fn a_closed_pipe_does_not_cut_a_sweep_short() {
    let tmp = tempfile::tempdir().unwrap();
    let bin = crate::util::bin();
    let script = format!(
        "'{}' sweep --mesh sphere --algo greedy selective --horizons 1 --runs 4 --out s 2>&1 \
         | head -1 >/dev/null; echo \"status ${{PIPESTATUS[0]}}\"",
        bin.display()
    );
    let out = std::process::Command::new("bash")
        .arg("-c")
        .arg(&script)
        .current_dir(tmp.path())
        .output()
        .unwrap();
    let said = String::from_utf8_lossy(&out.stdout);
    assert_eq!(said.trim(), "status 0", "{}", stderr(&out));
    assert!(
        tmp.path().join("s/report.md").is_file(),
        "the report was written"
    );
}

/// A benchmark of no repetition has nothing to report: `--repeat 0` ran once and said
/// "medians of 1 repetitions", `bench finish --runs 0` printed NaN %; `bench rss --horizon 0`
/// and `--algos optimum` made every child fail with no word of why.
#[test]
fn benchmarks_refuse_counts_of_zero() {
    let tmp = tempfile::tempdir().unwrap();
    for (args, expect) in [
        (
            &["bench", "optimum", "--repeat", "0"][..],
            "0 is not in 1..",
        ),
        (&["bench", "gpu", "--repeat", "0"], "0 is not in 1.."),
        (&["bench", "suite-eval", "--repeat", "0"], "0 is not in 1.."),
        (&["bench", "finish", "--runs", "0"], "0 is not in 1.."),
        (&["bench", "search", "--runs", "0"], "0 is not in 1.."),
        (&["bench", "rss", "--horizon", "0"], "0 is not in 1.."),
        (
            &["bench", "rss", "--algos", "optimum"],
            "optimum is not a search",
        ),
    ] {
        fails_with(tmp.path(), args, 2, expect);
    }
}

/// `--horizon` is checked by clap from 1 up: `-1` was said to be "not in 0..=4294967295" and
/// then 0 refused with "the horizon must be at least 1", which named no flag.
#[test]
fn horizons_start_at_one() {
    let tmp = tempfile::tempdir().unwrap();
    for h in ["0", "-1"] {
        let recombine = ["recombine", "sphere", "--algo", "selective", "--horizon", h];
        fails_with(tmp.path(), &recombine, 2, &format!("{h} is not in 1.."));
        let replay = ["replay", "nowhere", "0", "--horizon", h];
        fails_with(tmp.path(), &replay, 2, &format!("{h} is not in 1.."));
    }
}

/// What a written mesh holds that its user may not expect is said on stderr: quads of eta 0
/// under `--allow-invalid` (none under the default rule), and `--vtu-ascii` ignored by a .msh.
#[test]
fn written_meshes_say_what_they_hold() {
    let tmp = tempfile::tempdir().unwrap();
    let args = |extra: &[&'static str]| {
        let mut a = vec![
            "recombine",
            "borouchaki",
            "--algo",
            "greedy",
            "--no-optimum",
        ];
        a.extend_from_slice(extra);
        a
    };
    let o = run_in(tmp.path(), &args(&["--allow-invalid", "-o", "a.msh"]));
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    let line = err
        .lines()
        .find(|l| l.contains("have eta 0"))
        .unwrap_or_else(|| panic!("{err}"));
    assert!(line.starts_with("warning: a.msh: "), "{line}");
    let n: usize = line["warning: a.msh: ".len()..]
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(n > 0, "{line}");
    let o = run_in(tmp.path(), &args(&["-o", "b.msh", "--vtu-ascii"]));
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(!err.contains("have eta 0"), "{err}");
    assert!(
        err.contains("note: --vtu-ascii is ignored: b.msh is a .msh"),
        "{err}"
    );
    let o = run_in(tmp.path(), &args(&["-o", "c.vtu", "--vtu-ascii"]));
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stderr(&o).contains("ignored"), "{}", stderr(&o));
}

/// A stdout that cannot be written (a full disk under `> out.json`; `/dev/full` here) is an
/// error, exit 1, after the command's work: the JSON or table it meant to print is lost. A
/// reader that stopped reading (`| head -1`) is not: exit 0. `completions` wrote through
/// clap_complete, which panicked (exit 101) on such a stdout.
#[test]
fn a_stdout_that_cannot_be_written_is_exit_1() {
    let Ok(full) = std::fs::OpenOptions::new().write(true).open("/dev/full") else {
        eprintln!("skipped: no /dev/full on this system");
        return;
    };
    for args in [
        &[
            "recombine",
            "sphere",
            "--algo",
            "greedy",
            "--no-optimum",
            "--json",
        ][..],
        &["optimum", "sphere"],
        &["suite", "list"],
        &["completions", "bash"],
    ] {
        let out = Command::new(bin())
            .args(args)
            .stdout(full.try_clone().unwrap())
            .stderr(Stdio::piped())
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(
            err.contains("error: cannot write to stdout: No space left on device")
                && !err.contains("panicked"),
            "{args:?}: {err}"
        );
    }
    // A closed pipe: the run is not failed for it.
    let mut child = Command::new(bin())
        .args(["completions", "bash"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A review's papercuts: flags that change nothing are said to; `merge -q` is quiet as `sweep
/// -q` is; a directory given twice to `merge` is named so; a shard's report says it is one.
#[test]
fn flags_that_change_nothing_are_warned_of() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let sweep = |out: &str, extra: &[&str]| {
        let mut args = vec![
            "sweep",
            "--mesh",
            "sphere",
            "--backend",
            "cpu",
            "--out",
            out,
            "-q",
        ];
        args.extend(extra);
        let o = run_in(dir, &args);
        assert!(o.status.success(), "{}", stderr(&o));
        stderr(&o)
    };
    let err = sweep("a", &["--algo", "greedy", "--horizons", "3", "--no-report"]);
    assert!(
        err.contains(
            "warning: sweep: --horizons is read by uniform, selective, optimistic, mcts, beam \
             only, and --algo has none of them (greedy): it changes nothing"
        ),
        "{err}"
    );
    let err = sweep(
        "b",
        &[
            "--algo",
            "selective",
            "--horizons",
            "1",
            "--runs",
            "2",
            "--budgets",
            "8",
            "--no-report",
        ],
    );
    assert!(
        err.contains("warning: sweep: --budgets is read by optimistic, mcts, beam only"),
        "{err}"
    );
    // Warned of once, and not where a method reads them.
    assert_eq!(err.matches("warning").count(), 1, "{err}");
    let err = sweep(
        "c",
        &[
            "--algo",
            "selective",
            "--horizons",
            "1",
            "--runs",
            "2",
            "--no-report",
        ],
    );
    assert_eq!(err, "");
    let o = run_in(
        dir,
        &["report", "c", "--baseline", "greedy", "--no-pictures"],
    );
    assert!(
        stderr(&o).contains("warning: report: --baseline sets the method the \"Across meshes\""),
        "{}",
        stderr(&o)
    );
    // Shards, merged quietly; a part given twice.
    for s in ["1/2", "2/2"] {
        let out = format!("s{}", &s[..1]);
        sweep(
            &out,
            &[
                "--algo",
                "greedy",
                "selective",
                "--horizons",
                "1",
                "--runs",
                "4",
                "--shard",
                s,
            ],
        );
    }
    let o = run_in(dir, &["report", "s1", "--no-pictures"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let md = std::fs::read_to_string(dir.join("s1/report.md")).unwrap();
    assert!(
        md.contains("Shard 1/2 of a sweep: this directory holds 3 of its 5 runs"),
        "{md}"
    );
    let o = run_in(dir, &["merge", "s1", "s2", "--out", "m", "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(stderr(&o), "");
    assert!(o.stdout.is_empty());
    fails_with(
        dir,
        &["merge", "s1", "s1", "s2", "--out", "n"],
        3,
        "merge: s1: given twice",
    );
}
