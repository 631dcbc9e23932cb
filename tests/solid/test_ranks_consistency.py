#!/usr/bin/python3
"""Consistency of the distributed solid: 1 vs 2 vs 4 ranks give the same state to round-off.

The scene (data/ranks_balloon_artery.yaml) inflates a balloon into contact with a two-layer artery
whose media has a viscous branch: element assembly across partition boundaries, the displacement
each rank holds (its own nodes, its elements' others, the contact surfaces'), the balloon-artery
contact search and its tangent, the viscous history per Gauss point, the stress summary's reductions
and the state file's gather all depend on the partition. Newton is exact and converged to |r| of
1e-11 N or below, with a direct solver, so two rank counts can differ only by the rounding of their
sums: measured 7e-15 mm of displacement against a maximum of 0.8 mm. A partition bug (a missing ghost
contribution, a contact pair seen by no rank or by two) moves the state by orders of magnitude more
than the tolerances below, which sit far above round-off and far below the Newton tolerance's effect.
4 ranks run oversubscribed on a 2-core machine (ptscotch's partition, not a contiguous split).

Usage: test_ranks_consistency.py BIN_DIR [--ranks 1 2 4] [--keep DIR]
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import h5py
import numpy as np

HERE = Path(__file__).resolve().parent
SCENE = HERE / "data" / "ranks_balloon_artery.yaml"
sys.path.insert(0, str(HERE.parent / "scenes"))
from checklist import check, finish  # noqa: E402

DISPLACEMENT_TOL = 1e-10  # of the largest displacement of the part
STRESS_TOL = 1e-9  # relative, per step and layer


def run(bin_dir, ranks, run_dir):
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OPENBLAS_NUM_THREADS="1")
    cmd = ["mpirun", "--oversubscribe", "-n", str(ranks), str(Path(bin_dir) / "solid_solver")]
    r = subprocess.run(
        cmd + ["--scene", str(SCENE), "--run-dir", str(run_dir)], env=env, capture_output=True, text=True
    )
    check(r.returncode == 0, f"{ranks} rank(s): solid_solver exits 0 (got {r.returncode})")
    if r.returncode != 0:
        print(r.stdout[-3000:], r.stderr[-3000:])
        return None
    with h5py.File(run_dir / "solid" / "state.h5", "r") as f:
        u = {p: f["parts"][p]["displacement"][...] for p in f["parts"]}
    summary = json.loads((run_dir / "solid" / "summary.json").read_text())
    mem = summary["timing"].get("peak_memory_mib_per_rank", [])
    # each rank's peak resident set, gathered: one positive figure per rank, in MiB (a solid rank
    # holding this mesh, PETSc and MPI takes tens of MiB, never more than the machine)
    check(
        len(mem) == ranks and all(10.0 < m < 1e6 for m in mem),
        f"{ranks} rank(s): summary.json gives each rank's peak memory (got {mem} MiB)",
    )
    # the peak before the first solve: one per rank, positive and not above the run's peak
    setup = summary["timing"].get("setup_memory_mib_per_rank", [])
    check(
        len(setup) == ranks and all(0.0 < s <= m for s, m in zip(setup, mem)),
        f"{ranks} rank(s): summary.json gives each rank's memory before the first solve, at most its peak "
        f"(got {setup} against {mem} MiB)",
    )
    # PETSc's point-to-point messages: none on one rank, some on every rank of a partition (each
    # rank shares nodes with another, so its vector scatters and assembly send and receive)
    msgs = summary["timing"].get("petsc_messages_per_rank", [])
    check(
        len(msgs) == ranks and (msgs == [0.0] if ranks == 1 else all(m > 0 for m in msgs)),
        f"{ranks} rank(s): summary.json gives each rank's PETSc messages (got {msgs})",
    )
    # the nodes whose displacement each rank holds: every node on one rank; on more, each rank fewer
    # than all (its own, the rest of its elements', the contact surfaces' and the measured ones) and
    # every node held by its owner at least
    held = summary["timing"].get("held_nodes_per_rank", [])
    total = sum(len(v) for v in u.values())
    check(
        len(held) == ranks
        and (held == [float(total)] if ranks == 1 else all(h < total for h in held) and sum(held) >= total),
        f"{ranks} rank(s): each rank holds the displacement of its part of the {total} nodes (got {held})",
    )
    return u, summary["steps"]


def compare(ranks, ref, other):
    u1, steps1 = ref
    un, stepsn = other
    for part in u1:
        scale = np.abs(u1[part]).max()
        diff = np.abs(u1[part] - un[part]).max()
        check(
            diff <= DISPLACEMENT_TOL * scale,
            f"{ranks} ranks: {part} displacement within {DISPLACEMENT_TOL:g} of "
            f"its maximum {scale:.4g} mm of 1 rank's (max difference {diff:.3g} mm)",
        )
    check(len(steps1) == len(stepsn), f"{ranks} ranks: the same {len(steps1)} steps")
    worst = 0.0
    for key in (
        "max_principal_stress",
        "p99_principal_stress",
        "max_principal_stress_averaged",
        "max_principal_stress_nodal",
        "p99_principal_stress_nodal",
    ):
        # relative to the value, or to 1e-6 of the run's largest value of the measure where the value
        # is round-off of zero (the unloaded artery of the first step: 1e-17 MPa)
        floor = 1e-6 * max(abs(v) for s in steps1 for v in s[key].values())
        for a, b in zip(steps1, stepsn):
            for layer, v in a[key].items():
                worst = max(worst, abs(v - b[key][layer]) / max(abs(v), floor))
    check(
        worst <= STRESS_TOL,
        f"{ranks} ranks: per-layer stresses of every step within {STRESS_TOL:g} "
        f"relative of 1 rank's (worst {worst:.3g})",
    )


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("bin_dir")
    ap.add_argument("--ranks", type=int, nargs="+", default=[1, 2, 4])
    ap.add_argument("--keep", type=Path)
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        base = a.keep or Path(tmp)
        results = {n: run(a.bin_dir, n, base / f"np{n}") for n in a.ranks}
        ref = results[a.ranks[0]]
        if ref is not None:
            # a state that does not change with the partition must also be a loaded one
            media = ref[1][-1]["max_principal_stress"].get("media", 0.0)
            check(media > 0.1, f"the balloon loads the media (max p1 {media:.3g} MPa > 0.1)")
            for n in a.ranks[1:]:
                if results[n] is not None:
                    compare(n, ref, results[n])
    finish()


if __name__ == "__main__":
    main()
