"""Small test meshes for tests/it/io.rs, written by Gmsh (PyPI gmsh 4.15.2) in every format
variant quadrecomb reads. Run from this directory: python3 make_test_meshes.py"""
import gmsh


def start(name):
    """A fresh Gmsh session with one empty model."""
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add(name)


def mesh(size, dim=2):
    """Meshes the model's geometry with elements of about `size`."""
    gmsh.model.occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMin", size)
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.model.mesh.generate(dim)


def write(name, version, binary):
    gmsh.option.setNumber("Mesh.MshFileVersion", version)
    gmsh.option.setNumber("Mesh.Binary", binary)
    gmsh.write(name)


def suffix(version, binary):
    return f"{str(version).replace('.', '')}_{'bin' if binary else 'ascii'}.msh"


# Two surfaces sharing an edge (unit square cut at x = 0.5), coarse: a few dozen triangles,
# plus the points and lines Gmsh writes along (the reader must skip them).
start("two_squares")
occ = gmsh.model.occ
a = occ.addRectangle(0, 0, 0, 0.5, 1)
b = occ.addRectangle(0.5, 0, 0, 0.5, 1)
occ.fragment([(2, a)], [(2, b)])
mesh(0.3)
gmsh.option.setNumber("Mesh.SaveAll", 1)
for version in (2.2, 4.1):
    for binary in (0, 1):
        write("two_squares_" + suffix(version, binary), version, binary)

# The same with the right surface recombined into quads (input quads are kept as quads).
gmsh.model.mesh.setRecombine(2, b)
gmsh.model.mesh.generate(2)
write("mixed_41_ascii.msh", 4.1, 0)
write("mixed_22_ascii.msh", 2.2, 0)
gmsh.finalize()

# Parametric coordinates on curve and surface nodes: MSH 4.1 keeps them in $Nodes, MSH 2.2
# writes a $ParametricNodes section instead of $Nodes.
start("param")
gmsh.model.occ.addRectangle(0, 0, 0, 1, 1)
mesh(0.4)
gmsh.option.setNumber("Mesh.SaveParametric", 1)
write("param_41_ascii.msh", 4.1, 0)
write("param_41_bin.msh", 4.1, 1)
write("param_22_bin.msh", 2.2, 1)
write("param_22_ascii.msh", 2.2, 0)
gmsh.finalize()

# A mesh split into two partitions (MSH 4.1 puts each partition's elements on new entities,
# listed with their parent surface in $PartitionedEntities; 2.2 keeps the elementary tag).
# The order of $GhostElements varies from run to run.
start("parts")
gmsh.model.occ.addRectangle(0, 0, 0, 1, 1)
mesh(0.3)
gmsh.option.setNumber("Mesh.PartitionCreateTopology", 1)
gmsh.option.setNumber("Mesh.PartitionCreateGhostCells", 1)
gmsh.model.mesh.partition(2)
for version, binary in ((4.1, 0), (4.1, 1), (2.2, 0)):
    write("parts_" + suffix(version, binary), version, binary)
gmsh.finalize()

# Second-order triangles only (6 nodes, type 9): nothing the reader recombines.
start("order2")
gmsh.model.occ.addRectangle(0, 0, 0, 1, 1)
mesh(0.5)
gmsh.model.mesh.setOrder(2)
write("order2_41_ascii.msh", 4.1, 0)
gmsh.finalize()

# A partitioned 3D mesh (a box of tetrahedra in two partitions): with Gmsh's default
# PartitionCreateTopology, MSH 4.1 adds partition surfaces whose parent is the volume (the
# interface between the partitions), holding triangles inside the box: the reader skips
# them. The unpartitioned mesh is written first, for comparison.
start("box")
gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
mesh(0.5, dim=3)
write("box_41_ascii.msh", 4.1, 0)
gmsh.model.mesh.partition(2)
write("box_parts_41_ascii.msh", 4.1, 0)
write("box_parts_41_bin.msh", 4.1, 1)
gmsh.finalize()

# A channel of two surfaces with named physical groups, for writing back the model
# (tests/it/model.rs): the unit square "left" beside the square [1, 2] x [0, 1] minus a
# disk, "right"; the curves "inlet" (x = 0), "outlet" (x = 2) and "walls" (top, bottom and
# the hole). Only physical elements are saved (Gmsh's default): the surfaces' triangles,
# the lines of the named curves and no points; the nodes of the common curve x = 1 and of
# the corner points are classified on them all the same.
start("channel")
occ = gmsh.model.occ
left = occ.addRectangle(0, 0, 0, 1, 1)
right = occ.addRectangle(1, 0, 0, 1, 1)
occ.cut([(2, right)], [(2, occ.addDisk(1.5, 0.5, 0, 0.2, 0.2))])
occ.fragment([(2, left)], [e for e in occ.getEntities(2) if e[1] != left])
mesh(0.12)
groups = {"inlet": [], "outlet": [], "walls": []}
for _, c in gmsh.model.getEntities(1):
    x, _, _ = occ.getCenterOfMass(1, c)
    if abs(x) < 1e-9:
        groups["inlet"].append(c)
    elif abs(x - 2) < 1e-9:
        groups["outlet"].append(c)
    elif abs(x - 1) > 1e-9:
        groups["walls"].append(c)
for name, curves in groups.items():
    gmsh.model.addPhysicalGroup(1, curves, name=name)
for _, s in gmsh.model.getEntities(2):
    x, _, _ = occ.getCenterOfMass(2, s)
    gmsh.model.addPhysicalGroup(2, [s], name="left" if x < 1 else "right")
write("channel_41_ascii.msh", 4.1, 0)
write("channel_22_ascii.msh", 2.2, 0)
gmsh.finalize()

# Surfaces meeting three at an edge (tests/it/model.rs, valid_output.rs): a plate cut along
# y = 0 by a web standing on that line (the two halves of the plate and the web each have
# one triangle on every edge of the line), and a fin standing on the plate's upper half
# along a line inside it (two of the plate's triangles and one of the fin's on each edge).
# Named groups for the plate (both halves), the web, the fin and the plate's clamped edge
# x = 0.
start("stiffened")
occ = gmsh.model.occ
plate = occ.addRectangle(0, -1, 0, 3, 2)
web = occ.addRectangle(0, 0, 0, 3, 0.8)
occ.rotate([(2, web)], 0, 0, 0, 1, 0, 0, 1.5707963267948966)
fin = occ.addRectangle(1.5, 0.3, 0, 0.6, 0.5)
occ.rotate([(2, fin)], 1.5, 0.3, 0, 0, 1, 0, -1.5707963267948966)
occ.fragment([(2, plate)], [(2, web), (2, fin)])
mesh(0.2)
parts = {"plate": [], "web": [], "fin": []}
for _, s in gmsh.model.getEntities(2):
    x, y, z = occ.getCenterOfMass(2, s)
    parts["plate" if abs(z) < 1e-9 else "web" if abs(y) < 1e-9 else "fin"].append(s)
for name, surfaces in parts.items():
    gmsh.model.addPhysicalGroup(2, surfaces, name=name)
clamped = [c for _, c in gmsh.model.getEntities(1)
           if abs(occ.getCenterOfMass(1, c)[0]) < 1e-9 and abs(occ.getCenterOfMass(1, c)[2]) < 1e-9]
gmsh.model.addPhysicalGroup(1, clamped, name="clamped")
write("stiffened_41_ascii.msh", 4.1, 0)
gmsh.finalize()

# The six faces of a unit box and a wall across it at x = 0.5, meshed as shells (the volumes
# removed), with sizes drawn per corner (seeded): the wall meets four faces along lines where
# three surfaces share every edge, and most surfaces hold an odd number of triangles, so
# that all-quad needs sheets, which cross those lines (tests/it/all_quad.rs).
start("box_wall")
import random
random.seed(1)
occ = gmsh.model.occ
box = occ.addBox(0, 0, 0, 1, 1, 1)
wall = occ.addRectangle(0, 0, 0, 1, 1)
occ.rotate([(2, wall)], 0, 0, 0, 0, 1, 0, -1.5707963267948966)
occ.translate([(2, wall)], 0.5, 0, 0)
occ.fragment([(3, box)], [(2, wall)])
occ.synchronize()
gmsh.model.removeEntities(gmsh.model.getEntities(3))
for d, t in gmsh.model.getEntities(0):
    gmsh.model.mesh.setSize([(d, t)], random.uniform(0.15, 0.4))
gmsh.model.mesh.generate(2)
write("box_wall_41_ascii.msh", 4.1, 0)
gmsh.finalize()

# Two unit squares side by side, the right one recombined by Gmsh (input quads) and the left
# one of 73 triangles: all-quad must split a side of the odd left square, on a file whose
# point and line elements take the first element tags (tests/it/all_quad.rs).
start("mixed_odd")
occ = gmsh.model.occ
a = occ.addRectangle(0, 0, 0, 1, 1)
b = occ.addRectangle(1, 0, 0, 1, 1)
occ.fragment([(2, a)], [(2, b)])
gmsh.model.occ.synchronize()
gmsh.model.mesh.setRecombine(2, b)
mesh(0.22)
write("mixed_odd_41_ascii.msh", 4.1, 0)
gmsh.finalize()

# The box of tetrahedra again, finer (interior nodes), unpartitioned and in two partitions:
# MSH 4.1 puts the interior nodes on partition volumes, which the writer must give back to
# the box's volume (tests/it/model.rs).
start("box_fine")
gmsh.model.occ.addBox(0, 0, 0, 1, 1, 0.5)
mesh(0.25, dim=3)
write("box_fine_41_ascii.msh", 4.1, 0)
gmsh.model.mesh.partition(2)
write("box_fine_parts_41_ascii.msh", 4.1, 0)
gmsh.finalize()

# Models whose curves have no line elements (only physical surfaces: Gmsh saves no line
# elements, but classifies the curve nodes), with odd triangle counts so that all-quad adds
# nodes on curve sides (tests/it/model.rs): a square with parametric coordinates (a boundary
# split), and a disk inside a square, both surfaces odd (sheets across the interface circle).
start("square_nolines")
occ = gmsh.model.occ
occ.addRectangle(0, 0, 0, 1, 1)
occ.synchronize()
gmsh.model.mesh.setTransfiniteCurve(1, 8)
gmsh.model.addPhysicalGroup(2, [1], name="plate")
mesh(0.1)
assert len(gmsh.model.mesh.getElementsByType(2)[0]) % 2 == 1
gmsh.option.setNumber("Mesh.SaveParametric", 1)
write("square_nolines_41_ascii.msh", 4.1, 0)
gmsh.option.setNumber("Mesh.SaveParametric", 0)
gmsh.finalize()

start("disk_nolines")
occ = gmsh.model.occ
occ.fragment([(2, occ.addRectangle(0, 0, 0, 1, 1))], [(2, occ.addDisk(0.5, 0.5, 0, 0.25, 0.25))])
occ.synchronize()
for _, s in gmsh.model.getEntities(2):
    inner = abs(occ.getMass(2, s) - 3.14159265 * 0.0625) < 1e-3
    gmsh.model.addPhysicalGroup(2, [s], name="disk" if inner else "ring")
mesh(0.11)
counts = [len(gmsh.model.mesh.getElements(2, s)[1][0]) for _, s in gmsh.model.getEntities(2)]
assert all(n % 2 == 1 for n in counts), counts
write("disk_nolines_41_ascii.msh", 4.1, 0)
gmsh.finalize()

# Curves inside a surface, both sides of them on that surface (tests/it/model.rs): a square
# with an embedded crack (a polyline), an embedded circle and an embedded point, named groups
# for the plate, the crack, the circle, both ("monitor") and the outer boundary; and the shell of a cylinder,
# whose side surface meets itself along its seam curve (no groups: Gmsh saves every element,
# the seam's lines too). No quad may straddle those curves: their segments stay element sides.
start("crack")
occ = gmsh.model.occ
plate = occ.addRectangle(0, 0, 0, 1, 1)
pts = [occ.addPoint(x, y, 0) for x, y in [(0.2, 0.3), (0.45, 0.42), (0.6, 0.61), (0.8, 0.7)]]
crack = [occ.addLine(pts[i], pts[i + 1]) for i in range(3)]
circle = occ.addCircle(0.3, 0.75, 0, 0.12)
tip = occ.addPoint(0.75, 0.2, 0)
occ.synchronize()
gmsh.model.mesh.embed(1, crack + [circle], 2, plate)
gmsh.model.mesh.embed(0, [tip], 2, plate)
gmsh.model.addPhysicalGroup(2, [plate], name="plate")
gmsh.model.addPhysicalGroup(1, crack, name="crack")
gmsh.model.addPhysicalGroup(1, [circle], name="circle")
# The crack and the circle in a second group too: MSH 2.2 then writes their lines twice.
gmsh.model.addPhysicalGroup(1, crack + [circle], name="monitor")
gmsh.model.addPhysicalGroup(1, [c for _, c in gmsh.model.getBoundary([(2, plate)])], name="boundary")
gmsh.model.addPhysicalGroup(0, [tip], name="tip")
mesh(0.07)
write("crack_41_ascii.msh", 4.1, 0)
write("crack_22_ascii.msh", 2.2, 0)
gmsh.finalize()

start("cylinder")
occ = gmsh.model.occ
occ.addCylinder(0, 0, 0, 0, 0, 1, 0.5)
occ.synchronize()
gmsh.model.removeEntities(gmsh.model.getEntities(3))
mesh(0.15)
write("cylinder_41_ascii.msh", 4.1, 0)
gmsh.finalize()

# A mesh written one file per partition with ghost cells (PartitionSplitMeshFiles): each
# file's ghost surface holds copies of the neighbouring partition's triangles, which the
# reader skips, so the two files' triangles are the whole mesh's, each once. The whole mesh
# is written first, for comparison.
start("split")
gmsh.model.occ.addRectangle(0, 0, 0, 1, 1)
mesh(0.3)
gmsh.model.addPhysicalGroup(2, [1], name="S")
write("split_whole_41_ascii.msh", 4.1, 0)
gmsh.option.setNumber("Mesh.PartitionCreateGhostCells", 1)
gmsh.option.setNumber("Mesh.PartitionSplitMeshFiles", 1)
gmsh.model.mesh.partition(2)
write("split_41_ascii.msh", 4.1, 0)
gmsh.finalize()

# One surface in two physical groups: MSH 2.2 writes each triangle twice (once per group,
# another element tag each time), 4.1 once, with both groups on the surface. The reader
# keeps the first copy.
start("two_groups")
gmsh.model.occ.addRectangle(0, 0, 0, 1, 1)
mesh(0.3)
gmsh.model.addPhysicalGroup(2, [1], name="fluid")
gmsh.model.addPhysicalGroup(2, [1], name="all")
write("two_groups_41_ascii.msh", 4.1, 0)
write("two_groups_22_ascii.msh", 2.2, 0)
write("two_groups_22_bin.msh", 2.2, 1)
gmsh.finalize()

# A box of tetrahedra in MSH 2.2 with a volume group and a surface group: 2.2 has no
# $Entities, so the volume and the nodes inside it are known from the tetrahedra alone.
start("box_groups")
gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
gmsh.model.occ.synchronize()
gmsh.model.addPhysicalGroup(3, [1], name="vol")
gmsh.model.addPhysicalGroup(2, [1, 2, 3, 4, 5, 6], name="skin")
mesh(0.3, dim=3)
write("box_groups_22_ascii.msh", 2.2, 0)
write("box_groups_22_bin.msh", 2.2, 1)
gmsh.finalize()

# Nodes that MSH 2.2 does not classify, held by elements of two entities of one dimension:
# Gmsh gives them the entity of lowest tag (triangles before quads on one surface), whatever
# the order of the elements in the file, which 2.2 writes type by type. Two squares, quads on
# surface 1 and triangles on surface 2, no lines saved; then prisms (volume 1) under
# tetrahedra (volume 2), their common face in no group (no triangles there).
start("order_surfaces")
occ = gmsh.model.occ
occ.addRectangle(0, 0, 0, 1, 1)
occ.addRectangle(1, 0, 0, 1, 1)
occ.fragment([(2, 1)], [(2, 2)])
occ.synchronize()
gmsh.model.addPhysicalGroup(2, [1], name="L")
gmsh.model.addPhysicalGroup(2, [2], name="R")
gmsh.model.mesh.setRecombine(2, 1)
mesh(0.3)
write("order_surfaces_22_ascii.msh", 2.2, 0)
gmsh.finalize()

start("order_volumes")
geo = gmsh.model.geo
p = [geo.addPoint(x, y, 0, 0.4) for x, y in ((0, 0), (1, 0), (1, 1), (0, 1))]
lines = [geo.addLine(p[k], p[(k + 1) % 4]) for k in range(4)]
s = geo.addPlaneSurface([geo.addCurveLoop(lines)])
top = geo.extrude([(2, s)], 0, 0, 1, numElements=[2], recombine=True)[0][1]
geo.extrude([(2, top)], 0, 0, 1)
geo.synchronize()
gmsh.model.addPhysicalGroup(3, [1], name="prisms")
gmsh.model.addPhysicalGroup(3, [2], name="tets")
gmsh.model.addPhysicalGroup(2, [s], name="bottom")
gmsh.model.mesh.generate(3)
write("order_volumes_22_ascii.msh", 2.2, 0)
gmsh.finalize()
