#!/usr/bin/env bash
# The reduced forced fold (scenes/nscd/forced_fold_wedge.toml) with one change at a time,
# for docs/nscd/f1_paper.md, "What moves the gates":
#
#     scripts/nscd_f1_what_moves.sh OUT_ROOT VARIANT [SEED]     # one run, niced
#     POROFRAC=path/to/porofrac scripts/nscd_f1_what_moves.sh ...
#
# writes OUT_ROOT/VARIANT-sSEED (the run) and OUT_ROOT/VARIANT-sSEED.gates (the gates
# printed by scripts/nscd_f1_figures.py, figures into OUT_ROOT/figures), and prints the
# run's elapsed and CPU seconds and peak memory (KB). SEED is [particles] seed (default 1).
# The variants (each a set of --set overrides of the reduced scene):
#
#   flat          the scene as it is
#   base_mu08     the base's own friction μ_b = 0.8 (the disks' μ stays 0.4)
#   base_mu0      a frictionless base, μ_b = 0 (the other bound)
#   slow          the left wall at 0.25 m/s for 200 s (the same 50 m of shortening)
#   slow01        the left wall at 0.1 m/s for 500 s (20 000 steps; the quasi-static check)
#   dt_half       steps of 0.0125 s (8 000 steps)
#   theta1        θ = 1 (backward Euler) instead of ½
#   long          the layer 400 m long (W1-W6 where they were; the right wall at 400 m)
#   low_wall      the left wall only as high as the wedge (16 m)
#   cohesion      γ = 1e3 N/m, d_w = 5 mm between all disks
#   settled       gravity settling to K < 1e-8 ΔE_p (instead of 1e-6)
#   dense         packing fraction 0.79 (the random packing's densest that relaxes)
set -euo pipefail
root=${1:?OUT_ROOT}
variant=${2:?VARIANT}
seed=${3:-1}
bin=${POROFRAC:-porofrac}
scene=scenes/nscd/forced_fold_wedge.toml
speed=0.5
case $variant in
flat) sets=() ;;
base_mu08) sets=(--set wall.1.mu=0.8) ;;
base_mu0) sets=(--set wall.1.mu=0.0) ;;
slow)
    sets=(--set 'wall.2.velocity=[0.25, 0.0]' --set schedule.end_time=200.0)
    speed=0.25
    ;;
slow01)
    sets=(--set 'wall.2.velocity=[0.1, 0.0]' --set schedule.end_time=500.0)
    speed=0.1
    ;;
dt_half) sets=(--set schedule.dt=0.0125) ;;
theta1) sets=(--set nscd.theta=1.0) ;;
long)
    sets=(--set 'particles.polygon=[[0.0, 0.0], [400.0, 0.0], [400.0, 6.0], [60.0, 6.0], [15.0, 16.0], [0.0, 16.0]]'
        --set 'wall.1.to=[410.0, 0.0]' --set 'wall.3.from=[400.0, 48.0]' --set 'wall.3.to=[400.0, 0.0]')
    ;;
low_wall) sets=(--set 'wall.2.to=[0.0, 16.0]') ;;
cohesion) sets=(--set contact.cohesion=1000.0 --set contact.d_w=0.005) ;;
settled) sets=(--set nscd.settle_ratio=1e-8) ;;
dense) sets=(--set particles.packing_fraction=0.79) ;;
*)
    echo "unknown variant $variant" >&2
    exit 2
    ;;
esac
out=$root/$variant-s$seed
mkdir -p "$root/figures"
/usr/bin/time -f "%e s elapsed, %U s user, %M KB" -o "$out.time" \
    nice -n 10 "$bin" run $scene --out "$out" --set particles.seed="$seed" "${sets[@]}" \
    >"$out.log" 2>&1
python3 scripts/nscd_f1_figures.py "$out" --scale 0.2 --speed $speed \
    --figures "$root/figures" --prefix "$variant-s$seed" >"$out.gates"
echo "$variant seed $seed: $(cat "$out.time")"
grep -E "^gate|^\[probes|gate [34]" "$out.gates" | head -6
