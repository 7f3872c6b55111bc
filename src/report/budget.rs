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
    algo: String,
    nodes: f64,
    time: f64,
    q: [f64; 3],
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
        algo: c.algo.clone(),
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
             one line per method (selective: one point per horizon; the others one per \
             budget); dots at the medians, bars from the first to the third quartile."
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

/// Colours of the lines, by method (in order of appearance).
const COLORS: [RGBColor; 6] = [
    RGBColor(220, 20, 20),
    RGBColor(20, 60, 170),
    RGBColor(20, 140, 60),
    RGBColor(150, 60, 170),
    RGBColor(230, 130, 0),
    RGBColor(90, 90, 90),
];

/// The figure: one line per method through its configurations' medians, IQR bars.
fn figure(mesh: &str, name: &str, points: &[Point]) -> Result<String, ReportError> {
    let mut algos: Vec<&str> = points.iter().map(|p| p.algo.as_str()).collect();
    algos.sort_unstable();
    algos.dedup();
    let lines: Vec<Line> = (algos.iter())
        .map(|algo| {
            let mut mine: Vec<&Point> = points.iter().filter(|p| p.algo == *algo).collect();
            mine.sort_by(|a, b| a.nodes.total_cmp(&b.nodes));
            let pts = mine.iter().map(|p| (p.nodes.max(1.0), p.q)).collect();
            (algo.to_string(), pts)
        })
        .collect();
    lines_figure(
        &format!("{mesh}: quality against budget"),
        "tree nodes expanded per decision (median)",
        name,
        &lines,
        &COLORS,
    )
}

/// One line of a quality-against-budget figure: its label and its points in drawing order,
/// each `(x, [q1, median, q3])`.
pub(super) type Line = (String, Vec<(f64, [f64; 3])>);

/// Quality against a budget on a log x axis: one coloured line of medians per [`Line`], with
/// its points and interquartile bars (the node-budget and the time-budget figures).
pub(super) fn lines_figure(
    title: &str,
    x_desc: &str,
    name: &str,
    lines: &[Line],
    colors: &[RGBColor],
) -> Result<String, ReportError> {
    let points = || lines.iter().flat_map(|(_, pts)| pts.iter());
    let xs = points().map(|p| p.0);
    let (xmin, xmax) = xs.fold((f64::INFINITY, 0.0f64), |(a, b), x| (a.min(x), b.max(x)));
    let ys = points().flat_map(|p| [p.1[0], p.1[2]]);
    let (ymin, ymax) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), y| {
        (a.min(y), b.max(y))
    });
    let pad = ((ymax - ymin) * 0.08).max(1e-3);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, super::plots::SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(plot_err)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(
                ((xmin / 1.5)..(xmax * 1.5)).log_scale(),
                (ymin - pad)..(ymax + pad),
            )
            .map_err(plot_err)?;
        chart
            .configure_mesh()
            .x_desc(x_desc)
            .y_desc(name)
            .draw()
            .map_err(plot_err)?;
        for (i, (label, pts)) in lines.iter().enumerate() {
            let color = colors[i % colors.len()];
            chart
                .draw_series(LineSeries::new(
                    pts.iter().map(|&(x, q)| (x, q[1])),
                    color.stroke_width(2),
                ))
                .map_err(plot_err)?
                .label(label.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], color));
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
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .position(SeriesLabelPosition::LowerRight)
            .draw()
            .map_err(plot_err)?;
        root.present().map_err(plot_err)?;
    }
    Ok(svg)
}
