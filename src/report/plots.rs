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

/// Height of one legend row above the plot, in pixels.
pub(super) const LEGEND_ROW: u32 = 24;
/// Height of the title above the legend.
pub(super) const TITLE: u32 = 38;

/// One legend row: the colour of its dashed line sample, and the text.
struct LegendEntry {
    color: RGBColor,
    text: String,
}

/// Draws the box plot of `boxes` (sorted by horizon) as an SVG document; box ids start with
/// `id_prefix`.
///
/// The title and the legend sit above the plot, never over the boxes. The value axis spans
/// the boxes, whiskers and outliers (and the fitted line): a baseline outside that range is not
/// drawn, so that it cannot squeeze the boxes into lines; its legend entry gives its value and
/// says on which side of the axis it lies.
pub fn boxplot_svg(
    id_prefix: &str,
    title: &str,
    y_desc: &str,
    boxes: &[HorizonBox],
    log_y: bool,
    extras: &Extras,
) -> Result<String, ReportError> {
    let (hmin, hmax) = (
        boxes.iter().map(|b| b.horizon).min().unwrap_or(1),
        boxes.iter().map(|b| b.horizon).max().unwrap_or(1),
    );
    let x_range = (hmin as f64 - 0.6)..(hmax as f64 + 0.6);
    let (mut lo, mut hi) = value_range(boxes, extras);
    // Finite margins however large the values (a time of 1e308 made the log axis end at
    // infinity, and plotters looped forever over its decades).
    (lo, hi) = (lo.clamp(-1e300, 1e300), hi.clamp(-1e300, 1e300));
    let (y_lo, y_hi) = if log_y {
        // A fifth of a decade of margin on a log axis; time is positive.
        let lo = lo.max(1e-9) / 1.6;
        (lo, hi.max(lo * 10.0) * 1.6)
    } else {
        let pad = ((hi - lo) * 0.08).max(1e-6 * hi.abs().max(1.0));
        (lo - pad, hi + pad)
    };
    let mut legend = Vec::new();
    for (label, v) in &extras.baselines {
        let side = if *v < y_lo {
            ", below the axis"
        } else if *v > y_hi {
            ", above the axis"
        } else {
            ""
        };
        legend.push(LegendEntry {
            color: GREY,
            text: format!("{label} (median): {}{side}", format_tick(*v)),
        });
    }
    if let Some(fit) = &extras.fit {
        legend.push(LegendEntry {
            color: GREEN,
            text: format!(
                "fit h={}..{}: alpha = {:.3}",
                fit.h_min, fit.h_max, fit.alpha
            ),
        });
    }
    let top = TITLE + LEGEND_ROW * legend.len() as u32 + if legend.is_empty() { 0 } else { 6 };
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (SIZE.0, SIZE.1 + top)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_err)?;
        let (head, body) = root.split_vertically(top);
        draw_head(&head, title, &legend)?;
        let frame = Frame {
            y_desc,
            boxes,
            extras,
            hmin,
            hmax,
            y_range: (y_lo, y_hi),
        };
        if log_y {
            let y = (y_lo..y_hi)
                .log_scale()
                .with_key_points(log_ticks(y_lo, y_hi));
            draw(&body, x_range, y, &frame)?;
        } else {
            draw(&body, x_range, y_lo..y_hi, &frame)?;
        }
        root.present().map_err(plot_err)?;
    }
    Ok(tag_boxes(&svg, boxes, id_prefix))
}

/// Ticks of a log axis over `[lo, hi]`: 1, 2 and 5 times the powers of ten, or only the powers
/// when the axis spans more than three decades.
pub(super) fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let decades = (hi / lo).log10();
    let steps: &[f64] = if decades > 3.0 {
        &[1.0]
    } else {
        &[1.0, 2.0, 5.0]
    };
    let mut out = Vec::new();
    let mut p = 10f64.powi(lo.log10().floor() as i32);
    while p <= hi {
        out.extend(
            steps
                .iter()
                .map(|s| s * p)
                .filter(|v| (lo..=hi).contains(v)),
        );
        p *= 10.0;
    }
    out
}

/// The title, centred, and the legend rows under it.
fn draw_head(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    title: &str,
    legend: &[LegendEntry],
) -> Result<(), ReportError> {
    let (w, _) = area.dim_in_pixel();
    let style = TextStyle::from(("sans-serif", 22).into_font()).pos(
        plotters::style::text_anchor::Pos::new(
            plotters::style::text_anchor::HPos::Center,
            plotters::style::text_anchor::VPos::Top,
        ),
    );
    area.draw(&Text::new(title.to_string(), (w as i32 / 2, 8), style))
        .map_err(plot_err)?;
    let x = 90i32;
    for (i, e) in legend.iter().enumerate() {
        let y = (TITLE + LEGEND_ROW * i as u32 + LEGEND_ROW / 2) as i32;
        // Three dashes, as the lines they stand for are drawn.
        for k in 0..3 {
            let a = x + k * 10;
            area.draw(&PathElement::new(
                vec![(a, y), (a + 6, y)],
                e.color.stroke_width(2),
            ))
            .map_err(plot_err)?;
        }
        area.draw(&Text::new(
            e.text.clone(),
            (x + 36, y - 8),
            ("sans-serif", 18).into_font(),
        ))
        .map_err(plot_err)?;
    }
    Ok(())
}

/// The smallest and largest value the axis must show: whiskers, outliers and the fitted line
/// (baselines are left out: see [`boxplot_svg`]).
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
    if let Some(fit) = &extras.fit {
        for h in [fit.h_min, fit.h_max] {
            let v = 10f64.powf(fit.fit.intercept + fit.fit.slope * h as f64);
            if v.is_finite() {
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
    }
    if !lo.is_finite() {
        // No boxes: show the baselines alone.
        for (_, v) in &extras.baselines {
            lo = lo.min(*v);
            hi = hi.max(*v);
        }
    }
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    (lo, hi)
}

/// What one plot shows, besides its coordinates.
struct Frame<'a> {
    y_desc: &'a str,
    boxes: &'a [HorizonBox],
    extras: &'a Extras,
    hmin: u32,
    hmax: u32,
    y_range: (f64, f64),
}

fn draw<Y>(
    root: &DrawingArea<SVGBackend<'_>, Shift>,
    x_range: std::ops::Range<f64>,
    y_range: Y,
    f: &Frame<'_>,
) -> Result<(), ReportError>
where
    Y: AsRangedCoord<Value = f64>,
    Y::CoordDescType: Ranged<ValueType = f64> + plotters::coord::ranged1d::ValueFormatter<f64>,
{
    let (hmin, hmax) = (f.hmin, f.hmax);
    let mut chart = ChartBuilder::on(root)
        .margin(12)
        .margin_top(4)
        .x_label_area_size(48)
        .y_label_area_size(84)
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
        .label_style(("sans-serif", 18))
        .axis_desc_style(("sans-serif", 19))
        .x_desc("horizon")
        .y_desc(f.y_desc)
        .draw()
        .map_err(plot_err)?;
    const HALF: f64 = 0.28;
    for b in f.boxes {
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
    let (y_lo, y_hi) = f.y_range;
    for (_, v) in &f.extras.baselines {
        if (y_lo..=y_hi).contains(v) {
            chart
                .draw_series(DashedLineSeries::new(
                    vec![(x0, *v), (x1, *v)],
                    6,
                    4,
                    GREY.stroke_width(2),
                ))
                .map_err(plot_err)?;
        }
    }
    if let Some(fit) = &f.extras.fit {
        let (a, b) = (fit.h_min as f64, fit.h_max as f64);
        let at = |h: f64| 10f64.powf(fit.fit.intercept + fit.fit.slope * h);
        chart
            .draw_series(DashedLineSeries::new(
                vec![(a, at(a)), (b, at(b))],
                6,
                4,
                GREEN.stroke_width(2),
            ))
            .map_err(plot_err)?;
    }
    Ok(())
}

/// Tick label: up to 4 significant digits, no trailing zeros.
pub(super) fn format_tick(v: f64) -> String {
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
        if rest[i..end].contains(&fill)
            && let Some(b) = next.next()
        {
            out.push_str(&format!("id=\"{prefix}box-h{}\" ", b.horizon));
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

#[cfg(test)]
mod tests {
    use super::*;

    fn boxes(values: &[&[f64]]) -> Vec<HorizonBox> {
        (values.iter().enumerate())
            .map(|(i, v)| HorizonBox {
                horizon: i as u32 + 1,
                stats: BoxStats::of(v).unwrap(),
            })
            .collect()
    }

    /// The `height` of the rectangle with `id`.
    fn rect_height(svg: &str, id: &str) -> f64 {
        let at = svg.find(&format!("id=\"{id}\"")).expect("box id");
        let rect = &svg[at..at + svg[at..].find("/>").unwrap()];
        let h = &rect[rect.find("height=\"").unwrap() + 8..];
        h[..h.find('"').unwrap()].parse().unwrap()
    }

    #[test]
    fn a_far_baseline_does_not_squeeze_the_boxes() {
        let b = boxes(&[
            &[96.0, 96.2, 96.4, 96.6, 96.8],
            &[96.5, 96.7, 96.9, 97.1, 97.3],
        ]);
        let far = Extras {
            baselines: vec![("greedy".into(), 50.0)],
            fit: None,
        };
        let svg = boxplot_svg("", "t", "quality", &b, false, &far).unwrap();
        assert!(svg.contains("greedy (median): 50, below the axis"), "{svg}");
        // The IQR of 0.4 over a value axis of about 1.6: a quarter of the plot's height, not
        // the few pixels it got when the axis reached down to the baseline.
        assert!(rect_height(&svg, "box-h1") > 40.0, "{svg}");
        let near = Extras {
            baselines: vec![("greedy".into(), 96.5)],
            fit: None,
        };
        let svg = boxplot_svg("", "t", "quality", &b, false, &near).unwrap();
        assert!(svg.contains("greedy (median): 96.5\n"));
        assert!(!svg.contains("the axis"));
    }

    #[test]
    fn the_legend_sits_above_the_plot_with_a_dashed_sample() {
        let b = boxes(&[&[1.0, 2.0, 3.0]]);
        let e = Extras {
            baselines: vec![("greedy".into(), 2.0)],
            fit: None,
        };
        let svg = boxplot_svg("", "t", "y", &b, false, &e).unwrap();
        // The legend's text is above every box (smaller y), and its sample is three dashes.
        let text_y = {
            let at = svg.find("\ngreedy (median)").unwrap();
            let open = svg[..at].rfind("<text").unwrap();
            let y = &svg[open..at];
            let y = &y[y.find(" y=\"").unwrap() + 4..];
            y[..y.find('"').unwrap()].parse::<f64>().unwrap()
        };
        let box_y = {
            let at = svg.find("id=\"box-h1\"").unwrap();
            let y = &svg[at..];
            let y = &y[y.find(" y=\"").unwrap() + 4..];
            y[..y.find('"').unwrap()].parse::<f64>().unwrap()
        };
        assert!(text_y < box_y, "legend at y {text_y}, box at {box_y}");
        // The grey segments drawn above the plot (the legend's sample): three short dashes,
        // not one solid line.
        let grey = format!("stroke=\"#{:02X}{:02X}{:02X}\"", GREY.0, GREY.1, GREY.2);
        let sample: Vec<(f64, f64)> = (svg.split("<polyline").skip(1))
            .filter(|p| p[..p.find("/>").unwrap()].contains(&grey))
            .filter_map(|p| {
                let pts = &p[p.find("points=\"").unwrap() + 8..];
                let xy: Vec<f64> = pts[..pts.find('"').unwrap()]
                    .split([' ', ','])
                    .filter(|v| !v.is_empty())
                    .map(|v| v.parse().unwrap())
                    .collect();
                (xy[1] < box_y && xy[3] < box_y).then(|| (xy[0], xy[2]))
            })
            .collect();
        assert_eq!(sample.len(), 3, "legend sample {sample:?}");
        assert!(sample.iter().all(|(a, b)| b - a <= 8.0), "{sample:?}");
        // Text large enough to print: at least 13 px at the figure's 640 px width.
        for size in svg.split("font-size=\"").skip(1) {
            let px: f64 = size[..size.find('"').unwrap()].parse().unwrap();
            assert!(px >= 13.0, "font of {px} px");
        }
    }

    #[test]
    fn log_axis_ticks_every_1_2_5() {
        assert_eq!(log_ticks(0.023, 0.6), vec![0.05, 0.1, 0.2, 0.5]);
        assert_eq!(log_ticks(0.009, 0.11), vec![0.01, 0.02, 0.05, 0.1]);
        assert_eq!(
            log_ticks(1e-4, 10.0),
            vec![1e-4, 1e-3, 0.01, 0.1, 1.0, 10.0]
        );
        let b = boxes(&[&[0.03, 0.04, 0.05], &[0.2, 0.3, 0.4]]);
        let svg = boxplot_svg("", "t", "time (s)", &b, true, &Extras::default()).unwrap();
        for label in ["\n0.05\n", "\n0.1\n", "\n0.2\n"] {
            assert!(svg.contains(label), "no tick {label}");
        }
    }
}
