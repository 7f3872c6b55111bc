//! Descriptive statistics: quantiles, box-plot figures, mean and deviation, growth fits.
//!
//! Conventions, stated once:
//! - Quantiles interpolate linearly between order statistics (Hyndman & Fan type 7, the
//!   default of R and NumPy): for sorted x_1..x_n, Q(p) = x_k + (h - k)(x_{k+1} - x_k) with
//!   h = (n - 1) p + 1 and k = floor(h).
//! - Box plots follow Tukey: the box spans Q1..Q3; each whisker reaches the most extreme
//!   observation within 1.5 IQR of its quartile; observations beyond are outliers.
//! - The standard deviation is the sample one (divisor n - 1); 0 for a single observation.
//! - Growth with horizon: least squares of log10(time) against h; alpha = 10^slope is the
//!   per-level factor of the paper's n * alpha^h model.

use serde::{Deserialize, Serialize};

/// Arithmetic mean; NaN for an empty sample.
pub fn mean(xs: &[f64]) -> f64 {
    xs.iter().sum::<f64>() / xs.len() as f64
}

/// Sample standard deviation (divisor n - 1); 0 for one observation, NaN for none.
pub fn sd(xs: &[f64]) -> f64 {
    match xs.len() {
        0 => f64::NAN,
        1 => 0.0,
        n => {
            let m = mean(xs);
            (xs.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n - 1) as f64).sqrt()
        }
    }
}

/// Quantile p in [0, 1] of an ascending-sorted sample, type 7 (see the module docs).
///
/// # Panics
/// If the sample is empty or p is outside [0, 1].
pub fn quantile_sorted(sorted: &[f64], p: f64) -> f64 {
    assert!(!sorted.is_empty(), "quantile of an empty sample");
    assert!(
        (0.0..=1.0).contains(&p),
        "quantile probability {p} outside [0, 1]"
    );
    let h = (sorted.len() - 1) as f64 * p;
    let k = h.floor() as usize;
    if k + 1 >= sorted.len() {
        return sorted[sorted.len() - 1];
    }
    sorted[k] + (h - k as f64) * (sorted[k + 1] - sorted[k])
}

/// Quantile p of an unsorted sample (type 7); NaN values must not occur.
pub fn quantile(xs: &[f64], p: f64) -> f64 {
    quantile_sorted(&sorted(xs), p)
}

/// The median (type 7: the mean of the two middle values for even n).
pub fn median(xs: &[f64]) -> f64 {
    quantile(xs, 0.5)
}

fn sorted(xs: &[f64]) -> Vec<f64> {
    let mut v = xs.to_vec();
    v.sort_by(f64::total_cmp);
    v
}

/// Everything a box-and-whisker plot and a summary table need about one sample.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BoxStats {
    /// Observations.
    pub n: usize,
    /// Mean.
    pub mean: f64,
    /// Sample standard deviation.
    pub sd: f64,
    /// Smallest observation.
    pub min: f64,
    /// First quartile (type 7).
    pub q1: f64,
    /// Median.
    pub median: f64,
    /// Third quartile.
    pub q3: f64,
    /// Largest observation.
    pub max: f64,
    /// Q3 - Q1.
    pub iqr: f64,
    /// Lowest observation >= Q1 - 1.5 IQR.
    pub whisker_low: f64,
    /// Highest observation <= Q3 + 1.5 IQR.
    pub whisker_high: f64,
    /// Observations outside the whiskers, ascending.
    pub outliers: Vec<f64>,
}

impl BoxStats {
    /// Statistics of a sample; `None` when it is empty. Non-finite values are a caller bug.
    pub fn of(xs: &[f64]) -> Option<BoxStats> {
        if xs.is_empty() {
            return None;
        }
        debug_assert!(xs.iter().all(|x| x.is_finite()), "non-finite sample value");
        let s = sorted(xs);
        let q1 = quantile_sorted(&s, 0.25);
        let median = quantile_sorted(&s, 0.5);
        let q3 = quantile_sorted(&s, 0.75);
        let iqr = q3 - q1;
        let (lo, hi) = (q1 - 1.5 * iqr, q3 + 1.5 * iqr);
        let whisker_low = *s.iter().find(|&&x| x >= lo).expect("q1 itself is >= lo");
        let whisker_high = *s
            .iter()
            .rev()
            .find(|&&x| x <= hi)
            .expect("q3 itself is <= hi");
        let outliers = s.iter().copied().filter(|&x| x < lo || x > hi).collect();
        Some(BoxStats {
            n: s.len(),
            mean: mean(&s),
            sd: sd(&s),
            min: s[0],
            q1,
            median,
            q3,
            max: s[s.len() - 1],
            iqr,
            whisker_low,
            whisker_high,
            outliers,
        })
    }
}

/// A least-squares line y = intercept + slope * x.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LinearFit {
    /// Slope.
    pub slope: f64,
    /// Intercept.
    pub intercept: f64,
    /// Coefficient of determination (1 when all y are equal and fitted exactly).
    pub r2: f64,
    /// Points fitted.
    pub n: usize,
}

/// Ordinary least squares of y on x; `None` with fewer than two distinct x.
pub fn linear_fit(xs: &[f64], ys: &[f64]) -> Option<LinearFit> {
    assert_eq!(xs.len(), ys.len(), "linear_fit: x and y lengths differ");
    let n = xs.len();
    if n < 2 {
        return None;
    }
    let (mx, my) = (mean(xs), mean(ys));
    let sxx: f64 = xs.iter().map(|x| (x - mx) * (x - mx)).sum();
    if sxx == 0.0 {
        return None;
    }
    let sxy: f64 = xs.iter().zip(ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    let syy: f64 = ys.iter().map(|y| (y - my) * (y - my)).sum();
    let slope = sxy / sxx;
    let intercept = my - slope * mx;
    let sse: f64 = xs
        .iter()
        .zip(ys)
        .map(|(x, y)| (y - intercept - slope * x).powi(2))
        .sum();
    let r2 = if syy == 0.0 { 1.0 } else { 1.0 - sse / syy };
    Some(LinearFit {
        slope,
        intercept,
        r2,
        n,
    })
}

/// Growth of run time with horizon: log10(time) = intercept + slope * h, alpha = 10^slope.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Growth {
    /// The fit of log10(time) against h.
    pub fit: LinearFit,
    /// 10^slope: the factor time grows by per extra level of look-ahead.
    pub alpha: f64,
    /// Smallest horizon fitted.
    pub h_min: u32,
    /// Largest horizon fitted.
    pub h_max: u32,
}

/// Fits log10(time) against horizon over (horizon, time) points with time > 0; `None` with
/// fewer than two distinct horizons.
pub fn growth_fit(points: &[(u32, f64)]) -> Option<Growth> {
    let pts: Vec<(f64, f64)> = points
        .iter()
        .filter(|(_, t)| *t > 0.0 && t.is_finite())
        .map(|&(h, t)| (f64::from(h), t.log10()))
        .collect();
    let xs: Vec<f64> = pts.iter().map(|p| p.0).collect();
    let ys: Vec<f64> = pts.iter().map(|p| p.1).collect();
    let fit = linear_fit(&xs, &ys)?;
    let h_min = points.iter().map(|p| p.0).min()?;
    let h_max = points.iter().map(|p| p.0).max()?;
    Some(Growth {
        alpha: 10f64.powf(fit.slope),
        fit,
        h_min,
        h_max,
    })
}

/// Effective branching factor of a tree of depth `depth` that expands `nodes` nodes per
/// decision: the b >= 0 with b + b^2 + ... + b^depth = nodes (Russell & Norvig's definition,
/// counting the nodes below the root). `None` for depth 0 or a negative/non-finite count.
pub fn effective_branching_factor(nodes: f64, depth: u32) -> Option<f64> {
    if depth == 0 || !nodes.is_finite() || nodes < 0.0 {
        return None;
    }
    let total = |b: f64| (1..=depth).map(|l| b.powi(l as i32)).sum::<f64>();
    // total is increasing in b >= 0 and total(max(nodes, 1)) >= nodes.
    let (mut lo, mut hi) = (0.0f64, nodes.max(1.0));
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if total(mid) < nodes {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= 1e-12 * hi.max(1.0) {
            break;
        }
    }
    Some(0.5 * (lo + hi))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-9 * b.abs().max(1.0)
    }

    #[test]
    fn quantiles_match_r_type_7() {
        // R: quantile(c(1,2,3,4,5,6,7,8,9,10)) -> 1.00 3.25 5.50 7.75 10.00
        let xs: Vec<f64> = (1..=10).map(f64::from).collect();
        assert!(close(quantile(&xs, 0.25), 3.25));
        assert!(close(quantile(&xs, 0.5), 5.5));
        assert!(close(quantile(&xs, 0.75), 7.75));
        assert!(close(quantile(&xs, 0.0), 1.0));
        assert!(close(quantile(&xs, 1.0), 10.0));
        // R: quantile(c(7, 15, 36, 39, 40, 41)) -> 7.00 20.25 37.50 39.75 41.00
        let ys = [41.0, 7.0, 39.0, 15.0, 40.0, 36.0];
        assert!(close(quantile(&ys, 0.25), 20.25));
        assert!(close(median(&ys), 37.5));
        assert!(close(quantile(&ys, 0.75), 39.75));
        assert!(close(quantile(&ys, 0.1), 11.0));
        assert!(close(median(&[3.0]), 3.0));
    }

    #[test]
    fn mean_and_sd_textbook() {
        // The classic example: 2 4 4 4 5 5 7 9 has mean 5, population sd 2, sample sd sqrt(32/7).
        let xs = [2.0, 4.0, 4.0, 4.0, 5.0, 5.0, 7.0, 9.0];
        assert!(close(mean(&xs), 5.0));
        assert!(close(sd(&xs), (32.0f64 / 7.0).sqrt()));
        assert_eq!(sd(&[1.0]), 0.0);
        assert!(sd(&[]).is_nan());
    }

    #[test]
    fn box_stats_whiskers_and_outliers() {
        let mut xs: Vec<f64> = (1..=10).map(f64::from).collect();
        xs.push(30.0);
        xs.push(-20.0);
        let b = BoxStats::of(&xs).unwrap();
        // Sorted: -20, 1..10, 30. Type 7: Q1 at h = 11 * 0.25 = 2.75 -> 2 + 0.75 * (3 - 2);
        // Q3 = 8.25, IQR = 5.5, fences -5.5 and 16.5.
        assert!(close(b.q1, 2.75));
        assert!(close(b.q3, 8.25));
        assert!(close(b.median, 5.5));
        assert!(close(b.iqr, 5.5));
        assert_eq!(b.whisker_low, 1.0);
        assert_eq!(b.whisker_high, 10.0);
        assert_eq!(b.outliers, vec![-20.0, 30.0]);
        assert_eq!(b.n, 12);
        assert_eq!((b.min, b.max), (-20.0, 30.0));
        assert!(BoxStats::of(&[]).is_none());
        let one = BoxStats::of(&[4.0]).unwrap();
        assert_eq!((one.whisker_low, one.whisker_high), (4.0, 4.0));
        assert!(one.outliers.is_empty());
    }

    #[test]
    fn linear_fit_exact_and_noisy() {
        let f = linear_fit(&[1.0, 2.0, 3.0], &[3.0, 5.0, 7.0]).unwrap();
        assert!(close(f.slope, 2.0) && close(f.intercept, 1.0) && close(f.r2, 1.0));
        // Textbook: x = 1..5, y = 2,4,5,4,5 -> slope 0.6, intercept 2.2, r^2 = 0.6.
        let f = linear_fit(&[1.0, 2.0, 3.0, 4.0, 5.0], &[2.0, 4.0, 5.0, 4.0, 5.0]).unwrap();
        assert!(close(f.slope, 0.6) && close(f.intercept, 2.2) && close(f.r2, 0.6));
        assert!(linear_fit(&[1.0, 1.0], &[1.0, 2.0]).is_none());
    }

    #[test]
    fn growth_recovers_alpha() {
        // time = 0.01 * 1.33^h exactly.
        let pts: Vec<(u32, f64)> = (1..=10)
            .map(|h| (h, 0.01 * 1.33f64.powi(h as i32)))
            .collect();
        let g = growth_fit(&pts).unwrap();
        assert!(close(g.alpha, 1.33));
        assert!(close(g.fit.intercept, 0.01f64.log10()));
        assert_eq!((g.h_min, g.h_max), (1, 10));
        assert!(growth_fit(&[(3, 1.0), (3, 2.0)]).is_none());
    }

    #[test]
    fn branching_factor_inverts_tree_size() {
        // Binary tree of depth 3: 2 + 4 + 8 = 14 nodes.
        assert!((effective_branching_factor(14.0, 3).unwrap() - 2.0).abs() < 1e-9);
        assert!((effective_branching_factor(3.0, 1).unwrap() - 3.0).abs() < 1e-9);
        // 1 + 1 + 1 + 1 = 4 nodes at depth 4: b = 1.
        assert!((effective_branching_factor(4.0, 4).unwrap() - 1.0).abs() < 1e-9);
        assert!(effective_branching_factor(0.0, 2).unwrap().abs() < 1e-9);
        assert!(effective_branching_factor(5.0, 0).is_none());
    }
}
