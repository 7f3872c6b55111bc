//! Applying and undoing actions through the change log: `apply` / `apply_lazy` record
//! every change as an [`Op`], `undo` reverts the last action in O(1) per change, `reset`
//! returns to the initial state.

use super::{DEAD, Initial, KIND_DISTINCT, KIND_LOCAL, Op, State, is_split};
use crate::mesh::NONE;

/// Capacity of the change log kept across forward-mode actions (ops; 28 bytes each).
const LOG_KEEP: usize = 1 << 12;

impl State<'_> {
    /// Recombines the two triangles of candidate `c` (both must remain; the criterion is
    /// not required, and stays exact after a forbidden action too).
    pub fn apply(&mut self, c: u32) {
        self.apply_lazy(c);
        self.resolve_all();
    }

    /// Like [`State::apply`], but the verdicts the action may have changed are only marked;
    /// the lazy queries (and `resolve_all`) recheck them when asked. For the trees.
    pub fn apply_lazy(&mut self, c: u32) {
        // The arena is compacted here too, not only before a recheck: the split verdicts
        // an action keeps (`shrink_split`) append their certificates without one.
        if self.forward && self.base_cert.len() >= self.base_cert_compact_at {
            self.compact_base_cert();
        }
        let ci = c as usize;
        let [t0, t1] = self.table.pairs[ci];
        assert!(
            self.is_live(c),
            "apply({c}): a triangle of the pair is already used"
        );
        // An exact verdict that found one part needs no new search; a split does (its
        // parts are relabelled).
        let v = self.cand[ci].verdict;
        let exact_before = self.dirty_list.is_empty();
        let kept = !self.cand[ci].dirty && v.allowed && !is_split(v.kind);
        let r = if kept { v } else { self.check_parts(c) };
        let split = is_split(r.kind);
        self.last_local = if exact_before && r.kind == KIND_LOCAL {
            c
        } else {
            NONE
        };
        // The clean vertices now (a kept verdict's mask can be older: a recheck that
        // finds the same local verdict keeps it). Only forward mode's split shrinking reads
        // them: the trees' applies skip the lookups.
        let ymask = if self.forward {
            self.clean_mask(c) & 0xF
        } else {
            0
        };
        self.last_local_mask = ymask;
        // A distinct-components proof: its arcs' components before the unions below.
        let distinct = self.forward && r.kind == KIND_DISTINCT;
        self.y_roots.clear();
        if distinct {
            if kept {
                let cert = &self.base_cert[r.cert as usize..(r.cert + r.cert_len) as usize];
                self.y_roots.extend_from_slice(cert);
            } else {
                // Just checked: the roots are in scratch.
                self.y_roots
                    .extend_from_slice(&self.arc_roots[..self.narcs]);
            }
        }
        self.attached.clear();
        if self.forward {
            // Nothing will be undone: the log only serves the trees, whose splits can have
            // logged a large part; its capacity goes back.
            self.log.clear();
            self.log.shrink_to(LOG_KEEP);
        } else {
            self.log.push(Op::Apply(c));
        }
        self.changed.clear();
        if split {
            self.relabel_split(c, false);
        } else {
            let p = self.polder[t0 as usize];
            let psize = self.polder_size[p as usize];
            self.base_log(Op::PolderSize { p, old: psize });
            self.polder_size[p as usize] = psize - 2;
        }
        // Remove the pair.
        self.alive[t0 as usize] = false;
        self.alive[t1 as usize] = false;
        self.stamp[t0 as usize] = DEAD;
        self.stamp[t1 as usize] = DEAD;
        self.remaining -= 2;
        self.chosen.push(c);
        let total = self.quality() + self.table.eta[ci];
        if self.forward && self.quality.len() > 1 {
            // Nothing is undone: the initial quality (for a reset) and the current one.
            self.quality[1] = total;
        } else {
            self.quality.push(total);
        }
        for x in [t0, t1] {
            self.set_count(x, 0);
            for c2 in self.table.by_triangle[x as usize] {
                if c2 != NONE && self.cand[c2 as usize].verdict.allowed {
                    self.set_verdict_dead(c2);
                    let u = self.other(c2, x);
                    if self.alive[u as usize] {
                        let k = self.count[u as usize];
                        self.set_count(u, k - 1);
                    }
                }
            }
        }
        // Vertices whose fan lost its first triangle: their links are gone.
        self.moved.clear();
        for x in [t0, t1] {
            for v in self.verts(x) {
                let vi = v as usize;
                if self.dead_count[vi] == 0 && self.closed[vi] {
                    self.moved.push(v);
                }
                self.dead_count[vi] += 1;
            }
        }
        // The quad joins the dead components at its four vertices.
        let qv = self.table.quads[ci];
        for i in 1..4 {
            if let Some(child) = self.union(qv[0], qv[i], self.quad_path(c, 0, i), false) {
                if distinct {
                    self.attached.push(child);
                }
                // Pushes onto other roots' lists (`keep_distinct`) can move the slab: read
                // by index.
                let list = self.watch.root(child);
                for j in 0..self.watch.len(list) {
                    let (c2, ver) = self.watch.get(list, j);
                    if self.cert_ver[c2 as usize] == ver
                        && self.is_live(c2)
                        && !self.keep_distinct(c2, ver)
                    {
                        self.mark(c2);
                    }
                }
                // A root attached stays attached until a reset; without one (no initial
                // copy), its list is never read again.
                if self.forward && self.initial.is_none() {
                    self.watch.free(list);
                }
            }
        }
        let mut at = std::mem::take(&mut self.at_vertex);
        for i in 0..self.moved.len() {
            let v = self.moved[i];
            let start = self.corner_of([t0, t1], v);
            at.clear();
            self.candidates_at(v, start, &mut at);
            for &c2 in &at {
                if self.is_live(c2) {
                    self.mark(c2);
                }
            }
        }
        self.at_vertex = at;
        // Split verdicts exact before this action, which had a local proof and lies inside
        // one of their parts, are kept at once (`shrink_split`) instead of being marked:
        // in lazy mode they would otherwise be searched again when next read.
        let local = self.forward && r.kind == KIND_LOCAL;
        self.shrunk.clear();
        for x in [t0, t1] {
            // Nothing pushes onto `x`'s list meanwhile, but `shrink_split` pushes onto
            // others, which can move the slab: read by index.
            let n = self.watch.len(x);
            for j in 0..n {
                debug_assert_eq!(self.watch.len(x), n);
                let (c2, ver) = self.watch.get(x, j);
                if self.cert_ver[c2 as usize] == ver && self.is_live(c2) {
                    if (local || distinct) && !self.cand[c2 as usize].dirty {
                        if self.shrunk.contains(&c2) {
                            continue;
                        }
                        if self.shrink_split(c2, c, ymask, distinct) {
                            self.shrunk.push(c2);
                            continue;
                        }
                    }
                    self.mark(c2);
                }
            }
            // Forward mode never reads a used triangle's list again before a reset; without
            // a copy of the initial state there is none, and the list's memory goes back.
            if self.forward && self.initial.is_none() {
                self.watch.free(x);
            }
        }
        if self.forward && self.split.len() >= self.split_compact_at {
            self.drop_used_splits();
        }
        if !self.changed.is_empty() {
            for i in 0..self.split.len() {
                let c2 = self.split[i];
                if self.is_live(c2) {
                    let pc = self.polder[self.table.pairs[c2 as usize][0] as usize];
                    if self.changed.contains(&pc) {
                        self.mark(c2);
                    }
                }
            }
        }
    }

    /// Forward mode: drops the used candidates from the split list (no action reads a used
    /// candidate's verdict again before a reset, which restores the list): it kept every
    /// candidate whose verdict was ever a split, 674,000 of the 1.25 million of a
    /// 10^6-triangle grid by the end of a selective run, 8,000 of them live. Called when the
    /// list has doubled since the last call, so the copying costs O(1) per entry.
    fn drop_used_splits(&mut self) {
        let mut w = 0;
        for r in 0..self.split.len() {
            let c = self.split[r];
            if self.is_live(c) {
                self.split[w] = c;
                self.split_pos[c as usize] = w as u32;
                w += 1;
            } else {
                self.split_pos[c as usize] = NONE;
            }
        }
        self.split.truncate(w);
        self.split_compact_at = (2 * w).max(1024);
        self.split.shrink_to(self.split_compact_at);
    }

    /// Reverts the last `apply`. Panics when nothing was applied.
    pub fn undo(&mut self) {
        assert!(!self.chosen.is_empty(), "undo with nothing applied");
        assert!(!self.forward, "undo in forward mode");
        assert!(self.tree.is_empty(), "undo inside a look-ahead tree");
        while let Some(op) = self.log.pop() {
            if self.undo_shared(op) {
                continue;
            }
            match op {
                Op::Apply(c) => {
                    let [t0, t1] = self.table.pairs[c as usize];
                    for x in [t0, t1] {
                        self.alive[x as usize] = true;
                        self.stamp[x as usize] = 0;
                        for v in self.verts(x) {
                            self.dead_count[v as usize] -= 1;
                        }
                    }
                    self.remaining += 2;
                    self.chosen.pop();
                    self.quality.pop();
                    return;
                }
                Op::Verdict { c, old, ver } => {
                    self.cand[c as usize].verdict = old;
                    self.cert_ver[c as usize] = ver;
                }
                Op::Count { t, old } => {
                    let cur = self.count[t as usize];
                    self.move_count(t, cur, old);
                }
                Op::TreeApply(_)
                | Op::Polder { .. }
                | Op::PolderNew
                | Op::PolderSize { .. }
                | Op::Union { .. }
                | Op::OddActive { .. } => unreachable!("handled by undo_shared"),
                Op::Watch(t) => self.watch.pop(t),
                Op::SplitIns => {
                    let c = self.split.pop().expect("split entry");
                    self.split_pos[c as usize] = NONE;
                }
                Op::RootWatch(v) => self.watch.pop(self.watch.root(v)),
                Op::Dirty => {
                    let c = self.dirty_list.pop().expect("dirty entry");
                    self.cand[c as usize].dirty = false;
                }
                Op::Clean(c) => self.cand[c as usize].dirty = true,
                Op::DirtyPop(c) => self.dirty_list.push(c),
                Op::SplitRem { c, pos } => {
                    let p = pos as usize;
                    if p == self.split.len() {
                        self.split.push(c);
                    } else {
                        let y = self.split[p];
                        self.split.push(y);
                        self.split_pos[y as usize] = (self.split.len() - 1) as u32;
                        self.split[p] = c;
                    }
                    self.split_pos[c as usize] = pos;
                }
            }
        }
        unreachable!("undo log without an Apply marker");
    }

    /// Reverts every action applied. Panics in forward mode without a copy of the initial
    /// state ([`State::set_forward_uncopied`]) once an action was applied (see
    /// [`State::can_reset`]).
    pub fn reset(&mut self) {
        assert!(self.tree.is_empty(), "reset inside a look-ahead tree");
        if self.forward && self.initial.is_none() {
            // Nothing applied, nothing changed (the arena's initial certificates included).
            assert!(
                self.chosen.is_empty(),
                "reset of a forward state kept without a copy of its initial state"
            );
            return;
        } else if self.forward {
            self.restore_initial();
        } else {
            while !self.chosen.is_empty() {
                self.undo();
            }
        }
        self.base_cert.truncate(self.base_cert_init);
    }

    /// Forward mode (for runs, which never undo an applied action): `apply` keeps no undo
    /// log (look-ahead trees still undo their pushes) and [`State::reset`] restores a copy
    /// of the initial state instead of undoing every action. `undo` panics in this mode.
    /// Only at the initial state.
    pub fn set_forward(&mut self, on: bool) {
        assert!(self.chosen.is_empty(), "set_forward with actions applied");
        if on && self.initial.is_none() {
            self.initial = Some(Box::new(Initial {
                verdict: self.cand.iter().map(|l| l.verdict).collect(),
                cert_ver: self.cert_ver.clone(),
                count: self.count.clone(),
                sets: self.sets.clone(),
                polder: self.polder.clone(),
                polder_size: self.polder_size.clone(),
                dsu_parent: self.dsu_parent.clone(),
                dsu_size: self.dsu_size.clone(),
                dsu_par: self.dsu_par.clone(),
                split: self.split.clone(),
                split_pos: self.split_pos.clone(),
                watch_len: self.watch.lens().collect(),
                ver: self.ver,
            }));
        }
        self.forward = on;
        self.log.clear();
    }

    /// Forward mode for one run from the state as built: as `set_forward(true)`, but no
    /// copy of the initial state is made (about 50 bytes per triangle of a grid), so once
    /// an action is applied the state cannot be reset: build a new one. Only at the
    /// initial state.
    pub fn set_forward_uncopied(&mut self) {
        assert!(self.chosen.is_empty(), "set_forward with actions applied");
        self.initial = None;
        self.forward = true;
        self.log.clear();
    }

    /// [`State::reset`] can bring the initial state back: not in forward mode without a
    /// copy of it once an action was applied.
    pub fn can_reset(&self) -> bool {
        !self.forward || self.initial.is_some() || self.chosen.is_empty()
    }

    /// Forward mode's reset: copies the initial state back.
    fn restore_initial(&mut self) {
        let init = self
            .initial
            .as_ref()
            .expect("forward mode keeps the initial state");
        for (c, v) in init.verdict.iter().enumerate() {
            self.cand[c].verdict = *v;
        }
        self.cert_ver.copy_from_slice(&init.cert_ver);
        self.count.copy_from_slice(&init.count);
        self.sets.clone_from(&init.sets);
        self.polder.copy_from_slice(&init.polder);
        self.polder_size.clone_from(&init.polder_size);
        self.dsu_parent.copy_from_slice(&init.dsu_parent);
        self.dsu_size.copy_from_slice(&init.dsu_size);
        self.dsu_par.copy_from_slice(&init.dsu_par);
        self.odd_active = 0;
        self.split.clone_from(&init.split);
        self.split_pos.copy_from_slice(&init.split_pos);
        for (i, &n) in init.watch_len.iter().enumerate() {
            self.watch.truncate(i as u32, n as usize);
        }
        self.ver = init.ver;
        for &c in &self.dirty_list {
            self.cand[c as usize].dirty = false;
        }
        self.dirty_list.clear();
        self.alive.iter_mut().for_each(|a| *a = true);
        self.dead_count.iter_mut().for_each(|d| *d = 0);
        self.stamp.iter_mut().for_each(|s| *s = 0);
        self.remaining = self.alive.len() as u32;
        self.chosen.clear();
        self.quality.truncate(1);
        self.log.clear();
    }

    /// Reverts the changes that base applies and tree pushes share (polders, dead
    /// components); false for any other change.
    #[inline]
    pub(super) fn undo_shared(&mut self, op: Op) -> bool {
        match op {
            Op::Polder { t, old } => self.polder[t as usize] = old,
            Op::PolderNew => {
                self.polder_size.pop();
            }
            Op::PolderSize { p, old } => self.polder_size[p as usize] = old,
            Op::OddActive { old } => self.odd_active = old,
            Op::Union { child, root } => {
                self.dsu_parent[child as usize] = child;
                self.dsu_size[root as usize] -= self.dsu_size[child as usize];
            }
            _ => return false,
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate::{GridSpec, grid};
    use crate::quality::CandidateTable;

    /// Forward mode keeps the split list to its live candidates (and their positions
    /// right) and the quality to two values; a reset brings back the initial ones. (The
    /// list kept every candidate ever split: 674,000 of a 10^6-triangle grid's run.)
    #[test]
    fn forward_runs_keep_the_split_list_to_live_candidates() {
        let m = grid(GridSpec {
            triangles: 30_000,
            holes: true,
            seed: 3,
            ..GridSpec::default()
        });
        let table = CandidateTable::build(&m);
        let mut st = State::new(&m, &table);
        st.set_forward(true);
        let (split0, quality0) = (st.split.clone(), st.quality.clone());
        while let Some(k) = st.min_k() {
            let t = st.bucket_nth(k, 0);
            let c = (st.candidates_of(t).into_iter())
                .find(|&c| c != NONE && st.is_allowed(c))
                .expect("a triangle of P_k has an allowed action");
            st.apply(c);
            assert!(
                st.split.len() < 2 * st.split.iter().filter(|&&c| st.is_live(c)).count() + 1024
            );
            for (i, &c) in st.split.iter().enumerate() {
                assert_eq!(st.split_pos[c as usize], i as u32);
            }
            assert_eq!(st.quality.len(), 2);
        }
        assert!(st.chosen().len() > 1000, "{} actions", st.chosen().len());
        let sum: f64 = st.chosen().iter().map(|&c| table.eta[c as usize]).sum();
        assert_eq!(st.quality(), sum);
        st.reset();
        assert_eq!((st.split.clone(), st.quality.clone()), (split0, quality0));
    }
}
