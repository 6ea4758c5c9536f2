#!/usr/bin/env python3
"""Write the Gmsh test meshes of this folder (pip install gmsh==4.15.2): a 1 x 0.5 x 0.25 box with
physical groups SOLID (volume), Fixed (face x = 0) and an unnamed point group 7 at (1, 0.5, 0.25).
Usage: python3 make_msh.py crates/fe/tests/data"""
import gmsh, sys
out = sys.argv[1]
def box(kind, name, binary):
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add(name)
    v = gmsh.model.occ.addBox(0, 0, 0, 1.0, 0.5, 0.25)
    gmsh.model.occ.synchronize()
    gmsh.model.addPhysicalGroup(3, [v], name="SOLID")
    surfs = gmsh.model.getBoundary([(3, v)], oriented=False)
    fixed = [s[1] for s in surfs if abs(gmsh.model.occ.getCenterOfMass(2, s[1])[0]) < 1e-9]
    gmsh.model.addPhysicalGroup(2, fixed, name="Fixed")
    pts = gmsh.model.getBoundary([(3, v)], recursive=True)
    tip = [p[1] for p in pts if list(gmsh.model.getValue(0, p[1], [])) == [1.0, 0.5, 0.25]]
    gmsh.model.addPhysicalGroup(0, tip, 7)  # unnamed: GROUP0_7
    if kind.startswith("hex"):
        for c in gmsh.model.getEntities(1):
            gmsh.model.mesh.setTransfiniteCurve(c[1], 3)
        for s in gmsh.model.getEntities(2):
            gmsh.model.mesh.setTransfiniteSurface(s[1])
            gmsh.model.mesh.setRecombine(2, s[1])
        gmsh.model.mesh.setTransfiniteVolume(v)
    else:
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.3)
    gmsh.model.mesh.generate(3)
    if kind in ("tet10", "hex20"):
        gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 1)
        gmsh.model.mesh.setOrder(2)
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    gmsh.option.setNumber("Mesh.Binary", 1 if binary else 0)
    gmsh.write(f"{out}/{name}.msh")
    gmsh.finalize()
box("tet10", "box_tet10_ascii", False)
box("tet10", "box_tet10_binary", True)
box("hex20", "box_hex20_ascii", False)
box("hex8", "box_hex8_binary", True)
box("tet4", "box_tet4_ascii", False)
