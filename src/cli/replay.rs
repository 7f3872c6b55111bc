//! `quadrecomb replay DIR [RUN]`: one recorded run of a sweep re-run with the record's mesh,
//! eta and rule (through [`quadrecomb::internals::experiment::replay`], as the report's pictures), checked
//! against its record, and optionally written as `.msh` / `.vtu` (a finished run's finished
//! mesh: with all-quad, the split mesh rebuilt from the record).

use super::UsageError;
use quadrecomb::internals::experiment::replay::{self, EtaCheck, Replayer};
use quadrecomb::internals::report::{Config, Results, Run};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Results directory of a sweep (holding runs.jsonl and manifest.json).
    dir: PathBuf,
    /// Which run of the configuration: its run index (the records' `run` field), or
    /// `typical`, the median run by quality (the run the report pictures).
    #[arg(default_value = "typical")]
    run: String,
    /// Mesh of the configuration (its name in the records; default: the first mesh).
    #[arg(long)]
    mesh: Option<String>,
    /// Algorithm of the configuration (default: the first configuration in the report's
    /// order: greedy-nocrit, greedy, uniform, selective, optimistic, mcts, beam, optimum).
    #[arg(long)]
    algo: Option<String>,
    /// Horizon of the configuration (default: the smallest recorded).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    horizon: Option<u32>,
    /// Node budget of the configuration, for optimistic, mcts and beam (default: the
    /// smallest recorded).
    #[arg(long)]
    budget: Option<u32>,
    /// Time budget of the configuration, for those of `sweep --time-budgets` (seconds, as
    /// recorded in `time_budget_s`; default: a configuration without one first).
    #[arg(long, value_name = "T", value_parser = parse_time_budget)]
    time_budget: Option<quadrecomb::internals::experiment::calibrate::TimeBudget>,
    #[command(flatten)]
    out: super::MeshOutputArgs,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

/// A `--time-budget` value.
fn parse_time_budget(
    s: &str,
) -> Result<quadrecomb::internals::experiment::calibrate::TimeBudget, String> {
    s.parse().map_err(|e| format!("bad time budget: {e}"))
}

/// Which run: an index or the typical one.
enum Which {
    Index(u32),
    Typical,
}

fn parse_run(s: &str) -> Result<Which, UsageError> {
    if s == "typical" {
        return Ok(Which::Typical);
    }
    s.parse().map(Which::Index).map_err(|_| {
        UsageError(format!(
            "bad RUN {s:?}: expected a run index (the records' `run` field, e.g. 0) or `typical`"
        ))
    })
}

/// The first configuration of `results` (in report order) that the filters allow.
fn choose_config<'r>(
    results: &'r Results,
    args: &Args,
) -> Result<(&'r Config, &'r [Run]), UsageError> {
    let found = results.configs().find(|(c, _)| {
        args.mesh.as_ref().is_none_or(|m| *m == c.mesh)
            && args.algo.as_ref().is_none_or(|a| *a == c.algo)
            && args.horizon.is_none_or(|h| Some(h) == c.horizon)
            && args.budget.is_none_or(|b| Some(b) == c.budget)
            && args.time_budget.is_none_or(|t| Some(t) == c.time_budget)
    });
    if let Some((c, runs)) = found {
        return Ok((c, runs));
    }
    let mut asked = Vec::new();
    asked.extend(args.mesh.as_ref().map(|m| format!("mesh {m}")));
    asked.extend(args.algo.as_ref().map(|a| format!("algorithm {a}")));
    asked.extend(args.horizon.map(|h| format!("horizon {h}")));
    asked.extend(args.budget.map(|b| format!("budget {b}")));
    asked.extend(args.time_budget.map(|t| format!("time budget {t}")));
    let held: Vec<String> = (results.configs())
        .map(|(c, _)| format!("{} {}", c.mesh, c.label()))
        .collect();
    Err(UsageError(format!(
        "{}: no configuration with {} (it holds: {})",
        args.dir.display(),
        asked.join(", "),
        held.join("; ")
    )))
}

/// Sorted run indices as spans: "0 to 99", "0 to 2, 5".
fn spans(indices: impl Iterator<Item = u32>) -> String {
    let mut parts: Vec<(u32, u32)> = Vec::new();
    for i in indices {
        match parts.last_mut() {
            Some((_, end)) if end.checked_add(1) == Some(i) => *end = i,
            _ => parts.push((i, i)),
        }
    }
    let words: Vec<String> = (parts.iter())
        .map(|&(a, b)| {
            if a == b {
                a.to_string()
            } else {
                format!("{a} to {b}")
            }
        })
        .collect();
    words.join(", ")
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    super::oom::phase(super::oom::Phase::Replay);
    let which = parse_run(&args.run)?;
    super::check_mesh_output(args.out.output.as_deref())?;
    let results = Results::read(&args.dir)?;
    let (config, runs) = choose_config(&results, &args)?;
    let record = match which {
        Which::Typical => replay::typical_run(runs),
        Which::Index(i) => runs.iter().find(|r| r.run == i),
    };
    let Some(record) = record else {
        // Only an index can be missing: a configuration holds runs, so a typical one.
        let Which::Index(i) = which else {
            anyhow::bail!("{}: no run to replay", args.dir.display());
        };
        let with: Vec<String> = (results.configs())
            .filter(|(_, rs)| rs.iter().any(|r| r.run == i))
            .map(|(c, _)| format!("{} {}", c.mesh, c.label()))
            .collect();
        let elsewhere = match with.len() {
            0 => format!("no configuration here has a run {i}"),
            n => format!(
                "choose one with --mesh, --algo, --horizon or --budget; run {i} is in {}{}",
                with[..n.min(6)].join("; "),
                if n > 6 { "; ..." } else { "" }
            ),
        };
        return Err(UsageError(format!(
            "{}: {} {} has no run {i} (its runs: {}); {elsewhere}",
            args.dir.display(),
            config.mesh,
            config.label(),
            spans(runs.iter().map(|r| r.run))
        ))
        .into());
    };
    let mut replayer = Replayer::new(&results.dir, results.manifest.as_ref());
    let cannot = |e: replay::ReplayError| {
        super::InputError(format!(
            "{}: cannot replay {}: {e}",
            args.dir.display(),
            record.key()
        ))
    };
    if let Some(file) = replayer.mesh_file(record).map_err(cannot)? {
        super::check_not_input(args.out.output.as_deref(), &file.to_string_lossy())?;
    }
    // Nor a file of the results directory (through a link, say): its runs or manifest.
    for name in quadrecomb::internals::experiment::engine::SWEEP_FILES {
        super::check_not_same(
            args.out.output.as_deref(),
            &args.dir.join(name),
            &format!("{} of the results directory {}", name, args.dir.display()),
        )?;
    }
    let out = replayer.replay(record).map_err(cannot)?;
    let write = args.out.output.as_ref().filter(|_| out.reproduced);
    if let Some(path) = write {
        // A finished run writes its finished mesh (the split mesh with all-quad).
        match &out.finished {
            Some(f) => {
                let mesh = f.mesh.as_ref().unwrap_or(out.mesh);
                super::write_mesh_output(path, mesh, &f.recombined, args.out.vtu_ascii)?;
            }
            None => super::write_mesh_output(path, out.mesh, &out.recombined, args.out.vtu_ascii)?,
        }
    }
    let typical = matches!(which, Which::Typical);
    let rule = record.rule();
    if args.json {
        let mut v = serde_json::json!({
            "dir": args.dir,
            "mesh": record.mesh,
            "algo": record.algo,
            "horizon": record.horizon,
            "run": record.run,
            "seed": record.seed,
            "typical": typical,
            "backend": record.backend,
            "eta": out.eta,
            "eta_hash_matches": match out.eta_check {
                EtaCheck::Matches => Some(true),
                EtaCheck::NoMatch => Some(false),
                EtaCheck::Unchecked => None,
            },
            "quads": out.quads,
            "triangles_left": out.triangles_left,
            "quality": out.quality,
            "time_s": out.time_s,
            "recorded": {
                "quads": record.quads,
                "triangles_left": record.triangles_left,
                "quality": record.quality,
                "quality_pct": record.quality_pct,
                "time_s": record.time_s,
            },
            "reproduced": out.reproduced,
            "output": write,
        });
        super::add_element_fields(&mut v, &out.elements, rule);
        if let (Some(f), Some(rf)) = (&out.finish, &record.finish) {
            v["finish"] = serde_json::json!(f);
            v["recorded"]["finish"] = serde_json::json!(rf);
        }
        if let Some(b) = record.budget {
            v["budget"] = serde_json::json!(b);
        }
        outln!("{v}");
    } else {
        outln!("results         {}", args.dir.display());
        let what = if typical {
            format!(", the typical run (median by quality of {})", runs.len())
        } else {
            String::new()
        };
        outln!(
            "run             {} (seed {}){what}",
            record.key(),
            record.seed
        );
        outln!("eta             {}", out.eta_note());
        outln!("quads           {} (recorded {})", out.quads, record.quads);
        outln!(
            "triangles left  {} (recorded {})",
            out.triangles_left,
            record.triangles_left
        );
        outln!(
            "quality         {:.6} (recorded {:.6})",
            out.quality,
            record.quality
        );
        super::print_element_lines(&out.elements, rule);
        outln!(
            "time            {:.4} s (recorded {:.4} s)",
            out.time_s,
            record.time_s
        );
        if let (Some(f), Some(rf)) = (&out.finish, &record.finish) {
            outln!(
                "finished        {} quads, {} triangles left, quality {:.6} (recorded {} quads, \
                 {} left, {:.6}; rings {}, window {}; finish {:.4} s, recorded {:.4} s)",
                f.quads,
                f.triangles_left,
                f.quality,
                rf.quads,
                rf.triangles_left,
                rf.quality,
                f.rings,
                f.window,
                f.time_s,
                rf.time_s
            );
            if let Some(a) = f.all_quad {
                outln!(
                    "all-quad        {} boundary sides split, {} nodes added {} (recorded {})",
                    a.splits,
                    a.splits,
                    super::finish_report::SPLIT_PLACE,
                    rf.splits()
                );
                if a.sheets > 0 {
                    outln!(
                        "sheets          {} sheets, {} nodes added (inside and on sides), {} triangles replaced by {} (recorded {} triangles added in all)",
                        a.sheets,
                        a.sheet_nodes,
                        a.sheet_triangles_replaced,
                        a.sheet_triangles_replaced + a.sheet_triangles_added,
                        rf.triangles_added()
                    );
                }
            }
        }
        let same = if out.reproduced { "yes" } else { "no" };
        outln!("reproduced      {same}");
        if let Some(p) = write {
            outln!("wrote           {}", p.display());
        }
    }
    if !out.reproduced {
        // Name what differs: the search's figures, or (they agree) the finish's.
        let finish = match (&out.finish, &record.finish) {
            (Some(f), Some(rf)) if out.quads == record.quads && out.quality == record.quality => {
                format!(
                    "; the search agrees, the finish gives {} quads, {} triangles left and \
                     quality {:.6} where the record has {}, {} and {:.6}",
                    f.quads, f.triangles_left, f.quality, rf.quads, rf.triangles_left, rf.quality
                )
            }
            _ => String::new(),
        };
        anyhow::bail!(
            "run {} not reproduced: the replay gives {} quads and quality {:.6} where the \
             record has {} and {:.6}{finish} (eta from {}){}",
            record.key(),
            out.quads,
            out.quality,
            record.quads,
            record.quality,
            out.eta_note(),
            if args.out.output.is_some() {
                "; nothing written"
            } else {
                ""
            }
        );
    }
    Ok(ExitCode::SUCCESS)
}
