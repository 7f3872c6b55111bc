//! Mesh pictures like the paper's Figs. 4, 6 and 7: a recombined mesh with quads coloured by
//! their quality eta (viridis, with a colour bar), leftover triangles highlighted in red, and an
//! optional zoom window. Planar meshes are drawn in their own x–y coordinates; surfaces in 3D
//! are drawn in an orthographic view with back faces culled (closed surfaces; open ones are
//! drawn back to front).
//!
//! Each quad and leftover triangle is one SVG `<polygon>` with its outline as the polygon's
//! stroke, at sub-pixel coordinates (two decimals), so a picture of `q` visible quads and `l`
//! visible leftovers has `q + l` polygons (plus those of the inset, when there is one). Axes,
//! caption and colour bar are drawn by plotters; the faces are written after them in one group.

use super::ReportError;
use super::plots::plot_err;
use crate::mesh::{Mesh, Recombined};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

/// Colour of leftover (unrecombined) triangles.
pub const LEFTOVER: RGBColor = RGBColor(230, 30, 30);

/// How to draw a mesh picture.
#[derive(Debug, Clone)]
pub struct PictureOptions {
    /// Caption above the picture.
    pub title: String,
    /// Window `[x0, y0, x1, y1]` in the picture's coordinates (the mesh's x–y for planar
    /// meshes, the view plane's for surfaces) to zoom into; `None` for the whole mesh.
    pub zoom: Option<[f64; 4]>,
    /// Width of the mesh drawing in pixels (the colour bar is added to it).
    pub width: u32,
    /// Add a magnified inset of the densest region below the picture (its window marked on
    /// the picture), where the smallest elements are; ignored with a zoom.
    pub inset: bool,
}

impl Default for PictureOptions {
    fn default() -> Self {
        PictureOptions {
            title: String::new(),
            zoom: None,
            width: 720,
            inset: false,
        }
    }
}

/// What a picture shows, for captions and tests.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PictureCounts {
    /// Quads drawn.
    pub quads: usize,
    /// Leftover triangles drawn.
    pub leftover: usize,
    /// Faces culled as back-facing.
    pub culled: usize,
    /// The inset's window `[x0, y0, x1, y1]` and the quads and leftovers drawn in it.
    pub inset: Option<([f64; 4], usize, usize)>,
}

/// The viridis colour of `t` in `[0, 1]` (piecewise linear between nine reference colours).
pub fn viridis(t: f64) -> RGBColor {
    const STOPS: [(u8, u8, u8); 9] = [
        (68, 1, 84),
        (71, 44, 122),
        (59, 81, 139),
        (44, 113, 142),
        (33, 144, 141),
        (39, 173, 129),
        (92, 200, 99),
        (170, 220, 50),
        (253, 231, 37),
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let pos = t * (STOPS.len() - 1) as f64;
    let i = (pos.floor() as usize).min(STOPS.len() - 2);
    let f = pos - i as f64;
    let lerp = |a: u8, b: u8| (a as f64 + (b as f64 - a as f64) * f).round() as u8;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    RGBColor(lerp(a.0, b.0), lerp(a.1, b.1), lerp(a.2, b.2))
}

/// A face to draw: projected polygon, depth (larger is nearer) and colour.
struct Face {
    points: Vec<(f64, f64)>,
    depth: f64,
    color: RGBColor,
    leftover: bool,
}

/// The projection of a mesh to the picture plane.
struct View {
    /// True when the mesh lies in a plane z = const (drawn as is, nothing culled).
    planar: bool,
    right: [f64; 3],
    up: [f64; 3],
    toward_viewer: [f64; 3],
    /// +1 when the mesh's orientation points outward (closed surface), -1 inward, 0 unknown
    /// (open surface: nothing culled).
    outward: f64,
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn normalize(a: [f64; 3]) -> [f64; 3] {
    let n = dot(a, a).sqrt();
    [a[0] / n, a[1] / n, a[2] / n]
}

impl View {
    fn of(mesh: &Mesh) -> View {
        let z0 = mesh.vertices.first().map_or(0.0, |v| v[2]);
        let extent = mesh
            .vertices
            .iter()
            .flat_map(|v| v.iter())
            .fold(0.0f64, |m, c| m.max(c.abs()))
            .max(1e-300);
        let planar = mesh
            .vertices
            .iter()
            .all(|v| (v[2] - z0).abs() <= 1e-12 * extent);
        if planar {
            return View {
                planar,
                right: [1.0, 0.0, 0.0],
                up: [0.0, 1.0, 0.0],
                toward_viewer: [0.0, 0.0, 1.0],
                outward: 0.0,
            };
        }
        // A three-quarter view from above: camera toward (1, -1.4, 1.1), z up on screen.
        let toward_viewer = normalize([1.0, -1.4, 1.1]);
        let right = normalize(cross([0.0, 0.0, 1.0], toward_viewer));
        let up = cross(toward_viewer, right);
        // A closed surface (no boundary edge) has a signed volume whose sign says whether the
        // consistent orientation points outward.
        let closed = mesh.topology.num_boundary_edges == 0;
        let outward = if closed {
            let vol: f64 = mesh
                .triangles
                .iter()
                .map(|t| {
                    let [a, b, c] = t.map(|v| mesh.vertices[v as usize]);
                    dot(a, cross(b, c))
                })
                .sum();
            if vol >= 0.0 { 1.0 } else { -1.0 }
        } else {
            0.0
        };
        View {
            planar,
            right,
            up,
            toward_viewer,
            outward,
        }
    }

    fn project(&self, p: [f64; 3]) -> (f64, f64) {
        (dot(p, self.right), dot(p, self.up))
    }

    /// Depth of a face and whether it faces away from the viewer (and is culled).
    fn depth_and_back(&self, pts: &[[f64; 3]]) -> (f64, bool) {
        let depth = pts.iter().map(|&p| dot(p, self.toward_viewer)).sum::<f64>() / pts.len() as f64;
        if self.planar || self.outward == 0.0 {
            return (depth, false);
        }
        // Newell's normal, valid for any simple polygon.
        let mut n = [0.0; 3];
        for i in 0..pts.len() {
            let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
            n = [
                n[0] + (a[1] - b[1]) * (a[2] + b[2]),
                n[1] + (a[2] - b[2]) * (a[0] + b[0]),
                n[2] + (a[0] - b[0]) * (a[1] + b[1]),
            ];
        }
        (depth, self.outward * dot(n, self.toward_viewer) <= 0.0)
    }
}

/// Draws `rec` (quads and leftover triangles of `mesh`) as an SVG document.
pub fn mesh_svg(
    mesh: &Mesh,
    rec: &Recombined,
    opts: &PictureOptions,
) -> Result<(String, PictureCounts), ReportError> {
    let view = View::of(mesh);
    let mut faces: Vec<Face> = Vec::with_capacity(rec.quads.len() + rec.leftover.len());
    let mut counts = PictureCounts {
        quads: 0,
        leftover: 0,
        culled: 0,
        inset: None,
    };
    let mut add = |pts: Vec<[f64; 3]>, color: RGBColor, leftover: bool| {
        let (depth, back) = view.depth_and_back(&pts);
        if back {
            counts.culled += 1;
            return;
        }
        faces.push(Face {
            points: pts.iter().map(|&p| view.project(p)).collect(),
            depth,
            color,
            leftover,
        });
    };
    for (i, q) in rec.quads.iter().enumerate() {
        let eta = rec.quad_eta.get(i).copied().unwrap_or(0.0);
        add(
            q.iter().map(|&v| mesh.vertices[v as usize]).collect(),
            viridis(eta),
            false,
        );
    }
    for &t in &rec.leftover {
        add(mesh.triangle_points(t).to_vec(), LEFTOVER, true);
    }
    // Window: the zoom, or the bounding box of what is drawn.
    let window = match opts.zoom {
        Some([x0, y0, x1, y1]) => [x0.min(x1), y0.min(y1), x0.max(x1), y0.max(y1)],
        None => {
            let mut w = [
                f64::INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::NEG_INFINITY,
            ];
            for f in &faces {
                for &(x, y) in &f.points {
                    w = [w[0].min(x), w[1].min(y), w[2].max(x), w[3].max(y)];
                }
            }
            if !w[0].is_finite() {
                w = [0.0, 0.0, 1.0, 1.0];
            }
            w
        }
    };
    let drawn = clip_faces(&faces, window);
    counts.quads = drawn.iter().filter(|f| !f.leftover).count();
    counts.leftover = drawn.iter().filter(|f| f.leftover).count();
    let inset = (opts.inset && opts.zoom.is_none())
        .then(|| densest_window(&drawn, window))
        .flatten();
    let inset_faces = inset.map(|w| clip_faces(&faces, w));
    if let (Some(w), Some(f)) = (inset, &inset_faces) {
        let quads = f.iter().filter(|f| !f.leftover).count();
        counts.inset = Some((w, quads, f.len() - quads));
    }

    const Y_LABELS: u32 = 72;
    const X_LABELS: u32 = 44;
    const CAPTION: u32 = 38;
    const BAR: u32 = 120;
    let plot_w = opts.width.max(200) - Y_LABELS - 20;
    let aspect = |w: [f64; 4]| (w[3] - w[1]).max(1e-300) / (w[2] - w[0]).max(1e-300);
    let plot_h = ((plot_w as f64 * aspect(window)).round() as u32).clamp(120, 4 * plot_w);
    let main_h = plot_h + X_LABELS + CAPTION + 20;
    let inset_h = inset.map_or(0, |w| {
        ((plot_w as f64 * aspect(w)).round() as u32).clamp(120, 4 * plot_w)
            + X_LABELS
            + CAPTION
            + 20
    });
    let height = main_h + inset_h;
    let width = opts.width.max(200) + BAR;

    let mut svg = String::new();
    // Pixel mappings of the panels, known once plotters has laid them out.
    let mut panels: Vec<(Mapping, &[Face])> = Vec::new();
    {
        let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_err)?;
        let (pictures, bar) = root.split_horizontally(width - BAR);
        let (main, below) = pictures.split_vertically(main_h);
        let frame = |area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
                     title: &str,
                     w: [f64; 4]|
         -> Result<Mapping, ReportError> {
            let chart = ChartBuilder::on(area)
                .caption(title, ("sans-serif", 22))
                .margin(10)
                .x_label_area_size(X_LABELS)
                .y_label_area_size(Y_LABELS)
                .build_cartesian_2d(w[0]..w[2], w[1]..w[3])
                .map_err(plot_err)?;
            let mut chart = chart;
            chart
                .configure_mesh()
                .disable_mesh()
                .x_labels(6)
                .y_labels(6)
                .label_style(("sans-serif", 17))
                .axis_desc_style(("sans-serif", 18))
                .x_desc(if view.planar { "x" } else { "view x" })
                .y_desc(if view.planar { "y" } else { "view y" })
                .draw()
                .map_err(plot_err)?;
            Ok(Mapping::of(&chart, w))
        };
        let main_map = frame(&main, &opts.title, window)?;
        if let Some(w) = inset {
            let title = format!("{} (inset: the densest region)", opts.title);
            let inset_map = frame(&below, title.trim_start(), w)?;
            panels.push((main_map, &drawn));
            panels.push((inset_map, inset_faces.as_deref().unwrap_or(&[])));
        } else {
            panels.push((main_map, &drawn));
        }
        draw_colour_bar(&bar, main_h)?;
        root.present().map_err(plot_err)?;
    }
    let mut faces_svg = String::new();
    for (map, faces) in &panels {
        write_faces(&mut faces_svg, map, faces);
    }
    // The inset's window, framed on the picture above its faces.
    if let (Some(w), Some((map, _))) = (inset, panels.first()) {
        let (a, b) = (map.pixel((w[0], w[3])), map.pixel((w[2], w[1])));
        faces_svg.push_str(&format!(
            r##"<rect x="{:.2}" y="{:.2}" width="{:.2}" height="{:.2}" fill="none" stroke="#E61E1E" stroke-width="2"/>"##,
            a.0.min(b.0),
            a.1.min(b.1),
            (b.0 - a.0).abs(),
            (b.1 - a.1).abs()
        ));
    }
    let end = svg.rfind("</svg>").unwrap_or(svg.len());
    svg.insert_str(end, &faces_svg);
    Ok((svg, counts))
}

/// The faces of `faces` clipped to `window` (plotters does not clip), without those that fall
/// outside or only touch the window's border (a clipped polygon of zero area), back to front.
fn clip_faces(faces: &[Face], window: [f64; 4]) -> Vec<Face> {
    let min_area = 1e-12 * (window[2] - window[0]).abs() * (window[3] - window[1]).abs();
    let mut drawn: Vec<Face> = faces
        .iter()
        .filter_map(|f| {
            let points = clip_to_window(&f.points, window);
            (points.len() >= 3 && polygon_area(&points) > min_area).then_some(Face {
                points,
                depth: f.depth,
                color: f.color,
                leftover: f.leftover,
            })
        })
        .collect();
    drawn.sort_by(|a, b| a.depth.total_cmp(&b.depth));
    drawn
}

/// The window of the inset: a box of a sixth of the picture's width (half as high), centred
/// on the cell of a 24 x 24 grid over `window` that holds the most face centroids, and kept
/// inside `window`. `None` when there is nothing to magnify (fewer than 200 faces).
fn densest_window(faces: &[Face], window: [f64; 4]) -> Option<[f64; 4]> {
    const GRID: usize = 24;
    if faces.len() < 200 {
        return None;
    }
    let (dx, dy) = (window[2] - window[0], window[3] - window[1]);
    if dx <= 0.0 || dy <= 0.0 {
        return None;
    }
    let mut count = vec![0u32; GRID * GRID];
    let cell = |v: f64, lo: f64, d: f64| (((v - lo) / d * GRID as f64) as usize).min(GRID - 1);
    for f in faces {
        let n = f.points.len() as f64;
        let cx = f.points.iter().map(|p| p.0).sum::<f64>() / n;
        let cy = f.points.iter().map(|p| p.1).sum::<f64>() / n;
        count[cell(cy, window[1], dy) * GRID + cell(cx, window[0], dx)] += 1;
    }
    // The first densest cell in row-major order, for a deterministic choice.
    let best = (0..count.len()).max_by_key(|&i| (count[i], std::cmp::Reverse(i)))?;
    let centre = (
        window[0] + ((best % GRID) as f64 + 0.5) * dx / GRID as f64,
        window[1] + ((best / GRID) as f64 + 0.5) * dy / GRID as f64,
    );
    let (w, h) = (dx / 6.0, (dx / 12.0).min(dy));
    let x0 = (centre.0 - w / 2.0).clamp(window[0], window[2] - w);
    let y0 = (centre.1 - h / 2.0).clamp(window[1], window[3] - h);
    Some([x0, y0, x0 + w, y0 + h])
}

/// How picture coordinates map to the SVG's pixels in one panel: linearly, through the pixels
/// plotters gives the window's corners.
struct Mapping {
    origin: (f64, f64),
    scale: (f64, f64),
    window: [f64; 4],
}

impl Mapping {
    fn of<DB: DrawingBackend>(
        chart: &ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
        w: [f64; 4],
    ) -> Mapping {
        let (a, b) = (
            chart.backend_coord(&(w[0], w[1])),
            chart.backend_coord(&(w[2], w[3])),
        );
        let span = |p: i32, q: i32, d: f64| (q - p) as f64 / d.max(1e-300);
        Mapping {
            origin: (a.0 as f64, a.1 as f64),
            scale: (span(a.0, b.0, w[2] - w[0]), span(a.1, b.1, w[3] - w[1])),
            window: w,
        }
    }

    fn pixel(&self, p: (f64, f64)) -> (f64, f64) {
        (
            self.origin.0 + (p.0 - self.window[0]) * self.scale.0,
            self.origin.1 + (p.1 - self.window[1]) * self.scale.1,
        )
    }
}

/// Appends the faces as one SVG group of polygons at sub-pixel coordinates, outlined thinner
/// when the faces are small on screen, so that their colour still shows.
fn write_faces(out: &mut String, map: &Mapping, faces: &[Face]) {
    use std::fmt::Write as _;
    let mut sizes: Vec<f64> = faces
        .iter()
        .map(|f| polygon_area(&f.points) * (map.scale.0 * map.scale.1).abs())
        .collect();
    sizes.sort_by(f64::total_cmp);
    let typical = sizes.get(sizes.len() / 2).map_or(10.0, |a| a.sqrt());
    let stroke = (typical / 12.0).clamp(0.1, 1.0);
    let _ = write!(
        out,
        r##"<g stroke="#1E1E1E" stroke-width="{stroke:.2}" stroke-linejoin="round">"##
    );
    for f in faces {
        let points: Vec<String> = (f.points.iter())
            .map(|&p| {
                let (x, y) = map.pixel(p);
                format!("{x:.2},{y:.2}")
            })
            .collect();
        let c = f.color;
        let _ = write!(
            out,
            r##"<polygon points="{}" fill="#{:02X}{:02X}{:02X}"/>"##,
            points.join(" "),
            c.0,
            c.1,
            c.2
        );
    }
    out.push_str("</g>\n");
}

/// The eta colour bar and the leftover legend, in their own drawing area.
fn draw_colour_bar(
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    height: u32,
) -> Result<(), ReportError> {
    let top = 50i32;
    let bottom = (height as i32 - 90).max(top + 60);
    let (x0, x1) = (14i32, 36i32);
    const STEPS: i32 = 64;
    for k in 0..STEPS {
        let t = (k as f64 + 0.5) / STEPS as f64;
        let ya = bottom - (bottom - top) * k / STEPS;
        let yb = bottom - (bottom - top) * (k + 1) / STEPS;
        area.draw(&Rectangle::new([(x0, yb), (x1, ya)], viridis(t).filled()))
            .map_err(plot_err)?;
    }
    area.draw(&Rectangle::new(
        [(x0, top), (x1, bottom)],
        BLACK.stroke_width(1),
    ))
    .map_err(plot_err)?;
    let font = ("sans-serif", 17).into_font();
    for k in 0..=4 {
        let v = k as f64 / 4.0;
        let y = bottom - (bottom - top) * k / 4;
        area.draw(&PathElement::new(vec![(x1, y), (x1 + 4, y)], BLACK))
            .map_err(plot_err)?;
        area.draw(&Text::new(format!("{v:.2}"), (x1 + 7, y - 6), font.clone()))
            .map_err(plot_err)?;
    }
    area.draw(&Text::new("eta", (x0, top - 22), font.clone()))
        .map_err(plot_err)?;
    let ly = bottom + 24;
    area.draw(&Rectangle::new(
        [(x0, ly), (x0 + 14, ly + 14)],
        LEFTOVER.filled(),
    ))
    .map_err(plot_err)?;
    area.draw(&Text::new("leftover", (x0 + 18, ly), font.clone()))
        .map_err(plot_err)?;
    area.draw(&Text::new("triangle", (x0 + 18, ly + 14), font))
        .map_err(plot_err)?;
    Ok(())
}

/// Unsigned area of a simple polygon (shoelace formula).
fn polygon_area(p: &[(f64, f64)]) -> f64 {
    let twice: f64 = (0..p.len())
        .map(|i| {
            let (a, b) = (p[i], p[(i + 1) % p.len()]);
            a.0 * b.1 - b.0 * a.1
        })
        .sum();
    twice.abs() / 2.0
}

/// Sutherland–Hodgman clipping of a polygon to an axis-aligned window `[x0, y0, x1, y1]`.
fn clip_to_window(poly: &[(f64, f64)], w: [f64; 4]) -> Vec<(f64, f64)> {
    // Fast path: entirely inside.
    if poly
        .iter()
        .all(|&(x, y)| x >= w[0] && x <= w[2] && y >= w[1] && y <= w[3])
    {
        return poly.to_vec();
    }
    let mut out = poly.to_vec();
    // Each edge: keep points with `inside(p)`, intersect across the line.
    type Inside = fn((f64, f64), f64) -> bool;
    type Cut = fn((f64, f64), (f64, f64), f64) -> (f64, f64);
    let cut_x: Cut = |a, b, x| (x, a.1 + (b.1 - a.1) * (x - a.0) / (b.0 - a.0));
    let cut_y: Cut = |a, b, y| (a.0 + (b.0 - a.0) * (y - a.1) / (b.1 - a.1), y);
    let planes: [(Inside, Cut, f64); 4] = [
        (|p, v| p.0 >= v, cut_x, w[0]),
        (|p, v| p.0 <= v, cut_x, w[2]),
        (|p, v| p.1 >= v, cut_y, w[1]),
        (|p, v| p.1 <= v, cut_y, w[3]),
    ];
    for (inside, cut, v) in planes {
        if out.is_empty() {
            break;
        }
        let input = std::mem::take(&mut out);
        for i in 0..input.len() {
            let (a, b) = (input[i], input[(i + 1) % input.len()]);
            match (inside(a, v), inside(b, v)) {
                (true, true) => out.push(b),
                (true, false) => out.push(cut(a, b, v)),
                (false, true) => {
                    out.push(cut(a, b, v));
                    out.push(b);
                }
                (false, false) => {}
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clipping_keeps_inside_and_cuts_crossing_polygons() {
        let sq = [(0.0, 0.0), (2.0, 0.0), (2.0, 2.0), (0.0, 2.0)];
        assert_eq!(clip_to_window(&sq, [-1.0, -1.0, 3.0, 3.0]), sq.to_vec());
        let c = clip_to_window(&sq, [1.0, 1.0, 3.0, 3.0]);
        assert!((polygon_area(&c) - 1.0).abs() < 1e-12, "{c:?}");
        // Touching the window's border only: zero area left.
        assert_eq!(
            polygon_area(&clip_to_window(&sq, [2.0, 0.0, 3.0, 2.0])),
            0.0
        );
        assert!(clip_to_window(&sq, [5.0, 5.0, 6.0, 6.0]).is_empty());
    }

    #[test]
    fn viridis_ends() {
        assert_eq!(viridis(0.0), RGBColor(68, 1, 84));
        assert_eq!(viridis(1.0), RGBColor(253, 231, 37));
        assert_eq!(viridis(f64::NAN), RGBColor(68, 1, 84));
    }
}
