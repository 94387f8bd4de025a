#!/usr/bin/env bash
# Direct vs CG-AMG on the standard problems E2/E3, thread counts, and the FEniCSx peer,
# back to back: the rows of docs/BENCHMARKS.md "Linear solvers: direct vs AMG-CG".
#
#   scripts/solver_benchmarks.sh [fenics-python]
#
# fenics-python: a Python with dolfinx (for the FEniCSx driver `run_dolfinx.py`, kept
# outside this repository); without it the peer rows are skipped. Each case is its own
# process so that the peak RSS belongs to it. Columns of the porofrac rows: problem, n,
# dofs, equations, solver, grid, assembly, setup, solve, assembly + setup + solve [s], CG
# iterations, relative residual, L2 error, peak RSS [MB], hierarchy or factor.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -p porofrac-sim --example solvers >&2
bin=target/release/examples/solvers
py=${1:-}
peer=../shared/peers/fem/run_dolfinx.py

echo "# $(date -u +%FT%TZ) $(nproc) cores, load: $(cut -d' ' -f1-3 /proc/loadavg)"
row() { "$bin" "$@" | tr -s ' ' | sed "s/^/$* :: /"; }
for n in 100 300 500 1000; do
    row e2 "$n" cholesky
    row e2 "$n" cg-amg
done
for n in 10 20 40; do
    row e3 "$n" cholesky
    row e3 "$n" cg-amg
done
row e3 60 cg-amg
# Threads: the assembly and AMG kernels on 1 thread; faer's factorization sequential.
RAYON_NUM_THREADS=1 row e2 1000 cg-amg
RAYON_NUM_THREADS=1 row e3 40 cg-amg
FAER_THREADS=1 row e2 500 cholesky
FAER_THREADS=1 row e3 40 cholesky
# The peer's rule: the best of 3 runs in one process.
REPEAT=3 row e2 300 cg-amg
REPEAT=3 row e2 1000 cg-amg
REPEAT=3 row e3 40 cg-amg
if [[ -n "$py" && -f "$peer" ]]; then
    for args in "2 300" "2 1000" "3 40"; do
        # shellcheck disable=SC2086
        out=$( { /usr/bin/time -f "peak_kb %M" "$py" "$peer" $args gamg; } 2>&1 )
        echo "fenicsx $args gamg :: $(grep RESULT <<<"$out") $(grep peak_kb <<<"$out")"
    done
fi
echo "# done $(date -u +%FT%TZ), load: $(cut -d' ' -f1-3 /proc/loadavg)"
