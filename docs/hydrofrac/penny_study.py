#!/usr/bin/env python3
"""The penny-shaped hydraulic fracture, toughness-dominated: scenes/penny_toughness.toml at
two resolutions against the toughness vertex solution (Savitski & Detournay 2002), and
the plot docs/hydrofrac/penny_toughness.png.

Run from the repository root after `cargo build --release -p porofrac-cli`:
    python3 docs/hydrofrac/penny_study.py            # h = 0.5 m and 1/3 m
    python3 docs/hydrofrac/penny_study.py --plot-only DIR_COARSE DIR_FINE

Vertex solution (impermeable rock, uniform net pressure, Sneddon's opening):
    R(t) = (3/(pi sqrt 2))^(2/5) (E' Q0 t / K')^(2/5) = 0.8546 (E' Q0 t / K')^(2/5)
    p    = sqrt(pi) K_Ic / (2 sqrt R)      (K_I = 2 p sqrt(R/pi) = K_Ic)
    w(0) = 8 p R / (pi E')
with E' = E/(1 - nu^2), K' = 4 sqrt(2/pi) K_Ic, Q0 the rate into the whole penny.
"""

import math
import os
import subprocess
import sys

E, NU, K_IC, Q0 = 1.0e10, 0.25, 1.0e6, 1.0e-4
EP = E / (1 - NU * NU)
KP = 4 * math.sqrt(2 / math.pi) * K_IC
C_R = (3 / (math.pi * math.sqrt(2))) ** 0.4
T0 = 20.0  # compare from here on (after the initial transient)


def vertex(t):
    r = C_R * (EP * Q0 * t / KP) ** 0.4
    p = math.sqrt(math.pi) * K_IC / (2 * math.sqrt(r))
    return r, p, 8 * p * r / (math.pi * EP)


def rows(path):
    with open(path) as f:
        head = f.readline().strip().split(",")
        out = []
        for line in f:
            if line.strip():
                out.append([float(x) for x in line.strip().split(",")[: len(head)] if _num(x)])
        return head, out


def _num(x):
    try:
        float(x)
        return True
    except ValueError:
        return False


def measure(out, h):
    """Times, equivalent radius, inlet net pressure, inlet opening of a run in `out`."""
    head, probes = rows(os.path.join(out, "probes.csv"))
    fhead, frac = rows(os.path.join(out, "fracture.csv"))
    col = next(i for i, n in enumerate(fhead) if n.startswith("time"))
    times = [r[col] for r in frac]
    series = []
    for v in probes:
        t = v[0]
        n = sum(1 for tf in times if tf <= t + 1e-9)
        # n Kuhn tetrahedra of h^3/6 in a band h thick: a quarter of the area n h^2/6
        r = math.sqrt(4 * n * h * h / 6 / math.pi)
        series.append((t, r, v[1], v[2] - v[3]))
    return series


def errors(series):
    out = {"r": [], "p": [], "w": []}
    logs = []
    for t, r, p, w in series:
        if t < T0 - 1e-9:
            continue
        rv, pv, wv = vertex(t)
        out["r"].append(r / rv - 1)
        out["p"].append(p / pv - 1)
        out["w"].append(w / wv - 1)
        logs.append((math.log(t), math.log(r)))
    m = len(logs)
    mx = sum(a for a, _ in logs) / m
    my = sum(b for _, b in logs) / m
    ex = sum((a - mx) * (b - my) for a, b in logs) / sum((a - mx) ** 2 for a, _ in logs)
    stats = {
        k: (sum(v) / len(v), sum(abs(x) for x in v) / len(v), max(v, key=abs))
        for k, v in out.items()
    }
    return stats, ex


def run(h, fine, tag):
    mesh = "/tmp/penny_%s.vtu" % tag
    subprocess.run([sys.executable, "scenes/penny_mesh.py", str(h), str(fine), mesh], check=True)
    text = open("scenes/penny_toughness.toml").read()
    text = text.replace('path = "penny_toughness.vtu"', 'path = "%s"' % mesh)
    # the band, the mouth (2 x 2 boxes) and the probes at the resolution h (the scene: 0.5)
    b = 0.5 * h - 1e-4
    for old, new in [
        ("[[0.0, 0.0, -0.25], [4.5, 4.5, 0.25]]", "[[0.0, 0.0, -%r], [%r, %r, %r]]" % (b, fine * h + 0.01, fine * h + 0.01, b)),
        ("[[0.0, 0.0, -0.25], [1.0, 1.0, 0.25]]", "[[0.0, 0.0, -%r], [%r, %r, %r]]" % (b, 2 * h - 1e-4, 2 * h - 1e-4, b)),
        ("at = [0.2, 0.3, 0.05]", "at = [%r, %r, %r]" % (0.4 * h, 0.6 * h, 0.1 * h)),
        ("at = [0.0, 0.0, 0.25]", "at = [0.0, 0.0, %r]" % (0.5 * h)),
        ("at = [0.0, 0.0, -0.25]", "at = [0.0, 0.0, %r]" % (-0.5 * h)),
    ]:
        assert old in text, old
        text = text.replace(old, new)
    scene = "/tmp/penny_%s.toml" % tag
    open(scene, "w").write(text)
    out = "/tmp/penny_%s_out" % tag
    subprocess.run(["target/release/porofrac", "run", scene, "--out", out], check=True)
    return out


def plot(runs):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 3, figsize=(14, 4.2))
    ts = [0.5 * k for k in range(1, 201)]
    ax[0].plot(ts, [vertex(t)[0] for t in ts], "k-", label="vertex solution")
    ax[1].plot(ts, [vertex(t)[1] / 1e6 for t in ts], "k-", label="vertex solution")
    ax[2].plot(ts, [vertex(t)[2] * 1e3 for t in ts], "k-", label="vertex solution")
    for (label, series), style in zip(runs, ["o", "s"]):
        t = [s[0] for s in series[1:]]
        ax[0].plot(t, [s[1] for s in series[1:]], style, ms=3, label=label)
        ax[1].plot(t, [s[2] / 1e6 for s in series[1:]], style, ms=3, label=label)
        ax[2].plot(t, [s[3] * 1e3 for s in series[1:]], style, ms=3, label=label)
    ax[0].set_ylabel("equivalent radius √(A/π) (m)")
    ax[1].set_ylabel("inlet net pressure (MPa)")
    ax[2].set_ylabel("inlet opening (mm)")
    ax[1].set_ylim(0, 2.0)
    for a in ax:
        a.set_xlabel("time (s)")
        a.grid(alpha=0.3)
        a.legend(fontsize=8)
    fig.suptitle(
        "Penny-shaped hydraulic fracture, toughness-dominated: "
        "E = 10 GPa, ν = 0.25, K_Ic = 1 MPa·√m, Q₀ = 1e-4 m³/s"
    )
    fig.tight_layout()
    fig.savefig("docs/hydrofrac/penny_toughness.png", dpi=110)


def main():
    if len(sys.argv) > 1 and sys.argv[1] == "--plot-only":
        outs = [(0.5, sys.argv[2]), (1 / 3, sys.argv[3])]
    else:
        outs = [(0.5, run(0.5, 9, "coarse")), (1 / 3, run(1 / 3, 14, "fine"))]
    runs = []
    for h, out in outs:
        series = measure(out, h)
        stats, ex = errors(series)
        t_end, r_end = series[-1][0], series[-1][1]
        print(
            "h = %.3g m (%.1f cells per radius at %g s): exponent %.4f" % (h, r_end / h, t_end, ex)
        )
        for k, (mean, mabs, worst) in stats.items():
            print("  %s: mean %+.2f %%, mean |.| %.2f %%, largest %+.2f %%" % (
                k, 100 * mean, 100 * mabs, 100 * worst))
        runs.append(("h = %.3g m" % h, series))
    plot(runs)


main()
