"""A study file and the cases it expands into (docs/user-guide.md "Studies").

A study is one base scene and the cases derived from it: a grid (cartesian product) over scene key
paths, and/or an explicit list of changes, and/or a list of patient inputs. Every case is the base
scene plus `common` plus its own changes; its identity is a stable hash of its parameters (the
changes that make it differ from the others), which names its directory. The study's own identity
(the base scene's text and `common`) is kept in the output directory, so that two studies are never
mixed in one directory. Units in scenes and studies: mm, N, MPa, s.
"""
import copy
import hashlib
import itertools
import json
import os

import yaml

from scene_variant import SetError, apply_set

STUDY_KEYS = ("name", "base", "common", "grid", "cases", "patients", "outputs", "plot", "slurm")
PATIENT_KEYS = ("key", "files")
PLOT_KEYS = ("x", "y")
SLURM_KEYS = ("partition", "time", "mem_per_cpu", "max_parallel", "options")
# The scene key a patient input replaces unless the study names another (configs/patient_like.yaml).
PATIENT_KEY = "patient.centerline"
# The figures a study tabulates first and plots when it names none (report.py's results.json).
DEFAULT_OUTPUTS = ("stent.max", "stent.final", "stent.recoil_percent", "stent.dogboning_max_percent")


class StudyError(ValueError):
    """A study file that cannot run; the message names the file and the key."""


def params_key(params):
    """The case's identity: a stable hash of its parameters (key path -> value), order-independent."""
    text = json.dumps(params, sort_keys=True, separators=(",", ":"))
    return hashlib.sha1(text.encode()).hexdigest()[:12]


class Case:
    """One case of a study: its index in the expansion, parameters and scene."""

    def __init__(self, index, params, scene):
        self.index = index
        self.params = params
        self.scene = scene
        self.key = params_key(params)

    @property
    def name(self):
        return f"case-{self.key}"


class Study:
    def __init__(self, path):
        self.path = os.path.abspath(path)
        here = os.path.dirname(self.path)
        try:
            with open(self.path) as f:
                doc = yaml.safe_load(f)
        except (OSError, yaml.YAMLError) as e:
            raise StudyError(f"{path}: cannot read the study: {e}")
        if not isinstance(doc, dict):
            raise StudyError(f"{path}: expected a map with keys {', '.join(STUDY_KEYS)}, got {type(doc).__name__}")
        self.where = path
        for key in doc:
            if key not in STUDY_KEYS:
                raise StudyError(f"{path}: {key}: unknown key, expected one of {', '.join(STUDY_KEYS)}")
        if "base" not in doc:
            raise StudyError(f"{path}: base: missing (the scene every case starts from)")
        self.name = doc.get("name") or os.path.splitext(os.path.basename(path))[0]
        if not isinstance(self.name, str) or not self.name.replace("-", "").replace("_", "").isalnum():
            raise StudyError(f"{path}: name: expected letters, digits, '-' and '_', got {self.name!r}")
        self.base_path = os.path.normpath(os.path.join(here, str(doc["base"])))
        try:
            with open(self.base_path, "rb") as f:
                self.base_text = f.read()
            base = yaml.safe_load(self.base_text)
        except (OSError, yaml.YAMLError) as e:
            raise StudyError(f"{path}: base: cannot read the scene {self.base_path}: {e}")
        if not isinstance(base, dict):
            raise StudyError(f"{path}: base: {self.base_path} is not a scene (a map)")
        self.common = doc.get("common") or {}
        try:
            apply_set(base, self.common, f"{path}: common")
        except SetError as e:
            raise StudyError(str(e))
        self.base = base
        axes = self._grid(doc.get("grid"))
        listed = self._listed(doc.get("cases"))
        patients = self._patients(doc.get("patients"), here)
        if not axes and listed is None and not patients:
            raise StudyError(f"{path}: expected at least one of grid, cases, patients: a study of no cases")
        self.outputs = self._outputs(doc.get("outputs"))
        self.plot = self._plot(doc.get("plot"))
        self.slurm = self._slurm(doc.get("slurm"))
        self.cases = self._expand(axes, listed, patients)
        if self.plot and self.plot["x"] not in self.parameter_names():
            raise StudyError(
                f"{path}: plot: x: {self.plot['x']!r} is not a parameter of the study, expected one of "
                + ", ".join(self.parameter_names())
            )

    # -- sections --------------------------------------------------------------------------------
    def _grid(self, grid):
        if grid is None:
            return []
        if not isinstance(grid, dict) or not grid:
            raise StudyError(f"{self.where}: grid: expected a map of dotted key paths to lists of values, got {grid!r}")
        axes = []
        for key, values in grid.items():
            if not isinstance(values, list) or not values:
                raise StudyError(f"{self.where}: grid: {key}: expected a non-empty list of values, got {values!r}")
            axes.append([(key, v) for v in values])
        return axes

    def _listed(self, cases):
        if cases is None:
            return None
        if not isinstance(cases, list) or not cases:
            raise StudyError(f"{self.where}: cases: expected a non-empty list of maps (dotted key path: value)")
        for i, c in enumerate(cases):
            if not isinstance(c, dict) or not c:
                raise StudyError(
                    f"{self.where}: cases[{i}]: expected a non-empty map of dotted key paths to values, " f"got {c!r}"
                )
        return cases

    def _patients(self, patients, here):
        if patients is None:
            return []
        key, files = PATIENT_KEY, patients
        if isinstance(patients, dict):
            for k in patients:
                if k not in PATIENT_KEYS:
                    raise StudyError(f"{self.where}: patients: {k}: unknown key, expected key and files")
            key, files = patients.get("key", PATIENT_KEY), patients.get("files")
        if not isinstance(files, list) or not files:
            raise StudyError(f"{self.where}: patients: expected a non-empty list of files (or {{key, files}})")
        out = []
        for i, f in enumerate(files):
            p = os.path.normpath(os.path.join(here, str(f)))
            if not os.path.isfile(p):
                raise StudyError(f"{self.where}: patients[{i}]: {f}: no such file")
            out.append((key, p))
        return out

    def _outputs(self, outputs):
        if outputs is None:
            return list(DEFAULT_OUTPUTS)
        if not isinstance(outputs, list) or not outputs or not all(isinstance(o, str) and o for o in outputs):
            raise StudyError(f"{self.where}: outputs: expected a list of results.json paths such as stent.final")
        return outputs

    def _plot(self, plot):
        if plot is None:
            return None
        if not isinstance(plot, dict) or "x" not in plot:
            raise StudyError(f"{self.where}: plot: expected a map with x (a parameter) and optionally y (outputs)")
        for k in plot:
            if k not in PLOT_KEYS:
                raise StudyError(f"{self.where}: plot: {k}: unknown key, expected x and y")
        y = plot.get("y", self.outputs)
        if not isinstance(y, list) or not all(isinstance(o, str) for o in y):
            raise StudyError(f"{self.where}: plot: y: expected a list of results.json paths")
        return {"x": plot["x"], "y": y}

    def _slurm(self, slurm):
        if slurm is None:
            return {}
        if not isinstance(slurm, dict):
            raise StudyError(f"{self.where}: slurm: expected a map with keys {', '.join(SLURM_KEYS)}")
        for k in slurm:
            if k not in SLURM_KEYS:
                raise StudyError(f"{self.where}: slurm: {k}: unknown key, expected one of {', '.join(SLURM_KEYS)}")
        opts = slurm.get("options", [])
        if not isinstance(opts, list) or not all(isinstance(o, str) and o.startswith("--") for o in opts):
            raise StudyError(f"{self.where}: slurm: options: expected a list of sbatch options such as --account=x")
        mp = slurm.get("max_parallel")
        if mp is not None and (isinstance(mp, bool) or not isinstance(mp, int) or mp < 1):
            raise StudyError(f"{self.where}: slurm: max_parallel: expected a positive integer, got {mp!r}")
        return slurm

    # -- expansion -------------------------------------------------------------------------------
    def _expand(self, axes, listed, patients):
        combos = [dict(c) for c in itertools.product(*axes)] if axes else [{}]
        rows = []
        for g in combos:
            for i, extra in enumerate(listed if listed is not None else [{}]):
                clash = set(g) & set(extra)
                if clash:
                    raise StudyError(
                        f"{self.where}: cases[{i}]: {sorted(clash)[0]}: also a grid axis; "
                        "give each key path in one of grid and cases"
                    )
                for pk in patients or [None]:
                    params = {**g, **extra}
                    if pk is not None:
                        if pk[0] in params:
                            raise StudyError(f"{self.where}: patients: {pk[0]}: also set by grid or cases")
                        params[pk[0]] = pk[1]
                    rows.append(params)
        cases, seen = [], {}
        for index, params in enumerate(rows):
            scene = copy.deepcopy(self.base)
            try:
                apply_set(scene, params, f"{self.where}: case {index} {json.dumps(params, sort_keys=True)}")
            except SetError as e:
                raise StudyError(str(e))
            c = Case(index, params, scene)
            if c.key in seen:
                raise StudyError(
                    f"{self.where}: cases {seen[c.key]} and {index} are the same case "
                    f"({json.dumps(params, sort_keys=True)}): remove the duplicate"
                )
            seen[c.key] = index
            cases.append(c)
        return cases

    # -- identity --------------------------------------------------------------------------------
    def identity(self):
        """What must not change under a study's finished cases: its name, base scene text and common
        changes (adding grid values or cases keeps the finished ones)."""
        return {
            "name": self.name,
            "base": self.base_path,
            "base_sha1": hashlib.sha1(self.base_text).hexdigest(),
            "common": json.loads(json.dumps(self.common, sort_keys=True)),
        }

    def parameter_names(self):
        return list(dict.fromkeys(k for c in self.cases for k in c.params))

    def ranks(self, case):
        """The solid's MPI ranks of a case (solid.ranks, 1 if absent)."""
        solid = case.scene.get("solid") or {}
        r = solid.get("ranks", 1) if isinstance(solid, dict) else 1
        return r if isinstance(r, int) and not isinstance(r, bool) and r >= 1 else 1
