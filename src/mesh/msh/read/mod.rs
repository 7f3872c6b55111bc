//! The hand-written MSH parser: 2.2 and 4.1, ASCII and binary (native little-endian, checked
//! with the int `1` marker). One pass over the bytes, no per-line allocation.
//!
//! This module is the entry: format sniffing, the `$MeshFormat` header, the loop over the
//! sections and the sections both versions share (`$PhysicalNames`, the choice of node
//! reader). The rest lives beside it: [`element_types`] (Gmsh's element-type table),
//! [`parser`] (the byte cursor, number parsing and error positions), [`content`] (what is
//! collected while reading: nodes, elements, the model), [`v41`] and [`v22`] (the
//! sections of each version).
//!
//! Errors in ASCII files carry the line ([`ReadError::Syntax`]); errors in binary files past
//! their header carry the byte offset (as [`ReadError::Io`] of kind `InvalidData`, whose
//! message names the offset).

mod content;
mod element_types;
mod parser;
mod v22;
mod v41;

use super::{MshFile, MshVersion, SkipReason, SkippedElements};
use crate::mesh::ReadError;
use crate::mesh::msh::model::PhysicalName;
use content::{Content, NodeMap};
use parser::{Parser, Res, show, to_i32};
use std::path::Path;
use v22::{elements22_ascii, elements22_binary, nodes22_ascii, nodes22_binary, parametric_nodes22};
use v41::{elements41, entities41, nodes41, partitioned41};

pub(super) use element_types::element_type;

/// True when `bytes` start (after whitespace and an optional UTF-8 BOM) with `$MeshFormat`.
pub(super) fn looks_like_msh(bytes: &[u8]) -> bool {
    let b = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let start = b
        .iter()
        .position(|c| !c.is_ascii_whitespace())
        .unwrap_or(b.len());
    b[start..].starts_with(b"$MeshFormat")
}

pub(super) fn parse(path: &Path, bytes: &[u8]) -> Result<MshFile, ReadError> {
    if bytes.iter().all(|c| c.is_ascii_whitespace()) {
        return Err(ReadError::Syntax {
            path: path.to_path_buf(),
            line: 1,
            message: "the file is empty".into(),
        });
    }
    if !looks_like_msh(bytes) {
        return Err(ReadError::unknown_format(path, bytes));
    }
    let mut p = Parser {
        path,
        b: bytes,
        pos: if bytes.starts_with(b"\xEF\xBB\xBF") {
            3
        } else {
            0
        },
        binary: false,
        in_line: false,
    };
    let fmt = "$MeshFormat";
    p.token(); // $MeshFormat
    if p.b.get(p.pos) == Some(&b'\r') && p.b.get(p.pos + 1) != Some(&b'\n') {
        return Err(p.err(
            p.pos,
            "the lines end with a lone carriage return (\\r, classic Mac OS line ends), not \\n or \\r\\n: convert them first, e.g. tr '\\r' '\\n' < IN.msh > OUT.msh",
        ));
    }
    let (vp, vt) = p.need(fmt, &|| "the version number".into())?;
    let version = match vt {
        b"4.1" => MshVersion::V41,
        b"2.2" | b"2.1" | b"2.0" | b"2" => MshVersion::V22,
        _ => {
            return Err(p.err(
                vp,
                format!(
                    "unsupported MSH version `{}` (quadrecomb reads versions 2.2 and 4.1): {}",
                    show(vt),
                    crate::mesh::error::resave_hint(path)
                ),
            ));
        }
    };
    let file_type = p.uint(fmt, &|| "the file type (0 = ASCII, 1 = binary)".into())?;
    let (dp, _) = p.need(fmt, &|| "the data size".into())?;
    let data_size = p.b[dp..p.pos].to_vec();
    match file_type {
        0 => {}
        1 => {
            p.binary = true;
            if data_size != b"8" {
                return Err(p.err(
                    dp,
                    format!(
                        "unsupported data size `{}` in a binary file (only 8 is read: the size of a double in MSH 2.2, of a size_t in MSH 4.1)",
                        show(&data_size)
                    ),
                ));
            }
            p.binary_data_start();
            let at = p.pos;
            let one = p.bin_i32(fmt, &|| "the endianness marker (int 1)".into())?;
            if one != 1 {
                let msg = if one.swap_bytes() == 1 {
                    "big-endian binary MSH files are not supported (the int 1 marker is byte-swapped)"
                        .to_string()
                } else {
                    format!("bad endianness marker {one} (expected the int 1)")
                };
                return Err(p.err_bin(at, msg));
            }
        }
        _ => {
            return Err(p.err(
                dp,
                format!("unknown file type {file_type} (expected 0 = ASCII or 1 = binary)"),
            ));
        }
    }
    p.end(fmt, &|| "the format line".into())?;

    let mut c = Content::new();
    while let Some((start, name)) = p.token() {
        match name {
            b"$Nodes" | b"$ParametricNodes" => {
                if c.map.is_some() {
                    return Err(p.err(start, "a second $Nodes section"));
                }
                let at_nodes = p.clone();
                let section = if name == b"$Nodes" {
                    read_nodes(&mut p, &mut c, version, false)?;
                    "$Nodes"
                } else if version == MshVersion::V22 {
                    read_nodes(&mut p, &mut c, version, true)?;
                    "$ParametricNodes"
                } else {
                    return Err(p.err(
                        start,
                        "a $ParametricNodes section in an MSH 4.1 file (4.1 keeps parametric coordinates in $Nodes; $ParametricNodes is MSH 2)",
                    ));
                };
                p.end(section, &|| format!("{} nodes", c.node_tags.len()))?;
                let map = NodeMap::new(&c.node_tags).map_err(|t| {
                    let parametric = section == "$ParametricNodes";
                    match duplicate_node(&at_nodes, version, parametric, t) {
                        Some((first, second)) => {
                            let first = if p.binary {
                                format!("byte {first}")
                            } else {
                                format!("line {}", p.line_of(first))
                            };
                            p.err(
                                second,
                                format!(
                                    "node tag {t} is defined twice in {section} (first on {first})"
                                ),
                            )
                        }
                        None => p.err(start, format!("node tag {t} is defined twice in {section}")),
                    }
                })?;
                c.data.vertex_ids = std::mem::take(&mut c.node_tags);
                c.map = Some(map);
            }
            b"$Elements" => {
                let Some(map) = c.map.take() else {
                    return Err(p.err(start, "$Elements comes before any $Nodes section"));
                };
                if !c.data.triangle_ids.is_empty()
                    || !c.data.quad_ids.is_empty()
                    || !c.skipped.is_empty()
                {
                    return Err(p.err(start, "a second $Elements section"));
                }
                let n = match (version, p.binary) {
                    (MshVersion::V41, _) => elements41(&mut p, &mut c, &map)?,
                    (MshVersion::V22, false) => elements22_ascii(&mut p, &mut c, &map)?,
                    (MshVersion::V22, true) => elements22_binary(&mut p, &mut c, &map)?,
                };
                c.merge_group_copies();
                p.end("$Elements", &|| format!("{n} elements"))?;
                c.map = Some(map);
            }
            b"$PhysicalNames" => {
                if !c.model.physical_names.is_empty() {
                    return Err(p.err(start, "a second $PhysicalNames section"));
                }
                physical_names(&mut p, &mut c)?;
            }
            b"$Entities" if version == MshVersion::V41 => {
                if c.model.entities.is_some() {
                    return Err(p.err(start, "a second $Entities section"));
                }
                entities41(&mut p, &mut c)?;
            }
            b"$PartitionedEntities" if version == MshVersion::V41 => {
                partitioned41(&mut p, &mut c)?;
                p.skip_section(start, name)?;
            }
            _ if name.first() == Some(&b'$') && !name.starts_with(b"$End") => {
                p.skip_section(start, name)?;
            }
            _ => {
                return Err(p.err(
                    start,
                    format!("unexpected `{}` outside any section", show(name)),
                ));
            }
        }
    }
    if !c.parents.is_empty() {
        // Elements of a partition's surface belong to the model surface it was cut from.
        let parents = &c.parents;
        for s in c
            .data
            .triangle_surface
            .iter_mut()
            .chain(&mut c.data.quad_surface)
        {
            if let Some(&parent) = parents.get(&i64::from(*s)) {
                *s = parent;
            }
        }
    }
    let skipped: Vec<SkippedElements> = (c.skipped.iter())
        .map(|(&(t, why), &n)| {
            let (_, dim, name) = element_type(t).expect("skipped types are known");
            SkippedElements {
                gmsh_type: t,
                name,
                dim,
                count: n,
                why,
            }
        })
        .collect();
    let mut model = c.model.finish(&c.data);
    model.not_written = (skipped.iter())
        .filter(|s| s.why == SkipReason::Type && s.dim >= 2)
        .cloned()
        .collect();
    c.data.model = Some(Box::new(model));
    Ok(MshFile {
        data: c.data,
        version,
        binary: p.binary,
        ignored_elements: c.skipped.values().sum(),
        skipped,
    })
}

/// The `$PhysicalNames` section (ASCII in binary files too): per group, its dimension,
/// tag and name in double quotes, on a line of its own.
fn physical_names(p: &mut Parser<'_>, c: &mut Content) -> Res<()> {
    let s = "$PhysicalNames";
    let n = p.uint(s, &|| "the number of physical names".into())?;
    for i in 0..n {
        let what = || format!("physical name {} of {n}", i + 1);
        let dp = p.pos;
        let dim = p.int(s, &what)?;
        p.in_line = true;
        let tp = p.pos;
        let tag = p.int(s, &what)?;
        let Some(dim) = u8::try_from(dim).ok().filter(|&d| d <= 3) else {
            return Err(p.err(
                dp,
                format!("physical group {tag} has dimension {dim} (expected 0 to 3)"),
            ));
        };
        let tag = to_i32(p, tp, tag, "physical tag")?;
        p.skip_ws();
        let b = p.b;
        let open = p.pos;
        let close = (b.get(open) == Some(&b'"'))
            .then(|| {
                b[open + 1..]
                    .iter()
                    .position(|&ch| ch == b'"' || ch == b'\n')
            })
            .flatten()
            .map(|k| open + 1 + k)
            .filter(|&k| b[k] == b'"');
        let Some(close) = close else {
            return Err(p.err(
                open,
                format!(
                    "the name of physical group {tag} (dimension {dim}) is not in double quotes on its line"
                ),
            ));
        };
        let name = String::from_utf8_lossy(&b[open + 1..close]).into_owned();
        p.pos = close + 1;
        p.entry_end(&|| format!("the name of physical group {tag}"))?;
        p.in_line = false;
        c.model.physical_names.push(PhysicalName { dim, tag, name });
    }
    p.end(s, &|| format!("{n} physical names"))
}

/// Reads a `$Nodes` (or, in MSH 2.2, `$ParametricNodes`) section after its name.
fn read_nodes(p: &mut Parser<'_>, c: &mut Content, v: MshVersion, parametric: bool) -> Res<()> {
    match (v, p.binary) {
        _ if parametric => parametric_nodes22(p, c),
        (MshVersion::V41, _) => nodes41(p, c),
        (MshVersion::V22, false) => nodes22_ascii(p, c),
        (MshVersion::V22, true) => nodes22_binary(p, c),
    }
}

/// Where the first two nodes tagged `tag` are, by reading the section again from `p0` and
/// noting where each tag is (only on this error path: no offsets are kept otherwise).
fn duplicate_node(
    p0: &Parser<'_>,
    v: MshVersion,
    parametric: bool,
    tag: u64,
) -> Option<(usize, usize)> {
    let mut p = p0.clone();
    let mut c = Content::new();
    c.tag_pos = Some(Vec::new());
    read_nodes(&mut p, &mut c, v, parametric).ok()?;
    let pos = c.tag_pos?;
    let mut at = (c.node_tags.iter().zip(&pos))
        .filter(|(t, _)| **t == tag)
        .map(|(_, &p)| p);
    Some((at.next()?, at.next()?))
}
