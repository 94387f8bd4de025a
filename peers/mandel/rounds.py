#!/usr/bin/env python3
"""Back-to-back rounds: porofrac on scenes/mandel.toml, then mandel_scipy.py.

    python peers/mandel/rounds.py [ROUNDS] [--porofrac target/release/porofrac] [--out /tmp/m]

Run from the repository root with the venv's python. Each round runs, in this order,
`porofrac run scenes/mandel.toml --out /tmp/m` (stdout and stderr to
/dev/null), `mandel_scipy.py` (symmetric splu) and `mandel_scipy.py --splu default`, and
records for each the process wall time (perf_counter around the child process) and the
time the program reports (porofrac: summary.json wall_seconds.total; the peer: total_s),
the load average before the round, and the largest pressure error against the closed
form (compare.py). Prints a Markdown table and the medians of the ratios.
"""

import json
import os
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import compare  # noqa: E402


def timed(cmd, **kw):
    t0 = time.perf_counter()
    res = subprocess.run(cmd, check=True, **kw)
    return time.perf_counter() - t0, res


def max_error(probes_csv, result):
    import csv

    rows = list(csv.reader(open(probes_csv)))
    header, rows = rows[0], rows[1:]
    if result is None:
        cols = [header.index(f"p_{round(x * 1e4):04d}") for x in XS]
        values = {f"{float(r[0]):.2f}": [float(r[c]) for c in cols] for r in rows}
    else:
        values = {k: v[:-1] for k, v in result["probes"].items()}
    worst = 0.0
    for key, ps in values.items():
        t = float(key)
        if t == 0.0:
            continue
        worst = max(worst, max(abs(p - compare.pressure(x, t)) for x, p in zip(XS, ps)) / compare.P0)
    return worst


XS = [0.0125, 0.1375, 0.2625, 0.3875, 0.5125, 0.6375, 0.7625, 0.8875, 0.9875]


def main():
    args = sys.argv[1:]
    exe = "target/release/porofrac"
    if "--porofrac" in args:
        exe = args[args.index("--porofrac") + 1]
    rounds = int(args[0]) if args and args[0].isdigit() else 5
    out = args[args.index("--out") + 1] if "--out" in args else "/tmp/m"
    peer = [sys.executable, os.path.join(HERE, "mandel_scipy.py")]
    table = []
    for k in range(1, rounds + 1):
        load = os.getloadavg()[0]
        wall, _ = timed([exe, "run", "scenes/mandel.toml", "--out", out],
                        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        summary = json.load(open(os.path.join(out, "summary.json")))
        ours = summary["wall_seconds"]["total"]
        phases = summary["wall_seconds"]
        err_ours = max_error(os.path.join(out, "probes.csv"), None)
        row = {"round": k, "load": load, "porofrac_total": ours, "porofrac_wall": wall,
               "porofrac_err": err_ours, "porofrac_solve": phases["solve"],
               "porofrac_output": phases["output"]}
        for name, extra in [("peer", []), ("peer_default", ["--splu", "default"])]:
            pw, res = timed(peer + extra, capture_output=True, text=True)
            result = json.loads(next(line for line in res.stdout.splitlines()
                                     if line.startswith("RESULT "))[len("RESULT "):])
            row[name + "_total"] = result["total_s"]
            row[name + "_wall"] = pw
            row[name + "_err"] = max_error(os.path.join(out, "probes.csv"), result)
        row["ratio"] = row["peer_total"] / ours
        row["ratio_wall"] = row["peer_wall"] / wall
        row["ratio_default"] = row["peer_default_total"] / ours
        table.append(row)
    print("| round | load | porofrac total (wall) s | of which solve, output s "
          "| peer total (wall) s | ratio (wall) | peer, splu defaults, total s | ratio "
          "| max error/p0: porofrac, peer |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in table:
        print(f"| {r['round']} | {r['load']:.2f} | {r['porofrac_total']:.4f} ({r['porofrac_wall']:.4f}) "
              f"| {r['porofrac_solve']:.4f}, {r['porofrac_output']:.4f} "
              f"| {r['peer_total']:.4f} ({r['peer_wall']:.3f}) | {r['ratio']:.2f} ({r['ratio_wall']:.2f}) "
              f"| {r['peer_default_total']:.4f} | {r['ratio_default']:.2f} "
              f"| {r['porofrac_err']:.4%}, {r['peer_err']:.4%} |")
    med = {k: statistics.median(r[k] for r in table)
           for k in ["ratio", "ratio_wall", "ratio_default", "porofrac_total", "peer_total"]}
    print("MEDIANS " + json.dumps(med))


if __name__ == "__main__":
    main()
