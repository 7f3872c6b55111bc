//! Sweeps over node budgets: the budgeted policies run per (horizon, budget), their records
//! carry `budget`, a budget changes the seeds of its own configurations only, the summary gets
//! its budget column, the report its quality-against-budget section, and `replay` repeats a
//! budgeted run.

use crate::runner::{records, small_mesh, stderr, sweep, sweep_args};
use crate::util::run_in;

#[test]
fn a_budget_sweep_records_reports_and_replays_its_budgets() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = small_mesh(dir.path(), 400);
    let mut args = sweep_args(&mesh, "b", 3, "2");
    args.retain(|a| a != "--no-report");
    let out = sweep(
        dir.path(),
        &args,
        &[
            "--algo",
            "selective",
            "optimistic",
            "mcts",
            "beam",
            "greedy",
            "optimum",
            "--budgets",
            "4,16",
        ],
    );
    assert!(out.status.success(), "sweep: {}", stderr(&out));
    let recs = records(&dir.path().join("b"));
    // selective: 3 runs; each budgeted method: 2 budgets x 3 runs; greedy 2; optimum 1.
    assert_eq!(recs.len(), 3 + 3 * 2 * 3 + 2 + 1);
    for r in &recs {
        let budgeted = matches!(r.algo.as_str(), "optimistic" | "mcts" | "beam");
        assert_eq!(r.budget.is_some(), budgeted, "{}", r.key());
        if budgeted {
            assert!(r.nodes_expanded.is_some() && r.horizon == Some(2));
        }
    }
    let text = std::fs::read_to_string(dir.path().join("b/runs.jsonl")).unwrap();
    assert!(text.contains("\"budget\":16"));
    // Lines without a budget hold no budget field (older records' shape).
    assert!(
        text.lines()
            .filter(|l| l.contains("\"algo\":\"selective\""))
            .all(|l| !l.contains("budget"))
    );
    let seeds: std::collections::BTreeSet<u64> = recs.iter().map(|r| r.seed).collect();
    assert_eq!(seeds.len(), recs.len(), "one seed per run");
    let csv = std::fs::read_to_string(dir.path().join("b/summary.csv")).unwrap();
    assert!(csv.starts_with("mesh,algo,horizon,budget,metric,"));
    let report = std::fs::read_to_string(dir.path().join("b/report.md")).unwrap();
    assert!(report.contains("Quality against budget"), "{report}");
    assert!(report.contains("budget.svg"));
    assert!(report.contains("mcts h=2 b=16"));
    let key = recs.iter().find(|r| r.algo == "mcts").unwrap();
    let replay = run_in(
        dir.path(),
        &[
            "replay",
            "b",
            &format!("{}", key.run),
            "--algo",
            "mcts",
            "--horizon",
            "2",
            "--budget",
            &key.budget.unwrap().to_string(),
            "--json",
        ],
    );
    assert!(replay.status.success(), "replay: {}", stderr(&replay));
}
