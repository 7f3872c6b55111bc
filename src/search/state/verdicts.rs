//! Keeping verdicts current: rechecking a candidate and installing its verdict and
//! certificate (watches, split shrinking), the base certificate log, the counts per
//! triangle and bucket, stale marks and their lazy resolution.

use super::{
    Initial, KIND_DISTINCT, KIND_LOCAL, KIND_SPLIT, LINKED, Op, READ, State, Verdict, WatchLists,
    is_split,
};
use crate::mesh::NONE;

impl State<'_> {
    /// Recomputes the verdict of live candidate `c` and records its certificate.
    pub(super) fn recheck_one(&mut self, c: u32) {
        if self.forward && self.base_cert.len() >= self.base_cert_compact_at {
            self.compact_base_cert();
        }
        let y = self.last_local;
        if y != NONE
            && self.chosen.last() == Some(&y)
            && self.shrink_split(c, y, self.last_local_mask, false)
        {
            return;
        }
        let r = self.check(c);
        self.install_verdict(c, r);
    }

    /// Makes `r` the verdict of `c`, its certificate the one the last check left in scratch
    /// ([`State::append_cert`]), and updates the counts, watch lists and split list.
    pub(super) fn install_verdict(&mut self, c: u32, mut r: Verdict) {
        let ci = c as usize;
        let old = self.cand[ci].verdict;
        // A verdict of the local kind is never read back through its mask (the trees
        // recompute the local proof first), so a new mask alone is not a change.
        if r.kind == KIND_LOCAL && old.kind == KIND_LOCAL && r.allowed == old.allowed {
            return;
        }
        if self.forward && r.kind == KIND_DISTINCT && old.kind == KIND_DISTINCT {
            self.reinstall_distinct(c, r);
            return;
        }
        self.base_log(Op::Verdict {
            c,
            old,
            ver: self.cert_ver[ci],
        });
        self.ver = self.ver.wrapping_add(1);
        let ver = self.ver;
        self.cert_ver[ci] = ver;
        (r.cert, r.cert_len) = self.append_cert(r.kind, false);
        self.cand[ci].verdict = r;
        if r.allowed != old.allowed {
            let [t0, t1] = self.table.pairs[ci];
            for t in [t0, t1] {
                let k = self.count[t as usize];
                self.set_count(t, if r.allowed { k + 1 } else { k - 1 });
            }
        }
        if r.kind == KIND_DISTINCT {
            for i in 0..self.narcs {
                self.root_watch_push(self.arc_roots[i], c, ver);
            }
        } else if r.kind != KIND_LOCAL {
            // A split read off parities: its seeds are in the certificate (for the trees)
            // but not watched ([`READ`]).
            let seeds = if r.mask & READ != 0 { 0 } else { self.nsearch };
            for s in 0..seeds {
                for i in 0..self.cert_len[s] {
                    let t = self.queue[s][i];
                    self.watch_push(t, c, ver);
                }
            }
            if r.mask & READ == 0 {
                for i in 0..self.path.len() {
                    let t = self.path[i];
                    self.watch_push(t, c, ver);
                }
            }
            // Linked groups: every arc's root must stay a root.
            for i in 0..self.narcs {
                self.root_watch_push(self.arc_roots[i], c, ver);
            }
        }
        let in_split = self.split_pos[ci] != NONE;
        if is_split(r.kind) && !in_split {
            self.split_pos[ci] = self.split.len() as u32;
            self.split.push(c);
            self.base_log(Op::SplitIns);
        } else if !is_split(r.kind) && in_split {
            let p = self.split_pos[ci];
            self.split.swap_remove(p as usize);
            if let Some(&y) = self.split.get(p as usize) {
                self.split_pos[y as usize] = p;
            }
            self.split_pos[ci] = NONE;
            self.base_log(Op::SplitRem { c, pos: p });
        }
    }

    /// Keeps the split verdict of `c` without a new search when the only change since it
    /// was exact is the last action `y`, applied with a local proof, sharing no vertex
    /// with `c`, inside one of the parts `c` would leave. That part minus `y`'s pair is
    /// still one part: `y`'s remaining neighbours stay joined through the fans of its clean
    /// vertices, which hold no triangle of `c` (no shared vertex) and no used one. Its
    /// parity is unchanged (two triangles fewer), and so is the verdict. The certificate
    /// drops the pair: a finished part's list is the whole part again (rewritten in place
    /// when it was written after the initial state, else copied); the running part's paths
    /// along which its searches met gain those fans, through which they still meet
    /// (copied). Forward mode only (nothing to undo). A split verdict's certificate lists
    /// its finished parts first, `fin_known` triangles in all.
    ///
    /// `distinct`: `y` was applied with the distinct-dead-components proof instead (its arcs'
    /// components, before `y` joined them, in `y_roots`; this `apply`'s unions in
    /// `attached`). Its pair must then lie in a finished part of `c`, no vertex shared, and
    /// `c`'s quad must touch at most one of those components: without `c`'s pair, `y`'s
    /// arcs are then still in distinct components and `y` cuts nothing of `c`'s part.
    pub(super) fn shrink_split(&mut self, c: u32, y: u32, ymask: u8, distinct: bool) -> bool {
        if !self.forward {
            return false;
        }
        let ci = c as usize;
        let v = self.cand[ci].verdict;
        if v.kind != KIND_SPLIT || v.mask & LINKED != 0 {
            return false;
        }
        let (qc, qy) = (self.table.quads[ci], self.table.quads[y as usize]);
        if distinct {
            if qc.iter().any(|a| qy.contains(a)) || !self.distinct_without(c) {
                return false;
            }
        } else {
            // The links at a vertex `c`'s quad shares with `y`'s pass through `c`'s
            // triangles: only the other clean vertices count, and they must still join
            // `y`'s remaining neighbours (`c`'s own triangles left out).
            let mut ymask = ymask;
            for (i, v) in qy.iter().enumerate() {
                if qc.contains(v) {
                    ymask &= !(1 << i);
                }
            }
            if !self.joined_without(y, ymask, self.table.pairs[ci]) {
                return false;
            }
        }
        let [a, b] = self.table.pairs[y as usize];
        let (off, fin, len) = (v.cert as usize, v.fin_known as usize, v.cert_len as usize);
        let cert = &self.base_cert[off..off + len];
        let keep = |t: &u32| *t != a && *t != b;
        let (off, len, fin_known) = if let Some(ia) = cert[..fin].iter().position(|&t| t == a) {
            let ib = cert[..fin].iter().position(|&t| t == b);
            let ib = ib.expect("both triangles of a pair are in the same part");
            let (lo, hi) = (ia.min(ib), ia.max(ib));
            if off >= self.cert_floor() {
                // Swap the pair to the end of the finished parts, then close the gap.
                let arena = &mut self.base_cert;
                arena.swap(off + hi, off + fin - 1);
                arena.swap(off + lo, off + fin - 2);
                arena.copy_within(off + fin..off + len, off + fin - 2);
                (off, len - 2, v.fin_known - 2)
            } else {
                let new = self.base_cert.len();
                for i in off..off + len {
                    let t = self.base_cert[i];
                    if keep(&t) {
                        self.base_cert.push(t);
                    }
                }
                (new, len - 2, v.fin_known - 2)
            }
        } else {
            // The running part's paths through `y`'s pair are rerouted through the fans
            // of a local proof; a distinct-components proof gives no such detour.
            if distinct || !cert[fin..].iter().any(|t| !keep(t)) || !self.fans(y, ymask) {
                return false;
            }
            let new = self.base_cert.len();
            self.base_cert.extend_from_within(off..off + fin);
            for i in off + fin..off + len {
                let t = self.base_cert[i];
                if keep(&t) {
                    self.base_cert.push(t);
                }
            }
            let ver = self.cert_ver[ci];
            for i in 0..self.fan.len() {
                let t = self.fan[i];
                self.base_cert.push(t);
                self.watch_push(t, c, ver);
            }
            (new, self.base_cert.len() - new, v.fin_known)
        };
        let kept = Verdict {
            cert: off as u32,
            cert_len: len as u32,
            fin_known,
            ..v
        };
        self.cand[ci].verdict = kept;
        self.split_shrinks += 1;
        true
    }

    /// Forward mode, when a dead-component root that the distinct-components verdict of
    /// `c` (exact, version `ver`) watches was just attached: keeps the verdict when its
    /// arcs' components are still distinct, with their current roots as its certificate
    /// (each newly watched), instead of a recheck. The verdict needs nothing else: the
    /// arcs themselves (which quad vertices and sides are touched) change only when a
    /// clean vertex of the quad gets a used triangle, which marks it, or when a quad
    /// neighbour between two arcs goes, whose quad joins those arcs' components. On a
    /// jittered grid under the valid-quad rule, two rechecks in five were these (a tree of
    /// dropped pairs joining the front) and found the verdict again.
    pub(super) fn keep_distinct(&mut self, c: u32, ver: u32) -> bool {
        let ci = c as usize;
        let v = self.cand[ci].verdict;
        if !self.forward || v.kind != KIND_DISTINCT || self.cand[ci].dirty {
            return false;
        }
        let (off, len) = (v.cert as usize, v.cert_len as usize);
        debug_assert!(len <= 4, "a distinct verdict has at most 4 arcs");
        let mut roots = [NONE; 4];
        for k in 0..len {
            let r = self.find(self.base_cert[off + k]);
            if roots[..k].contains(&r) {
                return false;
            }
            roots[k] = r;
        }
        debug_assert_eq!(ver, self.cert_ver[ci]);
        self.set_distinct_cert(c, roots, len);
        self.distinct_kept += 1;
        true
    }

    /// Forward mode: makes the first `n` of `roots` the certificate of the
    /// distinct-components verdict of `c`, keeping its version: in place when its current
    /// certificate is its own (past [`State::cert_floor`]) and as long, else appended (an
    /// initial verdict's stays as it is for a reset). Only the roots the current certificate
    /// does not hold are newly watched; the others keep their entries, made under this
    /// version.
    fn set_distinct_cert(&mut self, c: u32, roots: [u32; 4], n: usize) {
        let ci = c as usize;
        let v = self.cand[ci].verdict;
        let (off, len) = (v.cert as usize, v.cert_len as usize);
        let mut before = [NONE; 4];
        before[..len].copy_from_slice(&self.base_cert[off..off + len]);
        let off = if n == len && off >= self.cert_floor() {
            off
        } else {
            let new = self.base_cert.len();
            self.base_cert.resize(new + n, NONE);
            new
        };
        self.base_cert[off..off + n].copy_from_slice(&roots[..n]);
        let v = &mut self.cand[ci].verdict;
        (v.cert, v.cert_len) = (off as u32, n as u32);
        let ver = self.cert_ver[ci];
        for &r in &roots[..n] {
            if !before[..len].contains(&r) {
                self.root_watch_push(r, c, ver);
            }
        }
    }

    /// Forward mode: installs distinct-components verdict `r` of `c` (the last check's, its
    /// roots in `arc_roots`) over a distinct-components verdict, keeping its version, so
    /// that only the roots the old certificate did not hold are newly watched (a recheck
    /// for a dirtied vertex mostly finds the same components). An entry can stay on a root
    /// the new certificate no longer holds only if that root was already attached (an arc
    /// only grows, and two arcs share a root only once their components merged): forward
    /// mode never reads such a list again, and were it read, `keep_distinct` works from the
    /// certificate's own roots and the other readers only mark, a check more and never one
    /// less. A root in both certificates keeps its entry, made under this version. Both
    /// verdicts are allowed: a dead component's arcs in distinct components cut nothing.
    fn reinstall_distinct(&mut self, c: u32, r: Verdict) {
        let ci = c as usize;
        let old = self.cand[ci].verdict;
        debug_assert!(old.allowed && r.allowed && self.forward);
        self.cand[ci].verdict = Verdict {
            cert: old.cert,
            cert_len: old.cert_len,
            ..r
        };
        let n = self.narcs;
        let mut roots = [NONE; 4];
        roots[..n].copy_from_slice(&self.arc_roots[..n]);
        self.set_distinct_cert(c, roots, n);
        self.distinct_rekept += 1;
    }

    /// Whether the quad of `c` touches at most one of the dead components in `y_roots`
    /// (roots before this `apply`'s unions, which attached the roots in `attached`).
    fn distinct_without(&self, c: u32) -> bool {
        let mut hit = NONE;
        for v in self.table.quads[c as usize] {
            // The root before this apply: no path compression, so walk up to the first
            // vertex that was a root then.
            let mut r = v;
            while self.dsu_parent[r as usize] != r && !self.attached.contains(&r) {
                r = self.dsu_parent[r as usize];
            }
            if self.y_roots.contains(&r) {
                if hit != NONE && hit != r {
                    return false;
                }
                hit = r;
            }
        }
        true
    }

    /// Whether the remaining neighbours of candidate `y`'s quad, the triangles `skip`
    /// left out, form one group when joined at the quad vertices `mask` (neighbours `i - 1`
    /// and `i` at vertex `i`, as in [`State::check_slow`]) and where a neighbour is the
    /// same triangle across two sides.
    fn joined_without(&self, y: u32, mask: u8, skip: [u32; 2]) -> bool {
        let n = self.cand[y as usize].nb;
        let live = n.map(|t| t != NONE && self.alive[t as usize] && !skip.contains(&t));
        let mut root = [0u8, 1, 2, 3];
        let join = |r: &mut [u8; 4], a: usize, b: usize| {
            let (x, z) = (r[a], r[b]);
            for k in r.iter_mut() {
                if *k == z {
                    *k = x;
                }
            }
        };
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
        let mut first = None;
        (0..4)
            .filter(|&i| live[i])
            .all(|i| *first.get_or_insert(root[i]) == root[i])
    }

    /// The triangles around the clean quad vertices `mask` of candidate `y` (both of its
    /// triangles remaining), `y`'s own excepted, into `self.fan`; false when a fan does not
    /// close within 64 steps.
    fn fans(&mut self, y: u32, mask: u8) -> bool {
        self.fan.clear();
        let [a, b] = self.table.pairs[y as usize];
        let q = self.table.quads[y as usize];
        for (i, &v) in q.iter().enumerate() {
            if mask & (1 << i) == 0 {
                continue;
            }
            let start = self.corner_of([a, b], v);
            // Walk around v: leave each triangle across its other edge at v.
            let (mut t, mut prev) = (start, NONE);
            for _ in 0..64 {
                let (_, next, _) = self.fan_step(t, v, prev);
                if next == NONE {
                    return false;
                }
                prev = t;
                t = next;
                if t == start {
                    break;
                }
                if t != a && t != b && !self.fan.contains(&t) {
                    self.fan.push(t);
                }
            }
            if t != start {
                return false;
            }
        }
        true
    }

    /// Forward mode: the certificate arena keeps only what the current verdicts of live
    /// candidates refer to (past the initial verdicts', which a reset brings back). Runs
    /// append a certificate per recomputed verdict; without this the arena grew with every
    /// recheck of a run (1.6 GB for greedy on a 10^6-triangle grid). Called when the arena
    /// has grown by twice the candidate count and twice what was kept, so the copying costs O(1)
    /// per appended entry. In place: the certificates kept move down in arena order (each
    /// verdict's certificate is its own, so none is overwritten before it moved).
    pub(super) fn compact_base_cert(&mut self) {
        debug_assert!(self.forward, "undo logs refer to arena offsets");
        let init = self.cert_floor();
        // Live candidates as `offset << 32 | id`, sorted by their certificate's offset (each
        // live verdict's own): sorting plain keys took half the time of sorting ids by a
        // key read from their records.
        let mut live: Vec<u64> = Vec::new();
        for c in 0..self.cand.len() {
            let v = self.cand[c].verdict;
            if (v.cert as usize) < init || v.cert_len == 0 {
                continue;
            }
            let [a, b] = self.table.pairs[c];
            if !self.alive[a as usize] || !self.alive[b as usize] {
                // Never read again before a reset restores the initial verdicts.
                let v = &mut self.cand[c].verdict;
                (v.cert, v.cert_len) = (0, 0);
                continue;
            }
            live.push((v.cert as u64) << 32 | c as u64);
        }
        live.sort_unstable();
        let mut end = init;
        for key in live {
            let v = &mut self.cand[key as u32 as usize].verdict;
            let (off, len) = (v.cert, v.cert_len as usize);
            self.base_cert
                .copy_within(off as usize..off as usize + len, end);
            v.cert = end as u32;
            end += len;
        }
        self.base_cert.truncate(end);
        self.set_cert_compact_at(init + (2 * (end - init)).max(2 * self.cand.len()));
    }

    /// Sets the arena length at which it is next compacted (at least the candidate count
    /// twice past what it keeps: the scan reads every candidate's record, 5 MB on a
    /// 10^5-triangle grid; halving the compactions cost 6–7 bytes per triangle at the peaks
    /// of `bench rss` at 10^6) and gives the arena that capacity, plus room for one action's appends.
    /// Growing to it by doubling instead would overshoot by up to its size: 16 bytes per
    /// triangle more at the peak of selective on a 10^6-triangle grid.
    pub(super) fn set_cert_compact_at(&mut self, at: usize) {
        self.base_cert_compact_at = at.max(1024);
        let room = self.base_cert_compact_at + self.base_cert_compact_at / 8;
        let len = self.base_cert.len();
        if self.base_cert.capacity() > room {
            self.base_cert.shrink_to(room);
        } else {
            self.base_cert.reserve_exact(room - len);
        }
    }

    /// Length of the arena's prefix that stays as it is: the initial verdicts'
    /// certificates, which a reset brings back; none in forward mode without a copy of the
    /// initial state (no reset), where they are compacted and edited like the others.
    #[inline]
    pub(super) fn cert_floor(&self) -> usize {
        if self.forward && self.initial.is_none() {
            0
        } else {
            self.base_cert_init
        }
    }

    /// Logs a change of the base state for `undo`; forward mode undoes nothing and keeps
    /// no log, nor does the build of the initial verdicts.
    #[inline]
    pub(super) fn base_log(&mut self, op: Op) {
        if !self.forward && !self.building {
            self.log.push(op);
        }
    }

    /// Logs a change that base applies and tree pushes share (polders, dead components):
    /// always inside a look-ahead tree (`tree`), which undoes its pushes, else as
    /// [`State::base_log`] (forward mode logs nothing: a relabelled part cost one entry per
    /// triangle, and the log kept the capacity of the largest).
    #[inline]
    pub(super) fn shared_log(&mut self, op: Op, tree: bool) {
        if tree {
            self.log.push(op);
        } else {
            self.base_log(op);
        }
    }

    /// Adds `(c, ver)` to the watch list of triangle `t` (logged).
    fn watch_push(&mut self, t: u32, c: u32, ver: u32) {
        self.list_push(t, c, ver);
        self.base_log(Op::Watch(t));
    }

    /// Adds `(c, ver)` to the watch list of dead-component root `v` (logged).
    fn root_watch_push(&mut self, v: u32, c: u32, ver: u32) {
        self.list_push(self.watch.root(v), c, ver);
        self.base_log(Op::RootWatch(v));
    }

    /// Adds `(c, ver)` to watch list `i`. In forward mode, where nothing is undone, a list
    /// that doubled is first cleared of the entries of verdicts since recomputed (those
    /// past the initial state's, which a reset brings back).
    #[inline]
    fn list_push(&mut self, i: u32, c: u32, ver: u32) {
        if self.forward {
            prune(&mut self.watch, i, self.initial.as_deref(), &self.cert_ver);
        }
        self.watch.push(i, (c, ver), first_block(self.building));
    }

    /// Moves triangle `t` from `P_old` to `P_new` (logged).
    pub(super) fn set_count(&mut self, t: u32, new: u8) {
        let old = self.count[t as usize];
        if old == new {
            return;
        }
        self.move_count(t, old, new);
        self.base_log(Op::Count { t, old });
    }

    /// Sets the count of `t` from `old` to `new` and moves it between the sets.
    #[inline]
    pub(super) fn move_count(&mut self, t: u32, old: u8, new: u8) {
        if old > 0 {
            self.sets.remove(old as usize, t);
        }
        if new > 0 {
            self.sets.insert(new as usize, t);
        }
        self.count[t as usize] = new;
    }

    pub(super) fn set_verdict_dead(&mut self, c: u32) {
        let ci = c as usize;
        self.base_log(Op::Verdict {
            c,
            old: self.cand[ci].verdict,
            ver: self.cert_ver[ci],
        });
        self.cand[ci].verdict.allowed = false;
    }

    /// Marks the verdict of `c` as possibly stale (logged).
    pub(super) fn mark(&mut self, c: u32) {
        let ci = c as usize;
        if !self.cand[ci].dirty {
            self.cand[ci].dirty = true;
            self.dirty_list.push(c);
            self.base_log(Op::Dirty);
        }
    }

    /// Makes the verdict of `c` exact (rechecks it if it was marked stale).
    #[inline]
    pub(crate) fn resolve(&mut self, c: u32) {
        if self.cand[c as usize].dirty {
            self.resolve_slow(c);
        }
    }

    fn resolve_slow(&mut self, c: u32) {
        if self.is_live(c) {
            self.recheck_one(c);
        }
        self.cand[c as usize].dirty = false;
        self.base_log(Op::Clean(c));
    }

    /// Makes every verdict exact.
    pub fn resolve_all(&mut self) {
        while let Some(c) = self.dirty_list.pop() {
            self.base_log(Op::DirtyPop(c));
            if self.cand[c as usize].dirty {
                self.resolve_slow(c);
            }
        }
    }

    /// Candidates marked stale since the list was last emptied (from position `from`):
    /// lets greedy revisit exactly the actions whose verdict may have changed.
    pub(crate) fn dirty_since(&self, from: usize) -> &[u32] {
        &self.dirty_list[from.min(self.dirty_list.len())..]
    }

    /// Exact allowed-ness inside a lazy tree (rechecks `c` first if needed).
    #[inline]
    pub fn is_allowed_lazy(&mut self, c: u32) -> bool {
        self.resolve(c);
        self.is_allowed(c)
    }

    /// Exact number of allowed actions of `t` inside a lazy tree.
    #[inline]
    pub fn allowed_count_lazy(&mut self, t: u32) -> u32 {
        if self.alive[t as usize] {
            for c in self.table.by_triangle[t as usize] {
                if c != NONE {
                    self.resolve(c);
                }
            }
        }
        self.count[t as usize] as u32
    }
}

/// Forward mode: when watch list `i` has doubled (from 4 entries on), drops the entries
/// past `keep` (the initial state's, which a reset brings back) whose verdict was since
/// recomputed, so that a list holds about twice its live entries at most.
/// The initial length is read only then (a load from another array per push otherwise).
#[inline]
fn prune(lists: &mut WatchLists, i: u32, initial: Option<&Initial>, cert_ver: &[u32]) {
    let n = lists.len(i);
    if n < 4 || !n.is_power_of_two() {
        return;
    }
    let keep = initial.map_or(0, |init| init.watch_len[i as usize] as usize);
    lists.retain_from(i, keep, |(c, ver)| cert_ver[c as usize] == ver);
}

/// The block a watch list gets at its first entry: while the initial verdicts are built
/// (`building`) room for one entry (they make most lists, and most lists of a corridor hold
/// one or two for the whole run), during a run four at once (each move to a larger block
/// costs more than the room).
#[inline]
fn first_block(building: bool) -> usize {
    if building { 1 } else { 4 }
}
