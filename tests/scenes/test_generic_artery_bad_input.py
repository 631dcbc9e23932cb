#!/usr/bin/python3
"""Bad input in the generic artery scene's keys is refused through the launcher: exit code 2 and a
message naming the file and the key path (docs/user-guide.md "Scenes"). One case per new key of the artery
procedure: viscous tau <= 0, beta < 0, apposition threshold < 0, a layer without a material,
an unknown key in the viscous branch, too many lumen stations, a stress-average radius of 0, an
axial refinement window outside the tube, a radial progression of 0; a solid Newton atol of the order of
the peak pressure load and a coupling rel_tol of 1 (tolerances that pass a step before it moves);
the interface Newton-Krylov without robin planes, and its section without it;
pressures far outside any clinical range (units mistaken); PETSc options naming a preconditioner or
factorization package that does not exist.
No run directory is created (the launcher asks the executables with --check first).
Usage: test_generic_artery_bad_input.py BIN_DIR
"""
import subprocess
import sys
import tempfile
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[2]
SCENE = ROOT / "configs" / "generic_artery.yaml"
failures = []


def media(s):
    return s["artery"]["layers"]["media"]


CASES = [
    ("viscous tau = 0", lambda s: media(s)["viscous"].update(tau=0.0), "artery.layers.media.viscous.tau"),
    ("viscous beta < 0", lambda s: media(s)["viscous"].update(beta=-0.1), "artery.layers.media.viscous.beta"),
    ("viscous typo", lambda s: media(s)["viscous"].update(taus=0.5), "artery.layers.media.viscous"),
    (
        "apposition threshold < 0",
        lambda s: s["artery"].update(summary={"apposition_threshold": -0.1}),
        "artery.summary.apposition_threshold",
    ),
    (
        "lumen stations huge",
        lambda s: s["artery"].update(summary={"lumen_stations": 10**9}),
        "artery.summary.lumen_stations",
    ),
    ("layer without material", lambda s: s["artery"]["layers"].pop("adventitia"), "artery.layers"),
    (
        "stress average radius 0",
        lambda s: s["artery"].update(summary={"stress_average_radius": 0.0}),
        "artery.summary.stress_average_radius",
    ),
    (
        "axial refinement outside the tube",
        lambda s: s["artery"]["mesh"].update(axial_refinement={"from": -3.0, "to": 8.0, "factor": 2.0}),
        "artery.mesh.axial_refinement.to",
    ),
    (
        "radial progression 0",
        lambda s: s["artery"]["mesh"]["layers"][0].update(progression=0.0),
        "artery.mesh.layers[0].progression",
    ),
    # tolerances that accept a step before it moves (the Newton ladder's atol 1 N ended "ok" uninflated)
    ("solid atol of the order of the load", lambda s: s["solid"]["newton"].update(atol=1.0), "solid.newton.atol"),
    ("coupling rel_tol 1", lambda s: s["coupling"].update(rel_tol=1.0), "coupling.rel_tol"),
    (
        "surface compliance without robin planes",
        lambda s: s["coupling"].update(scheme="dirichlet-neumann", surface_compliance=True),
        "coupling.surface_compliance",
    ),
    (
        "newton-krylov without robin planes",
        lambda s: s["coupling"].update(
            scheme="dirichlet-neumann", surface_compliance=False, acceleration="newton-krylov"
        ),
        "coupling.acceleration",
    ),
    (
        "newton_krylov section with another acceleration",
        lambda s: s["coupling"].update(acceleration="iqn-imvj", newton_krylov={"max_products": 5}),
        "coupling.newton_krylov",
    ),
    # absurd values inside the type's range: a pressure in Pa or kPa taken for MPa
    ("balloon pressure 1e6 MPa", lambda s: s["balloon"]["pressure"].update(value=1.0e6), "balloon.pressure"),
    (
        "blood pressure 85 (mmHg for MPa)",
        lambda s: s["artery"]["blood_pressure"].update(value=85.0),
        "artery.blood_pressure",
    ),
    # PETSc types and packages that do not exist (would fail at the first solve, after the start)
    (
        "unknown preconditioner",
        lambda s: s["solid"].update(petsc_options="-ksp_type preonly -pc_type lux"),
        "solid.petsc_options",
    ),
    (
        "unknown factorization package",
        lambda s: s["solid"].update(petsc_options="-ksp_type preonly -pc_type lu -pc_factor_mat_solver_type mumpz"),
        "solid.petsc_options",
    ),
    ("continuation 1", lambda s: s["solid"]["newton"].update(continuation=1), "solid.newton.continuation"),
    # the old factorization alone (preonly) would be taken for a solve of the current tangent
    (
        "reuse_preconditioner with preonly",
        lambda s: s["solid"]["newton"].update(tangent="exact", reuse_preconditioner=10)
        or s["solid"].update(petsc_options="-ksp_type preonly -pc_type lu -pc_factor_mat_solver_type mumps"),
        "solid.newton.reuse_preconditioner",
    ),
    # kept splits need a preconditioner split per part, a lag that renews them, and a part of the scene
    (
        "reuse_parts without fieldsplit",
        lambda s: s["solid"]["newton"].update(tangent="exact", reuse_preconditioner=10, reuse_parts=["artery"])
        or s["solid"].update(petsc_options="-ksp_type fgmres -pc_type lu -pc_factor_mat_solver_type mumps"),
        "solid.newton.reuse_parts",
    ),
    (
        "reuse_parts without reuse_preconditioner",
        lambda s: s["solid"]["newton"].update(tangent="exact", reuse_parts=["artery"])
        or s["solid"]["newton"].pop("reuse_preconditioner", None),
        "solid.newton.reuse_parts",
    ),
    (
        "reuse_parts naming a missing part",
        lambda s: s["solid"]["newton"].update(tangent="exact", reuse_preconditioner=10, reuse_parts=["stent"]),
        "solid.newton.reuse_parts[0]",
    ),
    # the virtual insertion tool and the contact switch-on time
    (
        "insertion axis of one point",
        lambda s: s["contact"].update(insertion={"axis": [[0, 0, 0]], "radius": 0.7}),
        "contact.insertion.axis",
    ),
    (
        "insertion radius negative",
        lambda s: s["contact"].update(insertion={"axis": [[0, 0, 0], [0, 0, 6]], "radius": -0.7}),
        "contact.insertion.radius",
    ),
    (
        "contact from not a time",
        lambda s: s["contact"].update(stent_artery={"penalty": 10.0, "from": "later"}),
        "contact.stent_artery.from",
    ),
]

with tempfile.TemporaryDirectory() as tmp:
    for name, edit, key in CASES:
        s = yaml.safe_load(SCENE.read_text())
        edit(s)
        scene = Path(tmp) / "bad.yaml"
        scene.write_text(yaml.safe_dump(s, sort_keys=False))
        r = subprocess.run(
            [
                sys.executable,
                str(ROOT / "scripts" / "launch.py"),
                str(scene),
                "--run-dir",
                str(Path(tmp) / name.replace(" ", "_")),
                "--build-dir",
                str(Path(sys.argv[1]).parent),
            ],
            capture_output=True,
            text=True,
            timeout=120,
        )
        out = r.stdout + r.stderr
        # the executables check the scene (--check) before the launcher creates the run directory
        left = (Path(tmp) / name.replace(" ", "_")).exists()
        ok = r.returncode == 2 and f"{scene}: {key}" in out and "Traceback" not in out and not left
        print(
            ("ok   " if ok else "FAIL ") + f"{name}: exit {r.returncode}, names '{key}', "
            f"run directory {'left behind' if left else 'not created'}",
            flush=True,
        )
        if not ok:
            print(out[-1500:])
            failures.append(name)
sys.exit(1 if failures else 0)
