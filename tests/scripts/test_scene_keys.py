#!/usr/bin/python3
"""The scene-key declarations (core/scene/keys.yaml, scripts/scene_keys.py): every key of every
shipped scene is declared, the Python checks and defaults follow the declarations, and the tools that
used to carry their own copy of a default now read the declared one. Consistency tests (no solver).

  python3 tests/scripts/test_scene_keys.py
"""
import glob
import sys
import tempfile
import unittest
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

import launch  # noqa: E402
import procedure  # noqa: E402
import scene_keys  # noqa: E402
from patient.errors import PatientInputError  # noqa: E402
from patient.lumen_surface import UNITS  # noqa: E402
from patient.prepare import device_of  # noqa: E402


def key_paths(node, path=""):
    """Every map key of a scene as a dotted path with list indices, not below a key declared `any`."""
    d = scene_keys.declared(path) if path else None
    if d is not None and d.types == ("any",):
        return
    if isinstance(node, dict):
        for k, v in node.items():
            sub = f"{path}.{k}" if path else str(k)
            yield sub
            yield from key_paths(v, sub)
    elif isinstance(node, list):
        for i, v in enumerate(node):
            if isinstance(v, dict):
                yield from key_paths(v, f"{path}[{i}]")


def shipped_scenes():
    files = sorted(glob.glob(str(ROOT / "configs" / "**" / "*.yaml"), recursive=True))
    files += sorted(glob.glob(str(ROOT / "tests" / "**" / "*.yaml"), recursive=True))
    for f in files:
        # not scenes of the solvers: the coupler's test participants (built-in parameters), the scene
        # reader's own fixtures, a material error on purpose
        if any(x in f for x in ("/tests/coupler/data/", "/tests/protocol/data/", "bad_material")):
            continue
        with open(f) as fh:
            scene = yaml.safe_load(fh)
        # study and stability-case files name a base scene and changes; they are not scenes
        if isinstance(scene, dict) and not ({"base", "grid", "changes", "set"} & set(scene)):
            yield f, scene


class SceneKeys(unittest.TestCase):
    def test_every_key_of_every_shipped_scene_is_declared(self):
        n = 0
        for f, scene in shipped_scenes():
            for p in key_paths(scene):
                n += 1
                self.assertIsNotNone(scene_keys.declared(p), f"{f}: {p} is not declared in core/scene/keys.yaml")
        self.assertGreater(n, 500)  # the walk reached the scenes' keys

    def test_lookup_prefers_exact_names_and_matches_list_entries(self):
        self.assertEqual(scene_keys.declared("artery.layers.media.fibers[3].k1").path, "artery.layers.*.fibers[].k1")
        self.assertEqual(scene_keys.declared("artery.mesh.layers[0].name").path, "artery.mesh.layers[].name")
        self.assertIsNone(scene_keys.declared("artery.layers[0].E"))  # a map of names, not a list
        self.assertIsNone(scene_keys.declared("coupling.rel_tl"))
        self.assertEqual(scene_keys.children("artery.layers.intima"), ["E", "nu", "fibers", "viscous"])

    def test_check_map_fills_defaults_and_names_the_key(self):
        got = scene_keys.check_map({"size": 0.4}, "patient.mesh", "s.yaml", PatientInputError)
        self.assertEqual(got, {"size": 0.4, "binary": True, "loft_spacing": 0.5, "refine": None})
        cases = [
            ({"siez": 0.4}, "s.yaml: patient.mesh.siez: unknown key", "did you mean `size`?"),
            ({"size": -1}, "s.yaml: patient.mesh.size: expected a positive number (mm), got -1", ""),
            ({"size": True}, "patient.mesh.size: expected a positive number", ""),
            ({"binary": "yes"}, "patient.mesh.binary: expected true or false", ""),
        ]
        for value, first, second in cases:
            with self.assertRaises(PatientInputError) as e:
                scene_keys.check_map(value, "patient.mesh", "s.yaml", PatientInputError)
            self.assertIn(first, str(e.exception))
            self.assertIn(second, str(e.exception))
        # a key of two shapes: a string out of its values, or a number in its range
        for ok in ("auto", 3.5):
            self.assertEqual(scene_keys.check_map({"stenosis": ok}, "patient", "s", PatientInputError)["stenosis"], ok)
        with self.assertRaises(PatientInputError) as e:
            scene_keys.check_map({"stenosis": -2}, "patient", "s", PatientInputError)
        self.assertIn("patient.stenosis: expected one of auto or a non-negative number (mm)", str(e.exception))
        with self.assertRaises(PatientInputError) as e:
            scene_keys.check_map({}, "patient.lumen_surface", "s", PatientInputError)
        self.assertIn("patient.lumen_surface.file: missing", str(e.exception))

    def test_the_tools_read_the_declarations(self):
        self.assertEqual(launch.SECTIONS, tuple(scene_keys.children("")))
        self.assertEqual(procedure.PHASE_KEYS, ("name", "end", "steps", "balloon", "stent", "insertion"))
        self.assertEqual(set(scene_keys.declared("patient.lumen_surface.units").values), set(UNITS))
        # device_of sizes the crimped stent with the generator's declared defaults (it once assumed 6
        # rings where the beam solver generated 4): (rings - 1) x pitch + strut height
        scene = {
            "balloon": {"mesh": {"generator": "tube", "length": 10.0, "outer_diameter": 1.0}},
            "stent": {"generator": {"type": "corrugated_rings"}, "section": {"radius": 0.05}},
        }
        dev = device_of(scene, "s.yaml")
        rings, pitch, height = (
            scene_keys.default(f"stent.generator.{k}") for k in ("rings", "ring_pitch", "strut_height")
        )
        self.assertAlmostEqual(dev.stent_length, (rings - 1) * pitch + height)
        self.assertAlmostEqual(dev.stent_radius, 0.5 * scene_keys.default("stent.generator.crimped_diameter") + 0.05)

    def test_generated_header_declares_every_key_and_its_defaults(self):
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp) / "keys_generated.hpp"
            self.assertEqual(scene_keys.main(["--cpp", str(out)]), 0)
            text = out.read_text()
        for d in scene_keys.declarations().values():
            self.assertIn(f'{{"{d.path}", ', text)
        self.assertIn("inline constexpr double coupling_rel_tol = 0.0001;", text)
        self.assertIn("inline constexpr int stent_generator_rings = 4;", text)

    def test_defaults_lie_in_their_ranges(self):
        for d in scene_keys.declarations().values():
            if d.has_default and d.range is not None and isinstance(d.default, (int, float)):
                self.assertIn(d.default, d.range, d.path)


if __name__ == "__main__":
    unittest.main()
