#!/usr/bin/env python3
"""Checks the benchmark plots: scripts/plot-bench.sh draws every plot from a copy
of the committed CSVs without a gnuplot warning, each PNG has the size its script
asks for, and the plotted medians are the ones the committed tables quote
(barrier rounds, lighting speed-ups), so plot and table cannot drift apart.

usage: check_plots.py SOURCE_DIR"""

import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile

source = sys.argv[1]
bench = os.path.join(source, "docs", "bench")
plots = os.path.join(source, "tests", "bench", "plots")
problems = []

with tempfile.TemporaryDirectory() as work:
    names = []
    for f in sorted(os.listdir(plots)):
        if f.endswith(".gp") and f != "style.gp":
            names.append(f[:-3])
            shutil.copy(os.path.join(bench, f[:-3] + ".csv"), work)
    run = subprocess.run([os.path.join(source, "scripts", "plot-bench.sh"), work], capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit(f"plot-bench.sh failed ({run.returncode}):\n{run.stdout}{run.stderr}")
    for name in names:
        script = open(os.path.join(plots, name + ".gp")).read()
        want = tuple(int(v) for v in re.search(r"width = (\d+); height = (\d+)", script).groups())
        with open(os.path.join(work, name + ".png"), "rb") as png:
            head = png.read(24)
        if head[:8] != b"\x89PNG\r\n\x1a\n":
            problems.append(f"{name}.png is not a PNG")
            continue
        size = struct.unpack(">II", head[16:24])
        if size != want:
            problems.append(f"{name}.png is {size[0]}×{size[1]}, its script asks for {want[0]}×{want[1]}")
        if os.path.getsize(os.path.join(work, name + ".png")) < 20000:
            problems.append(f"{name}.png is {os.path.getsize(os.path.join(work, name + '.png'))} bytes: nearly empty")

    # The plotted medians against the tables' cells.
    def series(name):
        out = os.path.join(work, name + ".dat")
        subprocess.run([sys.executable, os.path.join(plots, "series.py"), name, os.path.join(bench, name + ".csv"),
                        out], check=True)
        blocks = [[]]
        for line in open(out):
            if line.startswith("#"):
                continue
            if not line.strip():
                if blocks[-1]:
                    blocks.append([])
                continue
            blocks[-1].append([float(v) for v in line.split()])
        return [b for b in blocks if b]

    plotted = {int(r[0]): r[1] for r in series("barrier")[0]}
    for m in re.finditer(r"^\| (\d+) \| (\d+) \(", open(os.path.join(bench, "barrier.md")).read(), re.M):
        nodes, cell = int(m.group(1)), int(m.group(2))
        if round(plotted.get(nodes, -1)) != cell:
            problems.append(f"barrier: {nodes} nodes plotted {plotted.get(nodes)} µs, the table says {cell}")
    speedups = {}
    for lights, block in zip((20, 50, 100), series("lighting")):
        for r in block:
            speedups[(lights, int(r[0]))] = r[1]
    rows = re.findall(r"^\| (\d+) \| (\d) \| [\d /]+ \| [\d. /]+ \| [\d.]+ \([\d.–]+\) \| ([\d.]+) \(",
                      open(os.path.join(bench, "lighting.md")).read(), re.M)
    if len(rows) != len(speedups):
        problems.append(f"lighting: {len(rows)} speed-up rows in the table, {len(speedups)} plotted")
    for lights, nodes, cell in rows:
        got = speedups.get((int(lights), int(nodes)), -1)
        if f"{got:.2f}" != cell:
            problems.append(f"lighting: {lights} lights, {nodes} nodes plotted {got:.4f}, the table says {cell}")

for p in problems:
    print(p)
print(f"{len(names)} plots drawn; {len(problems)} problems")
sys.exit(1 if problems else 0)
