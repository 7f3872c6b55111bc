//! VTK `.vtu` (XML unstructured grid, ASCII) writer for ParaView, with per-cell quality.
//!
//! Hand-written: the file is a few XML elements, and `vtkio` (0.7.0-rc at the time) would add a
//! heavy dependency for it. Cells are quads (VTK type 9) and triangles (type 5), with three
//! cell-data arrays:
//! - `quality` (Float64): eta of each recombined quad; `-1` for leftover triangles and for
//!   quads that were in the input (no eta is computed for them);
//! - `surface` (Int32): the geometric entity (surface) tag;
//! - `kind` (UInt8): `0` recombined quad, `1` leftover triangle, `2` input quad.

use super::{Mesh, ReadError, Recombined};
use std::io::{self, Write};
use std::path::Path;

/// `kind` of a recombined quad.
pub const KIND_RECOMBINED: u8 = 0;
/// `kind` of a leftover triangle.
pub const KIND_TRIANGLE: u8 = 1;
/// `kind` of a quad that was in the input.
pub const KIND_INPUT_QUAD: u8 = 2;

/// Writes `mesh` recombined as `rec` to `path` as a `.vtu` file.
pub fn write(path: &Path, mesh: &Mesh, rec: &Recombined) -> Result<(), ReadError> {
    let io = |source| ReadError::Io {
        path: path.to_path_buf(),
        source,
    };
    let file = std::fs::File::create(path).map_err(io)?;
    let mut w = io::BufWriter::new(file);
    write_to(&mut w, mesh, rec).map_err(io)?;
    w.flush().map_err(io)
}

/// Writes the `.vtu` content to any writer.
pub fn write_to(w: &mut impl Write, mesh: &Mesh, rec: &Recombined) -> io::Result<()> {
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

    writeln!(w, r#"<?xml version="1.0"?>"#)?;
    writeln!(
        w,
        r#"<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">"#
    )?;
    writeln!(w, "<UnstructuredGrid>")?;
    writeln!(
        w,
        r#"<Piece NumberOfPoints="{}" NumberOfCells="{}">"#,
        mesh.vertices.len(),
        cells.len()
    )?;
    writeln!(w, "<Points>")?;
    writeln!(
        w,
        r#"<DataArray type="Float64" NumberOfComponents="3" format="ascii">"#
    )?;
    for p in &mesh.vertices {
        writeln!(w, "{:?} {:?} {:?}", p[0], p[1], p[2])?;
    }
    writeln!(w, "</DataArray>\n</Points>\n<Cells>")?;
    writeln!(
        w,
        r#"<DataArray type="Int64" Name="connectivity" format="ascii">"#
    )?;
    for (c, ..) in &cells {
        let line: Vec<String> = c.iter().map(u32::to_string).collect();
        writeln!(w, "{}", line.join(" "))?;
    }
    writeln!(w, "</DataArray>")?;
    writeln!(
        w,
        r#"<DataArray type="Int64" Name="offsets" format="ascii">"#
    )?;
    let mut off = 0;
    for (c, ..) in &cells {
        off += c.len();
        writeln!(w, "{off}")?;
    }
    writeln!(w, "</DataArray>")?;
    writeln!(w, r#"<DataArray type="UInt8" Name="types" format="ascii">"#)?;
    for (c, ..) in &cells {
        writeln!(w, "{}", if c.len() == 4 { 9 } else { 5 })?;
    }
    writeln!(w, "</DataArray>\n</Cells>")?;
    writeln!(w, r#"<CellData Scalars="quality">"#)?;
    writeln!(
        w,
        r#"<DataArray type="Float64" Name="quality" format="ascii">"#
    )?;
    for (_, eta, ..) in &cells {
        writeln!(w, "{eta:?}")?;
    }
    writeln!(w, "</DataArray>")?;
    writeln!(
        w,
        r#"<DataArray type="Int32" Name="surface" format="ascii">"#
    )?;
    for (_, _, s, _) in &cells {
        writeln!(w, "{s}")?;
    }
    writeln!(w, "</DataArray>")?;
    writeln!(w, r#"<DataArray type="UInt8" Name="kind" format="ascii">"#)?;
    for (.., k) in &cells {
        writeln!(w, "{k}")?;
    }
    writeln!(
        w,
        "</DataArray>\n</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>"
    )?;
    Ok(())
}
