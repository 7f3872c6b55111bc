//! The dual certificate of a solved matching ([`Matching::check`](super::Matching::check)):
//! feasibility of every reduced cost, the blossom family and complementary slackness.

use super::{CheckReport, Graph, NONE, Solver};

impl Solver {
    pub(super) fn check(&self, g: &Graph) -> Result<CheckReport, String> {
        let nn = self.parent.len();
        let mut rep = CheckReport::default();
        // Nodes alive: real vertices, dummies, blossoms reachable as parents or tops.
        let alive = |x: usize| x < self.n || self.is_dummy(x as u32) && self.comp[x] != NONE;
        // Matching.
        for v in 0..nn {
            if !alive(v) {
                continue;
            }
            let m = self.mate[v];
            if m == NONE {
                let size = if v < self.n {
                    self.comp_size(self.comp[v])
                } else {
                    2
                };
                if size > 1 {
                    return Err(format!("vertex {v} unmatched in a component of {size}"));
                }
                rep.unmatched += 1;
                continue;
            }
            if self.mate[m as usize] != v as u32 {
                return Err(format!("mate of {v} is {m} but mate of {m} is not {v}"));
            }
            if v < self.n && (m as usize) < self.n && !g.adj(v as u32).any(|k| g.nbr[k] == m) {
                return Err(format!("{v}-{m} matched but not an edge"));
            }
            if (v >= self.n) == (m as usize >= self.n) && (v >= self.n) {
                return Err(format!("dummies {v} and {m} matched together"));
            }
            if v >= self.n && self.comp[v] != self.comp[m as usize] {
                return Err(format!("dummy {v} matched outside its component"));
            }
            if v < self.n && m as usize >= self.n {
                rep.unmatched += 1;
            }
        }
        // Blossom family: depth, sizes, duals, full when positive.
        let mut depth = vec![0u32; nn];
        let mut zsum = vec![0i64; nn]; // sum of z over the node and its ancestors
        let mut size = vec![0u32; nn];
        let mut inner = vec![0u32; nn];
        let blossoms: Vec<usize> = (self.n..nn)
            .filter(|&x| self.is_blossom(x as u32))
            .collect();
        rep.blossoms = blossoms.len();
        for &b in &blossoms {
            for &c in &self.children[b - self.n] {
                if self.parent[c as usize] != b as u32 {
                    return Err(format!(
                        "child {c} of blossom {b} has parent {}",
                        self.parent[c as usize]
                    ));
                }
            }
            if self.children[b - self.n].len().is_multiple_of(2) {
                return Err(format!("blossom {b} has an even cycle"));
            }
            if self.dual[b] < 0 {
                return Err(format!("blossom {b} has dual {}", self.dual[b]));
            }
            if self.dual[b] > 0 {
                rep.positive_blossoms += 1;
            }
        }
        let chain = |x: usize| {
            let mut out = Vec::new();
            let mut y = self.parent[x];
            while y != NONE {
                out.push(y as usize);
                y = self.parent[y as usize];
            }
            out
        };
        for x in 0..nn {
            if !(alive(x) || self.is_blossom(x as u32)) {
                continue;
            }
            let anc = chain(x);
            depth[x] = anc.len() as u32;
            if x >= self.n && self.is_blossom(x as u32) {
                zsum[x] = self.dual[x] + anc.iter().map(|&a| self.dual[a]).sum::<i64>();
            } else {
                zsum[x] = anc.iter().map(|&a| self.dual[a]).sum::<i64>();
                for &a in &anc {
                    size[a] += 1;
                }
            }
        }
        for v in 0..nn {
            if !alive(v) {
                continue;
            }
            let m = self.mate[v];
            if m != NONE
                && (v as u32) < m
                && let Some(a) = self.common(v as u32, m, &depth)
            {
                let mut y = a;
                loop {
                    inner[y as usize] += 1;
                    y = self.parent[y as usize];
                    if y == NONE {
                        break;
                    }
                }
            }
        }
        for &b in &blossoms {
            if size[b].is_multiple_of(2) || size[b] < 3 {
                return Err(format!("blossom {b} has {} vertices", size[b]));
            }
            if self.dual[b] > 0 && inner[b] != (size[b] - 1) / 2 {
                return Err(format!(
                    "blossom {b} has positive dual but {} of {} inner pairs matched",
                    inner[b],
                    (size[b] - 1) / 2
                ));
            }
        }
        // Reduced costs: c - Y(u) - Y(v) + 2 * (sum of z over blossoms holding both).
        let reduced = |u: u32, v: u32, c: i64| {
            let both = self.common(u, v, &depth).map_or(0, |a| zsum[a as usize]);
            c - self.dual[u as usize] - self.dual[v as usize] + 2 * both
        };
        let mut checkedge = |u: u32, v: u32, c: i64| -> Result<(), String> {
            rep.edges_checked += 1;
            let r = reduced(u, v, c);
            if r < 0 {
                return Err(format!("edge {u}-{v} has negative reduced cost {r}"));
            }
            if self.mate[u as usize] == v && r != 0 {
                return Err(format!("matched edge {u}-{v} has reduced cost {r}"));
            }
            Ok(())
        };
        for u in 0..self.n as u32 {
            for k in g.adj(u) {
                let v = g.nbr[k];
                if u < v {
                    checkedge(u, v, self.cost_k(g, k))?;
                }
            }
            for &d in &self.comp_dummies[self.comp[u as usize] as usize] {
                checkedge(u, d, 0)?;
            }
        }
        Ok(rep)
    }

    /// The smallest blossom containing both `u` and `v`, if any.
    fn common(&self, u: u32, v: u32, depth: &[u32]) -> Option<u32> {
        let (mut a, mut b) = (self.parent[u as usize], self.parent[v as usize]);
        let d = |x: u32| if x == NONE { 0 } else { depth[x as usize] + 1 };
        while a != b {
            if d(a) >= d(b) {
                a = self.parent[a as usize];
            } else {
                b = self.parent[b as usize];
            }
        }
        (a != NONE).then_some(a)
    }
}
