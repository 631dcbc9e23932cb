#!/usr/bin/env python3
"""Memory, messages and time of the solid per rank against the number of solid ranks: does the
solid's memory per rank fall as 1/ranks, and which linear solver keeps it so?

  bench/bench_ranks.py STUDY.yaml [--ranks 1,2,4,8] [--only NAME ...] [--out-dir DIR] [--build-dir DIR]

A study file (YAML, e.g. configs/studies/patient_ranks_025.yaml) as for bench/sensitivity.py:
  base     the scene, relative to the study file
  common   optional {dotted.key.path: value} applied to the base first (a patient's mesh size, a short
           time window)
  changes  a list of {name, set: {dotted.key.path: value}}: each a run of the base plus `set` at every
           rank count (solver options: `solid.petsc_options`, `solid.newton.*`)
  ranks    optional list of solid rank counts (default 1, 2, 4, 8; --ranks overrides)
The baseline (the base with `common`) runs too. A scene with a stent runs as its solid alone (no
stent, no coupling, no stent contact; bench_scenes.py's `alone` variant): the figures are the solid's.
A patient scene (`patient:`) is completed once, as the launcher completes it (scripts/patient: the
artery meshed with gmsh, the devices placed), into OUT_DIR/geometry and OUT_DIR/scene.yaml, before
the stent is dropped; every run uses that mesh. The changes are applied to the completed scene, so
`patient.*` keys belong in `common`.

Per run, from the solid's solid/summary.json (`timing`): each rank's peak resident set and the same
before the first solve (MiB, getrusage), PETSc's messages and their volume over all ranks (as
-log_view counts them; not MUMPS' own traffic), per Newton iteration too, Newton and linear iterations,
linear and solve seconds; the largest rank's peak against the same change's 1-rank peak; and the
results against the 1-rank run of the same change: the largest relative difference of every layer's
element maximum and 99th percentile of the first principal stress and of the lumen's smallest
diameter at the last step (exact Newton gives round-off; an iterative solver its tolerance's effect).

Written to OUT_DIR (default runs/bench_ranks/<study>): bench_ranks.json and .csv, one row per change
and rank count, run-<name>-<ranks>/ per run. Printed: a Markdown table. Oversubscribed rank counts
(more ranks than cores) give real memory and message figures, not scaling times. Exit 1 if a run
failed, 2 for a bad study file or option (the message names the file and key). Units: MiB, s, mm.
"""
import argparse
import copy
import csv
import json
import os
import shutil
import sys
import time
from pathlib import Path

import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "scripts"))  # the tools
from bench_scenes import alone_scene, launch  # noqa: E402
from launch import install_prepared, prepare_patient  # noqa: E402
from scene_variant import SetError, StudyError, apply_set, load_study, variant_scene  # noqa: E402

ROOT = os.path.dirname(HERE)
DEFAULT_RANKS = (1, 2, 4, 8)


def fail(msg):
    print(f"bench_ranks: error: {msg}", file=sys.stderr)
    sys.exit(2)


def rank_counts(value, where):
    """A list of distinct positive rank counts, ascending."""
    if isinstance(value, str):
        try:
            value = [int(v) for v in value.split(",") if v.strip()]
        except ValueError:
            fail(f"{where}: expected rank counts such as 1,2,4,8, got {value!r}")
    if (
        not isinstance(value, list)
        or not value
        or not all(isinstance(v, int) and not isinstance(v, bool) and 1 <= v <= 256 for v in value)
    ):
        fail(f"{where}: expected a non-empty list of rank counts between 1 and 256, got {value!r}")
    return sorted(set(value))


def complete_patient(scene, base_path, out_dir):
    """The patient pipeline's completed scene, meshed once, as the launcher completes it: its geometry
    in out_dir/geometry, the completed scene in out_dir/scene.yaml (bad patient input: exit 2)."""
    path = install_prepared(prepare_patient(scene, Path(base_path)), Path(out_dir))
    with open(path) as f:
        return yaml.safe_load(f)


def summary_of(run_dir):
    with open(os.path.join(run_dir, "solid", "summary.json")) as f:
        return json.load(f)


def results_of(summary):
    """The compared results at the last step: per layer max and p99 of the first principal stress
    (MPa), the lumen's smallest diameter (mm); layers whose stress is round-off (an unloaded balloon)
    left out."""
    last = summary["steps"][-1]
    out = {}
    for key in ("max_principal_stress", "p99_principal_stress"):
        per = last.get(key) or {}
        top = max((abs(v) for v in per.values()), default=0.0)
        out.update({f"{layer}_{key}": v for layer, v in per.items() if abs(v) > 1e-6 * top})
    if last.get("lumen_diameter_min") is not None:
        out["lumen_diameter_min"] = last["lumen_diameter_min"]
    return out


def row_of(name, ranks, run_dir, rc, wall):
    row = {
        "name": name,
        "ranks": ranks,
        "run_dir": run_dir,
        "status": "ok" if rc == 0 else f"exit {rc}",
        "wall_s": wall,
    }
    if rc != 0:
        return row
    try:
        s = summary_of(run_dir)
        row.update(measures_of(s["timing"]), results=results_of(s))
    except (OSError, ValueError, KeyError, IndexError) as e:  # a solid without these figures (an old build)
        row["status"] = f"error: solid/summary.json: {type(e).__name__}: {e}"
    return row


def measures_of(t):
    """The row's figures from solid/summary.json's `timing`."""
    peak = t["peak_memory_mib_per_rank"]
    setup = t.get("setup_memory_mib_per_rank") or []
    msgs = t.get("petsc_messages_per_rank") or []
    vol = t.get("petsc_message_mib_per_rank") or []
    newton = t["newton_iterations"]
    return dict(
        dofs=t["dofs"],
        peak_mib_max=max(peak),
        peak_mib_min=min(peak),
        peak_mib_mean=sum(peak) / len(peak),
        peak_rank=peak.index(max(peak)),
        setup_mib_max=max(setup) if setup else None,
        setup_mib_min=min(setup) if setup else None,
        messages=sum(msgs),
        message_mib=sum(vol),
        messages_per_newton=sum(msgs) / newton if newton else None,
        message_mib_per_newton=sum(vol) / newton if newton else None,
        newton_iterations=newton,
        linear_iterations=t["linear_iterations"],
        linear_s=t["linear_seconds"],
        solve_s=t["solve_seconds"],
    )


def against_one_rank(rows):
    """Each row's largest rank against its change's 1-rank peak, and its results against that run's."""
    one = {r["name"]: r for r in rows if r["ranks"] == 1 and r["status"] == "ok"}
    for r in rows:
        ref = one.get(r["name"])
        if r["status"] != "ok" or ref is None:
            continue
        r["peak_vs_one_rank"] = r["peak_mib_max"] / ref["peak_mib_max"]
        diffs = [
            abs(v - ref["results"][k]) / abs(ref["results"][k])
            for k, v in r["results"].items()
            if ref["results"].get(k)
        ]
        r["results_rel_diff_vs_one_rank"] = max(diffs, default=0.0)


def fmt(v, spec):
    return "-" if v is None else format(v, spec)


def print_table(rows, study, base_path):
    print(f"scene {base_path}, study {study}\n")
    print(
        "| change | ranks | status | peak per rank, max / min / mean (MiB) | largest on rank | largest / 1 rank "
        "| before the first solve, max / min (MiB) | PETSc messages (per Newton it.) | volume MiB (per Newton it.) "
        "| Newton / linear it. | linear s | solve s | wall s | results vs 1 rank |"
    )
    print("|---|---:|---|---|---:|---:|---|---|---|---|---:|---:|---:|---:|")
    for r in rows:
        if r["status"] != "ok":
            print(f"| {r['name']} | {r['ranks']} | {r['status']} |" + " - |" * 11)
            continue
        print(
            f"| {r['name']} | {r['ranks']} | ok | {r['peak_mib_max']:,.0f} / {r['peak_mib_min']:,.0f} / "
            f"{r['peak_mib_mean']:,.0f} | {r['peak_rank']} | {fmt(r.get('peak_vs_one_rank'), '.3f')} | "
            f"{fmt(r['setup_mib_max'], ',.0f')} / {fmt(r['setup_mib_min'], ',.0f')} | "
            f"{r['messages']:,.0f} ({fmt(r['messages_per_newton'], ',.0f')}) | "
            f"{r['message_mib']:,.1f} ({fmt(r['message_mib_per_newton'], ',.1f')}) | "
            f"{r['newton_iterations']} / {r['linear_iterations']} | {r['linear_s']:.1f} | {r['solve_s']:.1f} | "
            f"{r['wall_s']:.1f} | {fmt(r.get('results_rel_diff_vs_one_rank'), '.1e')} |"
        )


CSV_COLUMNS = (
    "name ranks status wall_s dofs peak_mib_max peak_mib_min peak_mib_mean peak_rank peak_vs_one_rank setup_mib_max "
    "setup_mib_min messages message_mib messages_per_newton message_mib_per_newton newton_iterations "
    "linear_iterations linear_s solve_s results_rel_diff_vs_one_rank"
).split()


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("study")
    ap.add_argument("--ranks", help="solid rank counts, comma-separated (default: the study's, else 1,2,4,8)")
    ap.add_argument("--only", nargs="+", metavar="NAME", help="run these changes only ('baseline' names the base)")
    ap.add_argument("--out-dir")
    ap.add_argument("--build-dir", default=os.path.join(ROOT, "build"))
    a = ap.parse_args()
    try:
        base_path, runs, study = load_study(a.study, extra_keys=("ranks",))
    except StudyError as e:
        fail(str(e))
    ranks = (
        rank_counts(a.ranks, "--ranks")
        if a.ranks
        else rank_counts(study.get("ranks", list(DEFAULT_RANKS)), f"{a.study}: ranks")
    )
    for name, changes, _ in runs:
        for key in changes:
            if key.startswith("patient."):
                fail(f"{a.study}: changes ({name}): {key}: the patient is meshed once for the study; give it in common")
    base = runs[0][2]  # the baseline: the base with `common`
    if a.only:
        names = [r[0] for r in runs]
        for n in a.only:
            if n not in names:
                fail(f"--only: {n!r}: no such change in {a.study} (have: {', '.join(map(repr, names))})")
        runs = [r for r in runs if r[0] in a.only]
    out_dir = os.path.abspath(
        a.out_dir or os.path.join(ROOT, "runs", "bench_ranks", os.path.splitext(os.path.basename(a.study))[0])
    )
    os.makedirs(out_dir, exist_ok=True)
    if "patient" in base:
        base = complete_patient(base, base_path, out_dir)
    if "stent" in base:
        base = alone_scene(base)
    scenes = []  # every change's scene before the first run, so a bad change stops nothing half done
    for name, changes, _ in runs:
        try:
            scenes.append((name, apply_set(copy.deepcopy(base), changes, f"{a.study}: changes ({name}): set")))
        except SetError as e:
            fail(str(e))
    rows = []
    for name, scene in scenes:
        for n in ranks:
            run_dir = os.path.join(out_dir, f"run-{name}-{n}")
            shutil.rmtree(run_dir, ignore_errors=True)
            print(f"[bench_ranks] {name}, {n} rank(s) ...", file=sys.stderr, flush=True)
            t0 = time.time()
            with variant_scene(base_path, scene, f"bench_ranks_{name}", "generated by bench/bench_ranks.py") as path:
                rc, wall, _ = launch(path, run_dir, a.build_dir, n)
            rows.append(row_of(name, n, run_dir, rc, wall))
            print(f"[bench_ranks]   {rows[-1]['status']}, {time.time() - t0:.1f} s", file=sys.stderr, flush=True)
    against_one_rank(rows)
    with open(os.path.join(out_dir, "bench_ranks.json"), "w") as f:
        json.dump({"study": os.path.abspath(a.study), "scene": base_path, "ranks": ranks, "rows": rows}, f, indent=1)
    with open(os.path.join(out_dir, "bench_ranks.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(CSV_COLUMNS)
        for r in rows:
            w.writerow(["" if r.get(c) is None else r.get(c) for c in CSV_COLUMNS])
    print_table(rows, a.study, base_path)
    sys.exit(0 if all(r["status"] == "ok" for r in rows) else 1)


if __name__ == "__main__":
    main()
