#!/usr/bin/env python3
"""Wall time per Newton iteration of solid_solver for a scene, ranks and PETSc solver options.

  bench/bench_solid.py --exe build-solid/bin/solid_solver --scene configs/solid_artery_blood_pressure.yaml \
      --ranks 1 2 --steps 2

Runs the scene with `time.steps` and `time.end` scaled to the given number of steps and each solver
option string, reads <run>/solid/summary.json and prints seconds per Newton iteration (total step
wall time incl. assembly and output / Newton iterations).
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time

SOLVERS = {
    "gmres+bjacobi-ilu1": "-ksp_type gmres -ksp_gmres_restart 200 -pc_type bjacobi -sub_pc_type ilu "
    "-sub_pc_factor_levels 1",
    "mumps-lu": "-ksp_type preonly -pc_type lu -pc_factor_mat_solver_type mumps",
    "gmres+gamg": "-ksp_type gmres -ksp_gmres_restart 200 -pc_type gamg -pc_gamg_threshold 0.01",
    "gmres+hypre": "-ksp_type gmres -ksp_gmres_restart 200 -pc_type hypre -pc_hypre_type boomeramg",
}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--exe", required=True)
    ap.add_argument("--scene", required=True)
    ap.add_argument("--ranks", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--steps", type=int, default=2, help="load steps to run (of the scene's time.steps)")
    ap.add_argument("--solvers", nargs="+", default=["gmres+bjacobi-ilu1", "mumps-lu"])
    a = ap.parse_args()
    text = open(a.scene).read()
    m = re.search(r"time:\s*\{end:\s*([0-9.eE+-]+),\s*steps:\s*(\d+)\}", text)
    if not m:
        sys.exit("scene needs a one-line 'time: {end: E, steps: N}'")
    end, steps = float(m.group(1)), int(m.group(2))
    new_end = end * a.steps / steps
    text = text.replace(m.group(0), f"time: {{end: {new_end}, steps: {a.steps}}}")
    if not re.search(r"petsc_options:", text):
        sys.exit("scene needs a 'petsc_options:' line (solid section) for the solver options to vary")
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    print(f"{'ranks':>5} {'solver':<22} {'newton its':>10} {'s/iteration':>12} {'total s':>8}")
    for ranks in a.ranks:
        for name in a.solvers:
            opts = SOLVERS.get(name, name)
            t = re.sub(r"petsc_options:.*", f'petsc_options: "{opts}"', text)
            with tempfile.TemporaryDirectory() as d:
                scene = os.path.join(os.path.dirname(os.path.abspath(a.scene)), f".bench_{os.getpid()}.yaml")
                open(scene, "w").write(t)
                try:
                    t0 = time.time()
                    r = subprocess.run(
                        [
                            "mpirun",
                            "--allow-run-as-root",
                            "--oversubscribe",
                            "-n",
                            str(ranks),
                            a.exe,
                            "--scene",
                            scene,
                            "--run-dir",
                            d,
                        ],
                        env=env,
                        capture_output=True,
                        text=True,
                    )
                    wall = time.time() - t0
                finally:
                    os.remove(scene)
                if r.returncode != 0:
                    print(f"{ranks:>5} {name:<22} FAILED ({r.returncode}): {r.stderr[-300:]}")
                    continue
                s = json.load(open(os.path.join(d, "solid", "summary.json")))["steps"][1:]
                its = sum(x["newton_iterations"] for x in s)
                sec = sum(x["wall_seconds"] for x in s)
                print(f"{ranks:>5} {name:<22} {its:>10} {sec / max(its, 1):>12.3f} {wall:>8.1f}")


if __name__ == "__main__":
    main()
