#!/usr/bin/env bash
# Cost of the lattice solid model against the particle count, through `porofrac run`:
# a bonded square sample of N disks (hexagonal: radius 0.5 m; random: radii 0.25-0.5 m
# at packing fraction 0.8), E = 10 GPa, no loading, run for about 5e7 bond updates.
#
#   scripts/lsm_scaling.sh KIND N...      (KIND: hexagonal | random)
#
# One line per N: kind, particles, bonds, LSM steps, setup s (packing + bonds), step s,
# output s, M bond updates/s, peak memory MB, load average.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -p porofrac-cli >&2
kind=$1; shift
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for n in "$@"; do
  if [ "$kind" = hexagonal ]; then
    side=$(python3 -c "import math; print(round(math.sqrt($n/1.15),3))"); radius=0.5; phi=""
  else
    side=$(python3 -c "import math; print(round(math.sqrt($n*math.pi*0.1458/0.8),3))")
    radius="[0.25, 0.5]"; phi="packing_fraction = 0.8"
  fi
  end=$(python3 -c "print(5e7/(2.9*$n)*1.143e-4)")
  cat > "$out/s.toml" <<T
[scene]
name = "lsm_scaling"
dim = 2
model = "lsm"
[particles]
kind = "$kind"
region = [[0.0, 0.0], [$side, $side]]
radius = $radius
$phi
seed = 1
density = 2600.0
[bonds]
youngs_modulus = 10.0e9
poisson_ratio = 0.2
tensile_strength = 5.0e6
cohesion = 10.0e6
friction_angle = 30.0
tolerance = 0.05
[contacts]
friction = 0.6
[lsm]
damping = "local"
damping_coefficient = 0.7
[schedule]
end_time = $end
steps = 1
[output]
every = 1
T
  target/release/porofrac run "$out/s.toml" --out "$out/o" >/dev/null
  python3 -c "
import json; s=json.load(open('$out/o/summary.json')); w=s['wall_seconds']
print('$kind', s['particles'], s['bonds'], s['lsm_steps'], round(w['grid'],2), round(s['step_seconds'],2), round(w['output'],2), '%.2f'%(s['bond_updates_per_second']/1e6), s['peak_memory_bytes']//2**20, open('/proc/loadavg').read().split()[0])"
done
