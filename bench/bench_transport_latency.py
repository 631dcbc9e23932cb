#!/usr/bin/env python3
"""Round-trip latency of the zenoh transport between two processes.

Starts `transport_latency_bench server` (listening) and `transport_latency_bench client`
(connecting) for each transport (tcp loopback, unix socket), and reports median / p90 / min
round-trip times for requests carrying 1,000 and 10,000 3-vectors of doubles (24 kB and
240 kB, echoed back). Standard library only.

    python3 bench/bench_transport_latency.py --build-dir build-transport
"""
import argparse
import json
import os
import socket
import subprocess
import sys
import tempfile
from pathlib import Path


def find_bench(build_dir: Path) -> Path:
    candidates = [
        build_dir / "bin" / "transport_latency_bench",
        build_dir / "protocol" / "transport" / "transport_latency_bench",
    ]
    for c in candidates:
        if c.is_file() and os.access(c, os.X_OK):
            return c
    found = sorted(build_dir.rglob("transport_latency_bench"))
    found = [f for f in found if f.is_file() and os.access(f, os.X_OK)]
    if found:
        return found[0]
    sys.exit(
        f"transport_latency_bench not found under {build_dir}; build the target first "
        f"(cmake --build {build_dir} --target transport_latency_bench)"
    )


def free_tcp_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def run_pair(bench: Path, label: str, endpoint: str, args) -> list:
    key = f"angio/bench-{os.getpid()}/{label}/echo"
    server = subprocess.Popen(
        [str(bench), "server", "--listen", endpoint, "--key", key],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        client = subprocess.run(
            [
                str(bench),
                "client",
                "--connect",
                endpoint,
                "--key",
                key,
                "--vectors",
                args.vectors,
                "--rounds",
                str(args.rounds),
                "--warmup",
                str(args.warmup),
                "--label",
                label,
            ],
            capture_output=True,
            text=True,
            timeout=args.timeout,
        )
        if client.returncode != 0:
            sys.exit(f"{label}: client failed ({client.returncode}): {client.stderr.strip()}")
        results = [json.loads(line) for line in client.stdout.splitlines() if line.startswith("{")]
        server.wait(timeout=30)
        if server.returncode != 0:
            sys.exit(f"{label}: server failed ({server.returncode}): {server.stderr.read().strip()}")
        return results
    finally:
        if server.poll() is None:
            server.kill()
            server.wait()


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--build-dir", default="build", type=Path, help="CMake build directory (default: build)")
    p.add_argument("--vectors", default="1000,10000", help="comma-separated numbers of 3-vectors")
    p.add_argument("--rounds", type=int, default=500, help="timed round trips per size")
    p.add_argument("--warmup", type=int, default=50, help="untimed round trips per size")
    p.add_argument("--timeout", type=float, default=300, help="seconds allowed per transport run")
    p.add_argument("--json", action="store_true", help="print raw JSON lines instead of a table")
    args = p.parse_args()

    bench = find_bench(args.build_dir)
    results = []
    with tempfile.TemporaryDirectory(prefix="angio-bench-", dir="/tmp") as tmp:
        results += run_pair(bench, "tcp", f"tcp/127.0.0.1:{free_tcp_port()}", args)
        results += run_pair(bench, "unix", f"unixsock-stream/{tmp}/bench.sock", args)

    if args.json:
        for r in results:
            print(json.dumps(r))
        return 0
    print(
        f"{'transport':<10}{'3-vectors':>10}{'bytes':>9}{'round trips':>13}"
        f"{'median us':>11}{'p90 us':>10}{'min us':>10}"
    )
    for r in results:
        print(
            f"{r['transport']:<10}{r['vectors']:>10}{r['bytes']:>9}{r['round_trips']:>13}"
            f"{r['median_us']:>11.1f}{r['p90_us']:>10.1f}{r['min_us']:>10.1f}"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
