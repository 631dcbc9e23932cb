#!/usr/bin/env python3
"""One-factor-at-a-time sensitivity of a scene: how far the stent diameter and the per-layer wall
stresses move when one modelling choice changes (end springs, peak pressure, wall split, a contact
penalty, ...), each change run on its own against the same baseline.

  bench/sensitivity.py STUDY.yaml [--out-dir DIR] [--build-dir DIR] [--reuse JSON|RUN_DIR ...] [--only NAME ...]

A study file (YAML, e.g. configs/studies/generic_artery_sensitivity.yaml) has the keys
  base     the scene, relative to the study file
  common   optional {dotted.key.path: value}, applied to every run, the baseline included (e.g. a
           coarser mesh)
  changes  a list of {name, set: {dotted.key.path: value}}: one run each, the baseline plus `set`
Dotted key paths as in bench/stability.py (scene_variant.apply_set): each value replaces the
base's, a map or list as a whole (to change one layer of artery.mesh.layers, give the whole list).

Outputs of each run (work_precision.outputs_of, from scripts/report.py's results.json): stent
diameter at peak and final (mm), recoil and dogboning (%), for an artery the max and 99th-percentile
first principal stress per layer at peak and after and its recovered nodal maximum (MPa).
Difference of an output: (q - q_baseline) / |q_baseline| in %.

Written to OUT_DIR (default runs/sensitivity/<study>): sensitivity.json and .csv (one row per run:
name, status, wall time, every output and its difference) and run-<hash>/ per run. Printed: a
Markdown table, one row per run. A failed run is a row with its status; the exit code is 1 if any
run failed, 2 for a bad study file or option (the message names the file and key).
--reuse JSON: the finished runs of an earlier sensitivity.json whose variant scene is the same (its
hash) are taken from there instead of run again (failed ones are run again); --reuse RUN_DIR: a
finished run directory (e.g. run-<hash>/ of a study that was stopped) serves the same way. --only NAME: the
baseline and the named changes only. Units: mm, N, MPa, s.
"""
import argparse
import csv
import json
import os
import sys


sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "scripts"))  # the tools
from scene_variant import StudyError, load_study  # noqa: E402
from work_precision import ROOT, reused_run_dir, run_scene, scene_key  # noqa: E402


def fail(msg):
    print(f"sensitivity: error: {msg}", file=sys.stderr)
    sys.exit(2)


def columns(rows):
    """The table's outputs: diameters, then per layer (in results.json order) max/p99/nodal max at peak, after."""
    names = [n for r in rows for n in r["outputs"]]
    layers = dict.fromkeys(n.split("_max_")[0] for n in names if "_max_" in n)
    return ["D_peak", "D_final"] + [
        f"{layer}_{s}_{ph}" for ph in ("peak", "after") for layer in layers for s in ("max", "p99", "max_nodal")
    ]


def cell(r, name, is_base):
    v = r["outputs"].get(name)
    if v is None:
        return "-"
    s = f"{v:.3f}" if name.startswith("D_") else f"{v:.4g}"
    d = r["diff_percent"].get(name)
    if is_base or d is None:
        return s
    return f"{s} ({d:+.1f} %)" if abs(d) >= 0.1 or d == 0 else f"{s} ({d:+.1g} %)"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("study")
    ap.add_argument("--out-dir")
    ap.add_argument("--build-dir", default=os.path.join(ROOT, "build"))
    ap.add_argument(
        "--reuse",
        action="append",
        default=[],
        metavar="JSON|RUN_DIR",
        help="an earlier sensitivity.json, or a finished run directory (repeatable)",
    )
    ap.add_argument("--only", nargs="+", metavar="NAME", help="run the baseline and these changes only")
    a = ap.parse_args()
    try:
        base_path, runs, _ = load_study(a.study)
    except StudyError as e:
        fail(str(e))
    if a.only:
        for n in a.only:
            if n not in {r[0] for r in runs[1:]}:
                fail(f"--only: {n!r}: no such change in {a.study} (have: {', '.join(repr(r[0]) for r in runs[1:])})")
        runs = runs[:1] + [r for r in runs[1:] if r[0] in a.only]
    cache = {}
    for path in a.reuse:
        if os.path.isdir(path):  # a finished run directory of launch.py (e.g. a run of an earlier study)
            try:
                r = reused_run_dir(path)
            except (OSError, ValueError, KeyError) as e:
                fail(f"--reuse {path}: expected a run directory with scene.yaml and coupling_summary.json: {e}")
            if r["status"] == "ok":
                cache[r["run"]] = r
            continue
        try:
            for r in json.load(open(path))["runs"]:
                if r["status"] == "ok":
                    cache[r["run"]] = {k: r[k] for k in ("run", "status", "wall_s", "outputs")}
        except (OSError, ValueError, KeyError, TypeError) as e:
            fail(f"--reuse {path}: expected a sensitivity.json, got {type(e).__name__}: {e}")
    out_dir = a.out_dir or os.path.join(ROOT, "runs", "sensitivity", os.path.splitext(os.path.basename(a.study))[0])
    os.makedirs(out_dir, exist_ok=True)
    rows = []
    for name, changes, scene in runs:
        key = scene_key(scene)
        if name != "baseline" and key == scene_key(runs[0][2]):
            print(f"[sensitivity] note: '{name}' leaves the scene as the baseline has it", file=sys.stderr)
        reused = key in cache
        print(f"[sensitivity] {name} ({'reused' if reused else 'running'}) ...", file=sys.stderr, flush=True)
        try:
            r = dict(run_scene(base_path, scene, out_dir, a.build_dir, cache, by="sensitivity"))
        except Exception as e:  # a run that could not even start is a row too
            r = {"run": key, "status": f"error: {type(e).__name__}: {e}", "wall_s": 0.0, "outputs": {}}
        r.update(name=name, set=changes, reused=reused)
        rows.append(r)
        print(f"[sensitivity]   {r['status']}, {r['wall_s']:.1f} s", file=sys.stderr, flush=True)
    base_out = rows[0]["outputs"]
    for r in rows:
        r["diff_percent"] = {
            k: 100.0 * (v - base_out[k]) / abs(base_out[k]) for k, v in r["outputs"].items() if base_out.get(k)
        }
    with open(os.path.join(out_dir, "sensitivity.json"), "w") as f:
        json.dump({"study": os.path.abspath(a.study), "scene": base_path, "runs": rows}, f, indent=1)
    names = list(dict.fromkeys(n for r in rows for n in r["outputs"]))
    with open(os.path.join(out_dir, "sensitivity.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["name", "status", "wall_s", "reused", "run"] + names + [f"diff_percent_{n}" for n in names])
        for r in rows:
            w.writerow(
                [r["name"], r["status"], f"{r['wall_s']:.2f}", r["reused"], r["run"]]
                + [r["outputs"].get(n, "") for n in names]
                + [r["diff_percent"].get(n, "") for n in names]
            )
    cols = columns(rows)
    heads = [c.replace("_", " ") + (" (mm)" if c.startswith("D_") else " (MPa)") for c in cols]
    print(f"scene {base_path}, study {a.study}\n")
    print("| run | status | wall (s) | " + " | ".join(heads) + " |")
    print("|---|---|---:|" + "---:|" * len(cols))
    for i, r in enumerate(rows):
        print(
            f"| {r['name']} | {r['status']} | {r['wall_s']:.0f}{' (reused)' if r['reused'] else ''} | "
            + " | ".join(cell(r, c, i == 0) for c in cols)
            + " |"
        )
    print(f"\n(runs in {out_dir}; sensitivity.json/.csv)")
    return 0 if all(r["status"] == "ok" for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
