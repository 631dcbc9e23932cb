#!/usr/bin/env python3
"""Benchmark of the beam solver: wall time per Newton iteration for the generated stent.

Writes a beam-only scene for an N-ring stent (default 11 rings = 588 elements) expanded by the
radial line load of configs/beam_stent_radial_expansion.yaml up to t = 0.5 (plastic range),
runs beam_solver once per linear solver and prints the Newton time per iteration from
summary.json (assembly with exact tangent + sparse factorization + solve).

Usage: bench/bench_beam.py [--exe build-beam/bin/beam_solver] [--rings 11] [--steps 20]
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

SCENE = """time: {{end: 0.5, steps: {steps}}}
load_curves:
  expansion: [[0.0, 0.0], [1.0, 1.0], [2.0, 0.0]]
output: {{every: 1000}}
stent:
  material: {{E: 380000.0, nu: 0.3}}
  section: {{radius: 0.06}}
  plasticity: {{yield_moment: 0.08, tangent_modulus: 64000.0}}
  generator: {{type: corrugated_rings, rings: {rings}}}
  fixation: {{radial: auto}}
  loads:
    - {{type: radial_line, magnitude: 0.237, curve: expansion}}
  solver: {{linear_solver: {solver}, max_iterations: 40, residual_tol: 1.0e-9}}
"""


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--exe", default=os.path.join(os.path.dirname(__file__), "..", "build-beam", "bin", "beam_solver"))
    ap.add_argument("--rings", type=int, default=11)
    ap.add_argument("--steps", type=int, default=20)
    ap.add_argument("--solvers", default="klu,umfpack,sparselu")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        for solver in a.solvers.split(","):
            scene = os.path.join(tmp, f"bench_{solver}.yaml")
            with open(scene, "w") as f:
                f.write(SCENE.format(steps=a.steps, rings=a.rings, solver=solver))
            run = os.path.join(tmp, f"run_{solver}")
            r = subprocess.run(
                [a.exe, "--scene", scene, "--run-dir", run, "--log-level", "warn"], capture_output=True, text=True
            )
            if r.returncode != 0:
                print(r.stdout, r.stderr, file=sys.stderr)
                sys.exit(f"beam_solver failed with {solver}")
            s = json.load(open(os.path.join(run, "beam", "summary.json")))
            print(
                f"{solver:9s} elements {s['num_elements']:5d}  iterations {s['newton_iterations_total']:4d}  "
                f"{1e3 * s['seconds_per_newton_iteration']:7.2f} ms/iteration  "
                f"D(t=0.5) = {s['diameter']['final']:.4f} mm"
            )


if __name__ == "__main__":
    main()
