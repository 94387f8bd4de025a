#!/usr/bin/env python3
"""The table of docs/nscd/f1_paper.md, "What moves the gates", from the runs of
scripts/nscd_f1_what_moves.sh:

    python3 scripts/nscd_f1_what_moves_table.py OUT_ROOT [RUN ...]

For every run OUT_ROOT/RUN (default: every OUT_ROOT/*.gates) one markdown row: the time
reached, the four gates with their numbers as printed by scripts/nscd_f1_figures.py
(gates 3 and 4 by the probes, every step, and how many of the four frame readings of
eq. 7 hold them), W6's p at the start and its largest, the time W6 is loaded (the first
time the 2 s running mean of its p leaves 10 % of its start), and the base's grip
(tangential over normal force of the base contacts of the disks with centres in
x = 50-120 m at the last frame: scripts/nscd_f1_base_grip.py). A run not yet at its end
is read as far as it went (gates 2-4 "pending" unless gate 4 already fails: once W6's
smallest p is below 0.8 of its largest, no later value brings every p within 10 % of a
mean).
"""
import csv
import glob
import os
import re
import subprocess
import sys

import numpy as np


def probes(out):
    with open(os.path.join(out, "probes.csv")) as f:
        rows = list(csv.reader(f))
    head = [h.split(" [")[0] for h in rows[0]]
    data = np.array([[float(v) for v in row] for row in rows[1:] if row], dtype=float)
    return {h: data[:, k] for k, h in enumerate(head)}


def row(root, run):
    out = os.path.join(root, run)
    text = open(out + ".gates").read() if os.path.exists(out + ".gates") else ""
    c = probes(out)
    t = c["time"]
    p6 = c["p_W6"]
    window = max(1, int(round(2.0 / (t[1] - t[0]))))
    mean = np.convolve(p6, np.ones(window) / window, mode="valid")
    off = np.nonzero(np.abs(mean - mean[0]) > 0.1 * mean[0])[0]
    loaded = f"{t[off[0] + window - 1]:.1f} s" if len(off) else "not yet"
    g1 = re.search(r"gate 1.*max \|residual\| ([0-9.]+) m = ([0-9.]+) diameters.*: (\w+)", text)
    g2 = re.search(r"gate 2.*: ([0-9.]+) at t", text)
    g3 = re.findall(r"gate 3[^:]*: W1 ([0-9.]+) kPa[^W]*W3 ([0-9.]+) kPa[^W]*W4 ([0-9.]+) kPa"
                    r"[^:]*: (holds|does not hold)", text)
    g4 = re.findall(r"gate 4[^:]*:.*largest deviation ([0-9.]+) % of the mean.*: "
                    r"(holds|does not hold)", text)
    end = bool(g2)
    lx2 = float(g2.group(1)) if g2 else float(c["dilation_x_W2"][-1])
    gate1 = f"{'yes' if g1 and g1.group(3) == 'holds' else 'no'} ({g1.group(2)} d)" if g1 \
        else "pending"
    gate2 = f"{'yes' if 1.6 <= lx2 <= 2.4 else 'no'} ({lx2:.2f})" if end \
        else f"pending ({lx2:.2f} at {t[-1]:.0f} s)"
    if g3:
        w1, w3, w4, v = g3[0]
        frames = sum(1 for r in g3[1:] if r[3] == "holds")
        gate3 = f"{'yes' if v == 'holds' else 'no'} ({w1}/{w3}/{w4}; frames {frames}/4)"
    else:
        gate3 = "pending"
    if g4:
        frames = sum(1 for r in g4[1:] if r[1] == "holds")
        gate4 = f"{'yes' if g4[0][1] == 'holds' else 'no'} ({g4[0][0]} %; frames {frames}/4)"
    elif p6.min() < 0.8 * p6.max():
        gate4 = f"no (min/max {p6.min() / p6.max():.2f} by {t[-1]:.0f} s)"
    else:
        gate4 = "pending"
    grip = subprocess.run([sys.executable, os.path.join(os.path.dirname(__file__),
                                                         "nscd_f1_base_grip.py"),
                           out, "--every", "100000", "--zone", "50", "120"],
                          capture_output=True, text=True).stdout.strip().splitlines()
    tn = grip[-1].split()[1] if len(grip) > 1 else "-"
    return (f"| {run} | {t[-1]:.0f} s | {gate1} | {gate2} | {gate3} | {gate4} | "
            f"{p6[0] / 1e3:.1f} / {p6.max() / 1e3:.1f} | {loaded} | {tn} |")


def main():
    if len(sys.argv) < 2:
        raise SystemExit(__doc__)
    root = sys.argv[1]
    runs = sys.argv[2:] or sorted(os.path.basename(g)[:-6]
                                  for g in glob.glob(os.path.join(root, "*.gates")))
    print("| run | reached | gate 1 (largest residual) | gate 2 (W2 λx) | gate 3 (W1/W3/W4 "
          "peak p, kPa) | gate 4 (W6 off its mean) | W6 p start / largest (kPa) | W6 loaded "
          "| base T/N, x = 50-120 m |")
    print("|---|---|---|---|---|---|---|---|---|")
    for run in runs:
        print(row(root, run))


if __name__ == "__main__":
    sys.exit(main())
