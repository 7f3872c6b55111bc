//! Runs a planned sweep into a results directory, whatever does the runs: checks the
//! directory (fresh, or resumed with the same configuration), skips recorded runs, executes the
//! rest, appends their records, and writes the summary.

use std::collections::{BTreeMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use super::ExperimentError;
use super::events::{Event, Events};
use super::exec::{Outcome, WorkerFactory, execute};
use super::manifest::{MANIFEST_FILE, Manifest, OptimumEntry, Session};
use super::plan::{Job, execution_order, plan, shard};
use super::record::{self, RunKey, RunRecord};
use super::store::{self, RUNS_FILE, RunLog};
use super::summary;

/// Options of one execution of a sweep (derived from a
/// [`SweepConfig`](super::config::SweepConfig) by its `engine_options`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EngineOptions {
    /// Results directory (created if missing).
    pub dir: PathBuf,
    /// Continue a sweep already in `dir`.
    pub resume: bool,
    /// With `resume`: the configuration may extend the directory's (more algorithms,
    /// horizons or runs, with the same meshes, base seed, rule and plan version); the manifest
    /// is rewritten with it before any new run starts.
    pub extend: bool,
    /// Replace the results of an earlier sweep in `dir` (ignored with `resume`): its runs,
    /// manifest, summary, report and figures are removed first; the optimum cache is kept.
    pub overwrite: bool,
    /// Worker threads.
    pub threads: usize,
}

/// What an execution did.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EngineReport {
    /// Runs in this directory's share of the run list.
    pub planned: usize,
    /// Runs found already recorded (resume).
    pub already: usize,
    /// Runs done now.
    pub done_now: usize,
    /// Whether a torn last line was found and redone.
    pub torn: bool,
    /// Whether the cancel flag stopped the sweep early.
    pub cancelled: bool,
}

impl EngineReport {
    /// Whether every planned run is recorded.
    pub fn complete(&self) -> bool {
        self.already + self.done_now == self.planned
    }
}

/// Builds the record of a finished job.
pub fn make_record(manifest: &Manifest, job: &Job, out: Outcome) -> RunRecord {
    let mesh = &manifest.spec.meshes[job.mesh];
    let optimum = manifest.optimum.get(job.mesh).map(|o| o.quality);
    let recombined_pct = record::recombined_pct(out.quads, mesh.triangles);
    let branching_factor = record::branching_factor(job.horizon, out.nodes_expanded, out.trees);
    RunRecord {
        mesh: mesh.name.clone(),
        mesh_hash: mesh.hash.clone(),
        triangles: mesh.triangles,
        algo: job.algo.clone(),
        horizon: job.horizon,
        budget: job.budget,
        time_budget_s: job.time_budget,
        seed: job.seed,
        run: job.run,
        quads: out.quads,
        triangles_left: out.triangles_left,
        recombined_pct,
        quality: out.quality,
        quality_pct: optimum
            .filter(|&o| o > 0.0)
            .map(|o| 100.0 * out.quality / o),
        time_s: out.time_s,
        nodes_expanded: record::builds_trees(&job.algo).then_some(out.nodes_expanded),
        trees: record::builds_trees(&job.algo).then_some(out.trees),
        decisions: out.decisions,
        branching_factor,
        worst_eta: out.elements.worst,
        mean_eta: out.elements.mean,
        quads_eta_below_0_1: Some(out.elements.below_0_1),
        quads_eta_below_0_3: Some(out.elements.below_0_3),
        min_eta: manifest.spec.min_eta,
        allow_invalid: manifest.spec.allow_invalid,
        backend: manifest.backend.clone(),
        version: manifest.version.clone(),
        finish: out
            .finish
            .as_ref()
            .zip(manifest.spec.finish)
            .map(|(f, s)| super::finished::FinishRecord::new(s, f, mesh.triangles, optimum)),
    }
}

/// Checks that the records of `loaded` (read from `path`/runs.jsonl) are runs of `jobs`
/// (same keys, seeds, mesh hash and size), each at most once, with values a
/// run can have ([`check_values`], against the manifest's optimum). Errors give the line.
pub fn check_records(
    path: &Path,
    manifest: &Manifest,
    jobs: &[Job],
    loaded: &store::Loaded,
) -> Result<HashSet<RunKey>, ExperimentError> {
    let planned: BTreeMap<RunKey, &Job> = jobs.iter().map(|j| (j.key(&manifest.spec), j)).collect();
    let mut seen: BTreeMap<RunKey, usize> = BTreeMap::new();
    let runs = path.join(RUNS_FILE);
    for (r, &line) in loaded.records.iter().zip(&loaded.line_numbers) {
        let key = r.key();
        let Some(job) = planned.get(&key) else {
            return Err(ExperimentError::ForeignRecords {
                dir: path.to_path_buf(),
                message: format!(
                    "{}:{line}: run {key} is not part of this sweep (or of this shard)",
                    runs.display()
                ),
            });
        };
        let mesh = &manifest.spec.meshes[job.mesh];
        if r.seed != job.seed || r.mesh_hash != mesh.hash || r.triangles != mesh.triangles {
            return Err(ExperimentError::ForeignRecords {
                dir: path.to_path_buf(),
                message: format!(
                    "{}:{line}: run {key} has another seed, mesh hash or triangle count than \
                     this sweep's",
                    runs.display()
                ),
            });
        }
        check_values(r, manifest.optimum.get(job.mesh)).map_err(|why| {
            ExperimentError::Corrupt {
                path: runs.clone(),
                message: format!("line {line}: run {key}: {why}"),
            }
        })?;
        if r.backend != manifest.backend || r.version != manifest.version {
            return Err(ExperimentError::ForeignRecords {
                dir: path.to_path_buf(),
                message: format!(
                    "{}:{line}: run {key} was made by quadrecomb {} with eta from {}, this \
                     sweep's manifest says quadrecomb {} with eta from {}",
                    runs.display(),
                    r.version,
                    r.backend,
                    manifest.version,
                    manifest.backend
                ),
            });
        }
        if r.rule() != manifest.spec.rule() {
            return Err(ExperimentError::ForeignRecords {
                dir: path.to_path_buf(),
                message: format!(
                    "{}:{line}: run {key} was made under the rule {}, this sweep's is {}",
                    runs.display(),
                    r.rule(),
                    manifest.spec.rule()
                ),
            });
        }
        let finished = r
            .finish
            .as_ref()
            .map(|f| (f.rings, f.window, f.all_quad.is_some()));
        let wanted = manifest
            .spec
            .finish
            .filter(|_| super::record::is_search(&r.algo))
            .map(|s| (s.rings, s.window, s.all_quad));
        if finished != wanted {
            let say = |f: Option<(u32, u32, bool)>| {
                f.map_or("no finish".to_string(), |(k, w, a)| {
                    format!(
                        "finish rings {k} window {w}{}",
                        if a { " all-quad" } else { "" }
                    )
                })
            };
            return Err(ExperimentError::ForeignRecords {
                dir: path.to_path_buf(),
                message: format!(
                    "{}:{line}: run {key} has {}, this sweep's runs have {}",
                    runs.display(),
                    say(finished),
                    say(wanted)
                ),
            });
        }
        if let Some(first) = seen.insert(key.clone(), line) {
            return Err(ExperimentError::Corrupt {
                path: runs,
                message: format!(
                    "line {line}: run {key} is recorded twice (first on line {first})"
                ),
            });
        }
    }
    Ok(seen.into_keys().collect())
}

/// Refuses a record whose values no run can have: counts that do not add up, a percentage
/// out of its range, a non-finite or negative measure, an unknown algorithm, and, against the
/// mesh's optimum when known: more quads than the optimum's (it pairs as many triangles as
/// can be paired), a quality above it with as many quads (beyond the rounding of its integer
/// weights), or a `quality_pct` that is not 100 x quality / optimum (or is missing with a
/// positive optimum, or given with an optimum of 0). A run with fewer quads
/// than the optimum may exceed its quality (see docs/search.md); it cannot exceed its quads
/// (eta is at most 1).
pub fn check_values(r: &RunRecord, optimum: Option<&OptimumEntry>) -> Result<(), String> {
    let finite = [
        ("quality", r.quality),
        ("recombined_pct", r.recombined_pct),
        ("time_s", r.time_s),
    ];
    for (name, v) in finite {
        if !v.is_finite() || v < 0.0 {
            return Err(format!("{name} {v} is not a finite non-negative number"));
        }
    }
    if let Err(e) = crate::quality::Rule::new(r.min_eta, r.allow_invalid) {
        return Err(format!(
            "its rule (min_eta {}, allow_invalid {}): {e}",
            r.min_eta, r.allow_invalid
        ));
    }
    if !super::record::algo_names().contains(&r.algo.as_str()) {
        return Err(format!("unknown algorithm {:?}", r.algo));
    }
    if super::plan::has_horizon(&r.algo) != r.horizon.is_some() || r.horizon == Some(0) {
        return Err(format!(
            "horizon {:?} does not fit algorithm {}",
            r.horizon, r.algo
        ));
    }
    if super::plan::has_budget(&r.algo) != r.budget.is_some() || r.budget == Some(0) {
        return Err(format!(
            "budget {:?} does not fit algorithm {}",
            r.budget, r.algo
        ));
    }
    if 2 * r.quads as u128 + r.triangles_left as u128 != r.triangles as u128 {
        return Err(format!(
            "2 x {} quads + {} triangles left is not its {} triangles",
            r.quads, r.triangles_left, r.triangles
        ));
    }
    if r.recombined_pct > 100.0 + 1e-9 {
        return Err(format!("recombined_pct {} is above 100", r.recombined_pct));
    }
    // Derived figures are what they derive from (a report shows them as recorded).
    let pct = record::recombined_pct(r.quads, r.triangles);
    if !close(r.recombined_pct, pct) {
        return Err(format!(
            "recombined_pct {} is not 100 x 2 x {} quads / {} triangles = {pct}",
            r.recombined_pct, r.quads, r.triangles
        ));
    }
    let branching = match (r.nodes_expanded, r.trees) {
        (Some(nodes), Some(trees)) => record::branching_factor(r.horizon, nodes, trees),
        _ => None,
    };
    let same = match (r.branching_factor, branching) {
        (Some(a), Some(b)) => close(a, b),
        (a, b) => a.is_none() && b.is_none(),
    };
    if !same {
        return Err(format!(
            "branching_factor {} is not the one of its {} nodes in {} trees of horizon {} ({})",
            show(r.branching_factor),
            show(r.nodes_expanded.map(|n| n as f64)),
            show(r.trees.map(|n| n as f64)),
            show(r.horizon.map(f64::from)),
            show(branching)
        ));
    }
    // Sums of eta in different orders differ in the last bits.
    let slack = |q: f64| 1e-9 * q.abs().max(1.0);
    if r.quality > r.quads as f64 + slack(r.quality) {
        return Err(format!(
            "quality {} is above its {} quads (eta is at most 1 each)",
            r.quality, r.quads
        ));
    }
    // The element figures: eta lies in [0, 1] and not below the rule's threshold by more
    // than the f32 backends' rounding (the rule is decided on the f64 eta, the figures are
    // the rewards' eta: a valid quad of f64 eta 1e-6 may read 0 in f32), and no more quads
    // are poor than there are.
    for (name, v) in [("worst_eta", r.worst_eta), ("mean_eta", r.mean_eta)] {
        let low = (r.rule().min_eta() - 1e-5).max(0.0);
        let ok = |v: f64| v.is_finite() && (low..=1.0).contains(&v);
        if v.is_some_and(|v| !ok(v)) || (v.is_some() && r.quads == 0) {
            return Err(format!(
                "{name} {} is not the eta of one of its {} quads under the rule {}",
                show(v),
                r.quads,
                r.rule()
            ));
        }
    }
    mean_and_worst(r.quads, r.quality, r.mean_eta, r.worst_eta)?;
    if let Some(trees) = r.trees
        && trees > r.decisions
    {
        return Err(format!(
            "trees {trees} is more than its {} decisions (a tree per decision at most)",
            r.decisions
        ));
    }
    for (name, n) in [
        ("quads_eta_below_0_1", r.quads_eta_below_0_1),
        ("quads_eta_below_0_3", r.quads_eta_below_0_3),
    ] {
        if let Some(n) = n
            && n > r.quads
        {
            return Err(format!("{name} {n} is more than its {} quads", r.quads));
        }
    }
    if let (Some(a), Some(b)) = (r.quads_eta_below_0_1, r.quads_eta_below_0_3)
        && a > b
    {
        return Err(format!(
            "quads_eta_below_0_1 {a} is more than quads_eta_below_0_3 {b} (a quad below 0.1 is \
             below 0.3)"
        ));
    }
    if let Some(pct) = r.quality_pct
        && (!pct.is_finite() || pct < 0.0)
    {
        return Err(format!(
            "quality_pct {pct} is not a finite non-negative number"
        ));
    }
    if let Some(f) = &r.finish {
        let added = f.triangles_added();
        f.check(r.triangles)?;
        mean_and_worst(f.quads, f.quality, f.mean_eta, f.worst_eta)
            .map_err(|e| format!("finish: {e}"))?;
        let pct = record::recombined_pct(f.quads, r.triangles + added);
        if !close(f.recombined_pct, pct) {
            return Err(format!(
                "finish: recombined_pct {} is not 100 x 2 x {} quads / {} triangles = {pct}",
                f.recombined_pct,
                f.quads,
                r.triangles + added
            ));
        }
        if let Some(opt) = optimum {
            if f.quads > opt.quads + added {
                return Err(format!(
                    "finish: {} quads, more than the {} of its mesh's optimum",
                    f.quads, opt.quads
                ));
            }
            // All-quad's splits make another mesh, which the optimum does not bound.
            if added == 0 {
                against_optimum(f.quads, f.quality, opt).map_err(|e| format!("finish: {e}"))?;
            }
            quality_pct(f.quality_pct, f.quality, opt).map_err(|e| format!("finish: {e}"))?;
        }
    }
    let Some(opt) = optimum else {
        return Ok(());
    };
    if r.quads > opt.quads {
        return Err(format!(
            "{} quads, more than the {} of its mesh's optimum (the most triangle pairs there are)",
            r.quads, opt.quads
        ));
    }
    against_optimum(r.quads, r.quality, opt)?;
    // The optimum's own record is the optimum the manifest records, element figures
    // included (older manifests, without them, record none: nothing to compare).
    let e = &opt.elements;
    let same_elements = e.mean.is_none()
        || (r.worst_eta.zip(e.worst).is_some_and(|(a, b)| close(a, b))
            && r.mean_eta.zip(e.mean).is_some_and(|(a, b)| close(a, b))
            && r.quads_eta_below_0_1.is_none_or(|n| n == e.below_0_1)
            && r.quads_eta_below_0_3.is_none_or(|n| n == e.below_0_3));
    if r.algo == "optimum"
        && (r.quads != opt.quads || !close(r.quality, opt.quality) || !same_elements)
    {
        return Err(format!(
            "the optimum's record ({} quads, quality {}, worst eta {}, {} and {} quads below \
             0.1 and 0.3) is not its mesh's recorded optimum ({} quads, quality {}, worst eta \
             {}, {} and {})",
            r.quads,
            r.quality,
            show(r.worst_eta),
            r.quads_eta_below_0_1.map_or("?".into(), |n| n.to_string()),
            r.quads_eta_below_0_3.map_or("?".into(), |n| n.to_string()),
            opt.quads,
            opt.quality,
            show(e.worst),
            e.below_0_1,
            e.below_0_3
        ));
    }
    quality_pct(r.quality_pct, r.quality, opt)
}

/// Whether a recorded figure is the one it derives from, up to the last bits of a sum taken
/// in another order.
fn close(recorded: f64, derived: f64) -> bool {
    (recorded - derived).abs() <= 1e-9 * derived.abs().max(1.0)
}

/// The mean is the quality per quad (both read off the same eta), and no quad is worse than
/// the worst.
fn mean_and_worst(
    quads: usize,
    quality: f64,
    mean: Option<f64>,
    worst: Option<f64>,
) -> Result<(), String> {
    let Some(mean) = mean else {
        return Ok(());
    };
    if (mean * quads as f64 - quality).abs() > 1e-6 * quality.max(1.0) {
        return Err(format!(
            "mean_eta {mean} is not its quality {quality} over its {quads} quads"
        ));
    }
    if worst.is_some_and(|w| w > mean + 1e-9) {
        return Err(format!(
            "worst_eta {} is above its mean_eta {mean}",
            show(worst)
        ));
    }
    Ok(())
}

/// A value or "none", for messages.
fn show(v: Option<f64>) -> String {
    v.map_or("none".into(), |v| v.to_string())
}

/// A run's quality against its mesh's exact optimum: no run with as many quads beats it.
fn against_optimum(quads: usize, quality: f64, opt: &OptimumEntry) -> Result<(), String> {
    // The optimum maximises integer weights round(eta * 2^24): a run with as many quads can
    // beat it by at most half a unit per quad on each side.
    let rounding = quads as f64 / crate::search::optimum::WEIGHT_SCALE;
    if quads == opt.quads && quality > opt.quality + rounding + 1e-9 * opt.quality.abs().max(1.0) {
        return Err(format!(
            "quality {quality} is above the exact optimum {} of its mesh, with as many quads",
            opt.quality
        ));
    }
    Ok(())
}

/// A recorded quality_pct: present exactly when the optimum is positive (a report compares
/// it across runs, and falls back to the sum of eta only for a mesh whose runs all lack it),
/// and then `100 * quality / optimum`.
fn quality_pct(pct: Option<f64>, quality: f64, opt: &OptimumEntry) -> Result<(), String> {
    match pct {
        None if opt.quality > 0.0 => Err(format!(
            "quality_pct is missing, but its mesh's optimum {} is recorded",
            opt.quality
        )),
        Some(pct) if opt.quality <= 0.0 => Err(format!(
            "quality_pct {pct} given, but its mesh's optimum is {}",
            opt.quality
        )),
        Some(pct) if (pct - 100.0 * quality / opt.quality).abs() > 1e-6 * pct.abs().max(1.0) => {
            Err(format!(
                "quality_pct {pct} is not 100 x quality {quality} / optimum {}",
                opt.quality
            ))
        }
        _ => Ok(()),
    }
}

/// Removes what an earlier sweep wrote into `dir`, and nothing else: only a directory with a
/// sweep's manifest is touched, and only the files a sweep names (runs, manifest, summary,
/// report, and the figures its report listed in [`REPORT_FILES`]); `figures/` goes only if
/// that leaves it empty. A directory without a manifest keeps everything.
fn clear_results(dir: &Path) -> Result<(), ExperimentError> {
    if !dir.join(MANIFEST_FILE).exists() {
        return Ok(());
    }
    // Refuses a manifest that is not a sweep's (before deleting anything).
    Manifest::read(dir)?;
    let mut names: Vec<PathBuf> = report_files(dir)?.into_iter().map(PathBuf::from).collect();
    names.extend(SWEEP_FILES.map(PathBuf::from));
    for name in names {
        let path = dir.join(name);
        match std::fs::remove_file(&path) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                return Err(ExperimentError::io(&path, e));
            }
            _ => {}
        }
    }
    // Only when empty: a file the sweep did not write stays, and so does its directory.
    let _ = std::fs::remove_dir(dir.join(FIGURES_DIR));
    Ok(())
}

/// Refuses a directory without a sweep's manifest that holds a file a sweep or merge writes
/// (report, summary, the list of figures, a non-empty `figures/`): a user's own notes named
/// `report.md` were replaced without a word. The lock, the optimum cache and any other file
/// are no obstacle, nor is anything in a sweep's own directory.
pub(super) fn refuse_foreign_files(dir: &Path) -> Result<(), ExperimentError> {
    if dir.join(MANIFEST_FILE).exists() {
        return Ok(());
    }
    let mut files: Vec<String> = [
        REPORT_FILES,
        summary::SUMMARY_CSV,
        summary::SUMMARY_JSON,
        ACROSS_CSV,
        "report.md",
        "report.html",
    ]
    .into_iter()
    .filter(|name| dir.join(name).exists())
    .map(String::from)
    .collect();
    let figures = dir.join(FIGURES_DIR);
    if std::fs::read_dir(&figures).is_ok_and(|mut d| d.next().is_some()) {
        files.push(format!("{FIGURES_DIR}/"));
    }
    if files.is_empty() {
        Ok(())
    } else {
        Err(ExperimentError::ForeignFiles {
            dir: dir.to_path_buf(),
            files,
        })
    }
}

/// The files a sweep and its report write in a results directory, besides the figures.
pub const SWEEP_FILES: [&str; 8] = [
    REPORT_FILES,
    RUNS_FILE,
    MANIFEST_FILE,
    summary::SUMMARY_CSV,
    summary::SUMMARY_JSON,
    ACROSS_CSV,
    "report.md",
    "report.html",
];

/// File in a results directory listing the figures its report wrote, one relative path a
/// line, so that `--overwrite` and the next report remove those and no other file.
pub const REPORT_FILES: &str = "report-files.txt";
/// Sub-directory of a report's figures.
pub const FIGURES_DIR: &str = "figures";
/// The per-mesh medians a report of two or more meshes writes (`report::across`).
pub const ACROSS_CSV: &str = "across_meshes.csv";

/// The figures `dir`'s last report wrote (from [`REPORT_FILES`]; none if it is missing).
/// Only plain `figures/NAME.svg` paths are taken: a line naming anything else is an error,
/// not a file to delete.
pub fn report_files(dir: &Path) -> Result<Vec<String>, ExperimentError> {
    let path = dir.join(REPORT_FILES);
    super::store::refuse_irregular(&path)?;
    let text = match std::fs::read_to_string(&path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(ExperimentError::io(&path, e)),
    };
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let ok = line
            .strip_prefix("figures/")
            .and_then(|n| n.strip_suffix(".svg"))
            .is_some_and(|n| !n.is_empty() && !n.contains(['/', '\\']) && !n.starts_with('.'));
        if !ok {
            return Err(ExperimentError::Corrupt {
                path,
                message: format!(
                    "line {}: {line:?} is not a figure a report writes (figures/NAME.svg)",
                    i + 1
                ),
            });
        }
        out.push(line.to_string());
    }
    Ok(out)
}

/// Refuses to continue the directory whose manifest is `old` with `new`: another shard, or
/// another configuration ([`Manifest::incompatibility`]); with `extend`, a configuration that
/// does not extend the old one ([`Manifest::extension_refusal`]). A plain resume whose
/// configuration would be a valid extension says so ([`ExperimentError::Extendable`]).
fn check_resume(
    dir: &Path,
    old: &Manifest,
    new: &Manifest,
    extend: bool,
) -> Result<(), ExperimentError> {
    let mismatch = |message: String| ExperimentError::Mismatch {
        dir: dir.to_path_buf(),
        message,
    };
    if old.shard != new.shard {
        let s = |s: Option<super::manifest::Shard>| {
            s.map_or("the whole run list".to_string(), |s| format!("shard {s}"))
        };
        return Err(mismatch(format!(
            "{} vs {} (this sweep's vs the directory's)",
            s(new.shard),
            s(old.shard)
        )));
    }
    let Some(why) = new.incompatibility(old) else {
        return Ok(());
    };
    let why = format!("{why} (this sweep's vs the directory's)");
    let refusal = new.extension_refusal(old);
    if extend {
        if new.shard.is_some() {
            // A shard is a slice of the whole run list, which an extension changes.
            return Err(mismatch(format!(
                "{why}; a shard cannot be extended (its slice is cut from the whole run \
                 list, which an extension changes): extend the merged directory instead"
            )));
        }
        return match refusal {
            Some(r) => Err(mismatch(format!("cannot extend it: {r}"))),
            None => Ok(()),
        };
    }
    if refusal.is_none() && new.shard.is_none() {
        return Err(ExperimentError::Extendable {
            dir: dir.to_path_buf(),
            message: why,
        });
    }
    Err(mismatch(why))
}

/// Runs the sweep described by `manifest` (its spec and shard) into `opts.dir`.
///
/// A fresh directory must not hold runs yet; with `resume`, its manifest must describe the
/// same configuration, shard included, and its recorded runs are kept and skipped. Every
/// finished run is appended and flushed at once. The summary is written at the end, also
/// after a cancellation (of what was finished). Progress goes to `events`.
pub fn run(
    manifest: &Manifest,
    factory: &dyn WorkerFactory,
    opts: &EngineOptions,
    cancel: &AtomicBool,
    events: &mut Events<'_>,
) -> Result<EngineReport, ExperimentError> {
    let dir = &opts.dir;
    std::fs::create_dir_all(dir).map_err(|e| ExperimentError::io(dir, e))?;
    let _lock = super::lock::DirLock::acquire(dir)?;
    // A directory that is no sweep's keeps what it holds (`--overwrite` too replaces only a
    // sweep's files).
    refuse_foreign_files(dir)?;
    if opts.overwrite && !opts.resume {
        clear_results(dir)?;
    }
    let runs_path = dir.join(RUNS_FILE);
    let loaded = store::read(&runs_path)?;
    let mut manifest = manifest.clone();
    if dir.join(MANIFEST_FILE).exists() {
        let old = Manifest::read(dir)?;
        if opts.resume {
            // The directory's configuration given in another order is the directory's own
            // (not for a shard: its slice of the run list depends on the order).
            if manifest.shard.is_none() && manifest.spec.is_reordering_of(&old.spec) {
                manifest.spec = old.spec.clone();
            }
            check_resume(dir, &old, &manifest, opts.extend)?;
            // The records are checked against the directory's own manifest before it is
            // rewritten: a refused directory keeps its manifest. An extension plans every run
            // of the old list with the same seed (checked above), so they stay valid.
            let old_jobs = shard(plan(&old.spec), old.shard);
            check_records(dir, &old, &old_jobs, &loaded)?;
            if old.spec != manifest.spec {
                events(Event::Extending {
                    before: old_jobs.len(),
                    after: shard(plan(&manifest.spec), manifest.shard).len(),
                });
            }
            // A merged directory keeps the list of the parts it was made of, and every
            // directory the sweeps that ran its runs so far.
            manifest.merged_from = old.merged_from;
            manifest.sessions = old.sessions;
        } else if !loaded.records.is_empty() || loaded.torn_bytes > 0 {
            return Err(ExperimentError::AlreadyExists {
                dir: dir.clone(),
                records: loaded.records.len(),
            });
        }
    } else if !loaded.records.is_empty() || loaded.torn_bytes > 0 {
        return Err(ExperimentError::Corrupt {
            path: runs_path,
            message: format!("{} exists without {MANIFEST_FILE}", RUNS_FILE),
        });
    }
    // This sweep, after the records there are (a torn last line is cut off before appending).
    manifest.sessions.push(Session::now(loaded.records.len()));
    // Written whole (a temporary file renamed over the old one), before any new run is
    // appended: a kill leaves either manifest, and the records are a part of the run list of
    // either, which the next --resume completes.
    manifest.write(dir)?;
    let manifest = &manifest;

    let jobs = shard(plan(&manifest.spec), manifest.shard);
    let done = check_records(dir, manifest, &jobs, &loaded)?;
    let mut todo: Vec<Job> = jobs
        .iter()
        .filter(|j| !done.contains(&j.key(&manifest.spec)))
        .cloned()
        .collect();
    execution_order(&mut todo);

    let mut log = RunLog::open_for_append(&runs_path, loaded.valid_len)?;
    if !done.is_empty() {
        events(Event::Resuming {
            recorded: done.len(),
            planned: jobs.len(),
            torn: loaded.torn_bytes > 0,
        });
    }
    events(Event::Started {
        runs: todo.len() as u64,
    });
    let result = execute(&todo, opts.threads, factory, cancel, &mut |job, out| {
        let rec = make_record(manifest, job, out);
        // What report and merge would refuse is not recorded: a run that beats the optimum
        // means the optimum is wrong.
        check_values(&rec, manifest.optimum.get(job.mesh)).map_err(|why| {
            ExperimentError::OptimumContradicted {
                run: rec.key().to_string(),
                why,
            }
        })?;
        log.append(&rec)?;
        events(Event::RunDone);
        Ok(())
    });
    events(Event::Finished);
    let executed = result?;
    log.sync()?;
    drop(log);

    let all = store::read(&runs_path)?;
    summary::write(dir, &all.records)?;
    Ok(EngineReport {
        planned: jobs.len(),
        already: done.len(),
        done_now: executed.finished,
        torn: loaded.torn_bytes > 0,
        cancelled: executed.cancelled,
    })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::experiment::exec::tests::FakeFactory;
    use crate::experiment::manifest::{Machine, OptimumEntry, Shard};

    pub(crate) fn manifest(shard: Option<Shard>) -> Manifest {
        let spec = crate::experiment::plan::tests::spec();
        Manifest {
            version: crate::experiment::VERSION.into(),
            optimum: spec
                .meshes
                .iter()
                .map(|m| OptimumEntry {
                    mesh: m.name.clone(),
                    mesh_hash: m.hash.clone(),
                    eta_hash: "e".into(),
                    quality: 4.5,
                    quads: 5,
                    triangles_left: 0,
                    time_s: 0.0,
                    elements: Default::default(),
                })
                .collect(),
            spec,
            backend: "fake".into(),
            backend_requested: "cpu".into(),
            shard,
            threads: 1,
            machine: Machine::current(),
            merged_from: vec![],
            sessions: vec![],
        }
    }

    pub(crate) fn opts(dir: &Path, threads: usize, resume: bool) -> EngineOptions {
        EngineOptions {
            dir: dir.to_path_buf(),
            resume,
            extend: false,
            overwrite: false,
            threads,
        }
    }

    fn sorted(dir: &Path) -> Vec<RunRecord> {
        let mut r = store::read(&dir.join(RUNS_FILE)).unwrap().records;
        r.sort_by_key(|r| r.key());
        r
    }

    const OK: FakeFactory = FakeFactory { fail_on_run: None };

    #[test]
    fn threads_and_resume_give_the_same_records() {
        let tmp = tempfile::tempdir().unwrap();
        let m = manifest(None);
        let no = AtomicBool::new(false);
        let a = tmp.path().join("a");
        let rep = run(&m, &OK, &opts(&a, 1, false), &no, &mut |_| {}).unwrap();
        assert!(rep.complete() && rep.done_now == 40 && rep.already == 0);
        let b = tmp.path().join("b");
        run(&m, &OK, &opts(&b, 3, false), &no, &mut |_| {}).unwrap();
        assert_eq!(sorted(&a), sorted(&b));
        assert!(b.join("summary.csv").exists() && b.join("summary.json").exists());

        // Resume after a torn line: cut the file in the middle of its 10th line.
        let text = std::fs::read(b.join(RUNS_FILE)).unwrap();
        let cut = text
            .iter()
            .enumerate()
            .filter(|(_, c)| **c == b'\n')
            .nth(8)
            .unwrap()
            .0
            + 15;
        std::fs::write(b.join(RUNS_FILE), &text[..cut]).unwrap();
        let mut seen = Vec::new();
        let mut events = |e: Event<'_>| seen.push(format!("{e:?}"));
        let rep = run(&m, &OK, &opts(&b, 2, true), &no, &mut events).unwrap();
        assert_eq!((rep.already, rep.done_now, rep.torn), (9, 31, true));
        // What the caller is told: the resume, the runs to do, each run, the end.
        let done = format!("{:?}", Event::RunDone);
        assert_eq!(
            seen[..2],
            [
                "Resuming { recorded: 9, planned: 40, torn: true }",
                "Started { runs: 31 }"
            ]
        );
        assert_eq!(seen.iter().filter(|e| **e == done).count(), 31);
        assert_eq!(seen.last().unwrap(), &format!("{:?}", Event::Finished));
        assert_eq!(sorted(&a), sorted(&b));
        let lines = std::fs::read_to_string(b.join(RUNS_FILE)).unwrap();
        assert_eq!(lines.lines().count(), 40);

        // Resuming a complete directory does nothing.
        let rep = run(&m, &OK, &opts(&b, 2, true), &no, &mut |_| {}).unwrap();
        assert_eq!((rep.already, rep.done_now), (40, 0));
    }

    #[test]
    fn fresh_run_refuses_a_used_directory_and_resume_refuses_another_config() {
        let tmp = tempfile::tempdir().unwrap();
        let m = manifest(None);
        let no = AtomicBool::new(false);
        run(&m, &OK, &opts(tmp.path(), 1, false), &no, &mut |_| {}).unwrap();
        let err = run(&m, &OK, &opts(tmp.path(), 1, false), &no, &mut |_| {}).unwrap_err();
        assert!(
            matches!(err, ExperimentError::AlreadyExists { records: 40, .. }),
            "{err}"
        );
        let mut other = m.clone();
        other.spec.runs = 6;
        let err = run(&other, &OK, &opts(tmp.path(), 1, true), &no, &mut |_| {}).unwrap_err();
        assert!(err.to_string().contains("runs 6 vs 5"), "{err}");
        let sharded = manifest(Some(Shard { index: 1, count: 2 }));
        let err = run(&sharded, &OK, &opts(tmp.path(), 1, true), &no, &mut |_| {}).unwrap_err();
        assert!(
            err.to_string().contains("shard 1/2 vs the whole run list"),
            "{err}"
        );
    }

    /// The directory's own configuration with its algorithms and horizons in another order
    /// resumes it: a finished directory is left unchanged, a partial one is completed with
    /// the records a sweep in the first order makes. Its meshes in another order do not (the
    /// runs and the optimum are matched to a mesh by its place in the loaded list), nor does
    /// a shard's reordering (its slice depends on the order), nor a reordering that also
    /// changes something else.
    #[test]
    fn resume_takes_the_same_configuration_in_another_order() {
        let tmp = tempfile::tempdir().unwrap();
        let m = manifest(None);
        let no = AtomicBool::new(false);
        run(&m, &OK, &opts(tmp.path(), 1, false), &no, &mut |_| {}).unwrap();
        let before = std::fs::read(tmp.path().join(RUNS_FILE)).unwrap();
        let mut shuffled = m.clone();
        shuffled.spec.algos.reverse();
        shuffled.spec.horizons = vec![3, 1, 2];
        assert!(shuffled.spec.is_reordering_of(&m.spec));
        let rep = run(&shuffled, &OK, &opts(tmp.path(), 1, true), &no, &mut |_| {}).unwrap();
        assert_eq!((rep.already, rep.done_now), (40, 0));
        assert_eq!(Manifest::read(tmp.path()).unwrap().spec, m.spec);
        assert_eq!(std::fs::read(tmp.path().join(RUNS_FILE)).unwrap(), before);

        // A partial directory (its first 13 records) completed in the other order.
        let partial = tmp.path().join("partial");
        std::fs::create_dir(&partial).unwrap();
        std::fs::copy(tmp.path().join(MANIFEST_FILE), partial.join(MANIFEST_FILE)).unwrap();
        let cut = before
            .iter()
            .enumerate()
            .filter(|(_, c)| **c == b'\n')
            .nth(12)
            .unwrap()
            .0
            + 1;
        std::fs::write(partial.join(RUNS_FILE), &before[..cut]).unwrap();
        let rep = run(&shuffled, &OK, &opts(&partial, 2, true), &no, &mut |_| {}).unwrap();
        assert_eq!((rep.already, rep.done_now), (13, 27));
        assert_eq!(sorted(&partial), sorted(tmp.path()));
        assert_eq!(Manifest::read(&partial).unwrap().spec, m.spec);

        let mut meshes = m.clone();
        meshes.spec.meshes.reverse();
        meshes.optimum.reverse();
        assert!(!meshes.spec.is_reordering_of(&m.spec));
        let err = run(&meshes, &OK, &opts(tmp.path(), 1, true), &no, &mut |_| {}).unwrap_err();
        assert!(err.to_string().contains("meshes"), "{err}");
        assert_eq!(std::fs::read(tmp.path().join(RUNS_FILE)).unwrap(), before);

        let mut other = m.clone();
        other.spec.horizons = vec![3, 1, 1];
        assert!(!other.spec.is_reordering_of(&m.spec));
        let err = run(&other, &OK, &opts(tmp.path(), 1, true), &no, &mut |_| {}).unwrap_err();
        assert!(
            err.to_string().contains("horizons [3, 1, 1] vs [1, 2, 3]"),
            "{err}"
        );
        let shard = Some(Shard { index: 1, count: 2 });
        let dir = tmp.path().join("shard");
        run(
            &manifest(shard),
            &OK,
            &opts(&dir, 1, false),
            &no,
            &mut |_| {},
        )
        .unwrap();
        let mut part = manifest(shard);
        part.spec.algos.reverse();
        let err = run(&part, &OK, &opts(&dir, 1, true), &no, &mut |_| {}).unwrap_err();
        assert!(err.to_string().contains("algorithms"), "{err}");
    }

    #[test]
    fn extend_adds_runs_keeps_the_records_and_refuses_to_drop_any() {
        let tmp = tempfile::tempdir().unwrap();
        let m = manifest(None);
        let no = AtomicBool::new(false);
        run(&m, &OK, &opts(tmp.path(), 2, false), &no, &mut |_| {}).unwrap();
        let before = std::fs::read(tmp.path().join(RUNS_FILE)).unwrap();
        let mut wider = m.clone();
        wider.spec.horizons.push(4);
        wider.spec.runs = 6;
        // A plain resume says the configuration would extend the directory, and does nothing.
        let err = run(&wider, &OK, &opts(tmp.path(), 1, true), &no, &mut |_| {}).unwrap_err();
        assert!(matches!(err, ExperimentError::Extendable { .. }), "{err}");
        assert_eq!(Manifest::read(tmp.path()).unwrap().spec, m.spec);
        let mut o = opts(tmp.path(), 2, true);
        o.extend = true;
        let mut seen = Vec::new();
        let rep = run(&wider, &OK, &o, &no, &mut |e| seen.push(format!("{e:?}"))).unwrap();
        // 2 meshes x (4 horizons x 6 runs + 2 + 2 + 1) planned, 40 of them recorded before.
        assert_eq!((rep.planned, rep.already, rep.done_now), (58, 40, 18));
        assert_eq!(seen[0], "Extending { before: 40, after: 58 }");
        let after = std::fs::read(tmp.path().join(RUNS_FILE)).unwrap();
        assert!(after.starts_with(&before));
        assert_eq!(Manifest::read(tmp.path()).unwrap().spec, wider.spec);
        let fresh = tmp.path().join("fresh");
        run(&wider, &OK, &opts(&fresh, 1, false), &no, &mut |_| {}).unwrap();
        assert_eq!(sorted(tmp.path()), sorted(&fresh));
        // Back to fewer runs: refused, naming what would be dropped.
        let err = run(&m, &OK, &o, &no, &mut |_| {}).unwrap_err().to_string();
        assert!(
            err.contains("would leave out runs") && err.contains("a selective h=1: run 5"),
            "{err}"
        );
        let mut seed = wider.clone();
        seed.spec.seed += 1;
        let err = run(&seed, &OK, &o, &no, &mut |_| {})
            .unwrap_err()
            .to_string();
        assert!(err.contains("cannot extend it: seed 10 vs 9"), "{err}");
    }

    #[test]
    fn cancelled_sweep_keeps_what_finished_and_resumes() {
        let tmp = tempfile::tempdir().unwrap();
        let m = manifest(None);
        let yes = AtomicBool::new(true);
        let rep = run(&m, &OK, &opts(tmp.path(), 2, false), &yes, &mut |_| {}).unwrap();
        assert!(rep.cancelled && rep.done_now == 0 && !rep.complete());
        let no = AtomicBool::new(false);
        let rep = run(&m, &OK, &opts(tmp.path(), 2, true), &no, &mut |_| {}).unwrap();
        assert!(rep.complete() && !rep.cancelled);
    }

    #[test]
    fn records_carry_optimum_percent_and_branching() {
        let m = manifest(None);
        let job = plan(&m.spec)
            .into_iter()
            .find(|j| j.horizon == Some(2))
            .unwrap();
        let out = Outcome {
            quads: 4,
            triangles_left: 2,
            quality: 3.6,
            nodes_expanded: 60,
            trees: 10,
            decisions: 10,
            time_s: 0.5,
            elements: crate::quality::ElementQuality::of([0.5, 0.9]),
            finish: None,
        };
        let r = make_record(&m, &job, out);
        // Against the optimum 4.5.
        assert!((r.quality_pct.unwrap() - 80.0).abs() < 1e-9);
        let checked = RunRecord {
            quality: 3.0,
            quality_pct: Some(100.0 * 3.0 / 4.5),
            // The quality per quad.
            mean_eta: Some(0.75),
            ..r.clone()
        };
        assert_eq!(r.recombined_pct, 80.0);
        // 6 nodes expanded per tree at h = 2: 1 + b = 6 -> b = 5.
        assert!((r.branching_factor.unwrap() - 5.0).abs() < 1e-9);
        assert_eq!(r.seed, job.seed);
        let opt = &m.optimum[0];
        assert_eq!(check_values(&checked, Some(opt)), Ok(()));
        // The percentage goes with a positive optimum, and only with one.
        let missing = RunRecord {
            quality_pct: None,
            ..checked.clone()
        };
        let err = check_values(&missing, Some(opt)).unwrap_err();
        assert!(err.contains("quality_pct is missing"), "{err}");
        let zero = OptimumEntry {
            quality: 0.0,
            ..opt.clone()
        };
        let err = check_values(&checked, Some(&zero)).unwrap_err();
        assert!(err.contains("quality_pct 66.66"), "{err}");
        assert_eq!(check_values(&missing, Some(&zero)), Ok(()));
    }
}
