//! "Typical runs": pictures of the median-quality run of chosen configurations, replayed by
//! [`crate::experiment::replay`] ([`super::typical`]) and drawn by [`super::picture`].

use super::format::{mesh_slug, slug};
use super::mesh_section::tree_algos;
use super::{Config, Document, FIGURES_DIR, Metric, ReportError, ReportOptions, Results, Run};
use super::{picture, typical};
use crate::experiment::replay::Replayer;
use crate::stats::describe::median;

/// Fails when a configuration asked for with `--picture` matches none of the results'.
pub(super) fn check_pictures(results: &Results, opts: &ReportOptions) -> Result<(), ReportError> {
    let name = |a: &str, h: Option<u32>| match h {
        Some(h) => format!("{a}:{h}"),
        None => a.to_string(),
    };
    for (a, h) in &opts.picture_configs {
        let found = results
            .groups
            .keys()
            .any(|c| c.algo == *a && (h.is_none() || *h == c.horizon));
        if !found {
            let mut held: Vec<String> = Vec::new();
            for c in results.groups.keys() {
                let n = name(&c.algo, c.horizon);
                if !held.contains(&n) {
                    held.push(n);
                }
            }
            return Err(ReportError::NoSuchPicture(name(a, *h), held.join(", ")));
        }
    }
    Ok(())
}

/// The configurations whose typical run is pictured.
pub(super) fn picture_choice<'a>(
    configs: &[(&'a Config, &'a [Run])],
    opts: &ReportOptions,
) -> Vec<(&'a Config, &'a [Run])> {
    if !opts.picture_configs.is_empty() {
        return configs
            .iter()
            .filter(|(c, _)| {
                opts.picture_configs
                    .iter()
                    .any(|(a, h)| *a == c.algo && (h.is_none() || *h == c.horizon))
            })
            .copied()
            .collect();
    }
    let mut out: Vec<(&Config, &[Run])> = Vec::new();
    let algos = tree_algos(configs);
    for algo in algos {
        // The best median quality; the smallest horizon among equals (the cheapest to re-run).
        let mut best: Option<(&Config, &[Run], f64)> = None;
        for (c, r) in configs.iter().filter(|(c, _)| c.algo == algo) {
            let q = median(&Metric::Quality.values(r));
            if best.is_none_or(|b| q > b.2) {
                best = Some((c, r, q));
            }
        }
        out.extend(best.map(|(c, r, _)| (c, r)));
    }
    out
}

/// Pictures of typical (median-quality) runs, re-run from their seeds.
pub(super) fn pictures(
    doc: &mut Document,
    mesh: &str,
    configs: &[(&Config, &[Run])],
    opts: &ReportOptions,
    replayer: &mut Replayer<'_>,
) -> Result<(), ReportError> {
    let chosen = picture_choice(configs, opts);
    if chosen.is_empty() {
        return Ok(());
    }
    doc.heading(3, "Typical runs");
    for (c, runs) in chosen {
        let Some(run) = typical::median_run(runs) else {
            continue;
        };
        let t = match typical::rerun(replayer, run) {
            Ok(t) => t,
            Err(why) => {
                doc.para(format!("No picture of {mesh} {}: {why}.", c.label()));
                continue;
            }
        };
        let mut views = vec![(None, "mesh")];
        if let Some(z) = opts.zoom {
            views.push((Some(z), "zoom"));
        }
        for (zoom, kind) in views {
            let popts = picture::PictureOptions {
                title: format!(
                    "{mesh}: {}, typical run{}",
                    c.label(),
                    if zoom.is_some() { " (zoom)" } else { "" }
                ),
                zoom,
                inset: zoom.is_none(),
                ..picture::PictureOptions::default()
            };
            let (svg, counts) = picture::mesh_svg(t.mesh, &t.rec, &popts)?;
            let mut caption = format!(
                "{mesh}: {} Quads coloured by eta (colour bar), leftover triangles in red; \
                 {} quads and {} leftover triangles drawn",
                t.note, counts.quads, counts.leftover
            );
            if counts.culled > 0 {
                caption.push_str(&format!(", {} back faces culled", counts.culled));
            }
            if let Some(([x0, y0, x1, y1], quads, leftover)) = counts.inset {
                caption.push_str(&format!(
                    "; below, the densest region magnified (x {x0:.4}..{x1:.4}, y {y0:.4}..{y1:.4}, \
                     framed in red above: {quads} quads and {leftover} leftover triangles)"
                ));
            }
            if let Some([x0, y0, x1, y1]) = zoom {
                caption.push_str(&format!(", window x {x0}..{x1}, y {y0}..{y1}"));
            }
            caption.push('.');
            let file = format!(
                "{FIGURES_DIR}/{}-{}-{kind}.svg",
                mesh_slug(mesh),
                slug(&c.label())
            );
            doc.figure(file, svg, caption);
        }
    }
    Ok(())
}
