#!/usr/bin/python3
"""End-to-end tests of the coupled process chain over zenoh:

1. coupler + two spring test participants, started by scripts/launch.py: the converged contact
   force equals the analytic coupled solution (spring_participants.hpp), a recording is written.
2. coupler + two replay participants answering from that recording reproduce the recorded
   iteration history exactly (same iterations, residuals and relaxation factors per step).
3. a participant that dies makes the launcher stop everything and name it (non-zero exit); Ctrl-C
   stops after the step under way, with the participants shut down and the summary "interrupted".
4. a coupler without participants fails with a timeout error instead of hanging.
5. a frozen participant (SIGSTOP) stops the run within --timeout + a few seconds, the coupler names
   it, the launcher passes the coupler's diagnosis on, the summary says failed, nothing is left.
6. peer authentication (docs/reliability.md "Security"): a foreign replier on the solid's keys answering every
   request first does not change the run (same coupling history as run 1); a forged coupler
   sending the recorded requests with another key gets no answer; a participant with another key
   file is refused by name; a key file readable by others, or none, is bad input (exit 2, named).
"""
import json
import csv
import os
import secrets
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


def write_key(path):
    path.parent.mkdir(parents=True, exist_ok=True)
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    with os.fdopen(fd, "w") as f:
        f.write(secrets.token_hex(32) + "\n")
    return path


def rows(run_dir):
    with open(run_dir / "coupling.csv") as f:
        return list(csv.DictReader(f))


with tempfile.TemporaryDirectory() as tmp:
    tmp = Path(tmp)
    spring = str(BIN / "spring_participant")
    rec_rows = []
    # 1. real exchange with an analytic answer
    r = launch(
        tmp / "springs",
        "--record",
        "--run-id",
        "springs-1",
        "--beam-cmd",
        f"{spring} --role beam",
        "--solid-cmd",
        f"{spring} --role solid",
    )
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
        r2 = launch(
            tmp / "replay",
            "--run-id",
            "replayed",
            "--beam-cmd",
            f"{replay} --role beam --recording {rec}",
            "--solid-cmd",
            f"{replay} --role solid --recording {rec}",
        )
        check(r2.returncode == 0, f"replayed run exits 0 (got {r2.returncode})\n{r2.stdout}\n{r2.stderr}")
        if r2.returncode == 0:
            keys = ["step", "time", "coupling_iterations", "residual", "omega", "n_active", "contact_force_x"]
            a = [[row[k] for k in keys] for row in rec_rows]
            b = [[row[k] for k in keys] for row in rows(tmp / "replay")]
            check(a == b, "replay reproduces the recorded iteration history exactly")

    # 3. a dying participant is named and the others are stopped
    t0 = time.time()
    r3 = launch(tmp / "dies", "--beam-cmd", "/bin/false", "--solid-cmd", f"{spring} --role solid")
    check(
        r3.returncode != 0 and "beam_solver exited with code 1" in r3.stderr,
        f"launcher names the failed participant (rc {r3.returncode}): {r3.stderr.strip()}",
    )
    check(time.time() - t0 < 60, "and does not wait for the peers' timeout")

    # 3b. Ctrl-C reaches every process: the launcher exits 130 and leaves no process behind
    cmd = LAUNCH + [
        str(SCENE),
        "--run-dir",
        str(tmp / "interrupted"),
        "--build-dir",
        str(BIN.parent),
        "--run-id",
        "interrupt-me",
        "--beam-cmd",
        f"{spring} --role beam --delay 0.5",
        "--solid-cmd",
        f"{spring} --role solid",
    ]
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
    check(
        summ.get("status") == "interrupted" and summ.get("steps") == n_rows and n_rows >= 1,
        f"interrupted run: summary status {summ.get('status')}, {summ.get('steps')} steps, "
        f"{n_rows} rows in coupling.csv",
    )

    # 4. no participants: the coupler times out with a clear error
    write_key(tmp / "alone" / "run.key")
    t0 = time.time()
    r4 = subprocess.run(
        [
            str(BIN / "coupler"),
            "--scene",
            str(SCENE),
            "--run-dir",
            str(tmp / "alone"),
            "--endpoint",
            f"unixsock-stream/{tmp}/alone.sock",
            "--run-id",
            "alone",
            "--timeout",
            "3",
        ],
        capture_output=True,
        text=True,
        timeout=60,
    )
    check(
        r4.returncode != 0 and "did not answer" in r4.stderr,
        f"coupler alone fails with a timeout error (rc {r4.returncode}): {r4.stderr.strip()}",
    )
    check(time.time() - t0 < 30, f"within the timeout ({time.time() - t0:.1f} s)")

    # 5. a frozen participant: the coupler, which waits for it, names it within --timeout; the other
    # participant waits 2 x --timeout before giving up, so it does not pre-empt the diagnosis
    cmd = LAUNCH + [
        str(SCENE),
        "--run-dir",
        str(tmp / "frozen"),
        "--build-dir",
        str(BIN.parent),
        "--run-id",
        "freeze-me",
        "--timeout",
        "6",
        "--beam-cmd",
        f"{spring} --role beam --delay 0.5",
        "--solid-cmd",
        f"{spring} --role solid",
    ]
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(3.0)
    beam_pids = subprocess.run(
        ["pgrep", "-f", "role beam --delay 0.5.*freeze-me"], capture_output=True, text=True
    ).stdout.split()
    check(len(beam_pids) == 1, f"the beam participant of the run is found ({beam_pids})")
    for pid in beam_pids:
        subprocess.run(["kill", "-STOP", pid])
    t0 = time.time()
    try:
        out, err = p.communicate(timeout=60)
        took = time.time() - t0
        check(p.returncode not in (0, None), f"frozen beam: the launcher fails (rc {p.returncode})")
        check(took < 6 + 5, f"frozen beam: stopped within --timeout + 5 s ({took:.1f} s)")
        check(
            "coupler exited with code 3" in err and "beam participant did not answer" in err,
            f"frozen beam: the launcher names the silent participant: {err.strip()[-400:]}",
        )
        summ = json.loads((tmp / "frozen" / "coupling_summary.json").read_text())
        check(
            summ.get("status") == "failed" and "beam" in summ.get("error", ""),
            f"frozen beam: coupling_summary.json says failed and names it ({summ.get('status')})",
        )
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

    # 6. peer authentication
    keys = ["step", "time", "coupling_iterations", "residual", "omega", "n_active", "contact_force_x"]
    rec = tmp / "springs" / "exchanges.angiorec"
    guarded = tmp / "guarded"
    cmd = LAUNCH + [
        str(SCENE),
        "--run-dir",
        str(guarded),
        "--build-dir",
        str(BIN.parent),
        "--timeout",
        "30",
        "--run-id",
        "springs-1",  # the recording's: the forged coupler's requests name this run
        "--beam-cmd",
        f"{spring} --role beam --delay 0.3",
        "--solid-cmd",
        f"{spring} --role solid",
    ]
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    sock = guarded / "coupler.sock"
    for _ in range(100):
        if sock.exists():
            break
        time.sleep(0.1)
    ep = f"unixsock-stream/{sock}"
    foreign = subprocess.Popen(
        [
            str(BIN / "transport_test_server"),
            "--connect",
            ep,
            "--key",
            "angio/springs-1/solid/**",
            "--token",
            "angio/springs-1/foreign",
            "--max-seconds",
            "60",
        ],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    out, err = p.communicate(timeout=120)
    foreign.kill()
    foreign.wait()
    check(
        p.returncode == 0,
        f"foreign replier answering first: the run completes (rc {p.returncode}) {err.strip()[-400:]}",
    )
    if p.returncode == 0 and rec_rows:
        a = [[row[k] for k in keys] for row in rec_rows]
        b = [[row[k] for k in keys] for row in rows(guarded)]
        check(a == b, "foreign replier answering first: the coupling history equals run 1's")

    # a forged coupler (the recorded requests, sealed with another key) gets no answer
    ep = f"unixsock-stream/{tmp}/forged.sock"
    participant = subprocess.Popen(
        [
            spring,
            "--role",
            "beam",
            "--scene",
            str(SCENE),
            "--endpoint",
            ep,
            "--run-id",
            "springs-1",
            "--timeout",
            "1",
            "--run-dir",
            str(tmp / "forged"),
            "--key-file",
            str(write_key(tmp / "real.key")),
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    forged = subprocess.run(
        [
            str(BIN / "replay_driver"),
            "--recording",
            str(rec),
            "--role",
            "beam",
            "--endpoint",
            ep,
            "--key-file",
            str(write_key(tmp / "forged.key")),
            "--timeout",
            "3",
        ],
        capture_output=True,
        text=True,
        timeout=60,
    )
    try:
        plog, _ = participant.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        participant.kill()
        plog, _ = participant.communicate()
    check(
        forged.returncode != 0 and "not authenticated" in forged.stderr,
        f"a forged coupler gets no answer (rc {forged.returncode}): {forged.stderr.strip()[-300:]}",
    )
    check(
        "so far): message is not authenticated" in plog,
        f"the participant refuses the forged request and says so: {plog.strip()[-300:]}",
    )

    # a participant started with another key file: the coupler stops at the handshake and says why
    r6 = launch(
        tmp / "otherkey",
        "--timeout",
        "5",
        "--beam-cmd",
        f"{spring} --role beam --key-file {write_key(tmp / 'other.key')}",
        "--solid-cmd",
        f"{spring} --role solid",
        timeout=60,
    )
    check(
        r6.returncode != 0 and "not authenticated" in r6.stderr and "beam" in r6.stderr,
        f"a participant with another key is refused by name (rc {r6.returncode}): {r6.stderr.strip()[-400:]}",
    )

    # key files: readable by others, or missing, is bad input naming the file
    loose = write_key(tmp / "loose" / "run.key")
    os.chmod(loose, 0o644)
    for name, run_dir, what in (("loose", tmp / "loose", "mode 0644"), ("missing", tmp / "nokey", "run.key")):
        r = subprocess.run(
            [
                str(BIN / "coupler"),
                "--scene",
                str(SCENE),
                "--run-dir",
                str(run_dir),
                "--endpoint",
                f"unixsock-stream/{tmp}/{name}.sock",
                "--run-id",
                name,
                "--timeout",
                "3",
            ],
            capture_output=True,
            text=True,
            timeout=30,
        )
        check(
            r.returncode == 2 and what in r.stderr and str(run_dir / "run.key") in r.stderr,
            f"{name} key file: exit 2 naming the file (rc {r.returncode}): {r.stderr.strip()[-300:]}",
        )
    launched_key = guarded / "run.key"
    check(
        launched_key.stat().st_mode & 0o777 == 0o600 and len(launched_key.read_text().strip()) == 64,
        "the launcher writes a 0600 key of 64 hex digits into the run directory",
    )

sys.exit(1 if failures else 0)
