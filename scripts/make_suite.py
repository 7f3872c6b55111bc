#!/usr/bin/env python3
"""Generate the benchmark suite's Gmsh meshes, `meshes/suite/*.msh` (issue 24).

Needs the `gmsh` PyPI package, version 4.15.2 (`pip install gmsh==4.15.2`); the script refuses
another version unless --any-version is given (the meshers change between versions, and the
committed files are the ones 4.15.2 makes). Gmsh is never a runtime dependency of quadrecomb,
which embeds the committed files (`quadrecomb suite list`, `--mesh suite:NAME`).

Usage: python3 scripts/make_suite.py [--out DIR] [--only NAME ...] [--any-version]

  --out DIR       where to write the .msh files (default: the repository's meshes/suite/)
  --only NAME     make only these cases
  --any-version   run with another gmsh version (counts and bytes will differ)

Prints, per case, the triangle count, the number of surfaces and of surfaces with an odd
number of triangles, a BLAKE2b-128 hash of the file, its size, and whether a second run gave
identical bytes; exits 1 if a count differs from the expected one or a rerun differs.

The suite's other members are not made here: `sphere` and `borouchaki` are the built-in
meshes of scripts/make_meshes.py, and `grid-1m` is generated at first use by quadrecomb
(`generate grid --triangles 1000000 --seed 24 --holes`). Every case and its purpose is in
docs/meshes.md and meshes/README.md.

Output: as scripts/make_meshes.py: MSH 4.1 binary, triangles only (physical groups of
surfaces, Mesh.SaveAll = 0), one thread, Mesh.RandomSeed = 1: reruns are byte-identical.
Cases without physical groups of their own get one per surface, tagged like the surface.
"""

import argparse
import hashlib
import math
import os
import sys
import tempfile

import gmsh

GMSH_VERSION = "4.15.2"

# The plate: the paper's domain (unit square minus the disk of radius 0.15 at (0.75, 0.75))
# meshed by four of Gmsh's 2D algorithms with the same uniform size.
PLATE_SIZE = 0.02
PLATE_ALGOS = {"delquad": 8, "delaunay": 5, "frontal": 6, "meshadapt": 1}


def common_options():
    """Options that make a run deterministic and the output minimal."""
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.option.setNumber("General.Verbosity", 2)
    gmsh.option.setNumber("General.NumThreads", 1)
    gmsh.option.setNumber("Mesh.RandomSeed", 1)
    gmsh.option.setNumber("Geometry.OCCParallel", 0)


def uniform_size(h):
    gmsh.option.setNumber("Mesh.MeshSizeMin", h)
    gmsh.option.setNumber("Mesh.MeshSizeMax", h)


def plate(algorithm):
    def build():
        occ = gmsh.model.occ
        square = occ.addRectangle(0, 0, 0, 1, 1)
        disk = occ.addDisk(0.75, 0.75, 0, 0.15, 0.15)
        occ.cut([(2, square)], [(2, disk)])
        occ.synchronize()
        uniform_size(PLATE_SIZE)
        gmsh.option.setNumber("Mesh.Algorithm", algorithm)

    return build


def graded():
    """Unit square, size 0.0004 within 0.002 of the corner (0, 0), growing to 0.05 at 0.6 and
    beyond: a ratio of 125 between the smallest and the largest triangles."""
    occ = gmsh.model.occ
    occ.addRectangle(0, 0, 0, 1, 1)
    occ.synchronize()
    f = gmsh.model.mesh.field
    dist = f.add("Distance")
    corner = [p for _, p in gmsh.model.getEntities(0)
              if max(abs(c) for c in gmsh.model.getValue(0, p, [])) < 1e-12]
    f.setNumbers(dist, "PointsList", corner)
    thr = f.add("Threshold")
    f.setNumber(thr, "InField", dist)
    f.setNumber(thr, "SizeMin", 0.0004)
    f.setNumber(thr, "SizeMax", 0.05)
    f.setNumber(thr, "DistMin", 0.002)
    f.setNumber(thr, "DistMax", 0.6)
    f.setAsBackgroundMesh(thr)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    gmsh.option.setNumber("Mesh.Algorithm", 5)


def anisotropic():
    """Unit square meshed isotropically (Frontal-Delaunay, size 0.02), then its nodes mapped
    by (x, y) -> (5x, y/5): the rectangle [0, 5] x [0, 0.2] with every triangle stretched
    25:1 along x, as in a boundary layer. The stretch is applied to the mesh (Gmsh's
    affineTransform), so no anisotropic mesher is involved and the count is the isotropic one."""
    occ = gmsh.model.occ
    occ.addRectangle(0, 0, 0, 1, 1)
    occ.synchronize()
    uniform_size(0.02)
    gmsh.option.setNumber("Mesh.Algorithm", 6)


def anisotropic_after(model_entities):
    # x * 5, y / 5: aspect ratio 25.
    gmsh.model.mesh.affineTransform(
        [5.0, 0, 0, 0, 0, 0.2, 0, 0, 0, 0, 1, 0], model_entities
    )


def torus():
    gmsh.model.occ.addTorus(0, 0, 0, 1, 0.3)
    gmsh.model.occ.synchronize()
    uniform_size(0.07)
    gmsh.option.setNumber("Mesh.Algorithm", 6)


def cylinder():
    gmsh.model.occ.addCylinder(0, 0, 0, 0, 0, 2, 0.5)
    gmsh.model.occ.synchronize()
    uniform_size(0.06)
    gmsh.option.setNumber("Mesh.Algorithm", 6)


def revolution():
    """A vase: a B-spline profile in the xz-plane revolved about the z axis."""
    occ = gmsh.model.occ
    profile = [(0.5, 0.0), (0.9, 0.4), (0.6, 1.0), (0.35, 1.4), (0.55, 1.9)]
    pts = [occ.addPoint(r, 0, z) for r, z in profile]
    curve = occ.addBSpline(pts)
    occ.revolve([(1, curve)], 0, 0, 0, 0, 0, 1, 2 * math.pi)
    occ.synchronize()
    uniform_size(0.05)
    gmsh.option.setNumber("Mesh.Algorithm", 6)


def materials():
    """A multi-material plate: the rectangle [0, 2] x [0, 1] cut into a matrix, two disk
    inclusions and a rectangular insert (conforming interfaces, OCC fragment), with named
    physical groups "matrix", "inclusions" and "insert"."""
    occ = gmsh.model.occ
    outer = occ.addRectangle(0, 0, 0, 2, 1)
    d1 = occ.addDisk(0.5, 0.5, 0, 0.25, 0.25)
    d2 = occ.addDisk(1.0, 0.3, 0, 0.12, 0.12)
    ins = occ.addRectangle(1.3, 0.2, 0, 0.5, 0.6)
    out, _ = occ.fragment([(2, outer)], [(2, d1), (2, d2), (2, ins)])
    occ.synchronize()
    surfaces = sorted(t for d, t in out if d == 2)
    # Classify the fragments by their centre of mass.
    groups = {"matrix": [], "inclusions": [], "insert": []}
    for s in surfaces:
        x, y, _ = occ.getCenterOfMass(2, s)
        if abs(x - 0.5) < 1e-6 and abs(y - 0.5) < 1e-6 or abs(x - 1.0) < 1e-6 and abs(y - 0.3) < 1e-6:
            groups["inclusions"].append(s)
        elif abs(x - 1.55) < 1e-6 and abs(y - 0.5) < 1e-6:
            groups["insert"].append(s)
        else:
            groups["matrix"].append(s)
    for tag, (name, members) in enumerate(groups.items(), start=1):
        if not members:
            sys.exit(f"materials: no surface for group {name}")
        gmsh.model.addPhysicalGroup(2, members, tag, name)
    uniform_size(0.025)
    gmsh.option.setNumber("Mesh.Algorithm", 6)


def holes():
    """The rectangle [0, 2] x [0, 1] minus 6 x 3 = 18 disks on a jittered lattice, radii
    from 0.05 to 0.13 (fixed formula, no random numbers)."""
    occ = gmsh.model.occ
    rect = occ.addRectangle(0, 0, 0, 2, 1)
    disks = []
    for i in range(6):
        for j in range(3):
            k = 3 * i + j
            x = 0.2 + 0.32 * i + 0.04 * math.sin(1.7 * k)
            y = 0.2 + 0.3 * j + 0.03 * math.cos(2.3 * k)
            r = 0.05 + 0.08 * (0.5 + 0.5 * math.sin(0.9 * k + 0.4))
            disks.append((2, occ.addDisk(x, y, 0, r, r)))
    occ.cut([(2, rect)], disks)
    occ.synchronize()
    uniform_size(0.02)
    gmsh.option.setNumber("Mesh.Algorithm", 6)


def odd_pieces():
    """Seven disjoint planar pieces (disks, squares, a triangle, an annulus) of different
    sizes, an ellipse: seven surfaces, so seven components of the dual graph, five of them with an
    odd number of triangles (checked by the script), in each of which a triangle must stay."""
    occ = gmsh.model.occ
    occ.addDisk(0, 0, 0, 0.5, 0.5)
    occ.addDisk(1.5, 0, 0, 0.3, 0.3)
    occ.addRectangle(2.2, -0.4, 0, 0.8, 0.8)
    occ.addRectangle(3.3, -0.2, 0, 0.4, 0.5)
    p = [occ.addPoint(4.0, -0.4, 0), occ.addPoint(4.9, -0.4, 0), occ.addPoint(4.3, 0.5, 0)]
    lines = [occ.addLine(p[0], p[1]), occ.addLine(p[1], p[2]), occ.addLine(p[2], p[0])]
    occ.addPlaneSurface([occ.addCurveLoop(lines)])
    outer = occ.addDisk(5.8, 0, 0, 0.5, 0.5)
    inner = occ.addDisk(5.8, 0, 0, 0.2, 0.2)
    occ.cut([(2, outer)], [(2, inner)])
    occ.addDisk(7.0, 0, 0, 0.35, 0.2)
    occ.synchronize()
    uniform_size(0.046)
    gmsh.option.setNumber("Mesh.Algorithm", 6)


# name: (builder, what to do to the mesh after meshing or None)
CASES = {
    **{f"plate-{name}": (plate(algo), None) for name, algo in PLATE_ALGOS.items()},
    "graded-corner": (graded, None),
    "anisotropic-stretched": (anisotropic, anisotropic_after),
    "torus": (torus, None),
    "capped-cylinder": (cylinder, None),
    "vase-revolution": (revolution, None),
    "materials": (materials, None),
    "many-holes": (holes, None),
    "odd-pieces": (odd_pieces, None),
}

# Expected (triangles, surfaces, surfaces with an odd triangle count) with gmsh 4.15.2.
EXPECTED = {
    "plate-delquad": (4822, 1, 0),
    "plate-delaunay": (6178, 1, 0),
    "plate-frontal": (5538, 1, 0),
    "plate-meshadapt": (5896, 1, 0),
    "graded-corner": (3394, 1, 0),
    "anisotropic-stretched": (5830, 1, 0),
    "torus": (5878, 1, 0),
    "capped-cylinder": (5308, 3, 2),
    "vase-revolution": (7465, 1, 1),
    "materials": (7668, 4, 2),
    "many-holes": (8975, 1, 1),
    "odd-pieces": (3791, 7, 5),
}


def make(name, path):
    """Meshes case `name` and writes it to `path`; returns (triangles, surfaces, odd)."""
    build, after = CASES[name]
    gmsh.initialize(readConfigFiles=False)
    try:
        common_options()
        gmsh.model.add(name)
        build()
        gmsh.model.mesh.generate(2)
        if after is not None:
            after([])
        if not gmsh.model.getPhysicalGroups(2):
            for dim, tag in gmsh.model.getEntities(2):
                gmsh.model.addPhysicalGroup(dim, [tag], tag)
        gmsh.option.setNumber("Mesh.SaveAll", 0)
        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        gmsh.option.setNumber("Mesh.Binary", 1)
        counts = []
        for _, tag in gmsh.model.getEntities(2):
            types, tags, _ = gmsh.model.mesh.getElements(2, tag)
            others = [ty for ty in types if ty != 2]
            if others:
                sys.exit(f"{name}: unexpected 2D element types {others}")
            counts.append(sum(len(t) for t in tags))
        gmsh.write(path)
        return sum(counts), len(counts), sum(c % 2 for c in counts)
    finally:
        gmsh.finalize()


def digest(path):
    with open(path, "rb") as f:
        return hashlib.blake2b(f.read(), digest_size=16).hexdigest()


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=os.path.join(here, "..", "meshes", "suite"))
    ap.add_argument("--only", nargs="+", choices=sorted(CASES), metavar="NAME")
    ap.add_argument("--any-version", action="store_true")
    args = ap.parse_args()
    if gmsh.__version__ != GMSH_VERSION:
        msg = (f"gmsh {gmsh.__version__}, the committed files were made with {GMSH_VERSION} "
               f"(pip install gmsh=={GMSH_VERSION})")
        if not args.any_version:
            sys.exit(f"error: {msg}; --any-version runs anyway")
        print(f"warning: {msg}; counts and bytes will differ", file=sys.stderr)
    os.makedirs(args.out, exist_ok=True)
    status = 0
    for name in args.only or CASES:
        path = os.path.join(args.out, f"{name}.msh")
        got = make(name, path)
        with tempfile.TemporaryDirectory() as tmp:
            again = os.path.join(tmp, f"{name}.msh")
            make(name, again)
            same = digest(path) == digest(again)
        want = EXPECTED.get(name)
        note = "" if got == want else f"  (EXPECTED {want})"
        print(f"{name}: {got[0]} triangles, {got[1]} surfaces ({got[2]} odd){note}, "
              f"blake2b-128 {digest(path)}, {os.path.getsize(path)} bytes, "
              f"rerun identical: {same}")
        if got != want or not same:
            status = 1
    return status


if __name__ == "__main__":
    sys.exit(main())
