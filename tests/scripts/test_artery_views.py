#!/usr/bin/python3
"""The artery pictures of the report (scripts/artery_views.py) on synthetic solid.h5 files.

Exact counts: the boundary of a structured hex8 tube (n_circ x n_axial x n_radial) has
2 n_circ n_axial faces on its inner and outer surfaces and 2 n_circ n_radial on its ends; two tets
sharing a face have 6 boundary faces. The cut plane of a straight tube contains its axis, and
the far half holds half the boundary faces. render() writes one PNG per view from a run directory
with solid.h5 (and without beam output), and none, without an error, when no step was written.
Usage: test_artery_views.py   (a few seconds)
"""
import os
import sys
import tempfile
import unittest
from pathlib import Path

import h5py
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
from artery_views import boundary_faces, cut_frame, render  # noqa: E402

NC, NA, NR = 16, 6, 2


def hex_tube(ri=1.0, ro=1.5, length=4.0):
    """Nodes and hex8 connectivity of a structured tube along z."""
    th = np.linspace(0, 2 * np.pi, NC, endpoint=False)
    r = np.linspace(ri, ro, NR + 1)
    z = np.linspace(-length / 2, length / 2, NA + 1)
    idx = lambda i, j, k: (k * (NR + 1) + j) * NC + i % NC  # noqa: E731
    X = np.array([[rr * np.cos(t), rr * np.sin(t), zz] for zz in z for rr in r for t in th])
    conn = []
    for k in range(NA):
        for j in range(NR):
            for i in range(NC):
                conn.append(
                    [idx(i, j, k), idx(i + 1, j, k), idx(i + 1, j + 1, k), idx(i, j + 1, k)]
                    + [idx(i, j, k + 1), idx(i + 1, j, k + 1), idx(i + 1, j + 1, k + 1), idx(i, j + 1, k + 1)]
                )
    return X, np.array(conn)


def solid_run(run, times):
    """A run directory whose solid.h5 holds the hex tube (block 0, "media") and one output step per
    time: a radial displacement and a nodal stress growing along z."""
    X, conn = hex_tube()
    (run / "solid").mkdir()
    with h5py.File(run / "solid" / "solid.h5", "w") as f:
        f["/mesh/coordinates"] = X
        f["/mesh/hex8/connectivity"] = conn
        f["/mesh/hex8/block_id"] = np.zeros(len(conn), dtype=np.int32)
        for k, t in enumerate(times):
            g = f.create_group(f"/steps/{k}")
            g.attrs["time"] = t
            g["displacement"] = 0.1 * t * X * np.array([1, 1, 0])
            g["stress_p1_nodal_media"] = X[:, 2] + t
    return run


class ArteryViews(unittest.TestCase):
    def test_boundary_faces_counted_exactly(self):
        X, conn = hex_tube()
        faces = boundary_faces(conn, "hex8")
        self.assertEqual(len(faces), 2 * NC * NA + 2 * NC * NR)
        two_tets = np.array([[0, 1, 2, 3], [1, 2, 3, 4]])
        self.assertEqual(len(boundary_faces(two_tets, "tet4")), 6)

    def test_cut_plane_contains_the_axis(self):
        X, conn = hex_tube()
        c, axis, normal = cut_frame(X)
        self.assertAlmostEqual(abs(axis[2]), 1.0, places=9)
        self.assertAlmostEqual(normal[2], 0.0, places=9)
        faces = boundary_faces(conn, "hex8")
        far = [f for f in faces if (X[f].mean(axis=0) - c) @ normal < 0]
        self.assertAlmostEqual(len(far) / len(faces), 0.5, delta=2 / NC)

    def test_no_step_written_no_picture(self):
        """A run stopped before its first output step: no picture, no error."""
        with tempfile.TemporaryDirectory() as tmp:
            run = solid_run(Path(tmp), times=())
            self.assertEqual(render(run, [("peak", 1.0)], {0: "media"}, ["a.png"]), [])

    def test_render_writes_the_views(self):
        with tempfile.TemporaryDirectory() as tmp:
            run = solid_run(Path(tmp), times=(1.0, 2.0))
            names = render(run, [("peak", 1.0), ("after", 2.0)], {0: "media"}, ["a.png", "b.png"])
            self.assertEqual(names, ["a.png", "b.png"])
            for n in names:
                self.assertGreater((run / n).stat().st_size, 10000)


if __name__ == "__main__":
    unittest.main(verbosity=2)
