//! One run's result: the line format of `runs.jsonl`.
//!
//! Every finished run of a sweep is one [`RunRecord`], written as one JSON object on one line of
//! `runs.jsonl` and flushed at once, so that a killed sweep loses at most the line it was writing.
//! The field names are a stable contract read by `report` and by external tools.

use serde::{Deserialize, Serialize};

/// The algorithm names a record's `algo` field takes: the registry's
/// ([`crate::search::methods::METHODS`]).
pub fn algo_names() -> Vec<&'static str> {
    crate::search::methods::names().collect()
}

/// The result of one run of one algorithm on one mesh.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunRecord {
    /// Name of the mesh (built-in name or file stem).
    pub mesh: String,
    /// blake3 hex digest of the mesh's canonical content (see [`super::mesh_hash`]).
    pub mesh_hash: String,
    /// Number of triangles of the input mesh.
    pub triangles: usize,
    /// A method's name ([`algo_names`]: "greedy-nocrit", "greedy", "uniform", "selective",
    /// "optimum", "optimistic", "mcts", "beam").
    pub algo: String,
    /// Look-ahead horizon of the methods with one; `None` for the others.
    pub horizon: Option<u32>,
    /// Tree nodes per decision of the methods with a budget (optimistic, mcts, beam);
    /// absent for the others.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub budget: Option<u32>,
    /// The wall-time budget per run (seconds) that `horizon` or `budget` was calibrated for
    /// (`sweep --time-budgets`, see [`super::calibrate`]); absent for the others.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_budget_s: Option<super::calibrate::TimeBudget>,
    /// The per-run seed given to the search, derived by [`super::seed::derive_seed`].
    pub seed: u64,
    /// Index of the run within its (mesh, algo, horizon) configuration, from 0.
    pub run: u32,
    /// Quads created.
    pub quads: usize,
    /// Triangles left unrecombined.
    pub triangles_left: usize,
    /// 100 * 2 * quads / triangles.
    pub recombined_pct: f64,
    /// Sum of eta over the quads (the paper's eq. 2).
    pub quality: f64,
    /// 100 * quality / optimum quality of the mesh, when the optimum is known.
    pub quality_pct: Option<f64>,
    /// Seconds spent in the search (or the matching, for "optimum"), excluding loading and eta.
    pub time_s: f64,
    /// Tree nodes expanded by the search; `None` (null) for the algorithms that build no
    /// tree, "greedy-nocrit" and "optimum" (see [`builds_trees`]). Older records have 0 for
    /// the optimum and the decisions for greedy-nocrit, and are read as they are.
    pub nodes_expanded: Option<u64>,
    /// Look-ahead trees the search built: one per decision, except the selective decisions
    /// whose root triangle had a single allowed action (no tree can change those); greedy's
    /// are one-node trees (a uniform tree of horizon 1), one per decision. `None` (null) for
    /// "greedy-nocrit" and "optimum", which build none, and in records written before this
    /// field existed.
    #[serde(default)]
    pub trees: Option<u64>,
    /// Actions applied (decisions taken) by the search; quads for "optimum".
    pub decisions: u64,
    /// Effective branching factor of the look-ahead tree, for `uniform` and `selective` with
    /// h >= 2: the b with 1 + b + ... + b^(h-1) = nodes_expanded / trees (a tree of horizon
    /// h expands the nodes of depths 0..h-1; see
    /// [`crate::stats::describe::effective_branching_factor`]). `None` for h = 1 (only the root
    /// is expanded, whatever its width), for the other algorithms, and without trees.
    pub branching_factor: Option<f64>,
    /// The worst quad's eta (`None` without quads, and in records written before it existed).
    #[serde(default)]
    pub worst_eta: Option<f64>,
    /// Mean eta per quad (`quality / quads`; `None` without quads).
    #[serde(default)]
    pub mean_eta: Option<f64>,
    /// Quads with eta < 0.1 (poor elements).
    #[serde(default)]
    pub quads_eta_below_0_1: Option<usize>,
    /// Quads with eta < 0.3.
    #[serde(default)]
    pub quads_eta_below_0_3: Option<usize>,
    /// The quad-validity rule's threshold: only quads with eta > 0 and eta >= `min_eta` are
    /// made (see [`crate::quality::Rule`]); 0 under `allow_invalid`.
    #[serde(default)]
    pub min_eta: f64,
    /// Every pair was an action, eta-0 quads included (the paper as written). Records made
    /// before the rule existed were made so, and read as such.
    #[serde(default = "paper_literal")]
    pub allow_invalid: bool,
    /// Name of the evaluator that computed eta ("cpu-twin", "vulkan: llvmpipe ...", ...).
    pub backend: String,
    /// Version of quadrecomb that made the record.
    pub version: String,
    /// The run after `sweep --finish` (leftover elimination and local improvement, see
    /// docs/finish.md); absent without it. The fields above stay the search's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub finish: Option<super::finished::FinishRecord>,
}

/// Whether `algo` (a record's name) searches with look-ahead trees, so that its
/// `nodes_expanded` and `trees` apply: not "greedy-nocrit" (no criterion, no tree) nor
/// "optimum" (a matching), whose records hold null there, as `optimum --json` does.
pub fn builds_trees(algo: &str) -> bool {
    crate::search::methods::find(algo).is_some_and(|m| m.builds_trees)
}

pub use crate::search::methods::{Params, label};

/// A method's place in the reports' order (the registry's rank; unknown names last).
pub fn algo_rank(algo: &str) -> u8 {
    crate::search::methods::find(algo).map_or(u8::MAX, |m| m.rank)
}

/// Whether `algo` is a search run per seed (not the optimum, solved once per mesh).
pub fn is_search(algo: &str) -> bool {
    crate::search::methods::find(algo).is_some_and(|m| m.search)
}

/// What a field that records the rule reads when absent: the rule of every record and
/// manifest written before it existed (every pair an action).
pub(crate) fn paper_literal() -> bool {
    true
}

impl RunRecord {
    /// The rule the run was made under.
    pub fn rule(&self) -> crate::quality::Rule {
        crate::quality::Rule::new(self.min_eta, self.allow_invalid)
            .unwrap_or(crate::quality::Rule::AllPairs)
    }
}

/// Identifies a run within a sweep: no two records of a results directory share a key.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct RunKey {
    /// Mesh name.
    pub mesh: String,
    /// Algorithm name.
    pub algo: String,
    /// Horizon, for tree policies.
    pub horizon: Option<u32>,
    /// Budget, for the budgeted policies.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub budget: Option<u32>,
    /// Time budget, for the configurations calibrated to one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_budget_s: Option<super::calibrate::TimeBudget>,
    /// Run index.
    pub run: u32,
}

impl std::fmt::Display for RunKey {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} {}", self.mesh, self.algo)?;
        if let Some(h) = self.horizon {
            write!(f, " h={h}")?;
        }
        if let Some(b) = self.budget {
            write!(f, " b={b}")?;
        }
        if let Some(t) = self.time_budget_s {
            write!(f, " T={}s", t.seconds())?;
        }
        write!(f, " run {}", self.run)
    }
}

impl RunRecord {
    /// The record's key.
    pub fn key(&self) -> RunKey {
        RunKey {
            mesh: self.mesh.clone(),
            algo: self.algo.clone(),
            horizon: self.horizon,
            budget: self.budget,
            time_budget_s: self.time_budget_s,
            run: self.run,
        }
    }

    /// Whether two records hold the same result: every field but `time_s` and the finish's
    /// times (wall-clock time differs between any two executions) is equal.
    pub fn same_result(&self, other: &RunRecord) -> bool {
        let mut a = self.clone();
        a.time_s = other.time_s;
        let mut b = other.clone();
        a.finish = a.finish.as_ref().map(|f| f.without_times());
        b.finish = b.finish.as_ref().map(|f| f.without_times());
        a == b
    }

    /// The record as one JSON line, without the newline.
    pub fn to_json_line(&self) -> String {
        serde_json::to_string(self).expect("a RunRecord always serializes")
    }
}

/// A run's `recombined_pct`: `100 * 2 * quads / triangles` (0 for a mesh without triangles).
/// The one definition that records are written with and checked against.
pub fn recombined_pct(quads: usize, triangles: usize) -> f64 {
    if triangles == 0 {
        0.0
    } else {
        100.0 * 2.0 * quads as f64 / triangles as f64
    }
}

/// A run's `branching_factor` from its tree counts. A tree of horizon h expands the nodes at
/// depths 0..h-1: 1 + b + ... + b^(h-1) per tree; solve for b (the nodes below the root:
/// b + ... + b^(h-1) = N - 1). A tree of horizon 1 expands only its root, whatever its width:
/// no branching factor; nor without trees.
pub fn branching_factor(horizon: Option<u32>, nodes: u64, trees: u64) -> Option<f64> {
    match horizon {
        Some(h) if h >= 2 && trees > 0 => crate::stats::describe::effective_branching_factor(
            nodes as f64 / trees as f64 - 1.0,
            h - 1,
        ),
        _ => None,
    }
}
