//! The pairing being finished, rings of quads grown around triangles, and the exact re-solve
//! of a region with everything outside it fixed (the blossom matcher of
//! [`crate::search::optimum`] run on the region's induced subgraph).

use crate::mesh::NONE;
use crate::quality::CandidateTable;
use crate::search::optimum::{self, blossom};

/// The candidate each triangle is in (or [`NONE`]): a matching of the dual graph.
#[derive(Debug, Clone)]
pub(crate) struct Pairing {
    pub cand: Vec<u32>,
}

impl Pairing {
    /// The pairing of the candidates `chosen` (a matching) of a mesh of `nt` triangles.
    pub fn new(nt: usize, table: &CandidateTable, chosen: &[u32]) -> Pairing {
        let mut cand = vec![NONE; nt];
        for &c in chosen {
            for t in table.pairs[c as usize] {
                assert_eq!(
                    cand[t as usize], NONE,
                    "triangle {t} in two chosen candidates"
                );
                cand[t as usize] = c;
            }
        }
        Pairing { cand }
    }

    /// The triangle paired with `t`, or [`NONE`].
    #[inline]
    pub fn mate(&self, table: &CandidateTable, t: u32) -> u32 {
        match self.cand[t as usize] {
            NONE => NONE,
            c => table.other(c, t),
        }
    }

    /// The chosen candidates, ascending.
    pub fn chosen(&self, table: &CandidateTable) -> Vec<u32> {
        let mut out: Vec<u32> = self
            .cand
            .iter()
            .enumerate()
            .filter(|&(t, &c)| c != NONE && table.pairs[c as usize][0] == t as u32)
            .map(|(_, &c)| c)
            .collect();
        out.sort_unstable();
        out
    }

    /// Triangles in no candidate.
    pub fn leftovers(&self) -> impl Iterator<Item = u32> + '_ {
        (0..self.cand.len() as u32).filter(|&t| self.cand[t as usize] == NONE)
    }
}

/// Rings of quads grown around seed triangles: ring 0 is the seeds and their mates, ring
/// `i + 1` the triangles next to ring `i` through an allowed pair, with their mates. A region
/// so made holds whole quads only, so re-pairing it leaves the rest of the pairing as it is.
#[derive(Debug)]
pub(crate) struct Rings {
    stamp: Vec<u32>,
    epoch: u32,
    group_stamp: Vec<u32>,
    /// The triangles reached, ring after ring.
    pub members: Vec<u32>,
    /// `members[ends[i - 1]..ends[i]]` is ring `i` (`ends[-1]` = 0).
    pub ends: Vec<usize>,
}

impl Rings {
    pub fn new(nt: usize) -> Rings {
        Rings {
            stamp: vec![0; nt],
            epoch: 0,
            group_stamp: vec![0; nt],
            members: Vec::new(),
            ends: Vec::new(),
        }
    }

    fn next_epoch(&mut self) {
        self.epoch = self.epoch.wrapping_add(1);
        if self.epoch == 0 {
            self.stamp.fill(0);
            self.group_stamp.fill(0);
            self.epoch = 1;
        }
    }

    fn add(&mut self, table: &CandidateTable, pairing: &Pairing, t: u32) {
        if self.stamp[t as usize] != self.epoch {
            self.stamp[t as usize] = self.epoch;
            self.members.push(t);
        }
        let m = pairing.mate(table, t);
        if m != NONE && self.stamp[m as usize] != self.epoch {
            self.stamp[m as usize] = self.epoch;
            self.members.push(m);
        }
    }

    /// Grows `rings` rings around `seeds` (ring 0 included, so `rings + 1` in all).
    pub fn grow(&mut self, table: &CandidateTable, pairing: &Pairing, seeds: &[u32], rings: u32) {
        self.grow_where(table, pairing, seeds, rings, |_| true);
    }

    /// [`Rings::grow`] through the triangles `keep` accepts only (the others are walls; seeds
    /// and their mates must be kept ones).
    pub fn grow_where(
        &mut self,
        table: &CandidateTable,
        pairing: &Pairing,
        seeds: &[u32],
        rings: u32,
        keep: impl Fn(u32) -> bool,
    ) {
        self.next_epoch();
        self.members.clear();
        self.ends.clear();
        for &t in seeds {
            self.add(table, pairing, t);
        }
        self.ends.push(self.members.len());
        let mut start = 0;
        for _ in 0..rings {
            let end = self.members.len();
            for i in start..end {
                let t = self.members[i];
                for c in table.by_triangle[t as usize] {
                    if c != NONE {
                        let u = table.other(c, t);
                        if self.stamp[u as usize] != self.epoch && keep(u) {
                            self.add(table, pairing, u);
                        }
                    }
                }
            }
            self.ends.push(self.members.len());
            if self.members.len() == end {
                break;
            }
            start = end;
        }
    }

    /// True when no allowed pair leads from the region last grown to a triangle outside it
    /// that `keep` accepts: the region holds whole components of the dual graph less the
    /// triangles `keep` refuses.
    pub fn closed(&self, table: &CandidateTable, keep: impl Fn(u32) -> bool) -> bool {
        self.members.iter().all(|&t| {
            table.by_triangle[t as usize].into_iter().all(|c| {
                c == NONE || {
                    let u = table.other(c, t);
                    self.stamp[u as usize] == self.epoch || !keep(u)
                }
            })
        })
    }

    /// The connected groups of the region last grown (connected through allowed pairs), each
    /// with `closed` = true when no allowed pair leaves it (it holds whole components of the
    /// dual graph). Calls `f(group, closed)` for each.
    pub fn groups(&mut self, table: &CandidateTable, mut f: impl FnMut(&[u32], bool)) {
        let mut group = Vec::new();
        for k in 0..self.members.len() {
            let s = self.members[k];
            if self.group_stamp[s as usize] == self.epoch {
                continue;
            }
            group.clear();
            group.push(s);
            self.group_stamp[s as usize] = self.epoch;
            let mut closed = true;
            let mut i = 0;
            while i < group.len() {
                let t = group[i];
                i += 1;
                for c in table.by_triangle[t as usize] {
                    if c == NONE {
                        continue;
                    }
                    let u = table.other(c, t);
                    if self.stamp[u as usize] != self.epoch {
                        closed = false;
                    } else if self.group_stamp[u as usize] != self.epoch {
                        self.group_stamp[u as usize] = self.epoch;
                        group.push(u);
                    }
                }
            }
            f(&group, closed);
        }
    }
}

/// When a re-solved region replaces the pairing inside it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Accept {
    /// More quads, or as many with a higher total eta (leftover elimination).
    MoreQuadsFirst,
    /// At least as many quads and a higher total eta (local improvement: never lowers eta).
    HigherEta,
}

/// Re-solves regions exactly: the maximum-cardinality, maximum-weight matching (integer
/// weights as the optimum's) of the pairs inside the region, everything outside fixed.
#[derive(Debug)]
pub(crate) struct RegionSolver {
    local: Vec<u32>,
    edges: Vec<(u32, u32, i64)>,
    new_cands: Vec<u32>,
}

impl RegionSolver {
    pub fn new(nt: usize) -> RegionSolver {
        RegionSolver {
            local: vec![NONE; nt],
            edges: Vec::new(),
            new_cands: Vec::new(),
        }
    }

    /// Solves `region` (whole quads only: every paired triangle's mate inside) and keeps the
    /// result in `pairing` when `accept` says it is better than what is there; true if it did.
    pub fn solve(
        &mut self,
        table: &CandidateTable,
        pairing: &mut Pairing,
        region: &[u32],
        accept: Accept,
    ) -> bool {
        for (i, &t) in region.iter().enumerate() {
            self.local[t as usize] = i as u32;
        }
        self.edges.clear();
        let (mut old_quads, mut old_w, mut old_eta) = (0i64, 0i64, 0.0f64);
        for (i, &t) in region.iter().enumerate() {
            let own = pairing.cand[t as usize];
            for c in table.by_triangle[t as usize] {
                if c == NONE {
                    continue;
                }
                let u = table.other(c, t);
                let j = self.local[u as usize];
                if j == NONE || t > u {
                    continue;
                }
                let w = optimum::weight(table.eta[c as usize]);
                self.edges.push((i as u32, j, w));
                if own == c {
                    old_quads += 1;
                    old_w += w;
                    old_eta += table.eta[c as usize];
                }
            }
            debug_assert!(
                own == NONE || self.local[table.other(own, t) as usize] != NONE,
                "region holds whole quads"
            );
        }
        let mut applied = false;
        if !self.edges.is_empty() {
            let g = blossom::Graph::from_edges(region.len(), self.edges.iter().copied());
            let m = blossom::solve(&g);
            self.new_cands.clear();
            let (mut quads, mut w, mut eta) = (0i64, 0i64, 0.0f64);
            for (a, b) in m.pairs() {
                let (ta, tb) = (region[a as usize], region[b as usize]);
                let c = table.by_triangle[ta as usize]
                    .into_iter()
                    .find(|&c| c != NONE && table.other(c, ta) == tb)
                    .expect("matched pair is a candidate");
                self.new_cands.push(c);
                quads += 1;
                w += optimum::weight(table.eta[c as usize]);
                eta += table.eta[c as usize];
            }
            let better = match accept {
                Accept::MoreQuadsFirst => {
                    quads > old_quads || (quads == old_quads && w > old_w && eta > old_eta)
                }
                Accept::HigherEta => quads >= old_quads && w > old_w && eta > old_eta,
            };
            if better {
                for &t in region {
                    pairing.cand[t as usize] = NONE;
                }
                for &c in &self.new_cands {
                    for t in table.pairs[c as usize] {
                        pairing.cand[t as usize] = c;
                    }
                }
                applied = true;
            }
        }
        for &t in region {
            self.local[t as usize] = NONE;
        }
        applied
    }
}
