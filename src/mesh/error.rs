//! Typed errors for mesh input: what is wrong, and which element, node or line it concerns.
//!
//! `MeshError` says what is wrong with a mesh's *content* (geometry or topology);
//! `ReadError` wraps it with the file (and line, where a reader knows it) it came from.

use std::path::PathBuf;

/// Something wrong with a mesh's content. Element and node ids are the ones of the input
/// file (Gmsh tags), or 1-based indices for meshes that were built in memory.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeshError {
    #[error("the mesh is empty: no nodes and no elements")]
    Empty,
    #[error("the mesh has no triangles (nothing to recombine)")]
    NoTriangles,
    #[error(
        "the mesh has no 3-node triangles to recombine: its surface elements are {skipped}, which are not read (only 3-node triangles and 4-node quads are{hint})"
    )]
    OnlySkippedSurfaceElements {
        /// The skipped surface elements, per type ("212 Triangle 6 (type 9)").
        skipped: String,
        /// What to do about them, when there is something to do (high-order elements: make
        /// the mesh first order); empty otherwise.
        hint: String,
    },
    #[error(
        "the mesh is too large: {vertices} vertices, {triangles} triangles (at most 2^31 - 1 vertices and triangles, and fewer than 2^32 - 1 element sides: 3 per triangle, 4 per quad)"
    )]
    TooLarge { vertices: usize, triangles: usize },
    #[error("node {node} has a non-finite coordinate ({x}, {y}, {z})")]
    NonFiniteCoordinate { node: u64, x: f64, y: f64, z: f64 },
    #[error("element {element} refers to node {node}, which does not exist")]
    UnknownNode { element: u64, node: u64 },
    #[error("element {element} uses node {node} twice")]
    RepeatedNode { element: u64, node: u64 },
    #[error("triangle {element} is degenerate ({}): nodes {nodes:?}", flatness(*log10_height))]
    DegenerateTriangle {
        element: u64,
        nodes: [u64; 3],
        /// log10 of its smallest height over its longest edge (-inf for zero area).
        log10_height: f64,
    },
    #[error(
        "quad {element} is degenerate (its four nodes are collinear to within rounding: zero area): nodes {nodes:?}"
    )]
    DegenerateQuad { element: u64, nodes: [u64; 4] },
    #[error(
        "the mesh data's {field} holds {len} entries for {expected} {of} (one each, or none for the default)"
    )]
    Inconsistent {
        field: &'static str,
        len: usize,
        expected: usize,
        of: &'static str,
    },
    #[error("node tag {tag} is given to two vertices (tags must be unique)")]
    DuplicateNodeTag { tag: u64 },
    #[error(
        "element tag {tag} is given to two elements (tags must be unique: Gmsh would keep only the last one)"
    )]
    DuplicateElementTag { tag: u64 },
    #[error("triangle {element} duplicates triangle {first} (same three nodes)")]
    DuplicateTriangle { element: u64, first: u64 },
    #[error(
        "non-manifold edge between nodes {a} and {b}: shared by {count} elements of surface {surface} (first ones: {elements:?}; elements of different surfaces may share an edge, at most two of one surface)"
    )]
    NonManifoldEdge {
        a: u64,
        b: u64,
        surface: i32,
        count: usize,
        elements: Vec<u64>,
    },
    #[error(
        "surface {surface} is not orientable: triangles cannot be oriented consistently (conflict at triangle {element})"
    )]
    NonOrientable { surface: i32, element: u64 },
}

/// A mesh file that could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error(
        "{path}: unknown mesh format (expected a Gmsh .msh file, version 2.2 or 4.1, ASCII or binary, or a built-in name: {builtins}){hint}",
        hint = conversion_hint(.path)
    )]
    UnknownFormat { path: PathBuf, builtins: String },
    /// A compressed file, told by its first bytes (gzip, bzip2, xz, zstd, zip).
    #[error("{path}: the file is {what}: decompress it first (`{command}`) and give that file")]
    Compressed {
        path: PathBuf,
        what: &'static str,
        command: String,
    },
    #[error("{path}:{line}: {message}")]
    Syntax {
        path: PathBuf,
        line: usize,
        message: String,
    },
    #[error("{path}: {source}")]
    Mesh { path: PathBuf, source: MeshError },
    /// `suite:NAME` with a name the suite does not have.
    #[error("no suite mesh is named {name:?} (suite meshes: {names})")]
    UnknownSuiteMember { name: String, names: String },
}

impl ReadError {
    /// The error for `path`, whose first bytes `head` are no mesh quadrecomb reads: a
    /// compressed file (gzip, bzip2, xz, zstd, zip) gets the command that decompresses it,
    /// anything else [`ReadError::UnknownFormat`] with the conversion commands (Gmsh, given
    /// a gzip file, asks to uncompress it first).
    pub(crate) fn unknown_format(path: &std::path::Path, head: &[u8]) -> ReadError {
        const KINDS: [(&[u8], &str, &str); 5] = [
            (b"\x1f\x8b", "gzip-compressed", "gzip -dc"),
            (b"BZh", "bzip2-compressed", "bzip2 -dc"),
            (b"\xfd7zXZ\x00", "xz-compressed", "xz -dc"),
            (b"\x28\xb5\x2f\xfd", "zstd-compressed", "zstd -dc"),
            (b"PK\x03\x04", "a zip archive", "unzip -p"),
        ];
        let text = head.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(head);
        let blank = text.iter().take_while(|c| c.is_ascii_whitespace()).count();
        if let Some(section) = [&b"$NOD"[..], b"$ELM"]
            .iter()
            .find(|s| text[blank..].starts_with(s))
        {
            // Gmsh's legacy format (MSH 1.0), which Gmsh still reads and meshio does not.
            return ReadError::Syntax {
                path: path.to_path_buf(),
                line: 1 + text[..blank].iter().filter(|&&c| c == b'\n').count(),
                message: format!(
                    "this is Gmsh's legacy MSH 1.0 format (`{}`), which quadrecomb does not \
                     read (it reads versions 2.2 and 4.1): {}",
                    String::from_utf8_lossy(section),
                    resave_hint(path)
                ),
            };
        }
        let Some(&(_, what, tool)) = KINDS.iter().find(|k| head.starts_with(k.0)) else {
            return ReadError::UnknownFormat {
                path: path.to_path_buf(),
                builtins: super::builtin::NAMES.join(", "),
            };
        };
        // The name without its compression suffix, ending in .msh, and never the input's
        // own name (the shell would empty the input before the tool reads it).
        let compressed = ["gz", "bz2", "xz", "zst", "zip"];
        let mut out = path.to_path_buf();
        if out
            .extension()
            .is_some_and(|e| compressed.iter().any(|c| e.eq_ignore_ascii_case(c)))
        {
            out.set_extension("");
        }
        if !out
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("msh"))
        {
            out.as_mut_os_string().push(".msh");
        }
        // Never the input, nor a file that exists (the user's other mesh).
        if out == path || out.exists() {
            out.set_extension("decompressed.msh");
        }
        ReadError::Compressed {
            path: path.to_path_buf(),
            what,
            command: format!("{tool} {} > {}", shell_word(path), shell_word(&out)),
        }
    }
}

/// `path` as one word a POSIX shell reads back unchanged, and never as an option: quoted
/// (`'...'`, a `'` inside as `'\''`) unless it holds only characters no shell treats
/// specially, and prefixed with `./` when it begins with `-`.
fn shell_word(path: &std::path::Path) -> String {
    let mut s = path.to_string_lossy().into_owned();
    if s.starts_with('-') {
        s.insert_str(0, "./");
    }
    let plain = |c: char| c.is_ascii_alphanumeric() || "._/-+,:@%=".contains(c);
    if !s.is_empty() && s.chars().all(plain) {
        s
    } else {
        format!("'{}'", s.replace('\'', "'\\''"))
    }
}

/// Why a triangle of relative height `10^lg` is degenerate, in words.
fn flatness(lg: f64) -> String {
    if lg == f64::NEG_INFINITY || lg.is_nan() {
        "zero area".into()
    } else {
        format!(
            "flat to within rounding: its height is about 1e{:.0} times its longest edge, at \
             most 1e-14, so its angles cannot be told from 0 and 180 degrees",
            lg.round()
        )
    }
}

/// How to re-save a Gmsh file of a version quadrecomb does not read (1.0, 3.0, 4.0) as 4.1.
pub(crate) fn resave_hint(path: &std::path::Path) -> String {
    format!(
        "re-save it with Gmsh as version 4.1: `gmsh {} -0 -format msh41 -o {}`",
        path.display(),
        path.with_extension("41.msh").display()
    )
}

/// How to turn a mesh of another format into a `.msh` quadrecomb reads, naming the tools (Gmsh,
/// meshio) and the exact command for this file.
fn conversion_hint(path: &std::path::Path) -> String {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let what = match ext.as_str() {
        "stl" => "an STL triangulation",
        "vtk" | "vtu" | "vtp" => "a VTK file",
        "obj" => "a Wavefront OBJ file",
        "mesh" | "meshb" => "a Medit mesh",
        "ply" => "a PLY file",
        "off" => "an OFF file",
        "inp" => "an Abaqus input file",
        "med" => "a MED file",
        "unv" => "an I-DEAS universal file",
        "bdf" | "nas" => "a Nastran file",
        "cgns" => "a CGNS file",
        "su2" => "an SU2 mesh",
        _ => "",
    };
    if ext == "msh" {
        // Named .msh but not Gmsh's (ANSYS Fluent also uses .msh): no conversion to name.
        return "; the file does not begin with $MeshFormat (an ANSYS Fluent .msh is not \
                Gmsh's: convert it with `meshio convert FILE out.msh --output-format gmsh`)"
            .to_string();
    }
    let out = path.with_extension("msh");
    let (p, o) = (path.display(), out.display());
    let lead = if what.is_empty() {
        "if it is a mesh in another format".to_string()
    } else {
        format!("this looks like {what}")
    };
    format!(
        "; {lead}: convert it to .msh with Gmsh (`gmsh {p} -0 -format msh41 -o {o}`) or \
         meshio (`pip install meshio; meshio convert {p} {o} --output-format gmsh`)"
    )
}
