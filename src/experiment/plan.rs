//! The run list of a sweep, its sharding, and the order runs execute in.

use super::calibrate::{TimeBudget, has_knob};
use super::manifest::{Shard, SweepSpec};
use super::record::RunKey;
use super::seed::derive_seed;

use crate::search::methods::{self, ParamKind};

/// Algorithms with a look-ahead horizon (the registry's methods with a horizon parameter).
pub fn has_horizon(algo: &str) -> bool {
    methods::find(algo).is_some_and(|m| m.has(ParamKind::Horizon))
}

/// Algorithms with a node budget per decision (one configuration per `budgets` entry).
pub fn has_budget(algo: &str) -> bool {
    methods::find(algo).is_some_and(|m| m.has(ParamKind::Budget))
}

/// Algorithms that draw nothing at random and run `baseline_runs` times (plan version 2):
/// every run of one configuration is the same run (the registry's searches that are not
/// random: greedy and greedy-nocrit break ties by index, the uniform tree branches on every
/// action). The optimum, exact and no search, runs once.
pub fn runs_as_baseline(algo: &str) -> bool {
    methods::find(algo).is_some_and(|m| m.search && !m.random)
}

/// Plan version 1 ran the uniform tree `runs` times per horizon, as if it were random.
fn random_in(algo: &str, version: u32) -> bool {
    methods::find(algo).is_some_and(|m| m.random) || (algo == "uniform" && version < 2)
}

/// Whether `spec`'s run list uses its `runs` (a randomized tree algorithm: `selective` and
/// the budgeted policies, and `uniform` in plan version 1).
pub fn uses_runs(spec: &SweepSpec) -> bool {
    spec.algos.iter().any(|a| random_in(a, spec.plan_version))
}

/// Whether `spec`'s run list uses its `baseline_runs` (a deterministic configuration other
/// than the optimum).
pub fn uses_baseline_runs(spec: &SweepSpec) -> bool {
    spec.algos
        .iter()
        .any(|a| runs_as_baseline(a) && !random_in(a, spec.plan_version))
}

/// Runs per configuration of `algo` (per horizon and budget) under plan `version`.
fn runs_of(algo: &str, version: u32, runs: u32, baseline_runs: u32) -> u32 {
    match methods::find(algo) {
        Some(m) if !m.search => 1,
        _ if random_in(algo, version) => runs,
        _ => baseline_runs,
    }
}

/// One run to do.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Job {
    /// Position of the mesh in the spec.
    pub mesh: usize,
    /// Algorithm name.
    pub algo: String,
    /// Horizon, for the methods with one.
    pub horizon: Option<u32>,
    /// Nodes per decision, for the methods with a budget.
    pub budget: Option<u32>,
    /// The wall-time budget the horizon or node budget was calibrated for (`--time-budgets`).
    pub time_budget: Option<TimeBudget>,
    /// Run index within the configuration.
    pub run: u32,
    /// The derived seed.
    pub seed: u64,
}

impl Job {
    /// The key of the record this job makes.
    pub fn key(&self, spec: &SweepSpec) -> RunKey {
        RunKey {
            mesh: spec.meshes[self.mesh].name.clone(),
            algo: self.algo.clone(),
            horizon: self.horizon,
            budget: self.budget,
            time_budget_s: self.time_budget,
            run: self.run,
        }
    }
}

/// The number of runs [`plan`] makes under the current plan version, counted without making
/// them (saturating).
pub fn planned_runs(
    meshes: usize,
    algos: &[String],
    horizons: usize,
    budgets: usize,
    time_budgets: usize,
    runs: u32,
    baseline_runs: u32,
) -> u64 {
    let version = super::seed::PLAN_VERSION;
    let per_mesh = algos
        .iter()
        .map(|a| {
            let one = u64::from(runs_of(a, version, runs, baseline_runs));
            let mut n = one;
            if has_horizon(a) {
                n = (horizons as u64).saturating_mul(n);
            }
            if has_budget(a) {
                n = (budgets as u64).saturating_mul(n);
            }
            // A time budget is one more configuration per horizon of a budgeted method, and
            // one per mesh of selective and uniform (their horizon is the knob).
            if has_knob(a) {
                let per = if has_budget(a) { horizons as u64 } else { 1 };
                let timed = (time_budgets as u64)
                    .saturating_mul(per)
                    .saturating_mul(one);
                n = n.saturating_add(timed);
            }
            n
        })
        .fold(0u64, u64::saturating_add);
    per_mesh.saturating_mul(meshes as u64)
}

/// Every run of a sweep, in canonical order: by mesh, then algorithm (spec order), then
/// horizon, then budget, then run index. `optimum` is one run per mesh; `greedy` and `greedy-nocrit` are
/// `baseline_runs` runs; `selective` is `runs` runs per horizon; `uniform`, deterministic, is
/// `baseline_runs` runs per horizon (plan version 2; `runs` in version 1).
pub fn plan(spec: &SweepSpec) -> Vec<Job> {
    let mut jobs = Vec::new();
    for (m, mesh) in spec.meshes.iter().enumerate() {
        for algo in &spec.algos {
            let runs = runs_of(algo, spec.plan_version, spec.runs, spec.baseline_runs);
            let horizons: Vec<Option<u32>> = if has_horizon(algo) {
                spec.horizons.iter().map(|&h| Some(h)).collect()
            } else {
                vec![None]
            };
            let budgets: Vec<Option<u32>> = if has_budget(algo) {
                spec.budgets.iter().map(|&b| Some(b)).collect()
            } else {
                vec![None]
            };
            for horizon in horizons {
                for &budget in &budgets {
                    // A budget enters the seed as part of the name ("mcts b=64"), so that
                    // the configurations without one keep their seeds.
                    let named = match budget {
                        Some(b) => format!("{algo} b={b}"),
                        None => algo.clone(),
                    };
                    for run in 0..runs {
                        jobs.push(Job {
                            mesh: m,
                            algo: algo.clone(),
                            horizon,
                            budget,
                            time_budget: None,
                            run,
                            seed: derive_seed(
                                spec.plan_version,
                                spec.seed,
                                &mesh.hash,
                                &named,
                                horizon,
                                run,
                            ),
                        });
                    }
                }
            }
            if has_knob(algo) {
                timed_jobs(spec, m, algo, runs, &mut jobs);
            }
        }
    }
    jobs
}

/// The runs of `algo` on mesh `m` at each of the spec's time budgets, with the knob its
/// calibration chose (a time budget not calibrated yet has no runs). A time budget enters the
/// seed as part of the name ("mcts t=0.2"); the node budget chosen does not, so the runs of
/// optimistic, mcts and beam at a time budget have the same seeds on any machine, but the
/// horizon chosen for selective and uniform does (it is the seed's horizon).
fn timed_jobs(spec: &SweepSpec, m: usize, algo: &str, runs: u32, jobs: &mut Vec<Job>) {
    let mesh = &spec.meshes[m];
    let horizons: Vec<Option<u32>> = if has_budget(algo) {
        spec.horizons.iter().map(|&h| Some(h)).collect()
    } else {
        vec![None]
    };
    for given in horizons {
        for &t in &spec.time_budgets {
            let Some(c) = super::calibrate::find(spec, &mesh.name, algo, given, t) else {
                continue;
            };
            let named = format!("{algo} t={}", t.seconds());
            for run in 0..runs {
                jobs.push(Job {
                    mesh: m,
                    algo: algo.to_string(),
                    horizon: Some(c.horizon),
                    budget: c.budget,
                    time_budget: Some(t),
                    run,
                    seed: derive_seed(
                        spec.plan_version,
                        spec.seed,
                        &mesh.hash,
                        &named,
                        Some(c.horizon),
                        run,
                    ),
                });
            }
        }
    }
}

/// The jobs of one shard: job number k (0-based, canonical order) belongs to shard
/// `k % count + 1`. Striding spreads every configuration (and so the cost) evenly over shards.
pub fn shard(jobs: Vec<Job>, shard: Option<Shard>) -> Vec<Job> {
    match shard {
        None => jobs,
        Some(s) => jobs
            .into_iter()
            .enumerate()
            .filter(|(k, _)| (*k as u64) % u64::from(s.count) == u64::from(s.index - 1))
            .map(|(_, j)| j)
            .collect(),
    }
}

/// Execution order: interleaved by run index (run 0 of every configuration, then run 1, ...),
/// with the most expensive configurations (highest horizon) first within a round. An
/// interrupted sweep then holds about as many runs of every configuration, and the progress
/// rate (and ETA) stays steady.
pub fn execution_order(jobs: &mut [Job]) {
    jobs.sort_by_key(|j| {
        (
            j.run,
            std::cmp::Reverse(j.horizon.unwrap_or(0)),
            j.mesh,
            j.algo.clone(),
        )
    });
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::experiment::manifest::MeshEntry;

    pub(crate) fn spec() -> SweepSpec {
        SweepSpec {
            finish: None,
            meshes: vec![
                MeshEntry {
                    name: "a".into(),
                    source: "a".into(),
                    path: None,
                    hash: "aa".into(),
                    triangles: 10,
                },
                MeshEntry {
                    name: "b".into(),
                    source: "b.msh".into(),
                    path: None,
                    hash: "bb".into(),
                    triangles: 20,
                },
            ],
            algos: vec![
                "selective".into(),
                "greedy".into(),
                "greedy-nocrit".into(),
                "optimum".into(),
            ],
            horizons: vec![1, 2, 3],
            runs: 5,
            baseline_runs: 2,
            seed: 9,
            min_eta: 0.0,
            allow_invalid: false,
            plan_version: crate::experiment::seed::PLAN_VERSION,
            budgets: Vec::new(),
            time_budgets: Vec::new(),
            calibration: Vec::new(),
        }
    }

    #[test]
    fn the_uniform_tree_runs_once_per_horizon_from_plan_version_2() {
        let mut s = spec();
        s.algos = vec!["uniform".into(), "selective".into()];
        let count = |s: &SweepSpec, algo: &str| plan(s).iter().filter(|j| j.algo == algo).count();
        // Version 2: uniform, deterministic, like the baselines (2 runs per horizon here).
        assert_eq!(count(&s, "uniform"), 2 * 3 * 2);
        assert_eq!(count(&s, "selective"), 2 * 3 * 5);
        assert_eq!(
            planned_runs(2, &s.algos, 3, 0, 0, s.runs, s.baseline_runs),
            plan(&s).len() as u64
        );
        // Version 1 (older manifests) keeps its run list, so those sweeps still resume.
        s.plan_version = 1;
        assert_eq!(count(&s, "uniform"), 2 * 3 * 5);
        assert!(
            plan(&s)
                .iter()
                .any(|j| j.seed > crate::experiment::seed::MAX_EXACT_SEED)
        );
    }

    #[test]
    fn plan_counts_and_unique_keys() {
        let s = spec();
        let jobs = plan(&s);
        assert_eq!(jobs.len(), 2 * (3 * 5 + 2 + 2 + 1));
        let keys: std::collections::BTreeSet<_> = jobs.iter().map(|j| j.key(&s)).collect();
        assert_eq!(keys.len(), jobs.len());
        let seeds: std::collections::BTreeSet<_> = jobs.iter().map(|j| j.seed).collect();
        assert_eq!(seeds.len(), jobs.len());
        assert!(
            jobs.iter()
                .all(|j| j.horizon.is_some() == (j.algo == "selective"))
        );
    }

    #[test]
    fn shards_partition_the_plan() {
        let s = spec();
        let all = plan(&s);
        for n in [1u32, 2, 3, 7, 100] {
            let mut union = Vec::new();
            for i in 1..=n {
                let part = shard(all.clone(), Some(Shard { index: i, count: n }));
                let expected = all.len() / n as usize;
                assert!(part.len() == expected || part.len() == expected + 1);
                union.extend(part);
            }
            union.sort_by_key(|j| j.key(&s));
            let mut want = all.clone();
            want.sort_by_key(|j| j.key(&s));
            assert_eq!(union, want, "{n} shards");
        }
    }

    #[test]
    fn shard_parsing() {
        assert_eq!("2/3".parse::<Shard>(), Ok(Shard { index: 2, count: 3 }));
        assert!("0/3".parse::<Shard>().is_err());
        assert!("4/3".parse::<Shard>().is_err());
        assert!("1/0".parse::<Shard>().is_err());
        assert!("x".parse::<Shard>().is_err());
    }

    #[test]
    fn execution_order_is_a_permutation_interleaved_by_run() {
        let s = spec();
        let mut jobs = plan(&s);
        let mut sorted = jobs.clone();
        execution_order(&mut jobs);
        assert_eq!(jobs[0].run, 0);
        assert_eq!(jobs[0].horizon, Some(3));
        assert!(jobs.windows(2).all(|w| w[0].run <= w[1].run));
        jobs.sort_by_key(|j| j.key(&s));
        sorted.sort_by_key(|j| j.key(&s));
        assert_eq!(jobs, sorted);
    }
}
