#!/usr/bin/python3
"""The procedure's virtual insertion (scripts/procedure.py, scripts/insertion_tool.py) on scene
dicts, without solvers: when a phase's crimped devices need the tool (against the radii written
in the scene), the pressure-free window it works in (against the load curves' definition), the
tool's radius curve and the contacts' switch-on time (against the schedule's fractions), and the
errors naming the key. The runs themselves: configs/stability/procedure_tightest_lumen.yaml."""
import copy
import json
import math
import sys
import tempfile
import unittest
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))
import insertion_tool  # noqa: E402
import procedure  # noqa: E402
import yaml  # noqa: E402

TINY = ROOT / "tests" / "scenes" / "data" / "tiny_procedure.yaml"


def tiny(**curves):
    s = yaml.safe_load(TINY.read_text())
    s["load_curves"].update(curves)
    return s


class CurveWindow(unittest.TestCase):
    def test_curve_value_interpolates_and_holds(self):
        c = [[0.0, 0.0], [1.0, 2.0], [2.0, 0.0]]
        self.assertEqual(insertion_tool.curve_value(c, -1.0), 0.0)
        self.assertEqual(insertion_tool.curve_value(c, 0.25), 0.5)
        self.assertEqual(insertion_tool.curve_value(c, 1.5), 1.0)
        self.assertEqual(insertion_tool.curve_value(c, 5.0), 0.0)

    def test_quiet_until_is_the_last_zero_breakpoint(self):
        self.assertEqual(insertion_tool.quiet_until([[1.0, 0.0], [1.25, 0.0], [1.5, 1.3]], 1.0), 1.25)
        self.assertEqual(insertion_tool.quiet_until([[1.0, 0.0], [1.5, 1.3]], 1.0), 1.0)  # rises at once
        self.assertEqual(insertion_tool.quiet_until([[0.0, 0.0], [0.5, 1.0]], -0.6), 0.0)  # held 0 before
        self.assertEqual(insertion_tool.quiet_until([[0.0, 0.0], [0.5, 1.0]], 0.2), 0.2)  # already rising
        self.assertEqual(insertion_tool.quiet_until([[0.0, 0.0], [1.0, 0.0]], 0.0), math.inf)

    def test_add_tool_schedule_and_contacts(self):
        s = {"contact": {"stent_artery": {"penalty": 10.0}, "balloon_artery": {"penalty": 5.0, "from": 1.9}}}
        rep = insertion_tool.add_tool(s, 1.0, 2.0, 0.3, 0.7, 300.0)
        self.assertEqual(s["load_curves"]["insertion_tool"], [[1.0, 0.3], [1.5, 0.7], [1.6, 0.7], [2.0, 0.0]])
        self.assertEqual(
            s["contact"]["insertion"],
            {"axis": "balloon", "radius": {"value": 1.0, "curve": "insertion_tool"}, "penalty": 300.0},
        )
        self.assertEqual(s["contact"]["stent_artery"]["from"], 1.55)  # on once the tool is open
        self.assertEqual(s["contact"]["balloon_artery"]["from"], 1.9)  # the scene's later switch-on kept
        self.assertEqual(rep["contacts_from"], {"stent_artery": 1.55, "balloon_artery": 1.9})


class Plan(unittest.TestCase):
    def phases(self, scene):
        return procedure.phases(scene, "s.yaml")

    def test_devices_that_fit_need_no_tool(self):
        s = tiny()
        ph = self.phases(s)
        # predilatation balloon 0.9 mm: a 1.1 mm lumen clears it by 0.1 mm, more than the 0.065 mm clearance
        self.assertIsNone(procedure.insertion_plan(s, ph[0], 0, 1.1, "s.yaml"))

    def test_tight_first_phase_opens_to_the_balloon_plus_clearance(self):
        s = tiny()
        s["time"]["start"] = -0.6
        ph = self.phases(s)
        plan = procedure.insertion_plan(s, ph[0], 0, 0.4, "s.yaml")
        self.assertEqual((plan["t0"], plan["t1"]), (-0.6, 0.0))  # predil curve rises at t = 0
        self.assertAlmostEqual(plan["r0"], 0.9 * 0.2, places=12)
        self.assertAlmostEqual(plan["r_open"], 0.45 + 0.065, places=12)

    def test_the_deploying_phase_sizes_by_the_crimped_stent(self):
        s = tiny(deploy=[[1.0, 0.0], [1.25, 0.0], [1.5, 1.3], [2.0, 0.0]])
        ph = self.phases(s)
        self.assertTrue(ph[1]["new_stent"])
        plan = procedure.insertion_plan(s, ph[1], 1, 0.8, "s.yaml")
        self.assertAlmostEqual(plan["device_radius"], 1.15 / 2 + 0.06, places=12)  # crimped D/2 + strut radius
        self.assertEqual((plan["t0"], plan["t1"]), (1.0, 1.25))
        # 1.27 mm of stent in a 1.36 mm lumen: fits with 0.045 < 0.065 mm to spare -> tool; 1.41 mm fits
        self.assertIsNotNone(procedure.insertion_plan(s, ph[1], 1, 1.36, "s.yaml"))
        self.assertIsNone(procedure.insertion_plan(s, ph[1], 1, 1.41, "s.yaml"))

    def test_no_tool_inside_a_deployed_stent(self):
        s = tiny()
        ph = self.phases(s)
        self.assertTrue(ph[2]["stent"] and not ph[2]["new_stent"])
        self.assertIsNone(procedure.insertion_plan(s, ph[2], 2, 0.5, "s.yaml"))

    def test_no_pressure_free_time_names_the_curve(self):
        s = tiny()  # the deploy curve rises at the stenting's start
        ph = self.phases(s)
        with self.assertRaisesRegex(procedure.ProcedureError, r"load_curves\.deploy: expected no balloon pressure"):
            procedure.insertion_plan(s, ph[1], 1, 0.8, "s.yaml")
        s = tiny(deploy=[[1.0, 0.0], [1.1, 0.0], [1.5, 1.3], [2.0, 0.0]])  # 1.6 of 4 load steps
        with self.assertRaisesRegex(procedure.ProcedureError, r"at least 4 load steps"):
            procedure.insertion_plan(s, self.phases(s)[1], 1, 0.8, "s.yaml")

    def test_mode_off_refuses_a_tight_lesion(self):
        s = tiny()
        s["time"]["start"] = -0.6
        s["procedure"][0]["insertion"] = {"mode": "off"}
        with self.assertRaisesRegex(procedure.ProcedureError, r"procedure\[0\]\.insertion\.mode: expected auto"):
            procedure.insertion_plan(s, self.phases(s)[0], 0, 0.4, "s.yaml")

    def test_bad_insertion_keys_are_named(self):
        s = tiny()
        s["procedure"][0]["insertion"] = {"clearence": 0.1}
        with self.assertRaisesRegex(
            procedure.ProcedureError, r"procedure\[0\]\.insertion\.clearence: unknown key.*clearance"
        ):
            self.phases(s)
        s["procedure"][0]["insertion"] = {"clearance": -1}
        with self.assertRaisesRegex(procedure.ProcedureError, r"procedure\[0\]\.insertion\.clearance: expected"):
            self.phases(s)
        s = tiny(insertion_tool=[[0, 0]])
        with self.assertRaisesRegex(procedure.ProcedureError, r"load_curves\.insertion_tool: expected no curve"):
            procedure.complete(s, "s.yaml", "/nonexistent")

    def test_a_patient_first_phase_s_insertion_keys_reach_the_pipeline(self):
        # the patient pipeline's tool serves the first phase: its keys were silently ignored before
        s = tiny()
        s["patient"] = {"insertion": {"clearance": 0.05}}
        s["procedure"][0]["insertion"] = {"penalty": 30.0}
        out = procedure._first_tool_in_patient(s, "s.yaml")
        self.assertNotIn("procedure", out)
        self.assertEqual(out["patient"]["insertion"], {"clearance": 0.05, "penalty": 30.0})
        self.assertEqual(s["patient"]["insertion"], {"clearance": 0.05})  # the user's scene unchanged
        s["procedure"][0]["insertion"] = {"clearance": 0.1}
        with self.assertRaisesRegex(
            procedure.ProcedureError, r"procedure\[0\]\.insertion\.clearance: expected none or patient\.insertion"
        ):
            procedure._first_tool_in_patient(s, "s.yaml")
        s["procedure"][0]["insertion"] = {"penalty": -1}
        with self.assertRaisesRegex(procedure.ProcedureError, r"procedure\[0\]\.insertion\.penalty: expected"):
            procedure._first_tool_in_patient(s, "s.yaml")
        s["procedure"][0]["insertion"] = {"penalty": 30.0}
        del s["patient"]
        self.assertNotIn("patient", procedure._first_tool_in_patient(s, "s.yaml"))  # not a patient scene

    def test_phase_scene_carries_the_tool_and_drops_an_earlier_phase_s(self):
        s = tiny(deploy=[[1.0, 0.0], [1.25, 0.0], [1.5, 1.3], [2.0, 0.0]])
        ph = self.phases(s)
        plan = procedure.insertion_plan(s, ph[1], 1, 0.8, "s.yaml")
        one = procedure.phase_scene(s, ph[1], (Path("/r/1-predilatation"), False), plan)
        self.assertEqual(one["contact"]["insertion"]["radius"]["curve"], "insertion_tool")
        self.assertEqual(one["contact"]["stent_artery"]["from"], 1.1375)  # 1.0 + 0.55 * 0.25
        # a tool of the first phase (as the patient pipeline writes it) is not carried into the next
        first = copy.deepcopy(s)
        insertion_tool.add_tool(first, -0.2, 0.0, 0.2, 0.7, 300.0)
        two = procedure.phase_scene(first, ph[2], (Path("/r/2-stenting"), True))
        self.assertNotIn("insertion", two["contact"])
        self.assertNotIn("insertion_tool", two["load_curves"])

    def test_the_lumen_before_is_the_one_before_the_patient_pipeline_s_tool(self):
        # the pipeline's tool (a patient procedure's first phase) opens the lesion from t = -0.2 s and
        # retracts onto the crimped balloon by t = 0: the lumen before the procedure is the lesion's,
        # as for a tool the procedure plans itself (it was the one resting on the balloon at t = 0)
        s = tiny()
        ph = self.phases(s)[:1]
        steps = [
            {"time": -0.2, "balloon_pressure": 0.0, "lumen_diameter": [2.0, 0.7, 2.0]},
            {"time": -0.1, "balloon_pressure": 0.0, "lumen_diameter": [2.0, 1.4, 2.0]},
            {"time": 0.0, "balloon_pressure": 0.0, "lumen_diameter": [2.0, 0.9, 2.0]},
            {"time": 0.5, "balloon_pressure": 1.0, "lumen_diameter": [2.0, 1.5, 2.0]},
        ]
        with tempfile.TemporaryDirectory() as tmp:
            d = procedure.phase_dir(tmp, 0, ph[0]) / "solid"
            d.mkdir(parents=True)
            (d / "summary.json").write_text(json.dumps({"lumen_stations": [-1.0, 0.0, 1.0], "steps": steps}))
            ran = [(0, ph[0], "ok", 1.0)]
            without = procedure.summarize(tmp, s, "s.yaml", ran)
            self.assertEqual(without["lumen_before_procedure"]["time"], 0.0)
            insertion_tool.add_tool(s, -0.2, 0.0, 0.3, 0.7, 30.0)  # as the pipeline writes it
            out = procedure.summarize(tmp, s, "s.yaml", ran)
            self.assertEqual(out["lumen_before_procedure"]["time"], -0.2)
            self.assertEqual(out["phases"][0]["lumen"]["min_diameter_before_procedure"], 0.7)
            s["load_curves"]["mine"] = s["load_curves"].pop("insertion_tool")
            s["contact"]["insertion"]["radius"]["curve"] = "mine"  # the scene's own tool: not the pipeline's
            self.assertIsNone(procedure.pipeline_tool_start(s))

    def test_lumen_under_the_balloon(self):
        s = tiny()
        ph = self.phases(s)
        summary = {"lumen_stations": [-2.5, -1.0, 0.0, 1.0, 2.5]}
        step = {"lumen_diameter": [0.3, 1.2, 0.8, 1.1, 0.2]}
        # the predilatation balloon (2 mm at the artery's centre) covers stations -1 .. 1 only
        self.assertEqual(procedure.lumen_under(summary, step, s, ph[0]), 0.8)

    def test_segment_of_curved_devices_from_their_placed_stations(self):
        # a patient's balloons lie on a curved device centerline: no extent along the tube axis, so
        # without their placed stations the segment is every station and there is no reference lumen
        s = tiny()
        ph = self.phases(s)
        for p in ph:
            if p["balloon"] is not None:
                p["balloon"] = {"mesh": {"generator": "tube", "length": 2.0, "centerline": {"file": "c.txt"}}}
        stations = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0]
        self.assertIsNone(procedure.treated_segment(s, ph, stations, None))
        placed = {ph[0]["name"]: (2.0, 4.0), ph[1]["name"]: (1.8, 4.2), ph[2]["name"]: (2.5, 3.5)}
        mask = procedure.treated_segment(s, ph, stations, (1.5, 4.5), placed)
        self.assertEqual(mask, [False, False, True, True, True, False, False])
        # the reference lumen: the first station outside the segment on either side (1 and 5 mm)
        before = {"lumen_diameter": [3.0, 2.0, 1.0, 0.5, 1.0, 4.0, 3.0]}
        ref = procedure.reference_area(before, mask)
        self.assertAlmostEqual(ref, 0.5 * (math.pi * 2.0**2 / 4 + math.pi * 4.0**2 / 4))


if __name__ == "__main__":
    unittest.main()
