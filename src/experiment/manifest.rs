//! `manifest.json`: what a results directory was made from and on what.
//!
//! The [`SweepSpec`] part decides which runs exist and what their seeds are; two directories
//! can be merged only when their specs (and backends and versions) are equal. The machine and
//! the shard say where each part ran.

use serde::{Deserialize, Serialize};
use std::path::Path;

use super::ExperimentError;
use super::config::SizeError;

/// File name of the manifest in a results directory.
pub const MANIFEST_FILE: &str = "manifest.json";

/// The manifest of a results directory.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// quadrecomb version that wrote the directory.
    pub version: String,
    /// The sweep configuration: meshes, algorithms, horizons, runs, base seed.
    pub spec: SweepSpec,
    /// Name of the evaluator that computed eta for every mesh.
    pub backend: String,
    /// The backend asked for on the command line ("auto", "gpu" or "cpu").
    pub backend_requested: String,
    /// Optimum (exact maximum-weight matching of maximum cardinality) per mesh, in the order of `spec.meshes`.
    pub optimum: Vec<OptimumEntry>,
    /// Which slice of the run list this directory holds; `None` for the whole list.
    pub shard: Option<Shard>,
    /// Worker threads used.
    pub threads: usize,
    /// The machine this directory's runs ran on.
    pub machine: Machine,
    /// For a merged directory: the shards it was merged from, with their machines.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub merged_from: Vec<MergedPart>,
    /// The sweeps that ran this directory's runs, in order: the first, then each `--resume`
    /// or `--extend` (a merge runs none). Empty in directories written before builds were
    /// recorded (2026-12-05).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub sessions: Vec<Session>,
}

/// One sweep command that ran runs into a directory: which build, when, and from which record
/// on. Times are comparable only between runs of one build on one machine.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Session {
    /// The build that ran them ([`super::build`]).
    pub build: String,
    /// When the sweep started, UTC (ISO 8601, seconds).
    pub started: String,
    /// Records in `runs.jsonl` before it started: its runs are the records from this one
    /// on, up to the next session's.
    pub runs_before: usize,
}

impl Session {
    /// A session of this build starting now, after `runs_before` records.
    pub fn now(runs_before: usize) -> Session {
        let secs = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_secs());
        Session {
            build: super::build(),
            started: utc(secs),
            runs_before,
        }
    }
}

/// `secs` since the Unix epoch as `YYYY-MM-DDTHH:MM:SSZ` (the proleptic Gregorian calendar:
/// H. Hinnant's `civil_from_days`).
pub fn utc(secs: u64) -> String {
    let (days, rem) = ((secs / 86_400) as i64, secs % 86_400);
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}-{month:02}-{day:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        rem % 3600 / 60,
        rem % 60
    )
}

/// The configuration that decides the run list and the seeds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SweepSpec {
    /// Meshes, in order.
    pub meshes: Vec<MeshEntry>,
    /// Algorithm names, in order ("selective", "greedy", ...).
    pub algos: Vec<String>,
    /// Horizons for `uniform` and `selective`.
    pub horizons: Vec<u32>,
    /// Runs per (mesh, tree algorithm, horizon).
    pub runs: u32,
    /// Runs per mesh of `greedy` and `greedy-nocrit` (their only randomness is tie-breaking).
    pub baseline_runs: u32,
    /// Base seed; every run's seed is derived from it.
    pub seed: u64,
    /// The quad-validity rule's threshold (see [`crate::quality::Rule`]).
    #[serde(default)]
    pub min_eta: f64,
    /// Every pair an action, eta-0 quads included (manifests written before the rule
    /// existed read as such).
    #[serde(default = "super::record::paper_literal")]
    pub allow_invalid: bool,
    /// How the run list and the seeds are made ([`super::seed::PLAN_VERSION`] for new
    /// sweeps): version 1 (manifests without the field) derives 64-bit seeds and runs the
    /// uniform tree `runs` times per horizon; version 2 keeps seeds below 2^53 and runs
    /// every deterministic configuration (greedy, greedy-nocrit, uniform) `baseline_runs`
    /// times.
    #[serde(default = "plan_version_1")]
    pub plan_version: u32,
    /// Node budgets per decision of the methods with one (optimistic, mcts, beam); absent
    /// when no such method is swept.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub budgets: Vec<u32>,
    /// Each search run is finished after its search with these settings (`sweep
    /// --finish`); absent without.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub finish: Option<super::finished::FinishSettings>,
    /// Wall-time budgets per run (`sweep --time-budgets`), each calibrated into the knob of
    /// every method with one ([`super::calibrate`]); absent without.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub time_budgets: Vec<super::calibrate::TimeBudget>,
    /// The calibrations of the time budgets: the knob each (mesh, method, horizon, time
    /// budget) runs with, how it was found, on what machine. Made once; a resumed or
    /// extended sweep reuses them.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub calibration: Vec<super::calibrate::Calibrated>,
}

/// The plan version of manifests written before the field existed.
fn plan_version_1() -> u32 {
    1
}

impl SweepSpec {
    /// The rule the sweep recombines under.
    pub fn rule(&self) -> crate::quality::Rule {
        crate::quality::Rule::new(self.min_eta, self.allow_invalid)
            .unwrap_or(crate::quality::Rule::AllPairs)
    }

    /// Whether this is `other` with its algorithms, horizons or budgets listed in another
    /// order (`--algo optimum greedy selective --horizons 2,1` for a directory made with
    /// `--algo selective greedy optimum --horizons 1,2`): the same runs, since a run's seed
    /// derives from its configuration, not from its place in the run list. The meshes must
    /// come in the same order: the runs and the optimum are matched to a mesh by its place
    /// in the list the command line loaded.
    pub fn is_reordering_of(&self, other: &SweepSpec) -> bool {
        fn permutation<T: PartialEq>(a: &[T], b: &[T]) -> bool {
            let count = |v: &[T], x: &T| v.iter().filter(|y| *y == x).count();
            a.len() == b.len() && a.iter().all(|x| count(a, x) == count(b, x))
        }
        let mut same = self.clone();
        if self.meshes != other.meshes
            || !permutation(&self.algos, &other.algos)
            || !permutation(&self.horizons, &other.horizons)
            || !permutation(&self.budgets, &other.budgets)
            || !permutation(&self.time_budgets, &other.time_budgets)
        {
            return false;
        }
        same.algos.clone_from(&other.algos);
        same.horizons.clone_from(&other.horizons);
        same.budgets.clone_from(&other.budgets);
        same.time_budgets.clone_from(&other.time_budgets);
        same == *other
    }
}

/// One mesh of a sweep. Two entries are the same mesh when their name, content hash and
/// size agree, wherever the file was read from (shards run from other directories, or a
/// resume from another one, give the same path differently).
#[derive(Debug, Clone, Eq, Serialize, Deserialize)]
pub struct MeshEntry {
    /// Name used in records (built-in name or file stem).
    pub name: String,
    /// What was given on the command line (built-in name or path).
    pub source: String,
    /// The file's absolute path when the sweep read it (none for a built-in mesh), so that
    /// `report` finds the mesh from any working directory.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub path: Option<String>,
    /// blake3 hex digest of the mesh's canonical content.
    pub hash: String,
    /// Number of triangles.
    pub triangles: usize,
}

impl PartialEq for MeshEntry {
    fn eq(&self, other: &MeshEntry) -> bool {
        self.name == other.name && self.hash == other.hash && self.triangles == other.triangles
    }
}

/// The exact optimum of one mesh, with the eta it was computed from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OptimumEntry {
    /// Mesh name.
    pub mesh: String,
    /// Mesh hash.
    pub mesh_hash: String,
    /// blake3 hex digest of the eta table (f64 bits) the optimum and the searches used.
    pub eta_hash: String,
    /// Sum of eta over the optimum's quads.
    pub quality: f64,
    /// Quads of the optimum.
    pub quads: usize,
    /// Triangles the optimum leaves.
    pub triangles_left: usize,
    /// Seconds the matching took when it was computed (it may come from the cache since).
    pub time_s: f64,
    /// Worst and mean eta of the optimum's quads, and the poor ones (absent in manifests
    /// written before they were recorded).
    #[serde(default)]
    pub elements: crate::quality::ElementQuality,
}

/// The I-th (1-based) of N disjoint slices of a run list.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Shard {
    /// Slice index, 1..=count.
    pub index: u32,
    /// Number of slices.
    pub count: u32,
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl std::str::FromStr for Shard {
    type Err = String;

    /// Parses "I/N" with 1 <= I <= N.
    fn from_str(s: &str) -> Result<Shard, String> {
        let err = || format!("bad shard {s:?}: expected I/N with 1 <= I <= N, e.g. 2/8");
        let (i, n) = s.split_once('/').ok_or_else(err)?;
        let index: u32 = i.trim().parse().map_err(|_| err())?;
        let count: u32 = n.trim().parse().map_err(|_| err())?;
        if count == 0 || index == 0 || index > count {
            return Err(err());
        }
        Ok(Shard { index, count })
    }
}

/// Where a part of a merged directory ran.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MergedPart {
    /// The directory merged.
    pub dir: String,
    /// Its shard, if any.
    pub shard: Option<Shard>,
    /// Its machine.
    pub machine: Machine,
    /// Records taken from it.
    pub records: usize,
    /// The builds that ran its runs, in the order of its sessions ([`Session`]); empty
    /// where they were not recorded.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub builds: Vec<String>,
}

/// The machine a sweep ran on.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Machine {
    /// CPU model name (from /proc/cpuinfo where available).
    pub cpu: String,
    /// Logical cores available to the process.
    pub cores: usize,
    /// Operating system (family, distribution and kernel where available).
    pub os: String,
    /// Host name, where available.
    pub host: String,
}

impl Machine {
    /// Describes the machine this process runs on.
    pub fn current() -> Machine {
        let cpu = std::fs::read_to_string("/proc/cpuinfo")
            .ok()
            .and_then(|s| {
                s.lines()
                    .find(|l| l.starts_with("model name"))
                    .and_then(|l| l.split_once(':'))
                    .map(|(_, v)| v.trim().to_string())
            })
            .unwrap_or_else(|| std::env::consts::ARCH.to_string());
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        let mut os = std::env::consts::OS.to_string();
        if let Some(pretty) = std::fs::read_to_string("/etc/os-release")
            .ok()
            .and_then(|s| {
                s.lines()
                    .find_map(|l| l.strip_prefix("PRETTY_NAME="))
                    .map(|v| v.trim_matches('"').to_string())
            })
        {
            os = format!("{os} ({pretty})");
        }
        if let Ok(kernel) = std::fs::read_to_string("/proc/sys/kernel/osrelease") {
            os = format!("{os}, kernel {}", kernel.trim());
        }
        let host = std::fs::read_to_string("/proc/sys/kernel/hostname")
            .map(|s| s.trim().to_string())
            .unwrap_or_default();
        Machine {
            cpu,
            cores,
            os,
            host,
        }
    }
}

/// The first entry `spec` lists twice, named for a message: a mesh (by name or content),
/// an algorithm, a horizon, a budget or a time budget. A sweep refuses each of these.
fn repeated_entry(s: &SweepSpec) -> Option<String> {
    fn first_repeat<T: PartialEq>(items: &[T]) -> Option<&T> {
        (items.iter().enumerate()).find_map(|(i, x)| items[..i].contains(x).then_some(x))
    }
    let meshes = s.meshes.iter().enumerate().find_map(|(i, m)| {
        (s.meshes[..i].iter())
            .any(|o| o.name == m.name || o.hash == m.hash)
            .then(|| format!("mesh {:?}", m.name))
    });
    meshes
        .or_else(|| first_repeat(&s.algos).map(|a| format!("algorithm {a:?}")))
        .or_else(|| first_repeat(&s.horizons).map(|h| format!("horizon {h}")))
        .or_else(|| first_repeat(&s.budgets).map(|b| format!("budget {b}")))
        .or_else(|| first_repeat(&s.time_budgets).map(|t| format!("time budget {} s", t.seconds())))
}

impl Manifest {
    /// The builds of its sessions, each once, in order of first use.
    /// A merged directory's parts' builds come first, so that a merge of merged directories
    /// keeps them.
    pub fn builds(&self) -> Vec<String> {
        let mut builds: Vec<String> = Vec::new();
        for b in self.merged_from.iter().flat_map(|p| &p.builds) {
            if !builds.contains(b) {
                builds.push(b.clone());
            }
        }
        for s in &self.sessions {
            if !builds.contains(&s.build) {
                builds.push(s.build.clone());
            }
        }
        builds
    }

    /// Reads `dir/manifest.json`.
    pub fn read(dir: &Path) -> Result<Manifest, ExperimentError> {
        let path = dir.join(MANIFEST_FILE);
        super::store::refuse_irregular(&path)?;
        let text = std::fs::read_to_string(&path).map_err(|e| ExperimentError::io(&path, e))?;
        let m: Manifest = serde_json::from_str(&text).map_err(|e| ExperimentError::Corrupt {
            path: path.clone(),
            message: e.to_string(),
        })?;
        // What a sweep would have refused is refused here too, before a run list is built
        // from it (a manifest with runs 4294967295 made report and merge plan 8.6e9 runs).
        let s = &m.spec;
        let size = super::config::check_size(
            s.meshes.len(),
            &s.algos,
            s.horizons.len(),
            s.budgets.len(),
            s.time_budgets.len(),
            s.runs,
            s.baseline_runs,
        );
        let bad_time = (s.time_budgets.iter())
            .chain(s.calibration.iter().map(|c| &c.time_budget_s))
            .find(|t| !t.is_valid());
        let why = if s.plan_version == 0 || s.plan_version > super::seed::PLAN_VERSION {
            Some(format!(
                "plan version {} is not one this quadrecomb knows (1 to {}): made by a later \
                 version, or edited",
                s.plan_version,
                super::seed::PLAN_VERSION
            ))
        } else if s.runs == 0 || s.baseline_runs == 0 {
            Some(format!(
                "runs {} and baseline_runs {}: a sweep makes at least one run of each \
                 configuration",
                s.runs, s.baseline_runs
            ))
        } else if s.horizons.contains(&0) || s.budgets.contains(&0) {
            Some("a horizon or node budget of 0 (a sweep takes 1 or more)".to_string())
        } else if let Some(t) = bad_time {
            Some(format!("time budget {} s is out of range", t.seconds()))
        } else if let Some(repeat) = repeated_entry(s) {
            // Jobs are keyed by mesh, algorithm, horizon and budget: a repeat made merge
            // look a key up twice (a panic) where a sweep refuses the repeat.
            Some(format!("{repeat} is listed twice"))
        } else if let Err(e) = size {
            Some(match e {
                SizeError::Runs { total, .. } => format!(
                    "its spec makes {total} runs, more than a sweep takes ({})",
                    super::config::MAX_RUNS
                ),
                e => e.to_string(),
            })
        } else if m.optimum.len() > s.meshes.len() {
            Some("more optimum entries than meshes".to_string())
        } else if let Err(e) = crate::quality::Rule::new(s.min_eta, s.allow_invalid) {
            Some(format!(
                "its rule (min_eta {}, allow_invalid {}): {e}",
                s.min_eta, s.allow_invalid
            ))
        } else {
            None
        };
        match why {
            Some(message) => Err(ExperimentError::Corrupt { path, message }),
            None => Ok(m),
        }
    }

    /// Writes `dir/manifest.json` (through a temporary file, so a kill never leaves half of it).
    pub fn write(&self, dir: &Path) -> Result<(), ExperimentError> {
        let text = serde_json::to_string_pretty(self).expect("a Manifest always serializes");
        super::write_atomic(&dir.join(MANIFEST_FILE), format!("{text}\n").as_bytes())
    }

    /// Why `other` cannot be combined with `self` (resumed into, or merged), if it cannot:
    /// a different spec, backend or version.
    pub fn incompatibility(&self, other: &Manifest) -> Option<String> {
        if self.version != other.version {
            return Some(format!(
                "quadrecomb version {} vs {}",
                self.version, other.version
            ));
        }
        if self.backend != other.backend {
            return Some(format!(
                "eta backend {:?} vs {:?} (qualities may differ in the last bits)",
                self.backend, other.backend
            ));
        }
        spec_difference(&self.spec, &other.spec)
    }

    /// Why `other` cannot be combined with `self` even as an extension (or a merge of
    /// different configurations): another version or backend, or a difference in what fixes
    /// the existing runs' seeds and results ([`base_difference`]).
    pub fn base_incompatibility(&self, other: &Manifest) -> Option<String> {
        let mut same = other.clone();
        same.spec = self.spec.clone();
        self.incompatibility(&same)
            .or_else(|| base_difference(&self.spec, &other.spec))
    }

    /// Why this configuration cannot extend the directory whose manifest is `old`, if it
    /// cannot: another version, backend, mesh, base seed, rule or plan version
    /// ([`Self::base_incompatibility`], worded this one's vs `old`'s), or a run recorded under
    /// `old` that this one would not plan ([`dropped_runs`]).
    pub fn extension_refusal(&self, old: &Manifest) -> Option<String> {
        if let Some(why) = self.base_incompatibility(old) {
            return Some(format!("{why} (this sweep's vs the directory's)"));
        }
        let dropped = dropped_runs(&old.spec, &self.spec);
        (!dropped.is_empty()).then(|| {
            const SHOWN: usize = 6;
            let more = dropped.len().saturating_sub(SHOWN);
            format!(
                "it would leave out runs the directory's configuration plans, recorded or \
                 not yet run: {}{} (an extension keeps every configuration and run: give them \
                 again)",
                dropped[..dropped.len().min(SHOWN)].join("; "),
                if more > 0 {
                    format!("; and {more} more configurations")
                } else {
                    String::new()
                }
            )
        })
    }
}

/// The first difference between two specs in what decides the seeds and results of the runs
/// they share: the meshes (by name, hash and size), the base seed, the rule, the plan
/// version and the finish settings. Specs without one may hold different algorithms, horizons and run counts: every
/// run they have in common is the same run.
pub fn base_difference(a: &SweepSpec, b: &SweepSpec) -> Option<String> {
    let mut b2 = a.clone();
    b2.meshes = b.meshes.clone();
    b2.seed = b.seed;
    b2.min_eta = b.min_eta;
    b2.allow_invalid = b.allow_invalid;
    b2.plan_version = b.plan_version;
    b2.finish = b.finish;
    spec_difference(a, &b2)
}

/// The configurations of `old`'s run list that `new`'s lacks, in words, one item per
/// configuration ("mesh selective h=3: runs 3..4"); empty when `new` plans every run of `old`.
/// Specs must agree on [`base_difference`] (then shared runs have the same seeds).
pub fn dropped_runs(old: &SweepSpec, new: &SweepSpec) -> Vec<String> {
    use std::collections::{BTreeMap, BTreeSet};
    let planned: BTreeSet<_> = super::plan::plan(new).iter().map(|j| j.key(new)).collect();
    let mut missing: BTreeMap<(String, String, Option<u32>), Vec<u32>> = BTreeMap::new();
    for job in super::plan::plan(old) {
        let key = job.key(old);
        if !planned.contains(&key) {
            missing
                .entry((key.mesh, key.algo, key.horizon))
                .or_default()
                .push(key.run);
        }
    }
    missing
        .into_iter()
        .map(|((mesh, algo, horizon), runs)| {
            let h = horizon.map_or(String::new(), |h| format!(" h={h}"));
            let (first, last) = (runs[0], runs[runs.len() - 1]);
            let which = if runs.len() == 1 {
                format!("run {first}")
            } else if last - first + 1 == runs.len() as u32 {
                format!("runs {first}..{last}")
            } else {
                format!("{} runs", runs.len())
            };
            format!("{mesh} {algo}{h}: {which}")
        })
        .collect()
}

/// The union of two specs that agree on [`base_difference`]: `a`'s algorithms and horizons
/// then those only `b` has, and the larger run counts of the two, each taken only from a spec
/// that uses it (a spec without a randomized tree algorithm has no `runs` to contribute).
pub fn union_spec(a: &SweepSpec, b: &SweepSpec) -> SweepSpec {
    use super::plan::{uses_baseline_runs, uses_runs};
    let mut u = a.clone();
    for algo in &b.algos {
        if !u.algos.contains(algo) {
            u.algos.push(algo.clone());
        }
    }
    for h in &b.horizons {
        if !u.horizons.contains(h) {
            u.horizons.push(*h);
        }
    }
    for x in &b.budgets {
        if !u.budgets.contains(x) {
            u.budgets.push(*x);
        }
    }
    for t in &b.time_budgets {
        if !u.time_budgets.contains(t) {
            u.time_budgets.push(*t);
        }
    }
    for c in &b.calibration {
        let given = super::plan::has_budget(&c.algo).then_some(c.horizon);
        if !u
            .calibration
            .iter()
            .any(|d| d.is_for(&c.mesh, &c.algo, given, c.time_budget_s))
        {
            u.calibration.push(c.clone());
        }
    }
    u.runs = match (uses_runs(a), uses_runs(b)) {
        (true, true) => a.runs.max(b.runs),
        (false, true) => b.runs,
        _ => a.runs,
    };
    u.baseline_runs = match (uses_baseline_runs(a), uses_baseline_runs(b)) {
        (true, true) => a.baseline_runs.max(b.baseline_runs),
        (false, true) => b.baseline_runs,
        _ => a.baseline_runs,
    };
    u
}

/// Every difference between two specs, in words (`a`'s vs `b`'s), joined by "; ".
pub fn spec_difference(a: &SweepSpec, b: &SweepSpec) -> Option<String> {
    let mut found: Vec<String> = Vec::new();
    if a.meshes != b.meshes {
        let names = |s: &SweepSpec| {
            s.meshes
                .iter()
                .map(|m| format!("{} ({})", m.name, &m.hash[..m.hash.len().min(12)]))
                .collect::<Vec<_>>()
                .join(", ")
        };
        found.push(format!("meshes [{}] vs [{}]", names(a), names(b)));
    }
    if a.algos != b.algos {
        found.push(format!("algorithms {:?} vs {:?}", a.algos, b.algos));
    }
    if a.horizons != b.horizons {
        found.push(format!("horizons {:?} vs {:?}", a.horizons, b.horizons));
    }
    if a.budgets != b.budgets {
        found.push(format!("budgets {:?} vs {:?}", a.budgets, b.budgets));
    }
    if a.time_budgets != b.time_budgets {
        let say = |v: &[super::calibrate::TimeBudget]| {
            v.iter()
                .map(|t| t.seconds().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        };
        found.push(format!(
            "time budgets [{}] vs [{}]",
            say(&a.time_budgets),
            say(&b.time_budgets)
        ));
    }
    if a.calibration != b.calibration {
        found.push(
            "the calibrations of the time budgets differ (another calibration: resume with the \
             directory's own manifest)"
                .into(),
        );
    }
    if a.runs != b.runs {
        found.push(format!("runs {} vs {}", a.runs, b.runs));
    }
    if a.baseline_runs != b.baseline_runs {
        found.push(format!(
            "baseline runs {} vs {}",
            a.baseline_runs, b.baseline_runs
        ));
    }
    if a.seed != b.seed {
        found.push(format!("seed {} vs {}", a.seed, b.seed));
    }
    if a.rule() != b.rule() {
        found.push(format!("rule {} vs {}", a.rule(), b.rule()));
    }
    if a.finish != b.finish {
        let say = |f: Option<super::finished::FinishSettings>| {
            f.map_or("no finish".to_string(), |s| s.to_string())
        };
        found.push(format!("{} vs {}", say(a.finish), say(b.finish)));
    }
    if a.plan_version != b.plan_version {
        found.push(format!(
            "plan version {} vs {} (seeds and run lists of different quadrecomb releases: \
             finish that sweep with the release that began it, or start a new one)",
            a.plan_version, b.plan_version
        ));
    }
    (!found.is_empty()).then(|| found.join("; "))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Known instants, and GNU `date -u` (where present) on instants around leap days,
    /// century years and year ends.
    #[test]
    fn utc_matches_the_calendar() {
        for (secs, want) in [
            (0, "1970-01-01T00:00:00Z"),
            (951_782_400, "2000-02-29T00:00:00Z"),
            (1_700_000_000, "2023-11-14T22:13:20Z"),
            (4_102_444_799, "2099-12-31T23:59:59Z"),
        ] {
            assert_eq!(utc(secs), want);
        }
        let mut instants: Vec<u64> = (0..200u64).map(|k| k * 21_600_013 + 86_399).collect();
        instants.extend([951_868_799, 951_868_800, 4_107_542_400, 4_107_542_399]);
        for secs in instants {
            let Ok(out) = std::process::Command::new("date")
                .args(["-u", "-d", &format!("@{secs}"), "+%Y-%m-%dT%H:%M:%SZ"])
                .output()
            else {
                return;
            };
            if !out.status.success() {
                return;
            }
            assert_eq!(
                utc(secs),
                String::from_utf8_lossy(&out.stdout).trim(),
                "{secs}"
            );
        }
    }

    #[test]
    fn dropped_runs_and_union() {
        let a = crate::experiment::plan::tests::spec();
        let mut b = a.clone();
        b.algos = vec!["selective".into(), "uniform".into()];
        b.horizons = vec![3, 4];
        b.runs = 7;
        b.baseline_runs = 1;
        assert_eq!(base_difference(&a, &b), None);
        let dropped = dropped_runs(&a, &b);
        assert_eq!(dropped[0], "a greedy: runs 0..1");
        assert!(dropped.contains(&"b selective h=1: runs 0..4".to_string()));
        assert!(dropped_runs(&a, &a).is_empty());
        let u = union_spec(&a, &b);
        assert_eq!(
            u.algos,
            ["selective", "greedy", "greedy-nocrit", "optimum", "uniform"]
        );
        assert_eq!(
            (u.horizons.clone(), u.runs, u.baseline_runs),
            (vec![1, 2, 3, 4], 7, 2)
        );
        assert!(dropped_runs(&a, &u).is_empty() && dropped_runs(&b, &u).is_empty());
        // A spec without a randomized tree has no runs count to contribute.
        let mut g = a.clone();
        g.algos = vec!["greedy".into()];
        g.runs = 100;
        assert_eq!(union_spec(&a, &g).runs, a.runs);
        g.seed += 1;
        assert_eq!(base_difference(&a, &g), Some("seed 9 vs 10".into()));
    }
}
