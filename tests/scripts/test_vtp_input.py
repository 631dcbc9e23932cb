#!/usr/bin/python3
"""VTK XML PolyData input (scripts/patient/surface_file.py, centerline_vtp.py): lumen surfaces and
centerlines as SimVascular and VMTK write them, read through VTK.

Consistency checks: a stenosed tube written as VTP with quadrilateral facets and a point array reads
as the same checked surface as its STL triangulation (same vertices, two triangles per quad, the same
two boundary loops) with the array on the right vertices; a centerline polyline with VMTK's
MaximumInscribedSphereRadius reads as the same centerline as its CSV (points, radius, wall), also
through the patient pipeline (patient.centerline: a .vtp becomes the CSV the rest reads). Refusals
(PatientInputError naming the file): two polylines (a branching centerline), no radius array (the
arrays present listed), a negative radius (the point named), a file that is not VTK XML.
Usage: test_vtp_input.py   (a few seconds)
"""
import os
import shutil
import sys
import tempfile
import unittest
from pathlib import Path

import meshio
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
from patient.centerline_csv import read_centerline_csv, write_centerline_csv  # noqa: E402
from patient.centerline_vtp import read_centerline_vtp  # noqa: E402
from patient.errors import PatientInputError  # noqa: E402
from patient.lumen_sections import point_array  # noqa: E402
from patient.lumen_surface import read_lumen_surface  # noqa: E402
from patient.prepare import lumen_csv  # noqa: E402
from patient.surface_file import write_vtp  # noqa: E402

NC, NA, LENGTH = 24, 30, 10.0


def tube_quads():
    """Points and quadrilaterals of a straight tube (axis z) with a 40 % cosine stenosis."""
    z = np.linspace(0.0, LENGTH, NA + 1)
    r = 1.5 * (1 - 0.4 * 0.5 * (1 + np.cos(np.pi * np.clip((z - LENGTH / 2) / 2.0, -1, 1))))
    phi = np.linspace(0, 2 * np.pi, NC, endpoint=False)
    pts = np.array([[r[i] * np.cos(p), r[i] * np.sin(p), z[i]] for i in range(NA + 1) for p in phi])
    quads = np.array(
        [
            [i * NC + j, i * NC + (j + 1) % NC, (i + 1) * NC + (j + 1) % NC, (i + 1) * NC + j]
            for i in range(NA)
            for j in range(NC)
        ]
    )
    return pts, quads


class VtpInput(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="angio-vtp-")

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def path(self, name):
        return os.path.join(self.tmp, name)

    def test_surface_as_vtp_equals_its_stl(self):
        pts, quads = tube_quads()
        wall = 0.3 + 0.1 * pts[:, 0]  # varies around the vessel: tells vertices apart
        vtp = read_lumen_surface(
            write_vtp(self.path("lumen.vtp"), pts, polys=quads, point_data={"wall_thickness": wall})
        )
        tris = np.concatenate([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])
        stl_path = self.path("lumen.stl")
        meshio.write(stl_path, meshio.Mesh(pts, [("triangle", tris)]))
        stl = read_lumen_surface(stl_path)
        self.assertEqual(len(vtp.triangles), 2 * len(quads))  # every quad split in two
        self.assertEqual(len(vtp.points), len(pts))
        order = lambda p: np.lexsort(np.round(p, 9).T)  # noqa: E731
        np.testing.assert_allclose(vtp.points[order(vtp.points)], stl.points[order(stl.points)], atol=1e-6)
        self.assertEqual(sorted(len(lp) for lp in vtp.loops), [NC, NC])
        got = point_array(vtp.path, vtp, "wall_thickness", "the wall thickness")
        np.testing.assert_allclose(got, 0.3 + 0.1 * vtp.points[:, 0], atol=1e-12)
        with self.assertRaisesRegex(
            PatientInputError, "lumen.vtp: expected a point data array 'plaque'.*wall_thickness"
        ):
            point_array(vtp.path, vtp, "plaque", "labels")

    def centerline(self):
        s = np.linspace(0.0, 12.0, 25)
        pts = np.column_stack([np.sin(s / 6.0), np.zeros_like(s), s])
        return pts, 1.2 - 0.02 * s, 0.5 + 0.01 * s

    def test_centerline_as_vtp_equals_its_csv(self):
        pts, r, wall = self.centerline()
        csv_path = self.path("cl.csv")
        write_centerline_csv(csv_path, pts, r, wall=wall)
        ref = read_centerline_csv(csv_path)
        # points stored out of order: the polyline's ids give the order
        perm = np.random.default_rng(1).permutation(len(pts))
        inv = np.argsort(perm)
        vtp_path = write_vtp(
            self.path("cl.vtp"),
            pts[perm],
            lines=[inv],
            point_data={"MaximumInscribedSphereRadius": r[perm], "wall": wall[perm]},
        )
        got = read_centerline_vtp(vtp_path)
        np.testing.assert_allclose(got.points, ref.points, atol=1e-6)  # the CSV keeps 6 decimals
        np.testing.assert_allclose(got.radius, ref.radius, atol=1e-6)
        np.testing.assert_allclose(got.wall, ref.wall, atol=1e-6)
        # through the patient pipeline: the VTP becomes the CSV the rest of it reads
        out, sections, labels = lumen_csv(
            {"centerline": "cl.vtp", "lumen_surface": None}, Path(self.tmp, "scene.yaml"), Path(self.tmp), print
        )
        self.assertEqual(os.path.basename(out), "lumen_from_centerline.csv")
        self.assertIsNone(sections)
        np.testing.assert_allclose(read_centerline_csv(out).radius, ref.radius, atol=1e-6)

    def test_bad_centerlines_are_refused(self):
        pts, r, _ = self.centerline()
        ids = np.arange(len(pts))
        two = write_vtp(self.path("two.vtp"), pts, lines=[ids[:12], ids[12:]], point_data={"radius": r})
        with self.assertRaisesRegex(PatientInputError, "two.vtp: expected one centerline polyline .* got 2"):
            read_centerline_vtp(two)
        none = write_vtp(self.path("none.vtp"), pts, lines=[ids], point_data={"Abscissas": r})
        with self.assertRaisesRegex(
            PatientInputError, "none.vtp: expected a point data array with the lumen radius.*Abscissas"
        ):
            read_centerline_vtp(none)
        neg = r.copy()
        neg[7] = -0.1
        bad = write_vtp(self.path("neg.vtp"), pts, lines=[ids], point_data={"r": neg})
        with self.assertRaisesRegex(PatientInputError, "neg.vtp: point 7: radius: expected a positive lumen radius"):
            read_centerline_vtp(bad)
        junk = self.path("junk.vtp")
        with open(junk, "w") as f:
            f.write("solid not a vtp\n")
        with self.assertRaisesRegex(PatientInputError, "junk.vtp: cannot read"):
            read_centerline_vtp(junk)
        with self.assertRaisesRegex(PatientInputError, "junk.vtp: cannot read"):
            read_lumen_surface(junk)
        with self.assertRaisesRegex(PatientInputError, "missing.vtp: no such file"):
            read_lumen_surface(self.path("missing.vtp"))


if __name__ == "__main__":
    unittest.main(verbosity=2)
