//! `quadrecomb sweep`: the paper's horizon sweep (or any other) into a results directory.

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::Context;
use quadrecomb::internals::experiment::calibrate::TimeBudget;
use quadrecomb::internals::experiment::config::{
    ConfigError, DEFAULT_SEED, MAX_HORIZONS, MAX_RUNS, SizeError, SweepConfig, SweepRequest,
};
use quadrecomb::internals::experiment::events::Event;
use quadrecomb::internals::experiment::manifest::Shard;
use quadrecomb::internals::experiment::record::RunKey;
use quadrecomb::internals::experiment::sweep;
use quadrecomb::internals::gpu::Backend;
use quadrecomb::internals::search::{Params, Progress};

use super::UsageError;
use super::errors::EXIT_INTERRUPTED;
use super::sweep_progress::{ProgressMode, SweepDisplay};

/// `--backend`: who computes the quad qualities.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum BackendArg {
    /// A real GPU if present, else lavapipe (software Vulkan), else the CPU twin.
    Auto,
    /// A Vulkan adapter (the best one, lavapipe included); an error if there is none.
    Gpu,
    /// The CPU twin of the kernel (f32, all cores).
    Cpu,
}

impl From<BackendArg> for Backend {
    fn from(b: BackendArg) -> Backend {
        match b {
            BackendArg::Auto => Backend::Auto,
            BackendArg::Gpu => Backend::Gpu,
            BackendArg::Cpu => Backend::Cpu,
        }
    }
}

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Meshes (built-in names, suite:NAME, or files); default: borouchaki.
    #[arg(long = "mesh", value_name = "MESH", num_args = 1..)]
    meshes: Vec<String>,
    /// Every mesh of a benchmark suite (default, small, full: `quadrecomb suite list`), with
    /// the suite's defaults: --algo greedy selective optimum, --horizons 1,3,5, --runs 32
    /// (each can still be given), into results/suite (results/suite-<name> for the others).
    #[arg(long, value_name = "SUITE", conflicts_with = "meshes")]
    suite: Option<String>,
    /// Algorithms (see `recombine --help`): greedy-nocrit, greedy, uniform, selective,
    /// optimum, optimistic, mcts, beam; default: selective greedy greedy-nocrit optimum.
    #[arg(long = "algo", value_name = "ALGO", num_args = 1.., value_parser = algo_names())]
    algos: Vec<String>,
    /// Horizons of selective, uniform and the budgeted methods: a range A..B (inclusive), a
    /// list 1,3,5, or one value [default: 1..10; with --suite, 1,3,5].
    #[arg(long, value_name = "H", value_parser = parse_horizons)]
    horizons: Option<Horizons>,
    /// Node budgets per decision of optimistic, mcts and beam (one configuration each, per
    /// horizon): a list 16,64,256 or several values [default: 64; none with --time-budgets].
    #[arg(long, value_name = "B", num_args = 1.., value_delimiter = ',')]
    budgets: Vec<u32>,
    /// Wall-time budgets per run, in seconds (0.2, 2s) or milliseconds (50ms): each is
    /// calibrated once, by pilot runs, into the knob of every method with one (the node
    /// budget of optimistic, mcts and beam at each horizon; the horizon of selective and
    /// uniform), and recorded; the runs then replay from their seeds (docs/search.md).
    #[arg(long, value_name = "T", num_args = 1.., value_delimiter = ',', value_parser = parse_time_budget, allow_negative_numbers = true)]
    time_budgets: Vec<TimeBudget>,
    /// Runs per (mesh, randomized method, horizon, budget): selective, optimistic, mcts,
    /// beam [default: 128; with --suite, 32].
    #[arg(long)]
    runs: Option<u32>,
    /// Runs of each deterministic configuration: greedy and greedy-nocrit per mesh (ties are
    /// broken by index), uniform per horizon (it draws nothing at random). More than 1 only
    /// repeats the same run, for its timings.
    #[arg(long, default_value_t = 1)]
    baseline_runs: u32,
    /// Worker threads (default: every core).
    #[arg(long)]
    threads: Option<usize>,
    /// Base seed; every run's seed is derived from it and the run's identity.
    #[arg(long, default_value_t = DEFAULT_SEED)]
    seed: u64,
    /// Who computes the quad qualities. The default, the CPU twin of the kernel, gives the same
    /// bits on every machine, so a sweep's records are the same everywhere (the committed
    /// results/ are reproduced exactly); `gpu` or `auto` evaluate on a device, whose last-bit
    /// differences can break ties differently in individual runs.
    #[arg(long, value_enum, default_value_t = BackendArg::Cpu)]
    backend: BackendArg,
    #[command(flatten)]
    rule: super::RuleArgs,
    /// Results directory (default: results/<mesh> for one mesh, results/sweep otherwise;
    /// with --shard I/N, results/<mesh>-shard-I-of-N).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Continue the sweep in --out, skipping the runs it already recorded.
    #[arg(long)]
    resume: bool,
    /// Continue the sweep in --out with more algorithms, horizons or runs (same meshes, base
    /// seed and rule): the recorded runs are kept, the new ones added (implies --resume).
    #[arg(long, conflicts_with = "shard")]
    extend: bool,
    /// Replace the results of an earlier sweep in --out (runs, summary, report, figures).
    #[arg(long, conflicts_with_all = ["resume", "extend"])]
    overwrite: bool,
    /// Run only the I-th of N disjoint slices of the run list (1 <= I <= N).
    #[arg(long, value_name = "I/N")]
    shard: Option<Shard>,
    /// Do not write the report at the end.
    #[arg(long)]
    no_report: bool,
    /// Progress as plain lines even on a terminal.
    #[arg(long, conflicts_with = "quiet")]
    plain: bool,
    /// Quiet: only errors and warnings on stderr (no progress, no notices, no summary).
    #[arg(long, short)]
    quiet: bool,
    /// Print one JSON object on stdout when done (runs, files written, report, time);
    /// progress and notes stay on stderr.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    finish: SweepFinishArgs,
}

/// Finishing each search run after its search (docs/finish.md).
#[derive(Debug, clap::Args)]
pub struct SweepFinishArgs {
    /// Finish each search run after its search: pair the leftovers that can be paired, then
    /// improve by local re-solves. Records keep the search's figures and add a `finish`
    /// object; the report adds "+ finish" rows. Not for the optimum (nothing to finish).
    #[arg(long)]
    finish: bool,
    /// With --finish: rings of quads around the leftovers in the first elimination round (k,
    /// doubled until every leftover is settled).
    #[arg(long, requires = "finish", default_value_t = quadrecomb::internals::finish::DEFAULT_RINGS, value_parser = clap::value_parser!(u32).range(1..))]
    rings: u32,
    /// With --finish: rings of quads of each improvement window (r); 0 skips improvement.
    #[arg(long, requires = "finish", default_value_t = quadrecomb::internals::finish::DEFAULT_WINDOW)]
    window: u32,
    /// With --finish: also make odd components even by splitting a boundary side (a new node
    /// at its midpoint, on the chord), or by sheets where no split fixes a component, so that
    /// no triangle is left. Records then count the split mesh's triangles and add
    /// `finish.all_quad` (splits, nodes added, sheets when any); replay
    /// rebuilds the split mesh from the record.
    #[arg(long, requires = "finish")]
    all_quad: bool,
}

/// The sweep's own files that exist in `dir` (runs, manifest, summaries), by role, for a
/// `--json` object.
pub fn result_files(dir: &std::path::Path) -> serde_json::Value {
    use quadrecomb::internals::experiment::{manifest, store, summary};
    let mut files = serde_json::Map::new();
    for (role, name) in [
        ("runs", store::RUNS_FILE),
        ("manifest", manifest::MANIFEST_FILE),
        ("summary_json", summary::SUMMARY_JSON),
        ("summary_csv", summary::SUMMARY_CSV),
    ] {
        let path = dir.join(name);
        if path.is_file() {
            files.insert(role.into(), serde_json::json!(path));
        }
    }
    files.into()
}

#[derive(Debug, Clone)]
struct Horizons(Vec<u32>);

fn parse_horizons(s: &str) -> Result<Horizons, String> {
    let num = |t: &str| {
        t.trim()
            .parse::<u32>()
            .map_err(|_| format!("bad horizon {t:?} in {s:?}: expected A..B, a,b,c or a number"))
    };
    let list = if let Some((a, b)) = s.split_once("..") {
        let (a, b) = (num(a)?, num(b.trim_start_matches('='))?);
        if a > b {
            return Err(format!("empty horizon range {s:?}"));
        }
        // Checked before the range is collected.
        let n = u64::from(b - a) + 1;
        if n > MAX_HORIZONS as u64 {
            return Err(format!(
                "horizon range {s:?} holds {n} horizons; a sweep takes at most {MAX_HORIZONS}"
            ));
        }
        (a..=b).collect()
    } else {
        let n = s.split(',').count();
        if n > MAX_HORIZONS {
            return Err(format!(
                "{n} horizons given; a sweep takes at most {MAX_HORIZONS}"
            ));
        }
        s.split(',')
            .map(num)
            .collect::<Result<Vec<u32>, String>>()?
    };
    if list.contains(&0) {
        return Err("horizons must be at least 1".into());
    }
    Ok(Horizons(list))
}

/// Warns of `--horizons` or `--budgets` given where no method of `--algo` reads them (the
/// sweep runs without them, as asked, but the user probably meant another method).
fn ignored_flags(algos: &[String], horizons: bool, budgets: bool) {
    use quadrecomb::internals::experiment::plan::{has_budget, has_horizon};
    use quadrecomb::internals::search::methods;
    for (given, flag, reads) in [
        (horizons, "--horizons", has_horizon as fn(&str) -> bool),
        (budgets, "--budgets", has_budget),
    ] {
        if given && !algos.iter().any(|a| reads(a)) {
            let readers: Vec<&str> = methods::names().filter(|m| reads(m)).collect();
            noteln!(
                "warning: sweep: {flag} is read by {} only, and --algo has none of them ({}): \
                 it changes nothing",
                readers.join(", "),
                algos.join(" ")
            );
        }
    }
}

/// A `--time-budgets` value, with the flag in its error.
fn parse_time_budget(s: &str) -> Result<TimeBudget, String> {
    s.parse::<TimeBudget>()
        .map_err(|e| format!("bad time budget: {e}"))
}

/// Warns, once per configuration, of a run that will be long: the estimate and the wording
/// of `recombine`'s ([`super::progress_bar::cost_warning`]), with the run's key, and what a
/// Ctrl-C then does. Shown under `-q` too (a warning).
fn long_run_watch() -> sweep::RunWatch {
    let warned = std::sync::Mutex::new(std::collections::HashSet::new());
    std::sync::Arc::new(move |key: &RunKey, p: &Progress| {
        let params = Params {
            horizon: key.horizon,
            budget: key.budget,
        };
        let hint = super::progress_bar::faster_hint(params, true);
        let Some(w) = super::progress_bar::cost_warning(p, key.horizon, &hint) else {
            return true;
        };
        let config = RunKey {
            run: 0,
            ..key.clone()
        };
        let first = (warned.lock().unwrap_or_else(|e| e.into_inner())).insert(config);
        if first {
            let w = w.strip_prefix("warning: ").unwrap_or(&w);
            noteln!(
                "\nwarning: sweep: {key}: {w} (said once per configuration; after a Ctrl-C the \
                 runs in flight get {GRACE_S} s to finish, then are left to the next --resume)"
            );
        }
        false
    })
}

/// Set by Ctrl-C: the sweep stops handing out runs.
static CANCEL: AtomicBool = AtomicBool::new(false);

/// Seconds the runs in flight get after the first Ctrl-C before the sweep quits without
/// them: a run is not stopped halfway, and one of a large tree can last hours.
const GRACE_S: u64 = 10;

/// Where a sweep stands, for one that quits before its runs in flight finish
/// ([`quit_now`]): set before the runs and by the sweep's events.
#[derive(Debug)]
struct Standing {
    json: bool,
    out: Option<PathBuf>,
    shard: Option<String>,
    /// The flag that finishes the sweep: `--resume` or `--extend`.
    flag: &'static str,
    start: Option<std::time::Instant>,
    /// Runs in this directory's share of the run list, once the runs start.
    planned: Option<usize>,
    already: usize,
    done: usize,
    /// No run is in flight any more (the sweep ends on its own).
    finished: bool,
}

impl Standing {
    const EMPTY: Standing = Standing {
        json: false,
        out: None,
        shard: None,
        flag: "--resume",
        start: None,
        planned: None,
        already: 0,
        done: 0,
        finished: false,
    };

    fn event(&mut self, e: &Event<'_>) {
        match *e {
            Event::Resuming {
                recorded, planned, ..
            } => (self.already, self.planned) = (recorded, Some(planned)),
            Event::Started { runs } => {
                self.planned.get_or_insert(self.already + runs as usize);
            }
            Event::RunDone => self.done += 1,
            Event::Finished => self.finished = true,
            _ => {}
        }
    }
}

fn standing() -> std::sync::MutexGuard<'static, Standing> {
    static STANDING: std::sync::Mutex<Standing> = std::sync::Mutex::new(Standing::EMPTY);
    STANDING.lock().unwrap_or_else(|e| e.into_inner())
}

/// Exits at once (130), keeping every finished run (each record is appended whole as its run
/// ends; a line torn by the exit is redone by `--resume`): says what is recorded and, with
/// `--json`, prints the sweep's object as a cancelled sweep does (`backend` and `report`
/// null: the sweep did not get to them; the summary is written by the next `--resume`).
fn quit_now(why: &str) -> ! {
    let s = standing();
    let out = s.out.clone().unwrap_or_default();
    if s.json {
        outln!(
            "{}",
            serde_json::json!({
                "out": out,
                "runs": s.planned,
                "new": s.done,
                "already_recorded": s.planned.map(|_| s.already),
                "cancelled": true,
                "shard": s.shard,
                "backend": null,
                "files": result_files(&out),
                "report": null,
                "time_s": s.start.map(|t| t.elapsed().as_secs_f64()),
                "phases": null,
            })
        );
    }
    let shard = s
        .shard
        .as_ref()
        .map(|s| format!(" (shard {s})"))
        .unwrap_or_default();
    match s.planned {
        Some(planned) => noteln!(
            "\nsweep: {why}: quitting now: {} of {planned} runs recorded in {}{shard}, the runs \
             in flight not; run the same command with {} to finish",
            s.already + s.done,
            out.display(),
            s.flag
        ),
        None => noteln!(
            "\nsweep: {why}: quitting now, before any run (no run recorded); run the same \
             command again to start"
        ),
    }
    std::process::exit(i32::from(EXIT_INTERRUPTED));
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    super::oom::phase(super::oom::Phase::Sweep);
    let start = std::time::Instant::now();
    let mut paper = SweepRequest::default();
    let suite_defaults = args.suite.as_deref().map(suite_request).transpose()?;
    if let Some(s) = &suite_defaults {
        paper = SweepRequest {
            meshes: s.meshes.clone(),
            algos: s.algos.clone(),
            horizons: s.horizons.clone(),
            runs: s.runs,
            ..paper
        };
    }
    let meshes = if args.meshes.is_empty() {
        paper.meshes.clone()
    } else {
        args.meshes
    };
    let out = args.out.unwrap_or_else(|| {
        let base = match (&args.suite, meshes.as_slice()) {
            (Some(s), _) if s == "default" => "suite".to_string(),
            (Some(s), _) => format!("suite-{s}"),
            (None, [one]) => sweep::mesh_name(one),
            _ => "sweep".to_string(),
        };
        // A mesh whose stem is dots (a file `...msh`: "..") would name results/.., which is
        // the working directory: such a mesh's sweep goes where several meshes' go.
        let base = if base.chars().all(|c| c == '.') {
            "sweep".to_string()
        } else {
            base
        };
        // Shards get a directory each, so that they never share a run log.
        let name = match args.shard {
            Some(s) => format!("{base}-shard-{}-of-{}", s.index, s.count),
            None => base,
        };
        PathBuf::from("results").join(name)
    });
    super::errors::check_results_dir(&out)?;
    // Refused even where no method reads it (greedy alone), as `--horizons 0` is: it asks
    // for no runs, which the sweep would not do.
    if args.runs == Some(0) {
        return Err(config_error(ConfigError::ZeroRuns).into());
    }
    let (horizons_given, budgets_given) = (args.horizons.is_some(), !args.budgets.is_empty());
    let config = SweepConfig::new(SweepRequest {
        meshes,
        algos: if args.algos.is_empty() {
            paper.algos.clone()
        } else {
            args.algos
        },
        horizons: args.horizons.map_or(paper.horizons.clone(), |h| h.0),
        budgets: if args.budgets.is_empty() && args.time_budgets.is_empty() {
            paper.budgets.clone()
        } else {
            args.budgets
        },
        time_budgets: args.time_budgets,
        runs: args.runs.unwrap_or(paper.runs),
        baseline_runs: args.baseline_runs,
        seed: args.seed,
        threads: args.threads.unwrap_or(paper.threads),
        backend: args.backend.into(),
        rule: args.rule.rule()?,
        out: out.clone(),
        resume: args.resume,
        extend: args.extend,
        overwrite: args.overwrite,
        shard: args.shard,
        finish: args.finish.finish.then_some(
            quadrecomb::internals::experiment::finished::FinishSettings {
                rings: args.finish.rings,
                window: args.finish.window,
                all_quad: args.finish.all_quad,
            },
        ),
    })
    .map_err(config_error)?;
    ignored_flags(config.algos(), horizons_given, budgets_given);
    let fixed: Vec<&str> = (config.algos().iter())
        .map(String::as_str)
        .filter(|a| quadrecomb::internals::experiment::plan::runs_as_baseline(a))
        .collect();
    if !fixed.is_empty() && !args.quiet {
        let n = config.baseline_runs();
        noteln!(
            "sweep: {} deterministic (the same run whatever the seed): {n} run{} each{}, not \
             --runs; --baseline-runs repeats them for timings",
            fixed.join(", "),
            if n == 1 { "" } else { "s" },
            if fixed.contains(&"uniform") {
                " (uniform: per horizon)"
            } else {
                ""
            }
        );
    }
    let mut display = SweepDisplay::new(if args.quiet {
        ProgressMode::Quiet
    } else if args.plain {
        ProgressMode::Plain
    } else {
        ProgressMode::Auto
    });

    // Ctrl-C, SIGTERM (a batch scheduler's stop, `kill`) and SIGHUP (the terminal closed)
    // stop alike: ctrlc's `termination` feature.
    *standing() = Standing {
        json: args.json,
        out: Some(out.clone()),
        shard: args.shard.map(|s| s.to_string()),
        flag: if args.extend { "--extend" } else { "--resume" },
        start: Some(start),
        ..Standing::EMPTY
    };
    ctrlc::set_handler(|| {
        if CANCEL.swap(true, Ordering::SeqCst) {
            quit_now("interrupted again");
        }
        noteln!(
            "\nsweep: interrupted: finishing the runs in flight, for up to {GRACE_S} s (Ctrl-C \
             or SIGTERM again to quit now; runs not finished are redone by the next --resume)"
        );
        std::thread::spawn(|| {
            std::thread::sleep(std::time::Duration::from_secs(GRACE_S));
            if !standing().finished {
                quit_now(&format!(
                    "the runs in flight did not finish within {GRACE_S} s"
                ));
            }
        });
    })
    .context("installing the Ctrl-C / SIGTERM handler")?;

    // The searches' wall time: from the engine's start of the runs to their end.
    let (mut runs_start, mut runs_end) = (None, None);
    let done = sweep::run_timed(
        &config,
        &CANCEL,
        &mut |e| {
            match e {
                Event::Started { .. } => runs_start = Some(std::time::Instant::now()),
                Event::Finished => runs_end = Some(std::time::Instant::now()),
                _ => {}
            }
            standing().event(&e);
            display.event(e)
        },
        Some(long_run_watch()),
    );
    let (manifest, report, phases) = match done {
        // Stopped before any run (calibrating): an interruption like one between runs, with
        // nothing recorded and no run list read yet.
        Err(quadrecomb::internals::experiment::ExperimentError::Interrupted(why)) => {
            if args.json {
                outln!(
                    "{}",
                    serde_json::json!({
                        "out": out,
                        "runs": null,
                        "new": 0,
                        "already_recorded": null,
                        "cancelled": true,
                        "shard": args.shard.map(|s| s.to_string()),
                        "backend": null,
                        "files": result_files(&out),
                        "report": null,
                        "time_s": start.elapsed().as_secs_f64(),
                        "phases": null,
                    })
                );
            }
            noteln!(
                "sweep: {why}; run the same command again to calibrate and run (with {} where \
                 the directory already held runs)",
                if args.extend { "--extend" } else { "--resume" }
            );
            return Ok(ExitCode::from(EXIT_INTERRUPTED));
        }
        r => r?,
    };
    let searches_s = match (runs_start, runs_end) {
        (Some(a), Some(b)) => b.duration_since(a).as_secs_f64(),
        _ => 0.0,
    };
    let shard = manifest
        .shard
        .map(|s| format!(" (shard {s})"))
        .unwrap_or_default();
    let json = |report_paths: serde_json::Value, phases: serde_json::Value| {
        let v = serde_json::json!({
            "out": out,
            "runs": report.planned,
            "new": report.done_now,
            "already_recorded": report.already,
            "cancelled": report.cancelled,
            "shard": manifest.shard.map(|s| s.to_string()),
            "backend": manifest.backend,
            "files": result_files(&out),
            "report": report_paths,
            "time_s": start.elapsed().as_secs_f64(),
            "phases": phases,
        });
        outln!("{v}");
    };
    if report.cancelled {
        if args.json {
            json(serde_json::Value::Null, serde_json::Value::Null);
        }
        noteln!(
            "sweep: interrupted: {} of {} runs recorded in {}{shard}; run the same command with {} to finish",
            report.already + report.done_now,
            report.planned,
            out.display(),
            if args.extend { "--extend" } else { "--resume" }
        );
        return Ok(ExitCode::from(EXIT_INTERRUPTED));
    }
    if !args.quiet {
        noteln!(
            "sweep: {} runs done ({} new, {} already recorded) into {}{shard}; backend {}",
            report.planned,
            report.done_now,
            report.already,
            out.display(),
            manifest.backend
        );
    }
    let mut report_paths = serde_json::Value::Null;
    let report_clock = std::time::Instant::now();
    if !args.no_report && manifest.shard.is_none() {
        let paths = quadrecomb::internals::report::write(
            &out,
            &quadrecomb::internals::report::ReportOptions::default(),
        )
        .with_context(|| {
            format!(
                "the sweep's results are complete in {}, but writing its report failed \
                     (retry with `quadrecomb report {}`)",
                out.display(),
                out.display()
            )
        })?;
        if !args.quiet {
            noteln!("sweep: report in {}", paths.markdown.display());
        }
        report_paths = super::report::paths_json(&paths);
    }
    let timing = Timing {
        phases,
        searches_s,
        report_s: report_clock.elapsed().as_secs_f64(),
        total_s: start.elapsed().as_secs_f64(),
    };
    if !args.quiet {
        noteln!("sweep: {}", timing.line());
    }
    if args.json {
        json(report_paths, timing.json());
    }
    Ok(ExitCode::SUCCESS)
}

/// Where a sweep's wall time went: the runner's phases against its searches.
struct Timing {
    phases: sweep::PhaseTimes,
    /// From the first run handed out to the last one recorded.
    searches_s: f64,
    /// Writing the report (0 with --no-report).
    report_s: f64,
    /// The whole command.
    total_s: f64,
}

impl Timing {
    /// Everything but the searches: loading, eta, optimum, the engine's own work (manifest,
    /// checks, summary), the report and the command's start.
    fn overhead_s(&self) -> f64 {
        (self.total_s - self.searches_s).max(0.0)
    }

    fn line(&self) -> String {
        let p = &self.phases;
        format!(
            "time {:.2} s: searches {:.2} s; runner {:.2} s = {:.1} % (load {:.2} s, eta {:.2} \
             s, optimum {:.2} s, engine besides the runs {:.2} s, report {:.2} s)",
            self.total_s,
            self.searches_s,
            self.overhead_s(),
            100.0 * self.overhead_s() / self.total_s.max(f64::MIN_POSITIVE),
            p.load_s,
            p.eta_s,
            p.optimum_s,
            (p.engine_s - self.searches_s).max(0.0),
            self.report_s
        )
    }

    fn json(&self) -> serde_json::Value {
        serde_json::json!({
            "load_s": self.phases.load_s,
            "eta_s": self.phases.eta_s,
            "optimum_s": self.phases.optimum_s,
            "engine_s": self.phases.engine_s,
            "searches_s": self.searches_s,
            "report_s": self.report_s,
            "overhead_s": self.overhead_s(),
            "overhead_pct": 100.0 * self.overhead_s() / self.total_s.max(f64::MIN_POSITIVE),
        })
    }
}

/// The meshes and defaults of `sweep --suite NAME`: every member, the methods
/// (greedy, selective h = 1, 3, 5, optimum), 32 runs.
fn suite_request(name: &str) -> Result<SweepRequest, UsageError> {
    use quadrecomb::internals::mesh::suite;
    let members = suite::suite(name).ok_or_else(|| {
        UsageError(format!(
            "--suite {name:?}: no such suite (suites: {}; `quadrecomb suite list` shows them)",
            suite::suite_names()
        ))
    })?;
    Ok(SweepRequest {
        meshes: members.iter().map(|m| suite::spec(m)).collect(),
        algos: ["greedy", "selective", "optimum"]
            .map(String::from)
            .to_vec(),
        horizons: vec![1, 3, 5],
        runs: 32,
        ..SweepRequest::default()
    })
}

/// The `--algo` values: every method of the registry (the optimum included), with its line
/// of help.
fn algo_names() -> clap::builder::PossibleValuesParser {
    use quadrecomb::internals::search::methods::METHODS;
    clap::builder::PossibleValuesParser::new(
        METHODS
            .iter()
            .map(|m| clap::builder::PossibleValue::new(m.name).help(m.about)),
    )
}

/// A configuration error worded with the flags that set the values it names.
fn config_error(e: ConfigError) -> UsageError {
    UsageError(match e {
        ConfigError::ZeroRuns => "--runs must be at least 1".into(),
        ConfigError::SeedTooLarge(seed) => format!(
            "--seed {seed} is above 2^53 - 1 = {}: records hold it as a JSON number, which jq \
             and pandas would read rounded (another run); choose a smaller seed",
            quadrecomb::internals::experiment::seed::MAX_EXACT_SEED
        ),
        ConfigError::ZeroBaselineRuns(algos) => format!(
            "--baseline-runs must be at least 1 (it is the number of runs of {})",
            algos.join(", ")
        ),
        ConfigError::ZeroThreads => "--threads must be at least 1".into(),
        ConfigError::NoBudget => "--budgets: give at least one budget".into(),
        ConfigError::DuplicateTimeBudget(t) => format!("--time-budgets: {t} given twice"),
        ConfigError::TimeBudgetUnused(algos) => format!(
            "--time-budgets: none of the methods ({algos}) has a horizon or node budget to \
             calibrate (give selective, uniform, optimistic, mcts or beam)"
        ),
        ConfigError::TimeBudgetSharded => "--time-budgets cannot be used with --shard: each \
             shard would calibrate its own knobs and the shards would not merge; run the sweep \
             whole"
            .into(),
        ConfigError::BadBudget(b) => {
            format!("--budgets {b}: each budget must be in 1..=16777216 and given once")
        }
        ConfigError::TooLarge(SizeError::Horizons(n)) => {
            format!("{n} horizons given; a sweep takes at most {MAX_HORIZONS}")
        }
        ConfigError::TooLarge(SizeError::Runs {
            total,
            runs,
            baseline_runs,
            horizons,
            algos,
            meshes,
        }) => format!(
            "the sweep has {total} runs (--runs {runs}, --baseline-runs {baseline_runs}, \
             {horizons} horizon(s), {algos} algorithm(s), {meshes} mesh(es)); a sweep takes at \
             most {MAX_RUNS}: split it or run fewer"
        ),
        other => other.to_string(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn horizon_syntax() {
        assert_eq!(
            parse_horizons("1..10").unwrap().0,
            (1..=10).collect::<Vec<_>>()
        );
        assert_eq!(parse_horizons("2..=4").unwrap().0, vec![2, 3, 4]);
        assert_eq!(parse_horizons("1,3,5").unwrap().0, vec![1, 3, 5]);
        assert_eq!(parse_horizons("7").unwrap().0, vec![7]);
        assert!(parse_horizons("0..3").is_err());
        assert!(parse_horizons("5..3").is_err());
        assert!(parse_horizons("a").is_err());
        // Refused before a billion horizons are collected (it aborted allocating).
        let err = parse_horizons("1..1000000000").unwrap_err();
        assert!(err.contains("at most 1024"), "{err}");
        assert!(parse_horizons("1..1024").is_ok() && parse_horizons("1..1025").is_err());
    }

    #[test]
    fn config_errors_name_their_flags() {
        let msg = |e| config_error(e).0;
        assert_eq!(msg(ConfigError::ZeroRuns), "--runs must be at least 1");
        assert_eq!(
            msg(ConfigError::ZeroThreads),
            "--threads must be at least 1"
        );
        let m = msg(ConfigError::TooLarge(SizeError::Runs {
            total: 20_000_000,
            runs: 2_000_000,
            baseline_runs: 1,
            horizons: 10,
            algos: 1,
            meshes: 1,
        }));
        assert!(m.contains("(--runs 2000000, --baseline-runs 1,"), "{m}");
        assert_eq!(msg(ConfigError::NoMesh), "no mesh given");
    }
}
