//! Building the state: the per-candidate records and the dense dual graph laid out for the
//! criterion, the buckets, polders and `P_k` sets, and every initial verdict with its
//! certificate ([`State::new`]).

use super::pk::OrderedSets;
use super::tree::Overlay;
use super::{ACTIVE, CandRecord, ROOT_TAG, State, Verdict, WatchLists, parity};
use crate::mesh::{Mesh, NONE};
use crate::quality::CandidateTable;

impl<'a> State<'a> {
    /// The initial state of `mesh` (every triangle remaining) with every verdict computed.
    ///
    /// # Panics
    /// When `table` was not built for `mesh` ([`CandidateTable::assert_fits`]).
    pub fn new(mesh: &'a Mesh, table: &'a CandidateTable) -> State<'a> {
        table.assert_fits(mesh);
        let nt = mesh.num_triangles();
        let nv = mesh.vertices.len();
        let m = table.len();
        // Certificates tag dead-component roots with the top bit (`ROOT_TAG`).
        assert!(
            nt < ROOT_TAG as usize && nv < ROOT_TAG as usize,
            "mesh too large for the search state ({nt} triangles, {nv} vertices)"
        );
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
        // Edge weights for telling a part's parity without enumerating it, on the meshes
        // the argument covers; the triangles of odd initial polders do not count.
        let even = |t: u32| polder_size[polder[t as usize] as usize] % 2 == 0;
        let weights = parity::edge_weights(mesh, &vt_count, &vt_first, even);
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
        // The build's scratch goes before the initial verdicts, which set the state's peak
        // (on corridors, where the state is all there is).
        drop((vt_count, vt_first, has_quad));
        let cand: Vec<CandRecord> = (0..m)
            .map(|c| {
                let (quad, nb) = (table.quads[c], cand_nb[c]);
                let mut l = CandRecord {
                    nb,
                    verdict: Verdict::default(),
                    flags: 0,
                    shared: false,
                    par: 0,
                    dirty: false,
                };
                if let Some(w) = &weights {
                    // Side i of the quad joins its vertices i and i + 1: sides 0 and 1 are
                    // `t1`'s, 2 and 3 `t0`'s (as for `cand_nb` above).
                    let [t0, t1] = table.pairs[c];
                    for i in 0..4 {
                        let t = if i < 2 { t1 } else { t0 } as usize;
                        let (a, b) = (quad[i], quad[(i + 1) % 4]);
                        l.par |= parity::weight_of(mesh.triangles[t], w[t], a, b) << i;
                    }
                    if even(t0) {
                        l.par |= ACTIVE;
                    }
                }
                for i in 0..4 {
                    if closed[quad[i] as usize] {
                        l.flags |= 1 << i;
                    }
                    l.shared |= nb[i] != NONE && (0..i).any(|j| nb[j] == nb[i]);
                }
                l
            })
            .collect();
        drop(cand_nb);
        let mut st = State {
            mesh,
            table,
            closed,
            cert_ver: vec![0; m],
            cand,
            dual,
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
            watch: WatchLists::new(nt, nv),
            dsu_parent: (0..nv as u32).collect(),
            dsu_size: vec![1; nv],
            dsu_par: vec![0; nv],
            odd_active: 0,
            need_parts: false,
            arc_roots: [NONE; 4],
            narcs: 0,
            split: Vec::new(),
            split_pos: vec![NONE; m],
            split_compact_at: 0,
            dirty_list: Vec::new(),
            chosen: Vec::new(),
            quality: vec![0.0],
            log: Vec::new(),
            tree: Overlay::new(m, nv, nt),
            forward: false,
            initial: None,
            building: true,
            last_local: NONE,
            last_local_mask: 0,
            audit: None,
            stamp: vec![0; nt],
            epoch: 0,
            queue: Default::default(),
            head: [0; 4],
            nseed: [0; 4],
            cert_len: [0; 4],
            finished: [false; 4],
            path_bfs: Vec::new(),
            path: Vec::new(),
            group: [0; 4],
            nsearch: 0,
            changed: Vec::new(),
            moved: Vec::new(),
            fan: Vec::new(),
            at_vertex: Vec::new(),
            shrunk: Vec::new(),
            y_roots: Vec::new(),
            attached: Vec::new(),
            searches: 0,
            searched: 0,
            parity_splits: 0,
            parity_multi: [0; 2],
            split_shrinks: 0,
            distinct_kept: 0,
            distinct_rekept: 0,
        };
        // The removed region at the start: boundary edges (mesh, surface and quad
        // boundaries: dual sides without a neighbour) and input quads.
        for (t, tri) in mesh.triangles.iter().enumerate() {
            let w = weights.as_ref().map_or(0, |w| w[t]);
            for i in 0..3 {
                if st.dual[t][i] == NONE {
                    st.union(tri[i], tri[(i + 1) % 3], (w >> i) & 1, false);
                }
            }
        }
        drop(weights);
        for q in &mesh.quads {
            for i in 1..4 {
                st.union(q[0], q[i], 0, false);
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
        // The initial verdicts are the base state: nothing to undo before it (their changes,
        // the boundary's unions included, were not logged).
        st.building = false;
        debug_assert!(st.log.is_empty());
        st.base_cert_init = st.base_cert.len();
        st.set_cert_compact_at(st.base_cert_init + 2 * m);
        st
    }
}
