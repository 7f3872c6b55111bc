//! The summary's statistics of a configuration, as the sections read them: the report takes
//! medians, box statistics and growth fits from [`crate::experiment::summary`] (what
//! `summary.json` holds), computed once per report, rather than from the runs again.

use super::{Config, Metric, Run};
use crate::experiment::summary::{Group, GrowthEntry, Summary};
use crate::stats::describe::BoxStats;

/// The summary's group of configuration `c`: its raw runs.
fn group<'s>(summary: &'s Summary, c: &Config) -> Option<&'s Group> {
    finished_or_raw(summary, c, false)
}

/// The summary's group of the runs of `c` after their finish (`sweep --finish`), if any.
pub(super) fn finished_group<'s>(summary: &'s Summary, c: &Config) -> Option<&'s Group> {
    finished_or_raw(summary, c, true)
}

fn finished_or_raw<'s>(summary: &'s Summary, c: &Config, finished: bool) -> Option<&'s Group> {
    (summary.groups.iter()).find(|g| {
        g.mesh == c.mesh
            && g.algo == c.algo
            && g.horizon == c.horizon
            && g.budget == c.budget
            && g.time_budget_s == c.time_budget
            && g.finished == finished
    })
}

/// The median of a summarized field of `c`, when every run of `c` has it.
pub(super) fn median_of(
    summary: &Summary,
    c: &Config,
    field: fn(&Group) -> Option<&BoxStats>,
) -> Option<f64> {
    let g = group(summary, c)?;
    field(g).filter(|b| b.n == g.n).map(|b| b.median)
}

/// The box statistics of `metric` over `runs`, the runs of `c`: the summary's, except for
/// quality when some run has no percentage of the optimum (the measure is then the raw
/// quality, which the summary does not hold).
pub(super) fn metric_stats(
    summary: &Summary,
    c: &Config,
    runs: &[Run],
    metric: Metric,
) -> Option<BoxStats> {
    let field: fn(&Group) -> Option<&BoxStats> = match metric {
        Metric::Quality => |g| g.quality_pct.as_ref(),
        Metric::Recombined => |g| g.recombined_pct.as_ref(),
        Metric::Time => |g| g.time_s.as_ref(),
    };
    let summarized = group(summary, c).and_then(|g| field(g).filter(|b| b.n == g.n));
    match summarized {
        Some(b) => Some(b.clone()),
        None => BoxStats::of(&metric.values(runs)),
    }
}

/// The median of `metric` over `runs`, the runs of `c` (see [`metric_stats`]).
pub(super) fn metric_median(summary: &Summary, c: &Config, runs: &[Run], metric: Metric) -> f64 {
    metric_stats(summary, c, runs, metric).map_or(f64::NAN, |b| b.median)
}

/// The growth of time with horizon of `algo` on `mesh`.
pub(super) fn growth<'s>(summary: &'s Summary, mesh: &str, algo: &str) -> Option<&'s GrowthEntry> {
    (summary.growth.iter()).find(|g| g.mesh == mesh && g.algo == algo)
}
