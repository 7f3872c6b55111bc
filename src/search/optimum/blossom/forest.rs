//! The search forest: scanning edges into the event heap, plus and minus labels, one
//! dual step per event (`grow_forest`), dummies for stuck (Hungarian) trees, dissolving a
//! tree after it augments, and walking tree edges.

use super::{FREE, Graph, MINUS, NONE, PLUS, Solver};
use std::cmp::Reverse;

impl Solver {
    /// Calls `f(w, cost)` for every neighbour `w` of leaf `v` (dummy edges included).
    fn for_neighbours(&self, g: &Graph, v: u32, mut f: impl FnMut(&Self, u32, i64)) {
        if (v as usize) < self.n {
            for k in g.adj(v) {
                f(self, g.nbr[k], self.cost_k(g, k));
            }
            if self.stats.dummies > 0 {
                for &d in &self.comp_dummies[self.comp[v as usize] as usize] {
                    f(self, d, 0);
                }
            }
        } else {
            let c = self.comp[v as usize] as usize;
            for &w in &self.comp_verts[self.comp_start[c] as usize..self.comp_start[c + 1] as usize]
            {
                f(self, w, 0);
            }
        }
    }

    /// Event key for edge `v` (plus leaf) – `w`, or `None` when no event is needed.
    #[inline]
    fn edge_key(&self, v: u32, yv: i64, w: u32, c: i64) -> Option<i64> {
        let tw = self.top(w);
        if tw == self.top(v) {
            return None;
        }
        let lw = self.label[tw as usize];
        if lw == MINUS {
            return None;
        }
        let s = c - yv - self.yact(w);
        debug_assert!(s >= 0, "negative reduced cost {s} on {v}-{w}");
        if lw == PLUS {
            debug_assert!(s % 2 == 0, "odd slack between plus nodes");
            Some(self.delta + s / 2)
        } else {
            Some(self.delta + s)
        }
    }

    /// Pushes events for every edge out of plus leaf `v`.
    pub(super) fn scan(&mut self, g: &Graph, v: u32) {
        self.stats.scans += 1;
        let yv = self.yact(v);
        let mut heap = std::mem::take(&mut self.heap);
        self.for_neighbours(g, v, |s, w, c| {
            if let Some(key) = s.edge_key(v, yv, w, c) {
                heap.push(Reverse((key, v, w)));
            }
        });
        self.heap = heap;
    }

    /// Pushes events for every edge from a plus leaf into leaf `w` (which just left the tree).
    pub(super) fn rescan_into(&mut self, g: &Graph, w: u32) {
        self.stats.rescans += 1;
        let mut heap = std::mem::take(&mut self.heap);
        self.for_neighbours(g, w, |s, v, c| {
            if s.label[s.top(v) as usize] == PLUS
                && let Some(key) = s.edge_key(v, s.yact(v), w, c)
            {
                heap.push(Reverse((key, v, w)));
            }
        });
        self.heap = heap;
    }

    pub(super) fn set_label(&mut self, x: u32, label: u8, tree: u32) {
        self.freeze(x);
        self.label[x as usize] = label;
        self.tree_of[x as usize] = tree;
        self.trees[tree as usize].push(x);
    }

    /// Labels `x` plus in `tree` and scans its leaves.
    fn make_plus(&mut self, g: &Graph, x: u32, tree: u32) {
        self.set_label(x, PLUS, tree);
        let mut leaves = std::mem::take(&mut self.scratch);
        leaves.clear();
        self.leaves_into(x, &mut leaves);
        for &v in &leaves {
            self.scan(g, v);
        }
        self.scratch = leaves;
    }

    pub(super) fn make_minus(&mut self, x: u32, edge: [u32; 2], tree: u32) {
        self.set_label(x, MINUS, tree);
        self.tedge[x as usize] = edge;
        if self.is_blossom(x) {
            let key = self.delta + self.dual[x as usize];
            self.heap.push(Reverse((key, x, NONE)));
        }
    }

    /// Grows alternating trees from every free vertex at once, with one dual step `delta`
    /// for all: plus nodes rise, minus nodes fall. Two trees that meet augment and dissolve;
    /// the others go on.
    ///
    /// With a finite `budget` (events), a single tree that has not augmented by then stops at
    /// an even dual step (so that every free vertex keeps an even dual, which keeps slacks
    /// between plus nodes of different trees even) and is dissolved.
    pub(super) fn grow_forest(&mut self, g: &Graph, roots: &[u32], budget: usize) {
        self.delta = 0;
        self.heap.clear();
        let mut events = 0usize;
        for &r in roots {
            let t = self.trees.len() as u32;
            self.trees.push(Vec::new());
            self.tree_alive.push(true);
            self.alive += 1;
            self.stats.trees += 1;
            let root = self.top(r);
            debug_assert_eq!(self.base[root as usize], r);
            self.make_plus(g, root, t);
        }
        while self.alive > 0 {
            if events >= budget {
                let next = self.heap.peek().map(|e| e.0.0);
                if next.is_none_or(|k| k > self.delta) {
                    if self.delta % 2 != 0 {
                        self.delta += 1;
                    }
                    debug_assert!(next.is_none_or(|k| k >= self.delta));
                    let alive: Vec<u32> = (0..self.trees.len() as u32)
                        .filter(|&t| self.tree_alive[t as usize])
                        .collect();
                    for t in alive {
                        self.dissolve(g, t);
                    }
                    break;
                }
            }
            events += 1;
            let Some(Reverse((key, a, b))) = self.heap.pop() else {
                if budget != usize::MAX {
                    events = budget;
                    continue;
                }
                self.add_dummies(g);
                continue;
            };
            self.stats.events += 1;
            debug_assert!(key >= self.delta);
            self.delta = key;
            if b == NONE {
                if self.parent[a as usize] == NONE
                    && self.label[a as usize] == MINUS
                    && self.zact(a) == 0
                {
                    self.expand(g, a);
                }
                continue;
            }
            // Events are kept from either end: a plus end that left the tree hands over.
            let (mut v, mut w) = (a, b);
            let (mut tv, mut tw) = (self.top(v), self.top(w));
            if tv == tw {
                continue;
            }
            if self.label[tv as usize] != PLUS {
                if self.label[tw as usize] != PLUS {
                    continue;
                }
                std::mem::swap(&mut v, &mut w);
                std::mem::swap(&mut tv, &mut tw);
            }
            let lw = self.label[tw as usize];
            if lw == MINUS {
                continue;
            }
            let s = self.cost(g, v, w) - self.yact(v) - self.yact(w);
            debug_assert!(s >= 0);
            if s > 0 {
                debug_assert!(lw != PLUS || s % 2 == 0, "odd slack between plus nodes");
                let key = self.delta + if lw == PLUS { s / 2 } else { s };
                self.heap.push(Reverse((key, v, w)));
                continue;
            }
            let t = self.tree_of[tv as usize];
            if lw == PLUS {
                let u = self.tree_of[tw as usize];
                if u == t {
                    self.shrink(g, v, w);
                } else {
                    self.augment(v, w);
                    self.augment(w, v);
                    self.dissolve(g, t);
                    self.dissolve(g, u);
                }
            } else if self.mate[self.base[tw as usize] as usize] == NONE {
                // A free node with an unmatched base: a dummy.
                if self.is_blossom(tw) {
                    self.rotate(tw, w);
                }
                self.mate[w as usize] = v;
                self.augment(v, w);
                self.dissolve(g, t);
            } else {
                self.make_minus(tw, [v, w], t);
                let x = self.top(self.mate[self.base[tw as usize] as usize]);
                self.make_plus(g, x, t);
            }
        }
    }

    /// Every tree is stuck (no event left): each is a Hungarian tree, so its component needs
    /// one more unmatched vertex; add a dummy per tree and the events into it.
    fn add_dummies(&mut self, g: &Graph) {
        let alive: Vec<u32> = (0..self.trees.len() as u32)
            .filter(|&t| self.tree_alive[t as usize])
            .collect();
        for &t in &alive {
            let root = self.trees[t as usize][0];
            let c = self.comp[self.base[root as usize] as usize];
            self.add_dummy(c);
        }
        let _ = g;
        let mut leaves = Vec::new();
        for &t in &alive {
            for &x in &self.trees[t as usize] {
                if self.parent[x as usize] == NONE
                    && self.label[x as usize] == PLUS
                    && self.tree_of[x as usize] == t
                {
                    self.leaves_into(x, &mut leaves);
                }
            }
        }
        leaves.sort_unstable();
        leaves.dedup();
        for v in leaves {
            let c = self.comp[v as usize] as usize;
            for i in 0..self.comp_dummies[c].len() {
                let d = self.comp_dummies[c][i];
                if self.mate[d as usize] == NONE
                    && let Some(key) = self.edge_key(v, self.yact(v), d, 0)
                {
                    self.heap.push(Reverse((key, v, d)));
                }
            }
        }
    }

    /// Ends tree `t` after its augmentation: folds its duals, frees its nodes and adds the
    /// events from the remaining trees into its former minus nodes.
    fn dissolve(&mut self, g: &Graph, t: u32) {
        self.tree_alive[t as usize] = false;
        self.alive -= 1;
        let nodes = std::mem::take(&mut self.trees[t as usize]);
        let mut leaves = std::mem::take(&mut self.scratch2);
        leaves.clear();
        for &x in &nodes {
            if self.parent[x as usize] != NONE
                || self.label[x as usize] == FREE
                || self.tree_of[x as usize] != t
            {
                continue;
            }
            // Edges from other trees into former plus leaves already have (early) events;
            // edges into former minus leaves had none.
            let was_minus = self.label[x as usize] == MINUS;
            self.freeze(x);
            self.label[x as usize] = FREE;
            if was_minus {
                self.leaves_into(x, &mut leaves);
            }
        }
        for &v in &leaves {
            self.rescan_into(g, v);
        }
        self.scratch2 = leaves;
    }

    /// The plus node above plus node `x` in the tree, with the minus node between.
    pub(super) fn tree_parent(&self, x: u32) -> Option<(u32, u32)> {
        let m = self.mate[self.base[x as usize] as usize];
        if m == NONE {
            return None;
        }
        let mn = self.top(m);
        let p = self.top(self.tedge[mn as usize][0]);
        Some((mn, p))
    }

    /// The edge from tree node `parent` down to its child `child`, `[end in parent, end in
    /// child]`.
    pub(super) fn down_edge(&self, child: u32) -> [u32; 2] {
        if self.label[child as usize] == MINUS {
            self.tedge[child as usize]
        } else {
            let b = self.base[child as usize];
            [self.mate[b as usize], b]
        }
    }
}
