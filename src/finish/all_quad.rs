//! All-quad: a leftover that recombination alone must keep (one per odd component) is moved
//! along an alternating path to a triangle with a side on the mesh boundary, and that side is
//! split at its midpoint by a new node: the triangle becomes two, the component even, and
//! leftover elimination can pair them with their neighbours. The node lies on the chord (the
//! straight side): no boundary-curve geometry is read from the input.

use super::region::Pairing;
use crate::mesh::{Mesh, MeshData, MeshError, NONE};
use crate::quality::{CandidateTable, Rule, quad_eta};

/// One boundary side split.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Split {
    /// The triangle split (its index in both meshes; the new half is appended).
    pub triangle: u32,
    /// The node tags of the side's ends.
    pub side: [u64; 2],
    /// The new node's tag.
    pub node: u64,
    /// Triangles moved along the alternating path (0: the leftover itself was on the
    /// boundary).
    pub path_len: usize,
}

/// The boundary side of `t` to split, if it has one that works: a side used by no other
/// element (sides next to another surface or an input quad are no boundary) whose halves
/// would each make a quad `rule` allows with the triangle across their other inner side;
/// the longest such side.
fn boundary_side(mesh: &Mesh, is_boundary: &[bool], rule: Rule, t: u32) -> Option<usize> {
    let tri = mesh.triangles[t as usize];
    let at = |v: u32| mesh.vertices[v as usize];
    // The vertex of the triangle across side `j` of `t` opposite that side.
    let across = |j: usize| -> Option<u32> {
        let u = mesh.topology.neighbours[t as usize][j];
        if u == NONE {
            return None;
        }
        let (a, b) = (tri[j], tri[(j + 1) % 3]);
        mesh.triangles[u as usize]
            .into_iter()
            .find(|&v| v != a && v != b)
    };
    let len = |k: usize| {
        let (a, b) = (at(tri[k]), at(tri[(k + 1) % 3]));
        (0..3).map(|d| (a[d] - b[d]).powi(2)).sum::<f64>()
    };
    (0..3)
        .filter(|&i| {
            mesh.topology.neighbours[t as usize][i] == NONE
                && is_boundary[mesh.topology.triangle_edges[t as usize][i] as usize]
        })
        .filter(|&i| {
            let (p, q, s) = (tri[i], tri[(i + 1) % 3], tri[(i + 2) % 3]);
            let (pp, pq) = (at(p), at(q));
            let m: [f64; 3] = std::array::from_fn(|d| 0.5 * (pp[d] + pq[d]));
            let (Some(o_qs), Some(o_sp)) = (across((i + 1) % 3), across((i + 2) % 3)) else {
                return false;
            };
            // Half (p, m, s) with the triangle across s-p; half (m, q, s) across q-s.
            let first = quad_eta([at(s), at(o_sp), pp, m]);
            let second = quad_eta([pq, at(o_qs), at(s), m]);
            rule.allows(first) && rule.allows(second)
        })
        .max_by(|&i, &j| len(i).total_cmp(&len(j)))
}

/// Moves the leftover `t` to the nearest triangle (in alternating steps) with a boundary side
/// not yet taken, flipping the pairs on the way. Returns that triangle and the path length.
fn move_to_boundary(
    mesh: &Mesh,
    table: &CandidateTable,
    pairing: &mut Pairing,
    is_boundary: &[bool],
    taken: &[bool],
    rule: Rule,
    t: u32,
) -> Option<(u32, usize, usize)> {
    use std::collections::HashMap;
    // parent[even] = (previous even triangle, candidate from it to the odd one).
    let mut parent: HashMap<u32, (u32, u32)> = HashMap::new();
    let mut seen: std::collections::HashSet<u32> = std::collections::HashSet::new();
    let mut queue = std::collections::VecDeque::from([t]);
    seen.insert(t);
    let mut target = None;
    while let Some(x) = queue.pop_front() {
        if !taken[x as usize]
            && let Some(side) = boundary_side(mesh, is_boundary, rule, x)
        {
            target = Some((x, side));
            break;
        }
        for c in table.by_triangle[x as usize] {
            if c == NONE {
                continue;
            }
            let u = table.other(c, x);
            let mu = pairing.mate(table, u);
            if mu == NONE || seen.contains(&u) || seen.contains(&mu) {
                continue;
            }
            seen.insert(u);
            seen.insert(mu);
            parent.insert(mu, (x, c));
            queue.push_back(mu);
        }
    }
    let Some((b, side)) = target else {
        return nearest_boundary(mesh, table, pairing, is_boundary, taken, rule, t);
    };
    let mut path = Vec::new();
    let mut cur = b;
    while cur != t {
        let (x, c) = parent[&cur];
        path.push((x, c));
        cur = x;
    }
    pairing.cand[b as usize] = NONE;
    for &(x, c) in &path {
        let u = table.other(c, x);
        pairing.cand[x as usize] = c;
        pairing.cand[u as usize] = c;
    }
    Some((b, side, path.len()))
}

/// When no alternating path (found without shrinking blossoms) reaches a boundary side that
/// works: the nearest triangle of the component with one, through any pairs; it and its mate
/// are unpaired, and elimination then re-pairs the leftover, them and the halves exactly
/// (through blossoms too).
fn nearest_boundary(
    mesh: &Mesh,
    table: &CandidateTable,
    pairing: &mut Pairing,
    is_boundary: &[bool],
    taken: &[bool],
    rule: Rule,
    t: u32,
) -> Option<(u32, usize, usize)> {
    let mut dist = std::collections::HashMap::from([(t, 0usize)]);
    let mut queue = std::collections::VecDeque::from([t]);
    while let Some(x) = queue.pop_front() {
        if !taken[x as usize]
            && let Some(side) = boundary_side(mesh, is_boundary, rule, x)
        {
            let m = pairing.mate(table, x);
            pairing.cand[x as usize] = NONE;
            if m != NONE {
                pairing.cand[m as usize] = NONE;
            }
            return Some((x, side, dist[&x]));
        }
        let d = dist[&x];
        for c in table.by_triangle[x as usize] {
            if c != NONE {
                let u = table.other(c, x);
                if let std::collections::hash_map::Entry::Vacant(e) = dist.entry(u) {
                    e.insert(d + 1);
                    queue.push_back(u);
                }
            }
        }
    }
    None
}

/// The result of [`split_leftovers`].
pub(crate) struct SplitMesh {
    pub mesh: Mesh,
    pub table: CandidateTable,
    pub pairing: Pairing,
    pub splits: Vec<Split>,
}

/// Moves each of `leftovers` to the boundary and splits a boundary side of the triangle it
/// lands on; the new mesh, its table under `rule` (eta of the pairs that did not change kept
/// from `table`, new pairs in f64; the two halves of a split are never a pair: their quad has
/// a straight angle) and the pairing carried over. `None` when no leftover reaches a boundary.
/// Triangles marked in `excluded` are not split.
pub(crate) fn split_leftovers(
    mesh: &Mesh,
    table: &CandidateTable,
    pairing: &mut Pairing,
    leftovers: &[u32],
    rule: Rule,
    excluded: &[bool],
) -> Result<Option<SplitMesh>, MeshError> {
    let mut is_boundary = vec![false; mesh.topology.edges.len()];
    for &e in &mesh.topology.boundary_edges {
        is_boundary[e as usize] = true;
    }
    let nt = mesh.num_triangles();
    let mut taken = excluded.to_vec();
    let mut data = MeshData {
        vertices: mesh.vertices.clone(),
        vertex_ids: mesh.vertex_ids.clone(),
        triangles: mesh.triangles.clone(),
        triangle_ids: mesh.triangle_ids.clone(),
        triangle_surface: mesh.triangle_surface.clone(),
        quads: mesh.quads.clone(),
        quad_ids: Vec::new(),
        quad_surface: mesh.quad_surface.clone(),
        model: mesh.model.clone(),
    };
    let mut next_node = mesh.vertex_ids.iter().max().copied().unwrap_or(0) + 1;
    let mut next_element = mesh.triangle_ids.iter().max().copied().unwrap_or(0) + 1;
    let mut splits = Vec::new();
    for &t in leftovers {
        if pairing.cand[t as usize] != NONE {
            continue;
        }
        let Some((b, side, path_len)) =
            move_to_boundary(mesh, table, pairing, &is_boundary, &taken, rule, t)
        else {
            continue;
        };
        taken[b as usize] = true;
        let tri = mesh.triangles[b as usize];
        let (p, q, s) = (tri[side], tri[(side + 1) % 3], tri[(side + 2) % 3]);
        let (pp, pq) = (mesh.vertices[p as usize], mesh.vertices[q as usize]);
        let m = data.vertices.len() as u32;
        data.vertices
            .push(std::array::from_fn(|d| 0.5 * (pp[d] + pq[d])));
        data.vertex_ids.push(next_node);
        let mut new_tri = [0u32; 3];
        new_tri[side] = p;
        new_tri[(side + 1) % 3] = m;
        new_tri[(side + 2) % 3] = s;
        data.triangles[b as usize] = new_tri;
        data.triangles.push([m, q, s]);
        data.triangle_ids.push(next_element);
        data.triangle_surface
            .push(mesh.triangle_surface[b as usize]);
        if let Some(model) = data.model.as_deref_mut() {
            split_model_edge(model, p, q, m, mesh.triangle_surface[b as usize]);
        }
        splits.push(Split {
            triangle: b,
            side: [mesh.vertex_ids[p as usize], mesh.vertex_ids[q as usize]],
            node: next_node,
            path_len,
        });
        next_node += 1;
        next_element += 1;
    }
    if splits.is_empty() {
        return Ok(None);
    }
    let new_mesh = Mesh::new(data)?;
    // Old candidate of each pair of old triangles, to carry eta and the rule's verdict over.
    let full = CandidateTable::topology_only(mesh);
    let mut old_of_full = vec![NONE; full.len()];
    for c in 0..table.len() {
        let [a, b] = table.pairs[c];
        let i = full.by_triangle[a as usize]
            .into_iter()
            .find(|&f| f != NONE && full.other(f, a) == b)
            .expect("a candidate is a pair of neighbours");
        old_of_full[i as usize] = c as u32;
    }
    let split_set: std::collections::HashSet<u32> = splits.iter().map(|s| s.triangle).collect();
    let mut new_table = CandidateTable::topology_only(&new_mesh);
    let mut keep = vec![false; new_table.len()];
    for (c, kept) in keep.iter_mut().enumerate() {
        let [a, b] = new_table.pairs[c];
        let touched = b as usize >= nt || split_set.contains(&a) || split_set.contains(&b);
        if !touched {
            let f = full.by_triangle[a as usize]
                .into_iter()
                .find(|&f| f != NONE && full.other(f, a) == b)
                .expect("old triangles keep their neighbours");
            let old = old_of_full[f as usize];
            if old != NONE {
                *kept = true;
                new_table.eta[c] = table.eta[old as usize];
            }
            continue;
        }
        let eta = quad_eta(new_table.quads[c].map(|v| new_mesh.vertices[v as usize]));
        new_table.eta[c] = eta;
        // The two halves of one split make a quad with a straight angle: never a pair.
        let halves = b as usize >= nt && split_set.contains(&a) && {
            let k = b as usize - nt;
            splits[k].triangle == a
        };
        *kept = rule.allows(eta) && !halves;
    }
    let new_table = new_table.retain(&keep);
    let mut chosen = Vec::new();
    for (t, &c) in pairing.cand.iter().enumerate() {
        if c == NONE || table.pairs[c as usize][0] != t as u32 {
            continue;
        }
        let [a, b] = table.pairs[c as usize];
        let nc = new_table.by_triangle[a as usize]
            .into_iter()
            .find(|&n| n != NONE && new_table.other(n, a) == b)
            .expect("an unsplit pair stays a candidate");
        chosen.push(nc);
    }
    let new_pairing = Pairing::new(new_mesh.num_triangles(), &new_table, &chosen);
    Ok(Some(SplitMesh {
        mesh: new_mesh,
        table: new_table,
        pairing: new_pairing,
        splits,
    }))
}

/// Splits the model's line element on side `p`-`q` (if any) at the new node `m`, and
/// classifies `m` on that curve, or on surface `surface` when no line element lies there.
fn split_model_edge(model: &mut crate::mesh::msh::Model, p: u32, q: u32, m: u32, surface: i32) {
    let mut entity = (2u8, surface);
    let mut halves = None;
    for (i, e) in model.elements.iter().enumerate() {
        if e.dim == 1 && e.nodes.len() == 2 && (e.nodes == [p, q] || e.nodes == [q, p]) {
            entity = (1, e.entity);
            halves = Some(i);
            break;
        }
    }
    if let Some(i) = halves {
        let [a, b] = [model.elements[i].nodes[0], model.elements[i].nodes[1]];
        model.elements[i].nodes = vec![a, m];
        let mut second = model.elements[i].clone();
        second.nodes = vec![m, b];
        model.elements.insert(i + 1, second);
    }
    if !model.node_entity.is_empty() {
        model.node_entity.push(Some(entity));
    }
    if !model.node_param.is_empty() {
        model.node_param.push(None);
    }
}
