//! Topology built once from validated mesh data: the dual graph (neighbours across each
//! triangle side, same surface only), the numbers of edges and boundary edges, and the
//! connected components; the edges themselves on demand ([`Edges`]). Also validation and
//! consistent re-orientation of the input. Knows no geometry except the zero-area test.

use super::{Mesh, MeshData, MeshError, NONE};

/// Dual graph and components of a [`Mesh`], kept for its life (the edges, which the
/// searches never read, are computed when asked for: [`Mesh::edges`]).
///
/// Side `i` of triangle `t` is the edge from `triangles[t][i]` to `triangles[t][(i + 1) % 3]`.
#[derive(Debug, Clone, Default)]
pub struct Topology {
    /// Dual graph: the triangle across each side, or [`NONE`] on a boundary, next to a quad,
    /// or across a surface boundary.
    pub neighbours: Vec<[u32; 3]>,
    /// Number of unique edges, over triangles and input quads.
    pub num_edges: usize,
    /// Number of edges used by exactly one element (triangle or quad).
    pub num_boundary_edges: usize,
    /// Number of edges used by three or more elements (surfaces meeting there).
    pub num_junction_edges: usize,
    /// Number of edges between two triangles of one surface that a line element of the
    /// input lies on (an embedded curve, the seam of a closed surface): the triangles are
    /// not neighbours there, so no quad straddles a model curve.
    pub num_curve_edges: usize,
    /// Number of triangles in each connected component of the dual graph, the components
    /// numbered in order of their first triangle.
    pub component_sizes: Vec<u32>,
}

/// The edges of a [`Mesh`] ([`Mesh::edges`]), numbered in increasing vertex pair.
#[derive(Debug, Clone, Default)]
pub struct Edges {
    /// Unique edges as sorted vertex pairs, over triangles and input quads.
    pub edges: Vec<[u32; 2]>,
    /// Edge index of each triangle side.
    pub triangle_edges: Vec<[u32; 3]>,
    /// Edges used by exactly one element (triangle or quad).
    pub boundary_edges: Vec<u32>,
}

/// The edges of `mesh` (see [`Edges`]).
pub(super) fn edges(mesh: &Mesh) -> Edges {
    let nt = mesh.triangles.len();
    let half = HalfEdges::new(mesh.vertices.len(), &mesh.triangles, &mesh.quads)
        .expect("a built mesh's sides fit in u32");
    let mut out = Edges {
        edges: Vec::with_capacity(mesh.topology.num_edges),
        triangle_edges: vec![[NONE; 3]; nt],
        boundary_edges: Vec::with_capacity(mesh.topology.num_boundary_edges),
    };
    for (a, b, group) in half.groups() {
        let e = out.edges.len() as u32;
        out.edges.push([a, b]);
        if group.len() == 1 {
            out.boundary_edges.push(e);
        }
        for &(_, t) in group {
            if let Some(&tri) = mesh.triangles.get(t as usize) {
                out.triangle_edges[t as usize][side_of(tri, a, b)] = e;
            }
        }
    }
    out
}

impl Topology {
    /// Number of dual-graph edges (pairs of neighbouring triangles).
    pub fn num_dual_edges(&self) -> usize {
        self.neighbours
            .iter()
            .enumerate()
            .map(|(t, n)| n.iter().filter(|&&u| u != NONE && u as usize > t).count())
            .sum()
    }
}

/// Every element's sides (half-edges), grouped by edge: a counting sort on the smaller
/// vertex, each vertex's list sorted by (larger vertex, element), the order of a sort of
/// `(min, max, element)` tuples in 8 bytes per half-edge and 4 per vertex (the tuples and
/// their sort took 16 per half-edge, the topology build's peak). Elements `nt..` are the
/// quads.
struct HalfEdges {
    /// `start[a]..start[a + 1]`: the entries of the sides whose smaller vertex is `a`.
    start: Vec<u32>,
    /// (larger vertex, element) of each side.
    entries: Vec<(u32, u32)>,
}

impl HalfEdges {
    /// The sides of `data`'s triangles and quads (node indices checked); the mesh is too
    /// large when they do not fit in `u32` indices.
    fn new(nv: usize, triangles: &[[u32; 3]], quads: &[[u32; 4]]) -> Result<HalfEdges, MeshError> {
        let nt = triangles.len();
        let count = 3 * nt as u64 + 4 * quads.len() as u64;
        if count >= u64::from(NONE) {
            return Err(MeshError::TooLarge {
                vertices: nv,
                triangles: nt,
            });
        }
        let sides = || {
            let tris = triangles.iter().flat_map(|t| {
                (0..3).map(move |i| (t[i].min(t[(i + 1) % 3]), t[i].max(t[(i + 1) % 3])))
            });
            let quads = quads.iter().flat_map(|q| {
                (0..4).map(move |i| (q[i].min(q[(i + 1) % 4]), q[i].max(q[(i + 1) % 4])))
            });
            tris.chain(quads)
        };
        let mut start = vec![0u32; nv + 1];
        for (a, _) in sides() {
            start[a as usize + 1] += 1;
        }
        for v in 0..nv {
            start[v + 1] += start[v];
        }
        // Filled with start[a] as the cursor; it ends at the next list's start.
        let mut entries = vec![(0u32, 0u32); count as usize];
        for (k, (a, b)) in sides().enumerate() {
            let element = if k < 3 * nt {
                k / 3
            } else {
                nt + (k - 3 * nt) / 4
            };
            let slot = &mut start[a as usize];
            entries[*slot as usize] = (b, element as u32);
            *slot += 1;
        }
        start.copy_within(0..nv, 1);
        start[0] = 0;
        for v in 0..nv {
            entries[start[v] as usize..start[v + 1] as usize].sort_unstable();
        }
        Ok(HalfEdges { start, entries })
    }

    /// The edges in increasing (smaller vertex, larger vertex): each with the
    /// (larger vertex, element) of its sides, elements increasing.
    fn groups(&self) -> impl Iterator<Item = (u32, u32, &[(u32, u32)])> {
        self.start.windows(2).enumerate().flat_map(move |(a, w)| {
            self.entries[w[0] as usize..w[1] as usize]
                .chunk_by(|x, y| x.0 == y.0)
                .map(move |g| (a as u32, g[0].0, g))
        })
    }

    /// Two triangles with the same three vertices, if any: of the smallest sorted vertex
    /// triple, its first two triangles (in index order).
    fn duplicate_triangle(&self, triangles: &[[u32; 3]]) -> Option<(u32, u32)> {
        let mut third: Vec<(u32, u32)> = Vec::new();
        for (a, b, group) in self.groups() {
            if group.len() < 2 {
                continue;
            }
            // The triangles whose two smallest vertices are a and b, by their third.
            third.clear();
            third.extend(group.iter().filter_map(|&(_, t)| {
                let c = triangles
                    .get(t as usize)?
                    .iter()
                    .find(|&&v| v != a && v != b)?;
                (*c > b).then_some((*c, t))
            }));
            third.sort_unstable();
            if let Some(w) = third.windows(2).find(|w| w[0].0 == w[1].0) {
                return Some((w[0].1, w[1].1));
            }
        }
        None
    }

    /// The error for a mesh with a non-manifold edge (more than two elements of one surface
    /// on it: [`overfull_surface`]), the same whatever the order of the nodes and elements (the
    /// file's, or the spatial order of a loaded mesh): the edge with the smallest node tags,
    /// its nodes in increasing tag, the surface with the smallest tag among those overfull
    /// there, its first elements on that surface in increasing tag.
    fn non_manifold(
        &self,
        vertex_ids: &[u64],
        element_id: impl Fn(u32) -> u64,
        surface_of: impl Fn(u32) -> i32,
    ) -> MeshError {
        let mut worst: Option<(u64, u64, i32, Vec<u64>)> = None;
        for (a, b, group) in self.groups() {
            let Some(surface) = overfull_surface(group, &surface_of) else {
                continue;
            };
            let (ta, tb) = (vertex_ids[a as usize], vertex_ids[b as usize]);
            let key = (ta.min(tb), ta.max(tb));
            if worst.as_ref().is_none_or(|w| key < (w.0, w.1)) {
                let mut elements: Vec<u64> = group
                    .iter()
                    .filter(|h| surface_of(h.1) == surface)
                    .map(|h| element_id(h.1))
                    .collect();
                elements.sort_unstable();
                worst = Some((key.0, key.1, surface, elements));
            }
        }
        let (a, b, surface, elements) = worst.expect("a non-manifold edge");
        MeshError::NonManifoldEdge {
            a,
            b,
            surface,
            count: elements.len(),
            elements: elements.into_iter().take(4).collect(),
        }
    }
}

/// The smallest surface tag with more than two of `group`'s elements (the sides of one
/// edge), if any. Elements of different surfaces may share an edge in any number (three
/// panels meeting along a line, a stiffener on a plate: each surface stays a manifold, and
/// the dual graph does not cross from one surface to another); two of one surface are
/// neighbours, a third would leave no neighbour to tell.
fn overfull_surface(group: &[(u32, u32)], surface_of: impl Fn(u32) -> i32) -> Option<i32> {
    if group.len() <= 2 {
        return None;
    }
    let mut surfaces: Vec<i32> = group.iter().map(|h| surface_of(h.1)).collect();
    surfaces.sort_unstable();
    surfaces.windows(3).find(|w| w[0] == w[2]).map(|w| w[0])
}

/// The side of triangle `tri` whose ends are `a` and `b` (in either direction).
fn side_of(tri: [u32; 3], a: u32, b: u32) -> usize {
    (0..3)
        .find(|&i| {
            let (u, v) = (tri[i], tri[(i + 1) % 3]);
            (u == a && v == b) || (u == b && v == a)
        })
        .expect("a side of the triangle")
}

/// Most vertices (and triangles) a mesh may have: below 2^31, since the search state's
/// certificates tag dead-component roots (vertex ids) with the top bit of a `u32`. (The
/// element sides must also fit in `u32`: fewer than 2^32 - 1, so triangles stay below 2^31.)
pub const MAX_VERTICES: usize = (1 << 31) - 1;

/// Whether `nv` vertices and `nt` triangles are within [`MAX_VERTICES`].
fn fits(nv: usize, nt: usize) -> bool {
    nv <= MAX_VERTICES && nt <= MAX_VERTICES
}

/// Validates `data` and builds the mesh with its topology.
pub(super) fn build(mut data: MeshData) -> Result<Mesh, MeshError> {
    let nv = data.vertices.len();
    let nt = data.triangles.len();
    if nv == 0 && nt == 0 && data.quads.is_empty() {
        return Err(MeshError::Empty);
    }
    if nt == 0 {
        return Err(MeshError::NoTriangles);
    }
    if !fits(nv, nt) {
        return Err(MeshError::TooLarge {
            vertices: nv,
            triangles: nt,
        });
    }
    data.check_elements()?;
    assert_eq!(data.triangle_surface.len(), nt, "one surface per triangle");
    for (t, tri) in data.triangles.iter().enumerate() {
        let [a, b, c] = tri.map(|v| data.vertices[v as usize]);
        if triangle_is_flat(a, b, c) {
            return Err(MeshError::DegenerateTriangle {
                element: data.triangle_ids[t],
                nodes: tri.map(|v| data.vertex_ids[v as usize]),
                log10_height: log10_height(a, b, c),
            });
        }
    }
    let half = HalfEdges::new(nv, &data.triangles, &data.quads)?;
    if let Some((first, second)) = half.duplicate_triangle(&data.triangles) {
        return Err(MeshError::DuplicateTriangle {
            element: data.triangle_ids[second as usize],
            first: data.triangle_ids[first as usize],
        });
    }

    let element_id = |e: u32| -> u64 {
        let e = e as usize;
        if e < nt {
            data.triangle_ids[e]
        } else {
            data.quad_ids[e - nt]
        }
    };
    let surface_of = |e: u32| -> i32 {
        let e = e as usize;
        if e < nt {
            data.triangle_surface[e]
        } else {
            data.quad_surface[e - nt]
        }
    };
    // The sides of the model's 2-node line elements (sorted vertex pairs).
    let mut curve_sides: Vec<(u32, u32)> = (data.model.iter())
        .flat_map(|m| &m.elements)
        .filter(|e| e.dim == 1 && e.nodes.len() == 2)
        .map(|e| (e.nodes[0].min(e.nodes[1]), e.nodes[0].max(e.nodes[1])))
        .collect();
    curve_sides.sort_unstable();
    let mut neighbours = vec![[NONE; 3]; nt];
    let (mut num_edges, mut num_boundary_edges, mut num_junction_edges) = (0, 0, 0);
    let mut curve_pairs: Vec<(u32, u32)> = Vec::new();
    for (a, b, group) in half.groups() {
        if overfull_surface(group, surface_of).is_some() {
            return Err(half.non_manifold(&data.vertex_ids, element_id, surface_of));
        }
        num_edges += 1;
        num_boundary_edges += usize::from(group.len() == 1);
        num_junction_edges += usize::from(group.len() > 2);
        let side = |t: u32| side_of(data.triangles[t as usize], a, b);
        let on_curve = curve_sides.binary_search(&(a, b)).is_ok();
        // Two triangles of one surface on the edge are neighbours (at most two per surface),
        // unless a line element of the input lies on it.
        for (i, &(_, t)) in group.iter().enumerate() {
            for &(_, u) in &group[i + 1..] {
                let (ti, ui) = (t as usize, u as usize);
                if ti < nt && ui < nt && surface_of(t) == surface_of(u) {
                    neighbours[ti][side(t)] = u;
                    neighbours[ui][side(u)] = t;
                    if on_curve {
                        curve_pairs.push((t, u));
                    }
                }
            }
        }
    }
    drop(half);

    // Components, and consistent orientation within each (flip[t] = reverse t). Oriented
    // across the model's curves too, so that both sides of an embedded curve or a seam keep
    // one orientation.
    let (component, mut component_sizes, mut flip) =
        match orient(&data.triangles, &neighbours, 0..nt as u32) {
            Ok(o) => o,
            Err(_) => {
                // Which triangle the walk meets the conflict at depends on where it starts:
                // walked again from the lowest element tags, the error names the same
                // triangle whatever order the elements were read or stored in (`info`
                // reads the file's order, `recombine` a spatial one).
                let mut by_tag: Vec<u32> = (0..nt as u32).collect();
                by_tag.sort_unstable_by_key(|&t| data.triangle_ids[t as usize]);
                let t = orient(&data.triangles, &neighbours, by_tag.into_iter())
                    .expect_err("a conflict does not depend on the walk");
                return Err(MeshError::NonOrientable {
                    surface: data.triangle_surface[t as usize],
                    element: data.triangle_ids[t as usize],
                });
            }
        };
    // Flip the smaller side of each component so the input orientation wins where it can.
    let mut flipped_in = vec![0u32; component_sizes.len()];
    for t in 0..nt {
        if flip[t] {
            flipped_in[component[t] as usize] += 1;
        }
    }
    for t in 0..nt {
        let c = component[t] as usize;
        if 2 * flipped_in[c] > component_sizes[c] {
            flip[t] = !flip[t];
        }
    }
    // Then the sides on a model curve part: the dual graph's components are counted without
    // them (a closed curve encloses a component of its own).
    for &(t, u) in &curve_pairs {
        for (a, b) in [(t, u), (u, t)] {
            let n = &mut neighbours[a as usize];
            if let Some(k) = n.iter().position(|&x| x == b) {
                n[k] = NONE;
            }
        }
    }
    if !curve_pairs.is_empty() {
        component_sizes = orient(&data.triangles, &neighbours, 0..nt as u32)
            .expect("a part of an orientable dual graph is orientable")
            .1;
    }
    let mut reoriented = 0;
    for t in 0..nt {
        if flip[t] {
            reoriented += 1;
            // Reverse (a, b, c) -> (a, c, b): sides 0 and 2 swap, side 1 reverses in place.
            let [a, b, c] = data.triangles[t];
            data.triangles[t] = [a, c, b];
            neighbours[t].swap(0, 2);
        }
    }

    Ok(Mesh {
        vertices: data.vertices,
        vertex_ids: data.vertex_ids,
        triangles: data.triangles,
        triangle_ids: data.triangle_ids,
        triangle_surface: data.triangle_surface,
        quads: data.quads,
        quad_surface: data.quad_surface,
        reoriented,
        model: data.model,
        topology: Topology {
            num_edges,
            neighbours,
            num_boundary_edges,
            num_junction_edges,
            num_curve_edges: curve_pairs.len(),
            component_sizes,
        },
    })
}

/// Components of the dual graph `neighbours` of `triangles` and a consistent orientation
/// within each (`flip[t]`: reverse `t`), walked depth first from each triangle of `starts`
/// not reached yet, neighbours in side order. `Err(u)`: triangle `u` cannot be oriented
/// consistently with the neighbour the walk reached it from (the surface is not orientable).
#[allow(clippy::type_complexity)] // the three per-triangle arrays the walk fills
fn orient(
    triangles: &[[u32; 3]],
    neighbours: &[[u32; 3]],
    starts: impl Iterator<Item = u32>,
) -> Result<(Vec<u32>, Vec<u32>, Vec<bool>), u32> {
    let nt = triangles.len();
    let mut component = vec![NONE; nt];
    let mut component_sizes = Vec::new();
    let mut flip = vec![false; nt];
    let mut stack = Vec::new();
    for start in starts {
        if component[start as usize] != NONE {
            continue;
        }
        let c = component_sizes.len() as u32;
        component[start as usize] = c;
        let mut size = 0u32;
        stack.push(start);
        while let Some(t) = stack.pop() {
            size += 1;
            let tri = triangles[t as usize];
            for i in 0..3 {
                let u = neighbours[t as usize][i];
                if u == NONE {
                    continue;
                }
                // t traverses its side i as (tri[i] -> tri[i+1]); u must traverse it the other
                // way once both flips are applied.
                let other = triangles[u as usize];
                let k = (0..3).find(|&k| other[k] == tri[i]).expect("shared vertex");
                let same_direction = other[(k + 1) % 3] == tri[(i + 1) % 3];
                let want = flip[t as usize] ^ same_direction;
                if component[u as usize] == NONE {
                    component[u as usize] = c;
                    flip[u as usize] = want;
                    stack.push(u);
                } else if flip[u as usize] != want {
                    return Err(u);
                }
            }
        }
        component_sizes.push(size);
    }
    Ok((component, component_sizes, flip))
}

pub(super) fn sanity_check(mesh: &Mesh) -> Result<(), String> {
    let topo = &mesh.topology;
    let nt = mesh.triangles.len();
    if topo.neighbours.len() != nt {
        return Err("topology arrays do not match the triangle count".into());
    }
    if mesh.triangle_surface.len() != nt || mesh.triangle_ids.len() != nt {
        return Err("per-triangle arrays do not match the triangle count".into());
    }
    let all = edges(mesh);
    if all.edges.len() != topo.num_edges || all.boundary_edges.len() != topo.num_boundary_edges {
        return Err("edge counts do not match the edges".into());
    }
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for i in 0..3 {
            let (a, b) = (tri[i], tri[(i + 1) % 3]);
            let e = all.triangle_edges[t][i];
            if e as usize >= all.edges.len() || all.edges[e as usize] != [a.min(b), a.max(b)] {
                return Err(format!("triangle {t} side {i}: wrong edge {e}"));
            }
            let u = topo.neighbours[t][i];
            if u == NONE {
                continue;
            }
            let u = u as usize;
            if u >= nt || u == t {
                return Err(format!("triangle {t} side {i}: bad neighbour {u}"));
            }
            let j = (0..3).find(|&j| topo.neighbours[u][j] == t as u32);
            let Some(j) = j else {
                return Err(format!("dual graph not symmetric between {t} and {u}"));
            };
            if all.triangle_edges[u][j] != e {
                return Err(format!(
                    "triangles {t} and {u} are neighbours across different edges"
                ));
            }
            let other = mesh.triangles[u];
            if (other[j], other[(j + 1) % 3]) != (b, a) {
                return Err(format!(
                    "triangles {t} and {u} are not oriented consistently"
                ));
            }
            if mesh.triangle_surface[t] != mesh.triangle_surface[u] {
                return Err(format!(
                    "triangles {t} and {u} are neighbours across surfaces"
                ));
            }
        }
    }
    // Components by a walk of the dual graph, numbered by first triangle.
    let mut component = vec![NONE; nt];
    let mut sizes = Vec::new();
    for start in 0..nt {
        if component[start] != NONE {
            continue;
        }
        let c = sizes.len() as u32;
        component[start] = c;
        let (mut size, mut stack) = (0u32, vec![start as u32]);
        while let Some(t) = stack.pop() {
            size += 1;
            for &u in &topo.neighbours[t as usize] {
                if u != NONE && component[u as usize] == NONE {
                    component[u as usize] = c;
                    stack.push(u);
                }
            }
        }
        sizes.push(size);
    }
    if sizes != topo.component_sizes {
        return Err("component sizes do not match the dual graph's components".into());
    }
    if all.edges.windows(2).any(|w| w[0] >= w[1]) || all.edges.iter().any(|e| e[0] >= e[1]) {
        return Err("edges are not unique sorted pairs".into());
    }
    Ok(())
}

pub(crate) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
pub(crate) fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// Triangle `abc` has no area to within rounding: twice its area at most 1e-14 times its
/// longest side squared. Scale-free: the largest component of the edge vectors is brought to
/// 1, so that the squares neither overflow nor underflow for very large or small coordinates.
fn triangle_is_flat(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> bool {
    let (mut u, mut w) = (sub(b, a), sub(c, a));
    let m = u.iter().chain(&w).fold(0.0f64, |m, x| m.max(x.abs()));
    if m > 0.0 && m.is_finite() {
        u = u.map(|x| x / m);
        w = w.map(|x| x / m);
    }
    let scale = dot(u, u).max(dot(w, w)).max(dot(sub(w, u), sub(w, u)));
    norm(cross(u, w)) <= 1e-14 * scale || scale == 0.0
}

/// An input quad whose four nodes are collinear to within rounding: each of the four
/// triangles of three of its corners is flat ([`triangle_is_flat`]). A quad with a straight
/// or reflex corner, or a self-intersecting one (a bow tie), keeps an area in some corner
/// triangle and is read (its eta is 0, which `info` counts as poor).
pub(super) fn quad_is_flat(p: [[f64; 3]; 4]) -> bool {
    (0..4).all(|i| triangle_is_flat(p[i], p[(i + 1) % 4], p[(i + 2) % 4]))
}

/// log10 of the smallest height of triangle `abc` over its longest edge, without
/// under- or overflow (a triangle 1e200 long and 1e-200 high has area 0.5 and ratio 1e-400,
/// which no f64 holds): each edge vector is scaled by its own largest component and the
/// scales are added back as logarithms. -inf when the area is zero.
fn log10_height(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    let unit = |v: [f64; 3]| {
        let m = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        if m > 0.0 {
            (v.map(|x| x / m), m.log10())
        } else {
            (v, f64::NEG_INFINITY)
        }
    };
    let (u, lu) = unit(sub(b, a));
    let (w, lw) = unit(sub(c, a));
    let (e, le) = unit(sub(c, b));
    // 2 area = |u x w| 10^(lu + lw); longest edge^2 = max |.|^2 10^(2 l).
    let edge = [(u, lu), (w, lw), (e, le)]
        .iter()
        .map(|(v, l)| 0.5 * dot(*v, *v).log10() + l)
        .fold(f64::NEG_INFINITY, f64::max);
    norm(cross(u, w)).log10() + lu + lw - 2.0 * edge
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_size_limit_is_the_search_states() {
        // The state asserted fewer than 2^31 vertices while the reader accepted up to
        // 2^32 - 2: a mesh in between would have panicked instead of being refused.
        assert!(super::fits(super::MAX_VERTICES, 1));
        assert!(!super::fits(super::MAX_VERTICES + 1, 1));
        assert!(!super::fits(3, super::MAX_VERTICES + 1));
    }

    use super::*;

    /// Two triangles sharing the diagonal of the unit square, second one given with `order`.
    fn square(second: [u32; 3]) -> MeshData {
        MeshData {
            vertices: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 1.0, 0.0],
            ],
            triangles: vec![[0, 1, 2], second],
            ..MeshData::default()
        }
    }

    #[test]
    fn square_has_one_dual_edge_and_four_boundary_edges() {
        let mesh = Mesh::new(square([0, 2, 3])).unwrap();
        mesh.sanity_check().unwrap();
        assert_eq!(mesh.topology.num_dual_edges(), 1);
        assert_eq!(mesh.topology.num_boundary_edges, 4);
        assert_eq!(mesh.topology.num_edges, 5);
        let edges = mesh.edges();
        assert_eq!(edges.edges.len(), 5);
        assert_eq!(edges.boundary_edges.len(), 4);
        assert_eq!(mesh.topology.component_sizes, vec![2]);
        assert_eq!(mesh.reoriented, 0);
    }

    #[test]
    fn inconsistent_orientation_is_fixed() {
        let mesh = Mesh::new(square([0, 3, 2])).unwrap();
        mesh.sanity_check().unwrap();
        assert_eq!(mesh.reoriented, 1);
        assert_eq!(mesh.topology.num_dual_edges(), 1);
    }

    #[test]
    fn different_surfaces_are_not_neighbours() {
        let mut data = square([0, 2, 3]);
        data.triangle_surface = vec![1, 2];
        let mesh = Mesh::new(data).unwrap();
        mesh.sanity_check().unwrap();
        assert_eq!(mesh.topology.num_dual_edges(), 0);
        assert_eq!(mesh.topology.component_sizes, vec![1, 1]);
    }

    /// A line element on the diagonal (an embedded curve): the two triangles are not
    /// neighbours, each is a component, and an inconsistent orientation is still fixed
    /// across the curve. A line on a boundary side or on no side changes nothing.
    #[test]
    fn triangles_are_not_neighbours_across_a_line_element() {
        use crate::mesh::msh::{Element, Model};
        let line = |a: u32, b: u32| Element {
            gmsh_type: 1,
            dim: 1,
            entity: 7,
            nodes: vec![a, b],
        };
        for second in [[0, 2, 3], [0, 3, 2]] {
            let mut data = square(second);
            data.model = Some(Box::new(Model {
                elements: vec![line(2, 0), line(0, 1)],
                ..Model::default()
            }));
            let mesh = Mesh::new(data).unwrap();
            mesh.sanity_check().unwrap();
            assert_eq!(mesh.topology.num_dual_edges(), 0);
            assert_eq!(mesh.topology.num_curve_edges, 1);
            assert_eq!(mesh.topology.component_sizes, vec![1, 1]);
            assert_eq!(mesh.reoriented, usize::from(second == [0, 3, 2]));
            let [a, b] = [mesh.triangles[0], mesh.triangles[1]];
            // Consistent: the diagonal runs 2 -> 0 in one and 0 -> 2 in the other.
            let runs =
                |t: [u32; 3], p: u32, q: u32| (0..3).any(|i| t[i] == p && t[(i + 1) % 3] == q);
            assert!(runs(a, 2, 0) != runs(b, 2, 0), "{a:?} {b:?}");
        }
        let mut data = square([0, 2, 3]);
        data.model = Some(Box::new(Model {
            elements: vec![line(0, 1), line(1, 3)],
            ..Model::default()
        }));
        let mesh = Mesh::new(data).unwrap();
        assert_eq!(mesh.topology.num_dual_edges(), 1);
        assert_eq!(mesh.topology.num_curve_edges, 0);
    }

    /// The message names the same edge and elements whatever the order of the nodes and
    /// triangles (`info` reads the file's order, the other commands a spatial order).
    #[test]
    fn non_manifold_error_does_not_depend_on_the_order() {
        // Fins on a square: edges 1-3 (node ids) and 3-4 each in three triangles.
        let mut data = square([0, 2, 3]);
        data.vertices.push([1.0, 1.0, 1.0]);
        data.vertices.push([0.0, 1.0, 1.0]);
        data.triangles.push([0, 2, 4]);
        data.triangles.push([2, 3, 5]);
        data.triangles.push([2, 3, 4]);
        data.vertex_ids = vec![1, 2, 3, 4, 5, 6];
        data.triangle_ids = vec![10, 11, 12, 13, 14];
        data.triangle_surface = vec![1; 5];
        let want = Mesh::new(data.clone()).unwrap_err();
        assert!(
            matches!(&want, MeshError::NonManifoldEdge { a: 1, b: 3, surface: 1, count: 3, elements } if elements == &[10, 11, 12]),
            "{want}"
        );
        // Nodes and triangles in reverse order.
        let n = data.vertices.len() as u32;
        data.vertices.reverse();
        data.vertex_ids.reverse();
        for t in &mut data.triangles {
            *t = t.map(|v| n - 1 - v);
        }
        data.triangles.reverse();
        data.triangle_ids.reverse();
        assert_eq!(Mesh::new(data).unwrap_err(), want);
    }

    /// Surfaces may meet at an edge in any number, each with at most two triangles there:
    /// the dual graph joins the two of one surface and nothing across surfaces.
    #[test]
    fn surfaces_meet_at_an_edge_each_a_manifold() {
        // The square's diagonal 0-2 with fins standing on it: above at node 4, below at 5.
        let with = |fins: &[([u32; 3], i32)], square_surfaces: [i32; 2]| {
            let mut data = square([0, 2, 3]);
            data.vertices.push([1.0, 1.0, 1.0]);
            data.vertices.push([1.0, 1.0, -1.0]);
            data.triangle_surface = square_surfaces.to_vec();
            for &(tri, surface) in fins {
                data.triangles.push(tri);
                data.triangle_surface.push(surface);
            }
            Mesh::new(data)
        };
        let check = |mesh: Result<Mesh, MeshError>, dual_edges, mut sizes: Vec<u32>| {
            let mesh = mesh.unwrap();
            mesh.sanity_check().unwrap();
            assert_eq!(mesh.topology.num_dual_edges(), dual_edges);
            let mut got = mesh.topology.component_sizes.clone();
            got.sort_unstable();
            sizes.sort_unstable();
            assert_eq!(got, sizes);
            // The diagonal is no boundary edge: more than one element uses it.
            assert_eq!(
                mesh.topology.num_boundary_edges,
                mesh.topology.num_edges - 1
            );
            assert_eq!(mesh.topology.num_junction_edges, 1);
        };
        // One triangle of each of three surfaces (a T: a web on the line between two panels).
        check(with(&[([0, 2, 4], 3)], [1, 2]), 0, vec![1, 1, 1]);
        // Two of the plate's and one of a fin's.
        check(with(&[([0, 2, 4], 2)], [1, 1]), 1, vec![2, 1]);
        // Two of each (a wall through the plate).
        check(
            with(&[([0, 2, 4], 2), ([0, 2, 5], 2)], [1, 1]),
            2,
            vec![2, 2],
        );
        // Three of one surface beside one of another: that surface is no manifold there.
        let err = with(&[([0, 2, 4], 1), ([0, 2, 5], 2)], [1, 1]).unwrap_err();
        assert!(
            matches!(&err, MeshError::NonManifoldEdge { a: 1, b: 3, surface: 1, count: 3, elements } if elements == &[1, 2, 3]),
            "{err}"
        );
        assert!(err.to_string().contains("3 elements of surface 1"), "{err}");
    }

    #[test]
    fn non_manifold_edge_is_an_error() {
        let mut data = square([0, 2, 3]);
        data.vertices.push([1.0, 1.0, 1.0]);
        data.triangles.push([0, 2, 4]);
        data.triangle_ids = vec![10, 11, 12];
        let err = Mesh::new(data).unwrap_err();
        assert!(
            matches!(&err, MeshError::NonManifoldEdge { count: 3, elements, .. } if elements == &[10, 11, 12]),
            "{err}"
        );
    }

    #[test]
    fn degenerate_and_duplicate_triangles_are_errors() {
        let mut data = square([0, 2, 3]);
        data.vertices[1] = [2.0, 2.0, 0.0]; // triangle 1 = (0,0), (2,2), (1,1): collinear
        assert!(matches!(
            Mesh::new(data).unwrap_err(),
            MeshError::DegenerateTriangle { element: 1, .. }
        ));
        let mut data = square([0, 2, 3]);
        data.triangles.push([2, 0, 1]);
        assert!(matches!(
            Mesh::new(data).unwrap_err(),
            MeshError::DuplicateTriangle {
                element: 3,
                first: 1
            }
        ));
    }

    #[test]
    fn moebius_strip_is_not_orientable() {
        // A strip of 6 quads (12 triangles) whose ends are glued with a half twist.
        let n = 6;
        let mut vertices = Vec::new();
        for i in 0..n {
            let a = i as f64 / n as f64 * std::f64::consts::TAU;
            let half = a / 2.0;
            for s in [-0.3, 0.3] {
                let r = 1.0 + s * half.cos();
                vertices.push([r * a.cos(), r * a.sin(), s * half.sin()]);
            }
        }
        let mut triangles = Vec::new();
        for i in 0..n {
            let (a, b) = (2 * i as u32, 2 * i as u32 + 1);
            let (c, d) = if i + 1 < n {
                (2 * (i + 1) as u32, 2 * (i + 1) as u32 + 1)
            } else {
                (1, 0) // the half twist
            };
            triangles.push([a, c, d]);
            triangles.push([a, d, b]);
        }
        let err = Mesh::new(MeshData {
            vertices: vertices.clone(),
            triangles: triangles.clone(),
            ..MeshData::default()
        })
        .unwrap_err();
        assert!(matches!(err, MeshError::NonOrientable { .. }), "{err}");
        // The triangle named does not depend on the order the elements come in (`info`
        // keeps the file's, `recombine` sorts them spatially): every rotation and the
        // reversal of the element list, tags kept, name the same one.
        let named = |order: &[usize]| {
            let err = Mesh::new(MeshData {
                vertices: vertices.clone(),
                triangles: order.iter().map(|&i| triangles[i]).collect(),
                triangle_ids: order.iter().map(|&i| 10 + i as u64).collect(),
                triangle_surface: vec![1; order.len()],
                ..MeshData::default()
            })
            .unwrap_err();
            match err {
                MeshError::NonOrientable { element, .. } => element,
                e => panic!("{e}"),
            }
        };
        let mut order: Vec<usize> = (0..triangles.len()).collect();
        let first = named(&order);
        let mut seen = vec![];
        for _ in 0..order.len() {
            order.rotate_left(1);
            seen.push(named(&order));
            order.reverse();
            seen.push(named(&order));
            order.reverse();
        }
        assert!(seen.iter().all(|&e| e == first), "{first} vs {seen:?}");
    }

    #[test]
    fn flat_input_quads_are_errors_and_straight_corners_are_not() {
        // The square's two triangles and a quad (1, 4, 5, 2) beside them; node 5 moved.
        let with_quad = |p5: [f64; 3], order: [u32; 4]| {
            let mut data = square([0, 2, 3]);
            data.vertices.extend([[2.0, 0.0, 0.0], p5]);
            data.quads = vec![order];
            data.quad_ids = vec![7];
            data.quad_surface = vec![1];
            Mesh::new(data)
        };
        assert!(with_quad([2.0, 1.0, 0.0], [1, 4, 5, 2]).is_ok());
        // A straight corner at 4 (1, 4, 5 collinear) keeps an area: read, eta 0.
        assert!(with_quad([3.0, 0.0, 0.0], [1, 4, 5, 2]).is_ok());
        // A bow tie (self-intersecting, halves cancelling) is read too: eta 0.
        assert!(with_quad([2.0, 1.0, 0.0], [1, 5, 4, 2]).is_ok());
        // Four collinear nodes, also with two of them coincident.
        for (p5, order) in [
            ([3.0, 0.0, 0.0], [1, 4, 5, 0]),
            ([2.0, 0.0, 0.0], [1, 4, 5, 0]),
        ] {
            let err = with_quad(p5, order).unwrap_err();
            assert!(
                matches!(err, MeshError::DegenerateQuad { element: 7, .. }),
                "{err}"
            );
            assert!(err.to_string().starts_with("quad 7 is degenerate"), "{err}");
        }
    }

    #[test]
    fn mesh_data_of_inconsistent_lengths_or_repeated_node_tags_is_an_error() {
        // They panicked (an assert in check_elements), or a short quad_surface lost quads
        // in the written file, or repeated node tags made a file `load` refuses (a library
        // user's review).
        let mut data = square([0, 2, 3]);
        data.vertex_ids = vec![1, 2];
        let err = Mesh::new(data).unwrap_err();
        assert_eq!(
            err.to_string(),
            "the mesh data's vertex_ids holds 2 entries for 4 vertices (one each, or none for \
             the default)"
        );
        let mut data = square([0, 2, 3]);
        data.vertices.extend([[2.0, 0.0, 0.0], [2.0, 1.0, 0.0]]);
        data.quads = vec![[1, 4, 5, 2], [1, 4, 5, 2]];
        data.quad_surface = vec![1];
        assert!(matches!(
            Mesh::new(data).unwrap_err(),
            MeshError::Inconsistent {
                field: "quad_surface",
                len: 1,
                expected: 2,
                ..
            }
        ));
        let mut data = square([0, 2, 3]);
        data.triangle_surface = vec![1, 1, 1];
        assert!(matches!(
            Mesh::new(data).unwrap_err(),
            MeshError::Inconsistent {
                field: "triangle_surface",
                ..
            }
        ));
        let mut data = square([0, 2, 3]);
        data.vertex_ids = vec![5, 9, 5, 7];
        assert_eq!(
            Mesh::new(data).unwrap_err(),
            MeshError::DuplicateNodeTag { tag: 5 }
        );
    }

    #[test]
    fn empty_and_triangle_free_meshes_are_errors() {
        assert_eq!(
            Mesh::new(MeshData::default()).unwrap_err(),
            MeshError::Empty
        );
        let data = MeshData {
            vertices: vec![[0.0; 3], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
            quads: vec![[0, 1, 2, 3]],
            ..MeshData::default()
        };
        assert_eq!(Mesh::new(data).unwrap_err(), MeshError::NoTriangles);
    }
}
