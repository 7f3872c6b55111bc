//! Reliability of what the CLI reads and writes (issue 26): outputs written whole or not at
//! all, never over the input or a special file; one sweep per directory; records checked
//! before they are believed; bad sizes and inputs refused with a message.

use crate::util::{bin, run_in};
use std::path::{Path, PathBuf};
use std::process::Output;

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The arguments of a small sweep (sphere, selective h = 1, 2 and greedy) into `name`.
fn small_sweep_args(name: &str) -> Vec<&str> {
    vec![
        "sweep",
        "--mesh",
        "sphere",
        "--algo",
        "selective",
        "greedy",
        "--horizons",
        "1,2",
        "--runs",
        "3",
        "--backend",
        "cpu",
        "--out",
        name,
        "-q",
    ]
}

/// A small sweep ([`small_sweep_args`]) into `dir/name`, with its report.
fn small_sweep(dir: &Path, name: &str, extra: &[&str]) -> PathBuf {
    let mut args = small_sweep_args(name);
    args.extend_from_slice(extra);
    let o = run_in(dir, &args);
    assert!(o.status.success(), "{}", stderr(&o));
    dir.join(name)
}

/// Every regular file under `dir` (relative path, content), sorted.
fn snapshot(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let rel = p.strip_prefix(dir).unwrap().to_string_lossy().into_owned();
                out.push((rel, std::fs::read(&p).unwrap_or_default()));
            }
        }
    }
    out.sort();
    out
}

fn names(snap: &[(String, Vec<u8>)]) -> Vec<&str> {
    snap.iter().map(|(n, _)| n.as_str()).collect()
}

#[cfg(unix)]
fn mkfifo(path: &Path) -> bool {
    std::process::Command::new("mkfifo")
        .arg(path)
        .status()
        .is_ok_and(|s| s.success())
}

/// Item 5: a report that runs out of space (here a file size limit: writes beyond 10 KiB
/// fail with EFBIG, as on a full disk) leaves the earlier report whole and no temporary.
#[cfg(unix)]
#[test]
fn a_report_that_cannot_be_written_leaves_the_earlier_one_whole() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = small_sweep(tmp.path(), "d", &[]);
    let before = snapshot(&dir);
    assert!(
        names(&before).contains(&"report.md"),
        "{:?}",
        names(&before)
    );
    let o = run_limited(
        tmp.path(),
        "trap '' XFSZ; ulimit -f 10",
        &["report", "d", "--no-pictures"],
        120,
    );
    assert!(!o.status.success(), "the write should have failed");
    assert!(stderr(&o).contains("File too large"), "{}", stderr(&o));
    let after = snapshot(&dir);
    assert_eq!(names(&after), names(&before));
    assert!(after == before, "a file changed after a failed report");
}

/// Item 4: the output path is a FIFO (or a device): it is refused, not replaced by a
/// regular file, and no temporary is left.
#[cfg(unix)]
#[test]
fn an_output_that_is_a_fifo_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let fifo = tmp.path().join("out.msh");
    if !mkfifo(&fifo) {
        eprintln!("skipping: mkfifo is not available");
        return;
    }
    let o = run_in(
        tmp.path(),
        &[
            "recombine",
            "sphere",
            "--algo",
            "greedy",
            "--no-optimum",
            "-o",
            "out.msh",
        ],
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("FIFO"), "{}", stderr(&o));
    use std::os::unix::fs::FileTypeExt;
    assert!(
        std::fs::symlink_metadata(&fifo)
            .unwrap()
            .file_type()
            .is_fifo()
    );
    let left: Vec<_> = std::fs::read_dir(tmp.path()).unwrap().collect();
    assert_eq!(left.len(), 1, "a temporary was left behind");
}

/// Item 3: six sweeps with `--resume` started at once into one directory, 40 times. One
/// holds the directory's lock, the others are refused at once (exit 2, "another sweep") or
/// find the work done; no line of `runs.jsonl` is ever torn or interleaved, no run is
/// recorded twice, and the optimum cache (written by each sweep before it locks) is never
/// half-written. The PID-file lock of before let two sweeps in at once ("{"m{"mesh": ...").
#[test]
fn concurrent_sweeps_never_interleave_records() {
    let tmp = tempfile::tempdir().unwrap();
    let o = run_in(
        tmp.path(),
        &[
            "generate",
            "grid",
            "--triangles",
            "200",
            "--seed",
            "7",
            "-o",
            "g.msh",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let planned = 3 * 64 + 1; // selective h = 1..3, 64 runs each, and greedy once
    for round in 0..40 {
        let out = format!("d{round}");
        let args = [
            "sweep",
            "--mesh",
            "g.msh",
            "--algo",
            "selective",
            "greedy",
            "--horizons",
            "1..3",
            "--runs",
            "64",
            "--threads",
            "1",
            "--backend",
            "cpu",
            "--out",
            &out,
            "-q",
            "--no-report",
            "--resume",
        ];
        let children: Vec<_> = (0..6)
            .map(|_| {
                std::process::Command::new(bin())
                    .args(args)
                    .current_dir(tmp.path())
                    .stdout(std::process::Stdio::null())
                    .stderr(std::process::Stdio::piped())
                    .spawn()
                    .unwrap()
            })
            .collect();
        let mut ok = 0;
        for c in children {
            let o = c.wait_with_output().unwrap();
            match o.status.code() {
                Some(0) => ok += 1,
                Some(4) if stderr(&o).contains("another sweep") => {}
                _ => panic!("round {round}: {:?}: {}", o.status, stderr(&o)),
            }
        }
        assert!(ok >= 1, "round {round}: every sweep was refused");
        let text = std::fs::read_to_string(tmp.path().join(&out).join("runs.jsonl")).unwrap();
        let mut keys = std::collections::HashSet::new();
        for (i, line) in text.lines().enumerate() {
            let rec: serde_json::Value = serde_json::from_str(line)
                .unwrap_or_else(|e| panic!("round {round}, line {}: {e}: {line}", i + 1));
            let key = (
                rec["algo"].clone(),
                rec["horizon"].clone(),
                rec["run"].clone(),
            );
            assert!(
                keys.insert(format!("{key:?}")),
                "round {round}: {line} twice"
            );
        }
        assert!(text.ends_with('\n'));
        assert_eq!(keys.len(), planned, "round {round}");
        assert!(!tmp.path().join(&out).join(".lock").exists());
    }
}

/// Item 1: `-o` naming the input, as given, as `./in.msh`, through a symbolic link or a hard
/// link, is refused (exit 2) and the input is left untouched; another name is fine.
#[cfg(unix)]
#[test]
fn an_output_that_is_the_input_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let o = run_in(
        tmp.path(),
        &[
            "generate",
            "grid",
            "--triangles",
            "50",
            "--seed",
            "1",
            "-o",
            "in.msh",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    std::os::unix::fs::symlink("in.msh", tmp.path().join("link.msh")).unwrap();
    std::fs::hard_link(tmp.path().join("in.msh"), tmp.path().join("hard.msh")).unwrap();
    let input = std::fs::read(tmp.path().join("in.msh")).unwrap();
    for cmd in [
        &["recombine", "in.msh", "--algo", "greedy"][..],
        &["optimum", "in.msh"],
    ] {
        for out in ["in.msh", "./in.msh", "link.msh", "hard.msh"] {
            let mut args = cmd.to_vec();
            args.extend(["-o", out]);
            let o = run_in(tmp.path(), &args);
            assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
            assert!(stderr(&o).contains("is the input mesh"), "{}", stderr(&o));
            assert_eq!(std::fs::read(tmp.path().join("in.msh")).unwrap(), input);
        }
    }
    let o = run_in(
        tmp.path(),
        &["recombine", "in.msh", "--algo", "greedy", "-o", "out.msh"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
}

/// Item 2: `sweep --overwrite` into a directory that was never a sweep's deletes nothing of
/// it (and, holding files of a report's names, is refused); into a sweep's directory it deletes the sweep's files and the figures its report
/// listed, nothing else (a file of the user's in `figures/` stays).
#[test]
fn overwrite_deletes_only_what_a_sweep_wrote() {
    let tmp = tempfile::tempdir().unwrap();
    let p = tmp.path().join("p");
    std::fs::create_dir_all(p.join("figures/sub")).unwrap();
    std::fs::write(p.join("figures/sub/fig1.pdf"), "x").unwrap();
    std::fs::write(p.join("report.md"), "n").unwrap();
    std::fs::write(p.join("summary.csv"), "mine").unwrap();
    let before = snapshot(&p);
    let args = [
        "sweep",
        "--mesh",
        "sphere",
        "--algo",
        "greedy",
        "--horizons",
        "1",
        "--runs",
        "1",
        "--overwrite",
        "--out",
        "p",
        "--no-report",
        "-q",
        "--backend",
        "cpu",
    ];
    // Refused (exit 4): its report, summary and figures are the user's, and the sweep
    // would write files of those names (its summary replaced the user's before).
    let o = run_in(tmp.path(), &args);
    assert_eq!(o.status.code(), Some(4), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("not a sweep's results"),
        "{}",
        stderr(&o)
    );
    assert_eq!(snapshot(&p), before, "the directory was touched");

    // A sweep's directory with a report, and a file of the user's among its figures.
    let d = small_sweep(tmp.path(), "d", &[]);
    let figures = names(&snapshot(&d.join("figures")))
        .iter()
        .map(|s| s.to_string())
        .collect::<Vec<_>>();
    assert!(figures.len() >= 3, "{figures:?}");
    std::fs::write(d.join("figures/mine.pdf"), "keep").unwrap();
    std::fs::write(d.join("notes.txt"), "keep").unwrap();
    let o = run_in(
        tmp.path(),
        &[
            "sweep",
            "--mesh",
            "sphere",
            "--algo",
            "greedy",
            "--out",
            "d",
            "--overwrite",
            "--no-report",
            "-q",
            "--backend",
            "cpu",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let left = snapshot(&d);
    let left = names(&left);
    assert!(
        left.contains(&"figures/mine.pdf") && left.contains(&"notes.txt"),
        "{left:?}"
    );
    for f in &figures {
        assert!(
            !left.contains(&format!("figures/{f}").as_str()),
            "{f} left: {left:?}"
        );
    }
    assert!(!left.contains(&"report.md"), "{left:?}");
}

fn lines_of(path: &Path) -> Vec<String> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(String::from)
        .collect()
}

fn edit_line(line: &str, f: impl FnOnce(&mut serde_json::Value)) -> String {
    let mut v: serde_json::Value = serde_json::from_str(line).unwrap();
    f(&mut v);
    serde_json::to_string(&v).unwrap()
}

/// Writes `lines` as `dir/d/runs.jsonl` and checks that `report d` and `merge d --out m`
/// refuse them (exit 3) with `why` at `at`, merging nothing.
fn refused_by_report_and_merge(dir: &Path, lines: &[String], why: &str, at: &str) {
    std::fs::write(dir.join("d/runs.jsonl"), lines.join("\n") + "\n").unwrap();
    for cmd in [
        &["report", "d", "--no-pictures"][..],
        &["merge", "d", "--out", "m"],
    ] {
        let o = run_in(dir, cmd);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(3), "{cmd:?} {why}: {e}");
        assert!(e.contains(why) && e.contains(at), "{cmd:?} {why} {at}: {e}");
        assert!(!dir.join("m/runs.jsonl").exists());
    }
}

/// Item 6: `report` and `merge` refuse records no run of the sweep can have, naming the
/// line: a duplicate (83 runs were shown for 64), a configuration the sweep does not hold
/// (h = 77), another mesh (zero hash), a quality_pct of 150 or a quality above the optimum
/// with as many quads. `report` rewrites summary.csv from the runs it reads.
#[test]
fn report_and_merge_refuse_records_no_run_can_have() {
    let tmp = tempfile::tempdir().unwrap();
    let d = small_sweep(tmp.path(), "d", &["--algo", "optimum", "--no-report"]);
    let runs = d.join("runs.jsonl");
    let good = lines_of(&runs);
    let n = good.len();
    let optimum_line = good.iter().position(|l| l.contains("\"optimum\"")).unwrap();
    let h2 = good
        .iter()
        .position(|l| l.contains("\"selective\"") && l.contains("\"horizon\":2"))
        .unwrap();
    // The good lines with line `i` edited by `f`.
    let edited = |i: usize, f: &dyn Fn(&mut serde_json::Value)| {
        let mut l = good.clone();
        l[i] = edit_line(&l[i], f);
        l
    };
    // The optimum's record with its quality (and percentage) scaled by `f`, without the
    // element figures, which are checked against the quality.
    let optimum_scaled = |f: f64| {
        edited(optimum_line, &move |v| {
            let q = v["quality"].as_f64().unwrap() * f;
            v["quality"] = q.into();
            v["quality_pct"] = (100.0 * f).into();
            v["mean_eta"] = serde_json::Value::Null;
        })
    };
    let tampered: Vec<(&str, Vec<String>, String)> = vec![
        (
            "recorded twice (first on line 3)",
            {
                let mut l = good.clone();
                l.push(good[2].clone());
                l
            },
            format!("line {}", n + 1),
        ),
        (
            "not part of this sweep",
            edited(1, &|v| v["horizon"] = 77.into()),
            "runs.jsonl:2".into(),
        ),
        (
            "mesh hash",
            edited(0, &|v| v["mesh_hash"] = "0".repeat(64).into()),
            "runs.jsonl:1".into(),
        ),
        (
            "quality_pct 150",
            edited(3, &|v| v["quality_pct"] = 150.0.into()),
            "line 4".into(),
        ),
        (
            // A percentage beside other runs' raw sums would be compared with them.
            "quality_pct is missing, but its mesh's optimum",
            edited(3, &|v| v["quality_pct"] = serde_json::Value::Null),
            "line 4".into(),
        ),
        (
            "above the exact optimum",
            optimum_scaled(1.5),
            format!("line {}", optimum_line + 1),
        ),
        (
            "was made under the rule",
            edited(0, &|v| v["allow_invalid"] = true.into()),
            "runs.jsonl:1".into(),
        ),
        (
            "its rule (min_eta 2, allow_invalid false)",
            edited(2, &|v| v["min_eta"] = 2.0.into()),
            "line 3".into(),
        ),
        (
            "worst_eta 1.5 is not the eta of one of its",
            edited(1, &|v| v["worst_eta"] = 1.5.into()),
            "line 2".into(),
        ),
        // Derived figures that do not derive from the run's own (a report shows them as
        // recorded): all were shown before.
        (
            "recombined_pct 50 is not 100 x 2 x",
            edited(1, &|v| v["recombined_pct"] = 50.0.into()),
            "line 2".into(),
        ),
        (
            "branching_factor 99 is not the one of its",
            edited(h2, &|v| v["branching_factor"] = 99.0.into()),
            format!("line {}", h2 + 1),
        ),
        (
            "is more than quads_eta_below_0_3",
            edited(1, &|v| {
                let b = v["quads_eta_below_0_3"].as_u64().unwrap();
                v["quads_eta_below_0_3"] = 0.into();
                v["quads_eta_below_0_1"] = b.max(1).into();
            }),
            "line 2".into(),
        ),
        (
            "is not its mesh's recorded optimum",
            optimum_scaled(0.5),
            format!("line {}", optimum_line + 1),
        ),
        (
            // Its element figures too (a second review's edit, accepted before).
            "is not its mesh's recorded optimum",
            edited(optimum_line, &|v| v["worst_eta"] = 0.01.into()),
            format!("line {}", optimum_line + 1),
        ),
        (
            // Records of another base seed under this manifest (report took them before).
            "another seed",
            edited(h2, &|v| {
                v["seed"] = (v["seed"].as_u64().unwrap() ^ 1).into();
            }),
            format!("runs.jsonl:{}", h2 + 1),
        ),
    ];
    for (why, lines, at) in tampered {
        refused_by_report_and_merge(tmp.path(), &lines, why, &at);
    }
    std::fs::write(&runs, good.join("\n") + "\n").unwrap();
    let summary = std::fs::read(d.join("summary.csv")).unwrap();
    std::fs::write(d.join("summary.csv"), "stale\n").unwrap();
    let o = run_in(tmp.path(), &["report", "d", "--no-pictures"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(std::fs::read(d.join("summary.csv")).unwrap(), summary);
}

/// A finished run's figures are checked as the search's are: a recombined_pct that is not its
/// quads' share, a quality above the optimum with as many quads (with a quality_pct to match),
/// or a quality_pct that is not its quality's share were all shown by `report` before.
#[test]
fn report_and_merge_refuse_finish_figures_no_run_can_have() {
    let tmp = tempfile::tempdir().unwrap();
    let d = small_sweep(tmp.path(), "d", &["--finish", "--no-report"]);
    let runs = d.join("runs.jsonl");
    let good = lines_of(&runs);
    let i = good.iter().position(|l| l.contains("\"finish\"")).unwrap();
    let finish = |f: &dyn Fn(&mut serde_json::Value)| {
        let mut l = good.clone();
        l[i] = edit_line(&l[i], |v| f(&mut v["finish"]));
        l
    };
    let opt = {
        let v: serde_json::Value = serde_json::from_str(&good[i]).unwrap();
        100.0 * v["quality"].as_f64().unwrap() / v["quality_pct"].as_f64().unwrap()
    };
    let tampered: Vec<(&str, Vec<String>)> = vec![
        (
            "finish: recombined_pct 5 is not",
            finish(&|f| f["recombined_pct"] = 5.0.into()),
        ),
        (
            "finish: quality 700 is above the exact optimum",
            finish(&|f| {
                f["quality"] = 700.0.into();
                // Without its mean, which is checked against the quality.
                f["mean_eta"] = serde_json::Value::Null;
                f["quality_pct"] = (100.0 * 700.0 / opt).into();
            }),
        ),
        (
            "finish: quality_pct 99 is not 100 x quality",
            finish(&|f| f["quality_pct"] = 99.0.into()),
        ),
        (
            "finish: mean_eta 0.9 is not its quality",
            finish(&|f| f["mean_eta"] = 0.9.into()),
        ),
    ];
    for (why, lines) in tampered {
        refused_by_report_and_merge(tmp.path(), &lines, why, &format!("line {}", i + 1));
    }
}

/// Item 6: an optimum cache whose quality was edited (bits included) is not believed: the
/// sweep recomputes it (greedy was recorded at 166 % of a tampered optimum), and
/// `--overwrite` never reads the cache.
#[test]
fn an_edited_optimum_cache_is_recomputed() {
    let tmp = tempfile::tempdir().unwrap();
    let args = |out: &str, extra: &'static str| {
        let mut a = vec![
            "sweep",
            "--mesh",
            "sphere",
            "--algo",
            "greedy",
            "optimum",
            "--backend",
            "cpu",
            "--out",
            out,
            "-q",
            "--no-report",
        ];
        if !extra.is_empty() {
            a.push(extra);
        }
        a.into_iter().map(String::from).collect::<Vec<_>>()
    };
    let run = |a: Vec<String>| {
        let a: Vec<&str> = a.iter().map(String::as_str).collect();
        let o = run_in(tmp.path(), &a);
        assert!(o.status.success(), "{}", stderr(&o));
    };
    run(args("d", ""));
    let optimum = |d: &str| -> f64 {
        let m: serde_json::Value = serde_json::from_slice(
            &std::fs::read(tmp.path().join(d).join("manifest.json")).unwrap(),
        )
        .unwrap();
        m["optimum"][0]["quality"].as_f64().unwrap()
    };
    let true_opt = optimum("d");
    let cache_dir = tmp.path().join("d/optimum-cache");
    let cache = std::fs::read_dir(&cache_dir)
        .unwrap()
        .next()
        .unwrap()
        .unwrap()
        .path();
    let mut c: serde_json::Value = serde_json::from_slice(&std::fs::read(&cache).unwrap()).unwrap();
    let fake = true_opt * 0.6;
    c["optimum"]["quality"] = fake.into();
    c["quality_bits"] = fake.to_bits().into();
    let tampered = serde_json::to_vec(&c).unwrap();
    std::fs::write(&cache, &tampered).unwrap();
    // A fresh sweep into the same directory (the cache stays) and --overwrite.
    std::fs::remove_file(tmp.path().join("d/runs.jsonl")).unwrap();
    run(args("d", ""));
    assert_eq!(optimum("d"), true_opt);
    std::fs::write(&cache, &tampered).unwrap();
    run(args("d", "--overwrite"));
    assert_eq!(optimum("d"), true_opt);
    for line in lines_of(&tmp.path().join("d/runs.jsonl")) {
        let v: serde_json::Value = serde_json::from_str(&line).unwrap();
        assert!(v["quality_pct"].as_f64().unwrap() <= 100.0, "{line}");
    }
}

/// Item 8: sizes that cannot be held are refused before anything is allocated or written,
/// with the limit (they aborted, exit 134, leaving a manifest and a lock behind).
#[test]
fn huge_sizes_are_refused_with_their_limit() {
    let tmp = tempfile::tempdir().unwrap();
    let cases: [(&[&str], &str); 4] = [
        (
            &[
                "sweep",
                "--mesh",
                "sphere",
                "--horizons",
                "1..1000000000",
                "--out",
                "a",
            ],
            "at most 1024",
        ),
        (
            &[
                "sweep",
                "--mesh",
                "sphere",
                "--algo",
                "selective",
                "--runs",
                "4294967295",
                "--horizons",
                "1",
                "--out",
                "b",
            ],
            "at most 10000000",
        ),
        (
            &[
                "sweep",
                "--mesh",
                "sphere",
                "--algo",
                "greedy",
                "--baseline-runs",
                "4294967295",
                "--out",
                "c",
            ],
            "at most 10000000",
        ),
        (
            &[
                "generate",
                "grid",
                "--triangles",
                "2000000000",
                "-o",
                "g.msh",
            ],
            "GiB of memory",
        ),
    ];
    for (args, msg) in cases {
        let o = run_in(tmp.path(), args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(msg), "{args:?}: {}", stderr(&o));
    }
    let left: Vec<_> = std::fs::read_dir(tmp.path()).unwrap().collect();
    assert!(left.is_empty(), "{left:?}");
}

/// Runs `quadrecomb args` in `dir` under bash with `limits` (ulimit commands); kills it
/// after `secs` seconds (a hang is a failure, not a stuck test).
fn run_limited(dir: &Path, limits: &str, args: &[&str], secs: u64) -> Output {
    let mut child = std::process::Command::new("bash")
        .arg("-c")
        .arg(format!("{limits}; exec \"$0\" \"$@\""))
        .arg(bin())
        .args(args)
        .current_dir(dir)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed().as_secs() >= secs {
            child.kill().unwrap();
            let _ = child.wait();
            panic!("{args:?} did not finish in {secs} s");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

/// Item 10: inputs that never end. A FIFO without a writer (blocked forever), a character
/// device (`/dev/zero` was read for 8 GB) and a directory are refused as not regular files;
/// a 2 GB sparse file is called an unknown format from its first bytes, within 1 GB of
/// address space (it was read whole first).
#[cfg(unix)]
#[test]
fn inputs_that_never_end_are_refused_from_their_first_bytes() {
    let tmp = tempfile::tempdir().unwrap();
    let mut cases: Vec<(String, &str)> = vec![
        ("/dev/zero".into(), "a character device, not a mesh file"),
        (".".into(), "a directory, not a mesh file"),
    ];
    if mkfifo(&tmp.path().join("fifo.msh")) {
        cases.push(("fifo.msh".into(), "a FIFO (named pipe), not a mesh file"));
    }
    let big = std::fs::File::create(tmp.path().join("big.msh")).unwrap();
    big.set_len(2 << 30).unwrap();
    cases.push(("big.msh".into(), "unknown mesh format"));
    for (input, msg) in &cases {
        for cmd in ["info", "optimum"] {
            let o = run_limited(tmp.path(), "ulimit -v 1000000", &[cmd, input], 20);
            assert_eq!(o.status.code(), Some(3), "{cmd} {input}: {}", stderr(&o));
            assert!(stderr(&o).contains(msg), "{cmd} {input}: {}", stderr(&o));
        }
    }
}

/// Item 12: mesh names are escaped in report.md (`## Mesh <img src=x onerror=alert(2)>` was
/// raw HTML there), and meshes whose names slug alike (`a b`, `a-b`) get figures of their
/// own (both wrote `figures/a-b-*.svg`).
#[test]
fn report_escapes_mesh_names_and_keeps_figures_apart() {
    let tmp = tempfile::tempdir().unwrap();
    let names = ["a b", "a-b", "<img src=x onerror=alert(2)>"];
    for (i, n) in names.iter().enumerate() {
        let file = format!("{n}.msh");
        let seed = (i + 1).to_string();
        let args = [
            "generate",
            "grid",
            "--triangles",
            "60",
            "--seed",
            &seed,
            "-o",
            &file,
        ];
        let o = run_in(tmp.path(), &args);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let mut args = vec!["sweep", "--mesh"];
    let files: Vec<String> = names.iter().map(|n| format!("{n}.msh")).collect();
    args.extend(files.iter().map(String::as_str));
    args.extend([
        "--algo",
        "selective",
        "greedy",
        "--horizons",
        "1,2",
        "--runs",
        "2",
        "--backend",
        "cpu",
        "--out",
        "d",
        "-q",
    ]);
    let o = run_in(tmp.path(), &args);
    assert!(o.status.success(), "{}", stderr(&o));
    let md = std::fs::read_to_string(tmp.path().join("d/report.md")).unwrap();
    let raw = md.match_indices('<').any(|(i, _)| !md[..i].ends_with('\\'));
    assert!(!raw, "raw HTML in report.md");
    assert!(
        md.contains(r"## Mesh \<img src=x onerror=alert(2)\>"),
        "{md}"
    );
    let listed: Vec<String> = lines_of(&tmp.path().join("d/report-files.txt"));
    // Three box plots and one picture per mesh, none shared, and the critical-difference
    // diagram across the three meshes.
    assert_eq!(listed.len(), 3 * 4 + 1, "{listed:?}");
    assert!(listed.contains(&"figures/across-meshes-cd.svg".to_string()));
    let unique: std::collections::BTreeSet<_> = listed.iter().collect();
    assert_eq!(unique.len(), listed.len(), "{listed:?}");
    for f in &listed {
        assert!(tmp.path().join("d").join(f).is_file(), "{f}");
        assert!(md.contains(&format!("]({f})")), "{f} not linked");
    }
}

/// Item 13: a duplicate node tag is reported on its own line, with the line of the first
/// (it was reported at the `$Nodes` header line).
#[test]
fn a_duplicate_node_tag_is_reported_on_its_own_line() {
    use quadrecomb::internals::mesh::msh::read_bytes;
    let edit = |file: &str, line: usize, text: &str| -> Vec<u8> {
        let s =
            std::fs::read_to_string(crate::util::repo_path(&format!("tests/data/{file}"))).unwrap();
        let mut lines: Vec<&str> = s.lines().collect();
        lines[line - 1] = text;
        (lines.join("\n") + "\n").into_bytes()
    };
    // MSH 2.2: node 20 (line 25) given the tag of node 7 (line 12).
    let bytes = edit("two_squares_22_ascii.msh", 25, "7 0.28 0.62 0");
    let err = read_bytes("a.msh", &bytes).unwrap_err().to_string();
    assert_eq!(
        err,
        "a.msh:25: node tag 7 is defined twice in $Nodes (first on line 12)"
    );
    // MSH 4.1: the tag of block 2 (line 28) given the tag of block 1 (line 25).
    let bytes = edit("two_squares_41_ascii.msh", 28, "1");
    let err = read_bytes("b.msh", &bytes).unwrap_err().to_string();
    assert_eq!(
        err,
        "b.msh:28: node tag 1 is defined twice in $Nodes (first on line 25)"
    );
}

/// Item 13: a triangle 1e200 long and 1e-200 high (area 0.5) is degenerate for its shape,
/// not "zero area" as it was called; a collinear one still has zero area.
#[test]
fn a_flat_triangle_is_not_called_zero_area() {
    let mesh = |c: &str| {
        format!(
            "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n3\n1 0 0 0\n2 {c}\n3 0 1e-200 0\n\
             $EndNodes\n$Elements\n1\n1 2 2 0 1 1 2 3\n$EndElements\n"
        )
    };
    let err = quadrecomb::internals::mesh::msh::read_bytes("n.msh", mesh("1e200 0 0").as_bytes())
        .unwrap_err()
        .to_string();
    assert!(!err.contains("zero area"), "{err}");
    assert!(
        err.contains("flat to within rounding: its height is about 1e-400 times its longest edge"),
        "{err}"
    );
    let err = quadrecomb::internals::mesh::msh::read_bytes("z.msh", mesh("0 2e-200 0").as_bytes())
        .unwrap_err()
        .to_string();
    assert!(err.contains("degenerate (zero area)"), "{err}");
}

/// Item 13: `merge --out FILE` names the problem (it said `File exists (os error 17)`,
/// exit 1).
#[test]
fn merge_into_a_file_is_named() {
    let tmp = tempfile::tempdir().unwrap();
    small_sweep(tmp.path(), "d", &["--no-report"]);
    std::fs::write(tmp.path().join("m"), "mine").unwrap();
    let o = run_in(tmp.path(), &["merge", "d", "--out", "m"]);
    assert_eq!(o.status.code(), Some(4), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("--out m: is a regular file, not a directory"),
        "{}",
        stderr(&o)
    );
    assert_eq!(std::fs::read(tmp.path().join("m")).unwrap(), b"mine");
}

/// One mutation of a results directory's files: structure-aware (a field of a record or of
/// the manifest set to an odd value, lines duplicated, dropped, swapped) or raw bytes.
fn mutate(rng: &mut rand_chacha::ChaCha8Rng, runs: &mut Vec<String>, manifest: &mut String) {
    use rand::RngExt;
    use serde_json::{Value, json};
    let odd = |rng: &mut rand_chacha::ChaCha8Rng| -> Value {
        match rng.random_range(0..14) {
            0 => json!(0),
            1 => json!(-1),
            2 => json!(1e308),
            3 => json!(-1e308),
            4 => json!(u64::MAX),
            5 => json!(u32::MAX),
            6 => json!(150.0),
            7 => json!(null),
            8 => json!(""),
            9 => json!("<img src=x onerror=alert(1)>|*_`#"),
            10 => json!([1, 2]),
            11 => json!({"a": 1}),
            12 => json!(rng.random_range(-10.0..2000.0)),
            _ => json!(rng.random_range(0u32..100)),
        }
    };
    let n = runs.len();
    match rng.random_range(0..10) {
        0..=3 if n > 0 => {
            let i = rng.random_range(0..n);
            if let Ok(mut v) = serde_json::from_str::<Value>(&runs[i]) {
                let keys: Vec<String> = v.as_object().unwrap().keys().cloned().collect();
                let k = &keys[rng.random_range(0..keys.len())];
                v[k] = odd(rng);
                runs[i] = v.to_string();
            }
        }
        4 if n > 0 => {
            let i = rng.random_range(0..n);
            let line = runs[i].clone();
            runs.insert(rng.random_range(0..=n), line);
        }
        5 if n > 0 => {
            runs.remove(rng.random_range(0..n));
        }
        6 if n > 1 => {
            let (i, j) = (rng.random_range(0..n), rng.random_range(0..n));
            runs.swap(i, j);
        }
        7 => {
            if let Ok(mut v) = serde_json::from_str::<Value>(manifest) {
                let paths: [&[&str]; 8] = [
                    &["optimum", "0", "quality"],
                    &["optimum", "0", "quads"],
                    &["spec", "runs"],
                    &["spec", "horizons"],
                    &["spec", "meshes", "0", "name"],
                    &["spec", "meshes", "0", "triangles"],
                    &["spec", "algos"],
                    &["shard"],
                ];
                let path = paths[rng.random_range(0..paths.len())];
                let mut at = &mut v;
                for p in &path[..path.len() - 1] {
                    at = match p.parse::<usize>() {
                        Ok(i) => &mut at[i],
                        Err(_) => &mut at[*p],
                    };
                }
                at[path[path.len() - 1]] = odd(rng);
                *manifest = v.to_string();
            }
        }
        8 if n > 0 => {
            // Raw bytes: cut a line or splice random bytes into it.
            let i = rng.random_range(0..n);
            let mut b = runs[i].clone().into_bytes();
            let at = rng.random_range(0..=b.len());
            if rng.random_bool(0.5) {
                b.truncate(at);
            } else {
                let junk: Vec<u8> = (0..rng.random_range(1..8)).map(|_| rng.random()).collect();
                b.splice(at..at, junk);
            }
            runs[i] = String::from_utf8_lossy(&b).into_owned();
        }
        _ => {
            let mut b = manifest.clone().into_bytes();
            b.truncate(rng.random_range(0..=b.len()));
            *manifest = String::from_utf8_lossy(&b).into_owned();
        }
    }
}

/// Fuzz campaign on what `report` and `merge` read: record files (and manifests) mutated
/// from a real sweep's, 1 to 4 mutations each, read by the report (without pictures) and by
/// merge. No case may panic or take more than 30 s; most are refused with a message. Cases:
/// `QUADRECOMB_RECORD_FUZZ` (default 200; the campaign of docs/io.md runs 10^4).
#[test]
fn fuzz_report_and_merge_never_panic() {
    use rand::{RngExt, SeedableRng};
    let cases: u64 = std::env::var("QUADRECOMB_RECORD_FUZZ")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(200);
    let tmp = tempfile::tempdir().unwrap();
    let base = small_sweep(tmp.path(), "base", &["--algo", "optimum", "--no-report"]);
    let runs0 = lines_of(&base.join("runs.jsonl"));
    let manifest0 = std::fs::read_to_string(base.join("manifest.json")).unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(crate::util::SEED);
    let (mut refused, mut accepted) = (0u64, 0u64);
    let start = std::time::Instant::now();
    for case in 0..cases {
        let mut runs = runs0.clone();
        let mut manifest = manifest0.clone();
        for _ in 0..rng.random_range(1..=4) {
            mutate(&mut rng, &mut runs, &mut manifest);
        }
        let dir = tmp.path().join(format!("c{case}"));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("runs.jsonl"), runs.join("\n") + "\n").unwrap();
        std::fs::write(dir.join("manifest.json"), &manifest).unwrap();
        let (tx, rx) = std::sync::mpsc::channel();
        let d = dir.clone();
        std::thread::spawn(move || {
            let opts = quadrecomb::internals::report::ReportOptions {
                pictures: false,
                ..Default::default()
            };
            let r = std::panic::catch_unwind(|| {
                let report = quadrecomb::internals::report::write(&d, &opts).is_ok();
                let merge = quadrecomb::internals::experiment::merge::merge(
                    std::slice::from_ref(&d),
                    &d.join("m"),
                );
                (report, merge.is_ok())
            });
            let _ = tx.send(r);
        });
        match rx.recv_timeout(std::time::Duration::from_secs(30)) {
            Ok(Ok((r, m))) => {
                accepted += u64::from(r) + u64::from(m);
                refused += u64::from(!r) + u64::from(!m);
            }
            Ok(Err(_)) => panic!("case {case} panicked: runs {runs:?}, manifest {manifest}"),
            Err(_) => panic!("case {case} hung: runs {runs:?}, manifest {manifest}"),
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
    eprintln!(
        "record fuzz: {cases} cases, {accepted} reads accepted, {refused} refused, {:.1} s",
        start.elapsed().as_secs_f64()
    );
    assert!(refused > 0 && accepted > 0);
}

/// Found by the record fuzz campaign: a manifest whose `runs` is 4294967295 made `report`
/// and `merge` build a run list of 8.6e9 runs (a hang, then out of memory); it is refused as
/// corrupt, as the sweep would have refused the arguments.
#[test]
fn fuzz_manifest_with_huge_runs_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let d = small_sweep(tmp.path(), "d", &["--no-report"]);
    let path = d.join("manifest.json");
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace("\"runs\": 3,", "\"runs\": 4294967295,");
    std::fs::write(&path, text).unwrap();
    for cmd in [
        &["report", "d", "--no-pictures"][..],
        &["merge", "d", "--out", "m"],
    ] {
        let o = run_limited(tmp.path(), "ulimit -v 4000000", cmd, 20);
        assert_eq!(o.status.code(), Some(3), "{cmd:?}: {}", stderr(&o));
        assert!(
            stderr(&o).contains("makes 8589934591 runs, more than a sweep takes (10000000)"),
            "{}",
            stderr(&o)
        );
    }
}

/// Found by the record fuzz campaign: a run whose `time_s` is 1e308 (finite, so a valid
/// record) made the time plot's log axis end at infinity and `report` loop forever.
#[test]
fn fuzz_a_huge_time_is_plotted() {
    let tmp = tempfile::tempdir().unwrap();
    let d = small_sweep(tmp.path(), "d", &["--no-report"]);
    let runs = d.join("runs.jsonl");
    let mut lines = lines_of(&runs);
    let i = lines
        .iter()
        .position(|l| l.contains("\"horizon\":2"))
        .unwrap();
    lines[i] = edit_line(&lines[i], |v| v["time_s"] = 1e308.into());
    std::fs::write(&runs, lines.join("\n") + "\n").unwrap();
    let o = run_limited(tmp.path(), "true", &["report", "d", "--no-pictures"], 30);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// A manifest that lists a horizon, an algorithm or a mesh twice (a sweep refuses each), or
/// holds a plan version this build does not know, no runs or a horizon of 0, is refused by
/// `merge`, `report` and `sweep --resume` with exit 3, naming what is wrong (`merge`
/// panicked: "checked: none missing", a review's finding). A `runs.jsonl` or `manifest.json`
/// that is not a regular file (a directory; a link to a device) is refused with exit 3 by
/// `merge`, `report` and `--resume` (a directory gave exit 1, a FIFO made them wait forever, and
/// `/dev/zero` was read until memory ran out); so is such an optimum cache file (`--resume`)
/// or `report-files.txt` (`report`).
#[test]
fn repeated_manifest_entries_and_irregular_files_are_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let d = small_sweep(tmp.path(), "d", &["--no-report"]);
    let manifest = std::fs::read_to_string(d.join("manifest.json")).unwrap();
    let mut resume = small_sweep_args("d");
    resume.push("--resume");
    type Edit = fn(&mut serde_json::Value);
    let edits: [(&str, Edit); 6] = [
        ("horizon 2 is listed twice", |m| {
            m["spec"]["horizons"] = serde_json::json!([1, 2, 2])
        }),
        ("algorithm \"greedy\" is listed twice", |m| {
            m["spec"]["algos"] = serde_json::json!(["selective", "greedy", "greedy"])
        }),
        ("mesh \"sphere\" is listed twice", |m| {
            let mesh = m["spec"]["meshes"][0].clone();
            m["spec"]["meshes"].as_array_mut().unwrap().push(mesh);
        }),
        // Blamed on the records before ("run ... is not part of this sweep", "another
        // seed"), or told to --resume, which a sweep of such a spec cannot.
        ("plan version 3 is not one this quadrecomb knows", |m| {
            m["spec"]["plan_version"] = 3.into()
        }),
        ("runs 0 and baseline_runs", |m| m["spec"]["runs"] = 0.into()),
        ("a horizon or node budget of 0", |m| {
            m["spec"]["horizons"] = serde_json::json!([0, 1, 2])
        }),
    ];
    for (why, edit) in edits {
        let mut m: serde_json::Value = serde_json::from_str(&manifest).unwrap();
        edit(&mut m);
        std::fs::write(d.join("manifest.json"), m.to_string()).unwrap();
        for cmd in [&["merge", "d", "--out", "m"][..], &["report", "d"], &resume] {
            let o = run_in(tmp.path(), cmd);
            let e = stderr(&o);
            assert_eq!(o.status.code(), Some(3), "{cmd:?} {why}: {e}");
            assert!(
                e.contains(why) && e.contains("manifest.json"),
                "{cmd:?}: {e}"
            );
        }
    }
    std::fs::write(d.join("manifest.json"), &manifest).unwrap();
    let runs = d.join("runs.jsonl");
    let kept = std::fs::read(&runs).unwrap();
    for (file, why) in [
        ("runs.jsonl", "is a directory, not a regular file"),
        ("manifest.json", "is a directory, not a regular file"),
        (
            "runs.jsonl",
            "is a FIFO, socket or device, not a regular file",
        ),
        (
            "manifest.json",
            "is a FIFO, socket or device, not a regular file",
        ),
    ] {
        let path = d.join(file);
        let kept = std::fs::read(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        if why.contains("directory") {
            std::fs::create_dir(&path).unwrap();
        } else {
            std::os::unix::fs::symlink("/dev/null", &path).unwrap();
        }
        for cmd in [&["merge", "d", "--out", "m"][..], &["report", "d"], &resume] {
            let o = run_in(tmp.path(), cmd);
            let e = stderr(&o);
            if cmd[0] == "report" && file == "runs.jsonl" {
                // report names a missing log its own way ("no runs.jsonl").
                assert_eq!(o.status.code(), Some(3), "{cmd:?} {file}: {e}");
                continue;
            }
            assert_eq!(o.status.code(), Some(3), "{cmd:?} {file}: {e}");
            assert!(
                e.contains(&format!("{file}: corrupt: {why}")),
                "{cmd:?}: {e}"
            );
        }
        if path.is_dir() {
            std::fs::remove_dir(&path).unwrap();
        } else {
            std::fs::remove_file(&path).unwrap();
        }
        std::fs::write(&path, kept).unwrap();
    }
    assert_eq!(std::fs::read(&runs).unwrap(), kept);
    assert!(!tmp.path().join("m/runs.jsonl").exists());
    // The optimum cache (read by --resume) and the report's file list (read by report)
    // likewise: a FIFO there made them wait forever.
    let cache = std::fs::read_dir(d.join("optimum-cache"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|x| x == "json"))
        .expect("an optimum cache file");
    for (path, cmd) in [
        (cache, &resume[..]),
        (
            d.join("report-files.txt"),
            &["report", "d", "--no-pictures"][..],
        ),
    ] {
        let kept = std::fs::read(&path).ok();
        let _ = std::fs::remove_file(&path);
        std::os::unix::fs::symlink("/dev/null", &path).unwrap();
        let o = run_in(tmp.path(), cmd);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(3), "{cmd:?}: {e}");
        assert!(
            e.contains("is a FIFO, socket or device, not a regular file"),
            "{cmd:?}: {e}"
        );
        std::fs::remove_file(&path).unwrap();
        if let Some(kept) = kept {
            std::fs::write(&path, kept).unwrap();
        }
    }
}

#[test]
fn records_that_contradict_their_manifest_or_themselves_are_refused_naming_the_field() {
    // Hand-edited records were believed: another backend and version than the manifest's
    // (a report then said it was made by two versions), a mean eta that is not the quality
    // per quad; a negative count named no field.
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let out = run_in(dir, &small_sweep_args("s"));
    assert!(out.status.success(), "{}", stderr(&out));
    let runs = std::fs::read_to_string(dir.join("s/runs.jsonl")).unwrap();
    let edit = |field: &str, value: serde_json::Value, name: &str| {
        let sub = dir.join(name);
        std::fs::create_dir(&sub).unwrap();
        std::fs::copy(dir.join("s/manifest.json"), sub.join("manifest.json")).unwrap();
        let mut lines: Vec<String> = runs.lines().map(String::from).collect();
        let mut r: serde_json::Value = serde_json::from_str(&lines[1]).unwrap();
        r[field] = value;
        lines[1] = r.to_string();
        std::fs::write(sub.join("runs.jsonl"), lines.join("\n") + "\n").unwrap();
        run_in(dir, &["report", name, "--no-pictures"])
    };
    for (field, value, says) in [
        (
            "backend",
            serde_json::json!("vulkan: fake"),
            "with eta from vulkan: fake, this sweep's manifest says",
        ),
        (
            "version",
            serde_json::json!("9.9.9"),
            "was made by quadrecomb 9.9.9",
        ),
        (
            "mean_eta",
            serde_json::json!(0.01),
            "mean_eta 0.01 is not its quality",
        ),
        (
            "nodes_expanded",
            serde_json::json!(-5),
            "line 2: field nodes_expanded: invalid value",
        ),
    ] {
        let out = edit(field, value, field);
        assert_eq!(out.status.code(), Some(3), "{field}: {}", stderr(&out));
        assert!(stderr(&out).contains(says), "{field}: {}", stderr(&out));
    }
}

#[test]
fn results_paths_that_cannot_work_are_refused_before_any_run() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    // A dangling link and a loop as --out: refused at once (they failed after the runs'
    // preparation with the system's message).
    std::os::unix::fs::symlink(dir.join("nowhere/x"), dir.join("dangling")).unwrap();
    std::os::unix::fs::symlink("loop", dir.join("loop")).unwrap();
    for out_dir in ["dangling", "loop/sub"] {
        let mut args = small_sweep_args(out_dir);
        args.retain(|a| *a != "-q");
        let out = run_in(dir, &args);
        assert_eq!(out.status.code(), Some(4), "{out_dir}: {}", stderr(&out));
        assert!(
            stderr(&out).contains("symbolic link that leads nowhere"),
            "{}",
            stderr(&out)
        );
    }
    // A file the sweep writes that is a link where no file can be made (its directory
    // missing, a loop): refused before the runs (the write goes through the link, so it
    // failed after every run). A dangling link into a directory that exists is written
    // through: the file it names is created.
    for (name, to) in [
        ("summary.csv", "../elsewhere/summary.csv"),
        ("report.md", "report.md"),
    ] {
        let d = dir.join(format!("l-{name}"));
        std::fs::create_dir(&d).unwrap();
        std::os::unix::fs::symlink(to, d.join(name)).unwrap();
        let out = run_in(dir, &small_sweep_args(&format!("l-{name}")));
        assert_eq!(out.status.code(), Some(4), "{name}: {}", stderr(&out));
        assert!(
            stderr(&out).contains(&format!("{name} is a symbolic link to ")),
            "{}",
            stderr(&out)
        );
        assert!(!d.join("runs.jsonl").exists());
    }
    std::fs::create_dir_all(dir.join("ok/kept")).unwrap();
    std::os::unix::fs::symlink("kept/summary.csv", dir.join("ok/summary.csv")).unwrap();
    let out = run_in(dir, &small_sweep_args("ok"));
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        std::fs::symlink_metadata(dir.join("ok/summary.csv"))
            .unwrap()
            .is_symlink()
    );
    assert!(
        std::fs::read_to_string(dir.join("ok/kept/summary.csv"))
            .unwrap()
            .starts_with("mesh,")
    );
    // A file named `figures` where the report writes its figures: refused before the runs
    // (the sweep ran every run, then failed writing the report).
    std::fs::create_dir(dir.join("f")).unwrap();
    std::fs::write(dir.join("f/figures"), "mine").unwrap();
    let out = run_in(dir, &small_sweep_args("f"));
    assert_eq!(out.status.code(), Some(4), "{}", stderr(&out));
    assert!(!dir.join("f/runs.jsonl").exists());
    let out = run_in(dir, &small_sweep_args("s"));
    assert!(out.status.success(), "{}", stderr(&out));
    // `report` with a file it writes linked into a missing directory: exit 3 naming the
    // link, before anything is written (it failed after the pictures' runs).
    std::fs::remove_file(dir.join("s/report.html")).unwrap();
    std::fs::remove_file(dir.join("s/report.md")).unwrap();
    std::os::unix::fs::symlink("../gone/report.html", dir.join("s/report.html")).unwrap();
    let out = run_in(dir, &["report", "s"]);
    assert_eq!(out.status.code(), Some(3), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("report.html is a symbolic link to s/../gone/report.html"),
        "{}",
        stderr(&out)
    );
    assert!(!dir.join("s/report.md").exists());
    std::fs::remove_file(dir.join("s/report.html")).unwrap();
    // `report` on a results directory with a file `figures`: exit 3 naming it, nothing
    // written.
    std::fs::remove_dir_all(dir.join("s/figures")).ok();
    std::fs::write(dir.join("s/figures"), "mine").unwrap();
    let out = run_in(dir, &["report", "s"]);
    assert_eq!(out.status.code(), Some(3), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("figures is a regular file"),
        "{}",
        stderr(&out)
    );
    assert_eq!(
        std::fs::read_to_string(dir.join("s/figures")).unwrap(),
        "mine"
    );
    // runs.jsonl as a directory: named as such by report and replay.
    std::fs::remove_file(dir.join("s/runs.jsonl")).unwrap();
    std::fs::create_dir(dir.join("s/runs.jsonl")).unwrap();
    for cmd in [vec!["report", "s"], vec!["replay", "s"]] {
        let out = run_in(dir, &cmd);
        assert_eq!(out.status.code(), Some(3), "{cmd:?}: {}", stderr(&out));
        assert!(
            stderr(&out).contains("is a directory, not a regular file"),
            "{}",
            stderr(&out)
        );
    }
}

/// A directory's writers take turns: while another process holds `DIR/.lock` (a sweep
/// writing there), `report DIR` and `merge ... --out DIR` are refused at once (exit 4) and
/// change nothing; once it is released both go ahead.
#[test]
fn report_and_merge_wait_their_turn() {
    use quadrecomb::internals::experiment::lock::DirLock;
    let tmp = tempfile::tempdir().unwrap();
    let dir = small_sweep(tmp.path(), "d", &["--shard", "1/2"]);
    small_sweep(tmp.path(), "e", &["--shard", "2/2"]);
    std::fs::create_dir(tmp.path().join("m")).unwrap();
    for (held, args) in [
        ("d", &["report", "d", "--no-pictures"][..]),
        ("m", &["merge", "d", "e", "--out", "m"][..]),
    ] {
        let lock = DirLock::acquire(&tmp.path().join(held)).unwrap();
        let before = snapshot(&dir);
        let o = run_in(tmp.path(), args);
        assert_eq!(o.status.code(), Some(4), "{args:?}: {}", stderr(&o));
        assert!(
            stderr(&o).contains("another sweep, merge or report"),
            "{}",
            stderr(&o)
        );
        // Refused before anything was written.
        assert!(snapshot(&dir) == before, "{args:?} changed d");
        let in_m = std::fs::read_dir(tmp.path().join("m")).unwrap();
        assert!(in_m.map(|e| e.unwrap().file_name()).all(|n| n == ".lock"));
        drop(lock);
        let o = run_in(tmp.path(), args);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    }
    assert!(dir.join("report.md").is_file());
    assert!(tmp.path().join("m/runs.jsonl").is_file());
}

/// A merge that runs out of space writes its runs whole or not at all: none are left to be
/// taken for an interrupted sweep, and the same merge done again with room succeeds.
#[cfg(unix)]
#[test]
fn a_merge_that_cannot_write_its_runs_leaves_none() {
    let tmp = tempfile::tempdir().unwrap();
    for (name, shard) in [("d", "1/2"), ("e", "2/2")] {
        let mut args = small_sweep_args(name);
        args.extend(["--shard", shard, "--no-report"]);
        let runs = args.iter().position(|&a| a == "--runs").unwrap();
        args[runs + 1] = "20";
        let o = run_in(tmp.path(), &args);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let runs = std::fs::metadata(tmp.path().join("d/runs.jsonl"))
        .unwrap()
        .len()
        + std::fs::metadata(tmp.path().join("e/runs.jsonl"))
            .unwrap()
            .len();
    // Room for the manifest (a few KiB), not for the runs.
    let kib = 8;
    assert!(
        runs > kib * 1024,
        "the runs ({runs} B) must not fit in {kib} KiB"
    );
    let o = run_limited(
        tmp.path(),
        &format!("trap '' XFSZ; ulimit -f {kib}"),
        &["merge", "d", "e", "--out", "m", "--no-report"],
        120,
    );
    assert!(!o.status.success(), "the write should have failed");
    assert!(stderr(&o).contains("File too large"), "{}", stderr(&o));
    let m = tmp.path().join("m");
    assert!(
        !m.join("runs.jsonl").exists(),
        "a part of the runs was left"
    );
    let left: Vec<String> = std::fs::read_dir(&m)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".tmp"))
        .collect();
    assert!(left.is_empty(), "temporaries left: {left:?}");
    let o = run_in(
        tmp.path(),
        &["merge", "d", "e", "--out", "m", "--no-report"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        lines_of(&m.join("runs.jsonl")).len(),
        lines_of(&tmp.path().join("d/runs.jsonl")).len()
            + lines_of(&tmp.path().join("e/runs.jsonl")).len()
    );
}

/// A mesh file named `...msh` (stem "..") gets the default `--out` of several meshes,
/// `results/sweep`: `results/..` was the working directory, which the sweep filled.
#[test]
fn a_mesh_named_dots_gets_a_results_directory_of_its_own() {
    let tmp = tempfile::tempdir().unwrap();
    let o = run_in(
        tmp.path(),
        &["generate", "grid", "--triangles", "60", "-o", "...msh"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let o = run_in(
        tmp.path(),
        &[
            "sweep",
            "--mesh",
            "...msh",
            "--algo",
            "greedy",
            "--runs",
            "1",
            "-q",
            "--no-report",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(tmp.path().join("results/sweep/runs.jsonl").is_file());
    assert!(!tmp.path().join("runs.jsonl").exists());
}

/// An empty mesh name and an `optimum-cache` that is a file are named for what they are
/// (before: "loading mesh : : No such file or directory", "optimum-cache: File exists").
#[test]
fn an_empty_mesh_name_and_a_cache_that_is_a_file_are_named() {
    let tmp = tempfile::tempdir().unwrap();
    for args in [&["info", ""][..], &["recombine", "", "--algo", "greedy"]] {
        let o = run_in(tmp.path(), args);
        assert_eq!(o.status.code(), Some(3), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains("an empty mesh name"), "{}", stderr(&o));
    }
    std::fs::create_dir(tmp.path().join("c")).unwrap();
    std::fs::write(tmp.path().join("c/optimum-cache"), "").unwrap();
    let o = run_in(
        tmp.path(),
        &[
            "sweep", "--mesh", "sphere", "--algo", "greedy", "--out", "c", "-q",
        ],
    );
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("optimum-cache: is a regular file, not the directory"),
        "{}",
        stderr(&o)
    );
}
