//! The initial verdicts in components whose dual graph has no cycle (one-cell-wide
//! corridors: strips, spirals, mazes), all at once from subtree sizes. A search per
//! candidate costs its smaller parts, which on a strip of `n` triangles sums to `n^2 / 4`;
//! this costs O(n).
//!
//! In such a component removing a pair leaves one part per remaining neighbour of the quad
//! (a tree has one path between two triangles), each hanging off that neighbour: the
//! subtree below it in a rooted spanning tree, or the rest of the component for the
//! parent's side. The verdict is the criterion on those sizes; its certificate is the
//! neighbours, as for a search whose every part was found by one search alone
//! (`KIND_SPLIT_LONG`, see `check`).

use super::{KIND_LOCAL, KIND_SPLIT_LONG, State, Verdict};
use crate::mesh::NONE;

/// Subtree sizes of the acyclic components (as the state's dual graph connects them).
#[derive(Debug)]
pub(super) struct Acyclic {
    /// Per triangle: its parent in the component's rooted spanning tree (NONE at the root).
    parent: Vec<u32>,
    /// Per triangle: the size of its subtree.
    size: Vec<u32>,
    /// Per triangle: the size of its component when that component has no cycle, else 0.
    component: Vec<u32>,
}

impl State<'_> {
    /// The subtree sizes of every acyclic component, or `None` when no component is acyclic
    /// (or has more than one triangle, so a pair). O(n), breadth first.
    pub(super) fn acyclic_parts(&self) -> Option<Acyclic> {
        let nt = self.alive.len();
        let mut parent = vec![NONE; nt];
        let mut size = vec![0u32; nt];
        let mut component = vec![0u32; nt];
        let mut seen = vec![false; nt];
        let mut order: Vec<u32> = Vec::new();
        let mut any = false;
        for start in 0..nt {
            if seen[start] {
                continue;
            }
            order.clear();
            order.push(start as u32);
            seen[start] = true;
            let mut ends = 0usize; // edge ends met: twice the edges
            let mut head = 0;
            while head < order.len() {
                let x = order[head];
                head += 1;
                for u in self.dual[x as usize] {
                    if u == NONE {
                        continue;
                    }
                    ends += 1;
                    if !seen[u as usize] {
                        seen[u as usize] = true;
                        parent[u as usize] = x;
                        order.push(u);
                    }
                }
            }
            let n = order.len();
            if n < 2 || ends / 2 != n - 1 {
                continue;
            }
            any = true;
            for &x in order.iter().rev() {
                size[x as usize] += 1;
                let p = parent[x as usize];
                if p != NONE {
                    size[p as usize] += size[x as usize];
                }
                component[x as usize] = n as u32;
            }
        }
        any.then_some(Acyclic {
            parent,
            size,
            component,
        })
    }

    /// The initial verdict of `c` when its component is acyclic, with its certificate left
    /// in scratch as [`State::check`] leaves it; `None` to search instead (another
    /// component, or a clean quad vertex, which takes a cycle around it).
    pub(super) fn acyclic_verdict(&mut self, a: &Acyclic, c: u32) -> Option<Verdict> {
        let [t0, t1] = self.table.pairs[c as usize];
        let total = a.component[t0 as usize];
        if total == 0 || self.clean_mask(c) != 0 {
            return None;
        }
        // One of the pair is the other's parent; the parent's parent is on the rest's side.
        let upper = if a.parent[t1 as usize] == t0 { t0 } else { t1 };
        debug_assert!(a.parent[t0 as usize] == t1 || a.parent[t1 as usize] == t0);
        let nb = self.cand[c as usize].nb;
        self.path.clear();
        self.nsearch = 0;
        self.narcs = 0;
        let mut odd = 0;
        for s in nb {
            if s == NONE {
                continue;
            }
            let p = a.parent[s as usize];
            let part = if p == t0 || p == t1 {
                a.size[s as usize]
            } else {
                total - a.size[upper as usize]
            };
            odd += part & 1;
            let k = self.nsearch;
            self.queue[k].clear();
            self.queue[k].push(s);
            self.cert_len[k] = 1;
            self.finished[k] = true;
            self.nsearch += 1;
        }
        if self.nsearch <= 1 {
            // One part or none: what the search's grouping says before searching.
            self.nsearch = 0;
            return Some(Verdict {
                allowed: true,
                kind: KIND_LOCAL,
                ..Verdict::default()
            });
        }
        Some(Verdict {
            allowed: odd <= 1,
            kind: KIND_SPLIT_LONG,
            fin_odd: odd as u8,
            fin_known: total - 2,
            ..Verdict::default()
        })
    }
}
