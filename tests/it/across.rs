//! The report's "Across meshes" section (issue 24 item 3) on synthetic multi-mesh results:
//! the per-mesh medians, win/tie/loss against the baseline, Friedman's test (checked against
//! scipy reading our `across_meshes.csv`), the critical-difference diagram (parsed and rendered
//! by resvg), `--baseline`, and what is said when there are too few meshes for a test.

use crate::report::{parse_and_render, record};
use crate::util::{SEED, python, python_module_available, run_in};
use quadrecomb::internals::report::{self, ReportOptions};
use quadrecomb::internals::stats::describe::median;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::Path;

/// Six meshes; on five, quality rises with the selective horizon (h=5 > h=3 > h=1, by far
/// more than the noise); on "flat" every horizon draws from the same distribution. Greedy is
/// one run, 3 points below selective h=1's centre. Returns the qualities written, per (mesh,
/// label).
fn six_meshes(dir: &Path, runs: u32) -> Vec<(String, String, Vec<f64>)> {
    const MESHES: [&str; 6] = ["alpha", "beta", "gamma", "delta", "eps", "flat"];
    let mut rng = ChaCha8Rng::seed_from_u64(SEED);
    let (mut lines, mut written) = (Vec::new(), Vec::new());
    for (i, mesh) in MESHES.iter().enumerate() {
        let centre = 85.0 + 2.0 * i as f64;
        let q = centre - 3.0;
        lines.push(record(mesh, "greedy", None, 0, q, 90.0, 0.02));
        written.push((mesh.to_string(), "greedy".to_string(), vec![q]));
        for h in [1u32, 3, 5] {
            let step = if *mesh == "flat" { 0.0 } else { 0.8 };
            let mut qs = Vec::new();
            for run in 0..runs {
                let q = centre + step * f64::from(h) + rng.random_range(-0.3..0.3);
                qs.push(q);
                lines.push(record(mesh, "selective", Some(h), run, q, 95.0, 0.05));
            }
            written.push((mesh.to_string(), format!("selective h={h}"), qs));
        }
    }
    std::fs::write(dir.join("runs.jsonl"), lines.join("\n") + "\n").unwrap();
    written
}

fn opts() -> ReportOptions {
    ReportOptions {
        pictures: false,
        ..ReportOptions::default()
    }
}

#[test]
fn across_meshes_section_tables_tests_and_diagram() {
    let tmp = tempfile::tempdir().unwrap();
    let written = six_meshes(tmp.path(), 8);
    let paths = report::write(tmp.path(), &opts()).unwrap();
    let md = std::fs::read_to_string(&paths.markdown).unwrap();
    let section = &md[md.find("## Across meshes").expect("no section")..];
    assert!(
        section.contains("6 meshes (alpha, beta, gamma, delta, eps, flat), 4 methods, 150 runs"),
        "{section}"
    );
    // The medians: each cell is the median of the runs written for it.
    let row = section.lines().find(|l| l.starts_with("| beta |")).unwrap();
    let cells: Vec<&str> = row.split(" | ").collect();
    for (j, label) in ["greedy", "selective h=1", "selective h=3", "selective h=5"]
        .iter()
        .enumerate()
    {
        let qs = &written
            .iter()
            .find(|(m, l, _)| m == "beta" && l == label)
            .unwrap()
            .2;
        assert_eq!(
            cells[2 + j].trim_end_matches(" |"),
            format!("{:.2}", median(qs))
        );
    }
    assert!(
        section.contains("| runs per mesh |  | 1 | 8 | 8 | 8 |"),
        "{section}"
    );
    // h=5 wins on the five meshes where it is better, ties on "flat"; greedy loses everywhere
    // (tested as 8 runs against its single value).
    assert!(
        section.contains("| selective h=5 | 5 | 1 | 0 | 6 | 48 / 48 | flat (tie: "),
        "{section}"
    );
    assert!(
        section.contains("| greedy | 0 | 0 | 6 | 6 | 6 / 48 |"),
        "{section}"
    );
    let answer = (section.lines())
        .find(|l| l.starts_with("Does selective h=5"))
        .unwrap_or_else(|| panic!("no answer in {section}"));
    assert!(
        answer.contains("beat selective h=1 on every mesh? No:"),
        "{answer}"
    );
    assert!(answer.contains("5 of the 6 meshes"), "{answer}");
    assert!(answer.contains("not on flat (tie"), "{answer}");
    let friedman = (section.lines())
        .find(|l| l.starts_with("Friedman's test of 4 methods over 6 meshes"))
        .unwrap_or_else(|| panic!("no Friedman in {section}"));
    assert!(friedman.contains("of 150 runs in all"), "{friedman}");
    assert!(
        section.contains("critical difference CD = 1.915"),
        "{section}"
    );
    // 6 meshes: the signed-rank test can reach 0.05 (2/64), so p-values, not "too few".
    assert!(!section.contains("too few meshes"), "{section}");

    // The CSV, read by Python's csv module; Friedman's statistic recomputed by scipy from it.
    let csv = paths.across_csv.clone().expect("across_meshes.csv written");
    let check = python(
        "import csv, sys\n\
         rows = list(csv.DictReader(open(sys.argv[1])))\n\
         assert len(rows) == 24, len(rows)\n\
         by_mesh = {}\n\
         for r in rows: by_mesh.setdefault(r['mesh'], []).append(float(r['rank']))\n\
         assert all(sum(v) == 10 for v in by_mesh.values()), by_mesh\n\
         print(rows[3]['method'], rows[3]['runs'], rows[3]['median_quality_pct'])",
        &[&csv],
    );
    let h5_alpha = &written
        .iter()
        .find(|(m, l, _)| m == "alpha" && l == "selective h=5")
        .unwrap()
        .2;
    assert_eq!(
        check.trim(),
        format!("selective h=5 8 {}", median(h5_alpha))
    );
    if python_module_available("scipy") {
        let chi2 = python(
            "import csv, sys\n\
             from scipy.stats import friedmanchisquare\n\
             rows = list(csv.DictReader(open(sys.argv[1])))\n\
             methods = sorted({r['method'] for r in rows})\n\
             cols = [[float(r['median_quality_pct']) for r in rows if r['method'] == m] for m in methods]\n\
             print('%.3f' % friedmanchisquare(*cols).statistic)",
            &[&csv],
        );
        assert!(
            friedman.contains(&format!("chi-square = {} ", chi2.trim())),
            "scipy {chi2} vs {friedman}"
        );
    }

    // The diagram parses and renders, one group per method, the CD bar and the axis.
    let svg = std::fs::read_to_string(tmp.path().join("figures/across-meshes-cd.svg")).unwrap();
    let ids = parse_and_render(&svg);
    for id in ["cd-axis", "cd-bar", "cd-method-0", "cd-method-3"] {
        assert!(ids.iter().any(|i| i == id), "{id} not in {ids:?}");
    }
    assert!(!ids.iter().any(|i| i == "cd-method-4"), "{ids:?}");
    assert!(svg.contains("selective h=5 (1."), "{svg}");
    let list = std::fs::read_to_string(tmp.path().join("report-files.txt")).unwrap();
    assert!(list.contains("figures/across-meshes-cd.svg"), "{list}");

    // Another baseline.
    let with_greedy = ReportOptions {
        baseline: Some("greedy".into()),
        ..opts()
    };
    let md =
        std::fs::read_to_string(report::write(tmp.path(), &with_greedy).unwrap().markdown).unwrap();
    assert!(md.contains("### Against greedy"), "{md}");
    assert!(
        md.contains("| selective h=5 | 6 | 0 | 0 | 6 | 48 / 6 | – |"),
        "{md}"
    );
    assert!(
        md.contains("Does selective h=5 (the best average rank"),
        "{md}"
    );
    assert!(md.contains("beat greedy on every mesh? Yes:"), "{md}");

    // Down to one mesh: no section, and the CSV of the earlier report goes.
    let one: Vec<String> = std::fs::read_to_string(tmp.path().join("runs.jsonl"))
        .unwrap()
        .lines()
        .filter(|l| l.contains("\"mesh\":\"alpha\""))
        .map(String::from)
        .collect();
    assert!(!one.is_empty());
    std::fs::write(tmp.path().join("runs.jsonl"), one.join("\n") + "\n").unwrap();
    let paths = report::write(tmp.path(), &opts()).unwrap();
    let md = std::fs::read_to_string(&paths.markdown).unwrap();
    assert!(!md.contains("Across meshes"), "{md}");
    assert!(paths.across_csv.is_none());
    assert!(!csv.exists(), "stale {}", csv.display());
    assert!(!tmp.path().join("figures/across-meshes-cd.svg").exists());
}

#[test]
fn too_few_meshes_for_a_test_say_so() {
    // Two meshes, two methods: even full agreement gives an exact Friedman p of 1/2, and the
    // signed-rank test of 2 differences at best 1/2.
    let tmp = tempfile::tempdir().unwrap();
    let mut lines = Vec::new();
    for (i, mesh) in ["a", "b"].iter().enumerate() {
        lines.push(record(mesh, "greedy", None, 0, 80.0 + i as f64, 90.0, 0.02));
        for run in 0..5 {
            let q = 90.0 + i as f64 + f64::from(run) * 0.1;
            lines.push(record(mesh, "selective", Some(1), run, q, 95.0, 0.05));
        }
    }
    std::fs::write(tmp.path().join("runs.jsonl"), lines.join("\n") + "\n").unwrap();
    let md = std::fs::read_to_string(report::write(tmp.path(), &opts()).unwrap().markdown).unwrap();
    let section = &md[md.find("## Across meshes").expect("no section")..];
    let friedman = (section.lines())
        .find(|l| l.starts_with("Friedman's test"))
        .unwrap();
    assert!(
        friedman.contains("too few meshes for the test"),
        "{friedman}"
    );
    assert!(!friedman.contains("p = "), "{friedman}");
    assert!(
        section.contains("| greedy vs selective h=1 | 0 / 2 / 0 | T+ = 0 | too few meshes (2 that differ) | – | cannot be |"),
        "{section}"
    );
    // The answer still counts the per-mesh tests: 5 runs against a single greedy value.
    assert!(section.contains("Does greedy"), "{section}");
}

#[test]
fn a_significant_difference_between_equal_medians_is_a_loss_or_a_decrease() {
    // As on the committed budget-transfer grid: greedy's one run reaches 100, 32 of selective's
    // 128 runs fall below it, none above; the medians are equal (100), the signed-rank test
    // significant, A = 0.375. It was called a tie and a "small increase" (by the medians).
    let tmp = tempfile::tempdir().unwrap();
    let mut lines = Vec::new();
    for (i, mesh) in ["a", "b"].iter().enumerate() {
        lines.push(record(mesh, "greedy", None, 0, 100.0, 100.0, 0.02));
        for run in 0..128 {
            let q = if run % 4 == 0 {
                99.0 - 0.01 * f64::from(run) - i as f64
            } else {
                100.0
            };
            lines.push(record(mesh, "selective", Some(5), run, q, 100.0, 0.05));
        }
    }
    std::fs::write(tmp.path().join("runs.jsonl"), lines.join("\n") + "\n").unwrap();
    let md = std::fs::read_to_string(report::write(tmp.path(), &opts()).unwrap().markdown).unwrap();
    assert!(
        md.contains("selective h=5 vs greedy (small decrease, A = 0.38)"),
        "{md}"
    );
    assert!(!md.contains("increase"), "{md}");
    let section = &md[md.find("## Across meshes").expect("no section")..];
    let row = (section.lines())
        .find(|l| l.starts_with("| selective h=5 |"))
        .unwrap();
    assert!(row.starts_with("| selective h=5 | 0 | 0 | 2 |"), "{row}");
    assert!(
        row.contains("a (loss: 100.00 vs 100.00, A = 0.38, Holm p = "),
        "{row}"
    );
}

#[test]
fn unknown_baseline_is_a_usage_error() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("res");
    std::fs::create_dir(&dir).unwrap();
    six_meshes(&dir, 4);
    let out = run_in(
        tmp.path(),
        &[
            "report",
            "res",
            "--no-pictures",
            "--baseline",
            "selective h=9",
        ],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("--baseline \"selective h=9\": no such method")
            && err.contains("selective h=5"),
        "{err}"
    );
    let out = run_in(
        tmp.path(),
        &[
            "report",
            "res",
            "--no-pictures",
            "--baseline",
            "selective h=3",
            "--json",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(
        v["across_meshes"]
            .as_str()
            .unwrap()
            .ends_with("across_meshes.csv"),
        "{v}"
    );
    let md = std::fs::read_to_string(dir.join("report.md")).unwrap();
    assert!(md.contains("### Against selective h=3"), "{md}");
    assert!(md.contains("(chosen with --baseline)"), "{md}");
}

#[test]
fn the_deepest_horizon_is_asked_about_too_when_it_is_not_the_best() {
    // Three meshes where selective h=3 is best; h=5 beats h=1 on two of them and ties on "c".
    let tmp = tempfile::tempdir().unwrap();
    let mut lines = Vec::new();
    for (mesh, h5) in [("a", 92.0), ("b", 93.0), ("c", 90.0)] {
        for (h, centre) in [(1, 90.0), (3, 95.0), (5, h5)] {
            for run in 0..8 {
                let q = centre + f64::from(run) * 0.01;
                lines.push(record(mesh, "selective", Some(h), run, q, 95.0, 0.05));
            }
        }
    }
    std::fs::write(tmp.path().join("runs.jsonl"), lines.join("\n") + "\n").unwrap();
    let md = std::fs::read_to_string(report::write(tmp.path(), &opts()).unwrap().markdown).unwrap();
    let best = (md.lines())
        .find(|l| l.starts_with("Does selective h=3 (the best average rank"))
        .unwrap_or_else(|| panic!("{md}"));
    assert!(best.contains("selective h=1 on every mesh? Yes:"), "{best}");
    let deepest = (md.lines())
        .find(|l| l.starts_with("Does selective h=5 (the deepest horizon, average rank 2.17)"))
        .unwrap_or_else(|| panic!("{md}"));
    assert!(
        deepest.contains("No: it is significantly higher on 2 of the 3 meshes"),
        "{deepest}"
    );
    assert!(deepest.contains("not on c (tie: "), "{deepest}");
}

#[test]
fn each_node_budget_keeps_its_own_runs_across_meshes() {
    // Two meshes, mcts h=3 at budgets 2 and 32 far apart in quality: the section and
    // across_meshes.csv took the first budget's runs for every budget (the lookup ignored the
    // budget), so b=32 showed b=2's medians and the two tied.
    let tmp = tempfile::tempdir().unwrap();
    let mut lines = Vec::new();
    for (i, mesh) in ["a", "b"].iter().enumerate() {
        for run in 0..5 {
            let base = 90.0 + i as f64 + f64::from(run) * 0.1;
            lines.push(record(mesh, "selective", Some(3), run, base, 95.0, 0.05));
            for (budget, q) in [(2u32, base - 10.0), (32, base + 2.0)] {
                let mut r: serde_json::Value =
                    serde_json::from_str(&record(mesh, "mcts", Some(3), run, q, 95.0, 0.05))
                        .unwrap();
                r["budget"] = budget.into();
                lines.push(r.to_string());
            }
        }
    }
    std::fs::write(tmp.path().join("runs.jsonl"), lines.join("\n") + "\n").unwrap();
    let paths = report::write(tmp.path(), &opts()).unwrap();
    let csv =
        std::fs::read_to_string(paths.across_csv.expect("across_meshes.csv written")).unwrap();
    for (i, mesh) in ["a", "b"].iter().enumerate() {
        for (label, q) in [("mcts h=3 b=2", 80.2), ("mcts h=3 b=32", 92.2)] {
            let line = (csv.lines())
                .find(|l| l.starts_with(&format!("{mesh},")) && l.contains(&format!(",{label},")))
                .unwrap_or_else(|| panic!("no {mesh} {label} in\n{csv}"));
            let median: f64 = line.split(',').nth(6).unwrap().parse().unwrap();
            assert!((median - (q + i as f64)).abs() < 1e-9, "{line}\n{csv}");
        }
    }
}

#[test]
fn a_time_budget_is_one_method_across_meshes() {
    // Two meshes, selective calibrated to T = 0.5 s: the calibration chose h=8 on one and h=2
    // on the other. The section took each (algorithm, horizon) for a method of its own, run
    // on one mesh only, and left both out of the ranks; they are one method, "selective
    // (T=0.5s)", with each mesh's own horizon in across_meshes.csv.
    let tmp = tempfile::tempdir().unwrap();
    let mut lines = Vec::new();
    for (i, (mesh, h)) in [("a", 8u32), ("b", 2)].iter().enumerate() {
        for run in 0..5 {
            let base = 90.0 + i as f64 + f64::from(run) * 0.1;
            lines.push(record(mesh, "selective", Some(1), run, base, 95.0, 0.05));
            let mut r: serde_json::Value = serde_json::from_str(&record(
                mesh,
                "selective",
                Some(*h),
                run,
                base + 3.0,
                95.0,
                0.05,
            ))
            .unwrap();
            r["time_budget_s"] = 0.5.into();
            lines.push(r.to_string());
        }
    }
    std::fs::write(tmp.path().join("runs.jsonl"), lines.join("\n") + "\n").unwrap();
    let paths = report::write(tmp.path(), &opts()).unwrap();
    let csv =
        std::fs::read_to_string(paths.across_csv.expect("across_meshes.csv written")).unwrap();
    for (i, (mesh, h)) in [("a", 8u32), ("b", 2)].iter().enumerate() {
        let line = (csv.lines())
            .find(|l| l.starts_with(&format!("{mesh},")) && l.contains(",selective (T=0.5s),"))
            .unwrap_or_else(|| panic!("no {mesh} time-budget row in\n{csv}"));
        let f: Vec<&str> = line.split(',').collect();
        assert_eq!(f[4], h.to_string(), "{line}");
        let median: f64 = f[6].parse().unwrap();
        assert!((median - (93.2 + i as f64)).abs() < 1e-9, "{line}");
        assert_eq!(f[7], "1", "ranked first on every mesh: {line}\n{csv}");
    }
    let md = std::fs::read_to_string(&paths.markdown).unwrap();
    assert!(!md.contains("Not run on every mesh"), "{md}");
}
