//! Exact optimum: maximum-weight maximum-cardinality matching on the dual graph ("Blossom-quad").
//!
//! Every triangle is a vertex, every candidate quad (pair of neighbouring triangles of the same
//! surface) an edge weighted by its eta. The optimum recombines as many triangles as any
//! matching can (all of them when a perfect matching exists, all but one per odd component)
//! and, among those, maximises the sum of eta. Weights are made exact integers
//! (`round(eta * 2^24)`) so that the solver compares without rounding; the reported quality is
//! the sum of the f64 eta of the chosen candidates. The solver is [`blossom`], a sparse
//! primal–dual blossom algorithm with a greedy jump-start and heap-driven lazy dual updates.

pub mod blossom;

use crate::mesh::Mesh;
use crate::quality::CandidateTable;
use std::time::Instant;

/// Scale of the integer weights: `w = round(eta * 2^24)`.
pub const WEIGHT_SCALE: f64 = (1u64 << 24) as f64;

/// The exact optimum of a mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct Optimum {
    /// Chosen candidates (indices into the candidate table), ascending.
    pub chosen: Vec<u32>,
    /// Sum of the f64 eta of the chosen candidates.
    pub quality: f64,
    /// Number of quads (`chosen.len()`).
    pub quads: usize,
    /// Triangles left unrecombined.
    pub triangles_left: usize,
    /// Seconds from the loaded mesh and table to the matching (graph build included).
    pub time_s: f64,
}

/// Integer weight of a candidate of quality `eta`.
pub fn weight(eta: f64) -> i64 {
    (eta.clamp(0.0, 1.0) * WEIGHT_SCALE).round() as i64
}

/// The dual graph of `table` with integer weights.
pub fn graph(mesh: &Mesh, table: &CandidateTable) -> blossom::Graph {
    blossom::Graph::from_edges(
        mesh.num_triangles(),
        table
            .pairs
            .iter()
            .zip(&table.eta)
            .map(|(&[a, b], &eta)| (a, b, weight(eta))),
    )
}

/// Maximum-weight matching of maximum cardinality of the dual graph, weights eta.
///
/// # Panics
/// When `table` was not built for `mesh` ([`CandidateTable::assert_fits`]).
pub fn solve(mesh: &Mesh, table: &CandidateTable) -> Optimum {
    table.assert_fits(mesh);
    solve_certified(mesh, table, false).0
}

/// Like [`solve`]; with `check`, also verifies the dual certificate of the result
/// (see [`blossom::Matching::check`]); the check is not counted in `time_s`.
pub fn solve_certified(
    mesh: &Mesh,
    table: &CandidateTable,
    check: bool,
) -> (Optimum, Option<Result<blossom::CheckReport, String>>) {
    let t0 = Instant::now();
    let g = graph(mesh, table);
    let m = blossom::solve(&g);
    let mut chosen: Vec<u32> = m
        .pairs()
        .map(|(u, v)| {
            table.by_triangle[u as usize]
                .into_iter()
                .find(|&c| c != crate::mesh::NONE && table.other(c, u) == v)
                .expect("matched pair is a candidate")
        })
        .collect();
    chosen.sort_unstable();
    let time_s = t0.elapsed().as_secs_f64();
    let quality = table.quality_of(&chosen);
    let quads = chosen.len();
    let report = check.then(|| m.check(&g));
    (
        Optimum {
            chosen,
            quality,
            quads,
            triangles_left: mesh.num_triangles() - 2 * quads,
            time_s,
        },
        report,
    )
}
