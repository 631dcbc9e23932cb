#!/usr/bin/python3
"""A procedure of three phases (tests/scenes/data/tiny_procedure.yaml: predilatation, stenting,
post-dilatation in a coarse two-layer tube), run by the launcher end to end, and its bad input.

Checks:
  * every phase runs (procedure.json: status ok), each in its own run directory;
  * the state carries over (consistency): at each phase change the artery's displacement at the
    first step of the next phase equals that of the last step of the phase before (matched by
    reference coordinates, to 1e-12 mm), and the stent's positions and plastic curvature in the
    post-dilatation's first step equal those at the end of the stenting;
  * each dilatation leaves a lumen gain over the lumen before the procedure (> 0, minimal lumen
    diameter over the segment the devices cover), the stent stays open (final diameter above the
    crimped one), the per-layer stresses are finite and positive;
  * bad procedures are refused by --check with exit 2 naming the key: phases that overlap, a stent
    removed after deployment, an unknown phase key, time.end outside the phases, a bad value in a
    phase's balloon (found by the solver's own check of that phase).
Usage: test_procedure_short.py BIN_DIR [--keep DIR]
"""
import argparse
import json
import math
import subprocess
import sys
import tempfile
from pathlib import Path

import h5py
import numpy as np
import yaml

ROOT = Path(__file__).resolve().parents[2]
SCENE = ROOT / "tests" / "scenes" / "data" / "tiny_procedure.yaml"
LAUNCH = [sys.executable, str(ROOT / "scripts" / "launch.py")]
sys.path.insert(0, str(Path(__file__).resolve().parent))
from checklist import check, finish  # noqa: E402

ap = argparse.ArgumentParser()
ap.add_argument("bin_dir")
ap.add_argument("--keep", help="run into this directory and keep it")
args = ap.parse_args()
build = str(Path(args.bin_dir).resolve().parent)


def artery_displacement(h5, step):
    """{rounded reference coordinates: displacement} of the artery's nodes (lumen radius 0.8 mm: the
    balloons lie inside r < 0.5 mm) at step index `step` of a solid.h5 (-1: the last written)."""
    with h5py.File(h5) as f:
        X = f["mesh/coordinates"][:]
        keys = sorted(f["steps"].keys(), key=int)
        u = f["steps"][keys[step]]["displacement"][:]
    r = np.hypot(X[:, 0], X[:, 1])
    return {tuple(np.round(x, 9)): d for x, d, rr in zip(X, u, r) if rr > 0.7}


def beam_state(h5, step):
    with h5py.File(h5) as f:
        keys = sorted(k for k in f.keys() if k.startswith("step_"))
        g = f[keys[step]]
        return g["positions"][:], g["accumulated_plastic_curvature"][:]


with tempfile.TemporaryDirectory() as tmp:
    run = Path(args.keep or tmp) / "procedure"
    r = subprocess.run(
        LAUNCH + [str(SCENE), "--run-dir", str(run), "--build-dir", build], capture_output=True, text=True, timeout=1200
    )
    print(r.stdout[-3000:])
    check(r.returncode == 0, f"the procedure runs (exit {r.returncode}){r.stderr[-1500:]}")
    proc = json.loads((run / "procedure.json").read_text()) if (run / "procedure.json").is_file() else {"phases": []}
    names = [p["name"] for p in proc["phases"]]
    check(
        names == ["predilatation", "stenting", "postdilatation"] and all(p["status"] == "ok" for p in proc["phases"]),
        f"three phases, each ok: {[(p['name'], p['status']) for p in proc['phases']]}",
    )
    dirs = [run / f"{k + 1}-{n}" for k, n in enumerate(names)]
    for a, b in zip(dirs, dirs[1:]):
        ua, ub = artery_displacement(a / "solid" / "solid.h5", -1), artery_displacement(b / "solid" / "solid.h5", 0)
        common = set(ua) & set(ub)
        jump = max(float(np.linalg.norm(ua[x] - ub[x])) for x in common) if common else math.inf
        size = max(float(np.linalg.norm(ua[x])) for x in common) if common else 0.0
        check(
            len(common) == len(ua) == len(ub) and jump <= 1e-12 and size > 0.05,
            f"{b.name}: the artery starts where {a.name} ended ({len(common)} nodes, max |u| {size:.4f} mm, "
            f"jump {jump:.2e} mm)",
        )
    if len(dirs) == 3:
        xa, ka = beam_state(dirs[1] / "beam" / "beam.h5", -1)
        xb, kb = beam_state(dirs[2] / "beam" / "beam.h5", 0)
        check(
            np.abs(xa - xb).max() <= 1e-12 and np.abs(ka - kb).max() <= 1e-12 and ka.max() > 0,
            f"the stent enters the post-dilatation as the stenting left it (positions {np.abs(xa - xb).max():.1e} mm, "
            f"plastic curvature {np.abs(ka - kb).max():.1e} 1/mm, max {ka.max():.3f})",
        )
    before = None
    for p in proc["phases"]:
        lum = p.get("lumen") or {}
        before = lum.get("min_diameter_before_procedure")
        gain = lum.get("gain_since_procedure_start")
        check(
            isinstance(gain, float) and gain > 0,
            f"{p['name']}: lumen gain {gain} mm over the lumen before the procedure ({before} mm)",
        )
        st = p.get("stress") or {}
        vals = [v for k in ("at_peak", "end") for b, v in (st.get(k) or {}).items() if b in ("media", "adventitia")]
        check(
            len(vals) == 4 and all(math.isfinite(v) and v > 0 for v in vals),
            f"{p['name']}: per-layer stresses finite and positive {vals}",
        )
    last = proc["phases"][-1] if proc["phases"] else {}
    d = (last.get("stent_diameter") or {}).get("final")
    check(
        isinstance(d, float) and d > 1.3, f"the stent stays open after the post-dilatation (D = {d} mm, crimped 1.15)"
    )
    check((run / "lumen_profiles.png").is_file(), "lumen profiles plotted")
    ins = [(p.get("in_stent") or {}) for p in proc["phases"][1:]]
    check(
        len(ins) == 2
        and all(isinstance(i.get("expansion"), float) and i["expansion"] > 0 for i in ins)
        and ins[1]["min_lumen_diameter_end"] >= ins[0]["min_lumen_diameter_end"] - 0.01,
        f"in-stent lumen and expansion after stenting and post-dilatation "
        f"{[(i.get('min_lumen_diameter_end'), i.get('expansion')) for i in ins]} (the post-dilatation keeps it open)",
    )

    # bad procedures: --check exits 2 naming the key, before anything runs
    base = yaml.safe_load(SCENE.read_text())

    def refused(edit, key, what):
        s = json.loads(json.dumps(base))
        edit(s)
        p = Path(tmp) / "bad.yaml"
        p.write_text(yaml.safe_dump(s, sort_keys=False))
        r = subprocess.run(
            LAUNCH + [str(p), "--check", "--build-dir", build], capture_output=True, text=True, timeout=300
        )
        check(
            r.returncode == 2 and key in r.stderr,
            f"{what}: exit 2 naming {key} (rc {r.returncode}: "
            f"{r.stderr.strip().splitlines()[-1][:200] if r.stderr.strip() else ''})",
        )

    refused(lambda s: s["procedure"][1].update(end=0.5), "procedure[1].end", "phases that overlap")
    refused(lambda s: s["procedure"][2].update(stent=False), "procedure[2].stent", "the stent removed after deployment")
    refused(lambda s: s["procedure"][0].update(ballon={}), "procedure[0].ballon", "an unknown phase key")
    refused(lambda s: s["time"].update(end=3.0), "time.end", "time.end outside the phases")
    refused(
        lambda s: s["procedure"][2]["balloon"]["material"].update(E=-17.0),
        "balloon.material.E",
        "a bad value in a phase's balloon",
    )
    refused(
        lambda s: s["procedure"][0]["balloon"]["mesh"].update(length=6.0),
        "procedure[0].balloon.mesh",
        "a balloon longer than the vessel",
    )
finish()
