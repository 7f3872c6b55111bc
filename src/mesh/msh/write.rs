//! The MSH 4.1 ASCII writer.

use crate::mesh::{Mesh, Recombined};
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

/// Writes MSH 4.1 ASCII (see [`super::write`]) to any writer.
pub fn write_to(w: &mut impl Write, mesh: &Mesh, rec: &Recombined) -> io::Result<()> {
    check_recombined(mesh, rec)?;
    let surfaces = written_surfaces(mesh, rec);
    let slot = |s: i32| surfaces.binary_search(&s).unwrap_or(0);
    let ns = surfaces.len();

    // Elements per surface: quads (recombined, then input) and triangles.
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

    // Each node goes to the entity of the first surface that uses it (unused ones: the first).
    let nv = mesh.vertices.len();
    let mut owner = vec![usize::MAX; nv];
    let mut bbox = vec![
        [
            f64::INFINITY,
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY
        ];
        ns
    ];
    for k in 0..ns {
        let used = quads[k].iter().flatten().chain(tris[k].iter().flatten());
        for &v in used {
            let v = v as usize;
            if owner[v] == usize::MAX {
                owner[v] = k;
            }
            let p = mesh.vertices[v];
            let b = &mut bbox[k];
            for d in 0..3 {
                b[d] = b[d].min(p[d]);
                b[d + 3] = b[d + 3].max(p[d]);
            }
        }
    }
    let mut by_owner: Vec<Vec<u32>> = vec![Vec::new(); ns];
    for (v, &o) in owner.iter().enumerate() {
        by_owner[if o == usize::MAX { 0 } else { o }].push(v as u32);
    }

    writeln!(w, "$MeshFormat\n4.1 0 8\n$EndMeshFormat")?;
    writeln!(w, "$Entities\n0 0 {ns} 0")?;
    for (k, &s) in surfaces.iter().enumerate() {
        let b = bbox[k].map(|x| if x.is_finite() { x } else { 0.0 });
        writeln!(
            w,
            "{s} {:?} {:?} {:?} {:?} {:?} {:?} 0 0",
            b[0], b[1], b[2], b[3], b[4], b[5]
        )?;
    }
    writeln!(w, "$EndEntities")?;

    let ids = &mesh.vertex_ids;
    let id = |v: u32| ids.get(v as usize).copied().unwrap_or(u64::from(v) + 1);
    let (min_tag, max_tag) = (0..nv as u32)
        .map(id)
        .fold((u64::MAX, 0), |(a, b), t| (a.min(t), b.max(t)));
    let node_blocks = by_owner.iter().filter(|b| !b.is_empty()).count();
    writeln!(
        w,
        "$Nodes\n{node_blocks} {nv} {} {max_tag}",
        if nv == 0 { 0 } else { min_tag }
    )?;
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

    let ne: usize =
        quads.iter().map(Vec::len).sum::<usize>() + tris.iter().map(Vec::len).sum::<usize>();
    let blocks = quads.iter().filter(|b| !b.is_empty()).count()
        + tris.iter().filter(|b| !b.is_empty()).count();
    writeln!(
        w,
        "$Elements\n{blocks} {ne} {} {ne}",
        if ne == 0 { 0 } else { 1 }
    )?;
    let mut tag = 0u64;
    for k in 0..ns {
        if !quads[k].is_empty() {
            writeln!(w, "2 {} 3 {}", surfaces[k], quads[k].len())?;
            for q in &quads[k] {
                tag += 1;
                writeln!(
                    w,
                    "{tag} {} {} {} {}",
                    id(q[0]),
                    id(q[1]),
                    id(q[2]),
                    id(q[3])
                )?;
            }
        }
        if !tris[k].is_empty() {
            writeln!(w, "2 {} 2 {}", surfaces[k], tris[k].len())?;
            for t in &tris[k] {
                tag += 1;
                writeln!(w, "{tag} {} {} {}", id(t[0]), id(t[1]), id(t[2]))?;
            }
        }
    }
    writeln!(w, "$EndElements")?;
    Ok(())
}
