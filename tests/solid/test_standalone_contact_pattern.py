#!/usr/bin/python3
"""A solid run without a coupler has no stent line contact, so it reserves no stent-contact columns:
its matrix is the elements' (and the balloon-artery pairs') whatever contact.line_tangent says.

With averaged contact normals, `line_tangent: ring` declares for every face a strut could reach the
columns of the nodal normals' rings (the exact tangent's pattern). Without a coupler no stent points
ever arrive (a procedure's balloon-only phase, a solid scene alone), so the solver runs without the
stent contact: with its columns, the predilatation of configs/procedure_stenosis.yaml paid 32 % more
in linear solves for the same factorizations (docs/performance.md "The procedures' contact tangent").
Consistency check: the scene of solid.ranks_consistency (a balloon inflated into a two-layer artery,
exact Newton, MUMPS) with averaged normals and `face`, then `ring`: the same allocated matrix entries
(summary.json timing.matrix_nonzeros) and the same state, bit for bit (the same residual, tangent
and pattern); and the per-contact forces on the artery name no stent contact. The inflation check
(> 0.05 mm) only guards against a run that never loads the wall: the balloon's outer radius 0.49 mm
reaches the artery's lumen (1.4 - 0.6 = 0.8 mm) within the two steps (measured: the balloon moves
0.377 mm, the artery 0.067 mm).

Usage: test_standalone_contact_pattern.py BIN_DIR
"""
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import h5py
import numpy as np
import yaml

HERE = Path(__file__).resolve().parent
SCENE = HERE / "data" / "ranks_balloon_artery.yaml"
sys.path.insert(0, str(HERE.parent / "scenes"))
from checklist import check, finish  # noqa: E402


def run(bin_dir, tangent, tmp):
    scene = yaml.safe_load(SCENE.read_text())
    scene["contact"].update({"line_normals": "averaged", "line_tangent": tangent})
    scene["time"] = {"end": 0.4, "steps": 2}  # the balloon reaches the artery in the second step
    path = tmp / f"{tangent}.yaml"
    path.write_text(yaml.safe_dump(scene))
    run_dir = tmp / tangent
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OPENBLAS_NUM_THREADS="1")
    cmd = ["mpirun", "--oversubscribe", "-n", "1", str(Path(bin_dir) / "solid_solver")]
    r = subprocess.run(cmd + ["--scene", str(path), "--run-dir", str(run_dir)], env=env, capture_output=True, text=True)
    check(r.returncode == 0, f"{tangent}: solid_solver exits 0 (got {r.returncode})")
    if r.returncode != 0:
        print(r.stdout[-3000:], r.stderr[-3000:])
        return None, None
    summary = json.loads((run_dir / "solid" / "summary.json").read_text())
    forces = [set((s.get("artery_contact_force") or {}).keys()) for s in summary["steps"]]
    check(
        any(forces) and not any("stent" in f for f in forces),
        f"{tangent}: contact forces on the artery from {sorted(set().union(*forces))}, no stent contact",
    )
    timing = summary["timing"]
    with h5py.File(run_dir / "solid" / "state.h5", "r") as f:
        u = {p: f["parts"][p]["displacement"][...] for p in f["parts"]}
    return timing, u


with tempfile.TemporaryDirectory() as t:
    tmp = Path(t)
    face, u_face = run(sys.argv[1], "face", tmp)
    ring, u_ring = run(sys.argv[1], "ring", tmp)
    if face and ring:
        nz_face, nz_ring = face.get("matrix_nonzeros"), ring.get("matrix_nonzeros")
        check(nz_face is not None and nz_face > 0, f"summary.json gives the matrix's allocated entries ({nz_face})")
        check(
            nz_ring == nz_face, f"ring without a coupler: the elements' pattern ({nz_ring} against {nz_face} entries)"
        )
        check(u_face.keys() == u_ring.keys(), "the same parts")
        for p in u_face:
            d = float(np.max(np.abs(u_face[p] - u_ring[p])))
            check(d == 0.0, f"{p}: the same state bit for bit (max difference {d:.3e} mm)")
        check(max(float(np.max(np.abs(u))) for u in u_face.values()) > 0.05, "the balloon inflated (> 0.05 mm)")
finish()
