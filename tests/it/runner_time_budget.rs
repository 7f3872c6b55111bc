//! Sweeps over wall-time budgets (`sweep --time-budgets`): each budget is calibrated once
//! into the knob of every method with one and kept in the manifest; records carry
//! `time_budget_s` beside the knob and replay from their seeds; a killed sweep resumes with
//! the same calibration and makes the same records; committed records without the field read
//! and write unchanged; bad values are refused naming the flag.

use std::process::{Command, Stdio};
use std::time::Duration;

use quadrecomb::internals::experiment::manifest::Manifest;
use quadrecomb::internals::experiment::record::RunRecord;

use crate::runner::{assert_same, records, small_mesh, stderr, sweep, sweep_args, wait_for_lines};
use crate::util::{bin, repo_path, run_in};

#[test]
fn a_time_budget_sweep_calibrates_records_reports_and_replays() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = small_mesh(dir.path(), 400);
    let mut args = sweep_args(&mesh, "t", 3, "2");
    // Progress and notes on stderr: the calibrations are said there.
    args.retain(|a| a != "--no-report" && a != "--quiet");
    let out = sweep(
        dir.path(),
        &args,
        &[
            "--algo",
            "selective",
            "mcts",
            "greedy",
            "--time-budgets",
            "2ms,0.02",
            "--threads",
            "2",
        ],
    );
    assert!(out.status.success(), "sweep: {}", stderr(&out));
    let err = stderr(&out);
    assert_eq!(err.matches("sweep: calibrated ").count(), 4, "{err}");
    let m = Manifest::read(&dir.path().join("t")).unwrap();
    let secs: Vec<f64> = m.spec.time_budgets.iter().map(|t| t.seconds()).collect();
    assert_eq!(secs, [0.002, 0.02]);
    assert!(m.spec.budgets.is_empty(), "no node budget unless asked for");
    // selective x 2 time budgets, mcts at h=2 x 2.
    assert_eq!(m.spec.calibration.len(), 4);
    for c in &m.spec.calibration {
        assert!(
            !c.probes.is_empty() && c.pilots == 4 && c.threads == 2,
            "{c:?}"
        );
        assert!(c.probes.iter().all(|p| p.times_s.len() == 4));
        assert!(c.probes.iter().any(|p| p.knob == c.knob()));
        assert!(!c.machine.cpu.is_empty());
        assert_eq!(c.budget.is_some(), c.algo == "mcts");
        if c.algo == "mcts" {
            assert_eq!(c.horizon, 2, "a budgeted method keeps its horizon");
        }
    }
    // A larger time budget never gets a smaller knob.
    for algo in ["selective", "mcts"] {
        let knob = |t: f64| {
            (m.spec.calibration.iter())
                .find(|c| c.algo == algo && c.time_budget_s.seconds() == t)
                .unwrap()
                .knob()
        };
        assert!(
            knob(0.02) >= knob(0.002),
            "{algo}: {:?}",
            m.spec.calibration
        );
    }
    let recs = records(&dir.path().join("t"));
    // selective h=2: 3 runs; selective and mcts at each time budget: 3 runs; greedy 2.
    assert_eq!(recs.len(), 3 + 2 * 2 * 3 + 2);
    for r in &recs {
        match r.time_budget_s {
            Some(t) => {
                let c = (m.spec.calibration.iter())
                    .find(|c| c.algo == r.algo && c.time_budget_s == t)
                    .unwrap();
                assert_eq!(
                    (r.horizon, r.budget),
                    (Some(c.horizon), c.budget),
                    "{}",
                    r.key()
                );
            }
            None => assert!(r.algo != "mcts", "{}", r.key()),
        }
    }
    let seeds: std::collections::BTreeSet<u64> = recs.iter().map(|r| r.seed).collect();
    assert_eq!(seeds.len(), recs.len(), "one seed per run");
    let text = std::fs::read_to_string(dir.path().join("t/runs.jsonl")).unwrap();
    assert!(text.contains("\"time_budget_s\":0.02,"));
    assert!(
        (text.lines())
            .filter(|l| l.contains("\"algo\":\"greedy\""))
            .all(|l| !l.contains("time_budget")),
        "records without a time budget hold no field"
    );
    let csv = std::fs::read_to_string(dir.path().join("t/summary.csv")).unwrap();
    assert!(
        csv.starts_with("mesh,algo,horizon,budget,time_budget_s,metric,"),
        "{}",
        &csv[..80]
    );
    let report = std::fs::read_to_string(dir.path().join("t/report.md")).unwrap();
    assert!(report.contains("By time budget"), "{report}");
    assert!(report.contains("time-budget.svg"));
    assert!(report.contains("Policies against selective at the same time budget"));
    // An extension with one more time budget keeps the calibrations and makes only the new
    // ones (selective and mcts h=2 at 10 ms); the recorded runs stay.
    let before = std::fs::read(dir.path().join("t/runs.jsonl")).unwrap();
    let mut wider: Vec<&str> = args.iter().map(String::as_str).collect();
    wider.extend([
        "--algo",
        "selective",
        "mcts",
        "greedy",
        "--time-budgets",
        "2ms,0.02,10ms",
        "--threads",
        "2",
        "--extend",
        "--no-report",
    ]);
    let ext = run_in(dir.path(), &wider);
    assert!(ext.status.success(), "extend: {}", stderr(&ext));
    assert_eq!(
        stderr(&ext).matches("sweep: calibrated ").count(),
        2,
        "{}",
        stderr(&ext)
    );
    let m2 = Manifest::read(&dir.path().join("t")).unwrap();
    assert_eq!(
        m2.spec.calibration[..4],
        m.spec.calibration[..],
        "kept as they were"
    );
    assert_eq!(m2.spec.calibration.len(), 6);
    let after = std::fs::read(dir.path().join("t/runs.jsonl")).unwrap();
    assert!(after.starts_with(&before));
    assert_eq!(records(&dir.path().join("t")).len(), recs.len() + 2 * 3);
    // Every time-budgeted record replays from its seed.
    for r in recs.iter().filter(|r| r.time_budget_s.is_some()) {
        let mut a = vec![
            "replay".to_string(),
            "t".into(),
            r.run.to_string(),
            "--algo".into(),
            r.algo.clone(),
            "--horizon".into(),
            r.horizon.unwrap().to_string(),
            "--time-budget".into(),
            r.time_budget_s.unwrap().seconds().to_string(),
            "--json".into(),
        ];
        if let Some(b) = r.budget {
            a.extend(["--budget".into(), b.to_string()]);
        }
        let a: Vec<&str> = a.iter().map(String::as_str).collect();
        let replay = run_in(dir.path(), &a);
        assert!(replay.status.success(), "replay: {}", stderr(&replay));
        let v: serde_json::Value = serde_json::from_slice(&replay.stdout).unwrap();
        assert_eq!(v["reproduced"], true, "{}: {v}", r.key());
        assert_eq!(v["seed"], r.seed, "{v}");
    }
}

#[test]
fn a_killed_time_budget_sweep_resumes_with_its_calibration_and_the_same_records() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let mesh = small_mesh(dir, 1000);
    let mut args = sweep_args(&mesh, "killed", 60, "3");
    // Not quiet: a calibration would be said on stderr.
    args.retain(|a| a != "--quiet");
    args.extend(
        [
            "--algo",
            "selective",
            "beam",
            "--time-budgets",
            "3ms,10ms",
            "--threads",
            "2",
        ]
        .map(String::from),
    );
    let total = 60 + 2 * 2 * 60;
    let mut child = Command::new(bin())
        .args(&args)
        .current_dir(dir)
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let runs = dir.join("killed/runs.jsonl");
    let seen = wait_for_lines(&runs, 10, Duration::from_secs(120));
    child.kill().unwrap(); // SIGKILL
    child.wait().unwrap();
    assert!(seen >= 10, "only {seen} runs recorded before the kill");
    let recorded = quadrecomb::internals::experiment::store::read(&runs).unwrap();
    assert!(
        recorded.records.len() < total,
        "the sweep finished before it was killed: make it longer"
    );
    let manifest = std::fs::read_to_string(dir.join("killed/manifest.json")).unwrap();
    assert!(manifest.contains("\"calibration\""));

    let resumed = sweep(dir, &args, &["--resume"]);
    assert!(resumed.status.success(), "{}", stderr(&resumed));
    assert!(
        !stderr(&resumed).contains("calibrated"),
        "a resumed sweep calibrated again: {}",
        stderr(&resumed)
    );
    let after = std::fs::read_to_string(dir.join("killed/manifest.json")).unwrap();
    // The same manifest but for the resume's session, which it adds.
    let parse = |text: &str| -> (serde_json::Value, usize) {
        let mut v: serde_json::Value = serde_json::from_str(text).unwrap();
        let sessions = v.as_object_mut().unwrap().remove("sessions").unwrap();
        (v, sessions.as_array().unwrap().len())
    };
    let ((before, n_before), (after, n_after)) = (parse(&manifest), parse(&after));
    assert_eq!(before, after, "the resume changed the calibration");
    assert_eq!((n_before, n_after), (1, 2));
    let got = records(&dir.join("killed"));
    assert_eq!(got.len(), total);

    // The same calibration run whole, uninterrupted: the same records.
    std::fs::create_dir(dir.join("whole")).unwrap();
    std::fs::write(dir.join("whole/manifest.json"), &manifest).unwrap();
    let mut whole = args.clone();
    let at = whole.iter().position(|a| a == "killed").unwrap();
    whole[at] = "whole".into();
    let out = sweep(dir, &whole, &["--resume"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!stderr(&out).contains("calibrated"));
    assert_same(
        &records(&dir.join("whole")),
        &got,
        "killed + resumed vs whole",
    );
}

#[test]
fn merge_refuses_parts_that_calibrated_a_time_budget_differently() {
    // Two sweeps of one configuration whose calibrations chose different horizons (two
    // machines, or one under load) made different runs under one time budget: merge kept
    // the first part's calibration and dropped the other's runs without a word.
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let mesh = small_mesh(dir, 400);
    let args = |out: &str| {
        let mut a = sweep_args(&mesh, out, 3, "1");
        a.extend(["--algo", "selective", "greedy", "--time-budgets", "5ms"].map(String::from));
        a
    };
    let out = sweep(dir, &args("a"), &[]);
    assert!(out.status.success(), "{}", stderr(&out));
    // The other part: the same sweep under another calibration of selective's horizon.
    let mut m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("a/manifest.json")).unwrap())
            .unwrap();
    let mut other = 0;
    for c in m["spec"]["calibration"].as_array_mut().unwrap() {
        if c["algo"] == "selective" {
            let h = c["horizon"].as_u64().unwrap();
            other = if h > 1 { h - 1 } else { h + 1 };
            c["horizon"] = other.into();
        }
    }
    assert!(other > 0, "selective was calibrated");
    std::fs::create_dir(dir.join("b")).unwrap();
    std::fs::write(dir.join("b/manifest.json"), m.to_string()).unwrap();
    let out = sweep(dir, &args("b"), &["--resume"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(records(&dir.join("b")).len(), records(&dir.join("a")).len());

    let out = run_in(dir, &["merge", "a", "b", "--out", "merged"]);
    assert_eq!(out.status.code(), Some(3), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(
        err.contains("a and b are not parts of the same sweep")
            && err.contains("calibrated the time budget 0.005 s of selective")
            && err.contains(&format!("horizon {other})")),
        "{err}"
    );
    assert!(!dir.join("merged").exists(), "nothing written");
    // Parts of one calibration still merge.
    let out = run_in(dir, &["merge", "a", "--out", "alone"]);
    assert!(out.status.success(), "{}", stderr(&out));
}

#[test]
fn a_signal_while_calibrating_exits_130_with_the_cancelled_json() {
    // Stopped before its runs (the pilots of a 3 s budget take seconds), as between runs:
    // exit 130 and the `cancelled` JSON (it exited 1 with nothing on stdout).
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    // A built-in mesh whose pilots at a 3 s budget take seconds (a small grid's saturate
    // at once).
    let mut args = sweep_args(std::path::Path::new("borouchaki"), "cal", 3, "1");
    args.extend(["--algo", "selective", "--time-budgets", "3", "--json"].map(String::from));
    let child = Command::new(bin())
        .args(&args)
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(1500));
    let kill = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(130), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("interrupted while calibrating the time budgets: no run was made"),
        "{}",
        stderr(&out)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["cancelled"], true, "{v}");
    assert_eq!(v["new"], 0, "{v}");
    assert!(!dir.join("cal/runs.jsonl").exists(), "no run was made");
}

#[test]
fn committed_budget_records_and_manifest_serialise_unchanged() {
    let dir = repo_path("results/budget");
    let text = std::fs::read_to_string(dir.join("runs.jsonl")).unwrap();
    for (i, line) in text.lines().enumerate() {
        let r: RunRecord = serde_json::from_str(line).unwrap();
        assert!(r.time_budget_s.is_none());
        assert_eq!(r.to_json_line(), line, "line {}", i + 1);
    }
    let text = std::fs::read_to_string(dir.join("manifest.json")).unwrap();
    let m: Manifest = serde_json::from_str(&text).unwrap();
    assert!(m.spec.time_budgets.is_empty() && m.spec.calibration.is_empty());
    assert_eq!(
        format!("{}\n", serde_json::to_string_pretty(&m).unwrap()),
        text
    );
}

#[test]
fn bad_time_budgets_are_refused_naming_the_flag() {
    let dir = tempfile::tempdir().unwrap();
    for bad in ["0", "-1", "NaN", "inf", "1e9", "0.0001", "abc", "5min"] {
        let out = run_in(
            dir.path(),
            &[
                "sweep",
                "--mesh",
                "sphere",
                "--algo",
                "selective",
                "--time-budgets",
                bad,
                "--out",
                "x",
            ],
        );
        assert_eq!(out.status.code(), Some(2), "{bad}: {}", stderr(&out));
        let err = stderr(&out);
        assert!(
            err.contains("--time-budgets") && err.contains(bad),
            "{bad}: {err}"
        );
        let out = run_in(
            dir.path(),
            &[
                "recombine",
                "sphere",
                "--algo",
                "mcts",
                "--time-budget",
                bad,
            ],
        );
        assert_eq!(out.status.code(), Some(2), "{bad}: {}", stderr(&out));
        assert!(stderr(&out).contains("--time-budget"), "{bad}");
    }
    for (extra, want) in [
        (
            &["--algo", "selective", "--time-budgets", "1,1"][..],
            "given twice",
        ),
        (
            &["--algo", "greedy", "--time-budgets", "1"][..],
            "none of the methods",
        ),
        (
            &[
                "--algo",
                "selective",
                "--time-budgets",
                "1",
                "--shard",
                "1/2",
            ][..],
            "--shard",
        ),
    ] {
        let mut a = vec!["sweep", "--mesh", "sphere", "--out", "x"];
        a.extend_from_slice(extra);
        let out = run_in(dir.path(), &a);
        assert_eq!(out.status.code(), Some(2), "{extra:?}: {}", stderr(&out));
        let err = stderr(&out);
        assert!(
            err.contains("--time-budgets") && err.contains(want),
            "{err}"
        );
    }
    assert!(!dir.path().join("x").exists(), "nothing was written");
    let out = run_in(
        dir.path(),
        &[
            "recombine",
            "sphere",
            "--algo",
            "greedy",
            "--time-budget",
            "1",
        ],
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("no horizon or node budget"));
}

#[test]
fn recombine_calibrates_its_knob_and_says_how_to_repeat_the_run() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = small_mesh(dir.path(), 400);
    let m = mesh.to_str().unwrap();
    let out = run_in(
        dir.path(),
        &[
            "recombine",
            m,
            "--algo",
            "beam",
            "--horizon",
            "3",
            "--time-budget",
            "5ms",
            "--backend",
            "cpu",
            "--no-optimum",
            "--json",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(err.contains("calibrated to --budget"), "{err}");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let b = v["budget"].as_u64().unwrap();
    assert!(err.contains(&format!("give --budget {b} instead")), "{err}");
    // The run is the one its knob makes.
    let again = run_in(
        dir.path(),
        &[
            "recombine",
            m,
            "--algo",
            "beam",
            "--horizon",
            "3",
            "--budget",
            &b.to_string(),
            "--backend",
            "cpu",
            "--no-optimum",
            "--json",
        ],
    );
    let w: serde_json::Value = serde_json::from_slice(&again.stdout).unwrap();
    assert_eq!(
        (v["quads"].clone(), v["quality"].clone()),
        (w["quads"].clone(), w["quality"].clone())
    );
}

#[test]
fn the_report_shows_what_the_finish_added_to_time_budgeted_runs() {
    // `sweep --time-budgets --finish`: the finished runs of the calibrated configurations
    // were in summary.csv but nowhere in the report (Table 1 and its finish rows leave the
    // budgeted configurations to their own section, which shows no finish).
    let dir = tempfile::tempdir().unwrap();
    let mesh = small_mesh(dir.path(), 400);
    let mut args = sweep_args(&mesh, "t", 2, "1");
    args.retain(|a| a != "--no-report");
    let out = sweep(
        dir.path(),
        &args,
        &[
            "--algo",
            "selective",
            "--time-budgets",
            "0.02",
            "--finish",
            "--threads",
            "1",
        ],
    );
    assert!(out.status.success(), "sweep: {}", stderr(&out));
    let report = std::fs::read_to_string(dir.path().join("t/report.md")).unwrap();
    let added = report
        .split("### What the finish added")
        .nth(1)
        .unwrap_or_else(|| panic!("no finish table in\n{report}"));
    let rows: Vec<&str> = (added.lines())
        .filter(|l| l.starts_with("| selective"))
        .collect();
    assert!(
        rows.iter()
            .any(|l| l.starts_with("| selective (T=0.02s) |")),
        "{added}"
    );
    assert!(
        rows.iter().any(|l| l.starts_with("| selective |")),
        "{added}"
    );
}
