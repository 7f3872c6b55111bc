//! Finishing what a policy leaves: leftover elimination, all-quad splits for odd components,
//! and local improvement, each by re-solving regions exactly with the blossom matcher of
//! [`crate::search::optimum`] (maximum cardinality, then maximum total eta, pairs the rule
//! allows only) with everything outside the region fixed. See docs/finish.md.
//!
//! Steps, in order: `leftovers` (each group of leftovers with k rings of quads around it,
//! k doubling until every leftover that can be paired is, or its component is proven to
//! leave it), [`all_quad`] (optional: one leftover per odd component moved to the boundary,
//! a boundary side split where [`split_choice`] proves it makes the component perfectly
//! matchable, eliminated again; the components no such split fixes refined by [`sheets`]),
//! `improve` (windows of r rings swept until a
//! pass gains nothing). Imports `mesh`, `quality` and `search::optimum` only.

pub mod all_quad;
mod improve;
mod leftovers;
mod region;
pub mod sheets;
pub mod split_choice;

pub use all_quad::Split;
pub use sheets::{SheetError, SheetStats};
pub use split_choice::{Stuck, StuckReason};

use crate::mesh::{Mesh, MeshError};
use crate::quality::{CandidateTable, Rule};
use region::{Pairing, RegionSolver, Rings};
use std::time::Instant;

/// Settings of a finish.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FinishConfig {
    /// Rings of quads around the leftovers in the first elimination round (k; doubled each
    /// round until every leftover is settled), at least 1.
    pub rings: u32,
    /// Rings of quads of each improvement window around its seed triangle (r); 0 skips
    /// improvement.
    pub window: u32,
    /// Make odd components even by splitting a boundary side (see [`all_quad`]).
    pub all_quad: bool,
    /// The rule the pairs obey (needed for the pairs a split makes).
    pub rule: Rule,
}

impl Default for FinishConfig {
    fn default() -> FinishConfig {
        FinishConfig {
            rings: DEFAULT_RINGS,
            window: DEFAULT_WINDOW,
            all_quad: false,
            rule: Rule::default(),
        }
    }
}

/// Why a finish failed.
#[derive(Debug, thiserror::Error)]
pub enum FinishError {
    /// All-quad's split made an invalid mesh (it should not: boundary sides halved).
    #[error("all-quad split: {0}")]
    Mesh(#[from] MeshError),
    /// All-quad's sheet refinement cannot refine the mesh (a side shared with an input quad,
    /// a degenerate triangle).
    #[error(transparent)]
    Sheet(#[from] SheetError),
    /// The split mesh still leaves triangles although each split was checked to make its
    /// component perfectly matchable (a bug).
    #[error(
        "all-quad: the split mesh still leaves {0} triangles, although each split was checked to make its component perfectly matchable (a bug)"
    )]
    SplitLeft(usize),
}

/// Default first ring count of elimination.
pub const DEFAULT_RINGS: u32 = 2;
/// Default improvement window, in rings.
pub const DEFAULT_WINDOW: u32 = 8;

/// The figures of a pairing after one step.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct StepFigures {
    /// Quads made.
    pub quads: usize,
    /// Triangles left.
    pub triangles_left: usize,
    /// Sum of eta of the quads.
    pub quality: f64,
    /// Seconds the step took.
    pub time_s: f64,
}

/// Counters of a finish, for benchmarks and the docs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FinishStats {
    /// Regions re-solved by elimination (both rounds when all-quad split).
    pub regions: usize,
    /// The largest ring count elimination reached.
    pub max_rings: u32,
    /// Improvement passes (the last gained nothing).
    pub passes: usize,
    /// Improvement windows solved.
    pub windows: usize,
    /// Windows whose new pairing was kept.
    pub kept: usize,
}

/// A finished pairing.
#[derive(Debug, Clone)]
pub struct Finished {
    /// Chosen candidates, ascending: indices into the input table, or into [`Finished::table`]
    /// when all-quad split triangles.
    pub chosen: Vec<u32>,
    /// The figures after leftover elimination.
    pub eliminated: StepFigures,
    /// The figures after all-quad (`None` without `all_quad`); `time_s` includes the second
    /// elimination.
    pub all_quad: Option<StepFigures>,
    /// The figures after local improvement: the result.
    pub improved: StepFigures,
    /// The sides split by all-quad (empty without it, or when nothing was odd).
    pub splits: Vec<Split>,
    /// What all-quad's sheet refinement changed (zero when single splits sufficed).
    pub sheets: SheetStats,
    /// The mesh with the split triangles, when all-quad split any.
    pub mesh: Option<Mesh>,
    /// Its candidate table under the same rule.
    pub table: Option<CandidateTable>,
    /// Counters.
    pub stats: FinishStats,
}

impl Finished {
    /// The whole time of the finish.
    pub fn time_s(&self) -> f64 {
        self.eliminated.time_s + self.all_quad.map_or(0.0, |s| s.time_s) + self.improved.time_s
    }

    /// The mesh the result pairs (`input` unless all-quad split triangles).
    pub fn mesh<'a>(&'a self, input: &'a Mesh) -> &'a Mesh {
        self.mesh.as_ref().unwrap_or(input)
    }

    /// The candidate table `chosen` indexes.
    pub fn table<'a>(&'a self, input: &'a CandidateTable) -> &'a CandidateTable {
        self.table.as_ref().unwrap_or(input)
    }
}

fn figures(table: &CandidateTable, pairing: &Pairing, time_s: f64) -> StepFigures {
    let chosen = pairing.chosen(table);
    StepFigures {
        quads: chosen.len(),
        triangles_left: pairing.cand.len() - 2 * chosen.len(),
        quality: table.quality_of(&chosen),
        time_s,
    }
}

/// Finishes the pairing `chosen` (candidates of `table`, a matching) of `mesh`. Errors only
/// with all-quad: when sheet refinement cannot refine a component no boundary split fixes
/// ([`FinishError::Sheet`]: a sheet meets an input quad, a degenerate triangle), or (a bug)
/// when a split goes wrong.
///
/// # Panics
/// When `table` was not built for `mesh` ([`CandidateTable::assert_fits`]), or `chosen` is
/// not a matching of its candidates.
pub fn finish(
    mesh: &Mesh,
    table: &CandidateTable,
    chosen: &[u32],
    config: FinishConfig,
) -> Result<Finished, FinishError> {
    table.assert_fits(mesh);
    let nt = mesh.num_triangles();
    let mut stats = FinishStats::default();
    let t0 = Instant::now();
    let mut pairing = Pairing::new(nt, table, chosen);
    let mut rings = Rings::new(nt);
    let mut solver = RegionSolver::new(nt);
    let e = leftovers::eliminate(table, &mut pairing, &mut rings, &mut solver, config.rings);
    stats.regions += e.regions;
    stats.max_rings = e.max_rings;
    let eliminated = figures(table, &pairing, t0.elapsed().as_secs_f64());

    let mut split_mesh = None;
    let mut all_quad = None;
    let mut splits = Vec::new();
    let mut sheet_stats = SheetStats::default();
    if config.all_quad {
        let t1 = Instant::now();
        if pairing.leftovers().next().is_some() {
            let chosen = split_choice::choose(
                mesh,
                table,
                &pairing,
                config.rule,
                config.rings,
                &mut stats.regions,
            );
            let stuck = chosen.stuck.len();
            if !chosen.choices.is_empty() {
                let s = all_quad::split(mesh, table, &chosen, config.rule)?;
                let n = s.mesh.num_triangles();
                let mut p = s.pairing;
                (rings, solver) = (Rings::new(n), RegionSolver::new(n));
                // Pairs a half whose pair the new table computed otherwise (rounding) too.
                let e =
                    leftovers::eliminate(&s.table, &mut p, &mut rings, &mut solver, config.rings);
                stats.regions += e.regions;
                stats.max_rings = stats.max_rings.max(e.max_rings);
                pairing = p;
                splits = s.splits;
                split_mesh = Some((s.mesh, s.table));
            } else {
                pairing = chosen.pairing;
            }
            let left = pairing.leftovers().count();
            if left > 0 && stuck == 0 {
                return Err(FinishError::SplitLeft(left));
            }
            if left > 0 {
                // The components no single split fixes: sheet refinement.
                let (m, t) = split_mesh.as_ref().map_or((mesh, table), |(m, t)| (m, t));
                let r = sheets::refine(m, t, &pairing, config.rule)?;
                let n = r.mesh.num_triangles();
                (rings, solver) = (Rings::new(n), RegionSolver::new(n));
                pairing = r.pairing;
                sheet_stats = r.stats;
                split_mesh = Some((r.mesh, r.table));
            }
        }
        let t = split_mesh.as_ref().map_or(table, |(_, t)| t);
        all_quad = Some(figures(t, &pairing, t1.elapsed().as_secs_f64()));
    }
    let t = split_mesh.as_ref().map_or(table, |(_, t)| t);
    let t2 = Instant::now();
    if config.window > 0 {
        let i = improve::improve(t, &mut pairing, &mut rings, &mut solver, config.window);
        stats.passes = i.passes;
        stats.windows = i.windows;
        stats.kept = i.kept;
    }
    let improved = figures(t, &pairing, t2.elapsed().as_secs_f64());
    let chosen = pairing.chosen(t);
    let (mesh, table) = match split_mesh {
        Some((m, t)) => (Some(m), Some(t)),
        None => (None, None),
    };
    Ok(Finished {
        chosen,
        eliminated,
        all_quad,
        improved,
        splits,
        sheets: sheet_stats,
        mesh,
        table,
        stats,
    })
}
