#!/usr/bin/env python3
"""Loads a model (the repository's torus, uploaded as a .glb) and moves it on
a circle in front of the wall, once a frame, for a few seconds, with a warm
point light of its own riding above it; a copy of the installation's scene
turns red and back, and the scene's point lights go dark one at a time, a
second each. Run it against a master with master.api on, e.g.:

    optique-master --config configs/powerwall-2x2-api.json --local
    python3 circle.py --seconds 10
"""

import argparse
import math
import time
from pathlib import Path

import optique


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--host", default="127.0.0.1")
    parser.add_argument("--port", type=int, default=7490)
    parser.add_argument("--secret-file", help="the installation's shared secret, where the master needs it")
    parser.add_argument("--seconds", type=float, default=5.0)
    parser.add_argument("--radius", type=float, default=0.4, help="metres")
    torus = Path(__file__).resolve().parents[3] / "configs" / "assets" / "torus" / "torus.glb"
    parser.add_argument("--model", default=str(torus) if torus.is_file() else "",
                        help="a binary glTF (.glb) to upload and move on the circle (empty: the installation's scene)")
    args = parser.parse_args()

    with optique.connect(args.host, args.port, name="circle", secret_file=args.secret_file) as wall:
        asset = wall.scene.assets[0]  # the installation's own scene
        model = asset
        if args.model:
            model = "model-" + "".join(c if c.isalnum() or c in "-_." else "-" for c in Path(args.model).stem)[:50]
            if model not in wall.scene.assets:  # an asset id names one content for good
                with open(args.model, "rb") as glb:
                    frame = wall.load_asset(model, glb=glb.read())
                print(f"loaded '{model}' from {args.model}: every node draws it from frame {frame}")
        print(f"connected; {len(wall.scene.instances)} instance(s) already placed; placing '{model}' and '{asset}'")
        with wall.transaction() as t:
            # Replace what an earlier run of this example left (a master restarted from its journal keeps it).
            for instance in wall.scene.instances:
                if instance.instance in ("orbit", "beacon"):
                    t.remove(instance.instance)
            for light in wall.scene.point_lights:
                t.remove_point_light(light.light)
            t.create("orbit", model, position=(args.radius, 0.0, 0.3), scale=0.25)
            t.create("beacon", asset, position=(0.0, 0.0, 0.3), scale=0.15)
        print(f"placed from frame {t.frame}")
        start = time.monotonic()
        frames = []
        lights = wall.scene.light_count
        lamp = lights  # the first index after the scene's own lights
        dark = None  # the second whose light is off
        switches = 0
        while (now := time.monotonic() - start) < args.seconds:
            angle = now * 2.0 * math.pi / 4.0  # one turn every 4 s
            with wall.transaction() as t:
                x, y = args.radius * math.cos(angle), args.radius * math.sin(angle)
                t.move("orbit", position=(x, y, 0.3), rotation=(math.cos(angle / 2), 0.0, math.sin(angle / 2), 0.0))
                t.point_light(lamp, position=(x, y + 0.3, 0.6), colour=(1.0, 0.7, 0.4), intensity=0.3)
                red = 0.5 + 0.5 * math.sin(3.0 * now)
                t.tint("beacon", base_color=(1.0, 1.0 - red, 1.0 - red, 1.0))
                if lights and int(now) != dark:
                    if dark is not None:
                        t.switch_light(dark % lights, True)
                    dark = int(now)
                    t.switch_light(dark % lights, False)
                    switches += 1
            frames.append(t.frame)
            time.sleep(1.0 / 60.0)
        if frames:  # every light as the config has it again
            with wall.transaction() as t:
                if dark is not None:
                    t.switch_light(dark % lights, True)
                t.remove_point_light(lamp)
        print(f"moved it {len(frames)} times, frames {frames[0]} to {frames[-1]}; switched a light {switches} times")


if __name__ == "__main__":
    main()
