//! Leftover elimination: each group of leftover triangles with k rings of quads around it is
//! re-solved exactly (maximum cardinality first) with everything outside fixed; k doubles
//! until every leftover that can be paired is, or its component is proven to have no
//! matching that pairs it.

use super::region::{Accept, Pairing, RegionSolver, Rings};
use crate::quality::CandidateTable;

/// What elimination found.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Elimination {
    /// Regions re-solved.
    pub regions: usize,
    /// Rounds of growth (k doubles each round).
    pub rounds: usize,
    /// The largest k used.
    pub max_rings: u32,
}

/// Pairs the leftovers of `pairing` that can be paired. A leftover is settled when its
/// component (of the dual graph of allowed pairs) has as many leftovers as a maximum matching
/// must leave: one in an odd component by parity, or all that remain once a region covering
/// the whole component has been solved exactly.
pub(crate) fn eliminate(
    table: &CandidateTable,
    pairing: &mut Pairing,
    rings: &mut Rings,
    solver: &mut RegionSolver,
    first_rings: u32,
) -> Elimination {
    let nt = pairing.cand.len();
    let (component, sizes) = CandidateTable::components(&table.dual_graph());
    let mut proven = vec![false; sizes.len()];
    let mut left = vec![0u32; sizes.len()];
    let mut out = Elimination::default();
    let mut k = first_rings.max(1);
    let mut active = Vec::new();
    loop {
        left.fill(0);
        for t in pairing.leftovers() {
            left[component[t as usize] as usize] += 1;
        }
        active.clear();
        active.extend(pairing.leftovers().filter(|&t| {
            let c = component[t as usize] as usize;
            !proven[c] && left[c] > sizes[c] % 2
        }));
        if active.is_empty() {
            break;
        }
        out.rounds += 1;
        out.max_rings = k;
        rings.grow(table, pairing, &active, k);
        let mut groups: Vec<(Vec<u32>, bool)> = Vec::new();
        rings.groups(table, |g, closed| groups.push((g.to_vec(), closed)));
        for (group, closed) in groups {
            out.regions += 1;
            solver.solve(table, pairing, &group, Accept::MoreQuadsFirst);
            if closed {
                // The region is whole components, solved exactly: what is left there stays.
                for &t in &group {
                    proven[component[t as usize] as usize] = true;
                }
            }
        }
        // Past the whole mesh every group is closed; this only bounds k's type.
        k = k.saturating_mul(2).min(nt as u32 + 1);
    }
    out
}
