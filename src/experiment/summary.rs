//! `summary.json` and `summary.csv`: statistics per (mesh, algorithm, horizon) and the growth
//! of time with horizon per (mesh, algorithm).
//!
//! summary.csv is long-format: one row per (mesh, algo, horizon, metric) with the columns
//! `mesh,algo,horizon,metric,n,mean,sd,min,whisker_low,q1,median,q3,whisker_high,max,n_outliers`
//! (horizon empty for algorithms without one; a `budget` column after it when a group has a
//! budget, a `time_budget_s` column when a group was calibrated to a time budget (`sweep
//! --time-budgets`), and a `finish` column, "finish" on the rows of the finished groups of
//! `sweep --finish`, when a group is finished). Metrics: `quality_pct`, `recombined_pct`,
//! `time_s`, `nodes_expanded`, `branching_factor`, `mean_eta`, `worst_eta`,
//! `quads_eta_below_0_1`, `quads_eta_below_0_3` (each only where its runs record it).
//! summary.json holds the same groups with the outlier values, and the growth fits.

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};

use super::ExperimentError;
use super::calibrate::TimeBudget;
use super::record::RunRecord;
use crate::stats::describe::{BoxStats, Growth, growth_fit};

/// File names in a results directory.
pub const SUMMARY_JSON: &str = "summary.json";
/// See [`SUMMARY_JSON`].
pub const SUMMARY_CSV: &str = "summary.csv";

/// Metrics summarised, in CSV order.
pub const METRICS: &[&str] = &[
    "quality_pct",
    "recombined_pct",
    "time_s",
    "nodes_expanded",
    "branching_factor",
    "mean_eta",
    "worst_eta",
    "quads_eta_below_0_1",
    "quads_eta_below_0_3",
];

/// Statistics of one (mesh, algo, horizon) configuration.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Group {
    /// Mesh name.
    pub mesh: String,
    /// Algorithm name.
    pub algo: String,
    /// Horizon, for tree policies.
    pub horizon: Option<u32>,
    /// Node budget per decision, for the budgeted policies.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub budget: Option<u32>,
    /// The wall-time budget its horizon or node budget was calibrated for (`sweep
    /// --time-budgets`); absent for the others.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_budget_s: Option<super::calibrate::TimeBudget>,
    /// The group's figures are its runs after their finish (`sweep --finish`: the records'
    /// `finish` objects), beside the raw group of the same configuration; absent (false)
    /// for the raw groups. Time is then the finish's alone; no tree figures.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub finished: bool,
    /// Runs in the group.
    pub n: usize,
    /// Quality as % of the optimum (`None` when no run knows the optimum).
    pub quality_pct: Option<BoxStats>,
    /// Recombined triangles, %.
    pub recombined_pct: Option<BoxStats>,
    /// Search time, s.
    pub time_s: Option<BoxStats>,
    /// Tree nodes expanded per run.
    pub nodes_expanded: Option<BoxStats>,
    /// Effective branching factor per run (where defined).
    pub branching_factor: Option<BoxStats>,
    /// Mean of the runs' effective branching factors.
    pub mean_branching_factor: Option<f64>,
    /// Mean eta per quad of each run.
    #[serde(default)]
    pub mean_eta: Option<BoxStats>,
    /// The worst quad's eta of each run.
    #[serde(default)]
    pub worst_eta: Option<BoxStats>,
    /// Quads with eta < 0.1 per run.
    #[serde(default)]
    pub quads_eta_below_0_1: Option<BoxStats>,
    /// Quads with eta < 0.3 per run.
    #[serde(default)]
    pub quads_eta_below_0_3: Option<BoxStats>,
}

/// Growth of time with horizon for one (mesh, algo).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GrowthEntry {
    /// Mesh name.
    pub mesh: String,
    /// Algorithm name.
    pub algo: String,
    /// Fit of log10(median time) against h over every horizon.
    pub all: Option<Growth>,
    /// The same over the upper half of the horizons (h >= the median horizon), where the
    /// paper reads its asymptotic alpha.
    pub upper: Option<Growth>,
}

/// The whole summary.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// Configurations, sorted by mesh, algorithm, horizon.
    pub groups: Vec<Group>,
    /// Growth fits for algorithms with a horizon.
    pub growth: Vec<GrowthEntry>,
}

/// Computes the summary of a set of records.
pub fn summarize(records: &[RunRecord]) -> Summary {
    type Key = (String, String, Option<u32>, Option<u32>, Option<TimeBudget>);
    let mut by: BTreeMap<Key, Vec<&RunRecord>> = BTreeMap::new();
    for r in records {
        by.entry((
            r.mesh.clone(),
            r.algo.clone(),
            r.horizon,
            r.budget,
            r.time_budget_s,
        ))
        .or_default()
        .push(r);
    }
    let groups: Vec<Group> = by
        .into_iter()
        .map(|((mesh, algo, horizon, budget, time_budget_s), rs)| {
            let col = |f: &dyn Fn(&RunRecord) -> Option<f64>| -> Vec<f64> {
                rs.iter()
                    .filter_map(|r| f(r))
                    .filter(|x| x.is_finite())
                    .collect()
            };
            let bf = col(&|r| r.branching_factor);
            Group {
                mesh,
                algo,
                horizon,
                budget,
                time_budget_s,
                finished: false,
                n: rs.len(),
                quality_pct: BoxStats::of(&col(&|r| r.quality_pct)),
                recombined_pct: BoxStats::of(&col(&|r| Some(r.recombined_pct))),
                time_s: BoxStats::of(&col(&|r| Some(r.time_s))),
                nodes_expanded: BoxStats::of(&col(&|r| r.nodes_expanded.map(|n| n as f64))),
                mean_branching_factor: (!bf.is_empty()).then(|| crate::stats::describe::mean(&bf)),
                branching_factor: BoxStats::of(&bf),
                mean_eta: BoxStats::of(&col(&|r| r.mean_eta)),
                worst_eta: BoxStats::of(&col(&|r| r.worst_eta)),
                quads_eta_below_0_1: BoxStats::of(&col(&|r| {
                    r.quads_eta_below_0_1.map(|n| n as f64)
                })),
                quads_eta_below_0_3: BoxStats::of(&col(&|r| {
                    r.quads_eta_below_0_3.map(|n| n as f64)
                })),
            }
        })
        .collect();
    let mut groups = groups;
    groups.extend(finished_groups(records));
    groups.sort_by(|a, b| {
        (
            &a.mesh,
            &a.algo,
            a.horizon,
            a.budget,
            a.time_budget_s,
            a.finished,
        )
            .cmp(&(
                &b.mesh,
                &b.algo,
                b.horizon,
                b.budget,
                b.time_budget_s,
                b.finished,
            ))
    });
    let mut curves: BTreeMap<(String, String), Vec<(u32, f64)>> = BTreeMap::new();
    for g in &groups {
        let timed = g.time_budget_s.is_some();
        if let (Some(h), Some(t), None, false, false) =
            (g.horizon, &g.time_s, g.budget, g.finished, timed)
        {
            curves
                .entry((g.mesh.clone(), g.algo.clone()))
                .or_default()
                .push((h, t.median));
        }
    }
    let growth = curves
        .into_iter()
        .map(|((mesh, algo), pts)| {
            let hs: Vec<f64> = pts.iter().map(|p| f64::from(p.0)).collect();
            let h_mid = crate::stats::describe::median(&hs);
            let upper: Vec<(u32, f64)> = pts
                .iter()
                .copied()
                .filter(|p| f64::from(p.0) >= h_mid)
                .collect();
            GrowthEntry {
                mesh,
                algo,
                all: growth_fit(&pts),
                upper: growth_fit(&upper),
            }
        })
        .collect();
    Summary { groups, growth }
}

/// The groups of the finished runs (records with a `finish` object), one per configuration:
/// quality %, recombined %, the finish's time, mean and worst eta after the finish.
fn finished_groups(records: &[RunRecord]) -> Vec<Group> {
    type Key = (String, String, Option<u32>, Option<u32>, Option<TimeBudget>);
    let mut by: BTreeMap<Key, Vec<&super::finished::FinishRecord>> = BTreeMap::new();
    for r in records {
        if let Some(f) = &r.finish {
            by.entry((
                r.mesh.clone(),
                r.algo.clone(),
                r.horizon,
                r.budget,
                r.time_budget_s,
            ))
            .or_default()
            .push(f);
        }
    }
    by.into_iter()
        .map(|((mesh, algo, horizon, budget, time_budget_s), fs)| {
            let col = |f: &dyn Fn(&super::finished::FinishRecord) -> Option<f64>| -> Vec<f64> {
                fs.iter()
                    .filter_map(|r| f(r))
                    .filter(|x| x.is_finite())
                    .collect()
            };
            Group {
                mesh,
                algo,
                horizon,
                budget,
                time_budget_s,
                finished: true,
                n: fs.len(),
                quality_pct: BoxStats::of(&col(&|f| f.quality_pct)),
                recombined_pct: BoxStats::of(&col(&|f| Some(f.recombined_pct))),
                time_s: BoxStats::of(&col(&|f| Some(f.time_s))),
                nodes_expanded: None,
                branching_factor: None,
                mean_branching_factor: None,
                mean_eta: BoxStats::of(&col(&|f| f.mean_eta)),
                worst_eta: BoxStats::of(&col(&|f| f.worst_eta)),
                quads_eta_below_0_1: None,
                quads_eta_below_0_3: None,
            }
        })
        .collect()
}

impl Group {
    fn metric(&self, name: &str) -> Option<&BoxStats> {
        match name {
            "quality_pct" => self.quality_pct.as_ref(),
            "recombined_pct" => self.recombined_pct.as_ref(),
            "time_s" => self.time_s.as_ref(),
            "nodes_expanded" => self.nodes_expanded.as_ref(),
            "branching_factor" => self.branching_factor.as_ref(),
            "mean_eta" => self.mean_eta.as_ref(),
            "worst_eta" => self.worst_eta.as_ref(),
            "quads_eta_below_0_1" => self.quads_eta_below_0_1.as_ref(),
            "quads_eta_below_0_3" => self.quads_eta_below_0_3.as_ref(),
            _ => None,
        }
    }
}

/// The CSV text of a summary (see the module docs for the columns).
pub fn to_csv(summary: &Summary) -> String {
    // The budget column only where a group has a budget: summaries without one read as
    // they always did.
    let budgets = summary.groups.iter().any(|g| g.budget.is_some());
    // Likewise the finish column ("finish" on the finished groups' rows), only where a group
    // is finished.
    let finish = summary.groups.iter().any(|g| g.finished);
    // And the time budget column, only where a group was calibrated to one.
    let timed = summary.groups.iter().any(|g| g.time_budget_s.is_some());
    let mut out = String::from(if budgets {
        "mesh,algo,horizon,budget,metric,n,mean,sd,min,whisker_low,q1,median,q3,whisker_high,max,n_outliers\n"
    } else {
        "mesh,algo,horizon,metric,n,mean,sd,min,whisker_low,q1,median,q3,whisker_high,max,n_outliers\n"
    });
    if timed {
        out = out.replacen(",metric,", ",time_budget_s,metric,", 1);
    }
    if finish {
        out = out.replacen(",metric,", ",finish,metric,", 1);
    }
    for g in &summary.groups {
        for &metric in METRICS {
            if let Some(b) = g.metric(metric) {
                let mut h = g.horizon.map(|h| h.to_string()).unwrap_or_default();
                if budgets {
                    h.push(',');
                    h.push_str(&g.budget.map(|b| b.to_string()).unwrap_or_default());
                }
                if timed {
                    h.push(',');
                    let t = g.time_budget_s.map(|t| t.seconds().to_string());
                    h.push_str(&t.unwrap_or_default());
                }
                if finish {
                    h.push_str(if g.finished { ",finish" } else { "," });
                }
                out.push_str(&format!(
                    "{},{},{h},{metric},{},{},{},{},{},{},{},{},{},{},{}\n",
                    csv_field(&g.mesh),
                    g.algo,
                    b.n,
                    b.mean,
                    b.sd,
                    b.min,
                    b.whisker_low,
                    b.q1,
                    b.median,
                    b.q3,
                    b.whisker_high,
                    b.max,
                    b.outliers.len()
                ));
            }
        }
    }
    out
}

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// Writes summary.json and summary.csv into `dir`.
pub fn write(dir: &Path, records: &[RunRecord]) -> Result<Summary, ExperimentError> {
    let summary = summarize(records);
    let json = serde_json::to_string_pretty(&summary).expect("a Summary always serializes");
    super::write_atomic(&dir.join(SUMMARY_JSON), format!("{json}\n").as_bytes())?;
    super::write_atomic(&dir.join(SUMMARY_CSV), to_csv(&summary).as_bytes())?;
    Ok(summary)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::store::tests::record;

    #[test]
    fn groups_and_growth() {
        let mut recs = Vec::new();
        for h in 1..=4u32 {
            for run in 0..5 {
                let mut r = record(run);
                r.horizon = Some(h);
                r.time_s = 0.01 * 2f64.powi(h as i32) * (1.0 + 0.01 * f64::from(run));
                r.quality_pct = Some(90.0 + f64::from(h) + f64::from(run));
                recs.push(r);
            }
        }
        let mut g = record(0);
        g.algo = "greedy".into();
        g.horizon = None;
        g.branching_factor = None;
        recs.push(g);
        let s = summarize(&recs);
        assert_eq!(s.groups.len(), 5);
        let g0 = &s.groups[0];
        assert_eq!((g0.algo.as_str(), g0.horizon, g0.n), ("greedy", None, 1));
        assert!(g0.branching_factor.is_none() && g0.mean_branching_factor.is_none());
        let h2 = s.groups.iter().find(|g| g.horizon == Some(2)).unwrap();
        assert_eq!(h2.n, 5);
        assert_eq!(h2.quality_pct.as_ref().unwrap().median, 94.0);
        assert_eq!(h2.mean_branching_factor, Some(1.9));
        assert_eq!(s.growth.len(), 1);
        let all = s.growth[0].all.as_ref().unwrap();
        assert!((all.alpha - 2.0).abs() < 1e-9, "{}", all.alpha);
        let upper = s.growth[0].upper.as_ref().unwrap();
        assert_eq!((upper.h_min, upper.h_max), (3, 4));
        let csv = to_csv(&s);
        // 4 metrics and 4 element-quality ones per group, plus the tree groups' branching factor.
        assert_eq!(csv.lines().count(), 1 + 8 + 4 * 9);
        assert!(csv.contains("m,selective,2,quality_pct,5,94,"), "{csv}");
    }
}
