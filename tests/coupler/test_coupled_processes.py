#!/usr/bin/python3
"""End-to-end tests of the coupled process chain over zenoh (issue 2 item 8, issue 6 item 3a):

1. coupler + two spring test participants, started by scripts/launch.py: the converged contact
   force equals the analytic coupled solution (spring_participants.hpp), a recording is written.
2. coupler + two replay participants answering from that recording reproduce the recorded
   iteration history exactly (same iterations, residuals and relaxation factors per step).
3. a participant that dies makes the launcher stop everything and name it (non-zero exit); Ctrl-C
   stops after the step under way, with the participants shut down and the summary "interrupted".
4. a coupler without participants fails with a timeout error instead of hanging.
5. a frozen participant (SIGSTOP) stops the run within --timeout + a few seconds, the coupler names
   it, the launcher passes the coupler's diagnosis on, the summary says failed, nothing is left.
"""
import json
import csv
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

BIN = Path(sys.argv[1])
ROOT = Path(__file__).resolve().parents[2]
SCENE = ROOT / "tests" / "coupler" / "data" / "springs.yaml"
LAUNCH = [sys.executable, str(ROOT / "scripts" / "launch.py")]
failures = []


def check(cond, msg):
    print(("ok   " if cond else "FAIL ") + msg)
    if not cond:
        failures.append(msg)


def launch(run_dir, *extra, timeout=120):
    cmd = LAUNCH + [str(SCENE), "--run-dir", str(run_dir), "--build-dir", str(BIN.parent), "--timeout", "30", *extra]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)


def rows(run_dir):
    with open(run_dir / "coupling.csv") as f:
        return list(csv.DictReader(f))


with tempfile.TemporaryDirectory() as tmp:
    tmp = Path(tmp)
    spring = str(BIN / "spring_participant")
    # 1. real exchange with an analytic answer
    r = launch(tmp / "springs", "--record", "--run-id", "springs-1",
               "--beam-cmd", f"{spring} --role beam", "--solid-cmd", f"{spring} --role solid")
    check(r.returncode == 0, f"coupled spring run exits 0 (got {r.returncode})\n{r.stdout}\n{r.stderr}")
    if r.returncode == 0:
        rec_rows = rows(tmp / "springs")
        check(len(rec_rows) == 4, "four load steps in coupling.csv")
        # q* = eps (s − x0 − R)/(1 + eps/kb) per point, total force = n·w·q* (n = 4, w = 0.1)
        q_star = 10.0 * (1.5 - 1.0 - 0.05) / (1.0 + 10.0 / 1.0)
        fx = float(rec_rows[-1]["contact_force_x"])
        check(abs(fx - 4 * 0.1 * q_star) < 1e-8, f"final contact force {fx} equals analytic {4 * 0.1 * q_star}")
        check((tmp / "springs" / "exchanges.angiorec").stat().st_size > 0, "recording written")

        # 2. replay reproduces the iteration history exactly
        replay = str(BIN / "replay_participant")
        rec = tmp / "springs" / "exchanges.angiorec"
        r2 = launch(tmp / "replay", "--run-id", "replayed",
                    "--beam-cmd", f"{replay} --role beam --recording {rec}",
                    "--solid-cmd", f"{replay} --role solid --recording {rec}")
        check(r2.returncode == 0, f"replayed run exits 0 (got {r2.returncode})\n{r2.stdout}\n{r2.stderr}")
        if r2.returncode == 0:
            keys = ["step", "time", "coupling_iterations", "residual", "omega", "n_active", "contact_force_x"]
            a = [[row[k] for k in keys] for row in rec_rows]
            b = [[row[k] for k in keys] for row in rows(tmp / "replay")]
            check(a == b, "replay reproduces the recorded iteration history exactly")

    # 3. a dying participant is named and the others are stopped
    t0 = time.time()
    r3 = launch(tmp / "dies", "--beam-cmd", "/bin/false", "--solid-cmd", f"{spring} --role solid")
    check(r3.returncode != 0 and "beam_solver exited with code 1" in r3.stderr,
          f"launcher names the failed participant (rc {r3.returncode}): {r3.stderr.strip()}")
    check(time.time() - t0 < 60, "and does not wait for the peers' timeout")

    # 3b. Ctrl-C reaches every process: the launcher exits 130 and leaves no process behind
    cmd = LAUNCH + [str(SCENE), "--run-dir", str(tmp / "interrupted"), "--build-dir", str(BIN.parent),
                    "--run-id", "interrupt-me",
                    "--beam-cmd", f"{spring} --role beam --delay 0.5", "--solid-cmd", f"{spring} --role solid"]
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(3.0)
    p.send_signal(signal.SIGINT)
    try:
        _, err = p.communicate(timeout=30)
        check(p.returncode == 130, f"interrupted launcher exits 130 (got {p.returncode}): {err.strip()[-300:]}")
    except subprocess.TimeoutExpired:
        p.kill()
        check(False, "interrupted launcher ends within 30 s")
    left = subprocess.run(["pgrep", "-f", "interrupt-me"], capture_output=True, text=True).stdout.split()
    check(not left, f"no process of the interrupted run is left ({left})")
    # the first Ctrl-C stops after the step under way: the committed steps and the summary agree
    summ = json.loads((tmp / "interrupted" / "coupling_summary.json").read_text())
    n_rows = len(rows(tmp / "interrupted"))
    check(summ.get("status") == "interrupted" and summ.get("steps") == n_rows and n_rows >= 1,
          f"interrupted run: summary status {summ.get('status')}, {summ.get('steps')} steps, "
          f"{n_rows} rows in coupling.csv")

    # 4. no participants: the coupler times out with a clear error
    t0 = time.time()
    r4 = subprocess.run([str(BIN / "coupler"), "--scene", str(SCENE), "--run-dir", str(tmp / "alone"),
                         "--endpoint", f"unixsock-stream/{tmp}/alone.sock", "--run-id", "alone", "--timeout", "3"],
                        capture_output=True, text=True, timeout=60)
    check(r4.returncode != 0 and "did not answer" in r4.stderr,
          f"coupler alone fails with a timeout error (rc {r4.returncode}): {r4.stderr.strip()}")
    check(time.time() - t0 < 30, f"within the timeout ({time.time() - t0:.1f} s)")

    # 5. a frozen participant: the coupler, which waits for it, names it within --timeout; the other
    # participant waits 2 x --timeout before giving up, so it does not pre-empt the diagnosis
    cmd = LAUNCH + [str(SCENE), "--run-dir", str(tmp / "frozen"), "--build-dir", str(BIN.parent),
                    "--run-id", "freeze-me", "--timeout", "6",
                    "--beam-cmd", f"{spring} --role beam --delay 0.5", "--solid-cmd", f"{spring} --role solid"]
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(3.0)
    beam_pids = subprocess.run(["pgrep", "-f", "role beam --delay 0.5.*freeze-me"], capture_output=True,
                               text=True).stdout.split()
    check(len(beam_pids) == 1, f"the beam participant of the run is found ({beam_pids})")
    for pid in beam_pids:
        subprocess.run(["kill", "-STOP", pid])
    t0 = time.time()
    try:
        out, err = p.communicate(timeout=60)
        took = time.time() - t0
        check(p.returncode not in (0, None), f"frozen beam: the launcher fails (rc {p.returncode})")
        check(took < 6 + 5, f"frozen beam: stopped within --timeout + 5 s ({took:.1f} s)")
        check("coupler exited with code 3" in err and "beam participant did not answer" in err,
              f"frozen beam: the launcher names the silent participant: {err.strip()[-400:]}")
        summ = json.loads((tmp / "frozen" / "coupling_summary.json").read_text())
        check(summ.get("status") == "failed" and "beam" in summ.get("error", ""),
              f"frozen beam: coupling_summary.json says failed and names it ({summ.get('status')})")
    except subprocess.TimeoutExpired:
        p.kill()
        check(False, "frozen beam: the launcher ends within 60 s")
    for pid in beam_pids:
        subprocess.run(["kill", "-CONT", pid])
    time.sleep(1.0)
    left = subprocess.run(["pgrep", "-f", "freeze-me"], capture_output=True, text=True).stdout.split()
    check(not left, f"frozen beam: no process of the run is left ({left})")
    for pid in left:
        subprocess.run(["kill", "-KILL", pid])

sys.exit(1 if failures else 0)
