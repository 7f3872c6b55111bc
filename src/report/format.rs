//! Number formats of the report's tables and sentences.

use super::results::Metric;

/// A value of `metric`: percentages with 2 decimals, times with 3 significant digits;
/// `signed` adds a `+` to positive values (differences).
pub fn fmt_metric(metric: Metric, v: f64, signed: bool) -> String {
    let s = match metric {
        Metric::Quality | Metric::Recombined => format!("{v:.2}"),
        Metric::Time => fmt_sig(v, 3),
    };
    if signed && v > 0.0 {
        format!("+{s}")
    } else {
        s
    }
}

/// `v` with `digits` significant digits, without exponent for usual magnitudes.
pub fn fmt_sig(v: f64, digits: i32) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let mag = v.abs().log10().floor() as i32;
    if !(-5..=8).contains(&mag) {
        return format!("{:.*e}", (digits - 1) as usize, v);
    }
    let decimals = (digits - 1 - mag).max(0) as usize;
    format!("{v:.decimals$}")
}

/// A p-value: 3 significant digits, "< 1e-16" below double precision's reach.
pub fn fmt_p(p: f64) -> String {
    if p < 1e-16 {
        "< 1e-16".to_string()
    } else if p < 1e-3 {
        format!("{p:.2e}")
    } else {
        format!("{p:.3}")
    }
}

/// An optional percentage or "–".
pub fn fmt_opt(v: Option<f64>, decimals: usize) -> String {
    v.map_or("–".to_string(), |v| format!("{v:.decimals$}"))
}

/// A median of counts as `13` or `13.5`, or `–` when none.
pub fn fmt_count(v: Option<f64>) -> String {
    v.map_or("–".to_string(), |v| format!("{v}"))
}

/// File-name-safe form of a mesh name: its [`slug`] when that is the name itself, else the
/// slug and 8 hex digits of the name's hash (`a b` and `a-b` both gave `a-b`, and their
/// figures overwrote each other).
pub(super) fn mesh_slug(mesh: &str) -> String {
    let s = slug(mesh);
    if s == mesh {
        s
    } else {
        let h = blake3::hash(mesh.as_bytes()).to_hex();
        format!("{s}-{}", &h[..8])
    }
}

/// File-name-safe form of a label.
pub(super) fn slug(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '-'
            }
        })
        .collect::<String>()
        .split('-')
        .filter(|p| !p.is_empty())
        .collect::<Vec<_>>()
        .join("-")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats() {
        assert_eq!(fmt_sig(0.012345, 3), "0.0123");
        assert_eq!(fmt_sig(225.6, 3), "226");
        assert_eq!(fmt_sig(1.5, 3), "1.50");
        assert_eq!(fmt_metric(Metric::Quality, 1.234, true), "+1.23");
        assert_eq!(fmt_metric(Metric::Quality, -1.234, true), "-1.23");
        assert_eq!(fmt_p(0.0123), "0.012");
        assert_eq!(fmt_p(2.3e-11), "2.30e-11");
    }
}
