#!/usr/bin/env python3
"""Stability suite: stiff and extreme variants of the shipped scenes, each with its expected outcome.

  bench/stability.py                          # every case in configs/stability/
  bench/stability.py configs/stability/penalty_x100.yaml --keep runs/stability
  bench/stability.py --processors CASE        # the cores a case's run occupies (for ctest)

A case file names a shipped scene (`base`, relative to the case file), the keys it changes (`set`:
dotted key paths, each value replaces the base's) and what must happen (`expect`):
  converge  the run finishes (exit 0, status ok) with finite results: the stent diameter between
            its crimped value and 4 mm at every output, every stress finite;
  stop      a clean stop: an exit code other than 0 and 2 (2 is bad input) and not a crash, a message
            that names the step, the time and the residual history, and a run directory whose
            committed steps agree across files (coupling.csv, the solid's summary).
Either way within `max_wall` seconds (a hang is a failure). Prints one row per case and exits 1 if
any case does not behave as expected. Units: mm, N, MPa, s.
"""
import argparse
import csv
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

import yaml

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "scripts"))  # the tools
from launch import solid_ranks  # noqa: E402
from scene_variant import SetError, apply_set, launch_command, variant_scene  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CASE_KEYS = {"base", "expect", "set", "max_wall"}


def fail(msg):
    print(f"stability: error: {msg}", file=sys.stderr)
    sys.exit(2)


def load_case(path):
    try:
        case = yaml.safe_load(open(path))
    except (OSError, yaml.YAMLError) as e:
        fail(f"{path}: {e}")
    if not isinstance(case, dict) or set(case) - CASE_KEYS or not {"base", "expect"} <= set(case):
        fail(f"{path}: expected a map with base, expect and optionally set, max_wall; got {sorted(case or [])}")
    if case["expect"] not in ("converge", "stop"):
        fail(f"{path}: expect: expected 'converge' or 'stop', got {case['expect']!r}")
    return case


def compose(case, case_path):
    """The base scene with the case's changes applied (dotted key paths)."""
    base_path = os.path.normpath(os.path.join(os.path.dirname(case_path), case["base"]))
    scene = yaml.safe_load(open(base_path))
    try:
        apply_set(scene, case.get("set") or {}, f"{case_path}: set")
    except SetError as e:
        fail(str(e))
    return base_path, scene


def finite(v):
    if isinstance(v, dict):
        return all(finite(x) for x in v.values())
    if isinstance(v, list):
        return all(finite(x) for x in v)
    return v is not None and (not isinstance(v, float) or math.isfinite(v))


def run_dirs(run_dir):
    """The run directories of a launch: the run itself, or a procedure's phases (procedure.json)."""
    path = os.path.join(run_dir, "procedure.json")
    if not os.path.exists(path):
        return [run_dir]
    return [p["run_dir"] for p in json.load(open(path)).get("phases", []) if p.get("run_dir")]


def check_converge(run_dir, rc, log, problems):
    if rc != 0:
        problems.append(f"exit code {rc}, expected 0: {log[-300:]}")
        return
    proc = os.path.join(run_dir, "procedure.json")
    if os.path.exists(proc):
        bad = [(p["name"], p["status"]) for p in json.load(open(proc))["phases"] if p.get("status") != "ok"]
        if bad:
            problems.append(f"procedure phases not ok: {bad}")
    for d in run_dirs(run_dir):
        check_converge_run(d, problems)


def check_converge_run(run_dir, problems):
    coupled = os.path.exists(os.path.join(run_dir, "coupling_summary.json"))
    if coupled:
        c = json.load(open(os.path.join(run_dir, "coupling_summary.json")))
        if c.get("status") != "ok":
            problems.append(f"coupling status {c.get('status')}")
    beam = os.path.join(run_dir, "beam", "summary.json")
    if os.path.exists(beam):
        steps = json.load(open(beam)).get("steps", [])
        d = [s.get("diameter") for s in steps]
        if not all(isinstance(x, float) and 1.0 <= x <= 4.0 for x in d):
            problems.append(
                "stent diameter outside [1, 4] mm or not finite: "
                f"{[x for x in d if not (isinstance(x, float) and 1.0 <= x <= 4.0)][:3]}"
            )
    solid = os.path.join(run_dir, "solid", "summary.json")
    if os.path.exists(solid):
        for s in json.load(open(solid))["steps"]:
            if not finite(s.get("max_principal_stress")):
                problems.append(f"non-finite stress at t = {s.get('time')}")
                break


def check_stop(run_dir, rc, log, problems):
    if rc in (0, 2) or rc < 0 or rc >= 128:
        problems.append(f"exit code {rc}, expected a clean failure (not 0, not 2, not a signal)")
    # the coupler's (or a participant's) failure message: "step N ... t = T ... residual history [...]"
    if not re.search(r"\bstep \d+\b.*\bt = \S+.*residual history:? \[", log):
        problems.append("the error message does not name the step, the time and the residual history")
    for d in run_dirs(run_dir):
        check_stop_run(d, problems)


def check_stop_run(run_dir, problems):
    committed = None
    path = os.path.join(run_dir, "coupling.csv")
    if os.path.exists(path):
        rows = list(csv.DictReader(open(path)))
        committed = int(rows[-1]["step"]) if rows else 0
    solid = os.path.join(run_dir, "solid", "summary.json")
    if os.path.exists(solid):
        try:
            steps = json.load(open(solid))["steps"]
        except ValueError as e:
            problems.append(f"solid/summary.json unreadable after the stop: {e}")
            return
        if committed is not None and steps and steps[-1]["step"] != committed:
            problems.append(f"committed steps disagree: coupling.csv {committed}, solid summary {steps[-1]['step']}")
        if not all(finite(s.get("max_principal_stress")) for s in steps):
            problems.append("a non-finite stress was written")


def run_case(case_path, out_dir, build_dir):
    case = load_case(case_path)
    name = os.path.splitext(os.path.basename(case_path))[0]
    base_path, scene = compose(case, case_path)
    run_dir = os.path.join(out_dir, name)
    shutil.rmtree(run_dir, ignore_errors=True)
    max_wall = float(case.get("max_wall", 300))
    t0 = time.time()
    problems = []
    header = f"{name}: generated by bench/stability.py from {os.path.relpath(case_path, ROOT)}"
    with variant_scene(base_path, scene, f"stability_{name}", header) as scene_path:
        try:
            r = subprocess.run(
                # a peer silent for a tenth of the case's wall budget (at least 60 s) is a hang; a
                # fixed 60 s stopped a patient procedure whose solid solves took longer on a busy machine
                launch_command(scene_path, run_dir, build_dir, "--timeout", f"{max(60.0, 0.1 * max_wall):g}"),
                capture_output=True,
                text=True,
                errors="replace",
                timeout=max_wall,
            )
            rc, log = r.returncode, r.stdout + r.stderr
        except subprocess.TimeoutExpired as e:
            rc, log = None, str(e.stdout or "")
            problems.append(f"no outcome within {max_wall:.0f} s (a hang)")
    wall = time.time() - t0
    if os.path.isdir(run_dir):
        shutil.copy(case_path, os.path.join(run_dir, "case.yaml"))
    if rc is not None:
        (check_converge if case["expect"] == "converge" else check_stop)(run_dir, rc, log, problems)
    steps = cuts = None
    for d in run_dirs(run_dir) if os.path.isdir(run_dir) else []:
        path = os.path.join(d, "coupling_summary.json")
        if os.path.exists(path):
            c = json.load(open(path))
            steps, cuts = (steps or 0) + (c.get("steps") or 0), (cuts or 0) + (c.get("rejected_attempts") or 0)
    return {
        "case": name,
        "expect": case["expect"],
        "rc": rc,
        "ok": not problems,
        "problems": problems,
        "steps": steps,
        "cuts": cuts,
        "wall_s": wall,
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("cases", nargs="*", help="case files (default: configs/stability/*.yaml)")
    ap.add_argument("--keep", help="keep the run directories here (default: a temporary directory)")
    ap.add_argument("--build-dir", default=os.path.join(ROOT, "build"))
    ap.add_argument(
        "--processors",
        action="store_true",
        help="print the cores each case's run occupies (its solid ranks: the staggered participants "
        "take turns) and exit, without running",
    )
    a = ap.parse_args()
    cases = a.cases or sorted(
        os.path.join(ROOT, "configs", "stability", f)
        for f in os.listdir(os.path.join(ROOT, "configs", "stability"))
        if f.endswith(".yaml")
    )
    if a.processors:
        for c in cases:
            print(solid_ranks(compose(load_case(c), c)[1], c))
        return 0
    with tempfile.TemporaryDirectory() as tmp:
        out = a.keep or tmp
        os.makedirs(out, exist_ok=True)
        rows = []
        for c in cases:
            row = run_case(os.path.abspath(c), out, a.build_dir)
            rows.append(row)
            print(
                f"{'ok  ' if row['ok'] else 'FAIL'} {row['case']:<28} expect {row['expect']:<9} exit {row['rc']!s:<5}"
                f" steps {row['steps']!s:<5} cuts {row['cuts']!s:<4} {row['wall_s']:7.1f} s"
                + ("" if row["ok"] else "\n       " + "\n       ".join(row["problems"])),
                flush=True,
            )
    return 0 if all(r["ok"] for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
