#!/usr/bin/python3
"""bench/bench_scenes.py end to end on a 3-step variant of the straight free expansion.

  test_bench_scenes.py BIN_DIR

Checks what the benchmark table is made of, on real runs (consistency of the bookkeeping):
  * the coupled run and its solid-only twin (no stent, no coupling, no stent contact) both finish;
  * the row's counts are consistent: one solid solve per coupling iteration (no step is cut here),
    at most one factorization per Newton iteration or solve, contact time part of the assembly time,
    assembly + linear solve within the solid time the coupler measured;
  * the stent diameter comes from report.py (between the crimped 1.15 mm and 3 mm);
  * --compare against its own JSON prints the scene with a speedup and zero result changes;
  * a procedure (tests/scenes/data/tiny_procedure.yaml) gives one row per coupled phase, named
    <scene>/<k>-<phase>, each phase's wall within the whole launch's.
"""
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(Path(__file__).resolve().parent))
from checklist import check, failures  # noqa: E402


def bench_command(scene, out, bin_dir, *options):
    where = ["--out-dir", str(out), "--build-dir", str(bin_dir.parent)]
    return ["/usr/bin/python3", str(ROOT / "bench" / "bench_scenes.py"), str(scene), *options, *where]


def procedure_rows(bin_dir, tmp):
    scene = ROOT / "tests" / "scenes" / "data" / "tiny_procedure.yaml"
    out = tmp / "procedure_runs"
    r = subprocess.run(bench_command(scene, out, bin_dir, "--no-alone"), capture_output=True, text=True, timeout=900)
    print(r.stdout[-2000:], r.stderr[-1500:])
    check(r.returncode == 0, f"bench_scenes.py on a procedure exits 0 (got {r.returncode})")
    rows = json.load(open(out / "bench_scenes.json"))["rows"]
    phases = yaml.safe_load(open(scene))["procedure"]
    # coupled: the phase that deploys the stent and every phase after it (the stent stays)
    first = next(k for k, p in enumerate(phases) if p.get("stent"))
    coupled = [f"tiny_procedure/{k + 1}-{p['name']}" for k, p in enumerate(phases) if k >= first]
    names = [row["scene"] for row in rows]
    check(names == coupled, f"one row per coupled phase ({names}, expected {coupled})")
    for row in rows:
        check(
            row["status"] == "ok" and row["solid_solves"] >= row["coupling_iterations_total"] > 0,
            f"{row['scene']}: ok, one solid solve per coupling iteration at least ({row['status']}, "
            f"{row['solid_solves']}, {row['coupling_iterations_total']})",
        )
    walls = [row["wall_s"] for row in rows]
    check(
        rows and sum(walls) <= rows[0]["procedure_wall_s"] and all(w > 0 for w in walls),
        f"the phases' walls {walls} within the launch's {rows[0]['procedure_wall_s'] if rows else None}",
    )


def main():
    bin_dir = Path(sys.argv[1]).resolve()
    scene = yaml.safe_load(open(ROOT / "configs" / "straight_free_expansion.yaml"))
    scene["time"] = {"end": 0.06, "steps": 3}  # the nominal step of the shipped scene (0.02 s)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        path = tmp / "bench_short.yaml"
        yaml.safe_dump(scene, open(path, "w"))
        out = tmp / "runs"
        cmd = bench_command(path, out, bin_dir)
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=900)
        print(r.stdout[-3000:], r.stderr[-2000:])
        check(r.returncode == 0, f"bench_scenes.py exits 0 (got {r.returncode})")
        doc = json.load(open(out / "bench_scenes.json"))
        check(len(doc["rows"]) == 1, "one row for one scene")
        row = doc["rows"][0]
        check(
            row["scene"] == "bench_short" and row["status"] == "ok", f"row of bench_short, status ok ({row['status']})"
        )
        check(row["steps"] == 3 and row["cuts"] == 0, f"3 steps, no cuts ({row['steps']}, {row['cuts']})")
        its = row["coupling_iterations_total"]
        check(row["solid_solves"] == its, f"one solid solve per coupling iteration ({row['solid_solves']} vs {its})")
        check(row["solid_dofs"] == 7788 and row["solid_ranks"] == 1, "solid DOFs (1276 hex8 balloon) and ranks")
        check(
            0 < row["solid_factorizations"] <= row["solid_newton_iterations"] + row["solid_solves"],
            "factorizations counted, at most one per Newton iteration or solve",
        )
        check(0 <= row["solid_contact_s"] <= row["solid_assembly_s"], "contact time is part of the assembly time")
        check(
            row["solid_assembly_s"] + row["solid_linear_s"] <= row["solid_s"] * 1.0001,
            "assembly + linear solve fit in the solid time the coupler measured",
        )
        check(row["peak_rss_mib"] > 10, f"peak memory measured ({row['peak_rss_mib']:.0f} MiB)")
        check(
            row["stent_diameter_max"] is not None and 1.15 <= row["stent_diameter_max"] < 3.0,
            f"stent diameter from report.py ({row['stent_diameter_max']})",
        )
        alone = row.get("alone") or {}
        check(alone.get("status") == "ok" and alone.get("steps") == 3, f"the solid-only twin runs 3 steps ({alone})")
        twin = yaml.safe_load(open(out / "bench_short_alone.yaml"))
        check("stent" not in twin and "coupling" not in twin, "the twin has no stent and no coupling section")
        check(
            not any(k in twin.get("contact", {}) for k in ("stent_balloon", "stent_artery")),
            "the twin has no stent contact",
        )
        r2 = subprocess.run(
            cmd + ["--compare", str(out / "bench_scenes.json"), "--no-alone", "--json", str(tmp / "second.json")],
            capture_output=True,
            text=True,
            timeout=900,
        )
        print(r2.stdout[-1500:])
        lines = [l for l in r2.stdout.splitlines() if l.startswith("bench_short")]
        check(r2.returncode == 0 and len(lines) == 2, "--compare prints the table row and the comparison row")
        if len(lines) == 2:
            f = lines[1].split()
            check(
                float(f[3]) > 0 and f[4] in ("+0.0000", "-0.0000") and f[5] in ("+0.0000", "-0.0000"),
                f"comparison: a speedup and unchanged diameters ({lines[1]})",
            )
        procedure_rows(bin_dir, tmp)
    print(f"{len(failures)} failure(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
