//! `beam`: beam search over the selective tree's branching. Each decision keeps, depth after
//! depth, the `width` nodes with the largest summed eta among the children (by the paper's
//! drawing rule) of the nodes kept at the depth before, down to depth `h`; the first action
//! of the best complete path (depth `h`, or no action left) is applied. `width` is
//! `max(1, budget / h)`, so a decision expands at most about `budget` nodes. With a width
//! that keeps every node it finds the selective tree's best leaf.

use super::{BUDGET, HORIZON, Info, ParamSpec, Params, Policy};
use crate::search::Searcher;
use crate::search::policy::node_key;

/// The registry's entry.
pub static INFO: Info = Info {
    name: "beam",
    about: "beam search over the selective tree (width budget/h), depth h",
    params: &[
        ParamSpec {
            default: 5,
            ..HORIZON
        },
        BUDGET,
    ],
    random: true,
    builds_trees: true,
    search: true,
    rank: 7,
    policy: &Beam,
};

#[derive(Debug)]
struct Beam;

/// A node of the explicit tree: the action leading to it from `parent`.
#[derive(Debug, Clone, Copy)]
struct Node {
    parent: u32,
    action: u32,
    sum: f64,
    key: u64,
}

impl Policy for Beam {
    fn run(&self, s: &mut Searcher<'_>, p: Params) -> Vec<u32> {
        let h = p.horizon.unwrap_or(5).max(1);
        let width = (p.budget.unwrap_or(64) / h).max(1) as usize;
        let mut nodes: Vec<Node> = Vec::new();
        let (mut beam, mut next, mut path, mut kids) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut complete: Vec<u32> = Vec::new();
        s.decide_each(|s, key, root| {
            nodes.clear();
            beam.clear();
            complete.clear();
            // The best complete path's last node (a leaf at depth h, or one without action).
            let mut best: Option<u32> = None;
            let better = |nodes: &[Node], best: Option<u32>, i: u32| {
                best.is_none_or(|b| nodes[i as usize].sum > nodes[b as usize].sum)
            };
            for &(c, eta) in root {
                beam.push(nodes.len() as u32);
                nodes.push(Node {
                    parent: u32::MAX,
                    action: c,
                    sum: eta,
                    key: node_key(key, c),
                });
            }
            for _depth in 1..h {
                next.clear();
                for &i in &beam {
                    let n = nodes[i as usize];
                    s.push_path_to(&mut path, i, |j| {
                        (nodes[j as usize].action, nodes[j as usize].parent)
                    });
                    let any = s.selective_children(n.key, &mut kids);
                    s.pop_n(path.len());
                    if !any {
                        complete.push(i);
                        if better(&nodes, best, i) {
                            best = Some(i);
                        }
                        continue;
                    }
                    s.count_node();
                    for &(c, eta) in &kids {
                        next.push(nodes.len() as u32);
                        nodes.push(Node {
                            parent: i,
                            action: c,
                            sum: n.sum + eta,
                            key: node_key(n.key, c),
                        });
                    }
                }
                // The widest sums first; ties to the node made first (stable sort).
                next.sort_by(|&a, &b| nodes[b as usize].sum.total_cmp(&nodes[a as usize].sum));
                next.truncate(width);
                std::mem::swap(&mut beam, &mut next);
                if beam.is_empty() {
                    break;
                }
            }
            complete.extend_from_slice(&beam);
            for &i in &beam {
                if better(&nodes, best, i) {
                    best = Some(i);
                }
            }
            // The root child (in side order, the first on ties) under which the best
            // complete path lies.
            let best = nodes[best.expect("the root has an action") as usize].sum;
            let mut pick = usize::MAX;
            for &i in complete.iter() {
                let mut j = i as usize;
                while nodes[j].parent != u32::MAX {
                    j = nodes[j].parent as usize;
                }
                if nodes[i as usize].sum == best && j < pick {
                    pick = j;
                }
            }
            nodes[pick].action
        });
        s.state.chosen().to_vec()
    }
}
