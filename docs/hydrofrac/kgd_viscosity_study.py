"""KGD viscosity-dominated: scenes/kgd_viscosity.toml at three resolutions against the
viscosity vertex solution (Detournay 2004; Adachi & Detournay 2002), and the plot
docs/hydrofrac/kgd_viscosity.png.

    python3 docs/hydrofrac/kgd_viscosity_study.py [path/to/porofrac]   (from the repository root)

For refine = 8, 16, 32 (cells of h = 2/refine m along the path) it writes the scene with
the path row and the mouth moved to the row 50 < y < 50 + h, runs it, and prints, over
t >= 8 s (after the initial transient), the mean, mean absolute and largest relative
error of the half-length l and the inlet opening w against
l = 0.6152 (E' Q0^3 t^4 / mu')^(1/6), w(0, t) = 1.1265 (mu' Q0^3 t^2 / E')^(1/6),
mu' = 12 mu, and the time exponents fitted by least squares on the logarithms: of l
(2/3) and of the inlet net pressure p - p0 (-1/3; the constant of the inlet pressure is
not compared). The half-length is (failed cells of the path and mouth) h / 4. Needs
matplotlib for the plot.
"""
import math, os, subprocess, sys, tempfile, time

from kgd_study import results, scene_at  # the same path, mouth and probes moved with h

E, NU, MU, Q0, P0 = 1.0e10, 0.25, 1.0e-3, 1.0e-5, 1.0e7
EP = E / (1 - NU * NU)
MUP = 12 * MU
T0 = 8.0


def vertex(t):
    l = 0.6152 * (EP * Q0 ** 3 * t ** 4 / MUP) ** (1 / 6)
    w = 1.1265 * (MUP * Q0 ** 3 * t * t / EP) ** (1 / 6)
    return l, w


def fit(xs, ys):
    lx = [math.log(x) for x in xs]
    ly = [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sum((a - mx) ** 2 for a in lx)


def summary(rows):
    late = [r for r in rows if r[0] >= T0]
    out = {}
    for k, name in ((1, "l"), (3, "w")):
        e = [r[k] / vertex(r[0])[0 if k == 1 else 1] - 1 for r in late]
        out[name] = (sum(e) / len(e), sum(abs(x) for x in e) / len(e), max(e, key=abs))
    out["exponent"] = fit([r[0] for r in late], [r[1] for r in late])
    out["p_exponent"] = fit([r[0] for r in late], [r[2] for r in late])
    return out


def main():
    exe = sys.argv[1] if len(sys.argv) > 1 else "target/release/porofrac"
    text = open("scenes/kgd_viscosity.toml").read()
    runs, walls = {}, {}
    with tempfile.TemporaryDirectory() as tmp:
        for r in (8, 16, 32):
            path = os.path.join(tmp, f"kgd_{r}.toml")
            open(path, "w").write(scene_at(text, r, h_scene=0.125))
            out = os.path.join(tmp, f"out_{r}")
            start = time.time()
            subprocess.run([exe, "run", path, "--out", out], check=True, capture_output=True)
            walls[r] = time.time() - start
            runs[r] = results(out, 2.0 / r, P0)
    print("| refine | h (m) | cells per half-length at 40 s | l: mean, mean abs, largest | w: mean, mean abs, largest | exponent of l (2/3) | exponent of p (-1/3) | wall (s) |")
    print("|---:|---:|---:|---|---|---:|---:|---:|")
    for r, rows in runs.items():
        s = summary(rows)
        f = lambda v: f"{100 * v[0]:+.1f} %, {100 * v[1]:.1f} %, {100 * v[2]:+.1f} %"
        print(f"| {r} | {2 / r:g} | {vertex(40)[0] / (2 / r):.0f} | {f(s['l'])} | {f(s['w'])} | {s['exponent']:.3f} | {s['p_exponent']:.3f} | {walls[r]:.1f} |")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("no matplotlib: no plot")
        return
    ts = [0.2 * i for i in range(1, 201)]
    fig, ax = plt.subplots(1, 3, figsize=(14, 4.2))
    ax[0].plot(ts, [vertex(t)[0] for t in ts], "k-", label="vertex solution (Detournay 2004)")
    ax[2].plot(ts, [vertex(t)[1] * 1e3 for t in ts], "k-", label="vertex solution")
    for r, style in ((8, "C2:"), (16, "C1--"), (32, "C0-")):
        rows = runs[r]
        t = [x[0] for x in rows]
        ax[0].plot(t, [x[1] for x in rows], style, drawstyle="steps-post", label=f"porofrac, h = {2 / r:g} m")
        ax[1].plot(t, [x[2] * 1e-6 for x in rows], style, label=f"porofrac, h = {2 / r:g} m")
        ax[2].plot(t, [x[3] * 1e3 for x in rows], style, label=f"porofrac, h = {2 / r:g} m")
    for a, label in zip(ax, ("half-length ℓ (m)", "inlet net pressure p − p₀ (MPa)", "inlet opening w (mm)")):
        a.set_xlabel("time t (s)")
        a.set_ylabel(label)
        a.grid(alpha=0.3)
    ax[0].legend(fontsize=8)
    ax[1].legend(fontsize=8)
    fig.suptitle("KGD, viscosity-dominated (scenes/kgd_viscosity.toml): E′ = 10.67 GPa, μ = 1 mPa·s, K_Ic = 0.03 MPa·√m, Q₀ = 1e-5 m²/s")
    fig.tight_layout()
    fig.savefig("docs/hydrofrac/kgd_viscosity.png", dpi=110)
    print("wrote docs/hydrofrac/kgd_viscosity.png")


if __name__ == "__main__":
    main()
