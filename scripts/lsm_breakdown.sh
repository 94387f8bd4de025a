#!/usr/bin/env bash
# Breakdown of the borehole rock of scenes/lsm_hydrofrac.toml (978 disks for seed 1, radii
# 0.1-1 m, b = 22 m, a = 3 m) over packings, through `porofrac run`:
#
#   scripts/lsm_breakdown.sh MODES SEED...     e.g. scripts/lsm_breakdown.sh rays,wetted 1 2 3 4 5
#
# MODES (comma separated):
#   rays    dry, pressure wall on the faces seen from the hole centre
#           (scenes/lsm/borehole_dry.toml, 10 MPa/s to 10 MPa)
#   wetted  dry, pressure wall on the faces the fluid wets ([loading] wall = "wetted")
#   fluid   fluid injected into the hole (scenes/lsm_hydrofrac.toml; about 4 min each here)
# The packing of the calibration samples follows the seed as well, so p_b (the closed form
# with the Brazilian-calibrated sigma_t) is per seed. PORFRAC_BIN overrides the binary
# (default: build target/release/porofrac). Runs go to target/lsm_breakdown/MODE-SEED;
# with LSM_BREAKDOWN_REUSE=1 a run whose summary.json is there is tabulated, not redone.
#
# One row per run: mode, seed, particles, sigma_t (MPa), p_b (MPa), hole pressure at the
# first broken bond (MPa) and / p_b, at the tenth (MPa, interpolated in probes.csv) and
# / p_b, distance of the first break from the hole centre (m), run seconds; then per mode
# the mean, standard deviation and range of both ratios.
set -euo pipefail
cd "$(dirname "$0")/.."
modes=$1; shift
bin=${PORFRAC_BIN:-}
if [ -z "$bin" ]; then
  cargo build --release -p porofrac-cli >&2
  bin=target/release/porofrac
fi
fluid_end=${LSM_BREAKDOWN_FLUID_END:-0.45}
root=target/lsm_breakdown
mkdir -p "$root"
rows=$(mktemp)
trap 'rm -f "$rows"' EXIT
printf 'mode\tseed\tparticles\tsigma_t\tp_b\tfirst\tfirst/p_b\tp10\tp10/p_b\tfirst_r\tseconds\n'
for mode in ${modes//,/ }; do
  for seed in "$@"; do
    dir="$root/$mode-$seed"
    reuse=0
    if [ "${LSM_BREAKDOWN_REUSE:-0}" = 1 ] && [ -f "$dir/out/summary.json" ]; then
      reuse=1
    else
      rm -rf "$dir"; mkdir -p "$dir"
    fi
    case $mode in
      rays|wetted)
        sed -e "s/^seed = 1$/seed = $seed/" scenes/lsm/borehole_dry.toml > "$dir/scene.toml"
        if [ "$mode" = wetted ]; then
          sed -i 's/^pressure_rate = 1.0e7$/&\nwall = "wetted"/' "$dir/scene.toml"
        fi
        key=.breakdown_pressure ;;
      fluid)
        sed -e "s/^seed = 1$/seed = $seed/" \
            -e "s/^end_time = 0.25$/end_time = $fluid_end/" \
            -e "s/^steps = 25$/steps = $(printf '%.0f' "$(echo "$fluid_end * 100" | bc)")/" \
            scenes/lsm_hydrofrac.toml > "$dir/scene.toml"
        key=.injection.breakdown_pressure ;;
      *) echo "unknown mode $mode" >&2; exit 2 ;;
    esac
    grep -q "^seed = $seed$" "$dir/scene.toml"
    if [ $reuse = 0 ]; then
      t0=$(date +%s.%N)
      "$bin" run "$dir/scene.toml" --out "$dir/out" > "$dir/log.txt" 2>&1
      t1=$(date +%s.%N)
      echo "$t1 - $t0" | bc > "$dir/seconds"
    fi
    python3 - "$mode" "$seed" "$dir/out" "$(cat "$dir/seconds" 2>/dev/null || echo nan)" "$key" <<'PY' | tee -a "$rows"
import csv, json, math, sys
mode, seed, out, secs, key = sys.argv[1:]
summary = json.load(open(f"{out}/summary.json"))
s = summary
for part in key.strip(".").split("."):
    s = s.get(part) if isinstance(s, dict) else None
first = s or float("nan")
cal = summary["calibration"]
pb = cal["breakdown_estimate"]
probes = list(csv.DictReader(open(f"{out}/probes.csv")))
tp = [(float(r["time"]), float(r["pressure"])) for r in probes]
breaks = list(csv.DictReader(open(f"{out}/broken.csv")))
def pressure_at(t):
    for (t0, p0), (t1, p1) in zip(tp, tp[1:]):
        if t0 <= t <= t1:
            return p0 + (p1 - p0) * (t - t0) / (t1 - t0)
    return float("nan")
p10 = pressure_at(float(breaks[9]["time"])) if len(breaks) >= 10 else float("nan")
r1 = math.hypot(float(breaks[0]["x"]), float(breaks[0]["y"])) if breaks else float("nan")
print("\t".join([mode, seed, str(summary["particles"]), f"{cal['tensile_strength'] / 1e6:.3f}",
                 f"{pb / 1e6:.3f}", f"{first / 1e6:.3f}", f"{first / pb:.3f}", f"{p10 / 1e6:.3f}",
                 f"{p10 / pb:.3f}", f"{r1:.2f}", f"{float(secs):.0f}"]))
PY
  done
done
echo
python3 - "$rows" <<'PY'
import sys
rows = [l.rstrip("\n").split("\t") for l in open(sys.argv[1]) if l.strip()]
for mode in dict.fromkeys(r[0] for r in rows):
    for col, name in ((6, "first break"), (8, "10th break")):
        v = [float(r[col]) for r in rows if r[0] == mode]
        m = sum(v) / len(v)
        sd = (sum((x - m) ** 2 for x in v) / max(len(v) - 1, 1)) ** 0.5
        print(f"{mode}: {name} / p_b mean {m:.3f}, sd {sd:.3f}, range {min(v):.3f}-{max(v):.3f} ({len(v)} seeds)")
PY
