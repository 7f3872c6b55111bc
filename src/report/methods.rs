//! The "Methods" section: how the box plots, tests, effect sizes, intervals and growth fits
//! were computed.

use super::{Document, significance};

/// How the statistics were computed.
pub(super) fn method_notes(doc: &mut Document) {
    doc.heading(2, "Methods");
    doc.list(vec![
        "Box plots: quartiles interpolate linearly between order statistics (type 7); whiskers \
         reach the most extreme run within 1.5 IQR of the box; runs beyond are outliers."
            .to_string(),
        format!(
            "Differences between two sets of runs: two-sided Mann–Whitney U test (exact \
             distribution when the smaller sample has at most {} runs and there are no ties, \
             otherwise the normal approximation with tie and continuity corrections). Against a \
             configuration run once (a deterministic baseline such as greedy with one baseline \
             run), one value is not a sample to rank against: the other side is tested against \
             that value with the two-sided Wilcoxon signed-rank test (T+; exact for at most {} \
             differences without ties or zeros, otherwise normal with tie and continuity \
             corrections). p-values of one family (one question, one measure) are corrected \
             with Holm's step-down method; significant means Holm p < {}.",
            crate::stats::compare::EXACT_MAX_SIZE,
            crate::stats::compare::EXACT_MAX_SIGNED_RANK,
            significance::ALPHA
        ),
        "Effect size: Vargha–Delaney A = P(first > second) + P(equal)/2; |A - 0.5| of at least \
         0.06, 0.14, 0.21 (A = 0.56, 0.64, 0.71) is a small, medium, large effect."
            .to_string(),
        format!(
            "Median difference: 95% percentile bootstrap interval from {} seeded resamples \
             (ChaCha8).",
            crate::stats::compare::BOOTSTRAP_RESAMPLES
        ),
        "Branching factor of the time plots: least-squares slope of log10(median time) over \
         the upper half of the horizons; alpha = 10^slope, the growth factor per horizon of \
         the paper's n alpha^h complexity."
            .to_string(),
    ]);
}
