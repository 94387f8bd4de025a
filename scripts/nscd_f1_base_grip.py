#!/usr/bin/env python3
"""How the base and the right wall hold a forced-fold run (scenes/nscd/forced_fold_*.toml):
from the contact frames of OUT_DIR, at every K-th frame and the last,

    python3 scripts/nscd_f1_base_grip.py OUT_DIR [--mu MU] [--right X] [--every K]
                                         [--zone X0 X1]

* the base's grip: over the disks touching the base (contact points at y < 1e-6 m, the
  base line y = 0) with centres in [X0, X1] (default: the whole base), the sum of the
  tangential over the sum of the normal forces, and the fraction of those contacts at the
  Coulomb limit |f_t| >= (1 - 1e-6) MU f_n (MU the base's coefficient, default 0.4);
* the right wall's load: the sum of the normal forces of the contacts whose point lies
  on x = X (default the largest contact-point x of the first frame), N per metre.

A base that holds the layer carries tangential forces up to MU times the normal ones;
disks that roll on it carry less. The frames are those listed in the run's .pvd file
(written by `porofrac run`); nothing is written.
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import numpy as np  # noqa: E402

from nscd_f1_figures import contacts, frames  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out")
    ap.add_argument("--mu", type=float, default=0.4)
    ap.add_argument("--right", type=float, default=None)
    ap.add_argument("--every", type=int, default=10)
    ap.add_argument("--zone", type=float, nargs=2, default=None)
    a = ap.parse_args()
    rows = [r for r in frames(a.out) if r[2] is not None]
    if not rows:
        raise SystemExit(f"{a.out}: no contact frames")
    right = a.right
    print("t (s)  base T/N  at limit  base contacts  right wall (MN/m)")
    for k, (t, _, c) in enumerate(rows):
        if k % a.every and k != len(rows) - 1:
            continue
        ends_a, centres, fn, ft = contacts(c)
        if right is None:
            right = float(np.max(ends_a[:, 0]))
        on_base = ends_a[:, 1] < 1e-6
        if a.zone is not None:
            on_base &= (centres[:, 0] >= a.zone[0]) & (centres[:, 0] <= a.zone[1])
        on_right = np.abs(ends_a[:, 0] - right) < 1e-6
        n, tt = fn[on_base], ft[on_base]
        loaded = n > 0.0
        ratio = abs(float(np.sum(tt))) / max(float(np.sum(n)), 1e-300)
        limit = float(np.mean(np.abs(tt[loaded]) >= (1.0 - 1e-6) * a.mu * n[loaded])) \
            if np.any(loaded) else 0.0
        print(f"{t:6.1f}  {ratio:8.3f}  {limit:8.3f}  {int(np.sum(loaded)):13d}  "
              f"{float(np.sum(fn[on_right])) / 1e6:17.4f}")


if __name__ == "__main__":
    sys.exit(main())
