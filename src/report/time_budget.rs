//! "Quality against budget", by time budget (`sweep --time-budgets`): per time budget and
//! method, the knob its calibration chose, the median time the runs took against the budget,
//! and the quality (median and quartiles); where the methods without a knob fall; one
//! figure; and each policy against selective at the same time budget (Mann-Whitney with
//! Holm, A12, bootstrap interval, as the report's other comparisons).

use super::ReportError;
use super::budget::{Line, line_of, lines_figure};
use super::document::Document;
use super::format::fmt_sig;
use super::results::{Config, Metric, Run};
use super::significance::Family;
use crate::experiment::calibrate::{TimeBudget, has_knob};
use crate::stats::describe::{median, quantile};

/// One configuration calibrated to a time budget.
struct Row<'a> {
    config: &'a Config,
    runs: &'a [Run],
    t: TimeBudget,
    time: f64,
    q: [f64; 3],
}

/// Appends the time-budget part of the section for `mesh`.
pub(super) fn time_budgets(
    doc: &mut Document,
    mesh: &str,
    configs: &[(&Config, &[Run])],
    seed: u64,
) -> Result<(), ReportError> {
    let mut rows: Vec<Row<'_>> = (configs.iter())
        .filter_map(|&(c, runs)| {
            let t = c.time_budget?;
            let q = Metric::Quality.values(runs);
            let time: Vec<f64> = runs.iter().map(|r| r.time_s).collect();
            Some(Row {
                config: c,
                runs,
                t,
                time: median(&time),
                q: [quantile(&q, 0.25), median(&q), quantile(&q, 0.75)],
            })
        })
        .collect();
    // By time budget, then in the report's order of configurations.
    rows.sort_by(|a, b| a.t.cmp(&b.t).then_with(|| a.config.cmp(b.config)));
    let name = Metric::Quality.name(rows[0].runs);
    doc.para(
        "By time budget: each time budget T (seconds per run, `sweep --time-budgets`) was \
         calibrated once, before the runs, into each method's knob: the largest node budget \
         per decision (optimistic, mcts, beam, at each horizon) or horizon (selective, \
         uniform) whose median time over a few pilot runs was at most T plus 5 %, so that the \
         runs replay from their seeds (docs/search.md). The times below are the runs' own, \
         measured in the sweep beside each other; \"of T\" is their median as a percentage of \
         T, which shows how close the calibration came (pilots are few, and the machine's \
         load may differ between calibration and runs).",
    );
    doc.table(
        [
            "time budget (s)",
            "configuration",
            "knob",
            "runs",
            "median time (s)",
            "of T",
            "q1",
            "median",
            "q3",
        ]
        .map(String::from)
        .to_vec(),
        rows.iter()
            .map(|r| {
                let c = r.config;
                let h = c.horizon.unwrap_or(0);
                vec![
                    r.t.seconds().to_string(),
                    c.label(),
                    match c.budget {
                        Some(b) => format!("{b} nodes (h = {h})"),
                        None => format!("h = {h}"),
                    },
                    r.runs.len().to_string(),
                    fmt_sig(r.time, 3),
                    format!("{:.0} %", 100.0 * r.time / r.t.seconds()),
                    format!("{:.3}", r.q[0]),
                    format!("{:.3}", r.q[1]),
                    format!("{:.3}", r.q[2]),
                ]
            })
            .collect(),
    );
    let mut budgets: Vec<TimeBudget> = rows.iter().map(|r| r.t).collect();
    budgets.dedup();
    let fixed: Vec<String> = (configs.iter())
        .filter(|(c, _)| c.time_budget.is_none() && !has_knob(&c.algo))
        .map(|(c, runs)| {
            let time: Vec<f64> = runs.iter().map(|r| r.time_s).collect();
            let t = median(&time);
            let below = budgets.iter().filter(|b| b.seconds() < t).count();
            let place = match below {
                0 => "within every time budget".to_string(),
                n if n == budgets.len() => "above every time budget".to_string(),
                n => format!("above {n} of the {} time budgets", budgets.len()),
            };
            format!("{} {} s ({place})", c.label(), fmt_sig(t, 3))
        })
        .collect();
    if !fixed.is_empty() {
        doc.para(format!(
            "Without a knob to calibrate, run as usual (median time): {}.",
            fixed.join("; ")
        ));
    }
    let svg = figure(mesh, name, &rows)?;
    doc.figure(
        format!(
            "{}/{}-time-budget.svg",
            super::FIGURES_DIR,
            super::format::mesh_slug(mesh)
        ),
        svg,
        format!(
            "{mesh}: {name} against the time budget per run (log axis), one line per method \
             and horizon (for the budgeted methods); dots at the medians, bars from the first \
             to the third quartile."
        ),
    );
    // Each policy against selective at the same time budget.
    let mut sides = Vec::new();
    for &t in &budgets {
        let at: Vec<&Row<'_>> = rows.iter().filter(|r| r.t == t).collect();
        let Some(sel) = at.iter().find(|r| r.config.algo == "selective") else {
            continue;
        };
        for r in at.iter().filter(|r| r.config.algo != "selective") {
            sides.push((r.config.label(), r.runs, sel.config.label(), sel.runs));
        }
    }
    if sides.is_empty() {
        doc.para(
            "No policy and selective calibrated to the same time budget on this mesh: nothing \
             to compare at equal time.",
        );
        return Ok(());
    }
    doc.para(
        "Each policy against selective calibrated to the same time budget: a policy that wins \
         there wins at the same cost on this machine.",
    );
    let family = Family::build(
        "Policies against selective at the same time budget, quality".into(),
        Metric::Quality,
        sides,
        seed.wrapping_add(9500),
    );
    super::mesh_section::family_blocks(doc, &[family]);
    Ok(())
}

/// The figure: quality against the time budget, one line per method (and horizon, for the
/// budgeted methods), IQR bars.
fn figure(mesh: &str, name: &str, rows: &[Row<'_>]) -> Result<String, ReportError> {
    let line_of = |r: &Row<'_>| line_of(r.config);
    let mut labels: Vec<String> = rows.iter().map(line_of).collect();
    labels.sort_unstable();
    labels.dedup();
    let lines: Vec<Line> = (labels.into_iter())
        .map(|label| {
            let mut mine: Vec<&Row<'_>> = rows.iter().filter(|r| line_of(r) == label).collect();
            mine.sort_by_key(|r| r.t);
            let pts = mine.iter().map(|r| (r.t.seconds(), r.q)).collect();
            (label, pts)
        })
        .collect();
    lines_figure(
        &format!("{mesh}: quality against time budget"),
        "time budget per run (s)",
        name,
        &lines,
    )
}
