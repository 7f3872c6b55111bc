//! Subcommands, one module each: `Args` (clap derive) and `run(args)`.

mod bench;
mod generate;
mod info;
mod merge;
mod optimum;
mod recombine;
mod report;
mod sweep;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Exit code for bad input (unreadable or invalid mesh, bad arguments).
pub const EXIT_BAD_INPUT: u8 = 2;

#[derive(Debug, Parser)]
#[command(name = "quadrecomb", version, about, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Print a mesh's size, topology and candidate quad qualities.
    Info(info::Args),
    /// Generate a procedural mesh (jittered grid, icosphere) of any size.
    Generate(generate::Args),
    /// Recombine a mesh's triangles into quads with one policy.
    Recombine(recombine::Args),
    /// Compute the exact optimum (maximum-weight matching, "Blossom-quad").
    Optimum(optimum::Args),
    /// Run a seeded horizon sweep (the paper's experiment) into a results directory.
    Sweep(sweep::Args),
    /// Merge sharded sweep results into one directory.
    Merge(merge::Args),
    /// Write tables, figures and statistical comparisons for a results directory.
    Report(report::Args),
    /// Print benchmark figures.
    Bench(bench::Args),
}

/// Parses the command line and runs the subcommand.
pub fn run() -> anyhow::Result<ExitCode> {
    let cli = Cli::parse();
    match cli.command {
        Command::Info(args) => info::run(args),
        Command::Generate(args) => generate::run(args),
        Command::Recombine(args) => recombine::run(args),
        Command::Optimum(args) => optimum::run(args),
        Command::Sweep(args) => sweep::run(args),
        Command::Merge(args) => merge::run(args),
        Command::Report(args) => report::run(args),
        Command::Bench(args) => bench::run(args),
    }
}

/// Exit code for an error: [`EXIT_BAD_INPUT`] when the input was at fault, 1 otherwise.
pub fn exit_code(err: &anyhow::Error) -> u8 {
    let bad_input = err.chain().any(|e| {
        e.is::<quadrecomb::mesh::ReadError>()
            || e.is::<quadrecomb::mesh::MeshError>()
            || e.is::<BadInput>()
    });
    if bad_input { EXIT_BAD_INPUT } else { 1 }
}

/// An error in the user's arguments or input files that is not a mesh error.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct BadInput(pub String);

/// The error and its causes on one line, `a: b: c`, skipping a cause whose message its parent
/// already ends with (typed errors often print their source in their own message too).
pub fn describe(err: &anyhow::Error) -> String {
    let mut out = String::new();
    for cause in err.chain() {
        let msg = cause.to_string();
        if out.ends_with(&msg) {
            continue;
        }
        if !out.is_empty() {
            out.push_str(": ");
        }
        out.push_str(&msg);
    }
    out
}

/// Checks before any work that an output path names a `.msh` or `.vtu` file.
pub fn check_mesh_output(path: Option<&std::path::Path>) -> Result<(), BadInput> {
    match path {
        Some(p) if !matches!(p.extension().and_then(|e| e.to_str()), Some("msh" | "vtu")) => {
            Err(BadInput(format!(
                "output {}: expected a .msh or .vtu file name",
                p.display()
            )))
        }
        _ => Ok(()),
    }
}

/// Writes a recombined mesh as VTU (`.vtu`) or MSH 4.1 ASCII (anything else).
pub fn write_mesh_output(
    path: &std::path::Path,
    mesh: &quadrecomb::mesh::Mesh,
    rec: &quadrecomb::mesh::Recombined,
) -> Result<(), quadrecomb::mesh::ReadError> {
    if path.extension().is_some_and(|e| e == "vtu") {
        quadrecomb::mesh::vtu::write(path, mesh, rec)
    } else {
        quadrecomb::mesh::msh::write(path, mesh, rec)
    }
}
