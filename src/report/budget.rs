//! "Quality against budget": for the methods with a node budget per decision (optimistic,
//! mcts, beam) and the selective tree beside them, the median and interquartile range of the
//! quality against the measured cost (median tree nodes expanded per decision, and median
//! time per run), one figure per mesh; and each budgeted configuration against the selective
//! horizon of the nearest median time at or above its own (the matched cost), Mann-Whitney
//! with Holm, A12 and bootstrap interval as the report's other comparisons. With time
//! budgets (`sweep --time-budgets`): per time budget and method, the knob its calibration
//! chose, the median time measured against the budget and the quality, one figure, and each
//! policy against selective at the same time budget.

use super::ReportError;
use super::document::Document;
use super::format::fmt_sig;
use super::plots::plot_err;
use super::results::{Config, Metric, Run};
use super::significance::Family;
use crate::experiment::summary::Summary;
use crate::stats::describe::{median, quantile};
use plotters::prelude::*;

/// Per configuration: median nodes per decision, median time, and quality q1 / median / q3.
struct Point {
    label: String,
    /// The figure's line it is on: the method, and the horizon for a budgeted one.
    line: String,
    nodes: f64,
    time: f64,
    q: [f64; 3],
}

/// The line of a quality-against-budget figure that `c` is on: one per method, and per
/// horizon for a budgeted method (its budget is the x axis; a change of horizon is another
/// line, not a step along it).
pub(super) fn line_of(c: &Config) -> String {
    match c.budget {
        Some(_) => format!("{} h={}", c.algo, c.horizon.unwrap_or(0)),
        None => c.algo.clone(),
    }
}

fn point(c: &Config, runs: &[Run]) -> Point {
    let q = Metric::Quality.values(runs);
    let nodes: Vec<f64> = runs
        .iter()
        .map(|r| r.nodes_expanded.unwrap_or(0) as f64 / r.decisions.max(1) as f64)
        .collect();
    let time: Vec<f64> = runs.iter().map(|r| r.time_s).collect();
    Point {
        label: c.label(),
        line: line_of(c),
        nodes: median(&nodes),
        time: median(&time),
        q: [quantile(&q, 0.25), median(&q), quantile(&q, 0.75)],
    }
}

/// Appends the section for `mesh` when it has budgeted configurations.
pub(super) fn budget_section(
    doc: &mut Document,
    _summary: &Summary,
    mesh: &str,
    configs: &[(&Config, &[Run])],
    seed: u64,
) -> Result<(), ReportError> {
    let timed = configs.iter().any(|(c, _)| c.time_budget.is_some());
    let nodes = (configs.iter()).any(|(c, _)| c.budget.is_some() && c.time_budget.is_none());
    if !timed && !nodes {
        return Ok(());
    }
    doc.heading(3, "Quality against budget");
    if nodes {
        node_budgets(doc, mesh, configs, seed)?;
    }
    if timed {
        super::time_budget::time_budgets(doc, mesh, configs, seed)?;
    }
    Ok(())
}

/// The node budgets: table, figure and the comparison at matched time.
fn node_budgets(
    doc: &mut Document,
    mesh: &str,
    configs: &[(&Config, &[Run])],
    seed: u64,
) -> Result<(), ReportError> {
    let shown: Vec<(&Config, &[Run])> = (configs.iter().copied())
        .filter(|(c, _)| c.time_budget.is_none())
        .filter(|(c, _)| c.budget.is_some() || c.algo == "selective")
        .collect();
    let points: Vec<Point> = shown.iter().map(|(c, r)| point(c, r)).collect();
    let name = Metric::Quality.name(shown[0].1);
    doc.table(
        [
            "configuration",
            "runs",
            "nodes / decision",
            "time (s)",
            "q1",
            "median",
            "q3",
        ]
        .map(String::from)
        .to_vec(),
        (points.iter().zip(&shown))
            .map(|(p, (_, r))| {
                vec![
                    p.label.clone(),
                    r.len().to_string(),
                    fmt_sig(p.nodes, 3),
                    fmt_sig(p.time, 3),
                    format!("{:.3}", p.q[0]),
                    format!("{:.3}", p.q[1]),
                    format!("{:.3}", p.q[2]),
                ]
            })
            .collect(),
    );
    let svg = figure(mesh, name, &points)?;
    doc.figure(
        format!(
            "{}/{}-budget.svg",
            super::FIGURES_DIR,
            super::format::mesh_slug(mesh)
        ),
        svg,
        format!(
            "{mesh}: {name} against the median tree nodes expanded per decision (log axis), \
             one line per method and horizon for the budgeted methods (one point per budget), \
             one line for selective (one point per horizon); dots at the medians, bars from \
             the first to the third quartile."
        ),
    );
    // Each budgeted configuration against the cheapest selective horizon at least as slow.
    let selective: Vec<(&Config, &[Run], f64)> = (shown.iter())
        .zip(&points)
        .filter(|((c, _), _)| c.algo == "selective")
        .map(|((c, r), p)| (*c, *r, p.time))
        .collect();
    let mut sides = Vec::new();
    for ((c, r), p) in shown.iter().zip(&points) {
        if c.budget.is_none() {
            continue;
        }
        let matched = (selective.iter())
            .filter(|(_, _, t)| *t >= p.time)
            .min_by(|a, b| a.2.total_cmp(&b.2))
            .or_else(|| selective.iter().max_by(|a, b| a.2.total_cmp(&b.2)));
        if let Some((s, sr, _)) = matched {
            sides.push((c.label(), *r, s.label(), *sr));
        }
    }
    if sides.is_empty() {
        doc.para("No selective runs on this mesh to compare the budgeted methods with.");
        return Ok(());
    }
    doc.para(
        "Each budgeted configuration against the selective horizon whose median time is the \
         smallest at or above its own (the largest when none is): a budgeted method that wins \
         there wins at no more than selective's time.",
    );
    let family = Family::build(
        "Budgeted methods against selective at matched time, quality".into(),
        Metric::Quality,
        sides,
        seed.wrapping_add(9000),
    );
    super::mesh_section::family_blocks(doc, &[family]);
    Ok(())
}

/// Colours of the lines, in the order of their labels (methods, and horizons of the
/// budgeted ones): selective and three policies at three horizons fit.
pub(super) const COLORS: [RGBColor; 12] = [
    RGBColor(220, 20, 20),
    RGBColor(20, 60, 170),
    RGBColor(20, 140, 60),
    RGBColor(150, 60, 170),
    RGBColor(230, 130, 0),
    RGBColor(90, 90, 90),
    RGBColor(0, 170, 190),
    RGBColor(170, 110, 40),
    RGBColor(240, 120, 170),
    RGBColor(120, 170, 30),
    RGBColor(0, 0, 0),
    RGBColor(100, 150, 230),
];

/// The figure: one line per method (and horizon, for the budgeted ones) through its
/// configurations' medians, IQR bars.
fn figure(mesh: &str, name: &str, points: &[Point]) -> Result<String, ReportError> {
    let mut labels: Vec<&str> = points.iter().map(|p| p.line.as_str()).collect();
    labels.sort_unstable();
    labels.dedup();
    let lines: Vec<Line> = (labels.iter())
        .map(|label| {
            let mut mine: Vec<&Point> = points.iter().filter(|p| p.line == *label).collect();
            mine.sort_by(|a, b| a.nodes.total_cmp(&b.nodes));
            let pts = mine.iter().map(|p| (p.nodes.max(1.0), p.q)).collect();
            (label.to_string(), pts)
        })
        .collect();
    lines_figure(
        &format!("{mesh}: quality against budget"),
        "tree nodes expanded per decision (median)",
        name,
        &lines,
    )
}

/// One line of a quality-against-budget figure: its label and its points in drawing order,
/// each `(x, [q1, median, q3])`.
pub(super) type Line = (String, Vec<(f64, [f64; 3])>);

/// Ticks of the log x axis over `[lo, hi]`: 1, 2 and 5 times the powers of ten, or every
/// digit times them where that gives fewer than two, or the ends themselves.
fn x_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let ticks = super::plots::log_ticks(lo, hi);
    if ticks.len() >= 2 {
        return ticks;
    }
    let mut out = Vec::new();
    let mut p = 10f64.powi(lo.log10().floor() as i32);
    while p <= hi {
        out.extend(
            (1..10)
                .map(|d| d as f64 * p)
                .filter(|v| (lo..=hi).contains(v)),
        );
        p *= 10.0;
    }
    if out.len() >= 2 { out } else { vec![lo, hi] }
}

/// Quality against a budget on a log x axis: one coloured line of medians per [`Line`] (in
/// the colours of [`COLORS`]), with its points and interquartile bars (the node-budget and
/// the time-budget figures). The title and the legend (two columns) sit above the plot,
/// never over the data; the x axis is labelled at [`x_ticks`].
pub(super) fn lines_figure(
    title: &str,
    x_desc: &str,
    name: &str,
    lines: &[Line],
) -> Result<String, ReportError> {
    use super::plots::{LEGEND_ROW, SIZE, TITLE, format_tick};
    let points = || lines.iter().flat_map(|(_, pts)| pts.iter());
    let xs = points().map(|p| p.0);
    let (xmin, xmax) = xs.fold((f64::INFINITY, 0.0f64), |(a, b), x| (a.min(x), b.max(x)));
    let ys = points().flat_map(|p| [p.1[0], p.1[2]]);
    let (ymin, ymax) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), y| {
        (a.min(y), b.max(y))
    });
    let pad = ((ymax - ymin) * 0.08).max(1e-3);
    let (x_lo, x_hi) = (xmin / 1.25, xmax * 1.25);
    let color = |i: usize| COLORS[i % COLORS.len()];
    let rows = lines.len().div_ceil(2) as u32;
    let top = TITLE + LEGEND_ROW * rows + 6;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (SIZE.0, SIZE.1 + top)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_err)?;
        let (head, body) = root.split_vertically(top);
        let (w, _) = head.dim_in_pixel();
        let centred = TextStyle::from(("sans-serif", 20).into_font()).pos(
            plotters::style::text_anchor::Pos::new(
                plotters::style::text_anchor::HPos::Center,
                plotters::style::text_anchor::VPos::Top,
            ),
        );
        head.draw(&Text::new(title.to_string(), (w as i32 / 2, 8), centred))
            .map_err(plot_err)?;
        for (i, (label, _)) in lines.iter().enumerate() {
            let x = 80 + (i % 2) as i32 * (w as i32 - 80) / 2;
            let y = (TITLE + LEGEND_ROW * (i / 2) as u32 + LEGEND_ROW / 2) as i32;
            head.draw(&PathElement::new(
                vec![(x, y), (x + 24, y)],
                color(i).stroke_width(2),
            ))
            .map_err(plot_err)?;
            head.draw(&Circle::new((x + 12, y), 3, color(i).filled()))
                .map_err(plot_err)?;
            head.draw(&Text::new(
                label.clone(),
                (x + 32, y - 8),
                ("sans-serif", 16).into_font(),
            ))
            .map_err(plot_err)?;
        }
        let mut chart = ChartBuilder::on(&body)
            .margin(12)
            .margin_top(4)
            .x_label_area_size(44)
            .y_label_area_size(64)
            .build_cartesian_2d(
                (x_lo..x_hi)
                    .log_scale()
                    .with_key_points(x_ticks(x_lo, x_hi)),
                (ymin - pad)..(ymax + pad),
            )
            .map_err(plot_err)?;
        chart
            .configure_mesh()
            .light_line_style(WHITE.mix(0.0))
            .bold_line_style(BLACK.mix(0.12))
            .x_label_formatter(&|x| format_tick(*x))
            .x_desc(x_desc)
            .y_desc(name)
            .draw()
            .map_err(plot_err)?;
        for (i, (_, pts)) in lines.iter().enumerate() {
            let color = color(i);
            chart
                .draw_series(LineSeries::new(
                    pts.iter().map(|&(x, q)| (x, q[1])),
                    color.stroke_width(2),
                ))
                .map_err(plot_err)?;
            chart
                .draw_series(pts.iter().map(|&(x, q)| {
                    PathElement::new(vec![(x, q[0]), (x, q[2])], color.stroke_width(1))
                }))
                .map_err(plot_err)?;
            chart
                .draw_series(
                    pts.iter()
                        .map(|&(x, q)| Circle::new((x, q[1]), 3, color.filled())),
                )
                .map_err(plot_err)?;
        }
        root.present().map_err(plot_err)?;
    }
    Ok(svg)
}
