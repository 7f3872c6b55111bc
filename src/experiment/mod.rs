//! Experiments: seeded, parallel, resumable horizon sweeps and their run records.
//!
//! A sweep is a [`manifest::SweepSpec`] (meshes, algorithms, horizons, runs, base seed) turned
//! into a run list ([`plan`]), each run with a seed derived from what it is, never from where or
//! when it runs ([`seed`]). Runs execute on a thread pool ([`exec`]), each finished run is one
//! flushed line of `runs.jsonl` ([`store`]), and the directory can be resumed after a kill,
//! split into shards and merged back ([`merge`]). [`summary`] turns records into statistics.

pub mod calibrate;
pub mod config;
pub mod engine;
pub mod events;
pub mod exec;
pub mod finished;
pub mod lock;
pub mod manifest;
pub mod merge;
pub mod plan;
pub mod record;
pub mod replay;
pub mod seed;
pub mod store;
pub mod summary;
pub mod sweep;

pub use seed::{derive_seed, mesh_hash};

use std::path::{Path, PathBuf};

/// Errors of the experiment runner.
#[derive(Debug, thiserror::Error)]
pub enum ExperimentError {
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// A results file holds something that is not what the runner writes.
    #[error("{path}: corrupt: {message}")]
    Corrupt {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A results directory belongs to another configuration than the one asked for.
    #[error("{dir}: holds results of a different configuration: {message}")]
    Mismatch {
        /// The directory.
        dir: PathBuf,
        /// The first difference found.
        message: String,
    },
    /// A results directory is resumed with a configuration that is not its own but would
    /// extend it (more algorithms, horizons or runs; same meshes, base seed and rule).
    #[error(
        "{dir}: holds results of a different configuration: {message} (the new one \
         extends it: every run recorded there is one of its runs)"
    )]
    Extendable {
        /// The directory.
        dir: PathBuf,
        /// The first difference found.
        message: String,
    },
    /// A results directory's records do not fit its own manifest (runs of another sweep,
    /// shard, seed or rule).
    #[error("{dir}: holds results of a different configuration: {message}")]
    ForeignRecords {
        /// The directory.
        dir: PathBuf,
        /// The first record that does not fit, with its line.
        message: String,
    },
    /// A fresh sweep was pointed at a directory that already holds runs (neither resumed nor
    /// replaced).
    #[error("{dir}: already holds {records} run(s) of a sweep")]
    AlreadyExists {
        /// The directory.
        dir: PathBuf,
        /// Records found.
        records: usize,
    },
    /// A sweep or merge was pointed at a directory without a sweep's manifest that holds
    /// files it would write (a report, a summary, figures): someone else's, which it would
    /// replace.
    #[error(
        "{dir}: holds {} that a sweep writes, but no sweep's {}: they are not a sweep's \
         results, and nothing is written over them",
        files.join(", "),
        manifest::MANIFEST_FILE
    )]
    ForeignFiles {
        /// The directory.
        dir: PathBuf,
        /// The files in the way (relative to `dir`).
        files: Vec<String>,
    },
    /// `merge` was pointed at a directory that already holds runs.
    #[error("{dir}: already holds {records} run(s); merge writes into a new or empty directory")]
    MergeTargetNotEmpty {
        /// The directory.
        dir: PathBuf,
        /// Records found.
        records: usize,
    },
    /// The directory to write results into exists and is not a directory.
    #[error("{dir}: is {kind}, not a directory (results go into a directory)")]
    NotADirectory {
        /// The path.
        dir: PathBuf,
        /// What it is ("a regular file", ...).
        kind: String,
    },
    /// Another live process is writing the results directory.
    #[error(
        "{dir}: another sweep, merge or report{} is writing there",
        pid.map_or(String::new(), |p| format!(" (process {p})"))
    )]
    Busy {
        /// The directory.
        dir: PathBuf,
        /// The process holding the lock on `DIR/.lock`, when it could be read.
        pid: Option<u32>,
    },
    /// A part to merge ends with a torn line: its sweep was interrupted and not resumed.
    #[error(
        "{path} ends with a torn line (the sweep was interrupted): resume that sweep there first"
    )]
    TornPart {
        /// The part's run log.
        path: PathBuf,
    },
    /// Shards cannot be merged: missing, duplicated or foreign runs.
    #[error("merge: {0}")]
    Merge(String),
    /// The sweep configuration is invalid.
    #[error("{0}")]
    Invalid(String),
    /// A run's finish failed (`--all-quad`: a component keeps triangles no boundary split
    /// pairs, which every run on that mesh meets).
    #[error("finishing the run of seed {seed} on mesh {mesh}")]
    Finish {
        /// The mesh's name.
        mesh: String,
        /// The run's seed.
        seed: u64,
        /// The cause.
        #[source]
        source: crate::internals::finish::FinishError,
    },
    /// Computing qualities failed.
    #[error("computing quad qualities")]
    Gpu(#[from] crate::gpu::GpuError),
    /// A mesh could not be loaded.
    #[error("loading mesh {spec}")]
    Mesh {
        /// The mesh as given.
        spec: String,
        /// The cause.
        #[source]
        source: crate::mesh::ReadError,
    },
    /// A run did what the optimum recorded for its mesh says no run can: that optimum is
    /// wrong (an edited optimum cache); replacing the results recomputes it.
    #[error(
        "run {run}: {why}: the optimum recorded for its mesh is wrong (an edited optimum \
         cache?); replace the sweep's results to recompute it"
    )]
    OptimumContradicted {
        /// The run's key.
        run: String,
        /// What the run did.
        why: String,
    },
    /// A run failed.
    #[error("{0}")]
    Run(String),
    /// The cancel flag stopped the sweep before its runs began (while calibrating its time
    /// budgets): nothing was recorded.
    #[error("{0}")]
    Interrupted(String),
}

impl ExperimentError {
    pub(crate) fn io(path: &Path, source: std::io::Error) -> ExperimentError {
        ExperimentError::Io {
            path: path.to_path_buf(),
            source,
        }
    }
}

/// Writes a file through a temporary sibling and a rename ([`crate::output`]), so readers
/// never see half of it.
pub(crate) fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), ExperimentError> {
    crate::output::write_bytes(path, bytes).map_err(|e| ExperimentError::io(path, e))
}

/// Version recorded in records and manifests.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");

/// This binary's build, as a manifest's [`manifest::Session`] records it: the version, the git
/// commit it was built from (`+modified` where the tracked sources differed from it; `unknown`
/// outside a git checkout), and `debug assertions` for a build with them (whose times are
/// not an optimised build's).
pub fn build() -> String {
    format!(
        "quadrecomb {VERSION}, git {}{}",
        env!("QUADRECOMB_BUILD"),
        if cfg!(debug_assertions) {
            ", debug assertions"
        } else {
            ""
        }
    )
}
