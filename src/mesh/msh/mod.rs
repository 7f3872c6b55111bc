//! Gmsh MSH files: readers for versions 2.2 and 4.1, ASCII and binary, and the MSH 4.1 ASCII
//! writer.
//!
//! The parser is hand-written (the `mshio` crate reads 4.1 only and reports errors without
//! lines): one pass over the bytes, no allocation per line, node tags mapped to dense indices
//! (a vector when tags are compact, a hash map when they are sparse). Triangles (type 2) and
//! quads (type 3) are read with their element tag and geometric entity (surface) tag; points,
//! lines and other element types are counted in [`MshFile::ignored_elements`] and not
//! recombined. The file's [`Model`] (physical names, entities, node classification, points
//! and lines) is kept in [`MeshData::model`] and written back by [`write()`].
//! Binary files must be little-endian (checked with the format's int `1` marker) with 8-byte
//! `size_t`.
//!
//! Errors name the file and the line (ASCII files, [`ReadError::Syntax`]) or the byte offset
//! (binary files past their header, where binary data make line numbers meaningless:
//! [`ReadError::Io`] of kind `InvalidData` whose message starts with `byte offset N:`). Content errors found by [`Mesh::new`] come back as [`ReadError::Mesh`]
//! with the file's node and element tags.

mod model;
mod read;
mod write;

pub use model::{Element, Entity, Model, PhysicalName};

use super::{Mesh, MeshData, MeshError, ReadError, Recombined};
use std::fmt;
use std::path::Path;

pub(crate) use write::check_recombined;
pub use write::write_to;

/// MSH format version of a file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MshVersion {
    /// Version 2.2 (also read: 2.0 and 2.1, which share its layout).
    V22,
    /// Version 4.1.
    V41,
}

impl fmt::Display for MshVersion {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            MshVersion::V22 => "2.2",
            MshVersion::V41 => "4.1",
        })
    }
}

/// A parsed MSH file before validation: its content and what the format was.
#[derive(Debug, Clone)]
pub struct MshFile {
    /// Nodes, triangles and quads with the file's tags.
    pub data: MeshData,
    /// Format version.
    pub version: MshVersion,
    /// Binary (true) or ASCII.
    pub binary: bool,
    /// Elements that were skipped: of other types (points, lines, volumes, high order), on
    /// partition interfaces, ghost cells, and copies of an element for other physical groups.
    pub ignored_elements: usize,
    /// The same, per Gmsh element type (in increasing type number).
    pub skipped: Vec<SkippedElements>,
}

/// Elements of one Gmsh type that a reader skipped.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SkippedElements {
    /// Gmsh's element type number.
    pub gmsh_type: i64,
    /// Gmsh's name of the type ("Triangle 6", "Line 2", ...).
    pub name: &'static str,
    /// Dimension of the type (2: surface elements).
    pub dim: u8,
    /// How many were skipped.
    pub count: usize,
    /// Why they were skipped.
    pub why: SkipReason,
}

/// Why a reader skipped elements.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum SkipReason {
    /// Their type: points, lines, volumes, high-order and other surface elements.
    Type,
    /// On the interfaces between the volume partitions of a partitioned 3D mesh (MSH 4.1
    /// partition surfaces whose parent is a volume): triangles inside the volume, skipped
    /// whatever their type.
    PartitionInterface,
    /// Ghost cells: on a ghost entity of a partitioned mesh written one file per partition
    /// (copies of the neighbouring partitions' elements), skipped whatever their type.
    GhostCell,
    /// Exact copies of an element on an entity of two physical groups or more (MSH 2.2
    /// writes such an element once per group; Gmsh's re-saves of such a file repeat them):
    /// the first is kept, in every group.
    GroupCopy,
}

impl SkippedElements {
    /// True for surface elements of order 2 and up (Triangle 6, Quadrilateral 9, ...),
    /// which `setOrder(1)` turns into the triangles and quads that are read: the surface
    /// types with more than 4 nodes.
    pub fn is_high_order(&self) -> bool {
        self.dim == 2 && element_type(self.gmsh_type).is_some_and(|(nodes, _, _)| nodes > 4)
    }
}

impl fmt::Display for SkippedElements {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {} (type {})", self.count, self.name, self.gmsh_type)?;
        f.write_str(match self.why {
            SkipReason::Type => "",
            SkipReason::PartitionInterface => " on partition interfaces",
            SkipReason::GhostCell => " (ghost cells)",
            SkipReason::GroupCopy => " (copies for another physical group, merged)",
        })?;
        Ok(())
    }
}

impl MshFile {
    /// Validates the content into a [`Mesh`] (see [`Mesh::new`]); errors name `path`.
    /// A file whose only surface elements are of types not read (higher order, polygons,
    /// partition interfaces) says so, rather than that it has no triangles, and says how
    /// to make a high-order mesh first order.
    pub fn into_mesh(self, path: &Path) -> Result<Mesh, ReadError> {
        let surface: Vec<&SkippedElements> = self.skipped.iter().filter(|k| k.dim == 2).collect();
        let high_order = surface.iter().any(|k| k.is_high_order());
        let skipped: Vec<String> = surface.iter().map(ToString::to_string).collect();
        let no_triangles = self.data.triangles.is_empty();
        Mesh::new(self.data).map_err(|source| ReadError::Mesh {
            path: path.to_path_buf(),
            source: match source {
                MeshError::NoTriangles if no_triangles && !skipped.is_empty() => {
                    MeshError::OnlySkippedSurfaceElements {
                        skipped: skipped.join(", "),
                        hint: if high_order {
                            "; make the mesh first order, e.g. gmsh.model.mesh.setOrder(1) before writing it, or Gmsh's -order 1 option".into()
                        } else {
                            String::new()
                        },
                    }
                }
                e => e,
            },
        })
    }
}

/// Gmsh element type `t`: its number of nodes (0 for types without a fixed number, such as
/// polygons), dimension and Gmsh's name; `None` for a number Gmsh does not know. Elements
/// of every known type other than 2 (triangle) and 3 (quad) are skipped and counted.
pub fn element_type(t: i64) -> Option<(usize, u8, &'static str)> {
    read::element_type(t)
}

/// True when `bytes` look like a MSH file (they start with `$MeshFormat`).
pub fn is_msh(bytes: &[u8]) -> bool {
    read::looks_like_msh(bytes)
}

/// Parses MSH bytes (any supported version and type) without validating the content.
/// `path` names the source in errors.
pub fn parse(path: &Path, bytes: &[u8]) -> Result<MshFile, ReadError> {
    read::parse(path, bytes)
}

/// Reads and validates a MSH file.
pub fn read(path: &Path) -> Result<Mesh, ReadError> {
    let bytes = crate::mesh::load::read_file(path)?;
    let file = parse(path, &bytes)?;
    drop(bytes);
    file.into_mesh(path)
}

/// Reads and validates MSH content held in memory; `name` stands for the file in errors.
pub fn read_bytes(name: &str, bytes: &[u8]) -> Result<Mesh, ReadError> {
    let path = Path::new(name);
    parse(path, bytes)?.into_mesh(path)
}

/// Writes `mesh` recombined as `rec` to `path` as MSH 4.1 ASCII: per surface entity, one block
/// of quads (recombined and input quads, type 3) and one of leftover triangles (type 2), with
/// `$Entities` so that Gmsh opens it. A mesh read from a Gmsh file is written on its
/// [`Model`]: `$PhysicalNames`, its entities, every node on the entity it was classified on
/// (with its parametric coordinates), its point and line elements first; a mesh without one
/// (generated) has one surface entity per surface tag, each node on the first surface that
/// uses it. Node tags are the mesh's; elements are numbered from 1. The file is written whole
/// or not at all ([`crate::output::write_atomic`]): through a temporary file in `path`'s
/// directory (which must be writable), renamed over it, so on an error an existing file stays
/// as it was; a `path` that exists and is not a regular file (a directory, FIFO or device such
/// as `/dev/stdout`) is refused. To write a stream, use [`write_to`].
pub fn write(path: &Path, mesh: &Mesh, rec: &Recombined) -> Result<(), ReadError> {
    crate::output::write_atomic(path, |mut w| write_to(&mut w, mesh, rec)).map_err(|source| {
        ReadError::Io {
            path: path.to_path_buf(),
            source,
        }
    })
}
