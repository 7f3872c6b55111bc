//! What a reader collects: the node tag map, the mesh content (nodes, triangles, quads,
//! skipped elements, partitions) and the parts of the file's model, with the functions
//! that add an element to them.

use super::element_types::{QUAD, TRIANGLE};
use super::parser::{Parser, Res};
use crate::mesh::MeshData;
use crate::mesh::msh::SkipReason;
use crate::mesh::msh::model::{Element, Entity, Model, PhysicalName};
use std::collections::{BTreeMap, BTreeSet, HashMap, HashSet};

/// Node tag -> dense vertex index.
pub(super) enum NodeMap {
    /// Indexed by tag, and one bit per tag (a node has it) for [`NodeMap::contains`]: the
    /// check of skipped elements' nodes, which needs no index, reads 64 tags per word (a
    /// million tags in 128 KiB).
    Dense(Vec<u32>, Vec<u64>),
    Sparse(HashMap<u64, u32>),
}

impl NodeMap {
    /// The map for `tags` (in vertex order), or the first tag that appears twice.
    pub(super) fn new(tags: &[u64]) -> Result<NodeMap, u64> {
        let max = tags.iter().copied().max().unwrap_or(0);
        if max <= 4 * tags.len() as u64 + 1024 {
            let mut dense = vec![u32::MAX; max as usize + 1];
            let mut known = vec![0u64; max as usize / 64 + 1];
            for (i, &t) in tags.iter().enumerate() {
                let slot = &mut dense[t as usize];
                if *slot != u32::MAX {
                    return Err(t);
                }
                *slot = i as u32;
                known[t as usize / 64] |= 1 << (t % 64);
            }
            Ok(NodeMap::Dense(dense, known))
        } else {
            let mut map = HashMap::with_capacity(tags.len());
            for (i, &t) in tags.iter().enumerate() {
                if map.insert(t, i as u32).is_some() {
                    return Err(t);
                }
            }
            Ok(NodeMap::Sparse(map))
        }
    }

    #[inline]
    pub(super) fn get(&self, tag: u64) -> Option<u32> {
        match self {
            NodeMap::Dense(v, _) => v.get(tag as usize).copied().filter(|&i| i != u32::MAX),
            NodeMap::Sparse(m) => m.get(&tag).copied(),
        }
    }

    /// Whether a node has `tag`.
    #[inline]
    pub(super) fn contains(&self, tag: u64) -> bool {
        match self {
            NodeMap::Dense(_, known) => known
                .get((tag / 64) as usize)
                .is_some_and(|w| w >> (tag % 64) & 1 == 1),
            NodeMap::Sparse(m) => m.contains_key(&tag),
        }
    }
}

/// The content of a MSH file, before validation.
pub(super) struct Content {
    pub(super) data: MeshData,
    pub(super) node_tags: Vec<u64>,
    /// Where each node tag is (offsets), noted only when a duplicate tag is looked for.
    pub(super) tag_pos: Option<Vec<usize>>,
    pub(super) map: Option<NodeMap>,
    /// Skipped elements: count per Gmsh type and where they were.
    pub(super) skipped: BTreeMap<(i64, SkipReason), usize>,
    /// Partitioned files (4.1): the parent surface of each partition's surface entity.
    pub(super) parents: HashMap<i64, i32>,
    /// Partitioned 3D meshes (4.1): partition surfaces whose parent is a volume, the
    /// interfaces between volume partitions. Their triangles lie inside the volume, not on
    /// a model surface, and are skipped.
    pub(super) interfaces: HashSet<i64>,
    /// Partitioned files (4.1): the ghost entities of the header of `$PartitionedEntities`
    /// (copies of the elements of other partitions next to this one, in a file per
    /// partition).
    pub(super) ghosts: HashSet<i64>,
    /// MSH 4.1: the entities of the `$Nodes` blocks (Gmsh makes an entity a block names if
    /// `$Entities` does not declare it; an element block's entity must be declared one way).
    pub(super) node_block_entities: HashSet<(u8, i32)>,
    /// The model, as the file gives it (see [`ModelParts::finish`]).
    pub(super) model: ModelParts,
}

/// The parts of the file's model, collected while reading.
#[derive(Default)]
pub(super) struct ModelParts {
    pub(super) physical_names: Vec<PhysicalName>,
    /// `$Entities` (4.1), if the file has it.
    pub(super) entities: Option<Vec<Entity>>,
    /// The entity of each node as the file gives it, aligned with `Content::node_tags`
    /// (`None`: not given, MSH 2.2 `$Nodes`).
    pub(super) node_entity: Vec<Option<(u8, i32)>>,
    /// The parametric coordinates of each node, up to the last that has some (empty when
    /// none has: most files).
    pub(super) node_param: Vec<Option<[f64; 3]>>,
    /// Point and line elements (on the file's entities).
    pub(super) elements: Vec<Element>,
    /// Every entity an element is on, with the physical tags the elements give it (MSH
    /// 2.2; none in 4.1, where `$Entities` holds them).
    pub(super) element_entities: BTreeMap<(u8, i32), BTreeSet<i32>>,
    /// The last key added to `element_entities` (elements come in runs on one entity).
    pub(super) last_entity: Option<(u8, i32, i32)>,
    /// Partitioned files (4.1): the parent (dimension, tag) of each partition entity.
    pub(super) parents: HashMap<(u8, i32), (u8, i32)>,
    /// MSH 2.2: the lowest tag of the volumes whose elements hold each node (empty when the
    /// file has no volume element), for the nodes no lower element holds.
    pub(super) node_volume: Vec<Option<i32>>,
}

impl ModelParts {
    /// Records the parametric coordinates of the node just added to `node_entity`.
    #[inline]
    pub(super) fn push_param(&mut self, u: Option<[f64; 3]>) {
        if u.is_some() || !self.node_param.is_empty() {
            self.node_param.resize(self.node_entity.len() - 1, None);
            self.node_param.push(u);
        }
    }

    /// Notes that node `v` (an index) is a node of a volume element on volume `tag` (MSH 2.2).
    #[inline]
    pub(super) fn in_volume(&mut self, v: u32, tag: i32) {
        let v = v as usize;
        if self.node_volume.len() <= v {
            self.node_volume.resize(v + 1, None);
        }
        let slot = &mut self.node_volume[v];
        *slot = Some(slot.map_or(tag, |t| t.min(tag)));
    }

    /// Notes an element of dimension `dim` on entity `tag` in physical group `physical`
    /// (0: none).
    #[inline]
    pub(super) fn on_entity(&mut self, dim: u8, tag: i32, physical: i32) {
        if self.last_entity == Some((dim, tag, physical)) {
            return;
        }
        self.last_entity = Some((dim, tag, physical));
        let set = self.element_entities.entry((dim, tag)).or_default();
        if physical != 0 {
            set.insert(physical);
        }
    }

    /// The model: partition entities replaced by their parents (elements and node
    /// classifications on partition interfaces dropped, the parametric coordinates of a
    /// node moved to a parent of another dimension dropped), nodes the file does not
    /// classify put on the entity of the lowest dimension, then tag, whose elements hold
    /// them (as Gmsh reads MSH 2.2), and entities that `$Entities` lacks derived from the
    /// elements.
    pub(super) fn finish(mut self, data: &MeshData) -> Model {
        if !self.parents.is_empty() {
            let parents = &self.parents;
            for (v, on) in self.node_entity.iter_mut().enumerate() {
                if let Some((dim, tag)) = *on
                    && let Some(&(pd, pt)) = parents.get(&(dim, tag))
                {
                    *on = Some((pd, pt));
                    if let (true, Some(param)) = (pd != dim, self.node_param.get_mut(v)) {
                        *param = None;
                    }
                }
            }
            self.elements
                .retain_mut(|e| match parents.get(&(e.dim, e.entity)) {
                    Some(&(pd, pt)) if pd == e.dim => {
                        e.entity = pt;
                        true
                    }
                    Some(_) => false,
                    None => true,
                });
            let mut entities = BTreeMap::new();
            for (&(dim, tag), physicals) in &self.element_entities {
                let key = match parents.get(&(dim, tag)) {
                    Some(&(pd, pt)) if pd == dim => (dim, pt),
                    Some(_) => continue,
                    None => (dim, tag),
                };
                entities
                    .entry(key)
                    .or_insert_with(BTreeSet::new)
                    .extend(physicals);
            }
            self.element_entities = entities;
        }
        let nv = data.vertices.len();
        self.node_entity.resize(nv, None);
        if !self.node_param.is_empty() {
            self.node_param.resize(nv, None);
        }
        if self.node_entity.iter().any(Option::is_none) {
            // As Gmsh reads MSH 2.2 (its entities walked by dimension, then tag, each
            // claiming the nodes not yet claimed): among the elements that hold a node, the
            // lowest dimension, then the lowest entity tag, then triangles before quads.
            let on = &self.node_entity;
            let mut best: Vec<Option<(u8, i32, u8)>> = vec![None; nv];
            let mut claim = |nodes: &[u32], key: (u8, i32, u8)| {
                for &v in nodes {
                    let v = v as usize;
                    if on.get(v).is_some_and(Option::is_none) && best[v].is_none_or(|b| key < b) {
                        best[v] = Some(key);
                    }
                }
            };
            for e in self.elements.iter().filter(|e| e.dim <= 1) {
                claim(&e.nodes, (e.dim, e.entity, 0));
            }
            for (t, &s) in data.triangles.iter().zip(&data.triangle_surface) {
                claim(t, (2, s, 0));
            }
            for (q, &s) in data.quads.iter().zip(&data.quad_surface) {
                claim(q, (2, s, 1));
            }
            for (v, volume) in self.node_volume.iter().enumerate() {
                if let Some(tag) = *volume {
                    claim(&[v as u32], (3, tag, 0));
                }
            }
            for (slot, b) in self.node_entity.iter_mut().zip(best) {
                if slot.is_none() {
                    *slot = b.map(|(dim, tag, _)| (dim, tag));
                }
            }
        }
        let mut entities = self.entities.unwrap_or_default();
        let known: HashSet<(u8, i32)> = entities.iter().map(|e| (e.dim, e.tag)).collect();
        for ((dim, tag), physicals) in self.element_entities {
            if !known.contains(&(dim, tag)) {
                entities.push(Entity {
                    dim,
                    tag,
                    bbox: None,
                    physicals: physicals.into_iter().collect(),
                    bounding: Vec::new(),
                });
            }
        }
        Model {
            physical_names: self.physical_names,
            entities,
            node_entity: self.node_entity,
            node_param: self.node_param,
            elements: self.elements,
            not_written: Vec::new(),
        }
    }
}

impl Content {
    pub(super) fn new() -> Content {
        Content {
            data: MeshData::default(),
            node_tags: Vec::new(),
            tag_pos: None,
            map: None,
            skipped: BTreeMap::new(),
            parents: HashMap::new(),
            interfaces: HashSet::new(),
            ghosts: HashSet::new(),
            node_block_entities: HashSet::new(),
            model: ModelParts::default(),
        }
    }

    /// Notes where the node tag just pushed is, when asked to (see [`duplicate_node`](super::duplicate_node)).
    #[inline]
    pub(super) fn note_tag(&mut self, pos: usize) {
        if let Some(v) = &mut self.tag_pos {
            v.push(pos);
        }
    }

    /// MSH 2.2 writes the elements of an entity in several physical groups once per group:
    /// copies with the same nodes and elementary tag, another physical tag and element tag
    /// (Gmsh reads each copy as an element of its own, and writes each of those once per
    /// group again, in 2.2 and in 4.1; MSH 4.1 lists the groups on the entity instead). On an
    /// entity of two groups or more, keeps the first of each element (triangle and quad,
    /// point and line), in every group (the entity holds the physical tags of all its
    /// copies), so that the mesh and its groups are the ones Gmsh's 4.1 file of the model
    /// gives; an exact copy there is dropped whatever its group (Gmsh's re-saves repeat a
    /// group's copy). The copies dropped are counted as skipped.
    pub(super) fn merge_group_copies(&mut self) {
        let mut multi: HashSet<(u8, i32)> = (self.model.element_entities.iter())
            .filter(|(_, physicals)| physicals.len() > 1)
            .map(|(&key, _)| key)
            .collect();
        if let Some(entities) = &self.model.entities {
            multi.extend(
                entities
                    .iter()
                    .filter(|e| e.physicals.len() > 1)
                    .map(|e| (e.dim, e.tag)),
            );
        }
        if multi.is_empty() {
            return;
        }
        let surfaces: HashSet<i32> = (multi.iter())
            .filter(|&&(dim, _)| dim == 2)
            .map(|&(_, tag)| tag)
            .collect();
        let d = &mut self.data;
        let keep_t = first_copies(&d.triangles, &d.triangle_surface, &surfaces);
        let keep_q = first_copies(&d.quads, &d.quad_surface, &surfaces);
        let dropped = |keep: &[bool]| keep.iter().filter(|&&k| !k).count() as u64;
        let (nt, nq) = (dropped(&keep_t), dropped(&keep_q));
        if nt > 0 {
            retain(&mut d.triangles, &keep_t);
            retain(&mut d.triangle_ids, &keep_t);
            retain(&mut d.triangle_surface, &keep_t);
        }
        if nq > 0 {
            retain(&mut d.quads, &keep_q);
            retain(&mut d.quad_ids, &keep_q);
            retain(&mut d.quad_surface, &keep_q);
        }
        for (etype, n) in [(TRIANGLE, nt), (QUAD, nq)] {
            if n > 0 {
                self.skip(etype, n, SkipReason::GroupCopy);
            }
        }
        // Points and lines: the same element (type, entity, nodes as written) again.
        let mut seen = HashSet::new();
        let mut lower = BTreeMap::new();
        self.model.elements.retain(|e| {
            let copy = multi.contains(&(e.dim, e.entity))
                && !seen.insert((e.gmsh_type, e.dim, e.entity, e.nodes.clone()));
            if copy {
                *lower.entry(e.gmsh_type).or_insert(0u64) += 1;
            }
            !copy
        });
        for (etype, n) in lower {
            self.skip(etype, n, SkipReason::GroupCopy);
        }
    }

    /// Counts `n` skipped elements of type `etype`, skipped for `why`.
    pub(super) fn skip(&mut self, etype: i64, n: u64, why: SkipReason) {
        *self.skipped.entry((etype, why)).or_default() += n as usize;
    }
}

/// Checks that node `n` of skipped element `tag` exists: such an element is neither kept
/// nor written, but a file naming a missing node is broken, and Gmsh refuses it too.
#[inline]
pub(super) fn check_node(p: &Parser<'_>, map: &NodeMap, at: usize, tag: u64, n: u64) -> Res<()> {
    if map.contains(n) {
        Ok(())
    } else {
        Err(p.err(at, missing_node(tag, n)))
    }
}

/// [`check_node`] for every node of a block of skipped binary elements: `count` records of
/// `stride` bytes from byte offset `at0`, `tag(e)` and `node(e, k)` reading a record's tag
/// and its `nn` node tags as they are written (`T`: `u64` in MSH 4.1, `i32` in MSH 2.2),
/// `key` giving the node map's key of a node tag (a negative tag none, as 0: no node has it).
/// One pass without error paths; the element at fault is looked for only when one is.
#[allow(clippy::too_many_arguments)] // one record layout, read by the closures
pub(super) fn check_block_nodes<T: Copy + std::fmt::Display>(
    p: &Parser<'_>,
    map: &NodeMap,
    data: &[u8],
    at0: usize,
    stride: usize,
    nn: usize,
    tag: impl Fn(&[u8]) -> T,
    node: impl Fn(&[u8], usize) -> T,
    key: impl Fn(T) -> u64,
) -> Res<()> {
    let records = data.chunks_exact(stride);
    if records
        .clone()
        .all(|e| (0..nn).all(|k| map.contains(key(node(e, k)))))
    {
        return Ok(());
    }
    for (i, e) in records.enumerate() {
        for k in 0..nn {
            let n = node(e, k);
            if !map.contains(key(n)) {
                return Err(p.err(at0 + i * stride, missing_node(tag(e), n)));
            }
        }
    }
    unreachable!("a node that is not known was found")
}

/// Which of `elements` (on `surface`) to keep: all but the later copies of an element (same
/// surface, same nodes in the same cyclic order) on the surfaces `multi` (those of two
/// physical groups or more).
fn first_copies<const N: usize>(
    elements: &[[u32; N]],
    surface: &[i32],
    multi: &HashSet<i32>,
) -> Vec<bool> {
    let mut multi: Vec<i32> = multi.iter().copied().collect();
    multi.sort_unstable();
    let on_multi = |s: &i32| multi.binary_search(s).is_ok();
    let key = |e: &[u32; N], s: i32| {
        let mut key = *e;
        key.rotate_left((0..N).min_by_key(|&k| e[k]).unwrap_or(0));
        (s, key)
    };
    let mut keep = vec![true; elements.len()];
    // Most surfaces of two groups hold no copy (every 4.1 file with such a surface, but
    // for Gmsh's re-saves of 2.2 files): a sort of 64-bit fingerprints says so for less
    // than the exact sort below (measured in c90bcfe's message).
    let mut prints: Vec<u64> = (elements.iter().zip(surface))
        .filter(|(_, s)| on_multi(s))
        .map(|(e, &s)| {
            let (s, k) = key(e, s);
            k.iter().fold(s as u32 as u64, |h, &v| {
                (h ^ u64::from(v))
                    .wrapping_mul(0x9E37_79B9_7F4A_7C15)
                    .rotate_left(29)
            })
        })
        .collect();
    prints.sort_unstable();
    if prints.windows(2).all(|w| w[0] != w[1]) {
        return keep;
    }
    let mut keyed: Vec<((i32, [u32; N]), u32)> = (elements.iter().zip(surface).enumerate())
        .filter(|(_, (_, s))| on_multi(s))
        .map(|(i, (e, &s))| (key(e, s), i as u32))
        .collect();
    keyed.sort_unstable();
    for w in keyed.windows(2) {
        if w[0].0 == w[1].0 {
            keep[w[1].1 as usize] = false;
        }
    }
    keep
}

/// Keeps the items of `v` whose flag in `keep` is set.
fn retain<T>(v: &mut Vec<T>, keep: &[bool]) {
    let mut i = 0;
    v.retain(|_| {
        i += 1;
        keep.get(i - 1).copied().unwrap_or(true)
    });
}

fn missing_node(tag: impl std::fmt::Display, n: impl std::fmt::Display) -> String {
    format!("element {tag} refers to node {n}, which does not exist")
}

/// Adds a triangle or quad (`nodes` are its 3 or 4 node tags) of element `tag` on `surface`, or counts an
/// ignored element. `at` is where the element starts (for messages).
#[inline]
pub(super) fn push_element(
    p: &Parser<'_>,
    c: &mut Content,
    map: &NodeMap,
    at: usize,
    tag: u64,
    surface: i32,
    nodes: &[u64],
) -> Res<()> {
    let mut idx = [0u32; 4];
    for (k, &n) in nodes.iter().enumerate() {
        idx[k] = map.get(n).ok_or_else(|| p.err(at, missing_node(tag, n)))?;
    }
    if nodes.len() == 3 {
        c.data.triangles.push([idx[0], idx[1], idx[2]]);
        c.data.triangle_ids.push(tag);
        c.data.triangle_surface.push(surface);
    } else {
        c.data.quads.push(idx);
        c.data.quad_ids.push(tag);
        c.data.quad_surface.push(surface);
    }
    Ok(())
}

/// Adds a point or line element (`nodes`: its node tags) of element `tag`, type `etype`
/// and dimension `dim`, on entity `entity`, to the model.
#[allow(clippy::too_many_arguments)]
pub(super) fn push_lower(
    p: &Parser<'_>,
    c: &mut Content,
    map: &NodeMap,
    at: usize,
    tag: u64,
    (etype, dim): (i64, u8),
    entity: i32,
    nodes: &[u64],
) -> Res<()> {
    let nodes = nodes
        .iter()
        .map(|&n| map.get(n).ok_or_else(|| p.err(at, missing_node(tag, n))))
        .collect::<Res<Vec<u32>>>()?;
    c.model.elements.push(Element {
        gmsh_type: etype,
        dim,
        entity,
        nodes,
    });
    Ok(())
}

/// The first `n` of `u` as a node's parametric coordinates: none if `n` is 0 or one is not
/// finite (then they are not written back).
pub(super) fn parametric(n: usize, u: [f64; 3]) -> Option<[f64; 3]> {
    (n > 0 && u.iter().all(|x| x.is_finite())).then_some(u)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn node_map_is_dense_for_compact_tags_and_sparse_otherwise() {
        let dense = NodeMap::new(&[3, 1, 2]).unwrap();
        assert!(matches!(dense, NodeMap::Dense(..)));
        assert_eq!(
            (dense.get(1), dense.get(3), dense.get(0), dense.get(99)),
            (Some(1), Some(0), None, None)
        );
        let has = |m: &NodeMap| [0, 1, 2, 3, 4, 63, 64, 99, u64::MAX].map(|t| m.contains(t));
        let yes = [false, true, true, true, false, false, false, false, false];
        assert_eq!(has(&dense), yes);
        let wide = NodeMap::new(&[64, 1, 63]).unwrap();
        assert!(matches!(wide, NodeMap::Dense(..)));
        assert_eq!(
            has(&wide),
            [false, true, false, false, false, true, true, false, false]
        );
        let sparse = NodeMap::new(&[u64::MAX, 5]).unwrap();
        assert!(matches!(sparse, NodeMap::Sparse(_)));
        assert_eq!(
            (sparse.get(u64::MAX), sparse.get(5), sparse.get(6)),
            (Some(0), Some(1), None)
        );
        let hits = [u64::MAX, 5, 6, 0].map(|t| sparse.contains(t));
        assert_eq!(hits, [true, true, false, false]);
        assert_eq!(NodeMap::new(&[4, 7, 4]).err(), Some(4));
        assert_eq!(NodeMap::new(&[u64::MAX, 9, u64::MAX]).err(), Some(u64::MAX));
    }
}
