//! The report's opening: what was run (runs, configurations, meshes, versions, backends), under
//! which rule, on which machine and with which seeds.

use super::{Document, Results, Run};
use crate::experiment::plan;

/// Opening paragraph: what was run, where, by which version.
pub(super) fn overview(doc: &mut Document, results: &Results) {
    let runs: Vec<&Run> = results.groups.values().flatten().collect();
    let mut versions: Vec<&str> = runs.iter().map(|r| r.version.as_str()).collect();
    versions.sort_unstable();
    versions.dedup();
    let mut backends: Vec<&str> = runs.iter().map(|r| r.backend.as_str()).collect();
    backends.sort_unstable();
    backends.dedup();
    doc.para(format!(
        "{} runs in {} configurations on {} mesh(es), made by quadrecomb {} with eta computed by {}.",
        results.num_runs(),
        results.groups.len(),
        results.meshes.len(),
        versions.join(", "),
        backends.join(", "),
    ));
    if let Some(m) = &results.manifest {
        let (recorded, planned) = recorded_of_planned(results).unwrap_or_default();
        if recorded < planned {
            doc.para(format!(
                "Incomplete sweep: {recorded} of the {planned} runs planned {} are recorded (it \
                 was interrupted, or is still running). Run the same quadrecomb sweep command \
                 (the same flags, this directory as --out) with --resume to finish it. The medians, tests and figures below are over the \
                 recorded runs, so configurations may hold fewer runs than planned and \
                 different numbers of them.",
                m.shard
                    .map_or("in this directory".to_string(), |s| format!("in shard {s}")),
            ));
        }
    }
    if let Some((m, s)) = (results.manifest.as_ref()).and_then(|m| m.shard.map(|s| (m, s))) {
        doc.para(format!(
            "Shard {s} of a sweep: this directory holds {} of its {} runs, so each \
             configuration here has about 1/{} of the runs planned for it. Merge the shards \
             (quadrecomb merge DIR1 DIR2 ... --out DIR) for the whole sweep's report.",
            plan::shard(plan::plan(&m.spec), m.shard).len(),
            plan::plan(&m.spec).len(),
            s.count,
        ));
    }
    let mut rules: Vec<String> = runs.iter().map(|r| r.rule().to_string()).collect();
    rules.sort_unstable();
    rules.dedup();
    doc.para(format!(
        "Rule: {} (which pairs of triangles may be merged: set by --min-eta and --allow-invalid).",
        rules.join("; ")
    ));
    if let Some(m) = &results.manifest {
        let machine = |m: &crate::experiment::manifest::Machine| {
            format!("{} ({} logical cores), {}", m.cpu, m.cores, m.os)
        };
        if m.merged_from.is_empty() {
            doc.para(format!(
                "Machine: {}; {} worker thread(s). Base seed {}; {} runs per horizon, {} per \
                 baseline.",
                machine(&m.machine),
                m.threads,
                m.spec.seed,
                m.spec.runs,
                m.spec.baseline_runs,
            ));
        } else {
            let parts: Vec<String> = m
                .merged_from
                .iter()
                .map(|p| {
                    let builds = match p.builds.as_slice() {
                        [] => "build not recorded".to_string(),
                        b => format!("build {}", b.join(" then ")),
                    };
                    format!(
                        "{} ({} runs): {}, {builds}",
                        p.dir,
                        p.records,
                        machine(&p.machine)
                    )
                })
                .collect();
            doc.para(format!(
                "Merged from shards run on: {}. Base seed {}.",
                parts.join("; "),
                m.spec.seed
            ));
        }
        doc.para(builds(m, results.num_runs()));
    }
    if results.torn_bytes > 0 {
        doc.para(
            "The last line of runs.jsonl was torn (a run interrupted while being written) and is \
             not counted; quadrecomb sweep --resume redoes it.",
        );
    }
    let labels: Vec<String> = results
        .groups
        .iter()
        .map(|(c, r)| {
            let runs = if r.len() == 1 { "run" } else { "runs" };
            format!("{} {} ({} {runs})", c.mesh, c.label(), r.len())
        })
        .collect();
    doc.para(format!("Configurations: {}.", labels.join("; ")));
}

/// Which build ran which records ([`crate::experiment::manifest::Session`]), and that times
/// compare only within one build and machine.
pub(crate) fn builds(m: &crate::experiment::manifest::Manifest, records: usize) -> String {
    const CAVEAT: &str = "Times are of that build on that machine: compare them only with \
                          times of the same build and machine.";
    // Consecutive sessions of one build, as (build, first session's start, first record).
    let mut spans: Vec<(&str, &str, usize)> = Vec::new();
    for s in &m.sessions {
        if spans.last().is_none_or(|l| l.0 != s.build) {
            spans.push((&s.build, &s.started, s.runs_before));
        }
    }
    match spans.as_slice() {
        [] if m.merged_from.is_empty() => format!(
            "Build: not recorded (written before quadrecomb recorded its builds, 2026-12-05). \
             {CAVEAT}"
        ),
        [] => CAVEAT.to_string(),
        [(build, started, _)] => {
            let resumed = m.sessions.len() - 1;
            let resumed = match resumed {
                0 => String::new(),
                1 => ", resumed once".to_string(),
                n => format!(", resumed {n} times"),
            };
            format!("Build: {build} (sweep started {started}{resumed}). {CAVEAT}")
        }
        spans => {
            let parts: Vec<String> = spans
                .iter()
                .enumerate()
                .map(|(i, &(build, started, first))| {
                    let end = spans.get(i + 1).map_or(records, |n| n.2);
                    format!("records {}–{end} by {build} (started {started})", first + 1)
                })
                .collect();
            format!(
                "Builds: {}. Runs of different builds are mixed here: their times are not \
                 comparable with each other. {CAVEAT}",
                parts.join("; ")
            )
        }
    }
}

/// The runs recorded and the runs this directory's manifest plans (its shard's, for a
/// shard); `None` without a manifest.
pub(crate) fn recorded_of_planned(results: &Results) -> Option<(usize, usize)> {
    let m = results.manifest.as_ref()?;
    Some((
        results.num_runs(),
        plan::shard(plan::plan(&m.spec), m.shard).len(),
    ))
}

/// What a reader of the report alone would miss, one line each, for the command to print:
/// runs planned but not recorded, a torn last line.
pub(crate) fn warnings(results: &Results) -> Vec<String> {
    let mut out = Vec::new();
    if let Some((recorded, planned)) = recorded_of_planned(results)
        && recorded < planned
    {
        out.push(format!(
            "incomplete sweep: {recorded} of the {planned} planned runs are recorded, and the \
             report is over them; run the same sweep command with --resume to finish it"
        ));
    }
    if results.torn_bytes > 0 {
        out.push(
            "the last line of runs.jsonl is torn (a run interrupted while being written) and \
             not counted; sweep --resume redoes it"
                .to_string(),
        );
    }
    out
}
