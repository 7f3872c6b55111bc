//! Searches over recombination sequences: the state with undo, the polder criterion, the
//! policies (one registry: [`methods`]), and the exact optimum. Imports `mesh` and the
//! candidate table only.
//!
//! ```no_run
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use quadrecomb::{Algo, CandidateTable, Rule, Searcher};
//! let mesh = quadrecomb::load("sphere")?;
//! // The valid-quad rule, as the command line applies it (without `restrict`: every pair,
//! // eta-0 quads included, as `--allow-invalid`).
//! let table = CandidateTable::build(&mesh).restrict(&mesh, Rule::default());
//! let mut searcher = Searcher::new(&mesh, &table);
//! for seed in 0..4 {
//!     let out = searcher.run(Algo::selective(3), seed);
//!     println!("{} quads, quality {:.2}", out.quads, out.quality);
//! }
//! # Ok(()) }
//! ```

pub mod methods;
pub mod optimum;
mod policy;
pub mod state;

pub use methods::{Algo, AlgoError, Params};

use crate::mesh::Mesh;
use crate::quality::CandidateTable;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use state::State;
use std::fmt;
use std::time::Instant;

/// The result of one run of a policy.
#[derive(Debug, Clone, PartialEq)]
pub struct RunOutcome {
    /// Candidates recombined, in the order they were applied.
    pub chosen: Vec<u32>,
    /// Number of quads created.
    pub quads: usize,
    /// Triangles left (no allowed action remained for them).
    pub triangles_left: usize,
    /// Sum of eta over the quads (eq. 2).
    pub quality: f64,
    /// Tree nodes expanded (nodes whose children were generated); one per decision for the
    /// greedy policies.
    pub nodes_expanded: u64,
    /// Look-ahead trees built: one per decision, except the selective decisions whose drawn
    /// root triangle had a single allowed action (applied without a tree: none could change
    /// it). The greedy policies count each decision as a tree of horizon 1.
    pub trees: u64,
    /// Actions applied (= quads).
    pub decisions: u64,
    /// Time of the search itself, in seconds.
    pub time_s: f64,
}

/// Where a run stands, as its progress callback ([`Searcher::set_progress`]) sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Progress {
    /// Triangles of the mesh.
    pub triangles: usize,
    /// Triangles recombined so far (twice the quads).
    pub recombined: usize,
    /// Look-ahead trees built and tree nodes expanded so far.
    pub trees: u64,
    pub nodes: u64,
    /// Seconds since the run started.
    pub elapsed_s: f64,
}

/// A run's progress callback (the library prints nothing itself).
pub struct ProgressFn(Box<dyn FnMut(&Progress) + Send>);

impl fmt::Debug for ProgressFn {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("ProgressFn")
    }
}

/// The search state, built on first use: greedy without the criterion needs none (and
/// should not pay for every verdict in time and memory).
#[derive(Debug)]
struct LazyState<'a> {
    mesh: &'a Mesh,
    table: &'a CandidateTable,
    state: Option<State<'a>>,
    /// The tree audit hook, set on every state built ([`Searcher::set_tree_audit`]).
    audit: Option<state::TreeAudit>,
}

impl<'a> LazyState<'a> {
    /// Builds the state (every initial verdict) unless it is built. Runs never undo an
    /// applied action: no undo log. The first state keeps no copy of its initial position
    /// (a single run, as `recombine` makes, needs none: about 50 bytes per triangle less at
    /// its peak); [`LazyState::fresh`] replaces it by one that keeps it for the next runs.
    fn ensure(&mut self) {
        if self.state.is_none() {
            let mut state = State::new(self.mesh, self.table);
            state.set_forward_uncopied();
            state.set_tree_audit(self.audit);
            // The work counters count the runs' work, not the initial verdicts'.
            (state.searches, state.searched, state.parity_splits) = (0, 0, 0);
            self.state = Some(state);
        }
    }

    /// The state at its initial position: reset by copying back its initial state, or,
    /// for the first state (which keeps no copy) after a run, built again (the old one
    /// dropped first) with a copy kept for the runs that follow. The work counters carry
    /// over.
    fn fresh(&mut self) {
        self.ensure();
        let state = self.state.as_mut().expect("built above");
        if state.can_reset() {
            state.reset();
            return;
        }
        let counters = (
            state.searches,
            state.searched,
            state.split_shrinks,
            state.parity_splits,
        );
        self.state = None;
        let mut state = State::new(self.mesh, self.table);
        state.set_forward(true);
        state.set_tree_audit(self.audit);
        (
            state.searches,
            state.searched,
            state.split_shrinks,
            state.parity_splits,
        ) = counters;
        self.state = Some(state);
    }
}

impl<'a> std::ops::Deref for LazyState<'a> {
    type Target = State<'a>;
    fn deref(&self) -> &State<'a> {
        self.state
            .as_ref()
            .expect("the state is built before it is used")
    }
}

impl std::ops::DerefMut for LazyState<'_> {
    fn deref_mut(&mut self) -> &mut Self::Target {
        self.state
            .as_mut()
            .expect("the state is built before it is used")
    }
}

/// A reusable searcher for one mesh: the state (with every verdict) is built on the first
/// run that needs it, without a copy of its initial position (a single run needs none);
/// the second run builds it again, keeping that copy, and the runs after it reset by
/// copying, so they allocate nothing new.
#[derive(Debug)]
pub struct Searcher<'a> {
    state: LazyState<'a>,
    /// Candidates by decreasing eta, ties by increasing index.
    order: Vec<u32>,
    /// Position of each candidate in `order`.
    rank: Vec<u32>,
    /// Greedy: ranks before the cursor to look at again (their verdict may have changed).
    revisit: std::collections::BinaryHeap<std::cmp::Reverse<u32>>,
    /// First entry of `order` that may still be live on the main trajectory.
    cursor: usize,
    rng: ChaCha8Rng,
    nodes: u64,
    trees: u64,
    near: Vec<state::Near>,
    used: Vec<bool>,
    /// Uniform tree: ranks of the actions allowed at the root (no other action is allowed
    /// anywhere in the tree).
    allowed_ranks: Vec<u32>,
    /// Position in `order` up to which `allowed_ranks` is built.
    allowed_scan: usize,
    /// Called every 32 decisions of the tree policies, every 2^8 tree nodes and every 4,096
    /// greedy steps.
    progress: Option<ProgressFn>,
    started: Instant,
}

impl<'a> Searcher<'a> {
    /// Calls `f` with the run's progress as it goes (see [`Progress`]); replaces any
    /// callback set before.
    pub fn set_progress(&mut self, f: impl FnMut(&Progress) + Send + 'static) {
        self.progress = Some(ProgressFn(Box::new(f)));
    }

    /// Calls `audit` after every push and pop of the look-ahead trees of the runs that
    /// follow (`None` removes it): a test hook, see [`state::TreeView`]. It sees every tree
    /// node and may query its verdicts; the runs stay the same.
    pub fn set_tree_audit(&mut self, audit: Option<state::TreeAudit>) {
        self.state.audit = audit;
        if let Some(state) = &mut self.state.state {
            state.set_tree_audit(audit);
        }
    }

    /// Reports progress every 32 decisions, counted by the trees (each decision counts its
    /// tree first): a decision of selective h = 1 on `borouchaki` takes about a microsecond,
    /// and a report each cost a sweep 5 % of its time; slow decisions report through their
    /// tree nodes ([`Searcher::count_node`]).
    pub(crate) fn tick_decision(&mut self, quads: usize) {
        if self.trees & 31 == 0 {
            self.tick(quads);
        }
    }

    /// Reports progress to the callback, if any. `quads`: quads made so far.
    pub(crate) fn tick(&mut self, quads: usize) {
        if let Some(ProgressFn(f)) = &mut self.progress {
            f(&Progress {
                triangles: self.state.mesh.num_triangles(),
                recombined: 2 * quads,
                trees: self.trees,
                nodes: self.nodes,
                elapsed_s: self.started.elapsed().as_secs_f64(),
            });
        }
    }

    /// A searcher for `mesh` and `table` (the state and the eta order are built when a run
    /// first needs them).
    ///
    /// # Panics
    /// When `table` was not built for `mesh` ([`CandidateTable::assert_fits`]).
    pub fn new(mesh: &'a Mesh, table: &'a CandidateTable) -> Searcher<'a> {
        table.assert_fits(mesh);
        Searcher {
            state: LazyState {
                mesh,
                table,
                state: None,
                audit: None,
            },
            order: Vec::new(),
            rank: Vec::new(),
            revisit: std::collections::BinaryHeap::new(),
            cursor: 0,
            rng: ChaCha8Rng::seed_from_u64(0),
            nodes: 0,
            trees: 0,
            near: Vec::new(),
            allowed_ranks: Vec::new(),
            allowed_scan: 0,
            used: vec![false; mesh.num_triangles()],
            progress: None,
            started: Instant::now(),
        }
    }

    /// Builds the eta order and ranks (candidates by decreasing eta, ties by increasing
    /// index) unless built: for the policies that read them, before their run's clock.
    fn eta_order(&mut self) {
        let table = self.state.table;
        if self.order.len() == table.len() {
            return;
        }
        self.order = (0..table.len() as u32).collect();
        self.order.sort_by(|&a, &b| {
            table.eta[b as usize]
                .total_cmp(&table.eta[a as usize])
                .then(a.cmp(&b))
        });
        self.rank = vec![0u32; self.order.len()];
        for (i, &c) in self.order.iter().enumerate() {
            self.rank[c as usize] = i as u32;
        }
    }

    /// The state (at its initial position between runs), built if no run built it yet.
    pub fn state(&mut self) -> &State<'a> {
        self.state.fresh();
        &self.state
    }

    /// Work counters of the criterion in this searcher's runs: the checks that needed a
    /// search, and the triangles those searches visited (summed over runs, the initial
    /// verdicts left out; take differences around a run). Deterministic for a given run, unlike its time.
    pub fn criterion_work(&self) -> (u64, u64) {
        self.state
            .state
            .as_ref()
            .map_or((0, 0), |s| (s.searches, s.searched))
    }

    /// Runs `algo` with `seed` from the initial mesh. The same seed gives the same run on
    /// every platform (ChaCha8).
    pub fn run(&mut self, algo: Algo, seed: u64) -> RunOutcome {
        let info = algo.info();
        if info.builds_trees {
            self.state.fresh();
        }
        if info.policy.reads_eta_order() {
            self.eta_order();
        }
        self.cursor = 0;
        self.nodes = 0;
        self.trees = 0;
        self.rng = ChaCha8Rng::seed_from_u64(seed);
        let start = Instant::now();
        self.started = start;
        let chosen = info.policy.run(self, algo.params());
        let time_s = start.elapsed().as_secs_f64();
        let table = self.state.table;
        let quality = table.quality_of(&chosen);
        let quads = chosen.len();
        let out = RunOutcome {
            quads,
            triangles_left: self.state.mesh.num_triangles() - 2 * quads,
            quality,
            nodes_expanded: self.nodes,
            trees: self.trees,
            decisions: quads as u64,
            time_s,
            chosen,
        };
        if let Some(state) = &mut self.state.state
            && state.can_reset()
        {
            state.reset();
        }
        out
    }
}

/// Runs `algo` once on `mesh` (builds a [`Searcher`]; reuse one for many runs).
pub fn run(mesh: &Mesh, table: &CandidateTable, algo: Algo, seed: u64) -> RunOutcome {
    Searcher::new(mesh, table).run(algo, seed)
}
