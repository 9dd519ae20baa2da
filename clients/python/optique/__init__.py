"""Drive an optique wall from your own program.

The master's scene session (``master.api`` in the installation's config) takes
transactions of edits to the live scene: instances of assets, placed, moved,
re-parented, shown, hidden, tinted and removed. Each transaction lands whole in
one frame on every node, or not at all::

    import optique

    with optique.connect(name="my-app") as wall:
        with wall.transaction() as t:
            t.create("spinner", asset="torus", position=(0.0, 1.2, -0.5), scale=0.5)
        print("shown from frame", t.frame)
        wall.subscribe(frames=True)
        event = wall.next_event(timeout=1.0)   # session_pb2.Event: event.frame_begun.frame, ...

The messages are those of proto/optique/session.proto; docs/applications.md
in the repository lists every one, with its fields and errors.
"""

from optique import session_pb2  # the messages: session_pb2.Event, RunChanged, ...
from optique.client import (
    PROTOCOL_VERSION,
    ConnectionClosed,
    Refused,
    SessionRefused,
    Session,
    Transaction,
    connect,
)

__all__ = [
    "PROTOCOL_VERSION",
    "ConnectionClosed",
    "Refused",
    "SessionRefused",
    "Session",
    "Transaction",
    "connect",
    "session_pb2",
]
