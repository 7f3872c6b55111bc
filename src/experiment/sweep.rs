//! The real sweep: loads the meshes, computes every candidate's eta once (one evaluator batch
//! over all meshes), the optimum once per mesh (cached by mesh hash), and runs the searches
//! through [`super::engine`] with one reusable [`Searcher`] per thread and mesh.

use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use super::ExperimentError;
use super::config::SweepConfig;
use super::engine::{self, EngineReport};
use super::events::{Event, Events};
use super::exec::{Outcome, Worker, WorkerFactory};
use super::manifest::{Machine, Manifest, MeshEntry, OptimumEntry};
use super::plan::Job;
use super::record::RunKey;
use super::seed::{eta_hash, mesh_hash};
use crate::gpu::Evaluator;
use crate::mesh::Mesh;
use crate::quality::{CandidateTable, ElementQuality};
use crate::search::{Algo, Progress, Searcher};

/// Watches the sweep's runs that last: called from the run's thread with the run's key and
/// progress about every [`WATCH_PERIOD_S`] once it has lasted that long, until it returns
/// `false` (the caller warns of a run that will be long; the library prints nothing).
pub type RunWatch = Arc<dyn Fn(&RunKey, &Progress) -> bool + Send + Sync>;

/// Seconds between two calls of a [`RunWatch`] for one run, and before the first.
pub const WATCH_PERIOD_S: f64 = 1.0;

/// Directory of the optimum cache inside a results directory.
pub const OPTIMUM_CACHE_DIR: &str = "optimum-cache";

/// Meshes with their eta filled, optima computed, and the manifest of the sweep.
#[derive(Debug)]
pub struct Prepared {
    /// Meshes, in spec order.
    pub meshes: Vec<Mesh>,
    /// Candidate tables with eta, in spec order.
    pub tables: Vec<CandidateTable>,
    /// The manifest to write.
    pub manifest: Manifest,
    /// How long each step of the preparation took.
    pub phases: PhaseTimes,
}

/// Wall time of a sweep's phases (seconds): what the runner spends besides the searches.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct PhaseTimes {
    /// Loading and validating the meshes.
    pub load_s: f64,
    /// Candidate tables: topology, the evaluator (device opened, one batch for every mesh),
    /// restriction to the rule.
    pub eta_s: f64,
    /// The optimum of every mesh (solved, or read from the cache and verified).
    pub optimum_s: f64,
    /// The engine: manifest, records checked, the runs (searches), the summary.
    pub engine_s: f64,
}

/// The name a mesh has in records: the built-in name, the suite member's name (`suite:torus`
/// is `torus`), or the file stem.
pub fn mesh_name(spec: &str) -> String {
    if crate::mesh::builtin::NAMES.contains(&spec) {
        return spec.to_string();
    }
    if let Some(Ok(member)) = crate::mesh::suite::parse_spec(spec) {
        return member.name.to_string();
    }
    Path::new(spec)
        .file_stem()
        .map_or_else(|| spec.to_string(), |s| s.to_string_lossy().into_owned())
}

/// Loads the meshes, fills eta in one evaluator batch, and finds (or computes and caches
/// under the results directory) the optimum of each mesh. How the backend was chosen goes
/// to `events`.
pub fn prepare(config: &SweepConfig, events: &mut Events<'_>) -> Result<Prepared, ExperimentError> {
    // Before anything is written there (the optimum's cache): a directory that is no sweep's
    // and holds files a sweep writes is refused (the engine checks again under its lock).
    let out = config.out();
    if out.is_dir() {
        super::engine::refuse_foreign_files(out)?;
    }
    let mut phases = PhaseTimes::default();
    let clock = std::time::Instant::now();
    let mut meshes = Vec::new();
    let mut entries: Vec<MeshEntry> = Vec::new();
    for spec in config.meshes() {
        let mesh = crate::mesh::load(spec).map_err(|source| ExperimentError::Mesh {
            spec: spec.clone(),
            source,
        })?;
        let entry = MeshEntry {
            name: mesh_name(spec),
            source: spec.clone(),
            // The loader prefers a file over a built-in of the same name.
            path: std::fs::canonicalize(spec)
                .ok()
                .filter(|p| p.is_file())
                .map(|p| p.to_string_lossy().into_owned()),
            hash: mesh_hash(&mesh),
            triangles: mesh.num_triangles(),
        };
        if let Some(other) = entries.iter().find(|e| e.name == entry.name) {
            return Err(ExperimentError::Invalid(format!(
                "two meshes are named {:?} ({} and {}): rename one file",
                entry.name, other.source, entry.source
            )));
        }
        if let Some(other) = entries.iter().find(|e| e.hash == entry.hash) {
            return Err(ExperimentError::Invalid(format!(
                "{} and {} are the same mesh",
                other.source, entry.source
            )));
        }
        entries.push(entry);
        meshes.push(mesh);
    }
    phases.load_s = clock.elapsed().as_secs_f64();
    let clock = std::time::Instant::now();
    let evaluator = Evaluator::new(config.backend())?;
    for note in evaluator.notes() {
        events(Event::Backend(note));
    }
    let mut tables: Vec<CandidateTable> =
        meshes.iter().map(CandidateTable::topology_only).collect();
    {
        let mut jobs: Vec<(&Mesh, &mut CandidateTable)> =
            meshes.iter().zip(tables.iter_mut()).collect();
        evaluator.fill(&mut jobs)?;
    }
    let tables: Vec<CandidateTable> = (meshes.iter().zip(tables))
        .map(|(mesh, table)| table.restrict(mesh, config.rule()))
        .collect();
    phases.eta_s = clock.elapsed().as_secs_f64();
    let clock = std::time::Instant::now();
    let mut optimum = Vec::new();
    for ((mesh, table), entry) in meshes.iter().zip(&tables).zip(&entries) {
        optimum.push(cached_optimum(
            config.out(),
            mesh,
            table,
            entry,
            config.overwrite(),
        )?);
    }
    phases.optimum_s = clock.elapsed().as_secs_f64();
    let manifest = Manifest {
        version: super::VERSION.to_string(),
        spec: config.spec(entries),
        backend: evaluator.name().to_string(),
        backend_requested: config.backend().to_string(),
        optimum,
        shard: config.shard(),
        threads: config.threads(),
        machine: Machine::current(),
        merged_from: Vec::new(),
        sessions: Vec::new(),
    };
    Ok(Prepared {
        meshes,
        tables,
        manifest,
        phases,
    })
}

/// The optimum of `mesh` with `table`'s eta: read from `out/optimum-cache/<mesh hash>.json`
/// when it was computed from the same eta by the same version and its matching checks out
/// (disjoint candidates of the table whose eta sums bit for bit to the recorded quality), else
/// (and always with `recompute`) computed and written there.
pub fn cached_optimum(
    out: &Path,
    mesh: &Mesh,
    table: &CandidateTable,
    entry: &MeshEntry,
    recompute: bool,
) -> Result<OptimumEntry, ExperimentError> {
    let dir = out.join(OPTIMUM_CACHE_DIR);
    let path = dir.join(format!("{}.json", entry.hash));
    // A FIFO there would block the read forever (and no cache could be written over it).
    super::store::refuse_irregular(&path)?;
    let eta = eta_hash(&table.eta);
    let text = (!recompute)
        .then(|| std::fs::read_to_string(&path).ok())
        .flatten();
    if let Some(text) = text
        && let Ok(cached) = serde_json::from_str::<CachedOptimum>(&text)
        && cached.optimum.mesh_hash == entry.hash
        && cached.optimum.eta_hash == eta
        && cached.verify(mesh, table)
    {
        return Ok(OptimumEntry {
            mesh: entry.name.clone(),
            // JSON parsing of floats may be off by an ulp: restore the exact value,
            // so that quality_pct is bit-identical whether the optimum was cached.
            quality: f64::from_bits(cached.quality_bits),
            // From the verified matching, bit for bit as when it was solved.
            elements: ElementQuality::of_chosen(table, &cached.chosen),
            ..cached.optimum
        });
    }
    let opt = crate::search::optimum::solve(mesh, table);
    let found = OptimumEntry {
        mesh: entry.name.clone(),
        mesh_hash: entry.hash.clone(),
        eta_hash: eta,
        quality: opt.quality,
        quads: opt.quads,
        triangles_left: opt.triangles_left,
        time_s: opt.time_s,
        elements: ElementQuality::of_chosen(table, &opt.chosen),
    };
    if let Ok(meta) = std::fs::metadata(&dir)
        && !meta.is_dir()
    {
        return Err(ExperimentError::Invalid(format!(
            "{}: is {}, not the directory of the optimum's cache; remove or move it",
            dir.display(),
            crate::mesh::file_kind(&meta)
        )));
    }
    std::fs::create_dir_all(&dir).map_err(|e| ExperimentError::io(&dir, e))?;
    let cached = CachedOptimum {
        quality_bits: found.quality.to_bits(),
        optimum: found.clone(),
        solver: super::VERSION.to_string(),
        chosen: opt.chosen,
    };
    let text = serde_json::to_string_pretty(&cached).expect("serializes");
    super::write_atomic(&path, format!("{text}\n").as_bytes())?;
    Ok(found)
}

/// An optimum cache file: the entry, the exact bits of its quality, the version that solved
/// it and the matching itself (candidate indices, ascending), so that it can be checked.
#[derive(Debug, serde::Serialize, serde::Deserialize)]
struct CachedOptimum {
    optimum: OptimumEntry,
    quality_bits: u64,
    /// quadrecomb version that computed it (absent in caches written before: recomputed).
    #[serde(default)]
    solver: String,
    #[serde(default)]
    chosen: Vec<u32>,
}

impl CachedOptimum {
    /// Whether this cache can be trusted for `mesh` and `table`: written by this version,
    /// and its matching is one (candidates of the table, no triangle twice) whose eta sums
    /// to the recorded quality bit for bit, with the recorded counts. An edited quality fails
    /// here; a matching that passes is a real one, so its quality is not above the optimum.
    fn verify(&self, mesh: &Mesh, table: &CandidateTable) -> bool {
        let o = &self.optimum;
        let nt = mesh.num_triangles();
        let mut used = vec![false; nt];
        let ascending = self.chosen.windows(2).all(|w| w[0] < w[1]);
        let disjoint = self.chosen.iter().all(|&c| {
            table.pairs.get(c as usize).is_some_and(|&[a, b]| {
                let fresh = !used[a as usize] && !used[b as usize];
                used[a as usize] = true;
                used[b as usize] = true;
                fresh
            })
        });
        self.solver == super::VERSION
            && ascending
            && disjoint
            && o.quads == self.chosen.len()
            && 2 * o.quads + o.triangles_left == nt
            && o.quality.to_bits() == self.quality_bits
            && table.quality_of(&self.chosen).to_bits() == self.quality_bits
    }
}

/// Runs searches (and reports the precomputed optimum) for the engine.
pub struct SearchFactory<'a> {
    meshes: &'a [Mesh],
    tables: &'a [CandidateTable],
    optimum: &'a [OptimumEntry],
    finish: Option<super::finished::FinishSettings>,
    rule: crate::quality::Rule,
    spec: &'a super::manifest::SweepSpec,
    watch: Option<RunWatch>,
}

impl std::fmt::Debug for SearchFactory<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SearchFactory")
            .field("meshes", &self.spec.meshes.len())
            .field("rule", &self.rule)
            .field("watched", &self.watch.is_some())
            .finish_non_exhaustive()
    }
}

impl<'a> SearchFactory<'a> {
    /// A factory over prepared meshes.
    pub fn new(prepared: &'a Prepared) -> SearchFactory<'a> {
        SearchFactory {
            meshes: &prepared.meshes,
            tables: &prepared.tables,
            optimum: &prepared.manifest.optimum,
            finish: prepared.manifest.spec.finish,
            rule: prepared.manifest.spec.rule(),
            spec: &prepared.manifest.spec,
            watch: None,
        }
    }

    /// The factory with `watch` called on its runs that last (see [`RunWatch`]).
    pub fn watched(self, watch: Option<RunWatch>) -> SearchFactory<'a> {
        SearchFactory { watch, ..self }
    }
}

struct SearchWorker<'a> {
    factory: &'a SearchFactory<'a>,
    searchers: Vec<Option<Searcher<'a>>>,
}

impl WorkerFactory for SearchFactory<'_> {
    fn worker(&self) -> Box<dyn Worker + '_> {
        Box::new(SearchWorker {
            factory: self,
            searchers: (0..self.meshes.len()).map(|_| None).collect(),
        })
    }
}

impl Worker for SearchWorker<'_> {
    fn run(&mut self, job: &Job) -> Result<Outcome, ExperimentError> {
        let given = crate::search::Params {
            horizon: job.horizon,
            budget: job.budget,
        };
        let algo = Algo::of_record(&job.algo, given)
            .map_err(|e| ExperimentError::Invalid(e.to_string()))?;
        if !algo.info().search {
            return Ok(Outcome::of_optimum(&self.factory.optimum[job.mesh]));
        }
        let f = self.factory;
        let searcher = self.searchers[job.mesh]
            .get_or_insert_with(|| Searcher::new(&f.meshes[job.mesh], &f.tables[job.mesh]));
        if let Some(watch) = &f.watch {
            let (watch, key) = (Arc::clone(watch), job.key(f.spec));
            let (mut next_s, mut watching) = (WATCH_PERIOD_S, true);
            searcher.set_progress(move |p| {
                if watching && p.elapsed_s >= next_s {
                    next_s = p.elapsed_s + WATCH_PERIOD_S;
                    watching = watch(&key, p);
                }
            });
        }
        let out = searcher.run(algo, job.seed);
        let mut outcome = Outcome::of_run(&out, &f.tables[job.mesh]);
        if let Some(settings) = f.finish {
            let (mesh, table) = (&f.meshes[job.mesh], &f.tables[job.mesh]);
            outcome.finish = Some(
                super::finished::finish_run(mesh, table, &out.chosen, settings, f.rule).map_err(
                    |source| ExperimentError::Finish {
                        mesh: f.spec.meshes[job.mesh].name.clone(),
                        seed: job.seed,
                        source,
                    },
                )?,
            );
        }
        Ok(outcome)
    }
}

/// The calibrations of the sweep's time budgets: a resumed sweep takes its directory's
/// (never calibrating again: it must make the same runs); an extension takes them and
/// calibrates only what it adds; a new sweep calibrates every one, by pilot runs on the
/// prepared meshes with the sweep's threads.
fn calibration(
    config: &SweepConfig,
    prepared: &Prepared,
    cancel: &AtomicBool,
    events: &mut Events<'_>,
) -> Result<Vec<super::calibrate::Calibrated>, ExperimentError> {
    let dir = config.out();
    let existing = if config.resume() && dir.join(super::manifest::MANIFEST_FILE).is_file() {
        Some(Manifest::read(dir)?.spec.calibration)
    } else {
        None
    };
    match existing {
        // A plain resume: the directory's own (the engine refuses another configuration).
        Some(c) if !config.extend() => Ok(c),
        existing => {
            let factory = SearchFactory::new(prepared);
            super::calibrate::calibrate_spec(
                &prepared.manifest.spec,
                existing.as_deref().unwrap_or(&[]),
                &factory,
                config.threads(),
                cancel,
                &mut |note| events(Event::Calibrated(note)),
            )
        }
    }
}

/// Prepares and runs a sweep into its results directory; `cancel` stops it between runs,
/// progress and notices go to `events`.
pub fn run(
    config: &SweepConfig,
    cancel: &AtomicBool,
    events: &mut Events<'_>,
) -> Result<(Manifest, EngineReport), ExperimentError> {
    run_timed(config, cancel, events, None).map(|(m, r, _)| (m, r))
}

/// [`run`], with the time each phase took, and `watch` called on the runs that last.
pub fn run_timed(
    config: &SweepConfig,
    cancel: &AtomicBool,
    events: &mut Events<'_>,
    watch: Option<RunWatch>,
) -> Result<(Manifest, EngineReport, PhaseTimes), ExperimentError> {
    let mut prepared = prepare(config, events)?;
    if !prepared.manifest.spec.time_budgets.is_empty() {
        prepared.manifest.spec.calibration = calibration(config, &prepared, cancel, events)?;
    }
    let factory = SearchFactory::new(&prepared).watched(watch);
    let clock = std::time::Instant::now();
    let report = engine::run(
        &prepared.manifest,
        &factory,
        &config.engine_options(),
        cancel,
        events,
    )?;
    let phases = PhaseTimes {
        engine_s: clock.elapsed().as_secs_f64(),
        ..prepared.phases
    };
    Ok((prepared.manifest.clone(), report, phases))
}
