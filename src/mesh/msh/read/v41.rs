//! The MSH 4.1 sections, in either encoding: `$Entities`, `$PartitionedEntities`, `$Nodes`
//! (blocks per entity, with parametric coordinates) and `$Elements` (blocks per entity and
//! type).

use super::content::{
    Content, NodeMap, check_block_nodes, check_node, parametric, push_element, push_lower,
};
use super::element_types::{
    MAX_LOWER_NODES, QUAD, TRIANGLE, element_nodes, element_type, is_lower, unknown_type,
    variable_size,
};
use super::parser::{Parser, Res, cap, check_finite, f64_at, parse_u64, to_i32, u64_at};
use crate::mesh::msh::SkipReason;
use crate::mesh::msh::model::Entity;

/// The `$PartitionedEntities` section of MSH 4.1 (a mesh split into partitions, whose
/// elements are on new entities, one per partition and model entity): the parent of each
/// partition surface, into `c.parents`, or, for a surface cut from a volume (an interface
/// between volume partitions), its tag into `c.interfaces`; the parent of every partition
/// entity (volumes included: their nodes go to the parent volume) into `c.model.parents`.
pub(super) fn partitioned41(p: &mut Parser<'_>, c: &mut Content) -> Res<()> {
    let s = "$PartitionedEntities";
    p.binary_data_start();
    p.size_t(s, &|| "the number of partitions".into())?;
    let ghosts = p.size_t(s, &|| "the number of ghost entities".into())?;
    for _ in 0..ghosts {
        let tag = p.int_field(s, &|| "a ghost entity tag".into())?;
        p.int_field(s, &|| "a ghost entity's partition".into())?;
        c.ghosts.insert(tag);
    }
    let counts: Vec<u64> = ["points", "curves", "surfaces", "volumes"]
        .iter()
        .map(|what| p.size_t(s, &|| format!("the number of partition {what}")))
        .collect::<Res<_>>()?;
    for (dim, &count) in counts.iter().enumerate() {
        for i in 0..count {
            let what = || format!("partition entity {} of dimension {dim}", i + 1);
            let tag = p.int_field(s, &what)?;
            let parent_dim = p.int_field(s, &what)?;
            let pp = p.pos;
            let parent = p.int_field(s, &what)?;
            let parts = p.size_t(s, &what)?;
            for _ in 0..parts {
                p.int_field(s, &what)?;
            }
            // A point has its coordinates, a curve or surface its bounding box.
            for _ in 0..if dim == 0 { 3 } else { 6 } {
                p.double_field(s, &what)?;
            }
            let physicals = p.size_t(s, &what)?;
            for _ in 0..physicals {
                p.int_field(s, &what)?;
            }
            if dim > 0 {
                let bounding = p.size_t(s, &what)?;
                for _ in 0..bounding {
                    p.int_field(s, &what)?;
                }
            }
            if let (Ok(t), Ok(pd @ 0..=3), Ok(pt)) = (
                i32::try_from(tag),
                u8::try_from(parent_dim),
                i32::try_from(parent),
            ) {
                c.model.parents.insert((dim as u8, t), (pd, pt));
            }
            if dim == 2 {
                match parent_dim {
                    2 => {
                        c.parents
                            .insert(tag, to_i32(p, pp, parent, "parent entity tag")?);
                    }
                    3 => {
                        c.interfaces.insert(tag);
                    }
                    _ => {}
                }
            }
        }
    }
    Ok(())
}

/// The `$Entities` section of MSH 4.1, in either encoding: points (tag, coordinates,
/// physical tags), then curves, surfaces and volumes (tag, bounding box, physical tags,
/// signed tags of the bounding entities).
pub(super) fn entities41(p: &mut Parser<'_>, c: &mut Content) -> Res<()> {
    let s = "$Entities";
    p.binary_data_start();
    let counts: Vec<u64> = ["points", "curves", "surfaces", "volumes"]
        .iter()
        .map(|what| p.size_t(s, &|| format!("the number of {what}")))
        .collect::<Res<_>>()?;
    let mut entities = Vec::new();
    for (dim, &count) in counts.iter().enumerate() {
        for i in 0..count {
            let what = || format!("entity {} of dimension {dim} in $Entities", i + 1);
            let tp = p.pos;
            let tag = p.int_field(s, &what)?;
            let tag = to_i32(p, tp, tag, "entity tag")?;
            let cp = p.pos;
            let mut bbox = [0.0; 6];
            let coordinates = if dim == 0 { 3 } else { 6 };
            for x in bbox.iter_mut().take(coordinates) {
                *x = p.double_field(s, &what)?;
            }
            if dim == 0 {
                bbox.copy_within(0..3, 3);
            }
            if !bbox.iter().all(|x| x.is_finite()) {
                let msg = format!("entity {tag} of dimension {dim} has a non-finite coordinate");
                return Err(p.err(cp, msg));
            }
            let tags = |p: &mut Parser<'_>, kind: &str| -> Res<Vec<i32>> {
                let n = p.size_t(s, &what)?;
                let mut v = Vec::new();
                for _ in 0..n {
                    let at = p.pos;
                    let t = p.int_field(s, &what)?;
                    v.push(to_i32(p, at, t, kind)?);
                }
                Ok(v)
            };
            let physicals = tags(p, "physical tag")?;
            let bounding = if dim > 0 {
                tags(p, "bounding entity tag")?
            } else {
                Vec::new()
            };
            entities.push(Entity {
                dim: dim as u8,
                tag,
                bbox: Some(bbox),
                physicals,
                bounding,
            });
        }
    }
    p.end(s, &|| format!("{} entities", entities.len()))?;
    c.model.entities = Some(entities);
    Ok(())
}

/// The header of an MSH 4.1 `$Nodes` or `$Elements` section (`item`: "node" or
/// "element"): where it starts, the number of entity blocks and of items (the tag range is
/// not used).
fn header41(p: &mut Parser<'_>, s: &str, item: &str) -> Res<(usize, u64, u64)> {
    p.binary_data_start();
    let hp = p.pos;
    let blocks = p.size_t(s, &|| "the number of entity blocks".into())?;
    p.entry_start();
    let total = p.size_t(s, &|| format!("the number of {item}s"))?;
    p.size_t(s, &|| format!("the minimum {item} tag"))?;
    p.size_t(s, &|| format!("the maximum {item} tag"))?;
    p.entry_end(&|| format!("the {s} header"))?;
    Ok((hp, blocks, total))
}

/// Where a block header starts: in ASCII its first value (past the line end before it, so
/// that an error there names the header's line), in binary the next byte.
fn header_start(p: &mut Parser<'_>) -> usize {
    if !p.binary {
        p.skip_ws();
    }
    p.pos
}

/// The `$Nodes` section of MSH 4.1, in either encoding: the headers read alike, the
/// blocks' tags and coordinates per encoding.
pub(super) fn nodes41(p: &mut Parser<'_>, c: &mut Content) -> Res<()> {
    let s = "$Nodes";
    let (hp, blocks, total) = header41(p, s, "node")?;
    let left = p.b.len() - p.pos;
    let min_bytes = if p.binary { 32 } else { 8 };
    c.node_tags.reserve(cap(total, min_bytes, left));
    c.data.vertices.reserve(cap(total, min_bytes, left));
    c.model.node_entity.reserve(cap(total, min_bytes, left));
    for blk in 0..blocks {
        let what_blk = || format!("the header of node block {} of {blocks}", blk + 1);
        let dp = header_start(p);
        let dim = p.int_field(s, &what_blk)?;
        p.entry_start();
        let ep = p.pos;
        let entity = p.int_field(s, &what_blk)?;
        let parametric = p.int_field(s, &what_blk)?;
        let bp = p.pos;
        let n = p.size_t(s, &what_blk)?;
        p.entry_end(&what_blk)?;
        let have = c.node_tags.len() as u64;
        if n > total - have.min(total) {
            return Err(p.err(
                bp,
                format!(
                    "node block {} holds {n} nodes, more than the {total} nodes announced in the header",
                    blk + 1
                ),
            ));
        }
        let Some(dim) = u8::try_from(dim).ok().filter(|&d| d <= 3) else {
            return Err(p.err(
                dp,
                format!(
                    "node block {} is on an entity of dimension {dim} (expected 0 to 3)",
                    blk + 1
                ),
            ));
        };
        let entity = (dim, to_i32(p, ep, entity, "entity tag")?);
        let extra = match parametric {
            0 => 0,
            1 => dim as usize,
            _ => {
                return Err(p.err(
                    bp,
                    format!("bad parametric flag {parametric} for an entity of dimension {dim}"),
                ));
            }
        };
        c.node_block_entities.insert(entity);
        let block = NodeBlock41 {
            index: blk,
            len: n,
            entity,
            extra,
        };
        if p.binary {
            node_block41_binary(p, c, &block)?;
        } else {
            node_block41_ascii(p, c, &block)?;
        }
    }
    if c.node_tags.len() as u64 != total {
        return Err(p.err(
            hp,
            format!(
                "the $Nodes header announces {total} nodes but its blocks hold {}",
                c.node_tags.len()
            ),
        ));
    }
    Ok(())
}

/// An MSH 4.1 node block's header.
struct NodeBlock41 {
    /// 0-based position among the section's blocks.
    index: u64,
    /// Number of nodes.
    len: u64,
    /// The entity (dimension, tag) the nodes are on.
    entity: (u8, i32),
    /// Parametric coordinates per node (0 when the block has none).
    extra: usize,
}

/// Records the entity and parametric coordinates (`extra` of `params`) of a node.
fn classify_node(c: &mut Content, b: &NodeBlock41, params: [f64; 3]) {
    c.model.node_entity.push(Some(b.entity));
    c.model.push_param(parametric(b.extra, params));
}

/// The tags, then coordinates (with their parametric ones), of an ASCII node block.
fn node_block41_ascii(p: &mut Parser<'_>, c: &mut Content, b: &NodeBlock41) -> Res<()> {
    let s = "$Nodes";
    let (blk, n, extra) = (b.index, b.len, b.extra);
    for i in 0..n {
        let tag = p.uint(s, &|| format!("node tag {} of block {}", i + 1, blk + 1))?;
        if tag == 0 {
            return Err(p.err(p.pos, "bad node tag 0 (tags are positive)"));
        }
        p.entry_start();
        p.entry_end(&|| format!("node tag {tag}"))?;
        c.node_tags.push(tag);
        c.note_tag(p.pos);
    }
    let first = c.node_tags.len() - n as usize;
    for i in 0..n as usize {
        let tag = c.node_tags[first + i];
        let what = || format!("a coordinate of node {tag}");
        let (at, x) = p.float(s, &what)?;
        p.entry_start();
        let (_, y) = p.float(s, &what)?;
        let (_, z) = p.float(s, &what)?;
        check_finite(p, at, tag, [x, y, z])?;
        let mut params = [0.0; 3];
        for u in params.iter_mut().take(extra) {
            *u = p
                .float(s, &|| format!("a parametric coordinate of node {tag}"))?
                .1;
        }
        p.entry_end(&|| format!("the coordinates of node {tag}"))?;
        c.data.vertices.push([x, y, z]);
        classify_node(c, b, params);
    }
    Ok(())
}

/// The same for a binary node block.
fn node_block41_binary(p: &mut Parser<'_>, c: &mut Content, b: &NodeBlock41) -> Res<()> {
    let s = "$Nodes";
    let (blk, n, extra) = (b.index, b.len, b.extra);
    let what_tags = || format!("the node tags of block {}", blk + 1);
    let tp = p.pos;
    let tags = p.take_array(n, 8, s, &what_tags)?;
    if let Some(i) = tags.chunks_exact(8).position(|t| u64_at(t, 0) == 0) {
        return Err(p.err_bin(tp + 8 * i, "bad node tag 0 (tags are positive)"));
    }
    c.node_tags
        .extend(tags.chunks_exact(8).map(|t| u64_at(t, 0)));
    if c.tag_pos.is_some() {
        (0..n as usize).for_each(|i| c.note_tag(tp + 8 * i));
    }
    let first = c.node_tags.len() - n as usize;
    let stride = 8 * (3 + extra);
    let cp = p.pos;
    let what_xyz = || format!("the coordinates of block {}", blk + 1);
    let xyz = p.take_array(n, stride, s, &what_xyz)?;
    for (i, v) in xyz.chunks_exact(stride).enumerate() {
        let x = [f64_at(v, 0), f64_at(v, 8), f64_at(v, 16)];
        check_finite(p, cp + i * stride, c.node_tags[first + i], x)?;
        c.data.vertices.push(x);
        let mut params = [0.0; 3];
        for (k, u) in params.iter_mut().take(extra).enumerate() {
            *u = f64_at(v, 24 + 8 * k);
        }
        classify_node(c, b, params);
    }
    Ok(())
}

/// The `$Elements` section of MSH 4.1, in either encoding: the headers read alike, the
/// blocks' elements per encoding. Returns the number of elements.
pub(super) fn elements41(p: &mut Parser<'_>, c: &mut Content, map: &NodeMap) -> Res<u64> {
    let s = "$Elements";
    let (hp, blocks, total) = header41(p, s, "element")?;
    let mut seen = 0u64;
    for blk in 0..blocks {
        let what_blk = || format!("the header of element block {} of {blocks}", blk + 1);
        let dp = header_start(p);
        let entity_dim = p.int_field(s, &what_blk)?;
        p.entry_start();
        let ep = p.pos;
        let entity = p.int_field(s, &what_blk)?;
        let tp = p.pos;
        let etype = p.int_field(s, &what_blk)?;
        let bp = p.pos;
        let n = p.size_t(s, &what_blk)?;
        p.entry_end(&what_blk)?;
        if n > total - seen.min(total) {
            return Err(p.err(
                bp,
                format!(
                    "element block {} holds {n} elements, more than the {total} announced in the header",
                    blk + 1
                ),
            ));
        }
        let surface = to_i32(p, ep, entity, "entity tag")?;
        let Some((nodes, dim, name)) = element_type(etype) else {
            return Err(p.err(
                tp,
                unknown_type(&format!("element block {}", blk + 1), etype),
            ));
        };
        // Gmsh refuses elements on an entity of another dimension ("Trying to add
        // unsupported element in curve 2"): which entity they were meant for is unknown.
        if entity_dim != i64::from(dim) {
            return Err(p.err(
                dp,
                format!(
                    "element block {} holds {name} elements (type {etype}, dimension {dim}) but is on an entity of dimension {entity_dim} (tag {entity}); Gmsh refuses such a block",
                    blk + 1
                ),
            ));
        }
        let block = Block41 {
            index: blk,
            len: n,
            etype,
            dim,
            nodes,
            surface,
            why: match entity_dim {
                2 if c.interfaces.contains(&entity) => SkipReason::PartitionInterface,
                // A ghost entity is of the mesh's dimension; a surface of that tag that
                // `$PartitionedEntities` declares is a partition's own.
                2 if c.ghosts.contains(&entity) && !c.parents.contains_key(&entity) => {
                    SkipReason::GhostCell
                }
                _ => SkipReason::Type,
            },
        };
        if block.keep() || block.lower() {
            // With `$Entities`, the entity must be declared there, in `$PartitionedEntities`
            // or by a `$Nodes` block, as Gmsh requires ("Unknown entity 7 of dimension 2"):
            // else which entity, and which physical groups, the elements were meant for is
            // unknown. Without `$Entities` (meshio writes such files) the entity is made.
            let key = (dim, surface);
            let declared = |e: &[Entity]| e.iter().any(|e| (e.dim, e.tag) == key);
            if let Some(entities) = &c.model.entities
                && !declared(entities)
                && !c.model.parents.contains_key(&key)
                && !c.node_block_entities.contains(&key)
            {
                let kind = ["point", "curve", "surface"][usize::from(dim.min(2))];
                return Err(p.err(
                    ep,
                    format!(
                        "element block {} is on {kind} {surface}, which neither $Entities nor a $Nodes block declares; Gmsh refuses such a file (\"Unknown entity {surface} of dimension {dim}\")",
                        blk + 1
                    ),
                ));
            }
            c.model.on_entity(dim, surface, 0);
        }
        if p.binary {
            if nodes == 0 {
                let what = format!("element block {}", blk + 1);
                return Err(p.err(tp, variable_size(&what, etype, name)));
            }
            element_block41_binary(p, c, map, &block)?;
        } else {
            element_block41_ascii(p, c, map, &block)?;
        }
        seen += n;
    }
    if seen != total {
        return Err(p.err(
            hp,
            format!("the $Elements header announces {total} elements but its blocks hold {seen}"),
        ));
    }
    Ok(total)
}

/// An MSH 4.1 element block's header.
struct Block41 {
    /// 0-based position among the section's blocks.
    index: u64,
    /// Number of elements.
    len: u64,
    etype: i64,
    /// Dimension of the type.
    dim: u8,
    /// Nodes per element (0: no fixed number).
    nodes: usize,
    /// The entity the elements are on.
    surface: i32,
    /// Whether the block is on a partition interface or a ghost entity (then skipped).
    why: SkipReason,
}

impl Block41 {
    /// Whether the block's elements are read: triangles and quads not on an interface.
    fn keep(&self) -> bool {
        (self.etype == TRIANGLE || self.etype == QUAD) && self.why == SkipReason::Type
    }

    /// Whether the block's elements go to the model: points and lines.
    fn lower(&self) -> bool {
        is_lower(self.dim, self.nodes)
    }
}

/// The elements of an ASCII block, one per line: triangles and quads kept, the rest
/// skipped.
fn element_block41_ascii(
    p: &mut Parser<'_>,
    c: &mut Content,
    map: &NodeMap,
    b: &Block41,
) -> Res<()> {
    let s = "$Elements";
    let blk = b.index;
    let keep = b.keep();
    let lower = b.lower();
    let store = keep || lower;
    if keep && b.etype == TRIANGLE {
        let k = cap(b.len, 8, p.b.len() - p.pos);
        c.data.triangles.reserve(k);
        c.data.triangle_ids.reserve(k);
        c.data.triangle_surface.reserve(k);
    }
    let mut nodes = [0u64; MAX_LOWER_NODES];
    for i in 0..b.len {
        let (at, tt) = p.need(s, &|| format!("element {} of block {}", i + 1, blk + 1))?;
        let tag = parse_u64(tt).ok_or_else(|| {
            p.bad_token(at, tt, s, &|| {
                format!("the tag of element {} of block {}", i + 1, blk + 1)
            })
        })?;
        p.entry_start();
        if b.nodes == 0 {
            p.skip_line();
            continue;
        }
        for k in 0..b.nodes {
            let v = p.uint(s, &|| format!("node {} of element {tag}", k + 1))?;
            if let (true, Some(slot)) = (store, nodes.get_mut(k)) {
                *slot = v;
            } else {
                check_node(p, map, at, tag, v)?;
            }
        }
        p.entry_end(&|| element_nodes(tag, b.etype, b.nodes))?;
        if keep {
            push_element(p, c, map, at, tag, b.surface, &nodes[..b.nodes])?;
        } else if lower {
            let t = (b.etype, b.dim);
            push_lower(p, c, map, at, tag, t, b.surface, &nodes[..b.nodes])?;
        }
    }
    if !keep {
        c.skip(b.etype, b.len, b.why);
    }
    Ok(())
}

/// The elements of a binary block (fixed-size records).
fn element_block41_binary(
    p: &mut Parser<'_>,
    c: &mut Content,
    map: &NodeMap,
    b: &Block41,
) -> Res<()> {
    let s = "$Elements";
    let nn = b.nodes;
    let stride = 8 * (1 + nn);
    let at0 = p.pos;
    let data = p.take_array(b.len, stride, s, &|| {
        format!("element block {}", b.index + 1)
    })?;
    if b.keep() || b.lower() {
        let mut nodes = [0u64; MAX_LOWER_NODES];
        for (i, e) in data.chunks_exact(stride).enumerate() {
            let tag = u64_at(e, 0);
            for (k, slot) in nodes.iter_mut().take(nn).enumerate() {
                *slot = u64_at(e, 8 + 8 * k);
            }
            let at = at0 + i * stride;
            if b.keep() {
                push_element(p, c, map, at, tag, b.surface, &nodes[..nn])?;
            } else {
                let t = (b.etype, b.dim);
                push_lower(p, c, map, at, tag, t, b.surface, &nodes[..nn])?;
            }
        }
    } else {
        let tag = |e: &[u8]| u64_at(e, 0);
        let node = |e: &[u8], k: usize| u64_at(e, 8 + 8 * k);
        check_block_nodes(p, map, data, at0, stride, nn, tag, node, |v| v)?;
    }
    if !b.keep() {
        c.skip(b.etype, b.len, b.why);
    }
    Ok(())
}
