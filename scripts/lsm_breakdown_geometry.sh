#!/usr/bin/env bash
# Dry breakdown of the flooded borehole (scenes/lsm/borehole_flooded.toml: rays wall,
# flood_cracks, 2.5 MPa/s, a = 3 m) over packings and outer radii b, through `porofrac run`,
# against p_b = sigma_t (b^2 - a^2)/(b^2 + a^2) with sigma_t given (Pa) rather than the
# scene's own calibration:
#
#   scripts/lsm_breakdown_geometry.sh SIGMA_T B SEED...   e.g. ... 3.44e6 12 1 2 3 4 5
#
# SIGMA_T: the tensile strength for p_b (the recipe's Brazilian sigma_t of docs/models/lsm.md,
# "Calibration"); B: the outer radius (m; the bundled scene has 22). PORFRAC_BIN overrides the
# binary (default target/release/porofrac). Runs go to target/lsm_geometry/bB-SEED. One row per
# run: b, seed, particles, initiation (MPa), breakdown (MPa, the wall crack at 2a), breakdown /
# p_b, the scene's calibrated sigma_t (MPa), seconds; then mean, sd, range and the count within
# +-20 %.
#
# LSM_GEOMETRY_SCALE=S divides every radius by S (a/r_max = 3 S at the same a and b; the
# ramp against the wave transit of the rock is unchanged); LSM_GEOMETRY_CALIBRATE=0 skips
# the scene's own calibration (its sigma_t column reads nan); LSM_GEOMETRY_PORES=1 adds
# [loading] crack_across_pores = true (the crack traced through the pores it opens). Runs with
# S != 1 go to target/lsm_geometry/sS-bB-SEED, with PORES=1 to .../pores-....
set -euo pipefail
cd "$(dirname "$0")/.."
sigma=$1; b=$2; shift 2
bin=${PORFRAC_BIN:-target/release/porofrac}
scale=${LSM_GEOMETRY_SCALE:-1}
calibrate=${LSM_GEOMETRY_CALIBRATE:-1}
pores=${LSM_GEOMETRY_PORES:-0}
radii=$(python3 -c "print(f'[{0.1 / $scale!r}, {1.0 / $scale!r}]')")
rows=$(mktemp)
trap 'rm -f "$rows"' EXIT
printf 'b\tseed\tparticles\tinit_MPa\tbreakdown_MPa\tbd/p_b\tscene_sigma_t_MPa\tseconds\n'
for seed in "$@"; do
  dir=target/lsm_geometry/b$b-$seed
  [ "$scale" != 1 ] && dir=target/lsm_geometry/s$scale-b$b-$seed
  [ "$pores" = 1 ] && dir=target/lsm_geometry/pores-${dir#target/lsm_geometry/}
  rm -rf "$dir"; mkdir -p "$dir"
  sed -e "s/^seed = 1$/seed = $seed/" \
      -e "s/^disk = { center = \[0.0, 0.0\], radius = 22.0 }$/disk = { center = [0.0, 0.0], radius = $b }/" \
      -e "s/^radius = \[0.1, 1.0\]$/radius = $radii/" \
      scenes/lsm/borehole_flooded.toml > "$dir/scene.toml"
  [ "$calibrate" = 0 ] && sed -i -e "s/^calibrate = true$/calibrate = false/" "$dir/scene.toml"
  if [ "$pores" = 1 ]; then
    sed -i -e "s/^flood_cracks = true$/flood_cracks = true\ncrack_across_pores = true/" "$dir/scene.toml"
    grep -q "^crack_across_pores = true$" "$dir/scene.toml"
  fi
  grep -q "^radius = $(printf '%s' "$radii" | sed 's/[][]/\\&/g')$" "$dir/scene.toml"
  grep -q "^seed = $seed$" "$dir/scene.toml"
  grep -q "radius = $b }" "$dir/scene.toml"
  t0=$(date +%s.%N)
  "$bin" run "$dir/scene.toml" --out "$dir/out" > "$dir/log.txt" 2>&1
  t1=$(date +%s.%N)
  python3 - "$sigma" "$b" "$seed" "$dir/out" "$(echo "$t1 - $t0" | bc)" <<'PY' | tee -a "$rows"
import json, sys
sigma, b, seed, out, secs = sys.argv[1:]
sigma, b = float(sigma), float(b)
s = json.load(open(f"{out}/summary.json"))
a = s["breakdown_extent"] / 2
pb = sigma * (b * b - a * a) / (b * b + a * a)
nan = float("nan")
init = s.get("initiation_pressure") or nan
bd = s.get("breakdown_pressure") or nan
cal = (s.get("calibration") or {}).get("tensile_strength") or nan
print(f"{b:g}\t{seed}\t{s['particles']}\t{init / 1e6:.3f}\t{bd / 1e6:.3f}\t{bd / pb:.3f}\t"
      f"{cal / 1e6:.3f}\t{float(secs):.0f}")
PY
done
python3 - "$rows" <<'PY'
import math, sys
v = [float(l.split("\t")[5]) for l in open(sys.argv[1]) if l.strip()]
ok = [x for x in v if not math.isnan(x)]
m = sum(ok) / len(ok)
sd = (sum((x - m) ** 2 for x in ok) / max(len(ok) - 1, 1)) ** 0.5
inside = sum(1 for x in ok if abs(x - 1) < 0.2)
print(f"breakdown / p_b: mean {m:.3f}, sd {sd:.3f}, range {min(ok):.3f}-{max(ok):.3f}, "
      f"{inside} of {len(v)} within +-20 %")
PY
