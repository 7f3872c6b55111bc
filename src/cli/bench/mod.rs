//! `quadrecomb bench`: benchmark figures, one subcommand per area.

mod finish;
mod gpu;
mod io;
mod memory;
mod optimum;
mod rss;
mod search;
mod suite_eval;

use std::process::ExitCode;

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    what: What,
}

#[derive(Debug, clap::Subcommand)]
enum What {
    /// Mesh parsing and topology building.
    Io(io::Args),
    /// Search policies (greedy, selective, uniform).
    Search(search::Args),
    /// Exact optimum.
    Optimum(optimum::Args),
    /// Selective h=3 + --finish against the exact optimum (lattices; many runs on meshes).
    Finish(finish::Args),
    /// Quad-quality evaluation: CPU, lavapipe, GPU.
    Gpu(gpu::Args),
    /// Filling a suite's candidate tables: one device batch, one submission per mesh, the
    /// CPU twin.
    SuiteEval(suite_eval::Args),
    /// This machine's random-access latency by working-set size (what large meshes cost).
    Memory(memory::Args),
    /// Peak resident memory of `recombine` per triangle on generated shapes (grid, strip,
    /// spiral, maze), each run a child process.
    Rss(rss::Args),
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    match args.what {
        What::Io(a) => io::run(a),
        What::Search(a) => search::run(a),
        What::Optimum(a) => optimum::run(a),
        What::Finish(a) => finish::run(a),
        What::Gpu(a) => gpu::run(a),
        What::SuiteEval(a) => suite_eval::run(a),
        What::Memory(a) => memory::run(a),
        What::Rss(a) => rss::run(a),
    }
}

/// A count flag's parser that refuses 0 (a benchmark of no repetition has nothing to report).
fn at_least_one() -> clap::builder::RangedU64ValueParser<usize> {
    clap::builder::RangedU64ValueParser::<usize>::new().range(1..)
}
