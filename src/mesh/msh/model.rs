//! The Gmsh model a MSH file carries besides its triangles: physical group names, the
//! entities (points, curves, surfaces, volumes) with their physical tags and bounding
//! entities, the entity each node is classified on (with its parametric coordinates), and
//! the point and line elements. The readers fill it; the writer writes it back, so that Gmsh
//! can go on from a recombined mesh (smooth it without moving boundary nodes, refine it,
//! keep its boundary conditions).

/// The name of a physical group (`$PhysicalNames`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PhysicalName {
    /// Dimension of the group (0 to 3).
    pub dim: u8,
    /// The group's tag.
    pub tag: i32,
    /// Its name, without the quotes.
    pub name: String,
}

/// A model entity.
#[derive(Debug, Clone, PartialEq)]
pub struct Entity {
    /// Dimension: 0 point, 1 curve, 2 surface, 3 volume.
    pub dim: u8,
    /// The entity's tag (unique within its dimension).
    pub tag: i32,
    /// A point's coordinates twice, or the bounding box (`min x, min y, min z, max x, max y,
    /// max z`) as the file gives it; `None` where the file has no `$Entities` (MSH 2.2): the
    /// writer computes it from the entity's nodes.
    pub bbox: Option<[f64; 6]>,
    /// Tags of the physical groups (of the same dimension) the entity belongs to.
    pub physicals: Vec<i32>,
    /// Tags of the bounding entities of dimension `dim - 1`, signed for their orientation
    /// (empty for points, and for entities read from MSH 2.2, which has no topology).
    pub bounding: Vec<i32>,
}

/// A point or line element of the input (any Gmsh type of dimension 0 or 1 with a fixed
/// number of nodes).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Element {
    /// Gmsh element type (15: point, 1: 2-node line, ...).
    pub gmsh_type: i64,
    /// Dimension of the type (0 or 1), and of the entity the element is on.
    pub dim: u8,
    /// Tag of the entity the element is on.
    pub entity: i32,
    /// The element's nodes, as vertex indices of the mesh.
    pub nodes: Vec<u32>,
}

/// The model of a Gmsh file (see the module docs). Per-vertex arrays follow the mesh's
/// vertex order: [`Model::renumber`] keeps them in step when the vertices are permuted.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Model {
    /// `$PhysicalNames`, in file order.
    pub physical_names: Vec<PhysicalName>,
    /// The entities: those of `$Entities` (MSH 4.1), or those the elements and nodes are on
    /// (MSH 2.2, physical tags from the elements'), by dimension then in file order.
    pub entities: Vec<Entity>,
    /// The entity (dimension, tag) each vertex is classified on; `None` where the file does
    /// not say (an MSH 2.2 node that no element uses).
    pub node_entity: Vec<Option<(u8, i32)>>,
    /// The parametric coordinates of each vertex on its entity (one on a curve, two on a
    /// surface, three in a volume; the rest 0), where the file has them; empty when no
    /// node has any.
    pub node_param: Vec<Option<[f64; 3]>>,
    /// The point and line elements, in file order.
    pub elements: Vec<Element>,
    /// The input's elements that a written `.msh` lacks, per type: volume elements, high-order
    /// and other surface elements that are not read ([`super::SkipReason::Type`], dimension
    /// 2 and up; points and lines are written back, partition interfaces, ghost cells and
    /// group copies are not the model's own).
    pub not_written: Vec<super::SkippedElements>,
}

impl Model {
    /// Follows a permutation of the vertices: new vertex `i` is old vertex `from[i]`, old
    /// vertex `v` is new vertex `new_index[v]`.
    pub fn renumber(&mut self, from: &[u32], new_index: &[u32]) {
        if self.node_entity.len() == from.len() {
            self.node_entity = from.iter().map(|&v| self.node_entity[v as usize]).collect();
        }
        if self.node_param.len() == from.len() {
            self.node_param = from.iter().map(|&v| self.node_param[v as usize]).collect();
        }
        for e in &mut self.elements {
            for v in &mut e.nodes {
                if let Some(&n) = new_index.get(*v as usize) {
                    *v = n;
                }
            }
        }
    }

    /// What a `.msh` written from `mesh` on this model leaves out, for a warning: the
    /// elements of [`Model::not_written`] and the physical groups then left with no element,
    /// or `None` when nothing is left out.
    pub fn not_written_note(&self, mesh: &crate::mesh::Mesh) -> Option<String> {
        if self.not_written.is_empty() {
            return None;
        }
        let surfaces: std::collections::BTreeSet<i32> = (mesh.triangle_surface.iter())
            .chain(&mesh.quad_surface)
            .copied()
            .collect();
        let has_elements = |e: &Entity| match e.dim {
            0 | 1 => (self.elements.iter()).any(|x| x.dim == e.dim && x.entity == e.tag),
            2 => surfaces.contains(&e.tag),
            _ => false,
        };
        let mut groups = std::collections::BTreeMap::new();
        for e in &self.entities {
            for &p in &e.physicals {
                *groups.entry((e.dim, p)).or_insert(false) |= has_elements(e);
            }
        }
        let empty: Vec<String> = (groups.into_iter())
            .filter(|&(_, written)| !written)
            .map(|((dim, tag), _)| {
                let name = (self.physical_names.iter())
                    .find(|n| n.dim == dim && n.tag == tag)
                    .map_or(String::new(), |n| format!("\"{}\" ", n.name));
                format!("{name}(dimension {dim}, tag {tag})")
            })
            .collect();
        let what: Vec<String> = self.not_written.iter().map(ToString::to_string).collect();
        Some(format!(
            "the input's {} are not written (only the surface mesh is recombined: volume and \
             high-order elements are not carried over){}",
            what.join(", "),
            if empty.is_empty() {
                String::new()
            } else {
                format!(
                    "; physical groups left with no element: {}",
                    empty.join(", ")
                )
            }
        ))
    }

    /// The entity of dimension `dim` and tag `tag`, if the model has it.
    pub fn entity(&self, dim: u8, tag: i32) -> Option<&Entity> {
        self.entities.iter().find(|e| e.dim == dim && e.tag == tag)
    }
}
