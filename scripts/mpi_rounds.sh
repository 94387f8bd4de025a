#!/usr/bin/env bash
# The standard problems core for core: porofrac threaded (`porofrac run`, two threads),
# porofrac on two MPI ranks (`mpirun -n 2 porofrac run`, one thread per rank) and the
# FEniCSx peer on two MPI ranks (`mpiexec -n 2`, CG + GAMG), back to back: the rounds of
# docs/BENCHMARKS.md "Core for core on MPI ranks".
#
#   scripts/mpi_rounds.sh FENICS_VENV [ROUNDS] [PROBLEMS]
#
# FENICS_VENV: a Python venv with dolfinx (its `bin/python` and `bin/mpiexec`; the FEniCSx
# driver `run_dolfinx.py` is kept outside this repository, in ../shared/peers/fem).
# PROBLEMS: "e2 e3" by default. Time = assembly + solve of summary.json for porofrac (for
# the MPI run the slowest rank's: assembly of the owned rows, AMG setup and CG), assembly
# + solve for the peer (one pass, BEST_OF_CHEAP_S=0). One line per run: round, problem,
# tool, seconds, L2 error, CG iterations, extra (MPI: AMG setup s, CG s per iteration,
# peak memory per rank in MB; the peer: its assembly and solve s).
set -euo pipefail
cd "$(dirname "$0")/.."
venv=$1
rounds=${2:-5}
problems=${3:-"e2 e3"}
cargo build --release -p porofrac-cli --features mpi >&2
peer=$(cd ../shared/peers/fem && pwd)
out=$(mktemp -d)
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
echo "# $(date -u +%FT%TZ) $(nproc) cores, $(lscpu | sed -n 's/Model name: *//p'), load: $(cut -d' ' -f1-3 /proc/loadavg)"
summary() {
    python3 - "$@" <<'PY'
import json, sys
r, p, tool, path = sys.argv[1:5]
s = json.load(open(path))
w = s['wall_seconds']
d = s.get('distributed')
extra = ''
if d:
    extra = 'setup=%.3f per_it=%.4f mem_MB=%s' % (d['amg_setup_seconds'], d['seconds_per_iteration'],
            '/'.join(str(m // 2**20) for m in d['peak_memory_bytes_per_rank']))
else:
    extra = 'mem_MB=%d' % (s['peak_memory_bytes'] // 2**20)
print(r, p, tool, round(w['assembly'] + w['solve'], 3), s['errors']['l2_displacement'], s['solver']['iterations'], extra)
PY
}
for r in $(seq 1 "$rounds"); do
    for p in $problems; do
        case $p in e2) dim=2; n=1000 ;; e3) dim=3; n=40 ;; esac
        target/release/porofrac run "scenes/bench/$p.toml" --out "$out/$p-t" >/dev/null 2>&1
        summary "$r" "$p" threads "$out/$p-t/summary.json"
        mpirun --oversubscribe -n 2 -x RAYON_NUM_THREADS=1 target/release/porofrac run "scenes/bench/$p.toml" --out "$out/$p-m" >/dev/null 2>&1
        summary "$r" "$p" mpi2 "$out/$p-m/summary.json"
        (cd "$peer" && BEST_OF_CHEAP_S=0 "$venv/bin/mpiexec" -n 2 "$venv/bin/python" run_dolfinx.py "$dim" "$n" gamg) | sed -n 's/^RESULT //p' |
            python3 -c "import json,sys; d=json.loads(sys.stdin.read()); print($r, '$p', 'fenicsx2', round(d['t_assemble']+d['t_solve'],3), d['l2_err'], d['iters'], 'nprocs=%d assembly=%.3f solve=%.3f' % (d['nprocs'], d['t_assemble'], d['t_solve']))"
    done
done
rm -rf "$out"
