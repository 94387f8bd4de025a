#!/usr/bin/env bash
# Borehole breakdown against the resolution of the hole (dry runs, through `porofrac run`):
# the rock of scenes/lsm/borehole_dry.toml (b = 22 m, a = 3 m, radii 0.1-1 m, a/r_max = 3)
# with every radius divided by SCALE, so that a/r_max = 3 SCALE at the same b/a, and
# optionally a narrower radius range (RMIN_FRACTION = r_min/r_max, default 0.1).
#
#   scripts/lsm_resolution.sh MODES SCALE RMIN_FRACTION SEED...
#   e.g. scripts/lsm_resolution.sh rays,wetted 2 0.1 1 2 3 4 5
#
# MODES (comma separated): rays, wetted (the dry walls of scripts/lsm_breakdown.sh),
# flooded (rays, and the hole pressure in the crack connected to the wall: [loading]
# flood_cracks = true), wetted-flooded (both).
#
# The calibration samples (the Brazilian disk of radius 10 r_max and the uniaxial box of
# 20 r_max) use the same radii, so sigma_t is measured on the same packing statistics.
# Everything scales with the radii except time: the ramp (10 MPa/s) against the wave
# transit of the rock (b/c) is the same at every SCALE. LSM_RESOLUTION_RATE (Pa/s, default
# 1.0e7; the end time follows to reach 10 MPa) and LSM_RESOLUTION_ALPHA (local damping,
# default 0.7) test the loading. Runs go to
# target/lsm_resolution/MODE-sSCALE-fRMIN_FRACTION-SEED; LSM_RESOLUTION_REUSE=1 tabulates
# finished runs. One row per run: mode, scale, a/r_max, r_min/r_max, seed, particles,
# sigma_t (MPa), p_b (MPa), initiation / p_b, breakdown (wall crack at 2a) / p_b, wall
# crack at 3a / p_b, final extent / a, broken bonds, seconds; then mean, sd and range.
set -euo pipefail
cd "$(dirname "$0")/.."
modes=$1; scale=$2; frac=$3; shift 3
bin=${PORFRAC_BIN:-target/release/porofrac}
rate=${LSM_RESOLUTION_RATE:-1.0e7}
alpha=${LSM_RESOLUTION_ALPHA:-0.7}
end=${LSM_RESOLUTION_END:-$(python3 -c "print(1.0e7 / $rate)")}
tag=""
[ "$rate" != 1.0e7 ] && tag="$tag-rate$rate"
[ "$alpha" != 0.7 ] && tag="$tag-alpha$alpha"
root=target/lsm_resolution
mkdir -p "$root"
rows=$(mktemp)
trap 'rm -f "$rows"' EXIT
rmax=$(python3 -c "print(1.0 / $scale)")
rmin=$(python3 -c "print($frac / $scale)")
printf 'mode\tscale\ta/rmax\trmin/rmax\tseed\tparticles\tsigma_t\tp_b\tinit/p_b\tbd/p_b\tp3a/p_b\text/a\tbroken\tseconds\n'
for mode in ${modes//,/ }; do
  for seed in "$@"; do
    dir="$root/$mode-s$scale-f$frac$tag-$seed"
    reuse=0
    if [ "${LSM_RESOLUTION_REUSE:-0}" = 1 ] && [ -f "$dir/out/summary.json" ]; then
      reuse=1
    else
      rm -rf "$dir"; mkdir -p "$dir"
    fi
    sed -e "s/^seed = 1$/seed = $seed/" \
        -e "s/^radius = \[0.1, 1.0\]$/radius = [$rmin, $rmax]/" \
        -e "s/^end_time = 1.0$/end_time = $end/" \
        -e "s/^pressure_rate = 1.0e7$/pressure_rate = $rate/" \
        -e "s/^damping_coefficient = 0.7$/damping_coefficient = $alpha/" \
        scenes/lsm/borehole_dry.toml > "$dir/scene.toml"
    grep -q "^pressure_rate = $rate$" "$dir/scene.toml"
    case $mode in
      rays) ;;
      wetted) sed -i 's/^pressure_rate = .*$/&\nwall = "wetted"/' "$dir/scene.toml" ;;
      flooded) sed -i 's/^pressure_rate = .*$/&\nflood_cracks = true/' "$dir/scene.toml" ;;
      wetted-flooded)
        sed -i 's/^pressure_rate = .*$/&\nwall = "wetted"\nflood_cracks = true/' "$dir/scene.toml" ;;
      *) echo "unknown mode $mode" >&2; exit 2 ;;
    esac
    grep -q "^radius = \[$rmin, $rmax\]$" "$dir/scene.toml"
    if [ $reuse = 0 ]; then
      t0=$(date +%s.%N)
      nice -n 5 "$bin" run "$dir/scene.toml" --out "$dir/out" > "$dir/log.txt" 2>&1
      t1=$(date +%s.%N)
      echo "$t1 - $t0" | bc > "$dir/seconds"
    fi
    python3 - "$mode" "$scale" "$frac" "$seed" "$dir/out" "$(cat "$dir/seconds")" <<'PY' | tee -a "$rows"
import csv, json, sys
mode, scale, frac, seed, out, secs = sys.argv[1:]
s = json.load(open(f"{out}/summary.json"))
nan = float("nan")
a = s["breakdown_extent"] / 2
cal = s["calibration"]
pb = cal["breakdown_estimate"]
def rows(path):
    # the CSV headers carry units ("pressure [Pa]"): key the columns by their names
    return [{k.split(" [")[0]: v for k, v in r.items()} for r in csv.DictReader(open(path))]
crack = [(float(r["pressure"]), float(r["extent"])) for r in rows(f"{out}/crack.csv")]
p3a = next((p for p, e in crack if e >= 3 * a), nan)
init = s.get("initiation_pressure") or nan
bd = s.get("breakdown_pressure") or nan
print("\t".join([mode, scale, f"{3 * float(scale):g}", frac, seed, str(s["particles"]),
                 f"{cal['tensile_strength'] / 1e6:.3f}", f"{pb / 1e6:.3f}", f"{init / pb:.3f}",
                 f"{bd / pb:.3f}", f"{p3a / pb:.3f}", f"{s['crack_extent'] / a:.2f}",
                 str(s["broken_bonds"]), f"{float(secs):.0f}"]))
PY
  done
done
python3 - "$rows" <<'PY'
import math, sys
rows = [l.rstrip("\n").split("\t") for l in open(sys.argv[1]) if l.strip()]
for mode in dict.fromkeys(r[0] for r in rows):
    for col, name in ((6, "sigma_t (MPa)"), (8, "initiation / p_b"), (9, "breakdown (2a) / p_b"),
                      (10, "wall crack at 3a / p_b")):
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
