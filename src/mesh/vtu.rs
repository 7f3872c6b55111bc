//! VTK `.vtu` (XML unstructured grid) writer for ParaView, with per-cell quality.
//!
//! Hand-written: the file is a few XML elements, and `vtkio` (0.7.0-rc at the time) would add a
//! heavy dependency for it. By default the arrays are stored as VTK's own writer stores them:
//! zlib-compressed blocks of raw little-endian bytes in one `<AppendedData encoding="raw">`
//! section (`vtkZLibDataCompressor`; exact, and half the size of VTK's base64 default), or
//! inline as text on request
//! ([`Encoding::Ascii`]). Cells are quads (VTK type 9) and triangles (type 5), with three
//! cell-data arrays:
//! - `quality` (Float64): eta of each recombined quad; `-1` for leftover triangles and for
//!   quads that were in the input (no eta is computed for them);
//! - `surface` (Int32): the geometric entity (surface) tag;
//! - `kind` (UInt8): `0` recombined quad, `1` leftover triangle, `2` input quad.
//!
//! and one point-data array, `node` (UInt64): each point's node tag in the input file. The
//! points are every node of the input in the loaded mesh's order (spatial, not the file's:
//! [`super::order`]), so `node` is what maps them back to the input.

use super::{Mesh, ReadError, Recombined};
use std::io::{self, Write};
use std::path::Path;

/// `kind` of a recombined quad.
pub const KIND_RECOMBINED: u8 = 0;
/// `kind` of a leftover triangle.
pub const KIND_TRIANGLE: u8 = 1;
/// `kind` of a quad that was in the input.
pub const KIND_INPUT_QUAD: u8 = 2;

/// How the data arrays are stored in the file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Encoding {
    /// zlib-compressed raw little-endian blocks in the appended section (VTK header type
    /// UInt64, 32 KiB blocks).
    #[default]
    Binary,
    /// Whitespace-separated text inside each `<DataArray>`; floats written so that they read
    /// back to the same f64.
    Ascii,
}

/// Writes `mesh` recombined as `rec` to `path` as a binary `.vtu` file, whole or not at all
/// ([`crate::output::write_atomic`]): through a temporary file in `path`'s directory (which
/// must be writable), renamed over it, so on an error an existing file stays as it was; a
/// `path` that exists and is not a regular file (a directory, FIFO or device such as
/// `/dev/stdout`) is refused. To write a stream, use [`write_to`].
pub fn write(path: &Path, mesh: &Mesh, rec: &Recombined) -> Result<(), ReadError> {
    crate::output::write_atomic(path, |mut w| write_to(&mut w, mesh, rec, Encoding::Binary))
        .map_err(|source| ReadError::Io {
            path: path.to_path_buf(),
            source,
        })
}

/// One data array of the file.
enum Values {
    F64(Vec<f64>),
    I64(Vec<i64>),
    U64(Vec<u64>),
    I32(Vec<i32>),
    U8(Vec<u8>),
}

impl Values {
    fn vtk_type(&self) -> &'static str {
        match self {
            Values::F64(_) => "Float64",
            Values::I64(_) => "Int64",
            Values::U64(_) => "UInt64",
            Values::I32(_) => "Int32",
            Values::U8(_) => "UInt8",
        }
    }

    /// The values as text, `per_line` to a line.
    fn write_ascii(&self, w: &mut dyn Write, per_line: usize) -> io::Result<()> {
        fn lines<T>(
            w: &mut dyn Write,
            v: &[T],
            n: usize,
            f: impl Fn(&T) -> String,
        ) -> io::Result<()> {
            for chunk in v.chunks(n.max(1)) {
                let line: Vec<String> = chunk.iter().map(&f).collect();
                writeln!(w, "{}", line.join(" "))?;
            }
            Ok(())
        }
        match self {
            Values::F64(v) => lines(w, v, per_line, |x| format!("{x:?}")),
            Values::I64(v) => lines(w, v, per_line, i64::to_string),
            Values::U64(v) => lines(w, v, per_line, u64::to_string),
            Values::I32(v) => lines(w, v, per_line, i32::to_string),
            Values::U8(v) => lines(w, v, per_line, u8::to_string),
        }
    }

    /// The values as little-endian bytes.
    fn bytes(&self) -> Vec<u8> {
        match self {
            Values::F64(v) => v.iter().flat_map(|x| x.to_le_bytes()).collect(),
            Values::I64(v) => v.iter().flat_map(|x| x.to_le_bytes()).collect(),
            Values::U64(v) => v.iter().flat_map(|x| x.to_le_bytes()).collect(),
            Values::I32(v) => v.iter().flat_map(|x| x.to_le_bytes()).collect(),
            Values::U8(v) => v.clone(),
        }
    }
}

/// Uncompressed bytes per compressed block, as VTK's writer uses.
const BLOCK: usize = 1 << 15;

/// One array's bytes as VTK's zlib-compressed appended block: a header of UInt64 (number of
/// blocks, uncompressed block size, uncompressed size of a partial last block or 0, then each
/// block's compressed size), then the zlib streams one after the other.
fn compressed_block(bytes: &[u8]) -> io::Result<Vec<u8>> {
    use flate2::{Compression, write::ZlibEncoder};
    let mut streams = Vec::new();
    for chunk in bytes.chunks(BLOCK) {
        let mut z = ZlibEncoder::new(Vec::new(), Compression::fast());
        z.write_all(chunk)?;
        streams.push(z.finish()?);
    }
    let header = [streams.len(), BLOCK, bytes.len() % BLOCK]
        .into_iter()
        .chain(streams.iter().map(Vec::len));
    let mut out: Vec<u8> = header.flat_map(|n| (n as u64).to_le_bytes()).collect();
    streams.iter().for_each(|s| out.extend_from_slice(s));
    Ok(out)
}

/// A named data array: name (empty for the points), components, values, values per text line.
struct Array {
    name: &'static str,
    components: usize,
    values: Values,
    per_line: usize,
}

/// Writes the `.vtu` content to any writer, with the arrays stored as `encoding` says.
pub fn write_to(
    w: &mut impl Write,
    mesh: &Mesh,
    rec: &Recombined,
    encoding: Encoding,
) -> io::Result<()> {
    super::msh::check_recombined(mesh, rec)?;
    // Cells: recombined quads, input quads, leftover triangles.
    let mut cells: Vec<(&[u32], f64, i32, u8)> = Vec::new();
    for (i, (q, &s)) in rec.quads.iter().zip(&rec.quad_surface).enumerate() {
        let eta = rec.quad_eta.get(i).copied().unwrap_or(-1.0);
        cells.push((q, eta, s, KIND_RECOMBINED));
    }
    for (q, &s) in mesh.quads.iter().zip(&mesh.quad_surface) {
        cells.push((q, -1.0, s, KIND_INPUT_QUAD));
    }
    for &t in &rec.leftover {
        let t = t as usize;
        cells.push((
            &mesh.triangles[t],
            -1.0,
            mesh.triangle_surface[t],
            KIND_TRIANGLE,
        ));
    }
    let array = |name, components, values, per_line| Array {
        name,
        components,
        values,
        per_line,
    };
    let points = array(
        "",
        3,
        Values::F64(mesh.vertices.iter().flatten().copied().collect()),
        3,
    );
    let node = array("node", 1, Values::U64(mesh.vertex_ids.clone()), 1);
    let mut offsets = Vec::with_capacity(cells.len());
    let mut off = 0;
    for (c, ..) in &cells {
        off += c.len() as i64;
        offsets.push(off);
    }
    let cell_arrays = [
        array(
            "connectivity",
            1,
            Values::I64(
                cells
                    .iter()
                    .flat_map(|c| c.0.iter().map(|&v| v as i64))
                    .collect(),
            ),
            4,
        ),
        array("offsets", 1, Values::I64(offsets), 1),
        array(
            "types",
            1,
            Values::U8(
                cells
                    .iter()
                    .map(|c| if c.0.len() == 4 { 9 } else { 5 })
                    .collect(),
            ),
            1,
        ),
    ];
    let cell_data = [
        array(
            "quality",
            1,
            Values::F64(cells.iter().map(|c| c.1).collect()),
            1,
        ),
        array(
            "surface",
            1,
            Values::I32(cells.iter().map(|c| c.2).collect()),
            1,
        ),
        array(
            "kind",
            1,
            Values::U8(cells.iter().map(|c| c.3).collect()),
            1,
        ),
    ];

    let all: Vec<&Array> = std::iter::once(&points)
        .chain(&cell_arrays)
        .chain(&cell_data)
        .chain(std::iter::once(&node))
        .collect();
    // Binary: each array's compressed block, and its offset in the appended data.
    let blocks: Vec<Vec<u8>> = match encoding {
        Encoding::Binary => {
            (all.iter().map(|a| compressed_block(&a.values.bytes()))).collect::<io::Result<_>>()?
        }
        Encoding::Ascii => Vec::new(),
    };
    let mut offsets = blocks.iter().scan(0, |at, b| {
        let here = *at;
        *at += b.len();
        Some(here)
    });
    let mut element = |w: &mut dyn Write, a: &Array| -> io::Result<()> {
        let name = if a.name.is_empty() {
            String::new()
        } else {
            format!(r#" Name="{}""#, a.name)
        };
        let comps = if a.components > 1 {
            format!(r#" NumberOfComponents="{}""#, a.components)
        } else {
            String::new()
        };
        let ty = a.values.vtk_type();
        match offsets.next() {
            None => {
                writeln!(w, r#"<DataArray type="{ty}"{name}{comps} format="ascii">"#)?;
                a.values.write_ascii(w, a.per_line)?;
                writeln!(w, "</DataArray>")
            }
            Some(offset) => writeln!(
                w,
                r#"<DataArray type="{ty}"{name}{comps} format="appended" offset="{offset}"/>"#
            ),
        }
    };
    let compressor = match encoding {
        Encoding::Binary => r#" compressor="vtkZLibDataCompressor""#,
        Encoding::Ascii => "",
    };
    writeln!(w, r#"<?xml version="1.0"?>"#)?;
    writeln!(
        w,
        r#"<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64"{compressor}>"#
    )?;
    writeln!(w, "<UnstructuredGrid>")?;
    writeln!(
        w,
        r#"<Piece NumberOfPoints="{}" NumberOfCells="{}">"#,
        mesh.vertices.len(),
        cells.len()
    )?;
    writeln!(w, "<Points>")?;
    element(w, &points)?;
    writeln!(w, "</Points>\n<Cells>")?;
    for a in &cell_arrays {
        element(w, a)?;
    }
    writeln!(w, "</Cells>")?;
    writeln!(w, r#"<CellData Scalars="quality">"#)?;
    for a in &cell_data {
        element(w, a)?;
    }
    writeln!(w, "</CellData>")?;
    writeln!(w, "<PointData>")?;
    element(w, &node)?;
    writeln!(w, "</PointData>\n</Piece>\n</UnstructuredGrid>")?;
    if encoding == Encoding::Binary {
        // The data start after the underscore; meshio drops the line break before the
        // closing tag, VTK reads by the offsets.
        write!(w, "<AppendedData encoding=\"raw\">\n_")?;
        blocks.iter().try_for_each(|b| w.write_all(b))?;
        writeln!(w, "\n</AppendedData>")?;
    }
    writeln!(w, "</VTKFile>")
}
