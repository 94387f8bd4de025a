#!/usr/bin/env python3
"""Checks of the tracked-cell measures of scripts/nscd_f1_figures.py on synthetic frames
whose answers are known in closed form (Renouf, Dubois & Alart 2006, eqs. 7-11):

* a square lattice of disks (radius a, spacing 2a) carrying compressive contact forces
  Fx on its horizontal contacts and Fy on its vertical ones: eq. 7 over the contacts
  between tracked particles gives sigma_xx = n_h Fx 2a / V and sigma_yy = n_v Fy 2a / V
  (n_h, n_v the tracked pairs, counted here by brute force), over every contact of a
  tracked particle (Love's formula, each particle adding r n) sigma_xx = 2 M Fx a / V for
  M tracked particles of a lattice larger than the cell; a tangential force F_t on the
  horizontal contacts adds sigma_yx = n_h F_t 2a / V; a contact with a wall counts only
  in the second reading; p and q are the mean and half difference of the eigenvalues
  (eq. 8) and do not change when the whole frame is rotated;
* the same frame stretched affinely by 2 along x and 0.5 along y: lambda_x = 2 and
  lambda_y = 0.5 exactly (eq. 11), and the hull keeps its area (determinant 1);
* the hull of a unit square with interior points: area 1, perimeter 4.

The frames are written as the binary base64 VTK PolyData files of `porofrac run` (UInt64
headers) and read back through the script's own readers.

    python3 scripts/nscd_f1_figures_check.py     # prints each check, exits 1 on a failure
"""
import base64
import math
import os
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import nscd_f1_figures as f1  # noqa: E402

FAILED = []


def check(name, got, want, tol):
    ok = abs(got - want) <= tol * max(1.0, abs(want))
    print(f"{'ok  ' if ok else 'FAIL'} {name}: {got:.15g} (expected {want:.15g}, tol {tol:g})")
    if not ok:
        FAILED.append(name)


def array(name, values, width):
    data = np.ascontiguousarray(values, dtype="<f8").tobytes()
    text = base64.b64encode(np.array([len(data)], dtype="<u8").tobytes() + data).decode()
    comps = f' NumberOfComponents="{width}"' if width > 1 else ""
    return f'<DataArray type="Float64" Name="{name}"{comps} format="binary">\n{text}\n</DataArray>\n'


def pad3(p):
    p = np.asarray(p, dtype=float)
    return np.hstack([p, np.zeros((len(p), 1))])


def write_frame(path_p, path_c, x, r, u, lines):
    """A particle frame and a contact frame: lines (a, b, fn, ft), a the antagonist's end
    and b the candidate's centre, as `porofrac run` writes them."""
    with open(path_p, "w") as f:
        f.write('<?xml version="1.0"?>\n<VTKFile type="PolyData" header_type="UInt64">\n'
                + array("radius", r, 1) + array("displacement", pad3(u), 3)
                + array("Points", pad3(x), 3) + "</VTKFile>\n")
    a, b, fn, ft = lines
    pts = np.empty((2 * len(a), 2))
    pts[0::2], pts[1::2] = a, b
    with open(path_c, "w") as f:
        f.write('<?xml version="1.0"?>\n<VTKFile type="PolyData" header_type="UInt64">\n'
                + array("normal_force", fn, 1) + array("tangential_force", ft, 1)
                + array("Points", pad3(pts), 3) + "</VTKFile>\n")


def lattice(n, a, fx, fy, ft, rot):
    """An n x n square lattice of radius-a disks centred on the origin, rotated by rot,
    with its contacts: (x, r, lines, horizontal pairs, vertical pairs) where each contact
    line runs from the antagonist (the left or lower disk) to the candidate. One extra
    contact presses the lowest-left disk on a wall below it (force 7 Fy)."""
    c, s = math.cos(rot), math.sin(rot)
    turn = np.array([[c, -s], [s, c]])
    ij = np.array([(i, j) for j in range(n) for i in range(n)], dtype=float)
    x = (2 * a * (ij - (n - 1) / 2)) @ turn.T
    r = np.full(len(x), a)
    at = {(int(i), int(j)): k for k, (i, j) in enumerate(ij)}
    ea, eb, fn, fts, pairs = [], [], [], [], []
    for (i, j), k in at.items():
        for (di, dj), force, tang, kind in (((1, 0), fx, ft, "h"), ((0, 1), fy, 0.0, "v")):
            m = at.get((i + di, j + dj))
            if m is not None:
                ea.append(x[k])
                eb.append(x[m])
                fn.append(force)
                fts.append(tang)
                pairs.append((k, m, kind))
    wall = at[(0, 0)]
    ea.append(x[wall] - a * (turn @ np.array([0.0, 1.0])))
    eb.append(x[wall])
    fn.append(7.0 * fy)
    fts.append(0.0)
    return x, r, (np.array(ea), np.array(eb), np.array(fn), np.array(fts)), pairs, wall


def read(tmp, tag):
    pp, pc = os.path.join(tmp, f"particles_{tag}.vtp"), os.path.join(tmp, f"contacts_{tag}.vtp")
    x, r, u = f1.particles(pp)
    ea, eb, fn, ft = f1.contacts(pc)
    return x, r, u, (ea, eb, fn, ft, *f1.contact_index(x, ea, eb))


def main():
    a, n, fx, fy, ft = 0.5, 15, 3.0e5, 1.0e5, 2.0e4
    centre, radius = (0.3, -0.2), 4.1
    with tempfile.TemporaryDirectory() as tmp:
        results = []
        for rot in (0.0, 0.7):
            x, r, lines, pairs, wall = lattice(n, a, fx, fy, ft, rot)
            write_frame(os.path.join(tmp, f"particles_{rot}.vtp"),
                        os.path.join(tmp, f"contacts_{rot}.vtp"), x, r, np.zeros_like(x), lines)
            xr, rr, _, lr = read(tmp, rot)
            back = np.array([[math.cos(rot), math.sin(rot)], [-math.sin(rot), math.cos(rot)]])
            cell = f1.Cell(xr, rr, np.array(centre) @ back.T, radius)
            member = cell.member
            m = int(np.sum(member))
            nh = sum(1 for k, q, kind in pairs if kind == "h" and member[k] and member[q])
            nv = sum(1 for k, q, kind in pairs if kind == "v" and member[k] and member[q])
            v = math.pi * radius ** 2
            check(f"rot {rot}: vol = disks' area / initial packing = pi R^2",
                  cell.volume(xr, rr, "areas"), v, 1e-14)
            inner = cell.measure(xr, rr, lr, "internal", "areas")
            touch = cell.measure(xr, rr, lr, "touching", "areas")
            if rot == 0.0:
                check("internal sigma_xx = n_h Fx 2a / V", inner["sigma"][0, 0],
                      nh * fx * 2 * a / v, 1e-13)
                check("internal sigma_yy = n_v Fy 2a / V", inner["sigma"][1, 1],
                      nv * fy * 2 * a / v, 1e-13)
                check("internal sigma_yx = n_h Ft 2a / V", inner["sigma"][1, 0],
                      nh * ft * 2 * a / v, 1e-13)
                check("internal sigma_xy = 0", inner["sigma"][0, 1], 0.0, 1e-13)
                check("internal counts n_h + n_v contacts", inner["contacts"], nh + nv, 0)
                # Every tracked disk of the lattice has two horizontal contacts; the cell
                # stays off the lattice's edge, and the wall contact is the one of
                # disk (0, 0), outside the cell.
                inside_wall = bool(member[wall])
                check("touching sigma_xx = 2 M Fx a / V", touch["sigma"][0, 0],
                      2 * m * fx * a / v, 1e-13)
                check("touching sigma_yy = 2 M Fy a / V", touch["sigma"][1, 1],
                      (2 * m * fy * a + (7 * fy * a if inside_wall else 0.0)) / v, 1e-13)
                sxx, syy = inner["sigma"][0, 0], inner["sigma"][1, 1]
                sxy = 0.5 * (inner["sigma"][0, 1] + inner["sigma"][1, 0])
                lam = np.linalg.eigvalsh(np.array([[sxx, sxy], [sxy, syy]]))
                check("p = (s1 + s2)/2", inner["p"], 0.5 * (lam[0] + lam[1]), 1e-13)
                check("q = (s1 - s2)/2", inner["q"], 0.5 * (lam[1] - lam[0]), 1e-13)
                check("p > 0 in compression", float(inner["p"] > 0), 1.0, 0)
            results.append((inner, touch, m))
        (i0, t0, m0), (i1, t1, m1) = results
        check("the rotated frame selects the same number of disks", m1, m0, 0)
        for key in ("p", "q"):
            check(f"internal {key} unchanged by a rotation of the frame", i1[key], i0[key], 1e-12)
            check(f"touching {key} unchanged by a rotation of the frame", t1[key], t0[key], 1e-12)

        # A wall contact of a tracked disk counts only in the "touching" reading.
        x, r, lines, pairs, wall = lattice(n, a, fx, fy, ft, 0.0)
        write_frame(os.path.join(tmp, "particles_w.vtp"), os.path.join(tmp, "contacts_w.vtp"),
                    x, r, np.zeros_like(x), lines)
        xr, rr, _, lr = read(tmp, "w")
        cell = f1.Cell(xr, rr, xr[wall] + np.array([0.6, 0.6]), 1.5)
        assert cell.member[wall]
        m = int(np.sum(cell.member))
        v = math.pi * 1.5 ** 2
        inner = cell.measure(xr, rr, lr, "internal", "areas")
        touch = cell.measure(xr, rr, lr, "touching", "areas")
        nv = sum(1 for k, q, kind in pairs if kind == "v" and cell.member[k] and cell.member[q])
        check("internal sigma_yy leaves the wall out", inner["sigma"][1, 1],
              nv * fy * 2 * a / v, 1e-13)
        # Touching: every contact of a tracked disk adds Fy a, the wall's 7 Fy a.
        nvt = sum(int(cell.member[k]) + int(cell.member[q])
                  for k, q, kind in pairs if kind == "v")
        check("touching sigma_yy counts the wall contact", touch["sigma"][1, 1],
              (nvt * fy * a + 7 * fy * a) / v, 1e-13)

        # Affine stretch: x -> (2x, y/2) from t0 to t.
        x, r, lines, pairs, wall = lattice(n, a, fx, fy, ft, 0.0)
        write_frame(os.path.join(tmp, "particles_s0.vtp"), os.path.join(tmp, "contacts_s0.vtp"),
                    x, r, np.zeros_like(x), lines)
        x0, r0, _, l0 = read(tmp, "s0")
        cell = f1.Cell(x0, r0, centre, radius)
        stretch = np.array([2.0, 0.5])
        xs = x0 * stretch
        ea, eb, fn, fts = lines
        write_frame(os.path.join(tmp, "particles_s1.vtp"), os.path.join(tmp, "contacts_s1.vtp"),
                    xs, r0, xs - x0, (ea * stretch, eb * stretch, fn, fts))
        xs, rs, us, ls = read(tmp, "s1")
        check("the initial positions are x - displacement", float(np.max(np.abs(xs - us - x0))),
              0.0, 0)
        ms = cell.measure(xs, rs, ls)
        check("affine stretch: lambda_x = 2", ms["lx"], 2.0, 1e-15)
        check("affine stretch: lambda_y = 0.5", ms["ly"], 0.5, 1e-15)
        a0, _ = f1.hull(x0[cell.member])
        a1, _ = f1.hull(xs[cell.member])
        check("affine stretch: the hull's area times det = 1", a1 / a0, 1.0, 1e-13)

    sq = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0.5, 0.5], [0.2, 0.7], [1, 0.5]], float)
    area, per = f1.hull(sq)
    check("hull of a unit square: area 1", area, 1.0, 1e-15)
    check("hull of a unit square: perimeter 4", per, 4.0, 1e-15)

    print(f"{len(FAILED)} failed" if FAILED else "all checks pass")
    return 1 if FAILED else 0


if __name__ == "__main__":
    sys.exit(main())
