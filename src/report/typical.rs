//! Typical runs for the mesh pictures: the median-quality run of a configuration, replayed
//! by [`crate::experiment::replay`] (same mesh, same eta, same rule, from its seed), with a
//! caption that says how eta was rebuilt and whether the replay reproduced the record.

use super::results::Run;
use crate::experiment::replay::Replayer;
use crate::mesh::{Mesh, Recombined};

pub use crate::experiment::replay::typical_run as median_run;

/// A replayed typical run, ready to draw.
#[derive(Debug)]
pub struct Typical<'a> {
    /// The mesh.
    pub mesh: &'a Mesh,
    /// Its recombination.
    pub rec: Recombined,
    /// What was re-run and whether it reproduced the record, for the caption.
    pub note: String,
}

/// Replays `run` with `replayer`; an error in words when it cannot (mesh not found or
/// changed, unknown algorithm).
pub fn rerun<'a>(replayer: &'a mut Replayer<'_>, run: &Run) -> Result<Typical<'a>, String> {
    let out = replayer.replay(run).map_err(|e| e.to_string())?;
    let label = match run.horizon {
        Some(h) => format!("{} h={h}", run.algo),
        None => run.algo.clone(),
    };
    let verdict = if out.reproduced {
        "the re-run reproduces the recorded quads and quality exactly".to_string()
    } else {
        format!(
            "the re-run gives {} quads and quality {:.4} where the record has {} and {:.4} \
             (eta differs from the sweep's)",
            out.quads, out.quality, run.quads, run.quality
        )
    };
    // The optimum has no seed to re-run from: its matching is computed again.
    if !crate::experiment::record::is_search(&run.algo) {
        let note = format!(
            "optimum (maximum-weight matching of maximum cardinality): {} quads, {} triangles left, quality {:.4}. \
             Matching computed again with eta from {}; {verdict}.",
            out.quads,
            out.triangles_left,
            out.quality,
            out.eta_note(),
        );
        return Ok(Typical {
            mesh: out.mesh,
            rec: out.recombined,
            note,
        });
    }
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
        out.eta_note(),
    );
    Ok(Typical {
        mesh: out.mesh,
        rec: out.recombined,
        note,
    })
}
