//! What `recombine --finish` prints: the figures after each finishing step, as text or JSON.

use quadrecomb::internals::finish::{Finished, StepFigures};
use quadrecomb::internals::quality::{CandidateTable, ElementQuality};

/// Where all-quad puts its new nodes, in words (no boundary-curve geometry is read).
pub const SPLIT_PLACE: &str = "on the chord (midpoint of the straight side; the input's boundary curves are not known to quadrecomb)";

fn step_json(s: &StepFigures, pct: impl Fn(f64) -> Option<f64>) -> serde_json::Value {
    serde_json::json!({
        "quads": s.quads,
        "triangles_left": s.triangles_left,
        "quality": s.quality,
        "quality_pct": pct(s.quality),
        "time_s": s.time_s,
    })
}

/// The `finish` object of `recombine --json`.
pub fn json(
    f: &Finished,
    table: &CandidateTable,
    pct: impl Fn(f64) -> Option<f64> + Copy,
) -> serde_json::Value {
    let elements = ElementQuality::of_chosen(f.table(table), &f.chosen);
    serde_json::json!({
        "quads": f.improved.quads,
        "triangles_left": f.improved.triangles_left,
        "quality": f.improved.quality,
        "quality_pct": pct(f.improved.quality),
        "worst_eta": elements.worst,
        "time_s": f.time_s(),
        "eliminate": step_json(&f.eliminated, pct),
        "all_quad": f.all_quad.map(|s| step_json(&s, pct)),
        "improve": step_json(&f.improved, pct),
        "splits": f.splits.iter().map(|s| serde_json::json!({
            "side": s.side, "node": s.node, "path_len": s.path_len,
        })).collect::<Vec<_>>(),
        "split_place": (!f.splits.is_empty()).then_some("chord"),
        "sheets": (f.sheets.sheets > 0).then(|| serde_json::json!({
            "sheets": f.sheets.sheets,
            "nodes_added": f.sheets.nodes,
            "triangles_replaced": f.sheets.triangles_replaced,
            "triangles_added": f.sheets.triangles_added,
        })),
        "regions": f.stats.regions,
        "max_rings": f.stats.max_rings,
        "passes": f.stats.passes,
        "windows": f.stats.windows,
        "windows_kept": f.stats.kept,
    })
}

fn line(name: &str, s: &StepFigures, pct: impl Fn(f64) -> Option<f64>) {
    let p = pct(s.quality).map_or(String::new(), |p| format!(", {p:.2} % of the optimum"));
    outln!(
        "  {name:<13} {} quads, {} triangles left, quality {:.4}{p}, {:.4} s",
        s.quads,
        s.triangles_left,
        s.quality,
        s.time_s
    );
}

/// The text lines of `recombine --finish`.
pub fn print(f: &Finished, table: &CandidateTable, pct: impl Fn(f64) -> Option<f64> + Copy) {
    outln!("finish");
    line("eliminate", &f.eliminated, pct);
    if let Some(s) = &f.all_quad {
        line("all-quad", s, pct);
    }
    line("improve", &f.improved, pct);
    let elements = ElementQuality::of_chosen(f.table(table), &f.chosen);
    if let Some(w) = elements.worst {
        outln!("  worst eta     {w:.4}");
    }
    outln!(
        "  work          {} regions (up to {} rings), {} windows in {} passes, {} kept",
        f.stats.regions,
        f.stats.max_rings,
        f.stats.windows,
        f.stats.passes,
        f.stats.kept
    );
    if !f.splits.is_empty() {
        outln!(
            "  splits        {} boundary sides split, new nodes {SPLIT_PLACE}",
            f.splits.len()
        );
        for s in &f.splits {
            outln!(
                "                side {}-{} split by node {} (leftover moved {} steps)",
                s.side[0],
                s.side[1],
                s.node,
                s.path_len
            );
        }
    }
    if f.sheets.sheets > 0 {
        outln!(
            "  sheets        {} sheets through the components no split fixes: {} nodes added, {} triangles replaced by {} (as quads: {})",
            f.sheets.sheets,
            f.sheets.nodes,
            f.sheets.triangles_replaced,
            f.sheets.triangles_replaced + f.sheets.triangles_added,
            (f.sheets.triangles_replaced + f.sheets.triangles_added) / 2
        );
    }
    let added = f.splits.len() + f.sheets.triangles_added;
    if added > 0 && pct(f.improved.quality).is_some() {
        outln!(
            "  note          all-quad added {added} triangles: the % above are of the input \
             mesh's optimum, which the refined mesh can exceed (so can its quad count)"
        );
    }
    outln!("  finish time   {:.4} s", f.time_s());
}
