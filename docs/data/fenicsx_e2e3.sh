#!/usr/bin/env bash
# FEniCSx (dolfinx) peer points of the speed-against-error plot (docs/BENCHMARKS.md,
# "Speed against error: the plot"): runs the peer script for E2 and E3 on a ladder of
# sizes, one process each, and writes docs/data/fenicsx_e2e3.csv
# (dim,n,solver,t_assemble,t_solve,l2_err,ndofs,iters,reps) with the date, the machine
# load and the versions in comment lines.
#
# usage: docs/data/fenicsx_e2e3.sh [PYTHON] [PEERS_DIR]
#   PYTHON     the venv interpreter with dolfinx (default /tmp/fenv/bin/python)
#   PEERS_DIR  directory of run_dolfinx.py (the FEniCSx driver, kept outside this repository)
# QUICK=1 runs a tiny ladder.
set -euo pipefail
PY=${1:-/tmp/fenv/bin/python}
PEERS=${2:-/work/shared/peers/fem}
OUT=$(cd "$(dirname "$0")" && pwd)/fenicsx_e2e3.csv
if [[ "${QUICK:-0}" == 1 ]]; then
  RUNS="2:20:gamg 2:20:mumps 3:4:gamg"
else
  RUNS="2:50:gamg 2:100:gamg 2:200:gamg 2:300:gamg 2:500:gamg 2:700:gamg 2:1000:gamg
        2:100:mumps 2:300:mumps 2:500:mumps
        3:5:gamg 3:10:gamg 3:15:gamg 3:20:gamg 3:30:gamg 3:40:gamg
        3:10:mumps 3:20:mumps"
fi
TMP=$(mktemp)
{
  echo "# FEniCSx peer points: $PY $PEERS/run_dolfinx.py DIM N SOLVER, one process each"
  echo "# started $(date -u '+%Y-%m-%d %H:%M:%S UTC') on $(nproc) cores, uptime:$(uptime | sed 's/.*load/ load/')"
  echo "dim,n,solver,t_assemble,t_solve,l2_err,ndofs,iters,reps"
} > "$TMP"
VERSION=""
for run in $RUNS; do
  IFS=: read -r dim n solver <<< "$run"
  line=$(cd "$PEERS" && "$PY" run_dolfinx.py "$dim" "$n" "$solver" | grep '^RESULT ' | sed 's/^RESULT //')
  row=$(printf '%s' "$line" | "$PY" -c 'import json,sys
r = json.load(sys.stdin)
print("%d,%d,%s,%.6f,%.6f,%.6e,%d,%d,%d" % (r["dim"], r["n"], sys.argv[1], r["t_assemble"],
      r["t_solve"], r["l2_err"], r["ndofs"], r["iters"], r["reps"]))
print(r["version"], file=sys.stderr)' "$solver" 2>"$TMP.v")
  VERSION=$(cat "$TMP.v")
  echo "$row" | tee -a "$TMP" >&2
done
echo "# finished $(date -u '+%Y-%m-%d %H:%M:%S UTC'), uptime:$(uptime | sed 's/.*load/ load/'); $VERSION" >> "$TMP"
mv "$TMP" "$OUT"
rm -f "$TMP.v"
echo "wrote $OUT" >&2
