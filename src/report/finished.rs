//! The finished runs of `sweep --finish` in a mesh's section: one "+ finish" row per
//! configuration in the results table, and what the finish added (raw vs finished medians;
//! every finished configuration, node- and time-budgeted ones included).
//! Nothing is written for runs without a finish.

use super::format::{fmt_opt, fmt_sig};
use super::summarized::{finished_group, median_of};
use super::{Config, Document, Run};
use crate::experiment::summary::Summary;
use crate::stats::describe::median;

/// Whether some finished run of `runs` was refined by all-quad (a boundary split or sheets):
/// its mesh has more triangles, and so can have more quads, than the input, so its quality is
/// not comparable to the input's optimum (it can exceed 100 %).
fn refined(runs: &[Run]) -> bool {
    (runs.iter()).any(|r| {
        r.finish
            .as_ref()
            .and_then(|f| f.all_quad.as_ref())
            .is_some_and(|a| a.splits > 0 || a.sheets > 0)
    })
}

/// A quality percentage, marked with a dagger when the runs were refined by all-quad.
fn pct(v: Option<f64>, refined: bool) -> String {
    let s = fmt_opt(v, 2);
    if refined && v.is_some() {
        format!("{s} †")
    } else {
        s
    }
}

/// The note under a table whose rows carry a dagger.
const REFINED_NOTE: &str = "† Some runs were refined by --all-quad (a boundary side split, or \
    sheets where no single split could make a component even; docs/finish.md): their finished \
    mesh has more triangles, and can hold more quads, than the input, so its quality is not \
    comparable to the input's optimum (it can exceed 100 %). Compare their mean eta per quad \
    instead (runs.jsonl, finish.mean_eta).";

/// Whether any finished configuration of `configs` was refined by all-quad.
pub(super) fn any_refined(configs: &[(&Config, &[Run])]) -> bool {
    configs.iter().any(|(_, runs)| refined(runs))
}

/// The note to print under the results table when [`any_refined`].
pub(super) fn refined_note() -> &'static str {
    REFINED_NOTE
}

/// The results-table rows of the finished runs (same columns as the raw rows: algorithm,
/// horizon, runs, quality %, recombined %, time, nodes per tree, branching factor); time is
/// the search's and the finish's together, and the tree columns are "–".
pub(super) fn table_rows(summary: &Summary, configs: &[(&Config, &[Run])]) -> Vec<Vec<String>> {
    let mut rows = Vec::new();
    for (c, runs) in configs {
        let Some(g) = finished_group(summary, c) else {
            continue;
        };
        let total: Vec<f64> = (runs.iter())
            .filter_map(|r| r.finish.as_ref().map(|f| r.time_s + f.time_s))
            .collect();
        let whole = |b: Option<&crate::stats::describe::BoxStats>| {
            b.filter(|b| b.n == g.n).map(|b| b.median)
        };
        rows.push(vec![
            format!("{} + finish", super::mesh_section::row_name(c)),
            c.horizon.map_or("–".into(), |h| h.to_string()),
            g.n.to_string(),
            pct(whole(g.quality_pct.as_ref()), refined(runs)),
            fmt_opt(whole(g.recombined_pct.as_ref()), 2),
            if total.is_empty() {
                "–".into()
            } else {
                fmt_sig(median(&total), 3)
            },
            "–".into(),
            "–".into(),
        ]);
    }
    rows
}

/// "What the finish added": per finished configuration, the raw and finished medians of
/// quality and recombined, the median gain per run, and the finish's time.
pub(super) fn what_it_added(doc: &mut Document, summary: &Summary, configs: &[(&Config, &[Run])]) {
    let mut rows = Vec::new();
    let mut settings = None;
    for (c, runs) in configs {
        let Some(g) = finished_group(summary, c) else {
            continue;
        };
        let pairs: Vec<(&Run, &crate::experiment::finished::FinishRecord)> = (runs.iter())
            .filter_map(|r| r.finish.as_ref().map(|f| (r, f)))
            .collect();
        settings.get_or_insert((pairs[0].1.rings, pairs[0].1.window));
        let gain: Vec<f64> = (pairs.iter())
            .filter_map(|(r, f)| Some(f.quality_pct? - r.quality_pct?))
            .collect();
        let left: Vec<f64> = pairs.iter().map(|(_, f)| f.triangles_left as f64).collect();
        let time: Vec<f64> = pairs.iter().map(|(_, f)| f.time_s).collect();
        let whole = |b: Option<&crate::stats::describe::BoxStats>| {
            b.filter(|b| b.n == g.n).map(|b| b.median)
        };
        let mut algorithm = match c.budget {
            Some(b) => format!("{} b={b}", c.algo),
            None => c.algo.clone(),
        };
        if let Some(t) = c.time_budget {
            algorithm.push_str(&format!(" (T={}s)", t.seconds()));
        }
        rows.push(vec![
            algorithm,
            c.horizon.map_or("–".into(), |h| h.to_string()),
            g.n.to_string(),
            fmt_opt(median_of(summary, c, |g| g.quality_pct.as_ref()), 2),
            pct(whole(g.quality_pct.as_ref()), refined(runs)),
            pct(
                (gain.len() == pairs.len()).then(|| median(&gain)),
                refined(runs),
            ),
            fmt_opt(median_of(summary, c, |g| g.recombined_pct.as_ref()), 2),
            fmt_opt(whole(g.recombined_pct.as_ref()), 2),
            fmt_sig(median(&left), 3),
            fmt_sig(median(&time), 3),
        ]);
    }
    let Some((rings, window)) = settings else {
        return;
    };
    doc.heading(3, "What the finish added");
    doc.table(
        [
            "algorithm",
            "horizon",
            "runs",
            "quality raw (%)",
            "quality finished (%)",
            "gain (points)",
            "recombined raw (%)",
            "recombined finished (%)",
            "triangles left finished",
            "finish time (s)",
        ]
        .map(String::from)
        .to_vec(),
        rows,
    );
    doc.para(format!(
        "Each run of these configurations was finished after its search (sweep --finish, \
         rings {rings}, window {window}; docs/finish.md): leftover elimination, then local \
         improvement. Medians over the runs; the gain is the median of each run's finished \
         quality minus its raw quality, in points of the optimum; the finish time is the \
         finish's alone (the \"+ finish\" rows of the results table count the search's too)."
    ));
    if any_refined(configs) {
        doc.para(REFINED_NOTE);
    }
}
