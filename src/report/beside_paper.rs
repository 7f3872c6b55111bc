//! "Beside the paper's numbers": our medians next to the paper's, for meshes the paper has a
//! case for ([`super::paper`]).

use super::format::{fmt_opt, fmt_sig};
use super::summarized::{median_of, metric_median};
use super::{Config, Document, Metric, Run, paper};
use crate::experiment::summary::Summary;

/// The paper's numbers beside ours, for meshes the paper has a case for.
pub(super) fn paper_beside(
    doc: &mut Document,
    summary: &Summary,
    mesh: &str,
    configs: &[(&Config, &[Run])],
) {
    let Some(case) = paper::case_for(mesh) else {
        return;
    };
    doc.heading(3, "Beside the paper's numbers");
    doc.para(format!(
        "The paper's numbers were measured on a different mesh ({}; ours has {} triangles) and \
         different hardware ({}); they show what to expect, not what must match. The times \
         differ by more than the hardware: our trees are cut by exact branch and bound (see \
         nodes per tree) and the paper's were not, so a gap of orders of magnitude, above \
         all for the uniform tree, is mostly the algorithm's, not the machine's.",
        case.mesh,
        configs[0].1[0].triangles,
        paper::PAPER_MACHINE
    ));
    let find = |algo: &str, h: Option<u32>| {
        configs
            .iter()
            .find(|(c, _)| c.algo == algo && c.horizon == h)
            .map(|(c, r)| (*c, *r))
    };
    let mut rows = Vec::new();
    for p in case.rows {
        let ours = find(p.algo, p.horizon);
        let ours_med = |m: Metric| {
            ours.and_then(|(c, r)| match m {
                Metric::Quality => median_of(summary, c, |g| g.quality_pct.as_ref()),
                _ => Some(metric_median(summary, c, r, m)),
            })
        };
        rows.push(vec![
            p.algo.to_string(),
            p.horizon.map_or("–".into(), |h| h.to_string()),
            fmt_opt(ours_med(Metric::Quality), 2),
            paper_number(p.quality_pct),
            fmt_opt(ours_med(Metric::Recombined), 2),
            paper_number(p.recombined_pct),
            ours_med(Metric::Time).map_or("–".into(), |t| fmt_sig(t, 3)),
            paper_number(p.time_s),
            p.source.to_string(),
        ]);
    }
    doc.table(
        [
            "algorithm",
            "horizon",
            "quality % (ours)",
            "quality % (paper)",
            "recombined % (ours)",
            "recombined % (paper)",
            "time s (ours)",
            "time s (paper)",
            "paper's source",
        ]
        .map(String::from)
        .to_vec(),
        rows,
    );
    doc.list(case.notes.iter().map(|n| format!("Paper: {n}")).collect());
}

/// A number of the paper as printed there, or "–".
pub(super) fn paper_number(v: Option<f64>) -> String {
    v.map_or("–".into(), |v| format!("{v}"))
}
