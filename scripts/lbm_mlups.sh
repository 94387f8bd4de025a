#!/bin/sh
# MLUPS of the lattice Boltzmann model through the command: scenes/lbm/taylor_green.toml
# (fully periodic, no obstacle) at N × N nodes for N in 64 ... 4096, with 1 and 2 threads
# ([solver] threads). Prints N, threads, lattice steps, mlups from summary.json.
# Usage: scripts/lbm_mlups.sh [path/to/porofrac]
set -eu
bin=${1:-target/release/porofrac}
dir=$(mktemp -d)
for n in 64 256 1024 2048 4096; do
  steps=$(( 200000000 / (n * n) ))
  [ "$steps" -lt 20 ] && steps=20
  for threads in 1 2; do
    python3 - "$n" "$steps" "$threads" "$dir/tg_$n.toml" <<'PY'
import sys
n, steps, threads, path = int(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
text = open("scenes/lbm/taylor_green.toml").read()
dx = 0.1 / n
dt = 0.1 * dx * dx / 1e-6
lines = []
for line in text.splitlines():
    if line.startswith("spacing"):
        line = f"spacing = {dx!r}"
    elif line.startswith("end_time"):
        line = f"end_time = {steps * dt!r}"
    elif line.startswith("steps ="):
        line = "steps = 1"
    elif line.startswith("at ="):
        line = f"at = [{dx / 2!r}, {0.025 + dx / 2!r}]"
    lines.append(line)
lines.append(f"\n[solver]\nthreads = {threads}\n")
open(path, "w").write("\n".join(lines))
PY
    "$bin" run "$dir/tg_$n.toml" --out "$dir/out_$n" > /dev/null 2>&1
    mlups=$(python3 -c "import json,sys; s=json.load(open('$dir/out_$n/summary.json')); print(round(s['mlups'],1), s['lattice']['lattice_steps'])")
    echo "$n $threads $mlups"
  done
done
rm -rf "$dir"
