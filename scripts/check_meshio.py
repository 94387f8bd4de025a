#!/usr/bin/env python3
"""Check that meshio reads a .vtu file written by porofrac.

Usage (after `pip install meshio`):

    python3 scripts/check_meshio.py FILE.vtu [--points N] [--cells N] [--displacement]

Prints the point and cell counts, the cell blocks, and the point/cell/field data arrays.
With --points/--cells the counts are checked; with --displacement a point-data array
`displacement` with one 3-component vector per point must be present. Exits non-zero on
any failed check.

Example files: `cargo test -p porofrac-grid --test io meshio_example_files` writes
target/tmp/meshio/grid2d.vtu (2D simplices, 4 x 2 squares: 15 points, 16 cells) and
target/tmp/meshio/grid3d.vtu (3D cubes, 2 x 2 x 3: 36 points, 12 cells), both with a
`displacement` point array:

    python3 scripts/check_meshio.py target/tmp/meshio/grid2d.vtu --points 15 --cells 16 --displacement
    python3 scripts/check_meshio.py target/tmp/meshio/grid3d.vtu --points 36 --cells 12 --displacement
"""

import argparse
import sys


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("file")
    ap.add_argument("--points", type=int, help="expected number of points")
    ap.add_argument("--cells", type=int, help="expected number of cells")
    ap.add_argument(
        "--displacement",
        action="store_true",
        help="require a 3-component point-data array `displacement`",
    )
    args = ap.parse_args()
    try:
        import meshio
    except ImportError:
        print("meshio is not installed: pip install meshio", file=sys.stderr)
        return 2

    mesh = meshio.read(args.file)
    n_points = len(mesh.points)
    n_cells = sum(len(block.data) for block in mesh.cells)
    print(f"{args.file}: {n_points} points, {n_cells} cells")
    for block in mesh.cells:
        print(f"  cells: {block.type} x {len(block.data)}")
    for name, arr in mesh.point_data.items():
        print(f"  point data {name}: shape {arr.shape}")
    for name, blocks in mesh.cell_data.items():
        print(f"  cell data {name}: shapes {[b.shape for b in blocks]}")
    for name, arr in mesh.field_data.items():
        print(f"  field data {name}: shape {arr.shape}")

    failures = []
    if args.points is not None and n_points != args.points:
        failures.append(f"expected {args.points} points, found {n_points}")
    if args.cells is not None and n_cells != args.cells:
        failures.append(f"expected {args.cells} cells, found {n_cells}")
    if args.displacement:
        u = mesh.point_data.get("displacement")
        if u is None:
            failures.append("no point-data array `displacement`")
        elif u.shape != (n_points, 3):
            failures.append(f"`displacement` has shape {u.shape}, expected ({n_points}, 3)")
    for f in failures:
        print(f"FAIL: {f}", file=sys.stderr)
    print("ok" if not failures else f"{len(failures)} check(s) failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
