#!/usr/bin/env bash
# CPU cost per contact update of the sorted and the slab sweeps through the command:
# ROUNDS interleaved rounds of `porofrac run SCENE` with each ordering, every run timed by
# /usr/bin/time (user + system CPU seconds of the whole process, all threads, and wall
# seconds) and divided by summary.json `contact_updates`.
#
#   scripts/nscd_ordering_rounds.sh [SCENE] [ROUNDS] [--set KEY=VALUE ...]
#
# Default: scenes/nscd/fault.toml (the reduced F2: 968 disks, 300 steps), 5 rounds, no VTK
# and no plots; BIN=path runs another binary. One line per run: round, ordering, CPU s, wall s, contact updates, CPU s
# per million updates, sweeps per step (mean); then the median per ordering. The whole
# process is timed, so packing, settling and detection are in the CPU time too.
set -euo pipefail
cd "$(dirname "$0")/.."
scene=${1:-scenes/nscd/fault.toml}
rounds=${2:-5}
shift $(( $# > 2 ? 2 : $# ))
bin=${BIN:-target/release/porofrac}
out=$(mktemp -d)
echo "# $(date -u +%FT%TZ) $(nproc) cores, load: $(cut -d' ' -f1-3 /proc/loadavg), $scene"
for r in $(seq 1 "$rounds"); do
    for o in sorted slabs; do
        /usr/bin/time -f "%U %S %e" -o "$out/time" "$bin" run "$scene" --out "$out/$o" \
            --set "nscd.ordering=\"$o\"" --set output.vtk=false --set output.plots=false "$@" \
            > /dev/null 2>&1
        read -r user sys wall < "$out/time"
        python3 -c "
import json
s = json.load(open('$out/$o/summary.json'))
u = s['contact_updates']
cpu = $user + $sys
print($r, '$o', round(cpu, 2), $wall, u, round(cpu / (u / 1e6), 5), round(s['sweeps']['mean'], 1))"
    done
done | tee "$out/rows"
python3 -c "
import statistics
rows = [l.split() for l in open('$out/rows')]
for o in ('sorted', 'slabs'):
    c = [float(r[5]) for r in rows if r[1] == o]
    print('median', o, 'CPU s per million updates', statistics.median(c), 'over', len(c), 'runs')"
echo "# load at the end: $(cut -d' ' -f1-3 /proc/loadavg)"
