#!/usr/bin/env bash
# Refinement study of the hydraulic fracture of Nilsen et al. (2017) §3
# (scenes/hydrofrac_seed.toml): the round-well zone at h, h/√2 and h/2 (refine = 12, 17, 24;
# the well polygon follows, its default node spacing being half the zone's triangle size),
# the zone's extent, the far field, the loads and the schedule unchanged. Prints, per grid:
# cells, fractured cells at 40 min, the reach of each wing and of the crack (largest
# distance of a fractured centroid from the well centre), the direction of the crack (axis
# through the well centre of the fractured centroids, degrees from x; the largest
# compression is along y, 90°), the wall time; then the changes between the two finest
# grids.
#
# Usage (from the repository root, after `cargo build --release -p porofrac-cli`):
#     scripts/hydrofrac_refinement.sh [OUTDIR] [REFINE...]
# PORO_BIN overrides the binary (default target/release/porofrac); SCENE the base scene
# (default scenes/hydrofrac_seed.toml; it must hold a line `refine = 12 ...`); SET keys
# given to every run as `--set` (space-separated `key=value`, e.g.
# SET="physics.cavitation_pressure=2.3e3" for the fluid-lag scene bounded by cavitation).
# Also printed: the fractured cells and the reach of each wing at every 300 s, the total
# length (tip to tip: the two wings' reaches added), the one-crack offset (the largest
# distance from the line x = 15 m of a fractured centroid beyond two cells of the wall,
# against the cell `√2/refine`, as in crates/cli/tests/hydrofrac.rs), and the changes of
# the reach, of each wing and of the total length between the two finest grids. With
# RUN=0 the runs already in OUTDIR are only read (e.g. grids run one per call, possibly
# with a different `SET="schedule.dt=..."` each).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=${PORO_BIN:-$root/target/release/porofrac}
scene=${SCENE:-$root/scenes/hydrofrac_seed.toml}
out=${1:-/tmp/hydrofrac_refinement}
shift || true
refines=("$@")
[ ${#refines[@]} -eq 0 ] && refines=(12 17 24)
mkdir -p "$out"
for r in "${refines[@]}"; do
    [ "${RUN:-1}" = 0 ] && break
    d=$out/refine_$r
    mkdir -p "$d"
    sed -e "s/^refine = 12 .*/refine = $r/" -e "0,/^name = \".*\"/s//name = \"hydrofrac_refine_$r\"/" \
        "$scene" >"$d/scene.toml"
    grep -q "^refine = $r\$" "$d/scene.toml" || { echo "refine key not found" >&2; exit 1; }
    sets=()
    for kv in ${SET:-}; do sets+=(--set "$kv"); done
    "$bin" run "$d/scene.toml" --out "$d/out" "${sets[@]}" >"$d/log.txt" 2>&1 || { echo "refine $r failed, see $d/log.txt" >&2; exit 1; }
done
python3 - "$out" "${refines[@]}" <<'PY'
import csv, json, math, sys
from pathlib import Path
out, refines = Path(sys.argv[1]), [int(r) for r in sys.argv[2:]]
cx, cy = 15.0, 15.0
rows = []
for r in refines:
    d = out / f"refine_{r}" / "out"
    s = json.loads((d / "summary.json").read_text())
    # Columns `x [m]`, `y [m]`, `time [s]`.
    cells = [(float(f["x [m]"]) - cx, float(f["y [m]"]) - cy, float(f["time [s]"]))
             for f in csv.DictReader(open(d / "fracture.csv"))]
    pts = [(x, y) for x, y, t in cells if t <= 2400.0]

    def wings(T):
        up = max([math.hypot(x, y) for x, y, t in cells if t <= T and y > 0], default=0.0)
        down = max([math.hypot(x, y) for x, y, t in cells if t <= T and y < 0], default=0.0)
        return up, down

    history = [(sum(1 for _, _, t in cells if t <= T), *wings(T)) for T in range(300, 2401, 300)]
    # Axis through the centre: principal direction of the second moments about the centre.
    sxx = sum(x * x for x, _ in pts); syy = sum(y * y for _, y in pts); sxy = sum(x * y for x, y in pts)
    ang = 0.5 * math.degrees(math.atan2(2 * sxy, sxx - syy)) % 180.0
    up, down = wings(2400.0)
    cell = math.sqrt(2.0) / r
    off = max([abs(x) for x, y in pts if abs(y) > 0.25 + 2 * cell], default=0.0)
    rows.append(dict(r=r, cells=s["cells"], n=len(pts), up=up, down=down, reach=max(up, down),
                     total=up + down, ang=ang, off=off, cell=cell,
                     wall=s["wall_seconds"]["total"], history=history))
print("| h (m) | refine | cells | fractured | reach up (m) | reach down (m) | reach (m) | total (m) | direction (° from x) | off (m) / cell (m) | wall (s) |")
print("|---|---|---|---|---|---|---|---|---|---|---|")
for w in rows:
    print(f"| 1/{w['r']} | {w['r']} | {w['cells']} | {w['n']} | {w['up']:.3f} | {w['down']:.3f} | {w['reach']:.3f} | "
          f"{w['total']:.3f} | {w['ang']:.1f} | {w['off']:.3f} / {w['cell']:.3f} | {w['wall']:.1f} |")
print("\nfractured cells / reach up / reach down (m) against time\n")
print("| refine | " + " | ".join(f"{T} s" for T in range(300, 2401, 300)) + " |")
print("|---" * 9 + "|")
for w in rows:
    print(f"| {w['r']} | " + " | ".join(f"{n} / {u:.2f} / {d:.2f}" for n, u, d in w["history"]) + " |")
if len(rows) >= 2:
    a, b = rows[-2], rows[-1]
    change = {k: abs(b[k] - a[k]) / b[k] * 100 if b[k] > 0 else float("inf") for k in ("reach", "up", "down", "total")}
    print(f"\nbetween refine {a['r']} and {b['r']}: reach change {change['reach']:.1f} %, "
          f"direction change {abs(b['ang'] - a['ang']):.1f}°; upper wing {change['up']:.1f} %, "
          f"lower wing {change['down']:.1f} %, total length {change['total']:.1f} %")
PY
