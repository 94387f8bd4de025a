#!/usr/bin/env python3
"""Compare porofrac's probes.csv of scenes/mandel.toml with the RESULT line of
mandel_scipy.py, and both with Mandel's closed-form solution.

    python compare.py OUT/probes.csv RESULT.txt

RESULT.txt holds the output of mandel_scipy.py (the line starting with `RESULT `).
Prints, per output time, the largest pressure error of each against the closed form
(relative to the undrained pressure p0), the settlement error, and the largest
difference between the two programs; then a `COMPARE {json}` line with the maxima.

Closed form (Abousleiman et al. 1996), quarter domain [0, a] x [0, b], force F on the
platen of the quarter:
    p(x, t) = 2 p0 sum_n sin b_n / (b_n - sin b_n cos b_n) (cos(b_n x/a) - cos b_n) exp(-b_n^2 c t/a^2)
    u_y(b, t) = b [-F (1 - nu)/(2 G a) + F (1 - nu_u)/(G a) sum_n sin b_n cos b_n / (b_n - sin b_n cos b_n) exp(-b_n^2 c t/a^2)]
with tan b_n = (1 - nu)/(nu_u - nu) b_n, p0 = F B (1 + nu_u)/(3 a) and
c = 2 kappa B^2 G (1 - nu)(1 + nu_u)^2 / (9 (1 - nu_u)(nu_u - nu)).
"""

import csv
import json
import sys

import numpy as np

E, NU, PHI, CF, PERM, VISC, FORCE, A, B = 1e9, 0.25, 0.3, 1e-9, 1e-12, 1e-3, 1e6, 1.0, 1.0
G = E / (2 * (1 + NU))
K = E * NU / ((1 + NU) * (1 - 2 * NU)) + 2 * G / 3
M = 1 / (PHI * CF)
KU = K + M
SKEMPTON = M / KU
NU_U = (3 * KU - 2 * G) / (2 * (3 * KU + G))
C = 2 * PERM / VISC * SKEMPTON**2 * G * (1 - NU) * (1 + NU_U) ** 2 / (9 * (1 - NU_U) * (NU_U - NU))
P0 = FORCE * SKEMPTON * (1 + NU_U) / (3 * A)


def roots(n):
    coef = (1 - NU) / (NU_U - NU)
    lo = np.array([1e-9] + [(k - 1) * np.pi for k in range(2, n + 1)])
    hi = np.array([(k - 0.5) * np.pi for k in range(1, n + 1)])
    f = lambda x: np.sin(x) - coef * x * np.cos(x)
    flo = np.sign(f(lo))
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        same = np.sign(f(mid)) == flo
        lo, hi = np.where(same, mid, lo), np.where(same, hi, mid)
    return 0.5 * (lo + hi)


BETA = roots(400)
SN, CN = np.sin(BETA), np.cos(BETA)


def pressure(x, t):
    w = SN / (BETA - SN * CN) * np.exp(-BETA**2 * C * t / A**2)
    return 2 * P0 * float(np.sum(w * (np.cos(BETA * x / A) - CN)))


def settlement(t):
    w = SN * CN / (BETA - SN * CN) * np.exp(-BETA**2 * C * t / A**2)
    return B * (-FORCE * (1 - NU) / (2 * G * A) + FORCE * (1 - NU_U) / (G * A) * float(np.sum(w)))


def main():
    rows = list(csv.reader(open(sys.argv[1])))
    header, rows = rows[0], rows[1:]
    result = None
    for line in open(sys.argv[2]):
        if line.startswith("RESULT "):
            result = json.loads(line[len("RESULT "):])
    if result is None:
        sys.exit("no RESULT line in " + sys.argv[2])
    names = result["probe_names"]
    xs = result["probe_x"]
    col = [header.index(n) for n in names]
    worst = {"porofrac_p": 0.0, "peer_p": 0.0, "porofrac_uy": 0.0, "peer_uy": 0.0, "diff": 0.0}
    print("time  max|p-exact|/p0: porofrac  peer   settlement rel. err: porofrac  peer"
          "   max|porofrac-peer|/max|value|")
    for r in rows:
        key = f"{float(r[0]):.2f}"
        if key not in result["probes"]:
            continue
        t = float(r[0])
        ours = [float(r[c]) for c in col]
        peer = result["probes"][key]
        exact = [pressure(x, t) for x in xs]
        e_ours = max(abs(a - b) for a, b in zip(ours[:-1], exact)) / P0
        e_peer = max(abs(a - b) for a, b in zip(peer[:-1], exact)) / P0
        u = settlement(t)
        u_ours, u_peer = abs(ours[-1] - u) / abs(u), abs(peer[-1] - u) / abs(u)
        scale = max(abs(v) for v in ours[:-1])
        diff = max(max(abs(a - b) for a, b in zip(ours[:-1], peer[:-1])) / scale,
                   abs(ours[-1] - peer[-1]) / abs(ours[-1]))
        for k, v in [("porofrac_p", e_ours), ("peer_p", e_peer), ("porofrac_uy", u_ours),
                     ("peer_uy", u_peer), ("diff", diff)]:
            worst[k] = max(worst[k], v)
        print(f"{t:4.2f}  {e_ours:.4%}  {e_peer:.4%}   {u_ours:.4%}  {u_peer:.4%}   {diff:.1e}")
    print("COMPARE " + json.dumps(worst))


if __name__ == "__main__":
    main()
