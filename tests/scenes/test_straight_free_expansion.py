#!/usr/bin/python3
"""The default scene of the README run command, run whole: configs/straight_free_expansion.yaml.

Published benchmark (paper §3.1, DESIGN §4): the stent's mean diameter at 13 atm (≈2.59 mm) and
after deflation (2.31 mm), and the elastic recoil (0.28 mm); accepted within 2 % for the
diameters and 10 % for the recoil, the precision to which the paper's figures state them.
Consistency: the run reaches t = 2 s with every step committed (adaptive steps: at most the 100
nominal ones, no cut), and the balloon (elastic) returns to its initial outer diameter 0.98 mm at
zero pressure. The dogboning is not asserted: ours differs
from the paper's (README "Results").
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
    r = subprocess.run([sys.executable, str(ROOT / "scripts" / "launch.py"), str(SCENE), "--run-dir", str(run_dir),
                        "--build-dir", str(BIN.parent)], capture_output=True, text=True, timeout=2300)
    print(r.stdout[-3000:])
    check(r.returncode == 0, f"launch exits 0 (got {r.returncode})\n{r.stderr[-2000:]}")
    if r.returncode == 0:
        coupling = json.loads((run_dir / "coupling_summary.json").read_text())
        check(coupling["status"] == "ok" and coupling["steps"] <= 100 and coupling["rejected_attempts"] == 0,
              f"at most the 100 nominal steps, none cut ({coupling['steps']}, {coupling['rejected_attempts']} cut)")
        d = json.loads((run_dir / "beam" / "summary.json").read_text())["diameter"]
        check(near(d["max"], 2.59, 0.02), f"stent diameter at 13 atm {d['max']:.4f} mm vs paper 2.59 (2 %)")
        check(near(d["final"], 2.31, 0.02), f"stent diameter after deflation {d['final']:.4f} mm vs paper 2.31 (2 %)")
        check(near(d["recoil"], 0.28, 0.10), f"elastic recoil {d['recoil']:.4f} mm vs paper 0.28 (10 %)")
        last = json.loads((run_dir / "solid" / "summary.json").read_text())["steps"][-1]
        check(abs(last["time"] - 2.0) < 1e-9, f"the last committed step is at t = 2 s ({last['time']})")
        mid = last["balloon_outer_diameter"]["mid"]
        check(near(mid, 0.98, 1e-3), f"balloon outer diameter after deflation {mid:.5f} mm vs initial 0.98")

sys.exit(1 if failures else 0)
