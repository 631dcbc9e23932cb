"""Scene variants for the scripts that derive a scene from a shipped one (bench_scenes.py,
stability.py, work_precision.py): the variant is written next to its base while it runs, so that
the base's relative paths (e.g. `centerlines/...`) resolve as they do for the base, and it is
launched through scripts/launch.py like any scene (the launcher sets one BLAS thread per process).
Scene names resolve the same way in all of them (resolve_scene)."""
import contextlib
import os
import shutil
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


def resolve_scene(name):
    """A scene given as a path or as a name in configs/ (with or without .yaml); None if none exists."""
    for cand in (name, os.path.join(ROOT, "configs", name), os.path.join(ROOT, "configs", name + ".yaml")):
        if os.path.isfile(cand):
            return os.path.abspath(cand)
    return None


def launch_command(scene_path, run_dir, build_dir, *options):
    return [sys.executable, os.path.join(ROOT, "scripts", "launch.py"), scene_path, "--run-dir", run_dir,
            "--build-dir", build_dir, *options]
