//! Local improvement: windows of r rings of quads swept across the mesh, each re-solved
//! exactly with its boundary fixed, a new pairing kept only when it raises the total eta
//! (with no fewer quads). A pass seeds a window at every triangle not yet inside the inner
//! half of an earlier window, so windows overlap and each costs a bounded amount: a pass is
//! linear in the mesh. Later passes only revisit windows within reach of a change; the sweep
//! stops when a pass changes nothing.

use super::region::{Accept, Pairing, RegionSolver, Rings};
use crate::quality::CandidateTable;

/// What improvement did.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Improvement {
    /// Passes made (the last changed nothing).
    pub passes: usize,
    /// Windows solved.
    pub windows: usize,
    /// Windows whose new pairing was kept.
    pub kept: usize,
}

/// Sweeps windows of `window` rings until a pass gains nothing.
pub(crate) fn improve(
    table: &CandidateTable,
    pairing: &mut Pairing,
    rings: &mut Rings,
    solver: &mut RegionSolver,
    window: u32,
) -> Improvement {
    let nt = pairing.cand.len();
    let core = window.div_ceil(2) as usize;
    let mut out = Improvement::default();
    // Seeds worth a window this pass (all in the first).
    let mut hot = vec![true; nt];
    let mut covered = vec![false; nt];
    let mut changed: Vec<u32> = Vec::new();
    loop {
        out.passes += 1;
        covered.fill(false);
        changed.clear();
        for t in 0..nt as u32 {
            if !hot[t as usize] || covered[t as usize] {
                continue;
            }
            rings.grow(table, pairing, &[t], window);
            let inner = rings.ends[core.min(rings.ends.len() - 1)];
            for &u in &rings.members[..inner] {
                covered[u as usize] = true;
            }
            out.windows += 1;
            let region = std::mem::take(&mut rings.members);
            if solver.solve(table, pairing, &region, Accept::HigherEta) {
                out.kept += 1;
                changed.extend_from_slice(&region);
            }
            rings.members = region;
        }
        if changed.is_empty() {
            break;
        }
        // Next pass: the seeds whose windows reach a changed triangle.
        hot.fill(false);
        changed.sort_unstable();
        changed.dedup();
        rings.grow(table, pairing, &changed, window);
        for &u in &rings.members {
            hot[u as usize] = true;
        }
    }
    out
}
