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
/// compare only within one build and machine. Records before the first session are a
/// merge's parts' (named with their builds above) or, in a directory written before builds
/// were recorded, of a build not recorded; sessions that added no record are left out; a
/// list that contradicts the run log is said to be unusable rather than read.
pub(crate) fn builds(m: &crate::experiment::manifest::Manifest, records: usize) -> String {
    const CAVEAT: &str = "Times are of the build that ran them on that machine: compare them \
                          only with times of the same build and machine.";
    const MIXED: &str = "Runs of different builds are mixed here: their times are not \
                         comparable with each other.";
    let merged = !m.merged_from.is_empty();
    let parts_builds: Vec<&str> = (m.merged_from.iter())
        .flat_map(|p| {
            if p.builds.is_empty() {
                vec!["not recorded"]
            } else {
                p.builds.iter().map(String::as_str).collect()
            }
        })
        .collect();
    fn known(b: &str) -> &str {
        if b.is_empty() { "unknown" } else { b }
    }
    // (who ran them, start, first record): the records before the first session, then each
    // session's.
    let mut spans: Vec<(String, Option<&str>, usize)> = Vec::new();
    let first = m.sessions.first().map_or(records, |s| s.runs_before);
    if first > 0 {
        let who = if merged {
            "the merged parts (above)".to_string()
        } else {
            "a build not recorded (written before quadrecomb recorded its builds, \
             2026-12-05)"
                .to_string()
        };
        spans.push((who, None, 0));
    }
    let mut last = 0;
    for s in &m.sessions {
        if s.runs_before < last || s.runs_before > records {
            return format!(
                "Builds: the manifest's list of sessions does not fit the {records} records of \
                 runs.jsonl (a session after {} records, after one after {last}), so which \
                 build ran which records is unknown. {CAVEAT}",
                s.runs_before
            );
        }
        last = s.runs_before;
        match spans.last_mut() {
            // A session that added no record, or the same build resumed: one span.
            Some(l) if l.2 == s.runs_before => {
                *l = (known(&s.build).to_string(), Some(&s.started), l.2);
            }
            Some(l) if l.1.is_some() && l.0 == known(&s.build) => {}
            _ => spans.push((known(&s.build).to_string(), Some(&s.started), s.runs_before)),
        }
    }
    // A last session that added nothing.
    if spans.len() > 1 && spans.last().is_some_and(|l| l.2 >= records) {
        spans.pop();
    }
    let mut distinct: Vec<&str> = spans
        .iter()
        .filter(|s| s.1.is_some())
        .map(|s| s.0.as_str())
        .collect();
    if first > 0 {
        if merged {
            distinct.extend(&parts_builds);
        } else {
            distinct.push("not recorded");
        }
    }
    distinct.sort_unstable();
    distinct.dedup();
    let mixed = if distinct.len() > 1 { MIXED } else { "" };
    match spans.as_slice() {
        [] => CAVEAT.to_string(),
        [(who, Some(started), 0)] => {
            // The resumes that added runs.
            let added = (m.sessions.iter().skip(1))
                .filter(|s| s.runs_before < records)
                .count();
            let resumed = match added {
                0 => String::new(),
                1 => ", resumed once".to_string(),
                n => format!(", resumed {n} times"),
            };
            format!("Build: {who} (sweep started {started}{resumed}). {CAVEAT}")
        }
        [(_, None, _)] if merged => format!("{mixed} {CAVEAT}").trim_start().to_string(),
        [(who, None, _)] => format!("Build: {who}. {CAVEAT}"),
        spans => {
            const SHOWN: usize = 8;
            let mut parts: Vec<String> = (spans.iter().enumerate().take(SHOWN))
                .map(|(i, (who, started, first))| {
                    let end = spans.get(i + 1).map_or(records, |n| n.2);
                    let when = started.map_or(String::new(), |s| format!(" (started {s})"));
                    format!("records {}–{end} by {who}{when}", first + 1)
                })
                .collect();
            if spans.len() > SHOWN {
                parts.push(format!("and {} more spans", spans.len() - SHOWN));
            }
            format!("Builds: {}. {mixed} {CAVEAT}", parts.join("; ")).replace("  ", " ")
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
