# Checks an all-quad output against its input, both read by meshio (not by quadrecomb):
# no triangle; every quad strictly convex (cross products of consecutive sides, against the
# quad's Newell normal, all positive); every node not in the input lies strictly inside one
# boundary side of the input (a side used by one input element) on its chord (with sheet
# refinement: every new node on the output's boundary does, the others are inner); conformity:
# every edge is used by one or two quads (or, where surfaces meet, by as many as the input
# edge it lies on), and an edge used by one lies on an input boundary side; the quads cover the input's area. Prints one JSON object.
# Usage: python3 all_quad_check.py INPUT.msh OUTPUT.(msh|vtu) [INPUT OUTPUT ...]: one line
# per pair.
import json
import sys

import meshio
import numpy as np



def cells(m, kind):
    blocks = [c.data for c in m.cells if c.type == kind]
    return np.concatenate(blocks) if blocks else np.zeros((0, 3 if kind == "triangle" else 4), int)


def edge_use(elements):
    use = {}
    for e in elements:
        n = len(e)
        for i in range(n):
            k = tuple(sorted((int(e[i]), int(e[(i + 1) % n]))))
            use[k] = use.get(k, 0) + 1
    return use


def check(inp, out):
    tri_in = cells(inp, "triangle")
    quad_in = cells(inp, "quad")
    pin = inp.points
    scale = float(np.max(np.abs(pin))) or 1.0
    tol = 1e-9 * scale
    boundary_in = [
        k for k, n in edge_use(list(tri_in) + list(quad_in)).items() if n == 1
    ]
    seg = np.array([[pin[a], pin[b]] for a, b in boundary_in]) if boundary_in else np.zeros((0, 2, 3))


    def on_boundary_side(x):
        """Index of the input boundary side x lies strictly inside of (on its chord), or -1."""
        if len(seg) == 0:
            return -1
        a, b = seg[:, 0], seg[:, 1]
        d = b - a
        t = np.einsum("ij,ij->i", x - a, d) / np.einsum("ij,ij->i", d, d)
        foot = a + t[:, None] * d
        dist = np.linalg.norm(x - foot, axis=1)
        ok = np.where((dist < tol) & (t > 1e-9) & (t < 1 - 1e-9))[0]
        return int(ok[0]) if len(ok) else -1


    # Output points matched to input points by coordinates (writers may renumber).
    key = {tuple(np.round(p / tol).astype(np.int64)): i for i, p in enumerate(pin)}
    new_nodes = []
    for i, p in enumerate(out.points):
        if tuple(np.round(p / tol).astype(np.int64)) not in key:
            new_nodes.append(i)
    tri_out = cells(out, "triangle")
    quads = cells(out, "quad")
    used = set(int(v) for q in quads for v in q) | set(int(v) for t in tri_out for v in t)
    new_nodes = [i for i in new_nodes if i in used]
    off_side = [i for i in new_nodes if on_boundary_side(out.points[i]) < 0]

    P = out.points
    nonconvex = 0
    for q in quads:
        c = P[q]
        n = np.zeros(3)
        for i in range(4):
            a, b = c[i], c[(i + 1) % 4]
            n += np.cross(a, b)
        ok = True
        for i in range(4):
            a, b, cc = c[i], c[(i + 1) % 4], c[(i + 2) % 4]
            if np.dot(np.cross(b - a, cc - b), n) <= 0:
                ok = False
        nonconvex += not ok

    # Conformity. An edge may be used by more than two elements only where surfaces meet:
    # along an input edge used by as many.
    use = edge_use(list(quads) + list(tri_out))
    junctions_in = [(k, n) for k, n in edge_use(list(tri_in) + list(quad_in)).items() if n > 2]


    def on_input_junction(a, b, n):
        for (u, v), m in junctions_in:
            if m != n:
                continue
            s0, d = pin[u], pin[v] - pin[u]
            ok = True
            for x in (P[a], P[b]):
                t = np.dot(x - s0, d) / np.dot(d, d)
                ok &= bool(np.linalg.norm(x - (s0 + t * d)) <= tol and -1e-9 <= t <= 1 + 1e-9)
            if ok:
                return True
        return False


    over = sum(1 for (a, b), n in use.items() if n > 2 and not on_input_junction(a, b, n))


    def on_input_boundary(a, b):
        if len(seg) == 0:
            return False
        s0, d = seg[:, 0], seg[:, 1] - seg[:, 0]
        dd = np.einsum("ij,ij->i", d, d)
        good = np.ones(len(seg), bool)
        for x in (P[a], P[b]):
            t = np.einsum("ij,ij->i", x - s0, d) / dd
            dist = np.linalg.norm(x - (s0 + t[:, None] * d), axis=1)
            good &= (dist <= tol) & (t >= -1e-9) & (t <= 1 + 1e-9)
        return bool(good.any())


    hanging = sum(1 for (a, b), n in use.items() if n == 1 and not on_input_boundary(a, b))
    # New nodes on the output's boundary (an edge used once) must lie inside an input
    # boundary side; the others are inner nodes (sheet refinement's midpoints and centres).
    on_out_boundary = set(v for (a, b), n in use.items() if n == 1 for v in (a, b))
    new_boundary = [i for i in new_nodes if i in on_out_boundary]
    new_boundary_off = [i for i in new_boundary if on_boundary_side(P[i]) < 0]


    def area(c):
        n = np.zeros(3)
        for i in range(len(c)):
            n += np.cross(c[i], c[(i + 1) % len(c)])
        return 0.5 * np.linalg.norm(n)


    area_in = sum(area(pin[t]) for t in tri_in) + sum(area(pin[q]) for q in quad_in)
    area_out = sum(area(P[q]) for q in quads) + sum(area(P[t]) for t in tri_out)
    return {
        "triangles": len(tri_out),
        "quads": len(quads),
        "input_triangles": len(tri_in),
        "input_quads": len(quad_in),
        "new_nodes": len(new_nodes),
        "new_nodes_off_boundary_side": len(off_side),
        "new_boundary_nodes": len(new_boundary),
        "new_boundary_nodes_off_boundary_side": len(new_boundary_off),
        "nonconvex": nonconvex,
        "edges_over_two": over,
        "input_junction_edges": len(junctions_in),
        "hanging_edges": hanging,
        "area_in": area_in,
        "area_out": area_out,
        "planar": bool(np.all(pin[:, 2] == 0)),
    }


args = sys.argv[1:]
for k in range(0, len(args), 2):
    print(json.dumps(check(meshio.read(args[k]), meshio.read(args[k + 1]))))
