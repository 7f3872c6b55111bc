//! The real sweep: loads the meshes, computes every candidate's eta once (one evaluator batch
//! over all meshes), the optimum once per mesh (cached by mesh hash), and runs the searches
//! through [`super::engine`] with one reusable [`Searcher`] per thread and mesh.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use super::ExperimentError;
use super::engine::{self, EngineOptions, EngineReport};
use super::exec::{Outcome, Worker, WorkerFactory};
use super::manifest::{Machine, Manifest, MeshEntry, OptimumEntry, Shard, SweepSpec};
use super::plan::{Job, has_horizon};
use super::progress::ProgressMode;
use super::record::ALGO_NAMES;
use super::seed::{eta_hash, mesh_hash};
use crate::gpu::{Backend, Evaluator};
use crate::mesh::Mesh;
use crate::quality::{CandidateTable, ElementQuality, Rule};
use crate::search::{Algo, Searcher};

/// Algorithms of the default sweep (the paper's experiment), in order.
pub const DEFAULT_ALGOS: &[&str] = &["selective", "greedy", "greedy-nocrit", "optimum"];
/// The default base seed.
pub const DEFAULT_SEED: u64 = 2026;
/// Most horizons one sweep takes.
pub const MAX_HORIZONS: usize = 1024;
/// Most runs one sweep plans (its run list is held in memory, each run a line of the log).
pub const MAX_RUNS: u64 = 10_000_000;
/// Directory of the optimum cache inside a results directory.
pub const OPTIMUM_CACHE_DIR: &str = "optimum-cache";

/// A validated sweep configuration (what `quadrecomb sweep` parses its arguments into).
#[derive(Debug, Clone)]
pub struct SweepConfig {
    /// Meshes: built-in names or paths.
    pub meshes: Vec<String>,
    /// Algorithm names (see [`ALGO_NAMES`]).
    pub algos: Vec<String>,
    /// Horizons of `uniform` and `selective`.
    pub horizons: Vec<u32>,
    /// Runs per (mesh, tree algorithm, horizon).
    pub runs: u32,
    /// Runs of `greedy` and `greedy-nocrit` per mesh.
    pub baseline_runs: u32,
    /// Base seed.
    pub seed: u64,
    /// Worker threads.
    pub threads: usize,
    /// Who computes eta.
    pub backend: Backend,
    /// Which pairs may be merged (valid quads by default).
    pub rule: Rule,
    /// Results directory.
    pub out: PathBuf,
    /// Continue the sweep in `out`.
    pub resume: bool,
    /// Replace an earlier sweep's results in `out`.
    pub overwrite: bool,
    /// Run only this slice of the run list.
    pub shard: Option<Shard>,
    /// Progress display.
    pub progress: ProgressMode,
}

impl SweepConfig {
    /// The paper's experiment on `borouchaki` into `results/borouchaki`.
    pub fn paper() -> SweepConfig {
        SweepConfig {
            meshes: vec!["borouchaki".into()],
            algos: DEFAULT_ALGOS.iter().map(|s| s.to_string()).collect(),
            horizons: (1..=10).collect(),
            runs: 128,
            baseline_runs: 1,
            seed: DEFAULT_SEED,
            threads: std::thread::available_parallelism().map_or(1, |n| n.get()),
            backend: Backend::Auto,
            rule: Rule::default(),
            out: PathBuf::from("results/borouchaki"),
            resume: false,
            overwrite: false,
            shard: None,
            progress: ProgressMode::Auto,
        }
    }

    /// Checks the configuration before any work starts.
    pub fn validate(&self) -> Result<(), ExperimentError> {
        let bad = |m: String| Err(ExperimentError::Invalid(m));
        if self.meshes.is_empty() {
            return bad("no mesh given".into());
        }
        if self.algos.is_empty() {
            return bad("no algorithm given".into());
        }
        for (i, a) in self.algos.iter().enumerate() {
            if !ALGO_NAMES.contains(&a.as_str()) {
                return bad(format!(
                    "unknown algorithm {a:?} (expected one of {})",
                    ALGO_NAMES.join(", ")
                ));
            }
            if self.algos[..i].contains(a) {
                return bad(format!("algorithm {a:?} given twice"));
            }
        }
        if self.algos.iter().any(|a| has_horizon(a)) {
            if self.horizons.is_empty() {
                return bad("no horizon given".into());
            }
            if self.horizons.contains(&0) {
                return bad("horizons must be at least 1".into());
            }
            if self.runs == 0 {
                return bad("--runs must be at least 1".into());
            }
        }
        // `--baseline-runs` counts the greedy runs (the optimum always runs once).
        let baselines: Vec<&str> = (self.algos.iter().map(String::as_str))
            .filter(|a| matches!(*a, "greedy" | "greedy-nocrit"))
            .collect();
        if self.baseline_runs == 0 && !baselines.is_empty() {
            return bad(format!(
                "--baseline-runs must be at least 1 (it is the number of runs of {})",
                baselines.join(", ")
            ));
        }
        for (i, h) in self.horizons.iter().enumerate() {
            if self.horizons[..i].contains(h) {
                return bad(format!("horizon {h} given twice"));
            }
        }
        if self.threads == 0 {
            return bad("--threads must be at least 1".into());
        }
        if self.horizons.len() > MAX_HORIZONS {
            return bad(format!(
                "{} horizons given; a sweep takes at most {MAX_HORIZONS}",
                self.horizons.len()
            ));
        }
        // Counted before the run list is built (it is held in memory).
        let total = super::plan::planned_runs(
            self.meshes.len(),
            &self.algos,
            self.horizons.len(),
            self.runs,
            self.baseline_runs,
        );
        if total > MAX_RUNS {
            return bad(format!(
                "the sweep has {total} runs (--runs {}, --baseline-runs {}, {} horizon(s), {} \
                 algorithm(s), {} mesh(es)); a sweep takes at most {MAX_RUNS}: split it or run \
                 fewer",
                self.runs,
                self.baseline_runs,
                self.horizons.len(),
                self.algos.len(),
                self.meshes.len()
            ));
        }
        Ok(())
    }
}

/// Meshes with their eta filled, optima computed, and the manifest of the sweep.
#[derive(Debug)]
pub struct Prepared {
    /// Meshes, in spec order.
    pub meshes: Vec<Mesh>,
    /// Candidate tables with eta, in spec order.
    pub tables: Vec<CandidateTable>,
    /// The manifest to write.
    pub manifest: Manifest,
}

/// The name a mesh has in records: the built-in name, or the file stem.
pub fn mesh_name(spec: &str) -> String {
    if crate::mesh::builtin::NAMES.contains(&spec) {
        return spec.to_string();
    }
    Path::new(spec)
        .file_stem()
        .map_or_else(|| spec.to_string(), |s| s.to_string_lossy().into_owned())
}

/// Loads the meshes, fills eta in one evaluator batch, and finds (or computes and caches
/// under `config.out`) the optimum of each mesh.
pub fn prepare(config: &SweepConfig) -> Result<Prepared, ExperimentError> {
    config.validate()?;
    let mut meshes = Vec::new();
    let mut entries: Vec<MeshEntry> = Vec::new();
    for spec in &config.meshes {
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
    let evaluator = Evaluator::new(config.backend)?;
    let mut tables: Vec<CandidateTable> =
        meshes.iter().map(CandidateTable::topology_only).collect();
    {
        let mut jobs: Vec<(&Mesh, &mut CandidateTable)> =
            meshes.iter().zip(tables.iter_mut()).collect();
        evaluator.fill(&mut jobs)?;
    }
    let tables: Vec<CandidateTable> = (meshes.iter().zip(tables))
        .map(|(mesh, table)| table.restrict(mesh, config.rule))
        .collect();
    let mut optimum = Vec::new();
    for ((mesh, table), entry) in meshes.iter().zip(&tables).zip(&entries) {
        optimum.push(cached_optimum(
            &config.out,
            mesh,
            table,
            entry,
            config.overwrite,
        )?);
    }
    let manifest = Manifest {
        version: super::VERSION.to_string(),
        spec: SweepSpec {
            meshes: entries,
            algos: config.algos.clone(),
            horizons: if config.algos.iter().any(|a| has_horizon(a)) {
                config.horizons.clone()
            } else {
                Vec::new()
            },
            runs: config.runs,
            baseline_runs: config.baseline_runs,
            seed: config.seed,
            min_eta: config.rule.min_eta(),
            allow_invalid: config.rule.allows_invalid(),
        },
        backend: evaluator.name().to_string(),
        backend_requested: config.backend.to_string(),
        optimum,
        shard: config.shard,
        threads: config.threads,
        machine: Machine::current(),
        merged_from: Vec::new(),
    };
    Ok(Prepared {
        meshes,
        tables,
        manifest,
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
    let eta = eta_hash(&table.eta);
    let text = (!recompute)
        .then(|| std::fs::read_to_string(&path).ok())
        .flatten();
    if let Some(text) = text {
        if let Ok(cached) = serde_json::from_str::<CachedOptimum>(&text) {
            if cached.optimum.mesh_hash == entry.hash
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
        }
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
#[derive(Debug)]
pub struct SearchFactory<'a> {
    meshes: &'a [Mesh],
    tables: &'a [CandidateTable],
    optimum: &'a [OptimumEntry],
}

impl<'a> SearchFactory<'a> {
    /// A factory over prepared meshes.
    pub fn new(prepared: &'a Prepared) -> SearchFactory<'a> {
        SearchFactory {
            meshes: &prepared.meshes,
            tables: &prepared.tables,
            optimum: &prepared.manifest.optimum,
        }
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
        if job.algo == "optimum" {
            let o = &self.factory.optimum[job.mesh];
            return Ok(Outcome {
                quads: o.quads,
                triangles_left: o.triangles_left,
                quality: o.quality,
                nodes_expanded: 0,
                trees: 0,
                decisions: o.quads as u64,
                time_s: o.time_s,
                elements: o.elements,
            });
        }
        let algo = Algo::from_name(&job.algo, job.horizon.unwrap_or(1))
            .map_err(|e| ExperimentError::Invalid(e.to_string()))?;
        let f = self.factory;
        let searcher = self.searchers[job.mesh]
            .get_or_insert_with(|| Searcher::new(&f.meshes[job.mesh], &f.tables[job.mesh]));
        let out = searcher.run(algo, job.seed);
        Ok(Outcome {
            elements: ElementQuality::of_chosen(&f.tables[job.mesh], &out.chosen),
            quads: out.quads,
            triangles_left: out.triangles_left,
            quality: out.quality,
            nodes_expanded: out.nodes_expanded,
            trees: out.trees,
            decisions: out.decisions,
            time_s: out.time_s,
        })
    }
}

/// Prepares and runs a sweep into `config.out`; `cancel` stops it between runs.
pub fn run(
    config: &SweepConfig,
    cancel: &AtomicBool,
) -> Result<(Manifest, EngineReport), ExperimentError> {
    let prepared = prepare(config)?;
    let factory = SearchFactory::new(&prepared);
    let report = engine::run(
        &prepared.manifest,
        &factory,
        &EngineOptions {
            dir: config.out.clone(),
            resume: config.resume,
            overwrite: config.overwrite,
            threads: config.threads,
            progress: config.progress,
        },
        cancel,
    )?;
    Ok((prepared.manifest.clone(), report))
}
