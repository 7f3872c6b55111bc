//! The naive oracle of the recombination criterion: a full breadth-first search per action,
//! no caching, no cleverness, so that it is obviously the rule.
//!
//! The rule (issue 9, Definition 2 generalised to odd polders):
//! - *remaining* triangles are those not yet recombined;
//! - the *polder* P of an action (t, t') is the connected component, in the graph of the
//!   candidate pairs (the table's `pairs`: neighbouring triangles of the same surface, less the
//!   pairs the quad-validity rule dropped) restricted to remaining triangles, that holds t and t';
//! - removing t and t' leaves P \ {t, t'}, which splits into *parts*: the connected components
//!   of the dual graph restricted to P \ {t, t'};
//! - the action is *allowed* iff it does not increase the number of odd polders: if |P| is
//!   even, every part must be even; if |P| is odd, exactly one part must be odd;
//! - the actions are the candidates `c` of the `CandidateTable` (`pairs[c] = [t, t']`) whose two
//!   triangles both remain;
//! - `P_k` is the set of remaining triangles that take part in exactly k allowed actions.

use quadrecomb::internals::mesh::{Mesh, NONE};
use quadrecomb::internals::quality::CandidateTable;
use std::cell::RefCell;

/// Remaining triangles with an undo log, and the criterion computed from scratch on demand.
#[derive(Debug, Clone)]
pub struct Naive {
    neighbours: Vec<[u32; 3]>,
    pairs: Vec<[u32; 2]>,
    remaining: Vec<bool>,
    log: Vec<u32>,
    scratch: RefCell<Scratch>,
}

/// Reused search buffers (the searches themselves are from scratch every time).
#[derive(Debug, Clone, Default)]
struct Scratch {
    /// `mark[t] == stamp`: reached by the current search (or excluded from it).
    mark: Vec<u64>,
    stamp: u64,
    queue: Vec<u32>,
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
        // The graph of the candidate pairs, from the pairs alone.
        let mut neighbours = vec![[NONE; 3]; mesh.num_triangles()];
        for &[a, b] in &table.pairs {
            for (x, y) in [(a, b), (b, a)] {
                let slot = neighbours[x as usize].iter().position(|&u| u == NONE);
                neighbours[x as usize][slot.expect("at most three pairs per triangle")] = y;
            }
        }
        Naive {
            neighbours,
            pairs: table.pairs.clone(),
            remaining: vec![true; mesh.num_triangles()],
            log: Vec::new(),
            scratch: RefCell::new(Scratch {
                mark: vec![0; mesh.num_triangles()],
                ..Scratch::default()
            }),
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

    /// Breadth-first search from `start` over remaining triangles not yet marked with the
    /// current stamp, marking them; returns how many it reached.
    fn bfs(&self, start: u32, scratch: &mut Scratch) -> usize {
        let stamp = scratch.stamp;
        scratch.mark[start as usize] = stamp;
        scratch.queue.clear();
        scratch.queue.push(start);
        let mut head = 0;
        while head < scratch.queue.len() {
            let t = scratch.queue[head];
            head += 1;
            for &u in &self.neighbours[t as usize] {
                if u != NONE && self.remaining[u as usize] && scratch.mark[u as usize] != stamp {
                    scratch.mark[u as usize] = stamp;
                    scratch.queue.push(u);
                }
            }
        }
        scratch.queue.len()
    }

    /// The polder of remaining triangle `t`: its component among remaining triangles (BFS).
    pub fn polder(&self, t: u32) -> Vec<u32> {
        assert!(self.remaining[t as usize], "polder of a used triangle");
        let scratch = &mut *self.scratch.borrow_mut();
        scratch.stamp += 1;
        self.bfs(t, scratch);
        scratch.queue.clone()
    }

    /// Sizes of the parts left when the two triangles of `c` leave their polder, and the
    /// polder's size. `None` when `c` is not an action (a triangle is used).
    pub fn parts(&self, c: u32) -> Option<(usize, Vec<usize>)> {
        let [a, b] = self.pairs[c as usize];
        if !self.remaining[a as usize] || !self.remaining[b as usize] {
            return None;
        }
        // P: a BFS from a over remaining triangles.
        let polder = self.polder(a);
        assert!(
            polder.contains(&b),
            "candidate {c}: t and t' in different polders"
        );
        // Parts: BFS over remaining triangles but a and b, from each triangle of P not yet
        // reached. P is a component of the remaining triangles, so these searches stay in P.
        let scratch = &mut *self.scratch.borrow_mut();
        scratch.stamp += 1;
        scratch.mark[a as usize] = scratch.stamp;
        scratch.mark[b as usize] = scratch.stamp;
        let mut parts = Vec::new();
        for &t in &polder {
            if scratch.mark[t as usize] != scratch.stamp {
                parts.push(self.bfs(t, scratch));
            }
        }
        assert_eq!(parts.iter().sum::<usize>() + 2, polder.len());
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

    /// Allowed candidates of triangle `t` (0 once it is used), what the state's
    /// `allowed_count` gives.
    pub fn allowed_count(&self, table: &CandidateTable, t: u32) -> u32 {
        if !self.is_remaining(t) {
            return 0;
        }
        table.by_triangle[t as usize]
            .iter()
            .filter(|&&d| d != NONE && self.is_allowed(d))
            .count() as u32
    }

    /// Number of odd components of the dual graph of all remaining triangles.
    pub fn odd_polders(&self) -> usize {
        let scratch = &mut *self.scratch.borrow_mut();
        scratch.stamp += 1;
        let mut odd = 0;
        for t in 0..self.remaining.len() as u32 {
            if self.remaining[t as usize] && scratch.mark[t as usize] != scratch.stamp {
                odd += self.bfs(t, scratch) % 2;
            }
        }
        odd
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
