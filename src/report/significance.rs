//! The report's statistical comparisons: families of pairwise comparisons (consecutive horizons,
//! each configuration against greedy, one directory against another), each family corrected
//! with Holm, and sentences that say which differences are significant and how large.

use super::format::{fmt_metric, fmt_p};
use super::results::{Config, Metric, Run};
use crate::stats::compare::{Comparison, Magnitude, adjust_family, compare};

/// The family-wise significance level.
pub const ALPHA: f64 = 0.05;

/// One comparison of a family: labels of both sides, the metric, the numbers.
#[derive(Debug, Clone)]
pub struct Pair {
    /// Label of the first sample (e.g. "selective h=2").
    pub first: String,
    /// Label of the second sample (e.g. "selective h=1").
    pub second: String,
    /// The measure compared.
    pub metric: Metric,
    /// Unit-bearing metric name for these runs.
    pub metric_name: &'static str,
    /// The statistics.
    pub cmp: Comparison,
}

impl Pair {
    /// Whether the difference is significant at [`ALPHA`] after Holm's correction.
    pub fn significant(&self) -> bool {
        self.cmp.p_holm < ALPHA
    }

    /// One sentence: medians, difference with its CI, significance, effect size.
    pub fn sentence(&self) -> String {
        let c = &self.cmp;
        let m = self.metric;
        let diff = c.median[0] - c.median[1];
        let ci = c.ci95.map_or(String::new(), |(lo, hi)| {
            format!(
                ", 95% CI [{}, {}]",
                fmt_metric(m, lo, true),
                fmt_metric(m, hi, true)
            )
        });
        let verdict = if self.significant() {
            "significant"
        } else {
            "not significant"
        };
        format!(
            "{} vs {}, {}: median {} vs {} (difference {}{}); {} at {} after Holm \
             ({}, p = {}, Holm p = {}); A = {:.2}, {} {}.",
            self.first,
            self.second,
            self.metric_name,
            fmt_metric(m, c.median[0], false),
            fmt_metric(m, c.median[1], false),
            fmt_metric(m, diff, true),
            ci,
            verdict,
            ALPHA,
            c.test.statistic(),
            fmt_p(c.test.p()),
            fmt_p(c.p_holm),
            c.a,
            Magnitude::of(c.a).name(),
            direction(m, c.a),
        )
    }

    /// A table row: comparison, metric, medians, difference and CI, U, p, Holm p, A, verdict.
    pub fn row(&self) -> Vec<String> {
        let c = &self.cmp;
        let m = self.metric;
        let ci = c.ci95.map_or("-".to_string(), |(lo, hi)| {
            format!("[{}, {}]", fmt_metric(m, lo, true), fmt_metric(m, hi, true))
        });
        vec![
            format!("{} vs {}", self.first, self.second),
            self.metric_name.to_string(),
            format!(
                "{} / {}",
                fmt_metric(m, c.median[0], false),
                fmt_metric(m, c.median[1], false)
            ),
            format!("{} {}", fmt_metric(m, c.median[0] - c.median[1], true), ci),
            c.test.statistic(),
            fmt_p(c.test.p()),
            fmt_p(c.p_holm),
            format!("{:.2} ({})", c.a, Magnitude::of(c.a).name()),
            if self.significant() { "yes" } else { "no" }.to_string(),
        ]
    }
}

/// Header of [`Pair::row`] tables.
pub fn header() -> Vec<String> {
    [
        "comparison",
        "measure",
        "medians",
        "median difference [95% CI]",
        "test statistic",
        "p",
        "Holm p",
        "A (effect)",
        "significant",
    ]
    .map(String::from)
    .to_vec()
}

/// Words for the direction of an effect A of the first sample over the second.
fn direction(m: Metric, a: f64) -> &'static str {
    if Magnitude::of(a) == Magnitude::Negligible {
        return "effect";
    }
    match (m, a > 0.5) {
        (Metric::Time, true) => "effect (first slower)",
        (Metric::Time, false) => "effect (first faster)",
        (_, true) => "effect (first higher)",
        (_, false) => "effect (first lower)",
    }
}

/// A difference shown as it is, without a test: a test needs a sample on each side.
#[derive(Debug, Clone)]
pub struct Untested {
    /// Label of the first side.
    pub first: String,
    /// Label of the second side.
    pub second: String,
    /// The medians of both sides.
    pub median: [f64; 2],
    /// Why it is not tested.
    pub why: &'static str,
}

/// Why a comparison of samples `x` and `y` of `metric` cannot be tested, if it cannot: two
/// single runs (two deterministic configurations: their difference is exact, there is nothing
/// to test), or a single timing on either side (one measurement on a loaded machine is no
/// exact value to test a sample against).
fn untestable(metric: Metric, x: usize, y: usize) -> Option<&'static str> {
    if x <= 1 && y <= 1 {
        Some("one run on each side, so the difference is exact and there is nothing to test")
    } else if metric == Metric::Time && (x <= 1 || y <= 1) {
        Some("one timing on one side, which is no exact value to test a sample of times against")
    } else {
        None
    }
}

/// A family of comparisons, Holm-corrected together.
#[derive(Debug, Clone)]
pub struct Family {
    /// What the family asks (e.g. "consecutive horizons, quality").
    pub title: String,
    /// The measure compared.
    pub metric: Metric,
    /// The comparisons tested (and corrected together).
    pub pairs: Vec<Pair>,
    /// Differences shown without a test, outside the Holm family.
    pub untested: Vec<Untested>,
}

impl Family {
    /// Builds a family from `(first label, first runs, second label, second runs)` and applies
    /// Holm's correction to the comparisons that can be tested (see [`Untested`]). The
    /// bootstrap of comparison `i` (counting all sides) is seeded with `seed + i`.
    pub fn build(
        title: String,
        metric: Metric,
        sides: Vec<(String, &[Run], String, &[Run])>,
        seed: u64,
    ) -> Family {
        let mut untested = Vec::new();
        let mut kept = Vec::new();
        for (i, (first, x, second, y)) in sides.into_iter().enumerate() {
            match untestable(metric, x.len(), y.len()) {
                Some(why) => untested.push(Untested {
                    median: [
                        crate::stats::describe::median(&metric.values(x)),
                        crate::stats::describe::median(&metric.values(y)),
                    ],
                    first,
                    second,
                    why,
                }),
                None => kept.push((i, (first, x, second, y))),
            }
        }
        let (index, sides): (Vec<usize>, Vec<_>) = kept.into_iter().unzip();
        let mut cmps: Vec<Comparison> = sides
            .iter()
            .zip(&index)
            .map(|((_, x, _, y), &i)| {
                compare(
                    &metric.values(x),
                    &metric.values(y),
                    seed.wrapping_add(i as u64),
                )
            })
            .collect();
        adjust_family(&mut cmps);
        let pairs = sides
            .into_iter()
            .zip(cmps)
            .map(|((first, x, second, y), cmp)| Pair {
                first,
                second,
                metric,
                metric_name: metric_name_of_both(metric, x, y),
                cmp,
            })
            .collect();
        Family {
            title,
            metric,
            pairs,
            untested,
        }
    }

    /// A summary sentence: how many differences are significant, and which; then the
    /// differences not tested, as they are.
    pub fn summary(&self) -> String {
        let mut out = self.tested_summary();
        for u in &self.untested {
            let m = self.metric;
            out.push_str(&format!(
                " Not tested: {} vs {}, median {} vs {} (difference {}): {}.",
                u.first,
                u.second,
                fmt_metric(m, u.median[0], false),
                fmt_metric(m, u.median[1], false),
                fmt_metric(m, u.median[0] - u.median[1], true),
                u.why
            ));
        }
        out
    }

    fn tested_summary(&self) -> String {
        let sig: Vec<&Pair> = self.pairs.iter().filter(|p| p.significant()).collect();
        let n = self.pairs.len();
        if n == 0 {
            return format!("{}: no difference to test.", self.title);
        }
        if sig.is_empty() {
            return format!(
                "{}: none of the {n} differences is significant at {ALPHA} after Holm's correction.",
                self.title
            );
        }
        let list: Vec<String> = sig
            .iter()
            .map(|p| {
                format!(
                    "{} vs {} ({} {}, A = {:.2})",
                    p.first,
                    p.second,
                    Magnitude::of(p.cmp.a).name(),
                    if p.cmp.direction().is_ge() {
                        "increase"
                    } else {
                        "decrease"
                    },
                    p.cmp.a
                )
            })
            .collect();
        format!(
            "{}: {} of {n} differences are significant at {ALPHA} after Holm's correction: {}.",
            self.title,
            sig.len(),
            list.join("; ")
        )
    }
}

/// The metric's name when both samples agree on whether quality is a percentage.
fn metric_name_of_both(metric: Metric, x: &[Run], y: &[Run]) -> &'static str {
    let a = metric.name(x);
    if a == metric.name(y) {
        a
    } else {
        metric.name(&[])
    }
}

/// Comparisons of consecutive horizons of each look-ahead algorithm of one mesh: one family per
/// metric.
pub fn consecutive_horizons(configs: &[(&Config, &[Run])], seed: u64) -> Vec<Family> {
    let mut sides_by_metric = Vec::new();
    for metric in Metric::ALL {
        let mut sides = Vec::new();
        for w in configs.windows(2) {
            let ((a, ra), (b, rb)) = (w[0], w[1]);
            if a.algo == b.algo && a.horizon.is_some() && b.horizon.is_some() {
                sides.push((b.label(), rb, a.label(), ra));
            }
        }
        if !sides.is_empty() {
            sides_by_metric.push(Family::build(
                format!("Consecutive horizons, {}", metric.key()),
                metric,
                sides,
                seed.wrapping_add(1000 * metric as u64),
            ));
        }
    }
    sides_by_metric
}

/// Each configuration of one mesh against greedy's runs: one family per metric (none without
/// greedy).
pub fn against_greedy(configs: &[(&Config, &[Run])], seed: u64) -> Vec<Family> {
    let Some((g, gr)) = configs.iter().find(|(c, _)| c.algo == "greedy") else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for metric in Metric::ALL {
        let sides: Vec<_> = configs
            .iter()
            .filter(|(c, _)| c.algo != "greedy" && c.algo != "optimum")
            .map(|(c, r)| (c.label(), *r, g.label(), *gr))
            .collect();
        if !sides.is_empty() {
            out.push(Family::build(
                format!("Against greedy, {}", metric.key()),
                metric,
                sides,
                seed.wrapping_add(5000 + 1000 * metric as u64),
            ));
        }
    }
    out
}
