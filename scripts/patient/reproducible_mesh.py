"""build_artery (artery_mesh.py) in a child process whose memory layout is the same on every run, so
that a scene meshes to the same file every time it is launched.

Why: gmsh 4.8 keeps some of its containers ordered by memory address. With the kernel's address
space randomization the same geometry and options mesh differently from run to run. Measured on
configs/patient_like.yaml, launches a minute apart on one machine: the same 6,398 tet10, but 9,265
of the 9,986 nodes up to 0.031 mm apart, the minimal scaled Jacobian 0.204 or 0.062, and element
stresses up to 4 % apart. A fixed hash seed does not help; without address randomization
(util-linux's `setarch --addr-no-randomize`) the files were identical. So the child is started
through setarch, with a fixed hash seed and a fixed, minimal environment, and reads nothing that
names the run: what a process reads moves its heap too (two children given arguments of different
lengths meshed differently).

Whether two machines write the same file was not checked; validity does not depend on it
(artery_mesh.py checks and mends every mesh it writes).

The child reads its arguments from a pickle in its working folder, prints build_artery's log
lines, and writes the result or the exception it raised to a second pickle; the parent re-raises
that exception."""
import pickle
import platform
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

SCRIPTS = Path(__file__).resolve().parents[1]


def _fixed_layout_prefix(log):
    """The command prefix that starts a process without address randomization, or [] (with a
    warning) where the kernel or a container's seccomp profile does not allow it."""
    setarch = shutil.which("setarch")
    if setarch:
        prefix = [setarch, platform.machine(), "--addr-no-randomize"]
        probe = subprocess.run(prefix + ["true"], capture_output=True, text=True)
        if probe.returncode == 0:
            return prefix
        why = " ".join((probe.stderr or probe.stdout).split()) or f"exit code {probe.returncode}"
    else:
        why = "setarch (util-linux) not found"
    log(
        f"patient: warning: cannot start the mesher without address randomization ({why}); gmsh may "
        f"mesh this artery differently on the next run"
    )
    return []


def build_artery_reproducibly(points, radius, wall, spec, mesh_size, out_path, log=print, **kwargs):
    """build_artery(...) run in a child process with a fixed memory layout; the same return value
    (with `file` the path asked for) and the same exceptions."""
    with tempfile.TemporaryDirectory(prefix="artery-mesh-") as scratch:
        work = Path(scratch)
        # no argument, the mesh file's name relative to the working folder, whose random name the
        # child never sees (-P: not on sys.path)
        with open(work / "in.pickle", "wb") as f:
            pickle.dump(((points, radius, wall, spec, mesh_size, "artery.msh"), kwargs), f)
        # Every module compiled afresh (an empty bytecode cache, none written): a module loaded from
        # its .pyc allocates differently from one compiled, and whether a .pyc is there and current
        # depends on what ran before (measured: the launch after an edit meshed differently).
        env = {
            "PYTHONHASHSEED": "0",
            "PYTHONPATH": str(SCRIPTS),
            "PYTHONPYCACHEPREFIX": str(work / "bytecode"),
            "PYTHONDONTWRITEBYTECODE": "1",
            "OPENBLAS_NUM_THREADS": "1",
            "LC_ALL": "C",
        }
        cmd = _fixed_layout_prefix(log) + [sys.executable, "-P", "-m", "patient.reproducible_mesh"]
        # stderr to a file: a second pipe could fill while the log lines are read, and both block
        with open(work / "stderr.txt", "w+") as err:
            child = subprocess.Popen(cmd, env=env, cwd=work, stdout=subprocess.PIPE, stderr=err, text=True)
            for line in child.stdout:
                log(line.rstrip("\n"))
            child.wait()
            err.seek(0)
            stderr = err.read()
        if not (work / "out.pickle").exists():
            tail = " ".join(stderr.strip().splitlines()[-3:])[-500:] or "no message"
            raise RuntimeError(f"the artery mesher exited with code {child.returncode} ({tail})")
        with open(work / "out.pickle", "rb") as f:
            ok, value = pickle.load(f)
        if not ok:
            raise value
        shutil.move(work / "artery.msh", out_path)
    value["file"] = str(out_path)
    return value


def _child():
    from .artery_mesh import build_artery

    with open("in.pickle", "rb") as f:
        args, kwargs = pickle.load(f)
    try:
        result = (True, build_artery(*args, log=lambda m: print(m, flush=True), **kwargs))
    except Exception as e:  # handed to the parent, which raises it as build_artery would have
        result = (False, e)
    with open("out.pickle", "wb") as f:
        pickle.dump(result, f)


if __name__ == "__main__":
    _child()
