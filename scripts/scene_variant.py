"""Scene variants for the scripts that derive a scene from a shipped one (bench_scenes.py,
stability.py, work_precision.py, sensitivity.py): the variant is written next to its base while it
runs, so that the base's relative paths (e.g. `centerlines/...`) resolve as they do for the base,
and it is launched through scripts/launch.py like any scene (the launcher sets one BLAS thread per
process). Scene names resolve the same way in all of them (resolve_scene); changes given as dotted
key paths are applied the same way in all of them (apply_set)."""
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
