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
# The packing of the calibration samples follows the packing seed as well, so p_b (the closed form
# with the Brazilian-calibrated sigma_t) is per seed. PORFRAC_BIN overrides the binary
# (default: build target/release/porofrac). Runs go to target/lsm_breakdown/MODE-SEED;
# with LSM_BREAKDOWN_REUSE=1 a run whose summary.json is there is tabulated, not redone.
#
# One row per run: mode, seed, particles, sigma_t (MPa), p_b (MPa), the initiation pressure
# (first broken bond, MPa) and / p_b, the breakdown pressure (the crack connected to the
# hole wall reaches 2a from the centre, MPa) and / p_b, and / p_b with the size-consistent
# sigma_t = 3.4 MPa, the pressure at which that crack reaches 3a / p_b, its final extent / a,
# the distance of the first break from the centre (m), run seconds, the run directory,
# p_b (Pa), a (m); then per mode the mean, standard deviation and range of the ratios, and
# docs/lsm/crack_extent_MODE.png (the extent against the pressure, every seed).
# LSM_BREAKDOWN_FLUID_END sets the fluid runs' end time (s, default 0.45: the injection
# target reaches 10.8 MPa, about 2.2 p_b); LSM_BREAKDOWN_PLOT=0 skips the PNGs.
# A run that stops with an error is named on stderr and has no row (the series goes on).
# LSM_BREAKDOWN_PORES=1 adds [loading] crack_across_pores = true (the crack traced through the
# pores, the faces of the bond network, it opens); runs then go to target/lsm_breakdown/pores-MODE-SEED.
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
printf 'mode\tseed\tparticles\tsigma_t\tp_b\tinit\tinit/p_b\tbreakdown\tbd/p_b\tbd/p_b34\tp3a/p_b\text_end/a\tfirst_r\tseconds\n'
for mode in ${modes//,/ }; do
  for seed in "$@"; do
    dir="$root/$mode-$seed"
    [ "${LSM_BREAKDOWN_PORES:-0}" = 1 ] && dir="$root/pores-$mode-$seed"
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
        ;;
      fluid)
        sed -e "s/^seed = 1$/seed = $seed/" \
            -e "s/^end_time = 0.25$/end_time = $fluid_end/" \
            -e "s/^steps = 25$/steps = $(printf '%.0f' "$(echo "$fluid_end * 100" | bc)")/" \
            scenes/lsm_hydrofrac.toml > "$dir/scene.toml" ;;
      *) echo "unknown mode $mode" >&2; exit 2 ;;
    esac
    if [ "${LSM_BREAKDOWN_PORES:-0}" = 1 ]; then
      sed -i 's/^\[loading\]$/&\ncrack_across_pores = true/' "$dir/scene.toml"
      grep -q "^crack_across_pores = true$" "$dir/scene.toml"
    fi
    grep -q "^seed = $seed$" "$dir/scene.toml"
    if [ $reuse = 0 ]; then
      t0=$(date +%s.%N)
      # a run that stops with an error (e.g. the lattice's Mach limit long after breakdown)
      # is reported and skipped, not the end of the series
      "$bin" run "$dir/scene.toml" --out "$dir/out" > "$dir/log.txt" 2>&1 ||
        echo "$mode $seed: $(tail -n 1 "$dir/log.txt") (no row)" >&2
      t1=$(date +%s.%N)
      echo "$t1 - $t0" | bc > "$dir/seconds"
    fi
    python3 - "$mode" "$seed" "$dir/out" "$(cat "$dir/seconds" 2>/dev/null || echo nan)" <<'PY' | tee -a "$rows"
import csv, json, math, sys
mode, seed, out, secs = sys.argv[1:]
s = json.load(open(f"{out}/summary.json"))
if "calibration" not in s:
    sys.exit(0)  # a failed run: its summary has its status only
nan = float("nan")
init = s.get("initiation_pressure") or nan
bd = s.get("breakdown_pressure") or nan
two_a = s["breakdown_extent"]
a = two_a / 2
cal = s["calibration"]
pb = cal["breakdown_estimate"]
# the same closed form with the size-consistent sigma_t = 3.4 MPa of the Brazilian size study
pb34 = pb * 3.4e6 / cal["tensile_strength"]
def rows(path):
    # the CSV headers carry units ("pressure [Pa]"): key the columns by their names
    return [{k.split(" [")[0]: v for k, v in r.items()} for r in csv.DictReader(open(path))]
crack = [(float(r["pressure"]), float(r["extent"])) for r in rows(f"{out}/crack.csv")]
p3a = next((p for p, e in crack if e >= 3 * a), nan)
breaks = rows(f"{out}/broken.csv")
r1 = math.hypot(float(breaks[0]["x"]), float(breaks[0]["y"])) if breaks else nan
print("\t".join([mode, seed, str(s["particles"]), f"{cal['tensile_strength'] / 1e6:.3f}",
                 f"{pb / 1e6:.3f}", f"{init / 1e6:.3f}", f"{init / pb:.3f}", f"{bd / 1e6:.3f}",
                 f"{bd / pb:.3f}", f"{bd / pb34:.3f}", f"{p3a / pb:.3f}",
                 f"{s['crack_extent'] / a:.2f}", f"{r1:.2f}", f"{float(secs):.0f}",
                 f"{out}", f"{pb}", f"{a}"]))
PY
  done
done
echo
python3 - "$rows" <<'PY'
import math, sys
rows = [l.rstrip("\n").split("\t") for l in open(sys.argv[1]) if l.strip()]
for mode in dict.fromkeys(r[0] for r in rows):
    for col, name in ((6, "initiation / p_b"), (8, "breakdown (wall crack at 2a) / p_b"),
                      (9, "breakdown / p_b(sigma_t 3.4 MPa)"), (10, "wall crack at 3a / p_b")):
        all_ = [float(r[col]) for r in rows if r[0] == mode]
        v = [x for x in all_ if not math.isnan(x)]
        if not v:
            print(f"{mode}: {name}: not reached ({len(all_)} seeds)")
            continue
        m = sum(v) / len(v)
        sd = (sum((x - m) ** 2 for x in v) / max(len(v) - 1, 1)) ** 0.5
        miss = f", not reached in {len(all_) - len(v)}" if len(v) < len(all_) else ""
        print(f"{mode}: {name} mean {m:.3f}, sd {sd:.3f}, range {min(v):.3f}-{max(v):.3f} "
              f"({len(v)} seeds{miss})")
PY
# Extent of the wall crack against the hole pressure, one PNG per mode (docs/lsm/).
if [ "${LSM_BREAKDOWN_PLOT:-1}" = 1 ]; then
  cargo build --release -p porofrac-lsm --example crack_extent_plot >&2
  mkdir -p docs/lsm
  for mode in ${modes//,/ }; do
    args=()
    while IFS=$'\t' read -r m seed _ _ _ _ _ _ _ _ _ _ _ _ out pb a; do
      [ "$m" = "$mode" ] && args+=("seed $seed:$out:$pb") && hole=$a
    done < "$rows"
    target/release/examples/crack_extent_plot "docs/lsm/crack_extent_$mode.png" \
      "wall crack against hole pressure: $mode, ${#args[@]} packings" "$hole" "${args[@]}"
  done
fi
