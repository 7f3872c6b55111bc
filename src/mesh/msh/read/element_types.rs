//! Gmsh's element types: the table of every type Gmsh knows (nodes, dimension, name), the
//! types that are read (triangles, quads) or kept in the model (points, lines), and the
//! messages that name a type.

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
pub(in crate::internals::mesh::msh) fn element_type(
    etype: i64,
) -> Option<(usize, u8, &'static str)> {
    let i = ELEMENT_TYPES.binary_search_by_key(&etype, |e| e.0).ok()?;
    let (_, nodes, dim, name) = ELEMENT_TYPES[i];
    Some((nodes, dim, name))
}

pub(super) const TRIANGLE: i64 = 2;
pub(super) const QUAD: i64 = 3;

/// Whether elements of a type of dimension `dim` with `nodes` nodes go to the model: points
/// and lines with a fixed number of nodes.
pub(super) fn is_lower(dim: u8, nodes: usize) -> bool {
    dim <= 1 && nodes > 0
}

/// Most nodes of a point or line element Gmsh knows (Line 11).
pub(super) const MAX_LOWER_NODES: usize = 16;

/// What an element line holds, for messages: "the 3 nodes of element 72 (type 2)".
pub(super) fn element_nodes(tag: u64, etype: i64, nodes: usize) -> String {
    match nodes {
        1 => format!("the node of element {tag} (type {etype})"),
        _ => format!("the {nodes} nodes of element {tag} (type {etype})"),
    }
}

/// The message for a binary block or group (`what`) of elements without a fixed number of
/// nodes (polygons and the like), whose records have no fixed size.
pub(super) fn variable_size(what: &str, etype: i64, name: &str) -> String {
    format!(
        "{what} holds elements of type {etype} ({name}), which have no fixed number of nodes: not read in binary files"
    )
}

/// The message for an element type Gmsh does not know; `what` names the element or block.
pub(super) fn unknown_type(what: &str, etype: i64) -> String {
    format!(
        "{what} has type {etype}, which is not a Gmsh element type (Gmsh 4.15 numbers its types 1 to 140)"
    )
}
