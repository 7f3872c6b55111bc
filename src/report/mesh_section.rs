//! One mesh's section: its size and optimum, Table 1 (medians per configuration), the element
//! quality table, then the paper's numbers, box plots, pictures and statistical comparisons
//! (each from its own module).

use super::format::{fmt_count, fmt_opt, fmt_sig};
use super::significance::{self, Family};
use super::summarized::{median_of, metric_median};
use super::{Config, Document, Metric, ReportError, ReportOptions, Results, Run, results};
use crate::experiment::replay::Replayer;
use crate::experiment::summary::Summary;
use crate::stats::describe::median;

/// The optimum quality of `mesh` from the manifest, if recorded.
pub(super) fn optimum_of(results: &Results, mesh: &str) -> Option<f64> {
    results
        .manifest
        .as_ref()?
        .optimum
        .iter()
        .find(|o| o.mesh == mesh)
        .map(|o| o.quality)
}

/// A configuration's name in the first column of a table that gives the horizon in the
/// second: the algorithm, its node budget and the time budget it was calibrated to.
pub(super) fn row_name(c: &Config) -> String {
    let mut name = match c.budget {
        Some(b) => format!("{} b={b}", c.algo),
        None => c.algo.clone(),
    };
    if let Some(t) = c.time_budget {
        name += &format!(" (T={}s)", t.seconds());
    }
    name
}

/// One table row per configuration: its algorithm and horizon ("–" for none), then the
/// `cells` of its runs.
fn config_rows(
    configs: &[(&Config, &[Run])],
    cells: impl Fn(&Config, &[Run]) -> Vec<String>,
) -> Vec<Vec<String>> {
    (configs.iter())
        .map(|(c, runs)| {
            let mut row = vec![row_name(c), c.horizon.map_or("–".into(), |h| h.to_string())];
            row.extend(cells(c, runs));
            row
        })
        .collect()
}

pub(super) fn mesh_section(
    doc: &mut Document,
    results: &Results,
    summary: &Summary,
    mesh: &str,
    opts: &ReportOptions,
    seed: u64,
    replayer: &mut Replayer<'_>,
) -> Result<(), ReportError> {
    let every: Vec<(&Config, &[Run])> = results.configs_of(mesh).collect();
    let first = &every[0].1[0];
    // Tables 1 and the element quality list every configuration; the budgeted ones also have
    // their own section (quality against budget), and the horizon sections below (box
    // plots, the paper's numbers, pictures, tests between horizons) read the others.
    let configs: Vec<(&Config, &[Run])> = (every.iter().copied())
        .filter(|(c, _)| c.budget.is_none() && c.time_budget.is_none())
        .collect();
    let configs = if configs.is_empty() {
        every.clone()
    } else {
        configs
    };
    doc.heading(2, format!("Mesh {mesh}"));
    let opt = optimum_of(results, mesh);
    doc.para(format!(
        "{} triangles (mesh hash {}). Optimum quality: {} (the maximum-weight matching among \
         those of maximum cardinality, docs/optimum.md). Quality % is of it, so a run that \
         leaves more triangles can pass 100 % (a heavier set of fewer quads): read it beside \
         recombined %.",
        first.triangles,
        &first.mesh_hash[..first.mesh_hash.len().min(16)],
        opt.map_or("not recorded".to_string(), |q| format!("{q:.4}")),
    ));

    // Table 1.
    doc.heading(3, "Results (medians)");
    let rows = config_rows(&every, |c, runs| {
        vec![
            runs.len().to_string(),
            fmt_opt(median_of(summary, c, |g| g.quality_pct.as_ref()), 2),
            format!("{:.2}", metric_median(summary, c, runs, Metric::Recombined)),
            fmt_sig(metric_median(summary, c, runs, Metric::Time), 3),
            {
                // "–" where no run built a tree (it printed 0).
                let per_tree: Vec<f64> = runs.iter().filter_map(results::nodes_per_tree).collect();
                if per_tree.is_empty() {
                    "–".to_string()
                } else {
                    fmt_sig(median(&per_tree), 3)
                }
            },
            fmt_opt(median_of(summary, c, |g| g.branching_factor.as_ref()), 3),
        ]
    });
    let mut rows = rows;
    rows.extend(super::finished::table_rows(summary, &every));
    doc.table(
        [
            "algorithm",
            "horizon",
            "runs",
            "quality (% of optimum)",
            "recombined (%)",
            "time (s)",
            "nodes per tree",
            "branching factor",
        ]
        .map(String::from)
        .to_vec(),
        rows,
    );
    doc.para(
        "Medians over the runs of each configuration. Quality is the sum of eta over the quads as \
         a percentage of the optimum; recombined is the percentage of triangles merged into \
         quads; time is the search's wall time; nodes per tree is tree nodes expanded per \
         look-ahead tree (a selective decision whose root triangle has a single allowed action \
         builds none; – where the algorithm builds no tree); the branching factor is the runner's effective branching factor, the b \
         with 1 + b + ... + b^(h-1) = nodes per tree (none at h = 1). Both measure the search \
         as run: the selective tree cuts, by exact branch and bound, the subtrees that cannot \
         hold the best leaf, so it expands fewer nodes than the tree it explores (whose \
         decisions are unchanged), and its time grows more slowly with the horizon.",
    );

    if super::finished::any_refined(&every) {
        doc.para(super::finished::refined_note());
    }
    // Every finished configuration, the budgeted and time-budget ones included: their own
    // sections show no finish.
    super::finished::what_it_added(doc, summary, &every);
    element_table(doc, summary, &every);
    greedy_paradox(doc, &configs);
    super::beside_paper::paper_beside(doc, summary, mesh, &configs);
    super::box_plots::box_plots(doc, summary, mesh, &configs)?;
    if opts.pictures {
        super::pictures::pictures(doc, mesh, &configs, opts, replayer)?;
    }

    doc.heading(3, "Statistical comparisons");
    let mut families: Vec<Family> = significance::consecutive_horizons(&configs, seed);
    families.extend(significance::against_greedy(&configs, seed));
    if families.is_empty() {
        doc.para("Nothing to compare: no two horizons of one algorithm and no greedy runs.");
    }
    family_blocks(doc, &families);
    super::budget::budget_section(doc, summary, mesh, &every, seed)?;
    Ok(())
}

/// The element quality of each configuration beside its sum: a high sum with many
/// triangles left, or with near-degenerate quads, is not a better mesh.
pub(super) fn element_table(doc: &mut Document, summary: &Summary, configs: &[(&Config, &[Run])]) {
    if configs.iter().all(|(_, runs)| runs[0].mean_eta.is_none()) {
        return;
    }
    doc.heading(3, "Element quality (medians)");
    let rows = config_rows(configs, |c, runs| {
        vec![
            fmt_opt(median_of(summary, c, |g| g.mean_eta.as_ref()), 4),
            fmt_opt(median_of(summary, c, |g| g.worst_eta.as_ref()), 4),
            // Medians of counts: whole, or halves (an even number of runs).
            fmt_count(median_of(summary, c, |g| g.quads_eta_below_0_1.as_ref())),
            fmt_count(median_of(summary, c, |g| g.quads_eta_below_0_3.as_ref())),
            format!(
                "{}",
                median(
                    &runs
                        .iter()
                        .map(|r| r.triangles_left as f64)
                        .collect::<Vec<_>>()
                )
            ),
        ]
    });
    doc.table(
        [
            "algorithm",
            "horizon",
            "mean eta per quad",
            "worst eta",
            "quads with eta < 0.1",
            "quads with eta < 0.3",
            "triangles left",
        ]
        .map(String::from)
        .to_vec(),
        rows,
    );
    doc.para(
        "The quality percentage above sums eta over the quads made; these say what those quads \
         are: the mean eta per quad, the worst quad, and how many are poor, beside the triangles \
         left unrecombined (which count nothing in the sum). A policy that makes fewer quads \
         can reach a similar sum with a higher mean and more triangles left: compare the \
         columns together.",
    );
}

/// Where greedy's sum of eta beats a configuration that recombines more, the data say why:
/// greedy takes the best pairs first and stops where no allowed pair is left, so it makes
/// fewer quads of a higher mean eta; the other pairs almost every triangle, paying with worse
/// quads. Written from the medians of the runs, for every such configuration.
pub(super) fn greedy_paradox(doc: &mut Document, configs: &[(&Config, &[Run])]) {
    let Some((_, greedy)) = configs.iter().find(|(c, _)| c.algo == "greedy") else {
        return;
    };
    // Medians of (sum of eta, triangles left, quads, mean eta per quad); none without the
    // element fields (records older than them).
    let medians = |runs: &[Run]| -> Option<(f64, f64, f64, f64)> {
        let mean: Vec<f64> = runs.iter().filter_map(|r| r.mean_eta).collect();
        let of = |f: fn(&Run) -> f64| median(&runs.iter().map(f).collect::<Vec<_>>());
        (!mean.is_empty()).then(|| {
            (
                of(|r| r.quality),
                of(|r| r.triangles_left as f64),
                of(|r| r.quads as f64),
                median(&mean),
            )
        })
    };
    let Some((gq, gl, gn, gm)) = medians(greedy) else {
        return;
    };
    let mut lines = Vec::new();
    for (c, runs) in configs.iter().filter(|(c, _)| c.horizon.is_some()) {
        let Some((q, l, n, m)) = medians(runs) else {
            continue;
        };
        if q < gq && l < gl {
            lines.push(format!(
                "{}: a sum of eta of {q:.2} against greedy's {gq:.2} although it leaves {l} \
                 triangles against {gl} ({} times fewer): it makes {n} quads of mean eta {m:.4}, \
                 greedy {gn} of mean eta {gm:.4}",
                c.label(),
                fmt_sig(gl / l.max(1.0), 2),
            ));
        }
    }
    if lines.is_empty() {
        return;
    }
    doc.para(format!(
        "Why greedy's sum can beat a policy that recombines more (medians): {}. Greedy takes \
         the best allowed pair first and stops where no allowed pair is left, so it makes fewer \
         quads of a higher mean eta and leaves the triangles no good pair could take; the \
         look-ahead pairs almost every triangle, taking the poorer pairs that this needs. The \
         sum rewards the first and the mesh the second: a finite-element user wants the \
         triangles gone, so read the quality with the triangles left and the mean eta beside it.",
        lines.join("; ")
    ));
}

/// Summary sentences and a table per family.
pub(super) fn family_blocks(doc: &mut Document, families: &[Family]) {
    for f in families {
        doc.para(f.summary());
        if !f.pairs.is_empty() {
            doc.table(
                significance::header(),
                f.pairs.iter().map(|p| p.row()).collect(),
            );
        }
    }
}

/// The tree algorithms among `configs` (those with a horizon), each once, in order.
pub(super) fn tree_algos<'c>(configs: &[(&'c Config, &[Run])]) -> Vec<&'c str> {
    let mut algos: Vec<&str> = configs
        .iter()
        .filter(|(c, _)| c.horizon.is_some())
        .map(|(c, _)| c.algo.as_str())
        .collect();
    algos.dedup();
    algos
}
