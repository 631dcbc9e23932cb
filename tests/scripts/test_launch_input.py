#!/usr/bin/python3
"""Consistency/robustness test of scripts/launch.py: bad input and faults (docs/reliability.md).

Checks that the launcher
- refuses bad input with exit code 2 and one line `launch: error: <file>: <key path>: expected ...,
  got ...` on stderr, never a Python traceback, and leaves no run directory behind: unreadable
  scene files (directory, binary, permission, empty, YAML syntax, not a map), keys given twice
  anywhere in the YAML (both line numbers), unknown top-level sections (with "did you mean"),
  solid.ranks and --ranks outside 1..256 (bool included), bad --run-id, --timeout, --solid-cmd,
  --run-dir;
- reports an unexpected exception as one `launch: internal error:` line with exit code 1;
- runs a valid minimal scene with a fake participant, in an owner-only (0700) run directory,
  and keeps draining a participant's output that is not UTF-8;
- refuses a run directory another launch (or a running coupler) uses, and reuses it afterwards;
- gives two launches of one scene in the same second distinct default run directories;
- leaves no orphan when it is killed with SIGKILL (the child gets SIGTERM from the kernel).

No solver is built or run: the participants are fake commands (python -c / true), which ignore the
launcher's arguments. Each case takes about a second or less; the whole file about 20 s.
Usage: test_launch_input.py
"""
import fcntl
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest
import uuid
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
LAUNCH = [sys.executable, str(ROOT / "scripts" / "launch.py")]
PY = sys.executable
SOLID_ONLY = "time: {end: 1.0, steps: 2}\nballoon: {}\n"
TRUE = shutil.which("true") or "/bin/true"


def fake(seconds, *extra):
    """A fake participant that sleeps; python -c ignores the launcher's arguments after the code."""
    return " ".join([PY, "-c", f"'import time; time.sleep({seconds})'", *extra])


class Case(unittest.TestCase):
    def setUp(self):
        self.tmp = Path(tempfile.mkdtemp(prefix="launch_input_"))
        self.build = self.tmp / "no_build"  # no binaries: the launcher must not need any here

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def scene(self, text, name="scene.yaml"):
        p = self.tmp / name
        p.write_bytes(text if isinstance(text, bytes) else text.encode())
        return p

    def launch(self, scene, *args, run_dir="default", timeout=20):
        rd = [] if run_dir is None else ["--run-dir", str(self.tmp / "run" if run_dir == "default" else run_dir)]
        return subprocess.run(
            LAUNCH + [str(scene), "--build-dir", str(self.build), *rd, *args],
            capture_output=True,
            text=True,
            timeout=timeout,
        )

    def assert_refused(self, r, *expected, code=2):
        msg = f"\nexit {r.returncode}\nstdout: {r.stdout}\nstderr: {r.stderr}"
        self.assertEqual(r.returncode, code, msg)
        self.assertNotIn("Traceback", r.stderr + r.stdout, msg)
        for s in expected:
            self.assertIn(s, r.stderr, msg)
        self.assertFalse((self.tmp / "run").exists(), "bad input must leave no run directory" + msg)


class SceneFile(Case):
    """Files that are no scene: the message names the file."""

    TABLE = [  # name, scene text (None: made by setup), expected substrings
        ("empty", "", ["expected a YAML map of sections, got an empty document"]),
        ("comments only", "# nothing\n", ["got an empty document"]),
        ("binary", b"\x7fELF\x02\x01\x01\x00\xff\xfe\x00", ["expected a YAML text file (UTF-8), got byte 0xff"]),
        ("NUL in text", "time: {end: 1}\x00\n", ["expected valid YAML", "unacceptable character"]),
        ("syntax error", "time: {end: 1\nballoon: {}\n", ["line 2", "expected valid YAML, got a syntax error"]),
        ("bad indentation", "balloon:\n  a: 1\n b: 2\n", ["expected valid YAML, got a syntax error"]),
        ("two documents", "balloon: {}\n---\nstent: {}\n", ["expected a single document"]),
        ("top-level list", "- balloon\n- stent\n", ["expected a YAML map of sections at the top level, got a list"]),
        ("top-level scalar", "balloon\n", ["at the top level, got a str"]),
        ("nested too deeply", "balloon: " + "[" * 5000 + "\n", ["nested too deeply"]),
        (
            "nothing to simulate",
            "time: {end: 1}\nsolid: {ranks: 1}\n",
            ["expected at least one of 'stent', 'balloon', 'artery'"],
        ),
    ]

    def test_table(self):
        for name, text, expected in self.TABLE:
            with self.subTest(name):
                p = self.scene(text)
                self.assert_refused(self.launch(p), f"launch: error: {p}: ", *expected)

    def test_missing(self):
        p = self.tmp / "missing.yaml"
        self.assert_refused(self.launch(p), f"{p}: no such scene file")

    def test_directory(self):
        self.assert_refused(self.launch(self.tmp), f"{self.tmp}: expected a scene file (YAML), got a directory")

    def test_fifo(self):  # would block a reader forever
        p = self.tmp / "fifo.yaml"
        os.mkfifo(p)
        self.assert_refused(self.launch(p), f"{p}: expected a scene file (YAML), got not a regular file")

    def test_unreadable(self):
        if os.geteuid() != 0:
            p = self.scene(SOLID_ONLY)
            p.chmod(0)
        else:  # root reads any file; a write-only sysctl is unreadable even for root
            p = Path("/proc/sys/vm/compact_memory")
            try:
                open(p).close()
                self.skipTest("running as root without an unreadable file to try")
            except PermissionError:
                pass
            except OSError:
                self.skipTest("running as root without an unreadable file to try")
        self.assert_refused(self.launch(p), f"{p}: cannot read the scene file: Permission denied")


class DuplicateKeys(Case):
    TABLE = [  # name, scene text, key path, line numbers
        ("top-level section", "time: {end: 1}\nballoon: {}\ntime: {end: 2}\n", "time", "lines 1 and 3"),
        (
            "in stent.material",
            "time: {end: 1}\nballoon: {}\nstent:\n  material:\n    E: 380000\n    nu: 0.3\n    E: 200000\n",
            "stent.material.E",
            "lines 5 and 7",
        ),
        ("in a flow map", "balloon: {pressure: 1, pressure: 2}\n", "balloon.pressure", "line 1"),
        (
            "in a list item",
            "stent:\n  lines:\n    - {from: 1, to: 2}\n    - from: 3\n      from: 4\n",
            "stent.lines[1].from",
            "lines 4 and 5",
        ),
        ("quoted and plain", "balloon: {}\n'time': {end: 1}\ntime: {end: 2}\n", "time", "lines 2 and 3"),
    ]

    def test_table(self):
        for name, text, key, lines in self.TABLE:
            with self.subTest(name):
                p = self.scene(text)
                self.assert_refused(
                    self.launch(p), f"{p}: {key}: expected each key once in a map, got it twice ({lines})"
                )

    def test_merge_key_is_not_a_duplicate(self):
        # `<<: *defaults` followed by an override is YAML's merge, not a key given twice
        p = self.scene("time: &t {end: 1.0, steps: 2}\nballoon: {}\noutput: {<<: *t, every: 1, end: 2.0}\n")
        r = self.launch(p, "--solid-cmd", TRUE)
        self.assertEqual(r.returncode, 0, r.stderr)


class Sections(Case):
    def test_did_you_mean(self):
        for typo, meant in (("stnet", "stent"), ("couplng", "coupling"), ("outptu", "output"), ("ballon", "balloon")):
            with self.subTest(typo):
                p = self.scene(f"time: {{end: 1}}\nballoon: {{}}\n{typo}: {{}}\n")
                self.assert_refused(
                    self.launch(p),
                    f"{p}: {typo}: expected a top-level section",
                    f"got an unknown key; did you mean `{meant}`?",
                )

    def test_unknown_without_hint(self):
        p = self.scene("balloon: {}\nzzzz: 1\n")
        r = self.launch(p)
        self.assert_refused(r, f"{p}: zzzz: expected a top-level section", "got an unknown key")
        self.assertNotIn("did you mean", r.stderr)


class Ranks(Case):
    def test_scene(self):
        for value in ("true", "false", "0", "-1", "257", "2.5", "'2'", "[2]", "null"):
            with self.subTest(value):
                p = self.scene(f"balloon: {{}}\nsolid: {{ranks: {value}}}\n")
                self.assert_refused(self.launch(p), f"{p}: solid.ranks: expected an integer in 1..256, got")

    def test_solid_not_a_map(self):
        p = self.scene("balloon: {}\nsolid: 3\n")
        self.assert_refused(self.launch(p), f"{p}: solid: expected a map, got 3")

    def test_option(self):
        p = self.scene(SOLID_ONLY)
        for value in ("0", "-2", "257", "1.5", "two", "true"):
            with self.subTest(value):
                self.assert_refused(
                    self.launch(p, "--ranks", value), "argument --ranks: expected an integer in 1..256, got"
                )


class Options(Case):
    def test_table(self):
        p = self.scene(SOLID_ONLY)
        for args, expected in (
            (["--run-id", "a/b"], "--run-id: expected 1 to 64 of"),
            (["--run-id", "*"], "--run-id: expected"),
            (["--run-id", ""], "--run-id: expected"),
            (["--timeout", "0"], "--timeout: expected a positive number of seconds, got 0.0"),
            (["--timeout", "nan"], "--timeout: expected a positive number"),
            (["--timeout", "inf"], "--timeout: expected a positive number"),
            (["--solid-cmd", "python3 -c 'unterminated"], "--solid-cmd: expected a command line"),
            (["--solid-cmd", " "], "--solid-cmd: expected a command line, got an empty one"),
        ):
            with self.subTest(args):
                self.assert_refused(self.launch(p, *args), f"launch: error: {expected}")

    def test_run_dir_is_a_file(self):
        p = self.scene(SOLID_ONLY)
        f = self.tmp / "afile"
        f.write_text("x")
        r = self.launch(p, "--solid-cmd", TRUE, run_dir=f)
        self.assert_refused(r, f"{f}: expected a run directory, got an existing file")

    def test_internal_error_is_one_line(self):
        # any exception that is no bad input: one line, exit 1 (uuid4 made to fail before the run)
        p = self.scene(SOLID_ONLY)
        code = (
            "import runpy, sys, uuid\n"
            "def boom(): raise RuntimeError('boom\\nsecond line')\n"
            "uuid.uuid4 = boom\n"
            f"sys.argv = {[LAUNCH[1], str(p), '--solid-cmd', TRUE, '--run-dir', str(self.tmp / 'run')]!r}\n"
            f"runpy.run_path({LAUNCH[1]!r}, run_name='__main__')\n"
        )
        r = subprocess.run([PY, "-c", code], capture_output=True, text=True, timeout=20)
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertEqual(r.stderr, "launch: internal error: RuntimeError: boom second line\n")
        self.assertFalse((self.tmp / "run").exists())


class Runs(Case):
    def test_valid_minimal_scene(self):
        p = self.scene(SOLID_ONLY)
        r = self.launch(p, "--solid-cmd", fake(0.2))
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        self.assertIn(f"launch: run directory {self.tmp / 'run'}", r.stdout)
        self.assertIn("launch: processes: solid_solver", r.stdout)
        self.assertEqual((self.tmp / "run").stat().st_mode & 0o777, 0o700, "run directory owner-only")
        self.assertEqual((self.tmp / "run" / "scene.yaml").read_text(), SOLID_ONLY)

    def test_output_not_utf8(self):
        # more than a pipe buffer of lines that are not UTF-8: the launcher keeps draining the pipe
        # (a pump thread dying on a decode error would leave the solver blocked on its output)
        p = self.scene(SOLID_ONLY)
        code = "import sys; sys.stdout.buffer.write(b'\\xff not utf-8\\n' * 20000)"
        r = self.launch(p, "--solid-cmd", shlex.join([PY, "-c", code]))
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertNotIn("Traceback", r.stderr)
        log = (self.tmp / "run" / "solid_solver.log").read_text()
        self.assertEqual(log.count("\ufffd not utf-8\n"), 20000)

    def wait_for(self, cond, timeout=5.0, what=""):
        deadline = time.time() + timeout
        while not cond():
            if time.time() > deadline:
                self.fail(f"timed out waiting for {what}")
            time.sleep(0.05)

    def test_run_dir_in_use(self):
        p = self.scene(SOLID_ONLY)
        run = self.tmp / "shared"
        first = subprocess.Popen(
            LAUNCH + [str(p), "--run-dir", str(run), "--solid-cmd", fake(3)],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        try:
            self.wait_for(lambda: (run / "solid_solver.log").exists(), what="the first launch's solid")
            r = self.launch(p, "--solid-cmd", TRUE, run_dir=run)
            self.assertEqual(r.returncode, 2, r.stdout + r.stderr)
            self.assertIn(
                f"launch: error: {run}: expected a free run directory, got one in use by another "
                f"launch (pid {first.pid})",
                r.stderr,
            )
            self.assertNotIn("Traceback", r.stderr)
            out, err = first.communicate(timeout=20)
            self.assertEqual(first.returncode, 0, out + err)
        finally:
            if first.poll() is None:
                first.kill()
                first.wait()
        # the lock went with the first launcher: the directory is usable again
        r = self.launch(p, "--solid-cmd", TRUE, run_dir=run)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)

    def test_run_dir_with_running_coupler(self):
        # a coupler not started by this launcher holds zenoh's lock file of its socket
        p = self.scene(SOLID_ONLY)
        run = self.tmp / "coupled"
        run.mkdir()
        with open(run / "coupler.sock.lock", "w") as z:
            fcntl.flock(z, fcntl.LOCK_EX | fcntl.LOCK_NB)
            r = self.launch(p, "--solid-cmd", TRUE, run_dir=run)
        self.assertEqual(r.returncode, 2, r.stdout + r.stderr)
        self.assertIn("a running coupler holds coupler.sock.lock", r.stderr)

    def test_default_run_dirs_distinct(self):
        stem = f"launch-input-{uuid.uuid4().hex[:8]}"
        p = self.scene(SOLID_ONLY, name=f"{stem}.yaml")
        runs = ROOT / "runs"
        had_runs = runs.exists()
        cmd = LAUNCH + [str(p), "--build-dir", str(self.build), "--solid-cmd", TRUE]
        procs = [subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) for _ in range(2)]
        try:
            outs = [pr.communicate(timeout=20) for pr in procs]
            dirs = [m.group(1) for out, _ in outs for m in re.finditer(r"^launch: run directory (.+)$", out, re.M)]
            self.assertEqual(len(dirs), 2, outs)
            self.assertNotEqual(dirs[0], dirs[1])
            for d in dirs:
                self.assertRegex(d, rf"^{re.escape(str(runs))}/{stem}-\d{{8}}-\d{{6}}-[0-9a-f]{{12}}$")
            self.assertEqual([pr.returncode for pr in procs], [0, 0], outs)
        finally:
            for d in runs.glob(f"{stem}-*"):
                shutil.rmtree(d, ignore_errors=True)
            if not had_runs:
                try:
                    runs.rmdir()
                except OSError:
                    pass

    def test_no_orphan_after_sigkill(self):
        p = self.scene(SOLID_ONLY)
        marker = f"orphan-marker-{uuid.uuid4().hex}"
        launcher = subprocess.Popen(
            LAUNCH + [str(p), "--run-dir", str(self.tmp / "run"), "--solid-cmd", fake(60, marker)],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        child = None
        try:

            def find_child():
                # the marker is one argument of the fake only (the launcher has it inside --solid-cmd)
                nonlocal child
                for d in Path("/proc").iterdir():
                    try:
                        if d.name.isdigit() and marker.encode() in (d / "cmdline").read_bytes().split(b"\0"):
                            child = int(d.name)
                            return True
                    except OSError:  # the process ended meanwhile
                        pass
                return False

            self.wait_for(find_child, what="the fake solid to start")
            self.assertTrue(alive(child), "the fake solid runs until the launcher is killed")
            launcher.kill()  # SIGKILL: no handler of the launcher runs
            launcher.wait()
            self.wait_for(
                lambda: not alive(child), what=f"the fake solid (pid {child}) to end after the launcher's SIGKILL"
            )
        finally:
            if launcher.poll() is None:
                launcher.kill()
                launcher.wait()
            if child and alive(child):
                os.kill(child, signal.SIGKILL)


def alive(pid):
    """True while pid runs; a zombie (ended, not yet reaped by init in a container) counts as gone."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except (OSError, IndexError):
        return False


if __name__ == "__main__":
    unittest.main(verbosity=2)
