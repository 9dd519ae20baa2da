"""The Python client (clients/python) against real masters with local nodes:
sessions, transactions, refusals, reading the scene, the shared secret with
sealing, and the examples. Run by run.sh inside a virtual environment the
client was pip-installed into."""

import json
import os
import pathlib
import signal
import socket
import subprocess
import sys
import tempfile
import time
import unittest

import optique

BIN = pathlib.Path(os.environ["OPTIQUE_BIN_DIR"])
SOURCE = pathlib.Path(os.environ["OPTIQUE_SOURCE_DIR"])
WALL = SOURCE / "configs" / "powerwall-2x2.json"
EXAMPLES = SOURCE / "clients" / "python" / "examples"


class Master:
    """optique-master --local on `config` with null nodes and the scene session
    on a free port; stopped (SIGTERM) and waited for on exit."""

    def __init__(self, folder: pathlib.Path, config=WALL, frames=36000, more=()):
        self.folder = folder
        self.port_file = folder / "api.port"
        self.log = open(folder / "master.log", "w")
        self.process = subprocess.Popen(
            [str(BIN / "optique-master"), "--config", str(config), "--local", "--frames", str(frames),
             "--out", str(folder / "out"), "--no-status", "--node-arg=--renderer=null", "--api-port", "0",
             "--api-port-file", str(self.port_file), *more],
            stdout=self.log, stderr=subprocess.STDOUT)
        deadline = time.monotonic() + 20
        while not (self.port_file.exists() and self.port_file.read_text().strip()):
            if self.process.poll() is not None or time.monotonic() > deadline:
                raise RuntimeError("the master did not open its scene session:\n" + self.output())
            time.sleep(0.05)
        self.port = int(self.port_file.read_text())

    def output(self) -> str:
        return (self.folder / "master.log").read_text()

    def report(self) -> dict:
        return json.loads((self.folder / "out" / "run.json").read_text())

    def wait(self, timeout=60) -> int:
        code = self.process.wait(timeout)
        self.log.close()
        return code

    def stop(self) -> int:
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGTERM)
        return self.wait()


class OnAWall(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.folder = tempfile.TemporaryDirectory(prefix="optique-client-")
        cls.master = Master(pathlib.Path(cls.folder.name))

    @classmethod
    def tearDownClass(cls):
        cls.master.stop()
        cls.folder.cleanup()

    def connect(self, name="client-test"):
        return optique.connect(port=self.master.port, name=name)

    def test_a_transaction_lands_whole_in_the_frame_the_reply_names(self):
        with self.connect() as wall:
            self.assertEqual(list(wall.scene.assets), ["cubes"])
            with wall.transaction() as t:
                t.create("table", "cubes", position=(0.5, 0.0, 0.0))
                t.create("cup", "cubes", parent="table", position=(0.0, 0.2, 0.0), scale=0.1)
                t.tint("cup", base_color=(1.0, 0.0, 0.0, 1.0))
            self.assertIsInstance(t.frame, int)  # 0 when the frames have not begun yet
            with wall.transaction() as later:
                later.move("table", position=(-0.5, 0.0, 0.0))
            self.assertGreaterEqual(later.frame, t.frame)
            scene = {i.instance: i for i in wall.read_scene().instances}
            self.assertEqual(scene["table"].transform.position[:], [-0.5, 0.0, 0.0])
            self.assertEqual(scene["cup"].parent, "table")
            self.assertEqual(scene["cup"].base_color[:], [1.0, 0.0, 0.0, 1.0])
            with wall.transaction() as t:
                t.remove("table")
            self.assertEqual(len(wall.read_scene().instances), 0, "the cup went with its table")

    def test_a_refused_transaction_names_the_edit_and_changes_nothing(self):
        with self.connect() as wall:
            with self.assertRaises(optique.Refused) as refused:
                with wall.transaction() as t:
                    t.create("ok", "cubes")
                    t.create("bad", "cubes", scale=0.0)
            self.assertEqual(refused.exception.edit, 1)
            self.assertEqual(refused.exception.field, "edits[1].create.transform.scale[0]")
            self.assertIn("must be in [0.0001, 10000] (got 0)", refused.exception.reason)
            self.assertEqual(len(wall.read_scene().instances), 0)
            with self.assertRaises(optique.Refused) as unknown:
                with wall.transaction() as t:
                    t.create("pot", "teapot")
            self.assertEqual(unknown.exception.reason, "no asset 'teapot' is loaded")
            with wall.transaction() as t:  # the session goes on
                t.create("after", "cubes")
                t.remove("after")

    def test_a_bad_name_or_bad_numbers_never_reach_the_master(self):
        with self.assertRaises(optique.SessionRefused) as refused:
            self.connect(name="two words")
        self.assertIn("name the application", refused.exception.reason)
        with self.connect() as wall:
            with self.assertRaises(ValueError):
                wall.transaction().create("x", "cubes", position=(1.0, 2.0))

    def test_frames_arrive_as_events_once_subscribed(self):
        with self.connect(name="listener") as wall:
            self.assertIsNone(wall.next_event(timeout=0.2), "nothing before subscribing")
            wall.subscribe(frames=True)
            frames = []
            while len(frames) < 10:
                event = wall.next_event(timeout=5)
                self.assertIsNotNone(event, "a frame event within 5 s")
                self.assertEqual(event.WhichOneof("event"), "frame_begun")
                frames.append(event.frame_begun)
            self.assertEqual([f.frame for f in frames], list(range(frames[0].frame, frames[0].frame + 10)))
            self.assertAlmostEqual(frames[0].period_ns, 1e9 / 60, delta=1)
            for a, b in zip(frames, frames[1:]):
                self.assertGreater(b.display_ns, a.display_ns)
            # Events that come while a reply is awaited are kept for next_event.
            with wall.transaction() as t:
                t.create("stamp", "cubes")
                t.remove("stamp")
            wall.subscribe()
            while wall.next_event(timeout=0.2) is not None:
                pass
            self.assertIsNone(wall.next_event(timeout=0.2), "none after unsubscribing")

    def test_the_viewer_travels_and_lights_switch(self):
        with self.connect() as wall:
            with wall.transaction() as t:
                t.navigate(position=(0.0, 0.0, -10.0), scale=2).switch_light(0, False)
            contents = wall.read_scene()
            self.assertEqual(list(contents.navigation.position), [0.0, 0.0, -10.0])
            self.assertEqual(list(contents.navigation.scale), [2.0, 2.0, 2.0])
            self.assertIn((0, False), [(l.light, l.on) for l in contents.lights])
            with self.assertRaises(optique.Refused) as refused:
                with wall.transaction() as t:
                    t.navigate(scale=(1, 2, 1))
            self.assertEqual(refused.exception.field, "edits[0].navigation.transform.scale")
            with self.assertRaises(optique.Refused) as refused:
                with wall.transaction() as t:
                    t.switch_light(contents.light_count, True)
            self.assertEqual(refused.exception.field, "edits[0].light.light")
            with wall.transaction() as t:
                t.navigate(position=(0, 0, 0), scale=1).switch_light(0, True)

    def test_a_point_light_is_added_moved_and_removed(self):
        with self.connect() as wall:
            first = wall.scene.light_count
            with wall.transaction() as t:
                t.point_light(first, position=(0, 2, 1), colour=(1, 0.5, 0), intensity=3).switch_light(first, False)
            added = wall.read_scene().point_lights
            self.assertEqual([(l.light, list(l.position), list(l.colour), l.intensity) for l in added],
                             [(first, [0.0, 2.0, 1.0], [1.0, 0.5, 0.0], 3.0)])
            with wall.transaction() as t:
                t.point_light(first, position=(1, 2, 1))
            self.assertEqual(list(wall.read_scene().point_lights[0].position), [1.0, 2.0, 1.0])
            with self.assertRaises(optique.Refused) as refused:
                with wall.transaction() as t:
                    t.point_light(first + 1, colour=(1, 1, 1))
            self.assertEqual(refused.exception.field, "edits[0].point_light.position")
            with self.assertRaises(ValueError):
                t.point_light(first, position=(1, 2))
            with wall.transaction() as t:
                t.remove_point_light(first)
            contents = wall.read_scene()
            self.assertEqual(len(contents.point_lights), 0)
            self.assertNotIn(first, [l.light for l in contents.lights], "its switch went with it")

    def test_an_instances_animation_is_paused_and_sought(self):
        with self.connect() as wall:
            asset = wall.scene.assets[0]
            with wall.transaction() as t:
                t.create("clip", asset).animate("clip", playing=False, seek=2.5)
            view = [i for i in wall.read_scene().instances if i.instance == "clip"][0]
            self.assertTrue(view.HasField("animation"))
            self.assertFalse(view.animation.playing)
            self.assertEqual(view.animation.position, 2.5)
            with self.assertRaises(optique.Refused) as refused:
                with wall.transaction() as t:
                    t.animate("clip", seek=-1)
            self.assertEqual(refused.exception.field, "edits[0].animation.seek")
            with wall.transaction() as t:
                t.remove("clip")

    def test_an_asset_is_loaded_from_the_masters_folder_and_refused_with_its_field(self):
        with self.connect() as wall:
            frame = wall.load_asset("torus-file", path="assets/torus/torus.gltf")
            self.assertIn("torus-file", wall.read_scene().assets)
            with wall.transaction() as t:
                t.create("ring", "torus-file", position=(0.0, 0.0, 0.3))
            self.assertGreaterEqual(t.frame, frame)
            with self.assertRaises(optique.Refused) as refused:
                wall.load_asset("elsewhere", path="../../etc/passwd")
            self.assertEqual(refused.exception.field, "load_asset.path")
            with self.assertRaises(optique.Refused) as refused:
                wall.load_asset("junk", glb=b"not a glb")
            self.assertEqual(refused.exception.field, "load_asset.glb")
            with self.assertRaises(ValueError):
                wall.load_asset("both", path="a.gltf", glb=b"glTF")
            with wall.transaction() as t:
                t.remove("ring")

    def test_the_circle_example(self):
        run = subprocess.run([sys.executable, str(EXAMPLES / "circle.py"), "--port", str(self.master.port),
                              "--seconds", "1.5"], capture_output=True, text=True, timeout=60)
        self.assertEqual(run.returncode, 0, run.stdout + run.stderr)
        self.assertIn("placed from frame", run.stdout)
        self.assertIn("loaded 'model-torus' from ", run.stdout)
        self.assertIn("switched a light 2 times", run.stdout)  # at 0 s and at 1 s
        with self.connect() as wall:
            contents = wall.read_scene()
            self.assertTrue(all(light.on for light in contents.lights), "every light on again at the end")
            names = {i.instance for i in contents.instances}
            self.assertEqual(names & {"orbit", "beacon"}, {"orbit", "beacon"})
            self.assertEqual({i.asset for i in contents.instances if i.instance == "orbit"}, {"model-torus"})
            with wall.transaction() as t:
                t.remove("orbit").remove("beacon")


def free_udp_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class InTheFlystickCave(unittest.TestCase):
    def test_the_flystick_example_flies_turns_and_comes_back(self):
        udp = free_udp_port()
        with tempfile.TemporaryDirectory(prefix="optique-flystick-") as folder:
            master = Master(pathlib.Path(folder), config=SOURCE / "configs" / "cave-flystick.json",
                            more=("--tracking-port", str(udp)))
            try:
                run = subprocess.run([sys.executable, str(EXAMPLES / "flystick.py"), "--port", str(master.port),
                                      "--tracking-port", str(udp), "--seconds", "0.8"],
                                     capture_output=True, text=True, timeout=60)
            finally:
                master.stop()
            self.assertEqual(run.returncode, 0, run.stdout + run.stderr + master.output())
            lines = run.stdout.splitlines()
            self.assertEqual(len(lines), 3, run.stdout)
            forward = [float(v) for v in lines[0].split("(")[1].split(")")[0].split(",")]
            self.assertLess(forward[2], -0.5, lines[0])  # 1.5 m/s along -z for most of 0.8 s
            self.assertIn("turned", lines[1])
            self.assertGreater(int(lines[1].split("turned ")[1].split(" ")[0]), 10, lines[1])
            self.assertIn("reset: the room is at (0.00, 0.00, 0.00) in the world, turned 0 degrees", lines[2])
            self.assertIn("buttons down [1]", lines[2])


class AtTheEnd(unittest.TestCase):
    def test_the_run_says_it_stops(self):
        with tempfile.TemporaryDirectory(prefix="optique-end-") as folder:
            master = Master(pathlib.Path(folder), frames=120)
            try:
                with optique.connect(port=master.port, name="watcher") as wall:
                    wall.subscribe(run=True)
                    event = wall.next_event(timeout=20)
                    self.assertIsNotNone(event)
                    self.assertEqual(event.WhichOneof("event"), "run")
                    self.assertEqual(event.run.state, optique.session_pb2.RunChanged.STOPPING)
                    self.assertIn("120 frames", event.run.reason)
                    with self.assertRaises(optique.ConnectionClosed):
                        wall.next_event(timeout=20)
            finally:
                self.assertEqual(master.wait(), 0, master.output())


class WithTheSharedSecret(unittest.TestCase):
    """With master.secret_file every application proves it holds the secret,
    and everything after its hello is sealed."""

    def test_only_the_secret_opens_a_session(self):
        with tempfile.TemporaryDirectory(prefix="optique-secret-") as folder:
            folder = pathlib.Path(folder)
            secret = folder / "secret"
            secret.write_text("correct horse battery staple\n")
            secret.chmod(0o600)
            wrong = folder / "wrong"
            wrong.write_text("not the installation's secret")
            wrong.chmod(0o600)
            config = json.loads(WALL.read_text())
            config["master"]["secret_file"] = str(secret)
            config["master"]["max_message_bytes"] = 65536
            (folder / "wall.json").write_text(json.dumps(config))
            master = Master(folder, config=folder / "wall.json")
            try:
                with optique.connect(port=master.port, name="sealed", secret_file=str(secret)) as wall:
                    with wall.transaction() as t:
                        t.create("c", "cubes", position=(0.0, 1.0, 0.0))
                    self.assertEqual([i.instance for i in wall.read_scene().instances], ["c"])
                    # An upload over the master's message size is refused, and the
                    # sealed session goes on in step (the seal's count skips it).
                    with self.assertRaises(optique.Refused) as too_large:
                        wall.load_asset("big", glb=b"glTF" + bytes(100_000))
                    self.assertEqual(too_large.exception.field, "request")
                    self.assertIn("more than the 65536 this master takes", too_large.exception.reason)
                    with wall.transaction() as t:
                        t.move("c", position=(0.5, 1.0, 0.0))
                    self.assertEqual(wall.read_scene().instances[0].transform.position[0], 0.5)
                with self.assertRaises(optique.SessionRefused) as without:
                    optique.connect(port=master.port, name="open")
                self.assertIn("requires the installation's shared secret", without.exception.reason)
                with self.assertRaises(optique.SessionRefused) as mistaken:
                    optique.connect(port=master.port, name="guess", secret_file=str(wrong))
                self.assertIn("secret", mistaken.exception.reason)
            finally:
                master.stop()


if __name__ == "__main__":
    unittest.main()
