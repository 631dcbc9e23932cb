#!/usr/bin/python3
"""Compliance of the post-dilatation balloon of configs/procedure_stenosis.yaml (solid alone, free balloon).

The post-dilatation balloon is declared non-compliant: 2.5 mm nominal at 12 atm and growing well
below 1 %/atm above it. Against that declaration (its calibration targets, in the scene's comment):
the free balloon (the paper's 9.4 mm mesh, 0 -> 20 atm in 40 steps, mid diameter) reaches 2.5 mm
within 2 % at 12 atm, grows monotonically and less than 0.6 %/atm from 12 to 20 atm. The material
is read from the scene: the test follows what ships.
Usage: test_balloon_compliance.py BIN_DIR   (about 30 s)
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

import yaml

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BIN = sys.argv.pop(1) if len(sys.argv) > 1 else None
ATM = 0.101325  # MPa


def free_balloon(material, peak_atm=20.0, steps=40):
    return {
        "time": {"end": 1.0, "steps": steps},
        "load_curves": {"inflation": [[0.0, 0.0], [1.0, 1.0]]},
        "output": {"every": steps},
        "balloon": {
            "mesh": {"generator": "tube", "length": 9.4, "outer_diameter": 0.98, "wall": 0.04, "n_circ": 22,
                     "n_axial": 58, "center": [0, 0, 0]},
            "material": material,
            "pressure": {"value": peak_atm * ATM, "curve": "inflation"},
            "end_springs": 100.0,
            "summary": {"end_offset": 1.7},
        },
        "solid": {"ranks": 1, "petsc_options": "-ksp_type preonly -pc_type lu",
                  "newton": {"max_iterations": 30, "rtol": 1.0e-8, "atol": 1.0e-9}},
    }  # fmt: skip


@unittest.skipIf(BIN is None, "no BIN_DIR given")
class BalloonCompliance(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="angio-compliance-")
        with open(os.path.join(ROOT, "configs", "procedure_stenosis.yaml")) as f:
            phases = {p["name"]: p for p in yaml.safe_load(f)["procedure"]}
        cls.d = cls.diameters(phases["postdilatation"]["balloon"]["material"], "postdilatation")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    @classmethod
    def diameters(cls, material, name):
        """{pressure in atm (rounded): mid diameter in mm} of the free balloon."""
        path = os.path.join(cls.tmp, f"{name}.yaml")
        with open(path, "w") as f:
            yaml.safe_dump(free_balloon(material), f)
        run = os.path.join(cls.tmp, name)
        p = subprocess.run(
            [os.path.join(BIN, "solid_solver"), "--scene", path, "--run-dir", run],
            capture_output=True, text=True, timeout=600,
        )  # fmt: skip
        assert p.returncode == 0, p.stderr[-2000:]
        with open(os.path.join(run, "solid", "summary.json")) as f:
            steps = json.load(f)["steps"]
        return {round(s["balloon_pressure"] / ATM, 3): s["balloon_outer_diameter"]["mid"] for s in steps}

    def test_non_compliant_post_dilatation_balloon(self):
        d = self.d
        self.assertLess(abs(d[12.0] / 2.5 - 1), 0.02, d)
        self.assertLess((d[20.0] / d[12.0] - 1) / 8.0, 0.006, d)
        p = sorted(d)
        self.assertTrue(all(d[b] > d[a] for a, b in zip(p, p[1:])), d)


if __name__ == "__main__":
    unittest.main(verbosity=2)
