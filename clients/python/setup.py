"""Builds the covplan package with its gRPC stubs generated from the repository's proto/.

The stubs (covplan/v1/covplan_pb2.py, covplan_pb2_grpc.py) are written into the build tree,
never into the sources (but for an editable install). They come from protoc and grpc_python_plugin (Debian's
protobuf-compiler and protobuf-compiler-grpc: the versions of the python3-protobuf and
python3-grpcio runtime) or else from grpc_tools.protoc. Debian 12's python3-grpc-tools
(1.14) is older than proto3 `optional` and cannot compile covplan.proto, hence protoc first,
unless it belongs to another protobuf release than the installed runtime.
COVPLAN_PROTO_DIR names another proto/ directory.
"""
import os
import re
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


def _release(version):
    """The protobuf release a version string belongs to: protoc 3.21.x and the Python
    runtime 3.21.x / 4.21.x are release 21; protoc 25.x and runtime 4.25.x / 5.25.x, 25."""
    parts = [int(p) for p in re.findall(r"\d+", version)[:2]] + [0, 0]
    return parts[1] if parts[0] in (3, 4, 5) and parts[1] >= 0 else parts[0]


def protoc_matches_runtime(protoc):
    """Whether `protoc` generates code for the installed protobuf runtime's release."""
    try:
        import google.protobuf
        out = subprocess.run([protoc, "--version"], capture_output=True, text=True).stdout
        return _release(out.split()[-1]) == _release(google.protobuf.__version__)
    except (ImportError, OSError, IndexError):
        return True  # nothing to compare against: let protoc try


def generate(out_dir):
    source = proto_dir()
    protoc, plugin = shutil.which("protoc"), shutil.which("grpc_python_plugin")
    if protoc and plugin and not protoc_matches_runtime(protoc):
        print(f"covplan: {protoc} is another protobuf release than the Python runtime; "
              "trying grpc_tools.protoc", file=sys.stderr)
        protoc = None
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
        # An editable install (pip install -e) imports from the sources: generate there
        # (ignored by git); otherwise into the build tree the wheel is made from.
        generate(HERE if getattr(self, "editable_mode", False) else self.build_lib)


setup(cmdclass={"build_py": BuildWithStubs})
