//! The critical-difference diagram (Demšar 2006, Fig. 1): methods placed on an axis of
//! average rank (1, the best, on the left), Nemenyi's critical difference drawn as a red
//! interval above it, and thick black bars joining the methods whose ranks differ by less than
//! it (no significant difference). Written as SVG by hand, in the box plots' fonts and size.
//!
//! Ids for tests and readers: `cd-axis`, `cd-bar` (the critical difference), `cd-clique-<j>`,
//! `cd-method-<i>` (the i-th method by average rank, from 0).

use super::document::escape;
use crate::stats::ranks::cliques;

/// Width of the figure in pixels (as the box plots).
const WIDTH: f64 = 640.0;
/// Where the rank axis starts and ends, leaving room for labels on both sides.
const AXIS: (f64, f64) = (190.0, 450.0);
/// Vertical position of the axis.
const AXIS_Y: f64 = 110.0;
/// Vertical spacing of the method rows and of the clique bars.
const ROW: f64 = 26.0;
const CLIQUE_ROW: f64 = 9.0;
/// The report's red (medians and outliers in the box plots).
const RED: &str = "#DC1414";

/// Draws the diagram of `methods` (label, average rank), with critical difference `cd` if
/// known (without it, no bar and no clique is drawn). At least two methods.
pub fn cd_svg(title: &str, methods: &[(String, f64)], cd: Option<f64>) -> String {
    let mut sorted: Vec<(String, f64)> = methods.to_vec();
    sorted.sort_by(|a, b| a.1.total_cmp(&b.1));
    let k = sorted.len().max(2);
    let x = |rank: f64| AXIS.0 + (rank - 1.0) / (k as f64 - 1.0) * (AXIS.1 - AXIS.0);
    let ranks: Vec<f64> = sorted.iter().map(|m| m.1).collect();
    let groups = cd.map_or(Vec::new(), |cd| cliques(&ranks, cd));
    let first_row = AXIS_Y + 18.0 + CLIQUE_ROW * groups.len() as f64 + 14.0;
    let left = sorted.len().div_ceil(2);
    let rows = left.max(sorted.len() - left);
    let height = first_row + ROW * rows as f64;
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{WIDTH}\" height=\"{height}\" \
         viewBox=\"0 0 {WIDTH} {height}\">\n<rect width=\"{WIDTH}\" height=\"{height}\" \
         fill=\"#FFFFFF\"/>\n"
    );
    s.push_str(&format!(
        "<text x=\"{}\" y=\"28\" font-family=\"sans-serif\" font-size=\"20\" \
         text-anchor=\"middle\">{}</text>\n",
        WIDTH / 2.0,
        escape(title)
    ));
    if let Some(cd) = cd {
        let (x0, x1) = (x(1.0), x(1.0 + cd).min(AXIS.1 + 150.0));
        s.push_str(&format!(
            "<g id=\"cd-bar\"><line x1=\"{x0:.1}\" y1=\"58\" x2=\"{x1:.1}\" y2=\"58\" \
             stroke=\"{RED}\" stroke-width=\"2\"/><line x1=\"{x0:.1}\" y1=\"52\" x2=\"{x0:.1}\" \
             y2=\"64\" stroke=\"{RED}\" stroke-width=\"2\"/><line x1=\"{x1:.1}\" y1=\"52\" \
             x2=\"{x1:.1}\" y2=\"64\" stroke=\"{RED}\" stroke-width=\"2\"/><text x=\"{:.1}\" \
             y=\"48\" font-family=\"sans-serif\" font-size=\"14\" text-anchor=\"middle\" \
             fill=\"{RED}\">CD = {cd:.2}</text></g>\n",
            (x0 + x1) / 2.0
        ));
    }
    // The axis, ticked at every whole rank.
    s.push_str(&format!(
        "<g id=\"cd-axis\"><line x1=\"{:.1}\" y1=\"{AXIS_Y}\" x2=\"{:.1}\" y2=\"{AXIS_Y}\" \
         stroke=\"#000000\" stroke-width=\"1.5\"/>",
        AXIS.0, AXIS.1
    ));
    for r in 1..=k {
        let xr = x(r as f64);
        s.push_str(&format!(
            "<line x1=\"{xr:.1}\" y1=\"{}\" x2=\"{xr:.1}\" y2=\"{AXIS_Y}\" stroke=\"#000000\" \
             stroke-width=\"1\"/><text x=\"{xr:.1}\" y=\"{}\" font-family=\"sans-serif\" \
             font-size=\"14\" text-anchor=\"middle\">{r}</text>",
            AXIS_Y - 6.0,
            AXIS_Y - 10.0
        ));
    }
    s.push_str("</g>\n");
    // Methods: the better half on the left, the worse half on the right (worst on top).
    for (i, (label, rank)) in sorted.iter().enumerate() {
        let (row, lx, anchor) = if i < left {
            (i, AXIS.0 - 20.0, "end")
        } else {
            (sorted.len() - 1 - i, AXIS.1 + 20.0, "start")
        };
        let y = first_row + ROW * row as f64;
        let xr = x(*rank);
        s.push_str(&format!(
            "<g id=\"cd-method-{i}\"><polyline points=\"{xr:.1},{AXIS_Y} {xr:.1},{y:.1} \
             {:.1},{y:.1}\" fill=\"none\" stroke=\"#000000\" stroke-width=\"1\"/><text \
             x=\"{:.1}\" y=\"{:.1}\" font-family=\"sans-serif\" font-size=\"14\" \
             text-anchor=\"{anchor}\">{} ({rank:.2})</text></g>\n",
            if anchor == "end" {
                lx + 15.0
            } else {
                lx - 15.0
            },
            lx,
            y + 5.0,
            escape(label)
        ));
    }
    for (j, &(a, b)) in groups.iter().enumerate() {
        let y = AXIS_Y + 14.0 + CLIQUE_ROW * j as f64;
        s.push_str(&format!(
            "<line id=\"cd-clique-{j}\" x1=\"{:.1}\" y1=\"{y:.1}\" x2=\"{:.1}\" y2=\"{y:.1}\" \
             stroke=\"#000000\" stroke-width=\"4\" stroke-linecap=\"round\"/>\n",
            x(ranks[a]) - 4.0,
            x(ranks[b]) + 4.0
        ));
    }
    s.push_str("</svg>\n");
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_row_per_method_and_a_bar_per_clique() {
        let methods: Vec<(String, f64)> = [("a", 1.2), ("b <&>", 1.9), ("c", 3.4), ("d", 3.5)]
            .iter()
            .map(|(l, r)| (l.to_string(), *r))
            .collect();
        let svg = cd_svg("t", &methods, Some(1.0));
        for i in 0..4 {
            assert!(svg.contains(&format!("id=\"cd-method-{i}\"")), "{svg}");
        }
        // {a, b} and {c, d}.
        assert!(
            svg.contains("cd-clique-1") && !svg.contains("cd-clique-2"),
            "{svg}"
        );
        assert!(svg.contains("b &lt;&amp;&gt; (1.90)"), "{svg}");
        assert!(svg.contains("CD = 1.00"));
        let none = cd_svg("t", &methods, None);
        assert!(!none.contains("cd-bar") && !none.contains("cd-clique"));
    }
}
