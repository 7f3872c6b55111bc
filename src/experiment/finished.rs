//! `sweep --finish`: each search run finished after its search ([`crate::internals::finish::finish`],
//! leftover elimination then local improvement, no all-quad), and what its record keeps of
//! the finish. The raw fields of a record stay the search's; the finish is one optional
//! object beside them (absent without `--finish`, so older records read and write as they
//! did). See docs/finish.md and docs/runner.md.

use serde::{Deserialize, Serialize};

use crate::internals::finish::{FinishConfig, finish};
use crate::mesh::Mesh;
use crate::quality::{CandidateTable, ElementQuality, Rule};

/// The finish settings of a sweep (its manifest's `spec.finish`): part of what fixes the
/// results, so a resume or extension with others is refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct FinishSettings {
    /// Rings of quads around the leftovers in the first elimination round (k, at least 1).
    pub rings: u32,
    /// Rings of each improvement window (r; 0 skips improvement).
    pub window: u32,
}

impl Default for FinishSettings {
    fn default() -> FinishSettings {
        FinishSettings {
            rings: crate::internals::finish::DEFAULT_RINGS,
            window: crate::internals::finish::DEFAULT_WINDOW,
        }
    }
}

impl std::fmt::Display for FinishSettings {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "finish rings {} window {}", self.rings, self.window)
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
}

/// Finishes the pairing `chosen` (a search's) of `mesh` under `rule` with `settings`.
pub fn finish_run(
    mesh: &Mesh,
    table: &CandidateTable,
    chosen: &[u32],
    settings: FinishSettings,
    rule: Rule,
) -> FinishOutcome {
    let config = FinishConfig {
        rings: settings.rings.max(1),
        window: settings.window,
        all_quad: false,
        rule,
    };
    // Without all-quad the mesh is never rebuilt, the one way `finish` fails.
    let f = finish(mesh, table, chosen, config).expect("a finish without all-quad cannot fail");
    FinishOutcome {
        quads: f.improved.quads,
        triangles_left: f.improved.triangles_left,
        quality: f.improved.quality,
        eliminate_s: f.eliminated.time_s,
        improve_s: f.improved.time_s,
        elements: ElementQuality::of_chosen(table, &f.chosen),
    }
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
    /// Seconds of the whole finish (elimination + improvement); the search's own time stays
    /// in the record's `time_s`.
    pub time_s: f64,
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
        FinishRecord {
            rings: settings.rings,
            window: settings.window,
            quads: out.quads,
            triangles_left: out.triangles_left,
            recombined_pct: if triangles == 0 {
                0.0
            } else {
                100.0 * 2.0 * out.quads as f64 / triangles as f64
            },
            quality: out.quality,
            quality_pct: optimum
                .filter(|&o| o > 0.0)
                .map(|o| 100.0 * out.quality / o),
            worst_eta: out.elements.worst,
            mean_eta: out.elements.mean,
            eliminate_s: out.eliminate_s,
            improve_s: out.improve_s,
            time_s: out.eliminate_s + out.improve_s,
        }
    }

    /// The object with its times zeroed (for comparing results, not executions).
    pub fn without_times(&self) -> FinishRecord {
        FinishRecord {
            eliminate_s: 0.0,
            improve_s: 0.0,
            time_s: 0.0,
            ..self.clone()
        }
    }

    /// Why the object holds values no finish of a run on `triangles` triangles can have
    /// (counts that do not add up, measures out of range), if it does.
    pub fn check(&self, triangles: usize) -> Result<(), String> {
        if 2 * self.quads as u128 + self.triangles_left as u128 != triangles as u128 {
            return Err(format!(
                "finish: 2 x {} quads + {} triangles left is not its {triangles} triangles",
                self.quads, self.triangles_left
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
