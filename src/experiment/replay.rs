//! Replaying a recorded run: the same mesh, the same eta and the same rule, re-run from the
//! record's seed, and whether it gave the recorded result.
//!
//! Runs are deterministic given (mesh, eta table, algorithm, seed), so a replay reproduces a
//! record exactly when the eta table is bit for bit the one the sweep used. The sweep records
//! which evaluator filled eta (`backend`) and, in the manifest, a hash of the table
//! (`eta_hash`). [`Replayer`] finds the mesh (the manifest's source, its recorded path, the
//! source beside the results directory, the built-in of that name: the first with the
//! recorded hash), rebuilds the table with the recorded evaluator where it can be opened
//! here, else with the CPU twin, else with the f64 reference, and uses the first whose hash
//! matches the manifest's. The report's pictures and `quadrecomb replay` both go through it.

use super::manifest::Manifest;
use super::record::RunRecord;
use super::{mesh_hash, seed::eta_hash};
use crate::gpu::{Backend, Evaluator, GpuError};
use crate::mesh::{Mesh, Recombined};
use crate::quality::{CandidateTable, ElementQuality, Rule, recombined};
use crate::search::{self, Algo, optimum};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Who computes eta: the three evaluators a table can be filled by.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EtaSource {
    /// The f64 reference ([`CandidateTable::build`]), recorded as `exact`.
    Exact,
    /// The CPU twin of the GPU kernel (f32), recorded as `cpu-twin`.
    CpuTwin,
    /// The GPU kernel on the best Vulkan adapter (lavapipe included), recorded as
    /// `vulkan: <adapter>`.
    Device,
}

/// The name results record for the f64 reference.
pub const EXACT_NAME: &str = "exact";

impl EtaSource {
    /// The evaluator a recorded `backend` name denotes: `cpu-twin`, `exact`, or a Vulkan
    /// adapter (any other name).
    pub fn of_recorded(name: &str) -> EtaSource {
        if name == Evaluator::cpu_twin().name() {
            EtaSource::CpuTwin
        } else if name == EXACT_NAME {
            EtaSource::Exact
        } else {
            EtaSource::Device
        }
    }
}

/// The candidate table of `mesh` with eta from `source`, restricted to the pairs `rule`
/// allows, and the name of what filled it (as records write it). Fails when `source` is
/// [`EtaSource::Device`] and no Vulkan adapter opens.
pub fn eta_table(
    mesh: &Mesh,
    source: EtaSource,
    rule: Rule,
) -> Result<(CandidateTable, String), GpuError> {
    let ev = match source {
        EtaSource::Exact => {
            let table = CandidateTable::build(mesh).restrict(mesh, rule);
            return Ok((table, EXACT_NAME.into()));
        }
        EtaSource::CpuTwin => Evaluator::cpu_twin(),
        EtaSource::Device => Evaluator::new(Backend::Gpu)?,
    };
    let mut table = CandidateTable::topology_only(mesh);
    ev.fill(&mut [(mesh, &mut table)])?;
    Ok((table.restrict(mesh, rule), ev.name().to_string()))
}

/// The run shown as typical of a configuration: the median by quality (the lower middle one
/// for an even count; ties broken by run index).
pub fn typical_run(runs: &[RunRecord]) -> Option<&RunRecord> {
    let mut order: Vec<&RunRecord> = runs.iter().collect();
    order.sort_by(|a, b| a.quality.total_cmp(&b.quality).then(a.run.cmp(&b.run)));
    order.get(order.len().saturating_sub(1) / 2).copied()
}

/// Why a record cannot be replayed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ReplayError {
    /// The record names an algorithm this build does not know (or a zero horizon).
    #[error("cannot re-run {algo}: {why}")]
    Algo {
        /// The recorded algorithm.
        algo: String,
        /// Why.
        why: String,
    },
    /// The mesh was found but its hash is not the recorded one.
    #[error("mesh {mesh} has changed since the sweep (hash {found} vs recorded {recorded})")]
    MeshChanged {
        /// The mesh's source as the manifest gives it.
        mesh: String,
        /// The first 12 hex digits of the hash found.
        found: String,
        /// The first 12 hex digits of the recorded hash.
        recorded: String,
    },
    /// The mesh could not be loaded from any of its places.
    #[error("cannot load mesh {mesh}: {why}")]
    MeshNotFound {
        /// The mesh's source as the manifest gives it.
        mesh: String,
        /// The first loading error.
        why: String,
    },
    /// The run's finish failed again (all-quad: a component no boundary split pairs).
    #[error("cannot finish the run again: {0}")]
    Finish(String),
}

/// How the eta table of a replay compares with the sweep's.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EtaCheck {
    /// Its hash is the manifest's: the table is the sweep's.
    Matches,
    /// No evaluator here gives the manifest's hash; the recorded one's table (or the first
    /// that could be built) is used.
    NoMatch,
    /// No manifest (or no optimum entry for the mesh) to check against.
    Unchecked,
}

impl EtaCheck {
    /// The words the report and `replay` use.
    pub fn describe(self) -> &'static str {
        match self {
            EtaCheck::Matches => "its eta hash matches the manifest's",
            EtaCheck::NoMatch => "no evaluator here reproduces the manifest's eta hash",
            EtaCheck::Unchecked => "no manifest to check the eta hash against",
        }
    }
}

/// A mesh and its eta table as rebuilt for replaying, with how they were obtained.
#[derive(Debug)]
struct Prepared {
    mesh: Mesh,
    /// The file the mesh was read from; `None` for a built-in.
    file: Option<PathBuf>,
    table: CandidateTable,
    /// Which evaluator filled the table, as a phrase ("the CPU twin (as recorded)").
    eta: String,
    check: EtaCheck,
}

/// A replayed run.
#[derive(Debug)]
pub struct Replayed<'a> {
    /// The mesh.
    pub mesh: &'a Mesh,
    /// The file the mesh was read from; `None` for a built-in mesh.
    pub mesh_file: Option<&'a Path>,
    /// Its recombination (quads and leftover triangles).
    pub recombined: Recombined,
    /// Quads made.
    pub quads: usize,
    /// Triangles left.
    pub triangles_left: usize,
    /// Sum of eta over the quads.
    pub quality: f64,
    /// Element quality of the quads.
    pub elements: ElementQuality,
    /// Seconds the search (or the matching) took.
    pub time_s: f64,
    /// Which evaluator filled eta, as a phrase ("the CPU twin (as recorded)").
    pub eta: &'a str,
    /// Whether that table is the sweep's.
    pub eta_check: EtaCheck,
    /// Whether the replay gave the record's quads and quality (to 1e-9 relative: JSON may
    /// round the recorded float by an ulp), and, for a finished run, its finish's too.
    pub reproduced: bool,
    /// The replayed run finished again with the record's settings, when the record has a
    /// `finish` object (`sweep --finish`): its figures in the record's form.
    pub finish: Option<super::finished::FinishRecord>,
    /// The finished mesh and its elements, when the record has a `finish` object: with
    /// all-quad, the split mesh rebuilt from the record (what `replay -o` writes).
    pub finished: Option<super::finished::FinishedMesh>,
}

impl Replayed<'_> {
    /// "the CPU twin (as recorded); its eta hash matches the manifest's".
    pub fn eta_note(&self) -> String {
        format!("{}; {}", self.eta, self.eta_check.describe())
    }
}

/// Replays records of one results directory, loading each mesh and building its table once.
#[derive(Debug)]
pub struct Replayer<'m> {
    dir: PathBuf,
    manifest: Option<&'m Manifest>,
    prepared: HashMap<String, Result<Prepared, ReplayError>>,
}

impl<'m> Replayer<'m> {
    /// A replayer of the records of results directory `dir`, whose `manifest.json` (if
    /// any) is `manifest`.
    pub fn new(dir: &Path, manifest: Option<&'m Manifest>) -> Replayer<'m> {
        Replayer {
            dir: dir.to_path_buf(),
            manifest,
            prepared: HashMap::new(),
        }
    }

    /// The file `record`'s mesh is read from (`None` for a built-in), loading it and
    /// building its table if not yet done: to refuse an output that would overwrite it
    /// before running.
    pub fn mesh_file(&mut self, record: &RunRecord) -> Result<Option<&Path>, ReplayError> {
        Ok(self.prepare(record)?.file.as_deref())
    }

    /// Re-runs `record` on its mesh with the sweep's eta and rule, from its seed.
    pub fn replay(&mut self, record: &RunRecord) -> Result<Replayed<'_>, ReplayError> {
        let given = search::Params {
            horizon: record.horizon,
            budget: record.budget,
        };
        let algo = Algo::of_record(&record.algo, given)
            .map(|a| a.info().search.then_some(a))
            .map_err(|e| ReplayError::Algo {
                algo: record.algo.clone(),
                why: e.to_string(),
            })?;
        let p = self.prepare(record)?;
        let (chosen, quads, triangles_left, quality, time_s) = match algo {
            Some(algo) => {
                let o = search::run(&p.mesh, &p.table, algo, record.seed);
                (o.chosen, o.quads, o.triangles_left, o.quality, o.time_s)
            }
            None => {
                let o = optimum::solve(&p.mesh, &p.table);
                (o.chosen, o.quads, o.triangles_left, o.quality, o.time_s)
            }
        };
        let same = |q: usize, x: f64, rq: usize, rx: f64| {
            q == rq && (x - rx).abs() <= 1e-9 * rx.abs().max(1.0)
        };
        let (finish, finished) = match record.finish.as_ref() {
            Some(f) => {
                let settings = super::finished::FinishSettings {
                    rings: f.rings,
                    window: f.window,
                    all_quad: f.all_quad.is_some(),
                };
                let (out, finished) = super::finished::finish_run_with_mesh(
                    &p.mesh,
                    &p.table,
                    &chosen,
                    settings,
                    record.rule(),
                )
                .map_err(|e| ReplayError::Finish(e.to_string()))?;
                // The optimum the record's percentage was taken against.
                let optimum = record
                    .quality_pct
                    .filter(|&pct| pct > 0.0)
                    .map(|pct| 100.0 * record.quality / pct);
                let rec =
                    super::finished::FinishRecord::new(settings, &out, record.triangles, optimum);
                (Some(rec), Some(finished))
            }
            None => (None, None),
        };
        let reproduced = same(quads, quality, record.quads, record.quality)
            && match (&finish, &record.finish) {
                (Some(a), Some(b)) => {
                    same(a.quads, a.quality, b.quads, b.quality)
                        && a.splits() == b.splits()
                        && a.triangles_added() == b.triangles_added()
                }
                _ => true,
            };
        Ok(Replayed {
            mesh: &p.mesh,
            mesh_file: p.file.as_deref(),
            recombined: recombined(&p.mesh, &p.table, &chosen),
            elements: ElementQuality::of_chosen(&p.table, &chosen),
            quads,
            triangles_left,
            quality,
            time_s,
            eta: &p.eta,
            eta_check: p.check,
            reproduced,
            finish,
            finished,
        })
    }

    fn prepare(&mut self, record: &RunRecord) -> Result<&Prepared, ReplayError> {
        let (dir, manifest) = (&self.dir, self.manifest);
        self.prepared
            .entry(record.mesh.clone())
            .or_insert_with(|| prepare(dir, manifest, record))
            .as_ref()
            .map_err(Clone::clone)
    }
}

/// Loads the mesh of `record` and rebuilds the eta table that matches the sweep's.
fn prepare(
    dir: &Path,
    manifest: Option<&Manifest>,
    record: &RunRecord,
) -> Result<Prepared, ReplayError> {
    let (mesh, file) = load_mesh(dir, manifest, record)?;
    let want = manifest
        .and_then(|m| m.optimum.iter().find(|o| o.mesh == record.mesh))
        .map(|o| o.eta_hash.as_str());
    let recorded = record.backend.as_str();
    let first = EtaSource::of_recorded(recorded);
    let mut order = vec![first];
    order.extend(
        [EtaSource::CpuTwin, EtaSource::Exact]
            .into_iter()
            .filter(|s| *s != first),
    );
    // The evaluators in order, the recorded one first; the first table whose hash is the
    // manifest's is the sweep's (built lazily: the recorded one usually is).
    let mut fallback: Option<(String, CandidateTable)> = None;
    for source in order {
        let Ok((table, name)) = eta_table(&mesh, source, record.rule()) else {
            continue;
        };
        let what = eta_phrase(source, &name, source == first, recorded);
        let matches = want.is_some_and(|h| eta_hash(&table.eta) == h);
        if matches {
            return Ok(Prepared {
                mesh,
                file,
                table,
                eta: what,
                check: EtaCheck::Matches,
            });
        }
        fallback.get_or_insert((what, table));
        if want.is_none() {
            break;
        }
    }
    let (eta, table) = fallback.expect("the f64 reference always builds");
    Ok(Prepared {
        mesh,
        file,
        table,
        eta,
        check: if want.is_some() {
            EtaCheck::NoMatch
        } else {
            EtaCheck::Unchecked
        },
    })
}

/// How a table was filled, for notes: "the CPU twin (as recorded)", "vulkan: X (the sweep
/// used cpu-twin)".
fn eta_phrase(source: EtaSource, name: &str, first: bool, recorded: &str) -> String {
    let what = match source {
        EtaSource::CpuTwin => "the CPU twin".to_string(),
        EtaSource::Exact => "the f64 reference".to_string(),
        EtaSource::Device => name.to_string(),
    };
    if first && (source != EtaSource::Device || name == recorded) {
        format!("{what} (as recorded)")
    } else {
        format!("{what} (the sweep used {recorded})")
    }
}

/// Loads the mesh of `record` from where it may be: the manifest's source as given (from this
/// working directory), the absolute path the sweep recorded, the source relative to the
/// results directory, its file name inside the results directory, the built-in of that name; the first with the recorded hash. Returns it
/// and the file it was read from (`None` for a built-in).
fn load_mesh(
    dir: &Path,
    manifest: Option<&Manifest>,
    record: &RunRecord,
) -> Result<(Mesh, Option<PathBuf>), ReplayError> {
    let entry = manifest.and_then(|m| m.spec.meshes.iter().find(|e| e.name == record.mesh));
    let source = entry.map_or(record.mesh.clone(), |e| e.source.clone());
    let mut places: Vec<String> = vec![source.clone()];
    places.extend(entry.and_then(|e| e.path.clone()));
    let beside = dir.join(&source);
    if beside.is_file() {
        places.push(beside.to_string_lossy().into_owned());
    }
    // A mesh kept in the results directory itself (as the committed results keep theirs).
    if let Some(inside) = Path::new(&source).file_name().map(|f| dir.join(f))
        && inside != beside
        && inside.is_file()
    {
        places.push(inside.to_string_lossy().into_owned());
    }
    let loads = places.iter().map(|p| -> Result<_, crate::mesh::ReadError> {
        let src = crate::mesh::source(p)?;
        let file = (!src.builtin).then(|| src.path.clone());
        Ok((src.into_mesh()?, file))
    });
    let (mut first_err, mut other_hash) = (None, None);
    for loaded in loads {
        match loaded {
            Ok((m, file)) => {
                let hash = mesh_hash(&m);
                if record.mesh_hash.is_empty() || hash == record.mesh_hash {
                    return Ok((m, file));
                }
                other_hash.get_or_insert(hash);
            }
            Err(e) => {
                first_err.get_or_insert(e.to_string());
            }
        }
    }
    // A built-in of the source's name, when a file of that name shadowed it.
    if let Some(bytes) = crate::mesh::builtin::bytes(&source) {
        let src = crate::mesh::Source {
            path: source.clone().into(),
            builtin: true,
            bytes: bytes.into(),
        };
        match src.into_mesh() {
            Ok(m) if record.mesh_hash.is_empty() || mesh_hash(&m) == record.mesh_hash => {
                return Ok((m, None));
            }
            Ok(m) => {
                other_hash.get_or_insert(mesh_hash(&m));
            }
            Err(e) => {
                first_err.get_or_insert(e.to_string());
            }
        }
    }
    let short = |h: &str| h[..12.min(h.len())].to_string();
    Err(match other_hash {
        Some(hash) => ReplayError::MeshChanged {
            mesh: source,
            found: short(&hash),
            recorded: short(&record.mesh_hash),
        },
        None => ReplayError::MeshNotFound {
            mesh: source,
            why: first_err.unwrap_or_default(),
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recorded_names_denote_their_evaluator() {
        assert_eq!(EtaSource::of_recorded("cpu-twin"), EtaSource::CpuTwin);
        assert_eq!(EtaSource::of_recorded("exact"), EtaSource::Exact);
        assert_eq!(
            EtaSource::of_recorded("vulkan: llvmpipe (LLVM 19.1.7, 256 bits)"),
            EtaSource::Device
        );
    }

    #[test]
    fn typical_run_is_the_lower_median_by_quality() {
        let mut runs: Vec<RunRecord> = (0..4)
            .map(crate::experiment::store::tests::record)
            .collect();
        for (r, q) in runs.iter_mut().zip([3.0, 1.0, 4.0, 2.0]) {
            r.quality = q;
        }
        assert_eq!(typical_run(&runs).map(|r| r.run), Some(3));
        assert!(typical_run(&[]).is_none());
    }
}
