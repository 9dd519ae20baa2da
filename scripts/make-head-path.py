#!/usr/bin/env python3
"""Writes configs/assets/head-walk.csv: a head walking a loop in a 3 m CAVE,
looking around, for tracking's `replay` source (time s, x, y, z m, qw, qx, qy, qz).

    python3 scripts/make-head-path.py > configs/assets/head-walk.csv

A 0.5 m circle around the CAVE's centre in 10 s (0.31 m/s), the eyes at
1.60-1.65 m (a step's bob), the head turning ±40° about the vertical and
nodding ±10°, sampled at 60 Hz. The path closes on itself, so it loops."""
import math

RATE = 60.0
SECONDS = 10.0


def quaternion(yaw, pitch):
    # Yaw about y (up), then pitch about the head's own x: q = q_yaw * q_pitch.
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    return (cy * cp, cy * sp, sy * cp, -sy * sp)


print("time,x,y,z,qw,qx,qy,qz")
for i in range(int(RATE * SECONDS)):
    t = i / RATE
    phase = 2 * math.pi * t / SECONDS
    x = 0.5 * math.sin(phase)
    z = 0.5 * math.cos(phase) - 0.3
    y = 1.625 + 0.025 * math.sin(4 * phase * 5)
    yaw = math.radians(40) * math.sin(2 * phase)
    pitch = math.radians(10) * math.sin(3 * phase)
    qw, qx, qy, qz = quaternion(yaw, pitch)
    print(f"{t:.4f},{x:.5f},{y:.5f},{z:.5f},{qw:.6f},{qx:.6f},{qy:.6f},{qz:.6f}")
