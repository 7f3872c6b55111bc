//! The one integration-test binary: each module tests one area through the library or the CLI.

mod across;
mod all_quad;
mod cli_edge;
mod files;
mod finish;
mod gpu;
mod io;
mod memory;
mod meshes;
mod model;
mod optimum;
mod replay;
mod report;
mod results;
mod runner;
mod runner_budget;
mod runner_extend;
mod runner_time_budget;
mod search;
mod search_oracle;
mod suite;
mod sweep_all_quad;
mod sweep_finish;
mod util;
mod valid_output;
