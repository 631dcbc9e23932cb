"""The check list of the scene test scripts: `check(cond, msg)` prints ok/FAIL per check and
`finish()` exits 1 if any failed (every check runs, so one report shows all that is wrong)."""
import sys

failures = []


def check(cond, msg):
    print(("ok   " if cond else "FAIL ") + msg, flush=True)
    if not cond:
        failures.append(msg)


def finish():
    print("FAILED: " + "; ".join(failures) if failures else "all passed")
    sys.exit(1 if failures else 0)
