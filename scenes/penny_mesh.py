#!/usr/bin/env python3
"""Write the grid of the penny-shaped hydraulic fracture (scenes/penny_toughness.toml).

A quarter of the domain, x >= 0 and y >= 0 (the planes x = 0 and y = 0 are planes of
symmetry of a penny centred on the z axis), z on both sides of the crack plane z = 0.
A tensor-product grid: boxes of size h in x, y up to `fine` boxes from the axis and in
z over the crack band -h/2 < z < h/2 and `layers` boxes above and below it, growing by
the factor `ratio` beyond, up to about `extent` from the centre.

The hybrid of the continuum model: the boxes of the fine zone next to the crack band are
split into the six tetrahedra of the Kuhn (Freudenthal) split along their main diagonal
(MDEM, tag `mdem`); every other box is a VEM hexahedron. A box face between a hexahedron
and the tetrahedra is two triangles (the split of every box face runs from its lowest
corner to its highest, the same on both sides), so the grid is conforming. Each Kuhn
tetrahedron spans its box in all three directions: a tetrahedron of the band spans the
band, as a split square does in 2D (its smeared opening is the jump across the band, and
the tip rule reads the jump between the band's two faces).

Usage: python3 scenes/penny_mesh.py H FINE OUT.vtu  (e.g. 0.25 18 scenes/penny_toughness.vtu)
"""

import base64
import sys
import zlib

import numpy as np


def axis(h, fine, ratio, extent, start):
    """Node coordinates from `start`: `fine` steps of h, then growing by `ratio`."""
    xs = [start]
    for _ in range(fine):
        xs.append(xs[-1] + h)
    step = h
    while xs[-1] < extent - 1e-9:
        step *= ratio
        xs.append(xs[-1] + step)
    return np.array(xs)


def main():
    h = float(sys.argv[1])
    fine = int(sys.argv[2])
    out = sys.argv[3]
    ratio = 1.4
    extent = 4.0 * fine * h  # the far faces about four fine zones away
    layers = 2  # fine boxes above and below the band, in the MDEM zone
    xs = axis(h, fine, ratio, extent, 0.0)
    zup = axis(h, layers, ratio, extent, 0.5 * h)
    zs = np.concatenate([-zup[::-1], zup])
    nx, ny, nz = len(xs), len(xs), len(zs)
    kband = len(zup) - 1  # box index of the band -h/2 < z < h/2
    node = lambda i, j, k: (k * ny + j) * nx + i  # noqa: E731
    pts = np.array([[xs[i], xs[j], zs[k]] for k in range(nz) for j in range(ny) for i in range(nx)])

    def is_tet(i, j, k):
        return (
            0 <= i < nx - 1
            and 0 <= j < ny - 1
            and 0 <= k < nz - 1
            and i < fine
            and j < fine
            and abs(k - kband) <= layers
        )

    def corner(i, j, k, d):
        return node(i + d[0], j + d[1], k + d[2])

    conn, offsets, types, faces, faceoffsets, mdem = [], [], [], [], [], []

    def orient(loop, centre):
        p = pts[loop]
        n = np.zeros(3)
        for a in range(len(loop)):
            n += np.cross(p[a], p[(a + 1) % len(loop)])
        return loop if np.dot(n, p.mean(axis=0) - centre) > 0 else loop[::-1]

    for k in range(nz - 1):
        for j in range(ny - 1):
            for i in range(nx - 1):
                if is_tet(i, j, k):
                    for a, b in [(0, 1), (0, 2), (1, 0), (1, 2), (2, 0), (2, 1)]:
                        e1 = [0, 0, 0]
                        e1[a] = 1
                        e2 = list(e1)
                        e2[b] = 1
                        t = [corner(i, j, k, d) for d in ([0, 0, 0], e1, e2, [1, 1, 1])]
                        p = pts[t]
                        if np.dot(np.cross(p[1] - p[0], p[2] - p[0]), p[3] - p[0]) < 0:
                            t[2], t[3] = t[3], t[2]
                        conn += t
                        offsets.append(len(conn))
                        types.append(10)
                        faceoffsets.append(-1)
                        mdem.append(1)
                    continue
                cell = [corner(i, j, k, [a, b, c]) for c in (0, 1) for b in (0, 1) for a in (0, 1)]
                centre = pts[cell].mean(axis=0)
                stream = []
                for ax in range(3):
                    for side in (0, 1):
                        quad = []
                        for u, v in [(0, 0), (1, 0), (1, 1), (0, 1)]:
                            d = [0, 0, 0]
                            d[ax] = side
                            d[(ax + 1) % 3] = u
                            d[(ax + 2) % 3] = v
                            quad.append(corner(i, j, k, d))
                        nb = [i, j, k]
                        nb[ax] += 1 if side else -1
                        if is_tet(*nb):
                            # quad[0] is the face's lowest corner, quad[2] its highest
                            tris = [[quad[0], quad[1], quad[2]], [quad[0], quad[2], quad[3]]]
                        else:
                            tris = [quad]
                        for f in tris:
                            f = orient(f, centre)
                            stream += [len(f)] + list(f)
                conn += cell
                offsets.append(len(conn))
                types.append(42)
                count, pos = 0, 0
                while pos < len(stream):
                    count += 1
                    pos += 1 + stream[pos]
                faces += [count] + stream
                faceoffsets.append(len(faces))
                mdem.append(0)

    def block(values, dtype):
        """A zlib-compressed binary block, base64 (one block; header UInt32)."""
        raw = np.asarray(values, dtype=dtype).tobytes()
        packed = zlib.compress(raw, 9)
        head = np.array([1, len(raw), len(raw), len(packed)], dtype="<u4").tobytes()
        return (base64.b64encode(head) + base64.b64encode(packed)).decode()

    def array(name, values, dtype, vtk, comps=""):
        return '<DataArray type="%s" Name="%s"%s format="binary">%s</DataArray>\n' % (
            vtk, name, comps, block(values, dtype))

    with open(out, "w") as f:
        f.write('<?xml version="1.0"?>\n')
        f.write("<!-- written by scenes/penny_mesh.py %s %d -->\n" % (sys.argv[1], fine))
        f.write('<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" '
                'header_type="UInt32" compressor="vtkZLibDataCompressor">\n')
        f.write("<UnstructuredGrid>\n")
        f.write('<Piece NumberOfPoints="%d" NumberOfCells="%d">\n' % (len(pts), len(types)))
        f.write("<Points>" + array("points", pts.ravel(), "<f8", "Float64",
                                   ' NumberOfComponents="3"') + "</Points>\n<Cells>\n")
        for name, vals in [
            ("connectivity", conn),
            ("offsets", offsets),
            ("types", types),
            ("faces", faces),
            ("faceoffsets", faceoffsets),
        ]:
            f.write(array(name, vals, "<i8", "Int64"))
        f.write("</Cells>\n<CellData>\n" + array("tag:mdem", mdem, "<i4", "Int32"))
        f.write("</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n")
    print(
        "%s: %d points, %d cells (%d tetrahedra), x to %.3f, z to +-%.3f"
        % (out, len(pts), len(types), sum(mdem), xs[-1], zs[-1])
    )


main()
