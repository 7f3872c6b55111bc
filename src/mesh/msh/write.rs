//! The MSH 4.1 ASCII writer: the mesh alone, or, for a mesh read from a Gmsh file, the
//! mesh on the file's model (physical names, entities, node classification, points and
//! lines).

use super::model::{Entity, Model};
use crate::mesh::{Mesh, Recombined};
use std::collections::BTreeMap;
use std::io::{self, Write};

/// Checks that `rec` refers to vertices and triangles of `mesh`.
pub(crate) fn check_recombined(mesh: &Mesh, rec: &Recombined) -> io::Result<()> {
    let nv = mesh.vertices.len();
    let nt = mesh.num_triangles();
    let bad = |m: String| Err(io::Error::new(io::ErrorKind::InvalidInput, m));
    if rec.quad_surface.len() != rec.quads.len() {
        return bad("recombined quads and their surfaces differ in number".into());
    }
    if let Some(q) = rec
        .quads
        .iter()
        .find(|q| q.iter().any(|&v| v as usize >= nv))
    {
        return bad(format!(
            "recombined quad {q:?} refers to a vertex past the mesh's {nv}"
        ));
    }
    if let Some(t) = rec.leftover.iter().find(|&&t| t as usize >= nt) {
        return bad(format!("leftover triangle {t} is past the mesh's {nt}"));
    }
    Ok(())
}

/// Surface tags in the order they are written: sorted, distinct, over everything written.
fn written_surfaces(mesh: &Mesh, rec: &Recombined) -> Vec<i32> {
    let mut s: Vec<i32> = rec
        .quad_surface
        .iter()
        .chain(&mesh.quad_surface)
        .chain(
            rec.leftover
                .iter()
                .map(|&t| &mesh.triangle_surface[t as usize]),
        )
        .copied()
        .collect();
    s.sort_unstable();
    s.dedup();
    if s.is_empty() {
        s.push(1);
    }
    s
}

/// The elements written on each surface (in the order of `written_surfaces`): quads
/// (recombined, then input) and leftover triangles.
struct SurfaceElements {
    quads: Vec<Vec<[u32; 4]>>,
    tris: Vec<Vec<[u32; 3]>>,
}

impl SurfaceElements {
    fn new(mesh: &Mesh, rec: &Recombined, surfaces: &[i32]) -> SurfaceElements {
        let slot = |s: i32| surfaces.binary_search(&s).unwrap_or(0);
        let ns = surfaces.len();
        let mut quads: Vec<Vec<[u32; 4]>> = vec![Vec::new(); ns];
        let mut tris: Vec<Vec<[u32; 3]>> = vec![Vec::new(); ns];
        for (q, &s) in rec.quads.iter().zip(&rec.quad_surface) {
            quads[slot(s)].push(*q);
        }
        for (q, &s) in mesh.quads.iter().zip(&mesh.quad_surface) {
            quads[slot(s)].push(*q);
        }
        for &t in &rec.leftover {
            let t = t as usize;
            tris[slot(mesh.triangle_surface[t])].push(mesh.triangles[t]);
        }
        SurfaceElements { quads, tris }
    }

    /// The vertices surface `k` uses.
    fn used(&self, k: usize) -> impl Iterator<Item = u32> + '_ {
        let q = self.quads[k].iter().flatten();
        q.chain(self.tris[k].iter().flatten()).copied()
    }

    /// Surface of each vertex: the first (by `written_surfaces`) that uses it, `None` if
    /// none does.
    fn owners(&self, nv: usize) -> Vec<Option<usize>> {
        let mut owner = vec![None; nv];
        for k in 0..self.quads.len() {
            for v in self.used(k) {
                owner[v as usize].get_or_insert(k);
            }
        }
        owner
    }

    fn count(&self) -> (usize, usize) {
        let ne = self.quads.iter().map(Vec::len).sum::<usize>()
            + self.tris.iter().map(Vec::len).sum::<usize>();
        let blocks = self.quads.iter().filter(|b| !b.is_empty()).count()
            + self.tris.iter().filter(|b| !b.is_empty()).count();
        (blocks, ne)
    }

    /// Writes the element blocks of every surface, numbering the elements from
    /// `*tag + 1`.
    fn write(
        &self,
        w: &mut impl Write,
        surfaces: &[i32],
        id: impl Fn(u32) -> u64,
        tag: &mut u64,
    ) -> io::Result<()> {
        for (k, s) in surfaces.iter().enumerate() {
            if !self.quads[k].is_empty() {
                writeln!(w, "2 {s} 3 {}", self.quads[k].len())?;
                for q in &self.quads[k] {
                    *tag += 1;
                    let [a, b, c, d] = q.map(&id);
                    writeln!(w, "{tag} {a} {b} {c} {d}")?;
                }
            }
            if !self.tris[k].is_empty() {
                writeln!(w, "2 {s} 2 {}", self.tris[k].len())?;
                for t in &self.tris[k] {
                    *tag += 1;
                    let [a, b, c] = t.map(&id);
                    writeln!(w, "{tag} {a} {b} {c}")?;
                }
            }
        }
        Ok(())
    }
}

/// A bounding box being grown: min x, y, z then max x, y, z.
type Bbox = [f64; 6];

const EMPTY_BBOX: Bbox = [
    f64::INFINITY,
    f64::INFINITY,
    f64::INFINITY,
    f64::NEG_INFINITY,
    f64::NEG_INFINITY,
    f64::NEG_INFINITY,
];

fn grow(b: &mut Bbox, p: [f64; 3]) {
    for d in 0..3 {
        b[d] = b[d].min(p[d]);
        b[d + 3] = b[d + 3].max(p[d]);
    }
}

/// A grown box, with 0 for the coordinates of an empty one.
fn finite(b: Bbox) -> Bbox {
    b.map(|x| if x.is_finite() { x } else { 0.0 })
}

/// Writes MSH 4.1 ASCII (see [`super::write`]) to any writer.
pub fn write_to(w: &mut impl Write, mesh: &Mesh, rec: &Recombined) -> io::Result<()> {
    check_recombined(mesh, rec)?;
    let surfaces = written_surfaces(mesh, rec);
    let elements = SurfaceElements::new(mesh, rec, &surfaces);
    match &mesh.model {
        Some(model) => write_model(w, mesh, model, &surfaces, &elements),
        None => write_plain(w, mesh, &surfaces, &elements),
    }
}

/// The node tag of each vertex (1-based positions where the mesh has none).
fn node_id(mesh: &Mesh) -> impl Fn(u32) -> u64 + '_ {
    let ids = &mesh.vertex_ids;
    move |v: u32| ids.get(v as usize).copied().unwrap_or(u64::from(v) + 1)
}

/// The `$Nodes` header: blocks, nodes, smallest and largest tag.
fn nodes_header(w: &mut impl Write, mesh: &Mesh, blocks: usize) -> io::Result<()> {
    let nv = mesh.vertices.len();
    let id = node_id(mesh);
    let (min_tag, max_tag) = (0..nv as u32)
        .map(&id)
        .fold((u64::MAX, 0), |(a, b), t| (a.min(t), b.max(t)));
    writeln!(
        w,
        "$Nodes\n{blocks} {nv} {} {max_tag}",
        if nv == 0 { 0 } else { min_tag }
    )
}

/// A mesh without a model: one surface entity per surface tag, every node on the first
/// surface that uses it.
fn write_plain(
    w: &mut impl Write,
    mesh: &Mesh,
    surfaces: &[i32],
    elements: &SurfaceElements,
) -> io::Result<()> {
    let ns = surfaces.len();
    let nv = mesh.vertices.len();
    let mut bbox = vec![EMPTY_BBOX; ns];
    for (k, b) in bbox.iter_mut().enumerate() {
        for v in elements.used(k) {
            grow(b, mesh.vertices[v as usize]);
        }
    }
    // Each node goes to the entity of the first surface that uses it (unused ones: the first).
    let mut by_owner: Vec<Vec<u32>> = vec![Vec::new(); ns];
    for (v, o) in elements.owners(nv).into_iter().enumerate() {
        by_owner[o.unwrap_or(0)].push(v as u32);
    }

    writeln!(w, "$MeshFormat\n4.1 0 8\n$EndMeshFormat")?;
    writeln!(w, "$Entities\n0 0 {ns} 0")?;
    for (k, &s) in surfaces.iter().enumerate() {
        let b = finite(bbox[k]);
        writeln!(
            w,
            "{s} {:?} {:?} {:?} {:?} {:?} {:?} 0 0",
            b[0], b[1], b[2], b[3], b[4], b[5]
        )?;
    }
    writeln!(w, "$EndEntities")?;

    let id = node_id(mesh);
    let node_blocks = by_owner.iter().filter(|b| !b.is_empty()).count();
    nodes_header(w, mesh, node_blocks)?;
    for (k, block) in by_owner.iter().enumerate() {
        if block.is_empty() {
            continue;
        }
        writeln!(w, "2 {} 0 {}", surfaces[k], block.len())?;
        for &v in block {
            writeln!(w, "{}", id(v))?;
        }
        for &v in block {
            let p = mesh.vertices[v as usize];
            writeln!(w, "{:?} {:?} {:?}", p[0], p[1], p[2])?;
        }
    }
    writeln!(w, "$EndNodes")?;

    let (blocks, ne) = elements.count();
    writeln!(
        w,
        "$Elements\n{blocks} {ne} {} {ne}",
        if ne == 0 { 0 } else { 1 }
    )?;
    elements.write(w, surfaces, &id, &mut 0)?;
    writeln!(w, "$EndElements")?;
    Ok(())
}

/// A mesh read from a Gmsh file: its model written back (see [`super::write`]).
fn write_model(
    w: &mut impl Write,
    mesh: &Mesh,
    model: &Model,
    surfaces: &[i32],
    elements: &SurfaceElements,
) -> io::Result<()> {
    let nv = mesh.vertices.len();
    let bad = |m: String| io::Error::new(io::ErrorKind::InvalidInput, m);
    if let Some(n) = model
        .physical_names
        .iter()
        .find(|n| n.name.contains(['"', '\n', '\r']) || n.dim > 3)
    {
        return Err(bad(format!(
            "physical group {} (dimension {}) has a name MSH cannot hold: {:?}",
            n.tag, n.dim, n.name
        )));
    }
    if let Some(e) = model.elements.iter().find(|e| {
        e.dim > 1
            || e.nodes.iter().any(|&v| v as usize >= nv)
            || super::element_type(e.gmsh_type)
                .is_none_or(|(n, d, _)| n != e.nodes.len() || d != e.dim)
    }) {
        return Err(bad(format!(
            "model element of type {} on entity ({}, {}) does not fit the mesh or its type",
            e.gmsh_type, e.dim, e.entity
        )));
    }

    // The entity of each node: the model's, else the first surface that uses it.
    let owners = elements.owners(nv);
    let on: Vec<(u8, i32)> = (0..nv)
        .map(|v| {
            model
                .node_entity
                .get(v)
                .copied()
                .flatten()
                .filter(|&(d, _)| d <= 3)
                .unwrap_or_else(|| (2, surfaces[owners[v].unwrap_or(0)]))
        })
        .collect();

    // Entities: the model's, then any that nodes or elements are on and it lacks.
    let mut entities: Vec<Entity> = model
        .entities
        .iter()
        .filter(|e| e.dim <= 3)
        .cloned()
        .collect();
    let mut index: BTreeMap<(u8, i32), usize> = BTreeMap::new();
    for (i, e) in entities.iter().enumerate() {
        index.entry((e.dim, e.tag)).or_insert(i);
    }
    let needed = on
        .iter()
        .copied()
        .chain(model.elements.iter().map(|e| (e.dim, e.entity)))
        .chain(surfaces.iter().map(|&s| (2, s)));
    for (dim, tag) in needed {
        index.entry((dim, tag)).or_insert_with(|| {
            entities.push(Entity {
                dim,
                tag,
                bbox: None,
                physicals: Vec::new(),
                bounding: Vec::new(),
            });
            entities.len() - 1
        });
    }
    // Boxes the model does not give: from the entity's nodes and elements.
    let mut grown: Vec<Bbox> = vec![EMPTY_BBOX; entities.len()];
    let without_box: Vec<bool> = entities.iter().map(|e| e.bbox.is_none()).collect();
    if without_box.iter().any(|&b| b) {
        let mut add = |key: (u8, i32), v: u32| {
            let i = index[&key];
            if without_box[i] {
                grow(&mut grown[i], mesh.vertices[v as usize]);
            }
        };
        for (v, &key) in on.iter().enumerate() {
            add(key, v as u32);
        }
        for e in &model.elements {
            for &v in &e.nodes {
                add((e.dim, e.entity), v);
            }
        }
        for (k, &s) in surfaces.iter().enumerate() {
            for v in elements.used(k) {
                add((2, s), v);
            }
        }
    }

    writeln!(w, "$MeshFormat\n4.1 0 8\n$EndMeshFormat")?;
    if !model.physical_names.is_empty() {
        writeln!(w, "$PhysicalNames\n{}", model.physical_names.len())?;
        for n in &model.physical_names {
            writeln!(w, "{} {} \"{}\"", n.dim, n.tag, n.name)?;
        }
        writeln!(w, "$EndPhysicalNames")?;
    }
    let per_dim = |d: u8| entities.iter().filter(move |e| e.dim == d);
    let counts = [0, 1, 2, 3].map(|d| per_dim(d).count());
    writeln!(
        w,
        "$Entities\n{} {} {} {}",
        counts[0], counts[1], counts[2], counts[3]
    )?;
    let tags = |v: &[i32]| -> String {
        let mut s = v.len().to_string();
        for t in v {
            s.push(' ');
            s.push_str(&t.to_string());
        }
        s
    };
    for d in 0..4u8 {
        for e in per_dim(d) {
            let b = finite(e.bbox.unwrap_or(grown[index[&(e.dim, e.tag)]]));
            if d == 0 {
                writeln!(
                    w,
                    "{} {:?} {:?} {:?} {}",
                    e.tag,
                    b[0],
                    b[1],
                    b[2],
                    tags(&e.physicals)
                )?;
            } else {
                writeln!(
                    w,
                    "{} {:?} {:?} {:?} {:?} {:?} {:?} {} {}",
                    e.tag,
                    b[0],
                    b[1],
                    b[2],
                    b[3],
                    b[4],
                    b[5],
                    tags(&e.physicals),
                    tags(&e.bounding)
                )?;
            }
        }
    }
    writeln!(w, "$EndEntities")?;

    // Nodes grouped by entity (dimension, then tag), by tag within each.
    let id = node_id(mesh);
    let mut blocks: BTreeMap<(u8, i32), Vec<u32>> = BTreeMap::new();
    for (v, &key) in on.iter().enumerate() {
        blocks.entry(key).or_default().push(v as u32);
    }
    nodes_header(w, mesh, blocks.len())?;
    let params = |v: u32| model.node_param.get(v as usize).copied().flatten();
    for (&(dim, tag), block) in &mut blocks {
        block.sort_by_key(|&v| id(v));
        let parametric = dim > 0 && block.iter().all(|&v| params(v).is_some());
        writeln!(w, "{dim} {tag} {} {}", u8::from(parametric), block.len())?;
        for &v in block.iter() {
            writeln!(w, "{}", id(v))?;
        }
        for &v in block.iter() {
            let p = mesh.vertices[v as usize];
            write!(w, "{:?} {:?} {:?}", p[0], p[1], p[2])?;
            if let (true, Some(u)) = (parametric, params(v)) {
                for x in &u[..dim as usize] {
                    write!(w, " {x:?}")?;
                }
            }
            writeln!(w)?;
        }
    }
    writeln!(w, "$EndNodes")?;

    // Elements: the model's points and lines, by entity and type, then the surfaces'
    // quads and triangles; numbered from 1 in that order.
    let mut lower: BTreeMap<(u8, i32, i64), Vec<&[u32]>> = BTreeMap::new();
    for e in &model.elements {
        let key = (e.dim, e.entity, e.gmsh_type);
        lower.entry(key).or_default().push(&e.nodes);
    }
    let (surface_blocks, surface_elements) = elements.count();
    let ne = surface_elements + model.elements.len();
    writeln!(
        w,
        "$Elements\n{} {ne} {} {ne}",
        lower.len() + surface_blocks,
        if ne == 0 { 0 } else { 1 }
    )?;
    let mut tag = 0u64;
    for ((dim, entity, gmsh_type), block) in &lower {
        writeln!(w, "{dim} {entity} {gmsh_type} {}", block.len())?;
        for nodes in block {
            tag += 1;
            write!(w, "{tag}")?;
            for &v in *nodes {
                write!(w, " {}", id(v))?;
            }
            writeln!(w)?;
        }
    }
    elements.write(w, surfaces, &id, &mut tag)?;
    writeln!(w, "$EndElements")?;
    Ok(())
}
