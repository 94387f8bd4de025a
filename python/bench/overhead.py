#!/usr/bin/env python3
"""The Python path's overhead against `porofrac run` (docs/BENCHMARKS.md, "From Python").

Each round runs, back to back, for every scene: the command (`porofrac run SCENE --out
DIR`), Python writing the same files (`Scene.load(SCENE).run(out=DIR, fields=False)`) and
Python in memory (`Scene.load(SCENE).run(fields=...)`, POROFRAC_FIELDS=0 for `False`), each
in a fresh process after `porofrac.retain_freed_memory()` (the command's heap policy),
timed from start to exit
(wall seconds, so interpreter start and `import porofrac` count; and the process's CPU
seconds, user + system, less sensitive to other work on the machine). Prints a Markdown
table of the rounds and medians. Usage, from the workspace root, with the package installed:

    python python/bench/overhead.py [ROUNDS] [SCENE...]
"""

import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
BIN = ROOT / "target" / "release" / "porofrac"
SCENES = ["scenes/hydrofrac_seed.toml", "scenes/bench/e2.toml"]
# Whether the in-memory runs keep the state of the written steps (POROFRAC_FIELDS=0: no).
FIELDS = os.environ.get("POROFRAC_FIELDS", "1") != "0"
PY = (
    "import porofrac, sys; porofrac.retain_freed_memory(); "
    "porofrac.Scene.load(sys.argv[1]).run(out={out}, progress=False, fields={fields})"
)


def cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def timed(args):
    """(wall, CPU) seconds of a process."""
    t, c = time.perf_counter(), cpu()
    subprocess.run(args, check=True, cwd=ROOT, capture_output=True)
    return time.perf_counter() - t, cpu() - c


def main():
    rounds = int(sys.argv[1]) if len(sys.argv) > 1 else 5
    scenes = sys.argv[2:] or SCENES
    rows = {s: [] for s in scenes}
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(rounds):
            for s in scenes:
                out = Path(tmp) / f"{Path(s).stem}_{r}"
                cmd = timed([str(BIN), "run", s, "--out", str(out / "cmd")])
                files = timed(
                    [sys.executable, "-c", PY.format(out=repr(str(out / "py")), fields=False), s]
                )
                memory = timed([sys.executable, "-c", PY.format(out="None", fields=FIELDS), s])
                rows[s].append((cmd, files, memory))
                print(f"round {r + 1} {s}: {cmd} {files} {memory}", file=sys.stderr)
    print("| scene | round | command wall / CPU | Python, files | Python, in memory |")
    print("|---|---|---|---|---|")
    cell = lambda x: f"{x[0]:.2f} / {x[1]:.2f}"
    for s, rs in rows.items():
        for i, (c, f, m) in enumerate(rs, 1):
            print(f"| {s} | {i} | {cell(c)} | {cell(f)} | {cell(m)} |")
        med = [[statistics.median(x[k][j] for x in rs) for j in range(2)] for k in range(3)]
        rel = lambda k: "/".join(f"{100 * (med[k][j] / med[0][j] - 1):+.1f}" for j in range(2))
        print(
            f"| {s} | median | {cell(med[0])} | {cell(med[1])} ({rel(1)} %) "
            f"| {cell(med[2])} ({rel(2)} %) |"
        )


if __name__ == "__main__":
    main()
