//! The comparison section: one results directory against another, configuration by
//! configuration (`report --compare`). The configurations only one directory has are listed;
//! those both hold with the very same runs (a directory and its extension) are named and left
//! out of the tests.

use super::mesh_section::family_blocks;
use super::significance::Family;
use super::{Config, Document, Metric, Results, Run};

/// DIR against DIR2, configuration by configuration.
pub(super) fn compare_section(doc: &mut Document, a: &Results, b: &Results, seed: u64) {
    doc.heading(
        2,
        format!(
            "Comparison: {} (first) vs {} (second)",
            a.dir.display(),
            b.dir.display()
        ),
    );
    let mut common: Vec<(&Config, &[Run], &[Run])> = Vec::new();
    let mut only_a = Vec::new();
    for (c, ra) in &a.groups {
        match b.groups.get(c) {
            Some(rb) => common.push((c, ra, rb)),
            None => only_a.push(format!("{} {}", c.mesh, c.label())),
        }
    }
    let only_b: Vec<String> = b
        .groups
        .keys()
        .filter(|c| !a.groups.contains_key(*c))
        .map(|c| format!("{} {}", c.mesh, c.label()))
        .collect();
    let mut notes = Vec::new();
    if !only_a.is_empty() {
        notes.push(format!("Only in the first: {}.", only_a.join(", ")));
    }
    if !only_b.is_empty() {
        notes.push(format!("Only in the second: {}.", only_b.join(", ")));
    }
    let optimum = |r: &Results, mesh: &str| {
        let m = r.manifest.as_ref()?;
        let e = m.optimum.iter().find(|e| e.mesh == mesh)?;
        Some(format!("{:.2}", e.quality))
    };
    let mut rules_noted: Vec<&str> = Vec::new();
    for (c, ra, rb) in &common {
        let (rule_a, rule_b) = (ra[0].rule(), rb[0].rule());
        if rule_a != rule_b && !rules_noted.contains(&c.mesh.as_str()) {
            rules_noted.push(&c.mesh);
            let optima = match (optimum(a, &c.mesh), optimum(b, &c.mesh)) {
                (Some(x), Some(y)) => format!(" ({x} vs {y})"),
                _ => String::new(),
            };
            notes.push(format!(
                "{}: the two directories used different quad-validity rules ({rule_a} vs \
                 {rule_b}): quality is a % of each rule's own optimum{optima}, and which \
                 pairs may be merged differs, so the differences below are partly the rule's, \
                 not the method's.",
                c.mesh
            ));
        }
        if ra[0].mesh_hash != rb[0].mesh_hash {
            notes.push(format!(
                "{}: the two directories used different meshes under the same name (hashes \
                 differ).",
                c.mesh
            ));
        }
        if ra[0].backend != rb[0].backend {
            notes.push(format!(
                "{} {}: eta came from different backends ({} vs {}).",
                c.mesh,
                c.label(),
                ra[0].backend,
                rb[0].backend
            ));
        }
    }
    // A directory and its extension (or a merge of it) hold the same runs where their
    // configurations overlap: the same seeds, so the same results but for the time. Testing a
    // sample against itself says nothing, and would weigh on the Holm correction of the rest.
    let label = |c: &Config| format!("{} {}", c.mesh, c.label());
    let shared_runs = |ra: &[Run], rb: &[Run]| {
        ra.iter()
            .filter(|x| {
                rb.iter()
                    .any(|y| y.run == x.run && y.seed == x.seed && x.same_result(y))
            })
            .count()
    };
    let mut same = Vec::new();
    let mut overlapping = Vec::new();
    common.retain(|(c, ra, rb)| {
        let shared = shared_runs(ra, rb);
        if shared == ra.len() && shared == rb.len() {
            same.push(label(c));
            return false;
        }
        if shared > 0 {
            overlapping.push(format!("{} ({shared} runs)", label(c)));
        }
        true
    });
    if !same.is_empty() {
        notes.push(format!(
            "The same runs in both (same seeds and results, only time_s differs, as in a \
             directory and its extension), not tested: {}.",
            same.join(", ")
        ));
    }
    if !overlapping.is_empty() {
        notes.push(format!(
            "Runs shared by both (same seeds and results), so the two samples are not \
             independent: {}.",
            overlapping.join(", ")
        ));
    }
    notes.dedup();
    doc.list(notes);
    if common.is_empty() {
        doc.para(if same.is_empty() {
            "The two directories share no configuration: nothing to compare."
        } else {
            "The configurations the two directories share hold the same runs: nothing to \
             compare."
        });
        return;
    }
    let mut families = Vec::new();
    for metric in Metric::ALL {
        let sides: Vec<(String, &[Run], String, &[Run])> = common
            .iter()
            .map(|(c, ra, rb)| {
                let l = format!("{} {}", c.mesh, c.label());
                (format!("{l} (first)"), *ra, format!("{l} (second)"), *rb)
            })
            .collect();
        families.push(Family::build(
            format!("First vs second directory, {}", metric.key()),
            metric,
            sides,
            seed.wrapping_add(1000 * metric as u64),
        ));
    }
    family_blocks(doc, &families);
}
