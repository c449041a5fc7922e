#!/usr/bin/python3
"""gRPC while the JSON API is abused: the same `covplan load` run (plans of a
shipped map from random starts) against covplan-server twice, alone and
while HTTP clients misbehave on its --http_port:

  - SLOW connections that send their request headers one byte a second (they
    hold a civetweb thread until its request timeout, then reconnect);
  - FLOOD threads that send, as fast as the server answers, malformed JSON,
    wrong types, a 2 MB body of garbage, unknown paths and DELETEs.

It prints both load summaries and what the abusers got back (HTTP statuses),
and how a polite JSON API client (ListMaps every 0.5 s) fared meanwhile, so
the gRPC figures can be compared directly (the two load runs use different
seeds: a repeated request would be answered from the remembered plans).

  /usr/bin/python3 scripts/bench/http_abuse_bench.py --server build/bin/covplan-server \\
      --client build/bin/covplan [--seconds 20] [--slow 24] [--flood 2]
"""
import argparse
import collections
import os
import socket
import subprocess
import sys
import threading
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "tests", "console"))
from harness import ROOT, Server  # noqa: E402

BAD = [
    ("POST", "/v1/Plan", b'{"mapId": '),                      # malformed JSON
    ("POST", "/v1/Plan", b'{"mapId": 5}'),                    # wrong type
    ("POST", "/v1/Plan", b'{"robot": {"toolWidthM": "wide"}}'),
    ("POST", "/v1/PutMap", b'{"map": {"raster": {"image": "' + b"A" * (2 << 20) + b'"}}}'),
    ("POST", "/v1/NoSuchMethod", b"{}"),
    ("DELETE", "/v1/ListMaps", b""),
    ("GET", "/v1/events", b""),
]


def request(port, method, path, body):
    with socket.create_connection(("127.0.0.1", port), timeout=30) as s:
        head = (f"{method} {path} HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n"
                f"Content-Length: {len(body)}\r\nConnection: close\r\n\r\n").encode()
        s.sendall(head + body)
        reply = b""
        while b"\r\n" not in reply:
            chunk = s.recv(4096)
            if not chunk:
                break
            reply += chunk
        return reply.split(b" ")[1].decode() if reply.startswith(b"HTTP/") else "none"


def flood(port, stop, counts, lock):
    k = 0
    while not stop.is_set():
        method, path, body = BAD[k % len(BAD)]
        k += 1
        try:
            status = request(port, method, path, body)
        except OSError as e:
            status = type(e).__name__
        with lock:
            counts[status] += 1


def slow(port, stop, counts, lock):
    head = b"POST /v1/ListMaps HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n"
    while not stop.is_set():
        try:
            with socket.create_connection(("127.0.0.1", port), timeout=30) as s:
                for byte in head:
                    if stop.is_set():
                        return
                    s.sendall(bytes([byte]))
                    time.sleep(1.0)
        except OSError:
            with lock:
                counts["slow connection cut"] += 1


def probe(port, stop, latencies, lock):
    """A well-behaved JSON API client: ListMaps every half second."""
    while not stop.is_set():
        t0 = time.monotonic()
        try:
            status = request(port, "POST", "/v1/ListMaps", b"{}")
        except OSError:
            status = "error"
        with lock:
            latencies.append((status, time.monotonic() - t0))
        time.sleep(0.5)


def load(args, server, seed):
    out = subprocess.run(
        [args.client, "load", "--server", f"127.0.0.1:{server.grpc_port}", "--map",
         os.path.join(ROOT, "maps", "small_rooms.yaml"), "--concurrency", "2", "--duration",
         str(args.seconds), "--random-start", "--seed", str(seed), "--tool-width", "0.4",
         "--time-limit", "0.2"],
        capture_output=True, text=True, check=True)
    return out.stdout.strip()


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--server", required=True)
    parser.add_argument("--client", required=True)
    parser.add_argument("--seconds", type=float, default=20)
    parser.add_argument("--slow", type=int, default=24)
    parser.add_argument("--flood", type=int, default=2)
    args = parser.parse_args()
    server = Server(args.server)
    try:
        print("gRPC load alone:\n" + load(args, server, seed=1))
        stop, lock, counts = threading.Event(), threading.Lock(), collections.Counter()
        latencies = []
        threads = [threading.Thread(target=slow, args=(server.http_port, stop, counts, lock))
                   for _ in range(args.slow)]
        threads += [threading.Thread(target=flood, args=(server.http_port, stop, counts, lock))
                    for _ in range(args.flood)]
        threads.append(threading.Thread(target=probe, args=(server.http_port, stop, latencies, lock)))
        for t in threads:
            t.start()
        time.sleep(2)
        print(f"\ngRPC load with {args.slow} slow HTTP clients and {args.flood} flooding ones:\n"
              + load(args, server, seed=2))
        stop.set()
        for t in threads:
            t.join()
        print("\nHTTP abusers got: " + ", ".join(f"{k}: {v}" for k, v in sorted(counts.items())))
        ok = sorted(t for status, t in latencies if status == "200")
        print(f"a polite client's ListMaps meanwhile: {len(ok)} of {len(latencies)} answered 200, "
              f"median {1000 * ok[len(ok) // 2]:.0f} ms, slowest {1000 * ok[-1]:.0f} ms" if ok else
              f"a polite client's ListMaps meanwhile: none of {len(latencies)} answered")
    finally:
        print(f"server exit code {server.stop()}")


if __name__ == "__main__":
    main()
