//! `quadrecomb recombine`: one run of one policy on one mesh.

use super::BadInput;
use quadrecomb::quality::{self, CandidateTable};
use quadrecomb::search::{self, Algo, optimum};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, Clone, Copy, clap::ValueEnum)]
enum AlgoName {
    /// Decreasing eta, no criterion (the paper's naive greedy).
    #[value(name = "greedy-nocrit")]
    GreedyNocrit,
    /// Decreasing eta among allowed actions (uniform tree of horizon 1).
    Greedy,
    /// Uniform look-ahead tree (exact branch and bound).
    Uniform,
    /// Selective look-ahead tree.
    Selective,
}

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Mesh file (.msh) or built-in name (borouchaki, sphere).
    mesh: String,
    /// Policy.
    #[arg(long, value_enum)]
    algo: AlgoName,
    /// Horizon of the uniform / selective tree.
    #[arg(long, default_value_t = 1)]
    horizon: u32,
    /// Seed of the run (ChaCha8: the same seed gives the same run everywhere).
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Write the recombined mesh (quads and leftover triangles): .msh (MSH 4.1) or .vtu.
    #[arg(short = 'o', long)]
    output: Option<PathBuf>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
    /// Do not compute the exact optimum (skips `quality_pct`).
    #[arg(long)]
    no_optimum: bool,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let name = match args.algo {
        AlgoName::GreedyNocrit => "greedy-nocrit",
        AlgoName::Greedy => "greedy",
        AlgoName::Uniform => "uniform",
        AlgoName::Selective => "selective",
    };
    let algo = Algo::from_name(name, args.horizon).map_err(|e| BadInput(e.to_string()))?;
    super::check_mesh_output(args.output.as_deref())?;
    let mesh = quadrecomb::mesh::load(&args.mesh)?;
    let table = CandidateTable::build(&mesh);
    let out = search::run(&mesh, &table, algo, args.seed);
    let nt = mesh.num_triangles();
    let recombined_pct = 100.0 * (2 * out.quads) as f64 / nt as f64;
    let opt = (!args.no_optimum).then(|| optimum::solve(&mesh, &table));
    let quality_pct = opt
        .as_ref()
        .filter(|o| o.quality > 0.0)
        .map(|o| 100.0 * out.quality / o.quality);
    if let Some(path) = &args.output {
        let rec = quality::recombined(&mesh, &table, &out.chosen);
        super::write_mesh_output(path, &mesh, &rec)?;
    }
    let horizon = match algo {
        Algo::GreedyNocrit | Algo::Greedy => None,
        _ => Some(algo.horizon()),
    };
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
            "nodes_expanded": out.nodes_expanded,
            "trees": out.trees,
            "decisions": out.decisions,
        });
        if let Some(p) = quality_pct {
            v["quality_pct"] = serde_json::json!(p);
            v["optimum"] = serde_json::json!(opt.as_ref().map(|o| o.quality));
        }
        println!("{v}");
    } else {
        println!("mesh            {}", args.mesh);
        println!("triangles       {nt}");
        match horizon {
            Some(h) => println!("algo            {} (horizon {h}, seed {})", algo, args.seed),
            None => println!("algo            {} (seed {})", algo, args.seed),
        }
        println!("quads           {}", out.quads);
        println!("triangles left  {}", out.triangles_left);
        println!("recombined      {recombined_pct:.2} %");
        match (quality_pct, &opt) {
            (Some(p), Some(o)) => println!(
                "quality         {:.4} (sum of eta; {p:.2} % of the optimum {:.4})",
                out.quality, o.quality
            ),
            _ => println!("quality         {:.4} (sum of eta)", out.quality),
        }
        println!(
            "nodes expanded  {} ({} look-ahead trees)",
            out.nodes_expanded, out.trees
        );
        println!("time            {:.4} s", out.time_s);
        if let Some(p) = &args.output {
            println!("wrote           {}", p.display());
        }
    }
    Ok(ExitCode::SUCCESS)
}
