#!/usr/bin/python3
"""The lumen-surface route end to end in CI: a small segmented lesion written by
scripts/make_lesion_surface.py as VTP (8 mm, reference lumen 2 mm, 15 % narrowing, elliptic
section of aspect 1.3 moved 0.1 mm off-center, a wall from 0.6 to 1.2 mm as the point array
wall_thickness, a calcified arc as the label array plaque_label), through the launcher with
configs/lesion_surface.yaml's materials, contact and solvers: blood pressure and the start of the
inflation (12 load steps, a 3-ring stent on a 6.5 mm balloon, tet10 of 0.8 mm).
Checks (consistency with the generated geometry, which is known exactly): exit 0; the artery's
sections are the surface's own (aspect 1.3 recovered within 0.02, the wall range 0.6-1.2 mm within
0.01 mm); the labelled arc became one calcified region spanning the labelled 60-120 deg and the
lesion's half-depth stretch (s = 4 +- 2.08 mm) within a station and a few rays; every element has a
positive Jacobian (gmsh's minimal scaled Jacobian, placement.json); the run reports the calcified
layer beside intima, media and adventitia with finite stresses in every phase and every layer in
tension under blood pressure.
Usage: test_lesion_surface_short.py BIN_DIR   (about 3 minutes)
"""
import json
import math
import subprocess
import sys
import tempfile
from pathlib import Path

import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent))
from checklist import check, finish  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
BIN = sys.argv[1] if len(sys.argv) > 1 else str(ROOT / "build" / "bin")
HALF_DEPTH = 2.5 * math.sqrt(math.log(2.0))  # mm: the generator's Gaussian (width 2.5 mm) above 1/2


def scene():
    s = yaml.safe_load((ROOT / "configs" / "lesion_surface.yaml").read_text())
    s["time"] = {"start": -0.2, "end": 0.04, "steps": 12, "min_step": 0.0005}
    s["output"] = {"every": 2}
    pat = s["patient"]
    pat["lumen_surface"] = {
        "file": "lesion.vtp",
        "units": "mm",
        "plaque": {"array": "plaque_label", "types": ["calcified"], "thickness": 0.2},
    }
    pat.pop("plaque", None)  # the plaque comes from the labels
    pat["mesh"] = {"size": 0.8, "binary": True}
    s["stent"]["generator"].update(rings=3, ring_pitch=1.5)
    s["balloon"]["mesh"].update(length=6.5, n_axial=44)
    s["solid"]["ranks"] = 1
    return s


with tempfile.TemporaryDirectory(prefix="lesion-surface-short-") as tmp:
    tmp = Path(tmp)
    gen = [sys.executable, str(ROOT / "scripts" / "make_lesion_surface.py"), str(tmp / "lesion.vtp")]
    gen += ["--length", "8", "--radius", "1.0", "--narrowing", "0.15", "--aspect", "1.3", "--shift", "0.1"]
    subprocess.run(gen, check=True, capture_output=True)
    (tmp / "scene.yaml").write_text(yaml.safe_dump(scene(), sort_keys=False))
    cmd = [sys.executable, str(ROOT / "scripts" / "launch.py"), str(tmp / "scene.yaml")]
    cmd += ["--build-dir", str(Path(BIN).parent), "--run-dir", str(tmp / "run"), "--timeout", "120"]
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=1500)
    print(p.stdout[-3000:], p.stderr[-3000:])
    check(p.returncode == 0, f"the lesion surface scene runs (exit {p.returncode})")
    if p.returncode == 0:
        run = tmp / "run"
        plc = json.loads((run / "geometry" / "placement.json").read_text())
        sec = plc["lumen_sections"]
        check(abs(sec["aspect_max"] - 1.3) < 0.02, f"the elliptic section recovered (aspect {sec['aspect_max']:.3f})")
        lo, hi = sec["wall_range"]
        check(
            abs(lo - 0.6) < 0.01 and abs(hi - 1.2) < 0.01 and sec["wall_from"] == "surface",
            f"the wall from the surface's array, 0.6-1.2 mm ({lo:.3f}-{hi:.3f})",
        )
        regions = plc["plaque"]
        check(len(regions) == 1 and regions[0]["layer"] == "plaque_calcified", f"one calcified region ({regions})")
        if len(regions) == 1:
            r = regions[0]
            a0, a1 = r["angle"]
            # a station is 0.2 mm here, a ray 7.5 deg; the arc is labelled on the generator's ellipse
            # parameter, which the off-center ellipse turns by up to ~10 deg in the sections' angle
            check(40 <= a0 <= 60 and 120 <= a1 <= 140, f"the region spans the labelled 60-120 deg ({a0}-{a1})")
            check(
                abs(r["from_s"] - (4 - HALF_DEPTH)) < 0.25 and abs(r["to_s"] - (4 + HALF_DEPTH)) < 0.25,
                f"the region spans the labelled s = {4 - HALF_DEPTH:.2f}-{4 + HALF_DEPTH:.2f} mm "
                f"({r['from_s']:.2f}-{r['to_s']:.2f})",
            )
        mesh = plc["artery_mesh"]
        check(
            0.0 < mesh["min_scaled_jacobian"] <= 1.0 and mesh["per_layer"].get("plaque_calcified", 0) > 0,
            f"a valid tet10 mesh with the calcified layer (min sJ {mesh['min_scaled_jacobian']:.3f}, "
            f"{mesh['per_layer']})",
        )
        res = json.loads((run / "results.json").read_text())["artery"]
        layers = res["layers"]
        check(
            set(layers) == {"intima", "media", "adventitia", "plaque_calcified"},
            f"every layer and the plaque reported ({layers})",
        )
        vals = [
            ph["layers"][L][k]
            for ph in res["phases"].values()
            for L in layers
            for k in ("max_principal_stress", "p99_principal_stress")
        ]
        check(all(isinstance(v, float) and math.isfinite(v) for v in vals), "every layer stress finite")
        pre = res["phases"]["prestressed"]["layers"]
        check(
            all(pre[L]["max_principal_stress"] > 0 for L in layers),
            "blood pressure puts every layer, the plaque included, in tension (max principal > 0)",
        )
finish()
