//! `quadrecomb bench finish`: selective h = 3 plus `--finish` against the exact optimum, timed
//! in the same run: on seeded jittered equilateral lattices of growing size (time, % of the
//! optimum, triangles left, time per triangle), and over many runs on the built-in meshes
//! (median % of the optimum and % recombined, for h = 3 and h = 1).

use crate::cli::UsageError;
use quadrecomb::internals::finish::{self, FinishConfig};
use quadrecomb::internals::mesh::{self, generate};
use quadrecomb::internals::quality::{CandidateTable, Rule};
use quadrecomb::internals::search::{Algo, Searcher, optimum};
use std::process::ExitCode;
use std::time::Instant;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Lattice sizes in triangles (comma-separated, each at least 100; seed 2, as `bench
    /// optimum` and `generate lattice --seed 2`).
    #[arg(long, value_delimiter = ',', default_values_t = [100_000usize, 1_000_000, 4_000_000])]
    lattice_sizes: Vec<usize>,
    /// Built-in meshes (or .msh files) for the many-run table; empty to skip.
    #[arg(long, value_delimiter = ',', default_values_t = [String::from("borouchaki")])]
    meshes: Vec<String>,
    /// Runs (seeds 0..runs) per horizon on each mesh.
    #[arg(long, default_value_t = 128, value_parser = clap::value_parser!(u64).range(1..))]
    runs: u64,
    /// Improvement window in rings.
    #[arg(long, default_value_t = finish::DEFAULT_WINDOW)]
    window: u32,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    if let Some(&n) = args.lattice_sizes.iter().find(|&&n| n < 100) {
        return Err(UsageError(format!("--lattice-sizes: {n} is below 100 triangles")).into());
    }
    let config = FinishConfig {
        window: args.window,
        ..FinishConfig::default()
    };
    if !args.lattice_sizes.is_empty() {
        outln!(
            "lattices (seed 2), selective h=3 seed 0 + finish (window {}), valid-quad rule",
            args.window
        );
        outln!(
            "{:>10} {:>9} {:>9} {:>9} {:>8} {:>6} {:>9} {:>7} {:>11}",
            "triangles",
            "sel_s",
            "finish_s",
            "opt_s",
            "%opt",
            "left",
            "raw%opt",
            "ratio",
            "us/tri"
        );
    }
    for &n in &args.lattice_sizes {
        let mesh = generate::lattice(n, 2);
        let table = CandidateTable::build(&mesh).restrict(&mesh, Rule::default());
        let mut searcher = Searcher::new(&mesh, &table);
        let out = searcher.run(Algo::selective(3), 0);
        drop(searcher);
        let f = finish::finish(&mesh, &table, &out.chosen, config)?;
        let t = Instant::now();
        let opt = optimum::solve(&mesh, &table);
        let opt_s = t.elapsed().as_secs_f64();
        let ours = out.time_s + f.time_s();
        let nt = mesh.num_triangles();
        outln!(
            "{:>10} {:>9.3} {:>9.3} {:>9.3} {:>8.3} {:>6} {:>9.3} {:>7.3} {:>11.3}",
            nt,
            out.time_s,
            f.time_s(),
            opt_s,
            100.0 * f.improved.quality / opt.quality,
            f.improved.triangles_left,
            100.0 * out.quality / opt.quality,
            ours / opt_s,
            1e6 * ours / nt as f64,
        );
    }
    outln!("(ratio = (selective + finish time) / optimum time; us/tri = that time per triangle)");
    for name in args.meshes.iter().filter(|m| !m.is_empty()) {
        let mesh = mesh::load(name)?;
        let table = CandidateTable::build(&mesh).restrict(&mesh, Rule::default());
        let opt = optimum::solve(&mesh, &table);
        let mut searcher = Searcher::new(&mesh, &table);
        for h in [3u32, 1] {
            let (mut raw, mut fin, mut rec, mut ts) = (vec![], vec![], vec![], vec![]);
            for seed in 0..args.runs {
                let out = searcher.run(Algo::selective(h), seed);
                let f = finish::finish(&mesh, &table, &out.chosen, config)?;
                raw.push(100.0 * out.quality / opt.quality);
                fin.push(100.0 * f.improved.quality / opt.quality);
                rec.push(100.0 * (2 * f.improved.quads) as f64 / mesh.num_triangles() as f64);
                ts.push(f.time_s());
            }
            outln!(
                "{name} selective h={h}, {} runs: raw median {:.3} % of the optimum; finished \
                 median {:.3} % (min {:.3}), recombined median {:.3} % (min {:.3}); finish time \
                 median {:.3} s (optimum {:.3} s)",
                args.runs,
                median(&mut raw),
                median(&mut fin),
                fin.iter().copied().fold(f64::INFINITY, f64::min),
                median(&mut rec),
                rec.iter().copied().fold(f64::INFINITY, f64::min),
                median(&mut ts),
                opt.time_s,
            );
        }
    }
    Ok(ExitCode::SUCCESS)
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        return f64::NAN;
    }
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}
