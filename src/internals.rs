//! Not API: the modules behind the crate root, public only for this package's command line,
//! benchmarks and tests. Anything here may change or disappear in any release; use what the
//! crate root re-exports.

#[path = "experiment/mod.rs"]
pub mod experiment;
#[path = "finish/mod.rs"]
pub mod finish;
#[path = "gpu/mod.rs"]
pub mod gpu;
#[path = "mesh/mod.rs"]
pub mod mesh;
#[path = "output/mod.rs"]
pub mod output;
#[path = "quality.rs"]
pub mod quality;
#[path = "report/mod.rs"]
pub mod report;
#[path = "search/mod.rs"]
pub mod search;
#[path = "stats/mod.rs"]
pub mod stats;
