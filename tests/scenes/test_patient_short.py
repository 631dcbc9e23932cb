#!/usr/bin/python3
"""The patient pipeline end to end in CI: a tiny curved centerline with a stenosis (8 mm,
CSV x,y,z,r,wall), a 3-ring stent on a 6.5 mm balloon, a coarse tet10 three-layer artery, through
the launcher: blood pressure and the start of the inflation (12 load steps) with configs/patient_like.yaml's
materials, contact and solvers. Checks: exit 0; the placement meets eq. (3) (or the least-squares cubic)
and clears the endothelium by the requested margin; every layer's stresses finite; the fiber frames
written to solid.h5 orthonormal, axial along the lumen centerline tangent and radial away from it
(consistency with the definition, paper §4.2.1); the lumen and stent summaries present. A lesion
narrower than the crimped stent (0.935 mm lumen) through the virtual insertion, to t = 0: the lumen
opened and the wall resting on the stent once the tool is gone. Then bad centerlines and devices
through the launcher: exit 2 naming the file and the problem.
Usage: test_patient_short.py BIN_DIR
"""
import json
import math
import subprocess
import sys
import tempfile
from pathlib import Path

import h5py
import numpy as np
import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent))
from checklist import check, finish  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))
from patient.centerline_csv import arc_length, read_centerline_csv, write_centerline_csv  # noqa: E402
from patient.placement import nearest_on_polyline  # noqa: E402


def tiny_centerline(n=41, length=8.0, bend=12.0):
    s = np.linspace(0.0, length, n)
    pts = np.column_stack([bend * np.sin(s / bend), bend * (1 - np.cos(s / bend)), 0.1 * np.sin(s)])
    bump = np.exp(-(((s - 0.5 * length) / 1.2) ** 2))
    return pts, 0.85 * (1 - 0.2 * bump), 0.7 + 0.3 * bump


def scene_for(csv_name, **edits):
    s = yaml.safe_load((ROOT / "configs" / "patient_like.yaml").read_text())
    s["time"] = {"start": -0.2, "end": 0.04, "steps": 12, "min_step": 0.0005}
    s["output"] = {"every": 2}
    s["patient"]["centerline"] = csv_name
    s["patient"]["mesh"] = {"size": 1.0, "binary": True}
    s["stent"]["generator"].update(rings=3, ring_pitch=1.5)
    s["balloon"]["mesh"].update(length=6.5, n_axial=44)
    s["solid"]["ranks"] = 1
    for k, v in edits.items():
        v(s)
    return s


def launch(tmp, scene, name, run=True):
    path = Path(tmp) / f"{name}.yaml"
    path.write_text(yaml.safe_dump(scene, sort_keys=False))
    cmd = [
        sys.executable,
        str(ROOT / "scripts" / "launch.py"),
        str(path),
        "--build-dir",
        str(Path(BIN).parent),
        "--run-dir",
        str(Path(tmp) / f"run-{name}"),
        "--timeout",
        "120",
    ]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=1500)


BIN = sys.argv[1] if len(sys.argv) > 1 else str(ROOT / "build" / "bin")
with tempfile.TemporaryDirectory(prefix="patient-short-") as tmp:
    pts, r, wall = tiny_centerline()
    write_centerline_csv(Path(tmp) / "tiny.csv", pts, r, wall)
    p = launch(tmp, scene_for("tiny.csv"), "ok")
    print(p.stdout[-3000:], p.stderr[-3000:])
    check(p.returncode == 0, f"the tiny patient scene runs (exit {p.returncode})")
    run = Path(tmp) / "run-ok"
    if p.returncode == 0:
        plc = json.loads((run / "geometry" / "placement.json").read_text())
        cases = [sp["case"] for sp in plc["placement"]["spline"]]
        check(
            all(c in ("eq. (3) holds", "least-squares cubic, residual below zeta") for c in cases),
            f"balloon spline: eq. (3) or the least-squares cubic ({cases})",
        )
        # the clearance recomputed from the files the solvers read (device centerline, lumen CSV)
        dev = np.loadtxt(run / "geometry" / "device_centerline.txt")
        lum_csv = read_centerline_csv(run / "geometry" / "lumen.csv")
        sig = arc_length(dev)
        geo = yaml.safe_load((run / "scene.yaml").read_text())
        gaps = []
        for start, length, radius in (
            (
                geo["balloon"]["mesh"]["start"],
                geo["balloon"]["mesh"]["length"],
                0.5 * geo["balloon"]["mesh"]["outer_diameter"],
            ),
            (
                geo["stent"]["generator"]["start"],
                4.5,
                0.5 * geo["stent"]["generator"]["crimped_diameter"] + geo["stent"]["section"]["radius"],
            ),
        ):
            on = (sig >= start) & (sig <= start + length)
            d, rr = nearest_on_polyline(lum_csv.points, lum_csv.radius, dev[on])
            gaps.append(float((rr - d - radius).min()))
        check(
            min(gaps) >= 0.02 - 1e-3,
            f"devices clear the endothelium by the margin 0.02 mm (balloon {gaps[0]:.4f}, "
            f"stent {gaps[1]:.4f}; 1e-3 for the 0.05 mm sampling of the fit)",
        )
        res = json.loads((run / "results.json").read_text())["artery"]
        check(res["layers"] == ["intima", "media", "adventitia"], f"layers from the mesh ({res['layers']})")
        vals = [
            ph["layers"][L][k]
            for ph in res["phases"].values()
            for L in res["layers"]
            for k in ("max_principal_stress", "p99_principal_stress")
        ]
        check(all(isinstance(v, float) and math.isfinite(v) for v in vals), "every layer stress finite")
        pre = res["phases"]["prestressed"]["layers"]
        check(
            all(pre[L]["max_principal_stress"] > 0 for L in res["layers"]),
            "blood pressure puts every layer in tension (max principal > 0)",
        )
        st = res.get("straightening", {})
        check(
            all(k in st and math.isfinite(st[k]["radius"]) for k in ("reference", "prestressed")),
            f"artery axis bow reported ({ {k: round(v['radius'], 2) for k, v in st.items()} })",
        )
        with h5py.File(run / "solid" / "solid.h5") as f:
            X = f["/mesh/coordinates"][:]
            conn = f["/mesh/tet10/connectivity"][:]
            Fa, Fc, Fr = (f[f"/mesh/tet10/frame_{k}"][:] for k in ("axial", "circumferential", "radial"))
        c = X[conn].mean(axis=1)
        G = np.stack([Fc, Fa, Fr], axis=1)
        check(np.abs(np.einsum("eij,ekj->eik", G, G) - np.eye(3)).max() < 1e-9, "frames orthonormal")
        lum = np.loadtxt(run / "geometry" / "lumen_centerline.txt")
        # tangent of the closest lumen segment at each element centroid
        a, b = lum[:-1], lum[1:]
        d = b - a
        t = np.clip(np.einsum("mij,ij->mi", c[:, None] - a[None], d) / np.einsum("ij,ij->i", d, d)[None], 0, 1)
        foot = a[None] + t[..., None] * d[None]
        k = np.argmin(np.linalg.norm(c[:, None] - foot, axis=2), axis=1)
        tan = d[k] / np.linalg.norm(d[k], axis=1)[:, None]
        check(np.abs(np.einsum("ij,ij->i", Fa, tan)).min() > 0.999, "axial frame along the lumen tangent")
        rad = c - foot[np.arange(len(c)), k]
        check((np.einsum("ij,ij->i", Fr, rad) > 0).all(), "radial frame points away from the centerline")

    # a lesion narrower than the crimped stent (0.935 mm lumen against 1.27 mm): the virtual insertion
    # opens it before the inflation and the wall comes to rest on the stent (to t = 0, the tool gone)
    tight_r = 0.85 * (1 - 0.45 * np.exp(-(((arc_length(pts) - 4.0) / 1.2) ** 2)))
    write_centerline_csv(Path(tmp) / "tight.csv", pts, tight_r, wall)

    def tight(s):
        s["time"] = {"start": -0.2, "end": 0.0, "steps": 10, "min_step": 0.0005}
        s["patient"]["mesh"]["size"] = 0.5  # 1.0 (one tet10 through the intima) inverts elements
        s["solid"]["ranks"] = 2

    p = launch(tmp, scene_for("tight.csv", t=tight), "tight")
    print(p.stdout[-2000:], p.stderr[-2000:])
    check(p.returncode == 0, f"the tight lesion runs with the virtual insertion (exit {p.returncode})")
    if p.returncode == 0:
        run = Path(tmp) / "run-tight"
        plc = json.loads((run / "geometry" / "placement.json").read_text())
        check(
            plc["placement"]["insertion"] and plc["placement"]["clearance"]["stent"] < 0,
            f"placed by insertion, the crimped stent overlapping the wall ({plc['placement']['clearance']})",
        )
        pre = json.loads((run / "results.json").read_text())["artery"]["phases"]["prestressed"]
        lumen = pre["lumen_diameter_min_all_stations"]
        check(lumen > 2 * tight_r.min() + 0.2, f"lumen opened from {2 * tight_r.min():.3f} to {lumen:.3f} mm")
        force = pre["artery_contact_force"]
        check(
            force["stent"] > 0 and force["insertion"] == 0,
            f"at t = 0 the tool is gone and the wall rests on the stent ({force})",
        )

    # a procedure on the patient artery (checked, not run: each phase would cost a run of its own):
    # the pipeline meshes and places once, each phase's balloon goes on the device centerline
    def procedure(s, postdil_length=5.0):
        s["time"] = {"start": -0.2, "min_step": 0.0005}
        s["load_curves"].update(
            predil=[[0.0, 0.0], [0.5, 0.8], [1.0, 0.0]],
            deploy=[[1.0, 0.0], [1.5, 1.3], [2.0, 0.0]],
            postdil=[[2.0, 0.0], [2.5, 1.8], [3.0, 0.0]],
        )
        s["balloon"]["pressure"] = {"value": 1.0, "curve": "deploy"}
        small = {
            **s["balloon"],
            "mesh": {**s["balloon"]["mesh"], "length": 5.0, "n_axial": 34},
            "pressure": {"value": 1.0, "curve": "predil"},
        }
        post = {
            **small,
            "mesh": {**small["mesh"], "length": postdil_length},
            "pressure": {"value": 1.0, "curve": "postdil"},
        }
        s["procedure"] = [
            {"name": "predilatation", "end": 1.0, "steps": 20, "balloon": small},
            {"name": "stenting", "end": 2.0, "steps": 20, "stent": True},
            {"name": "postdilatation", "end": 3.0, "steps": 20, "balloon": post},
        ]

    def check_only(scene, name):
        path = Path(tmp) / f"{name}.yaml"
        path.write_text(yaml.safe_dump(scene, sort_keys=False))
        return subprocess.run(
            [
                sys.executable,
                str(ROOT / "scripts" / "launch.py"),
                str(path),
                "--check",
                "--build-dir",
                str(Path(BIN).parent),
            ],
            capture_output=True,
            text=True,
            timeout=600,
        )

    p = check_only(scene_for("tiny.csv", p=procedure), "procedure")
    check(
        p.returncode == 0 and "the procedure is valid" in p.stdout,
        f"a patient procedure is meshed, placed and every phase checked (exit {p.returncode}) {p.stderr[-300:]}",
    )
    p = check_only(scene_for("tiny.csv", p=lambda s: procedure(s, postdil_length=12.0)), "procedure_long")
    msg = p.stderr.strip().splitlines()[-1] if p.stderr.strip() else ""
    check(
        p.returncode == 2 and "procedure[2].balloon.mesh.length" in msg,
        f"a phase balloon longer than the device centerline: exit {p.returncode}, '{msg[:200]}'",
    )
    # the same launched for a run: the check meshes into the run's geometry/ (once, for the run) and,
    # failing, leaves no run directory behind
    long_scene = Path(tmp) / "procedure_long.yaml"
    long_run = Path(tmp) / "procedure_long_run"
    p = subprocess.run(
        [sys.executable, str(ROOT / "scripts" / "launch.py"), str(long_scene), "--run-dir", str(long_run)]
        + ["--build-dir", str(Path(BIN).parent)],
        capture_output=True,
        text=True,
        timeout=600,
    )
    check(
        p.returncode == 2 and not long_run.exists(),
        f"a procedure whose check fails: exit {p.returncode} (2), run directory left: {long_run.exists()}",
    )

    # bad input: exit 2 naming the file and the problem (before anything is meshed)
    bad = [
        ("three points", lambda: write_centerline_csv(Path(tmp) / "b.csv", pts[:3], r[:3], wall[:3]), {}, "at least 4"),
        (
            "repeated point",
            lambda: write_centerline_csv(
                Path(tmp) / "b.csv", np.vstack([pts[:5], pts[4:]]), np.r_[r[:5], r[4:]], np.r_[wall[:5], wall[4:]]
            ),
            {},
            "repeated",
        ),
        (
            "zero radius",
            lambda: write_centerline_csv(Path(tmp) / "b.csv", pts, np.r_[r[:7], 0.0, r[8:]], wall),
            {},
            "positive lumen radius",
        ),
        (
            "balloon longer than the centerline",
            lambda: write_centerline_csv(Path(tmp) / "b.csv", pts, r, wall),
            {"b": lambda s: s["balloon"]["mesh"].update(length=12.0)},
            "reaches beyond the centerline",
        ),
        (
            "stent does not fit",
            lambda: write_centerline_csv(Path(tmp) / "b.csv", pts, r, wall),
            {
                "s": lambda s: s["stent"]["generator"].update(crimped_diameter=1.6),
                "i": lambda s: s["patient"].update(insertion={"mode": "off"}),
            },
            "does not fit in the lumen",
        ),
        (
            "tight lesion without a phase before the inflation",
            lambda: write_centerline_csv(Path(tmp) / "b.csv", pts, r, wall),
            {
                "s": lambda s: s["stent"]["generator"].update(crimped_diameter=1.6),
                "t": lambda s: s["time"].update(start=0.0),
            },
            "time.start",
        ),
        (
            "unknown patient key",
            lambda: write_centerline_csv(Path(tmp) / "b.csv", pts, r, wall),
            {"k": lambda s: s["patient"].update(stenosys="auto")},
            "did you mean `stenosis`",
        ),
    ]
    for name, make, edits, expect in bad:
        make()
        p = launch(tmp, scene_for("b.csv", **edits), "bad")
        msg = p.stderr.strip().splitlines()[-1] if p.stderr.strip() else ""
        check(
            p.returncode == 2 and expect in msg and ("b.csv" in msg or "bad.yaml" in msg),
            f"{name}: exit {p.returncode}, '{msg[:160]}'",
        )
        check("Traceback" not in p.stderr, f"{name}: no traceback")
        check(not (Path(tmp) / "run-bad").exists(), f"{name}: no run directory left behind")

finish()
