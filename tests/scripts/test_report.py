#!/usr/bin/python3
"""scripts/report.py on synthetic run directories (no solver needed; stdlib unittest only).

  python3 tests/scripts/test_report.py            (or: python3 -m unittest tests/scripts/test_report.py)

An artery run (stent + balloon + two-layer artery, the pseudo-time of paper §4.1) and a straight free
expansion run are written into a temporary directory with the files the solvers produce; report.py runs
as a subprocess, and its table rows, results.json and plots are checked against the synthetic numbers.
"""
import json
import os
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[2]
REPORT = ROOT / "scripts" / "report.py"
ATM = 0.101325

ARTERY_SCENE = """\
time: {start: -0.2, end: 2.0, steps: 8}
stent:
  generator: {type: corrugated_rings, rings: 4, crowns: 8, crimped_diameter: 1.15}
balloon:
  mesh: {generator: tube, length: 9.4, outer_diameter: 0.98, wall: 0.04, n_circ: 22, n_axial: 58, center: [0, 0, 3.0]}
artery:
  mesh:
    generator: tube
    length: 11.0
    outer_diameter: 2.8
    center: [0, 0, 3.0]
    n_circ: 48
    n_axial: 36
    layers:
      - {name: media, thickness: 0.3, n_radial: 2}
      - {name: adventitia, thickness: 0.3, n_radial: 2}
"""
STRAIGHT_SCENE = """\
time: {end: 2.0, steps: 4}
stent:
  generator: {type: corrugated_rings, rings: 4, crowns: 8, crimped_diameter: 1.15}
balloon:
  mesh: {generator: tube, length: 9.4, outer_diameter: 0.98, wall: 0.04, n_circ: 22, n_axial: 58, center: [0, 0, 3.0]}
"""

# the synthetic artery run: times, pressures (MPa) and what the solid measured
TIMES = [-0.2, -0.1, 0.0, 0.5, 1.0, 1.5, 2.0]
BALLOON = [0.0, 0.0, 0.0, 0.6585, 1.317, 0.6585, 0.0]
BLOOD = [0.0, 0.01133, 0.01133, 0.01133, 0.01133, 0.01133, 0.01133]
MEDIA_MAX = [0.0, 0.0021, 0.0024, 2.5, 8.1, 1.2, 0.19]  # MPa
MEDIA_P99 = [0.0, 0.0018, 0.0020, 1.1, 3.3, 0.6, 0.09]
ADV_MAX = [0.0, 0.00015, 0.00016, 0.02, 0.051, 0.03, 0.014]
ADV_P99 = [0.0, 0.0001, 0.00012, 0.01, 0.03, 0.02, None]  # null as the solid writes it
# recovered nodal values (*_nodal keys): above the element ones, the media's peak on the lumen surface
MEDIA_MAX_NODAL = [0.0, 0.0030, 0.0033, 4.0, 12.5, 2.0, 0.31]
MEDIA_P99_NODAL = [0.0, 0.0025, 0.0028, 1.6, 4.4, 0.8, 0.12]
MEDIA_ENDO_NODAL = [0.0, 0.0030, 0.0033, 4.0, 12.0, 1.9, 0.30]
ADV_MAX_NODAL = [0.0, 0.0002, 0.00021, 0.025, 0.06, 0.035, 0.016]
# averaged over the ball of stress_average_radius (*_averaged keys): below the element maxima at a strut
MEDIA_AVG = [0.0, 0.0019, 0.0022, 1.3, 4.2, 0.7, 0.12]
U_ARTERY = [0.0, 0.12, 0.13, 0.2, 0.3, 0.28, 0.27]
STENT_D = [1.15, 1.15, 1.16, 1.6, 2.14, 2.16, 1.90]  # beam max (2.16) is not at the peak
STATIONS = [-5.5 + i for i in range(12)]  # mm, stent spans -3 .. 3
STENTED = [s for s in STATIONS if -3.0 <= s <= 3.0]


def lumen(phase_d):
    return [phase_d if -3.0 <= s <= 3.0 else 1.62 for s in STATIONS]


LUMEN = {0: [1.60] * 12, 2: [1.62] * 12, 4: lumen(2.10), 6: lumen(1.91)}
LUMEN[6][5] = 1.85  # the narrowest stented station after


def write(path, text):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)


def make_artery_run(run):
    write(run / "scene.yaml", ARTERY_SCENE)
    steps = []
    for i, t in enumerate(TIMES):
        s = {
            "step": i,
            "time": t,
            "balloon_pressure": BALLOON[i],
            "blood_pressure": BLOOD[i],
            "max_principal_stress": {"balloon": 1.0 + i, "media": MEDIA_MAX[i], "adventitia": ADV_MAX[i]},
            "p99_principal_stress": {"balloon": 0.5, "media": MEDIA_P99[i], "adventitia": ADV_P99[i]},
            "max_principal_stress_at": {"balloon": [0, 0, 3], "media": [0.8, 0, 3], "adventitia": [1.1, 0, 3]},
            "max_principal_stress_nodal": {
                "balloon": 2.0 + i,
                "media": MEDIA_MAX_NODAL[i],
                "adventitia": ADV_MAX_NODAL[i],
            },
            "p99_principal_stress_nodal": {"balloon": 0.6, "media": MEDIA_P99_NODAL[i], "adventitia": None},
            "max_principal_stress_nodal_at": {"balloon": [0, 0, 3], "media": [0.79, 0, 3], "adventitia": [1.1, 0, 3]},
            # only the layer that touches the lumen
            "max_principal_stress_endothelium_nodal": {"media": MEDIA_ENDO_NODAL[i]},
            "max_principal_stress_averaged": {"balloon": 0.9, "media": MEDIA_AVG[i], "adventitia": None},
            "max_displacement": {"balloon": 0.5 * i, "artery": U_ARTERY[i]},
            "balloon_outer_diameter": {"mid": 1.0, "end0": 1.1, "end1": 1.1, "dogboning": 0.01 * i},
        }
        prof = LUMEN.get(i, [1.62 + 0.05 * i] * 12)
        s.update(lumen_diameter=prof, lumen_diameter_min=min(prof), lumen_diameter_max=max(prof))
        if t >= 0:
            s["artery_contact_force"] = {"stent": 0.1 * BALLOON[i] + 0.05 * i, "balloon": 2.0 * BALLOON[i]}
        if t > 0:
            s["stent_stations"] = [-3.0, 3.0]  # the stent's extent on the lumen stations
        if i == len(TIMES) - 1:
            s["apposition"] = {
                "stent_length": 60.0,
                "malapposed_length": 6.0,
                "malapposed_fraction": 0.1,
                "max_gap": 0.23,
                "mean_gap": 0.02,
            }
        s.update(newton_iterations=3, residual=1e-9, wall_seconds=0.5)
        steps.append(s)
    solid = {
        "units": {"length": "mm", "stress": "MPa", "force": "N", "time": "s"},
        "blocks": [
            {"id": 0, "name": "balloon", "part": "balloon"},
            {"id": 1, "name": "media", "part": "artery"},
            {"id": 2, "name": "adventitia", "part": "artery"},
        ],
        "lumen_stations": STATIONS,
        "apposition_threshold": 0.1,
        "stress_average_radius": 0.25,
        "steps": steps,
    }
    write(run / "solid" / "summary.json", json.dumps(solid, indent=1))
    write(
        run / "solid" / "apposition.csv",
        "# stent apposition at t = 2 s: gap = distance (mm); malapposed if gap > 0.1 mm\n"
        "point,weight,gap,malapposed\n0,10,0.01,0\n1,5,0.23,1\n2,1,inf,1\n",
    )
    beam_steps = [
        {"step": i, "time": t, "diameter": STENT_D[i], "iterations": 2, "residual": 1e-10}
        for i, t in enumerate(TIMES)
        if i > 0
    ]
    beam = {
        "status": "ok",
        "diameter": {
            "initial": 1.15,
            "max": 2.16,
            "time_of_max": 1.5,
            "final": 1.90,
            "recoil": 0.26,
            "recoil_percent": 12.04,
        },
        "stent": {
            "dogboning_max_percent": 3.0,
            "time_of_dogboning_max": 0.5,
            "foreshortening_at_max_diameter_percent": 1.0,
            "foreshortening_final_percent": 0.8,
            "axis_radius_initial": None,
        },
        "steps": beam_steps,
    }
    write(run / "beam" / "summary.json", json.dumps(beam))
    write(
        run / "coupling.csv",
        "step,time,pressure\n" + "".join(f"{i},{t},{BALLOON[i]}\n" for i, t in enumerate(TIMES) if i > 0),
    )
    write(
        run / "coupling_summary.json",
        json.dumps(
            {
                "status": "ok",
                "steps": 6,
                "coupling_iterations_mean": 4.5,
                "coupling_iterations_max": 9,
                "wall_time": 100.0,
                "messaging_share": 0.01,
            }
        ),
    )


def make_straight_run(run):
    write(run / "scene.yaml", STRAIGHT_SCENE)
    times = [0.5, 1.0, 1.5, 2.0]
    D = [1.8, 2.6, 2.4, 2.3]
    beam = {
        "status": "ok",
        "diameter": {
            "initial": 1.15,
            "max": 2.6,
            "time_of_max": 1.0,
            "final": 2.3,
            "recoil": 0.3,
            "recoil_percent": 11.54,
        },
        "stent": {
            "dogboning_max_percent": 5.0,
            "time_of_dogboning_max": 0.5,
            "foreshortening_at_max_diameter_percent": 2.0,
            "foreshortening_final_percent": 1.5,
            "axis_radius_initial": None,
        },
        "steps": [{"step": i + 1, "time": t, "diameter": d} for i, (t, d) in enumerate(zip(times, D))],
    }
    write(run / "beam" / "summary.json", json.dumps(beam))
    steps = [
        {
            "step": i,
            "time": t,
            "balloon_pressure": p,
            "max_principal_stress": {"balloon": 1.0},
            "max_displacement": {"balloon": 0.5},
            "balloon_outer_diameter": {"mid": 1.0, "end0": 1.1, "end1": 1.1, "dogboning": dg},
        }
        for i, (t, p, dg) in enumerate(zip([0.0] + times, [0, 0.66, 1.317, 0.66, 0], [0, 0.2, 0.1, 0.05, 0]))
    ]
    write(
        run / "solid" / "summary.json",
        json.dumps({"units": {}, "blocks": [{"id": 0, "name": "balloon", "part": "balloon"}], "steps": steps}),
    )
    write(
        run / "coupling.csv",
        "step,time,pressure\n"
        + "".join(f"{i + 1},{t},{p}\n" for i, (t, p) in enumerate(zip(times, [0.66, 1.317, 0.66, 0.0]))),
    )
    write(
        run / "coupling_summary.json",
        json.dumps(
            {
                "status": "ok",
                "steps": 4,
                "coupling_iterations_mean": 3.0,
                "coupling_iterations_max": 5,
                "wall_time": 10.0,
                "messaging_share": 0.02,
            }
        ),
    )


def run_report(run):
    r = subprocess.run(
        [sys.executable, str(REPORT), str(run)],
        capture_output=True,
        text=True,
        timeout=120,
        env=dict(os.environ, MPLBACKEND="Agg"),
    )
    return r


def table(stdout):
    """row name -> (ours, paper) strings of the report's table."""
    lines = stdout.splitlines()
    head = next(i for i, l in enumerate(lines) if l.startswith("quantity"))
    w = lines[head].index("this run") - 4  # name column width ("quantity".ljust(w) + 2 spaces + 12-wide column)
    rows = {}
    for l in lines[head + 1 :]:
        if l.startswith("report:"):
            continue
        rows[l[:w].rstrip()] = (l[w + 2 : w + 14].strip(), l[w + 16 :].strip())
    return rows


def has_module(name):
    return subprocess.run([sys.executable, "-c", f"import {name}"], capture_output=True).returncode == 0


class ArteryReport(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.run_dir = Path(cls.tmp.name) / "run"
        make_artery_run(cls.run_dir)
        cls.r = run_report(cls.run_dir)
        cls.rows = table(cls.r.stdout) if cls.r.returncode == 0 else {}
        cls.raw = (cls.run_dir / "results.json").read_text() if cls.r.returncode == 0 else "{}"
        cls.res = json.loads(cls.raw)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def ours(self, name):
        self.assertIn(name, self.rows, f"row '{name}' in\n{self.r.stdout}")
        return float(self.rows[name][0])

    def paper(self, name):
        return float(self.rows[name][1])

    def test_runs(self):
        self.assertEqual(self.r.returncode, 0, self.r.stderr)
        self.assertNotIn("Traceback", self.r.stderr)

    def test_stent_rows(self):
        self.assertAlmostEqual(self.ours("stent diameter at peak pressure (mm)"), 2.14, places=3)
        self.assertAlmostEqual(self.paper("stent diameter at peak pressure (mm)"), 2.12)
        self.assertAlmostEqual(self.ours("stent diameter final (mm)"), 1.90, places=3)
        self.assertAlmostEqual(self.paper("stent diameter final (mm)"), 1.89)
        self.assertAlmostEqual(self.ours("elastic recoil, peak - final (%)"), 100 * 0.24 / 2.14, places=2)
        self.assertAlmostEqual(self.paper("elastic recoil, peak - final (%)"), 10.8)

    def test_prestressed(self):
        # prestressed = last step with t <= 0: index 2
        self.assertAlmostEqual(
            self.ours("prestressed: media max principal stress (kPa)"), MEDIA_MAX[2] * 1000, places=3
        )
        self.assertAlmostEqual(self.paper("prestressed: media max principal stress (kPa)"), 2.3)
        self.assertAlmostEqual(
            self.ours("prestressed: adventitia max principal stress (kPa)"), ADV_MAX[2] * 1000, places=4
        )
        self.assertAlmostEqual(self.ours("prestressed: max artery displacement (mm)"), U_ARTERY[2])
        self.assertAlmostEqual(self.paper("prestressed: max artery displacement (mm)"), 0.14)

    def test_peak_and_after(self):
        self.assertAlmostEqual(self.ours("peak: media max principal stress (kPa)"), 8100.0)
        self.assertAlmostEqual(self.paper("peak: media max principal stress (kPa)"), 7990.0)  # innermost layer
        self.assertAlmostEqual(self.ours("peak: media p99 principal stress (kPa)"), 3300.0)
        self.assertAlmostEqual(self.paper("peak: adventitia max principal stress (kPa)"), 49.5)
        self.assertAlmostEqual(self.ours("after: media max principal stress (kPa)"), 190.0)
        self.assertAlmostEqual(self.paper("after: media max principal stress (kPa)"), 187.5)
        self.assertNotIn("after: adventitia p99 principal stress (kPa)", self.rows)  # null: no row
        self.assertAlmostEqual(self.ours("contact force balloon -> artery at peak (N)"), 2 * 1.317, places=3)
        self.assertAlmostEqual(self.ours("  balloon pressure at peak (atm)"), 1.317 / ATM, places=2)

    def test_nodal_stress_rows(self):
        # next to the element rows, which stay as they were
        self.assertAlmostEqual(self.ours("peak: media max principal stress (kPa)"), 8100.0)
        self.assertAlmostEqual(self.ours("peak: media max principal stress, nodal (kPa)"), 12500.0)
        self.assertAlmostEqual(self.paper("peak: media max principal stress, nodal (kPa)"), 7990.0)
        self.assertAlmostEqual(self.ours("peak: media max principal stress, endothelium nodal (kPa)"), 12000.0)
        # the paper's 7.99 MPa is "at the endothelial surface": the innermost layer's lumen-side nodes
        self.assertAlmostEqual(self.paper("peak: media max principal stress, endothelium nodal (kPa)"), 7990.0)
        self.assertAlmostEqual(self.ours("peak: media p99 principal stress, nodal (kPa)"), 4400.0)
        self.assertAlmostEqual(self.ours("after: adventitia max principal stress, nodal (kPa)"), 16.0)
        self.assertAlmostEqual(self.paper("after: adventitia max principal stress, nodal (kPa)"), 13.7)
        self.assertAlmostEqual(self.ours("prestressed: media max principal stress, nodal (kPa)"), 3.3)
        self.assertNotIn("prestressed: media p99 principal stress, nodal (kPa)", self.rows)  # as the element p99
        self.assertNotIn("peak: adventitia max principal stress, endothelium nodal (kPa)", self.rows)  # no lumen
        self.assertNotIn("peak: adventitia p99 principal stress, nodal (kPa)", self.rows)  # null
        self.assertFalse(any("balloon" in n and "nodal" in n for n in self.rows))  # artery layers only
        layer = self.res["artery"]["phases"]["peak"]["layers"]["media"]
        self.assertAlmostEqual(layer["max_principal_stress_nodal"], 12.5)
        self.assertAlmostEqual(layer["p99_principal_stress_nodal"], 4.4)
        self.assertEqual(layer["max_principal_stress_nodal_at"], [0.79, 0, 3])
        self.assertAlmostEqual(layer["max_principal_stress_endothelium_nodal"], 12.0)
        self.assertAlmostEqual(layer["paper_max_principal_stress_endothelium"], 7.99)
        adv = self.res["artery"]["phases"]["peak"]["layers"]["adventitia"]
        self.assertIsNone(adv["max_principal_stress_endothelium_nodal"])
        self.assertIsNone(adv["paper_max_principal_stress_endothelium"])

    def test_averaged_stress_rows(self):
        # the ball average: a row per phase and layer where the solid wrote one, named with its radius
        self.assertAlmostEqual(self.ours("peak: media max principal stress, averaged over 0.25 mm (kPa)"), 4200.0)
        self.assertAlmostEqual(self.ours("after: media max principal stress, averaged over 0.25 mm (kPa)"), 120.0)
        self.assertAlmostEqual(self.ours("prestressed: media max principal stress, averaged over 0.25 mm (kPa)"), 2.2)
        self.assertNotIn("peak: adventitia max principal stress, averaged over 0.25 mm (kPa)", self.rows)  # null
        self.assertFalse(any("balloon" in n and "averaged" in n for n in self.rows))  # artery layers only
        self.assertEqual(self.res["artery"]["stress_average_radius"], 0.25)
        self.assertAlmostEqual(
            self.res["artery"]["phases"]["peak"]["layers"]["media"]["max_principal_stress_averaged"], 4.2
        )

    def test_lumen_and_apposition(self):
        self.assertAlmostEqual(self.ours("min lumen diameter after, stented (mm)"), 1.85)
        self.assertAlmostEqual(self.ours("min lumen diameter peak, stented (mm)"), 2.10)
        gain = (sum(1.91 - 1.62 for _ in STENTED) - 0.06) / len(STENTED)
        self.assertAlmostEqual(self.ours("lumen gain after - prestressed, mean stented (mm)"), gain, places=3)
        self.assertAlmostEqual(self.ours("malapposed stent length after (gap > 0.1 mm) (%)"), 10.0)
        self.assertAlmostEqual(self.ours("max strut-wall gap after (mm)"), 0.23)

    def test_results_json(self):
        self.assertNotIn("NaN", self.raw)
        self.assertNotIn("Infinity", self.raw)
        a = self.res["artery"]
        self.assertEqual(a["layers"], ["media", "adventitia"])
        self.assertEqual(a["innermost_layer"], "media")
        self.assertEqual(set(a["phases"]), {"prestressed", "peak", "after"})
        self.assertEqual(a["phases"]["prestressed"]["time"], 0.0)
        self.assertEqual(a["phases"]["peak"]["time"], 1.0)
        self.assertEqual(a["phases"]["after"]["time"], 2.0)
        self.assertAlmostEqual(a["phases"]["prestressed"]["layers"]["media"]["max_principal_stress"], MEDIA_MAX[2])
        self.assertIsNone(a["phases"]["after"]["layers"]["adventitia"]["p99_principal_stress"])
        self.assertEqual(a["lumen"]["stations"], STATIONS)
        self.assertEqual(a["lumen"]["profiles"]["after"], LUMEN[6])
        self.assertTrue(a["lumen"]["scope"].startswith("stations within the stent's axial extent"))
        self.assertAlmostEqual(a["lumen"]["stent_extent"]["min"], -3.0)
        self.assertAlmostEqual(a["lumen"]["stent_extent"]["max"], 3.0)
        self.assertAlmostEqual(a["stent"]["diameter_peak"], 2.14)
        self.assertEqual(a["apposition"]["csv"]["malapposed_points"], 2)
        self.assertEqual(a["contact_force_at_peak"]["stent"], 0.1 * 1.317 + 0.05 * 4)

    def test_plots(self):
        if not has_module("matplotlib"):
            self.skipTest("matplotlib not available to " + sys.executable)
        for name in (
            "diameter_vs_time.png",
            "diameter_vs_pressure.png",
            "stress_vs_time.png",
            "lumen_profile.png",
            "contact_force_vs_time.png",
        ):
            self.assertTrue((self.run_dir / name).is_file(), name)


class StraightReport(unittest.TestCase):
    def test_free_expansion_rows(self):
        with tempfile.TemporaryDirectory() as tmp:
            run = Path(tmp) / "run"
            make_straight_run(run)
            r = run_report(run)
            self.assertEqual(r.returncode, 0, r.stderr)
            rows = table(r.stdout)
            expected = [
                "stent diameter crimped (mm)",
                "stent diameter max (mm)",
                "stent diameter final (mm)",
                "elastic recoil (mm)",
                "elastic recoil (%)",
                "stent dogboning max (%)",
                "  at time (s)",
                "  at pressure (atm)",
                "foreshortening at max diameter (%)",
                "foreshortening final (%)",
                "balloon dogboning max (%)",
                "load steps",
                "coupling iterations mean / max",
                "wall time (s)",
                "messaging share (%)",
            ]
            for name in expected:
                self.assertIn(name, rows)
            self.assertEqual(rows["stent diameter max (mm)"], ("2.6", "2.59"))
            self.assertFalse(any(n.startswith(("prestressed", "peak", "after", "min lumen")) for n in rows))
            res = json.loads((run / "results.json").read_text())
            self.assertNotIn("artery", res)


class EmptyRun(unittest.TestCase):
    def test_no_summaries(self):
        with tempfile.TemporaryDirectory() as tmp:
            r = run_report(Path(tmp))
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertNotIn("Traceback", r.stderr)
            self.assertEqual(json.loads((Path(tmp) / "results.json").read_text()), {})

    def test_unfinished_artery_run(self):
        """A run that stopped during the inflation, with an older summary (no lumen, no apposition)."""
        with tempfile.TemporaryDirectory() as tmp:
            run = Path(tmp) / "run"
            make_artery_run(run)
            solid = json.loads((run / "solid" / "summary.json").read_text())
            for s in solid["steps"]:
                for k in (
                    "lumen_diameter",
                    "lumen_diameter_min",
                    "lumen_diameter_max",
                    "apposition",
                    "artery_contact_force",
                    "p99_principal_stress",
                    "max_principal_stress_nodal",
                    "p99_principal_stress_nodal",
                    "max_principal_stress_nodal_at",
                    "max_principal_stress_endothelium_nodal",
                ):
                    s.pop(k, None)
            solid["steps"] = solid["steps"][:4]
            del solid["lumen_stations"]
            (run / "solid" / "summary.json").write_text(json.dumps(solid))
            (run / "solid" / "apposition.csv").unlink()
            (run / "beam" / "summary.json").write_text('{"diameter": {"initial": 1.15}, "steps": []}')
            r = run_report(run)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertNotIn("Traceback", r.stderr)
            raw = (run / "results.json").read_text()
            self.assertNotIn("NaN", raw)
            rows = table(r.stdout)
            self.assertIn("prestressed: media max principal stress (kPa)", rows)
            self.assertFalse(any("nodal" in n for n in rows))  # a run before the nodal recovery: no nodal rows


class ContinuedPatientRun(unittest.TestCase):
    def test_paper_column_follows_the_geometry_of_the_first_run(self):
        """A patient run continued with launch.py --resume: its directory has no geometry/ of its own;
        the artery mesh in its scene points into the first run's, whose placement.json makes it a
        patient run (the paper's §4.2 patient in the column, not the generic artery of §4.1)."""
        with tempfile.TemporaryDirectory() as tmp:
            first = Path(tmp) / "first"
            write(first / "geometry" / "placement.json", "{}")
            run = first / "continued"
            make_artery_run(run)
            scene = yaml.safe_load((run / "scene.yaml").read_text())
            scene["artery"]["mesh"] = {"file": str(first / "geometry" / "artery.msh")}
            (run / "scene.yaml").write_text(yaml.safe_dump(scene))
            r = run_report(run)
            self.assertEqual(r.returncode, 0, r.stderr)
            rows = table(r.stdout)
            # the media at peak: 78.3 kPa in the paper's patient, where its generic artery's column gives
            # the innermost layer's 7,990 kPa (this run's media is its innermost layer)
            self.assertEqual(rows["peak: media max principal stress (kPa)"][1], "78.3")


if __name__ == "__main__":
    unittest.main(verbosity=2)
