//! `quadrecomb merge`: combine the results directories of a sweep's shards.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use quadrecomb::internals::experiment::merge::merge;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Results directories of the shards (`sweep --shard I/N --out DIR`).
    #[arg(required = true, value_name = "DIR")]
    dirs: Vec<PathBuf>,
    /// Directory to write the merged results into (must not hold runs yet).
    #[arg(long)]
    out: PathBuf,
    /// Do not write the report of the merged results.
    #[arg(long)]
    no_report: bool,
    /// Print one JSON object on stdout (runs, parts, files written, time); notes stay on
    /// stderr.
    #[arg(long)]
    json: bool,
    /// Quiet: only errors and warnings on stderr (as `sweep -q`).
    #[arg(long, short)]
    quiet: bool,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    super::oom::phase(super::oom::Phase::Merge);
    let start = std::time::Instant::now();
    super::errors::check_results_dir(&args.out)?;
    let merged = merge(&args.dirs, &args.out)?;
    if !args.quiet {
        noteln!(
            "merge: {} runs from {} directories into {}",
            merged.records,
            merged.parts,
            args.out.display()
        );
    }
    let mut report = serde_json::Value::Null;
    if !args.no_report {
        let out = &args.out;
        let _lock = quadrecomb::internals::experiment::lock::DirLock::acquire(out)?;
        let paths = quadrecomb::internals::report::write(
            out,
            &quadrecomb::internals::report::ReportOptions::default(),
        )
        .with_context(|| {
            format!(
                "the merged results are complete in {}, but writing their report failed \
                     (retry with `quadrecomb report {}`)",
                out.display(),
                out.display()
            )
        })?;
        if !args.quiet {
            noteln!("merge: report in {}", paths.markdown.display());
        }
        report = super::report::paths_json(&paths);
    }
    if args.json {
        let v = serde_json::json!({
            "out": args.out,
            "parts": args.dirs,
            "runs": merged.records,
            "files": super::sweep::result_files(&args.out),
            "report": report,
            "time_s": start.elapsed().as_secs_f64(),
        });
        outln!("{v}");
    }
    Ok(ExitCode::SUCCESS)
}
