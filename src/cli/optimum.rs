//! `quadrecomb optimum`: the exact optimum (maximum-weight matching of maximum cardinality).

use quadrecomb::internals::quality::{self, CandidateTable, ElementQuality};
use quadrecomb::internals::search::optimum;
use std::process::ExitCode;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Mesh file (.msh) or built-in name.
    mesh: String,
    /// Print one JSON object: mesh, triangles, algo ("optimum"), horizon, seed,
    /// nodes_expanded and trees (null), quads, triangles_left, recombined_pct, quality,
    /// time_s, worst_eta, mean_eta, quads_eta_below_0_1 / _0_3, min_eta and allow_invalid as
    /// `recombine --json` has them, plus `check` with --check.
    #[arg(long)]
    json: bool,
    /// Also verify the dual certificate of the matching (feasible duals, complementary
    /// slackness); exits with an error if it fails. Not counted in `time_s`.
    #[arg(long)]
    check: bool,
    #[command(flatten)]
    out: super::MeshOutputArgs,
    #[command(flatten)]
    rule: super::RuleArgs,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    super::check_mesh_output(args.out.output.as_deref())?;
    let rule = args.rule.rule()?;
    super::check_not_input(args.out.output.as_deref(), &args.mesh)?;
    use super::oom::{self, Phase};
    oom::phase(Phase::Reading);
    let mesh = quadrecomb::internals::mesh::load(&args.mesh)?;
    oom::mesh_size(mesh.num_triangles());
    oom::phase(Phase::Candidates);
    let table = CandidateTable::build(&mesh).restrict(&mesh, rule);
    oom::phase(Phase::Optimum);
    let (opt, report) = optimum::solve_certified(&mesh, &table, args.check);
    let nt = mesh.num_triangles();
    let elements = ElementQuality::of_chosen(&table, &opt.chosen);
    let pct = if nt == 0 {
        0.0
    } else {
        100.0 * (2 * opt.quads) as f64 / nt as f64
    };
    let report = match report {
        Some(Ok(r)) => Some(r),
        Some(Err(e)) => anyhow::bail!("certificate check failed: {e}"),
        None => None,
    };
    // A failed write is reported after the figures, which are printed all the same.
    oom::phase(Phase::Writing);
    let written = args.out.output.as_ref().map(|path| {
        super::write_mesh_output(
            path,
            &mesh,
            &quality::recombined(&mesh, &table, &opt.chosen),
            args.out.vtu_ascii,
        )
    });
    if args.json {
        let mut v = serde_json::json!({
            "mesh": args.mesh,
            "triangles": nt,
            "algo": "optimum",
            "horizon": null,
            "seed": null,
            "quads": opt.quads,
            "triangles_left": opt.triangles_left,
            "recombined_pct": pct,
            "quality": opt.quality,
            "time_s": opt.time_s,
            "nodes_expanded": null,
            "trees": null,
        });
        super::add_element_fields(&mut v, &elements, rule);
        if let Some(r) = report {
            v["check"] = serde_json::json!({
                "ok": true,
                "edges_checked": r.edges_checked,
                "blossoms": r.blossoms,
                "positive_blossoms": r.positive_blossoms,
            });
        }
        outln!("{v}");
    } else {
        outln!("mesh            {}", args.mesh);
        outln!("triangles       {nt}");
        super::print_input_quads(&mesh);
        outln!("quads           {}", opt.quads);
        outln!("triangles left  {}", opt.triangles_left);
        outln!("recombined      {pct:.2} %");
        outln!("quality         {:.6} (sum of eta)", opt.quality);
        super::print_element_lines(&elements, rule);
        outln!("time            {:.4} s", opt.time_s);
        if let Some(r) = report {
            outln!(
                "certificate     ok ({} edges, {} blossoms, {} with positive dual)",
                r.edges_checked,
                r.blossoms,
                r.positive_blossoms
            );
        }
        if let (Some(p), Some(Ok(()))) = (&args.out.output, &written) {
            outln!("wrote           {}", p.display());
        }
    }
    written.transpose()?;
    Ok(ExitCode::SUCCESS)
}
