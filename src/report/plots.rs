//! Box-and-whisker plots against horizon (the paper's Fig. 8), drawn with plotters' SVG backend:
//! medians as red lines, interquartile ranges as blue boxes, whiskers in black reaching the most
//! extreme values within 1.5 IQR of the box, outliers as red crosses. The time plot has a
//! logarithmic axis and the fitted growth line whose slope gives the branching factor.
//!
//! Each box is an SVG `<rect>` with `id="<prefix>box-h<H>"` (added after drawing, as plotters
//! has no element ids; the prefix keeps ids unique when figures share an HTML page), so tests
//! and readers can find and count them.

use super::ReportError;
use crate::stats::describe::{BoxStats, Growth};
use plotters::coord::Shift;
use plotters::coord::ranged1d::{AsRangedCoord, Ranged};
use plotters::prelude::*;

/// Fill colour of the IQR boxes (unique in the figure: ids are attached by it).
const BOX_FILL: RGBColor = RGBColor(70, 130, 220);
/// Box outline.
const BOX_EDGE: RGBColor = RGBColor(20, 60, 170);
/// Medians and outliers, as in the paper.
const RED: RGBColor = RGBColor(220, 20, 20);
/// Baseline lines (e.g. greedy's median).
const GREY: RGBColor = RGBColor(120, 120, 120);
/// The fitted growth line.
const GREEN: RGBColor = RGBColor(20, 140, 60);

/// Width and height of a box plot in pixels.
pub const SIZE: (u32, u32) = (640, 420);

/// One box: its horizon and the box-plot figures of its values.
#[derive(Debug, Clone)]
pub struct HorizonBox {
    /// Horizon (the x position).
    pub horizon: u32,
    /// Quartiles, whiskers and outliers.
    pub stats: BoxStats,
}

/// What to draw besides the boxes.
#[derive(Debug, Clone, Default)]
pub struct Extras {
    /// Horizontal reference lines: label and value (e.g. greedy's median).
    pub baselines: Vec<(String, f64)>,
    /// The fitted growth of the median with horizon (time plots).
    pub fit: Option<Growth>,
}

/// Draws the box plot of `boxes` (sorted by horizon) as an SVG document; box ids start with
/// `id_prefix`.
pub fn boxplot_svg(
    id_prefix: &str,
    title: &str,
    y_desc: &str,
    boxes: &[HorizonBox],
    log_y: bool,
    extras: &Extras,
) -> Result<String, ReportError> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(plot_err)?;
        let (hmin, hmax) = (
            boxes.iter().map(|b| b.horizon).min().unwrap_or(1),
            boxes.iter().map(|b| b.horizon).max().unwrap_or(1),
        );
        let x_range = (hmin as f64 - 0.6)..(hmax as f64 + 0.6);
        let (mut lo, mut hi) = value_range(boxes, extras);
        // Finite margins however large the values (a time of 1e308 made the log axis end at
        // infinity, and plotters looped forever over its decades).
        (lo, hi) = (lo.clamp(-1e300, 1e300), hi.clamp(-1e300, 1e300));
        if log_y {
            // Half a decade of margin on a log axis; time is positive.
            lo = (lo.max(1e-9)) / 1.5;
            hi = hi.max(lo * 10.0) * 1.5;
            let y = (lo..hi).log_scale();
            draw(&root, title, y_desc, x_range, y, boxes, extras, hmin, hmax)?;
        } else {
            let pad = ((hi - lo) * 0.08).max(1e-6 * hi.abs().max(1.0));
            draw(
                &root,
                title,
                y_desc,
                x_range,
                (lo - pad)..(hi + pad),
                boxes,
                extras,
                hmin,
                hmax,
            )?;
        }
        root.present().map_err(plot_err)?;
    }
    Ok(tag_boxes(&svg, boxes, id_prefix))
}

/// The smallest and largest value to show: whiskers, outliers, baselines.
fn value_range(boxes: &[HorizonBox], extras: &Extras) -> (f64, f64) {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for b in boxes {
        for v in b
            .stats
            .outliers
            .iter()
            .chain([&b.stats.whisker_low, &b.stats.whisker_high])
        {
            lo = lo.min(*v);
            hi = hi.max(*v);
        }
    }
    for (_, v) in &extras.baselines {
        lo = lo.min(*v);
        hi = hi.max(*v);
    }
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    (lo, hi)
}

#[allow(clippy::too_many_arguments)]
fn draw<Y>(
    root: &DrawingArea<SVGBackend<'_>, Shift>,
    title: &str,
    y_desc: &str,
    x_range: std::ops::Range<f64>,
    y_range: Y,
    boxes: &[HorizonBox],
    extras: &Extras,
    hmin: u32,
    hmax: u32,
) -> Result<(), ReportError>
where
    Y: AsRangedCoord<Value = f64>,
    Y::CoordDescType: Ranged<ValueType = f64> + plotters::coord::ranged1d::ValueFormatter<f64>,
{
    let mut chart = ChartBuilder::on(root)
        .caption(title, ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(64)
        .build_cartesian_2d(x_range, y_range)
        .map_err(plot_err)?;
    let n_labels = (hmax - hmin + 1) as usize;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .light_line_style(WHITE.mix(0.0))
        .bold_line_style(BLACK.mix(0.12))
        .x_labels(n_labels.clamp(2, 20) * 2 + 1)
        .x_label_formatter(&|x| {
            // Label only the integer horizons.
            if (x - x.round()).abs() < 1e-9 && x.round() >= hmin as f64 {
                format!("{}", x.round() as i64)
            } else {
                String::new()
            }
        })
        .y_label_formatter(&|y| format_tick(*y))
        .x_desc("horizon")
        .y_desc(y_desc)
        .draw()
        .map_err(plot_err)?;

    const HALF: f64 = 0.28;
    for b in boxes {
        let x = b.horizon as f64;
        let s = &b.stats;
        // Whiskers: vertical lines from the box to the whisker ends, with caps.
        for (from, to) in [(s.q1, s.whisker_low), (s.q3, s.whisker_high)] {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(x, from), (x, to)],
                    BLACK.stroke_width(1),
                )))
                .map_err(plot_err)?;
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(x - HALF / 2.0, to), (x + HALF / 2.0, to)],
                    BLACK.stroke_width(1),
                )))
                .map_err(plot_err)?;
        }
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [(x - HALF, s.q1), (x + HALF, s.q3)],
                BOX_FILL.mix(0.35).filled(),
            )))
            .map_err(plot_err)?;
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [(x - HALF, s.q1), (x + HALF, s.q3)],
                BOX_EDGE.stroke_width(1),
            )))
            .map_err(plot_err)?;
        chart
            .draw_series(std::iter::once(PathElement::new(
                vec![(x - HALF, s.median), (x + HALF, s.median)],
                RED.stroke_width(2),
            )))
            .map_err(plot_err)?;
        chart
            .draw_series(
                s.outliers
                    .iter()
                    .map(|&v| Cross::new((x, v), 4, RED.stroke_width(1))),
            )
            .map_err(plot_err)?;
    }
    let x0 = hmin as f64 - 0.5;
    let x1 = hmax as f64 + 0.5;
    for (label, v) in &extras.baselines {
        chart
            .draw_series(DashedLineSeries::new(
                vec![(x0, *v), (x1, *v)],
                6,
                4,
                GREY.stroke_width(1),
            ))
            .map_err(plot_err)?
            .label(format!("{label} (median)"))
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], GREY.stroke_width(1)));
    }
    if let Some(fit) = &extras.fit {
        let (a, b) = (fit.h_min as f64, fit.h_max as f64);
        let at = |h: f64| 10f64.powf(fit.fit.intercept + fit.fit.slope * h);
        chart
            .draw_series(DashedLineSeries::new(
                vec![(a, at(a)), (b, at(b))],
                6,
                4,
                GREEN.stroke_width(2),
            ))
            .map_err(plot_err)?
            .label(format!(
                "fit h={}..{}: alpha = {:.3}",
                fit.h_min, fit.h_max, fit.alpha
            ))
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], GREEN.stroke_width(2)));
    }
    if !extras.baselines.is_empty() || extras.fit.is_some() {
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.4))
            .label_font(("sans-serif", 12))
            .draw()
            .map_err(plot_err)?;
    }
    Ok(())
}

/// Tick label: up to 4 significant digits, no trailing zeros.
fn format_tick(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let mag = v.abs().log10().floor() as i32;
    let decimals = (3 - mag).clamp(0, 8) as usize;
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// Adds `id="<prefix>box-h<H>"` to each box's filled rectangle, in drawing order.
fn tag_boxes(svg: &str, boxes: &[HorizonBox], prefix: &str) -> String {
    let fill = format!(
        "fill=\"#{:02X}{:02X}{:02X}\"",
        BOX_FILL.0, BOX_FILL.1, BOX_FILL.2
    );
    let mut out = String::with_capacity(svg.len() + boxes.len() * 16);
    let mut rest = svg;
    let mut next = boxes.iter();
    while let Some(i) = rest.find("<rect ") {
        let end = rest[i..].find("/>").map_or(rest.len(), |e| i + e);
        out.push_str(&rest[..i]);
        out.push_str("<rect ");
        if rest[i..end].contains(&fill) {
            if let Some(b) = next.next() {
                out.push_str(&format!("id=\"{prefix}box-h{}\" ", b.horizon));
            }
        }
        rest = &rest[i + "<rect ".len()..];
    }
    out.push_str(rest);
    out
}

/// A plotters error as a report error.
pub(super) fn plot_err<E: std::error::Error + Send + Sync>(
    e: plotters::drawing::DrawingAreaErrorKind<E>,
) -> ReportError {
    ReportError::Plot(e.to_string())
}
