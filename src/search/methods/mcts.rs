//! `mcts`: UCT (Kocsis and Szepesvári, 2006) on the selective tree's branching. Each
//! decision runs iterations from the drawn root triangle's actions: selection by UCB1 among
//! the children not yet exhausted (an unvisited child first; the mean return normalised by
//! the range of returns seen in this tree, exploration constant [`C`]), expansion of the
//! node reached (its children by the paper's drawing rule), a rollout from it down to depth
//! `h` by the selective rule at horizon 1 (the drawn triangle's largest-eta allowed action),
//! and the backup of the summed eta (path and rollout) to the root. The budget counts the
//! tree's expansions (a rollout's steps are counted in the run's nodes, not in the budget,
//! so that rollouts cannot starve the tree); a decision stops at `budget` expansions or when
//! the tree to depth `h` is exhausted, and applies the first action of the best return found (in a deterministic
//! problem every return is a path that can be followed). Its draws come from the tree's key,
//! drawn from the run's stream: seeded. With a budget that covers the tree it finds the
//! selective tree's best leaf.

use super::{BUDGET, HORIZON, Info, ParamSpec, Params, Policy};
use crate::search::Searcher;
use crate::search::policy::node_key;

/// The registry's entry.
pub static INFO: Info = Info {
    name: "mcts",
    about: "UCT / MCTS: UCB1 selection, expansion, selective h=1 rollouts to depth h, \
            budget nodes per decision",
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
    rank: 6,
    policy: &Mcts,
};

/// UCB1's exploration constant, on returns normalised to [0, 1].
pub const C: f64 = 0.7;

#[derive(Debug)]
struct Mcts;

/// A node of the explicit tree: the action leading to it from `parent`.
#[derive(Debug, Clone, Copy)]
struct Node {
    parent: u32,
    action: u32,
    depth: u32,
    sum: f64,
    key: u64,
    /// Children `first..first + len` in the arena once expanded.
    first: u32,
    len: u8,
    expanded: bool,
    /// Nothing below is left to explore (depth h, no action, or every child exhausted).
    done: bool,
    visits: u32,
    total: f64,
    best: f64,
}

impl Node {
    fn new(parent: u32, action: u32, depth: u32, sum: f64, key: u64) -> Node {
        Node {
            parent,
            action,
            depth,
            sum,
            key,
            first: 0,
            len: 0,
            expanded: false,
            done: false,
            visits: 0,
            total: 0.0,
            best: f64::NEG_INFINITY,
        }
    }
}

impl Policy for Mcts {
    fn run(&self, s: &mut Searcher<'_>, p: Params) -> Vec<u32> {
        let h = p.horizon.unwrap_or(10).max(1);
        let budget = u64::from(p.budget.unwrap_or(64).max(1));
        let mut t: Vec<Node> = Vec::new();
        let (mut path, mut kids) = (Vec::new(), Vec::new());
        s.decide_each(|s, key, root| {
            t.clear();
            let mut r0 = Node::new(u32::MAX, u32::MAX, 0, 0.0, key);
            r0.expanded = true;
            r0.first = 1;
            r0.len = root.len() as u8;
            t.push(r0);
            for &(c, eta) in root {
                t.push(Node::new(0, c, 1, eta, node_key(key, c)));
            }
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            let mut spent = 1u64;
            while spent < budget && !t[0].done {
                // Selection.
                let mut cur = 0usize;
                path.clear();
                while t[cur].expanded && !t[cur].done && t[cur].len > 0 {
                    let n = t[cur];
                    let ln = f64::from(n.visits.max(1)).ln();
                    let mut pick = usize::MAX;
                    let mut score = f64::NEG_INFINITY;
                    let first = n.first as usize;
                    let kids_of = &t[first..first + usize::from(n.len)];
                    for (i, ch) in (first..).zip(kids_of) {
                        if ch.done {
                            continue;
                        }
                        let v = if ch.visits == 0 {
                            f64::INFINITY
                        } else {
                            let mean = ch.total / f64::from(ch.visits);
                            let norm = if hi - lo > 1e-12 {
                                (mean - lo) / (hi - lo)
                            } else {
                                0.5
                            };
                            norm + C * (ln / f64::from(ch.visits)).sqrt()
                        };
                        if v > score {
                            (score, pick) = (v, i);
                        }
                    }
                    debug_assert!(pick != usize::MAX, "a live node has a live child");
                    path.push(t[pick].action);
                    s.state.tree_push(t[pick].action);
                    cur = pick;
                }
                // Expansion.
                let n = t[cur];
                if !n.expanded && n.depth < h {
                    let any = s.selective_children(n.key, &mut kids);
                    s.count_node();
                    spent += 1;
                    let first = t.len() as u32;
                    for &(c, eta) in &kids {
                        t.push(Node::new(
                            cur as u32,
                            c,
                            n.depth + 1,
                            n.sum + eta,
                            node_key(n.key, c),
                        ));
                    }
                    let node = &mut t[cur];
                    node.expanded = true;
                    node.first = first;
                    node.len = kids.len() as u8;
                    node.done = !any;
                } else if n.depth >= h {
                    t[cur].done = true;
                }
                // Rollout: the selective rule at horizon 1 from the node, to depth h.
                let mut ret = n.sum;
                let (mut d, mut k, mut pushed) = (n.depth, n.key, 0usize);
                if t[cur].expanded && t[cur].len > 0 {
                    while d < h {
                        if !s.selective_children(k, &mut kids) {
                            break;
                        }
                        s.count_node();
                        let (mut c, mut eta) = kids[0];
                        for &(c2, e2) in &kids[1..] {
                            if e2 > eta {
                                (c, eta) = (c2, e2);
                            }
                        }
                        s.state.tree_push(c);
                        pushed += 1;
                        ret += eta;
                        k = node_key(k, c);
                        d += 1;
                    }
                }
                s.pop_n(pushed + path.len());
                lo = lo.min(ret);
                hi = hi.max(ret);
                // Backup, and exhaustion.
                let mut j = cur;
                loop {
                    let node = &mut t[j];
                    node.visits += 1;
                    node.total += ret;
                    node.best = node.best.max(ret);
                    if node.expanded && node.len > 0 && !node.done {
                        let (a, b) = (
                            node.first as usize,
                            (node.first + u32::from(node.len)) as usize,
                        );
                        if t[a..b].iter().all(|c| c.done) {
                            t[j].done = true;
                        }
                    }
                    if j == 0 {
                        break;
                    }
                    j = t[j].parent as usize;
                }
            }
            // The first action of the best return (ties: side order).
            let (a, b) = (
                t[0].first as usize,
                (t[0].first + u32::from(t[0].len)) as usize,
            );
            let mut pick = a;
            for (i, ch) in (a..).zip(&t[a..b]) {
                if ch.best > t[pick].best {
                    pick = i;
                }
            }
            t[pick].action
        });
        s.state.chosen().to_vec()
    }
}
