//! quadrecomb: recombine triangle meshes into quad meshes by sequential decision-making.
//!
//! Data flows one way: a mesh file becomes a [`Mesh`] (geometry and topology), the mesh gives a
//! [`CandidateTable`] (pairs, quad vertices, eta), the table feeds the searches ([`run`],
//! [`optimum`]), searches give run records, records give statistics, statistics give reports
//! (`docs/architecture.md` describes the layers).
//!
//! This crate root is the library's API: load a mesh, build its candidate table, run a method,
//! run a sweep, read and report results. Everything else is internal and may change in any
//! release.
//!
//! ```no_run
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use quadrecomb::{Algo, CandidateTable, Rule};
//! let mesh = quadrecomb::load("sphere")?; // a .msh path or a built-in name
//! let table = CandidateTable::build(&mesh).restrict(&mesh, Rule::default());
//! let best = quadrecomb::optimum(&mesh, &table);
//! for seed in 0..4 {
//!     let out = quadrecomb::run(&mesh, &table, Algo::selective(3), seed);
//!     println!(
//!         "{} quads, {:.2} % of the optimum",
//!         out.quads,
//!         100.0 * out.quality / best.quality
//!     );
//!     let rec = quadrecomb::recombined(&mesh, &table, &out.chosen);
//!     quadrecomb::write_msh(std::path::Path::new(&format!("sphere-{seed}.msh")), &mesh, &rec)?;
//! }
//! # Ok(()) }
//! ```

// The modules live in `internals` (not API); these paths keep `crate::mesh::...` working inside.
use internals::{experiment, gpu, mesh, output, quality, report, search, stats};

// Meshes: reading, validating, writing.
pub use mesh::msh::write as write_msh;
pub use mesh::topology::{Edges, Topology};
pub use mesh::vtu::write as write_vtu;
pub use mesh::{Mesh, MeshData, MeshError, ReadError, Recombined, load};

// Candidate pairs and their quality.
pub use gpu::{Backend, BackendNote, Evaluator, GpuError};
pub use quality::{CandidateTable, ElementQuality, Rule, RuleError, quad_eta, recombined};

// Methods.
pub use search::optimum::{Optimum, solve as optimum};
pub use search::state::State;
pub use search::{Algo, AlgoError, Progress, RunOutcome, Searcher, run};

// Finishing what a policy leaves (all quads, near the optimum).
pub use internals::finish::all_quad::Split;
pub use internals::finish::{FinishConfig, FinishError, Finished, StepFigures, finish};

// Sweeps and their results.
pub use experiment::ExperimentError;
pub use experiment::calibrate::TimeBudget;
pub use experiment::config::{ConfigError, SweepConfig, SweepRequest};
pub use experiment::engine::EngineReport;
pub use experiment::events::Event;
pub use experiment::finished::FinishSettings;
pub use experiment::manifest::Manifest;
pub use experiment::record::RunRecord;
pub use experiment::replay::{ReplayError, Replayed, Replayer};
pub use experiment::store::Loaded;
pub use experiment::store::read as read_records;
pub use experiment::summary::Summary;
pub use experiment::sweep::run as run_sweep;
pub use report::{ReportError, ReportOptions, ReportPaths, write as write_report};

/// Not API: the modules behind the crate root, public only for this package's command line,
/// benchmarks and tests. Anything here may change or disappear in any release.
#[doc(hidden)]
pub mod internals;
