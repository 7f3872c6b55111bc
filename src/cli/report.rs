//! `quadrecomb report DIR [--compare DIR2] [--zoom x0,y0,x1,y1]`.

use super::UsageError;
use quadrecomb::internals::experiment::lock::DirLock;
use quadrecomb::internals::report::{self, ReportOptions};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Results directory of a sweep (holding runs.jsonl and manifest.json).
    dir: PathBuf,
    /// Another results directory to compare with, configuration by configuration.
    #[arg(long, value_name = "DIR2")]
    compare: Option<PathBuf>,
    /// Also draw the mesh pictures zoomed into this window (mesh x-y for planar meshes,
    /// view-plane coordinates for surfaces, as the pictures' axes show; negative values need
    /// no `=`: `--zoom -1,-1,0,0`).
    #[arg(long, value_name = "x0,y0,x1,y1", allow_hyphen_values = true)]
    zoom: Option<String>,
    /// Picture the typical run of this configuration, e.g. `selective:5` or `greedy`
    /// (repeatable; default: the best horizon of each look-ahead algorithm).
    #[arg(long = "picture", value_name = "ALGO[:H]")]
    pictures: Vec<String>,
    /// Leave out the mesh pictures (they re-run each typical run); not with `--picture` or
    /// `--zoom`, which ask for pictures.
    #[arg(long, conflicts_with_all = ["pictures", "zoom"])]
    no_pictures: bool,
    /// Across meshes (two or more): the method every other is compared with, as the report
    /// names it, e.g. "selective h=3" (default: selective h=1, else the first method run on
    /// every mesh).
    #[arg(long, value_name = "METHOD")]
    baseline: Option<String>,
    /// Seed of the bootstrap confidence intervals.
    #[arg(long, default_value_t = ReportOptions::default().seed)]
    seed: u64,
    /// Print one JSON object on stdout (the files written, the time) instead of their paths.
    #[arg(long)]
    json: bool,
}

/// The files a report wrote, as the `report` member of a `--json` object (`sweep`,
/// `merge`) or the whole of `report --json`'s.
pub fn paths_json(paths: &report::ReportPaths) -> serde_json::Value {
    let mut v = serde_json::json!({
        "markdown": paths.markdown,
        "html": paths.html,
        "figures": paths.figures,
    });
    if let Some(csv) = &paths.across_csv {
        v["across_meshes"] = serde_json::json!(csv);
    }
    v
}

/// Parses "x0,y0,x1,y1" into a window with x0 < x1 and y0 < y1.
fn parse_zoom(s: &str) -> Result<[f64; 4], UsageError> {
    let bad = || {
        UsageError(format!(
            "bad --zoom {s:?}: expected x0,y0,x1,y1 with x0 < x1 and y0 < y1, e.g. 0.6,0.6,1,1"
        ))
    };
    let v: Vec<f64> = s
        .split(',')
        .map(|p| p.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| bad())?;
    match v[..] {
        [x0, y0, x1, y1] if v.iter().all(|c| c.is_finite()) && x0 < x1 && y0 < y1 => {
            Ok([x0, y0, x1, y1])
        }
        _ => Err(bad()),
    }
}

/// Parses "algo" or "algo:h".
fn parse_picture(s: &str) -> Result<(String, Option<u32>), UsageError> {
    match s.split_once(':') {
        None => Ok((s.to_string(), None)),
        Some((a, h)) => h
            .parse::<u32>()
            .map(|h| (a.to_string(), Some(h)))
            .map_err(|_| {
                UsageError(format!(
                    "bad --picture {s:?}: expected ALGO or ALGO:H, e.g. selective:5"
                ))
            }),
    }
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    super::oom::phase(super::oom::Phase::Report);
    let start = std::time::Instant::now();
    let zoom = args.zoom.as_deref().map(parse_zoom).transpose()?;
    let picture_configs = args
        .pictures
        .iter()
        .map(|s| parse_picture(s))
        .collect::<Result<Vec<_>, _>>()?;
    if args.baseline.is_some()
        && let Ok(r) = quadrecomb::internals::report::Results::read(&args.dir)
        && r.meshes.len() < 2
    {
        noteln!(
            "warning: report: --baseline sets the method the \"Across meshes\" section compares \
             with, and a directory of one mesh has no such section: it changes nothing"
        );
    }
    let opts = ReportOptions {
        compare: args.compare,
        zoom,
        pictures: !args.no_pictures,
        picture_configs,
        seed: args.seed,
        baseline: args.baseline,
    };
    // The directory's writers take turns: a report written while a sweep or merge is
    // writing there would put a summary of fewer runs over theirs. (A missing directory or
    // a file is left to `report::write`, which names it.)
    let _lock = args
        .dir
        .is_dir()
        .then(|| DirLock::acquire(&args.dir))
        .transpose()?;
    // Its exit code follows the error's kind (`errors::exit_code`).
    let paths = report::write(&args.dir, &opts)?;
    for w in &paths.warnings {
        noteln!("warning: report: {}: {w}", args.dir.display());
    }
    if args.json {
        let mut v = paths_json(&paths);
        v["warnings"] = serde_json::json!(paths.warnings);
        v["dir"] = serde_json::json!(args.dir);
        v["time_s"] = serde_json::json!(start.elapsed().as_secs_f64());
        outln!("{v}");
        return Ok(ExitCode::SUCCESS);
    }
    outln!("{}", paths.markdown.display());
    outln!("{}", paths.html.display());
    for f in &paths.figures {
        outln!("{}", f.display());
    }
    if let Some(csv) = &paths.across_csv {
        outln!("{}", csv.display());
    }
    Ok(ExitCode::SUCCESS)
}
