//! `quadrecomb bench search`: time per run of every policy on the built-in meshes, and time
//! per triangle of the selective tree on generated grids of growing size.

use crate::cli::UsageError;
use quadrecomb::internals::mesh::{
    self,
    generate::{self, GridSpec},
};
use quadrecomb::internals::quality::CandidateTable;
use quadrecomb::internals::search::{Algo, Searcher, optimum};
use std::process::ExitCode;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Seeds per randomized configuration (0, 1, ...); medians are reported.
    #[arg(long, default_value_t = 9, value_parser = clap::value_parser!(u64).range(1..))]
    runs: u64,
    /// Largest generated grid for the per-triangle scaling rows (triangles; the grids are
    /// 10,000, 100,000, ... up to this, so at least 10,000).
    #[arg(long, default_value_t = 1_000_000)]
    max_grid: usize,
    /// Largest uniform horizon on `sphere` (the paper's table stops at 2; h = 3 takes
    /// milliseconds, h = 4 about 0.2 s, h = 5 about 20 s: each level more multiplies the
    /// time by about a hundred from there).
    #[arg(long, default_value_t = 2)]
    max_uniform: u32,
    /// Also compare greedy with selective h = 1 on this mesh (a .msh file or a built-in
    /// name; repeatable): the meshes on which greedy leaves many triangles, such as Gmsh
    /// Delaunay meshes of a square with holes, are where its criterion searched longest.
    #[arg(long = "mesh", value_name = "MESH")]
    meshes: Vec<String>,
    /// Only the greedy / selective h = 1 comparison (`borouchaki` and the --mesh meshes).
    #[arg(long)]
    greedy_only: bool,
    #[command(flatten)]
    rule: crate::cli::RuleArgs,
}

/// CPU time of this thread in seconds (Linux schedstat), when available: on a loaded
/// machine it is the fairer figure; wall-clock time is reported beside it.
fn thread_cpu_s() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let ns: f64 = s.split_whitespace().next()?.parse().ok()?;
    Some(ns * 1e-9)
}

/// The first (smallest) grid of the scaling rows, in triangles; then 10 times larger up to
/// `--max-grid`.
const FIRST_GRID: usize = 10_000;

/// Rounds of the grid rows.
const GRID_ROUNDS: usize = 3;

/// Rounds of the greedy / selective h = 1 comparison (alternating the two).
const RATIO_ROUNDS: usize = 5;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

struct Row {
    mesh: String,
    algo: String,
    runs: u64,
    wall_ms: f64,
    cpu_ms: Option<f64>,
    quality_pct: Option<f64>,
    recombined_pct: f64,
    nodes_per_decision: f64,
    /// Median per run of tree nodes expanded, per triangle of the mesh.
    nodes_per_triangle: f64,
    /// Median per run of the triangles the criterion's searches visited, per triangle.
    searched_per_triangle: f64,
    /// Median per run of the criterion's checks that needed a search, per triangle.
    searches_per_triangle: f64,
}

/// Runs `algo` with seeds `0..runs` and summarises the medians.
fn measure(
    searcher: &mut Searcher<'_>,
    name: &str,
    triangles: usize,
    opt: Option<f64>,
    algo: Algo,
    runs: u64,
) -> Row {
    let (mut wall, mut cpu, mut q, mut rec, mut bf) = (vec![], vec![], vec![], vec![], vec![]);
    let (mut nodes, mut searched, mut searches) = (vec![], vec![], vec![]);
    for seed in 0..runs {
        let c0 = thread_cpu_s();
        let w0 = searcher.criterion_work();
        let out = searcher.run(algo, seed);
        let w1 = searcher.criterion_work();
        searched.push((w1.1 - w0.1) as f64 / triangles as f64);
        searches.push((w1.0 - w0.0) as f64 / triangles as f64);
        nodes.push(out.nodes_expanded as f64 / triangles as f64);
        if let (Some(a), Some(b)) = (c0, thread_cpu_s()) {
            cpu.push((b - a) * 1e3);
        }
        wall.push(out.time_s * 1e3);
        q.push(out.quality);
        rec.push(100.0 * (2 * out.quads) as f64 / triangles as f64);
        bf.push(out.nodes_expanded as f64 / out.decisions.max(1) as f64);
    }
    let label = algo.label();
    Row {
        mesh: name.to_string(),
        algo: label,
        runs,
        wall_ms: median(wall),
        cpu_ms: (!cpu.is_empty()).then(|| median(cpu)),
        quality_pct: opt.map(|o| 100.0 * median(q) / o),
        recombined_pct: median(rec),
        nodes_per_decision: median(bf),
        nodes_per_triangle: median(nodes),
        searched_per_triangle: median(searched),
        searches_per_triangle: median(searches),
    }
}

/// Greedy against selective h = 1 on one mesh, alternately over [`RATIO_ROUNDS`] rounds
/// (this VM's speed drifts): the medians of each round's runs, the median of the rounds'
/// ratios, and the criterion's work per triangle.
fn greedy_row(name: &str, m: &mesh::Mesh, t: &CandidateTable, runs: u64) {
    let mut s = Searcher::new(m, t);
    let nt = m.num_triangles();
    let sel = Algo::selective(1);
    let (mut g, mut h, mut ratio) = (vec![], vec![], vec![]);
    let mut last = None;
    for _ in 0..RATIO_ROUNDS {
        let a = measure(&mut s, name, nt, None, Algo::greedy(), runs);
        let b = measure(&mut s, name, nt, None, sel, runs);
        g.push(a.wall_ms);
        h.push(b.wall_ms);
        ratio.push(a.wall_ms / b.wall_ms);
        last = Some((a, b));
    }
    let (a, b) = last.expect("at least one round");
    let left = |r: &Row| (nt as f64 * (1.0 - r.recombined_pct / 100.0)).round();
    outln!(
        "| {name} | {nt} | {} / {} | {:.1} | {:.1} | {:.2} | {:.3} / {:.1} | {:.3} / {:.1} |",
        left(&a),
        left(&b),
        median(g),
        median(h),
        median(ratio),
        a.searches_per_triangle,
        a.searched_per_triangle,
        b.searches_per_triangle,
        b.searched_per_triangle,
    );
}

fn print_row(r: &Row) {
    let cpu = r.cpu_ms.map_or("-".into(), |c| format!("{c:.1}"));
    let q = r.quality_pct.map_or("-".into(), |q| format!("{q:.2}"));
    outln!(
        "| {} | {} | {} | {:.1} | {} | {} | {:.2} | {:.2} |",
        r.mesh,
        r.algo,
        r.runs,
        r.wall_ms,
        cpu,
        q,
        r.recombined_pct,
        r.nodes_per_decision
    );
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    if args.runs == 0 {
        return Err(UsageError("--runs must be at least 1".into()).into());
    }
    if args.max_grid < FIRST_GRID {
        return Err(UsageError(format!(
            "--max-grid {}: the grid rows start at {FIRST_GRID} triangles (then 10 times \
             larger up to --max-grid), so at least {FIRST_GRID}",
            args.max_grid
        ))
        .into());
    }
    let rule = args.rule.rule()?;
    let mut named = vec!["borouchaki".to_string()];
    named.extend(args.meshes.iter().cloned());
    let mut compared = Vec::new();
    for name in &named {
        // Loaded before any timing: a bad file fails at once.
        compared.push((name, mesh::load(name)?));
    }
    outln!(
        "Greedy against selective h=1, {RATIO_ROUNDS} rounds alternating them, {} seeds each \
         (greedy is deterministic): triangles left, median wall ms, the median of the rounds' \
         ratios greedy / selective, and the criterion's work per triangle (checks that needed \
         a search / triangles they visited). Rule: {rule}.\n",
        args.runs
    );
    outln!(
        "| mesh | triangles | left, greedy / selective | greedy ms | selective h=1 ms | ratio \
         | greedy searches / searched | selective searches / searched |"
    );
    outln!("|---|---:|---:|---:|---:|---:|---:|---:|");
    for (name, m) in &compared {
        let t = CandidateTable::build(m).restrict(m, rule);
        greedy_row(name, m, &t, args.runs);
    }
    outln!();
    if args.greedy_only {
        return Ok(ExitCode::SUCCESS);
    }
    outln!(
        "Per run (median over seeds 0..{}): wall and thread-CPU milliseconds, quality as % of \
         the exact optimum, % of triangles recombined, nodes expanded per decision. Rule: {rule}.\n",
        args.runs
    );
    outln!("| mesh | algo | runs | wall ms | cpu ms | quality % | recombined % | nodes/decision |");
    outln!("|---|---|---:|---:|---:|---:|---:|---:|");
    let b = mesh::load("borouchaki")?;
    let bt = CandidateTable::build(&b).restrict(&b, rule);
    let bopt = optimum::solve(&b, &bt).quality;
    let mut s = Searcher::new(&b, &bt);
    let nb = b.num_triangles();
    print_row(&measure(
        &mut s,
        "borouchaki",
        nb,
        Some(bopt),
        Algo::greedy_nocrit(),
        args.runs,
    ));
    print_row(&measure(
        &mut s,
        "borouchaki",
        nb,
        Some(bopt),
        Algo::greedy(),
        args.runs,
    ));
    for h in 1..=10 {
        let algo = Algo::selective(h);
        print_row(&measure(
            &mut s,
            "borouchaki",
            nb,
            Some(bopt),
            algo,
            args.runs,
        ));
    }
    drop(s);
    let sp = mesh::load("sphere")?;
    let st = CandidateTable::build(&sp).restrict(&sp, rule);
    let sopt = optimum::solve(&sp, &st).quality;
    let mut s = Searcher::new(&sp, &st);
    let ns = sp.num_triangles();
    for h in 1..=args.max_uniform {
        // Deterministic: one run.
        let algo = Algo::uniform(h);
        print_row(&measure(&mut s, "sphere", ns, Some(sopt), algo, 1));
    }
    for h in [1, 3] {
        let algo = Algo::selective(h);
        print_row(&measure(&mut s, "sphere", ns, Some(sopt), algo, args.runs));
    }
    drop(s);

    outln!(
        "\nSelective h=3 on generated jittered grids (one surface, no hole), {GRID_ROUNDS} rounds \
         alternating the sizes (this VM's speed drifts from minute to minute): ns per triangle \
         of the search, median over the seeds of a round, best and worst round; and the work, \
         which does not depend on the machine: tree nodes expanded and triangles visited by the \
         criterion's searches, per triangle (medians over the seeds):\n"
    );
    outln!(
        "| triangles | runs per round | ns per triangle (best round) | worst round | recombined % \
         | nodes per triangle | searched per triangle |"
    );
    outln!("|---:|---:|---:|---:|---:|---:|---:|");
    // As `generate grid` then `mesh::load` would give them: in spatial order.
    let mut grids = Vec::new();
    let mut n = FIRST_GRID;
    while n <= args.max_grid {
        let g = generate::grid(GridSpec {
            triangles: n,
            ..GridSpec::default()
        });
        let mut data = mesh::MeshData {
            vertices: g.vertices.clone(),
            triangles: g.triangles.clone(),
            ..Default::default()
        };
        mesh::order::spatial(&mut data);
        let g = mesh::Mesh::new(data)?;
        let t = CandidateTable::build(&g).restrict(&g, rule);
        grids.push((g, t));
        n *= 10;
    }
    let mut searchers: Vec<Searcher<'_>> = grids.iter().map(|(g, t)| Searcher::new(g, t)).collect();
    // Small grids take milliseconds: more seeds there, so that every row's median rests on
    // about as much work (the thread-CPU clock of some VMs ticks in 4 ms steps, so the figure
    // uses the search's own wall clock).
    let runs_for = |nt: usize| {
        if nt >= 1_000_000 {
            args.runs.min(3)
        } else {
            args.runs * (100_000 / nt as u64).max(1)
        }
    };
    let mut per = vec![Vec::new(); grids.len()];
    let mut recombined = vec![0.0; grids.len()];
    let mut work = vec![(0.0, 0.0); grids.len()];
    for _ in 0..GRID_ROUNDS {
        for (i, ((g, _), s)) in grids.iter().zip(&mut searchers).enumerate() {
            let nt = g.num_triangles();
            let r = measure(s, "grid", nt, None, Algo::selective(3), runs_for(nt));
            per[i].push(r.wall_ms * 1e6 / nt as f64);
            recombined[i] = r.recombined_pct;
            work[i] = (r.nodes_per_triangle, r.searched_per_triangle);
        }
    }
    for (i, (g, _)) in grids.iter().enumerate() {
        let nt = g.num_triangles();
        let best = per[i].iter().copied().fold(f64::INFINITY, f64::min);
        let worst = per[i].iter().copied().fold(0.0, f64::max);
        outln!(
            "| {nt} | {} | {best:.0} | {worst:.0} | {:.2} | {:.3} | {:.2} |",
            runs_for(nt),
            recombined[i],
            work[i].0,
            work[i].1
        );
    }
    Ok(ExitCode::SUCCESS)
}
