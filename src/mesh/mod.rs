//! The triangle mesh: geometry (vertices, triangles, input quads, surface tags) and the
//! topology built once from it (edges, dual graph, components). Imports nothing of ours.

pub mod builtin;
mod error;
pub mod generate;
mod load;
#[cfg(test)]
mod load_memory;
pub mod msh;
pub mod order;
pub mod suite;
pub(crate) mod topology;
pub mod vtu;

pub use load::{Source, file_kind, load, read_file, source};

pub use error::{MeshError, ReadError};
pub use topology::{Edges, Topology};

/// Marker for "no triangle / no candidate" in `u32` index arrays.
pub const NONE: u32 = u32::MAX;

/// A surface mesh of triangles (and, optionally, quads given in the input, which are kept as
/// they are and never recombined). Build it with [`Mesh::new`], which validates the input,
/// orients every surface consistently and builds the topology.
#[derive(Debug, Clone)]
pub struct Mesh {
    /// Vertex coordinates; planar meshes have z = 0.
    pub vertices: Vec<[f64; 3]>,
    /// Node id of each vertex in the input file (Gmsh node tag), for messages and output.
    pub vertex_ids: Vec<u64>,
    /// Triangles as vertex indices, oriented consistently within each surface.
    pub triangles: Vec<[u32; 3]>,
    /// Element id of each triangle in the input file (Gmsh element tag).
    pub triangle_ids: Vec<u64>,
    /// Geometric entity (surface tag) of each triangle. Only triangles of the same surface
    /// are neighbours in the dual graph.
    pub triangle_surface: Vec<i32>,
    /// Quads present in the input, kept as quads.
    pub quads: Vec<[u32; 4]>,
    /// Surface tag of each input quad.
    pub quad_surface: Vec<i32>,
    /// Number of triangles whose orientation was flipped to make their surface consistent.
    pub reoriented: usize,
    /// The Gmsh model of the input file (physical groups, entities, node classification,
    /// point and line elements), which the MSH writer writes back; `None` for generated
    /// meshes.
    pub model: Option<Box<msh::Model>>,
    /// Dual graph, numbers of edges and boundary edges, components (the edges themselves:
    /// [`Mesh::edges`]).
    pub topology: Topology,
}

/// The raw content of a mesh before validation, as a reader or a generator produces it.
#[derive(Debug, Clone, Default)]
pub struct MeshData {
    pub vertices: Vec<[f64; 3]>,
    /// Node tag of each vertex; empty means 1-based indices.
    pub vertex_ids: Vec<u64>,
    pub triangles: Vec<[u32; 3]>,
    /// Element tag of each triangle; empty means 1-based indices.
    pub triangle_ids: Vec<u64>,
    /// Surface tag of each triangle; empty means every triangle is on surface 1.
    pub triangle_surface: Vec<i32>,
    pub quads: Vec<[u32; 4]>,
    /// Element tag of each quad; empty means numbered after the triangles.
    pub quad_ids: Vec<u64>,
    /// Surface tag of each quad; empty means surface 1.
    pub quad_surface: Vec<i32>,
    /// The Gmsh model of a file (see [`msh::Model`]); its per-vertex arrays follow
    /// `vertices`. `None` for generated meshes.
    pub model: Option<Box<msh::Model>>,
}

impl MeshData {
    /// Fills the defaults ([`MeshData::materialise_defaults`]) and checks what every element
    /// must satisfy, triangle or quad: finite coordinates, nodes that exist, no node twice in
    /// one element. [`Mesh::new`] does this first; a mesh of quads only (which it refuses:
    /// nothing to recombine) can still be checked and described.
    pub fn check_elements(&mut self) -> Result<(), MeshError> {
        self.materialise_defaults();
        let nv = self.vertices.len();
        let (nt, nq) = (self.triangles.len(), self.quads.len());
        for (field, len, expected, of) in [
            ("vertex_ids", self.vertex_ids.len(), nv, "vertices"),
            ("triangle_ids", self.triangle_ids.len(), nt, "triangles"),
            (
                "triangle_surface",
                self.triangle_surface.len(),
                nt,
                "triangles",
            ),
            ("quad_ids", self.quad_ids.len(), nq, "quads"),
            ("quad_surface", self.quad_surface.len(), nq, "quads"),
        ] {
            if len != expected {
                return Err(MeshError::Inconsistent {
                    field,
                    len,
                    expected,
                    of,
                });
            }
        }
        if let Some(tag) = repeated(self.vertex_ids.iter().copied()) {
            return Err(MeshError::DuplicateNodeTag { tag });
        }
        for (i, p) in self.vertices.iter().enumerate() {
            if !p.iter().all(|c| c.is_finite()) {
                return Err(MeshError::NonFiniteCoordinate {
                    node: self.vertex_ids[i],
                    x: p[0],
                    y: p[1],
                    z: p[2],
                });
            }
        }
        let elements = self
            .triangles
            .iter()
            .map(|t| &t[..])
            .zip(&self.triangle_ids)
            .chain(self.quads.iter().map(|q| &q[..]).zip(&self.quad_ids));
        for (nodes, &element) in elements {
            for (k, &v) in nodes.iter().enumerate() {
                if v as usize >= nv {
                    // Readers map unknown tags to indices past the end; report the index as
                    // given.
                    return Err(MeshError::UnknownNode {
                        element,
                        node: v as u64 + 1,
                    });
                }
                if nodes[..k].contains(&v) {
                    return Err(MeshError::RepeatedNode {
                        element,
                        node: self.vertex_ids[v as usize],
                    });
                }
            }
        }
        // Input quads of zero area, here so that a file of quads only (`info`) is checked too.
        for (q, quad) in self.quads.iter().enumerate() {
            if topology::quad_is_flat(quad.map(|v| self.vertices[v as usize])) {
                return Err(MeshError::DegenerateQuad {
                    element: self.quad_ids[q],
                    nodes: quad.map(|v| self.vertex_ids[v as usize]),
                });
            }
        }
        if let Some(tag) = repeated(self.triangle_ids.iter().chain(&self.quad_ids).copied()) {
            return Err(MeshError::DuplicateElementTag { tag });
        }
        Ok(())
    }

    /// Distinct surface tags of the triangles and quads, sorted (after
    /// [`MeshData::materialise_defaults`]).
    pub fn surfaces(&self) -> Vec<i32> {
        distinct_surfaces(&self.triangle_surface, &self.quad_surface)
    }

    /// Fills the tags and surfaces left empty with what empty means: nodes and triangles
    /// numbered from 1, quads numbered after the triangles, everything on surface 1.
    pub fn materialise_defaults(&mut self) {
        let (nv, nt, nq) = (self.vertices.len(), self.triangles.len(), self.quads.len());
        if self.vertex_ids.is_empty() {
            self.vertex_ids = (1..=nv as u64).collect();
        }
        if self.triangle_ids.is_empty() {
            self.triangle_ids = (1..=nt as u64).collect();
        }
        if self.triangle_surface.is_empty() {
            self.triangle_surface = vec![1; nt];
        }
        if self.quad_ids.is_empty() {
            self.quad_ids = (nt as u64 + 1..=(nt + nq) as u64).collect();
        }
        if self.quad_surface.is_empty() {
            self.quad_surface = vec![1; nq];
        }
    }
}

impl Mesh {
    /// Validates `data` and builds the mesh: finite coordinates, node indices in range, no
    /// repeated node in an element, no zero-area or duplicate triangle, no edge shared by more
    /// than two elements of one surface (surfaces may meet three or more at an edge);
    /// inconsistent orientations are fixed (and counted in `reoriented`) where the surface is
    /// orientable, and an error otherwise.
    pub fn new(data: MeshData) -> Result<Mesh, MeshError> {
        topology::build(data)
    }

    /// Number of triangles.
    pub fn num_triangles(&self) -> usize {
        self.triangles.len()
    }

    /// Coordinates of the three corners of triangle `t`.
    pub fn triangle_points(&self, t: u32) -> [[f64; 3]; 3] {
        self.triangles[t as usize].map(|v| self.vertices[v as usize])
    }

    /// Distinct surface tags, sorted.
    pub fn surfaces(&self) -> Vec<i32> {
        distinct_surfaces(&self.triangle_surface, &self.quad_surface)
    }

    /// The unique edges, each triangle side's edge and the boundary edges, computed (`O(n)`,
    /// 24 to 32 bytes per triangle): the mesh does not keep them, the searches never read
    /// them.
    pub fn edges(&self) -> Edges {
        topology::edges(self)
    }

    /// Checks every invariant of the mesh and its topology; returns the first violation.
    /// Meant for tests and debugging (`O(n log n)`).
    pub fn sanity_check(&self) -> Result<(), String> {
        topology::sanity_check(self)
    }
}

/// A recombined mesh ready to be written: the quads made by merging triangle pairs (with their
/// quality), the input quads, and the triangles left over. Built by
/// `quality::recombined`; writers take it so that `mesh` needs nothing from later modules.
#[derive(Debug, Clone, Default)]
pub struct Recombined {
    /// Quads made by recombination, vertex indices in boundary order.
    pub quads: Vec<[u32; 4]>,
    /// Surface tag of each recombined quad.
    pub quad_surface: Vec<i32>,
    /// eta of each recombined quad.
    pub quad_eta: Vec<f64>,
    /// Indices (into `Mesh::triangles`) of the triangles left unrecombined.
    pub leftover: Vec<u32>,
}

impl Recombined {
    /// Nothing recombined: every triangle of `mesh` left over (to write a plain mesh).
    pub fn unrecombined(mesh: &Mesh) -> Recombined {
        Recombined {
            leftover: (0..mesh.num_triangles() as u32).collect(),
            ..Recombined::default()
        }
    }
}

/// The smallest value that occurs more than once, if any (one pass when the values
/// increase, as files usually number their elements).
fn repeated(values: impl Iterator<Item = u64> + Clone) -> Option<u64> {
    let mut last = None;
    if values
        .clone()
        .all(|v| last.replace(v).is_none_or(|l| l < v))
    {
        return None;
    }
    let mut v: Vec<u64> = values.collect();
    v.sort_unstable();
    v.windows(2).find(|w| w[0] == w[1]).map(|w| w[0])
}

/// Distinct tags of `a` and `b`, sorted.
fn distinct_surfaces(a: &[i32], b: &[i32]) -> Vec<i32> {
    let mut s: Vec<i32> = a.iter().chain(b).copied().collect();
    s.sort_unstable();
    s.dedup();
    s
}
