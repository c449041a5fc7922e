"""Builds the covplan package with its gRPC stubs generated from the repository's proto/.

The stubs (covplan/v1/covplan_pb2.py, covplan_pb2_grpc.py) are written into the build tree,
never into the sources. They come from protoc and grpc_python_plugin (Debian's
protobuf-compiler and protobuf-compiler-grpc: the versions of the python3-protobuf and
python3-grpcio runtime) or else from grpc_tools.protoc. Debian 12's python3-grpc-tools
(1.14) is older than proto3 `optional` and cannot compile covplan.proto, hence protoc first.
COVPLAN_PROTO_DIR names another proto/ directory.
"""
import os
import shutil
import subprocess
import sys

from setuptools import setup
from setuptools.command.build_py import build_py

HERE = os.path.dirname(os.path.abspath(__file__))
PROTO = os.path.join("covplan", "v1", "covplan.proto")


def proto_dir():
    candidates = [os.environ.get("COVPLAN_PROTO_DIR", ""),
                  os.path.join(HERE, "..", "..", "proto")]
    for candidate in candidates:
        if candidate and os.path.isfile(os.path.join(candidate, PROTO)):
            return os.path.abspath(candidate)
    sys.exit("covplan: cannot find proto/covplan/v1/covplan.proto (build from the repository, "
             "or set COVPLAN_PROTO_DIR)")


def generate(out_dir):
    source = proto_dir()
    protoc, plugin = shutil.which("protoc"), shutil.which("grpc_python_plugin")
    if protoc and plugin:
        command = [protoc, f"-I{source}", f"--python_out={out_dir}", f"--grpc_out={out_dir}",
                   f"--plugin=protoc-gen-grpc={plugin}", os.path.join(source, PROTO)]
    else:
        command = [sys.executable, "-m", "grpc_tools.protoc", f"-I{source}",
                   f"--python_out={out_dir}", f"--grpc_python_out={out_dir}",
                   os.path.join(source, PROTO)]
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode != 0:
        sys.exit("covplan: generating the gRPC stubs failed (install protobuf-compiler and "
                 f"protobuf-compiler-grpc):\n$ {' '.join(command)}\n{result.stderr}")


class BuildWithStubs(build_py):
    def run(self):
        super().run()
        generate(self.build_lib)


setup(cmdclass={"build_py": BuildWithStubs})
