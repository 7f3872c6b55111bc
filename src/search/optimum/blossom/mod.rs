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
//!
//! Files. This module holds the graph, the public results ([`Matching`], [`Stats`],
//! [`CheckReport`]), the solver's state with its node and dual bookkeeping, and the phases'
//! order (`Solver::run`); `start` finds the components and runs the greedy jump-start,
//! `forest` grows the search trees by dual steps (events, labels, dummies for stuck
//! trees), `blossoms` shrinks and expands blossoms and augments along a found path, and
//! `certificate` checks the final matching against its duals.

mod blossoms;
mod certificate;
mod forest;
mod start;

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
