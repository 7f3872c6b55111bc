"""Small test meshes for tests/it/io.rs, written by Gmsh (PyPI gmsh 4.15.2) in every format
variant quadrecomb reads. Run from this directory: python3 make_test_meshes.py"""
import gmsh

gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)

# Two surfaces sharing an edge (unit square cut at x = 0.5), coarse: a few dozen triangles,
# plus the points and lines Gmsh writes along (the reader must skip them).
gmsh.model.add("two_squares")
occ = gmsh.model.occ
a = occ.addRectangle(0, 0, 0, 0.5, 1)
b = occ.addRectangle(0.5, 0, 0, 0.5, 1)
occ.fragment([(2, a)], [(2, b)])
occ.synchronize()
gmsh.option.setNumber("Mesh.MeshSizeMin", 0.3)
gmsh.option.setNumber("Mesh.MeshSizeMax", 0.3)
gmsh.model.mesh.generate(2)
gmsh.option.setNumber("Mesh.SaveAll", 1)
for version in (2.2, 4.1):
    for binary in (0, 1):
        gmsh.option.setNumber("Mesh.MshFileVersion", version)
        gmsh.option.setNumber("Mesh.Binary", binary)
        name = f"two_squares_{str(version).replace('.', '')}_{'bin' if binary else 'ascii'}.msh"
        gmsh.write(name)

# The same with the right surface recombined into quads (input quads are kept as quads).
gmsh.model.mesh.setRecombine(2, b)
gmsh.model.mesh.generate(2)
gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
gmsh.option.setNumber("Mesh.Binary", 0)
gmsh.write("mixed_41_ascii.msh")
gmsh.option.setNumber("Mesh.MshFileVersion", 2.2)
gmsh.write("mixed_22_ascii.msh")
gmsh.finalize()

# MSH 4.1 with parametric coordinates on curve and surface nodes.
gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.add("param")
gmsh.model.occ.addRectangle(0, 0, 0, 1, 1)
gmsh.model.occ.synchronize()
gmsh.option.setNumber("Mesh.MeshSizeMin", 0.4)
gmsh.option.setNumber("Mesh.MeshSizeMax", 0.4)
gmsh.model.mesh.generate(2)
gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
gmsh.option.setNumber("Mesh.SaveParametric", 1)
gmsh.write("param_41_ascii.msh")
gmsh.option.setNumber("Mesh.Binary", 1)
gmsh.write("param_41_bin.msh")
# MSH 2.2 writes them in a $ParametricNodes section instead of $Nodes.
gmsh.option.setNumber("Mesh.MshFileVersion", 2.2)
gmsh.write("param_22_bin.msh")
gmsh.option.setNumber("Mesh.Binary", 0)
gmsh.write("param_22_ascii.msh")
gmsh.finalize()

# A mesh split into two partitions (MSH 4.1 puts each partition's elements on new entities,
# listed with their parent surface in $PartitionedEntities; 2.2 keeps the elementary tag).
gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.add("parts")
gmsh.model.occ.addRectangle(0, 0, 0, 1, 1)
gmsh.model.occ.synchronize()
gmsh.option.setNumber("Mesh.MeshSizeMin", 0.3)
gmsh.option.setNumber("Mesh.MeshSizeMax", 0.3)
gmsh.model.mesh.generate(2)
gmsh.option.setNumber("Mesh.PartitionCreateTopology", 1)
gmsh.option.setNumber("Mesh.PartitionCreateGhostCells", 1)
gmsh.model.mesh.partition(2)
for version, binary in ((4.1, 0), (4.1, 1), (2.2, 0)):
    gmsh.option.setNumber("Mesh.MshFileVersion", version)
    gmsh.option.setNumber("Mesh.Binary", binary)
    name = f"parts_{str(version).replace('.', '')}_{'bin' if binary else 'ascii'}.msh"
    gmsh.write(name)
gmsh.finalize()

# Second-order triangles only (6 nodes, type 9): nothing the reader recombines.
gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.add("order2")
gmsh.model.occ.addRectangle(0, 0, 0, 1, 1)
gmsh.model.occ.synchronize()
gmsh.option.setNumber("Mesh.MeshSizeMin", 0.5)
gmsh.option.setNumber("Mesh.MeshSizeMax", 0.5)
gmsh.model.mesh.generate(2)
gmsh.model.mesh.setOrder(2)
gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
gmsh.option.setNumber("Mesh.Binary", 0)
gmsh.write("order2_41_ascii.msh")
gmsh.finalize()

# A partitioned 3D mesh (a box of tetrahedra in two partitions): with Gmsh's default
# PartitionCreateTopology, MSH 4.1 adds partition surfaces whose parent is the volume (the
# interface between the partitions), holding triangles inside the box: the reader skips
# them. The unpartitioned mesh is written first, for comparison.
gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.add("box")
gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
gmsh.model.occ.synchronize()
gmsh.option.setNumber("Mesh.MeshSizeMin", 0.5)
gmsh.option.setNumber("Mesh.MeshSizeMax", 0.5)
gmsh.model.mesh.generate(3)
gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
gmsh.option.setNumber("Mesh.Binary", 0)
gmsh.write("box_41_ascii.msh")
gmsh.model.mesh.partition(2)
gmsh.write("box_parts_41_ascii.msh")
gmsh.option.setNumber("Mesh.Binary", 1)
gmsh.write("box_parts_41_bin.msh")
gmsh.finalize()
