#!/usr/bin/python3
"""bench/work_precision.py --quick in CI on a 4-step variant of the straight free
expansion: every run of the quick ladders (load steps x 1/2, 1, 2; coupling rel_tol 1e-2, 1e-3,
1e-4; beam elements per strut 2, 3) finishes, the JSON/CSV/PNG are written, the finest run of a
ladder without a Richardson reference has zero error, and tightening the coupling tolerance brings
the stent diameter closer to the reference (convergence in the coupling tolerance); --reuse of the
JSON reproduces every run without running it again; --reuse of a run directory with --levels takes
the shipped run from that directory.
Usage: test_work_precision_quick.py BIN_DIR
"""
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent))
from checklist import check, finish  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]


bin_dir = Path(sys.argv[1]).resolve()
with tempfile.TemporaryDirectory(prefix="wp-quick-") as tmp:
    tmp = Path(tmp)
    s = yaml.safe_load(open(ROOT / "configs" / "straight_free_expansion.yaml"))
    s["time"] = {"end": 0.12, "steps": 4}  # 3 % of the inflation: the stent already in contact
    scene = tmp / "wp_short.yaml"
    yaml.safe_dump(s, open(scene, "w"), sort_keys=False)
    out = tmp / "out"
    r = subprocess.run(
        [
            "/usr/bin/python3",
            str(ROOT / "bench" / "work_precision.py"),
            str(scene),
            "--quick",
            "--out-dir",
            str(out),
            "--build-dir",
            str(bin_dir.parent),
        ],
        capture_output=True,
        text=True,
        timeout=1200,
    )
    print(r.stdout[-4000:], r.stderr[-2000:])
    check(r.returncode == 0, f"work_precision.py --quick exits 0 (got {r.returncode})")
    doc = json.load(open(out / "work_precision.json"))
    check(set(doc["knobs"]) == {"steps", "coupling_tol", "beam"}, f"three quick knobs ({sorted(doc['knobs'])})")
    check(
        (out / "work_precision.csv").stat().st_size > 0 and (out / "work_precision.png").stat().st_size > 0,
        "CSV and PNG written",
    )
    for knob, k in doc["knobs"].items():
        check(
            all(r["status"] == "ok" and "D_peak" in r["outputs"] for r in k["runs"]),
            f"{knob}: every run finished with a stent diameter",
        )
        check(sum(r["shipped"] for r in k["runs"]) == 1, f"{knob}: the shipped setting is in the ladder")
    ct = sorted(doc["knobs"]["coupling_tol"]["runs"], key=lambda r: -r["level"])  # 1e-2, 1e-3, 1e-4
    e = [r["errors"]["D_peak"] for r in ct]
    check(ct[-1]["reference"]["D_peak"] != "finest" or e[-1] == 0.0, "the finest run is the reference")
    # strict: the loose tolerance must move the diameter at all (measured 6.8e-5 against 1.2e-7)
    check(e[0] > 0 and e[0] > e[1], f"tighter coupling tolerance, smaller diameter error ({e[0]:.2e} > {e[1]:.2e})")
    check("verdict" in r.stdout, "a verdict is printed")
    # --reuse: the same ladders from the first invocation's JSON, without running anything again
    out2 = tmp / "out2"
    r2 = subprocess.run(
        [
            "/usr/bin/python3",
            str(ROOT / "bench" / "work_precision.py"),
            str(scene),
            "--quick",
            "--out-dir",
            str(out2),
            "--reuse",
            str(out / "work_precision.json"),
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    check(r2.returncode == 0 and not list(out2.glob("run-*")), f"--reuse runs nothing again (rc {r2.returncode})")
    if r2.returncode == 0:
        doc2 = json.load(open(out2 / "work_precision.json"))
        same = all(
            a["outputs"] == b["outputs"]
            for k in doc["knobs"]
            for a, b in zip(doc["knobs"][k]["runs"], doc2["knobs"][k]["runs"])
        )
        check(same, "--reuse gives the same outputs per run")
    # --reuse of a run directory (a long run made by launch.py) and --levels: the shipped run taken
    # from its directory (wall time from its coupling_summary.json), the 1e-2 run from the JSON
    shipped = next(r for r in doc["knobs"]["coupling_tol"]["runs"] if r["shipped"])
    run_dir = out / f"run-{shipped['run']}"
    out3 = tmp / "out3"
    r3 = subprocess.run(
        [
            "/usr/bin/python3",
            str(ROOT / "bench" / "work_precision.py"),
            str(scene),
            "--knobs",
            "coupling_tol",
            "--levels",
            "coupling_tol=1e-2",
            "--out-dir",
            str(out3),
            "--reuse",
            str(out / "work_precision.json"),
            "--reuse",
            str(run_dir),
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    check(
        r3.returncode == 0 and not list(out3.glob("run-*")),
        f"--levels with --reuse of a run directory runs nothing again (rc {r3.returncode}) {r3.stderr[-300:]}",
    )
    if r3.returncode == 0:
        runs3 = json.load(open(out3 / "work_precision.json"))["knobs"]["coupling_tol"]["runs"]
        wall = json.load(open(run_dir / "coupling_summary.json"))["wall_time"]
        check(
            sorted(r["level"] for r in runs3) == [1e-3, 1e-2],
            f"--levels: 1e-2 and the shipped 1e-3 " f"({[r['level'] for r in runs3]})",
        )
        s3 = next(r for r in runs3 if r["shipped"])
        check(
            s3["wall_s"] == wall and s3["outputs"] == shipped["outputs"],
            "the shipped run is the run directory's (its wall time, the same outputs)",
        )

# the mesh knob on a patient artery scales its size and the refined span's alike
sys.path.insert(0, str(ROOT / "bench"))
import work_precision  # noqa: E402

pat = {"patient": {"mesh": {"size": 0.8, "refine": {"size": 0.4, "layers": ["intima"]}}}}
work_precision._set_mesh(pat, 2.0)
check(
    pat["patient"]["mesh"] == {"size": 0.4, "refine": {"size": 0.2, "layers": ["intima"]}},
    f"mesh knob x2 on a patient artery: size and refine.size halved ({pat['patient']['mesh']})",
)

finish()
