#!/usr/bin/env python3
"""Flies the CAVE with a flystick, with no DTrack at hand: plays ART DTrack on
UDP (a head at the room's centre, a flystick in front of it pointing ahead),
pushes the joystick forward, then sideways, then presses the reset button, and
listens as an application to where the viewer is in the world and what the
flystick does. Run it against the flystick CAVE:

    optique-master --config configs/cave-flystick.json --local
    python3 flystick.py

With a real DTrack, leave the first part out: the master reads the tracker, and
an application hears the same `flystick` and `head` events.
"""

import argparse
import math
import socket
import time

import optique


def dtrack_frame(frame: int, joystick_x: float, joystick_y: float, buttons: int) -> bytes:
    """One DTrack frame: body 0 (the head) and flystick 0 (6 buttons, a joystick),
    unturned, in millimetres, as DTrack's ASCII output writes them."""
    unturned = "1 0 0 0 1 0 0 0 1"
    head = f"[0 1.000][0.000 1600.000 0.000][{unturned}]"
    stick = f"[0 1.000 6 2][200.000 1200.000 -300.000][{unturned}][{buttons} {joystick_x:.3f} {joystick_y:.3f}]"
    return f"fr {frame}\r\n6d 1 {head}\r\n6df2 1 1 {stick}\r\n".encode()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--host", default="127.0.0.1")
    parser.add_argument("--port", type=int, default=7490, help="the master's master.api port")
    parser.add_argument("--tracking-port", type=int, default=5000, help="where the master listens for DTrack")
    parser.add_argument("--reset-button", type=int, default=1, help="viewer.navigation.reset_button")
    parser.add_argument("--seconds", type=float, default=1.0, help="how long each move lasts")
    args = parser.parse_args()

    tracker = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    with optique.connect(args.host, args.port, name="flystick") as cave:
        cave.subscribe(head=True, flysticks=True)
        moves = [("forward", 0.0, 1.0, 0), ("turning right", 1.0, 0.0, 0), ("reset", 0.0, 0.0, 1 << args.reset_button)]
        frame = 0
        for name, x, y, buttons in moves:
            until = time.monotonic() + args.seconds
            where = None
            pressed = None
            while time.monotonic() < until:
                frame += 1
                tracker.sendto(dtrack_frame(frame, x, y, buttons), (args.host, args.tracking_port))
                event = cave.next_event(timeout=1.0 / 60.0)
                if event is None:
                    continue
                if event.WhichOneof("event") == "head":
                    where = event.head.navigation
                elif event.WhichOneof("event") == "flystick":
                    pressed = [i for i, down in enumerate(event.flystick.buttons) if down]
            if where is None:
                raise SystemExit("flystick: no head event came: is viewer.navigation on, and the tracking port right?")
            x_, y_, z_ = where.position
            w = where.rotation[0]
            turned = math.degrees(2.0 * math.acos(max(-1.0, min(1.0, w))))
            print(f"{name}: the room is at ({x_:.2f}, {y_:.2f}, {z_:.2f}) in the world, turned {turned:.0f} degrees;"
                  f" buttons down {pressed}")


if __name__ == "__main__":
    main()
