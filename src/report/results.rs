//! Reading a results directory (`runs.jsonl`, optional `manifest.json`) and grouping its runs
//! into configurations (mesh, algorithm, horizon).

use super::ReportError;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// One run as the report reads it from `runs.jsonl` (the runner's `RunRecord` fields the report
/// uses; other fields are ignored).
#[derive(Debug, Clone, Deserialize)]
pub struct Run {
    /// Mesh name or path as given to the sweep.
    pub mesh: String,
    /// Hash of the mesh the run used.
    #[serde(default)]
    pub mesh_hash: String,
    /// Number of triangles of the input mesh.
    pub triangles: usize,
    /// Policy name ("greedy-nocrit", "greedy", "uniform", "selective").
    pub algo: String,
    /// Horizon of the look-ahead policies.
    #[serde(default)]
    pub horizon: Option<u32>,
    /// The run's own seed.
    pub seed: u64,
    /// Run index within its configuration.
    pub run: u32,
    /// Quads made.
    pub quads: usize,
    /// Triangles left unrecombined.
    pub triangles_left: usize,
    /// Percentage of triangles recombined.
    pub recombined_pct: f64,
    /// Total quality (sum of eta).
    pub quality: f64,
    /// Quality as a percentage of the optimum, when the optimum is known.
    #[serde(default)]
    pub quality_pct: Option<f64>,
    /// Wall time of the run in seconds.
    pub time_s: f64,
    /// Tree nodes expanded.
    pub nodes_expanded: u64,
    /// Decisions (recombinations) made.
    pub decisions: u64,
    /// Effective branching factor of the look-ahead tree, when there is one.
    #[serde(default)]
    pub branching_factor: Option<f64>,
    /// Backend that filled the candidate table's eta.
    #[serde(default)]
    pub backend: String,
    /// Tool version that produced the run.
    #[serde(default)]
    pub version: String,
}

impl Run {
    /// Tree nodes expanded per decision (0 when no decision was made).
    pub fn nodes_per_step(&self) -> f64 {
        if self.decisions == 0 {
            0.0
        } else {
            self.nodes_expanded as f64 / self.decisions as f64
        }
    }
}

/// A configuration: what a group of runs shares.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Config {
    /// Mesh name or path.
    pub mesh: String,
    /// Rank of the algorithm in the report's order (baselines first).
    algo_rank: u8,
    /// Algorithm name.
    pub algo: String,
    /// Horizon, if the algorithm has one.
    pub horizon: Option<u32>,
}

impl Config {
    /// The configuration of `run`.
    pub fn of(run: &Run) -> Config {
        Config {
            mesh: run.mesh.clone(),
            algo_rank: algo_rank(&run.algo),
            algo: run.algo.clone(),
            horizon: run.horizon,
        }
    }

    /// "selective h=3", "greedy".
    pub fn label(&self) -> String {
        match self.horizon {
            Some(h) => format!("{} h={h}", self.algo),
            None => self.algo.clone(),
        }
    }
}

/// Order of algorithms in tables: baselines first, then uniform, selective, the optimum,
/// unknown names.
fn algo_rank(algo: &str) -> u8 {
    match algo {
        "greedy-nocrit" => 0,
        "greedy" => 1,
        "uniform" => 2,
        "selective" => 3,
        "optimum" => 4,
        _ => 5,
    }
}

/// The runs of one results directory, grouped by configuration.
#[derive(Debug, Clone)]
pub struct Results {
    /// The directory read.
    pub dir: PathBuf,
    /// Runs per configuration, in report order, each group sorted by run index.
    pub groups: BTreeMap<Config, Vec<Run>>,
    /// Meshes in report order (order of first appearance in `runs.jsonl`).
    pub meshes: Vec<String>,
    /// `manifest.json`, if present.
    pub manifest: Option<serde_json::Value>,
    /// Lines of `runs.jsonl` that could not be read (only a torn last line is tolerated).
    pub skipped_lines: usize,
}

impl Results {
    /// Reads `dir/runs.jsonl` and, if present, `dir/manifest.json`. A torn (unparsable) last line
    /// is skipped, as the runner redoes it on `--resume`; any other bad line is an error.
    pub fn read(dir: &Path) -> Result<Results, ReportError> {
        let path = dir.join("runs.jsonl");
        let text = std::fs::read_to_string(&path).map_err(|source| ReportError::Io {
            path: path.clone(),
            source,
        })?;
        let lines: Vec<(usize, &str)> = text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty())
            .collect();
        let mut runs = Vec::with_capacity(lines.len());
        let mut skipped_lines = 0;
        for (k, &(i, line)) in lines.iter().enumerate() {
            match serde_json::from_str::<Run>(line) {
                Ok(r) => runs.push(r),
                Err(_) if k + 1 == lines.len() && !text.ends_with('\n') => skipped_lines += 1,
                Err(e) => {
                    return Err(ReportError::Syntax {
                        path: path.clone(),
                        line: i + 1,
                        message: e.to_string(),
                    });
                }
            }
        }
        if runs.is_empty() {
            return Err(ReportError::NoRuns { path });
        }
        let manifest_path = dir.join("manifest.json");
        let manifest = match std::fs::read_to_string(&manifest_path) {
            Ok(t) => Some(serde_json::from_str(&t).map_err(|e| ReportError::Syntax {
                path: manifest_path.clone(),
                line: e.line(),
                message: e.to_string(),
            })?),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => None,
            Err(source) => {
                return Err(ReportError::Io {
                    path: manifest_path,
                    source,
                });
            }
        };
        Ok(Results::from_runs(dir, runs, manifest, skipped_lines))
    }

    /// Groups `runs` (already read) by configuration.
    pub fn from_runs(
        dir: &Path,
        runs: Vec<Run>,
        manifest: Option<serde_json::Value>,
        skipped_lines: usize,
    ) -> Results {
        let mut meshes: Vec<String> = Vec::new();
        let mut groups: BTreeMap<Config, Vec<Run>> = BTreeMap::new();
        for r in runs {
            if !meshes.contains(&r.mesh) {
                meshes.push(r.mesh.clone());
            }
            groups.entry(Config::of(&r)).or_default().push(r);
        }
        for g in groups.values_mut() {
            g.sort_by_key(|r| r.run);
        }
        Results {
            dir: dir.to_path_buf(),
            groups,
            meshes,
            manifest,
            skipped_lines,
        }
    }

    /// Configurations of `mesh`, in report order.
    pub fn configs_of<'a>(
        &'a self,
        mesh: &'a str,
    ) -> impl Iterator<Item = (&'a Config, &'a [Run])> {
        self.groups
            .iter()
            .filter(move |(c, _)| c.mesh == mesh)
            .map(|(c, r)| (c, r.as_slice()))
    }

    /// The runs of a configuration, if present.
    pub fn get(&self, mesh: &str, algo: &str, horizon: Option<u32>) -> Option<&[Run]> {
        self.groups
            .iter()
            .find(|(c, _)| c.mesh == mesh && c.algo == algo && c.horizon == horizon)
            .map(|(_, r)| r.as_slice())
    }

    /// Total number of runs.
    pub fn num_runs(&self) -> usize {
        self.groups.values().map(Vec::len).sum()
    }
}

/// The measures the report summarizes and compares.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Metric {
    /// Quality as % of the optimum (raw quality when the optimum is unknown).
    Quality,
    /// % of triangles recombined.
    Recombined,
    /// Wall time in seconds.
    Time,
}

impl Metric {
    /// All metrics, in report order.
    pub const ALL: [Metric; 3] = [Metric::Quality, Metric::Recombined, Metric::Time];

    /// The metric's values over `runs`. Quality is the % of optimum when every run has one,
    /// otherwise the raw quality.
    pub fn values(self, runs: &[Run]) -> Vec<f64> {
        match self {
            Metric::Quality => {
                let pct: Option<Vec<f64>> = runs.iter().map(|r| r.quality_pct).collect();
                pct.unwrap_or_else(|| runs.iter().map(|r| r.quality).collect())
            }
            Metric::Recombined => runs.iter().map(|r| r.recombined_pct).collect(),
            Metric::Time => runs.iter().map(|r| r.time_s).collect(),
        }
    }

    /// Name with unit, given whether quality is a percentage for these runs.
    pub fn name(self, runs: &[Run]) -> &'static str {
        match self {
            Metric::Quality if runs.iter().all(|r| r.quality_pct.is_some()) => {
                "quality (% of optimum)"
            }
            Metric::Quality => "quality (sum of eta)",
            Metric::Recombined => "recombined (%)",
            Metric::Time => "time (s)",
        }
    }

    /// Short key for file names.
    pub fn key(self) -> &'static str {
        match self {
            Metric::Quality => "quality",
            Metric::Recombined => "recombined",
            Metric::Time => "time",
        }
    }
}
