#!/usr/bin/env python3
"""Regenerates the binary, appended and compressed mesh fixtures of tests/io_encodings.rs.

Needs the `gmsh` and `vtk` Python packages (tested with gmsh 4.15.2 and VTK 9.7.2):

    python3 -m venv /tmp/fixtures && /tmp/fixtures/bin/pip install gmsh vtk
    cd crates/grid/tests/data && /tmp/fixtures/bin/python make_fixtures.py

Two meshes are made with Gmsh:

* `enc2d`: [0, 1] x [0, 1] in triangles (physical surface 1 "tri") next to [1, 2] x [0, 1]
  in recombined quadrangles (physical surface 2 "quad"), the left edge as physical curve
  3 "left". Area 2.
* `enc3d`: the unit cube cut at z = 0.5 into two boxes of tetrahedra (physical volumes
  1 "lower" and 2 "upper"), the bottom face as physical surface 5 "bottom". Volume 1.

Each is written by Gmsh as MSH 4.1 ASCII and MSH 4.1 binary (`Mesh.Binary = 1`), and, as
a vtkUnstructuredGrid holding the same nodes and cells with an Int32 cell-data array
`tag` (the physical group of each cell), by VTK's vtkXMLUnstructuredGridWriter in these
encodings:

| file suffix | data mode | appended encoding | compressor | header | byte order |
|---|---|---|---|---|---|
| `ascii` | ascii | | none | UInt64 | little |
| `appended_raw` | appended | raw | none | UInt64 | little |
| `appended_zlib` | appended | raw | zlib (ParaView's default save) | UInt64 | little |
| `appended_base64` | appended | base64 | none | UInt64 | little |
| `binary_zlib` | binary (inline base64) | | zlib | UInt64 | little |
| `appended_zlib_u32_be` | appended | raw | zlib, 512-byte blocks | UInt32 | big |

Node coordinates are rounded to multiples of 2^-12 after meshing, so that every
coordinate has a short exact decimal form and the ASCII files hold exactly the same
doubles as the binary ones.
"""

import gmsh
import vtk

STEP = 2.0**-12
VTK_TYPE = {2: vtk.VTK_TRIANGLE, 3: vtk.VTK_QUAD, 4: vtk.VTK_TETRA}


def snap_nodes():
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    for k, t in enumerate(tags):
        p = [round(c / STEP) * STEP for c in xyz[3 * k : 3 * k + 3]]
        gmsh.model.mesh.setNode(int(t), p, [])


def mesh_2d():
    gmsh.model.add("enc2d")
    occ = gmsh.model.occ
    a = occ.addRectangle(0, 0, 0, 1, 1)
    b = occ.addRectangle(1, 0, 0, 1, 1)
    occ.fragment([(2, a)], [(2, b)])
    occ.synchronize()
    gmsh.model.mesh.setRecombine(2, b)
    gmsh.model.addPhysicalGroup(2, [a], 1, "tri")
    gmsh.model.addPhysicalGroup(2, [b], 2, "quad")
    left = [
        c
        for (_, c) in gmsh.model.getEntities(1)
        if abs(occ.getCenterOfMass(1, c)[0]) < 1e-9
    ]
    gmsh.model.addPhysicalGroup(1, left, 3, "left")
    gmsh.option.setNumber("Mesh.MeshSizeMin", 0.35)
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.35)
    gmsh.model.mesh.generate(2)
    snap_nodes()


def mesh_3d():
    gmsh.model.add("enc3d")
    occ = gmsh.model.occ
    lo = occ.addBox(0, 0, 0, 1, 1, 0.5)
    hi = occ.addBox(0, 0, 0.5, 1, 1, 0.5)
    occ.fragment([(3, lo)], [(3, hi)])
    occ.synchronize()
    gmsh.model.addPhysicalGroup(3, [lo], 1, "lower")
    gmsh.model.addPhysicalGroup(3, [hi], 2, "upper")
    bottom = [
        s
        for (_, s) in gmsh.model.getEntities(2)
        if abs(occ.getCenterOfMass(2, s)[2]) < 1e-9
    ]
    gmsh.model.addPhysicalGroup(2, bottom, 5, "bottom")
    gmsh.option.setNumber("Mesh.MeshSizeMin", 0.6)
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.6)
    gmsh.model.mesh.generate(3)
    snap_nodes()


def write_msh(name):
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    gmsh.option.setNumber("Mesh.Binary", 0)
    gmsh.write(f"{name}_ascii.msh")
    gmsh.option.setNumber("Mesh.Binary", 1)
    gmsh.write(f"{name}_binary.msh")
    gmsh.option.setNumber("Mesh.Binary", 0)


def vtk_grid(dim):
    """The current Gmsh model's cells of dimension `dim` as a vtkUnstructuredGrid."""
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    index = {int(t): k for k, t in enumerate(tags)}
    points = vtk.vtkPoints()
    points.SetDataTypeToDouble()
    for k in range(len(tags)):
        points.InsertNextPoint(xyz[3 * k], xyz[3 * k + 1], xyz[3 * k + 2])
    grid = vtk.vtkUnstructuredGrid()
    grid.SetPoints(points)
    phys = vtk.vtkIntArray()
    phys.SetName("tag")
    for _, entity in gmsh.model.getEntities(dim):
        groups = gmsh.model.getPhysicalGroupsForEntity(dim, entity)
        types, _, nodes = gmsh.model.mesh.getElements(dim, entity)
        for t, nn in zip(types, nodes):
            per = gmsh.model.mesh.getElementProperties(t)[3]
            for e in range(len(nn) // per):
                ids = vtk.vtkIdList()
                for n in nn[per * e : per * (e + 1)]:
                    ids.InsertNextId(index[int(n)])
                grid.InsertNextCell(VTK_TYPE[t], ids)
                phys.InsertNextValue(int(groups[0]))
    grid.GetCellData().AddArray(phys)
    return grid


def write_vtu(grid, name):
    variants = {
        "ascii": dict(mode="ascii"),
        "appended_raw": dict(mode="appended", encode=False),
        "appended_zlib": dict(mode="appended", encode=False, zlib=True),
        "appended_base64": dict(mode="appended", encode=True),
        "binary_zlib": dict(mode="binary", zlib=True),
        "appended_zlib_u32_be": dict(
            mode="appended", encode=False, zlib=True, u32=True, be=True, block=512
        ),
    }
    for suffix, v in variants.items():
        w = vtk.vtkXMLUnstructuredGridWriter()
        w.SetInputData(grid)
        w.SetFileName(f"{name}_{suffix}.vtu")
        {"ascii": w.SetDataModeToAscii, "binary": w.SetDataModeToBinary,
         "appended": w.SetDataModeToAppended}[v["mode"]]()
        if v["mode"] == "appended":
            w.SetEncodeAppendedData(v["encode"])
        if v.get("zlib"):
            w.SetCompressorTypeToZLib()
        else:
            w.SetCompressorTypeToNone()
        if v.get("u32"):
            w.SetHeaderTypeToUInt32()
        else:
            w.SetHeaderTypeToUInt64()
        if v.get("be"):
            w.SetByteOrderToBigEndian()
        else:
            w.SetByteOrderToLittleEndian()
        if "block" in v:
            w.SetBlockSize(v["block"])
        if w.Write() != 1:
            raise RuntimeError(f"VTK could not write {name}_{suffix}.vtu")


def main():
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    mesh_2d()
    write_msh("enc2d")
    write_vtu(vtk_grid(2), "enc2d")
    mesh_3d()
    write_msh("enc3d")
    write_vtu(vtk_grid(3), "enc3d")
    gmsh.finalize()


if __name__ == "__main__":
    main()
