//! The experiment runner end to end through the CLI: thread-count and shard invariance,
//! kill -9 and Ctrl-C then --resume, torn lines, merge checks, statistics.

use crate::util::{SEED, bin, run_in};
use quadrecomb::internals::experiment::record::RunRecord;
use quadrecomb::internals::experiment::store;
use quadrecomb::internals::stats::describe::{BoxStats, quantile, sd};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// A small generated mesh with an odd component, written into `dir`.
pub(crate) fn small_mesh(dir: &Path, triangles: usize) -> PathBuf {
    let out = run_in(
        dir,
        &[
            "generate",
            "grid",
            "--triangles",
            &triangles.to_string(),
            "--seed",
            &SEED.to_string(),
            "--drop-triangles",
            "1",
            "-o",
            "small.msh",
        ],
    );
    assert!(out.status.success(), "generate: {}", stderr(&out));
    dir.join("small.msh")
}

pub(crate) fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Arguments of a quick sweep on `mesh` into `out`.
pub(crate) fn sweep_args(mesh: &Path, out: &str, runs: u32, horizons: &str) -> Vec<String> {
    [
        "sweep",
        "--mesh",
        mesh.to_str().unwrap(),
        "--horizons",
        horizons,
        "--runs",
        &runs.to_string(),
        "--baseline-runs",
        "2",
        "--seed",
        &SEED.to_string(),
        "--backend",
        "cpu",
        "--no-report",
        "--quiet",
        "--out",
        out,
    ]
    .iter()
    .map(|s| s.to_string())
    .collect()
}

pub(crate) fn sweep(dir: &Path, args: &[String], extra: &[&str]) -> Output {
    let mut all: Vec<&str> = args.iter().map(String::as_str).collect();
    all.extend_from_slice(extra);
    run_in(dir, &all)
}

pub(crate) fn records(dir: &Path) -> Vec<RunRecord> {
    let mut r = store::read(&dir.join("runs.jsonl")).unwrap().records;
    r.sort_by_key(|r| r.key());
    r
}

/// Same runs with the same results (every field but the wall-clock time).
pub(crate) fn assert_same(a: &[RunRecord], b: &[RunRecord], what: &str) {
    assert_eq!(a.len(), b.len(), "{what}: record counts differ");
    for (x, y) in a.iter().zip(b) {
        assert!(x.same_result(y), "{what}: {x:?}\n  vs\n{y:?}");
    }
}

#[test]
fn threads_and_merged_shards_give_identical_records() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let mesh = small_mesh(dir, 600);
    let one = sweep(
        dir,
        &sweep_args(&mesh, "t1", 5, "1..4"),
        &["--threads", "1"],
    );
    assert!(one.status.success(), "{}", stderr(&one));
    let two = sweep(
        dir,
        &sweep_args(&mesh, "t2", 5, "1..4"),
        &["--threads", "2"],
    );
    assert!(two.status.success(), "{}", stderr(&two));
    for i in 1..=3 {
        let shard = format!("{i}/3");
        let out = sweep(
            dir,
            &sweep_args(&mesh, &format!("s{i}"), 5, "1..4"),
            &["--shard", &shard, "--threads", "2"],
        );
        assert!(out.status.success(), "{}", stderr(&out));
    }
    let merged = run_in(
        dir,
        &["merge", "s1", "s2", "s3", "--out", "merged", "--no-report"],
    );
    assert!(merged.status.success(), "{}", stderr(&merged));

    let a = records(&dir.join("t1"));
    // 4 horizons x 5 runs of selective + 2 greedy + 2 greedy-nocrit + 1 optimum.
    assert_eq!(a.len(), 4 * 5 + 2 + 2 + 1);
    assert_same(&a, &records(&dir.join("t2")), "1 vs 2 threads");
    assert_same(
        &a,
        &records(&dir.join("merged")),
        "1 thread vs 3 merged shards",
    );
    // Shards are disjoint and none is empty.
    let sizes: Vec<usize> = (1..=3)
        .map(|i| records(&dir.join(format!("s{i}"))).len())
        .collect();
    assert_eq!(sizes.iter().sum::<usize>(), a.len());
    assert!(sizes.iter().all(|&s| s > 0));

    // The records are real runs: the optimum bounds every run, seeds differ between runs.
    let opt = a.iter().find(|r| r.algo == "optimum").unwrap();
    assert!((opt.quality_pct.unwrap() - 100.0).abs() < 1e-9);
    for r in &a {
        assert!(r.quality <= opt.quality + 1e-9, "{r:?}");
        assert_eq!(r.quads * 2 + r.triangles_left, r.triangles);
        assert_eq!(r.backend, "cpu-twin");
    }
    let sel: Vec<&RunRecord> = a.iter().filter(|r| r.algo == "selective").collect();
    assert!(sel.iter().all(|r| r.nodes_expanded.is_some_and(|n| n > 0)));
    assert!(
        sel.iter()
            .all(|r| r.branching_factor.is_some() == (r.horizon > Some(1)))
    );
    let seeds: std::collections::BTreeSet<u64> = a.iter().map(|r| r.seed).collect();
    assert_eq!(seeds.len(), a.len());
    for f in ["manifest.json", "summary.csv", "summary.json"] {
        assert!(dir.join("merged").join(f).exists(), "{f}");
    }
}

/// Waits until `path` holds at least `lines` complete lines (or `limit` passes).
pub(crate) fn wait_for_lines(path: &Path, lines: usize, limit: Duration) -> usize {
    let start = Instant::now();
    loop {
        let n = std::fs::read(path)
            .map(|b| b.iter().filter(|&&c| c == b'\n').count())
            .unwrap_or(0);
        if n >= lines || start.elapsed() > limit {
            return n;
        }
        std::thread::sleep(Duration::from_millis(2));
    }
}

#[test]
fn kill_9_then_resume_equals_an_uninterrupted_sweep() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    // About 600 runs: long enough (seconds) to be killed after 20 of them.
    let mesh = small_mesh(dir, 1000);
    let args = sweep_args(&mesh, "killed", 100, "1..6");
    let total = 6 * 100 + 2 + 2 + 1;
    let mut child = Command::new(bin())
        .args(&args)
        .args(["--threads", "2"])
        .current_dir(dir)
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let runs = dir.join("killed/runs.jsonl");
    let seen = wait_for_lines(&runs, 20, Duration::from_secs(60));
    child.kill().unwrap(); // SIGKILL
    child.wait().unwrap();
    let after_kill = store::read(&runs).unwrap();
    assert!(seen >= 20, "only {seen} runs recorded before the kill");
    assert!(
        after_kill.records.len() < total,
        "the sweep finished before it was killed: make it longer"
    );
    let resumed = sweep(dir, &args, &["--resume", "--threads", "2"]);
    assert!(resumed.status.success(), "{}", stderr(&resumed));

    let full = sweep(
        dir,
        &sweep_args(&mesh, "full", 100, "1..6"),
        &["--threads", "2"],
    );
    assert!(full.status.success(), "{}", stderr(&full));
    let a = records(&dir.join("full"));
    assert_eq!(a.len(), total);
    assert_same(
        &a,
        &records(&dir.join("killed")),
        "killed + resumed vs uninterrupted",
    );
    // Every line is complete and parses: no torn or duplicated line survived.
    let text = std::fs::read_to_string(&runs).unwrap();
    assert_eq!(text.lines().count(), total);
    assert!(text.ends_with('\n'));
}

#[test]
fn torn_last_line_is_redone_on_resume_and_fresh_sweep_refuses_a_used_dir() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let mesh = small_mesh(dir, 600);
    let args = sweep_args(&mesh, "out", 4, "1..3");
    assert!(sweep(dir, &args, &[]).status.success());
    let want = records(&dir.join("out"));
    let runs = dir.join("out/runs.jsonl");
    let text = std::fs::read(&runs).unwrap();
    // Drop the last 3 lines and tear the one before them.
    let ends: Vec<usize> = text
        .iter()
        .enumerate()
        .filter(|(_, c)| **c == b'\n')
        .map(|(i, _)| i)
        .collect();
    let cut = ends[ends.len() - 5] + 1 + 30;
    std::fs::write(&runs, &text[..cut]).unwrap();
    assert_eq!(store::read(&runs).unwrap().records.len(), want.len() - 4);

    let again = sweep(dir, &args, &[]);
    assert_eq!(again.status.code(), Some(4), "{}", stderr(&again));
    assert!(stderr(&again).contains("--resume"), "{}", stderr(&again));

    let resumed = sweep(dir, &args, &["--resume"]);
    assert!(resumed.status.success(), "{}", stderr(&resumed));
    assert_same(
        &want,
        &records(&dir.join("out")),
        "torn + resumed vs original",
    );
    assert_eq!(
        std::fs::read_to_string(&runs).unwrap().lines().count(),
        want.len()
    );

    // Resuming with another configuration is refused.
    let other = sweep(dir, &sweep_args(&mesh, "out", 5, "1..3"), &["--resume"]);
    assert_eq!(other.status.code(), Some(4));
    assert!(stderr(&other).contains("runs 5 vs 4"), "{}", stderr(&other));
}

/// The manifest records each sweep that ran runs into a directory: the build (this checkout's
/// git commit), the start (checked against `date -u`) and the records before it; the report
/// names the build, says when builds are mixed (which records each ran), and says when the
/// build was not recorded.
#[test]
fn manifest_records_each_sweeps_build_and_the_report_says_which_ran_what() {
    use serde_json::Value;
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let mesh = small_mesh(dir, 600);
    let args = sweep_args(&mesh, "out", 4, "1..3");
    let minute = || {
        let out = Command::new("date")
            .args(["-u", "+%Y-%m-%dT%H:%M"])
            .output()
            .unwrap();
        String::from_utf8(out.stdout).unwrap().trim().to_string()
    };
    let before = minute();
    assert!(sweep(dir, &args, &[]).status.success());
    let after = minute();
    let manifest = |d: &Path| -> Value {
        serde_json::from_str(&std::fs::read_to_string(d.join("out/manifest.json")).unwrap())
            .unwrap()
    };
    let m = manifest(dir);
    let sessions = m["sessions"].as_array().unwrap();
    assert_eq!(sessions.len(), 1, "{m}");
    let build = sessions[0]["build"].as_str().unwrap().to_string();
    assert!(build.starts_with("quadrecomb 0.1.0, git "), "{build}");
    let head = Command::new("git")
        .args(["rev-parse", "--short=12", "HEAD"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .ok()
        .filter(|o| o.status.success());
    if let Some(head) = head {
        let head = String::from_utf8(head.stdout).unwrap();
        assert!(build.contains(head.trim()), "{build} vs HEAD {head}");
    }
    let started = sessions[0]["started"].as_str().unwrap();
    assert!(
        (started.starts_with(&before) || started.starts_with(&after)) && started.ends_with('Z'),
        "{started} vs date -u {before} .. {after}"
    );
    assert_eq!(sessions[0]["runs_before"], 0);

    // Cut the log to its first `kept` records and resume: a second session after them.
    let runs = dir.join("out/runs.jsonl");
    let text = std::fs::read_to_string(&runs).unwrap();
    let total = text.lines().count();
    let kept = total - 3;
    let head: Vec<&str> = text.lines().take(kept).collect();
    std::fs::write(&runs, head.join("\n") + "\n").unwrap();
    assert!(sweep(dir, &args, &["--resume"]).status.success());
    let m = manifest(dir);
    let sessions = m["sessions"].as_array().unwrap();
    assert_eq!(sessions.len(), 2, "{m}");
    assert_eq!(sessions[1]["runs_before"], kept);
    assert_eq!(sessions[1]["build"], build.as_str());

    let report = |d: &Path| {
        let out = run_in(d, &["report", "out"]);
        assert!(out.status.success(), "{}", stderr(&out));
        std::fs::read_to_string(d.join("out/report.md")).unwrap()
    };
    let text = report(dir);
    assert!(
        text.contains(&format!(
            "Build: {build} (sweep started {started}, resumed once)"
        )),
        "{text}"
    );
    assert!(
        text.contains("compare them only with times of the same build"),
        "{text}"
    );

    // The first sweep's build made another: the report says which records each ran.
    let mut m = manifest(dir);
    m["sessions"][0]["build"] = "quadrecomb 0.0.9, git 000000000000".into();
    std::fs::write(dir.join("out/manifest.json"), m.to_string()).unwrap();
    let text = report(dir);
    let want = format!(
        "Builds: records 1–{kept} by quadrecomb 0.0.9, git 000000000000 (started {started}); \
         records {}–{total} by {build}",
        kept + 1
    );
    assert!(text.contains(&want), "{want}\n{text}");
    assert!(text.contains("their times are not comparable"), "{text}");

    // A later sweep that added no run (a resume of a finished directory) is no build of
    // these records.
    let other = "quadrecomb 0.0.9, git 000000000000";
    let session = |build: &str, runs_before: usize| serde_json::json!({"build": build, "started": started, "runs_before": runs_before});
    m["sessions"] = serde_json::json!([session(&build, 0), session(other, total)]);
    std::fs::write(dir.join("out/manifest.json"), m.to_string()).unwrap();
    let text = report(dir);
    assert!(
        text.contains(&format!("Build: {build} (sweep started {started}).")),
        "{text}"
    );
    assert!(!text.contains("are mixed"), "{text}");

    // A directory written before builds were recorded, then resumed: its first records are
    // no build's that the manifest knows.
    m["sessions"] = serde_json::json!([session(other, kept)]);
    std::fs::write(dir.join("out/manifest.json"), m.to_string()).unwrap();
    let text = report(dir);
    let want = format!(
        "Builds: records 1–{kept} by a build not recorded (written before quadrecomb \
         recorded its builds, 2026-12-05); records {}–{total} by {other} (started {started}). \
         Runs of different builds are mixed here",
        kept + 1
    );
    assert!(text.contains(&want), "{want}\n{text}");

    // A list that contradicts the run log is not read.
    m["sessions"] = serde_json::json!([session(other, 0), session(&build, total + 5)]);
    std::fs::write(dir.join("out/manifest.json"), m.to_string()).unwrap();
    assert!(report(dir).contains("does not fit the"), "{}", report(dir));

    // A directory written before builds were recorded.
    m.as_object_mut().unwrap().remove("sessions");
    std::fs::write(dir.join("out/manifest.json"), m.to_string()).unwrap();
    assert!(report(dir).contains("Build: a build not recorded"));
}

#[test]
fn overwrite_replaces_an_earlier_sweep_with_another_configuration() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let mesh = small_mesh(dir, 600);
    assert!(
        sweep(dir, &sweep_args(&mesh, "out", 4, "1..3"), &[])
            .status
            .success()
    );
    // The sweep's report listed its figures: --overwrite removes those (and keeps a file
    // it did not write).
    assert!(
        run_in(dir, &["report", "out", "--no-pictures"])
            .status
            .success()
    );
    let listed = std::fs::read_to_string(dir.join("out/report-files.txt")).unwrap();
    let figure = dir.join("out").join(listed.lines().next().unwrap());
    assert!(figure.is_file());
    let mine = dir.join("out/figures/mine.svg");
    std::fs::write(&mine, "<svg/>").unwrap();
    let args = sweep_args(&mesh, "out", 3, "1..2");
    let refused = sweep(dir, &args, &[]);
    assert_eq!(refused.status.code(), Some(4));
    assert!(
        stderr(&refused).contains("--overwrite"),
        "{}",
        stderr(&refused)
    );

    let replaced = sweep(dir, &args, &["--overwrite"]);
    assert!(replaced.status.success(), "{}", stderr(&replaced));
    assert!(!figure.exists(), "old figures are removed");
    assert!(mine.exists(), "a file the sweep did not write is kept");
    let fresh = sweep(dir, &sweep_args(&mesh, "fresh", 3, "1..2"), &[]);
    assert!(fresh.status.success());
    assert_same(
        &records(&dir.join("fresh")),
        &records(&dir.join("out")),
        "overwritten vs fresh",
    );
    let both = sweep(dir, &args, &["--overwrite", "--resume"]);
    assert_eq!(
        both.status.code(),
        Some(2),
        "--overwrite conflicts with --resume"
    );
}

#[test]
fn ctrl_c_saves_finished_runs_and_exits_non_zero() {
    interrupted_sweep_keeps_its_runs("-INT");
}

/// SIGTERM (`kill`, a batch scheduler's stop) stops a sweep as Ctrl-C does: the runs in
/// flight finish, no line is torn, exit 130 (the default action killed it mid-write).
#[test]
fn sigterm_stops_a_sweep_as_ctrl_c_does() {
    interrupted_sweep_keeps_its_runs("-TERM");
}

/// A sweep sent `signal` (a `kill` option) once it has recorded ten runs: a second sweep into
/// its directory meanwhile is refused; it exits 130, keeps every finished run without a torn
/// line, and `--resume` completes it.
fn interrupted_sweep_keeps_its_runs(signal: &str) {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let mesh = small_mesh(dir, 1000);
    let args = sweep_args(&mesh, "int", 100, "1..6");
    let total = 6 * 100 + 2 + 2 + 1;
    let child = Command::new(bin())
        .args(&args)
        .args(["--threads", "2"])
        .current_dir(dir)
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let runs = dir.join("int/runs.jsonl");
    assert!(wait_for_lines(&runs, 10, Duration::from_secs(60)) >= 10);
    // A second sweep into the same directory while the first runs is refused.
    let second = sweep(dir, &args, &["--resume"]);
    assert_eq!(second.status.code(), Some(4), "{}", stderr(&second));
    assert!(
        stderr(&second).contains("another sweep"),
        "{}",
        stderr(&second)
    );
    let kill = Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(130), "{}", stderr(&out));
    assert!(stderr(&out).contains("interrupted"), "{}", stderr(&out));
    let kept = store::read(&runs).unwrap();
    assert_eq!(kept.torn_bytes, 0, "a clean stop leaves no torn line");
    assert!(kept.records.len() >= 10 && kept.records.len() < total);
    let resumed = sweep(dir, &args, &["--resume", "--threads", "2"]);
    assert!(resumed.status.success(), "{}", stderr(&resumed));
    assert_eq!(records(&dir.join("int")).len(), total);
}

/// A run that will last hours is warned about while it runs (a sweep's progress counts
/// finished runs, and none finishes), and a stop does not wait for it: after SIGTERM the
/// runs in flight get 10 s, then the sweep quits (130), says what is recorded, and prints
/// its `--json` object. (A run of the uniform tree of horizon 8 on `sphere`: its first tree
/// alone is not done after minutes.)
#[test]
fn a_long_run_is_warned_about_and_does_not_hold_a_stop() {
    use std::io::BufRead;
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let args = "sweep --mesh sphere --algo uniform --horizons 8 --out long --plain --json";
    let args = args.split_whitespace();
    let mut child = Command::new(bin())
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let (tx, rx) = std::sync::mpsc::channel();
    let err = child.stderr.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut all = String::new();
        for line in std::io::BufReader::new(err).lines().map_while(Result::ok) {
            if line.starts_with("warning: sweep:") {
                let _ = tx.send(line.clone());
            }
            all += &line;
            all.push('\n');
        }
        all
    });
    let warning = rx.recv_timeout(Duration::from_secs(120));
    let kill = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let stopped = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if stopped.elapsed() > Duration::from_secs(60) {
            child.kill().unwrap();
            panic!("the sweep still ran 60 s after SIGTERM");
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    let waited = stopped.elapsed();
    let out = child.wait_with_output().unwrap();
    let err = reader.join().unwrap();
    let warning = warning.unwrap_or_else(|_| panic!("no warning within 120 s: {err}"));
    assert!(
        warning.contains("sphere uniform h=8 run 0: the first look-ahead tree has expanded")
            && warning.contains("a lower --horizons is faster"),
        "{warning}"
    );
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert!(
        err.contains(
            "the runs in flight did not finish within 10 s: quitting now: 0 of 1 runs recorded"
        ),
        "{err}"
    );
    assert!(
        waited >= Duration::from_secs(9) && waited < Duration::from_secs(60),
        "{waited:?}"
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["cancelled"], true);
    assert_eq!((v["runs"].as_u64(), v["new"].as_u64()), (Some(1), Some(0)));
    let kept = store::read(&dir.join("long/runs.jsonl")).unwrap();
    assert_eq!((kept.records.len(), kept.torn_bytes), (0, 0));
}

#[test]
fn a_second_sweep_into_a_busy_directory_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let mesh = small_mesh(dir, 600);
    // Long enough to still be running when the second one starts; killed at the end.
    let args = sweep_args(&mesh, "busy", 5000, "1..4");
    let mut first = Command::new(bin())
        .args(&args)
        .args(["--threads", "1"])
        .current_dir(dir)
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let runs = dir.join("busy/runs.jsonl");
    assert!(wait_for_lines(&runs, 2, Duration::from_secs(60)) >= 2);
    let second = sweep(dir, &args, &["--resume"]);
    let still_running = first.try_wait().unwrap().is_none();
    first.kill().unwrap();
    first.wait().unwrap();
    assert!(
        still_running,
        "the first sweep ended too early for this test"
    );
    assert_eq!(second.status.code(), Some(4), "{}", stderr(&second));
    assert!(
        stderr(&second).contains("another sweep"),
        "{}",
        stderr(&second)
    );
    // Once the writer is gone (killed, leaving a stale lock), the lock is taken over: what
    // stops this resume is now its different shard, not the lock.
    let resumed = sweep(
        dir,
        &sweep_args(&mesh, "busy", 5000, "1..4"),
        &["--resume", "--shard", "1/1"],
    );
    assert_eq!(
        resumed.status.code(),
        Some(4),
        "a shard of another list is refused"
    );
    assert!(
        stderr(&resumed).contains("shard 1/1 vs the whole run list"),
        "{}",
        stderr(&resumed)
    );
}

#[test]
fn merge_rejects_foreign_missing_and_duplicated_parts() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let mesh = small_mesh(dir, 600);
    for i in 1..=2 {
        let shard = format!("{i}/2");
        let out = sweep(
            dir,
            &sweep_args(&mesh, &format!("p{i}"), 3, "1..2"),
            &["--shard", &shard],
        );
        assert!(out.status.success(), "{}", stderr(&out));
    }
    let mut other = sweep_args(&mesh, "q2", 3, "1..2");
    let seed_pos = other.iter().position(|a| a == "--seed").unwrap();
    other[seed_pos + 1] = "1".into();
    assert!(sweep(dir, &other, &["--shard", "2/2"]).status.success());

    let foreign = run_in(dir, &["merge", "p1", "q2", "--out", "m1", "--no-report"]);
    assert_eq!(foreign.status.code(), Some(3));
    assert!(
        stderr(&foreign).contains("not parts of the same sweep"),
        "{}",
        stderr(&foreign)
    );
    assert!(stderr(&foreign).contains("seed"), "{}", stderr(&foreign));

    let missing = run_in(dir, &["merge", "p1", "--out", "m2", "--no-report"]);
    assert_eq!(missing.status.code(), Some(3));
    assert!(stderr(&missing).contains("missing"), "{}", stderr(&missing));

    let dup = run_in(
        dir,
        &["merge", "p1", "p2", "p2", "--out", "m3", "--no-report"],
    );
    assert_eq!(dup.status.code(), Some(3));
    assert!(stderr(&dup).contains("p2: given twice"), "{}", stderr(&dup));

    // Shards cut with another --shard count are named as such, not as a duplicated run.
    let args = sweep_args(&mesh, "r3", 3, "1..2");
    assert!(sweep(dir, &args, &["--shard", "2/3"]).status.success());
    let counts = run_in(dir, &["merge", "p1", "r3", "--out", "m6", "--no-report"]);
    assert_eq!(counts.status.code(), Some(3));
    assert!(
        stderr(&counts).contains("is shard 1/2 but") && stderr(&counts).contains("shard 2/3"),
        "{}",
        stderr(&counts)
    );

    let nodir = run_in(dir, &["merge", "p1", "nodir", "--out", "m5", "--no-report"]);
    assert_eq!(nodir.status.code(), Some(3));
    assert!(
        stderr(&nodir).contains("nodir: no such results directory"),
        "{}",
        stderr(&nodir)
    );

    // A successful merge writes the report of the merged results.
    let ok = run_in(dir, &["merge", "p1", "p2", "--out", "m4"]);
    assert!(ok.status.success(), "{}", stderr(&ok));
    // Merging into a directory that holds runs is refused, with advice merge can follow.
    let again = run_in(dir, &["merge", "p1", "p2", "--out", "m4", "--no-report"]);
    assert_eq!(again.status.code(), Some(4));
    assert!(
        stderr(&again).contains("choose another --out"),
        "{}",
        stderr(&again)
    );
    assert!(!stderr(&again).contains("--resume"), "{}", stderr(&again));
    assert!(dir.join("m4/report.md").exists());
    // 2 horizons x 3 runs of selective + 2 greedy + 2 greedy-nocrit + 1 optimum.
    assert_eq!(records(&dir.join("m4")).len(), 2 * 3 + 2 + 2 + 1);
}

#[test]
fn sweep_writes_summary_and_report_by_default() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let mesh = small_mesh(dir, 400);
    let args: Vec<String> = sweep_args(&mesh, "rep", 3, "1..2")
        .into_iter()
        .filter(|a| a != "--no-report")
        .collect();
    let out = sweep(dir, &args, &[]);
    assert!(out.status.success(), "{}", stderr(&out));
    for f in [
        "runs.jsonl",
        "manifest.json",
        "summary.csv",
        "summary.json",
        "report.md",
    ] {
        assert!(dir.join("rep").join(f).exists(), "{f} missing");
    }
    let csv = std::fs::read_to_string(dir.join("rep/summary.csv")).unwrap();
    assert!(csv.contains("small,selective,2,quality_pct,3,"), "{csv}");
    assert!(csv.contains("small,optimum,,quality_pct,1,100,"), "{csv}");
}

#[test]
fn statistics_match_textbook_values() {
    // R: quantile(1:10, type = 7) -> 1.00 3.25 5.50 7.75 10.00
    let xs: Vec<f64> = (1..=10).map(f64::from).collect();
    assert_eq!(quantile(&xs, 0.25), 3.25);
    assert_eq!(quantile(&xs, 0.75), 7.75);
    // 2 4 4 4 5 5 7 9: sample variance 32 / 7.
    let ys = [2.0, 4.0, 4.0, 4.0, 5.0, 5.0, 7.0, 9.0];
    assert!((sd(&ys) - (32.0f64 / 7.0).sqrt()).abs() < 1e-12);
    // Tukey: 1..10 plus 30 -> Q1 3.5, Q3 8.5, upper fence 16, so 30 is an outlier.
    let mut zs = xs.clone();
    zs.push(30.0);
    let b = BoxStats::of(&zs).unwrap();
    assert_eq!((b.q1, b.median, b.q3), (3.5, 6.0, 8.5));
    assert_eq!((b.whisker_low, b.whisker_high), (1.0, 10.0));
    assert_eq!(b.outliers, vec![30.0]);
}

/// Arguments a sweep cannot follow are refused up front with one clear line and the exit
/// code of their kind: baselines asked for with zero runs (usage, 2), a missing mesh (bad
/// input, 3; its cause said once), an `--out` that is a file (results directory, 4).
#[test]
fn sweep_refuses_arguments_it_cannot_follow() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(dir.join("afile"), "").unwrap();
    for (args, expect, code) in [
        (
            &[
                "--mesh",
                "sphere",
                "--algo",
                "greedy",
                "--baseline-runs",
                "0",
                "--out",
                "a",
            ][..],
            "--baseline-runs must be at least 1 (it is the number of runs of greedy)",
            2,
        ),
        (
            &[
                "--mesh",
                "sphere",
                "--horizons",
                "1",
                "--runs",
                "1",
                "--out",
                "afile",
            ][..],
            "--out afile: is a regular file, not a directory",
            4,
        ),
        (
            &["--mesh", "nosuch.msh", "--out", "b"][..],
            "nosuch.msh: No such file",
            3,
        ),
    ] {
        let mut all = vec!["sweep", "--backend", "cpu", "--quiet"];
        all.extend_from_slice(args);
        let out = run_in(dir, &all);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(code), "{args:?}: {err}");
        assert!(err.contains(expect), "{args:?}: {err}");
        assert!(
            err.matches("No such file").count() <= 1,
            "cause repeated: {err}"
        );
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
    }
    assert!(!dir.join("a").exists() && !dir.join("b").join("runs.jsonl").exists());
    // The optimum runs once whatever --baseline-runs says: 0 is fine without the greedy ones.
    let mesh = small_mesh(dir, 200);
    let out = run_in(
        dir,
        &[
            "sweep",
            "--mesh",
            mesh.to_str().unwrap(),
            "--algo",
            "selective",
            "optimum",
            "--horizons",
            "1",
            "--runs",
            "1",
            "--baseline-runs",
            "0",
            "--backend",
            "cpu",
            "--quiet",
            "--no-report",
            "--out",
            "c",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(records(&dir.join("c")).len(), 2);
}

/// Shards run from different working directories (the mesh given by different relative
/// paths) merge, and the merged report finds the mesh for its pictures from any directory:
/// the manifest compares meshes by name and content and records the file's absolute path.
#[test]
fn shards_from_other_directories_merge_and_report_finds_the_mesh() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    small_mesh(dir, 300);
    let sub = dir.join("sub");
    std::fs::create_dir(&sub).unwrap();
    let a = sweep(
        dir,
        &sweep_args(Path::new("small.msh"), "p1", 2, "1"),
        &["--shard", "1/2"],
    );
    assert!(a.status.success(), "{}", stderr(&a));
    let b = sweep(
        &sub,
        &sweep_args(Path::new("../small.msh"), "../p2", 2, "1"),
        &["--shard", "2/2"],
    );
    assert!(b.status.success(), "{}", stderr(&b));
    let m = run_in(dir, &["merge", "p1", "p2", "--out", "m"]);
    assert!(m.status.success(), "{}", stderr(&m));
    let report = std::fs::read_to_string(dir.join("m/report.md")).unwrap();
    assert!(
        report.contains("![") && !report.contains("No picture"),
        "{report}"
    );
    // From another directory, where `small.msh` does not resolve, and from one where it
    // names another mesh (the recorded path, whose hash matches, is used instead).
    for other_mesh_there in [false, true] {
        if other_mesh_there {
            small_mesh(&sub, 500);
        }
        let r = run_in(&sub, &["report", "../m"]);
        assert!(r.status.success(), "{}", stderr(&r));
        let report = std::fs::read_to_string(dir.join("m/report.md")).unwrap();
        assert!(
            report.contains("![") && !report.contains("No picture"),
            "{report}"
        );
    }
}

/// Plan version 2: deterministic configurations run once (uniform once per horizon) and the
/// sweep says so; seeds are below 2^53; the default backend is the CPU twin (also where a
/// Vulkan adapter exists, as lavapipe does in CI); a version-1 directory is not resumed with
/// the new recipe.
#[test]
fn deterministic_runs_once_seeds_fit_doubles_and_the_default_is_the_twin() {
    let tmp = tempfile::tempdir().unwrap();
    let args = [
        "sweep",
        "--mesh",
        "sphere",
        "--algo",
        "uniform",
        "selective",
        "greedy",
        "--horizons",
        "1..2",
        "--runs",
        "3",
        "--out",
        "d",
        "--no-report",
        "--plain",
    ];
    let out = run_in(tmp.path(), &args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("uniform, greedy deterministic"), "{err}");
    let text = std::fs::read_to_string(tmp.path().join("d/runs.jsonl")).unwrap();
    let recs: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let count = |algo: &str| recs.iter().filter(|r| r["algo"] == algo).count();
    assert_eq!(
        (count("uniform"), count("selective"), count("greedy")),
        (2, 6, 1)
    );
    for r in &recs {
        let seed = r["seed"].as_u64().unwrap();
        assert!(seed < 1 << 53, "seed {seed}");
        assert_eq!(r["backend"], "cpu-twin");
    }
    let bad = run_in(
        tmp.path(),
        &[
            "sweep",
            "--mesh",
            "sphere",
            "--seed",
            "9007199254740992",
            "--out",
            "e",
        ],
    );
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("above 2^53 - 1"));
    // A directory of plan version 1 (its manifest has no plan_version) is not resumed.
    let manifest = tmp.path().join("d/manifest.json");
    let mut m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&manifest).unwrap()).unwrap();
    m["spec"].as_object_mut().unwrap().remove("plan_version");
    std::fs::write(&manifest, serde_json::to_string_pretty(&m).unwrap()).unwrap();
    let mut resume = args.to_vec();
    resume.push("--resume");
    let again = run_in(tmp.path(), &resume);
    assert_eq!(
        again.status.code(),
        Some(4),
        "{}",
        String::from_utf8_lossy(&again.stderr)
    );
    assert!(String::from_utf8_lossy(&again.stderr).contains("plan version 2 vs 1"));
}
