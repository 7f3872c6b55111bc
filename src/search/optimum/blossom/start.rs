//! The jump-start: connected components (and their dummy vertices), the greedy initial
//! duals and matching with its short augmenting paths.

use super::{Graph, NONE, Solver};

impl Solver {
    pub(super) fn comp_size(&self, c: u32) -> u32 {
        self.comp_start[c as usize + 1] - self.comp_start[c as usize]
    }

    pub(super) fn components(&mut self, g: &Graph) {
        let mut ncomp = 0u32;
        let mut order = Vec::with_capacity(self.n);
        self.comp_start.push(0);
        for s in 0..self.n as u32 {
            if self.comp[s as usize] != NONE {
                continue;
            }
            let first = order.len();
            self.comp[s as usize] = ncomp;
            order.push(s);
            let mut i = first;
            while i < order.len() {
                let v = order[i];
                i += 1;
                for k in g.adj(v) {
                    let w = g.nbr[k];
                    if self.comp[w as usize] == NONE {
                        self.comp[w as usize] = ncomp;
                        order.push(w);
                    }
                }
            }
            self.comp_start.push(order.len() as u32);
            ncomp += 1;
        }
        self.comp_verts = order;
        self.comp_dummies = vec![Vec::new(); ncomp as usize];
    }

    /// Greedy jump-start: duals from the cheapest incident edges, then each free vertex is
    /// raised to its tightest edge and matched along it when the other end is free.
    pub(super) fn greedy(&mut self, g: &Graph) {
        for v in 0..self.n as u32 {
            let m = g.adj(v).map(|k| self.cost_k(g, k)).min().unwrap_or(0);
            self.dual[v as usize] = m / 2;
        }
        for v in 0..self.n as u32 {
            if self.mate[v as usize] != NONE {
                continue;
            }
            let yv = self.dual[v as usize];
            let Some(s) = g
                .adj(v)
                .map(|k| self.cost_k(g, k) - yv - self.dual[g.nbr[k] as usize])
                .min()
            else {
                continue;
            };
            let yv = yv + s;
            self.dual[v as usize] = yv;
            for k in g.adj(v) {
                let w = g.nbr[k];
                if self.mate[w as usize] == NONE
                    && self.cost_k(g, k) - yv - self.dual[w as usize] == 0
                {
                    self.mate[v as usize] = w;
                    self.mate[w as usize] = v;
                    break;
                }
            }
        }
        // Augmenting paths of length three along tight edges: free v, w = x, free z.
        for v in 0..self.n as u32 {
            if self.mate[v as usize] != NONE {
                continue;
            }
            let yv = self.dual[v as usize];
            'found: for k in g.adj(v) {
                let w = g.nbr[k];
                let x = self.mate[w as usize];
                if x == NONE || self.cost_k(g, k) != yv + self.dual[w as usize] {
                    continue;
                }
                let yx = self.dual[x as usize];
                for k2 in g.adj(x) {
                    let z = g.nbr[k2];
                    if z != v
                        && self.mate[z as usize] == NONE
                        && self.cost_k(g, k2) == yx + self.dual[z as usize]
                    {
                        self.mate[v as usize] = w;
                        self.mate[w as usize] = v;
                        self.mate[x as usize] = z;
                        self.mate[z as usize] = x;
                        break 'found;
                    }
                }
            }
        }
    }

    /// Adds a dummy vertex to component `c`, joined to all its vertices at cost 0, with the
    /// highest feasible dual.
    pub(super) fn add_dummy(&mut self, c: u32) -> u32 {
        let d = self.new_node();
        self.comp[d as usize] = c;
        let h = self.new_handle(d);
        self.hnd[d as usize] = h;
        let range = self.comp_start[c as usize] as usize..self.comp_start[c as usize + 1] as usize;
        let y = self.comp_verts[range]
            .iter()
            .map(|&v| -self.yact(v))
            .min()
            .expect("non-empty component");
        self.dual[d as usize] = y;
        self.comp_dummies[c as usize].push(d);
        self.stats.dummies += 1;
        d
    }
}
