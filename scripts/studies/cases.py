"""A study's output directory and one case's run in it.

  <out>/study.json          the study's identity and its cases (index, key, parameters)
  <out>/case-<key>/         one per case: case.json (state, exit code, wall time, message, host),
                            launch.log, run/ (the launcher's run directory), case.lock
A case is run by `run_case` whatever runs it (the local pool, a Slurm array task): it holds
case.lock (flock) while it runs, so `status` tells a running case from one whose runner died, and two
runners never run one case at the same time.
"""
import fcntl
import json
import os
import shutil
import socket
import subprocess
import time

from scene_variant import launch_command, variant_scene
from .spec import StudyError

STATES = ("done", "failed", "stopped", "running", "pending")


def prepare_out_dir(study, out_dir):
    """Creates out_dir for `study` or checks that it holds the same study (never two in one)."""
    os.makedirs(out_dir, exist_ok=True)
    path = os.path.join(out_dir, "study.json")
    ident = study.identity()
    if os.path.isfile(path):
        try:
            with open(path) as f:
                old = json.load(f).get("identity")
        except (OSError, ValueError) as e:
            raise StudyError(f"{path}: cannot read the study kept there: {e}")
        if old != ident:
            what = [k for k in ident if (old or {}).get(k) != ident[k]]
            raise StudyError(
                f"{study.where}: {out_dir} holds another study (its {', '.join(what) or 'identity'} "
                "differs): pass another --out-dir, or remove that directory"
            )
    doc = {
        "identity": ident,
        "study": study.path,
        "cases": [{"index": c.index, "key": c.key, "params": c.params} for c in study.cases],
    }
    write_json(path, doc)


def write_json(path, doc):
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        json.dump(doc, f, indent=1)
    os.replace(tmp, path)


def case_dir(out_dir, case):
    return os.path.join(out_dir, case.name)


def _lock_held(path):
    """True if another process holds the flock on `path`."""
    try:
        with open(path, "a") as f:
            fcntl.flock(f, fcntl.LOCK_EX | fcntl.LOCK_NB)
            fcntl.flock(f, fcntl.LOCK_UN)
        return False
    except BlockingIOError:
        return True
    except OSError:
        return False


def case_state(out_dir, case):
    """case.json's content with `state` one of STATES ("stopped": its runner died while running)."""
    d = case_dir(out_dir, case)
    try:
        with open(os.path.join(d, "case.json")) as f:
            info = json.load(f)
    except (OSError, ValueError):
        return {"state": "pending"}
    if info.get("state") == "running" and not _lock_held(os.path.join(d, "case.lock")):
        info["state"] = "stopped"
    return info


def last_error(log_path, limit=300):
    """The launcher's error line (or the last line) of a case's log."""
    try:
        with open(log_path, errors="replace") as f:
            lines = [ln.strip() for ln in f if ln.strip()]
    except OSError:
        return ""
    for ln in reversed(lines):
        if "error" in ln.lower():
            return ln[:limit]
    return lines[-1][:limit] if lines else ""


def run_case(study, case, out_dir, build_dir, quiet=True):
    """Runs one case to its end; returns its case.json content. A case whose lock another runner
    holds is left to it (state "running")."""
    d = case_dir(out_dir, case)
    os.makedirs(d, exist_ok=True)
    lock = open(os.path.join(d, "case.lock"), "a")
    try:
        fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        lock.close()
        return {"state": "running", "message": "run by another runner"}
    try:
        run_dir = os.path.join(d, "run")
        shutil.rmtree(run_dir, ignore_errors=True)  # a retried case starts afresh
        info = {
            "state": "running",
            "index": case.index,
            "key": case.key,
            "params": case.params,
            "host": socket.gethostname(),
            "started": time.strftime("%Y-%m-%dT%H:%M:%S"),
            "slurm_job": slurm_task_id(),
        }
        write_json(os.path.join(d, "case.json"), info)
        log_path = os.path.join(d, "launch.log")
        t0 = time.time()
        try:
            with variant_scene(
                study.base_path,
                case.scene,
                f"study_{case.key}",
                f"case {case.key} of study {study.name} (scripts/study.py)",
            ) as path:
                with open(log_path, "w") as log:
                    rc = subprocess.call(launch_command(path, run_dir, build_dir), stdout=log, stderr=subprocess.STDOUT)
            message = "" if rc == 0 else last_error(log_path)
        except OSError as e:  # the scene beside its base, or the log, cannot be written: this case fails
            rc, message = 1, f"cannot start the case: {e}"
        info.update(
            state="done" if rc == 0 else "failed",
            exit_code=rc,
            wall_s=round(time.time() - t0, 3),
            finished=time.strftime("%Y-%m-%dT%H:%M:%S"),
            message=message,
        )
        write_json(os.path.join(d, "case.json"), info)
        return info
    finally:
        lock.close()


def slurm_task_id():
    job, task = os.environ.get("SLURM_ARRAY_JOB_ID"), os.environ.get("SLURM_ARRAY_TASK_ID")
    if job and task:
        return f"{job}_{task}"
    return os.environ.get("SLURM_JOB_ID")


def results_of(out_dir, case):
    """The case's results.json (report.py), {} if absent."""
    try:
        with open(os.path.join(case_dir(out_dir, case), "run", "results.json")) as f:
            return json.load(f)
    except (OSError, ValueError):
        return {}
