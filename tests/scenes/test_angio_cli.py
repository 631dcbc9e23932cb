#!/usr/bin/python3
"""The `angio` command (scripts/angio): it finds a Python with numpy, scipy and yaml by itself even
when the first python3 on PATH (or ANGIO_PYTHON) lacks them, checks a scene (exit 0), refuses a bad
one with exit 2 naming the file and key, and refuses an unknown command with exit 2.
Usage: test_angio_cli.py BIN_DIR
"""
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[2]
ANGIO = ROOT / "scripts" / "angio"
failures = []


def check(name, ok, out):
    print(("ok   " if ok else "FAIL ") + name, flush=True)
    if not ok:
        print(out[-1500:])
        failures.append(name)


with tempfile.TemporaryDirectory() as tmp:
    # a python3 without the modules, first on PATH and named by ANGIO_PYTHON
    fake = Path(tmp) / "bin" / "python3"
    fake.parent.mkdir()
    fake.write_text("#!/bin/sh\necho \"ModuleNotFoundError: No module named 'numpy'\" >&2\nexit 1\n")
    fake.chmod(0o755)
    env = dict(
        os.environ,
        PATH=f"{fake.parent}:{os.environ.get('PATH', '')}",
        ANGIO_PYTHON=str(fake),
        BUILD_DIR=str(Path(sys.argv[1]).parent),
    )

    def angio(*args):
        r = subprocess.run([str(ANGIO), *map(str, args)], capture_output=True, text=True, env=env, timeout=300)
        return r.returncode, r.stdout + r.stderr

    scene = ROOT / "configs" / "generic_artery.yaml"
    code, out = angio("check", scene)
    check(
        "angio check on the shipped scene: exit 0 with a python3 lacking numpy first",
        code == 0 and "the scene is valid" in out,
        out,
    )
    bad = yaml.safe_load(scene.read_text())
    bad["balloon"]["pressure"]["value"] = 1.0e6
    bad_path = Path(tmp) / "bad.yaml"
    bad_path.write_text(yaml.safe_dump(bad, sort_keys=False))
    code, out = angio("check", bad_path)
    check(
        "angio check on a bad scene: exit 2 naming file and key",
        code == 2 and f"{bad_path}: balloon.pressure" in out and "Traceback" not in out,
        out,
    )
    code, out = angio("frobnicate")
    check("angio with an unknown command: exit 2 and the usage", code == 2 and "angio run SCENE" in out, out)
    code, out = angio("--help")
    check("angio --help: exit 0", code == 0 and "angio check SCENE" in out, out)
sys.exit(1 if failures else 0)
