# Regenerates the gmsh_*.msh fixtures with the Gmsh Python package (pip install gmsh):
#   cd crates/grid/tests/data && python3 gmsh_generate.py && mv p2.msh gmsh_tri_quad.msh && mv p3.msh gmsh_tets.msh && mv p4.msh gmsh_prisms.msh
import gmsh, sys
gmsh.initialize(); gmsh.option.setNumber("General.Terminal", 0)
gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
# 2D: rectangle with a hole-free split: left part triangles, right part recombined quads
gmsh.model.add("p2")
occ = gmsh.model.occ
a = occ.addRectangle(0, 0, 0, 1, 1); b = occ.addRectangle(1, 0, 0, 1.5, 1)
occ.fragment([(2, a)], [(2, b)]); occ.synchronize()
gmsh.model.mesh.setRecombine(2, b)
gmsh.model.addPhysicalGroup(2, [a], 1, "tri"); gmsh.model.addPhysicalGroup(2, [b], 2, "quad")
left = [c for (d, c) in gmsh.model.getEntities(1) if abs(gmsh.model.occ.getCenterOfMass(1, c)[0]) < 1e-9]
gmsh.model.addPhysicalGroup(1, left, 3, "left")
gmsh.option.setNumber("Mesh.MeshSizeMax", 0.2)
gmsh.model.mesh.generate(2); gmsh.write("p2.msh")
# 3D: box tets + extruded prisms (with hexes via recombine), pyramids via transition
gmsh.model.add("p3")
occ = gmsh.model.occ
v1 = occ.addBox(0, 0, 0, 1, 1, 1); occ.synchronize()
gmsh.model.addPhysicalGroup(3, [v1], 1, "box")
bottom = [s for (d, s) in gmsh.model.getEntities(2) if abs(gmsh.model.occ.getCenterOfMass(2, s)[2]) < 1e-9]
gmsh.model.addPhysicalGroup(2, bottom, 5, "bottom")
gmsh.option.setNumber("Mesh.MeshSizeMax", 0.3)
gmsh.model.mesh.generate(3); gmsh.write("p3.msh")
# 3D extruded prisms/hexes from a 2D mesh with tris and quads
gmsh.model.add("p4")
geo = gmsh.model.geo
p = [geo.addPoint(0,0,0,0.3), geo.addPoint(2,0,0,0.3), geo.addPoint(2,1,0,0.3), geo.addPoint(0,1,0,0.3)]
l = [geo.addLine(p[i], p[(i+1)%4]) for i in range(4)]
s = geo.addPlaneSurface([geo.addCurveLoop(l)])
ex = geo.extrude([(2, s)], 0, 0, 0.5, numElements=[2], recombine=True)
geo.synchronize()
vol = [t for (d, t) in ex if d == 3]
gmsh.model.addPhysicalGroup(3, vol, 1, "layer")
gmsh.model.addPhysicalGroup(2, [s], 2, "base")
gmsh.model.mesh.generate(3); gmsh.write("p4.msh")
gmsh.finalize()
