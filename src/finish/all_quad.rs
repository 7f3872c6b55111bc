//! All-quad: one triangle per odd component must stay under recombination alone. A
//! boundary side of a well-chosen triangle `s` is split at its midpoint by a new node: `s`
//! becomes two halves, the component even, and the halves pair with the triangles across
//! `s`'s two inner sides. Which triangle is chosen, and why, is [`super::split_choice`]'s
//! part; this module builds the split mesh, its candidate table and the pairing carried
//! over. The node lies on the chord (the straight side): no boundary-curve geometry is read
//! from the input.

use super::region::Pairing;
use super::split_choice::Chosen;
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
    /// Pairs crossed from the component's leftover to the split triangle (0: the leftover
    /// itself was split).
    pub path_len: usize,
}

/// The result of [`split`].
pub(crate) struct SplitMesh {
    pub mesh: Mesh,
    pub table: CandidateTable,
    pub pairing: Pairing,
    pub splits: Vec<Split>,
}

/// Splits the boundary sides `chosen` picked: the new mesh, its table under `rule` (eta of
/// the pairs that did not change kept from `table`, new pairs in f64; the two halves of a
/// split are never a pair: their quad has a straight angle) and `chosen`'s pairing carried
/// over, with each half paired with the triangle across its inner side where the new table
/// has that pair.
pub(crate) fn split(
    mesh: &Mesh,
    table: &CandidateTable,
    chosen: &Chosen,
    rule: Rule,
) -> Result<SplitMesh, MeshError> {
    let nt = mesh.num_triangles();
    let pairing = &chosen.pairing;
    let mut data = editable_copy(mesh);
    let first_node = mesh.vertex_ids.iter().max().copied().unwrap_or(0) + 1;
    let first_element = first_free_element_tag(mesh);
    let mut splits = Vec::new();
    // (first half, the triangle across its inner side), (second half, ...) per split.
    let mut half_pairs = Vec::new();
    for (k, choice) in chosen.choices.iter().enumerate() {
        let (next_node, next_element) = (first_node + k as u64, first_element + k as u64);
        let (b, side) = (choice.triangle, choice.side);
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
        let second = data.triangles.len() as u32;
        data.triangles.push([m, q, s]);
        data.triangle_ids.push(next_element);
        data.triangle_surface
            .push(mesh.triangle_surface[b as usize]);
        if let Some(model) = data.model.as_deref_mut() {
            // A side all-quad splits is used by one element: a boundary.
            split_model_edge(model, [p, q], m, mesh.triangle_surface[b as usize], true);
        }
        let nb = mesh.topology.neighbours[b as usize];
        half_pairs.push((b, nb[(side + 2) % 3]));
        half_pairs.push((second, nb[(side + 1) % 3]));
        splits.push(Split {
            triangle: b,
            side: [mesh.vertex_ids[p as usize], mesh.vertex_ids[q as usize]],
            node: next_node,
            path_len: choice.steps,
        });
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
        let p = new_table.quads[c].map(|v| new_mesh.vertices[v as usize]);
        let eta = quad_eta(p);
        new_table.eta[c] = eta;
        // The two halves of one split make a quad with a straight angle: never a pair.
        let halves = b as usize >= nt && split_set.contains(&a) && {
            let k = b as usize - nt;
            splits[k].triangle == a
        };
        *kept = rule.allows_pair(eta, p) && !halves;
    }
    let new_table = new_table.retain(&keep);
    let mut chosen: Vec<u32> = Vec::new();
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
    for (half, other) in half_pairs {
        if let Some(nc) = new_table.by_triangle[half as usize]
            .into_iter()
            .find(|&n| n != NONE && new_table.other(n, half) == other)
        {
            chosen.push(nc);
        }
    }
    let new_pairing = Pairing::new(new_mesh.num_triangles(), &new_table, &chosen);
    Ok(SplitMesh {
        mesh: new_mesh,
        table: new_table,
        pairing: new_pairing,
        splits,
    })
}

/// Splits the model's line elements on side `p`-`q` (if any: every copy) at the new node `m`, and
/// classifies `m` on the curve the side lies on, or on surface `surface` when it lies on none.
/// `edge` says whether the side is one where a curve must lie: used by one element, or by
/// elements of two surfaces or by three or more.
///
/// Gmsh saves line elements only for curves in physical groups (unless `Mesh.SaveAll`), but
/// classifies every node: without a line element, the curve is read off the ends' entities
/// ([`curve_of_side`]). A curve node on a surface made Gmsh's `recombine()` drop it and open
/// a hole in the mesh. On a curve, `m` gets the mean of its ends' parameters where both have
/// one (the side is a segment of the curve between them).
pub(crate) fn split_model_edge(
    model: &mut crate::mesh::msh::Model,
    [p, q]: [u32; 2],
    m: u32,
    surface: i32,
    edge: bool,
) {
    // Every line element on the side: a file may give a segment more than once (Gmsh's MSH
    // 2.2 writes a curve's lines once per physical group; two curves may share a segment).
    let lines: Vec<usize> = (model.elements.iter().enumerate())
        .filter(|(_, e)| e.dim == 1 && e.nodes.len() == 2)
        .filter(|(_, e)| e.nodes == [p, q] || e.nodes == [q, p])
        .map(|(i, _)| i)
        .collect();
    let curve = match lines.first() {
        Some(&i) => Some(model.elements[i].entity),
        None => curve_of_side(model, [p, q], surface, edge),
    };
    // From the last, so that the insertions leave the earlier indices in place.
    for &i in lines.iter().rev() {
        let [a, b] = [model.elements[i].nodes[0], model.elements[i].nodes[1]];
        model.elements[i].nodes = vec![a, m];
        let mut second = model.elements[i].clone();
        second.nodes = vec![m, b];
        model.elements.insert(i + 1, second);
    }
    let entity = curve.map_or((2u8, surface), |c| (1, c));
    let param = curve.and_then(|_| {
        let on = |v: u32| model.node_entity.get(v as usize).copied().flatten();
        let u = |v: u32| model.node_param.get(v as usize).copied().flatten();
        match (u(p), u(q)) {
            (Some(a), Some(b)) if on(p) == Some(entity) && on(q) == Some(entity) => {
                Some([0.5 * (a[0] + b[0]), 0.0, 0.0])
            }
            _ => None,
        }
    });
    if !model.node_entity.is_empty() {
        model.node_entity.push(Some(entity));
    }
    if !model.node_param.is_empty() {
        model.node_param.push(param);
    }
}

/// The curve that side `p`-`q` (of an element of `surface`) lies on, read off the entities
/// its ends are classified on, when no line element lies on it: both on one curve; one on a
/// curve and the other on a point that bounds it (MSH 4.1's `$Entities` give the bounding
/// points; without them, any point); or both on the two points that bound exactly one curve.
/// Only for a side where a curve must lie (`edge`), or, inside one surface, for a curve
/// embedded in it (not among its bounding curves; none is known without `$Entities`): a side
/// of one surface's interior whose ends are on a curve bounding it is a chord across the
/// surface (a triangle with its three corners on the curve has one). And never for a curve
/// whose segments the file gives as line elements: a side without one is not a segment.
/// `None` otherwise: the node stays on the surface.
fn curve_of_side(
    model: &crate::mesh::msh::Model,
    [p, q]: [u32; 2],
    surface: i32,
    edge: bool,
) -> Option<i32> {
    let on = |v: u32| model.node_entity.get(v as usize).copied().flatten();
    let bounds = |c: i32, t: i32| {
        model
            .entity(1, c)
            .is_some_and(|e| e.bounding.iter().any(|&b| b.abs() == t.abs()))
    };
    let topology = |c: i32| model.entity(1, c).is_some_and(|e| !e.bounding.is_empty());
    let curve = match (on(p)?, on(q)?) {
        ((1, a), (1, b)) if a == b => a,
        ((1, c), (0, t)) | ((0, t), (1, c)) if bounds(c, t) || !topology(c) => c,
        ((0, s), (0, t)) if s != t => {
            let mut curves = (model.entities.iter())
                .filter(|e| e.dim == 1 && bounds(e.tag, s) && bounds(e.tag, t));
            match (curves.next(), curves.next()) {
                (Some(c), None) => c.tag,
                _ => return None,
            }
        }
        _ => return None,
    };
    if (model.elements.iter()).any(|e| e.dim == 1 && e.entity == curve) {
        return None;
    }
    let embedded = || {
        model.entity(2, surface).is_some_and(|s| {
            !s.bounding.is_empty() && !s.bounding.iter().any(|b| b.abs() == curve.abs())
        })
    };
    (edge || embedded()).then_some(curve)
}

/// `mesh`'s data, to add nodes and elements to (split sides, sheets): the input quads keep
/// their corners and surfaces, not their tags (a [`Mesh`] does not keep them): they are
/// numbered after the largest triangle tag, and added elements after them
/// ([`first_free_element_tag`]). Numbering them from the triangle count up, as an empty
/// list would, collided with the triangles' own tags in a Gmsh file, whose point and line
/// elements come first ("element tag 75 is given to two elements").
pub(crate) fn editable_copy(mesh: &Mesh) -> MeshData {
    let after = max_triangle_tag(mesh);
    MeshData {
        vertices: mesh.vertices.clone(),
        vertex_ids: mesh.vertex_ids.clone(),
        triangles: mesh.triangles.clone(),
        triangle_ids: mesh.triangle_ids.clone(),
        triangle_surface: mesh.triangle_surface.clone(),
        quads: mesh.quads.clone(),
        quad_ids: (1..=mesh.quads.len() as u64).map(|k| after + k).collect(),
        quad_surface: mesh.quad_surface.clone(),
        model: mesh.model.clone(),
    }
}

fn max_triangle_tag(mesh: &Mesh) -> u64 {
    mesh.triangle_ids.iter().max().copied().unwrap_or(0)
}

/// The first element tag no element of [`editable_copy`]`(mesh)` has.
pub(crate) fn first_free_element_tag(mesh: &Mesh) -> u64 {
    max_triangle_tag(mesh) + mesh.quads.len() as u64 + 1
}
