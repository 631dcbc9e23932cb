#!/usr/bin/python3
"""bench/bench_ranks.py end to end on small solid scenes.

  test_bench_ranks.py BIN_DIR

Checks what the scaling table is made of, on real runs (consistency of the bookkeeping):
  * the generated artery under blood pressure (2 steps) at 1 and 2 ranks with its own solver and a
    changed one: a row per change and rank count, each rank's memory, PETSc's messages (none on one
    rank, some on two), the largest rank against the 1-rank run (1 on one rank), and the results
    (every layer's stresses, last step) the same on 1 and 2 ranks to 1e-6 relative (exact Newton to
    rtol 1e-8 / atol 1e-10 N, whatever the Krylov tolerance: ranks differ by round-off, a rank bug by far more);
  * a patient scene (configs/patient_like.yaml) is completed once (meshed, devices placed) and run as
    its solid alone: no stent, the artery's layers in the results;
  * bad study files and options stop with exit 2, naming the file and key.
"""
import csv
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(Path(__file__).resolve().parent))
from checklist import check, finish  # noqa: E402

RANK_TOL = 1e-6


def run(study, out, bin_dir, *extra):
    cmd = ["/usr/bin/python3", str(ROOT / "bench" / "bench_ranks.py"), str(study), "--out-dir", str(out)]
    cmd += ["--build-dir", str(bin_dir.parent), *extra]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=900)
    print(r.stdout[-3000:], r.stderr[-2000:])
    return r


def main():
    bin_dir = Path(sys.argv[1]).resolve()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        study = tmp / "ranks.yaml"
        yaml.safe_dump(
            {
                "base": str(ROOT / "configs" / "solid_artery_blood_pressure.yaml"),
                "common": {"time": {"end": 0.2, "steps": 2}},
                "ranks": [2, 1],
                "changes": [{"name": "gmres_ilu0", "set": {"solid.petsc_options": "-ksp_type gmres -ksp_rtol 1e-10"}}],
            },
            open(study, "w"),
        )
        out = tmp / "out"
        r = run(study, out, bin_dir)
        check(r.returncode == 0, f"bench_ranks.py exits 0 (got {r.returncode})")
        doc = json.load(open(out / "bench_ranks.json"))
        rows = doc["rows"]
        check(
            [(x["name"], x["ranks"]) for x in rows]
            == [("baseline", 1), ("baseline", 2), ("gmres_ilu0", 1), ("gmres_ilu0", 2)],
            "a row per change and rank count, the ranks ascending",
        )
        check(all(x["status"] == "ok" for x in rows), "every run ok")
        for x in rows:
            tag = f"{x['name']}, {x['ranks']} rank(s)"
            check(x["dofs"] == 26640, f"{tag}: the artery's 26,640 DOFs")
            check(10 < x["peak_mib_min"] <= x["peak_mib_mean"] <= x["peak_mib_max"], f"{tag}: memory per rank")
            check(0 <= x["peak_rank"] < x["ranks"], f"{tag}: the largest rank is one of the run's")
            check(x["setup_mib_max"] <= x["peak_mib_max"], f"{tag}: memory before the first solve within the peak")
            check(x["newton_iterations"] >= 2, f"{tag}: Newton iterations counted")
            if x["ranks"] == 1:
                check(x["messages"] == 0, f"{tag}: no PETSc messages on one rank ({x['messages']})")
                check(x["peak_vs_one_rank"] == 1.0, f"{tag}: largest / 1 rank is 1 on one rank")
            else:
                check(x["messages"] > 0 and x["message_mib"] > 0, f"{tag}: PETSc messages between the ranks")
                check(
                    x["messages_per_newton"] == x["messages"] / x["newton_iterations"],
                    f"{tag}: messages per Newton iteration",
                )
                check(0 < x["peak_vs_one_rank"] < 2, f"{tag}: largest / 1 rank ({x['peak_vs_one_rank']:.3f})")
            check(
                set(x["results"]) >= {"media_max_principal_stress", "adventitia_p99_principal_stress"},
                f"{tag}: every layer's stresses compared ({sorted(x['results'])})",
            )
            if x["ranks"] == 1:  # compared with itself: the bookkeeping must pair a run with its own change's
                check(x["results_rel_diff_vs_one_rank"] == 0.0, f"{tag}: the 1-rank run is its own reference")
            else:
                check(
                    x["results_rel_diff_vs_one_rank"] < RANK_TOL,
                    f"{tag}: results as on one rank ({x['results_rel_diff_vs_one_rank']:.1e} < {RANK_TOL})",
                )
        with open(out / "bench_ranks.csv") as f:
            table = list(csv.DictReader(f))
        check(len(table) == 4 and table[1]["ranks"] == "2", "the CSV has the four rows")
        check("| gmres_ilu0 | 2 | ok |" in r.stdout, "the Markdown table has the changed solver's 2-rank row")

        # a patient scene: completed once, run as its solid alone, one rank, one step
        pstudy = tmp / "patient.yaml"
        yaml.safe_dump(
            {
                "base": str(ROOT / "configs" / "patient_like.yaml"),
                "common": {"time": {"start": -0.2, "end": -0.15, "steps": 1, "min_step": 0.0005}},
                "ranks": [1],
                "changes": [{"name": "loose", "set": {"solid.newton.rtol": 1.0e-6}}],
            },
            open(pstudy, "w"),
        )
        pout = tmp / "pout"
        r = run(pstudy, pout, bin_dir, "--only", "baseline")
        check(r.returncode == 0, f"the patient study exits 0 (got {r.returncode})")
        prow = json.load(open(pout / "bench_ranks.json"))["rows"]
        check(len(prow) == 1 and prow[0]["status"] == "ok", "one patient run (--only baseline), ok")
        check((pout / "geometry").is_dir(), "the patient's geometry meshed into OUT_DIR/geometry")
        ran = yaml.safe_load(open(pout / "run-baseline-1" / "scene.yaml"))
        check("stent" not in ran and "patient" not in ran, "the run is the completed scene's solid alone")
        check(
            any(k.startswith("intima_") for k in prow[0].get("results", {})),
            "the patient artery's intima among the results",
        )

        # bad input: exit 2, the file and key named
        def refused(doc, extra, needle, what):
            bad = tmp / "bad.yaml"
            yaml.safe_dump(doc, open(bad, "w"))
            r = run(bad, tmp / "bad_out", bin_dir, *extra)
            check(r.returncode == 2 and needle in r.stderr, f"{what}: exit 2 naming {needle!r} (got {r.returncode})")

        good = yaml.safe_load(open(study))
        refused({**good, "ranks": [0, 2]}, [], "ranks", "a rank count of 0")
        refused({**good, "rank": [1]}, [], "rank: unknown key", "a misspelt key")
        refused(good, ["--ranks", "1,x"], "--ranks", "a bad --ranks")
        refused(good, ["--only", "nope"], "'nope'", "--only with an unknown change")
        patient = yaml.safe_load(open(pstudy))
        refused(
            {**patient, "changes": [{"name": "m", "set": {"patient.mesh.size": 0.4}}]},
            [],
            "patient.mesh.size: the patient is meshed once",
            "a patient key in a change",
        )
        refused(
            {**good, "changes": [{"name": "m", "set": {"solid.nope.x": 1}}]},
            [],
            "solid.nope.x",
            "a key the scene lacks",
        )
    finish()


if __name__ == "__main__":
    main()
