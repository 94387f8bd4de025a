#!/usr/bin/env bash
# Cosserat DEM speed and accuracy against two peers, back to back on the same meshes: the
# plate with a hole (F. Marazzato (2021), arXiv:2101.08712, §3.9.1; r = 0.216 mm, r/l =
# 1.063, N = 0.5, reference SCF 2.5548).
#
# usage: scripts/cosserat_rounds.sh [LEVEL ...]        (default: 3 5 8 12 18)
#
# For each O-grid level L (320 L^2 triangles, written by `plate_hole mesh L 0.216 FILE`):
#   porofrac   crates/cosserat/examples/plate_hole.rs `run FILE ... auto` (library: assembly
#              with the reconstruction; the solver "auto" picks the LDLT + Schur complement
#              solve, single-precision factors refined by GMRES, below 150,000 unknowns and
#              GMRES with the multigrid preconditioner above), REPEAT times (default 3);
#              once `... gmres-amg` where auto is the factorisation, and up to LU_MAX_LEVEL
#              (default 8) `... lu` (faer sparse LU)
#   command    `porofrac run` on a copy of scenes/cosserat_plate_hole.toml pointing at FILE
#              (the user's path; times from summary.json, whole process from `date`)
#   python-dem peers/cosserat/dem.py (the same method in numpy/scipy, spsolve)
#   fenicsx    peers/cosserat/fenicsx_p2p1.py (mixed P2-P1 FEM, MUMPS)
# Above DEM_MAX_LEVEL (default 18: 103,680 triangles) only FEniCSx runs; the Python DEM runs
# up to PY_MAX_LEVEL (default 12: at level 18 SciPy's SuperLU needed more than 17 minutes
# and 8 GB), under a 16 GB address-space limit (PY_MEM_KB); a MemoryError there is logged.
# FEM_EXTRA_LEVELS (default "1 2") adds FEniCSx-only coarse levels (to reach the DEM's
# error range). Every run prints one `RESULT {json}` line; everything goes to stdout and to
# $OUT/rounds.txt (OUT default target/cosserat_rounds). FEM_PYTHON / FEM_LIB select the
# FEniCSx venv (default /work/venv-fem/bin/python with LD_LIBRARY_PATH=/work/venv-fem/lib).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
if [ $# -eq 0 ]; then set -- 3 5 8 12 18; fi
levels=("$@")
out=${OUT:-$root/target/cosserat_rounds}
dem_max=${DEM_MAX_LEVEL:-18}
lu_max=${LU_MAX_LEVEL:-8}
py_max=${PY_MAX_LEVEL:-12}
repeat=${REPEAT:-3}
py_mem_kb=${PY_MEM_KB:-16000000}
fem_extra=${FEM_EXTRA_LEVELS:-1 2}
fem_python=${FEM_PYTHON:-/work/venv-fem/bin/python}
fem_lib=${FEM_LIB:-/work/venv-fem/lib}
r=0.216 rl=1.063 n=0.5
mkdir -p "$out"
log="$out/rounds.txt"
: >"$log"
say() { echo "$*" | tee -a "$log"; }

cargo build --release -q -p porofrac-cosserat --example plate_hole
cargo build --release -q -p porofrac-cli
ex=target/release/examples/plate_hole
cli=target/release/porofrac
py() { LD_LIBRARY_PATH="$fem_lib" "$fem_python" "$@"; }

say "# start $(date -u +%FT%TZ) load $(cat /proc/loadavg) nproc $(nproc)"
say "# $(lscpu | sed -n 's/^Model name: *//p')"
for L in $fem_extra; do
    mesh="$out/L$L.vtu"
    "$ex" mesh "$L" "$r" "$mesh" >/dev/null
    (cd peers/cosserat && py fenicsx_p2p1.py "$mesh" "$r" "$rl" "$n") | grep '^RESULT' | sed "s/^RESULT {/RESULT {\"level\": $L, /" | tee -a "$log"
done
for L in "${levels[@]}"; do
    mesh="$out/L$L.vtu"
    "$ex" mesh "$L" "$r" "$mesh" >/dev/null
    say "# level $L $(date -u +%T) load $(cut -d' ' -f1-3 /proc/loadavg)"
    if [ "$L" -gt "$dem_max" ]; then
        say "# level $L: DEM runs skipped (above DEM_MAX_LEVEL=$dem_max, memory of the LU)"
        (cd peers/cosserat && py fenicsx_p2p1.py "$mesh" "$r" "$rl" "$n") | grep '^RESULT' | sed "s/^RESULT {/RESULT {\"level\": $L, /" | tee -a "$log"
        continue
    fi
    for _ in $(seq "$repeat"); do
        say "# load $(cut -d' ' -f1-3 /proc/loadavg)"
        "$ex" run "$mesh" "$r" "$rl" "$n" auto 2>&1 | sed "s/^RESULT {/RESULT {\"level\": $L, /" | tee -a "$log"
    done
    if [ "$(( 960 * L * L ))" -lt 150000 ]; then
        "$ex" run "$mesh" "$r" "$rl" "$n" gmres-amg | sed "s/^RESULT {\"code\": \"porofrac\"/RESULT {\"level\": $L, \"code\": \"porofrac-gmres-amg\"/" | tee -a "$log"
    fi
    if [ "$L" -le "$lu_max" ]; then
        "$ex" run "$mesh" "$r" "$rl" "$n" lu | sed "s/^RESULT {\"code\": \"porofrac\"/RESULT {\"level\": $L, \"code\": \"porofrac-lu\"/" | tee -a "$log"
    fi
    # The command: the bundled scene with the mesh path replaced.
    scene="$out/scene_L$L.toml"
    sed "s|^path = .*|path = \"$mesh\"|" scenes/cosserat_plate_hole.toml >"$scene"
    t0=$(date +%s.%N)
    "$cli" run "$scene" --out "$out/run_L$L" >/dev/null
    t1=$(date +%s.%N)
    python3 - "$out/run_L$L/summary.json" "$L" "$t0" "$t1" <<'EOF' | tee -a "$log"
import json, sys
s = json.load(open(sys.argv[1]))
w = s["wall_seconds"]
print("RESULT " + json.dumps({"level": int(sys.argv[2]), "code": "porofrac-command", "cells": s["cells"],
      "dofs": s["dofs"], "scf": s["field_extrema"]["syy"][1], "t_grid": w["grid"],
      "t_assembly_and_factor": w["assembly"], "t_solve": w["solve"], "t_output": w["output"],
      "t_total": w["total"], "t_process": float(sys.argv[4]) - float(sys.argv[3]),
      "peak_memory_bytes": s.get("peak_memory_bytes"), "linear": s["solver"]["linear"],
      "iterations": s["solver"]["iterations"]}))
EOF
    if [ "$L" -le "$py_max" ]; then
        say "# python-dem $(date -u +%T) load $(cut -d' ' -f1-3 /proc/loadavg)"
        (cd peers/cosserat && ulimit -v "$py_mem_kb" && py dem.py "$mesh" "$r" "$rl" "$n" 2>&1 | tail -3) | sed "s/^RESULT {/RESULT {\"level\": $L, /" | tee -a "$log" || say "# level $L: python-dem failed"
    else
        say "# level $L: python-dem skipped (above PY_MAX_LEVEL=$py_max)"
    fi
    say "# load $(cut -d' ' -f1-3 /proc/loadavg)"
    (cd peers/cosserat && py fenicsx_p2p1.py "$mesh" "$r" "$rl" "$n") | grep '^RESULT' | sed "s/^RESULT {/RESULT {\"level\": $L, /" | tee -a "$log"
done
say "# end $(date -u +%FT%TZ) load $(cat /proc/loadavg)"
