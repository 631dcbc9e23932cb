#!/usr/bin/python3
"""Cohort and parameter studies: one study file, run on this machine or as a Slurm job array.

  scripts/study.py run STUDY [--runner local|slurm] [--jobs N] [--retry-failed] [--out-dir DIR]
                             [--build-dir DIR] [--no-check] [--dry-run] [--sbatch-option OPT ...]
  scripts/study.py status STUDY [--out-dir DIR]     done / running / stopped / failed / pending, wall times
  scripts/study.py table STUDY [--out-dir DIR]      table.csv (+ .parquet), plots/ from what is finished
  scripts/study.py case STUDY --index I --key K     one case (what a Slurm array task runs)

A study file (YAML; docs/user-guide.md "Studies"; example configs/studies/straight_pressures.yaml):
  name      optional, default the file's stem; the output directory is runs/studies/<name>
  base      the scene every case starts from, relative to the study file
  common    optional {dotted.key.path: value} applied to every case
  grid      optional {dotted.key.path: [values]}: the cartesian product of the lists
  cases     optional list of {dotted.key.path: value}: explicit cases (crossed with grid)
  patients  optional list of patient inputs (files, relative to the study file), or {key, files}:
            each replaces patient.centerline (or `key`), crossed with the rest
  outputs   optional results.json paths tabulated first and plotted (default stent.max, stent.final,
            stent.recoil_percent, stent.dogboning_max_percent)
  plot      optional {x: a parameter's key path, y: [outputs]}
  slurm     optional {partition, time, mem_per_cpu, max_parallel, options: [--sbatch-option, ...]}
Key paths as in scripts/scene_variant.py (apply_set). Each case runs in <out>/case-<hash of its
parameters>/; a rerun skips finished cases and cases running elsewhere, runs stopped and pending ones,
and failed ones with --retry-failed. Every case's scene is checked (launch.py --check) before anything
runs or is submitted. Exit codes: 0 all cases done, 1 some failed or are not finished, 2 a bad study
file or option (the message names the file and key; nothing is run or submitted). Units: mm, N, MPa, s.
"""
import argparse
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from scene_variant import ROOT, launch_command, variant_scene  # noqa: E402
from studies.cases import STATES, case_state, prepare_out_dir, run_case  # noqa: E402
from studies.local_runner import default_jobs, run_local  # noqa: E402
from studies.slurm_runner import sbatch_path, submit  # noqa: E402
from studies.spec import Study, StudyError  # noqa: E402
from studies.table import plot, rows_of, write_table  # noqa: E402


def fail(msg):
    print(f"study: error: {msg}", file=sys.stderr)
    sys.exit(2)


def check_scenes(study, cases, build_dir):
    """launch.py --check of every case's scene: a bad value anywhere stops the study before it runs."""
    for c in cases:
        try:
            with variant_scene(study.base_path, c.scene, f"study_check_{c.key}", "checked by scripts/study.py") as path:
                out = subprocess.run(
                    launch_command(path, "unused", build_dir, "--check"), capture_output=True, text=True
                )
        except OSError as e:  # each case's scene is written beside the base (its relative paths resolve there)
            fail(f"{study.where}: base: cannot write a case's scene beside {study.base_path}: {e.strerror}")
        if out.returncode != 0:
            why = (out.stderr.strip() or out.stdout.strip()).splitlines()
            why = why[-1] if why else out.returncode
            fail(f"{study.where}: case {c.index} {c.params}: the scene is not valid: {why}")


def cmd_run(a, study, out_dir):
    if a.runner == "slurm":
        try:
            sbatch_path()
        except StudyError as e:
            fail(str(e))
    if a.jobs is not None and a.jobs < 1:
        fail(f"--jobs: expected a positive integer, got {a.jobs}")
    todo, skipped = [], {}
    for c in study.cases:
        st = case_state(out_dir, c)["state"]
        if st in ("pending", "stopped") or (st == "failed" and a.retry_failed):
            todo.append(c)
        else:
            skipped[st] = skipped.get(st, 0) + 1
    print(
        f"[study] {study.name}: {len(study.cases)} cases, {len(todo)} to run"
        + "".join(f", {n} {s}" for s, n in skipped.items())
        + f" ({out_dir})",
        file=sys.stderr,
    )
    if not todo:
        return finish(study, out_dir)
    if not a.no_check:
        check_scenes(study, todo, a.build_dir)
    if a.runner == "slurm":
        try:
            job = submit(
                study,
                todo,
                out_dir,
                os.path.abspath(a.build_dir),
                sys.executable,
                ROOT,
                extra=a.sbatch_option,
                dry_run=a.dry_run,
            )
        except RuntimeError as e:
            print(f"study: {e}", file=sys.stderr)
            return 1
        if job:
            print(
                f"[study] submitted job array {job} ({len(todo)} tasks); follow with: "
                f"scripts/study.py status {a.study}" + (f" --out-dir {a.out_dir}" if a.out_dir else "")
            )
        return 0
    if a.dry_run:
        for c in todo:
            print(f"[study] would run case {c.index} ({c.key}): {c.params}", file=sys.stderr)
        return 0
    run_local(study, todo, out_dir, a.build_dir, a.jobs or default_jobs(study, todo))
    return finish(study, out_dir)


def finish(study, out_dir):
    rows, _, written = write_table(study, out_dir)
    written += plot(study, rows, out_dir)
    print_status(study, rows)
    print("[study] written: " + ", ".join(os.path.relpath(p) for p in written), file=sys.stderr)
    return 0 if all(r["state"] == "done" for r in rows) else 1


def print_status(study, rows):
    counts = {s: sum(r["state"] == s for r in rows) for s in STATES}
    print(f"{study.name}: " + ", ".join(f"{n} {s}" for s, n in counts.items() if n))
    names = study.parameter_names()
    for r in rows:
        wall = f"{r['wall_s']:.1f} s" if isinstance(r.get("wall_s"), (int, float)) else "-"
        params = ", ".join(f"{k}={r[k]}" for k in names if k in r)
        print(
            f"  {r['index']:>4}  {r['case']}  {r['state']:<8} {wall:>9}  {params}"
            + (f"  ({r['message']})" if r["message"] else "")
        )


def cmd_status(a, study, out_dir):
    rows = rows_of(study, out_dir)
    print_status(study, rows)
    return 0 if all(r["state"] == "done" for r in rows) else 1


def cmd_case(a, study, out_dir):
    if not 0 <= a.index < len(study.cases):
        fail(f"--index: expected 0..{len(study.cases) - 1}, got {a.index}")
    c = study.cases[a.index]
    if a.key and a.key != c.key:
        fail(
            f"{study.where}: case {a.index} is {c.key} now, {a.key} when it was submitted: "
            "the study file changed since; submit again"
        )
    info = run_case(study, c, out_dir, a.build_dir)
    print(
        f"[study] case {c.index} ({c.key}): {info['state']}" + (f": {info['message']}" if info.get("message") else "")
    )
    return 0 if info["state"] in ("done", "running") else 1


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="command", required=True)
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("study", help="study file (YAML)")
    common.add_argument("--out-dir", help="output directory (default runs/studies/<name>)")
    common.add_argument("--build-dir", default=os.environ.get("BUILD_DIR") or os.path.join(ROOT, "build"))
    r = sub.add_parser("run", parents=[common], help="run the study's unfinished cases")
    r.add_argument("--runner", choices=["local", "slurm"], default="local")
    r.add_argument("--jobs", type=int, help="local: cases at once (default: cores / (solid ranks + 1))")
    r.add_argument("--retry-failed", action="store_true", help="run failed cases again")
    r.add_argument("--no-check", action="store_true", help="skip launch.py --check of every case")
    r.add_argument("--dry-run", action="store_true", help="say what would run or be submitted")
    r.add_argument(
        "--sbatch-option",
        action="append",
        default=[],
        metavar="OPT",
        help="slurm: an extra sbatch option, e.g. --sbatch-option=--account=lab (repeatable)",
    )
    sub.add_parser("status", parents=[common], help="state of every case")
    sub.add_parser("table", parents=[common], help="table.csv and plots from the finished cases")
    c = sub.add_parser("case", parents=[common], help="run one case (a Slurm array task)")
    c.add_argument("--index", type=int, required=True)
    c.add_argument("--key", help="the case's hash when it was submitted (checked)")
    a = ap.parse_args()
    try:
        study = Study(a.study)
    except StudyError as e:
        fail(str(e))
    out_dir = os.path.abspath(a.out_dir or os.path.join(ROOT, "runs", "studies", study.name))
    if a.command not in ("run", "case") and not os.path.isfile(os.path.join(out_dir, "study.json")):
        fail(f"{out_dir}: no study there yet (run it first: scripts/study.py run {a.study})")
    try:
        prepare_out_dir(study, out_dir)  # the same study there, or a new directory for it
    except StudyError as e:
        fail(str(e))
    return {"run": cmd_run, "status": cmd_status, "table": lambda a, s, o: finish(s, o), "case": cmd_case}[a.command](
        a, study, out_dir
    )


if __name__ == "__main__":
    try:
        sys.exit(main())
    except KeyboardInterrupt:
        print("study: interrupted", file=sys.stderr)
        sys.exit(130)
