//! Typical runs for the mesh pictures: the median-quality run of a configuration, re-run from
//! its recorded seed on the same mesh with the same eta.
//!
//! Runs are deterministic given (mesh, eta table, algorithm, seed), so re-running reproduces a
//! recorded run exactly when the eta table is bit-for-bit the one the sweep used. The sweep
//! records which evaluator filled eta (`backend`) and, in the manifest, a hash of the table
//! (`eta_hash`). The table is rebuilt with the recorded evaluator where it can be opened here,
//! else with the CPU twin, else with the f64 reference ([`CandidateTable::build`]); the first
//! whose hash matches the manifest's is used. Whether the re-run reproduced the record (same
//! quads and quality) is checked and said in the picture's caption.

use super::results::{Results, Run};
use crate::experiment::{mesh_hash, seed::eta_hash};
use crate::gpu::{Backend, Evaluator};
use crate::mesh::{Mesh, Recombined};
use crate::quality::{CandidateTable, recombined};
use crate::search::{self, Algo};
use std::collections::HashMap;

/// The run shown as typical of a configuration: the median by quality (the lower middle one
/// for an even count; ties broken by run index).
pub fn median_run(runs: &[Run]) -> Option<&Run> {
    let mut order: Vec<&Run> = runs.iter().collect();
    order.sort_by(|a, b| a.quality.total_cmp(&b.quality).then(a.run.cmp(&b.run)));
    order.get(order.len().saturating_sub(1) / 2).copied()
}

/// A mesh and its eta table as rebuilt for re-running, with how the table was obtained.
#[derive(Debug)]
struct Prepared {
    mesh: Mesh,
    table: CandidateTable,
    /// Which evaluator filled the table, and whether its hash matched the manifest's.
    eta_note: String,
}

/// Rebuilds meshes and tables once per mesh, and re-runs typical runs.
#[derive(Debug, Default)]
pub struct Rerunner {
    prepared: HashMap<String, Result<Prepared, String>>,
}

/// A re-run typical run, ready to draw.
#[derive(Debug)]
pub struct Typical<'a> {
    /// The mesh.
    pub mesh: &'a Mesh,
    /// Its recombination.
    pub rec: Recombined,
    /// What was re-run and whether it reproduced the record, for the caption.
    pub note: String,
}

impl Rerunner {
    /// Re-runs `run` of `results`; an error in words when it cannot (mesh not found or
    /// changed, unknown algorithm).
    pub fn rerun<'a>(&'a mut self, results: &Results, run: &Run) -> Result<Typical<'a>, String> {
        let algo = Algo::from_name(&run.algo, run.horizon.unwrap_or(1))
            .map_err(|e| format!("cannot re-run {}: {e}", run.algo))?;
        let prepared = self
            .prepared
            .entry(run.mesh.clone())
            .or_insert_with(|| prepare(results, run))
            .as_ref()
            .map_err(Clone::clone)?;
        let out = search::run(&prepared.mesh, &prepared.table, algo, run.seed);
        let same = out.quads == run.quads
            && (out.quality - run.quality).abs() <= 1e-9 * run.quality.abs().max(1.0);
        let label = match run.horizon {
            Some(h) => format!("{} h={h}", run.algo),
            None => run.algo.clone(),
        };
        let verdict = if same {
            "the re-run reproduces the recorded quads and quality exactly".to_string()
        } else {
            format!(
                "the re-run gives {} quads and quality {:.4} where the record has {} and {:.4} \
                 (eta differs from the sweep's)",
                out.quads, out.quality, run.quads, run.quality
            )
        };
        let note = format!(
            "{label}, run {} (seed {}), the median run by quality: {} quads, {} triangles left, \
             quality {:.4}{}. Re-run from its seed with eta from {}; {verdict}.",
            run.run,
            run.seed,
            out.quads,
            out.triangles_left,
            out.quality,
            run.quality_pct
                .map_or(String::new(), |p| format!(" ({p:.2}% of optimum recorded)")),
            prepared.eta_note,
        );
        Ok(Typical {
            mesh: &prepared.mesh,
            rec: recombined(&prepared.mesh, &prepared.table, &out.chosen),
            note,
        })
    }
}

/// Loads the mesh of `run` (its source in the manifest, else its name) and rebuilds the eta
/// table that matches the sweep's.
fn prepare(results: &Results, run: &Run) -> Result<Prepared, String> {
    let manifest = results.manifest.as_ref();
    let entry = manifest.and_then(|m| m.spec.meshes.iter().find(|e| e.name == run.mesh));
    let source = entry.map_or(run.mesh.clone(), |e| e.source.clone());
    // Where the mesh may be: the source as given (from this working directory), the absolute
    // path the sweep recorded, the source relative to the results directory, and the built-in
    // of that name. Loaded in that order until one has the recorded hash.
    let mut places: Vec<String> = vec![source.clone()];
    places.extend(entry.and_then(|e| e.path.clone()));
    let beside = results.dir.join(&source);
    if beside.is_file() {
        places.push(beside.to_string_lossy().into_owned());
    }
    let builtin = crate::mesh::builtin::bytes(&source).map(|bytes| crate::mesh::Source {
        path: source.clone().into(),
        builtin: true,
        bytes: bytes.into(),
    });
    let loads = (places.iter().map(|p| crate::mesh::load(p)))
        .chain(builtin.map(|src| src.mesh()))
        .map(|m| m.map_err(|e| e.to_string()));
    let (mut first_err, mut other_hash) = (None, None);
    let mut found = None;
    for loaded in loads {
        match loaded {
            Ok(m) => {
                let hash = mesh_hash(&m);
                if run.mesh_hash.is_empty() || hash == run.mesh_hash {
                    found = Some(m);
                    break;
                }
                other_hash.get_or_insert(hash);
            }
            Err(e) => {
                first_err.get_or_insert(e);
            }
        }
    }
    let mesh = match (found, other_hash) {
        (Some(m), _) => m,
        (None, Some(hash)) => {
            return Err(format!(
                "mesh {source} has changed since the sweep (hash {} vs recorded {})",
                &hash[..12.min(hash.len())],
                &run.mesh_hash[..12.min(run.mesh_hash.len())]
            ));
        }
        (None, None) => {
            let why = first_err.unwrap_or_default();
            return Err(format!("cannot load mesh {source}: {why}"));
        }
    };
    let want = manifest
        .and_then(|m| m.optimum.iter().find(|o| o.mesh == run.mesh))
        .map(|o| o.eta_hash.clone());
    // Candidate evaluators, the recorded one first.
    let mut tried: Vec<(String, CandidateTable)> = Vec::new();
    let fill = |ev: &Evaluator| -> Option<CandidateTable> {
        let mut table = CandidateTable::topology_only(&mesh);
        ev.fill(&mut [(&mesh, &mut table)]).ok()?;
        Some(table)
    };
    if run.backend == "cpu-twin" {
        if let Some(t) = fill(&Evaluator::cpu_twin()) {
            tried.push(("the CPU twin (as recorded)".into(), t));
        }
    } else if let Ok(ev) = Evaluator::new(Backend::Gpu) {
        if let Some(t) = fill(&ev) {
            let same = ev.name() == run.backend;
            let what = if same {
                format!("{} (as recorded)", ev.name())
            } else {
                format!("{} (the sweep used {})", ev.name(), run.backend)
            };
            tried.push((what, t));
        }
    }
    if run.backend != "cpu-twin" {
        if let Some(t) = fill(&Evaluator::cpu_twin()) {
            tried.push((format!("the CPU twin (the sweep used {})", run.backend), t));
        }
    }
    tried.push((
        format!("the f64 reference (the sweep used {})", run.backend),
        CandidateTable::build(&mesh),
    ));
    // The pairs the run's rule allowed: the manifest's eta hash is over those.
    let rule = run.rule();
    let mut tried: Vec<(String, CandidateTable)> = (tried.into_iter())
        .map(|(what, t)| (what, t.restrict(&mesh, rule)))
        .collect();
    let pick = match &want {
        Some(h) => tried.iter().position(|(_, t)| &eta_hash(&t.eta) == h),
        None => None,
    };
    let (i, matched) = match pick {
        Some(i) => (i, "its eta hash matches the manifest's"),
        None if want.is_some() => (0, "no evaluator here reproduces the manifest's eta hash"),
        None => (0, "no manifest to check the eta hash against"),
    };
    let (what, table) = tried.swap_remove(i);
    Ok(Prepared {
        mesh,
        table,
        eta_note: format!("{what}; {matched}"),
    })
}
