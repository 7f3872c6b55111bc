//! Sparse primal–dual blossom algorithm: minimum-cost perfect matching in integers, used for
//! the maximum-weight matching of maximum cardinality.
//!
//! Formulation. Weights `w` become costs `c = 4 (w_max - w)` (even, and every jump-start dual
//! even, so that every dual step is an integer). Each connected component that has no perfect
//! matching receives "dummy" vertices joined to all its vertices at cost 0, one per vertex that
//! must stay unmatched: an odd component gets one up front, and search trees that get stuck
//! (Hungarian trees: no perfect matching exists) add one each. A perfect matching of the
//! augmented graph is then exactly a maximum-cardinality matching of the graph, and the
//! cheapest one is the heaviest.
//!
//! Algorithm. A greedy jump-start sets vertex duals to half the cheapest incident cost, raises
//! each free vertex to its tightest edge, matches tight edges between free vertices and
//! augments along tight paths of length three. Then Edmonds' primal–dual method with blossoms:
//! two rounds of short single-tree searches from each free vertex (stopped after 64, then 512
//! events, their dual progress kept), then one forest of trees from all remaining free vertices that share
//! one dual step; two trees that meet augment and dissolve, the others go on. Dual changes are
//! lazy: a tree node stores the step `delta` at which it joined and its dual moves by
//! `+/-(delta - join)`; a leaf reaches its top-level node through a handle that shrinks and
//! expansions pass small-to-large. Events (an edge becoming tight, a minus blossom's dual
//! reaching zero) sit in a binary heap keyed by the step at which they happen, so a dual step
//! costs one heap pop instead of a scan of the graph. Blossoms are shrunk when two plus nodes
//! of one tree meet and expanded lazily, only when their dual reaches zero as a minus node;
//! blossoms outlive their tree.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// Marker for "no vertex / no node".
pub const NONE: u32 = u32::MAX;

const FREE: u8 = 0;
const PLUS: u8 = 1;
const MINUS: u8 = 2;

/// An undirected graph in compressed adjacency form, with integer weights.
#[derive(Debug, Clone, Default)]
pub struct Graph {
    n: usize,
    start: Vec<u32>,
    nbr: Vec<u32>,
    weight: Vec<i64>,
}

impl Graph {
    /// Builds the graph on `n` vertices from `(u, v, weight)` edges (no self-loops; weights
    /// non-negative and below 2^40).
    pub fn from_edges(n: usize, edges: impl Iterator<Item = (u32, u32, i64)> + Clone) -> Graph {
        let mut deg = vec![0u32; n + 1];
        let mut m = 0;
        for (u, v, w) in edges.clone() {
            assert!(
                u != v && (u as usize) < n && (v as usize) < n,
                "bad edge {u}-{v}"
            );
            assert!((0..1 << 40).contains(&w), "weight {w} out of range");
            deg[u as usize] += 1;
            deg[v as usize] += 1;
            m += 1;
        }
        let mut start = vec![0u32; n + 1];
        for i in 0..n {
            start[i + 1] = start[i] + deg[i];
        }
        let mut fill = start.clone();
        let mut nbr = vec![0u32; 2 * m];
        let mut weight = vec![0i64; 2 * m];
        for (u, v, w) in edges {
            for (a, b) in [(u, v), (v, u)] {
                let k = fill[a as usize] as usize;
                nbr[k] = b;
                weight[k] = w;
                fill[a as usize] += 1;
            }
        }
        Graph {
            n,
            start,
            nbr,
            weight,
        }
    }

    /// Number of vertices.
    pub fn num_vertices(&self) -> usize {
        self.n
    }

    /// Number of edges.
    pub fn num_edges(&self) -> usize {
        self.nbr.len() / 2
    }

    fn adj(&self, v: u32) -> std::ops::Range<usize> {
        self.start[v as usize] as usize..self.start[v as usize + 1] as usize
    }
}

/// Events a short single-tree search may use before it is stopped, per round (all free
/// vertices get a search in each round); what remains goes to the forest.
const SHORT_SEARCH_EVENTS: [usize; 2] = [64, 512];

/// Counters of one solve, for benchmarks and tests.
#[derive(Debug, Clone, Copy, Default)]
pub struct Stats {
    /// Vertices left free by the greedy jump-start (roots of trees).
    pub free_after_greedy: usize,
    /// Trees grown: short single-tree searches plus the trees of the final forest.
    pub trees: usize,
    /// Blossoms shrunk.
    pub shrinks: usize,
    /// Blossoms expanded.
    pub expands: usize,
    /// Dummy vertices added (one per vertex left unmatched in a non-trivial component).
    pub dummies: usize,
    /// Heap events popped.
    pub events: usize,
    /// Leaves scanned (edges out of plus leaves pushed as events).
    pub scans: usize,
    /// Leaves rescanned (after leaving a tree).
    pub rescans: usize,
}

/// A solved matching with its dual certificate.
#[derive(Debug)]
pub struct Matching {
    s: Solver,
    /// Counters of the solve.
    pub stats: Stats,
}

impl Matching {
    /// The mate of each vertex, or [`NONE`].
    pub fn mate(&self, v: u32) -> u32 {
        let m = self.s.mate[v as usize];
        if (m as usize) < self.s.n { m } else { NONE }
    }

    /// Matched pairs `(u, v)` with `u < v`.
    pub fn pairs(&self) -> impl Iterator<Item = (u32, u32)> + '_ {
        (0..self.s.n as u32).filter_map(|u| {
            let v = self.mate(u);
            (v != NONE && u < v).then_some((u, v))
        })
    }

    /// Total weight of the matching.
    pub fn weight(&self, g: &Graph) -> i64 {
        self.pairs()
            .map(|(u, v)| {
                let k = g.adj(u).find(|&k| g.nbr[k] == v).expect("matched edge");
                g.weight[k]
            })
            .sum()
    }

    /// Checks the optimality certificate against `g`: the matching is a matching of `g`;
    /// with the dummy vertices it is perfect on every component of two or more vertices; the
    /// duals are feasible (every reduced cost `>= 0`, every blossom dual `>= 0`, blossoms are
    /// odd, laminar and full when their dual is positive) and complementary slackness holds
    /// (every matched edge has reduced cost 0). This proves maximum weight among matchings
    /// that leave the same number of vertices unmatched in each component; the cardinality
    /// itself rests on the stuck trees (a parity argument for odd components).
    pub fn check(&self, g: &Graph) -> Result<CheckReport, String> {
        self.s.check(g)
    }
}

/// What the certificate check looked at.
#[derive(Debug, Clone, Copy, Default)]
pub struct CheckReport {
    /// Edges whose reduced cost was checked (graph plus dummy edges).
    pub edges_checked: usize,
    /// Blossoms in the final laminar family.
    pub blossoms: usize,
    /// Blossoms with a positive dual.
    pub positive_blossoms: usize,
    /// Vertices left unmatched.
    pub unmatched: usize,
}

/// Maximum-weight matching of maximum cardinality of `g`.
pub fn solve(g: &Graph) -> Matching {
    let mut s = Solver::new(g);
    s.run(g);
    let stats = s.stats;
    Matching { s, stats }
}

#[derive(Debug, Default)]
struct Solver {
    /// Real vertices: ids `0..n`; dummies and blossoms take ids from `n` on.
    n: usize,
    /// Cost of the cheapest edge is `2 * (wmax - w)`.
    wmax: i64,
    // Per node.
    parent: Vec<u32>,
    label: Vec<u8>,
    join: Vec<i64>,
    /// Leaves: the total dual `Y(v)` (vertex dual plus all enclosing blossom duals) is
    /// `dual[v] + hoff[h] + lazy(hnode[h])` with `h = hnd[v]`. Blossoms: the blossom dual `z`
    /// as of `join[b]` (top level) or fixed (nested).
    dual: Vec<i64>,
    /// Minus nodes: the tree edge `[plus end, end in this node]`.
    tedge: Vec<[u32; 2]>,
    base: Vec<u32>,
    mate: Vec<u32>,
    /// Leaves: handle of the top-level node holding the leaf. A shrink hands the largest
    /// child's handle to the new blossom and an expansion hands it back to the largest child,
    /// so only the leaves of the smaller parts are touched (small-to-large).
    hnd: Vec<u32>,
    /// Per handle: its top-level node and the dual change it has accumulated.
    hnode: Vec<u32>,
    hoff: Vec<i64>,
    free_handles: Vec<u32>,
    /// Per node: its handle while top level, else [`NONE`].
    node_h: Vec<u32>,
    /// Per node: number of leaves.
    size: Vec<u32>,
    comp: Vec<u32>,
    // Per extra node (id - n): blossom cycle, base child first; `cedges[i]` joins child `i`
    // (first end) to child `i + 1` (second end). Empty for dummies and freed ids.
    children: Vec<Vec<u32>>,
    cedges: Vec<Vec<[u32; 2]>>,
    free_ids: Vec<u32>,
    // Components of the real graph.
    comp_start: Vec<u32>,
    comp_verts: Vec<u32>,
    comp_dummies: Vec<Vec<u32>>,
    // Tree state.
    delta: i64,
    heap: BinaryHeap<Reverse<(i64, u32, u32)>>,
    /// Nodes labelled in each tree (with stale entries; `tree_of` says which are current).
    trees: Vec<Vec<u32>>,
    tree_alive: Vec<bool>,
    alive: usize,
    tree_of: Vec<u32>,
    mark: Vec<u32>,
    stamp: u32,
    scratch: Vec<u32>,
    scratch2: Vec<u32>,
    stats: Stats,
}

impl Solver {
    fn new(g: &Graph) -> Solver {
        let n = g.n;
        let wmax = g.weight.iter().copied().max().unwrap_or(0);
        Solver {
            n,
            wmax,
            parent: vec![NONE; n],
            label: vec![FREE; n],
            join: vec![0; n],
            dual: vec![0; n],
            tedge: vec![[NONE; 2]; n],
            base: (0..n as u32).collect(),
            mate: vec![NONE; n],
            hnd: (0..n as u32).collect(),
            hnode: (0..n as u32).collect(),
            hoff: vec![0; n],
            node_h: (0..n as u32).collect(),
            size: vec![1; n],
            comp: vec![NONE; n],
            mark: vec![0; n],
            tree_of: vec![NONE; n],
            ..Solver::default()
        }
    }

    #[inline]
    fn cost_k(&self, g: &Graph, k: usize) -> i64 {
        4 * (self.wmax - g.weight[k])
    }

    /// Cost of edge `v`–`w` (0 for a dummy edge).
    fn cost(&self, g: &Graph, v: u32, w: u32) -> i64 {
        if v as usize >= self.n || w as usize >= self.n {
            return 0;
        }
        let k = g.adj(v).find(|&k| g.nbr[k] == w).expect("edge exists");
        self.cost_k(g, k)
    }

    #[inline]
    fn is_blossom(&self, x: u32) -> bool {
        x as usize >= self.n && !self.children[x as usize - self.n].is_empty()
    }

    #[inline]
    fn is_dummy(&self, x: u32) -> bool {
        x as usize >= self.n && self.children[x as usize - self.n].is_empty()
    }

    /// The top-level node holding leaf `v`.
    #[inline]
    fn top(&self, v: u32) -> u32 {
        self.hnode[self.hnd[v as usize] as usize]
    }

    /// Dual change of top-level node `x` since it joined its tree.
    #[inline]
    fn lazy(&self, x: u32) -> i64 {
        let x = x as usize;
        match self.label[x] {
            PLUS => self.delta - self.join[x],
            MINUS => self.join[x] - self.delta,
            _ => 0,
        }
    }

    /// Current total dual of leaf `v`.
    #[inline]
    fn yact(&self, v: u32) -> i64 {
        let h = self.hnd[v as usize] as usize;
        self.dual[v as usize] + self.hoff[h] + self.lazy(self.hnode[h])
    }

    /// Folds the pending dual change of top-level node `x` into its handle (and its blossom
    /// dual) and restarts its clock, so that its label may change.
    fn freeze(&mut self, x: u32) {
        let l = self.lazy(x);
        if l != 0 {
            self.hoff[self.node_h[x as usize] as usize] += l;
            if self.is_blossom(x) {
                self.dual[x as usize] += l;
            }
        }
        self.join[x as usize] = self.delta;
    }

    fn new_handle(&mut self, x: u32) -> u32 {
        let h = if let Some(h) = self.free_handles.pop() {
            self.hnode[h as usize] = x;
            self.hoff[h as usize] = 0;
            h
        } else {
            self.hnode.push(x);
            self.hoff.push(0);
            (self.hnode.len() - 1) as u32
        };
        self.node_h[x as usize] = h;
        h
    }

    /// Current dual of top-level blossom `b`.
    #[inline]
    fn zact(&self, b: u32) -> i64 {
        let b = b as usize;
        match self.label[b] {
            PLUS => self.dual[b] + (self.delta - self.join[b]),
            MINUS => self.dual[b] - (self.delta - self.join[b]),
            _ => self.dual[b],
        }
    }

    fn new_node(&mut self) -> u32 {
        if let Some(id) = self.free_ids.pop() {
            let i = id as usize;
            self.parent[i] = NONE;
            self.label[i] = FREE;
            self.dual[i] = 0;
            self.base[i] = id;
            self.mate[i] = NONE;
            self.node_h[i] = NONE;
            self.size[i] = 1;
            self.comp[i] = NONE;
            return id;
        }
        let id = self.parent.len() as u32;
        self.parent.push(NONE);
        self.label.push(FREE);
        self.join.push(0);
        self.dual.push(0);
        self.tedge.push([NONE; 2]);
        self.base.push(id);
        self.mate.push(NONE);
        self.hnd.push(NONE);
        self.node_h.push(NONE);
        self.size.push(1);
        self.comp.push(NONE);
        self.mark.push(0);
        self.tree_of.push(NONE);
        self.children.push(Vec::new());
        self.cedges.push(Vec::new());
        id
    }

    /// Appends the leaves of `x` to `out`.
    fn leaves_into(&self, x: u32, out: &mut Vec<u32>) {
        if !self.is_blossom(x) {
            out.push(x);
            return;
        }
        let mut stack = vec![x];
        while let Some(y) = stack.pop() {
            if self.is_blossom(y) {
                stack.extend_from_slice(&self.children[y as usize - self.n]);
            } else {
                out.push(y);
            }
        }
    }

    fn run(&mut self, g: &Graph) {
        self.components(g);
        self.greedy(g);
        // One dummy per odd component of three or more vertices.
        for c in 0..self.comp_dummies.len() {
            let size = self.comp_start[c + 1] - self.comp_start[c];
            if size >= 3 && size % 2 == 1 {
                self.add_dummy(c as u32);
            }
        }
        self.stats.free_after_greedy = (0..self.n)
            .filter(|&v| self.mate[v] == NONE && self.comp_size(self.comp[v]) > 1)
            .count();
        // Short single-tree searches first: most free vertices find a partner nearby, and a
        // search that runs long is stopped (its dual progress is kept) for the forest.
        for budget in SHORT_SEARCH_EVENTS {
            for r in 0..self.n as u32 {
                if self.mate[r as usize] == NONE && self.comp_size(self.comp[r as usize]) > 1 {
                    self.grow_forest(g, &[r], budget);
                }
            }
        }
        let roots: Vec<u32> = (0..self.n as u32)
            .filter(|&r| self.mate[r as usize] == NONE && self.comp_size(self.comp[r as usize]) > 1)
            .collect();
        self.grow_forest(g, &roots, usize::MAX);
        self.heap = BinaryHeap::new();
        // Every node is free again: fold the handles' offsets into the leaves.
        for v in 0..self.parent.len() {
            let h = self.hnd[v];
            if h != NONE && (v < self.n || self.is_dummy(v as u32)) {
                self.dual[v] += self.hoff[h as usize];
            }
        }
        self.hoff.iter_mut().for_each(|o| *o = 0);
    }

    fn comp_size(&self, c: u32) -> u32 {
        self.comp_start[c as usize + 1] - self.comp_start[c as usize]
    }

    fn components(&mut self, g: &Graph) {
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
    fn greedy(&mut self, g: &Graph) {
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
    fn add_dummy(&mut self, c: u32) -> u32 {
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
    fn scan(&mut self, g: &Graph, v: u32) {
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
    fn rescan_into(&mut self, g: &Graph, w: u32) {
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

    fn set_label(&mut self, x: u32, label: u8, tree: u32) {
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

    fn make_minus(&mut self, x: u32, edge: [u32; 2], tree: u32) {
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
    fn grow_forest(&mut self, g: &Graph, roots: &[u32], budget: usize) {
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
    fn tree_parent(&self, x: u32) -> Option<(u32, u32)> {
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
    fn down_edge(&self, child: u32) -> [u32; 2] {
        if self.label[child as usize] == MINUS {
            self.tedge[child as usize]
        } else {
            let b = self.base[child as usize];
            [self.mate[b as usize], b]
        }
    }

    /// Shrinks the blossom closed by the tight edge `u`–`v` between two plus nodes.
    fn shrink(&mut self, g: &Graph, u: u32, v: u32) {
        self.stats.shrinks += 1;
        let (bu, bv) = (self.top(u), self.top(v));
        self.stamp = self.stamp.wrapping_add(1).max(1);
        let st = self.stamp;
        self.mark[bu as usize] = st;
        self.mark[bv as usize] = st;
        let mut pu = vec![bu];
        let mut pv = vec![bv];
        let lca = 'find: loop {
            for path in [&mut pu, &mut pv] {
                if let Some((m, p)) = self.tree_parent(*path.last().expect("non-empty")) {
                    path.push(m);
                    path.push(p);
                    if self.mark[p as usize] == st {
                        break 'find p;
                    }
                    self.mark[p as usize] = st;
                }
            }
        };
        let cut = |path: &mut Vec<u32>| {
            let i = path.iter().position(|&x| x == lca).expect("lca on path");
            path.truncate(i + 1);
        };
        cut(&mut pu);
        cut(&mut pv);
        // Cycle: lca, down pu to bu, across u-v, up pv to just below lca.
        let k = pu.len() + pv.len() - 1;
        let mut ch = Vec::with_capacity(k);
        let mut ed = Vec::with_capacity(k);
        for i in (1..pu.len()).rev() {
            ch.push(pu[i]);
            ed.push(self.down_edge(pu[i - 1]));
        }
        ch.push(bu);
        ed.push([u, v]);
        for &x in &pv[..pv.len() - 1] {
            ch.push(x);
            let [a, b] = self.down_edge(x);
            ed.push([b, a]);
        }
        debug_assert_eq!(ch.len(), k);
        debug_assert!(k % 2 == 1);

        // Fold every child's pending change; the largest child hands its handle to `b`.
        for &c in &ch {
            self.freeze(c);
        }
        let big = *ch
            .iter()
            .max_by_key(|&&c| self.size[c as usize])
            .expect("children");
        let hb = self.node_h[big as usize];
        let b = self.new_node();
        self.base[b as usize] = self.base[lca as usize];
        self.parent[b as usize] = NONE;
        self.dual[b as usize] = 0;
        self.node_h[b as usize] = hb;
        self.hnode[hb as usize] = b;
        self.node_h[big as usize] = NONE;
        self.size[b as usize] = ch.iter().map(|&c| self.size[c as usize]).sum();
        let tree = self.tree_of[lca as usize];
        self.set_label(b, PLUS, tree);
        let mut leaves = std::mem::take(&mut self.scratch);
        let mut new_plus = std::mem::take(&mut self.scratch2);
        new_plus.clear();
        for &c in &ch {
            let was_minus = self.label[c as usize] == MINUS;
            if c != big {
                let hc = self.node_h[c as usize];
                let diff = self.hoff[hc as usize] - self.hoff[hb as usize];
                leaves.clear();
                self.leaves_into(c, &mut leaves);
                for &w in &leaves {
                    self.dual[w as usize] += diff;
                    self.hnd[w as usize] = hb;
                }
                self.free_handles.push(hc);
                self.node_h[c as usize] = NONE;
                if was_minus {
                    new_plus.extend_from_slice(&leaves);
                }
            } else if was_minus {
                self.leaves_into(c, &mut new_plus);
            }
            self.label[c as usize] = FREE;
            self.parent[c as usize] = b;
        }
        self.children[b as usize - self.n] = ch;
        self.cedges[b as usize - self.n] = ed;
        for &w in &new_plus {
            self.scan(g, w);
        }
        self.scratch = leaves;
        self.scratch2 = new_plus;
    }

    /// Expands the minus blossom `b`, whose dual is zero.
    fn expand(&mut self, g: &Graph, b: u32) {
        self.stats.expands += 1;
        self.freeze(b);
        debug_assert_eq!(self.dual[b as usize], 0);
        let hb = self.node_h[b as usize];
        let [p, x] = self.tedge[b as usize];
        let tree = self.tree_of[b as usize];
        let ch = std::mem::take(&mut self.children[b as usize - self.n]);
        let ed = std::mem::take(&mut self.cedges[b as usize - self.n]);
        self.label[b as usize] = FREE;
        self.node_h[b as usize] = NONE;
        self.free_ids.push(b);
        let big = *ch
            .iter()
            .max_by_key(|&&c| self.size[c as usize])
            .expect("children");
        let mut leaves = std::mem::take(&mut self.scratch);
        for &c in &ch {
            self.parent[c as usize] = NONE;
            self.label[c as usize] = FREE;
            if c == big {
                self.node_h[c as usize] = hb;
                self.hnode[hb as usize] = c;
            } else {
                let hc = self.new_handle(c);
                let off = self.hoff[hb as usize];
                leaves.clear();
                self.leaves_into(c, &mut leaves);
                for &w in &leaves {
                    self.dual[w as usize] += off;
                    self.hnd[w as usize] = hc;
                }
            }
        }
        let k = ch.len();
        let mut t = x;
        while self.parent[t as usize] != NONE {
            t = self.parent[t as usize];
        }
        let i = ch.iter().position(|&c| c == t).expect("entry child");
        // Even path from child i to the base child 0, labelled minus, plus, ..., minus.
        let mut path: Vec<(u32, [u32; 2])> = Vec::new();
        path.push((ch[i], [p, x]));
        if i % 2 == 0 {
            for j in (0..i).rev() {
                let [a, c] = ed[j];
                path.push((ch[j], [c, a]));
            }
        } else {
            for j in i..k {
                path.push((ch[(j + 1) % k], ed[j]));
            }
        }
        let mut on_path = std::mem::take(&mut self.scratch2);
        on_path.clear();
        for (s, &(c, e)) in path.iter().enumerate() {
            if s % 2 == 0 {
                self.make_minus(c, e, tree);
            } else {
                self.set_label(c, PLUS, tree);
            }
            on_path.push(c);
        }
        for (s, &(c, _)) in path.iter().enumerate() {
            if s % 2 == 1 {
                leaves.clear();
                self.leaves_into(c, &mut leaves);
                for &w in &leaves {
                    self.scan(g, w);
                }
            }
        }
        for &c in &ch {
            if self.label[c as usize] == FREE {
                leaves.clear();
                self.leaves_into(c, &mut leaves);
                for &w in &leaves {
                    self.rescan_into(g, w);
                }
            }
        }
        self.scratch = leaves;
        self.scratch2 = on_path;
    }

    /// Augments along the tree path from plus leaf `v` to its root, matching `v` to `w`.
    fn augment(&mut self, v: u32, w: u32) {
        let (mut s, mut t) = (v, w);
        loop {
            let ts = self.top(s);
            let old = self.mate[self.base[ts as usize] as usize];
            if self.is_blossom(ts) {
                self.rotate(ts, s);
            }
            self.mate[s as usize] = t;
            if old == NONE {
                break;
            }
            let m = self.top(old);
            let [p, x] = self.tedge[m as usize];
            if self.is_blossom(m) {
                self.rotate(m, x);
            }
            self.mate[x as usize] = p;
            s = p;
            t = x;
        }
    }

    /// Makes leaf `v` the base of blossom `b`, flipping the matching along the even path of
    /// every enclosing cycle (no recursion: a work stack).
    fn rotate(&mut self, b: u32, v: u32) {
        let mut stack = vec![(b, v)];
        let mut chain = Vec::new();
        while let Some((b, v)) = stack.pop() {
            // The blossoms from `b` down to `v`, each rotated once.
            chain.clear();
            let mut t = v;
            while t != b {
                chain.push(t);
                t = self.parent[t as usize];
            }
            let mut x = b;
            for &t in chain.iter().rev() {
                self.rotate_level(x, t, &mut stack);
                self.base[x as usize] = v;
                x = t;
            }
        }
    }

    /// Rotates the cycle of blossom `b` so that its child `t` comes first, rematching the
    /// even path; sub-blossoms whose base changes go on `stack`.
    fn rotate_level(&mut self, b: u32, t: u32, stack: &mut Vec<(u32, u32)>) {
        let bi = b as usize - self.n;
        let k = self.children[bi].len();
        let i = self.children[bi]
            .iter()
            .position(|&c| c == t)
            .expect("child");
        if i == 0 {
            return;
        }
        let js = if i % 2 == 0 {
            (0..i - 1).step_by(2)
        } else {
            (i + 1..k).step_by(2)
        };
        for j in js {
            let [a, c] = self.cedges[bi][j];
            let (ca, cc) = (self.children[bi][j], self.children[bi][(j + 1) % k]);
            self.mate[a as usize] = c;
            self.mate[c as usize] = a;
            if self.is_blossom(ca) {
                stack.push((ca, a));
            }
            if self.is_blossom(cc) {
                stack.push((cc, c));
            }
        }
        self.children[bi].rotate_left(i);
        self.cedges[bi].rotate_left(i);
    }

    fn check(&self, g: &Graph) -> Result<CheckReport, String> {
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
            if self.children[b - self.n].len() % 2 == 0 {
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
            if m != NONE && (v as u32) < m {
                if let Some(a) = self.common(v as u32, m, &depth) {
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
        }
        for &b in &blossoms {
            if size[b] % 2 == 0 || size[b] < 3 {
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

#[cfg(test)]
mod tests {
    use super::*;

    fn solve_edges(n: usize, edges: &[(u32, u32, i64)]) -> (Vec<(u32, u32)>, i64) {
        let g = Graph::from_edges(n, edges.iter().copied());
        let m = solve(&g);
        m.check(&g).expect("certificate");
        (m.pairs().collect(), m.weight(&g))
    }

    #[test]
    fn path_prefers_two_light_edges_over_one_heavy() {
        // Maximum cardinality first: 2 pairs of weight 1 beat 1 pair of weight 100.
        let (pairs, w) = solve_edges(4, &[(0, 1, 1), (1, 2, 100), (2, 3, 1)]);
        assert_eq!(pairs, vec![(0, 1), (2, 3)]);
        assert_eq!(w, 2);
    }

    #[test]
    fn odd_cycle_leaves_the_cheapest_vertex() {
        // Triangle 0-1-2 plus pendant 3 at 0: one vertex must stay single; the best pairs are
        // 0-3 (5) and 1-2 (7).
        let (pairs, w) = solve_edges(4, &[(0, 1, 9), (1, 2, 7), (2, 0, 1), (0, 3, 5)]);
        assert_eq!(pairs, vec![(0, 3), (1, 2)]);
        assert_eq!(w, 12);
        // A lone triangle: one pair, the heaviest.
        let (pairs, w) = solve_edges(3, &[(0, 1, 2), (1, 2, 3), (2, 0, 4)]);
        assert_eq!((pairs.len(), w), (1, 4));
    }

    #[test]
    fn blossom_is_needed() {
        // Two triangles joined by a bridge: the perfect matching uses the bridge.
        let e = [
            (0, 1, 5),
            (1, 2, 5),
            (2, 0, 5),
            (3, 4, 5),
            (4, 5, 5),
            (5, 3, 5),
            (2, 3, 0),
        ];
        let (pairs, w) = solve_edges(6, &e);
        assert_eq!(pairs.len(), 3);
        assert!(pairs.contains(&(2, 3)));
        assert_eq!(w, 10);
    }

    #[test]
    fn even_component_without_perfect_matching() {
        // A claw (star with three leaves): only one pair; the heaviest spoke.
        let (pairs, w) = solve_edges(4, &[(0, 1, 3), (0, 2, 8), (0, 3, 5)]);
        assert_eq!(pairs, vec![(0, 2)]);
        assert_eq!(w, 8);
    }

    #[test]
    fn isolated_vertices_and_empty_graph() {
        let (pairs, w) = solve_edges(3, &[]);
        assert!(pairs.is_empty() && w == 0);
        let (pairs, _) = solve_edges(0, &[]);
        assert!(pairs.is_empty());
    }

    #[test]
    fn ties_give_any_perfect_matching() {
        // All weights equal on an even cycle with chords: any perfect matching is optimal.
        let e = [
            (0, 1, 7),
            (1, 2, 7),
            (2, 3, 7),
            (3, 4, 7),
            (4, 5, 7),
            (5, 0, 7),
            (0, 3, 7),
        ];
        let (pairs, w) = solve_edges(6, &e);
        assert_eq!((pairs.len(), w), (3, 21));
    }
}
