#!/usr/bin/env bash
# The standard problems through the command, back to back with the `solvers` example and
# the FEniCSx peer (CG + GAMG): the rounds of docs/BENCHMARKS.md "The command against the
# library and FEniCSx".
#
#   scripts/command_rounds.sh FENICS_PYTHON [ROUNDS]
#
# FENICS_PYTHON: a Python with dolfinx (and the FEniCSx driver `run_dolfinx.py`, kept
# outside this repository). Each round runs, for E2 n = 1000 and E3 n = 40: `porofrac run
# scenes/bench/eK.toml` (time = assembly + solve of summary.json, error =
# errors.l2_displacement), the `solvers` example on the same problem (assembly + setup +
# solve), and the peer once (BEST_OF_CHEAP_S=1: one pass; assembly + solve). One line per
# run: round, problem, tool, seconds, L2 error.
set -euo pipefail
cd "$(dirname "$0")/.."
py=$1
rounds=${2:-5}
cargo build --release -p porofrac-cli -p porofrac-sim --example solvers >&2
peer=$(cd ../shared/peers/fem && pwd)
out=$(mktemp -d)
echo "# $(date -u +%FT%TZ) $(nproc) cores, $(lscpu | sed -n 's/Model name: *//p'), load: $(cut -d' ' -f1-3 /proc/loadavg)"
for r in $(seq 1 "$rounds"); do
    for p in "e2 2 1000" "e3 3 40"; do
        set -- $p
        target/release/porofrac run "scenes/bench/$1.toml" --out "$out/$1" 2>/dev/null
        python3 -c "import json,sys; s=json.load(open('$out/$1/summary.json')); w=s['wall_seconds']; print($r, '$1', 'porofrac', round(w['assembly']+w['solve'],3), s['errors']['l2_displacement'])"
        target/release/examples/solvers "$1" "$3" cg-amg 1e-8 | awk -v r="$r" -v p="$1" -F'|' '/cg-amg/ {gsub(/ /,"",$11); gsub(/ /,"",$14); print r, p, "example", $11, $14}'
        (cd "$peer" && BEST_OF_CHEAP_S=1 "$py" run_dolfinx.py "$2" "$3" gamg) | sed -n 's/^RESULT //p' |
            python3 -c "import json,sys; d=json.loads(sys.stdin.read()); print($r, '$1', 'fenicsx', round(d['t_assemble']+d['t_solve'],3), d['l2_err'])"
    done
done
