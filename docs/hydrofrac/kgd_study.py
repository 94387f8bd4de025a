"""KGD toughness-dominated: scenes/kgd_toughness.toml at three resolutions against the
vertex solution (Detournay 2004), and the plot docs/hydrofrac/kgd_toughness.png.

    python3 docs/hydrofrac/kgd_study.py [path/to/porofrac]   (from the repository root)

For refine = 8, 16, 32 (cells of h = 2/refine m along the path) it writes the scene with
the path row and the mouth moved to the row 50 < y < 50 + h, runs it, and prints, over
t >= 20 s (after the initial transient), the mean and largest relative error of the
half-length l, the inlet net pressure p and the inlet opening w against
l = 0.9324 (E' Q0 t / K')^(2/3), p = K_Ic / sqrt(pi l), w = 4 p l / E', and the time
exponent of l fitted by least squares on log l against log t. The half-length is
(failed cells of the path and mouth) h / 4: a square of the row is two triangles, and
the crack has two wings. Needs matplotlib for the plot.
"""
import csv, math, os, re, subprocess, sys, tempfile

E, NU, K_IC, Q0 = 1.0e10, 0.25, 1.0e6, 1.0e-5
EP = E / (1 - NU * NU)
KP = 4 * math.sqrt(2 / math.pi) * K_IC
T0 = 20.0


def vertex(t):
    l = 0.9324 * (EP * Q0 * t / KP) ** (2 / 3)
    p = K_IC / math.sqrt(math.pi * l)
    return l, p, 4 * p * l / EP


def scene_at(text, r, h_scene=2.0 / 32):
    """A KGD scene's text (`h_scene`: its own cell size along the path) at refine = r: the
    path's row, the mouth and the probes moved to the row 50 < y < 50 + h, h = 2/r."""
    h = 2.0 / r

    def at(x):
        return repr(round(x, 6))

    text = re.sub(r"refine = \d+", f"refine = {r}", text)
    b = h_scene
    for old, new in [
        (f"[[46.001, 50.001], [53.999, {at(50 + b - 0.001)}]]",
         f"[[46.001, 50.001], [53.999, {50 + h - 0.001}]]"),
        (f"[[{at(50 - b + 0.001)}, 50.001], [{at(50 + b - 0.001)}, {at(50 + b - 0.001)}]]",
         f"[[{50 - h + 0.001}, 50.001], [{50 + h - 0.001}, {50 + h - 0.001}]]"),
        (f"at = [50.0001, {at(50 + b / 2)}]", f"at = [50.0001, {50 + h / 2}]"),
        (f"at = [50.0, {at(50 + b)}]", f"at = [50.0, {50 + h}]"),
    ]:
        assert old in text, old
        text = text.replace(old, new)
    return text


def results(out, h, p0=0.0):
    """Rows (t, half-length, inlet net pressure (inlet pressure − p0), inlet opening) of
    a run's folder, t > 0."""
    probes = list(csv.DictReader(open(os.path.join(out, "probes.csv"))))
    failed = [float(f["time [s]"]) for f in csv.DictReader(open(os.path.join(out, "fracture.csv")))]
    rows = []
    for r in probes:
        t = float(r["time [s]"])
        if t == 0:
            continue
        n = sum(1 for tf in failed if tf <= t + 1e-9)
        w = float(r["uy_top [m]"]) - float(r["uy_bottom [m]"])
        rows.append((t, n * h / 4, float(r["p_inlet [Pa]"]) - p0, w))
    return rows


def summary(rows):
    late = [r for r in rows if r[0] >= T0]
    out = {}
    for k, name in ((1, "l"), (2, "p"), (3, "w")):
        e = [r[k] / vertex(r[0])[k - 1] - 1 for r in late]
        out[name] = (sum(e) / len(e), sum(abs(x) for x in e) / len(e), max(e, key=abs))
    xs = [math.log(r[0]) for r in late]
    ys = [math.log(r[1]) for r in late]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    out["exponent"] = sum((a - mx) * (b - my) for a, b in zip(xs, ys)) / sum((a - mx) ** 2 for a in xs)
    return out


def main():
    exe = sys.argv[1] if len(sys.argv) > 1 else "target/release/porofrac"
    text = open("scenes/kgd_toughness.toml").read()
    runs = {}
    with tempfile.TemporaryDirectory() as tmp:
        for r in (8, 16, 32):
            path = os.path.join(tmp, f"kgd_{r}.toml")
            open(path, "w").write(scene_at(text, r))
            out = os.path.join(tmp, f"out_{r}")
            subprocess.run([exe, "run", path, "--out", out], check=True, capture_output=True)
            runs[r] = results(out, 2.0 / r)
    print("| refine | h (m) | cells per half-length at 100 s | l: mean, mean abs, largest | p: mean, mean abs, largest | w: mean, mean abs, largest | exponent of l |")
    for r, rows in runs.items():
        s = summary(rows)
        f = lambda v: f"{100 * v[0]:+.1f} %, {100 * v[1]:.1f} %, {100 * v[2]:+.1f} %"
        print(f"| {r} | {2 / r:g} | {vertex(100)[0] / (2 / r):.0f} | {f(s['l'])} | {f(s['p'])} | {f(s['w'])} | {s['exponent']:.3f} |")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("no matplotlib: no plot")
        return
    ts = [0.5 * i for i in range(1, 201)]
    fig, ax = plt.subplots(1, 3, figsize=(14, 4.2))
    for k, (label, scale) in enumerate((("half-length ℓ (m)", 1), ("inlet net pressure p (MPa)", 1e-6), ("inlet opening w (mm)", 1e3))):
        ax[k].plot(ts, [vertex(t)[k] * scale for t in ts], "k-", label="vertex solution (Detournay 2004)")
        for r, style in ((8, "C2:"), (16, "C1--"), (32, "C0-")):
            rows = runs[r]
            ax[k].plot([x[0] for x in rows], [x[k + 1] * scale for x in rows], style, drawstyle="steps-post" if k == 0 else "default",
                       label=f"porofrac, h = {2 / r:g} m")
        ax[k].set_xlabel("time t (s)")
        ax[k].set_ylabel(label)
        ax[k].grid(alpha=0.3)
    ax[0].legend(fontsize=8)
    ax[1].set_ylim(0, 1.5)
    fig.suptitle("KGD, toughness-dominated (scenes/kgd_toughness.toml): E′ = 10.67 GPa, K_Ic = 1 MPa·√m, Q₀ = 1e-5 m²/s")
    fig.tight_layout()
    fig.savefig("docs/hydrofrac/kgd_toughness.png", dpi=110)
    print("wrote docs/hydrofrac/kgd_toughness.png")


if __name__ == "__main__":
    main()
