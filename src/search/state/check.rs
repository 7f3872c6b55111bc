//! The criterion for one candidate in the current state (local proof, distinct dead
//! components, lockstep search), the dead-component union–find, and the polder relabelling
//! after a split. See the module docs of `state` for the rule and why it is exact.

/// `clean_mask` bit: the local proof settles the verdict.
pub(super) const LOCAL_PROOF: u8 = 1 << 4;

/// The local proof by table, indexed by `live | clean << 4` (4 bits each, quad side / vertex
/// order): neighbours i-1 and i are linked at quad vertex i when both remain and the vertex
/// is clean; it holds when the links leave at most one group of remaining neighbours.
const LOCAL_OK: [bool; 256] = {
    let mut table = [false; 256];
    let mut idx = 0;
    while idx < 256 {
        let (live, clean) = (idx & 0xF, idx >> 4);
        let before = ((live << 1) | (live >> 3)) & 0xF;
        let links = live & before & clean;
        let groups = if links == 0xF {
            1
        } else {
            (live as u32).count_ones() - (links as u32).count_ones()
        };
        table[idx] = groups <= 1;
        idx += 1;
    }
    table
};

use super::{
    ACTIVE, BLOCKED, DEAD, EPOCH_LIMIT, KIND_DISTINCT, KIND_LOCAL, KIND_MET, KIND_SPLIT,
    KIND_SPLIT_LONG, LINKED, LONG_PART, Op, READ, ROOT_TAG, State, Verdict,
};
use crate::mesh::NONE;

impl State<'_> {
    /// Checks candidate `c` (both triangles remaining) in the current state. The verdict's
    /// certificate is left in scratch (`queue[..nsearch]` up to `cert_len`, or
    /// `arc_roots[..narcs]`; see [`State::append_cert`]); the searches' parts stay in
    /// `queue` / `group` / `head` for [`State::relabel_split`].
    pub(super) fn check(&mut self, c: u32) -> Verdict {
        let mask = self.clean_mask(c);
        if mask & LOCAL_PROOF != 0 {
            self.nsearch = 0;
            self.narcs = 0;
            self.path.clear();
            return Verdict {
                allowed: true,
                kind: KIND_LOCAL,
                mask: mask & 0xF,
                ..Verdict::default()
            };
        }
        self.check_slow(c, mask & 0xF)
    }

    /// The quad vertices of candidate `c` that are clean (bits 0..4: closed fan, no used
    /// triangle), plus `LOCAL_PROOF` when the links at those vertices join every remaining
    /// neighbour of the quad (one part: the action is allowed). A handful of loads.
    #[inline(always)]
    pub(super) fn clean_mask(&self, c: u32) -> u8 {
        let l = &self.cand[c as usize];
        let q = &self.table.quads[c as usize];
        let (dead, alive) = (&self.dead_count[..], &self.alive[..]);
        let clean = |i: usize| ((dead[q[i] as usize] == 0) as u8) << i;
        // `get` answers false for NONE (out of range): no separate test.
        let live = |i: usize| ((alive.get(l.nb[i] as usize) == Some(&true)) as u8) << i;
        let mask = (clean(0) | clean(1) | clean(2) | clean(3)) & l.flags;
        let live_bits = live(0) | live(1) | live(2) | live(3);
        let proof = LOCAL_OK[(live_bits | mask << 4) as usize] & !l.shared;
        mask | (proof as u8) << 4
    }
    /// [`State::check`] when the local proof does not settle it (or the quad has a
    /// neighbour across two of its sides); `mask`: the clean quad vertices.
    pub(super) fn check_slow(&mut self, c: u32, mask: u8) -> Verdict {
        self.path.clear();
        let [t0, t1] = self.table.pairs[c as usize];
        let n = self.cand[c as usize].nb;
        let q = self.table.quads[c as usize];
        // Group label of each neighbour slot, kept flat: joining relabels the 4 slots.
        let mut root = [0u8, 1, 2, 3];
        #[inline(always)]
        fn join(r: &mut [u8; 4], a: usize, b: usize) {
            let (x, y) = (r[a], r[b]);
            if x != y {
                for k in r.iter_mut() {
                    if *k == y {
                        *k = x;
                    }
                }
            }
        }
        let mut live = [false; 4];
        for i in 0..4 {
            live[i] = n[i] != NONE && self.alive[n[i] as usize];
        }
        for i in 0..4 {
            if !live[i] {
                continue;
            }
            for j in 0..i {
                if live[j] && n[i] == n[j] {
                    join(&mut root, i, j);
                }
            }
            let j = (i + 1) % 4;
            if live[j] && mask & (1 << j) != 0 {
                join(&mut root, i, j);
            }
        }
        // Distinct groups of live neighbours: one search per group.
        let groups_of = |root: &[u8; 4]| {
            let mut sid = [u8::MAX; 4];
            let mut ns = 0usize;
            for i in 0..4 {
                if live[i] {
                    let r = root[i] as usize;
                    if sid[r] == u8::MAX {
                        sid[r] = ns as u8;
                        ns += 1;
                    }
                }
            }
            (sid, ns)
        };
        let (mut sid, mut ns) = groups_of(&root);
        self.nsearch = 0;
        self.narcs = 0;
        let verdict = |allowed: bool, kind: u8| Verdict {
            allowed,
            kind,
            mask,
            ..Verdict::default()
        };
        if ns <= 1 {
            return verdict(true, KIND_LOCAL);
        }
        // Where the quad touches the removed region: arcs of touched vertices joined by
        // touched edges, each between two live neighbours (the edge before its first
        // vertex and the one after its last: a clean vertex's edges are live). A split
        // needs one dead component to touch the quad twice.
        let mut arc_link = [(0usize, 0usize); 4];
        let mut arc_at = [0usize; 4];
        let mut distinct = true;
        for i in 0..4 {
            let prev = (i + 3) % 4;
            let touched = mask & (1 << i) == 0;
            let touched_prev = mask & (1 << prev) == 0;
            // Edge `prev` joins q[prev] and q[i]; touched when its neighbour is gone.
            if touched && (live[prev] || !touched_prev) {
                let r = self.find(q[i]);
                distinct &= !self.arc_roots[..self.narcs].contains(&r);
                // The arc runs over touched edges (whose ends are touched) to a live one;
                // there is one, since two groups of live neighbours exist.
                let mut j = i;
                while !live[j] {
                    j = (j + 1) % 4;
                }
                arc_link[self.narcs] = (prev, j);
                arc_at[self.narcs] = i;
                self.arc_roots[self.narcs] = r;
                self.narcs += 1;
            }
        }
        if distinct && self.narcs > 0 {
            return verdict(true, KIND_DISTINCT);
        }
        // A dead component that touches the quad in one arc only links the live
        // neighbours on either side of that arc: the frontier of the component (through
        // remaining triangles, crossing only candidate sides) runs from one to the other
        // around it, and meets the quad nowhere else. So only components touching it twice
        // separate groups. The link holds while the arcs' components stay distinct (every
        // arc's root stays a root: watched) and the clean vertices clean; the roots join
        // the certificate. (Skipped when the links leave one group: that happens only on a
        // surface that is not a sphere or plane, where a component touched twice need not
        // cut; the searches decide those as before.)
        let mut linked = false;
        if self.narcs > 2 {
            let mut root2 = root;
            for a in 0..self.narcs {
                let r = self.arc_roots[a];
                if self.arc_roots[..self.narcs]
                    .iter()
                    .filter(|&&x| x == r)
                    .count()
                    == 1
                {
                    let (b, e) = arc_link[a];
                    join(&mut root2, b, e);
                }
            }
            let (sid2, ns2) = groups_of(&root2);
            if ns2 >= 2 && ns2 < ns {
                (root, sid, ns) = (root2, sid2, ns2);
                linked = true;
            }
        }
        // Groups separated by the one dead component the quad touches `k >= 2` times (the
        // others touch it once): on a sphere with holes its arcs cut the quad's boundary
        // into `k` runs, one group each, each in a part of its own; the path of dead edges
        // between a run's two end arcs closes, with the quad's sides along the run, into a
        // curve around that part, whose triangles number the parity of its edge weights
        // ([`super::parity`], [`State::run_parities`]). The polder is even (none that was is
        // odd), and the verdict is that of a long split certified by every group's seeds.
        let one = if ns >= 2
            && !self.need_parts
            && self.odd_active == 0
            && self.cand[c as usize].par & ACTIVE != 0
            && !self.cand[c as usize].shared
        {
            self.arcs_of_one().filter(|&(_, k)| k == ns)
        } else {
            None
        };
        if !linked {
            self.narcs = 0;
        }
        let vmask = if linked { mask | LINKED } else { mask };
        let verdict = |allowed: bool, kind: u8| Verdict {
            allowed,
            kind,
            mask: vmask,
            ..Verdict::default()
        };
        if let Some((d, k)) = one {
            let odd = self.run_parities(c, &arc_at, &d[..k]);
            let total = self.polder_size[self.polder[t0 as usize] as usize];
            debug_assert_eq!(total % 2, 0, "an active polder is even");
            debug_assert_eq!(
                odd[..k].iter().fold(0, |x, &y| x ^ y),
                0,
                "the parts of an even polder less a quad have an even total"
            );
            debug_assert!(
                self.runs_are_groups(&arc_at, &d[..k], &live, &root),
                "each run of neighbours between two arcs is one group"
            );
            self.parity_splits += 1;
            if k > 2 {
                self.parity_multi[k - 3] += 1;
            }
            self.nsearch = ns;
            for s in 0..ns {
                self.queue[s].clear();
                self.group[s] = s as u8;
                self.finished[s] = true;
            }
            for i in 0..4 {
                if live[i] {
                    self.queue[sid[root[i] as usize] as usize].push(n[i]);
                }
            }
            for s in 0..ns {
                self.nseed[s] = self.queue[s].len();
                self.cert_len[s] = self.nseed[s];
            }
            let odd_parts = odd[..k].iter().map(|&x| x as u32).sum::<u32>();
            return Verdict {
                fin_odd: odd_parts as u8,
                fin_known: total - 2,
                mask: vmask | READ,
                ..verdict(odd_parts == 0, KIND_SPLIT_LONG)
            };
        }
        self.searches += 1;
        self.epoch += 1;
        if self.epoch > EPOCH_LIMIT {
            self.stamp.iter_mut().for_each(|s| {
                if *s != DEAD {
                    *s = 0;
                }
            });
            self.epoch = 1;
        }
        let base = self.epoch << 3;
        self.stamp[t0 as usize] = base | BLOCKED;
        self.stamp[t1 as usize] = base | BLOCKED;
        self.nsearch = ns;
        for s in 0..ns {
            self.queue[s].clear();
            self.head[s] = 0;
            self.group[s] = s as u8;
        }
        for i in 0..4 {
            if live[i] {
                let t = n[i] as usize;
                if self.stamp[t] < base {
                    let s = sid[root[i] as usize];
                    self.stamp[t] = base | s as u32;
                    self.queue[s as usize].push(t as u32);
                }
            }
        }
        for s in 0..ns {
            self.nseed[s] = self.queue[s].len();
        }
        // The dense dual graph: a search streams through many triangles and reads only
        // their neighbours.
        let nb = &self.dual[..];
        loop {
            // The verdict can only change when a search runs dry or two groups meet.
            let mut event = false;
            for s in 0..ns {
                event |= search_step(
                    s,
                    ns,
                    base,
                    nb,
                    &mut self.queue[s],
                    &mut self.head[s],
                    &mut self.stamp,
                    &mut self.group,
                );
            }
            if !event {
                continue;
            }
            // Groups and how many are still running.
            let mut groups = 0;
            let mut running = 0;
            let (gsize, gdone) = self.group_parts(ns);
            for s in 0..ns {
                if self.group[s] as usize == s {
                    groups += 1;
                    if !gdone[s] {
                        running += 1;
                    }
                }
            }
            if groups == 1 {
                self.count_searched(ns);
                self.join_paths((1 << ns) - 1, base);
                return verdict(true, KIND_MET);
            }
            if running <= 1 {
                self.count_searched(ns);
                let total = self.polder_size[self.polder[t0 as usize] as usize] - 2;
                let mut odd = 0;
                let mut known = 0;
                for s in 0..ns {
                    if self.group[s] as usize == s && gdone[s] {
                        odd += gsize[s] & 1;
                        known += gsize[s];
                    }
                }
                let mut all = odd;
                if running == 1 {
                    all += (total - known) & 1;
                } else {
                    debug_assert_eq!(known, total, "parts add up to the polder");
                }
                // Certificate: the finished parts whole; for the running part, the paths
                // along which its searches met, or only its seeds when it is one search
                // (every triangle of that part then hangs off those seeds). A finished part
                // of more than LONG_PART triangles found by one search is certified by its
                // seeds too (KIND_SPLIT_LONG): while they remain (and its clean vertices
                // stay clean) it stays one part, hanging off them, and an action inside it
                // changes its parity only by cutting off pieces of odd total, which
                // changes the parity of the polder as well; so the verdict holds while no
                // split changes the polder's parity.
                let mut long = false;
                for s in 0..ns {
                    let g = self.group[s] as usize;
                    let alone = (0..ns).filter(|&r| self.group[r] as usize == g).count() == 1;
                    let seeds = alone && (!gdone[g] || self.queue[s].len() > LONG_PART);
                    long |= seeds && gdone[g];
                    self.cert_len[s] = if seeds {
                        self.nseed[s]
                    } else {
                        self.queue[s].len()
                    };
                    self.finished[s] = gdone[g];
                }
                let running_searches = (0..ns)
                    .filter(|&s| !gdone[self.group[s] as usize])
                    .fold(0u8, |m, s| m | 1 << s);
                if running_searches.count_ones() >= 2 {
                    self.join_paths(running_searches, base);
                }
                let kind = if long { KIND_SPLIT_LONG } else { KIND_SPLIT };
                return Verdict {
                    fin_odd: odd as u8,
                    fin_known: known,
                    ..verdict(all <= 1, kind)
                };
            }
        }
    }

    /// After lockstep searches met in one group (`members`, a bit per search; marks `base |
    /// s`): makes that group's share of the certificate the paths that join its searches
    /// (in `path`, `cert_len` 0 for its searches), not every triangle they visited (the
    /// queues stay whole: a split's parts are relabelled from them). A breadth-first search through the group's visited triangles from the
    /// first search's seeds reaches a seed of every other one (a search's seeds count as
    /// one: their links are certified apart); the tree paths back from
    /// those seeds are the certificate. While those triangles remain, the searches' groups
    /// stay one part (the links within a search's seeds are certified apart: clean
    /// vertices, linked arcs' roots). Searches meet where the quad touches one dead
    /// component twice without cutting the polder: around a handle (a torus). There the
    /// visited sets went round the handle, and every action on them sent the verdict back
    /// to a search as long (uniform h = 2 on the suite's torus took 1.4 s; selective h = 3
    /// 0.16 s).
    fn join_paths(&mut self, members: u8, base: u32) {
        /// Marks of this pass: reached by the breadth-first search, and on a path.
        const REACHED: u32 = 6;
        const ON_PATH: u32 = 5;
        let first = members.trailing_zeros() as usize;
        let others = || (first + 1..4).filter(move |&s| members & (1 << s) != 0);
        let mut bfs = std::mem::take(&mut self.path_bfs);
        bfs.clear();
        // A search's seeds are joined by the links that grouped them (clean vertices,
        // linked arcs), not always through the triangles visited so far: reaching one
        // reaches them all (a step of no triangle, certified apart).
        let seed_search = |t: u32| {
            (1..4).find(|&s| members & (1 << s) != 0 && self.queue[s][..self.nseed[s]].contains(&t))
        };
        for &t in &self.queue[first][..self.nseed[first]] {
            self.stamp[t as usize] = base | REACHED;
            bfs.push([t, NONE]);
        }
        // The index in `bfs` of the seed reached first for each other search.
        let mut target = [NONE; 4];
        let mut left = others().count();
        let mut head = 0;
        while left > 0 {
            let Some(&[x, _]) = bfs.get(head) else {
                // Unreachable (the searches met through these triangles and links); were it
                // reached, every visited triangle is a certificate as before.
                debug_assert!(false, "the met searches' triangles join their seeds");
                for s in 0..4 {
                    if members & (1 << s) != 0 {
                        self.cert_len[s] = self.queue[s].len();
                    }
                }
                self.path_bfs = bfs;
                return;
            };
            for &u in &self.dual[x as usize] {
                let Some(m) = self.stamp.get_mut(u as usize) else {
                    continue;
                };
                // Visited by a search of the group: marked `base | s`, `s` a member.
                if *m < base || *m == DEAD || members & (1 << (*m & 7)) == 0 {
                    continue;
                }
                *m = base | REACHED;
                bfs.push([u, head as u32]);
                let at = bfs.len() as u32 - 1;
                if let Some(s) = seed_search(u)
                    && target[s] == NONE
                {
                    target[s] = at;
                    left -= 1;
                    for &t in &self.queue[s][..self.nseed[s]] {
                        if self.stamp[t as usize] != base | REACHED {
                            self.stamp[t as usize] = base | REACHED;
                            bfs.push([t, at]);
                        }
                    }
                }
            }
            head += 1;
        }
        let path = &mut self.path;
        path.clear();
        for s in others() {
            let mut i = target[s];
            while i != NONE {
                let [t, parent] = bfs[i as usize];
                if self.stamp[t as usize] == base | ON_PATH {
                    break;
                }
                self.stamp[t as usize] = base | ON_PATH;
                path.push(t);
                i = parent;
            }
            self.cert_len[s] = 0;
        }
        self.cert_len[first] = 0;
        self.path_bfs = bfs;
    }

    /// The arcs (indices, in quad order, and how many) of the one dead component that
    /// touches the quad more than once, when every other arc's component touches it once.
    fn arcs_of_one(&self) -> Option<([usize; 4], usize)> {
        let roots = &self.arc_roots[..self.narcs];
        let mut d = NONE;
        for &r in roots {
            if r != d && roots.iter().filter(|&&x| x == r).count() > 1 {
                if d != NONE {
                    return None;
                }
                d = r;
            }
        }
        if d == NONE {
            return None;
        }
        let (mut arcs, mut k) = ([0usize; 4], 0);
        for (a, &r) in roots.iter().enumerate() {
            if r == d {
                arcs[k] = a;
                k += 1;
            }
        }
        Some((arcs, k))
    }

    /// The parity of each part when the quad of `c` touches one dead component at the arcs
    /// `d` (indices into `arc_at`, the arcs' first quad vertices, in quad order): part `r`
    /// holds the run of neighbours from arc `d[r]` forwards to arc `d[r + 1]` (cyclically),
    /// and its parity is the weight of the closed curve made of the dead path between the
    /// two arcs' first vertices ([`State::find_par`]) and the quad's sides from `d[r]`'s
    /// forwards to `d[r + 1]`'s: exactly the sides facing that run (and its arcs' own dead
    /// sides, which are dead edges of the components they belong to). (The other way round
    /// gives the same sum: the quad's four sides sum to 0, its two triangles counting
    /// alike.)
    fn run_parities(&self, c: u32, arc_at: &[usize; 4], d: &[usize]) -> [u8; 4] {
        let q = &self.table.quads[c as usize];
        let mut at_par = [0u8; 4];
        for (r, &a) in d.iter().enumerate() {
            at_par[r] = self.find_par(q[arc_at[a]]).1;
        }
        debug_assert_eq!(self.quad_path(c, 0, 4), 0, "a quad's sides sum to 0");
        let mut odd = [0u8; 4];
        for r in 0..d.len() {
            let r2 = (r + 1) % d.len();
            let (s, e) = (arc_at[d[r]], arc_at[d[r2]]);
            let sides = if s < e {
                self.quad_path(c, s, e)
            } else {
                self.quad_path(c, s, 4) ^ self.quad_path(c, 0, e)
            };
            odd[r] = at_par[r] ^ at_par[r2] ^ sides;
        }
        odd
    }

    /// Whether the live neighbours between consecutive arcs `d` (of `arc_at`, as for
    /// [`State::run_parities`]) are one group per run, a different one for each run
    /// (`root`: the groups' labels per quad side). A debug check.
    fn runs_are_groups(
        &self,
        arc_at: &[usize; 4],
        d: &[usize],
        live: &[bool; 4],
        root: &[u8; 4],
    ) -> bool {
        let mut label = [u8::MAX; 4];
        for r in 0..d.len() {
            let (s, e) = (arc_at[d[r]], arc_at[d[(r + 1) % d.len()]]);
            // Sides s, s + 1, ... up to (not including) e, cyclically.
            let mut i = s;
            loop {
                if live[i] {
                    if label[r] == u8::MAX {
                        label[r] = root[i];
                    } else if label[r] != root[i] {
                        return false;
                    }
                }
                i = (i + 1) % 4;
                if i == e {
                    break;
                }
            }
            if label[r] == u8::MAX || label[..r].contains(&label[r]) {
                return false;
            }
        }
        true
    }

    /// Per group (indexed by its root search) of the current searches: triangles visited,
    /// and whether every search of the group has finished.
    #[inline]
    fn group_parts(&self, ns: usize) -> ([u32; 4], [bool; 4]) {
        let mut gsize = [0u32; 4];
        let mut gdone = [true; 4];
        for s in 0..ns {
            let g = self.group[s] as usize;
            gsize[g] += self.queue[s].len() as u32;
            if self.head[s] < self.queue[s].len() {
                gdone[g] = false;
            }
        }
        (gsize, gdone)
    }

    /// Appends the certificate of the last [`State::check`] (of a verdict of kind `kind`)
    /// to the base arena (`tree == false`) or the tree's, and returns `(offset, length)`:
    /// dead-component roots for `KIND_DISTINCT`, triangles for `KIND_MET` / `KIND_SPLIT`.
    pub(super) fn append_cert(&mut self, kind: u8, tree: bool) -> (u32, u32) {
        let arena = if tree {
            &mut self.tree.cert
        } else {
            &mut self.base_cert
        };
        let off = arena.len();
        if kind == KIND_DISTINCT {
            arena.extend_from_slice(&self.arc_roots[..self.narcs]);
        } else if kind == KIND_SPLIT {
            // The finished parts first (`fin_known` triangles), then the running part's.
            for fin in [true, false] {
                for s in 0..self.nsearch {
                    if self.finished[s] == fin {
                        arena.extend_from_slice(&self.queue[s][..self.cert_len[s]]);
                    }
                }
            }
        } else if kind != KIND_LOCAL {
            for s in 0..self.nsearch {
                arena.extend_from_slice(&self.queue[s][..self.cert_len[s]]);
            }
        }
        if kind != KIND_DISTINCT && kind != KIND_LOCAL {
            // The paths joining searches that met (the running part's, after a split's
            // finished parts).
            arena.extend_from_slice(&self.path);
            // Linked groups: the arcs' roots, tagged.
            arena.extend(self.arc_roots[..self.narcs].iter().map(|&r| r | ROOT_TAG));
        }
        (off as u32, (arena.len() - off) as u32)
    }

    /// Whether verdict `v` of candidate `c` (both triangles remaining) still holds in the
    /// current state, reached from the state it was computed in by applying actions only
    /// (never undoing past it); `Some(allowed)` if so, `None` if it must be recomputed. The
    /// vertices that were clean must still be, its certificate (in `arena`) intact; a split's
    /// verdict is re-derived from the current size of the polder (the running part is the
    /// rest of it); a long split's holds while its polder is not among `changed` (the
    /// polders whose parity a split changed since the verdict was computed, with every
    /// part later cut from them).
    #[inline]
    pub(super) fn still_holds(
        &self,
        c: u32,
        v: &Verdict,
        arena: &[u32],
        changed: &[u32],
    ) -> Option<bool> {
        if v.mask != 0 {
            let q = self.table.quads[c as usize];
            for i in 0..4 {
                if v.mask & (1 << i) != 0 && self.dead_count[q[i] as usize] != 0 {
                    return None;
                }
            }
        }
        if v.kind == KIND_LOCAL {
            return Some(v.allowed);
        }
        let cert = &arena[v.cert as usize..(v.cert + v.cert_len) as usize];
        if v.kind == KIND_DISTINCT {
            return cert
                .iter()
                .all(|&r| self.dsu_parent[r as usize] == r)
                .then_some(true);
        }
        let intact = if v.mask & LINKED == 0 {
            cert.iter().all(|&t| self.alive[t as usize])
        } else {
            cert.iter().all(|&t| {
                if t & ROOT_TAG == 0 {
                    self.alive[t as usize]
                } else {
                    let r = t & !ROOT_TAG;
                    self.dsu_parent[r as usize] == r
                }
            })
        };
        if !intact {
            return None;
        }
        if v.kind == KIND_MET {
            return Some(true);
        }
        let t0 = self.table.pairs[c as usize][0];
        if v.kind == KIND_SPLIT_LONG {
            let p = self.polder[t0 as usize];
            return (!changed.contains(&p)).then_some(v.allowed);
        }
        let total = self.polder_size[self.polder[t0 as usize] as usize] - 2;
        let rest = total.wrapping_sub(v.fin_known);
        Some(v.fin_odd as u32 + (rest & 1) <= 1)
    }

    /// Root of vertex `v`'s dead component.
    #[inline]
    pub(super) fn find(&self, mut v: u32) -> u32 {
        while self.dsu_parent[v as usize] != v {
            v = self.dsu_parent[v as usize];
        }
        v
    }

    /// Root of vertex `v`'s dead component and the parity of the edge weights along the
    /// union–find's path of dead edges from `v` to it ([`super::parity`]).
    #[inline]
    pub(super) fn find_par(&self, mut v: u32) -> (u32, u8) {
        let mut p = 0;
        while self.dsu_parent[v as usize] != v {
            p ^= self.dsu_par[v as usize];
            v = self.dsu_parent[v as usize];
        }
        (v, p)
    }

    /// Joins the dead components of `a` and `b`, which a path of dead edges of weight
    /// parity `w` joins (logged inside a look-ahead tree, `tree`, else as a base change:
    /// [`State::shared_log`]); returns the root that was attached under the other, if they
    /// were distinct.
    pub(super) fn union(&mut self, a: u32, b: u32, w: u8, tree: bool) -> Option<u32> {
        let ((mut ra, pa), (mut rb, pb)) = (self.find_par(a), self.find_par(b));
        if ra == rb {
            return None;
        }
        if self.dsu_size[ra as usize] < self.dsu_size[rb as usize] {
            std::mem::swap(&mut ra, &mut rb);
        }
        self.dsu_parent[rb as usize] = ra;
        self.dsu_par[rb as usize] = pa ^ pb ^ w;
        self.dsu_size[ra as usize] += self.dsu_size[rb as usize];
        self.shared_log(
            Op::Union {
                child: rb,
                root: ra,
            },
            tree,
        );
        Some(rb)
    }

    /// The parity of the edge weights along candidate `c`'s quad sides from its vertex
    /// `from` to its vertex `to` (`from <= to`), forwards: sides `from..to`.
    #[inline]
    pub(super) fn quad_path(&self, c: u32, from: usize, to: usize) -> u8 {
        let sides = (1u8 << to) - (1u8 << from);
        ((self.cand[c as usize].par & sides).count_ones() & 1) as u8
    }

    /// [`State::check`], searching whatever the verdict: the parts of a split are left for
    /// [`State::relabel_split`].
    pub(super) fn check_parts(&mut self, c: u32) -> Verdict {
        self.need_parts = true;
        let v = self.check(c);
        self.need_parts = false;
        v
    }

    fn count_searched(&mut self, ns: usize) {
        for s in 0..ns {
            self.searched += self.queue[s].len() as u64;
        }
    }

    /// After a [`State::check_parts`] that found a split of candidate `c`'s polder: gives each
    /// finished part a new polder id (logged as [`State::union`] is) and the rest (the
    /// running part, or the largest when all finished) the old id with its new size. The ids whose size changed parity
    /// are left in `changed`.
    pub(super) fn relabel_split(&mut self, c: u32, tree: bool) {
        let t0 = self.table.pairs[c as usize][0];
        let changed_before = self.changed.len();
        let p = self.polder[t0 as usize];
        let psize = self.polder_size[p as usize];
        let ns = self.nsearch;
        // Whole parts found: each finished group; keep the old id for the running one, or
        // for the largest when all finished.
        let (gsize, gdone) = self.group_parts(ns);
        let mut keep = usize::MAX;
        for g in 0..ns {
            if self.group[g] as usize == g && !gdone[g] {
                keep = g;
            }
        }
        if keep == usize::MAX {
            for g in 0..ns {
                if self.group[g] as usize == g && (keep == usize::MAX || gsize[g] > gsize[keep]) {
                    keep = g;
                }
            }
        }
        let mut known = 0;
        for g in 0..ns {
            if self.group[g] as usize != g || g == keep {
                continue;
            }
            let id = self.polder_size.len() as u32;
            self.polder_size.push(gsize[g]);
            self.shared_log(Op::PolderNew, tree);
            known += gsize[g];
            if gsize[g] % 2 != psize % 2 {
                self.changed.push(id);
            }
            for s in 0..ns {
                if self.group[s] as usize != g {
                    continue;
                }
                for i in 0..self.queue[s].len() {
                    let t = self.queue[s][i];
                    self.shared_log(Op::Polder { t, old: p }, tree);
                    self.polder[t as usize] = id;
                }
            }
        }
        let rest = psize - 2 - known;
        if rest % 2 != psize % 2 {
            self.changed.push(p);
        }
        self.shared_log(Op::PolderSize { p, old: psize }, tree);
        self.polder_size[p as usize] = rest;
        // An even polder left an odd part (an action the criterion forbids): parities no
        // longer tell parts apart ([`super::parity`]) until that is undone.
        if self.cand[c as usize].par & ACTIVE != 0 && self.changed.len() > changed_before {
            let old = self.odd_active;
            self.shared_log(Op::OddActive { old }, tree);
            self.odd_active = old + 1;
        }
    }
}

/// One step of lockstep search `s` (of `ns`, marks `base | s`): visits the next triangle of
/// its queue. True when that changed what the verdict can be: the search ran dry or met
/// another group (the groups are then merged). Arguments apart so that the compiler knows
/// they do not overlap.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn search_step(
    s: usize,
    ns: usize,
    base: u32,
    nb: &[[u32; 3]],
    queue: &mut Vec<u32>,
    head: &mut usize,
    stamp: &mut [u32],
    group: &mut [u8; 4],
) -> bool {
    let h = *head;
    let Some(&x) = queue.get(h) else {
        return false;
    };
    *head = h + 1;
    let own = base | s as u32;
    let mut event = false;
    for &u in &nb[x as usize] {
        // `get_mut` answers None for NONE (out of range): no separate test.
        let Some(m) = stamp.get_mut(u as usize) else {
            continue;
        };
        if *m < base {
            *m = own;
            queue.push(u);
        } else if *m != own && *m != DEAD && *m != base | BLOCKED {
            // Another search's triangle. Groups are kept flat (`group[s]` is the root), so a
            // meeting is one comparison; a merge relabels the (at most 4) members.
            let (a, b) = (group[(*m & 7) as usize], group[s]);
            if a != b {
                for g in group[..ns].iter_mut() {
                    if *g == a {
                        *g = b;
                    }
                }
                event = true;
            }
        }
    }
    event || h + 1 == queue.len()
}
