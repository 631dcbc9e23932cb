#!/usr/bin/python3
"""Launch one scene: start exactly the processes it needs and supervise them.

  stent + balloon/artery -> coupler + beam_solver + solid_solver (mpirun -n <solid.ranks>)
  stent only             -> beam_solver alone (beam-only scene)
  balloon/artery only    -> solid_solver alone (mpirun), no coupling iterations

A unique endpoint per run (a unix socket in the run directory, or a free loopback TCP port) keeps
parallel runs apart. Ctrl-C is forwarded to every process; if one process fails, the others are
stopped and the exit code names the failing process. Units in scenes: mm, N, MPa, s.
"""
import argparse
import os
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
import uuid
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parent.parent
UNIX_PATH_MAX = 107


def die(msg, code=2):
    print(f"launch: error: {msg}", file=sys.stderr)
    sys.exit(code)


def load_scene(path):
    try:
        with open(path) as f:
            scene = yaml.safe_load(f)
    except FileNotFoundError:
        die(f"{path}: no such scene file")
    except yaml.YAMLError as e:
        die(f"{path}: YAML syntax error: {e}")
    if not isinstance(scene, dict):
        die(f"{path}: expected a YAML map at the top level")
    return scene


def free_tcp_port():
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def pick_endpoint(run_dir, transport):
    sock = (run_dir / "coupler.sock").resolve()
    if transport == "unix" or (transport == "auto" and len(str(sock)) <= UNIX_PATH_MAX - 1):
        if len(str(sock)) > UNIX_PATH_MAX - 1:
            die(f"unix socket path {sock} is longer than {UNIX_PATH_MAX} bytes; use --transport tcp")
        if sock.exists():
            sock.unlink()
        return f"unixsock-stream/{sock}"
    return f"tcp/127.0.0.1:{free_tcp_port()}"


def find_binary(build_dir, name):
    p = build_dir / "bin" / name
    if not p.is_file():
        die(f"{p} not found: build first (scripts/build.sh) or pass --build-dir")
    return str(p)


def int_setting(scene, section, key, default, scene_path):
    sec = scene.get(section) or {}
    v = sec.get(key, default) if isinstance(sec, dict) else default
    if not isinstance(v, int) or v < 1:
        die(f"{scene_path}: {section}.{key}: expected an integer >= 1, got {v!r}")
    return v


class Proc:
    def __init__(self, name, cmd, log_path, echo_all=True):
        self.name = name
        self.echo_all = echo_all
        self.cmd = cmd
        self.log = open(log_path, "w")
        # Own process group: Ctrl-C reaches the launcher only, which forwards it deliberately.
        self.p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                  start_new_session=True, text=True, bufsize=1)
        self.t = threading.Thread(target=self._pump, daemon=True)
        self.t.start()

    def _pump(self):
        for line in self.p.stdout:
            # In coupled runs the coupler's line per step is the progress; participants show
            # only their warnings and errors on the terminal (everything is in their log file).
            if self.echo_all or "WARN" in line or "ERROR" in line or "rror" in line:
                sys.stdout.write(line)
                sys.stdout.flush()
            self.log.write(line)
            self.log.flush()

    def signal(self, sig):
        if self.p.poll() is None:
            try:
                os.killpg(self.p.pid, sig)
            except ProcessLookupError:
                pass


def stop_all(procs, grace=5.0):
    for pr in procs:
        pr.signal(signal.SIGTERM)
    deadline = time.time() + grace
    for pr in procs:
        try:
            pr.p.wait(timeout=max(0.1, deadline - time.time()))
        except subprocess.TimeoutExpired:
            pr.signal(signal.SIGKILL)
            pr.p.wait()


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene", help="scene file (YAML)")
    ap.add_argument("--run-dir", help="run directory (default: runs/<scene>-<time>)")
    ap.add_argument("--build-dir", default=str(ROOT / "build"), help="CMake build directory")
    ap.add_argument("--ranks", type=int, help="MPI ranks of the solid solver (overrides solid.ranks)")
    ap.add_argument("--transport", choices=["auto", "unix", "tcp"], default="auto")
    ap.add_argument("--record", action="store_true", help="record all exchanges (coupled scenes)")
    ap.add_argument("--timeout", type=float, default=600.0, help="peer silence timeout, s")
    ap.add_argument("--log-level", default="info", choices=["debug", "info", "warn", "error"])
    ap.add_argument("--verbose", action="store_true",
                    help="show every participant's output on the terminal (default: coupler only)")
    ap.add_argument("--run-id", help="run id (default: random); replays need the recorded one")
    ap.add_argument("--beam-cmd", help="replace the beam participant executable (same CLI)")
    ap.add_argument("--solid-cmd", help="replace the solid participant executable (same CLI)")
    args = ap.parse_args()

    # One BLAS thread per process: the solid runs one MPI rank per core, and a threaded OpenBLAS under
    # MUMPS would oversubscribe the cores (a user's explicit setting wins).
    for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS"):
        os.environ.setdefault(var, "1")
    scene_path = Path(args.scene).resolve()
    scene = load_scene(scene_path)
    has_stent = "stent" in scene
    has_solid = "balloon" in scene or "artery" in scene
    if not has_stent and not has_solid:
        die(f"{scene_path}: the scene has none of 'stent', 'balloon', 'artery': nothing to simulate")

    build = Path(args.build_dir).resolve()
    stamp = time.strftime("%Y%m%d-%H%M%S")
    run_dir = Path(args.run_dir or ROOT / "runs" / f"{scene_path.stem}-{stamp}").resolve()
    run_dir.mkdir(parents=True, exist_ok=True)
    shutil.copy(scene_path, run_dir / "scene.yaml")
    run_id = args.run_id or uuid.uuid4().hex[:12]
    common = ["--scene", str(scene_path), "--run-dir", str(run_dir), "--log-level", args.log_level,
              "--timeout", str(args.timeout)]

    ranks = args.ranks or int_setting(scene, "solid", "ranks", 1, scene_path)
    mpirun = ["mpirun", "-n", str(ranks), "--oversubscribe", "--bind-to", "none"]
    if os.geteuid() == 0:
        mpirun.append("--allow-run-as-root")
    beam_exe = args.beam_cmd.split() if args.beam_cmd else [find_binary(build, "beam_solver")] if has_stent else None
    solid_exe = (args.solid_cmd.split() if args.solid_cmd else mpirun + [find_binary(build, "solid_solver")]) if has_solid else None

    plan = []
    if has_stent and has_solid:
        endpoint = pick_endpoint(run_dir, args.transport)
        coupled = ["--endpoint", endpoint, "--run-id", run_id]
        coupler = [find_binary(build, "coupler")] + common + coupled + (["--record"] if args.record else [])
        plan = [("coupler", coupler), ("beam_solver", beam_exe + common + coupled),
                ("solid_solver", solid_exe + common + coupled)]
    elif has_stent:
        plan = [("beam_solver", beam_exe + common)]
    else:
        plan = [("solid_solver", solid_exe + common)]

    print(f"launch: run directory {run_dir}")
    print("launch: processes: " + ", ".join(name for name, _ in plan))
    procs = []
    interrupted = {"sig": None}

    def forward(sig, _frame):
        interrupted["sig"] = sig
        for pr in procs:
            pr.signal(signal.SIGINT if sig == signal.SIGINT else signal.SIGTERM)

    signal.signal(signal.SIGINT, forward)
    signal.signal(signal.SIGTERM, forward)
    t0 = time.time()
    for name, cmd in plan:
        try:
            echo = args.verbose or len(plan) == 1 or name == "coupler"
            procs.append(Proc(name, cmd, run_dir / f"{name}.log", echo_all=echo))
        except OSError as e:
            stop_all(procs)
            die(f"cannot start {name} ({' '.join(cmd[:1])}): {e.strerror}", code=10 + len(procs))

    failed = None
    while True:
        alive = [pr for pr in procs if pr.p.poll() is None]
        for pr in procs:
            rc = pr.p.poll()
            if rc not in (None, 0) and failed is None and interrupted["sig"] is None:
                failed = (pr.name, rc)
        if failed or not alive:
            break
        if interrupted["sig"] is not None:
            stop_all(procs, grace=10.0)
            break
        time.sleep(0.2)

    if failed:
        stop_all([pr for pr in procs if pr.p.poll() is None])
    for pr in procs:
        pr.p.wait()
        pr.t.join(timeout=2.0)
    wall = time.time() - t0
    if interrupted["sig"] is not None:
        print(f"launch: interrupted after {wall:.1f} s; partial results in {run_dir}", file=sys.stderr)
        return 130
    if failed:
        name, rc = failed
        print(f"launch: error: {name} exited with code {rc} after {wall:.1f} s "
              f"(log: {run_dir / (name + '.log')}); the other processes were stopped", file=sys.stderr)
        # 2 is every executable's "bad scene or mesh" (the message names the file and key): passed on
        # unchanged, so that a bad scene is exit code 2 from the launcher as from the solvers
        return 2 if rc == 2 else 10 + [n for n, _ in plan].index(name)
    print(f"launch: finished in {wall:.1f} s; results in {run_dir}")
    report = ROOT / "scripts" / "report.py"
    if report.is_file():
        subprocess.call([sys.executable, str(report), str(run_dir)])
    return 0


if __name__ == "__main__":
    sys.exit(main())
