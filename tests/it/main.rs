//! The one integration-test binary: each module tests one area through the library or the CLI.

mod gpu;
mod io;
mod memory;
mod meshes;
mod optimum;
mod report;
mod results;
mod runner;
mod search;
mod search_oracle;
mod util;
