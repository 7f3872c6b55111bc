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

    /// The entity of dimension `dim` and tag `tag`, if the model has it.
    pub fn entity(&self, dim: u8, tag: i32) -> Option<&Entity> {
        self.entities.iter().find(|e| e.dim == dim && e.tag == tag)
    }
}
