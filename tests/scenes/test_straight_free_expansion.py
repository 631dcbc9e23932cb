#!/usr/bin/python3
"""The default scene of the README run command, run whole: configs/straight_free_expansion.yaml.

Published benchmark (paper §3.1; docs/validation.md, Paper comparison): the stent's mean diameter at
13 atm (≈2.59 mm) and after deflation (2.31 mm), and the elastic recoil (0.28 mm); accepted within 2 % for the
diameters and 10 % for the recoil, the precision to which the paper's figures state them.
Consistency: the run reaches its end (t = 2.2 s: deflated at 2 s, then held) with every step committed
(adaptive steps: at most the 110 nominal ones, no cut), and the balloon (elastic) returns to its initial
outer diameter 0.98 mm at zero pressure. The stent's dogboning, (D_distal - D_central)/D_distal, peaks at 20.4 % at
10.4 atm in the paper: accepted within 10 % of its value (a ratio of diameter differences, read at
load steps 0.26 atm apart), and its peak must lie in the lock-up (8-12 atm), not in the balloon's
unfolding plateau (5-7 atm), where it sat with end springs 1000x too stiff (7.3 % at 6.2 atm).
"""
import json
import subprocess
import sys
import tempfile
from pathlib import Path

BIN = Path(sys.argv[1])
ROOT = Path(__file__).resolve().parents[2]
SCENE = ROOT / "configs" / "straight_free_expansion.yaml"
sys.path.insert(0, str(Path(__file__).resolve().parent))
from checklist import check, failures  # noqa: E402


def near(value, reference, rel):
    return abs(value - reference) <= rel * abs(reference)


with tempfile.TemporaryDirectory() as tmp:
    run_dir = Path(tmp) / "run"
    r = subprocess.run(
        [
            sys.executable,
            str(ROOT / "scripts" / "launch.py"),
            str(SCENE),
            "--run-dir",
            str(run_dir),
            "--build-dir",
            str(BIN.parent),
        ],
        capture_output=True,
        text=True,
        timeout=2300,
    )
    print(r.stdout[-3000:])
    check(r.returncode == 0, f"launch exits 0 (got {r.returncode})\n{r.stderr[-2000:]}")
    if r.returncode == 0:
        coupling = json.loads((run_dir / "coupling_summary.json").read_text())
        check(
            coupling["status"] == "ok" and coupling["steps"] <= 110 and coupling["rejected_attempts"] == 0,
            f"at most the 110 nominal steps, none cut ({coupling['steps']}, {coupling['rejected_attempts']} cut)",
        )
        d = json.loads((run_dir / "beam" / "summary.json").read_text())["diameter"]
        check(near(d["max"], 2.59, 0.02), f"stent diameter at 13 atm {d['max']:.4f} mm vs paper 2.59 (2 %)")
        check(near(d["final"], 2.31, 0.02), f"stent diameter after deflation {d['final']:.4f} mm vs paper 2.31 (2 %)")
        check(near(d["recoil"], 0.28, 0.10), f"elastic recoil {d['recoil']:.4f} mm vs paper 0.28 (10 %)")
        st = json.loads((run_dir / "beam" / "summary.json").read_text())["stent"]
        dog = st["dogboning_max_percent"]
        check(near(dog, 20.4, 0.10), f"stent dogboning max {dog:.2f} % vs paper 20.4 % (10 %)")
        t_dog = st["time_of_dogboning_max"]
        p_dog = 13.0 * min(t_dog, 2.0 - t_dog)  # the pressure curve: 0 -> 13 atm at t = 1 s -> 0 at 2 s
        check(8.0 <= p_dog <= 12.0, f"stent dogboning peaks at {p_dog:.2f} atm, in the lock-up (8-12 atm; paper 10.4)")
        last = json.loads((run_dir / "solid" / "summary.json").read_text())["steps"][-1]
        check(abs(last["time"] - 2.2) < 1e-9, f"the last committed step is at t = 2.2 s ({last['time']})")
        mid = last["balloon_outer_diameter"]["mid"]
        check(near(mid, 0.98, 1e-3), f"balloon outer diameter after deflation {mid:.5f} mm vs initial 0.98")

sys.exit(1 if failures else 0)
