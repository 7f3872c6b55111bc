//! `optimistic`: optimistic planning for deterministic systems (Hren and Munos, 2008) on the
//! selective tree's branching. Each decision grows a tree from the drawn root triangle's
//! actions, always expanding the leaf with the largest upper bound (its path's summed eta
//! plus `top` per step left to the horizon, `top` being the largest eta of any action still
//! live at the decision: no step can add more), until `budget` nodes are expanded or no leaf
//! can beat the best path found; the first action of the path with the largest sum is
//! applied. With a budget that covers the tree it finds the selective tree's best leaf.

use super::{BUDGET, HORIZON, Info, ParamSpec, Params, Policy};
use crate::search::Searcher;
use crate::search::policy::{BOUND_SLACK, node_key};
use std::cmp::{Ordering, Reverse};
use std::collections::BinaryHeap;

/// The registry's entry.
pub static INFO: Info = Info {
    name: "optimistic",
    about: "optimistic planning (Hren & Munos): expand the leaf with the largest upper bound, \
            budget nodes per decision, depth at most h",
    params: &[
        ParamSpec {
            default: 10,
            ..HORIZON
        },
        BUDGET,
    ],
    random: true,
    builds_trees: true,
    search: true,
    rank: 5,
    policy: &Optimistic,
};

#[derive(Debug)]
struct Optimistic;

/// A node of the explicit tree: the action leading to it from `parent`.
#[derive(Debug, Clone, Copy)]
struct Node {
    parent: u32,
    action: u32,
    depth: u32,
    sum: f64,
    key: u64,
}

/// A leaf waiting for expansion, by upper bound (ties: the older node first).
#[derive(Debug, PartialEq)]
struct Leaf(f64, Reverse<u32>);

impl Eq for Leaf {}

impl PartialOrd for Leaf {
    fn partial_cmp(&self, other: &Leaf) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Leaf {
    fn cmp(&self, other: &Leaf) -> Ordering {
        self.0.total_cmp(&other.0).then(self.1.cmp(&other.1))
    }
}

impl Policy for Optimistic {
    fn run(&self, s: &mut Searcher<'_>, p: Params) -> Vec<u32> {
        let h = p.horizon.unwrap_or(10).max(1);
        let budget = u64::from(p.budget.unwrap_or(64).max(1));
        let mut nodes: Vec<Node> = Vec::new();
        let mut heap = BinaryHeap::new();
        let (mut path, mut kids) = (Vec::new(), Vec::new());
        s.decide_each(|s, key, root| {
            s.advance_cursor();
            let top = s.state.table().eta[s.order[s.cursor] as usize];
            nodes.clear();
            heap.clear();
            let mut best = 0u32;
            let add = |nodes: &mut Vec<Node>, heap: &mut BinaryHeap<Leaf>, best: &mut u32, n| {
                let i = nodes.len() as u32;
                let Node { depth, sum, .. } = n;
                nodes.push(n);
                if sum > nodes[*best as usize].sum {
                    *best = i;
                }
                if depth < h {
                    heap.push(Leaf(sum + f64::from(h - depth) * top, Reverse(i)));
                }
            };
            for &(c, eta) in root {
                let n = Node {
                    parent: u32::MAX,
                    action: c,
                    depth: 1,
                    sum: eta,
                    key: node_key(key, c),
                };
                add(&mut nodes, &mut heap, &mut best, n);
            }
            let mut expanded = 1u64;
            while expanded < budget {
                let Some(Leaf(bound, Reverse(i))) = heap.pop() else {
                    break;
                };
                if bound + BOUND_SLACK < nodes[best as usize].sum {
                    break; // no leaf can beat the best path, nor tie with it
                }
                let n = nodes[i as usize];
                s.push_path_to(&mut path, i, |j| {
                    (nodes[j as usize].action, nodes[j as usize].parent)
                });
                s.selective_children(n.key, &mut kids);
                s.pop_n(path.len());
                s.count_node();
                expanded += 1;
                for &(c, eta) in &kids {
                    let child = Node {
                        parent: i,
                        action: c,
                        depth: n.depth + 1,
                        sum: n.sum + eta,
                        key: node_key(n.key, c),
                    };
                    add(&mut nodes, &mut heap, &mut best, child);
                }
            }
            // The root child (in side order, the first on ties) whose subtree holds the
            // largest sum: the first action of the best path.
            let mut by_root = vec![f64::NEG_INFINITY; root.len()];
            for (i, n) in nodes.iter().enumerate() {
                let mut j = i;
                while nodes[j].parent != u32::MAX {
                    j = nodes[j].parent as usize;
                }
                by_root[j] = by_root[j].max(n.sum);
            }
            let mut pick = 0;
            for (r, &v) in by_root.iter().enumerate() {
                if v > by_root[pick] {
                    pick = r;
                }
            }
            nodes[pick].action
        });
        s.state.chosen().to_vec()
    }

    fn reads_eta_order(&self) -> bool {
        true
    }
}
