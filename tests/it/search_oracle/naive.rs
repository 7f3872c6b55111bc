//! The naive oracle of the recombination criterion: a full breadth-first search per action,
//! no caching, no cleverness, so that it is obviously the rule.
//!
//! The rule (issue 9, Definition 2 generalised to odd polders):
//! - *remaining* triangles are those not yet recombined;
//! - the *polder* P of an action (t, t') is the connected component, in the dual graph
//!   (`mesh.topology.neighbours`, which links only triangles of the same surface) restricted to
//!   remaining triangles, that holds t and t';
//! - removing t and t' leaves P \ {t, t'}, which splits into *parts*: the connected components
//!   of the dual graph restricted to P \ {t, t'};
//! - the action is *allowed* iff it does not increase the number of odd polders: if |P| is
//!   even, every part must be even; if |P| is odd, exactly one part must be odd;
//! - the actions are the candidates `c` of the `CandidateTable` (`pairs[c] = [t, t']`) whose two
//!   triangles both remain;
//! - `P_k` is the set of remaining triangles that take part in exactly k allowed actions.

use quadrecomb::mesh::{Mesh, NONE};
use quadrecomb::quality::CandidateTable;

/// Remaining triangles with an undo log, and the criterion computed from scratch on demand.
#[derive(Debug, Clone)]
pub struct Naive {
    neighbours: Vec<[u32; 3]>,
    pairs: Vec<[u32; 2]>,
    remaining: Vec<bool>,
    log: Vec<u32>,
}

/// Everything the oracle says about one remaining set: the reference a fast state must equal.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Verdicts {
    /// Remaining flag of each triangle.
    pub remaining: Vec<bool>,
    /// Allowed flag of each candidate (false when one of its triangles is used).
    pub allowed: Vec<bool>,
    /// Number of allowed actions of each triangle (k of P_k; 0 for a used triangle).
    pub count: Vec<u32>,
}

impl Verdicts {
    /// The allowed candidates, increasing.
    pub fn allowed_actions(&self) -> Vec<u32> {
        (0..self.allowed.len() as u32)
            .filter(|&c| self.allowed[c as usize])
            .collect()
    }
}

impl Naive {
    /// Every triangle remaining, nothing applied.
    pub fn new(mesh: &Mesh, table: &CandidateTable) -> Naive {
        Naive {
            neighbours: mesh.topology.neighbours.clone(),
            pairs: table.pairs.clone(),
            remaining: vec![true; mesh.num_triangles()],
            log: Vec::new(),
        }
    }

    /// Number of candidates.
    pub fn num_candidates(&self) -> usize {
        self.pairs.len()
    }

    /// The two triangles of candidate `c`.
    pub fn pair(&self, c: u32) -> [u32; 2] {
        self.pairs[c as usize]
    }

    /// The candidates applied so far, oldest first.
    pub fn path(&self) -> &[u32] {
        &self.log
    }

    /// True while `t` is not recombined.
    pub fn is_remaining(&self, t: u32) -> bool {
        self.remaining[t as usize]
    }

    /// Recombines the two triangles of `c` (both must remain; the criterion is not asked).
    pub fn apply(&mut self, c: u32) {
        let [a, b] = self.pairs[c as usize];
        assert!(
            self.remaining[a as usize] && self.remaining[b as usize],
            "oracle: candidate {c} = [{a}, {b}] applied with a used triangle"
        );
        self.remaining[a as usize] = false;
        self.remaining[b as usize] = false;
        self.log.push(c);
    }

    /// Reverts the last `apply`.
    pub fn undo(&mut self) {
        let c = self.log.pop().expect("oracle: undo with nothing applied");
        let [a, b] = self.pairs[c as usize];
        self.remaining[a as usize] = true;
        self.remaining[b as usize] = true;
    }

    /// Connected components of the dual graph restricted to the triangles where `keep` holds:
    /// each component as its list of triangles, in order of first triangle.
    fn components(&self, keep: &[bool]) -> Vec<Vec<u32>> {
        let mut seen = vec![false; keep.len()];
        let mut out = Vec::new();
        for start in 0..keep.len() {
            if !keep[start] || seen[start] {
                continue;
            }
            seen[start] = true;
            let mut comp = vec![start as u32];
            let mut head = 0;
            while head < comp.len() {
                let t = comp[head];
                head += 1;
                for &u in &self.neighbours[t as usize] {
                    if u != NONE && keep[u as usize] && !seen[u as usize] {
                        seen[u as usize] = true;
                        comp.push(u);
                    }
                }
            }
            out.push(comp);
        }
        out
    }

    /// The polder of remaining triangle `t`: its component among remaining triangles (BFS).
    pub fn polder(&self, t: u32) -> Vec<u32> {
        assert!(self.remaining[t as usize], "polder of a used triangle");
        let mut seen = vec![false; self.remaining.len()];
        seen[t as usize] = true;
        let mut out = vec![t];
        let mut head = 0;
        while head < out.len() {
            let x = out[head];
            head += 1;
            for &u in &self.neighbours[x as usize] {
                if u != NONE && self.remaining[u as usize] && !seen[u as usize] {
                    seen[u as usize] = true;
                    out.push(u);
                }
            }
        }
        out
    }

    /// Sizes of the parts left when the two triangles of `c` leave their polder, and the
    /// polder's size. `None` when `c` is not an action (a triangle is used).
    pub fn parts(&self, c: u32) -> Option<(usize, Vec<usize>)> {
        let [a, b] = self.pairs[c as usize];
        if !self.remaining[a as usize] || !self.remaining[b as usize] {
            return None;
        }
        let polder = self.polder(a);
        assert!(
            polder.contains(&b),
            "candidate {c}: t and t' in different polders"
        );
        let mut keep = vec![false; self.remaining.len()];
        for &t in &polder {
            keep[t as usize] = true;
        }
        keep[a as usize] = false;
        keep[b as usize] = false;
        let parts = self.components(&keep).iter().map(Vec::len).collect();
        Some((polder.len(), parts))
    }

    /// The criterion for candidate `c`: an action that does not increase the odd polders.
    pub fn is_allowed(&self, c: u32) -> bool {
        match self.parts(c) {
            None => false,
            Some((size, parts)) => {
                let odd = parts.iter().filter(|&&p| p % 2 == 1).count();
                if size % 2 == 0 { odd == 0 } else { odd == 1 }
            }
        }
    }

    /// Number of odd components of the dual graph of all remaining triangles.
    pub fn odd_polders(&self) -> usize {
        self.components(&self.remaining)
            .iter()
            .filter(|c| c.len() % 2 == 1)
            .count()
    }

    /// The same criterion stated globally, as a cross-check of [`Naive::is_allowed`]: apply
    /// `c` and compare the number of odd components of the whole remaining graph.
    pub fn is_allowed_globally(&mut self, c: u32) -> bool {
        let [a, b] = self.pairs[c as usize];
        if !self.remaining[a as usize] || !self.remaining[b as usize] {
            return false;
        }
        let before = self.odd_polders();
        self.apply(c);
        let after = self.odd_polders();
        self.undo();
        after <= before
    }

    /// Every verdict for the current remaining set, each from its own BFS.
    pub fn verdicts(&self) -> Verdicts {
        let allowed: Vec<bool> = (0..self.pairs.len() as u32)
            .map(|c| self.is_allowed(c))
            .collect();
        let mut count = vec![0u32; self.remaining.len()];
        for (c, &[a, b]) in self.pairs.iter().enumerate() {
            if allowed[c] {
                count[a as usize] += 1;
                count[b as usize] += 1;
            }
        }
        Verdicts {
            remaining: self.remaining.clone(),
            allowed,
            count,
        }
    }
}
