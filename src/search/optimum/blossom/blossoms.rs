//! Blossoms: shrinking an odd cycle of a tree into one node, expanding a minus blossom
//! whose dual reached zero, augmenting along a path, and rotating a blossom's cycle to a
//! new base.

use super::{FREE, Graph, MINUS, NONE, PLUS, Solver};

impl Solver {
    /// Shrinks the blossom closed by the tight edge `u`–`v` between two plus nodes.
    pub(super) fn shrink(&mut self, g: &Graph, u: u32, v: u32) {
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
    pub(super) fn expand(&mut self, g: &Graph, b: u32) {
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
    pub(super) fn augment(&mut self, v: u32, w: u32) {
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
    pub(super) fn rotate(&mut self, b: u32, v: u32) {
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
}
