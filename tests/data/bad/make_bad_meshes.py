"""Small bad (and edge-case) MSH files for the bad-input tests in tests/it/io.rs, written by
hand so that each shows exactly one problem. Run from this directory: python3 make_bad_meshes.py"""
import math

HEAD = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"


def msh22(nodes, elements, node_count=None, elem_count=None, end_nodes=True):
    s = HEAD + "$Nodes\n%d\n" % (len(nodes) if node_count is None else node_count)
    for i, (x, y, z) in enumerate(nodes, 1):
        s += "%d %s %s %s\n" % (i, x, y, z)
    if end_nodes:
        s += "$EndNodes\n"
    s += "$Elements\n%d\n" % (len(elements) if elem_count is None else elem_count)
    for i, (etype, vs) in enumerate(elements, 1):
        s += "%d %d 2 1 1 %s\n" % (i, etype, " ".join(map(str, vs)))
    return s + "$EndElements\n"


SQUARE = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]
TWO = [(2, (1, 2, 3)), (2, (1, 3, 4))]

files = {
    "unknown_format.msh": "solid cube\n  facet normal 0 0 1\nendsolid cube\n",
    "unsupported_version.msh": "$MeshFormat\n3.0 0 8\n$EndMeshFormat\n",
    "wrong_node_count.msh": msh22(SQUARE, TWO, node_count=5),
    "wrong_element_count.msh": msh22(SQUARE, TWO, elem_count=3),
    "unknown_node.msh": msh22(SQUARE, [(2, (1, 2, 3)), (2, (1, 3, 9))]),
    "nan_coordinate.msh": msh22([(0, 0, 0), (1, 0, 0), ("nan", 1, 0), (0, 1, 0)], TWO),
    "inf_coordinate.msh": msh22([(0, 0, 0), (1, 0, 0), (1, "inf", 0), (0, 1, 0)], TWO),
    "degenerate.msh": msh22(SQUARE + [(2, 2, 0)], TWO + [(2, (1, 3, 5))]),
    "duplicate.msh": msh22(SQUARE, TWO + [(2, (3, 4, 1))]),
    "non_manifold.msh": msh22(SQUARE + [(1, 0, 1)], TWO + [(2, (1, 3, 5))]),
    "inconsistent_orientation.msh": msh22(SQUARE, [(2, (1, 2, 3)), (2, (1, 4, 3))]),
    "empty.msh": HEAD,
    "no_triangles.msh": msh22(SQUARE, [(1, (1, 2)), (1, (2, 3))]),
    "odd_triangles.msh": msh22(SQUARE + [(2, 0, 0)], TWO + [(2, (2, 5, 3))]),
    "missing_end_nodes.msh": msh22(SQUARE, TWO, end_nodes=False),
}
files["truncated.msh"] = files["odd_triangles.msh"][:-40]

# Moebius strip: n segments around a circle, the strip's direction turns by pi once around,
# so the last segment joins the first one flipped.
n = 12
nodes = []
for i in range(n):
    t = 2 * math.pi * i / n
    for s in (-0.3, 0.3):
        r = 1 + s * math.cos(t / 2)
        nodes.append((r * math.cos(t), r * math.sin(t), s * math.sin(t / 2)))
elements = []
for i in range(n):
    a, b = 2 * i + 1, 2 * i + 2
    if i + 1 < n:
        c, d = 2 * i + 3, 2 * i + 4
    else:
        c, d = 2, 1  # flipped join
    elements += [(2, (a, c, b)), (2, (b, c, d))]
files["moebius.msh"] = msh22(nodes, elements)

for name, text in files.items():
    with open(name, "w") as f:
        f.write(text)
