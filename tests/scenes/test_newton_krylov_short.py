#!/usr/bin/python3
"""The interface Newton-Krylov through the processes (docs/design.md 5.5): the default scene
configs/straight_free_expansion.yaml to t = 0.5 s (the balloon unfolds onto the stent and expands
it), once with IQN-IMVJ (4 carried steps) and once with `coupling.acceleration: newton-krylov`, whose products
ask the beam and the solid for their linearized responses (BeamLinearRequest, SolidLinearRequest).
Consistency: both converge every step to the same coupling tolerance, so the stent's diameter at
0.5 s agrees to within what that tolerance allows (rel_tol 1e-3 of the contact loads; the two runs of
2026-12-02 differ by 2.5e-5 mm at 1.45 mm, bound 1e-3 mm), and the Newton-Krylov run did ask for
products (its coupler log names them) and needed no more coupling iterations than IQN-IMVJ.
Usage: test_newton_krylov_short.py BIN_DIR
"""
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import yaml

BIN = Path(sys.argv[1])
ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(Path(__file__).resolve().parent))
from checklist import check, failures  # noqa: E402


def run(tmp, name, coupling):
    scene = yaml.safe_load((ROOT / "configs" / "straight_free_expansion.yaml").read_text())
    scene["time"]["end"] = 0.5
    scene["time"]["steps"] = 25
    scene["coupling"].update(coupling)
    scene["coupling"] = {k: v for k, v in scene["coupling"].items() if v is not None}
    path = Path(tmp) / f"{name}.yaml"
    path.write_text(yaml.safe_dump(scene))
    run_dir = Path(tmp) / name
    r = subprocess.run(
        [
            sys.executable,
            str(ROOT / "scripts" / "launch.py"),
            str(path),
            "--run-dir",
            str(run_dir),
            "--build-dir",
            str(BIN.parent),
            "--log-level",
            "debug",
        ],
        capture_output=True,
        text=True,
        timeout=900,
    )
    check(r.returncode == 0, f"{name}: launch exits 0 (got {r.returncode})\n{r.stdout[-1500:]}\n{r.stderr[-1500:]}")
    if r.returncode != 0:
        return None
    summary = json.loads((run_dir / "coupling_summary.json").read_text())
    beam = json.loads((run_dir / "beam" / "summary.json").read_text())
    solid = json.loads((run_dir / "solid" / "summary.json").read_text())
    # the solid times every product it answers: its count is the coupler's
    summary["solid_products"] = solid["timing"]["interface_products"]
    summary["solid_product_seconds"] = solid["timing"]["interface_product_seconds"]
    log = (run_dir / "coupler.log").read_text()
    return summary, beam["diameter"]["final"], log


with tempfile.TemporaryDirectory() as tmp:
    iqn = run(tmp, "iqn", {"acceleration": "iqn-imvj", "iqn": {"reused_steps": 4}})
    nk = run(tmp, "nk", {"acceleration": "newton-krylov", "iqn": None})
    if iqn and nk:
        (s_iqn, d_iqn, _), (s_nk, d_nk, log_nk) = iqn, nk
        print(
            f"IQN-IMVJ {s_iqn['coupling_iterations_total']} coupling iterations, D = {d_iqn:.6f} mm; "
            f"Newton-Krylov {s_nk['coupling_iterations_total']}, D = {d_nk:.6f} mm"
        )
        check(
            s_nk["status"] == "ok" and s_nk["rejected_attempts"] == 0, f"newton-krylov: every step committed ({s_nk})"
        )
        check(
            s_nk["jacobian_products"] > 0 and "products, linear residual" in log_nk,
            f"newton-krylov asked the participants for products ({s_nk['jacobian_products']})",
        )
        check(s_iqn["jacobian_products"] == 0, "IQN-IMVJ asked for none")
        check(
            s_nk["solid_products"] == s_nk["jacobian_products"] and s_iqn["solid_products"] == 0,
            f"the solid counted the products it answered ({s_nk['solid_products']}, {s_iqn['solid_products']})",
        )
        check(
            0.0 < s_nk["solid_product_seconds"] <= s_nk["product_time"],
            f"the solid's product time is part of the coupler's ({s_nk['solid_product_seconds']} s of "
            f"{s_nk['product_time']} s)",
        )
        check(abs(d_nk - d_iqn) <= 1e-3, f"stent diameter at 0.5 s: {d_nk:.6f} vs {d_iqn:.6f} mm (within 1e-3 mm)")
        its_nk, its_iqn = s_nk["coupling_iterations_total"], s_iqn["coupling_iterations_total"]
        check(its_nk <= its_iqn, f"coupling iterations {its_nk} <= IQN-IMVJ's {its_iqn}")
sys.exit(1 if failures else 0)
