#!/usr/bin/env bash
# Cosserat DEM speed against the same method in numpy/scipy (peers/cosserat/dem.py), runs
# interleaved on the same meshes (the plate with a hole, r = 0.216 mm, r/l = 1.063, N = 0.5),
# and optionally against binaries of an earlier version of porofrac.
#
# usage: scripts/cosserat_speed.sh [LEVEL:LIB_RUNS:PY_RUNS:CMD_RUNS ...]
#        (default: 3:8:6:6 5:4:3:4 8:3:2:3 12:2:1:2)
#
# For each O-grid level (320 L^2 triangles, written by `plate_hole mesh L 0.216 FILE`):
#   library  `plate_hole run FILE 0.216 1.063 0.5 auto` (assembly + solve), LIB_RUNS times,
#            interleaved with $BEFORE_PLATE_HOLE when set;
#   python   `dem.py FILE 0.216 1.063 0.5` (t_assemble + t_solve), PY_RUNS times, each
#            after a library run; the ratio of the medians;
#   command  `porofrac run` on a copy of scenes/cosserat_plate_hole.toml pointing at FILE
#            (summary.json's total and the process's wall time), CMD_RUNS times,
#            interleaved with $BEFORE_POROFRAC when set.
# PYTHON selects the interpreter with numpy and scipy (default: python3). Output on stdout;
# meshes and runs under $OUT (default target/cosserat_speed).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
if [ $# -eq 0 ]; then set -- 3:8:6:6 5:4:3:4 8:3:2:3 12:2:1:2; fi
out=${OUT:-$root/target/cosserat_speed}
python=${PYTHON:-python3}
mkdir -p "$out"
cargo build --release -q -p porofrac-cosserat --example plate_hole
cargo build --release -q -p porofrac-cli
ex=$root/target/release/examples/plate_hole
cli=$root/target/release/porofrac
r=0.216 rl=1.063 n=0.5

# Medians of `label value ...` lines: label, count, median, min, max.
medians() {
    python3 -c '
import sys, statistics as st
d = {}
for line in sys.stdin:
    f = line.split()
    d.setdefault(f[0], []).append(float(f[1]))
for k, v in d.items():
    print(f"{k}: n {len(v)}, median {st.median(v):.4f} s, min {min(v):.4f}, max {max(v):.4f}; " + " ".join(f"{x:.3f}" for x in v))
if "python" in d and "porofrac" in d:
    print("python / porofrac (medians): %.2f" % (st.median(d["python"]) / st.median(d["porofrac"])))
'
}
# assembly + solve of a RESULT line.
lib_time() { sed -n 's/^RESULT //p' | python3 -c 'import json, sys; d = json.loads(sys.stdin.read()); print(d["t_assemble"] + d["t_solve"])'; }

echo "# $(date -u +%FT%TZ), load $(cut -d' ' -f1-3 /proc/loadavg), $(lscpu | sed -n 's/^Model name: *//p'), $(nproc) cores"
for spec in "$@"; do
    IFS=: read -r L nl np nc <<<"$spec"
    mesh="$out/L$L.vtu"
    "$ex" mesh "$L" "$r" "$mesh" >/dev/null
    echo "## level $L ($(date -u +%T), load $(cut -d' ' -f1-3 /proc/loadavg))"
    {
        for _ in $(seq "$nl"); do
            echo "porofrac $("$ex" run "$mesh" "$r" "$rl" "$n" auto | lib_time)"
            if [ -n "${BEFORE_PLATE_HOLE:-}" ]; then
                echo "before $("$BEFORE_PLATE_HOLE" run "$mesh" "$r" "$rl" "$n" auto | lib_time)"
            fi
        done
    } | medians | sed 's/^/library /'
    {
        for _ in $(seq "$np"); do
            echo "porofrac $("$ex" run "$mesh" "$r" "$rl" "$n" auto | lib_time)"
            echo "python $(cd peers/cosserat && "$python" dem.py "$mesh" "$r" "$rl" "$n" | lib_time)"
        done
    } | medians | sed 's/^/peer /'
    scene="$out/scene_L$L.toml"
    sed "s|^path = .*|path = \"$mesh\"|" scenes/cosserat_plate_hole.toml >"$scene"
    {
        for _ in $(seq "$nc"); do
            for bin in "$cli" ${BEFORE_POROFRAC:+"$BEFORE_POROFRAC"}; do
                label=porofrac
                [ "$bin" = "$cli" ] || label=before
                rm -rf "$out/run_L$L"
                "$bin" run "$scene" --out "$out/run_L$L" >/dev/null
                python3 -c 'import json, sys; print(sys.argv[2], json.load(open(sys.argv[1]))["wall_seconds"]["total"])' \
                    "$out/run_L$L/summary.json" "$label"
            done
        done
    } | medians | sed 's/^/command /'
done
