//! Where all-quad splits. Splitting a boundary side of triangle `s` (a node `m` on the side,
//! joined to the opposite corner) makes two halves `A`, `B`; their own pair is a degenerate
//! quad (a straight angle at `m`), so `A` can only pair with `n1` and `B` with `n2`, the
//! triangles across `s`'s two inner sides. The split component has a perfect matching iff the
//! dual graph less `{s, n1, n2}` has one there. Which `s` qualifies is a question of the
//! graph, not of where the leftover happens to be: on a lattice (a bipartite dual graph) an
//! odd component has one colour in excess, and splitting a triangle of that colour leaves
//! the imbalance at two, whatever alternating path led there.
//!
//! The choice, per odd component that keeps one leftover `t`:
//! 1. a necessary condition from the Gallai–Edmonds decomposition: when `s`–`n1` and
//!    `s`–`n2` are both allowed pairs, a perfect matching `M'` of the rest gives the matching
//!    `M' + (s, n1)` of the component that misses only `n2`, so `n1` and `n2` must both lie in
//!    `D` (the triangles some maximum matching misses). `D` is the set reached from `t` by
//!    even alternating paths; it is bounded here from above by the triangles reached by even
//!    alternating *walks* (a search that shrinks no blossom), which is `D` itself when the
//!    graph is bipartite. Candidates failing it are ruled out without a solve;
//! 2. the candidates left, nearest to `t` first, are checked exactly: `s`, `n1`, `n2` are taken
//!    out of the pairing (their mates freed), and rings of quads grown around the free
//!    triangles are re-solved with the blossom matcher, everything outside fixed, the ring
//!    count doubling until all are paired (the split works) or the region covers what is left
//!    of the components and still leaves some (it cannot work). The first that works is taken.

use super::region::{Accept, Pairing, RegionSolver, Rings};
use crate::mesh::{Mesh, NONE};
use crate::quality::{CandidateTable, Rule};
use std::collections::{BTreeMap, VecDeque};

/// A split chosen: the triangle, the index of its boundary side, its distance from the
/// leftover (pairs crossed).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Choice {
    pub triangle: u32,
    pub side: usize,
    pub steps: usize,
}

/// The splits chosen and the pairing of the unsplit mesh that goes with them: a perfect
/// matching of every component a split touches, less the split triangles and their two
/// inner neighbours (left unpaired: they pair with the halves once the mesh is split).
pub(crate) struct Chosen {
    pub choices: Vec<Choice>,
    pub pairing: Pairing,
    /// The components no split fixes (their leftovers stay in `pairing`).
    pub stuck: Vec<Stuck>,
}

/// Why no boundary split makes a component perfectly matchable.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum StuckReason {
    /// The component's best pairing leaves more triangles than one split can remove (a
    /// split adds one triangle and lowers what must stay by at most one).
    TooManyLeft,
    /// No triangle of the component has a boundary side whose halves would both make a
    /// quad the rule allows with the triangle across their other side.
    NoSplittableSide,
    /// Every splittable side was checked, and none leaves the rest perfectly matchable.
    NoneWorks {
        /// Splittable sides of the component.
        candidates: usize,
        /// Of those, ruled out by the Gallai–Edmonds condition (no solve needed).
        ruled_out: usize,
        /// Of those, proven not to work by an exact re-solve.
        solved: usize,
    },
}

/// A component all-quad cannot make perfectly matchable.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Stuck {
    /// Element tag of a triangle it leaves.
    pub element: u64,
    /// Its surface tag.
    pub surface: i32,
    /// Triangles in the component (of the dual graph of allowed pairs).
    pub size: usize,
    /// Triangles its best pairing leaves.
    pub left: usize,
    /// Why no split helps.
    pub reason: StuckReason,
}

impl std::fmt::Display for Stuck {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "the component of {} triangles holding element {} (surface {}) keeps {} triangle{}: ",
            self.size,
            self.element,
            self.surface,
            self.left,
            if self.left == 1 { "" } else { "s" }
        )?;
        match self.reason {
            StuckReason::TooManyLeft => write!(
                f,
                "{}, and one boundary split adds a triangle and lowers what must stay by at most one",
                if self.size.is_multiple_of(2) {
                    "it is even but has no perfect matching"
                } else {
                    "more than its parity asks"
                }
            ),
            StuckReason::NoSplittableSide => write!(
                f,
                "none of its triangles has a boundary side whose two halves would each make a \
                 quad the rule allows with the triangle across their other side"
            ),
            StuckReason::NoneWorks {
                candidates,
                ruled_out,
                solved,
            } => write!(
                f,
                "none of its {candidates} splittable boundary sides leaves the rest perfectly \
                 matchable ({ruled_out} ruled out by the Gallai-Edmonds condition, {solved} by \
                 an exact re-solve)"
            ),
        }
    }
}

/// The boundary side of `s` all-quad can split, with the triangles across its two other
/// sides: `(side, n1, n2)`, `n1` across the side after the split one's second corner (it pairs
/// with the half at the side's first corner), `n2` across the other. A side used by no other
/// element (a side next to another surface or an input quad is no boundary) whose halves
/// would each make a quad `rule` allows with the triangle across their inner side.
pub(crate) fn split_side(
    mesh: &Mesh,
    triangle_edges: &[[u32; 3]],
    is_boundary: &[bool],
    rule: Rule,
    s: u32,
) -> Option<(usize, u32, u32)> {
    let tri = mesh.triangles[s as usize];
    let nb = mesh.topology.neighbours[s as usize];
    let at = |v: u32| mesh.vertices[v as usize];
    // The vertex of the triangle across side `j` of `s` opposite that side.
    let across = |j: usize| -> Option<u32> {
        let u = nb[j];
        if u == NONE {
            return None;
        }
        let (a, b) = (tri[j], tri[(j + 1) % 3]);
        mesh.triangles[u as usize]
            .into_iter()
            .find(|&v| v != a && v != b)
    };
    (0..3).find_map(|i| {
        if nb[i] != NONE || !is_boundary[triangle_edges[s as usize][i] as usize] {
            return None;
        }
        let (p, q, o) = (tri[i], tri[(i + 1) % 3], tri[(i + 2) % 3]);
        let (pp, pq) = (at(p), at(q));
        let m: [f64; 3] = std::array::from_fn(|d| 0.5 * (pp[d] + pq[d]));
        let (o_qo, o_op) = (across((i + 1) % 3)?, across((i + 2) % 3)?);
        // Half (p, m, o) with the triangle across o-p; half (m, q, o) across q-o.
        let first = [at(o), at(o_op), pp, m];
        let second = [pq, at(o_qo), at(o), m];
        (rule.allows_quad(first) && rule.allows_quad(second)).then_some((
            i,
            nb[(i + 2) % 3],
            nb[(i + 1) % 3],
        ))
    })
}

/// True when `a`–`b` is a pair of `table`.
fn is_pair(table: &CandidateTable, a: u32, b: u32) -> bool {
    table.by_triangle[a as usize]
        .into_iter()
        .any(|c| c != NONE && table.other(c, a) == b)
}

/// Chooses one split per component that keeps a triangle in `pairing` (a maximum matching of
/// `table`'s dual graph, as elimination leaves it), each checked exactly; the components no
/// split can fix are named in [`Chosen::stuck`]. `regions` counts the regions re-solved.
pub(crate) fn choose(
    mesh: &Mesh,
    table: &CandidateTable,
    pairing: &Pairing,
    rule: Rule,
    first_rings: u32,
    regions: &mut usize,
) -> Chosen {
    let nt = pairing.cand.len();
    let edges = mesh.edges();
    let mut is_boundary = vec![false; edges.edges.len()];
    for &e in &edges.boundary_edges {
        is_boundary[e as usize] = true;
    }
    let (component, sizes) = CandidateTable::components(&table.dual_graph());
    let mut left_in: BTreeMap<u32, Vec<u32>> = BTreeMap::new();
    for t in pairing.leftovers() {
        left_in.entry(component[t as usize]).or_default().push(t);
    }
    let mut p = pairing.clone();
    let mut blocked = vec![false; nt];
    let mut choices = Vec::new();
    let mut stuck = Vec::new();
    let (mut rings, mut solver) = (Rings::new(nt), RegionSolver::new(nt));
    // Per-triangle scratch, reset after each component.
    let mut dist = vec![usize::MAX; nt];
    let mut even = vec![false; nt];
    let mut odd = vec![false; nt];
    for (&c, lefts) in &left_in {
        let left: Vec<u32> = lefts
            .iter()
            .copied()
            .filter(|&t| p.cand[t as usize] == NONE && !blocked[t as usize])
            .collect();
        let Some(&t) = left.first() else {
            continue; // paired by an earlier split that reached into this component
        };
        let stuck_as = |reason| Stuck {
            element: mesh.triangle_ids[t as usize],
            surface: mesh.triangle_surface[t as usize],
            size: sizes[c as usize] as usize,
            left: left.len(),
            reason,
        };
        if sizes[c as usize] % 2 == 0 || left.len() > 1 {
            stuck.push(stuck_as(StuckReason::TooManyLeft));
            continue;
        }
        // Distances from t, and the triangles reached from t by even alternating walks.
        let mut order = vec![t];
        let mut touches_blocked = false;
        dist[t as usize] = 0;
        let mut i = 0;
        while i < order.len() {
            let x = order[i];
            i += 1;
            for cand in table.by_triangle[x as usize] {
                if cand == NONE {
                    continue;
                }
                let u = table.other(cand, x);
                if blocked[u as usize] {
                    touches_blocked = true;
                } else if dist[u as usize] == usize::MAX {
                    dist[u as usize] = dist[x as usize] + 1;
                    order.push(u);
                }
            }
        }
        let mut queue = VecDeque::from([t]);
        even[t as usize] = true;
        while let Some(x) = queue.pop_front() {
            for cand in table.by_triangle[x as usize] {
                if cand == NONE {
                    continue;
                }
                let u = table.other(cand, x);
                if blocked[u as usize] || odd[u as usize] {
                    continue;
                }
                odd[u as usize] = true;
                let m = p.mate(table, u);
                if m != NONE && !even[m as usize] {
                    even[m as usize] = true;
                    queue.push_back(m);
                }
            }
        }
        let (mut candidates, mut ruled_out, mut solved) = (0, 0, 0);
        let mut found = None;
        for &s in &order {
            let Some((side, n1, n2)) =
                split_side(mesh, &edges.triangle_edges, &is_boundary, rule, s)
            else {
                continue;
            };
            if blocked[n1 as usize] || blocked[n2 as usize] {
                continue;
            }
            candidates += 1;
            let condition_holds = touches_blocked
                || !is_pair(table, s, n1)
                || !is_pair(table, s, n2)
                || (even[n1 as usize] && even[n2 as usize]);
            if !condition_holds {
                ruled_out += 1;
                continue;
            }
            solved += 1;
            // The leftovers of every component the split touches.
            let mut seeds: Vec<u32> = Vec::new();
            for x in [s, n1, n2] {
                if let Some(l) = left_in.get(&component[x as usize]) {
                    seeds.extend(l.iter().copied().filter(|&u| {
                        p.cand[u as usize] == NONE
                            && !blocked[u as usize]
                            && ![s, n1, n2].contains(&u)
                    }));
                }
            }
            seeds.sort_unstable();
            seeds.dedup();
            if let Some(q) = repair_without(
                table,
                &p,
                &mut blocked,
                [s, n1, n2],
                seeds,
                first_rings,
                &mut rings,
                &mut solver,
                regions,
            ) {
                found = Some((s, side, dist[s as usize], q));
                break;
            }
        }
        for &u in &order {
            dist[u as usize] = usize::MAX;
        }
        for &u in &order {
            even[u as usize] = false;
            odd[u as usize] = false;
        }
        match found {
            Some((s, side, steps, q)) => {
                choices.push(Choice {
                    triangle: s,
                    side,
                    steps,
                });
                p = q;
            }
            None if candidates == 0 => stuck.push(stuck_as(StuckReason::NoSplittableSide)),
            None => stuck.push(stuck_as(StuckReason::NoneWorks {
                candidates,
                ruled_out,
                solved,
            })),
        }
    }
    Chosen {
        choices,
        pairing: p,
        stuck,
    }
}

/// Takes `triple` out of `pairing` (blocked from now on when this succeeds; their mates
/// freed) and re-solves rings of quads around the free triangles (`seeds` and the mates),
/// the ring count doubling from `first_rings`, until every free triangle is paired (the
/// pairing, returned) or the region closes with some still free (`None`; `triple` is
/// unblocked again).
#[allow(clippy::too_many_arguments)]
fn repair_without(
    table: &CandidateTable,
    pairing: &Pairing,
    blocked: &mut [bool],
    triple: [u32; 3],
    mut seeds: Vec<u32>,
    first_rings: u32,
    rings: &mut Rings,
    solver: &mut RegionSolver,
    regions: &mut usize,
) -> Option<Pairing> {
    let mut q = pairing.clone();
    for x in triple {
        blocked[x as usize] = true;
    }
    for x in triple {
        let m = q.mate(table, x);
        q.cand[x as usize] = NONE;
        if m != NONE {
            q.cand[m as usize] = NONE;
            if !blocked[m as usize] {
                seeds.push(m);
            }
        }
    }
    seeds.sort_unstable();
    seeds.dedup();
    let nt = q.cand.len();
    let mut k = first_rings.max(1);
    let result = loop {
        if seeds.is_empty() {
            break Some(q);
        }
        let walls: &[bool] = blocked;
        let keep = |u: u32| !walls[u as usize];
        rings.grow_where(table, &q, &seeds, k, keep);
        let closed = rings.closed(table, keep);
        let region = std::mem::take(&mut rings.members);
        *regions += 1;
        solver.solve(table, &mut q, &region, Accept::MoreQuadsFirst);
        seeds.clear();
        seeds.extend(
            region
                .iter()
                .copied()
                .filter(|&u| q.cand[u as usize] == NONE),
        );
        rings.members = region;
        if seeds.is_empty() {
            break Some(q);
        }
        if closed {
            break None;
        }
        k = k.saturating_mul(2).min(nt as u32 + 1);
    };
    if result.is_none() {
        for x in triple {
            blocked[x as usize] = false;
        }
    }
    result
}
