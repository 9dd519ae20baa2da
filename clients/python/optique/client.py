"""The scene session over TCP: framing, the hello (with the installation's
shared secret, its proof and the sealing of every message after it), requests
and their replies. Blocking and single-threaded: one request at a time."""

import hashlib
import hmac
import collections
import os
import socket
import struct
from typing import Iterable, List, Optional, Sequence

from optique import session_pb2, wire_pb2

# The master's wire protocol version (net::kProtocolVersion); a master that
# speaks another refuses the hello and says which it speaks.
PROTOCOL_VERSION = 8
CAPABILITY = "scene-session"

_HEADER = struct.Struct(">I")
_MAX_REPLY_BYTES = 256 << 20  # a whole scene of 100,000 instances is about 15 MB
_TAG_BYTES = 16


class SessionRefused(Exception):
    """The master refused the session (no secret, wrong secret, too many
    sessions, another protocol version); ``retriable`` says whether trying
    again later may help."""

    def __init__(self, reason: str, retriable: bool = False):
        super().__init__(reason)
        self.reason = reason
        self.retriable = retriable


class ConnectionClosed(Exception):
    """The master closed the session (it shut down, or said goodbye)."""


class Refused(Exception):
    """A transaction the master refused: nothing of it was applied. ``edit`` is
    the index of the first edit that could not be, ``field`` names what is
    wrong (``edits[3].transform.scale[1]``) and ``reason`` says why."""

    def __init__(self, edit: int, field: str, reason: str):
        super().__init__(f"{field}: {reason}")
        self.edit = edit
        self.field = field
        self.reason = reason


def _read_secret(path: str) -> bytes:
    # As the master reads it: trailing blanks and line breaks are not part of it.
    with open(path, "rb") as f:
        secret = f.read().rstrip(b" \t\r\n")
    if len(secret) < 16:
        raise ValueError(f"{path}: a shared secret is at least 16 bytes")
    return secret


def _be32(n: int) -> bytes:
    return struct.pack(">I", n)


class _Sealing:
    """AES-256-GCM both ways, keys from HKDF-SHA256 over the secret and both
    nonces; each direction's nonce is its message count (net/session_seal.h)."""

    def __init__(self, secret: bytes, master_nonce: bytes, own_nonce: bytes, name: str):
        try:
            from cryptography.hazmat.primitives import hashes
            from cryptography.hazmat.primitives.ciphers.aead import AESGCM
            from cryptography.hazmat.primitives.kdf.hkdf import HKDF
        except ImportError as e:  # pragma: no cover - depends on the machine
            raise SessionRefused("this master needs the shared secret, and sealing needs the "
                                 "'cryptography' package (Debian: python3-cryptography)") from e
        info = b"optique session v1" + _be32(len(name.encode())) + name.encode() + _be32(PROTOCOL_VERSION)
        keys = HKDF(algorithm=hashes.SHA256(), length=64, salt=master_nonce + own_nonce, info=info).derive(secret)
        self._to_me = AESGCM(keys[:32])
        self._to_master = AESGCM(keys[32:])
        self._sent = 0
        self._received = 0

    @staticmethod
    def _iv(count: int) -> bytes:
        return b"\0\0\0\0" + struct.pack(">Q", count)

    def seal(self, payload: bytes) -> bytes:
        sealed = self._to_master.encrypt(self._iv(self._sent), payload, None)
        self._sent += 1
        return sealed

    def open(self, sealed: bytes) -> bytes:
        payload = self._to_me.decrypt(self._iv(self._received), sealed, None)
        self._received += 1
        return payload


def _vector(values: Optional[Iterable[float]], name: str, lengths: Sequence[int]) -> List[float]:
    if values is None:
        return []
    if isinstance(values, (int, float)):
        values = [values]
    out = [float(v) for v in values]
    if len(out) not in lengths:
        raise ValueError(f"{name} takes {' or '.join(map(str, lengths))} numbers, not {len(out)}")
    return out


def _transform(target: session_pb2.Transform, position=None, rotation=None, scale=None) -> None:
    target.position.extend(_vector(position, "position", [3]))
    target.rotation.extend(_vector(rotation, "rotation (w, x, y, z)", [4]))
    target.scale.extend(_vector(scale, "scale", [1, 3]))


class Transaction:
    """Edits that land together in one frame, or not at all. Made by
    ``Session.transaction()``; sent when its ``with`` block ends (unless the
    block raised), after which ``frame`` holds the frame that shows it."""

    def __init__(self, session: "Session"):
        self._session = session
        self.message = session_pb2.Transaction()
        self.frame: Optional[int] = None

    def create(self, instance: str, asset: str, parent: str = "", position=None, rotation=None, scale=None,
               hidden: bool = False) -> "Transaction":
        """A new instance of `asset` under `parent` (empty: the world)."""
        c = self.message.edits.add().create
        c.instance, c.asset, c.parent, c.hidden = instance, asset, parent, hidden
        _transform(c.transform, position, rotation, scale)
        return self

    def move(self, instance: str, position=None, rotation=None, scale=None) -> "Transaction":
        """A new placement, relative to the parent; what is left out keeps its value."""
        t = self.message.edits.add().transform
        t.instance = instance
        _transform(t.transform, position, rotation, scale)
        return self

    def reparent(self, instance: str, parent: str) -> "Transaction":
        p = self.message.edits.add().parent
        p.instance, p.parent = instance, parent
        return self

    def show(self, instance: str, visible: bool = True) -> "Transaction":
        v = self.message.edits.add().visible
        v.instance, v.visible = instance, visible
        return self

    def hide(self, instance: str) -> "Transaction":
        return self.show(instance, False)

    def tint(self, instance: str, base_color=None, emissive=None) -> "Transaction":
        """Factors on the asset's materials: base colour (r, g, b, a) in [0, 1], emissive (r, g, b) >= 0."""
        f = self.message.edits.add().factors
        f.instance = instance
        f.base_color.extend(_vector(base_color, "base_color", [4]))
        f.emissive.extend(_vector(emissive, "emissive", [3]))
        return self

    def remove(self, instance: str) -> "Transaction":
        """Removes the instance and every instance under it."""
        self.message.edits.add().remove.instance = instance
        return self

    def navigate(self, position=None, rotation=None, scale=None) -> "Transaction":
        """Where the installation is in the world (world <- installation): the
        viewer travels. `scale` is one number, or three equal ones."""
        _transform(self.message.edits.add().navigation.transform, position, rotation, scale)
        return self

    def switch_light(self, light: int, on: bool) -> "Transaction":
        """One of the scene's point lights, by its index, on or off."""
        edit = self.message.edits.add().light
        edit.light, edit.on = light, on
        return self

    def point_light(self, light: int, position=None, colour=None, intensity=None) -> "Transaction":
        """Adds a point light (index from the scene's light count on), or
        changes one added before: `position` (world metres, needed to add
        it), linear `colour` (r, g, b), `intensity`; what is None stays."""
        edit = self.message.edits.add().point_light
        edit.light = light
        edit.position.extend(_vector(position, "position", [3]))
        edit.colour.extend(_vector(colour, "colour", [3]))
        if intensity is not None:
            edit.intensity = float(intensity)
        return self

    def remove_point_light(self, light: int) -> "Transaction":
        """Removes a point light added with point_light (and its switch)."""
        self.message.edits.add().remove_point_light.light = light
        return self

    def animate(self, instance: str, playing=None, seek=None) -> "Transaction":
        """The instance's own clock for its asset's animations: played (True) or
        paused (False), and/or sought to `seek` seconds; what is None stays."""
        edit = self.message.edits.add().animation
        edit.instance = instance
        if playing is not None:
            edit.playing = bool(playing)
        if seek is not None:
            edit.seek = float(seek)
        return self

    def __enter__(self) -> "Transaction":
        return self

    def __exit__(self, kind, value, trace) -> None:
        if kind is None:
            self.frame = self._session.apply(self)


class Session:
    """One application's session with the master (see ``connect``)."""

    def __init__(self, host: str = "127.0.0.1", port: int = 7490, name: str = "python",
                 secret_file: Optional[str] = None, timeout: float = 10.0):
        self._sequence = 0
        self._request = 0
        self._sealing: Optional[_Sealing] = None
        self._buffer = b""
        self._events = collections.deque()  # events that came while a reply was awaited
        self._socket = socket.create_connection((host, port), timeout=timeout)
        self._socket.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        try:
            self._hello(name, secret_file)
            # The master answers a hello only when it refuses it: the first
            # reply (the scene as it is) says the session is open.
            self.scene = self.read_scene()
        except BaseException:
            self._socket.close()
            raise

    def _hello(self, name: str, secret_file: Optional[str]) -> None:
        challenge = self._receive()
        if challenge.WhichOneof("body") != "challenge":
            raise SessionRefused(f"expected the master's challenge, got {challenge.WhichOneof('body')}")
        hello = wire_pb2.Envelope()
        hello.hello.node_id = name
        hello.hello.capabilities.append(CAPABILITY)
        sealing = None
        if challenge.challenge.secret_required:
            if secret_file is None:
                raise SessionRefused("this master requires the installation's shared secret: pass secret_file")
            secret = _read_secret(secret_file)
            own_nonce = os.urandom(32)
            nonce = challenge.challenge.nonce + own_nonce
            proof = (b"optique hello v1" + _be32(len(nonce)) + nonce + _be32(len(name.encode())) + name.encode() +
                     _be32(PROTOCOL_VERSION))
            hello.hello.nonce_mac = hmac.new(secret, proof, hashlib.sha256).digest()
            hello.hello.node_nonce = own_nonce
            sealing = _Sealing(secret, challenge.challenge.nonce, own_nonce, name)
        self._send(hello)
        self._sealing = sealing

    def _send(self, envelope: wire_pb2.Envelope) -> None:
        self._sequence += 1
        envelope.protocol_version = PROTOCOL_VERSION
        envelope.sequence = self._sequence
        payload = envelope.SerializeToString()
        if self._sealing is not None:
            payload = self._sealing.seal(payload)
        self._socket.sendall(_HEADER.pack(len(payload)) + payload)

    def _read_exactly(self, n: int) -> bytes:
        while len(self._buffer) < n:
            chunk = self._socket.recv(max(65536, n - len(self._buffer)))
            if not chunk:
                raise ConnectionClosed("the master closed the session")
            self._buffer += chunk
        out, self._buffer = self._buffer[:n], self._buffer[n:]
        return out

    def _receive(self) -> wire_pb2.Envelope:
        (length,) = _HEADER.unpack(self._read_exactly(_HEADER.size))
        if length > _MAX_REPLY_BYTES:
            raise ConnectionClosed(f"the master sent a message of {length} bytes; this client takes at most "
                                   f"{_MAX_REPLY_BYTES}")
        payload = self._read_exactly(length)
        envelope = wire_pb2.Envelope()
        if self._sealing is not None:
            try:
                opened = self._sealing.open(payload)
            except Exception:
                # A refusal of the hello comes before the sealing starts: in the clear.
                try:
                    envelope.ParseFromString(payload)
                except Exception:
                    envelope.Clear()
                if envelope.WhichOneof("body") == "refuse":
                    raise SessionRefused(envelope.refuse.reason, envelope.refuse.retriable)
                raise ConnectionClosed("a message from the master failed authentication")
            payload = opened
        envelope.ParseFromString(payload)
        body = envelope.WhichOneof("body")
        if body == "refuse":
            raise SessionRefused(envelope.refuse.reason, envelope.refuse.retriable)
        if body == "goodbye":
            raise ConnectionClosed(f"the master said goodbye: {envelope.goodbye.reason}")
        return envelope

    def _ask(self, fill) -> session_pb2.Reply:
        self._request += 1
        envelope = wire_pb2.Envelope()
        envelope.session_request.id = self._request
        fill(envelope.session_request)
        self._send(envelope)
        while True:
            reply = self._receive()
            if reply.WhichOneof("body") == "session_event":
                self._events.append(reply.session_event)
            elif reply.WhichOneof("body") == "session_reply" and (
                    reply.session_reply.id == self._request or
                    (reply.session_reply.id == 0 and reply.session_reply.WhichOneof("reply") == "refused")):
                # Id 0: the master could not read the request (too large, or not
                # one); one request is out at a time, so it is this one.
                return reply.session_reply

    def transaction(self) -> Transaction:
        """Edits to send together: ``with session.transaction() as t: t.create(...)``."""
        return Transaction(self)

    def apply(self, transaction: Transaction) -> int:
        """Sends the transaction; returns the frame from which every node shows
        it, or raises ``Refused`` (and nothing of it was applied)."""
        reply = self._ask(lambda r: r.transaction.CopyFrom(transaction.message))
        if reply.WhichOneof("reply") == "refused":
            raise Refused(reply.refused.edit, reply.refused.field, reply.refused.reason)
        if reply.WhichOneof("reply") != "applied":
            raise ConnectionClosed(f"the master answered a transaction with {reply.WhichOneof('reply')}")
        return reply.applied.frame

    def load_asset(self, asset: str, path: Optional[str] = None, glb: Optional[bytes] = None,
                   timeout: float = 60.0) -> int:
        """Loads a glTF asset that instances may then name (``create(..., asset=...)``):
        ``path`` a file inside the master's ``master.api.assets`` folder (relative to
        it), or ``glb`` the bytes of a binary glTF this application sends (e.g.
        ``open("duck.glb", "rb").read()``). Waits until every node can draw it and
        returns the first frame from which they can, or raises ``Refused`` naming
        why not (``field`` ``load_asset.path``, ``load_asset.glb`` ...). The reply
        waits for every node: up to ``timeout`` seconds (or the session's, if longer)."""
        if (path is None) == (glb is None):
            raise ValueError("give the asset's path or its glb bytes, one of them")

        def fill(request):
            request.load_asset.asset = asset
            if path is not None:
                request.load_asset.path = path
            else:
                request.load_asset.glb = glb
        previous = self._socket.gettimeout()
        self._socket.settimeout(max(previous or 0.0, timeout))
        try:
            reply = self._ask(fill)
        finally:
            self._socket.settimeout(previous)
        if reply.WhichOneof("reply") == "refused":
            raise Refused(reply.refused.edit, reply.refused.field, reply.refused.reason)
        if reply.WhichOneof("reply") != "applied":
            raise ConnectionClosed(f"the master answered LoadAsset with {reply.WhichOneof('reply')}")
        return reply.applied.frame

    def read_scene(self) -> session_pb2.SceneContents:
        """The live scene as it is: ``assets`` and ``instances`` (InstanceView), by id."""
        reply = self._ask(lambda r: r.read_scene.SetInParent())
        if reply.WhichOneof("reply") != "scene":
            raise ConnectionClosed(f"the master answered ReadScene with {reply.WhichOneof('reply')}")
        return reply.scene

    def subscribe(self, frames: bool = False, head: bool = False, run: bool = False,
                  nodes: bool = False, flysticks: bool = False) -> None:
        """From now on the master sends these kinds of events (all off at first):
        ``frames`` each frame it begins (FrameBegun: frame, display_ns, period_ns),
        ``head`` the viewer's eyes in each frame (HeadShown), ``run`` paused,
        resumed or stopping (RunChanged), ``nodes`` a projector's node up or down
        (NodeChanged), ``flysticks`` a flystick's buttons, joystick or pose
        (FlystickChanged, with a DTrack tracker). Read them with ``next_event``; an application that stops
        reading them is closed by the master after a while."""
        def fill(request):
            request.subscribe.frames, request.subscribe.head = frames, head
            request.subscribe.run, request.subscribe.nodes = run, nodes
            request.subscribe.flysticks = flysticks
        reply = self._ask(fill)
        if reply.WhichOneof("reply") != "subscribed":
            raise ConnectionClosed(f"the master answered Subscribe with {reply.WhichOneof('reply')}")

    def next_event(self, timeout: Optional[float] = None) -> Optional[session_pb2.Event]:
        """The next event (session_pb2.Event: its ``WhichOneof('event')`` says
        which kind), or None when none came within `timeout` seconds."""
        if self._events:
            return self._events.popleft()
        previous = self._socket.gettimeout()
        self._socket.settimeout(timeout)
        try:
            while True:
                message = self._receive()
                if message.WhichOneof("body") == "session_event":
                    return message.session_event
        except socket.timeout:
            return None
        finally:
            self._socket.settimeout(previous)

    def close(self) -> None:
        try:
            goodbye = wire_pb2.Envelope()
            goodbye.goodbye.reason = "the application is done"
            self._send(goodbye)
        except OSError:
            pass
        self._socket.close()

    def __enter__(self) -> "Session":
        return self

    def __exit__(self, kind, value, trace) -> None:
        self.close()


def connect(host: str = "127.0.0.1", port: int = 7490, name: str = "python", secret_file: Optional[str] = None,
            timeout: float = 10.0) -> Session:
    """Opens a scene session: `name` is how the master's log and page call this
    application (1 to 64 letters, digits, '-', '_' or '.'); `secret_file` the
    installation's shared secret where the master requires it (any address
    but its own machine's)."""
    return Session(host, port, name, secret_file, timeout)
