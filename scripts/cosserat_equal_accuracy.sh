#!/usr/bin/env bash
# Cosserat DEM: porofrac against the same method in numpy/scipy (peers/cosserat/dem.py) at
# the same stress concentration error, back to back on the same meshes: the plate with a
# hole (F. Marazzato (2021), arXiv:2101.08712, §3.9.1; r = 0.216 mm, r/l = 1.063, N = 0.5,
# Mindlin SCF 2.5548), the O-grid meshes of `plate_hole mesh L 0.216 FILE` (320 L^2
# triangles).
#
# usage: scripts/cosserat_equal_accuracy.sh [LEVEL:CMD_RUNS:PY_RUNS ...]
#        (default: 3:5:3 5:5:3 8:5:1 12:5:1)
#
# Per level, CMD_RUNS times `porofrac run` on a copy of scenes/cosserat_plate_hole.toml
# pointing at the mesh (summary.json: assembly with the factorisation + solve, and the
# total with output), each followed by the library (`plate_hole run FILE ... auto`), and
# PY_RUNS times `dem.py FILE 0.216 1.063 0.5` (t_assemble + t_solve) in between; the SCF of
# every code. PEER_RULE=smallest-weight runs the peer with the paper's wider pool and the
# smallest largest weight everywhere (`--select minmax --depth 2 --bselect same`) instead
# of porofrac's default. CPUS (e.g. 0) pins every process to those cores with taskset and
# sets `[solver] threads` to their number. One `CSV code,level,cells,dofs,t_assemble,
# t_solve,t_total,scf,err_rel` line per run (the columns of scripts/cosserat_table.py, for
# the speed_error_plot example), medians at the end of each level.
# PYTHON selects the interpreter with numpy and scipy (default python3); OUT the work
# directory (default target/cosserat_equal_accuracy).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
if [ $# -eq 0 ]; then set -- 3:5:3 5:5:3 8:5:1 12:5:1; fi
out=${OUT:-$root/target/cosserat_equal_accuracy}
python=${PYTHON:-python3}
r=0.216 rl=1.063 n=0.5 ref=2.5548
mkdir -p "$out"
cargo build --release -q -p porofrac-cosserat --example plate_hole
cargo build --release -q -p porofrac-cli
ex=$root/target/release/examples/plate_hole
cli=$root/target/release/porofrac
pin=()
threads=0
if [ -n "${CPUS:-}" ]; then
    pin=(taskset -c "$CPUS")
    threads=$(awk -F, '{print NF}' <<<"$CPUS")
fi
peer_flags=()
if [ "${PEER_RULE:-}" = smallest-weight ]; then
    peer_flags=(--select minmax --depth 2 --bselect same)
fi
# One CSV line from a RESULT json: row JSON CODE LEVEL.
row() {
    python3 - "$@" "$ref" <<'PY'
import json, sys
d, code, level, ref = json.loads(sys.argv[1]), sys.argv[2], sys.argv[3], float(sys.argv[4])
t = d["t_assemble"] + d["t_solve"]
print(f"CSV {code},{level},{d['cells']},{d['dofs']},{d['t_assemble']:.6f},{d['t_solve']:.6f},"
      f"{t:.6f},{d['scf']:.15e},{d['scf'] / ref - 1:.6e}")
PY
}
echo "# $(date -u +%FT%TZ), load $(cut -d' ' -f1-3 /proc/loadavg), $(nproc) cores, cpus ${CPUS:-all}, peer ${PEER_RULE:-default}"
for spec in "$@"; do
    IFS=: read -r L nc np <<<"$spec"
    mesh="$out/L$L.vtu"
    "$ex" mesh "$L" "$r" "$mesh" >/dev/null
    scene="$out/scene_L$L.toml"
    sed "s|^path = .*|path = \"$mesh\"|" scenes/cosserat_plate_hole.toml >"$scene"
    printf '\n[solver]\nthreads = %s\n' "$threads" >>"$scene"
    echo "## level $L ($(date -u +%T), load $(cut -d' ' -f1-3 /proc/loadavg))"
    for i in $(seq "$nc"); do
        rm -rf "$out/run_L$L"
        "${pin[@]}" "$cli" run "$scene" --out "$out/run_L$L" >/dev/null
        python3 - "$out/run_L$L/summary.json" "$L" "$ref" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
w, scf = d["wall_seconds"], d["field_extrema"]["syy"][1]
ref = float(sys.argv[3])
print(f"CSV porofrac-command,{sys.argv[2]},{d['cells']},{d['dofs']},{w['assembly']:.6f},{w['solve']:.6f},"
      f"{w['assembly'] + w['solve']:.6f},{scf:.15e},{scf / ref - 1:.6e}  (total with output {w['total']:.4f})")
PY
        res=$("${pin[@]}" "$ex" run "$mesh" "$r" "$rl" "$n" auto | sed -n 's/^RESULT //p')
        row "$res" porofrac "$L"
        if [ "$i" -le "$np" ]; then
            res=$(cd peers/cosserat && "${pin[@]}" "$python" dem.py "$mesh" "$r" "$rl" "$n" "${peer_flags[@]}" | sed -n 's/^RESULT //p')
            row "$res" "python-dem${PEER_RULE:+-$PEER_RULE}" "$L"
        fi
    done
done
