#!/usr/bin/python3
"""Launch one scene: start exactly the processes it needs and supervise them.

  stent + balloon/artery -> coupler + beam_solver + solid_solver (mpirun -n <solid.ranks>)
  stent only             -> beam_solver alone (beam-only scene)
  balloon/artery only    -> solid_solver alone (mpirun), no coupling iterations

A scene with a `patient:` section (a lumen centerline CSV) is completed first (scripts/patient/:
stenosis, balloon and stent placement, three-layer tet10 artery mesh); the solvers then read the
completed scene <run_dir>/scene.yaml and the user's scene is kept as <run_dir>/scene.input.yaml.

A unique endpoint per run (a unix socket in the run directory, or a free loopback TCP port) keeps
parallel runs apart. Ctrl-C is forwarded to every process; if one process fails, the others are
stopped and the exit code names the failing process. Units in scenes: mm, N, MPa, s.
"""
import argparse
import atexit
import ctypes
import difflib
import fcntl
import json
import math
import os
import re
import shlex
import shutil
import signal
import secrets
import socket
import stat
import subprocess
import sys
import tempfile
import threading
import time
import uuid
from pathlib import Path

import yaml

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))  # the sibling tools, also under runpy
import scene_keys  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
UNIX_PATH_MAX = 107
# The top-level sections some executable reads (core/scene/keys.yaml). The launcher picks the
# processes from these keys, so a misspelt one must stop the launch instead of silently running
# another simulation (a scene without its `stent` runs the balloon alone).
SECTIONS = tuple(scene_keys.children(""))
# Catches typos (-n 2000 oversubscribes the machine into the ground) without limiting real runs.
MAX_RANKS = 256
# The run id is a chunk of the zenoh key expressions angio/<run_id>/...: '/' would shift the chunks
# and '*', '$', '?', '#' are wildcards or reserved, i.e. could reach another run's processes.
RUN_ID = re.compile(r"[A-Za-z0-9._-]{1,64}")
PR_SET_PDEATHSIG = 1  # linux/prctl.h


def die(msg, code=2):
    print(f"launch: error: {msg}", file=sys.stderr)
    sys.exit(code)


def shown(v, n=60):
    """repr(v) cut to n characters: a message stays one readable line whatever the value."""
    r = repr(v)
    return r if len(r) <= n else r[: n - 3] + "..."


class DuplicateKey(Exception):
    pass


class SceneLoader(yaml.SafeLoader):
    """SafeLoader that refuses a key given twice in one map. PyYAML keeps the last one silently, so
    a scene with `E:` twice in stent.material would run with whichever came last.

    The check runs on the composed node tree, before anything is constructed: nested maps are
    constructed out of document order (generators), so a construct_mapping override would not know
    their key path, and merge keys (`<<: *defaults`) are flattened into the maps in place there,
    after which an overridden merged key would look like a duplicate."""

    def construct_document(self, node):
        self._check(node, "", set())
        return super().construct_document(node)

    def _check(self, node, path, seen):
        if id(node) in seen:  # an alias of a node already checked (or a recursive one)
            return
        seen.add(id(node))
        if isinstance(node, yaml.MappingNode):
            first = {}
            for k, v in node.value:
                name = k.value if isinstance(k, yaml.ScalarNode) else "?"
                sub = f"{path}.{name}" if path else name
                if isinstance(k, yaml.ScalarNode) and k.tag != "tag:yaml.org,2002:merge":
                    line = k.start_mark.line + 1
                    if (k.tag, k.value) in first:
                        raise DuplicateKey(sub, first[(k.tag, k.value)], line)
                    first[(k.tag, k.value)] = line
                self._check(v, sub, seen)
        elif isinstance(node, yaml.SequenceNode):
            for i, v in enumerate(node.value):
                self._check(v, f"{path}[{i}]", seen)


def load_scene(path):
    """The scene as a dict of known sections, or exit 2 with a message naming the file."""
    try:
        st = os.stat(path)
        if not stat.S_ISREG(st.st_mode):  # a directory, or a FIFO or device that never ends
            kind = "a directory" if stat.S_ISDIR(st.st_mode) else "not a regular file"
            die(f"{path}: expected a scene file (YAML), got {kind}")
        with open(path, "rb") as f:
            data = f.read()
    except FileNotFoundError:
        die(f"{path}: no such scene file")
    except OSError as e:
        die(f"{path}: cannot read the scene file: {e.strerror}")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as e:
        die(f"{path}: expected a YAML text file (UTF-8), got byte 0x{data[e.start]:02x} at offset {e.start}")
    try:
        scene = yaml.load(text, Loader=SceneLoader)
    except DuplicateKey as e:
        key, a, b = e.args
        lines = f"lines {a} and {b}" if a != b else f"line {a}"
        die(f"{path}: {key}: expected each key once in a map, got it twice ({lines})")
    except yaml.MarkedYAMLError as e:
        m = e.problem_mark
        where = f"line {m.line + 1}, column {m.column + 1}: " if m else ""
        what = " ".join(f"{e.problem or ''} {e.context or ''}".split())
        die(f"{path}: {where}expected valid YAML, got a syntax error: {what}")
    except yaml.YAMLError as e:  # e.g. a control character (ReaderError)
        die(f"{path}: expected valid YAML, got: {' '.join(str(e).split())}")
    except RecursionError:
        die(f"{path}: expected a scene, got YAML nested too deeply to read")
    if scene is None:
        die(f"{path}: expected a YAML map of sections, got an empty document")
    if not isinstance(scene, dict):
        die(f"{path}: expected a YAML map of sections at the top level, got a {type(scene).__name__}")
    for key in scene:
        if key not in SECTIONS:
            near = difflib.get_close_matches(str(key), SECTIONS, n=1)
            hint = f"; did you mean `{near[0]}`?" if near else ""
            die(f"{path}: {key}: expected a top-level section ({', '.join(SECTIONS)}), got an unknown key{hint}")
    return scene, data


def prepare_patient(scene, scene_path):
    """Runs the patient pipeline into a scratch directory: (scratch dir, completed scene). Bad input
    (the centerline, the patient keys, devices that do not fit) exits 2 naming the file and key."""
    sys.path.insert(0, str(ROOT / "scripts"))
    try:
        from patient.errors import PatientInputError
        from patient.prepare import prepare_scene
    except ImportError as e:  # numpy/scipy/gmsh missing: a setup problem, not a bad scene
        die(f"{scene_path}: patient: the pipeline needs numpy, scipy and gmsh (scripts/setup.sh): {e}", code=1)
    scratch = Path(tempfile.mkdtemp(prefix="angio-patient-"))
    atexit.register(shutil.rmtree, scratch, True)  # left over only if the launch stops before the move
    try:
        done, _ = prepare_scene(scene, scene_path, scratch, log=lambda m: print(f"launch: {m}", flush=True))
    except PatientInputError as e:  # bad input, including a geometry gmsh cannot mesh (the atexit removes scratch)
        die(str(e))
    return scratch, done


def scratch_scene(prepared):
    """The completed patient scene written into its scratch directory (for --check)."""
    scratch, done = prepared
    path = scratch / "scene.yaml"
    with open(path, "w") as f:
        yaml.safe_dump(done, f, sort_keys=False)
    return path


def check_scene_with(name, exe, scene_path):
    """Runs `exe --scene S --check`: exit 2 with the executable's own message (file, key) if the
    scene is bad."""
    try:
        r = subprocess.run(
            exe + ["--scene", str(scene_path), "--check", "--log-level", "error"],
            capture_output=True,
            text=True,
            errors="replace",
            timeout=600,
        )
    except (OSError, subprocess.TimeoutExpired) as e:
        die(f"cannot check the scene with {name}: {e}", code=1)
    if r.returncode == 0:
        return
    msg = next((ln for ln in reversed((r.stderr + r.stdout).splitlines()) if ln.strip()), "")
    msg = re.sub(r"^\[[a-z_]+\] (ERROR: )?", "", msg.strip())
    if r.returncode == 2:
        die(msg or f"{name} refused the scene")
    die(f"{name} --check failed with exit code {r.returncode}: {msg}", code=1)


def install_prepared(prepared, run_dir):
    """Moves the generated geometry to <run_dir>/geometry and writes the completed scene with its
    paths there; returns the completed scene's path."""
    scratch, done = prepared
    dest = run_dir / "geometry"
    if dest.exists():  # a reused --run-dir: the geometry of this launch replaces the last one's
        shutil.rmtree(dest)
    (scratch / "scene.yaml").unlink(missing_ok=True)  # the checked copy, with the scratch paths
    shutil.move(str(scratch), str(dest))

    def relocate(node):
        if isinstance(node, dict):
            return {k: relocate(v) for k, v in node.items()}
        if isinstance(node, list):
            return [relocate(v) for v in node]
        if isinstance(node, str) and node.startswith(str(scratch)):
            return str(dest) + node[len(str(scratch)) :]
        return node

    path = run_dir / "scene.yaml"
    with open(path, "w") as f:
        f.write("# Completed by the launcher from scene.input.yaml (patient pipeline, geometry/placement.json)\n")
        yaml.safe_dump(relocate(done), f, sort_keys=False)
    return path


def free_tcp_port(host="127.0.0.1"):
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind((host, 0))
        return s.getsockname()[1]


def pick_endpoint(run_dir, transport):
    if transport == "auto" and in_slurm_allocation() and int(os.environ.get("SLURM_JOB_NUM_NODES", "1")) > 1:
        # ranks on other nodes cannot reach a unix socket or the loopback of this one
        return f"tcp/{host_address()}:{free_tcp_port('0.0.0.0')}"
    sock = (run_dir / "coupler.sock").resolve()
    if transport == "unix" or (transport == "auto" and len(str(sock)) <= UNIX_PATH_MAX - 1):
        if len(str(sock)) > UNIX_PATH_MAX - 1:
            die(f"unix socket path {sock} is longer than {UNIX_PATH_MAX} bytes; use --transport tcp")
        if sock.exists():
            sock.unlink()
        return f"unixsock-stream/{sock}"
    return f"tcp/127.0.0.1:{free_tcp_port()}"


def host_address():
    """This host's address as other nodes reach it: a non-loopback IPv4 address its name resolves to
    (Debian maps the host name to 127.0.1.1 in /etc/hosts when it has no other)."""
    try:
        infos = socket.getaddrinfo(socket.gethostname(), None, socket.AF_INET)
    except OSError:
        infos = []
    routable = sorted(a for a in {ai[4][0] for ai in infos} if not a.startswith("127."))
    if not routable:
        die(
            f"{socket.gethostname()} resolves to no address other nodes can reach; "
            "pass --endpoint tcp/<this node's address>:<port>"
        )
    return routable[0]


def in_slurm_allocation():
    return bool(os.environ.get("SLURM_JOB_ID")) and shutil.which("srun") is not None


def mpi_command(launcher, ranks):
    """How the solid's ranks start: mpirun on a workstation; srun inside a Slurm allocation (a job
    or an array task of scripts/study.py), so that Slurm places the ranks on the allocated cores and
    nodes. srun's MPI plugin is SLURM_MPI_TYPE if set, else pmix (Debian's Open MPI and Slurm)."""
    if launcher == "auto":
        launcher = "srun" if in_slurm_allocation() else "mpirun"
    if launcher == "srun":
        if shutil.which("srun") is None:
            die("--mpi-launcher srun: srun not found on PATH")
        return [
            "srun",
            f"--mpi={os.environ.get('SLURM_MPI_TYPE') or 'pmix'}",
            "--ntasks",
            str(ranks),
            "--input",
            "none",
            "--kill-on-bad-exit=1",
        ]
    cmd = ["mpirun", "-n", str(ranks), "--oversubscribe", "--bind-to", "none"]
    if os.geteuid() == 0:
        cmd.append("--allow-run-as-root")
    return cmd


def endpoint_arg(text):
    if not re.fullmatch(r"tcp/[A-Za-z0-9._-]+:[0-9]{1,5}", text):
        raise argparse.ArgumentTypeError(f"expected tcp/HOST:PORT, got {text!r}")
    return text


def find_binary(build_dir, name):
    p = build_dir / "bin" / name
    if not p.is_file():
        die(f"{p} not found: build first (scripts/build.sh) or pass --build-dir")
    return str(p)


def solid_ranks(scene, scene_path):
    sec = scene.get("solid")
    if sec is None:
        return 1
    if not isinstance(sec, dict):
        die(f"{scene_path}: solid: expected a map, got {shown(sec)}")
    v = sec.get("ranks", 1)
    # bool is an int in Python: `ranks: true` must not run one rank
    if isinstance(v, bool) or not isinstance(v, int) or not 1 <= v <= MAX_RANKS:
        die(f"{scene_path}: solid.ranks: expected an integer in 1..{MAX_RANKS}, got {shown(v)}")
    return v


def ranks_arg(text):
    try:
        v = int(text)
    except ValueError:
        v = 0
    if not 1 <= v <= MAX_RANKS:
        raise argparse.ArgumentTypeError(f"expected an integer in 1..{MAX_RANKS}, got {text!r}")
    return v


def command_arg(option, text):
    try:
        cmd = shlex.split(text)  # quotes as in a shell: paths with spaces, python -c '...'
    except ValueError as e:
        die(f"{option}: expected a command line, got {shown(text)} ({e})")
    if not cmd:
        die(f"{option}: expected a command line, got an empty one")
    return cmd


def make_run_dir(run_dir, explicit):
    """Creates the run directory owner-only (it holds the coupler's socket: whoever can connect to it
    can talk to the solvers); an explicit --run-dir that exists is reused."""
    try:
        run_dir.mkdir(mode=0o700, parents=True)
        os.chmod(run_dir, 0o700)  # mkdir's mode is masked by the umask
    except FileExistsError:
        if not explicit:  # a fresh default name that exists: never write into someone else's run
            die(f"{run_dir}: expected a new run directory, got an existing one; pass --run-dir")
        if not run_dir.is_dir():
            die(f"{run_dir}: expected a run directory, got an existing file")
    except OSError as e:
        die(f"{run_dir}: cannot create the run directory: {e.strerror}")


def write_run_key(path):
    """A new secret for this launch (docs/reliability.md "Security"): every message of the run carries an
    HMAC-SHA256 tag under it, and the executables read it from <run dir>/run.key, so only processes
    that can read this owner-only file can speak for the coupler or a participant."""
    try:
        path.unlink(missing_ok=True)  # a reused run directory: never the last launch's key
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        with os.fdopen(fd, "w") as f:
            f.write(secrets.token_hex(32) + "\n")
    except OSError as e:
        die(f"{path}: cannot write the run's key: {e.strerror}")


def lock_run_dir(run_dir):
    """Holds <run_dir>/launch.lock (flock) until the launcher exits. The kernel drops the lock when
    the launcher dies however it dies, so a leftover file never blocks a later launch. Returns the
    open file: the lock lives as long as it."""
    try:
        f = open(run_dir / "launch.lock", "a+")
    except OSError as e:
        die(f"{run_dir}: cannot write to the run directory: {e.strerror}")
    try:
        fcntl.flock(f, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        f.seek(0)
        other = f.read().strip() or "?"
        die(
            f"{run_dir}: expected a free run directory, got one in use by another launch (pid {other}); "
            "pass another --run-dir"
        )
    f.seek(0)
    f.truncate()
    f.write(f"{os.getpid()}\n")
    f.flush()
    # A coupler started some other way (an older launcher, by hand) holds zenoh's lock on its socket:
    # starting a second one here would unlink that socket under the running coupler.
    zlock = run_dir / "coupler.sock.lock"
    if zlock.exists():
        try:
            with open(zlock) as z:
                fcntl.flock(z, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            die(
                f"{run_dir}: expected a free run directory, got one in use by another launch "
                "(a running coupler holds coupler.sock.lock); pass another --run-dir"
            )
        except OSError as e:
            die(f"{zlock}: cannot check the coupler's lock: {e.strerror}")
    return f


def die_with_launcher():
    """preexec_fn for every child: PR_SET_PDEATHSIG makes the kernel send SIGTERM to the child when
    the launcher dies, even by SIGKILL, where no handler of ours runs (mpirun passes SIGTERM on to its
    ranks). preexec_fn runs between fork and exec while the pump threads of earlier children exist,
    so it only calls a prctl resolved here, before the fork. None where there is no prctl."""
    if not sys.platform.startswith("linux"):
        return None
    try:
        prctl = ctypes.CDLL(None, use_errno=True).prctl
    except (OSError, AttributeError):
        return None
    parent, sig = os.getpid(), ctypes.c_ulong(int(signal.SIGTERM))

    def preexec():
        prctl(PR_SET_PDEATHSIG, sig)
        if os.getppid() != parent:  # the launcher died before the prctl: no signal will come
            os._exit(128 + int(signal.SIGTERM))

    return preexec


class Proc:
    def __init__(self, name, cmd, log_path, echo_all=True):
        self.name = name
        self.echo_all = echo_all
        self.echo_ok = True
        self.cmd = cmd
        self.log = open(log_path, "w")
        # Own process group: Ctrl-C reaches the launcher only, which forwards it deliberately.
        # errors="replace": a byte that is not UTF-8 in a solver's output must not kill the pump.
        self.p = subprocess.Popen(
            cmd,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            start_new_session=True,
            preexec_fn=die_with_launcher(),
            text=True,
            errors="replace",
            bufsize=1,
        )
        self.t = threading.Thread(target=self._pump, daemon=True)
        self.t.start()

    def _pump(self):
        # Whatever happens to the terminal or the disk, the pipe is drained to the end: a pump that
        # stopped would block the process on its next line once the pipe buffer is full.
        for line in self.p.stdout:
            # In coupled runs the coupler's line per step is the progress; participants show
            # only their warnings and errors on the terminal (everything is in their log file).
            if self.echo_ok and (self.echo_all or "WARN" in line or "ERROR" in line or "rror" in line):
                try:
                    sys.stdout.write(line)
                    sys.stdout.flush()
                except (OSError, ValueError):  # terminal gone, stdout closed (| head)
                    self.echo_ok = False
            if self.log:
                try:
                    self.log.write(line)
                    self.log.flush()
                except OSError as e:  # disk full: say so once, keep draining
                    self.log = None
                    try:
                        print(f"launch: warning: {self.name}.log: {e.strerror}; log incomplete", file=sys.stderr)
                    except (OSError, ValueError):
                        pass

    def signal(self, sig):
        if self.p.poll() is None:
            try:
                os.killpg(self.p.pid, sig)
            except ProcessLookupError:
                pass


def last_error_line(log_path, limit=400):
    """The last ERROR line of a process's log (its own diagnosis, e.g. which participant went
    silent), cut to one readable line; '' if there is none."""
    try:
        with open(log_path, "rb") as f:
            f.seek(max(0, os.path.getsize(log_path) - 65536))
            lines = f.read().decode("utf-8", "replace").splitlines()
    except OSError:
        return ""
    for ln in reversed(lines):
        if "ERROR" in ln:
            ln = " ".join(ln.split())
            return ln if len(ln) <= limit else ln[: limit - 3] + "..."
    return ""


def stop_all(procs, grace=5.0):
    for pr in procs:
        pr.signal(signal.SIGTERM)
        pr.signal(signal.SIGCONT)  # a stopped (frozen) process acts on the SIGTERM only once continued
    deadline = time.time() + grace
    for pr in procs:
        try:
            pr.p.wait(timeout=max(0.1, deadline - time.time()))
        except subprocess.TimeoutExpired:
            pr.signal(signal.SIGKILL)
            pr.p.wait()


def state_time(path):
    """The committed pseudo-time of a solver's state file (state_file.hpp), or exit 2 naming it."""
    try:
        import h5py

        with h5py.File(path, "r") as f:
            t = float(f.attrs["time"])
    except (OSError, KeyError, ValueError, ImportError) as e:
        die(f"{path}: expected a state file of a run (output.state), got: {' '.join(str(e).split())}")
    if not math.isfinite(t):
        die(f"{path}: expected a finite time in the state file, got {t}")
    return t


def resumed_scene(scene, scene_path, run_dir):
    """The scene continued from the state files of an earlier run of it (--resume): time.start at the
    states' time, the steps left at the scene's nominal increment, every part from its state. Written
    next to the scene as .<stem>.resume-<t>.yaml; returns its path."""
    if "procedure" in scene or "patient" in scene:
        die(
            f"--resume: a {'procedure' if 'procedure' in scene else 'patient scene'} cannot be resumed yet; "
            "continue it with solid.initial_state / stent.initial_state by hand"
        )
    states = {}
    if "stent" in scene:
        states["beam"] = run_dir / "beam" / "state.h5"
    if "balloon" in scene or "artery" in scene:
        states["solid"] = run_dir / "solid" / "state.h5"
    for p in states.values():
        if not p.is_file():
            die(f"--resume {run_dir}: expected {p} (a run of this scene with output.state), got none")
    times = {k: state_time(p) for k, p in states.items()}
    t = next(iter(times.values()))
    if any(abs(v - t) > 1e-9 * max(1.0, abs(t)) for v in times.values()):
        die(
            f"--resume {run_dir}: expected the solvers' state files at one time, got "
            + ", ".join(f"{k} t = {v}" for k, v in times.items())
            + " (the run stopped while they were written)"
        )
    ts = dict(scene.get("time") or {})
    start, end, steps = float(ts.get("start", 0.0)), float(ts.get("end", 1.0)), int(ts.get("steps", 1))
    if not t < end - 1e-12 * max(1.0, abs(end)):
        die(
            f"--resume {run_dir}: the states are at t = {t} s, the scene's end (time.end = {end} s): "
            "nothing left to run"
        )
    ts.update(start=t, steps=max(1, round(steps * (end - t) / (end - start))))
    s = json.loads(json.dumps(scene))
    s["time"] = ts
    if "beam" in states:
        s["stent"]["initial_state"] = {"file": str(states["beam"])}
    if "solid" in states:
        s.setdefault("solid", {})["initial_state"] = {"file": str(states["solid"])}
    path = scene_path.parent / f".{scene_path.stem}.resume-{t:g}.yaml"
    try:
        path.write_text(
            f"# {scene_path.name} continued from {run_dir} at t = {t} s (launch.py --resume)\n"
            + yaml.safe_dump(s, sort_keys=False)
        )
    except OSError as e:
        die(f"{path}: cannot write the continued scene: {e.strerror}")
    print(f"launch: resuming {scene_path.name} from {run_dir} at t = {t} s ({ts['steps']} steps left)")
    return path


def run_procedure(scene, scene_path, scene_text, args):
    """A scene with `procedure:`: every phase checked, then run one after the other into
    <run dir>/<k>-<name>/ (scripts/procedure.py)."""
    sys.path.insert(0, str(ROOT / "scripts"))
    import procedure

    for opt in ("record", "run_id", "beam_cmd", "solid_cmd"):
        if getattr(args, opt):
            die(f"--{opt.replace('_', '-')}: not supported for a procedure (a scene with `procedure:`)")
    passed = [
        "--build-dir",
        args.build_dir,
        "--transport",
        args.transport,
        "--mpi-launcher",
        args.mpi_launcher,
        "--log-level",
        args.log_level,
    ]
    passed += (["--ranks", str(args.ranks)] if args.ranks is not None else []) + (["--verbose"] if args.verbose else [])
    passed += ["--timeout", str(args.timeout)] if args.timeout is not None else []
    passed += ["--endpoint", args.endpoint] if args.endpoint else []
    try:
        procedure.phases(scene, scene_path)
        if args.check:
            procedure.check(scene, scene_path, passed)
            print(f"launch: {scene_path}: the procedure is valid (every phase checked)")
            return 0
    except procedure.ProcedureError as e:
        die(str(e))
    stamp = time.strftime("%Y%m%d-%H%M%S")
    run_dir = Path(args.run_dir or ROOT / "runs" / f"{scene_path.stem}-{stamp}-{uuid.uuid4().hex[:12]}").resolve()
    fresh = not run_dir.exists()
    make_run_dir(run_dir, explicit=args.run_dir is not None)
    lock = lock_run_dir(run_dir)  # noqa: F841 (held until return)
    # A patient procedure is meshed and placed once, by the check, into the run's geometry/; a check
    # that fails leaves no run directory behind (a reused one keeps what it had but that geometry/).
    geometry = run_dir / "geometry"
    had_geometry = geometry.exists()
    try:
        completed = procedure.check(scene, scene_path, passed, geometry_dir=geometry)
    except procedure.ProcedureError as e:
        if fresh:
            shutil.rmtree(run_dir, ignore_errors=True)
        elif not had_geometry:
            shutil.rmtree(geometry, ignore_errors=True)
        die(str(e))
    (run_dir / "scene.yaml").write_bytes(scene_text)
    print(f"launch: procedure run directory {run_dir}")
    try:
        return procedure.run(scene, scene_path, run_dir, passed, completed=completed)
    except procedure.ProcedureError as e:
        die(str(e))


def parse_args():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene", help="scene file (YAML)")
    ap.add_argument(
        "--run-dir",
        help="run directory (default: runs/<scene>-<time>-<token>); " "refused while another launch uses it",
    )
    ap.add_argument("--build-dir", default=str(ROOT / "build"), help="CMake build directory")
    ap.add_argument("--ranks", type=ranks_arg, help="MPI ranks of the solid solver (overrides solid.ranks)")
    ap.add_argument(
        "--transport",
        choices=["auto", "unix", "tcp"],
        default="auto",
        help="auto: a unix socket in the run directory, tcp on this host's address when a "
        "Slurm allocation spans nodes (the solid's ranks may start elsewhere)",
    )
    ap.add_argument(
        "--endpoint",
        type=endpoint_arg,
        help="the coupler's zenoh endpoint, e.g. tcp/10.0.0.1:7447 (default: chosen by --transport); "
        "for participants on other hosts or network namespaces",
    )
    ap.add_argument(
        "--mpi-launcher",
        choices=["auto", "mpirun", "srun"],
        default="auto",
        help="how the solid's ranks start (auto: srun inside a Slurm allocation, else mpirun)",
    )
    ap.add_argument("--record", action="store_true", help="record all exchanges (coupled scenes)")
    ap.add_argument(
        "--timeout", type=float, help="peer silence timeout, s (default: the executables' own, `coupler --help`)"
    )
    ap.add_argument("--log-level", default="info", choices=["debug", "info", "warn", "error"])
    ap.add_argument(
        "--verbose", action="store_true", help="show every participant's output on the terminal (default: coupler only)"
    )
    ap.add_argument("--run-id", help="run id (default: random); replays need the recorded one")
    ap.add_argument("--beam-cmd", help="replace the beam participant executable (same CLI)")
    ap.add_argument("--solid-cmd", help="replace the solid participant executable (same CLI)")
    ap.add_argument(
        "--resume",
        metavar="RUN_DIR",
        help="continue a stopped run of this scene from its state files (RUN_DIR/solid/state.h5, "
        "beam/state.h5) to the scene's end, into RUN_DIR/continued-<time>/ unless --run-dir",
    )
    ap.add_argument(
        "--check",
        action="store_true",
        help="check the scene (every executable reads its keys; a patient's geometry is generated "
        "and meshed) and exit 0, or 2 naming the file and key; nothing is run or written",
    )
    args = ap.parse_args()
    if args.timeout is not None and not (math.isfinite(args.timeout) and args.timeout > 0):
        die(f"--timeout: expected a positive number of seconds, got {args.timeout}")
    if args.run_id is not None and not RUN_ID.fullmatch(args.run_id):
        die(f"--run-id: expected 1 to 64 of A-Z a-z 0-9 . _ -, got {shown(args.run_id)}")
    return args


def process_plan(run_dir, run_id, args, exes, solver_scene):
    """[(name, command)] of the processes to start: coupler, beam and solid for a coupled scene, else
    the one solver."""
    beam_exe, solid_exe, coupler_exe = exes
    common = ["--scene", str(solver_scene), "--run-dir", str(run_dir), "--log-level", args.log_level]
    if args.timeout is not None:
        common += ["--timeout", str(args.timeout)]
    if beam_exe and solid_exe:
        write_run_key(run_dir / "run.key")
        endpoint = args.endpoint or pick_endpoint(run_dir, args.transport)
        coupled = ["--endpoint", endpoint, "--run-id", run_id]
        coupler = coupler_exe + common + coupled + (["--record"] if args.record else [])
        return [
            ("coupler", coupler),
            ("beam_solver", beam_exe + common + coupled),
            ("solid_solver", solid_exe + common + coupled),
        ]
    if beam_exe:
        return [("beam_solver", beam_exe + common)]
    return [("solid_solver", solid_exe + common)]


def supervise(plan, run_dir, args):
    """Starts the processes, forwards Ctrl-C and SIGTERM, stops the others when one fails; the
    launcher's exit code, and the report of a finished run."""
    procs = []
    interrupted = {"sig": None}

    coupler_proc = lambda: next((pr for pr in procs if pr.name == "coupler"), None)  # noqa: E731

    def forward(sig, _frame):
        # A first Ctrl-C in a coupled run goes to the coupler alone: it finishes the step under way and
        # shuts the participants down, so every summary is written (mpirun would kill the solid's ranks
        # on a SIGINT of its own). A second Ctrl-C, or SIGTERM, stops everything now.
        c = coupler_proc()
        if sig == signal.SIGINT and interrupted["sig"] is None and c is not None and c.p.poll() is None:
            interrupted["sig"] = sig
            interrupted["graceful"] = True
            print("launch: stopping after the current step (Ctrl-C again to stop now)", file=sys.stderr, flush=True)
            c.signal(signal.SIGINT)
            return
        interrupted["sig"] = sig
        interrupted["graceful"] = False
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
        if interrupted["sig"] is not None and not interrupted.get("graceful"):
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
        why = last_error_line(run_dir / f"{name}.log")
        print(
            f"launch: error: {name} exited with code {rc} after {wall:.1f} s{': ' + why if why else ''} "
            f"(log: {run_dir / (name + '.log')}); the other processes were stopped",
            file=sys.stderr,
        )
        # 2 is every executable's "bad scene or mesh" (the message names the file and key): passed on
        # unchanged, so that a bad scene is exit code 2 from the launcher as from the solvers
        return 2 if rc == 2 else 10 + [n for n, _ in plan].index(name)
    print(f"launch: finished in {wall:.1f} s; results in {run_dir}")
    report = ROOT / "scripts" / "report.py"
    if report.is_file():
        subprocess.call([sys.executable, str(report), str(run_dir)])
    return 0


def main():
    args = parse_args()
    # One BLAS thread per process: the solid runs one MPI rank per core, and a threaded OpenBLAS under
    # MUMPS would oversubscribe the cores (a user's explicit setting wins).
    for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS"):
        os.environ.setdefault(var, "1")
    # All of the input is checked before the run directory exists: bad input leaves nothing behind.
    scene_path = Path(args.scene).resolve()
    scene, scene_text = load_scene(scene_path)
    if args.resume:
        resume_dir = Path(args.resume).resolve()
        scene_path = resumed_scene(scene, scene_path, resume_dir)
        scene, scene_text = load_scene(scene_path)
        if args.run_dir is None:
            args.run_dir = str(resume_dir / f"continued-{time.strftime('%Y%m%d-%H%M%S')}")
    if "procedure" in scene:  # phases, each a launch of its own (scripts/procedure.py)
        return run_procedure(scene, scene_path, scene_text, args)
    has_stent = "stent" in scene
    has_solid = "balloon" in scene or "artery" in scene
    if not has_stent and not has_solid:
        die(f"{scene_path}: expected at least one of 'stent', 'balloon', 'artery', got none: nothing to simulate")
    ranks = solid_ranks(scene, scene_path)
    if args.ranks is not None:
        ranks = args.ranks

    # A patient scene: geometry and mesh are generated before the run directory exists (bad input
    # leaves nothing behind), into a scratch directory moved into the run directory below.
    prepared = prepare_patient(scene, scene_path) if "patient" in scene else None

    build = Path(args.build_dir).resolve()
    mpirun = mpi_command(args.mpi_launcher, ranks)
    beam_exe = solid_exe = coupler_exe = None
    if has_stent:
        beam_exe = command_arg("--beam-cmd", args.beam_cmd) if args.beam_cmd else [find_binary(build, "beam_solver")]
    if has_solid:
        solid_exe = (
            command_arg("--solid-cmd", args.solid_cmd)
            if args.solid_cmd
            else mpirun + [find_binary(build, "solid_solver")]
        )
    if has_stent and has_solid:
        coupler_exe = [find_binary(build, "coupler")]

    # Each executable reads the keys of its sections; asking them (--check) before the run directory
    # exists means a bad key anywhere leaves nothing behind. Replaced commands (--beam-cmd,
    # --solid-cmd) may not know --check and are not asked.
    check_path = scene_path if prepared is None else scratch_scene(prepared)
    checks = [
        ("beam_solver", beam_exe if has_stent and not args.beam_cmd else None),
        ("solid_solver", [find_binary(build, "solid_solver")] if has_solid and not args.solid_cmd else None),
        ("coupler", coupler_exe),
    ]
    for name, exe in checks:
        if exe:
            check_scene_with(name, exe, check_path)
    if args.check:
        asked = [name for name, exe in checks if exe]
        print(f"launch: {scene_path}: the scene is valid ({', '.join(asked) or 'no executable'} asked)")
        return 0

    token = uuid.uuid4().hex[:12]
    run_id = args.run_id or token
    # The token makes the default name unique for launches of one scene in the same second (with a
    # random run id it is the run id).
    stamp = time.strftime("%Y%m%d-%H%M%S")
    run_dir = Path(args.run_dir or ROOT / "runs" / f"{scene_path.stem}-{stamp}-{token}").resolve()
    make_run_dir(run_dir, explicit=args.run_dir is not None)
    lock = lock_run_dir(run_dir)  # noqa: F841 (the flock lasts as long as this open file, i.e. until main returns)
    solver_scene = scene_path
    try:
        if prepared is None:
            (run_dir / "scene.yaml").write_bytes(scene_text)  # the text that was checked
        else:
            (run_dir / "scene.input.yaml").write_bytes(scene_text)
            solver_scene = install_prepared(prepared, run_dir)
    except OSError as e:
        die(f"{run_dir}: cannot write the scene: {e.strerror}")
    plan = process_plan(run_dir, run_id, args, (beam_exe, solid_exe, coupler_exe), solver_scene)
    print(f"launch: run directory {run_dir}")
    via = f" ({ranks} rank{'s' if ranks > 1 else ''} via {mpirun[0]})" if has_solid and not args.solid_cmd else ""
    print("launch: processes: " + ", ".join(name + (via if name == "solid_solver" else "") for name, _ in plan))
    return supervise(plan, run_dir, args)


if __name__ == "__main__":
    # Bad input exits 2 through die() (SystemExit passes through here); anything else is a bug of the
    # launcher: one line instead of a traceback. Children still running get SIGTERM from the kernel
    # as the launcher exits (die_with_launcher).
    try:
        code = main()
    except KeyboardInterrupt:  # Ctrl-C before the handler forwarding it is installed
        print("launch: interrupted", file=sys.stderr)
        code = 130
    except Exception as e:
        print(f"launch: internal error: {type(e).__name__}: {' '.join(str(e).split())}", file=sys.stderr)
        code = 1
    sys.exit(code)
