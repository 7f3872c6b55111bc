//! Interim descriptive numbers with the same API as the runner's `stats::describe` (type-7
//! quantiles, Tukey box plots, log10 growth fit), used until that module is merged.

/// Median (type 7); NaN when empty.
pub fn median(xs: &[f64]) -> f64 {
    if xs.is_empty() {
        return f64::NAN;
    }
    let mut s = xs.to_vec();
    s.sort_by(f64::total_cmp);
    quantile_sorted(&s, 0.5)
}

fn quantile_sorted(s: &[f64], p: f64) -> f64 {
    let h = (s.len() - 1) as f64 * p;
    let k = h.floor() as usize;
    if k + 1 >= s.len() {
        return s[s.len() - 1];
    }
    s[k] + (h - k as f64) * (s[k + 1] - s[k])
}

/// Box-plot figures of a sample.
#[derive(Debug, Clone, PartialEq)]
pub struct BoxStats {
    /// Observations.
    pub n: usize,
    /// First quartile.
    pub q1: f64,
    /// Median.
    pub median: f64,
    /// Third quartile.
    pub q3: f64,
    /// Lowest observation >= Q1 - 1.5 IQR.
    pub whisker_low: f64,
    /// Highest observation <= Q3 + 1.5 IQR.
    pub whisker_high: f64,
    /// Observations outside the whiskers.
    pub outliers: Vec<f64>,
}

impl BoxStats {
    /// Statistics of a sample; `None` when empty.
    pub fn of(xs: &[f64]) -> Option<BoxStats> {
        if xs.is_empty() {
            return None;
        }
        let mut s = xs.to_vec();
        s.sort_by(f64::total_cmp);
        let q1 = quantile_sorted(&s, 0.25);
        let median = quantile_sorted(&s, 0.5);
        let q3 = quantile_sorted(&s, 0.75);
        let iqr = q3 - q1;
        let (lo, hi) = (q1 - 1.5 * iqr, q3 + 1.5 * iqr);
        Some(BoxStats {
            n: s.len(),
            q1,
            median,
            q3,
            whisker_low: *s.iter().find(|&&x| x >= lo).expect("q1 >= lo"),
            whisker_high: *s.iter().rev().find(|&&x| x <= hi).expect("q3 <= hi"),
            outliers: s.iter().copied().filter(|&x| x < lo || x > hi).collect(),
        })
    }
}

/// A least-squares line.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearFit {
    /// Slope.
    pub slope: f64,
    /// Intercept.
    pub intercept: f64,
}

/// log10(time) = intercept + slope * h; alpha = 10^slope.
#[derive(Debug, Clone, PartialEq)]
pub struct Growth {
    /// The fit.
    pub fit: LinearFit,
    /// 10^slope.
    pub alpha: f64,
    /// Smallest horizon fitted.
    pub h_min: u32,
    /// Largest horizon fitted.
    pub h_max: u32,
}

/// Least squares of log10(time) on h over points with time > 0; `None` with fewer than two
/// distinct horizons.
pub fn growth_fit(points: &[(u32, f64)]) -> Option<Growth> {
    let pts: Vec<(f64, f64)> = points
        .iter()
        .filter(|(_, t)| *t > 0.0 && t.is_finite())
        .map(|&(h, t)| (f64::from(h), t.log10()))
        .collect();
    let n = pts.len() as f64;
    if pts.len() < 2 {
        return None;
    }
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / n;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    if sxx == 0.0 {
        return None;
    }
    let slope = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>() / sxx;
    Some(Growth {
        fit: LinearFit {
            slope,
            intercept: my - slope * mx,
        },
        alpha: 10f64.powf(slope),
        h_min: points.iter().map(|p| p.0).min()?,
        h_max: points.iter().map(|p| p.0).max()?,
    })
}
