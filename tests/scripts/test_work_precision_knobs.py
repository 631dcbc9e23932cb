#!/usr/bin/python3
"""bench/work_precision.py's knobs on the shipped scenes, without running anything (stdlib unittest).

  python3 tests/scripts/test_work_precision_knobs.py

The artery_size knob sets a patient artery's element size and nothing else (the balloon's mesh is
kept, a refined span keeps its ratio to the rest), is finer when smaller, and is offered only for a
scene with a patient artery; a variant of it hashes like the same scene written by hand, so a long
run made with launch.py is taken by --reuse. The intima_size knob refines the intima alone over the
balloon's span and nothing else, its shipped level is the scene itself, and a variant hashes like the
scene written by hand; it is offered only for a patient artery without its own refinement. The
artery_mesh knob scales a generated tube artery's divisions and nothing else, and is offered only for
such a scene.
"""
import copy
import sys
import unittest
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "bench"))
import work_precision as wp  # noqa: E402

COUPLING = {"rel_tol": 5e-3}


def scene(name):
    return yaml.safe_load(open(ROOT / "configs" / name))


class ArterySizeKnob(unittest.TestCase):
    def test_ladder_of_the_patient_scene(self):
        base = scene("patient_like.yaml")
        levels, apply, shipped, _, ratio = wp.knobs(base, False, COUPLING)["artery_size"]
        self.assertEqual(shipped, base["patient"]["mesh"]["size"])
        self.assertEqual(levels, [shipped, shipped / 1.5, shipped / 2.0])
        self.assertIsNone(ratio)  # not a geometric ladder from the shipped size down: no Richardson
        s = copy.deepcopy(base)
        apply(s, 0.25)
        self.assertEqual(s["patient"]["mesh"]["size"], 0.25)
        self.assertEqual(s["balloon"], base["balloon"])  # only the wall is refined
        s["patient"]["mesh"]["size"] = shipped
        self.assertEqual(s, base)  # and nothing else changed

    def test_refined_span_keeps_its_ratio(self):
        base = scene("patient_like.yaml")
        base["patient"]["mesh"]["refine"] = {"size": 0.4, "layers": ["intima"]}
        s = copy.deepcopy(base)
        wp.knobs(base, False, COUPLING)["artery_size"][1](s, 0.4)
        self.assertAlmostEqual(s["patient"]["mesh"]["refine"]["size"], 0.2, places=12)
        self.assertEqual(s["patient"]["mesh"]["refine"]["layers"], ["intima"])

    def test_default_size_when_the_scene_gives_none(self):
        base = scene("patient_like.yaml")
        del base["patient"]["mesh"]
        levels = wp.knobs(base, False, COUPLING)["artery_size"][0]
        self.assertEqual(levels[0], wp.default("patient.mesh.size"))
        s = copy.deepcopy(base)
        wp.knobs(base, False, COUPLING)["artery_size"][1](s, 0.5)
        self.assertEqual(s["patient"]["mesh"], {"size": 0.5})

    def test_mesh_knob_refines_the_wall_alike(self):
        # the mesh knob refines a patient wall through the same setting (and the balloon besides),
        # also where the scene gives no patient.mesh (it did not before: the wall stayed coarse)
        for drop in (False, True):
            base = scene("patient_like.yaml")
            if drop:
                del base["patient"]["mesh"]
            h = wp.knobs(base, False, COUPLING)["artery_size"][2]
            s = copy.deepcopy(base)
            wp.knobs(base, False, COUPLING)["mesh"][1](s, 2.0)
            self.assertEqual(s["patient"]["mesh"]["size"], h / 2.0)
            self.assertNotEqual(s["balloon"]["mesh"], base["balloon"]["mesh"])

    def test_only_for_a_patient_artery(self):
        for name in ("straight_free_expansion.yaml", "generic_artery.yaml"):
            self.assertNotIn("artery_size", wp.knobs(scene(name), False, COUPLING), name)

    def test_smaller_is_finer(self):
        self.assertTrue(wp.is_finer("artery_size", 0.25, 0.8))
        self.assertFalse(wp.is_finer("artery_size", 0.8, 0.25))

    def test_variant_hashes_like_the_same_scene_written_by_hand(self):
        base = scene("patient_like.yaml")
        s = copy.deepcopy(base)
        wp.knobs(base, False, COUPLING)["artery_size"][1](s, 0.533)
        text = (ROOT / "configs" / "patient_like.yaml").read_text()
        by_hand = yaml.safe_load(text.replace("mesh: {size: 0.8,", "mesh: {size: 0.533,"))
        self.assertNotEqual(by_hand, base)  # the replacement took
        self.assertEqual(wp.scene_key(s), wp.scene_key(by_hand))


class IntimaSizeKnob(unittest.TestCase):
    def test_ladder_of_the_patient_scene(self):
        base = scene("patient_like.yaml")
        levels, apply, shipped, _, ratio = wp.knobs(base, False, COUPLING)["intima_size"]
        self.assertEqual(shipped, base["patient"]["mesh"]["size"])
        self.assertEqual(levels, [0.8, 0.4, 0.25])  # to the paper's 0.25 mm
        self.assertIsNone(ratio)
        s = copy.deepcopy(base)
        apply(s, shipped)
        self.assertEqual(s, base)  # the shipped level is the scene itself
        apply(s, 0.25)
        self.assertEqual(s["patient"]["mesh"]["refine"], {"size": 0.25, "layers": ["intima"]})
        self.assertEqual(s["patient"]["mesh"]["size"], shipped)  # the other layers keep the wall's size
        self.assertEqual(s["balloon"], base["balloon"])
        del s["patient"]["mesh"]["refine"]
        self.assertEqual(s, base)  # and nothing else changed
        apply(s, 0.4)
        apply(s, shipped)
        self.assertEqual(s, base)  # back to the shipped level: the refinement is gone again

    def test_variant_hashes_like_the_same_scene_written_by_hand(self):
        base = scene("patient_like.yaml")
        s = copy.deepcopy(base)
        wp.knobs(base, False, COUPLING)["intima_size"][1](s, 0.25)
        text = (ROOT / "configs" / "patient_like.yaml").read_text()
        refined = "mesh: {size: 0.8, binary: true, refine: {size: 0.25, layers: [intima]}}"
        by_hand = yaml.safe_load(text.replace("mesh: {size: 0.8, binary: true}", refined))
        self.assertNotEqual(by_hand, base)  # the replacement took
        self.assertEqual(wp.scene_key(s), wp.scene_key(by_hand))

    def test_only_for_a_patient_artery_without_its_own_refinement(self):
        for name in ("straight_free_expansion.yaml", "generic_artery.yaml"):
            self.assertNotIn("intima_size", wp.knobs(scene(name), False, COUPLING), name)
        base = scene("patient_like.yaml")
        base["patient"]["mesh"]["refine"] = {"size": 0.4}  # its shipped level would not be the scene
        self.assertNotIn("intima_size", wp.knobs(base, False, COUPLING))

    def test_smaller_is_finer(self):
        self.assertTrue(wp.is_finer("intima_size", 0.25, 0.8))
        self.assertFalse(wp.is_finer("intima_size", 0.8, 0.25))


class ArteryMeshKnob(unittest.TestCase):
    def test_ladder_of_the_generic_scene(self):
        base = scene("generic_artery.yaml")
        levels, apply, shipped, _, _ = wp.knobs(base, False, COUPLING)["artery_mesh"]
        self.assertEqual((levels, shipped), ([1.0, 1.5, 2.0], 1.0))
        m = base["artery"]["mesh"]
        for f, want in ((0.667, (32, 24, [1, 1])), (1.5, (72, 54, [3, 3]))):  # the ladder study's meshes
            s = copy.deepcopy(base)
            apply(s, f)
            got = s["artery"]["mesh"]
            self.assertEqual((got["n_circ"], got["n_axial"], [L["n_radial"] for L in got["layers"]]), want)
            self.assertEqual(s["balloon"], base["balloon"])  # only the wall is refined
            for k in ("n_circ", "n_axial", "layers"):
                got[k] = m[k]
            self.assertEqual(s, base)  # and nothing else changed

    def test_only_for_a_tube_artery(self):
        for name in ("straight_free_expansion.yaml", "patient_like.yaml"):
            self.assertNotIn("artery_mesh", wp.knobs(scene(name), False, COUPLING), name)

    def test_larger_is_finer(self):
        self.assertTrue(wp.is_finer("artery_mesh", 1.5, 1.0))


if __name__ == "__main__":
    unittest.main()
