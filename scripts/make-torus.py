#!/usr/bin/env python3
"""Writes the source of the textured torus test model: torus.obj, torus.mtl and
torus.png (256x256 RGB) into the folder given, as a modelling tool would export
them. obj2gltf and gltf-pipeline turn them into glTF (scripts/make-gltf-assets.sh).

The torus has 64 x 64 quads (8,192 triangles), a major radius of 0.35 m and a
minor one of 0.15 m, its axis along y; u runs around the axis, v around the tube.
The texture is a checker of warm and cool squares with a brighter band, so that
its orientation and its sampling are visible; its mean is about 128/255."""
import math
import os
import struct
import sys
import zlib

SEGMENTS = 64
MAJOR = 0.35
MINOR = 0.15
SIZE = 256


def write_obj(folder):
    lines = ["# a torus, 64 x 64 quads (8192 triangles), made by scripts/make-torus.py",
             "mtllib torus.mtl", "o torus"]
    for i in range(SEGMENTS + 1):
        a = 2 * math.pi * i / SEGMENTS
        for j in range(SEGMENTS + 1):
            b = 2 * math.pi * j / SEGMENTS
            r = MAJOR + MINOR * math.cos(b)
            lines.append("v %.6f %.6f %.6f" % (r * math.cos(a), MINOR * math.sin(b), -r * math.sin(a)))
    for i in range(SEGMENTS + 1):
        for j in range(SEGMENTS + 1):
            # OBJ's v runs up the image; (0, 0) is its bottom-left corner.
            lines.append("vt %.6f %.6f" % (i / SEGMENTS, 1.0 - j / SEGMENTS))
    for i in range(SEGMENTS + 1):
        a = 2 * math.pi * i / SEGMENTS
        for j in range(SEGMENTS + 1):
            b = 2 * math.pi * j / SEGMENTS
            lines.append("vn %.6f %.6f %.6f" % (math.cos(b) * math.cos(a), math.sin(b), -math.cos(b) * math.sin(a)))
    lines.append("usemtl checker")
    row = SEGMENTS + 1
    for i in range(SEGMENTS):
        for j in range(SEGMENTS):
            k00 = i * row + j + 1
            k10 = (i + 1) * row + j + 1
            k11 = (i + 1) * row + j + 2
            k01 = i * row + j + 2
            # Counter-clockwise seen from outside.
            for tri in ((k00, k10, k11), (k00, k11, k01)):
                lines.append("f " + " ".join("%d/%d/%d" % (k, k, k) for k in tri))
    with open(os.path.join(folder, "torus.obj"), "w") as f:
        f.write("\n".join(lines) + "\n")
    with open(os.path.join(folder, "torus.mtl"), "w") as f:
        f.write("newmtl checker\nKa 0 0 0\nKd 1 1 1\nKs 0 0 0\nNs 10\nillum 2\nmap_Kd torus.png\n")


def texel(x, y):
    checker = ((x // 32) + (y // 32)) % 2
    warm = (222, 122, 52)
    cool = (44, 118, 170)
    colour = warm if checker else cool
    if 112 <= y < 144:  # a band around the tube
        colour = tuple(min(255, c + 60) for c in colour)
    return colour


def write_png(folder):
    raw = bytearray()
    for y in range(SIZE):
        raw.append(0)  # filter: none
        for x in range(SIZE):
            raw.extend(texel(x, y))

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", SIZE, SIZE, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(bytes(raw), 9)) + chunk(b"IEND", b"")
    with open(os.path.join(folder, "torus.png"), "wb") as f:
        f.write(png)
    mean = sum(raw[1 + y * (1 + 3 * SIZE) + i] for y in range(SIZE) for i in range(3 * SIZE)) / (3 * SIZE * SIZE)
    print("torus.png: mean %.1f/255" % mean)


if __name__ == "__main__":
    folder = sys.argv[1] if len(sys.argv) > 1 else "."
    write_obj(folder)
    write_png(folder)
