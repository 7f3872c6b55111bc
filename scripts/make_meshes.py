#!/usr/bin/env python3
"""Generate the built-in benchmark meshes `meshes/borouchaki.msh` and `meshes/sphere.msh`.

Needs the `gmsh` PyPI package, version 4.15.2 (`pip install gmsh==4.15.2`); Gmsh is never a
runtime dependency of quadrecomb, which embeds the committed files.

Usage: python3 scripts/make_meshes.py [--out DIR]

  --out DIR   where to write the .msh files (default: the repository's meshes/)

Prints, per case, the triangle count, a BLAKE2b-128 hash of the file, its size, and whether a
second run gave identical bytes; exits 1 if a count differs from the expected one or a rerun
differs. Expected hashes with gmsh 4.15.2 are in meshes/README.md.

The two cases (parameters exactly as in issue 2):

- borouchaki: the paper's test domain, the unit square minus the disk of radius 0.15 centred at
  (0.75, 0.75) (OpenCASCADE `addRectangle` cut by `addDisk`), sized by the background MathEval
  field 0.00279*(1+8*Fabs(Sqrt((x-0.75)^2+(y-0.75)^2)-0.15)) with
  Mesh.MeshSizeExtendFromBoundary = Mesh.MeshSizeFromPoints = Mesh.MeshSizeFromCurvature = 0 and
  Mesh.Algorithm = 8 (Frontal-Delaunay for quads, the paper's "delquad").
  Expected: 34,456 triangles (the paper had 34,562).
- sphere: OpenCASCADE `addSphere(0, 0, 0, 1)`, Mesh.MeshSizeMin = Mesh.MeshSizeMax = 0.121,
  Mesh.Algorithm = 6 (Frontal-Delaunay), other options default.
  Expected: 2,104 triangles (the paper had 2,152).

Output: MSH 4.1 binary (Mesh.Binary = 1, smaller and faster to parse than ASCII), with only
the 2D elements (triangles) and the nodes they use: one physical group per surface, tagged like
the surface, and Mesh.SaveAll = 0. Entity tags are those of the OCC surfaces (one surface each). General.NumThreads = 1 and Mesh.RandomSeed fixed make runs reproducible; the script
checks that by meshing each case twice and comparing the files byte for byte.
"""

import argparse
import hashlib
import os
import sys
import tempfile

import gmsh

GMSH_VERSION = "4.15.2"

# Expected triangle counts with gmsh 4.15.2 (the paper's counts in comments).
EXPECTED = {
    "borouchaki": 34456,  # paper: 34,562
    "sphere": 2104,  # paper: 2,152
}


def common_options():
    """Options that make a run deterministic and the output minimal."""
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.option.setNumber("General.Verbosity", 2)
    gmsh.option.setNumber("General.NumThreads", 1)
    gmsh.option.setNumber("Mesh.RandomSeed", 1)
    gmsh.option.setNumber("Geometry.OCCParallel", 0)


def build_borouchaki():
    gmsh.model.add("borouchaki")
    occ = gmsh.model.occ
    square = occ.addRectangle(0, 0, 0, 1, 1)
    disk = occ.addDisk(0.75, 0.75, 0, 0.15, 0.15)
    occ.cut([(2, square)], [(2, disk)])
    occ.synchronize()
    field = gmsh.model.mesh.field.add("MathEval")
    gmsh.model.mesh.field.setString(
        field, "F", "0.00279*(1+8*Fabs(Sqrt((x-0.75)^2+(y-0.75)^2)-0.15))"
    )
    gmsh.model.mesh.field.setAsBackgroundMesh(field)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    gmsh.option.setNumber("Mesh.Algorithm", 8)


def build_sphere():
    gmsh.model.add("sphere")
    gmsh.model.occ.addSphere(0, 0, 0, 1)
    gmsh.model.occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMin", 0.121)
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.121)
    gmsh.option.setNumber("Mesh.Algorithm", 6)


CASES = {"borouchaki": build_borouchaki, "sphere": build_sphere}


def make(name, path):
    """Meshes case `name` in 2D and writes it to `path`; returns the triangle count."""
    gmsh.initialize(readConfigFiles=False)
    try:
        common_options()
        CASES[name]()
        gmsh.model.mesh.generate(2)
        # Keep only the surfaces' elements: a physical group per surface (tag = surface tag)
        # with SaveAll = 0 writes just the triangles and the nodes they use.
        for dim, tag in gmsh.model.getEntities(2):
            gmsh.model.addPhysicalGroup(dim, [tag], tag)
        gmsh.option.setNumber("Mesh.SaveAll", 0)
        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        gmsh.option.setNumber("Mesh.Binary", 1)
        types, tags, _ = gmsh.model.mesh.getElements(2)
        triangles = sum(len(t) for ty, t in zip(types, tags) if ty == 2)
        others = [ty for ty in types if ty != 2]
        if others:
            sys.exit(f"{name}: unexpected 2D element types {others}")
        gmsh.write(path)
        return triangles
    finally:
        gmsh.finalize()


def digest(path):
    with open(path, "rb") as f:
        return hashlib.blake2b(f.read(), digest_size=16).hexdigest()


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=os.path.join(here, "..", "meshes"))
    args = ap.parse_args()
    if gmsh.__version__ != GMSH_VERSION:
        print(
            f"warning: gmsh {gmsh.__version__}, the committed files were made with "
            f"{GMSH_VERSION}; counts may differ",
            file=sys.stderr,
        )
    os.makedirs(args.out, exist_ok=True)
    status = 0
    for name in CASES:
        path = os.path.join(args.out, f"{name}.msh")
        count = make(name, path)
        # Determinism: a second run must give the same bytes.
        with tempfile.TemporaryDirectory() as tmp:
            again = os.path.join(tmp, f"{name}.msh")
            make(name, again)
            same = digest(path) == digest(again)
        note = "" if count == EXPECTED[name] else f"  (EXPECTED {EXPECTED[name]})"
        print(f"{name}: {count} triangles{note}, blake2b-128 {digest(path)}, "
              f"{os.path.getsize(path)} bytes, rerun identical: {same}")
        if count != EXPECTED[name] or not same:
            status = 1
    return status


if __name__ == "__main__":
    sys.exit(main())
