#!/usr/bin/python3
"""Participants on different hosts: the coupler, the beam and the solid (2 ranks) of the tiny coupled
scene each in its own network namespace, joined by a bridge (10.201.0.0/24), talking over tcp
endpoints only (launch.py --endpoint), as they would from three nodes of a cluster.

Consistency check: the run ends where the same scene run on one host ends (stent diameter equal to
1e-9 mm; the same executables, the same messages, only the route differs). Needs root and iproute2
(`ip netns`); where namespaces cannot be made the test fails saying why, it is not skipped.
Usage: test_network_namespaces.py BIN_DIR   (about 20 s)
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest
import uuid

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCENE = os.path.join(ROOT, "tests", "integration", "data", "tiny_coupled.yaml")
LAUNCH = [sys.executable, os.path.join(ROOT, "scripts", "launch.py")]
BIN = None


def ip(*args):
    out = subprocess.run(["ip", *args], capture_output=True, text=True)
    if out.returncode != 0:
        raise RuntimeError(f"ip {' '.join(args)}: {out.stderr.strip()}")


class Namespaces:
    """Three namespaces: coupler (bridge br0, 10.201.0.1), beam (.2), solid (.3)."""

    def __init__(self):
        tag = uuid.uuid4().hex[:4]
        self.names = {k: f"angio-{k}-{tag}" for k in ("c", "b", "s")}
        self.tag = tag

    def __enter__(self):
        c = self.names["c"]
        try:
            for n in self.names.values():
                ip("netns", "add", n)
                ip("-n", n, "link", "set", "lo", "up")
            ip("-n", c, "link", "add", "br0", "type", "bridge")
            ip("-n", c, "addr", "add", "10.201.0.1/24", "dev", "br0")
            ip("-n", c, "link", "set", "br0", "up")
            for k, host in (("b", 2), ("s", 3)):
                inner, outer = f"v{k}{self.tag}", f"v{k}{self.tag}c"
                ip("link", "add", inner, "type", "veth", "peer", "name", outer)
                ip("link", "set", inner, "netns", self.names[k])
                ip("link", "set", outer, "netns", c)
                ip("-n", c, "link", "set", outer, "master", "br0")
                ip("-n", c, "link", "set", outer, "up")
                ip("-n", self.names[k], "addr", "add", f"10.201.0.{host}/24", "dev", inner)
                ip("-n", self.names[k], "link", "set", inner, "up")
        except (RuntimeError, OSError) as e:
            self.__exit__()
            raise AssertionError(f"cannot set up network namespaces (root and iproute2 needed): {e}")
        return self

    def exec(self, k):
        return ["ip", "netns", "exec", self.names[k]]

    def __exit__(self, *exc):
        for n in self.names.values():
            subprocess.run(["ip", "netns", "del", n], capture_output=True)
        return False


def final_diameter(run_dir):
    with open(os.path.join(run_dir, "results.json")) as f:
        return json.load(f)["stent"]["final"]


class NetworkNamespaces(unittest.TestCase):
    def test_participants_in_three_network_namespaces(self):
        tmp = tempfile.mkdtemp(prefix="angio-netns-")
        build = os.path.dirname(BIN)
        try:
            here = os.path.join(tmp, "one_host")
            r = subprocess.run(
                LAUNCH + [SCENE, "--run-dir", here, "--build-dir", build], capture_output=True, text=True
            )
            self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
            with Namespaces() as ns:
                # the solid's ranks talk to each other inside their namespace; rank 0 to the coupler over tcp
                mpirun = "mpirun -n 2 --oversubscribe --bind-to none" + (
                    " --allow-run-as-root" if os.geteuid() == 0 else ""
                )
                apart = os.path.join(tmp, "three_hosts")
                cmd = (
                    ns.exec("c")
                    + LAUNCH
                    + [
                        SCENE,
                        "--run-dir",
                        apart,
                        "--build-dir",
                        build,
                        "--endpoint",
                        "tcp/10.201.0.1:7447",
                        "--log-level",
                        "debug",
                        "--beam-cmd",
                        " ".join(ns.exec("b") + [os.path.join(BIN, "beam_solver")]),
                        "--solid-cmd",
                        " ".join(ns.exec("s") + mpirun.split() + [os.path.join(BIN, "solid_solver")]),
                    ]
                )
                r = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
                self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
            with open(os.path.join(apart, "solid_solver.log")) as f:
                self.assertIn("via tcp/10.201.0.1:7447", f.read())  # the solid served the coupler over the bridge
            self.assertAlmostEqual(final_diameter(apart), final_diameter(here), delta=1e-9)
        finally:
            shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit("usage: test_network_namespaces.py BIN_DIR")
    BIN = os.path.abspath(sys.argv.pop(1))
    unittest.main(verbosity=2)
