//! `quadrecomb recombine`: one run of one policy on one mesh.

use super::UsageError;
use quadrecomb::internals::experiment::calibrate::{self, TimeBudget};
use quadrecomb::internals::experiment::replay::{self, EtaSource};
use quadrecomb::internals::quality::{self, CandidateTable, ElementQuality, Rule};
use quadrecomb::internals::search::{self, Algo, optimum};
use std::process::ExitCode;

/// The `--algo` values: every search method of the registry, with its line of help.
pub fn algo_values() -> clap::builder::PossibleValuesParser {
    use quadrecomb::internals::search::methods::METHODS;
    clap::builder::PossibleValuesParser::new(
        METHODS
            .iter()
            .filter(|m| m.search)
            .map(|m| clap::builder::PossibleValue::new(m.name).help(m.about)),
    )
}

/// Who computes eta.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum EtaBackend {
    /// The f64 reference (`CandidateTable::build`).
    Exact,
    /// The CPU twin of the GPU kernel (f32), what `sweep --backend cpu` records as
    /// `cpu-twin`.
    Cpu,
    /// The GPU kernel on a Vulkan adapter (lavapipe included), as `sweep --backend gpu`.
    Gpu,
}

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Mesh file (.msh) or built-in name (borouchaki, sphere).
    mesh: String,
    /// Policy.
    #[arg(long, value_parser = algo_values())]
    algo: String,
    /// Horizon of the tree policies (default 1 for uniform and selective, 10 for
    /// optimistic and mcts, 5 for beam; the greedy policies have none).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    horizon: Option<u32>,
    /// Tree nodes expanded per decision of optimistic, mcts and beam (default 64; the
    /// others have none).
    #[arg(long)]
    budget: Option<u32>,
    /// A wall-time budget for the run, in seconds (0.2, 2s) or milliseconds (50ms): the
    /// node budget (optimistic, mcts, beam) or the horizon (selective, uniform) is first
    /// calibrated by pilot runs on other seeds to the largest whose median time fits, said
    /// on stderr; give that knob to repeat the run (docs/search.md).
    #[arg(long, value_name = "T", value_parser = parse_time_budget, allow_negative_numbers = true)]
    time_budget: Option<TimeBudget>,
    /// Seed of the run (ChaCha8: the same seed gives the same run everywhere).
    #[arg(long, default_value_t = 0)]
    seed: u64,
    #[command(flatten)]
    out: super::MeshOutputArgs,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
    /// Do not compute the exact optimum (skips `quality_pct`).
    #[arg(long)]
    no_optimum: bool,
    /// Who computes eta. Runs are exact given the eta table, but the f32 kernel's values
    /// differ from the f64 reference in the last bits, which can change ties and so the
    /// run: to repeat a sweep's run, pass its record's `seed` and `--backend cpu` (records
    /// with backend `cpu-twin`) or `--backend gpu` (a `vulkan: ...` backend).
    #[arg(long, value_enum, default_value_t = EtaBackend::Exact)]
    backend: EtaBackend,
    #[command(flatten)]
    rule: super::RuleArgs,
    #[command(flatten)]
    finish: FinishArgs,
}

/// Finishing what the policy leaves (docs/finish.md).
#[derive(Debug, clap::Args)]
pub struct FinishArgs {
    /// Finish the run: pair the leftovers that can be paired (each group with rings of quads
    /// around it re-solved exactly), then improve by exact windows until a pass gains nothing.
    #[arg(long)]
    pub finish: bool,
    /// With --finish: also make odd components even by splitting a boundary side (a new node
    /// at its midpoint, on the chord), and refine by sheets the components no split fixes,
    /// so that no triangle is left.
    #[arg(long, requires = "finish")]
    pub all_quad: bool,
    /// With --finish: rings of quads around the leftovers in the first elimination round (k,
    /// doubled until every leftover is settled).
    #[arg(long, requires = "finish", default_value_t = quadrecomb::internals::finish::DEFAULT_RINGS, value_parser = clap::value_parser!(u32).range(1..))]
    pub rings: u32,
    /// With --finish: rings of quads of each improvement window (r); 0 skips improvement.
    #[arg(long, requires = "finish", default_value_t = quadrecomb::internals::finish::DEFAULT_WINDOW)]
    pub window: u32,
}

impl FinishArgs {
    /// The finish configuration, if --finish.
    pub fn config(&self, rule: Rule) -> Option<quadrecomb::internals::finish::FinishConfig> {
        self.finish
            .then_some(quadrecomb::internals::finish::FinishConfig {
                rings: self.rings,
                window: self.window,
                all_quad: self.all_quad,
                rule,
            })
    }
}

/// The candidate table of `mesh` with eta from `backend`, restricted to the pairs `rule`
/// allows, and the evaluator's name.
pub fn eta_table(
    mesh: &quadrecomb::internals::mesh::Mesh,
    backend: EtaBackend,
    rule: Rule,
) -> anyhow::Result<(CandidateTable, String)> {
    let source = match backend {
        EtaBackend::Exact => EtaSource::Exact,
        EtaBackend::Cpu => EtaSource::CpuTwin,
        EtaBackend::Gpu => EtaSource::Device,
    };
    Ok(replay::eta_table(mesh, source, rule)?)
}

/// A `--time-budget` value.
fn parse_time_budget(s: &str) -> Result<TimeBudget, String> {
    s.parse::<TimeBudget>()
        .map_err(|e| format!("bad time budget: {e}"))
}

/// The horizon of a tree policy; `None` for the greedy ones.
fn horizon_of(algo: Algo) -> Option<u32> {
    algo.params().horizon
}

/// `algo` with its knob calibrated to `t` by pilot runs (on stderr: what was chosen).
fn calibrated(
    mesh: &quadrecomb::internals::mesh::Mesh,
    table: &CandidateTable,
    algo: Algo,
    t: TimeBudget,
    seed: u64,
) -> anyhow::Result<Algo> {
    let name = algo.name();
    let nodes = algo.budget().is_some();
    let horizon = if nodes { algo.params().horizon } else { None };
    let (choice, probes) = calibrate::calibrate_run(mesh, table, name, horizon, t, seed)
        .map_err(|e| UsageError(e.to_string()))?;
    let params = if nodes {
        search::Params {
            horizon,
            budget: Some(choice.knob),
        }
    } else {
        search::Params {
            horizon: Some(choice.knob),
            budget: None,
        }
    };
    let flag = if nodes { "--budget" } else { "--horizon" };
    noteln!(
        "recombine: --time-budget {t} calibrated to {flag} {} (median {:.3} s over {} pilot runs \
         on other seeds; {} values tried){}; to repeat this run give {flag} {} instead",
        choice.knob,
        choice.median_s,
        calibrate::MIN_PILOTS,
        probes.len(),
        if choice.saturated {
            ": it covers the pilots' trees, a larger one makes the same runs"
        } else if !choice.fits {
            ": over the budget even at the smallest value"
        } else {
            ""
        },
        choice.knob
    );
    Ok(Algo::new(name, params).map_err(|e| UsageError(e.to_string()))?)
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let name = args.algo.as_str();
    let given = search::Params {
        horizon: args.horizon,
        budget: args.budget,
    };
    if let Some(t) = args.time_budget {
        if !calibrate::has_knob(name) {
            return Err(UsageError(format!(
                "--time-budget {t}: {name} has no horizon or node budget to calibrate (give \
                 selective, uniform, optimistic, mcts or beam)"
            ))
            .into());
        }
        let knob = if search::methods::find(name)
            .is_some_and(|m| m.has(search::methods::ParamKind::Budget))
        {
            args.budget.map(|_| "--budget")
        } else {
            args.horizon.map(|_| "--horizon")
        };
        if let Some(flag) = knob {
            return Err(UsageError(format!(
                "--time-budget {t} and {flag}: the time budget chooses {flag} for {name}; give \
                 one of them"
            ))
            .into());
        }
    }
    let mut algo = Algo::new(name, given).map_err(|e| match e {
        // Name the flag that carried the value.
        search::methods::AlgoError::OutOfRange { param, .. } => {
            UsageError(format!("--{param}: {e}"))
        }
        e => UsageError(e.to_string()),
    })?;
    for kind in algo.ignored(given) {
        match kind {
            search::methods::ParamKind::Horizon => {
                noteln!("note: --horizon is ignored: {name} looks no further than one action")
            }
            search::methods::ParamKind::Budget => {
                noteln!("note: --budget is ignored: {name} has no node budget")
            }
        }
    }
    super::check_mesh_output(args.out.output.as_deref())?;
    let rule = args.rule.rule()?;
    super::check_not_input(args.out.output.as_deref(), &args.mesh)?;
    use super::oom::{self, Phase};
    oom::phase(Phase::Reading);
    let mesh = quadrecomb::internals::mesh::load(&args.mesh)?;
    oom::mesh_size(mesh.num_triangles());
    oom::phase(Phase::Candidates);
    let (table, backend) = eta_table(&mesh, args.backend, rule)?;
    if let Some(t) = args.time_budget {
        algo = calibrated(&mesh, &table, algo, t, args.seed)?;
    }
    oom::phase(Phase::Search);
    let mut searcher = search::Searcher::new(&mesh, &table);
    let bar = super::progress_bar::attach(&mut searcher, algo.params());
    let out = searcher.run(algo, args.seed);
    bar.finish_and_clear();
    drop(searcher);
    let elements = ElementQuality::of_chosen(&table, &out.chosen);
    let nt = mesh.num_triangles();
    let recombined_pct = 100.0 * (2 * out.quads) as f64 / nt as f64;
    oom::phase(Phase::Optimum);
    let opt = (!args.no_optimum).then(|| optimum::solve(&mesh, &table));
    let finished = match args.finish.config(rule) {
        Some(config) => Some(
            quadrecomb::internals::finish::finish(&mesh, &table, &out.chosen, config)
                .map_err(|e| anyhow::Error::new(e).context(args.mesh.clone()))?,
        ),
        None => None,
    };
    oom::phase(Phase::Writing);
    let quality_pct = opt
        .as_ref()
        .filter(|o| o.quality > 0.0)
        .map(|o| 100.0 * out.quality / o.quality);
    // A failed write is reported after the run's figures, which are printed all the same:
    // the work is not lost with the file.
    let written = args.out.output.as_ref().map(|path| match &finished {
        Some(f) => {
            let (m, t) = (f.mesh(&mesh), f.table(&table));
            let rec = quality::recombined(m, t, &f.chosen);
            super::write_mesh_output(path, m, &rec, args.out.vtu_ascii)
        }
        None => {
            let rec = quality::recombined(&mesh, &table, &out.chosen);
            super::write_mesh_output(path, &mesh, &rec, args.out.vtu_ascii)
        }
    });
    let pct_of = |q: f64| {
        opt.as_ref()
            .filter(|o| o.quality > 0.0)
            .map(|o| 100.0 * q / o.quality)
    };
    let horizon = horizon_of(algo);
    // null where the policy builds no tree (greedy-nocrit), as its sweep record has it.
    let trees = algo.info().builds_trees;
    let (nodes_expanded, tree_count) = (
        trees.then_some(out.nodes_expanded),
        trees.then_some(out.trees),
    );
    if args.json {
        let mut v = serde_json::json!({
            "mesh": args.mesh,
            "triangles": nt,
            "algo": algo.name(),
            "horizon": horizon,
            "seed": args.seed,
            "quads": out.quads,
            "triangles_left": out.triangles_left,
            "recombined_pct": recombined_pct,
            "quality": out.quality,
            "time_s": out.time_s,
            "nodes_expanded": nodes_expanded,
            "trees": tree_count,
            "decisions": out.decisions,
            "backend": backend,
        });
        super::add_element_fields(&mut v, &elements, rule);
        if let Some(p) = quality_pct {
            v["quality_pct"] = serde_json::json!(p);
            v["optimum"] = serde_json::json!(opt.as_ref().map(|o| o.quality));
        }
        if let Some(b) = algo.budget() {
            v["budget"] = serde_json::json!(b);
        }
        if let Some(f) = &finished {
            v["finish"] = super::finish_report::json(f, &table, pct_of);
        }
        outln!("{v}");
    } else {
        outln!("mesh            {}", args.mesh);
        outln!("triangles       {nt}");
        super::print_input_quads(&mesh);
        match (horizon, algo.budget()) {
            (Some(h), Some(b)) => outln!(
                "algo            {} (horizon {h}, budget {b}, seed {})",
                algo,
                args.seed
            ),
            (Some(h), None) => {
                outln!("algo            {} (horizon {h}, seed {})", algo, args.seed)
            }
            _ => outln!("algo            {} (seed {})", algo, args.seed),
        }
        outln!("eta             {backend}");
        outln!("quads           {}", out.quads);
        outln!("triangles left  {}", out.triangles_left);
        outln!("recombined      {recombined_pct:.2} %");
        match (quality_pct, &opt) {
            (Some(p), Some(o)) => outln!(
                "quality         {:.4} (sum of eta; {p:.2} % of the optimum {:.4})",
                out.quality,
                o.quality
            ),
            _ => outln!("quality         {:.4} (sum of eta)", out.quality),
        }
        super::print_element_lines(&elements, rule);
        match (nodes_expanded, tree_count) {
            (Some(n), Some(t)) => outln!("nodes expanded  {n} ({t} look-ahead trees)"),
            _ => outln!("nodes expanded  – (no look-ahead tree: {algo} builds none)"),
        }
        outln!("time            {:.4} s", out.time_s);
        if let Some(f) = &finished {
            super::finish_report::print(f, &table, pct_of);
        }
        if let (Some(p), Some(Ok(()))) = (&args.out.output, &written) {
            outln!("wrote           {}", p.display());
        }
    }
    written.transpose()?;
    Ok(ExitCode::SUCCESS)
}
