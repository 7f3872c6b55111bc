//! Look-ahead trees on top of the exact base state.
//!
//! `tree_push(c)` / `tree_pop()` change only what the criterion reads: the remaining
//! triangles (and their search marks), the fans' used-triangle counts, the dead components
//! and the polders. Nothing about verdicts is written on a push: a verdict asked for inside
//! the tree ([`State::tree_allowed`]) is, in this order,
//! 1. the tree's own verdict for the candidate, when it was computed at this node or an
//!    ancestor of it and still holds;
//! 2. the base verdict (exact at the root), when it still holds;
//! 3. recomputed, and kept (with its certificate in the tree's arena) for this node and its
//!    descendants.
//!
//! "Still holds" ([`State::still_holds`]) is decided on reading: the vertices that were
//! clean are clean, the certificate is intact (the triangles remain, the dead-component roots
//! are roots) and, for a split, the verdict is re-derived from the polder's current size.
//! Going down a path only removes triangles, so these conditions are exactly the ones the
//! base state's certificates rely on (module docs of `state`).
//!
//! `P_min` at a node below the root (needed only when no triangle next to the path's quads
//! can be recombined) is the base sets corrected by every triangle whose count the path can
//! have changed: the path's triangles and their partners, the candidates at the path's quad
//! vertices, the base verdicts watching a removed triangle or a merged dead component, and
//! the base split verdicts (their polder's parity may differ).

use super::TreeEvent;
use super::check::LOCAL_PROOF;
use super::tree_cache::CandMap;
use super::{DEAD, KIND_LOCAL, Op, State, Verdict, is_split};
use crate::mesh::NONE;

/// A triangle next to the path's quads, as [`State::tree_near`] lists it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Near {
    /// The triangle.
    pub t: u32,
    /// Its number of allowed actions at the current node.
    pub k: u8,
    /// Bit i: its action `by_triangle[t][i]` is allowed at the current node.
    pub allowed: u8,
    /// Each of its actions was dead or allowed by the local proof: the entry holds while
    /// the pushes use no triangle around a vertex of its quads.
    local: bool,
}

/// A verdict computed inside the tree, with the depth and serial number of its node.
#[derive(Debug, Clone, Copy, Default)]
struct Cached {
    verdict: Verdict,
    depth: u32,
    serial: u32,
}

/// The tree's side of the state: its path, its verdict cache and scratch.
#[derive(Debug, Clone)]
pub(super) struct Overlay {
    /// Verdicts computed inside the tree, with the node they were computed at (only what
    /// the current tree stored: emptied at each `tree_begin`).
    cached: CandMap<Cached>,
    /// Ancestors' verdicts overwritten below them, restored when the node is popped:
    /// `(depth of the overwriting node, candidate, the entry)`.
    shadowed: Vec<(u32, u32, Cached)>,
    /// `tree_near`'s lists, a stack with one list per depth (depth d: from `slots_end[d-1]`
    /// to `slots_end[d]`; `slots_end[0] == 0`).
    slots: Vec<Near>,
    slots_end: Vec<usize>,
    /// Serial number of the node each depth's list was computed at.
    slots_serial: Vec<u32>,
    /// Per vertex: serial number of the deepest node of the current path whose push used a
    /// triangle around it (restored on pop from `touched_log`).
    touched_at: Vec<u32>,
    touched_log: Vec<u32>,
    /// Certificates of the tree's verdicts (cleared at each `tree_begin`, and cut back on
    /// each pop to its length at the push: the popped nodes' verdicts are never read again,
    /// so a tree holds certificates for its current path only, however many nodes it
    /// explores).
    pub(super) cert: Vec<u32>,
    cert_len: Vec<usize>,
    /// Sizes for the per-element arrays, allocated at the first `tree_begin` (greedy builds
    /// no tree and needs none of them).
    sizes: (usize, usize, usize),
    /// Actions pushed, and the serial number of the node at each depth (0: the root).
    pub(super) path: Vec<u32>,
    serial: Vec<u32>,
    next_serial: u32,
    /// Polder ids whose size changed parity at a split on the path, and how many there
    /// were before each push.
    changed: Vec<u32>,
    changed_len: Vec<usize>,
    /// Scratch for `P_min` below the root.
    affected_cands: Vec<u32>,
    affected: Vec<u32>,
    affected_mark: Vec<u32>,
    affected_epoch: u32,
    new_count: Vec<u8>,
    removed: Vec<u32>,
    added: Vec<u32>,
    /// Log length at `tree_begin`.
    log_start: usize,
}

impl Overlay {
    pub(super) fn new(m: usize, nv: usize, nt: usize) -> Overlay {
        Overlay {
            slots: Vec::new(),
            slots_end: vec![0],
            slots_serial: Vec::new(),
            touched_at: Vec::new(),
            touched_log: Vec::new(),
            cached: CandMap::new(),
            shadowed: Vec::new(),
            cert: Vec::new(),
            cert_len: Vec::new(),
            sizes: (m, nv, nt),
            path: Vec::new(),
            serial: Vec::new(),
            next_serial: 0,
            changed: Vec::new(),
            changed_len: Vec::new(),
            affected_cands: Vec::new(),
            affected: Vec::new(),
            affected_mark: Vec::new(),
            affected_epoch: 0,
            new_count: Vec::new(),
            removed: Vec::new(),
            added: Vec::new(),
            log_start: 0,
        }
    }

    /// No action pushed.
    pub(super) fn is_empty(&self) -> bool {
        self.path.is_empty()
    }
}

impl State<'_> {
    /// Starts a look-ahead tree at the current state (resolves every base verdict). Nothing
    /// may be pushed.
    pub fn tree_begin(&mut self) {
        assert!(self.tree.is_empty(), "tree_begin with actions pushed");
        self.resolve_all();
        let tr = &mut self.tree;
        if tr.touched_at.is_empty() {
            let (_, nv, nt) = tr.sizes;
            tr.touched_at = vec![0; nv];
            tr.affected_mark = vec![0; nt];
        }
        // The previous tree's verdicts are never read again (their serial numbers are
        // older than every node of this tree).
        tr.cached.clear();
        if tr.next_serial >= u32::MAX - (1 << 20) {
            // Serial numbers are about to wrap: forget every serial kept.
            tr.slots_serial.iter_mut().for_each(|s| *s = 0);
            tr.touched_at.iter_mut().for_each(|s| *s = 0);
            tr.next_serial = 0;
        }
        tr.next_serial += 1;
        tr.serial.clear();
        tr.serial.push(tr.next_serial);
        tr.shadowed.clear();
        tr.cert.clear();
        tr.log_start = self.log.len();
    }

    /// True when candidate `c` may be applied at the current node: both triangles remain
    /// and the criterion allows it.
    #[inline]
    pub fn tree_allowed(&mut self, c: u32) -> bool {
        self.is_live(c) && self.tree_verdict(c).0
    }

    /// Number of allowed actions of triangle `t` at the current node (0 if used).
    pub fn tree_count(&mut self, t: u32) -> u32 {
        if self.tree.is_empty() {
            return self.count[t as usize] as u32;
        }
        self.count_local(t).k as u32
    }

    /// Which actions of triangle `t` are allowed at the current node: bit i for
    /// `by_triangle[t][i]` (0 if `t` is used).
    pub fn tree_allowed_mask(&mut self, t: u32) -> u8 {
        if self.tree.is_empty() {
            let mut bits = 0;
            for (i, c) in self.table.by_triangle[t as usize].into_iter().enumerate() {
                if c != NONE && self.is_allowed(c) {
                    bits |= 1 << i;
                }
            }
            return bits;
        }
        self.count_local(t).allowed
    }

    /// The remaining triangles across the sides of the path's quads (root first, sides in
    /// quad order; a triangle next to two quads appears twice) with their allowed actions at
    /// the current node. Incremental: the parent node's list minus the triangles the last
    /// push used, each kept as it was when all its actions were dead or local there and the
    /// push used no triangle around any vertex of their quads, then the last quad's sides.
    pub fn tree_near(&mut self) -> &[Near] {
        let d = self.tree.path.len();
        if d == 0 {
            return &[];
        }
        {
            let tr = &mut self.tree;
            if tr.slots_serial.len() <= d {
                tr.slots_serial.resize(d + 1, 0);
            }
            if tr.slots_end.len() <= d {
                tr.slots_end.resize(d + 1, 0);
            }
        }
        let here = self.tree.serial[d];
        if self.tree.slots_serial[d] == here {
            let (lo, hi) = (self.tree.slots_end[d - 1], self.tree.slots_end[d]);
            return &self.tree.slots[lo..hi];
        }
        let tr = &mut self.tree;
        let from = if d >= 2 && tr.slots_serial[d - 1] == tr.serial[d - 1] {
            // The parent's list is the last one kept: start from it.
            let (lo, hi) = (tr.slots_end[d - 2], tr.slots_end[d - 1]);
            tr.slots.truncate(hi);
            for i in lo..hi {
                let tr = &self.tree;
                let slot = tr.slots[i];
                let t = slot.t;
                if !self.alive[t as usize] {
                    continue;
                }
                // Every vertex of every quad `t` can be part of: its own and its
                // candidates' quads'.
                let keep = slot.local
                    && (self.verts(t).iter()).all(|&v| tr.touched_at[v as usize] != here)
                    && (self.table.by_triangle[t as usize].iter())
                        .filter(|&&c| c != NONE)
                        .all(|&c| {
                            (self.table.quads[c as usize].iter())
                                .all(|&v| tr.touched_at[v as usize] != here)
                        });
                let slot = if keep { slot } else { self.count_local(t) };
                self.tree.slots.push(slot);
            }
            d - 1
        } else {
            // Built from the whole path, as the only list kept.
            tr.slots.clear();
            tr.slots_end[d - 1] = 0;
            0
        };
        let start = self.tree.slots_end[d - 1];
        for i in from..d {
            for t in self.cand[self.tree.path[i] as usize].nb {
                if t != NONE && self.alive[t as usize] {
                    let slot = self.count_local(t);
                    self.tree.slots.push(slot);
                }
            }
        }
        let tr = &mut self.tree;
        tr.slots_end[d] = tr.slots.len();
        tr.slots_serial[d] = here;
        &tr.slots[start..]
    }

    /// The allowed actions of `t` at a node below the root, and whether each of its actions
    /// is dead or allowed by the local proof.
    fn count_local(&mut self, t: u32) -> Near {
        let mut slot = Near {
            t,
            k: 0,
            allowed: 0,
            local: true,
        };
        if !self.alive[t as usize] {
            return slot;
        }
        for (i, c) in self.table.by_triangle[t as usize].into_iter().enumerate() {
            if c == NONE || !self.alive[self.other(c, t) as usize] {
                continue;
            }
            // The local proof inline; the rest of `tree_verdict` when it fails.
            let mask = self.clean_mask(c);
            let (allowed, local) = if mask & LOCAL_PROOF != 0 {
                (true, true)
            } else {
                (self.tree_verdict_slow(c, mask).0, false)
            };
            slot.k += allowed as u8;
            slot.allowed |= (allowed as u8) << i;
            slot.local &= allowed && local;
        }
        slot
    }

    /// `(allowed, kind)` of live candidate `c` at the current node.
    #[inline]
    fn tree_verdict(&mut self, c: u32) -> (bool, u8) {
        if self.tree.path.is_empty() {
            let v = &self.cand[c as usize].verdict;
            return (v.allowed, v.kind);
        }
        // The local proof costs a few loads: cheaper than looking anything up. When it
        // fails, no verdict of the local kind can still hold either.
        let mask = self.clean_mask(c);
        if mask & LOCAL_PROOF != 0 {
            return (true, KIND_LOCAL);
        }
        self.tree_verdict_slow(c, mask)
    }

    /// [`State::tree_verdict`] below the root when the local proof fails (`mask`: the clean
    /// quad vertices): the cached or base verdict if it still holds, else a new one.
    #[inline(never)]
    fn tree_verdict_slow(&mut self, c: u32, mask: u8) -> (bool, u8) {
        let ci = c as usize;
        let tr = &self.tree;
        let d = tr.path.len();
        let e = tr.cached.get(c);
        let od = e.depth as usize;
        let ancestor = od <= d && tr.serial[od] == e.serial;
        if ancestor {
            let v = e.verdict;
            // Parity changes on the path below the node the verdict was computed at.
            let since = tr.changed_len.get(od).map_or(tr.changed.len(), |&n| n);
            if let Some(a) = self.still_holds(c, &v, &tr.cert, &tr.changed[since..]) {
                return (a, v.kind);
            }
        }
        let v = self.cand[ci].verdict;
        if v.kind != KIND_LOCAL {
            let tr = &self.tree;
            if let Some(a) = self.still_holds(c, &v, &self.base_cert, &tr.changed) {
                return (a, v.kind);
            }
        }
        let mut v = self.check_slow(c, mask & 0xF);
        (v.cert, v.cert_len) = self.append_cert(v.kind, true);
        let tr = &mut self.tree;
        if ancestor && od < d {
            let old = (d as u32, c, e);
            tr.shadowed.push(old);
        }
        let e = Cached {
            verdict: v,
            depth: d as u32,
            serial: tr.serial[d],
        };
        tr.cached.set(c, e);
        (v.allowed, v.kind)
    }

    /// Recombines the pair of candidate `c` (both must remain) inside the tree.
    pub fn tree_push(&mut self, c: u32) {
        assert!(
            self.is_live(c),
            "tree_push({c}): a triangle of the pair is already used"
        );
        let ci = c as usize;
        let [t0, t1] = self.table.pairs[ci];
        // Only a split changes more than the polder's size.
        let split = is_split(self.tree_verdict(c).1);
        self.log.push(Op::TreeApply(c));
        self.tree.changed_len.push(self.tree.changed.len());
        // The parts are needed to relabel them: search again (the smaller parts). A verdict
        // of a split kind can have become one part since it was found, still exact in what
        // it allows: one of its parts, even, used up by actions that did not invalidate it
        // (a split read off parities, `READ`, or kept by `shrink_split` across an action
        // that was a part by itself). Then there is nothing to relabel.
        if split && is_split(self.check_parts(c).kind) {
            // Parities are relative to the root: a part of a polder whose parity already
            // changed on the path has changed too, whatever this split does.
            let p = self.polder[t0 as usize];
            let inherited = self.tree.changed.contains(&p);
            let first_new = self.polder_size.len() as u32;
            self.changed.clear();
            self.relabel_split(c, true);
            self.tree.changed.extend_from_slice(&self.changed);
            if inherited {
                let tr = &mut self.tree;
                tr.changed.extend(first_new..self.polder_size.len() as u32);
            }
        } else {
            let p = self.polder[t0 as usize];
            let old = self.polder_size[p as usize];
            self.log.push(Op::PolderSize { p, old });
            self.polder_size[p as usize] = old - 2;
        }
        for x in [t0, t1] {
            self.alive[x as usize] = false;
            self.stamp[x as usize] = DEAD;
            for v in self.verts(x) {
                self.dead_count[v as usize] += 1;
            }
        }
        self.remaining -= 2;
        let q = self.table.quads[ci];
        for i in 1..4 {
            self.union(q[0], q[i], self.quad_path(c, 0, i), true);
        }
        let tr = &mut self.tree;
        tr.next_serial += 1;
        tr.cert_len.push(tr.cert.len());
        tr.path.push(c);
        tr.serial.push(tr.next_serial);
        for v in q {
            tr.touched_log.push(tr.touched_at[v as usize]);
            tr.touched_at[v as usize] = tr.next_serial;
        }
        self.audit_tree(TreeEvent::Push(c));
    }

    /// Reverts the last `tree_push`. Panics when nothing was pushed.
    pub fn tree_pop(&mut self) {
        let c = self.tree_undo();
        self.audit_tree(TreeEvent::Pop(c));
    }

    /// [`State::tree_pop`] before the audit hook: returns the candidate popped.
    #[inline(always)]
    fn tree_undo(&mut self) -> u32 {
        assert!(!self.tree.is_empty(), "tree_pop with nothing pushed");
        let tr = &mut self.tree;
        let d = tr.path.len() as u32;
        while let Some(&(at, c, e)) = tr.shadowed.last() {
            if at < d {
                break;
            }
            tr.cached.set(c, e);
            tr.shadowed.pop();
        }
        let c = tr.path.pop().expect("a pushed action");
        let n = tr.changed_len.pop().expect("logged");
        tr.changed.truncate(n);
        let n = tr.cert_len.pop().expect("logged");
        tr.cert.truncate(n);
        for v in self.table.quads[c as usize].into_iter().rev() {
            tr.touched_at[v as usize] = tr.touched_log.pop().expect("logged");
        }
        tr.serial.pop();
        while let Some(op) = self.log.pop() {
            if self.undo_shared(op) {
                continue;
            }
            let Op::TreeApply(c) = op else {
                unreachable!("a base change inside a look-ahead tree");
            };
            for x in self.table.pairs[c as usize] {
                self.alive[x as usize] = true;
                self.stamp[x as usize] = 0;
                for v in self.verts(x) {
                    self.dead_count[v as usize] -= 1;
                }
            }
            self.remaining += 2;
            return c;
        }
        unreachable!("tree log without a TreeApply marker");
    }

    /// Draws from `P_min` at the current node: `pick(n)` chooses an index in `0..n`, and the
    /// triangle returned is the member with that many members of smaller id. `None` when no
    /// action is allowed.
    pub fn tree_pick_pmin(&mut self, mut pick: impl FnMut(usize) -> usize) -> Option<u32> {
        if self.tree.is_empty() {
            let k = self.min_k()?;
            let i = pick(self.bucket_len(k));
            return Some(self.bucket_nth(k, i));
        }
        self.collect_affected();
        let aff = std::mem::take(&mut self.tree.affected);
        let mut new_count = std::mem::take(&mut self.tree.new_count);
        new_count.clear();
        for &t in &aff {
            new_count.push(self.tree_count(t) as u8);
        }
        let mut found = None;
        for k in 1..4u8 {
            let (mut removed, mut added) = (0usize, 0usize);
            for (&t, &n) in aff.iter().zip(&new_count) {
                let old = self.count[t as usize];
                removed += (old == k && n != k) as usize;
                added += (old != k && n == k) as usize;
            }
            let size = self.sets.len(k as usize) - removed + added;
            if size > 0 {
                found = Some((k, size));
                break;
            }
        }
        let picked = found.map(|(k, size)| {
            let i = pick(size);
            self.tree.removed.clear();
            self.tree.added.clear();
            for (&t, &n) in aff.iter().zip(&new_count) {
                let old = self.count[t as usize];
                if old == k && n != k {
                    self.tree.removed.push(t);
                } else if old != k && n == k {
                    self.tree.added.push(t);
                }
            }
            self.tree.removed.sort_unstable();
            self.tree.added.sort_unstable();
            self.nth_corrected(k as usize, i)
        });
        self.tree.affected = aff;
        self.tree.new_count = new_count;
        picked
    }

    /// The member with `i` members of smaller id of `P_k` minus `tree.removed` plus
    /// `tree.added` (both sorted): binary search on the id.
    fn nth_corrected(&self, k: usize, i: usize) -> u32 {
        let tr = &self.tree;
        // Members with id below x.
        let below = |x: u32| {
            self.sets.rank(k, x) - tr.removed.partition_point(|&t| t < x)
                + tr.added.partition_point(|&t| t < x)
        };
        let (mut lo, mut hi) = (0u32, self.alive.len() as u32 - 1);
        while lo < hi {
            let mid = lo + (hi - lo) / 2;
            if below(mid + 1) > i {
                hi = mid;
            } else {
                lo = mid + 1;
            }
        }
        lo
    }

    /// Appends to `out` every candidate whose verdict may differ between the root and the
    /// current node (some more than once; module docs): the actions of the path's
    /// triangles, the candidates at the path's quad vertices, the base verdicts watching a
    /// removed triangle or a merged dead component, and the base split verdicts when a
    /// polder split on the path. Every other live candidate reads as at the root.
    fn tree_affected(&self, out: &mut Vec<u32>) {
        let tr = &self.tree;
        for &c in &tr.path {
            for x in self.table.pairs[c as usize] {
                out.extend(
                    self.table.by_triangle[x as usize]
                        .iter()
                        .filter(|&&c2| c2 != NONE),
                );
                for &(c2, ver) in self.watch.slice(x) {
                    if self.cert_ver[c2 as usize] == ver {
                        out.push(c2);
                    }
                }
            }
            // Only a closed fan's vertex can be clean, so only there can a candidate's
            // verdict depend on its vertex staying clean (its other dependencies are
            // watched, as in `apply`).
            let pair = self.table.pairs[c as usize];
            for v in self.table.quads[c as usize] {
                if self.closed[v as usize] {
                    self.candidates_at(v, self.corner_of(pair, v), out);
                }
            }
        }
        for op in &self.log[tr.log_start..] {
            if let Op::Union { child, .. } = *op {
                for &(c2, ver) in self.watch.slice(self.watch.root(child)) {
                    if self.cert_ver[c2 as usize] == ver {
                        out.push(c2);
                    }
                }
            }
        }
        // A split verdict reads differently only when its polder's parity changed, which
        // takes a split on the path (otherwise every polder lost an even number).
        if !tr.changed.is_empty() {
            for &c2 in &self.split {
                let t0 = self.table.pairs[c2 as usize][0];
                if self.is_live(c2) && tr.changed.contains(&self.polder[t0 as usize]) {
                    out.push(c2);
                }
            }
        }
    }

    /// Fills `tree.affected` with the triangles of every candidate of [`State::tree_affected`]
    /// (each once): those whose number of allowed actions may differ from the root's.
    fn collect_affected(&mut self) {
        let mut cands = std::mem::take(&mut self.tree.affected_cands);
        cands.clear();
        self.tree_affected(&mut cands);
        let tr = &mut self.tree;
        tr.affected.clear();
        tr.affected_epoch = tr.affected_epoch.wrapping_add(1);
        if tr.affected_epoch == 0 {
            tr.affected_mark.iter_mut().for_each(|m| *m = 0);
            tr.affected_epoch = 1;
        }
        let epoch = tr.affected_epoch;
        for &c in &cands {
            for t in self.table.pairs[c as usize] {
                if tr.affected_mark[t as usize] != epoch {
                    tr.affected_mark[t as usize] = epoch;
                    tr.affected.push(t);
                }
            }
        }
        tr.affected_cands = cands;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate::{GridSpec, grid};
    use crate::quality::CandidateTable;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// A tree keeps certificates for its current path only: after any number of nodes
    /// explored below the root, popping back leaves the arena as the root had it. (It kept
    /// every node's until the next tree: selective h = 100 grew without end.)
    #[test]
    fn tree_certificates_are_bounded_by_the_path() {
        let m = grid(GridSpec {
            triangles: 600,
            holes: true,
            drop_triangles: 3,
            seed: 11,
            ..GridSpec::default()
        });
        let table = CandidateTable::build(&m);
        let mut st = State::new(&m, &table);
        st.set_forward(true);
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let nc = table.len() as u64;
        for _decision in 0..5 {
            st.tree_begin();
            let mut grew = false;
            for _excursion in 0..300 {
                let mut at_root = None;
                for _depth in 0..8 {
                    // Ask for verdicts (some recomputed, with certificates), then go down.
                    for _ in 0..20 {
                        let c = (rng.next_u64() % nc) as u32;
                        if st.is_live(c) {
                            st.tree_allowed(c);
                        }
                    }
                    let live: Vec<u32> = (0..nc as u32)
                        .filter(|&c| st.is_live(c) && st.tree_allowed(c))
                        .collect();
                    let here = st.tree.cert.len();
                    grew |= at_root.is_some_and(|r| here > r);
                    at_root.get_or_insert(here);
                    if live.is_empty() {
                        break;
                    }
                    st.tree_push(live[(rng.next_u64() % live.len() as u64) as usize]);
                }
                while !st.tree.is_empty() {
                    st.tree_pop();
                }
                let at_root = at_root.expect("the root was visited");
                assert_eq!(st.tree.cert.len(), at_root, "back at the root");
            }
            assert!(grew, "the excursions computed certificates");
            let first = (0..nc as u32)
                .find(|&c| st.is_allowed(c))
                .expect("an action");
            st.apply(first);
        }
    }
}
