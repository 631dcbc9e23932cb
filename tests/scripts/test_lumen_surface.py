#!/usr/bin/python3
"""Lumen surfaces without a centerline (scripts/patient/lumen_surface.py, lumen_centerline.py and the
scripts/lumen_centerline.py command).

Analytic check: a curved tube (centerline an arc of radius 20 mm over 0.6 rad, lumen radius 1.5 mm with a
40 % cosine stenosis over 4 mm) triangulated with 48 segments around, written as STL: the centerline found
from the surface alone lies within 0.02 mm of the arc, its length within 1 % of 12 mm, and its radius
within 1 % of the equivalent radius of the 48-gon sections (sqrt(A/pi)), the stenosis included.
Robustness: the same surface in metres is refused (exit 2, "metres") and accepted with --units m (the
same centerline to 1e-6 mm); a closed surface, a surface open at one end only, a non-manifold edge and
two separate pieces are refused naming the file; triangles of mixed orientation are reoriented.
Usage: test_lumen_surface.py   (about 20 s)
"""
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

import meshio
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
from patient.centerline_csv import read_centerline_csv  # noqa: E402
from patient.errors import PatientInputError  # noqa: E402
from patient.lumen_surface import read_lumen_surface  # noqa: E402

CMD = [sys.executable, os.path.join(ROOT, "scripts", "lumen_centerline.py")]
RC, ANGLE, NC, NA = 20.0, 0.6, 48, 120
LENGTH = RC * ANGLE


def radius(s):
    x = (s - LENGTH / 2) / 2.0
    return 1.5 * (1 - 0.4 * np.where(np.abs(x) < 1, 0.5 * (1 + np.cos(np.pi * x)), 0.0))


def tube(caps=0):
    """Points and triangles of the curved stenosed tube; caps: 0, 1 or 2 ends closed by a fan."""
    s = np.linspace(0, LENGTH, NA + 1)
    th = s / RC
    phi = np.linspace(0, 2 * np.pi, NC, endpoint=False)
    pts = []
    for i in range(NA + 1):
        c = np.array([RC * np.cos(th[i]), RC * np.sin(th[i]), 0.0])
        n1 = np.array([np.cos(th[i]), np.sin(th[i]), 0.0])
        for p in phi:
            pts.append(c + radius(s[i]) * (np.cos(p) * n1 + np.sin(p) * np.array([0, 0, 1.0])))
    tris = []
    for i in range(NA):
        for j in range(NC):
            a, b, c, d = i * NC + j, i * NC + (j + 1) % NC, (i + 1) * NC + j, (i + 1) * NC + (j + 1) % NC
            tris += [[a, b, d], [a, d, c]]
    pts = np.array(pts)
    for end in range(caps):
        ring = np.arange(NC) + (0 if end == 0 else NA * NC)
        centre = len(pts)
        pts = np.vstack([pts, pts[ring].mean(axis=0)])
        tris += [
            [ring[(j + 1) % NC], ring[j], centre] if end == 0 else [ring[j], ring[(j + 1) % NC], centre]
            for j in range(NC)
        ]
    return pts, np.array(tris)


class LumenSurface(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="angio-lumen-")

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def write(self, pts, tris, name="lumen.stl"):
        path = os.path.join(self.tmp, name)
        meshio.write(path, meshio.Mesh(pts, [("triangle", tris)]))
        return path

    def run_cmd(self, surface, *extra):
        out = os.path.join(self.tmp, "cl.csv")
        r = subprocess.run(CMD + [surface, "-o", out, *extra], capture_output=True, text=True)
        return r, out

    def test_centerline_and_radius_of_a_curved_stenosed_tube(self):
        r, out = self.run_cmd(self.write(*tube()))
        self.assertEqual(r.returncode, 0, r.stderr)
        cl = read_centerline_csv(out)  # the pipeline's own reader takes it
        p, rad = cl.points, cl.radius
        off_axis = np.abs(np.hypot(p[:, 0], p[:, 1]) - RC) + np.abs(p[:, 2])
        self.assertLess(off_axis.max(), 0.02)
        self.assertLess(abs(cl.arc_length[-1] - LENGTH) / LENGTH, 0.01)
        s = np.arctan2(p[:, 1], p[:, 0]) * RC
        polygon = radius(s) * np.sqrt(NC / (2 * np.pi) * np.sin(2 * np.pi / NC))  # equivalent radius of the 48-gon
        self.assertLess(np.max(np.abs(rad - polygon) / polygon), 0.01)
        self.assertAlmostEqual(rad.min() / rad.max(), 0.6, delta=0.01)  # the 40 % stenosis

    def test_units(self):
        pts, tris = tube()
        r, _ = self.run_cmd(self.write(pts / 1000.0, tris, "metres.stl"))
        self.assertEqual(r.returncode, 2)
        self.assertIn("metres.stl", r.stderr)
        self.assertIn("in metres", r.stderr)
        self.assertNotIn("Traceback", r.stderr)
        r, out = self.run_cmd(os.path.join(self.tmp, "metres.stl"), "--units", "m")
        self.assertEqual(r.returncode, 0, r.stderr)
        in_m = read_centerline_csv(out)
        r, out = self.run_cmd(self.write(pts, tris))
        in_mm = read_centerline_csv(out)
        self.assertLess(np.abs(in_m.points - in_mm.points).max(), 1e-5)

    def test_bad_surfaces_are_refused(self):
        pts, tris = tube(caps=2)
        with self.assertRaisesRegex(PatientInputError, r"\(2 boundary loops\), got 0"):
            read_lumen_surface(self.write(pts, tris, "closed.stl"))
        pts, tris = tube(caps=1)
        with self.assertRaisesRegex(PatientInputError, r"\(2 boundary loops\), got 1"):
            read_lumen_surface(self.write(pts, tris, "one_end.stl"))
        pts, tris = tube()
        hole = np.ones(len(tris), dtype=bool)
        hole[2 * NC * (NA // 2) : 2 * NC * (NA // 2) + 6] = False  # a side hole: the stub of a branch
        with self.assertRaisesRegex(PatientInputError, r"got 3 \(side branches or holes"):
            read_lumen_surface(self.write(pts, tris[hole], "branch.stl"))
        extra = np.vstack([pts, [[0.0, 0.0, 50.0]]])
        fin = np.vstack([tris, [[tris[0][1], tris[0][2], len(pts)]]])  # a third triangle on an inner edge
        with self.assertRaisesRegex(PatientInputError, "more than two triangles"):
            read_lumen_surface(self.write(extra, fin, "fin.stl"))
        two = np.vstack([pts, pts + [0.0, 0.0, 10.0]])
        with self.assertRaisesRegex(PatientInputError, "one connected surface, got 2 pieces"):
            read_lumen_surface(self.write(two, np.vstack([tris, tris + len(pts)]), "two.stl"))
        r, _ = self.run_cmd(os.path.join(self.tmp, "nothing.stl"))
        self.assertEqual(r.returncode, 2)
        self.assertIn("no such file", r.stderr)

    def test_patient_pipeline_from_a_surface(self):
        """patient.lumen_surface instead of patient.centerline: the shipped patient-like scene's devices
        placed at the stenosis of the curved tube given as STL only (devices shortened to fit its 12 mm)."""
        import yaml

        from patient.prepare import prepare_scene

        surface = self.write(*tube(), "vessel.stl")
        with open(os.path.join(ROOT, "configs", "patient_like.yaml")) as f:
            scene = yaml.safe_load(f)
        # circles: this test is about the centerline (the surface's own sections are scripts.lumen_sections'),
        # and its coarse mesh (1 mm against a 0.075 mm intima) meshes with circles only
        scene["patient"]["lumen_surface"] = {"file": surface, "sections": "circles"}
        del scene["patient"]["centerline"]
        scene["patient"]["wall"]["thickness"] = 0.6
        scene["patient"]["mesh"]["size"] = 1.0  # coarse: this test is about the lumen
        scene["balloon"]["mesh"].update(length=8.0, n_axial=50)
        scene["stent"]["generator"].update(rings=3, ring_pitch=1.5)
        scene_path = os.path.join(self.tmp, "scene.yaml")
        out = os.path.join(self.tmp, "prepared")
        os.makedirs(out)
        done, report = prepare_scene(scene, scene_path, out, log=lambda m: None)
        self.assertTrue(os.path.isfile(os.path.join(out, "lumen_from_surface.csv")))
        self.assertAlmostEqual(report["lumen_length"], LENGTH, delta=0.1)
        self.assertAlmostEqual(min(report["lumen_diameter_range"]), 1.8, delta=0.02)  # 40 % of 3 mm
        # gmsh's minimal scaled Jacobian of the written mesh: positive (no inverted element), at most 1
        self.assertTrue(0.0 < report["artery_mesh"]["min_scaled_jacobian"] <= 1.0, report["artery_mesh"])
        # neither key, or a thickness from a column the surface does not have: refused naming the key
        neither = dict(scene, patient={k: v for k, v in scene["patient"].items() if k != "lumen_surface"})
        with self.assertRaisesRegex(PatientInputError, "expected centerline .* got neither"):
            prepare_scene(neither, scene_path, out, log=lambda m: None)
        col = dict(scene, patient=dict(scene["patient"], wall={"thickness": "from_centerline"}))
        with self.assertRaisesRegex(PatientInputError, "patient.wall.thickness"):
            prepare_scene(col, scene_path, out, log=lambda m: None)

    def test_mixed_orientation_is_repaired(self):
        pts, tris = tube()
        mixed = tris.copy()
        mixed[::3] = mixed[::3, ::-1]
        s = read_lumen_surface(self.write(pts, mixed, "mixed.stl"))
        ref = read_lumen_surface(self.write(pts, tris, "ok.stl"))
        self.assertEqual(len(s.loops), 2)
        # the orientation chosen is the one of the first triangle: equal to the original up to one global flip
        rot = lambda t: min((t[i], t[(i + 1) % 3], t[(i + 2) % 3]) for i in range(3))  # noqa: E731
        a = {rot(tuple(t)) for t in s.triangles}
        b = {rot(tuple(t)) for t in ref.triangles}
        flipped = {rot(tuple(t[::-1])) for t in ref.triangles}
        self.assertTrue(a == b or a == flipped)


if __name__ == "__main__":
    unittest.main(verbosity=2)
