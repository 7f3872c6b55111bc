#!/usr/bin/env python3
"""Time Gmsh's blossom recombination beside `quadrecomb optimum` on the same meshes.

Gmsh: the mesh is opened, then `gmsh.model.mesh.recombine()` runs with
Mesh.RecombinationAlgorithm = 1 (blossom), Mesh.RecombineOptimizeTopology = 0 and
Mesh.Smoothing = 0, so only the matching is timed (best of --repeat runs, each on a freshly
opened mesh). Ours: `quadrecomb optimum MESH --json`, whose time_s runs from the loaded mesh to
the matching (best of --repeat). Prints one row per mesh with both times and the ratio.

Usage: scripts/bench_gmsh_blossom.py [MESH.msh ...] [--bin target/release/quadrecomb]
Default meshes: meshes/borouchaki.msh and meshes/sphere.msh of the repository.
Needs the `gmsh` Python module (pip install gmsh); exits with a note when it is missing.
"""

import argparse
import json
import pathlib
import subprocess
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent


def gmsh_blossom(gmsh, path, repeat):
    best = None
    for _ in range(repeat):
        gmsh.clear()
        gmsh.open(str(path))
        gmsh.option.setNumber("Mesh.RecombinationAlgorithm", 1)
        gmsh.option.setNumber("Mesh.RecombineOptimizeTopology", 0)
        gmsh.option.setNumber("Mesh.Smoothing", 0)
        gmsh.option.setNumber("Mesh.RecombineAll", 0)
        t0 = time.perf_counter()
        gmsh.model.mesh.recombine()
        t = time.perf_counter() - t0
        best = t if best is None else min(best, t)
    quads = tris = 0
    for dim, tag in gmsh.model.getEntities(2):
        types, etags, _ = gmsh.model.mesh.getElements(dim, tag)
        for ty, et in zip(types, etags):
            if ty == 2:
                tris += len(et)
            elif ty == 3:
                quads += len(et)
    return best, quads, tris


def ours(binary, path, repeat):
    best = None
    for _ in range(repeat):
        out = subprocess.run([str(binary), "optimum", str(path), "--json"],
                             check=True, capture_output=True, text=True)
        rec = json.loads(out.stdout)
        best = rec if best is None or rec["time_s"] < best["time_s"] else best
    return best


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("meshes", nargs="*", type=pathlib.Path,
                    default=[ROOT / "meshes" / "borouchaki.msh", ROOT / "meshes" / "sphere.msh"])
    ap.add_argument("--bin", type=pathlib.Path, default=ROOT / "target" / "release" / "quadrecomb")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    try:
        import gmsh
    except ImportError:
        print("note: the gmsh Python module is not importable; nothing to compare")
        return 0
    if not args.bin.exists():
        print(f"error: {args.bin} not found; build it with `cargo build --release`", file=sys.stderr)
        return 1
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    print(f"{'mesh':<16} {'triangles':>9} {'gmsh_s':>9} {'gmsh_quads':>10} {'gmsh_left':>9} "
          f"{'ours_s':>9} {'ours_quads':>10} {'ours_left':>9} {'ratio':>7}")
    for path in args.meshes:
        if not path.exists():
            print(f"{path.stem:<16} (missing: {path})")
            continue
        gt, gq, gl = gmsh_blossom(gmsh, path, args.repeat)
        rec = ours(args.bin, path, args.repeat)
        ratio = gt / rec["time_s"] if rec["time_s"] > 0 else float("inf")
        print(f"{path.stem:<16} {rec['triangles']:>9} {gt:>9.4f} {gq:>10} {gl:>9} "
              f"{rec['time_s']:>9.4f} {rec['quads']:>10} {rec['triangles_left']:>9} {ratio:>6.1f}x")
    gmsh.finalize()
    return 0


if __name__ == "__main__":
    sys.exit(main())
