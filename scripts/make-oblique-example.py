#!/usr/bin/env python3
"""Writes the measured points for configs/powerwall-oblique-3.json.

Three projectors are modelled as pinhole cameras aimed by hand at a 3.2 m x 0.9 m
wall: one below the wall tilted up, one above-left tilted down, one to the right
yawed and rolled, so each image is visibly keystoned and neighbours overlap. For
each projector, 20 pixels on a 5 x 4 grid are "measured" on the wall with 1 mm of
Gaussian error (seeded), as a user would with a tape or a tracker. Then
`optique-master calibrate --points X.points.json --out X.json` gives the
calibration files the config names.

Usage: scripts/make-oblique-example.py [OUT_DIR]   (default configs/calibration)
"""
import json
import math
import os
import random
import sys

WIDTH, HEIGHT = 1024, 768

# name: (position [m], aim point on the wall [m], throw ratio, roll [degrees])
PROJECTORS = {
    "oblique-left": ((0.25, 1.15, 1.2), (0.53, 0.50), 1.0, -2.0),
    "oblique-centre": ((1.6, -0.35, 1.3), (1.6, 0.47), 1.0, 1.5),
    "oblique-right": ((2.95, 0.3, 1.3), (2.64, 0.47), 0.95, 2.5),
}


def sub(a, b):
    return [x - y for x, y in zip(a, b)]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def unit(a):
    n = math.sqrt(sum(x * x for x in a))
    return [x / n for x in a]


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def homography(position, aim, throw, roll_deg):
    """Screen (X, Y) on z = 0 -> pixel, as a 3x3 list of rows."""
    forward = unit(sub([aim[0], aim[1], 0.0], position))
    right = unit(cross(forward, [0.0, 1.0, 0.0]))
    down = cross(forward, right)
    roll = math.radians(roll_deg)
    right, down = ([math.cos(roll) * r + math.sin(roll) * d for r, d in zip(right, down)],
                   [-math.sin(roll) * r + math.cos(roll) * d for r, d in zip(right, down)])
    f = throw * WIDTH
    k = [[f, 0.0, WIDTH / 2.0], [0.0, f, HEIGHT / 2.0], [0.0, 0.0, 1.0]]
    rows = [right, down, forward]
    # Camera coordinates of (X, Y, 0): X R e_x + Y R e_y - R C.
    m = [[row[0], row[1], -dot(row, position)] for row in rows]
    return [[sum(k[i][j] * m[j][c] for j in range(3)) for c in range(3)] for i in range(3)]


def inverse(m):
    a, b, c = m[0]
    d, e, f = m[1]
    g, h, i = m[2]
    det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)
    return [[(e * i - f * h) / det, (c * h - b * i) / det, (b * f - c * e) / det],
            [(f * g - d * i) / det, (a * i - c * g) / det, (c * d - a * f) / det],
            [(d * h - e * g) / det, (b * g - a * h) / det, (a * e - b * d) / det]]


def apply(m, p):
    x = m[0][0] * p[0] + m[0][1] * p[1] + m[0][2]
    y = m[1][0] * p[0] + m[1][1] * p[1] + m[1][2]
    w = m[2][0] * p[0] + m[2][1] * p[1] + m[2][2]
    return [x / w, y / w]


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "configs/calibration"
    os.makedirs(out, exist_ok=True)
    rng = random.Random(4)
    for name, (position, aim, throw, roll) in PROJECTORS.items():
        h = homography(position, aim, throw, roll)
        to_screen = inverse(h)
        corners = [apply(to_screen, p) for p in ([0, 0], [WIDTH, 0], [WIDTH, HEIGHT], [0, HEIGHT])]
        print(name, "lit quad (m):", " ".join("(%.3f, %.3f)" % tuple(c) for c in corners))
        points = []
        for gy in range(4):
            for gx in range(5):
                pixel = [round((gx + 0.5) * WIDTH / 5) + 0.5, round((gy + 0.5) * HEIGHT / 4) + 0.5]
                screen = apply(to_screen, pixel)
                measured = [round(screen[0] + rng.gauss(0.0, 0.001), 4), round(screen[1] + rng.gauss(0.0, 0.001), 4)]
                points.append({"pixel": pixel, "screen": measured})
        with open(os.path.join(out, name + ".points.json"), "w") as f:
            f.write('{"projector": {"width": %d, "height": %d},\n "points": [\n' % (WIDTH, HEIGHT))
            f.write(",\n".join("  " + json.dumps(p) for p in points))
            f.write("\n ]}\n")


if __name__ == "__main__":
    main()
