//! `quadrecomb bench optimum`: time of the exact optimum on the built-in meshes and on
//! generated jittered grids of growing size, with the fitted growth exponent and peak memory.

use crate::cli::UsageError;
use quadrecomb::internals::mesh::Mesh;
use quadrecomb::internals::mesh::generate::{self, GridSpec, MAX_GRID_TRIANGLES};
use quadrecomb::internals::quality::{CandidateTable, Rule};
use quadrecomb::internals::search::optimum;
use quadrecomb::internals::stats::describe::linear_fit;
use std::process::{Command, ExitCode};

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Grid sizes in triangles (comma-separated, each at least 100; each is rounded to a grid
    /// of squares).
    #[arg(long, value_delimiter = ',', default_values_t = [10_000usize, 30_000, 100_000, 300_000, 1_000_000])]
    sizes: Vec<usize>,
    /// Sizes of the jittered equilateral lattices, at least 100 triangles (near-equilateral triangles like a frontal
    /// Delaunay mesh: a much harder matching than the right-triangle grids).
    #[arg(long, value_delimiter = ',', default_values_t = [10_000usize, 30_000, 100_000, 200_000])]
    lattice_sizes: Vec<usize>,
    /// Built-in meshes or mesh files to time as well (skipped with a note when not loadable).
    #[arg(long, value_delimiter = ',', default_values_t = ["borouchaki".to_string(), "sphere".to_string()])]
    meshes: Vec<String>,
    /// Timed runs per mesh; the minimum is reported.
    #[arg(long, default_value_t = 5, value_parser = super::at_least_one())]
    repeat: usize,
    /// Skip the peak-memory measurement (one child process per grid size).
    #[arg(long)]
    no_rss: bool,
    #[command(flatten)]
    rule: crate::cli::RuleArgs,
    /// Internal: solve one grid of this many triangles and print the peak RSS in bytes.
    #[arg(long, hide = true)]
    rss_child: Option<usize>,
}

/// Smallest grid or lattice size `bench optimum` times: below it a solve takes microseconds
/// and measures the timer and the set-up, not the matching, and the growth fit means nothing.
pub const MIN_SIZE: usize = 100;

/// Refuses, before any work, sizes outside [`MIN_SIZE`, [`MAX_GRID_TRIANGLES`]] (0 panicked,
/// 1 and 2 timed a 2-triangle mesh), naming the flag and the limit.
fn check_sizes(flag: &str, sizes: &[usize]) -> Result<(), UsageError> {
    match sizes
        .iter()
        .find(|&&n| !(MIN_SIZE..=MAX_GRID_TRIANGLES).contains(&n))
    {
        Some(n) => Err(UsageError(format!(
            "{flag} {n}: sizes must be between {MIN_SIZE} triangles (below that the time is the \
             timer's and the set-up's, not the matching's) and {MAX_GRID_TRIANGLES}"
        ))),
        None => Ok(()),
    }
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    check_sizes("--sizes", &args.sizes)?;
    check_sizes("--lattice-sizes", &args.lattice_sizes)?;
    let rule = args.rule.rule()?;
    if let Some(n) = args.rss_child {
        let mesh = grid(n, 1);
        let table = CandidateTable::build(&mesh).restrict(&mesh, rule);
        let opt = optimum::solve(&mesh, &table);
        std::hint::black_box(&opt);
        outln!("{} {}", mesh.num_triangles(), peak_rss().unwrap_or(0));
        return Ok(ExitCode::SUCCESS);
    }
    outln!("Rule: {rule}.");
    outln!(
        "{:<22} {:>10} {:>9} {:>6} {:>14} {:>10} {:>10} {:>12}",
        "mesh",
        "triangles",
        "quads",
        "left",
        "quality",
        "wall_ms",
        "cpu_ms",
        "rss_B/tri"
    );
    for spec in &args.meshes {
        match quadrecomb::internals::mesh::load(spec) {
            Ok(mesh) => {
                let (opt, t, cpu) = time(&mesh, rule, args.repeat);
                print_row(spec, &mesh, &opt, t, cpu, None);
            }
            Err(e) => outln!("{spec:<22} (not loadable here: {e})"),
        }
    }
    let mut points = Vec::new();
    for &n in &args.sizes {
        let mesh = grid(n, 1);
        let repeat = if mesh.num_triangles() > 200_000 {
            args.repeat.min(3)
        } else {
            args.repeat
        };
        let (opt, t, cpu) = time(&mesh, rule, repeat);
        let rss = if args.no_rss {
            None
        } else {
            child_rss(n, &args.rule)
        };
        print_row(&format!("grid {n}"), &mesh, &opt, t, cpu, rss);
        points.push((mesh.num_triangles() as f64, cpu.unwrap_or(t)));
    }
    if points.len() >= 2 {
        outln!(
            "growth exponent (least-squares slope of log cpu time vs log triangles, grids): {:.2}",
            slope(&points)
        );
    }
    let mut points = Vec::new();
    for &n in &args.lattice_sizes {
        let mesh = lattice(n, 2);
        let repeat = if mesh.num_triangles() > 50_000 {
            args.repeat.min(2)
        } else {
            args.repeat
        };
        let (opt, t, cpu) = time(&mesh, rule, repeat);
        print_row(&format!("lattice {n}"), &mesh, &opt, t, cpu, None);
        points.push((mesh.num_triangles() as f64, cpu.unwrap_or(t)));
    }
    if points.len() >= 2 {
        outln!(
            "growth exponent (least-squares slope of log cpu time vs log triangles, lattices): {:.2}",
            slope(&points)
        );
    }
    Ok(ExitCode::SUCCESS)
}

fn print_row(
    name: &str,
    mesh: &Mesh,
    opt: &optimum::Optimum,
    t: f64,
    cpu: Option<f64>,
    rss: Option<f64>,
) {
    let rss = rss.map_or("-".to_string(), |r| format!("{r:.0}"));
    let cpu = cpu.map_or("-".to_string(), |c| format!("{:.2}", 1e3 * c));
    outln!(
        "{:<22} {:>10} {:>9} {:>6} {:>14.4} {:>10.2} {:>10} {:>12}",
        name,
        mesh.num_triangles(),
        opt.quads,
        opt.triangles_left,
        opt.quality,
        1e3 * t,
        cpu,
        rss
    );
}

/// Best wall time and mean on-CPU time of at least `repeat` solves under `rule`, repeated until they add
/// up to 0.3 s (table built once, outside the timing). On a shared machine the on-CPU time
/// (the scheduler's count for this thread, coarse for one short run, hence the mean over many)
/// is the steadier figure.
fn time(mesh: &Mesh, rule: Rule, repeat: usize) -> (optimum::Optimum, f64, Option<f64>) {
    let table = CandidateTable::build(mesh).restrict(mesh, rule);
    let mut best: Option<optimum::Optimum> = None;
    let c0 = thread_cpu_s();
    let start = std::time::Instant::now();
    let mut runs = 0;
    while runs < repeat.max(1) || (start.elapsed().as_secs_f64() < 0.3 && runs < 1000) {
        let o = optimum::solve(mesh, &table);
        if best.as_ref().is_none_or(|b| o.time_s < b.time_s) {
            best = Some(o);
        }
        runs += 1;
    }
    let cpu = match (c0, thread_cpu_s()) {
        (Some(a), Some(b)) if b > a => Some((b - a) / runs as f64),
        _ => None,
    };
    let best = best.expect("at least one run");
    let t = best.time_s;
    (best, t, cpu)
}

/// Seconds this thread has spent on a CPU (`/proc/thread-self/schedstat`), where it exists.
fn thread_cpu_s() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let ns: u64 = text.split_whitespace().next()?.parse().ok()?;
    Some(ns as f64 * 1e-9)
}

/// Peak RSS per triangle of a child process that builds and solves one grid.
fn child_rss(n: usize, rule: &crate::cli::RuleArgs) -> Option<f64> {
    let exe = std::env::current_exe().ok()?;
    let out = Command::new(exe)
        .args(["bench", "optimum", "--rss-child", &n.to_string()])
        .args(rule.flags())
        .output()
        .ok()?;
    let text = String::from_utf8_lossy(&out.stdout);
    let mut it = text.split_whitespace();
    let nt: f64 = it.next()?.parse().ok()?;
    let bytes: f64 = it.next()?.parse().ok()?;
    (bytes > 0.0).then_some(bytes / nt)
}

/// Peak resident set size of this process in bytes (`VmHWM`), where /proc exists.
fn peak_rss() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Least-squares slope of `ln t` against `ln n`.
fn slope(points: &[(f64, f64)]) -> f64 {
    let xs: Vec<f64> = points.iter().map(|p| p.0.ln()).collect();
    let ys: Vec<f64> = points.iter().map(|p| p.1.ln()).collect();
    linear_fit(&xs, &ys).map_or(f64::NAN, |fit| fit.slope)
}

/// The seeded jittered right-triangle grid of about `n` triangles (`generate grid`), so that
/// every run times the same mesh.
fn grid(n: usize, seed: u64) -> Mesh {
    generate::grid(GridSpec {
        triangles: n,
        seed,
        ..GridSpec::default()
    })
}

/// The seeded jittered equilateral lattice of about `n` triangles (`generate lattice`).
pub fn lattice(n: usize, seed: u64) -> Mesh {
    generate::lattice(n, seed)
}
