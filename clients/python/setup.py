"""Generates the protocol's Python modules (optique/*_pb2.py) from the
repository's .proto files with protoc while the package is built, so that the
client and the master always speak the checkout's protocol."""

import pathlib
import shutil
import subprocess

from setuptools import setup
from setuptools.command.build_py import build_py

HERE = pathlib.Path(__file__).resolve().parent
PROTO_ROOT = HERE.parent.parent / "proto"
PROTOS = ["optique/config.proto", "optique/session.proto", "optique/wire.proto"]


class BuildWithProtocol(build_py):
    def run(self):
        super().run()
        protoc = shutil.which("protoc")
        if protoc is None:
            raise SystemExit("optique-client: protoc is needed to build this package "
                             "(Debian: apt install protobuf-compiler)")
        missing = [p for p in PROTOS if not (PROTO_ROOT / p).is_file()]
        if missing:
            raise SystemExit(f"optique-client: build it from an optique checkout; {PROTO_ROOT} lacks {missing}")
        out = pathlib.Path(self.build_lib)
        subprocess.run([protoc, f"-I{PROTO_ROOT}", f"--python_out={out}", *PROTOS], check=True)


setup(cmdclass={"build_py": BuildWithProtocol})
