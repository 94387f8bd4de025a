"""Gmsh meshes of the quarter plate with a hole (the Cosserat SCF case), written as ASCII
.vtu triangle meshes that `porofrac` (grid.kind = "file"), the `plate_hole run` example and
peers/cosserat/dem.py read.

usage: python cosserat_gmsh_plate.py R SCALE OUT.vtu

The plate is [0, 16.2]² mm minus the disk of radius R (mm) at the origin. The mesh size
grows linearly with the distance d to the hole, h(d) = SCALE·min(0.15 R + 0.12 d, 1.2)
(mm): halving SCALE gives about four times the triangles (SCALE 1 → about 2,600
triangles for R = 0.216). Needs the `gmsh` Python package (PyPI `gmsh`).
"""
import sys

import gmsh
import numpy as np

SIDE = 16.2


def build(r, scale):
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add("plate")
    occ = gmsh.model.occ
    square = occ.addRectangle(0.0, 0.0, 0.0, SIDE, SIDE)
    disk = occ.addDisk(0.0, 0.0, 0.0, r, r)
    occ.cut([(2, square)], [(2, disk)])
    occ.synchronize()
    hole = [c for _, c in gmsh.model.getEntities(1)
            if max(gmsh.model.getBoundingBox(1, c)[3:5]) < 1.5 * r]
    if len(hole) != 1:
        raise RuntimeError(f"expected one hole curve, found {hole}")
    f = gmsh.model.mesh.field
    dist = f.add("Distance")
    f.setNumbers(dist, "CurvesList", hole)
    f.setNumber(dist, "Sampling", 400)
    size = f.add("MathEval")
    f.setString(size, "F", f"{scale}*Min({0.15 * r}+0.12*F{dist}, 1.2)")
    f.setAsBackgroundMesh(size)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    gmsh.option.setNumber("Mesh.Algorithm", 6)
    gmsh.model.mesh.generate(2)
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    xyz = xyz.reshape(-1, 3)
    _, elem_nodes = gmsh.model.mesh.getElementsByType(2)
    gmsh.finalize()
    index = np.full(int(tags.max()) + 1, -1, dtype=np.int64)
    index[tags.astype(np.int64)] = np.arange(len(tags))
    tri = index[elem_nodes.astype(np.int64)].reshape(-1, 3)
    used = np.unique(tri)
    remap = np.full(len(tags), -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    pts = xyz[used, :2]
    tri = remap[tri]
    # Counter-clockwise triangles.
    a, b, c = pts[tri[:, 0]], pts[tri[:, 1]], pts[tri[:, 2]]
    cw = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]) < 0
    tri[cw] = tri[cw][:, [0, 2, 1]]
    # Snap the straight sides exactly onto their planes.
    for k in range(2):
        pts[np.abs(pts[:, k]) < 1e-9 * SIDE, k] = 0.0
        pts[np.abs(pts[:, k] - SIDE) < 1e-9 * SIDE, k] = SIDE
    return pts, tri


def write_vtu(path, pts, tri):
    with open(path, "w") as out:
        out.write('<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" version="1.0" '
                  'byte_order="LittleEndian" header_type="UInt64">\n<UnstructuredGrid>\n'
                  f'<Piece NumberOfPoints="{len(pts)}" NumberOfCells="{len(tri)}">\n'
                  '<Points>\n<DataArray type="Float64" NumberOfComponents="3" format="ascii">\n')
        for p in pts:
            out.write(f"{float(p[0])!r} {float(p[1])!r} 0\n")
        out.write('</DataArray>\n</Points>\n<Cells>\n'
                  '<DataArray type="Int64" Name="connectivity" format="ascii">\n')
        for t in tri:
            out.write(f"{t[0]} {t[1]} {t[2]}\n")
        out.write('</DataArray>\n<DataArray type="Int64" Name="offsets" format="ascii">\n')
        out.write(" ".join(str(3 * (i + 1)) for i in range(len(tri))))
        out.write('\n</DataArray>\n<DataArray type="UInt8" Name="types" format="ascii">\n')
        out.write(" ".join("5" for _ in range(len(tri))))
        out.write("\n</DataArray>\n</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n")


def main():
    if len(sys.argv) != 4:
        sys.exit("usage: python cosserat_gmsh_plate.py R SCALE OUT.vtu")
    r, scale, path = float(sys.argv[1]), float(sys.argv[2]), sys.argv[3]
    if not (0 < r < SIDE / 2 and scale > 0):
        sys.exit(f"need 0 < R < {SIDE / 2} and SCALE > 0, got {r}, {scale}")
    pts, tri = build(r, scale)
    write_vtu(path, pts, tri)
    print(f"{len(tri)} triangles, {len(pts)} nodes -> {path}")


if __name__ == "__main__":
    main()
