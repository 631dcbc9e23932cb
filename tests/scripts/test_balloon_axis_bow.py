#!/usr/bin/python3
"""bench/balloon_axis_bow.py on a synthetic run directory (no solver; stdlib unittest + h5py).

A curved balloon is written as rings of nodes around a circular-arc centerline of radius 15 mm
(solid.h5 layout of the solid solver: /mesh/coordinates, /mesh/hex8/{connectivity, block_id},
/steps/<k>/displacement with attribute time). Checked against closed forms: at step 0 the axis
radius of the whole balloon and of each half is the arc's 15 mm; a step whose displacement maps
every node onto a straight tube of the same length gives an infinite radius (printed as inf); a
rigid translation leaves the radius unchanged. The kernels alone: the circle through three points
of a circle of radius R has radius R; the arc length of a point projected on a polyline.
"""
import json
import math
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

import h5py
import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "bench"))
from balloon_axis_bow import arc_length_of, circle_radius  # noqa: E402

R, LENGTH, N_RING, N_AXIAL, r_tube = 15.0, 18.0, 12, 73, 0.49


def arc(s):
    """Point and frame of the arc (x-y plane, centre (0, R, 0)) at arc length s."""
    a = s / R
    p = np.array([R * math.sin(a), R - R * math.cos(a), 0.0])
    t = np.array([math.cos(a), math.sin(a), 0.0])
    n = np.array([-math.sin(a), math.cos(a), 0.0])
    return p, t, n


def tube_nodes(straight):
    nodes = []
    for k in range(N_AXIAL):
        s = LENGTH * k / (N_AXIAL - 1)
        p, t, n = (np.array([s, 0.0, 0.0]), np.array([1.0, 0, 0]), np.array([0, 1.0, 0])) if straight else arc(s)
        b = np.cross(t, n)
        for j in range(N_RING):
            phi = 2 * math.pi * j / N_RING
            nodes.append(p + r_tube * (math.cos(phi) * n + math.sin(phi) * b))
    return np.array(nodes)


class Kernels(unittest.TestCase):
    def test_circle_radius(self):
        pts = [arc(s)[0] for s in (1.0, 7.0, 16.0)]
        self.assertAlmostEqual(circle_radius(*pts), R, places=9)
        self.assertEqual(circle_radius(np.zeros(3), np.array([1.0, 0, 0]), np.array([2.0, 0, 0])), float("inf"))

    def test_arc_length_of(self):
        line = np.array([arc(s)[0] for s in np.linspace(0, 24, 97)])
        s = arc_length_of(np.array([arc(5.0)[0] + 0.3 * arc(5.0)[2], arc(12.5)[0]]), line)
        # the polyline is made of h = 0.25 mm chords: a point on the arc projects to within the
        # chord's sagitta h²/8R = 5e-4 mm of its arc length; a chord turns by up to h/2R from the
        # tangent, so a point d = 0.3 mm off the arc moves by up to d·h/2R = 2.5e-3 mm more
        self.assertAlmostEqual(s[1], 12.5, delta=5e-4)
        self.assertAlmostEqual(s[0], 5.0, delta=3e-3)


class Script(unittest.TestCase):
    def test_curved_straight_and_moved(self):
        with tempfile.TemporaryDirectory() as tmp:
            run = Path(tmp)
            line = np.array([arc(s)[0] for s in np.linspace(0, LENGTH, 145)])
            np.savetxt(run / "centerline.txt", line)
            (run / "scene.yaml").write_text("balloon:\n  mesh: {generator: tube, centerline: {file: centerline.txt}}\n")
            (run / "solid").mkdir()
            (run / "solid" / "summary.json").write_text(
                json.dumps({"blocks": [{"id": 0, "name": "balloon", "part": "balloon"}]})
            )
            X = tube_nodes(straight=False)
            # two 8-node cells per ring cover its 12 nodes: every node belongs to the balloon block
            conn = np.array([[q * N_RING + j + o for j in range(8)] for q in range(N_AXIAL) for o in (0, N_RING - 8)])
            with h5py.File(run / "solid" / "solid.h5", "w") as f:
                f["mesh/coordinates"] = X
                f["mesh/hex8/connectivity"] = conn
                f["mesh/hex8/block_id"] = np.zeros(len(conn), dtype=int)
                for k, (t, u) in enumerate(
                    [
                        (0.0, np.zeros_like(X)),
                        (1.0, tube_nodes(straight=True) - X),
                        (2.0, np.tile([3.0, -1.0, 0.5], (len(X), 1))),
                    ]
                ):
                    g = f.create_group(f"steps/{k}")
                    g.attrs["time"] = t
                    g["displacement"] = u
            r = subprocess.run(
                [sys.executable, str(ROOT / "bench" / "balloon_axis_bow.py"), str(run)],
                capture_output=True,
                text=True,
            )
            self.assertEqual(r.returncode, 0, r.stderr)
            rows = [line.split() for line in r.stdout.splitlines() if line and line[0] == " " and "time" not in line]
            self.assertEqual(len(rows), 3, r.stdout)
            for v in rows[0][1:4] + rows[2][1:4]:
                # printed to 0.01 mm; a station's centroid (three rings 0.25 mm apart on the arc) lies
                # 1.4e-3 mm inside the arc, so the circle through three of them has R - 1.4e-3
                self.assertAlmostEqual(float(v), R, delta=0.01, msg=r.stdout)
            for v in rows[1][1:4]:
                self.assertEqual(v, "inf")


if __name__ == "__main__":
    unittest.main()
