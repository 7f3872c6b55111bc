//! `quadrecomb bench io`: parse, topology and candidate-table times (median of repetitions).

use crate::cli::UsageError;
use quadrecomb::internals::mesh::{self, Mesh};
use quadrecomb::internals::quality::CandidateTable;
use std::process::ExitCode;
use std::time::Instant;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Mesh files or built-in names (default: the built-in `borouchaki`).
    meshes: Vec<String>,
    /// Repetitions per step; the median is reported.
    #[arg(long, default_value_t = 21)]
    reps: usize,
}

/// Median of `reps` runs of `f`, in milliseconds.
fn median_ms(reps: usize, mut f: impl FnMut()) -> f64 {
    let mut t: Vec<f64> = (0..reps)
        .map(|_| {
            let s = Instant::now();
            f();
            s.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[t.len() / 2]
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    if args.reps == 0 {
        return Err(UsageError("--reps must be at least 1".into()).into());
    }
    let meshes = if args.meshes.is_empty() {
        if mesh::builtin::bytes("borouchaki").is_none() {
            return Err(UsageError(
                "no built-in `borouchaki` in this build: give mesh files to benchmark".into(),
            )
            .into());
        }
        vec!["borouchaki".to_string()]
    } else {
        args.meshes
    };
    outln!(
        "median of {} repetitions, {} threads available",
        args.reps,
        std::thread::available_parallelism().map_or(1, |n| n.get())
    );
    outln!(
        "{:<28} {:>16} {:>10} {:>10} {:>12} {:>13}",
        "mesh",
        "format",
        "triangles",
        "parse ms",
        "topology ms",
        "candidates ms"
    );
    for spec in &meshes {
        let src = mesh::source(spec)?;
        let file = mesh::msh::parse(&src.path, &src.bytes)?;
        let format = format!(
            "msh {} {}",
            file.version,
            if file.binary { "binary" } else { "ascii" }
        );
        let data = file.data.clone();
        let m = file.into_mesh(&src.path)?;
        let parse = median_ms(args.reps, || {
            let f = mesh::msh::parse(&src.path, &src.bytes);
            std::hint::black_box(f.is_ok());
        });
        let topology = {
            let mut t: Vec<f64> = (0..args.reps)
                .map(|_| {
                    let d = data.clone();
                    let s = Instant::now();
                    let r = Mesh::new(d);
                    let e = s.elapsed().as_secs_f64() * 1e3;
                    std::hint::black_box(r.is_ok());
                    e
                })
                .collect();
            t.sort_by(f64::total_cmp);
            t[t.len() / 2]
        };
        let candidates = median_ms(args.reps, || {
            std::hint::black_box(CandidateTable::build(&m).len());
        });
        outln!(
            "{:<28} {:>16} {:>10} {:>10.2} {:>12.2} {:>13.2}",
            spec,
            format,
            m.num_triangles(),
            parse,
            topology,
            candidates
        );
    }
    Ok(ExitCode::SUCCESS)
}
