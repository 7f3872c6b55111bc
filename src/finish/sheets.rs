//! All-quad's fallback: sheet refinement, for the components no single boundary split makes
//! perfectly matchable. Every leftover triangle becomes 3 quads (new nodes at the midpoints of
//! its sides and at its centroid); the midpoint on a side shared with a quad (a pair) is
//! matched on the quad's opposite side, the quad split in two by the segment joining the two
//! midpoints, and the sheet goes on across that opposite side, quad after quad, until it
//! reaches a mesh boundary side (the node lies on the chord) or a side of another leftover. A
//! quad crossed by two sheets becomes 4 quads around the crossing of its two midlines (their
//! common midpoint, the mean of the four midpoints). Sides between surfaces are crossed like
//! any inner side, so the result conforms; where three or more elements share a side
//! (surfaces meeting), the sheet goes on across each of them. Each new quad is written as
//! two triangles (the shorter diagonal) paired, so the result is a triangle mesh and a perfect
//! pairing: the existing model. A sheet through sides of two elements is deterministic and
//! reversible; one that branches where surfaces meet can come back to a side it gave a
//! midpoint, which is not crossed again, so every side is crossed at most once.

use super::region::Pairing;
use crate::mesh::{Mesh, MeshData, MeshError, NONE};
use crate::quality::{CandidateTable, Rule, quad_eta};
use std::collections::hash_map::Entry;
use std::collections::{HashMap, HashSet};

/// What sheet refinement changed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SheetStats {
    /// Sheets traced (each from a leftover's side to a boundary side or another leftover).
    pub sheets: usize,
    /// Nodes added (midpoints, centroids of leftovers, centres of quads crossed twice).
    pub nodes: usize,
    /// Triangles of the mesh replaced (the leftovers and the two of each quad crossed).
    pub triangles_replaced: usize,
    /// Triangles added to the mesh (each new quad is two triangles).
    pub triangles_added: usize,
}

/// Why sheet refinement cannot make the mesh all-quad.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SheetError {
    /// A sheet reaches a side it cannot cross conformingly.
    #[error(
        "all-quad sheet refinement: a sheet reaches side {}-{} of element {element} (surface {surface}), which {why}",
        side[0], side[1]
    )]
    Blocked {
        element: u64,
        surface: i32,
        side: [u64; 2],
        why: &'static str,
    },
    /// A new quad is not a pair the rule allows (a degenerate or near-degenerate element).
    #[error(
        "all-quad sheet refinement: the new quad of nodes {nodes:?} made from element {element} (surface {surface}) has eta {eta}, which the rule does not allow (element {element} is degenerate or nearly so, or --min-eta is above what halving the quads a sheet crosses keeps)"
    )]
    InvalidQuad {
        element: u64,
        surface: i32,
        nodes: [u64; 4],
        eta: f64,
    },
    /// The refined mesh is invalid (a bug).
    #[error("all-quad sheet refinement made an invalid mesh: {0}")]
    Mesh(#[from] MeshError),
}

/// The result of [`refine`].
pub(crate) struct SheetMesh {
    pub mesh: Mesh,
    pub table: CandidateTable,
    pub pairing: Pairing,
    pub stats: SheetStats,
}

fn key(a: u32, b: u32) -> [u32; 2] {
    [a.min(b), a.max(b)]
}

/// The side index of triangle `tri` joining `a` and `b`.
fn side_of(tri: [u32; 3], a: u32, b: u32) -> Option<usize> {
    (0..3).find(|&j| key(tri[j], tri[(j + 1) % 3]) == key(a, b))
}

/// Refines every leftover of `pairing` (a matching of `table`, `mesh`'s candidates) by
/// sheets: the new mesh, its table under `rule` (eta of the pairs no sheet touched kept from
/// `table`) and a perfect pairing of it.
pub(crate) fn refine(
    mesh: &Mesh,
    table: &CandidateTable,
    pairing: &Pairing,
    rule: Rule,
) -> Result<SheetMesh, SheetError> {
    let nt = mesh.num_triangles();
    let topo = mesh.edges();
    let leftovers: Vec<u32> = pairing.leftovers().collect();
    let mut is_left = vec![false; nt];
    for &t in &leftovers {
        is_left[t as usize] = true;
    }
    // Triangles on each edge, over all surfaces (the dual graph stops at interfaces).
    let mut on_edge: Vec<Vec<u32>> = vec![Vec::new(); topo.edges.len()];
    for (t, edges) in topo.triangle_edges.iter().enumerate() {
        for &e in edges {
            on_edge[e as usize].push(t as u32);
        }
    }
    let mut is_boundary = vec![false; topo.edges.len()];
    for &e in &topo.boundary_edges {
        is_boundary[e as usize] = true;
    }
    let blocked = |t: u32, a: u32, b: u32, why| SheetError::Blocked {
        element: mesh.triangle_ids[t as usize],
        surface: mesh.triangle_surface[t as usize],
        side: [mesh.vertex_ids[a as usize], mesh.vertex_ids[b as usize]],
        why,
    };

    let mut stats = SheetStats::default();
    // Sides with a midpoint, in the order traced, with the surface of the element traced from
    // and whether a curve must lie on the side (see `split_model_edge`).
    let mut mids: HashMap<[u32; 2], u32> = HashMap::new();
    let mut mid_order: Vec<([u32; 2], i32, bool)> = Vec::new();
    let curve_side = |e: usize| match on_edge[e][..] {
        [x, y] => mesh.triangle_surface[x as usize] != mesh.triangle_surface[y as usize],
        _ => true,
    };
    let first_vertex = mesh.vertices.len() as u32;
    let mut cut = vec![false; table.len()];
    let mut side_done = vec![[false; 3]; nt];
    // Sides of input quads: a sheet cannot cross them (the quad is never split).
    let quad_sides: HashSet<[u32; 2]> = mesh
        .quads
        .iter()
        .flat_map(|q| (0..4).map(move |i| key(q[i], q[(i + 1) % 4])))
        .collect();
    // The sides still to trace across, each with the element the sheet reaches it from.
    let mut todo: Vec<(u32, u32, u32)> = Vec::new();
    let mut steps = 0usize;
    for &t in &leftovers {
        for j in 0..3 {
            if side_done[t as usize][j] {
                continue;
            }
            side_done[t as usize][j] = true;
            stats.sheets += 1;
            let tri = mesh.triangles[t as usize];
            todo.push((t, tri[j], tri[(j + 1) % 3]));
            let mut first = true;
            while let Some((cur, a, b)) = todo.pop() {
                match mids.entry(key(a, b)) {
                    Entry::Vacant(v) => {
                        v.insert(first_vertex + mid_order.len() as u32);
                        let s = side_of(mesh.triangles[cur as usize], a, b)
                            .expect("the sheet's side is a side of its triangle");
                        let e = topo.triangle_edges[cur as usize][s] as usize;
                        mid_order.push((
                            key(a, b),
                            mesh.triangle_surface[cur as usize],
                            curve_side(e),
                        ));
                    }
                    // Reached again (a sheet through a side shared by three or more
                    // elements can come back to it): whoever gave it its midpoint went on
                    // across every element on it.
                    Entry::Occupied(_) if !first => continue,
                    Entry::Occupied(_) => {}
                }
                first = false;
                if quad_sides.contains(&key(a, b)) {
                    return Err(blocked(
                        cur,
                        a,
                        b,
                        "is shared with an input quad (sheets do not split input quads; \
                         --finish without --all-quad finishes it, leaving triangles)",
                    ));
                }
                let ct = mesh.triangles[cur as usize];
                let s = side_of(ct, a, b).expect("the sheet's side is a side of its triangle");
                let e = topo.triangle_edges[cur as usize][s] as usize;
                // Every other triangle on the side (of this surface or another): two or more
                // where surfaces meet, and the sheet goes on across each.
                let others = on_edge[e].iter().copied().filter(|&u| u != cur);
                for x in others {
                    if is_left[x as usize] {
                        let sx = side_of(mesh.triangles[x as usize], a, b)
                            .expect("a neighbour shares the side");
                        side_done[x as usize][sx] = true;
                        continue;
                    }
                    let c = pairing.cand[x as usize];
                    let y = table.other(c, x);
                    let q = table.quads[c as usize];
                    let i = (0..4)
                        .find(|&i| key(q[i], q[(i + 1) % 4]) == key(a, b))
                        .ok_or_else(|| {
                            blocked(
                                cur,
                                a,
                                b,
                                "is the diagonal of a quad (the mesh is not a manifold there)",
                            )
                        })?;
                    cut[c as usize] = true;
                    let (na, nb) = (q[(i + 2) % 4], q[(i + 3) % 4]);
                    let next = if side_of(mesh.triangles[x as usize], na, nb).is_some() {
                        x
                    } else {
                        y
                    };
                    todo.push((next, na, nb));
                    steps += 1;
                    assert!(
                        steps <= 3 * nt + 1,
                        "sheets cross each quad side at most once"
                    );
                }
            }
        }
    }

    let mut data = super::all_quad::editable_copy(mesh);
    let first_node = mesh.vertex_ids.iter().max().copied().unwrap_or(0) + 1;
    let mut next_node = first_node;
    let at = |data: &MeshData, v: u32| data.vertices[v as usize];
    let mean = |ps: &[[f64; 3]]| -> [f64; 3] {
        std::array::from_fn(|d| ps.iter().map(|p| p[d]).sum::<f64>() / ps.len() as f64)
    };
    for &([a, b], surface, edge) in &mid_order {
        let p = mean(&[at(&data, a), at(&data, b)]);
        let m = add_node(&mut data, &mut next_node, p);
        if let Some(model) = data.model.as_deref_mut() {
            super::all_quad::split_model_edge(model, [a, b], m, surface, edge);
        }
    }
    let mid = |a: u32, b: u32| mids[&key(a, b)];
    // The new quads of each replaced element group, with the triangles they replace.
    let mut groups: Vec<(Vec<u32>, Vec<[u32; 4]>)> = Vec::new();
    for &t in &leftovers {
        let v = mesh.triangles[t as usize];
        let surface = mesh.triangle_surface[t as usize];
        let p = mean(&v.map(|u| mesh.vertices[u as usize]));
        let g = add_inner_node(&mut data, &mut next_node, p, surface);
        let m = [mid(v[0], v[1]), mid(v[1], v[2]), mid(v[2], v[0])];
        let quads = (0..3).map(|i| [v[i], m[i], g, m[(i + 2) % 3]]).collect();
        groups.push((vec![t], quads));
    }
    for c in (0..table.len()).filter(|&c| cut[c]) {
        let [ta, tb] = table.pairs[c];
        let surface = mesh.triangle_surface[ta as usize];
        let mut q = table.quads[c];
        // Orient the quad as triangle `ta`: one of its sides runs forward in the cycle.
        let tri = mesh.triangles[ta as usize];
        let forward =
            (0..4).any(|i| (0..3).any(|j| q[i] == tri[j] && q[(i + 1) % 4] == tri[(j + 1) % 3]));
        if !forward {
            q = [q[0], q[3], q[2], q[1]];
        }
        let has = |i: usize| mids.contains_key(&key(q[i], q[(i + 1) % 4]));
        let m: [u32; 4] = std::array::from_fn(|i| {
            if has(i) {
                mid(q[i], q[(i + 1) % 4])
            } else {
                NONE
            }
        });
        let quads = match (has(0), has(1)) {
            (true, false) => vec![[q[0], m[0], m[2], q[3]], [m[0], q[1], q[2], m[2]]],
            (false, true) => vec![[q[0], q[1], m[1], m[3]], [m[3], m[1], q[2], q[3]]],
            (true, true) => {
                let p = mean(&m.map(|u| at(&data, u)));
                let g = add_inner_node(&mut data, &mut next_node, p, surface);
                vec![
                    [q[0], m[0], g, m[3]],
                    [m[0], q[1], m[1], g],
                    [g, m[1], q[2], m[2]],
                    [m[3], g, m[2], q[3]],
                ]
            }
            (false, false) => unreachable!("a quad crossed has a midpoint on a side"),
        };
        groups.push((vec![ta, tb], quads));
    }
    stats.nodes = data.vertices.len() - mesh.vertices.len();

    let first_element = super::all_quad::first_free_element_tag(mesh);
    let mut next_element = first_element;
    let mut replaced = vec![false; nt];
    // The two triangles of each new quad, to pair them.
    let mut new_pairs: Vec<([u32; 2], [u32; 4], u32)> = Vec::new();
    for (slots, quads) in &groups {
        let surface = mesh.triangle_surface[slots[0] as usize];
        let mut free = slots.iter().copied();
        for &quad in quads {
            let p = quad.map(|v| at(&data, v));
            let d2 =
                |i: usize, j: usize| -> f64 { (0..3).map(|d| (p[i][d] - p[j][d]).powi(2)).sum() };
            let [t1, t2] = if d2(0, 2) <= d2(1, 3) {
                [[quad[0], quad[1], quad[2]], [quad[0], quad[2], quad[3]]]
            } else {
                [[quad[1], quad[2], quad[3]], [quad[1], quad[3], quad[0]]]
            };
            let mut ids = [0u32; 2];
            for (k, tri) in [t1, t2].into_iter().enumerate() {
                ids[k] = match free.next() {
                    Some(s) => {
                        replaced[s as usize] = true;
                        data.triangles[s as usize] = tri;
                        s
                    }
                    None => {
                        data.triangles.push(tri);
                        data.triangle_ids.push(next_element);
                        next_element += 1;
                        data.triangle_surface.push(surface);
                        (data.triangles.len() - 1) as u32
                    }
                };
            }
            new_pairs.push((ids, quad, slots[0]));
        }
    }
    stats.triangles_replaced = replaced.iter().filter(|&&r| r).count();
    stats.triangles_added = data.triangles.len() - nt;
    let new_mesh = Mesh::new(data)?;

    // Old candidate of each pair of old triangles, to carry eta and the rule's verdict over.
    let find = |t: &CandidateTable, a: u32, b: u32| {
        t.by_triangle[a as usize]
            .into_iter()
            .find(|&f| f != NONE && t.other(f, a) == b)
    };
    let mut new_table = CandidateTable::topology_only(&new_mesh);
    let mut keep = vec![false; new_table.len()];
    for (c, kept) in keep.iter_mut().enumerate() {
        let [a, b] = new_table.pairs[c];
        let touched =
            a as usize >= nt || b as usize >= nt || replaced[a as usize] || replaced[b as usize];
        if !touched {
            if let Some(old) = find(table, a, b) {
                *kept = true;
                new_table.eta[c] = table.eta[old as usize];
            }
            continue;
        }
        let p = new_table.quads[c].map(|v| new_mesh.vertices[v as usize]);
        let eta = quad_eta(p);
        new_table.eta[c] = eta;
        *kept = rule.allows_pair(eta, p);
    }
    let new_table = new_table.retain(&keep);
    let mut chosen: Vec<u32> = Vec::new();
    for (t, &c) in pairing.cand.iter().enumerate() {
        if c == NONE || table.pairs[c as usize][0] != t as u32 || cut[c as usize] {
            continue;
        }
        let [a, b] = table.pairs[c as usize];
        chosen.push(find(&new_table, a, b).expect("an untouched pair stays a candidate"));
    }
    for ([a, b], quad, from) in new_pairs {
        match find(&new_table, a, b) {
            Some(c) => chosen.push(c),
            None => {
                return Err(SheetError::InvalidQuad {
                    element: mesh.triangle_ids[from as usize],
                    surface: mesh.triangle_surface[from as usize],
                    nodes: quad.map(|v| new_mesh.vertex_ids[v as usize]),
                    eta: quad_eta(quad.map(|v| new_mesh.vertices[v as usize])),
                });
            }
        }
    }
    let new_pairing = Pairing::new(new_mesh.num_triangles(), &new_table, &chosen);
    Ok(SheetMesh {
        mesh: new_mesh,
        table: new_table,
        pairing: new_pairing,
        stats,
    })
}

/// Appends a node at `p` with the next tag: its vertex index.
fn add_node(data: &mut MeshData, next_node: &mut u64, p: [f64; 3]) -> u32 {
    let v = data.vertices.len() as u32;
    data.vertices.push(p);
    data.vertex_ids.push(*next_node);
    *next_node += 1;
    v
}

/// [`add_node`], classified on surface `surface` in the model (a node inside an element).
fn add_inner_node(data: &mut MeshData, next_node: &mut u64, p: [f64; 3], surface: i32) -> u32 {
    let v = add_node(data, next_node, p);
    if let Some(model) = data.model.as_deref_mut() {
        if !model.node_entity.is_empty() {
            model.node_entity.push(Some((2, surface)));
        }
        if !model.node_param.is_empty() {
            model.node_param.push(None);
        }
    }
    v
}
