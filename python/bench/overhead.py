#!/usr/bin/env python3
"""The Python path's overhead against `porofrac run` (docs/BENCHMARKS.md, "From Python").

Each round runs, back to back, for every scene: the command (`porofrac run SCENE --out
DIR`), Python writing the same files (`Scene.load(SCENE).run(out=DIR)`) and Python in
memory (`Scene.load(SCENE).run()`), each in a fresh process, timed from start to exit
(wall seconds, so interpreter start and `import porofrac` count). Prints a Markdown table
of the rounds and medians. Usage, from the workspace root, with the package installed:

    python python/bench/overhead.py [ROUNDS] [SCENE...]
"""

import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
BIN = ROOT / "target" / "release" / "porofrac"
SCENES = ["scenes/hydrofrac_seed.toml", "scenes/bench/e2.toml"]
PY = "import porofrac, sys; porofrac.Scene.load(sys.argv[1]).run(out={out}, progress=False)"


def timed(args):
    t = time.perf_counter()
    subprocess.run(args, check=True, cwd=ROOT, capture_output=True)
    return time.perf_counter() - t


def main():
    rounds = int(sys.argv[1]) if len(sys.argv) > 1 else 5
    scenes = sys.argv[2:] or SCENES
    rows = {s: [] for s in scenes}
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(rounds):
            for s in scenes:
                out = Path(tmp) / f"{Path(s).stem}_{r}"
                cmd = timed([str(BIN), "run", s, "--out", str(out / "cmd")])
                files = timed([sys.executable, "-c", PY.format(out=repr(str(out / "py"))), s])
                memory = timed([sys.executable, "-c", PY.format(out="None"), s])
                rows[s].append((cmd, files, memory))
                print(f"round {r + 1} {s}: {cmd:.3f} {files:.3f} {memory:.3f}", file=sys.stderr)
    print("| scene | round | command | Python, files | Python, in memory |")
    print("|---|---|---|---|---|")
    for s, rs in rows.items():
        for i, (c, f, m) in enumerate(rs, 1):
            print(f"| {s} | {i} | {c:.2f} | {f:.2f} | {m:.2f} |")
        med = [statistics.median(x[k] for x in rs) for k in range(3)]
        print(
            f"| {s} | median | {med[0]:.2f} | {med[1]:.2f} ({100 * (med[1] / med[0] - 1):+.1f} %) "
            f"| {med[2]:.2f} ({100 * (med[2] / med[0] - 1):+.1f} %) |"
        )


if __name__ == "__main__":
    main()
