//! The recombination state: remaining triangles, chosen quads, the running quality, and the
//! exact set of allowed actions under the generalised polder criterion, with `apply` / `undo`
//! through a change log (flat arrays, `u32` indices, nothing cloned).
//!
//! # The criterion
//! Removing the two triangles of candidate `c` from their polder `P` (connected component of
//! the dual graph of the remaining triangles) leaves up to four parts. The action is forbidden
//! iff it increases the number of odd polders: with `|P|` even every part must be even, with
//! `|P|` odd exactly one part may be odd. Both cases read "at most one odd part".
//!
//! # How it stays exact and fast
//! * **Local proof.** Around each quad vertex `v` whose triangle fan is closed (interior,
//!   manifold) and has no removed triangle, the two quad neighbours meeting at `v` are
//!   connected through the fan. When these links connect every remaining neighbour, the
//!   removal disconnects nothing and the action is allowed in O(1) (`dead_count[v] == 0`).
//! * **Parity by the boundary** (`parity`): on a sphere with holes, a quad that touches one
//!   dead component `k >= 2` times (every other once) splits its polder into `k` parts, and
//!   the parity of each is that of edge weights summed along a path of dead edges and the
//!   quad's sides facing it, which the union–find keeps per vertex: no search.
//! * **Lockstep search** otherwise: one breadth-first search per group of neighbours, one
//!   triangle per search per round; groups merge when they meet; it stops when all groups
//!   met (one part) or all but one finished. Finished groups are whole parts (sizes known),
//!   the last part's size is `|P| - 2 - (the others)`, so the cost is the smaller parts.
//! * **Certificates.** A verdict stays valid while (a) the link vertices it may use keep no
//!   removed triangle, (b) every triangle its search visited remains (where searches met,
//!   only the paths that join them: `join_paths`), and (c) for verdicts
//!   that found a split, the parity of the polder holding the candidate is unchanged. So
//!   applying an action rechecks only: the candidates at vertices whose fan just lost its
//!   first triangle, the verdicts watching the two removed triangles, and, when a polder
//!   changes parity (only an odd polder can split into parts of other parity), the split
//!   verdicts in the parts that changed. A distinct-components verdict whose watched root
//!   merged is kept when its arcs' components are still distinct (forward mode), and a
//!   split read off parities watches no seed (`READ`). Proof sketch in `docs/search.md`.
//! * **Linked groups.** A dead component that touches the quad in one arc joins the
//!   neighbours on either side of it (its frontier runs around it from one to the other), so
//!   the searches start from fewer groups; such a verdict also watches the arcs' roots.
//! * Polder ids and sizes are kept per triangle; a split relabels only the finished
//!   (smaller) parts the search already enumerated.
//! * `P_k` are kept as bitmaps over triangle ids with a counting Fenwick tree over blocks
//!   (`pk`): a uniform draw takes the i-th member in increasing id order, so it depends on
//!   the current state only.
//! * **Look-ahead trees** (`tree`) explore on top of this exact base state without
//!   maintaining it: `tree_push` / `tree_pop` change only what the criterion reads (remaining
//!   triangles, fans, dead components, polders), and a verdict asked for inside the tree is
//!   taken from the base or from the tree's own cache when it *still holds* (its clean
//!   vertices still clean, its certificate intact: checked on reading, nothing is marked),
//!   else recomputed. `P_min` inside the tree (rare) is the base sets corrected by the
//!   triangles the path can have changed.
//! * **Layout.** What is read together is stored together: one 36-byte record per candidate
//!   (the quad's neighbours, verdict and stale mark), its verdict's version apart in a
//!   4-byte array (every watch entry read checks it, and most are stale); the quad, the pair and
//!   each triangle's candidates are read from the table and a triangle's vertices from the
//!   mesh, not repeated (memory: a 64-byte candidate record with them cost 80 bytes per
//!   triangle of a grid, a triangle record of its ring of six vertices 24); the lockstep
//!   search, which streams through many triangles for their neighbours only, reads a dense
//!   dual graph.
//!
//! # Files
//! This module holds the records, the [`State`] struct and its read-only accessors;
//! `build` builds the layout and the initial verdicts ([`State::new`]), `verdicts` keeps
//! verdicts and their certificates current (recheck, lazy resolution), `undo` applies and
//! reverts actions through the change log, `check` evaluates the criterion for one
//! candidate, `oracle` holds the invariant checker and the from-scratch criterion the
//! tests compare against, `watch` keeps the watch lists (the verdicts each triangle and
//! dead-component root certifies) in one slab, and `acyclic`, `parity`, `pk` and `tree`
//! are described above.

#![allow(clippy::needless_range_loop)] // index loops over the 4 quad sides read best

mod acyclic;
mod audit;
mod build;
mod check;
mod oracle;
mod parity;
mod pk;
mod tree;
mod tree_cache;
mod undo;
mod verdicts;
mod watch;

use crate::mesh::{Mesh, NONE};
use crate::quality::CandidateTable;
pub use audit::{TreeAudit, TreeEvent, TreeView};
pub use oracle::naive_allowed;
use pk::OrderedSets;
pub use tree::Near;
use tree::Overlay;
use watch::WatchLists;

/// How a verdict was reached (what it depends on).
const KIND_LOCAL: u8 = 0;
/// The searches met: one part. Depends on the visited triangles.
const KIND_MET: u8 = 1;
/// A split was found. Depends on the visited triangles and the polder's parity.
const KIND_SPLIT: u8 = 2;
/// The quad touches removed regions in several places, all in distinct dead components:
/// one part. Depends on those components staying distinct.
const KIND_DISTINCT: u8 = 3;
/// A split with a finished part too large to list (over [`LONG_PART`] triangles, found by
/// one search): that part is certified by its seeds only, like the running part. Depends
/// on the listed triangles and on no split on its polder changing the polder's parity
/// (the verdict is not re-derived from the polder's size).
const KIND_SPLIT_LONG: u8 = 4;
/// Largest finished part a split verdict's certificate lists triangle by triangle. A part
/// found by one search needs only its seeds (see [`KIND_SPLIT_LONG`]): on a long thin
/// polder (a one-cell strip) listing every part made the certificates quadratic in the
/// strip's length.
const LONG_PART: usize = 32;

/// `Verdict::mask` bit: the verdict's groups were joined through dead components that
/// touch the quad once (see `check_slow`); its certificate ends with the roots of every arc,
/// tagged with [`ROOT_TAG`], which must stay roots.
const LINKED: u8 = 1 << 7;
/// `Verdict::mask` bit: a split read off parities ([`parity`]), certified by its groups'
/// seeds for the trees (`still_holds`); the base does not watch them. Using a seed cannot
/// change the verdict unnoticed: the seed's part loses the pair (its parity unchanged) or is
/// cut, and a cut piece no longer beside the quad changes the polder's parity exactly when
/// it is odd (the split list marks the verdict); a cut between seeds of one group needs a
/// link of the group to break (a clean vertex dirtied, marked; a linked arc's root merged,
/// watched).
const READ: u8 = 1 << 6;
/// Tag of a dead-component root in a triangle certificate (vertex and triangle ids stay
/// below it).
const ROOT_TAG: u32 = 1 << 31;
// Every mesh the reader accepts has its vertex and triangle ids below the tag.
const _: () = assert!(crate::mesh::topology::MAX_VERTICES < ROOT_TAG as usize);

/// A split verdict, listed (`KIND_SPLIT`) or long (`KIND_SPLIT_LONG`).
#[inline]
fn is_split(kind: u8) -> bool {
    kind == KIND_SPLIT || kind == KIND_SPLIT_LONG
}
/// Per candidate: what the local proof reads beside the quad (the table's `quads`), its
/// verdict and stale mark, which are read together. 36 bytes: the quad and the pair are
/// read from the table (they were repeated here, on a 64-byte line), the verdict's version
/// from `State::cert_ver`.
#[derive(Debug, Clone, Copy)]
struct CandRecord {
    /// The neighbours across the quad's sides (NONE where none).
    nb: [u32; 4],
    /// Its current verdict (base state).
    verdict: Verdict,
    /// Bit i: quad vertex i has a closed fan.
    flags: u8,
    /// One triangle neighbours the quad across two of its sides (no local proof then).
    shared: bool,
    /// Bits 0..4: the edge weights of the quad's sides ([`parity`]); [`ACTIVE`]: its
    /// polder was even at the start, on a mesh the parity argument covers.
    par: u8,
    /// The verdict was marked possibly stale by an action and not yet rechecked.
    dirty: bool,
}
const _: () = assert!(std::mem::size_of::<CandRecord>() == 36);

/// `CandRecord::par` bit: the candidate's parts can be told apart by parity alone
/// ([`parity`]).
const ACTIVE: u8 = 1 << 4;

/// Owner mark for the two triangles being removed during a search.
const BLOCKED: u32 = 7;
/// Search mark of a used triangle: above every epoch's marks, so one comparison tells an
/// unvisited remaining triangle from a visited or used one.
const DEAD: u32 = u32::MAX;
/// Epochs stay below this so that `epoch << 3 | owner` never reaches `DEAD`.
const EPOCH_LIMIT: u32 = (1 << 29) - 2;

/// One reversible change.
#[derive(Debug, Clone, Copy)]
enum Op {
    /// Start of an `apply(c)`: undone last, revives the pair.
    Apply(u32),
    /// Start of a `tree_push(c)`: undone last by `tree_pop`, revives the pair.
    TreeApply(u32),
    /// Previous verdict of candidate `c` and its version.
    Verdict { c: u32, old: Verdict, ver: u32 },
    /// Triangle `t` had `old` allowed actions.
    Count { t: u32, old: u8 },
    /// Triangle `t` was in polder `old`.
    Polder { t: u32, old: u32 },
    /// A polder id was created.
    PolderNew,
    /// Polder `p` had size `old`.
    PolderSize { p: u32, old: u32 },
    /// A watch entry was pushed onto triangle `t`'s list.
    Watch(u32),
    /// Candidate was pushed onto the split-verdict list.
    SplitIns,
    /// Candidate `c` was removed from position `pos` of the split-verdict list.
    SplitRem { c: u32, pos: u32 },
    /// Dead-component root `child` was attached under `root`.
    Union { child: u32, root: u32 },
    /// [`State::odd_active`] was `old`.
    OddActive { old: u32 },
    /// A watch entry was pushed onto dead-component root `v`'s list.
    RootWatch(u32),
    /// A candidate was marked stale (pushed on the dirty list).
    Dirty,
    /// Candidate `c` was rechecked and marked exact.
    Clean(u32),
    /// Candidate `c` was popped from the dirty list.
    DirtyPop(u32),
}

/// A verdict of the criterion and what it depends on.
#[derive(Debug, Clone, Copy, Default)]
struct Verdict {
    allowed: bool,
    /// `KIND_*`: how it was reached.
    kind: u8,
    /// Bit i: quad vertex i was clean (closed fan, no used triangle) when it was computed;
    /// the verdict holds only while these stay clean. Bit 7: [`LINKED`].
    mask: u8,
    /// Split: odd parts among the finished (enumerated) parts.
    fin_odd: u8,
    /// Split: triangles in the finished parts.
    fin_known: u32,
    /// Certificate in its arena (`offset`, `length`): dead-component roots for
    /// `KIND_DISTINCT`, triangles for `KIND_MET` / `KIND_SPLIT` (then, for a [`LINKED`]
    /// verdict, the arcs' roots tagged with [`ROOT_TAG`]).
    cert: u32,
    cert_len: u32,
}

/// What forward mode resets to (see [`State::set_forward`]).
#[derive(Debug, Clone)]
struct Initial {
    verdict: Vec<Verdict>,
    cert_ver: Vec<u32>,
    count: Vec<u8>,
    sets: OrderedSets,
    polder: Vec<u32>,
    polder_size: Vec<u32>,
    dsu_parent: Vec<u32>,
    dsu_size: Vec<u32>,
    dsu_par: Vec<u8>,
    split: Vec<u32>,
    split_pos: Vec<u32>,
    watch_len: Vec<u32>,
    ver: u32,
}

/// The recombination state. See the module docs.
#[derive(Debug, Clone)]
pub struct State<'a> {
    mesh: &'a Mesh,
    table: &'a CandidateTable,
    // ---- static ----
    /// Vertex fan is one closed cycle of triangles in the dual graph.
    closed: Vec<bool>,
    /// Per candidate: its quad's neighbours, verdict, stale mark.
    cand: Vec<CandRecord>,
    /// Per candidate: the version of its verdict, which the watch lists refer to. Apart from
    /// the records: every watch entry read or pruned reads it, and most entries are stale
    /// (a 4-byte array stays in cache where 36-byte records do not).
    cert_ver: Vec<u32>,
    /// The candidates' dual graph as a dense array (the triangle across each side through a
    /// candidate, or NONE), which the lockstep searches stream through.
    dual: Vec<[u32; 3]>,
    // ---- dynamic ----
    alive: Vec<bool>,
    remaining: u32,
    count: Vec<u8>,
    sets: OrderedSets,
    /// Certificates of the base verdicts (append-only; cut back to the initial verdicts'
    /// when the state is reset).
    base_cert: Vec<u32>,
    base_cert_init: usize,
    /// Forward mode: arena length from which [`State::compact_base_cert`] drops the
    /// certificates of verdicts since recomputed.
    base_cert_compact_at: usize,
    ver: u32,
    dead_count: Vec<u32>,
    polder: Vec<u32>,
    polder_size: Vec<u32>,
    /// The watch lists: per triangle, the verdicts whose certificate holds it, and per
    /// dead-component root (`watch.root(v)`), the verdicts that rely on it staying a root.
    watch: WatchLists,
    /// Union-find (by size, no path compression, so it can be undone) over vertices: the
    /// connected pieces of the removed region (used triangles, boundaries, input quads).
    dsu_parent: Vec<u32>,
    dsu_size: Vec<u32>,
    /// Per vertex, the parity of the edge weights ([`parity`]) along a path of dead edges
    /// to its parent in the union–find.
    dsu_par: Vec<u8>,
    /// Odd polders among those that were even at the start (none unless an action the
    /// criterion forbids was applied): while there are, no verdict is read off parities.
    odd_active: u32,
    /// [`State::check`] must search (the parts are relabelled after it), not read a split
    /// off parities.
    need_parts: bool,
    arc_roots: [u32; 4],
    narcs: usize,
    /// The candidates with a split verdict (`split_pos`: their positions, NONE for the
    /// others), which a polder's change of parity marks; in forward mode used candidates
    /// are dropped from it now and then ([`State::drop_used_splits`]).
    split: Vec<u32>,
    split_pos: Vec<u32>,
    /// Forward mode: length of `split` from which the used candidates are dropped.
    split_compact_at: usize,
    /// Verdicts marked possibly stale and not yet rechecked (their records say `dirty`).
    dirty_list: Vec<u32>,
    chosen: Vec<u32>,
    quality: Vec<f64>,
    log: Vec<Op>,
    /// The look-ahead tree on top of the base state.
    tree: Overlay,
    /// Forward mode (`set_forward`) and the initial state it resets to (none after
    /// [`State::set_forward_uncopied`]: a single run from the state as built).
    forward: bool,
    initial: Option<Box<Initial>>,
    /// [`State::new`] is computing the initial verdicts: nothing before them is undone, so
    /// their changes are not logged (the log was the build's peak: 500 bytes per triangle
    /// of a grid).
    building: bool,
    /// The last action applied, when every verdict was exact before it and it had a local
    /// proof (its remaining neighbours stay joined around its clean vertices): what
    /// [`State::shrink_split`] needs. `NONE` otherwise.
    last_local: u32,
    /// The clean quad vertices (bits) of `last_local`'s proof.
    last_local_mask: u8,
    /// Test hook called after every tree push and pop ([`State::set_tree_audit`]).
    audit: Option<TreeAudit>,

    // ---- scratch ----
    /// Search marks: `epoch << 3 | owner` (owner = search index or `BLOCKED`) for a triangle
    /// visited by the current search, lower for an unvisited one, `DEAD` for a used one.
    stamp: Vec<u32>,
    epoch: u32,
    queue: [Vec<u32>; 4],
    head: [usize; 4],
    /// Seeds (the quad's neighbours) at the front of each search queue.
    nseed: [usize; 4],
    /// How much of each queue the verdict depends on (its certificate).
    cert_len: [usize; 4],
    /// Split: whether each search's group finished (its queue is a whole part).
    finished: [bool; 4],
    /// The breadth-first search of [`State::join_paths`]: triangle and parent index.
    path_bfs: Vec<[u32; 2]>,
    /// Part of the last check's certificate: the paths joining searches that met
    /// ([`State::join_paths`]); empty when none met.
    path: Vec<u32>,
    group: [u8; 4],
    nsearch: usize,
    changed: Vec<u32>,
    moved: Vec<u32>,
    /// Fan triangles for [`State::shrink_split`].
    fan: Vec<u32>,
    /// Candidates at a vertex ([`State::candidates_at`]) for `apply`.
    at_vertex: Vec<u32>,
    /// Candidates whose split verdict the current `apply` kept by `shrink_split`.
    shrunk: Vec<u32>,
    /// The dead components an action's distinct-components proof saw (roots before its
    /// unions), and the roots its unions attached: for `shrink_split`.
    y_roots: Vec<u32>,
    attached: Vec<u32>,
    /// Number of criterion checks that needed a search (statistics).
    pub searches: u64,
    /// Number of triangles those searches visited.
    pub searched: u64,
    /// Splits decided by parity without a search (statistics).
    pub parity_splits: u64,
    /// Of those, splits into three parts and into four: one dead component touching the
    /// quad three or four times (statistics).
    pub parity_multi: [u64; 2],
    /// Split verdicts kept across an action inside one of their parts instead of a new
    /// search (statistics).
    pub split_shrinks: u64,
    /// Distinct-components verdicts kept when one of their roots was attached, instead of
    /// a recheck (statistics).
    pub distinct_kept: u64,
    /// Distinct-components verdicts found again by a recheck, installed keeping their
    /// version (`reinstall_distinct`) (statistics).
    pub distinct_rekept: u64,
}

impl<'a> State<'a> {
    /// The mesh this state recombines.
    pub fn mesh(&self) -> &'a Mesh {
        self.mesh
    }

    /// The candidate table.
    pub fn table(&self) -> &'a CandidateTable {
        self.table
    }

    /// True when candidate `c` may be applied now: both triangles remain and the criterion
    /// allows it. Exact at any time.
    #[inline]
    pub fn is_allowed(&self, c: u32) -> bool {
        self.cand[c as usize].verdict.allowed
    }

    /// Number of allowed actions of triangle `t` (the `k` of `P_k`); 0 for a used triangle.
    #[inline]
    pub fn allowed_count(&self, t: u32) -> u32 {
        self.count[t as usize] as u32
    }

    /// True when triangle `t` is not yet part of a quad.
    #[inline]
    pub fn is_remaining(&self, t: u32) -> bool {
        self.alive[t as usize]
    }

    /// Both triangles of `c` remain (whatever the criterion says).
    #[inline]
    pub fn is_live(&self, c: u32) -> bool {
        let [a, b] = self.table.pairs[c as usize];
        self.alive[a as usize] && self.alive[b as usize]
    }

    /// The vertices of triangle `t` (as in the mesh).
    #[inline]
    fn verts(&self, t: u32) -> [u32; 3] {
        self.mesh.triangles[t as usize]
    }

    /// The triangle of `pair` that has vertex `v` (the first when both have it): where a
    /// walk around `v` starts.
    #[inline]
    fn corner_of(&self, [a, b]: [u32; 2], v: u32) -> u32 {
        if self.verts(a).contains(&v) { a } else { b }
    }

    /// One step of a walk around vertex `v` through the dual graph, in triangle `t`
    /// (arrived from `prev`, `NONE` at the start): the side `t` is left by (the side at `v`
    /// not towards `prev`), the triangle across it (`NONE` where the fan is open) and the
    /// index of `v` in `t`. Sides at `v`: side k (tri[k], tri[k+1]) and side k-1; side k+1
    /// is opposite `v`.
    #[inline]
    fn fan_step(&self, t: u32, v: u32, prev: u32) -> (usize, u32, usize) {
        let k = (self.verts(t).iter())
            .position(|&x| x == v)
            .expect("v is a corner of its fan's triangles");
        let nb = &self.dual[t as usize];
        let side = if nb[k] != prev { k } else { (k + 2) % 3 };
        (side, nb[side], k)
    }

    /// Appends to `out` every candidate whose quad has vertex `v`, whose fan is closed
    /// (`closed[v]`), from `start`, a triangle of the fan: the candidates of the fan's
    /// triangles, walked through the dual graph (each has `v` in its quad, and every quad
    /// with `v` has a triangle in the fan), each once: per triangle, the pair across its
    /// side opposite `v` and the pair with the next triangle of the walk. Takes the place
    /// of a vertex-to-candidate list (16 bytes per candidate).
    fn candidates_at(&self, v: u32, start: u32, out: &mut Vec<u32>) {
        debug_assert!(self.closed[v as usize]);
        let (mut t, mut prev) = (start, NONE);
        loop {
            let (side, next, k) = self.fan_step(t, v, prev);
            debug_assert_ne!(next, NONE, "a closed fan");
            let cands = &self.table.by_triangle[t as usize];
            let opposite = cands[(k + 1) % 3];
            if opposite != NONE {
                out.push(opposite);
            }
            // The dual graph joins candidates' pairs only: a candidate across `side`.
            out.push(cands[side]);
            prev = t;
            t = next;
            if t == start {
                return;
            }
        }
    }

    /// The candidate across each side of triangle `t` (the table's `by_triangle[t]`).
    #[inline]
    pub fn candidates_of(&self, t: u32) -> [u32; 3] {
        self.table.by_triangle[t as usize]
    }

    /// The triangle of `c` other than `t`.
    #[inline]
    fn other(&self, c: u32, t: u32) -> u32 {
        let [a, b] = self.table.pairs[c as usize];
        if a == t { b } else { a }
    }

    /// Every allowed action, in increasing candidate order (O(candidates); for tests).
    pub fn allowed_actions(&self) -> Vec<u32> {
        (0..self.table.len() as u32)
            .filter(|&c| self.is_allowed(c))
            .collect()
    }

    /// Triangles with exactly `k` allowed actions (`P_k`, k in 1..=3), in increasing id
    /// (O(|P_k| log n); for tests).
    pub fn bucket(&self, k: u32) -> Vec<u32> {
        (0..self.bucket_len(k))
            .map(|i| self.bucket_nth(k, i))
            .collect()
    }

    /// Size of `P_k` (k in 1..=3).
    #[inline]
    pub fn bucket_len(&self, k: u32) -> usize {
        self.sets.len(k as usize)
    }

    /// The member of `P_k` with `i` members of smaller id (`i < bucket_len(k)`): a uniform
    /// draw from `P_k` is `bucket_nth(k, uniform(0..len))`. O(log n).
    #[inline]
    pub fn bucket_nth(&self, k: u32, i: usize) -> u32 {
        self.sets.select(k as usize, i)
    }

    /// The smallest `k` with `P_k` non-empty, or `None` when no action is allowed.
    #[inline]
    pub fn min_k(&self) -> Option<u32> {
        (1..4u32).find(|&k| self.bucket_len(k) > 0)
    }

    /// Candidates applied so far, in order.
    pub fn chosen(&self) -> &[u32] {
        &self.chosen
    }

    /// Number of quads created.
    pub fn quads(&self) -> usize {
        self.chosen.len()
    }

    /// Number of remaining triangles.
    pub fn triangles_left(&self) -> usize {
        self.remaining as usize
    }

    /// Sum of eta over the quads created (eq. 2).
    pub fn quality(&self) -> f64 {
        *self.quality.last().expect("base quality")
    }

    /// Polder id of a remaining triangle.
    pub fn polder_of(&self, t: u32) -> u32 {
        self.polder[t as usize]
    }

    /// Size of polder `p`.
    pub fn polder_size(&self, p: u32) -> u32 {
        self.polder_size[p as usize]
    }

    /// The neighbours across the quad edges of candidate `c`, `NONE` where there is none.
    #[inline]
    pub fn quad_neighbours(&self, c: u32) -> [u32; 4] {
        self.cand[c as usize].nb
    }

    /// Number of applied actions that `undo` can revert.
    pub fn depth(&self) -> usize {
        self.chosen.len()
    }
}
