#!/usr/bin/python3
"""The real solid_solver runs the small balloon-in-artery scene (contact: section, no stent) on 2
MPI ranks from one command, and the balloon ends in active contact with the artery (consistency:
the balloon's free inflation at the final pressure would cross the endothelium).

  test_balloon_in_artery_run.py <bin-dir> <scene.yaml>
"""
import os
import re
import subprocess
import sys
import tempfile

bin_dir, scene = sys.argv[1], sys.argv[2]
mpirun = ["mpirun", "-n", "2", "--oversubscribe", "--bind-to", "none"] + (
    ["--allow-run-as-root"] if os.geteuid() == 0 else []
)
with tempfile.TemporaryDirectory() as tmp:
    r = subprocess.run(
        mpirun + [os.path.join(bin_dir, "solid_solver"), "--scene", scene, "--run-dir", tmp],
        capture_output=True,
        text=True,
        timeout=280,
    )
    print(r.stdout[-3000:])
    print(r.stderr[-3000:], file=sys.stderr)
    if r.returncode != 0:
        sys.exit(f"solid_solver exited with {r.returncode}")
    active = [int(m.group(1)) for m in re.finditer(r"balloon-artery: (\d+)/\d+ Gauss points active", r.stdout)]
    if not active or active[-1] <= 0:
        sys.exit(f"no active balloon-artery contact at the end (active counts per solve: {active})")
    if not os.path.isfile(os.path.join(tmp, "solid", "summary.json")):
        sys.exit("solid/summary.json missing")
print("ok: balloon ends in contact with the artery")
