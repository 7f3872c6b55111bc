//! `quadrecomb suite list`: the benchmark suite's meshes (`suite:NAME`), their sizes and what
//! each one tests, and the named suites `sweep --suite` takes.

use std::process::ExitCode;

use quadrecomb::internals::mesh::suite::{self, MEMBERS, SUITES};

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, clap::Subcommand)]
enum Command {
    /// List the suite's meshes (name, triangles, odd components, family, what each tests) and
    /// the named suites of `sweep --suite`.
    List(ListArgs),
}

#[derive(Debug, clap::Args)]
struct ListArgs {
    /// Only the members of this suite (default, small, full).
    #[arg(long, value_name = "SUITE")]
    suite: Option<String>,
    /// One JSON object on stdout: `members` (name, spec, triangles, odd_components, family,
    /// tests, origin, suites) and `suites` (name, members, about).
    #[arg(long)]
    json: bool,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    match args.command {
        Command::List(a) => list(a),
    }
}

fn list(args: ListArgs) -> anyhow::Result<ExitCode> {
    let members = match &args.suite {
        Some(name) => suite::suite(name).ok_or_else(|| {
            super::UsageError(format!(
                "--suite {name:?}: no such suite (suites: {})",
                suite::suite_names()
            ))
        })?,
        None => MEMBERS.iter().collect(),
    };
    let suites_of = |name: &str| -> Vec<&str> {
        (SUITES.iter())
            .filter(|(s, _, _)| suite::suite(s).is_some_and(|m| m.iter().any(|m| m.name == name)))
            .map(|(s, _, _)| *s)
            .collect()
    };
    if args.json {
        let v = serde_json::json!({
            "members": members.iter().map(|m| serde_json::json!({
                "name": m.name,
                "spec": suite::spec(m),
                "triangles": m.triangles,
                "odd_components": m.odd_components,
                "family": m.family,
                "tests": m.tests,
                "origin": m.origin_text(),
                "suites": suites_of(m.name),
            })).collect::<Vec<_>>(),
            "suites": SUITES.iter().map(|(name, _, about)| serde_json::json!({
                "name": name,
                "members": suite::suite(name).unwrap_or_default().iter().map(|m| m.name).collect::<Vec<_>>(),
                "about": about,
            })).collect::<Vec<_>>(),
        });
        outln!("{v}");
        return Ok(ExitCode::SUCCESS);
    }
    let width = members.iter().map(|m| m.name.len()).max().unwrap_or(4);
    outln!(
        "{:<width$}  {:>9}  {:>4}  {:<10}  what it tests",
        "name",
        "triangles",
        "odd",
        "family"
    );
    for m in &members {
        outln!(
            "{:<width$}  {:>9}  {:>4}  {:<10}  {}",
            m.name,
            m.triangles,
            m.odd_components,
            m.family,
            m.tests
        );
    }
    outln!();
    outln!("Use a member as --mesh suite:NAME (any command that takes a mesh).");
    for (name, _, about) in SUITES {
        let n = suite::suite(name).map_or(0, |m| m.len());
        outln!("sweep --suite {name}: {n} meshes, {about}");
    }
    Ok(ExitCode::SUCCESS)
}
