#!/usr/bin/env python3
"""Turns a benchmark's CSV (every run, as the bench wrote it) into the series its
plot draws: the medians its tables quote, with the min and max over runs as the
error. Writes gnuplot data: one block per series group, blocks apart by two blank
lines (gnuplot's `index`), one number per column, NaN where there is none.

usage: series.py NAME CSV OUT.dat   (NAME: barrier, calibration, dof, fields,
                                     lighting, oblique, oblique-depth,
                                     live-scene, scene-transfer, tracking,
                                     upconversion)

The drawing is tests/bench/plots/NAME.gp; scripts/plot-bench.sh runs both."""

import csv
import math
import sys
from collections import defaultdict


def median(values):
    """Nearest-rank median, as the benches' tables (bench::spread): the lower
    middle of an even count."""
    ordered = sorted(values)
    return ordered[max(1, math.ceil(len(ordered) * 0.5 - 1e-9)) - 1]


def spread(values):
    return (median(values), min(values), max(values))


def read(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def fail(message):
    sys.exit("series.py: " + message)


def barrier(rows):
    """Per node count, medians over runs: barrier round, the ready/go baseline and
    the present skew (median and p99 of each run). One node has no skew."""
    by_nodes = defaultdict(list)
    for r in rows:
        by_nodes[int(r["nodes"])].append(r)
    lines = []
    for nodes in sorted(by_nodes):
        runs = by_nodes[nodes]
        cells = []
        for column in ("barrier_median_us", "barrier_p99_us", "ready_go_median_us", "ready_go_p99_us",
                       "present_skew_median_us", "present_skew_p99_us"):
            m, lo, hi = spread([float(r[column]) for r in runs])
            if column.startswith("present_skew") and nodes == 1:
                m, lo, hi = math.nan, math.nan, math.nan
            cells += [m, lo, hi]
        lines.append([nodes] + cells)
    return [lines]


CALIBRATION_METHODS = ("DLT only", "DLT + refinement", "robust (RANSAC + refinement)")


def calibration(rows):
    """Block 0, clean points: time per fit (median, min, max over repeats) per
    method. Block 1, with gross outliers: transfer error ÷ its optimum, the error
    pooled over every fit as the table does (the repeats hold as many fits each)."""
    clean, dirty = [], []
    points = sorted({int(r["points"]) for r in rows})
    for n in points:
        clean_row, dirty_row = [n], [n]
        for method in CALIBRATION_METHODS:
            picked = [r for r in rows if int(r["points"]) == n and r["method"] == method]
            if not picked:
                fail(f"calibration: no rows for method '{method}' at {n} points")
            no_outliers = [r for r in picked if int(r["outliers"]) == 0]
            with_outliers = [r for r in picked if int(r["outliers"]) > 0]
            clean_row += list(spread([float(r["us_per_fit"]) for r in no_outliers])) if no_outliers else [math.nan] * 3
            if with_outliers:
                pooled = math.sqrt(sum(float(r["transfer_rms_px"]) ** 2 for r in with_outliers) / len(with_outliers))
                dirty_row.append(pooled / float(with_outliers[0]["optimum_px"]))
            else:
                dirty_row.append(math.nan)
        clean.append(clean_row)
        if not all(math.isnan(v) for v in dirty_row[1:]):
            dirty.append(dirty_row)
    return [clean, dirty]


DOF_METHODS = ("all-in-focus", "pair-16bit", "pair-8bit", "gather-normalized")
DOF_GAIN_FLOOR = -15.0  # dB: lower gains are drawn on the floor with their own mark


def dof(rows):
    """Block 0: PSNR away from focus per focal depth b for each method. Block 1:
    per object and b, the pair's gain over all-in-focus against the object's c_r
    (gains under the floor in block 2, drawn at the floor)."""
    psnr = defaultdict(dict)
    objects = defaultdict(dict)
    for r in rows:
        if r["table"] == "psnr" and r["subject"] == "away-from-focus" and r["metric"] == "psnr_luma_db":
            psnr[float(r["focal_depth_m"])][r["method"]] = float(r["value"])
        elif r["table"] == "object":
            key = (float(r["focal_depth_m"]), r["subject"])
            objects[key][r["method"] or r["metric"]] = float(r["value"])
    if not psnr or not objects:
        fail("dof: no 'psnr' or 'object' rows")
    sweep = []
    for b in sorted(psnr):
        missing = [m for m in DOF_METHODS if m not in psnr[b]]
        if missing:
            fail(f"dof: b = {b} lacks {', '.join(missing)}")
        sweep.append([b] + [psnr[b][m] for m in DOF_METHODS])
    shown, floored = [], []
    for key in sorted(objects):
        o = objects[key]
        gain = o["pair-16bit"] - o["all-in-focus"]
        (shown if gain >= DOF_GAIN_FLOOR else floored).append([o["coc"], max(gain, DOF_GAIN_FLOOR)])
    return [sweep, shown or [[math.nan, math.nan]], floored or [[math.nan, math.nan]]]


def lighting(rows):
    """Identical nodes, one block per scene (light count): per node count, the
    speed-up (full render's time / slowest node's, per run: the median over frames
    of the slowest node) as median, min, max over runs, and the median PSNR of the
    8-bit sum against the exact render."""
    ms = defaultdict(lambda: defaultdict(list))  # (lights, nodes) -> (run, frame) -> node times
    psnr = defaultdict(list)
    for r in rows:
        if r["group"] != "identical":
            continue
        key = (int(r["scene_lights"]), int(r["nodes"]))
        if r["metric"] == "ms":
            ms[key][(int(r["run"]), int(r["frame"]))].append(float(r["value"]))
        elif r["metric"] == "psnr_vs_exact_db":
            psnr[key].append(float(r["value"]))

    def slowest_per_run(key):
        runs = defaultdict(list)
        for (run, _frame), nodes in ms[key].items():
            runs[run].append(max(nodes))
        return {run: median(frames) for run, frames in runs.items()}

    blocks = []
    for lights in sorted({k[0] for k in ms}):
        if (lights, 1) not in ms:
            fail(f"lighting: {lights} lights has no one-node (full) row")
        full = slowest_per_run((lights, 1))
        block = []
        for nodes in sorted(k[1] for k in ms if k[0] == lights):
            split = slowest_per_run((lights, nodes))
            speedups = [full[run] / split[run] for run in split if run in full]
            block.append([nodes, *spread(speedups), median(psnr[(lights, nodes)]) if psnr[(lights, nodes)] else math.nan])
        blocks.append(block)
    return blocks


OBLIQUE_METHODS = (("single_ms", "single_psnr_db"), ("two_ms", "two_psnr_db"), ("two_equal_ms", "two_equal_psnr_db"))


def oblique(rows):
    """One block per projector, one line per method (single pass, two passes at the
    densest pitch, two passes with as many texels as pixels): frame time (median
    over runs of the run's median, min, max over runs) and PSNR (median over frames)."""
    projectors = []
    for r in rows:
        if r["projector"] not in projectors:
            projectors.append(r["projector"])
    blocks = []
    for p in projectors:
        mine = [r for r in rows if r["projector"] == p]
        block = []
        for i, (time_column, psnr_column) in enumerate(OBLIQUE_METHODS):
            per_run = defaultdict(list)
            for r in mine:
                per_run[int(r["run"])].append(float(r[time_column]))
            times = spread([median(v) for v in per_run.values()])
            psnrs = [float(r[psnr_column]) for r in mine if r[psnr_column] != ""]
            block.append([i, *times, median(psnrs)])
        blocks.append(block)
    return blocks


OBLIQUE_DEPTH_METHODS = ("ours", "paper", "aligned")
OBLIQUE_DEPTH_SERIES = ("yaw", "diagonal-rolled", "askew-close")


def oblique_depth(rows):
    """Blocks 0–2, one per series: the depth compression c of ours and of the
    paper's third row against the incidence θ (c < 0: depth order reversed).
    Block 3: per separation δ (mm), the worst share of counted pixels that show the
    wrong object (24-bit depth) over every frame (series × θ), per method."""
    compression = {s: {} for s in OBLIQUE_DEPTH_SERIES}
    worst = defaultdict(lambda: dict.fromkeys(OBLIQUE_DEPTH_METHODS, 0.0))
    for r in rows:
        if r["depth"] != "fixed24" or r["method"] not in OBLIQUE_DEPTH_METHODS:
            continue
        if r["series"] not in compression:
            fail(f"oblique-depth: unknown series '{r['series']}'")
        compression[r["series"]][float(r["incidence_deg"])] = (float(r["compression_ours"]),
                                                               float(r["compression_paper"]))
        counted = int(r["counted"])
        if counted:
            delta_mm = 1000.0 * float(r["delta_m"])
            share = 100.0 * int(r["errors"]) / counted
            worst[delta_mm][r["method"]] = max(worst[delta_mm][r["method"]], share)
    blocks = [[[theta, *c] for theta, c in sorted(compression[s].items())] for s in OBLIQUE_DEPTH_SERIES]
    blocks.append([[delta] + [worst[delta][m] for m in OBLIQUE_DEPTH_METHODS] for delta in sorted(worst)])
    return blocks


def fields(rows):
    """One block per scene, one line per method in the order run: method index,
    draw ms, ratio to one moment per frame and ratio to per-field (median, min,
    max over runs each), the fringe width, PSNR_Y against the ideal and the worst
    channel's PSNR against per-field (one perceive each; NaN where identical)."""
    scenes, methods = [], []
    for r in rows:
        if r["scene"] not in scenes:
            scenes.append(r["scene"])
        if r["method"] not in methods:
            methods.append(r["method"])
    blocks = []
    for scene in scenes:
        block = []
        for i, method in enumerate(methods):
            mine = [r for r in rows if r["scene"] == scene and r["method"] == method]
            if not mine:
                fail(f"fields: no rows for {scene} / {method}")
            worst = float(mine[0]["worst_channel_db_vs_per_field"])
            block.append([i, *spread([float(r["draw_ms_median"]) for r in mine]),
                          *spread([float(r["ratio_to_one_moment"]) for r in mine]),
                          *spread([float(r["ratio_to_per_field"]) for r in mine]),
                          float(mine[0]["fringe_px"]), float(mine[0]["psnr_y_db"]),
                          worst if math.isfinite(worst) else math.nan])
        blocks.append(block)
    return blocks


def upconversion(rows):
    """One block per way in the bench's order (average at 4:1, then motion
    interpolated and extrapolated at each ratio, then both at 4:1 with the key
    frames spread), one line per scene in order:
    scene index, cost per display frame ÷ every frame drawn (median, min, max
    over runs), PSNR_Y of the frames between (the first run; it does not vary)."""
    ways, scenes = [], []
    for r in rows:
        way = (r["method"], r["mode"], r["ratio"], r["spread"])
        if way not in ways:
            ways.append(way)
        if r["scene"] not in scenes:
            scenes.append(r["scene"])
    blocks = []
    for way in ways:
        block = []
        for i, scene in enumerate(scenes):
            mine = [r for r in rows if r["scene"] == scene and (r["method"], r["mode"], r["ratio"], r["spread"]) == way]
            if not mine:
                continue
            psnr = float(mine[0]["psnr_y_db"])
            block.append([i, *spread([float(r["cost_ratio"]) for r in mine]), min(psnr, 100.0)])
        if not block:
            fail(f"upconversion: no rows for {way}")
        blocks.append(block)
    return blocks


def tracking(rows):
    """One block per prediction (method and smoothing, in the bench's order), one
    row per tracker latency: latency ms, median and p99 of the eyes' error mm.
    Simulated time: one run, no spread over runs."""
    order = []
    by = defaultdict(list)
    for r in rows:
        key = (r["method"], r["smoothing"])
        if key not in by:
            order.append(key)
        by[key].append([float(r["latency_ms"]), float(r["median_mm"]), float(r["p99_mm"])])
    return [by[key] for key in order]


def scene_transfer(rows):
    """One row per method, in the bench's order: index, then the median, min and
    max over runs of MiB/s."""
    order = []
    by = defaultdict(list)
    for r in rows:
        if r["method"] not in by:
            order.append(r["method"])
        by[r["method"]].append(float(r["mib_per_s"]))
    return [[[i, *spread(by[method])] for i, method in enumerate(order)]]


def live_scene(rows):
    """Block 0, per instance count moved each frame (the at-begin runs): the
    count, then (median, min, max over runs) of the barrier round median, the
    scene bytes a frame (FrameBegin and staged edits) and the snapshot bytes.
    Block 1: the runs without an application, at x = 0.5 (the plot's 'none')."""
    columns = ("barrier_median_us", "frame_state_bytes_median", "snapshot_bytes")
    by = defaultdict(list)
    for r in rows:
        if r["send"] in ("none", "at-begin"):
            by[int(r["moved"])].append(r)
    if 0 not in by:
        fail("live-scene: no run without an application (send 'none')")

    def cells(runs):
        out = []
        for column in columns:
            out += spread([float(r[column]) for r in runs])
        return out

    moved = [[count, *cells(by[count])] for count in sorted(by) if count > 0]
    return [moved, [[0.5, *cells(by[0])]]]


SERIES = {"barrier": barrier, "calibration": calibration, "dof": dof, "fields": fields, "lighting": lighting,
          "live-scene": live_scene, "oblique": oblique, "oblique-depth": oblique_depth,
          "scene-transfer": scene_transfer, "tracking": tracking, "upconversion": upconversion}


def main():
    if len(sys.argv) != 4 or sys.argv[1] not in SERIES:
        fail("usage: series.py {" + ",".join(SERIES) + "} CSV OUT.dat")
    name, source, target = sys.argv[1:]
    try:
        rows = read(source)
    except OSError as e:
        fail(f"{source}: {e.strerror}")
    if not rows:
        fail(f"{source}: no rows")
    try:
        blocks = SERIES[name](rows)
    except (KeyError, ValueError) as e:
        fail(f"{source}: not a {name} bench CSV ({type(e).__name__}: {e})")
    with open(target, "w") as out:
        out.write(f"# {name} series from {source}\n")
        for i, block in enumerate(blocks):
            if i:
                out.write("\n\n")
            for line in block:
                out.write(" ".join("NaN" if isinstance(v, float) and math.isnan(v) else f"{v:.6g}" for v in line) + "\n")


if __name__ == "__main__":
    main()
