//! Reading a results directory (`runs.jsonl`, optional `manifest.json`) and grouping its runs
//! into configurations (mesh, algorithm, horizon).

use super::ReportError;
pub use crate::experiment::record::RunRecord as Run;
use crate::experiment::{manifest, store};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Tree nodes expanded per look-ahead tree of a run; `None` when it built none (the
/// optimum, greedy-nocrit, a run whose record predates the count).
pub fn nodes_per_tree(run: &Run) -> Option<f64> {
    match (run.nodes_expanded, run.trees) {
        (Some(n), Some(t)) if t > 0 => Some(n as f64 / t as f64),
        _ => None,
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
    /// Node budget per decision, if the algorithm has one.
    pub budget: Option<u32>,
    /// The wall-time budget its horizon or node budget was calibrated for, if any.
    pub time_budget: Option<crate::experiment::calibrate::TimeBudget>,
}

impl Config {
    /// The configuration of `run`.
    pub fn of(run: &Run) -> Config {
        Config {
            mesh: run.mesh.clone(),
            algo_rank: algo_rank(&run.algo),
            algo: run.algo.clone(),
            horizon: run.horizon,
            budget: run.budget,
            time_budget: run.time_budget_s,
        }
    }

    /// "selective h=3", "mcts h=10 b=64", "greedy"; "mcts h=3 b=40 (T=0.2s)" for a
    /// configuration calibrated to a time budget.
    pub fn label(&self) -> String {
        let label = crate::experiment::record::label(
            &self.algo,
            crate::experiment::record::Params {
                horizon: self.horizon,
                budget: self.budget,
            },
        );
        match self.time_budget {
            Some(t) => format!("{label} (T={}s)", t.seconds()),
            None => label,
        }
    }

    /// The method as compared across meshes: the configuration without its mesh and, when
    /// it was calibrated to a time budget, without the knob the calibration chose (each mesh
    /// gets its own: selective's horizon, a budgeted tree's node budget), so that
    /// "selective (T=0.5s)" is one method on every mesh.
    pub fn method(&self) -> Config {
        let mut m = self.clone();
        m.mesh.clear();
        if m.time_budget.is_some() {
            if m.budget.is_some() {
                m.budget = None;
            } else {
                m.horizon = None;
            }
        }
        m
    }
}

/// Order of algorithms in tables: the registry's ranks (baselines first, then uniform,
/// selective, the budgeted policies, the optimum), unknown names last.
fn algo_rank(algo: &str) -> u8 {
    crate::experiment::record::algo_rank(algo)
}

/// The runs of one results directory, grouped by configuration.
#[derive(Debug, Clone)]
pub struct Results {
    /// The directory read.
    pub dir: PathBuf,
    /// Runs per configuration, in report order, each group sorted by run index.
    pub groups: BTreeMap<Config, Vec<Run>>,
    /// Meshes in report order: the sweep's (`--mesh`, as the manifest lists them), then any
    /// other in order of first appearance in `runs.jsonl`.
    pub meshes: Vec<String>,
    /// `manifest.json`, if present.
    pub manifest: Option<manifest::Manifest>,
    /// Bytes of a torn last line of `runs.jsonl` (a run interrupted while being written),
    /// ignored; 0 if none.
    pub torn_bytes: u64,
}

impl Results {
    /// Reads `dir/runs.jsonl` (through the runner's reader: a torn last line is ignored, any
    /// other bad line is an error) and, if present, `dir/manifest.json`.
    pub fn read(dir: &Path) -> Result<Results, ReportError> {
        if !dir.is_dir() {
            return Err(ReportError::NotResults {
                dir: dir.to_path_buf(),
                why: if dir.exists() {
                    "not a directory (give the sweep's results directory)".into()
                } else {
                    "no such directory".into()
                },
            });
        }
        let path = dir.join(store::RUNS_FILE);
        // A FIFO, device or directory in its place is named as such.
        store::refuse_irregular(&path)?;
        if !path.is_file() {
            return Err(ReportError::NotResults {
                dir: dir.to_path_buf(),
                why: format!("no {} (not a sweep's results directory)", store::RUNS_FILE),
            });
        }
        let loaded = store::read(&path)?;
        if loaded.records.is_empty() {
            return Err(ReportError::NoRuns { path });
        }
        store::refuse_irregular(&dir.join(manifest::MANIFEST_FILE))?;
        let manifest = if dir.join(manifest::MANIFEST_FILE).is_file() {
            Some(manifest::Manifest::read(dir)?)
        } else {
            None
        };
        check(dir, manifest.as_ref(), &loaded)?;
        Ok(Results::from_runs(
            dir,
            loaded.records,
            manifest,
            loaded.torn_bytes,
        ))
    }

    /// Every run, in configuration order.
    pub fn runs(&self) -> Vec<Run> {
        self.groups.values().flatten().cloned().collect()
    }

    /// Groups `runs` (already read) by configuration.
    pub fn from_runs(
        dir: &Path,
        runs: Vec<Run>,
        manifest: Option<manifest::Manifest>,
        torn_bytes: u64,
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
        // Not the order in which runs finished: with several threads that changed from one
        // sweep to the next, and with it the report's sections and tables.
        if let Some(m) = &manifest {
            let rank = |name: &String| m.spec.meshes.iter().position(|e| e.name == *name);
            meshes.sort_by_key(|name| rank(name).unwrap_or(usize::MAX));
        }
        Results {
            dir: dir.to_path_buf(),
            groups,
            meshes,
            manifest,
            torn_bytes,
        }
    }

    /// Every configuration in report order: mesh by mesh ([`Results::meshes`]), each
    /// mesh's in [`Config`] order.
    pub fn configs(&self) -> impl Iterator<Item = (&Config, &[Run])> {
        self.meshes.iter().flat_map(|m| self.configs_of(m))
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

    /// The runs of `method` (a configuration whatever its mesh: algorithm, horizon, node
    /// budget and time budget; a time budget's calibrated knob may differ, see
    /// [`Config::method`]) on `mesh`, if present.
    pub fn get_on(&self, mesh: &str, method: &Config) -> Option<&[Run]> {
        self.groups
            .iter()
            .find(|(c, _)| c.mesh == mesh && c.method() == method.method())
            .map(|(_, r)| r.as_slice())
    }

    /// Total number of runs.
    pub fn num_runs(&self) -> usize {
        self.groups.values().map(Vec::len).sum()
    }
}

/// Refuses records the report must not believe: with a manifest, a run that is not one of
/// its sweep's configurations (mesh, algorithm, horizon, run index), of another mesh (hash or
/// size) or seed, or above the recorded optimum; without one, values no run can have; in
/// both, a run recorded twice.
fn check(
    dir: &Path,
    manifest: Option<&manifest::Manifest>,
    loaded: &store::Loaded,
) -> Result<(), ReportError> {
    use crate::experiment::ExperimentError;
    if let Some(m) = manifest {
        let jobs = crate::experiment::plan::plan(&m.spec);
        crate::experiment::engine::check_records(dir, m, &jobs, loaded)?;
        return Ok(());
    }
    let path = dir.join(store::RUNS_FILE);
    let mut seen = std::collections::HashMap::new();
    for (r, &line) in loaded.records.iter().zip(&loaded.line_numbers) {
        let corrupt = |message: String| ExperimentError::Corrupt {
            path: path.clone(),
            message,
        };
        crate::experiment::engine::check_values(r, None)
            .map_err(|why| corrupt(format!("line {line}: run {}: {why}", r.key())))?;
        if let Some(first) = seen.insert(r.key(), line) {
            return Err(corrupt(format!(
                "line {line}: run {} is recorded twice (first on line {first})",
                r.key()
            ))
            .into());
        }
    }
    Ok(())
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
