#!/usr/bin/python3
"""Studies (scripts/study.py): bad study files refused before anything runs, a 3-case pressure study
run by the local pool and as a job array on a real single-node Slurm (started here from Debian's
slurmctld, slurmd and munge), and the aggregated table.

Physics check (consistency): the tiny coupled scene's stent diameter grows with the balloon
pressure, and the Slurm array gives the same table as the local pool (the same executables on the
same inputs: equal to 1e-9 mm). Robustness: unknown keys and key paths, an empty grid, duplicate
cases, a second study in one directory and a Slurm runner without sbatch are exit 2 with the file
and key named and nothing run or submitted; a rerun skips finished cases, runs stopped ones and
failed ones only with --retry-failed.
Usage: test_study.py BIN_DIR   (about 60 s on an idle machine)
"""
import csv
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
from slurm_cluster import SlurmCluster  # noqa: E402

STUDY = [sys.executable, os.path.join(ROOT, "scripts", "study.py")]
BUILD = None
TINY = os.path.join(ROOT, "tests", "integration", "data", "tiny_coupled.yaml")
PRESSURES = [0.8, 1.0, 1.2]


def study_text(**extra):
    doc = {
        "base": TINY,
        "common": {"solid.ranks": 2},  # 2 ranks: srun starts a real MPI job in every task
        "grid": {"balloon.pressure.value": PRESSURES},
        "plot": {"x": "balloon.pressure.value", "y": ["stent.final"]},
    }
    doc.update(extra)
    return json.dumps(doc)  # JSON is YAML


def read(path):
    with open(path, errors="replace") as f:
        return f.read()


def table(out):
    with open(os.path.join(out, "table.csv")) as f:
        return list(csv.DictReader(f))


class Study(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="angio-study-")

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def write(self, text, name="s.yaml"):
        p = os.path.join(self.tmp, name)
        with open(p, "w") as f:
            f.write(text)
        return p

    def study(self, *args, env=None):
        return subprocess.run(
            STUDY + list(args[:1]) + list(args[1:]) + ["--build-dir", BUILD], capture_output=True, text=True, env=env
        )

    def refused(self, text, *words, args=(), env=None):
        p = self.write(text)
        out_dir = os.path.join(self.tmp, "out")
        r = self.study("run", p, "--out-dir", out_dir, *args, env=env)
        self.assertEqual(r.returncode, 2, r.stdout + r.stderr)
        self.assertIn("study: error:", r.stderr)
        self.assertNotIn("Traceback", r.stderr)
        for w in words:
            self.assertIn(w, r.stderr)
        self.assertFalse(
            any(n.startswith("case-") for n in os.listdir(out_dir)) if os.path.isdir(out_dir) else False,
            "a refused study ran a case",
        )
        return r.stderr

    def test_bad_study_files_are_refused_before_anything_runs(self):
        self.refused(study_text(grids={"a": [1]}), "s.yaml", "grids: unknown key")
        self.refused(study_text(grid={"balloon.pressure.value": []}), "grid: balloon.pressure.value", "non-empty list")
        self.refused(study_text(grid={"baloon.pressure.value": [1.0]}), "baloon.pressure.value", "no map at 'baloon'")
        # a misspelt last key is caught by the solver's own key check of the case's scene
        self.refused(study_text(grid={"balloon.pressure.valu": [1.0]}, plot=None), "case 0", "valu")
        self.refused(study_text(grid={"balloon.pressure.value": [1.0, 1.0]}), "cases 0 and 1 are the same case")
        self.refused(
            study_text(grid=None, cases=[{"balloon.pressure.value": 1.0}, {"balloon.pressure.value": 1.0}]),
            "the same case",
        )
        self.refused(study_text(patients=["nope.csv"]), "patients[0]: nope.csv: no such file")
        self.refused(study_text(plot={"x": "balloon.pressure"}), "plot: x: 'balloon.pressure' is not a parameter")
        self.refused(study_text(base="missing.yaml"), "base:")
        # a Slurm runner without sbatch: nothing submitted
        env = dict(os.environ, PATH="/nonexistent")
        err = self.refused(study_text(), "sbatch not found", args=("--runner", "slurm"), env=env)
        self.assertIn("nothing was submitted", err)

    def test_another_study_in_the_same_directory_is_refused(self):
        out = os.path.join(self.tmp, "out")
        os.makedirs(out)
        with open(os.path.join(out, "study.json"), "w") as f:
            json.dump({"identity": {"name": "other"}}, f)
        r = self.study("run", self.write(study_text()), "--out-dir", out, "--dry-run")
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("holds another study", r.stderr)

    def test_local_pool_then_slurm_array(self):
        p = self.write(study_text())
        local = os.path.join(self.tmp, "local")
        r = self.study("run", p, "--out-dir", local, "--jobs", "2")
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        rows = table(local)
        self.assertEqual([float(x["balloon.pressure.value"]) for x in rows], PRESSURES)
        self.assertTrue(all(x["state"] == "done" for x in rows), rows)
        d = [float(x["stent.final"]) for x in rows]
        self.assertTrue(d[0] < d[1] < d[2], f"stent diameter not growing with pressure: {d}")
        self.assertTrue(os.path.isfile(os.path.join(local, "plots", "stent.final.png")))

        # a rerun runs nothing; a stopped case (runner died) runs again; a failed one only on request
        t0 = time.time()
        r = self.study("run", p, "--out-dir", local)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("0 to run, 3 done", r.stderr)
        self.assertLess(time.time() - t0, 20)
        cases = sorted(n for n in os.listdir(local) if n.startswith("case-"))
        for name, state in ((cases[0], "running"), (cases[1], "failed")):
            path = os.path.join(local, name, "case.json")
            info = json.loads(read(path))
            info["state"] = state
            with open(path, "w") as f:
                json.dump(info, f)
        r = subprocess.run(STUDY + ["status", p, "--out-dir", local], capture_output=True, text=True)
        self.assertEqual(r.returncode, 1)
        self.assertIn("1 failed, 1 stopped", r.stdout)
        r = self.study("run", p, "--out-dir", local)
        self.assertEqual(r.returncode, 1, r.stderr)  # the failed case is still failed
        self.assertIn("1 to run", r.stderr)
        r = self.study("run", p, "--out-dir", local, "--retry-failed")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("1 to run", r.stderr)

        # the same study as a Slurm job array on a cluster started here
        with SlurmCluster() as cluster:
            array = os.path.join(self.tmp, "slurm")
            r = self.study("run", p, "--out-dir", array, "--runner", "slurm", env=cluster.env)
            self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
            self.assertIn("submitted job array", r.stdout)
            deadline = time.time() + 300
            while time.time() < deadline:
                st = subprocess.run(STUDY + ["status", p, "--out-dir", array], capture_output=True, text=True)
                if st.returncode == 0:
                    break
                time.sleep(2)
            if st.returncode != 0:
                logs = [
                    read(os.path.join(array, "slurm", f))
                    for f in os.listdir(os.path.join(array, "slurm"))
                    if f.endswith(".out")
                ]
                self.fail("the array did not finish in 300 s:\n" + st.stdout + "\n".join(logs))
        r = subprocess.run(STUDY + ["table", p, "--out-dir", array], capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stderr)
        for a, b in zip(table(local), table(array)):
            self.assertEqual(a["case"], b["case"])
            self.assertAlmostEqual(float(a["stent.final"]), float(b["stent.final"]), delta=1e-9)
            info = json.loads(read(os.path.join(array, f"case-{b['case']}", "case.json")))
            self.assertTrue(info["slurm_job"], info)
            log = read(os.path.join(array, f"case-{b['case']}", "launch.log"))
            self.assertIn("via srun", log)  # the solid's ranks started by Slurm


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit("usage: test_study.py BIN_DIR")
    BUILD = os.path.dirname(os.path.abspath(sys.argv.pop(1)))
    unittest.main(verbosity=2)
