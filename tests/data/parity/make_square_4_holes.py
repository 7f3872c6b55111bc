# Writes square_4_holes_41_ascii.msh (tests/it/search_oracle/parity.rs): the unit square less
# four disks, one surface; run with the gmsh Python module (4.15).
import gmsh
gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.add("square_4_holes")
occ = gmsh.model.occ
sq = occ.addRectangle(0, 0, 0, 1, 1)
holes = [occ.addDisk(x, y, 0, 0.12, 0.12) for (x, y) in [(0.27, 0.27), (0.73, 0.27), (0.27, 0.73), (0.73, 0.73)]]
occ.cut([(2, sq)], [(2, h) for h in holes])
occ.synchronize()
gmsh.option.setNumber("Mesh.MeshSizeMin", 0.11)
gmsh.option.setNumber("Mesh.MeshSizeMax", 0.11)
gmsh.model.mesh.generate(2)
gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
gmsh.option.setNumber("Mesh.Binary", 0)
gmsh.write(__file__.replace("make_square_4_holes.py", "square_4_holes_41_ascii.msh"))
types, tags, nodes = gmsh.model.mesh.getElements(2)
print([len(t) for t in tags])
gmsh.finalize()
