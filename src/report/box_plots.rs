//! "Box plots against horizon": Fig.-8-style box plots of each measure per look-ahead
//! algorithm, with the greedy reference and, for time, the growth fit.

use super::format::{mesh_slug, slug};
use super::mesh_section::tree_algos;
use super::plots::{Extras, HorizonBox, boxplot_svg};
use super::summarized::{growth, metric_median, metric_stats};
use super::{Config, Document, FIGURES_DIR, Metric, ReportError, Run};
use crate::experiment::summary::Summary;

/// Fig.-8-style box plots for each algorithm with horizons.
pub(super) fn box_plots(
    doc: &mut Document,
    summary: &Summary,
    mesh: &str,
    configs: &[(&Config, &[Run])],
) -> Result<(), ReportError> {
    let algos = tree_algos(configs);
    if algos.is_empty() {
        return Ok(());
    }
    doc.heading(3, "Box plots against horizon");
    let greedy = configs.iter().find(|(c, _)| c.algo == "greedy");
    for algo in algos {
        let group: Vec<(&Config, u32, &[Run])> = configs
            .iter()
            .filter(|(c, _)| c.algo == algo)
            .filter_map(|(c, r)| c.horizon.map(|h| (*c, h, *r)))
            .collect();
        for metric in Metric::ALL {
            let all: Vec<Run> = group
                .iter()
                .flat_map(|(_, _, r)| r.iter().cloned())
                .collect();
            let name = metric.name(&all);
            let boxes: Vec<HorizonBox> = group
                .iter()
                .filter_map(|(c, h, r)| {
                    let stats = metric_stats(summary, c, r, metric)?;
                    Some(HorizonBox { horizon: *h, stats })
                })
                .collect();
            let mut extras = Extras::default();
            if let Some((g, gr)) = greedy
                && metric.name(gr) == name
            {
                extras
                    .baselines
                    .push((g.label(), metric_median(summary, g, gr, metric)));
            }
            let mut caption = format!(
                "{mesh}, {algo}: {name} against horizon ({} runs per horizon). Red lines: medians; \
                 blue boxes: interquartile ranges; whiskers: most extreme runs within 1.5 IQR; \
                 red crosses: outliers.",
                group.iter().map(|(_, _, r)| r.len()).max().unwrap_or(0)
            );
            let log_y = metric == Metric::Time;
            if log_y {
                // The runner's growth fits (as in summary.json): log10(median time) on h over
                // every horizon, and over the upper half where the paper reads alpha.
                let entry = growth(summary, mesh, algo);
                extras.fit = entry.and_then(|g| g.upper.clone().or_else(|| g.all.clone()));
                caption.push_str(" Logarithmic axis.");
                if let Some(f) = &extras.fit {
                    caption.push_str(&format!(
                        " Green: least-squares fit of log10(median time) on h = {}..{}, slope {:.3} \
                         per horizon, branching factor alpha = 10^slope = {:.3}",
                        f.h_min, f.h_max, f.fit.slope, f.alpha
                    ));
                    if f.fit.n < 3 {
                        caption.push_str(
                            " (a line through two points, which any two horizons fit exactly: \
                             not a measured growth; sweep more horizons for one)",
                        );
                    }
                    if let Some(a) = entry.and_then(|g| g.all.as_ref()) {
                        caption.push_str(&format!(
                            " (over every horizon h = {}..{}: alpha = {:.3})",
                            a.h_min, a.h_max, a.alpha
                        ));
                    }
                    caption.push_str(match algo {
                        "selective" => {
                            "; the paper reports 1.33 for its selective tree on its \
                                        Borouchaki mesh."
                        }
                        "uniform" => {
                            "; the uniform tree branches on every allowed action (its \
                                      exact bound cuts the subtrees that cannot hold the best \
                                      sequence), so its alpha is not comparable with the \
                                      paper's 1.33 for the selective tree."
                        }
                        _ => ".",
                    });
                }
            }
            let stem = format!("{}-{}-{}", mesh_slug(mesh), slug(algo), metric.key());
            let svg = boxplot_svg(
                &format!("{stem}-"),
                &format!("{mesh}: {algo}"),
                name,
                &boxes,
                log_y,
                &extras,
            )?;
            let file = format!("{FIGURES_DIR}/{stem}.svg");
            doc.figure(file, svg, caption);
        }
    }
    Ok(())
}
