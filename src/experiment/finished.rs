//! `sweep --finish`: each search run finished after its search ([`crate::internals::finish::finish`],
//! leftover elimination, all-quad splits with `--all-quad`, then local improvement), and what
//! its record keeps of the finish. A split mesh is not stored: replay rebuilds it from the
//! record (seed, rule, finish settings), the finish being deterministic. The raw fields of a record stay the search's; the finish is one optional
//! object beside them (absent without `--finish`, so older records read and write as they
//! did). See docs/finish.md and docs/runner.md.

use serde::{Deserialize, Serialize};

use crate::internals::finish::{FinishConfig, FinishError, finish};
use crate::mesh::Mesh;
use crate::mesh::Recombined;
use crate::quality::{CandidateTable, ElementQuality, Rule, recombined};

fn is_false(b: &bool) -> bool {
    !*b
}

/// The finish settings of a sweep (its manifest's `spec.finish`): part of what fixes the
/// results, so a resume or extension with others is refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct FinishSettings {
    /// Rings of quads around the leftovers in the first elimination round (k, at least 1).
    pub rings: u32,
    /// Rings of each improvement window (r; 0 skips improvement).
    pub window: u32,
    /// Make odd components even by boundary splits (`--all-quad`); absent when false, so
    /// manifests without it read and write as before.
    #[serde(default, skip_serializing_if = "is_false")]
    pub all_quad: bool,
}

impl Default for FinishSettings {
    fn default() -> FinishSettings {
        FinishSettings {
            rings: crate::internals::finish::DEFAULT_RINGS,
            window: crate::internals::finish::DEFAULT_WINDOW,
            all_quad: false,
        }
    }
}

impl std::fmt::Display for FinishSettings {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "finish rings {} window {}", self.rings, self.window)?;
        if self.all_quad {
            write!(f, " all-quad")?;
        }
        Ok(())
    }
}

/// What a finish produced for one run, before the record's percentages.
#[derive(Debug, Clone, PartialEq)]
pub struct FinishOutcome {
    /// Quads after the finish.
    pub quads: usize,
    /// Triangles left after the finish.
    pub triangles_left: usize,
    /// Sum of eta after the finish.
    pub quality: f64,
    /// Seconds of leftover elimination.
    pub eliminate_s: f64,
    /// Seconds of local improvement.
    pub improve_s: f64,
    /// The finished quads' eta figures.
    pub elements: ElementQuality,
    /// What all-quad did (with `all_quad` settings only).
    pub all_quad: Option<AllQuadFigures>,
}

/// What all-quad did to one run: the record's `finish.all_quad` object.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AllQuadFigures {
    /// Boundary sides split (one per odd component that kept a triangle).
    pub splits: usize,
    /// Nodes added to the mesh (one per split, on the chord of the side, and those of the
    /// sheets).
    pub nodes_added: usize,
    /// Seconds of all-quad (the choice of the splits, the new mesh, its elimination).
    pub time_s: f64,
    /// Sheets of sheet refinement, for the components no single split fixes (0: absent).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub sheets: usize,
    /// Nodes the sheets added (within `nodes_added`).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub sheet_nodes: usize,
    /// Triangles of the (split) mesh the sheets replaced.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub sheet_triangles_replaced: usize,
    /// Triangles the sheets added to the mesh.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub sheet_triangles_added: usize,
}

fn is_zero(n: &usize) -> bool {
    *n == 0
}

impl AllQuadFigures {
    /// Triangles added to the mesh: one per split, and the sheets'.
    pub fn triangles_added(&self) -> usize {
        self.splits + self.sheet_triangles_added
    }
}

/// The finished mesh of a run: the split mesh when all-quad split (else `None`: the input),
/// and its elements.
#[derive(Debug, Clone)]
pub struct FinishedMesh {
    /// The split mesh, when all-quad split sides.
    pub mesh: Option<Mesh>,
    /// The finished quads and the triangles left, on that mesh.
    pub recombined: Recombined,
}

/// Finishes the pairing `chosen` (a search's) of `mesh` under `rule` with `settings`. Fails
/// only with all-quad, when a component keeps triangles no boundary split can pair.
pub fn finish_run(
    mesh: &Mesh,
    table: &CandidateTable,
    chosen: &[u32],
    settings: FinishSettings,
    rule: Rule,
) -> Result<FinishOutcome, FinishError> {
    finish_run_with_mesh(mesh, table, chosen, settings, rule).map(|(o, _)| o)
}

/// [`finish_run`], and the finished mesh (for writing it).
pub fn finish_run_with_mesh(
    mesh: &Mesh,
    table: &CandidateTable,
    chosen: &[u32],
    settings: FinishSettings,
    rule: Rule,
) -> Result<(FinishOutcome, FinishedMesh), FinishError> {
    let config = FinishConfig {
        rings: settings.rings.max(1),
        window: settings.window,
        all_quad: settings.all_quad,
        rule,
    };
    let f = finish(mesh, table, chosen, config)?;
    let t = f.table(table);
    let outcome = FinishOutcome {
        quads: f.improved.quads,
        triangles_left: f.improved.triangles_left,
        quality: f.improved.quality,
        eliminate_s: f.eliminated.time_s,
        improve_s: f.improved.time_s,
        elements: ElementQuality::of_chosen(t, &f.chosen),
        all_quad: f.all_quad.map(|s| AllQuadFigures {
            splits: f.splits.len(),
            nodes_added: f.splits.len() + f.sheets.nodes,
            time_s: s.time_s,
            sheets: f.sheets.sheets,
            sheet_nodes: f.sheets.nodes,
            sheet_triangles_replaced: f.sheets.triangles_replaced,
            sheet_triangles_added: f.sheets.triangles_added,
        }),
    };
    let rec = recombined(f.mesh(mesh), t, &f.chosen);
    let split_mesh = f.mesh;
    Ok((
        outcome,
        FinishedMesh {
            mesh: split_mesh,
            recombined: rec,
        },
    ))
}

/// The `finish` object of a record: the run after its finish.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FinishRecord {
    /// Rings of the first elimination round used.
    pub rings: u32,
    /// Improvement window used (rings).
    pub window: u32,
    /// Quads after the finish.
    pub quads: usize,
    /// Triangles left after the finish.
    pub triangles_left: usize,
    /// 100 * 2 * quads / triangles after the finish.
    pub recombined_pct: f64,
    /// Sum of eta after the finish.
    pub quality: f64,
    /// 100 * quality / optimum quality, when the optimum is known.
    pub quality_pct: Option<f64>,
    /// The worst quad's eta after the finish (`None` without quads).
    pub worst_eta: Option<f64>,
    /// Mean eta per quad after the finish.
    pub mean_eta: Option<f64>,
    /// Seconds of leftover elimination.
    pub eliminate_s: f64,
    /// Seconds of local improvement.
    pub improve_s: f64,
    /// Seconds of the whole finish (elimination, all-quad, improvement); the search's own
    /// time stays in the record's `time_s`.
    pub time_s: f64,
    /// What all-quad did (`sweep --finish --all-quad` only; absent otherwise). With splits,
    /// the counts above are of the split mesh (`triangles + splits + sheet_triangles_added`
    /// triangles).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub all_quad: Option<AllQuadFigures>,
}

impl FinishRecord {
    /// The record object of `out`, on a mesh of `triangles` triangles whose optimum quality is
    /// `optimum` (when known).
    pub fn new(
        settings: FinishSettings,
        out: &FinishOutcome,
        triangles: usize,
        optimum: Option<f64>,
    ) -> FinishRecord {
        let triangles = triangles + out.all_quad.map_or(0, |a| a.triangles_added());
        FinishRecord {
            rings: settings.rings,
            window: settings.window,
            quads: out.quads,
            triangles_left: out.triangles_left,
            recombined_pct: super::record::recombined_pct(out.quads, triangles),
            quality: out.quality,
            quality_pct: optimum
                .filter(|&o| o > 0.0)
                .map(|o| 100.0 * out.quality / o),
            worst_eta: out.elements.worst,
            mean_eta: out.elements.mean,
            eliminate_s: out.eliminate_s,
            improve_s: out.improve_s,
            time_s: out.eliminate_s + out.all_quad.map_or(0.0, |a| a.time_s) + out.improve_s,
            all_quad: out.all_quad,
        }
    }

    /// Boundary sides all-quad split (0 without).
    pub fn splits(&self) -> usize {
        self.all_quad.map_or(0, |a| a.splits)
    }

    /// Triangles added by all-quad's splits and sheets (0 without).
    pub fn triangles_added(&self) -> usize {
        self.all_quad.map_or(0, |a| a.triangles_added())
    }

    /// The object with its times zeroed (for comparing results, not executions).
    pub fn without_times(&self) -> FinishRecord {
        FinishRecord {
            eliminate_s: 0.0,
            improve_s: 0.0,
            time_s: 0.0,
            all_quad: self.all_quad.map(|a| AllQuadFigures { time_s: 0.0, ..a }),
            ..self.clone()
        }
    }

    /// Why the object holds values no finish of a run on `triangles` triangles can have
    /// (counts that do not add up, measures out of range), if it does.
    pub fn check(&self, triangles: usize) -> Result<(), String> {
        let added = self.triangles_added();
        if 2 * self.quads as u128 + self.triangles_left as u128 != triangles as u128 + added as u128
        {
            return Err(format!(
                "finish: 2 x {} quads + {} triangles left is not its {triangles} triangles + {added} added by all-quad",
                self.quads, self.triangles_left
            ));
        }
        if let Some(a) = self.all_quad
            && (a.nodes_added != a.splits + a.sheet_nodes
                || !a.time_s.is_finite()
                || a.time_s < 0.0)
        {
            return Err(format!(
                "finish: all_quad {} nodes added for {} splits and {} sheet nodes, time {}",
                a.nodes_added, a.splits, a.sheet_nodes, a.time_s
            ));
        }
        for (name, v) in [
            ("quality", self.quality),
            ("recombined_pct", self.recombined_pct),
            ("time_s", self.time_s),
            ("eliminate_s", self.eliminate_s),
            ("improve_s", self.improve_s),
        ] {
            if !v.is_finite() || v < 0.0 {
                return Err(format!(
                    "finish: {name} {v} is not a finite non-negative number"
                ));
            }
        }
        if self.recombined_pct > 100.0 + 1e-9 {
            return Err(format!(
                "finish: recombined_pct {} is above 100",
                self.recombined_pct
            ));
        }
        if self.quality > self.quads as f64 * (1.0 + 1e-9) + 1e-9 {
            return Err(format!(
                "finish: quality {} is above its {} quads",
                self.quality, self.quads
            ));
        }
        if self.rings == 0 {
            return Err("finish: rings 0 (at least 1)".into());
        }
        Ok(())
    }
}
