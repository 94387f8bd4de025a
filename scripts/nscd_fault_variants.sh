#!/usr/bin/env bash
# Runs a reduced F2 fault scene (scenes/nscd/fault_gamma*.toml) with some keys replaced,
# through `porofrac run`, and prints one table row per run: the fault measures of
# summary.json and the W1 mean pressure over phase 1 ([T/8, T/4]) and phase 2 ([T/4, T]).
#
#   scripts/nscd_fault_variants.sh SCENE LABEL 'sed-expr' [LABEL 'sed-expr' ...]
#
# Each sed expression edits a copy of SCENE (e.g. 's/^d_w = .*/d_w = 0.001/'). The copies
# and the run directories go under ${OUT:-/tmp/nscd_variants}. Needs the release binary
# (cargo build --release -p porofrac-cli) and python3 for the table.
set -euo pipefail
scene=$1; shift
out=${OUT:-/tmp/nscd_variants}
bin=${BIN:-target/release/porofrac}
mkdir -p "$out"
while [ $# -ge 2 ]; do
  label=$1; expr=$2; shift 2
  file="$out/$label.toml"
  sed -e "$expr" "$scene" > "$file"
  # Scene outputs: no VTK, no plots (the measures only).
  sed -i -e 's/^plots = true/plots = false/' "$file"
  start=$(date +%s.%N)
  "$bin" run "$file" --out "$out/$label" > "$out/$label.log" 2>&1
  end=$(date +%s.%N)
  python3 - "$out/$label" "$label" "$start" "$end" <<'PY'
import csv, json, sys
d, label, t0, t1 = sys.argv[1], sys.argv[2], float(sys.argv[3]), float(sys.argv[4])
s = json.load(open(f"{d}/summary.json"))
f = s.get("fault") or {}
# Column names carry their unit ("time [s]", "p_W1 [Pa]"): key the rows by the name.
rows = [{k.split(" [")[0]: v for k, v in r.items()} for r in csv.DictReader(open(f"{d}/probes.csv"))]
t = [float(r["time"]) for r in rows]
p = [float(r["p_W1"]) for r in rows]
T = t[-1]
def mean(a, b):
    v = [pi for ti, pi in zip(t, p) if a <= ti <= b]
    return sum(v) / len(v)
tri = f.get("trishear") or {}
la = f.get("limit_angle_deg")
print(f"| {label} | {s.get('particles')} | {t1 - t0:.1f} | {s['sweeps']['mean']:.0f} | "
      f"{la if la is None else round(la, 1)} | {f.get('run_out', float('nan')):.2f} | "
      f"{tri.get('half_apex_deg', float('nan')):.0f} | {tri.get('l2', float('nan')):.3f} | "
      f"{p[0] / 1e3:.1f} / {mean(T / 8, T / 4) / 1e3:.1f} / {mean(T / 4, T) / 1e3:.1f} |")
PY
done
