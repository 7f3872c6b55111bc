//! The registry of methods: every policy and the exact optimum, each described once (name,
//! one line of help, parameters, whether it draws at random, whether it builds trees, its
//! place in reports) with how to run it. The command line, the sweep's plan, the records,
//! the summaries and the reports read this list; adding a policy is one file in this folder
//! and one line in [`METHODS`].
//!
//! A method with its parameter values is an [`Algo`], serialised as the strings records have
//! always held (`algo`, `horizon`, and `budget` for the methods that have one).

mod beam;
mod greedy;
mod greedy_nocrit;
mod mcts;
mod optimistic;
mod optimum;
mod selective;
mod uniform;

use super::Searcher;
use std::fmt;
use std::str::FromStr;

/// Every method, in the order help lists them.
pub static METHODS: &[&Info] = &[
    &greedy_nocrit::INFO,
    &greedy::INFO,
    &uniform::INFO,
    &selective::INFO,
    &optimum::INFO,
    &optimistic::INFO,
    &mcts::INFO,
    &beam::INFO,
];

/// The method named `name`.
pub fn find(name: &str) -> Option<&'static Info> {
    METHODS.iter().copied().find(|m| m.name == name)
}

/// Every method's name, in registry order.
pub fn names() -> impl Iterator<Item = &'static str> {
    METHODS.iter().map(|m| m.name)
}

/// A policy: runs a whole recombination on the searcher's state (reset, with the run's
/// stream seeded) and returns the candidates it applied, in order. It reaches the state
/// (`s.state`: `apply`, `tree_begin` / `tree_push` / `tree_pop` / `tree_allowed`, `min_k`,
/// `candidates_of`), the run's stream, and the counters (`s.nodes`, `s.trees`, with
/// `count_node` and `tick` for progress) through the searcher, and the shared helpers of
/// `search::policy` (the selective rule's children, the decision loop).
pub trait Policy: Sync + fmt::Debug {
    /// One run with parameters `p` (each parameter of the method's [`Info::params`] set).
    fn run(&self, s: &mut Searcher<'_>, p: Params) -> Vec<u32>;

    /// Whether its runs read the candidates in decreasing eta (the searcher's eta order
    /// and ranks, 8 bytes per candidate, built before the run's clock starts only for the
    /// policies that say so).
    fn reads_eta_order(&self) -> bool {
        false
    }
}

/// What a method is, for everything that is not the search itself.
#[derive(Debug)]
pub struct Info {
    /// Its stable name: the command line's `--algo` value and the records' `algo`.
    pub name: &'static str,
    /// One line of help.
    pub about: &'static str,
    /// Its parameters.
    pub params: &'static [ParamSpec],
    /// Draws at random: a sweep runs it `runs` times per configuration; otherwise every run
    /// is the same and it runs `baseline_runs` times (the optimum once).
    pub random: bool,
    /// Builds the criterion's state and counts tree nodes and trees (null in records
    /// otherwise).
    pub builds_trees: bool,
    /// A search run per seed; false for the optimum (exact, solved once per mesh).
    pub search: bool,
    /// Place in the reports' order (lower first).
    pub rank: u8,
    /// How to run it.
    pub policy: &'static dyn Policy,
}

impl Info {
    /// Whether the method has a parameter of kind `kind`.
    pub fn has(&self, kind: ParamKind) -> bool {
        self.params.iter().any(|p| p.kind == kind)
    }
}

/// A kind of parameter. Records keep each as its own optional field.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ParamKind {
    /// Look-ahead depth (`horizon`).
    Horizon,
    /// Tree nodes expanded per decision (`budget`).
    Budget,
}

/// The parameter's name as records and flags spell it (`horizon`, `budget`).
impl fmt::Display for ParamKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            ParamKind::Horizon => "horizon",
            ParamKind::Budget => "budget",
        })
    }
}

/// One parameter of a method: its kind, help, default and range (inclusive).
#[derive(Debug, Clone, Copy)]
pub struct ParamSpec {
    pub kind: ParamKind,
    pub about: &'static str,
    pub default: u32,
    pub min: u32,
    pub max: u32,
}

/// The look-ahead depth of the trees (default 1).
pub const HORIZON: ParamSpec = ParamSpec {
    kind: ParamKind::Horizon,
    about: "look-ahead depth",
    default: 1,
    min: 1,
    max: u32::MAX,
};

/// Tree nodes expanded per decision (default 64).
pub const BUDGET: ParamSpec = ParamSpec {
    kind: ParamKind::Budget,
    about: "tree nodes expanded per decision",
    default: 64,
    min: 1,
    max: 1 << 24,
};

/// Parameter values; `None` for those a method does not have.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Params {
    pub horizon: Option<u32>,
    pub budget: Option<u32>,
}

impl Params {
    fn get(&self, kind: ParamKind) -> Option<u32> {
        match kind {
            ParamKind::Horizon => self.horizon,
            ParamKind::Budget => self.budget,
        }
    }

    fn set(&mut self, kind: ParamKind, v: Option<u32>) {
        match kind {
            ParamKind::Horizon => self.horizon = v,
            ParamKind::Budget => self.budget = v,
        }
    }
}

/// A method with its parameter values: what a run runs and a record names.
#[derive(Clone, Copy)]
pub struct Algo {
    info: &'static Info,
    params: Params,
}

impl Algo {
    /// The method named `name` with `given` parameter values: those it has and were not given
    /// take their default, those it does not have are dropped (see [`Algo::ignored`]).
    pub fn new(name: &str, given: Params) -> Result<Algo, AlgoError> {
        let info = find(name).ok_or_else(|| AlgoError::Unknown(name.to_string()))?;
        let mut params = Params::default();
        for spec in info.params {
            let v = given.get(spec.kind).unwrap_or(spec.default);
            if v < spec.min || v > spec.max {
                return Err(match spec.kind {
                    ParamKind::Horizon if v == 0 => AlgoError::ZeroHorizon,
                    kind => AlgoError::OutOfRange {
                        method: info.name,
                        param: kind,
                        value: v,
                        min: spec.min,
                        max: spec.max,
                    },
                });
            }
            params.set(spec.kind, Some(v));
        }
        Ok(Algo { info, params })
    }

    /// The method named `name` with `horizon` (dropped by the methods without one; at least
    /// 1 for those with one), other parameters at their defaults.
    pub fn from_name(name: &str, horizon: u32) -> Result<Algo, AlgoError> {
        Algo::new(
            name,
            Params {
                horizon: Some(horizon),
                budget: None,
            },
        )
    }

    /// The method of a record: its name and the parameters it recorded (each must be there
    /// exactly when the method has it).
    pub fn of_record(name: &str, given: Params) -> Result<Algo, AlgoError> {
        let info = find(name).ok_or_else(|| AlgoError::Unknown(name.to_string()))?;
        for kind in [ParamKind::Horizon, ParamKind::Budget] {
            if info.has(kind) != given.get(kind).is_some() {
                return Err(AlgoError::Mismatch {
                    method: info.name,
                    param: kind,
                    value: given.get(kind),
                });
            }
        }
        Algo::new(name, given)
    }

    /// The kinds of parameter given in `given` that the method does not have.
    pub fn ignored(&self, given: Params) -> Vec<ParamKind> {
        [ParamKind::Horizon, ParamKind::Budget]
            .into_iter()
            .filter(|&k| given.get(k).is_some() && !self.info.has(k))
            .collect()
    }

    /// Greedy without the criterion.
    pub fn greedy_nocrit() -> Algo {
        Algo::new("greedy-nocrit", Params::default()).expect("registered")
    }

    /// Greedy under the criterion.
    pub fn greedy() -> Algo {
        Algo::new("greedy", Params::default()).expect("registered")
    }

    /// The uniform tree of horizon `h` (at least 1).
    ///
    /// # Panics
    ///
    /// If `h` is 0; [`Algo::from_name`]`("uniform", h)` returns the error instead.
    pub fn uniform(h: u32) -> Algo {
        Algo::from_name("uniform", h).expect("a horizon of at least 1")
    }

    /// The selective tree of horizon `h` (at least 1).
    ///
    /// # Panics
    ///
    /// If `h` is 0; [`Algo::from_name`]`("selective", h)` returns the error instead.
    pub fn selective(h: u32) -> Algo {
        Algo::from_name("selective", h).expect("a horizon of at least 1")
    }

    /// What the method is.
    pub fn info(&self) -> &'static Info {
        self.info
    }

    /// The parameter values (`None` for those the method does not have).
    pub fn params(&self) -> Params {
        self.params
    }

    /// The method's name.
    pub fn name(&self) -> &'static str {
        self.info.name
    }

    /// The horizon of a method that has one; 1 for greedy (a tree of horizon 1), 0 for the
    /// others.
    pub fn horizon(&self) -> u32 {
        match self.params.horizon {
            Some(h) => h,
            None if self.info.name == "greedy" => 1,
            None => 0,
        }
    }

    /// The budget (tree nodes per decision) of a method that has one.
    pub fn budget(&self) -> Option<u32> {
        self.params.budget
    }

    /// "selective h=5", "mcts h=10 b=64", "greedy".
    pub fn label(&self) -> String {
        label(self.name(), self.params)
    }
}

/// "NAME h=H b=B" with the parameters that are set.
pub fn label(name: &str, p: Params) -> String {
    let mut s = name.to_string();
    if let Some(h) = p.horizon {
        s.push_str(&format!(" h={h}"));
    }
    if let Some(b) = p.budget {
        s.push_str(&format!(" b={b}"));
    }
    s
}

impl PartialEq for Algo {
    fn eq(&self, other: &Algo) -> bool {
        self.info.name == other.info.name && self.params == other.params
    }
}

impl Eq for Algo {}

impl std::hash::Hash for Algo {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        self.info.name.hash(state);
        self.params.hash(state);
    }
}

impl fmt::Debug for Algo {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Algo({})", self.label())
    }
}

/// The method's name (its parameters are not part of it; see [`Algo::label`]).
impl fmt::Display for Algo {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Parses a method name, optionally with a horizon: `selective` (horizon 1), `selective:5`.
impl FromStr for Algo {
    type Err = AlgoError;
    fn from_str(s: &str) -> Result<Algo, AlgoError> {
        match s.split_once(':') {
            Some((name, h)) => {
                let h = h
                    .parse()
                    .map_err(|_| AlgoError::BadHorizon(h.to_string()))?;
                Algo::from_name(name, h)
            }
            None => Algo::from_name(s, 1),
        }
    }
}

/// The names of every method, for error messages.
fn known() -> String {
    names().collect::<Vec<_>>().join(", ")
}

/// A method name or parameter that does not parse or fit.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum AlgoError {
    #[error("unknown algorithm {0:?} (expected one of {names})", names = known())]
    Unknown(String),
    #[error("bad horizon {0:?} (expected a positive integer)")]
    BadHorizon(String),
    #[error("the horizon must be at least 1")]
    ZeroHorizon,
    #[error("{method}: {param} {value} is out of range {min}..={max}")]
    OutOfRange {
        method: &'static str,
        param: ParamKind,
        value: u32,
        min: u32,
        max: u32,
    },
    #[error(
        "{method}: {param} {value:?} does not fit the method (it has the parameter: a value; it has not: none)"
    )]
    Mismatch {
        method: &'static str,
        param: ParamKind,
        value: Option<u32>,
    },
}
