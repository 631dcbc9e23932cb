"""Scene variants for the scripts that derive a scene from a shipped one (bench_scenes.py,
stability.py, work_precision.py, sensitivity.py): the variant is written next to its base while it
runs, so that the base's relative paths (e.g. `centerlines/...`) resolve as they do for the base,
and it is launched through scripts/launch.py like any scene (the launcher sets one BLAS thread per
process). Scene names resolve the same way in all of them (resolve_scene); changes given as dotted
key paths are applied the same way in all of them (apply_set), and study files (a base scene, common
changes, named changes) are read the same way by sensitivity.py and bench_ranks.py (load_study)."""
import contextlib
import copy
import json
import os
import shutil
import subprocess
import sys

import yaml

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


@contextlib.contextmanager
def variant_scene(base_path, scene, tag, header, keep=None):
    """Yields the path of `scene` written as a hidden file beside `base_path`; removes it afterwards,
    leaving a copy at `keep` if given."""
    path = os.path.join(os.path.dirname(base_path), f".{tag}_{os.getpid()}.yaml")
    with open(path, "w") as f:
        f.write(f"# {header}\n")
        yaml.safe_dump(scene, f, sort_keys=False)
    try:
        yield path
    finally:
        if keep:
            shutil.copy(path, keep)
        os.remove(path)


class SetError(ValueError):
    """A change that does not fit the base scene; the message names where it was given and the key."""


def apply_set(scene, changes, where):
    """Applies `changes` ({dotted.key.path: value}) to `scene` in place: each value replaces the
    base's (a map or list included, as a whole); the maps (or lists, indexed by a number, e.g.
    procedure.2.steps) on the way must exist in the base, so a misspelt section is an error instead
    of a new key. `where` (e.g. "case.yaml: set") starts the message of the SetError raised otherwise."""
    if not isinstance(changes, dict):
        raise SetError(f"{where}: expected a map of dotted key paths to values, got {type(changes).__name__}")
    for key, value in changes.items():
        if not isinstance(key, str) or not all(key.split(".")):
            raise SetError(f"{where}: {key!r}: expected a dotted key path such as artery.mesh.n_circ")
        node, parts = scene, key.split(".")
        for p in parts[:-1]:
            if isinstance(node, list):
                if not (p.isdigit() and int(p) < len(node) and isinstance(node[int(p)], (dict, list))):
                    raise SetError(f"{where}: {key}: the base scene has no entry {p} in its list there")
                node = node[int(p)]
                continue
            if not isinstance(node.get(p), (dict, list)):
                raise SetError(f"{where}: {key}: the base scene has no map at '{p}'")
            node = node[p]
        if isinstance(node, list):
            last = parts[-1]
            if not (last.isdigit() and int(last) < len(node)):
                raise SetError(f"{where}: {key}: the base scene has no entry {last} in its list there")
            node[int(last)] = copy.deepcopy(value)
        else:
            node[parts[-1]] = copy.deepcopy(value)
    return scene


class StudyError(ValueError):
    """A bad study file (bench/sensitivity.py, bench/bench_ranks.py); the message names the file and key."""


STUDY_KEYS = ("base", "common", "changes")


def _yaml_map(path, where, expected):
    """The map in the YAML file `path`; StudyError starting with `where` if unreadable or not a map."""
    try:
        doc = yaml.safe_load(open(path))
    except (OSError, yaml.YAMLError) as e:
        raise StudyError(f"{where}: {e}") from None
    if not isinstance(doc, dict):
        raise StudyError(f"{where}: expected {expected}, got {type(doc).__name__}")
    return doc


def load_study(path, extra_keys=()):
    """A study file: `base` (a scene, relative to the study), `common` ({dotted.key.path: value} for
    every run), `changes` (a non-empty list of {name, set}: the baseline plus `set` each), and the
    calling script's own `extra_keys`. Returns (base scene path, [(name, changes, scene)] with the
    baseline first and named "baseline", the study map); StudyError on a bad file."""
    keys = STUDY_KEYS + tuple(extra_keys)
    study = _yaml_map(path, f"{path}", f"a map with keys {', '.join(keys)}")
    for key in study:
        if key not in keys:
            raise StudyError(f"{path}: {key}: unknown key, expected {', '.join(keys)}")
    for key in ("base", "changes"):
        if key not in study:
            raise StudyError(f"{path}: {key}: missing")
    if not isinstance(study["changes"], list) or not study["changes"]:
        raise StudyError(f"{path}: changes: expected a non-empty list of {{name, set}}")
    base_path = os.path.normpath(os.path.join(os.path.dirname(path), str(study["base"])))
    base = _yaml_map(base_path, f"{path}: base", f"a scene (a map) in {base_path}")
    runs, names = [], {"baseline"}
    try:
        apply_set(base, study.get("common") or {}, f"{path}: common")
        runs.append(("baseline", {}, base))
        for i, c in enumerate(study["changes"]):
            where = f"{path}: changes[{i}]"
            if not isinstance(c, dict):
                raise StudyError(f"{where}: expected a map with name and set, got {c!r}")
            for key in c:
                if key not in ("name", "set"):
                    raise StudyError(f"{where}: {key}: unknown key, expected name and set")
            name = c.get("name")
            if not isinstance(name, str) or not name.strip():
                raise StudyError(f"{where}: name: expected a non-empty string, got {name!r}")
            if name in names:
                raise StudyError(
                    f"{where}: name: "
                    + (
                        "'baseline' names the unchanged run, expected another name"
                        if name == "baseline"
                        else f"'{name}' is given twice"
                    )
                )
            names.add(name)
            if not isinstance(c.get("set"), dict) or not c["set"]:
                raise StudyError(
                    f"{where} ({name}): set: expected a map of dotted key paths to values, got {c.get('set')!r}"
                )
            runs.append((name, c["set"], apply_set(copy.deepcopy(base), c["set"], f"{where} ({name}): set")))
    except SetError as e:
        raise StudyError(str(e)) from None
    return base_path, runs, study


def resolve_scene(name):
    """A scene given as a path or as a name in configs/ (with or without .yaml); None if none exists."""
    for cand in (name, os.path.join(ROOT, "configs", name), os.path.join(ROOT, "configs", name + ".yaml")):
        if os.path.isfile(cand):
            return os.path.abspath(cand)
    return None


def launch_command(scene_path, run_dir, build_dir, *options):
    return [
        sys.executable,
        os.path.join(ROOT, "scripts", "launch.py"),
        scene_path,
        "--run-dir",
        run_dir,
        "--build-dir",
        build_dir,
        *options,
    ]


def coupling_settings(scene_path, build_dir):
    """The scene's coupling settings as the coupler runs them, every default filled in
    (`coupler --print-settings`): the defaults are declared once, in the C++."""
    exe = os.path.join(build_dir, "bin", "coupler")
    out = subprocess.run([exe, "--scene", scene_path, "--print-settings"], capture_output=True, text=True)
    if out.returncode != 0:
        raise ValueError(f"{exe} --print-settings failed: {out.stderr.strip() or out.stdout.strip()}")
    return json.loads(out.stdout)
