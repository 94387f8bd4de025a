#!/usr/bin/env bash
# The F2 trend table of docs/nscd/fault_trends.md: the 2/5-scale fault sample
# (scenes/nscd/fault_thick.toml) for packing seeds SEEDS × γ ∈ {0, 1e3, 1e4, 1e5}
# (d_w = 5 mm for γ > 0), one `porofrac run` at a time through
# scripts/nscd_fault_variants.sh, then the measures per γ with their scatter by
# scripts/nscd_fault_trends.py.
#
#   SEEDS="1 2 3 4 5" OUT=/tmp/nscd_seeds scripts/nscd_fault_trends.sh
#
# 20 runs of 4 000 steps (1.5–7 minutes each on the shared 2-core machine); runs whose
# summary.json exists under OUT are kept. Needs the release binary
# (cargo build --release -p porofrac-cli), python3 and numpy.
set -euo pipefail
out=${OUT:-/tmp/nscd_seeds}
seeds=${SEEDS:-1 2 3 4 5}
here=$(dirname "$0")
dirs=()
for s in $seeds; do
  for g in 0 1e3 1e4 1e5; do
    label="s${s}_g${g}"
    dirs+=("$out/$label")
    [ -f "$out/$label/summary.json" ] && continue
    if [ "$g" = 0 ]; then
      expr="s/^seed = .*/seed = $s/"
    else
      expr="s/^seed = .*/seed = $s/; s/^cohesion = .*/cohesion = ${g/e/.0e+0}/; s/^d_w = .*/d_w = 0.005/"
    fi
    OUT="$out" "$here/nscd_fault_variants.sh" scenes/nscd/fault_thick.toml "$label" "$expr"
  done
done
python3 "$here/nscd_fault_trends.py" "${dirs[@]}"
