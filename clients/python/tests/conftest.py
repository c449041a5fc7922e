"""A covplan-server for the Python client's tests: started once per run on a free port with
a store of its own (COVPLAN_SERVER names the binary; default build/bin/covplan-server), and
a second one with TLS and bearer tokens when openssl can make certificates. Sessions idle
for 3 s end (--session_idle_s), so a test can see one end."""
import hashlib
import os
import shutil
import socket
import subprocess
import tempfile
import time

import pytest

import covplan

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))))
MAPS = os.path.join(ROOT, "maps")
TOKEN = "py-client-test-token"


SERVER_BINARY = os.environ.get("COVPLAN_SERVER", os.path.join(ROOT, "build/bin/covplan-server"))


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Server:
    def __init__(self, *flags):
        binary = SERVER_BINARY
        if not os.access(binary, os.X_OK):
            pytest.fail(f"no covplan-server at {binary} (set COVPLAN_SERVER)")
        self.dir = tempfile.mkdtemp(prefix="covplan-py-")
        self.port = free_port()
        self.address = f"127.0.0.1:{self.port}"
        self.log = open(os.path.join(self.dir, "server.log"), "w+")
        self.proc = subprocess.Popen(
            [binary, f"--port={self.port}", "--metrics_port=-1", f"--store_dir={self.dir}/maps",
             "--threads=2", "--session_idle_s=3", *flags], stdout=self.log,
            stderr=subprocess.STDOUT)

    def wait(self, client):
        deadline = time.monotonic() + 60
        while True:
            if self.proc.poll() is not None:
                raise RuntimeError("covplan-server exited: " + self.output())
            try:
                client.list_maps(timeout=2)
                return
            except covplan.Unavailable:
                if time.monotonic() > deadline:
                    raise RuntimeError("covplan-server did not answer: " + self.output())
                time.sleep(0.2)

    def output(self):
        self.log.seek(0)
        return self.log.read()[-4000:]

    def stop(self):
        self.proc.terminate()
        try:
            self.proc.wait(timeout=60)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        self.log.close()
        shutil.rmtree(self.dir, ignore_errors=True)


@pytest.fixture(scope="session")
def server():
    process = Server()
    with covplan.Client(process.address) as client:
        process.wait(client)
    yield process
    process.stop()


@pytest.fixture
def client(server):
    with covplan.Client(server.address, timeout=60) as c:
        yield c


@pytest.fixture(scope="session")
def office_id(server):
    with covplan.Client(server.address) as c:
        return c.put_map(os.path.join(MAPS, "sample_office.yaml")).map_id


def make_certificates(directory):
    """A CA and a server certificate for 127.0.0.1 signed by it (openssl CLI)."""
    script = f"""set -e; cd {directory}
openssl genpkey -algorithm EC -pkeyopt ec_paramgen_curve:prime256v1 -out ca.key
openssl req -x509 -new -key ca.key -out ca.pem -days 2 -subj /CN=covplan-test-ca
openssl genpkey -algorithm EC -pkeyopt ec_paramgen_curve:prime256v1 -out server.key
openssl req -new -key server.key -out server.csr -subj /CN=127.0.0.1
printf 'subjectAltName=IP:127.0.0.1,DNS:localhost\\n' > san.cnf
openssl x509 -req -in server.csr -CA ca.pem -CAkey ca.key -CAcreateserial -out server.pem \
  -days 2 -extfile san.cnf"""
    result = subprocess.run(["bash", "-c", script], capture_output=True, text=True)
    if result.returncode != 0:
        pytest.fail("openssl could not make test certificates: " + result.stderr)


@pytest.fixture(scope="session")
def secure_server():
    directory = tempfile.mkdtemp(prefix="covplan-py-tls-")
    make_certificates(directory)
    with open(os.path.join(directory, "tokens"), "w") as f:
        f.write(f"{hashlib.sha256(TOKEN.encode()).hexdigest()} tenant-py\n")
    process = Server(f"--tls_cert={directory}/server.pem", f"--tls_key={directory}/server.key",
                     f"--token_file={directory}/tokens")
    process.ca = os.path.join(directory, "ca.pem")
    with covplan.Client(process.address, token=TOKEN, root_certificates=process.ca) as c:
        process.wait(c)
    yield process
    process.stop()
    shutil.rmtree(directory, ignore_errors=True)
