//! `quadrecomb merge`: combine the results directories of a sweep's shards.

use std::path::PathBuf;
use std::process::ExitCode;

use quadrecomb::experiment::merge::merge;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Results directories of the shards (`sweep --shard I/N --out DIR`).
    #[arg(required = true, value_name = "DIR")]
    dirs: Vec<PathBuf>,
    /// Directory to write the merged results into (must not hold runs yet).
    #[arg(long)]
    out: PathBuf,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let merged = merge(&args.dirs, &args.out).map_err(super::sweep::bad_input)?;
    eprintln!(
        "merge: {} runs from {} directories into {}",
        merged.records,
        merged.parts,
        args.out.display()
    );
    Ok(ExitCode::SUCCESS)
}
