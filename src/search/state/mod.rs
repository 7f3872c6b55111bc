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
//! * **Lockstep search** otherwise: one breadth-first search per group of neighbours, one
//!   triangle per search per round; groups merge when they meet; it stops when all groups
//!   met (one part) or all but one finished. Finished groups are whole parts (sizes known),
//!   the last part's size is `|P| - 2 - (the others)`, so the cost is the smaller parts.
//! * **Certificates.** A verdict stays valid while (a) the link vertices it may use keep no
//!   removed triangle, (b) every triangle its search visited remains, and (c) for verdicts
//!   that found a split, the parity of the polder holding the candidate is unchanged. So
//!   applying an action rechecks only: the candidates at vertices whose fan just lost its
//!   first triangle, the verdicts watching the two removed triangles, and, when a polder
//!   changes parity (only an odd polder can split into parts of other parity), the split
//!   verdicts in the parts that changed. Proof sketch in `docs/search.md`.
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
//! * **Layout.** What is read together is stored together: one 64-byte record per candidate
//!   (quad, neighbours, pair, verdict, its version and stale mark) and one per triangle
//!   (its ring of vertices, neighbours, candidates), so that touching an element costs one
//!   cache line; the lockstep search, which streams through many triangles for their
//!   neighbours only, reads the mesh's dense dual graph instead.

#![allow(clippy::needless_range_loop)] // index loops over the 4 quad sides read best

mod acyclic;
mod check;
mod pk;
mod tree;

use crate::mesh::{Mesh, NONE};
use crate::quality::CandidateTable;
use pk::OrderedSets;
pub use tree::Near;
use tree::Overlay;

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

/// A split verdict, listed (`KIND_SPLIT`) or long (`KIND_SPLIT_LONG`).
#[inline]
fn is_split(kind: u8) -> bool {
    kind == KIND_SPLIT || kind == KIND_SPLIT_LONG
}
/// Per candidate, on one cache line (64 bytes, aligned): what the local proof reads, its
/// pair, its verdict, the verdict's version and stale mark, which are read together.
#[derive(Debug, Clone, Copy)]
#[repr(align(64))]
struct CandRecord {
    /// The quad's vertices and the neighbours across its sides (NONE where none).
    quad: [u32; 4],
    nb: [u32; 4],
    /// The candidate's two triangles (as in the table; kept here, on the same cache line
    /// as the rest, because nearly every access to a candidate reads them).
    pair: [u32; 2],
    /// Its current verdict (base state).
    verdict: Verdict,
    /// Version of the verdict, which the watch lists refer to (read for every watch entry,
    /// which then reads the pair).
    cert_ver: u32,
    /// Bit i: quad vertex i has a closed fan.
    flags: u8,
    /// One triangle neighbours the quad across two of its sides (no local proof then).
    shared: bool,
    /// The verdict was marked possibly stale by an action and not yet rechecked.
    dirty: bool,
}
const _: () = assert!(std::mem::size_of::<CandRecord>() == 64);

/// Per triangle, in one record: what the searches, `apply` and the trees read about it.
#[derive(Debug, Clone, Copy)]
struct TriRecord {
    /// Its vertices, then the vertex across each of its sides (NONE without a neighbour):
    /// every vertex of every quad it can be part of.
    ring: [u32; 6],
    /// The triangle across each side (the dual graph), or NONE.
    nb: [u32; 3],
    /// The candidate across each side (the table's `by_triangle`), or NONE.
    cands: [u32; 3],
}

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
    /// the verdict holds only while these stay clean.
    mask: u8,
    /// Split: odd parts among the finished (enumerated) parts.
    fin_odd: u8,
    /// Split: triangles in the finished parts.
    fin_known: u32,
    /// Certificate in its arena (`offset`, `length`): dead-component roots for
    /// `KIND_DISTINCT`, triangles for `KIND_MET` / `KIND_SPLIT`.
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
    split: Vec<u32>,
    split_pos: Vec<u32>,
    watch_len: Vec<u32>,
    root_watch_len: Vec<u32>,
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
    /// Per candidate: its quad, neighbours, pair, verdict, version, stale mark (one cache line).
    cand: Vec<CandRecord>,
    /// Per triangle: its ring of vertices, neighbours and candidates.
    tri: Vec<TriRecord>,
    /// The candidates' dual graph as a dense array (the triangle across each side through a
    /// candidate, or NONE), which the lockstep searches stream through.
    dual: Vec<[u32; 3]>,
    /// Candidates whose quad has vertex `v` (CSR).
    vc_start: Vec<u32>,
    vc_list: Vec<u32>,
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
    watch: Vec<Vec<(u32, u32)>>,
    /// Union-find (by size, no path compression, so it can be undone) over vertices: the
    /// connected pieces of the removed region (used triangles, boundaries, input quads).
    dsu_parent: Vec<u32>,
    dsu_size: Vec<u32>,
    /// Verdicts that rely on a dead-component root staying a root.
    root_watch: Vec<Vec<(u32, u32)>>,
    arc_roots: [u32; 4],
    narcs: usize,
    split: Vec<u32>,
    split_pos: Vec<u32>,
    /// Verdicts marked possibly stale and not yet rechecked (their records say `dirty`).
    dirty_list: Vec<u32>,
    chosen: Vec<u32>,
    quality: Vec<f64>,
    log: Vec<Op>,
    /// The look-ahead tree on top of the base state.
    tree: Overlay,
    /// Forward mode (`set_forward`) and the initial state it resets to.
    forward: bool,
    initial: Option<Box<Initial>>,
    /// The last action applied, when every verdict was exact before it and it had a local
    /// proof (its remaining neighbours stay joined around its clean vertices): what
    /// [`State::shrink_split`] needs. `NONE` otherwise.
    last_local: u32,
    /// The clean quad vertices (bits) of `last_local`'s proof.
    last_local_mask: u8,

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
    group: [u8; 4],
    nsearch: usize,
    changed: Vec<u32>,
    moved: Vec<u32>,
    /// Fan triangles for [`State::shrink_split`].
    fan: Vec<u32>,
    /// Number of criterion checks that needed a search (statistics).
    pub searches: u64,
    /// Number of triangles those searches visited.
    pub searched: u64,
    /// Split verdicts kept across an action inside one of their parts instead of a new
    /// search (statistics).
    pub split_shrinks: u64,
}

impl<'a> State<'a> {
    /// The initial state of `mesh` (every triangle remaining) with every verdict computed.
    pub fn new(mesh: &'a Mesh, table: &'a CandidateTable) -> State<'a> {
        let nt = mesh.num_triangles();
        let nv = mesh.vertices.len();
        let m = table.len();
        // The dual graph of the candidates: the mesh's, less the pairs the rule dropped
        // (those sides are boundaries for the criterion, like a surface's).
        let dual = table.dual_graph();
        let (polder, polder_size) = CandidateTable::components(&dual);
        let nb = &dual;
        let cand_nb: Vec<[u32; 4]> = (0..m)
            .map(|c| {
                let [t0, t1] = table.pairs[c];
                let [s0, o1, s1, o0] = table.quads[c];
                let across = |t: u32, a: u32, b: u32| {
                    let tri = mesh.triangles[t as usize];
                    (0..3)
                        .find(|&i| {
                            let (x, y) = (tri[i], tri[(i + 1) % 3]);
                            (x == a && y == b) || (x == b && y == a)
                        })
                        .map_or(NONE, |i| nb[t as usize][i])
                };
                [
                    across(t1, s0, o1),
                    across(t1, o1, s1),
                    across(t0, s1, o0),
                    across(t0, o0, s0),
                ]
            })
            .collect();
        // Vertex fans: closed iff walking around v through the dual graph visits every
        // incident triangle and comes back.
        let mut vt_count = vec![0u32; nv];
        let mut vt_first = vec![NONE; nv];
        for (t, tri) in mesh.triangles.iter().enumerate() {
            for &v in tri {
                vt_count[v as usize] += 1;
                vt_first[v as usize] = t as u32;
            }
        }
        let has_quad: Vec<bool> = {
            let mut h = vec![false; nv];
            for q in &mesh.quads {
                for &v in q {
                    h[v as usize] = true;
                }
            }
            h
        };
        let closed: Vec<bool> = (0..nv)
            .map(|v| {
                let n = vt_count[v];
                if n < 3 || has_quad[v] {
                    return false;
                }
                let start = vt_first[v];
                let (mut prev, mut cur) = (NONE, start);
                for step in 0..n {
                    let tri = mesh.triangles[cur as usize];
                    let j = tri.iter().position(|&x| x == v as u32).expect("incident");
                    let (a, b) = (nb[cur as usize][j], nb[cur as usize][(j + 2) % 3]);
                    let next = if a != prev { a } else { b };
                    if next == NONE || (step == 0 && a == NONE) {
                        return false;
                    }
                    prev = cur;
                    cur = next;
                    if cur == start {
                        return step + 1 == n;
                    }
                }
                false
            })
            .collect();
        let mut vc_start = vec![0u32; nv + 1];
        for q in &table.quads {
            for &v in q {
                vc_start[v as usize + 1] += 1;
            }
        }
        for v in 0..nv {
            vc_start[v + 1] += vc_start[v];
        }
        let mut fill = vc_start.clone();
        let mut vc_list = vec![0u32; vc_start[nv] as usize];
        for (c, q) in table.quads.iter().enumerate() {
            for &v in q {
                vc_list[fill[v as usize] as usize] = c as u32;
                fill[v as usize] += 1;
            }
        }
        let cand: Vec<CandRecord> = (0..m)
            .map(|c| {
                let (quad, nb) = (table.quads[c], cand_nb[c]);
                let mut l = CandRecord {
                    quad,
                    nb,
                    pair: table.pairs[c],
                    verdict: Verdict::default(),
                    cert_ver: 0,
                    flags: 0,
                    shared: false,
                    dirty: false,
                };
                for i in 0..4 {
                    if closed[quad[i] as usize] {
                        l.flags |= 1 << i;
                    }
                    l.shared |= nb[i] != NONE && (0..i).any(|j| nb[j] == nb[i]);
                }
                l
            })
            .collect();
        let tri: Vec<TriRecord> = (0..nt)
            .map(|t| {
                let tri = mesh.triangles[t];
                let mut r = [tri[0], tri[1], tri[2], NONE, NONE, NONE];
                for i in 0..3 {
                    let u = nb[t][i];
                    if u != NONE {
                        let (a, b) = (tri[i], tri[(i + 1) % 3]);
                        r[3 + i] = mesh.triangles[u as usize]
                            .into_iter()
                            .find(|&x| x != a && x != b)
                            .unwrap_or(NONE);
                    }
                }
                TriRecord {
                    ring: r,
                    nb: nb[t],
                    cands: table.by_triangle[t],
                }
            })
            .collect();
        let mut st = State {
            mesh,
            table,
            closed,
            cand,
            tri,
            dual,
            vc_start,
            vc_list,
            alive: vec![true; nt],
            remaining: nt as u32,
            count: vec![0; nt],
            sets: OrderedSets::new(nt),
            base_cert: Vec::new(),
            base_cert_init: 0,
            base_cert_compact_at: 0,
            ver: 0,
            dead_count: vec![0; nv],
            polder,
            polder_size,
            watch: vec![Vec::new(); nt],
            dsu_parent: (0..nv as u32).collect(),
            dsu_size: vec![1; nv],
            root_watch: vec![Vec::new(); nv],
            arc_roots: [NONE; 4],
            narcs: 0,
            split: Vec::new(),
            split_pos: vec![NONE; m],
            dirty_list: Vec::new(),
            chosen: Vec::new(),
            quality: vec![0.0],
            log: Vec::new(),
            tree: Overlay::new(m, nv, nt),
            forward: false,
            initial: None,
            last_local: NONE,
            last_local_mask: 0,
            stamp: vec![0; nt],
            epoch: 0,
            queue: Default::default(),
            head: [0; 4],
            nseed: [0; 4],
            cert_len: [0; 4],
            finished: [false; 4],
            group: [0; 4],
            nsearch: 0,
            changed: Vec::new(),
            moved: Vec::new(),
            fan: Vec::new(),
            searches: 0,
            searched: 0,
            split_shrinks: 0,
        };
        // The removed region at the start: boundary edges (mesh, surface and quad
        // boundaries: dual sides without a neighbour) and input quads.
        for (t, tri) in mesh.triangles.iter().enumerate() {
            for i in 0..3 {
                if st.dual[t][i] == NONE {
                    st.union(tri[i], tri[(i + 1) % 3]);
                }
            }
        }
        for q in &mesh.quads {
            for i in 1..4 {
                st.union(q[0], q[i]);
            }
        }
        // Components without a cycle (corridors) all at once; a search per candidate
        // elsewhere.
        let acyclic = st.acyclic_parts();
        for c in 0..m as u32 {
            match acyclic.as_ref().and_then(|a| st.acyclic_verdict(a, c)) {
                Some(r) => st.install_verdict(c, r),
                None => st.recheck_one(c),
            }
        }
        drop(acyclic);
        // The initial verdicts are the base state: nothing to undo before it (and the log's
        // memory, as large as every initial change, is given back).
        st.log = Vec::new();
        st.base_cert_init = st.base_cert.len();
        st.base_cert.shrink_to_fit();
        st.base_cert_compact_at = st.base_cert_init + m.max(1024);
        st
    }

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
        let [a, b] = self.cand[c as usize].pair;
        self.alive[a as usize] && self.alive[b as usize]
    }

    /// The vertices of triangle `t` (as in the mesh).
    #[inline]
    fn verts(&self, t: u32) -> [u32; 3] {
        let r = &self.tri[t as usize].ring;
        [r[0], r[1], r[2]]
    }

    /// The candidate across each side of triangle `t` (the table's `by_triangle[t]`), read
    /// from the state's per-triangle record.
    #[inline]
    pub fn candidates_of(&self, t: u32) -> [u32; 3] {
        self.tri[t as usize].cands
    }

    /// The triangle of `c` other than `t`.
    #[inline]
    fn other(&self, c: u32, t: u32) -> u32 {
        let [a, b] = self.cand[c as usize].pair;
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

    /// Recomputes the verdict of live candidate `c` and records its certificate.
    fn recheck_one(&mut self, c: u32) {
        if self.forward && self.base_cert.len() >= self.base_cert_compact_at {
            self.compact_base_cert();
        }
        if self.shrink_split(c) {
            return;
        }
        let r = self.check(c);
        self.install_verdict(c, r);
    }

    /// Makes `r` the verdict of `c`, its certificate the one the last check left in scratch
    /// ([`State::append_cert`]), and updates the counts, watch lists and split list.
    fn install_verdict(&mut self, c: u32, mut r: Verdict) {
        let ci = c as usize;
        let old = self.cand[ci].verdict;
        // A verdict of the local kind is never read back through its mask (the trees
        // recompute the local proof first), so a new mask alone is not a change.
        if r.kind == KIND_LOCAL && old.kind == KIND_LOCAL && r.allowed == old.allowed {
            return;
        }
        self.base_log(Op::Verdict {
            c,
            old,
            ver: self.cand[ci].cert_ver,
        });
        self.ver = self.ver.wrapping_add(1);
        let ver = self.ver;
        self.cand[ci].cert_ver = ver;
        (r.cert, r.cert_len) = self.append_cert(r.kind, false);
        self.cand[ci].verdict = r;
        if r.allowed != old.allowed {
            let [t0, t1] = self.cand[ci].pair;
            for t in [t0, t1] {
                let k = self.count[t as usize];
                self.set_count(t, if r.allowed { k + 1 } else { k - 1 });
            }
        }
        if r.kind == KIND_DISTINCT {
            for i in 0..self.narcs {
                let root = self.arc_roots[i];
                self.root_watch[root as usize].push((c, ver));
                self.base_log(Op::RootWatch(root));
            }
        } else if r.kind != KIND_LOCAL {
            for s in 0..self.nsearch {
                for i in 0..self.cert_len[s] {
                    let t = self.queue[s][i];
                    self.watch_push(t, c, ver);
                }
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
    fn shrink_split(&mut self, c: u32) -> bool {
        let y = self.last_local;
        if y == NONE || !self.forward || self.chosen.last() != Some(&y) {
            return false;
        }
        let ci = c as usize;
        let v = self.cand[ci].verdict;
        if v.kind != KIND_SPLIT {
            return false;
        }
        let (qc, qy) = (self.cand[ci].quad, self.cand[y as usize].quad);
        if qc.iter().any(|a| qy.contains(a)) {
            return false;
        }
        let [a, b] = self.cand[y as usize].pair;
        let (off, fin, len) = (v.cert as usize, v.fin_known as usize, v.cert_len as usize);
        let cert = &self.base_cert[off..off + len];
        let keep = |t: &u32| *t != a && *t != b;
        let (off, len, fin_known) = if let Some(ia) = cert[..fin].iter().position(|&t| t == a) {
            let ib = cert[..fin].iter().position(|&t| t == b);
            let ib = ib.expect("both triangles of a pair are in the same part");
            let (lo, hi) = (ia.min(ib), ia.max(ib));
            if off >= self.base_cert_init {
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
            if !cert[fin..].iter().any(|t| !keep(t)) || !self.fans(y, self.last_local_mask) {
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
            let ver = self.cand[ci].cert_ver;
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

    /// The triangles around the clean quad vertices `mask` of candidate `y` (both of its
    /// triangles remaining), `y`'s own excepted, into `self.fan`; false when a fan does not
    /// close within 64 steps.
    fn fans(&mut self, y: u32, mask: u8) -> bool {
        self.fan.clear();
        let [a, b] = self.cand[y as usize].pair;
        let q = self.cand[y as usize].quad;
        for (i, &v) in q.iter().enumerate() {
            if mask & (1 << i) == 0 {
                continue;
            }
            let start = if self.verts(a).contains(&v) { a } else { b };
            // Walk around v: leave each triangle across its other edge at v.
            let (mut t, mut prev) = (start, NONE);
            for _ in 0..64 {
                let r = &self.tri[t as usize];
                let k = r.ring[..3]
                    .iter()
                    .position(|&x| x == v)
                    .expect("v is a corner");
                // Edges at v: (tri[k], tri[k+1]) is side k, (tri[k-1], tri[k]) side k-1.
                let (s1, s2) = (r.nb[k], r.nb[(k + 2) % 3]);
                let next = if s1 != prev { s1 } else { s2 };
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
    /// has grown by the candidate count and twice what was kept, so the copying costs O(1)
    /// per appended entry.
    fn compact_base_cert(&mut self) {
        debug_assert!(self.forward, "undo logs refer to arena offsets");
        let init = self.base_cert_init;
        let mut kept: Vec<u32> = Vec::new();
        for c in 0..self.cand.len() {
            let v = self.cand[c].verdict;
            if (v.cert as usize) < init || v.cert_len == 0 {
                continue;
            }
            let [a, b] = self.cand[c].pair;
            let v = &mut self.cand[c].verdict;
            if !self.alive[a as usize] || !self.alive[b as usize] {
                // Never read again before a reset restores the initial verdicts.
                (v.cert, v.cert_len) = (0, 0);
                continue;
            }
            let (off, len) = (v.cert as usize, v.cert_len as usize);
            v.cert = (init + kept.len()) as u32;
            kept.extend_from_slice(&self.base_cert[off..off + len]);
        }
        self.base_cert.truncate(init);
        self.base_cert.extend_from_slice(&kept);
        self.base_cert_compact_at = init + (2 * kept.len()).max(self.cand.len()).max(1024);
    }

    /// Logs a change of the base state for `undo`; forward mode undoes nothing and keeps
    /// no log.
    #[inline]
    fn base_log(&mut self, op: Op) {
        if !self.forward {
            self.log.push(op);
        }
    }

    /// Adds `(c, ver)` to the watch list of triangle `t` (logged). In forward mode, where
    /// nothing is undone, a list that doubled is first cleared of the entries of verdicts
    /// since recomputed (those past the initial state's, which a reset brings back).
    fn watch_push(&mut self, t: u32, c: u32, ver: u32) {
        let list = &mut self.watch[t as usize];
        if self.forward && list.len() >= 16 && list.len().is_power_of_two() {
            let keep = self.initial.as_ref().map_or(0, |i| i.watch_len[t as usize]) as usize;
            let cand = &self.cand;
            let mut w = keep;
            for r in keep..list.len() {
                let (c2, v2) = list[r];
                if cand[c2 as usize].cert_ver == v2 {
                    list[w] = (c2, v2);
                    w += 1;
                }
            }
            list.truncate(w);
        }
        list.push((c, ver));
        self.base_log(Op::Watch(t));
    }

    /// Moves triangle `t` from `P_old` to `P_new` (logged).
    fn set_count(&mut self, t: u32, new: u8) {
        let old = self.count[t as usize];
        if old == new {
            return;
        }
        self.move_count(t, old, new);
        self.base_log(Op::Count { t, old });
    }

    /// Sets the count of `t` from `old` to `new` and moves it between the sets.
    #[inline]
    fn move_count(&mut self, t: u32, old: u8, new: u8) {
        if old > 0 {
            self.sets.remove(old as usize, t);
        }
        if new > 0 {
            self.sets.insert(new as usize, t);
        }
        self.count[t as usize] = new;
    }

    fn set_verdict_dead(&mut self, c: u32) {
        let ci = c as usize;
        self.base_log(Op::Verdict {
            c,
            old: self.cand[ci].verdict,
            ver: self.cand[ci].cert_ver,
        });
        self.cand[ci].verdict.allowed = false;
    }

    /// Marks the verdict of `c` as possibly stale (logged).
    fn mark(&mut self, c: u32) {
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
            for c in self.tri[t as usize].cands {
                if c != NONE {
                    self.resolve(c);
                }
            }
        }
        self.count[t as usize] as u32
    }

    // ------------------------------------------------------------------------------------
    // Apply and undo.

    /// Recombines the two triangles of candidate `c` (both must remain; the criterion is
    /// not required, and stays exact after a forbidden action too).
    pub fn apply(&mut self, c: u32) {
        self.apply_lazy(c);
        self.resolve_all();
    }

    /// Like [`State::apply`], but the verdicts the action may have changed are only marked;
    /// the lazy queries (and `resolve_all`) recheck them when asked. For the trees.
    pub fn apply_lazy(&mut self, c: u32) {
        let ci = c as usize;
        let [t0, t1] = self.cand[ci].pair;
        assert!(
            self.is_live(c),
            "apply({c}): a triangle of the pair is already used"
        );
        // An exact verdict that found one part needs no new search; a split does (its
        // parts are relabelled).
        let v = self.cand[ci].verdict;
        let exact_before = self.dirty_list.is_empty();
        let r = if !self.cand[ci].dirty && v.allowed && !is_split(v.kind) {
            v
        } else {
            self.check(c)
        };
        let split = is_split(r.kind);
        self.last_local = if exact_before && r.kind == KIND_LOCAL {
            c
        } else {
            NONE
        };
        self.last_local_mask = r.mask;
        if self.forward {
            // Nothing will be undone: the log only serves the trees.
            self.log.clear();
        } else {
            self.log.push(Op::Apply(c));
        }
        self.changed.clear();
        if split {
            self.relabel_split(t0);
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
        self.quality.push(total);
        for x in [t0, t1] {
            self.set_count(x, 0);
            for c2 in self.tri[x as usize].cands {
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
        let qv = self.cand[ci].quad;
        for i in 1..4 {
            if let Some(child) = self.union(qv[0], qv[i]) {
                for j in 0..self.root_watch[child as usize].len() {
                    let (c2, ver) = self.root_watch[child as usize][j];
                    if self.cand[c2 as usize].cert_ver == ver && self.is_live(c2) {
                        self.mark(c2);
                    }
                }
            }
        }
        for i in 0..self.moved.len() {
            let v = self.moved[i] as usize;
            for j in self.vc_start[v]..self.vc_start[v + 1] {
                let c2 = self.vc_list[j as usize];
                if self.is_live(c2) {
                    self.mark(c2);
                }
            }
        }
        for x in [t0, t1] {
            // Marking touches no watch list: iterate the list taken out, then put it back.
            let list = std::mem::take(&mut self.watch[x as usize]);
            for &(c2, ver) in &list {
                if self.cand[c2 as usize].cert_ver == ver && self.is_live(c2) {
                    self.mark(c2);
                }
            }
            self.watch[x as usize] = list;
        }
        if !self.changed.is_empty() {
            for i in 0..self.split.len() {
                let c2 = self.split[i];
                if self.is_live(c2) {
                    let pc = self.polder[self.cand[c2 as usize].pair[0] as usize];
                    if self.changed.contains(&pc) {
                        self.mark(c2);
                    }
                }
            }
        }
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
                    let [t0, t1] = self.cand[c as usize].pair;
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
                    self.cand[c as usize].cert_ver = ver;
                }
                Op::Count { t, old } => {
                    let cur = self.count[t as usize];
                    self.move_count(t, cur, old);
                }
                Op::TreeApply(_)
                | Op::Polder { .. }
                | Op::PolderNew
                | Op::PolderSize { .. }
                | Op::Union { .. } => unreachable!("handled by undo_shared"),
                Op::Watch(t) => {
                    self.watch[t as usize].pop();
                }
                Op::SplitIns => {
                    let c = self.split.pop().expect("split entry");
                    self.split_pos[c as usize] = NONE;
                }
                Op::RootWatch(v) => {
                    self.root_watch[v as usize].pop();
                }
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

    /// Reverts every action applied.
    pub fn reset(&mut self) {
        assert!(self.tree.is_empty(), "reset inside a look-ahead tree");
        if self.forward {
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
                cert_ver: self.cand.iter().map(|l| l.cert_ver).collect(),
                count: self.count.clone(),
                sets: self.sets.clone(),
                polder: self.polder.clone(),
                polder_size: self.polder_size.clone(),
                dsu_parent: self.dsu_parent.clone(),
                dsu_size: self.dsu_size.clone(),
                split: self.split.clone(),
                split_pos: self.split_pos.clone(),
                watch_len: self.watch.iter().map(|w| w.len() as u32).collect(),
                root_watch_len: self.root_watch.iter().map(|w| w.len() as u32).collect(),
                ver: self.ver,
            }));
        }
        self.forward = on;
        self.log.clear();
    }

    /// Forward mode's reset: copies the initial state back.
    fn restore_initial(&mut self) {
        let init = self
            .initial
            .as_ref()
            .expect("forward mode keeps the initial state");
        for (c, (v, &ver)) in init.verdict.iter().zip(&init.cert_ver).enumerate() {
            self.cand[c].verdict = *v;
            self.cand[c].cert_ver = ver;
        }
        self.count.copy_from_slice(&init.count);
        self.sets.clone_from(&init.sets);
        self.polder.copy_from_slice(&init.polder);
        self.polder_size.clone_from(&init.polder_size);
        self.dsu_parent.copy_from_slice(&init.dsu_parent);
        self.dsu_size.copy_from_slice(&init.dsu_size);
        self.split.clone_from(&init.split);
        self.split_pos.copy_from_slice(&init.split_pos);
        for (w, &n) in self.watch.iter_mut().zip(&init.watch_len) {
            w.truncate(n as usize);
        }
        for (w, &n) in self.root_watch.iter_mut().zip(&init.root_watch_len) {
            w.truncate(n as usize);
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
    fn undo_shared(&mut self, op: Op) -> bool {
        match op {
            Op::Polder { t, old } => self.polder[t as usize] = old,
            Op::PolderNew => {
                self.polder_size.pop();
            }
            Op::PolderSize { p, old } => self.polder_size[p as usize] = old,
            Op::Union { child, root } => {
                self.dsu_parent[child as usize] = child;
                self.dsu_size[root as usize] -= self.dsu_size[child as usize];
            }
            _ => return false,
        }
        true
    }

    /// Checks the state's internal invariants (buckets, counts, polder sizes) and the
    /// verdicts against a from-scratch evaluation of the criterion. O(n) per candidate:
    /// for tests only.
    pub fn sanity_check(&self) -> Result<(), String> {
        if let Some(c) = (0..self.cand.len()).find(|&c| self.cand[c].dirty) {
            return Err(format!("candidate {c} still marked stale"));
        }
        let nt = self.alive.len();
        for t in 0..nt {
            let k = self.count[t];
            let expect = if self.alive[t] {
                self.table.by_triangle[t]
                    .iter()
                    .filter(|&&c| c != NONE && self.cand[c as usize].verdict.allowed)
                    .count() as u8
            } else {
                0
            };
            if k != expect {
                return Err(format!("triangle {t}: count {k}, allowed actions {expect}"));
            }
        }
        for k in 1..4u32 {
            let members = self.bucket(k);
            let expect: Vec<u32> = (0..nt as u32)
                .filter(|&t| self.count[t as usize] as u32 == k)
                .collect();
            if members != expect {
                return Err(format!("P_{k} holds {members:?}, counts say {expect:?}"));
            }
        }
        let naive = naive_allowed(self.mesh, self.table, &self.alive);
        for (c, &ok) in naive.iter().enumerate() {
            if ok != self.cand[c].verdict.allowed {
                return Err(format!(
                    "candidate {c}: allowed {} but the naive criterion says {ok}",
                    self.cand[c].verdict.allowed
                ));
            }
        }
        Ok(())
    }
}

/// The criterion evaluated from scratch for every candidate (a full search from each
/// neighbour of the pair, same rule: at most one odd part): the reference the fast state is
/// tested against. `alive[t]` says which triangles remain.
pub fn naive_allowed(mesh: &Mesh, table: &CandidateTable, alive: &[bool]) -> Vec<bool> {
    debug_assert_eq!(mesh.num_triangles(), alive.len());
    let nb = &table.dual_graph();
    let nt = alive.len();
    let mut stack = Vec::new();
    let mut mark = vec![0u32; nt];
    let mut epoch = 0;
    (0..table.len())
        .map(|c| {
            let [t0, t1] = table.pairs[c];
            if !alive[t0 as usize] || !alive[t1 as usize] {
                return false;
            }
            epoch += 1;
            mark[t0 as usize] = epoch;
            mark[t1 as usize] = epoch;
            let mut odd = 0;
            for &s in nb[t0 as usize].iter().chain(&nb[t1 as usize]) {
                if s == NONE || !alive[s as usize] || mark[s as usize] == epoch {
                    continue;
                }
                mark[s as usize] = epoch;
                stack.push(s);
                let mut size = 0u32;
                while let Some(x) = stack.pop() {
                    size += 1;
                    for &u in &nb[x as usize] {
                        if u != NONE && alive[u as usize] && mark[u as usize] != epoch {
                            mark[u as usize] = epoch;
                            stack.push(u);
                        }
                    }
                }
                odd += size & 1;
            }
            odd <= 1
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::MeshData;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// A jittered `n` x `n` grid of split squares with one square removed (a hole) and one
    /// extra lone triangle (an odd component).
    fn mesh(n: usize, seed: u64) -> Mesh {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut d = MeshData::default();
        for j in 0..=n {
            for i in 0..=n {
                let inner = i > 0 && j > 0 && i < n && j < n;
                let mut jit = || (rng.next_u64() as f64 / u64::MAX as f64 - 0.5) * 0.4;
                let (dx, dy) = if inner { (jit(), jit()) } else { (0.0, 0.0) };
                d.vertices.push([i as f64 + dx, j as f64 + dy, 0.0]);
            }
        }
        let v = |i: usize, j: usize| (j * (n + 1) + i) as u32;
        for j in 0..n {
            for i in 0..n {
                if (i, j) == (n / 2, n / 2) {
                    continue;
                }
                if (i + j) % 3 == 0 {
                    d.triangles.push([v(i, j), v(i + 1, j), v(i + 1, j + 1)]);
                    d.triangles.push([v(i, j), v(i + 1, j + 1), v(i, j + 1)]);
                } else {
                    d.triangles.push([v(i, j), v(i + 1, j), v(i, j + 1)]);
                    d.triangles
                        .push([v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)]);
                }
            }
        }
        let b = d.vertices.len() as u32;
        d.vertices
            .extend([[-3.0, 0.0, 0.0], [-2.0, 0.0, 0.0], [-3.0, 1.0, 0.0]]);
        d.triangles.push([b, b + 1, b + 2]);
        Mesh::new(d).unwrap()
    }

    /// Lazy applies (as the trees do) with lazy queries must agree with the naive criterion
    /// once resolved, and undo must restore the exact earlier state.
    #[test]
    fn lazy_walks_resolve_to_the_naive_criterion() {
        for seed in 0..4 {
            let m = mesh(7, seed);
            let table = CandidateTable::build(&m);
            let mut st = State::new(&m, &table);
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            for _ in 0..3 {
                loop {
                    // Lazy queries agree with the naive criterion on what they read.
                    let naive = naive_allowed(&m, &table, &st.alive);
                    let c = (rng.next_u64() % table.len() as u64) as u32;
                    assert_eq!(st.is_allowed_lazy(c), naive[c as usize], "candidate {c}");
                    let t = table.pairs[c as usize][0];
                    let k = table.by_triangle[t as usize]
                        .iter()
                        .filter(|&&x| x != NONE && naive[x as usize])
                        .count() as u32;
                    let k = if st.is_remaining(t) { k } else { 0 };
                    assert_eq!(st.allowed_count_lazy(t), k);
                    let allowed: Vec<u32> = (0..table.len() as u32)
                        .filter(|&x| naive[x as usize])
                        .collect();
                    if allowed.is_empty() {
                        break;
                    }
                    if st.depth() > 0 && rng.next_u64() % 4 == 0 {
                        st.undo();
                    } else {
                        let a = allowed[(rng.next_u64() % allowed.len() as u64) as usize];
                        st.apply_lazy(a);
                    }
                    if rng.next_u64() % 3 == 0 {
                        st.resolve_all();
                        st.sanity_check().unwrap();
                    }
                }
                st.reset();
                st.sanity_check().unwrap();
            }
        }
    }
}
