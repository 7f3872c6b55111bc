//! A sweep's configuration: what was asked for ([`SweepRequest`], any values) becomes a
//! [`SweepConfig`] only through [`SweepConfig::new`], which checks it once; a `SweepConfig`
//! cannot hold an invalid value. The manifest's [`SweepSpec`] and the engine's
//! [`EngineOptions`] are derived from it.
//!
//! Errors name values, not command-line flags ([`ConfigError`]); the command line maps them
//! to its own wording.

use std::path::{Path, PathBuf};

use super::engine::EngineOptions;
use super::manifest::{MeshEntry, Shard, SweepSpec};
use super::plan::{has_budget, has_horizon, planned_runs};
use super::record::algo_names;
use crate::gpu::Backend;
use crate::quality::Rule;

/// Algorithms of the default sweep (the paper's experiment), in order.
pub const DEFAULT_ALGOS: &[&str] = &["selective", "greedy", "greedy-nocrit", "optimum"];
/// The default base seed.
pub const DEFAULT_SEED: u64 = 2026;
/// Most horizons one sweep takes.
pub const MAX_HORIZONS: usize = 1024;
/// Most runs one sweep plans (its run list is held in memory, each run a line of the log).
pub const MAX_RUNS: u64 = 10_000_000;

/// What a sweep is asked to do, before it is checked: any values. [`Default`] is the paper's
/// experiment on `borouchaki` into `results/borouchaki`.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepRequest {
    /// Meshes: built-in names or paths; at least one.
    pub meshes: Vec<String>,
    /// Algorithm names, each one of [`algo_names`] and given once; at least one.
    pub algos: Vec<String>,
    /// Horizons of `uniform` and `selective`: each at least 1 and given once, at most
    /// [`MAX_HORIZONS`]; at least one when a tree algorithm is asked for.
    pub horizons: Vec<u32>,
    /// Node budgets per decision of the methods with one (optimistic, mcts, beam): each in
    /// the registry's range and given once; at least one when such a method is asked for.
    pub budgets: Vec<u32>,
    /// Wall-time budgets per run, each calibrated once into the knob of every method with
    /// one (see [`super::calibrate`]): given once each; not with a shard (every shard would
    /// calibrate on its own).
    pub time_budgets: Vec<super::calibrate::TimeBudget>,
    /// Runs per (mesh, tree algorithm, horizon): at least 1 when a tree algorithm is asked
    /// for, and the whole sweep at most [`MAX_RUNS`] runs.
    pub runs: u32,
    /// Runs of `greedy` and `greedy-nocrit` per mesh: at least 1 when either is asked for.
    pub baseline_runs: u32,
    /// Base seed.
    pub seed: u64,
    /// Worker threads: at least 1.
    pub threads: usize,
    /// Who computes eta (its name is recorded with every run: `cpu-twin`, or `vulkan: `
    /// and the adapter).
    pub backend: Backend,
    /// Which pairs may be merged (valid quads by default); the manifest records it as
    /// `min_eta` and `allow_invalid`.
    pub rule: Rule,
    /// Results directory.
    pub out: PathBuf,
    /// Continue the sweep in `out`.
    pub resume: bool,
    /// Continue the sweep in `out` with this configuration, which may add algorithms,
    /// horizons and runs to the directory's (same meshes, base seed and rule; implies
    /// `resume`).
    pub extend: bool,
    /// Replace an earlier sweep's results in `out`: its runs, manifest, summary, report and
    /// figures (ignored with `resume`).
    pub overwrite: bool,
    /// Run only this slice of the run list.
    pub shard: Option<Shard>,
    /// Finish each search run after its search with these settings (`--finish`).
    pub finish: Option<super::finished::FinishSettings>,
}

impl Default for SweepRequest {
    fn default() -> SweepRequest {
        SweepRequest {
            meshes: vec!["borouchaki".into()],
            algos: DEFAULT_ALGOS.iter().map(|s| s.to_string()).collect(),
            horizons: (1..=10).collect(),
            budgets: vec![crate::search::methods::BUDGET.default],
            time_budgets: Vec::new(),
            runs: 128,
            baseline_runs: 1,
            seed: DEFAULT_SEED,
            threads: std::thread::available_parallelism().map_or(1, |n| n.get()),
            backend: Backend::Cpu,
            rule: Rule::default(),
            out: PathBuf::from("results/borouchaki"),
            resume: false,
            extend: false,
            overwrite: false,
            shard: None,
            finish: None,
        }
    }
}

/// Why a [`SweepRequest`] is not a sweep. Each names the value at fault.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ConfigError {
    /// The mesh list is empty.
    #[error("no mesh given")]
    NoMesh,
    /// The algorithm list is empty.
    #[error("no algorithm given")]
    NoAlgorithm,
    /// An algorithm name is not one of [`algo_names`].
    #[error("unknown algorithm {0:?} (expected one of {names})", names = algo_names().join(", "))]
    UnknownAlgorithm(String),
    /// An algorithm is listed twice.
    #[error("algorithm {0:?} given twice")]
    DuplicateAlgorithm(String),
    /// A tree algorithm is asked for, with no horizon.
    #[error("no horizon given")]
    NoHorizon,
    /// A horizon of 0.
    #[error("horizons must be at least 1")]
    ZeroHorizon,
    /// A horizon listed twice.
    #[error("horizon {0} given twice")]
    DuplicateHorizon(u32),
    /// Zero runs per (mesh, tree algorithm, horizon), with a tree algorithm asked for.
    #[error("the runs per configuration must be at least 1")]
    ZeroRuns,
    /// Zero runs of the baselines named, with a baseline asked for.
    #[error("the runs of {} must be at least 1", .0.join(", "))]
    ZeroBaselineRuns(Vec<String>),
    /// Zero worker threads.
    #[error("the worker threads must be at least 1")]
    ZeroThreads,
    /// A method with a node budget is asked for without any budget.
    #[error("no budget given for the methods with a node budget")]
    NoBudget,
    /// A budget is out of range or given twice.
    #[error("budget {0} is out of range (1..=16777216) or given twice")]
    BadBudget(u32),
    /// A time budget given twice.
    #[error("time budget {0} given twice")]
    DuplicateTimeBudget(super::calibrate::TimeBudget),
    /// Time budgets given, but none of the methods has a knob to calibrate.
    #[error(
        "time budgets given, but none of the methods has a horizon or node budget to \
         calibrate ({0})"
    )]
    TimeBudgetUnused(String),
    /// Time budgets with a shard: each shard would calibrate on its own machine.
    #[error(
        "time budgets cannot be sharded: each shard would calibrate its own knobs, and the \
         shards would not merge (run the sweep whole)"
    )]
    TimeBudgetSharded,
    /// A base seed above 2^53 - 1, which JSON readers that hold numbers as doubles (jq,
    /// pandas with pyarrow) would read as another seed.
    #[error(
        "base seed {0} is above 2^53 - 1 = {max}, which jq and pandas would read rounded",
        max = super::seed::MAX_EXACT_SEED
    )]
    SeedTooLarge(u64),
    /// More horizons or runs than a sweep holds.
    #[error(transparent)]
    TooLarge(#[from] SizeError),
}

/// A sweep larger than [`MAX_HORIZONS`] or [`MAX_RUNS`] (its run list is held in memory).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum SizeError {
    /// This many horizons.
    #[error("{0} horizons, more than a sweep takes ({MAX_HORIZONS})")]
    Horizons(usize),
    /// This many runs, from these counts.
    #[error("{total} runs, more than a sweep takes ({MAX_RUNS})")]
    Runs {
        /// Runs planned.
        total: u64,
        /// Runs per (mesh, tree algorithm, horizon).
        runs: u32,
        /// Runs per mesh of each baseline.
        baseline_runs: u32,
        /// Horizons.
        horizons: usize,
        /// Algorithms.
        algos: usize,
        /// Meshes.
        meshes: usize,
    },
}

/// Checks that a sweep of these sizes can be planned (counted before its run list is built),
/// for a new sweep and for a manifest read back alike.
pub fn check_size(
    meshes: usize,
    algos: &[String],
    horizons: usize,
    budgets: usize,
    time_budgets: usize,
    runs: u32,
    baseline_runs: u32,
) -> Result<(), SizeError> {
    if horizons > MAX_HORIZONS {
        return Err(SizeError::Horizons(horizons));
    }
    let total = planned_runs(
        meshes,
        algos,
        horizons,
        budgets,
        time_budgets,
        runs,
        baseline_runs,
    );
    if total > MAX_RUNS {
        return Err(SizeError::Runs {
            total,
            runs,
            baseline_runs,
            horizons,
            algos: algos.len(),
            meshes,
        });
    }
    Ok(())
}

/// A checked sweep configuration: made only by [`SweepConfig::new`], read through its
/// accessors.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepConfig(SweepRequest);

impl SweepConfig {
    /// Checks `request` and makes it a configuration, or says what is wrong with it.
    pub fn new(request: SweepRequest) -> Result<SweepConfig, ConfigError> {
        let r = &request;
        if r.meshes.is_empty() {
            return Err(ConfigError::NoMesh);
        }
        if r.algos.is_empty() {
            return Err(ConfigError::NoAlgorithm);
        }
        for (i, a) in r.algos.iter().enumerate() {
            if !algo_names().contains(&a.as_str()) {
                return Err(ConfigError::UnknownAlgorithm(a.clone()));
            }
            if r.algos[..i].contains(a) {
                return Err(ConfigError::DuplicateAlgorithm(a.clone()));
            }
        }
        if r.algos.iter().any(|a| has_horizon(a)) {
            if r.horizons.is_empty() {
                return Err(ConfigError::NoHorizon);
            }
            if r.horizons.contains(&0) {
                return Err(ConfigError::ZeroHorizon);
            }
            if r.runs == 0 {
                return Err(ConfigError::ZeroRuns);
            }
        }
        if r.seed > super::seed::MAX_EXACT_SEED {
            return Err(ConfigError::SeedTooLarge(r.seed));
        }
        // The baseline runs count the runs of the deterministic configurations (the optimum
        // always runs once).
        let baselines: Vec<String> = (r.algos.iter())
            .filter(|a| super::plan::runs_as_baseline(a))
            .cloned()
            .collect();
        if r.baseline_runs == 0 && !baselines.is_empty() {
            return Err(ConfigError::ZeroBaselineRuns(baselines));
        }
        for (i, h) in r.horizons.iter().enumerate() {
            if r.horizons[..i].contains(h) {
                return Err(ConfigError::DuplicateHorizon(*h));
            }
        }
        for (i, t) in r.time_budgets.iter().enumerate() {
            if r.time_budgets[..i].contains(t) {
                return Err(ConfigError::DuplicateTimeBudget(*t));
            }
        }
        if !r.time_budgets.is_empty() {
            if !r.algos.iter().any(|a| super::calibrate::has_knob(a)) {
                return Err(ConfigError::TimeBudgetUnused(r.algos.join(", ")));
            }
            if r.shard.is_some() {
                return Err(ConfigError::TimeBudgetSharded);
            }
        }
        if r.algos.iter().any(|a| has_budget(a)) {
            if r.budgets.is_empty() && r.time_budgets.is_empty() {
                return Err(ConfigError::NoBudget);
            }
            let range = crate::search::methods::BUDGET;
            for (i, b) in r.budgets.iter().enumerate() {
                if *b < range.min || *b > range.max || r.budgets[..i].contains(b) {
                    return Err(ConfigError::BadBudget(*b));
                }
            }
        }
        if r.threads == 0 {
            return Err(ConfigError::ZeroThreads);
        }
        check_size(
            r.meshes.len(),
            &r.algos,
            r.horizons.len(),
            r.budgets.len(),
            r.time_budgets.len(),
            r.runs,
            r.baseline_runs,
        )?;
        Ok(SweepConfig(request))
    }

    /// The paper's experiment on `borouchaki` into `results/borouchaki`.
    pub fn paper() -> SweepConfig {
        SweepConfig::new(SweepRequest::default()).expect("the default request is valid")
    }

    /// Meshes: built-in names or paths.
    pub fn meshes(&self) -> &[String] {
        &self.0.meshes
    }

    /// Algorithm names, in order.
    pub fn algos(&self) -> &[String] {
        &self.0.algos
    }

    /// Horizons of `uniform` and `selective`.
    pub fn horizons(&self) -> &[u32] {
        &self.0.horizons
    }

    /// Wall-time budgets per run, to calibrate.
    pub fn time_budgets(&self) -> &[super::calibrate::TimeBudget] {
        &self.0.time_budgets
    }

    /// Runs per (mesh, tree algorithm, horizon).
    pub fn runs(&self) -> u32 {
        self.0.runs
    }

    /// Runs of `greedy` and `greedy-nocrit` per mesh.
    pub fn baseline_runs(&self) -> u32 {
        self.0.baseline_runs
    }

    /// Base seed.
    pub fn seed(&self) -> u64 {
        self.0.seed
    }

    /// Worker threads (at least 1).
    pub fn threads(&self) -> usize {
        self.0.threads
    }

    /// Who computes eta.
    pub fn backend(&self) -> Backend {
        self.0.backend
    }

    /// Which pairs may be merged.
    pub fn rule(&self) -> Rule {
        self.0.rule
    }

    /// Results directory.
    pub fn out(&self) -> &Path {
        &self.0.out
    }

    /// Whether the sweep in [`Self::out`] is continued.
    pub fn resume(&self) -> bool {
        self.0.resume || self.0.extend
    }

    /// Whether the sweep in [`Self::out`] may be extended to this configuration.
    pub fn extend(&self) -> bool {
        self.0.extend
    }

    /// Whether an earlier sweep's results in [`Self::out`] are replaced (not with resume).
    pub fn overwrite(&self) -> bool {
        self.0.overwrite && !self.resume()
    }

    /// The slice of the run list to run, if not all of it.
    pub fn shard(&self) -> Option<Shard> {
        self.0.shard
    }

    /// The manifest's spec of this sweep over `meshes` (the loaded meshes' entries, in the
    /// order of [`Self::meshes`]). Horizons are kept only when a tree algorithm uses them.
    pub fn spec(&self, meshes: Vec<MeshEntry>) -> SweepSpec {
        let c = &self.0;
        SweepSpec {
            meshes,
            algos: c.algos.clone(),
            horizons: if c.algos.iter().any(|a| has_horizon(a)) {
                c.horizons.clone()
            } else {
                Vec::new()
            },
            budgets: if c.algos.iter().any(|a| has_budget(a)) {
                c.budgets.clone()
            } else {
                Vec::new()
            },
            time_budgets: if c.algos.iter().any(|a| super::calibrate::has_knob(a)) {
                c.time_budgets.clone()
            } else {
                Vec::new()
            },
            calibration: Vec::new(),
            runs: c.runs,
            baseline_runs: c.baseline_runs,
            seed: c.seed,
            min_eta: c.rule.min_eta(),
            allow_invalid: c.rule.allows_invalid(),
            plan_version: super::seed::PLAN_VERSION,
            finish: c.finish,
        }
    }

    /// The engine's options for this sweep.
    pub fn engine_options(&self) -> EngineOptions {
        EngineOptions {
            dir: self.0.out.clone(),
            resume: self.resume(),
            extend: self.0.extend,
            overwrite: self.overwrite(),
            threads: self.0.threads,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn with(f: impl FnOnce(&mut SweepRequest)) -> Result<SweepConfig, ConfigError> {
        let mut r = SweepRequest::default();
        f(&mut r);
        SweepConfig::new(r)
    }

    #[test]
    fn each_invalid_value_is_refused_by_name() {
        let strings = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        assert!(with(|_| {}).is_ok());
        assert_eq!(with(|r| r.meshes.clear()), Err(ConfigError::NoMesh));
        assert_eq!(with(|r| r.algos.clear()), Err(ConfigError::NoAlgorithm));
        assert_eq!(
            with(|r| r.algos = strings(&["greedy", "best"])),
            Err(ConfigError::UnknownAlgorithm("best".into()))
        );
        assert_eq!(
            with(|r| r.algos = strings(&["greedy", "greedy"])),
            Err(ConfigError::DuplicateAlgorithm("greedy".into()))
        );
        assert_eq!(with(|r| r.horizons.clear()), Err(ConfigError::NoHorizon));
        assert_eq!(
            with(|r| r.horizons = vec![0]),
            Err(ConfigError::ZeroHorizon)
        );
        assert_eq!(with(|r| r.runs = 0), Err(ConfigError::ZeroRuns));
        assert_eq!(
            with(|r| r.seed = 1 << 53),
            Err(ConfigError::SeedTooLarge(1 << 53))
        );
        assert!(with(|r| r.seed = (1 << 53) - 1).is_ok());
        assert_eq!(
            with(|r| r.baseline_runs = 0),
            Err(ConfigError::ZeroBaselineRuns(strings(&[
                "greedy",
                "greedy-nocrit"
            ])))
        );
        assert_eq!(
            with(|r| r.horizons = vec![2, 3, 2]),
            Err(ConfigError::DuplicateHorizon(2))
        );
        assert_eq!(with(|r| r.threads = 0), Err(ConfigError::ZeroThreads));
        assert_eq!(
            with(|r| r.horizons = (1..=1025).collect()),
            Err(SizeError::Horizons(1025).into())
        );
        let too_many = with(|r| r.runs = u32::MAX).unwrap_err();
        assert!(
            matches!(too_many, ConfigError::TooLarge(SizeError::Runs { runs, .. }) if runs == u32::MAX),
            "{too_many}"
        );
        // Without a tree algorithm, horizons and runs are not used, so not checked.
        assert!(
            with(|r| {
                r.algos = strings(&["greedy"]);
                r.horizons.clear();
                r.runs = 0;
            })
            .is_ok()
        );
        // No message names a command-line flag.
        for e in [
            ConfigError::ZeroRuns,
            ConfigError::ZeroBaselineRuns(strings(&["greedy"])),
            ConfigError::ZeroThreads,
            too_many,
        ] {
            assert!(!e.to_string().contains("--"), "{e}");
        }
    }

    #[test]
    fn spec_and_engine_options_are_derived() {
        let c = with(|r| {
            r.algos = vec!["greedy".into()];
            r.overwrite = true;
            r.resume = true;
            r.threads = 3;
        })
        .unwrap();
        let spec = c.spec(Vec::new());
        assert!(spec.horizons.is_empty(), "greedy has no horizon");
        assert_eq!((spec.runs, spec.seed), (128, DEFAULT_SEED));
        assert_eq!(spec.rule(), Rule::default());
        let o = c.engine_options();
        assert_eq!((o.resume, o.overwrite, o.threads), (true, false, 3));
        assert_eq!(o.dir, PathBuf::from("results/borouchaki"));
    }
}
