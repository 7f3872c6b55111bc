//! The hand-written MSH parser: 2.2 and 4.1, ASCII and binary (native little-endian, checked
//! with the int `1` marker). One pass over the bytes, no per-line allocation.
//!
//! Errors in ASCII files carry the line ([`ReadError::Syntax`]); errors in binary files past
//! their header carry the byte offset (as [`ReadError::Io`] of kind `InvalidData`, whose
//! message names the offset).

use super::model::{Element, Entity, Model, PhysicalName};
use super::{MshFile, MshVersion, SkippedElements};
use crate::mesh::{MeshData, ReadError};
use std::collections::{BTreeMap, BTreeSet, HashMap, HashSet};
use std::path::Path;

/// Gmsh's element types (4.15, as its MSH reader knows them: `MElement::getInfoMSH`):
/// number, nodes (0: no fixed number, polygons and the like), dimension, name. Sorted by
/// number. A test checks the table against `gmsh.model.mesh.getElementProperties`, which
/// answers for all but 18 of them (the border and child lines, the border triangle, the
/// prisms of order 3 and up and the trihedron, for which it raises another error than
/// "Unknown type"); those rows are from `getInfoMSH`.
#[rustfmt::skip]
const ELEMENT_TYPES: [(i64, usize, u8, &str); 135] = [
    (1, 2, 1, "Line 2"),
    (2, 3, 2, "Triangle 3"),
    (3, 4, 2, "Quadrilateral 4"),
    (4, 4, 3, "Tetrahedron 4"),
    (5, 8, 3, "Hexahedron 8"),
    (6, 6, 3, "Prism 6"),
    (7, 5, 3, "Pyramid 5"),
    (8, 3, 1, "Line 3"),
    (9, 6, 2, "Triangle 6"),
    (10, 9, 2, "Quadrilateral 9"),
    (11, 10, 3, "Tetrahedron 10"),
    (12, 27, 3, "Hexahedron 27"),
    (13, 18, 3, "Prism 18"),
    (14, 14, 3, "Pyramid 14"),
    (15, 1, 0, "Point"),
    (16, 8, 2, "Quadrilateral 8"),
    (17, 20, 3, "Hexahedron 20"),
    (18, 15, 3, "Prism 15"),
    (19, 13, 3, "Pyramid 13"),
    (20, 9, 2, "Triangle 9"),
    (21, 10, 2, "Triangle 10"),
    (22, 12, 2, "Triangle 12"),
    (23, 15, 2, "Triangle 15"),
    (24, 15, 2, "Triangle 15I"),
    (25, 21, 2, "Triangle 21"),
    (26, 4, 1, "Line 4"),
    (27, 5, 1, "Line 5"),
    (28, 6, 1, "Line 6"),
    (29, 20, 3, "Tetrahedron 20"),
    (30, 35, 3, "Tetrahedron 35"),
    (31, 56, 3, "Tetrahedron 56"),
    (32, 22, 3, "Tetrahedron 22"),
    (33, 28, 3, "Tetrahedron 28"),
    (34, 0, 2, "Polygon"),
    (35, 0, 3, "Polyhedron"),
    (36, 16, 2, "Quadrilateral 16"),
    (37, 25, 2, "Quadrilateral 25"),
    (38, 36, 2, "Quadrilateral 36"),
    (39, 12, 2, "Quadrilateral 12"),
    (40, 16, 2, "Quadrilateral 16I"),
    (41, 20, 2, "Quadrilateral 20"),
    (42, 28, 2, "Triangle 28"),
    (43, 36, 2, "Triangle 36"),
    (44, 45, 2, "Triangle 45"),
    (45, 55, 2, "Triangle 55"),
    (46, 66, 2, "Triangle 66"),
    (47, 49, 2, "Quadrilateral 49"),
    (48, 64, 2, "Quadrilateral 64"),
    (49, 81, 2, "Quadrilateral 81"),
    (50, 100, 2, "Quadrilateral 100"),
    (51, 121, 2, "Quadrilateral 121"),
    (52, 18, 2, "Triangle 18"),
    (53, 21, 2, "Triangle 21I"),
    (54, 24, 2, "Triangle 24"),
    (55, 27, 2, "Triangle 27"),
    (56, 30, 2, "Triangle 30"),
    (57, 24, 2, "Quadrilateral 24"),
    (58, 28, 2, "Quadrilateral 28"),
    (59, 32, 2, "Quadrilateral 32"),
    (60, 36, 2, "Quadrilateral 36I"),
    (61, 40, 2, "Quadrilateral 40"),
    (62, 7, 1, "Line 7"),
    (63, 8, 1, "Line 8"),
    (64, 9, 1, "Line 9"),
    (65, 10, 1, "Line 10"),
    (66, 11, 1, "Line 11"),
    (67, 2, 1, "Line Border"),
    (68, 3, 2, "Triangle Border"),
    (69, 0, 2, "Polygon Border"),
    (70, 2, 1, "Line Child"),
    (71, 84, 3, "Tetrahedron 84"),
    (72, 120, 3, "Tetrahedron 120"),
    (73, 165, 3, "Tetrahedron 165"),
    (74, 220, 3, "Tetrahedron 220"),
    (75, 286, 3, "Tetrahedron 286"),
    (79, 34, 3, "Tetrahedron 34"),
    (80, 40, 3, "Tetrahedron 40"),
    (81, 46, 3, "Tetrahedron 46"),
    (82, 52, 3, "Tetrahedron 52"),
    (83, 58, 3, "Tetrahedron 58"),
    (84, 1, 1, "Line 1"),
    (85, 1, 2, "Triangle 1"),
    (86, 1, 2, "Quadrilateral 1"),
    (87, 1, 3, "Tetrahedron 1"),
    (88, 1, 3, "Hexahedron 1"),
    (89, 1, 3, "Prism 1"),
    (90, 40, 3, "Prism 40"),
    (91, 75, 3, "Prism 75"),
    (92, 64, 3, "Hexahedron 64"),
    (93, 125, 3, "Hexahedron 125"),
    (94, 216, 3, "Hexahedron 216"),
    (95, 343, 3, "Hexahedron 343"),
    (96, 512, 3, "Hexahedron 512"),
    (97, 729, 3, "Hexahedron 729"),
    (98, 1000, 3, "Hexahedron 1000"),
    (99, 32, 3, "Hexahedron 32"),
    (100, 44, 3, "Hexahedron 44"),
    (101, 56, 3, "Hexahedron 56"),
    (102, 68, 3, "Hexahedron 68"),
    (103, 80, 3, "Hexahedron 80"),
    (104, 92, 3, "Hexahedron 92"),
    (105, 104, 3, "Hexahedron 104"),
    (106, 126, 3, "Prism 126"),
    (107, 196, 3, "Prism 196"),
    (108, 288, 3, "Prism 288"),
    (109, 405, 3, "Prism 405"),
    (110, 550, 3, "Prism 550"),
    (111, 24, 3, "Prism 24"),
    (112, 33, 3, "Prism 33"),
    (113, 42, 3, "Prism 42"),
    (114, 51, 3, "Prism 51"),
    (115, 60, 3, "Prism 60"),
    (116, 69, 3, "Prism 69"),
    (117, 78, 3, "Prism 78"),
    (118, 30, 3, "Pyramid 30"),
    (119, 55, 3, "Pyramid 55"),
    (120, 91, 3, "Pyramid 91"),
    (121, 140, 3, "Pyramid 140"),
    (122, 204, 3, "Pyramid 204"),
    (123, 285, 3, "Pyramid 285"),
    (124, 385, 3, "Pyramid 385"),
    (125, 21, 3, "Pyramid 21"),
    (126, 29, 3, "Pyramid 29"),
    (127, 37, 3, "Pyramid 37"),
    (128, 45, 3, "Pyramid 45"),
    (129, 53, 3, "Pyramid 53"),
    (130, 61, 3, "Pyramid 61"),
    (131, 69, 3, "Pyramid 69"),
    (132, 1, 3, "Pyramid 1"),
    (133, 0, 0, "Point Xfem"),
    (134, 0, 1, "Line Xfem"),
    (135, 0, 2, "Triangle Xfem"),
    (136, 0, 3, "Tetrahedron Xfem"),
    (137, 16, 3, "Tetrahedron 16"),
    (140, 4, 3, "Trihedron 4"),
];

/// The nodes, dimension and name of Gmsh element type `etype`; `None` for a number Gmsh
/// does not know.
pub(super) fn element_type(etype: i64) -> Option<(usize, u8, &'static str)> {
    let i = ELEMENT_TYPES.binary_search_by_key(&etype, |e| e.0).ok()?;
    let (_, nodes, dim, name) = ELEMENT_TYPES[i];
    Some((nodes, dim, name))
}

const TRIANGLE: i64 = 2;
const QUAD: i64 = 3;

/// Node tag -> dense vertex index.
enum NodeMap {
    Dense(Vec<u32>),
    Sparse(HashMap<u64, u32>),
}

impl NodeMap {
    /// The map for `tags` (in vertex order), or the first tag that appears twice.
    fn new(tags: &[u64]) -> Result<NodeMap, u64> {
        let max = tags.iter().copied().max().unwrap_or(0);
        if max <= 4 * tags.len() as u64 + 1024 {
            let mut dense = vec![u32::MAX; max as usize + 1];
            for (i, &t) in tags.iter().enumerate() {
                let slot = &mut dense[t as usize];
                if *slot != u32::MAX {
                    return Err(t);
                }
                *slot = i as u32;
            }
            Ok(NodeMap::Dense(dense))
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
    fn get(&self, tag: u64) -> Option<u32> {
        match self {
            NodeMap::Dense(v) => v.get(tag as usize).copied().filter(|&i| i != u32::MAX),
            NodeMap::Sparse(m) => m.get(&tag).copied(),
        }
    }
}

fn parse_u64(t: &[u8]) -> Option<u64> {
    if t.is_empty() || t.len() > 20 {
        return None;
    }
    let mut v: u64 = 0;
    for &c in t {
        let d = c.wrapping_sub(b'0');
        if d > 9 {
            return None;
        }
        v = v.checked_mul(10)?.checked_add(u64::from(d))?;
    }
    Some(v)
}

fn parse_i64(t: &[u8]) -> Option<i64> {
    match t.split_first() {
        Some((b'-', rest)) => parse_u64(rest)
            .filter(|&v| v <= i64::MAX as u64 + 1)
            .map(|v| (v as i64).wrapping_neg()),
        Some((b'+', rest)) => parse_u64(rest).and_then(|v| i64::try_from(v).ok()),
        _ => parse_u64(t).and_then(|v| i64::try_from(v).ok()),
    }
}

fn parse_f64(t: &[u8]) -> Option<f64> {
    std::str::from_utf8(t).ok()?.parse().ok()
}

/// Shows a token in a message: at most 40 characters, non-printable bytes escaped.
fn show(t: &[u8]) -> String {
    let s: String = t
        .iter()
        .take(40)
        .flat_map(|&c| std::ascii::escape_default(c))
        .map(char::from)
        .collect();
    if t.len() > 40 { format!("{s}...") } else { s }
}

#[derive(Clone)]
struct Parser<'a> {
    path: &'a Path,
    b: &'a [u8],
    pos: usize,
    binary: bool,
    /// Inside one entry of an ASCII section (a node, an element, a header): its values are
    /// on one line, so tokens do not cross a line end (see [`Parser::entry_end`]).
    in_line: bool,
}

type Res<T> = Result<T, ReadError>;

impl<'a> Parser<'a> {
    fn line_of(&self, pos: usize) -> usize {
        1 + self.b[..pos.min(self.b.len())]
            .iter()
            .filter(|&&c| c == b'\n')
            .count()
    }

    /// An error at position `pos`: its line in an ASCII file, its byte offset in a binary one
    /// (where binary data make line numbers meaningless).
    fn err(&self, pos: usize, message: impl Into<String>) -> ReadError {
        if self.binary {
            return self.err_bin(pos, message.into());
        }
        ReadError::Syntax {
            path: self.path.to_path_buf(),
            line: self.line_of(pos),
            message: message.into(),
        }
    }

    /// An error inside binary data at byte offset `pos`.
    fn err_bin(&self, pos: usize, message: impl std::fmt::Display) -> ReadError {
        ReadError::Io {
            path: self.path.to_path_buf(),
            source: std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                format!("byte offset {pos}: {message}"),
            ),
        }
    }

    fn skip_ws(&mut self) {
        let b = self.b;
        if self.in_line {
            while self.pos < b.len() && b[self.pos].is_ascii_whitespace() && b[self.pos] != b'\n' {
                self.pos += 1;
            }
        } else {
            while self.pos < b.len() && b[self.pos].is_ascii_whitespace() {
                self.pos += 1;
            }
        }
    }

    /// From here to [`Parser::entry_end`], the values read are on the current line.
    #[inline]
    fn entry_start(&mut self) {
        self.in_line = !self.binary;
    }

    /// Ends an entry begun with [`Parser::entry_start`]: the rest of its line must be blank
    /// (`what` names the entry). A value left over means the line holds more than its entry
    /// (Gmsh writes one entry per line), which would shift every later read.
    fn entry_end(&mut self, what: &dyn Fn() -> String) -> Res<()> {
        if !self.in_line {
            return Ok(());
        }
        self.skip_ws();
        self.in_line = false;
        if self.pos < self.b.len() && self.b[self.pos] != b'\n' {
            let at = self.pos;
            let t = self.token().map_or(&b""[..], |(_, t)| t);
            return Err(self.err(
                at,
                format!(
                    "unexpected `{}` after {}: the line holds more values than it should",
                    show(t),
                    what()
                ),
            ));
        }
        Ok(())
    }

    /// Next whitespace-separated token and its position, or `None` at the end of the file.
    #[inline]
    fn token(&mut self) -> Option<(usize, &'a [u8])> {
        self.skip_ws();
        let start = self.pos;
        let b = self.b;
        let mut p = start;
        while p < b.len() && !b[p].is_ascii_whitespace() {
            p += 1;
        }
        self.pos = p;
        if p == start {
            None
        } else {
            Some((start, &b[start..p]))
        }
    }

    /// Next token, or an error saying the file ends inside `section`.
    #[inline]
    fn need(&mut self, section: &str, what: &dyn Fn() -> String) -> Res<(usize, &'a [u8])> {
        match self.token() {
            Some(t) => Ok(t),
            None if self.pos < self.b.len() => Err(self.err(
                self.pos,
                format!(
                    "the line ends where {} was expected (the values of an entry are on one line)",
                    what()
                ),
            )),
            None => Err(self.err(
                self.b.len(),
                format!(
                    "file is truncated: it ends inside {section} while {} was expected (missing $End{})",
                    what(),
                    section.trim_start_matches('$')
                ),
            )),
        }
    }

    fn bad_token(
        &self,
        pos: usize,
        tok: &[u8],
        section: &str,
        what: &dyn Fn() -> String,
    ) -> ReadError {
        if tok.first() == Some(&b'$') {
            self.err(
                pos,
                format!(
                    "found `{}` where {} was expected: {section} holds fewer entries than its header announces",
                    show(tok),
                    what()
                ),
            )
        } else {
            self.err(pos, format!("expected {}, found `{}`", what(), show(tok)))
        }
    }

    #[inline]
    fn uint(&mut self, section: &str, what: &dyn Fn() -> String) -> Res<u64> {
        let (p, t) = self.need(section, what)?;
        parse_u64(t).ok_or_else(|| self.bad_token(p, t, section, what))
    }

    #[inline]
    fn int(&mut self, section: &str, what: &dyn Fn() -> String) -> Res<i64> {
        let (p, t) = self.need(section, what)?;
        parse_i64(t).ok_or_else(|| self.bad_token(p, t, section, what))
    }

    #[inline]
    fn float(&mut self, section: &str, what: &dyn Fn() -> String) -> Res<(usize, f64)> {
        let (p, t) = self.need(section, what)?;
        parse_f64(t)
            .map(|v| (p, v))
            .ok_or_else(|| self.bad_token(p, t, section, what))
    }

    /// A `size_t` field of an MSH 4.1 header: 8 little-endian bytes in a binary file, an
    /// unsigned token in an ASCII one.
    fn size_t(&mut self, section: &str, what: &dyn Fn() -> String) -> Res<u64> {
        if self.binary {
            self.bin_u64(section, what)
        } else {
            self.uint(section, what)
        }
    }

    /// An `int` field of an MSH 4.1 header: 4 little-endian bytes in a binary file, a
    /// signed token in an ASCII one.
    fn int_field(&mut self, section: &str, what: &dyn Fn() -> String) -> Res<i64> {
        if self.binary {
            self.bin_i32(section, what).map(i64::from)
        } else {
            self.int(section, what)
        }
    }

    /// A `double` field: 8 little-endian bytes in a binary file, a token in an ASCII one.
    fn double_field(&mut self, section: &str, what: &dyn Fn() -> String) -> Res<f64> {
        if self.binary {
            let s = self.take(8, section, what)?;
            Ok(f64_at(s, 0))
        } else {
            self.float(section, what).map(|(_, v)| v)
        }
    }

    /// Skips the rest of the current line (ASCII element lines of types without a fixed
    /// number of nodes) and ends the entry.
    fn skip_line(&mut self) {
        while self.pos < self.b.len() && self.b[self.pos] != b'\n' {
            self.pos += 1;
        }
        self.in_line = false;
    }

    /// Expects the `$End...` token closing `section`, after `count` entries.
    fn end(&mut self, section: &str, count: &dyn Fn() -> String) -> Res<()> {
        let end = format!("$End{}", section.trim_start_matches('$'));
        match self.token() {
            Some((_, t)) if t == end.as_bytes() => Ok(()),
            Some((p, t)) => Err(self.err(
                p,
                format!(
                    "expected {end} after {}, found `{}`: {section} holds more than its header announces, or is not closed",
                    count(),
                    show(t)
                ),
            )),
            None => Err(self.err(
                self.b.len(),
                format!("file is truncated: missing {end} (the file ends inside {section})"),
            )),
        }
    }

    /// Skips a section we do not read, up to its `$End...` marker.
    fn skip_section(&mut self, start: usize, name: &[u8]) -> Res<()> {
        let mut end = b"$End".to_vec();
        end.extend_from_slice(&name[1..]);
        let hay = &self.b[self.pos..];
        match hay.windows(end.len()).position(|w| w == end.as_slice()) {
            Some(i) => {
                self.pos += i + end.len();
                Ok(())
            }
            None => Err(self.err(
                start,
                format!(
                    "file is truncated: section {} is never closed (missing {})",
                    show(name),
                    show(&end)
                ),
            )),
        }
    }

    /// After a section header in a binary file: the single newline before the binary data
    /// (nothing in an ASCII file, where the newline is whitespace).
    fn binary_data_start(&mut self) {
        if !self.binary {
            return;
        }
        if self.b.get(self.pos) == Some(&b'\r') {
            self.pos += 1;
        }
        if self.b.get(self.pos) == Some(&b'\n') {
            self.pos += 1;
        }
    }

    /// `n` bytes of binary data, or a truncation error naming `what`.
    #[inline]
    fn take(&mut self, n: usize, section: &str, what: &dyn Fn() -> String) -> Res<&'a [u8]> {
        let left = self.b.len() - self.pos;
        if n > left {
            return Err(self.err_bin(
                self.pos,
                format!(
                    "file is truncated inside {section}: {} needs {n} bytes, {left} left",
                    what()
                ),
            ));
        }
        let s = &self.b[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }

    fn bin_i32(&mut self, section: &str, what: &dyn Fn() -> String) -> Res<i32> {
        let s = self.take(4, section, what)?;
        Ok(i32::from_le_bytes([s[0], s[1], s[2], s[3]]))
    }

    fn bin_u64(&mut self, section: &str, what: &dyn Fn() -> String) -> Res<u64> {
        let s = self.take(8, section, what)?;
        Ok(u64_at(s, 0))
    }

    /// `count * size` bytes, checked for overflow and truncation.
    fn take_array(
        &mut self,
        count: u64,
        size: usize,
        section: &str,
        what: &dyn Fn() -> String,
    ) -> Res<&'a [u8]> {
        let n = usize::try_from(count)
            .ok()
            .and_then(|c| c.checked_mul(size))
            .ok_or_else(|| {
                self.err_bin(self.pos, format!("{}: count {count} is too large", what()))
            })?;
        self.take(n, section, what)
    }
}

#[inline]
fn u64_at(s: &[u8], i: usize) -> u64 {
    let mut a = [0u8; 8];
    a.copy_from_slice(&s[i..i + 8]);
    u64::from_le_bytes(a)
}

#[inline]
fn f64_at(s: &[u8], i: usize) -> f64 {
    let mut a = [0u8; 8];
    a.copy_from_slice(&s[i..i + 8]);
    f64::from_le_bytes(a)
}

#[inline]
fn i32_at(s: &[u8], i: usize) -> i32 {
    i32::from_le_bytes([s[i], s[i + 1], s[i + 2], s[i + 3]])
}

/// A capacity for `count` items of at least `min_bytes` each that the file can really hold.
fn cap(count: u64, min_bytes: usize, bytes_left: usize) -> usize {
    (count.min((bytes_left / min_bytes.max(1)) as u64)) as usize
}

/// The content of a MSH file, before validation.
struct Content {
    data: MeshData,
    node_tags: Vec<u64>,
    /// Where each node tag is (offsets), noted only when a duplicate tag is looked for.
    tag_pos: Option<Vec<usize>>,
    map: Option<NodeMap>,
    /// Skipped elements: count per Gmsh type and whether they were on a partition
    /// interface (a surface inside a volume; see `interfaces`).
    skipped: BTreeMap<(i64, bool), usize>,
    /// Partitioned files (4.1): the parent surface of each partition's surface entity.
    parents: HashMap<i64, i32>,
    /// Partitioned 3D meshes (4.1): partition surfaces whose parent is a volume, the
    /// interfaces between volume partitions. Their triangles lie inside the volume, not on
    /// a model surface, and are skipped.
    interfaces: HashSet<i64>,
    /// The model, as the file gives it (see [`ModelParts::finish`]).
    model: ModelParts,
}

/// The parts of the file's model, collected while reading.
#[derive(Default)]
struct ModelParts {
    physical_names: Vec<PhysicalName>,
    /// `$Entities` (4.1), if the file has it.
    entities: Option<Vec<Entity>>,
    /// The entity of each node as the file gives it, aligned with `Content::node_tags`
    /// (`None`: not given, MSH 2.2 `$Nodes`).
    node_entity: Vec<Option<(u8, i32)>>,
    /// The parametric coordinates of each node, up to the last that has some (empty when
    /// none has: most files).
    node_param: Vec<Option<[f64; 3]>>,
    /// Point and line elements (on the file's entities).
    elements: Vec<Element>,
    /// Every entity an element is on, with the physical tags the elements give it (MSH
    /// 2.2; none in 4.1, where `$Entities` holds them).
    element_entities: BTreeMap<(u8, i32), BTreeSet<i32>>,
    /// The last key added to `element_entities` (elements come in runs on one entity).
    last_entity: Option<(u8, i32, i32)>,
    /// Partitioned files (4.1): the parent (dimension, tag) of each partition entity.
    parents: HashMap<(u8, i32), (u8, i32)>,
}

impl ModelParts {
    /// Records the parametric coordinates of the node just added to `node_entity`.
    #[inline]
    fn push_param(&mut self, u: Option<[f64; 3]>) {
        if u.is_some() || !self.node_param.is_empty() {
            self.node_param.resize(self.node_entity.len() - 1, None);
            self.node_param.push(u);
        }
    }

    /// Notes an element of dimension `dim` on entity `tag` in physical group `physical`
    /// (0: none).
    #[inline]
    fn on_entity(&mut self, dim: u8, tag: i32, physical: i32) {
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
    /// classify put on the entity of the lowest-dimension element that holds them (as Gmsh
    /// reads MSH 2.2), and entities that `$Entities` lacks derived from the elements.
    fn finish(mut self, data: &MeshData) -> Model {
        if !self.parents.is_empty() {
            let parents = &self.parents;
            for (v, on) in self.node_entity.iter_mut().enumerate() {
                if let Some((dim, tag)) = *on {
                    if let Some(&(pd, pt)) = parents.get(&(dim, tag)) {
                        *on = Some((pd, pt));
                        if let (true, Some(param)) = (pd != dim, self.node_param.get_mut(v)) {
                            *param = None;
                        }
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
            let on = &mut self.node_entity;
            let mut classify = |nodes: &[u32], dim: u8, tag: i32| {
                for &v in nodes {
                    if let Some(slot @ None) = on.get_mut(v as usize) {
                        *slot = Some((dim, tag));
                    }
                }
            };
            for dim in [0, 1] {
                for e in self.elements.iter().filter(|e| e.dim == dim) {
                    classify(&e.nodes, dim, e.entity);
                }
            }
            for (t, &s) in data.triangles.iter().zip(&data.triangle_surface) {
                classify(t, 2, s);
            }
            for (q, &s) in data.quads.iter().zip(&data.quad_surface) {
                classify(q, 2, s);
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
        }
    }
}

impl Content {
    fn new() -> Content {
        Content {
            data: MeshData::default(),
            node_tags: Vec::new(),
            tag_pos: None,
            map: None,
            skipped: BTreeMap::new(),
            parents: HashMap::new(),
            interfaces: HashSet::new(),
            model: ModelParts::default(),
        }
    }

    /// Notes where the node tag just pushed is, when asked to (see [`duplicate_node`]).
    #[inline]
    fn note_tag(&mut self, pos: usize) {
        if let Some(v) = &mut self.tag_pos {
            v.push(pos);
        }
    }

    /// Counts `n` skipped elements of type `etype` (on a partition interface or not).
    fn skip(&mut self, etype: i64, n: u64, on_interface: bool) {
        *self.skipped.entry((etype, on_interface)).or_default() += n as usize;
    }
}

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
        return Err(ReadError::UnknownFormat {
            path: path.to_path_buf(),
            builtins: crate::mesh::builtin::NAMES.join(", "),
        });
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
                    "unsupported MSH version `{}` (quadrecomb reads versions 2.2 and 4.1)",
                    show(vt)
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
                        "unsupported data size `{}` in a binary file (only 8-byte size_t is read)",
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
    let model = c.model.finish(&c.data);
    c.data.model = Some(Box::new(model));
    Ok(MshFile {
        data: c.data,
        version,
        binary: p.binary,
        ignored_elements: c.skipped.values().sum(),
        skipped: c
            .skipped
            .into_iter()
            .map(|((t, on_interface), n)| {
                let (_, dim, name) = element_type(t).expect("skipped types are known");
                SkippedElements {
                    gmsh_type: t,
                    name,
                    dim,
                    count: n,
                    on_partition_interfaces: on_interface,
                }
            })
            .collect(),
    })
}

/// Checks that a node's coordinates are finite.
fn check_finite(p: &Parser<'_>, at: usize, tag: u64, x: [f64; 3]) -> Res<()> {
    if x.iter().all(|v| v.is_finite()) {
        return Ok(());
    }
    let msg = format!(
        "node {tag} has a non-finite coordinate ({}, {}, {})",
        x[0], x[1], x[2]
    );
    Err(p.err(at, msg))
}

fn to_i32(p: &Parser<'_>, at: usize, v: i64, what: &str) -> Res<i32> {
    i32::try_from(v).map_err(|_| {
        let msg = format!("{what} {v} is out of range");
        p.err(at, msg)
    })
}

/// The `$PartitionedEntities` section of MSH 4.1 (a mesh split into partitions, whose
/// elements are on new entities, one per partition and model entity): the parent of each
/// partition surface, into `c.parents`, or, for a surface cut from a volume (an interface
/// between volume partitions), its tag into `c.interfaces`. Reads up to the surfaces
/// (points and curves are read past); the caller skips the rest.
fn partitioned41(p: &mut Parser<'_>, c: &mut Content) -> Res<()> {
    let s = "$PartitionedEntities";
    p.binary_data_start();
    p.size_t(s, &|| "the number of partitions".into())?;
    let ghosts = p.size_t(s, &|| "the number of ghost entities".into())?;
    for _ in 0..ghosts {
        p.int_field(s, &|| "a ghost entity tag".into())?;
        p.int_field(s, &|| "a ghost entity's partition".into())?;
    }
    let counts: Vec<u64> = ["points", "curves", "surfaces", "volumes"]
        .iter()
        .map(|what| p.size_t(s, &|| format!("the number of partition {what}")))
        .collect::<Res<_>>()?;
    for (dim, &count) in counts.iter().take(3).enumerate() {
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

/// The `$Entities` section of MSH 4.1, in either encoding: points (tag, coordinates,
/// physical tags), then curves, surfaces and volumes (tag, bounding box, physical tags,
/// signed tags of the bounding entities).
fn entities41(p: &mut Parser<'_>, c: &mut Content) -> Res<()> {
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

/// The `$Nodes` section of MSH 4.1, in either encoding: the headers read alike, the
/// blocks' tags and coordinates per encoding.
fn nodes41(p: &mut Parser<'_>, c: &mut Content) -> Res<()> {
    let s = "$Nodes";
    let (hp, blocks, total) = header41(p, s, "node")?;
    let left = p.b.len() - p.pos;
    let min_bytes = if p.binary { 32 } else { 8 };
    c.node_tags.reserve(cap(total, min_bytes, left));
    c.data.vertices.reserve(cap(total, min_bytes, left));
    c.model.node_entity.reserve(cap(total, min_bytes, left));
    for blk in 0..blocks {
        let what_blk = || format!("the header of node block {} of {blocks}", blk + 1);
        let dp = p.pos;
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

/// The first `n` of `u` as a node's parametric coordinates: none if `n` is 0 or one is not
/// finite (then they are not written back).
fn parametric(n: usize, u: [f64; 3]) -> Option<[f64; 3]> {
    (n > 0 && u.iter().all(|x| x.is_finite())).then_some(u)
}

/// The tags, then coordinates (with their parametric ones), of an ASCII node block.
fn node_block41_ascii(p: &mut Parser<'_>, c: &mut Content, b: &NodeBlock41) -> Res<()> {
    let s = "$Nodes";
    let (blk, n, extra) = (b.index, b.len, b.extra);
    for i in 0..n {
        let tag = p.uint(s, &|| format!("node tag {} of block {}", i + 1, blk + 1))?;
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

fn nodes22_ascii(p: &mut Parser<'_>, c: &mut Content) -> Res<()> {
    let s = "$Nodes";
    let total = p.uint(s, &|| "the number of nodes".into())?;
    let left = p.b.len() - p.pos;
    c.node_tags.reserve(cap(total, 8, left));
    c.data.vertices.reserve(cap(total, 8, left));
    for i in 0..total {
        let tag = p.uint(s, &|| format!("the tag of node {} of {total}", i + 1))?;
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
fn parametric_nodes22(p: &mut Parser<'_>, c: &mut Content) -> Res<()> {
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

fn nodes22_binary(p: &mut Parser<'_>, c: &mut Content) -> Res<()> {
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

/// Adds a triangle or quad (`nodes` are its 3 or 4 node tags) of element `tag` on `surface`, or counts an
/// ignored element. `at` is where the element starts (for messages).
#[inline]
fn push_element(
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
        idx[k] = map.get(n).ok_or_else(|| {
            let msg = format!("element {tag} refers to node {n}, which does not exist");
            p.err(at, msg)
        })?;
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
fn push_lower(
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
        .map(|&n| {
            map.get(n).ok_or_else(|| {
                let msg = format!("element {tag} refers to node {n}, which does not exist");
                p.err(at, msg)
            })
        })
        .collect::<Res<Vec<u32>>>()?;
    c.model.elements.push(Element {
        gmsh_type: etype,
        dim,
        entity,
        nodes,
    });
    Ok(())
}

/// Whether elements of a type of dimension `dim` with `nodes` nodes go to the model: points
/// and lines with a fixed number of nodes.
fn is_lower(dim: u8, nodes: usize) -> bool {
    dim <= 1 && nodes > 0
}

/// Most nodes of a point or line element Gmsh knows (Line 11).
const MAX_LOWER_NODES: usize = 16;

/// The `$Elements` section of MSH 4.1, in either encoding: the headers read alike, the
/// blocks' elements per encoding. Returns the number of elements.
fn elements41(p: &mut Parser<'_>, c: &mut Content, map: &NodeMap) -> Res<u64> {
    let s = "$Elements";
    let (hp, blocks, total) = header41(p, s, "element")?;
    let mut seen = 0u64;
    for blk in 0..blocks {
        let what_blk = || format!("the header of element block {} of {blocks}", blk + 1);
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
        let block = Block41 {
            index: blk,
            len: n,
            etype,
            dim,
            nodes,
            surface,
            on_interface: entity_dim == 2 && c.interfaces.contains(&entity),
        };
        if block.keep() || block.lower() {
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
    /// On a partition interface (skipped whatever its type).
    on_interface: bool,
}

impl Block41 {
    /// Whether the block's elements are read: triangles and quads not on an interface.
    fn keep(&self) -> bool {
        (self.etype == TRIANGLE || self.etype == QUAD) && !self.on_interface
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
        c.skip(b.etype, b.len, b.on_interface);
    }
    Ok(())
}

/// What an element line holds, for messages: "the 3 nodes of element 72 (type 2)".
fn element_nodes(tag: u64, etype: i64, nodes: usize) -> String {
    match nodes {
        1 => format!("the node of element {tag} (type {etype})"),
        _ => format!("the {nodes} nodes of element {tag} (type {etype})"),
    }
}

/// The message for a binary block or group (`what`) of elements without a fixed number of
/// nodes (polygons and the like), whose records have no fixed size.
fn variable_size(what: &str, etype: i64, name: &str) -> String {
    format!(
        "{what} holds elements of type {etype} ({name}), which have no fixed number of nodes: not read in binary files"
    )
}

/// The message for an element type Gmsh does not know; `what` names the element or block.
fn unknown_type(what: &str, etype: i64) -> String {
    format!(
        "{what} has type {etype}, which is not a Gmsh element type (Gmsh 4.15 numbers its types 1 to 140)"
    )
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
    }
    if !b.keep() {
        c.skip(b.etype, b.len, b.on_interface);
    }
    Ok(())
}

/// Surface of an MSH 2.2 element: its elementary tag (the second tag), else 0 (as Gmsh
/// reads it: an element without one is on entity 0, not on another surface).
fn surface22(tags: &[i64]) -> i64 {
    tags.get(1).copied().unwrap_or(0)
}

fn elements22_ascii(p: &mut Parser<'_>, c: &mut Content, map: &NodeMap) -> Res<u64> {
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
            c.skip(etype, 1, false);
        }
        if nn == 0 {
            p.skip_line();
            continue;
        }
        for k in 0..nn {
            let v = p.uint(s, &|| format!("node {} of element {tag}", k + 1))?;
            if let (true, Some(slot)) = (keep || lower, nodes.get_mut(k)) {
                *slot = v;
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

fn elements22_binary(p: &mut Parser<'_>, c: &mut Content, map: &NodeMap) -> Res<u64> {
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
        }
        if !keep {
            c.skip(etype, n as u64, false);
        }
        seen += n as u64;
    }
    Ok(total)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integers_parse_exactly_or_not_at_all() {
        assert_eq!(parse_u64(b"0"), Some(0));
        assert_eq!(parse_u64(b"18446744073709551615"), Some(u64::MAX));
        assert_eq!(parse_u64(b"18446744073709551616"), None);
        assert_eq!(parse_u64(b"-1"), None);
        assert_eq!(parse_u64(b"1.0"), None);
        assert_eq!(parse_u64(b""), None);
        assert_eq!(parse_i64(b"-9223372036854775808"), Some(i64::MIN));
        assert_eq!(parse_i64(b"-9223372036854775809"), None);
        assert_eq!(parse_i64(b"9223372036854775808"), None);
        assert_eq!(parse_i64(b"+5"), Some(5));
        assert_eq!(parse_i64(b"-"), None);
    }

    #[test]
    fn node_map_is_dense_for_compact_tags_and_sparse_otherwise() {
        let dense = NodeMap::new(&[3, 1, 2]).unwrap();
        assert!(matches!(dense, NodeMap::Dense(_)));
        assert_eq!(
            (dense.get(1), dense.get(3), dense.get(0), dense.get(99)),
            (Some(1), Some(0), None, None)
        );
        let sparse = NodeMap::new(&[u64::MAX, 5]).unwrap();
        assert!(matches!(sparse, NodeMap::Sparse(_)));
        assert_eq!(
            (sparse.get(u64::MAX), sparse.get(5), sparse.get(6)),
            (Some(0), Some(1), None)
        );
        assert_eq!(NodeMap::new(&[4, 7, 4]).err(), Some(4));
        assert_eq!(NodeMap::new(&[u64::MAX, 9, u64::MAX]).err(), Some(u64::MAX));
    }

    #[test]
    fn shown_tokens_are_short_and_printable() {
        assert_eq!(show(b"ab\x01"), "ab\\x01");
        assert!(show(&[b'x'; 100]).ends_with("..."));
    }
}
