//! The MSH 2.2 sections (also 2.0 and 2.1), in either encoding: `$Nodes`,
//! `$ParametricNodes` and `$Elements` (one element per record, its tags before its nodes).

use super::content::{
    Content, NodeMap, check_block_nodes, check_node, parametric, push_element, push_lower,
};
use super::element_types::{
    MAX_LOWER_NODES, QUAD, TRIANGLE, element_nodes, element_type, is_lower, unknown_type,
    variable_size,
};
use super::parser::{Parser, Res, cap, check_finite, f64_at, i32_at, parse_u64, to_i32};
use crate::mesh::msh::SkipReason;

pub(super) fn nodes22_ascii(p: &mut Parser<'_>, c: &mut Content) -> Res<()> {
    let s = "$Nodes";
    let total = p.uint(s, &|| "the number of nodes".into())?;
    let left = p.b.len() - p.pos;
    c.node_tags.reserve(cap(total, 8, left));
    c.data.vertices.reserve(cap(total, 8, left));
    for i in 0..total {
        let tag = p.uint(s, &|| format!("the tag of node {} of {total}", i + 1))?;
        if tag == 0 {
            return Err(p.err(p.pos, "bad node tag 0 (tags are positive)"));
        }
        let what = || format!("a coordinate of node {tag}");
        p.entry_start();
        let (at, x) = p.float(s, &what)?;
        let (_, y) = p.float(s, &what)?;
        let (_, z) = p.float(s, &what)?;
        p.entry_end(&|| format!("the coordinates of node {tag}"))?;
        check_finite(p, at, tag, [x, y, z])?;
        c.node_tags.push(tag);
        c.note_tag(p.pos);
        c.data.vertices.push([x, y, z]);
    }
    Ok(())
}

/// The `$ParametricNodes` section of MSH 2.2 (written instead of `$Nodes` with Gmsh's
/// `Mesh.SaveParametric`), in either encoding: per node, its tag, coordinates, the
/// dimension and tag of the entity it is on, and its parametric coordinates on that entity
/// (one on a curve, two on a surface, none on a point or volume), which are read past.
pub(super) fn parametric_nodes22(p: &mut Parser<'_>, c: &mut Content) -> Res<()> {
    let s = "$ParametricNodes";
    let total = p.uint(s, &|| "the number of nodes".into())?;
    p.binary_data_start();
    let left = p.b.len() - p.pos;
    let min_bytes = if p.binary { 36 } else { 12 };
    c.node_tags.reserve(cap(total, min_bytes, left));
    c.data.vertices.reserve(cap(total, min_bytes, left));
    c.model.node_entity.reserve(cap(total, min_bytes, left));
    for i in 0..total {
        let tp = p.pos;
        let tag = p.int_field(s, &|| format!("the tag of node {} of {total}", i + 1))?;
        if tag <= 0 {
            return Err(p.err(tp, format!("bad node tag {tag} (tags are positive)")));
        }
        p.entry_start();
        let what = || format!("a coordinate of node {tag}");
        let cp = p.pos;
        let x = [
            p.double_field(s, &what)?,
            p.double_field(s, &what)?,
            p.double_field(s, &what)?,
        ];
        let what = || format!("the entity of node {tag}");
        let dp = p.pos;
        let dim = p.int_field(s, &what)?;
        let ep = p.pos;
        let entity = p.int_field(s, &what)?;
        let params = match dim {
            0 | 3 => 0,
            1 => 1,
            2 => 2,
            _ => {
                return Err(p.err(
                    dp,
                    format!("node {tag} is on an entity of dimension {dim} (expected 0 to 3)"),
                ));
            }
        };
        let entity = to_i32(p, ep, entity, "entity tag")?;
        let mut u = [0.0; 3];
        for slot in u.iter_mut().take(params) {
            *slot = p.double_field(s, &|| format!("a parametric coordinate of node {tag}"))?;
        }
        p.entry_end(&|| {
            format!("the coordinates, entity and parametric coordinates of node {tag}")
        })?;
        check_finite(p, cp, tag as u64, x)?;
        c.node_tags.push(tag as u64);
        c.note_tag(if p.binary { tp } else { p.pos });
        c.data.vertices.push(x);
        c.model.node_entity.push(Some((dim as u8, entity)));
        c.model.push_param(parametric(params, u));
    }
    Ok(())
}

pub(super) fn nodes22_binary(p: &mut Parser<'_>, c: &mut Content) -> Res<()> {
    let s = "$Nodes";
    let total = p.uint(s, &|| "the number of nodes".into())?;
    p.binary_data_start();
    let at = p.pos;
    let data = p.take_array(total, 28, s, &|| format!("{total} nodes"))?;
    c.node_tags.reserve(total as usize);
    c.data.vertices.reserve(total as usize);
    for (i, v) in data.chunks_exact(28).enumerate() {
        let tag = i32_at(v, 0);
        let pos = at + 28 * i;
        if tag <= 0 {
            return Err(p.err_bin(pos, format!("bad node tag {tag} (tags are positive)")));
        }
        let x = [f64_at(v, 4), f64_at(v, 12), f64_at(v, 20)];
        check_finite(p, pos, tag as u64, x)?;
        c.node_tags.push(tag as u64);
        c.note_tag(pos);
        c.data.vertices.push(x);
    }
    Ok(())
}

/// Surface of an MSH 2.2 element: its elementary tag (the second tag), else 0 (as Gmsh
/// reads it: an element without one is on entity 0, not on another surface).
fn surface22(tags: &[i64]) -> i64 {
    tags.get(1).copied().unwrap_or(0)
}

pub(super) fn elements22_ascii(p: &mut Parser<'_>, c: &mut Content, map: &NodeMap) -> Res<u64> {
    let s = "$Elements";
    let total = p.uint(s, &|| "the number of elements".into())?;
    let left = p.b.len() - p.pos;
    let k = cap(total, 12, left);
    c.data.triangles.reserve(k);
    c.data.triangle_ids.reserve(k);
    c.data.triangle_surface.reserve(k);
    let mut nodes = [0u64; MAX_LOWER_NODES];
    for i in 0..total {
        let (at, tt) = p.need(s, &|| format!("element {} of {total}", i + 1))?;
        let tag = parse_u64(tt).ok_or_else(|| {
            p.bad_token(at, tt, s, &|| {
                format!("the tag of element {} of {total}", i + 1)
            })
        })?;
        p.entry_start();
        let tp = p.pos;
        let etype = p.int(s, &|| format!("the type of element {tag}"))?;
        let Some((nn, dim, _)) = element_type(etype) else {
            return Err(p.err(tp, unknown_type(&format!("element {tag}"), etype)));
        };
        let ntags = p.uint(s, &|| format!("the number of tags of element {tag}"))?;
        let mut tags = [0i64; 2];
        for k in 0..ntags {
            let v = p.int(s, &|| format!("a tag of element {tag}"))?;
            if let Some(slot) = tags.get_mut(k as usize) {
                *slot = v;
            }
        }
        let keep = etype == TRIANGLE || etype == QUAD;
        let lower = is_lower(dim, nn);
        if !keep {
            c.skip(etype, 1, SkipReason::Type);
        }
        let volume = if dim == 3 {
            let used = &tags[..(ntags as usize).min(2)];
            let entity = to_i32(p, at, surface22(used), "elementary tag")?;
            c.model
                .on_entity(3, entity, to_i32(p, at, tags[0], "physical tag")?);
            Some(entity)
        } else {
            None
        };
        if nn == 0 {
            p.skip_line();
            continue;
        }
        for k in 0..nn {
            let v = p.uint(s, &|| format!("node {} of element {tag}", k + 1))?;
            if let (true, Some(slot)) = (keep || lower, nodes.get_mut(k)) {
                *slot = v;
            } else {
                check_node(p, map, at, tag, v)?;
                if let (Some(entity), Some(i)) = (volume, map.get(v)) {
                    c.model.in_volume(i, entity);
                }
            }
        }
        p.entry_end(&|| element_nodes(tag, etype, nn))?;
        if keep || lower {
            let used = &tags[..(ntags as usize).min(2)];
            let entity = to_i32(p, at, surface22(used), "elementary tag")?;
            let physical = to_i32(p, at, tags[0], "physical tag")?;
            c.model.on_entity(dim, entity, physical);
            if keep {
                push_element(p, c, map, at, tag, entity, &nodes[..nn])?;
            } else {
                push_lower(p, c, map, at, tag, (etype, dim), entity, &nodes[..nn])?;
            }
        }
    }
    Ok(total)
}

pub(super) fn elements22_binary(p: &mut Parser<'_>, c: &mut Content, map: &NodeMap) -> Res<u64> {
    let s = "$Elements";
    let total = p.uint(s, &|| "the number of elements".into())?;
    p.binary_data_start();
    let mut seen = 0u64;
    let mut nodes = [0u64; MAX_LOWER_NODES];
    while seen < total {
        let hp = p.pos;
        let what = || format!("the header of an element group ({seen} of {total} elements read)");
        let etype = i64::from(p.bin_i32(s, &what)?);
        let n = p.bin_i32(s, &what)?;
        let ntags = p.bin_i32(s, &what)?;
        if n <= 0 || n as u64 > total - seen || ntags < 0 {
            return Err(p.err_bin(
                hp,
                format!(
                    "bad element group header: type {etype}, {n} elements, {ntags} tags ({} of {total} elements left)",
                    total - seen
                ),
            ));
        }
        let Some((nn, dim, name)) = element_type(etype) else {
            return Err(p.err(hp, unknown_type("an element group", etype)));
        };
        if nn == 0 {
            return Err(p.err(hp, variable_size("an element group", etype, name)));
        }
        let ntags = ntags as usize;
        let stride = 4 * (1 + ntags + nn);
        let at0 = p.pos;
        let data = p.take_array(n as u64, stride, s, &|| {
            let plural = if n == 1 { "" } else { "s" };
            format!("a group of {n} element{plural} of type {etype}")
        })?;
        let keep = etype == TRIANGLE || etype == QUAD;
        if keep || is_lower(dim, nn) {
            for (i, e) in data.chunks_exact(stride).enumerate() {
                let at = at0 + i * stride;
                let tag = i32_at(e, 0);
                if tag <= 0 {
                    return Err(p.err_bin(at, format!("bad element tag {tag} (tags are positive)")));
                }
                let physical = if ntags >= 1 { i32_at(e, 4) } else { 0 };
                let surface = if ntags >= 2 { i32_at(e, 8) } else { 0 };
                for (k, slot) in nodes.iter_mut().take(nn).enumerate() {
                    let v = i32_at(e, 4 * (1 + ntags + k));
                    *slot = u64::try_from(v).unwrap_or(0);
                }
                c.model.on_entity(dim, surface, physical);
                if keep {
                    push_element(p, c, map, at, tag as u64, surface, &nodes[..nn])?;
                } else {
                    let t = (etype, dim);
                    push_lower(p, c, map, at, tag as u64, t, surface, &nodes[..nn])?;
                }
            }
        } else {
            // Refused as in a kept group: what the skipped elements name must exist too.
            if let Some(i) = data.chunks_exact(stride).position(|e| i32_at(e, 0) <= 0) {
                let tag = i32_at(&data[i * stride..], 0);
                let at = at0 + i * stride;
                return Err(p.err_bin(at, format!("bad element tag {tag} (tags are positive)")));
            }
            let tag = |e: &[u8]| i32_at(e, 0);
            let node = |e: &[u8], k: usize| i32_at(e, 4 * (1 + ntags + k));
            // A negative node tag is looked up as 0, which no node has (tags are positive).
            let key = |v: i32| u64::try_from(v).unwrap_or(0);
            check_block_nodes(p, map, data, at0, stride, nn, tag, node, key)?;
            if dim == 3 {
                for e in data.chunks_exact(stride) {
                    let physical = if ntags >= 1 { i32_at(e, 4) } else { 0 };
                    let volume = if ntags >= 2 { i32_at(e, 8) } else { 0 };
                    c.model.on_entity(3, volume, physical);
                    for k in 0..nn {
                        if let Some(i) = map.get(key(node(e, k))) {
                            c.model.in_volume(i, volume);
                        }
                    }
                }
            }
        }
        if !keep {
            c.skip(etype, n as u64, SkipReason::Type);
        }
        seen += n as u64;
    }
    Ok(total)
}
