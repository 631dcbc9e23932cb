#!/usr/bin/env python3
"""Benchmark of the shipped coupled scenes: one table row per scene, and the price of the coupling.

  bench/bench_scenes.py                                  # every coupled scene in configs/
  bench/bench_scenes.py straight_free_expansion --compare old.json
  bench/bench_scenes.py configs/generic_artery.yaml --no-alone --json bench.json

Each scene runs through scripts/launch.py (the processes and settings a user gets), then
scripts/report.py derives its results. A row holds: wall time, load steps, rejected attempts
(cuts), coupling iterations (mean, max), solid Newton iterations and factorizations, the time split
(solid assembly of which contact, solid linear solve, beam, messaging), the peak resident memory of
the largest process, and the stent diameter at peak and final. The same balloon (and artery)
without the stent then runs alone (solid-only scene: same steps, solver and loads, `--no-alone`
skips it); coupled/alone is the price of the coupling.

A procedure (a scene with `procedure:`) runs whole, as `angio run` runs it, and gives one row per
coupled phase (`<scene>/<k>-<phase>`, its wall the phase's coupler wall; the whole launch's wall in
`procedure_wall_s`); it has no alone run.

The rows go to a JSON file (--json, default bench_scenes.json in the output directory);
--compare OLD.json prints the ratios new/old per scene and the changes of the results.
Units: s, MiB, mm. Run on an idle machine: the figures are wall times.
"""
import argparse
import copy
import json
import os
import platform
import subprocess
import sys
import time

import yaml

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "scripts"))  # the tools
from scene_variant import launch_command, resolve_scene, variant_scene  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PYTHON = "/usr/bin/python3" if os.path.exists("/usr/bin/python3") else sys.executable


def coupled_scenes():
    out = []
    for name in sorted(os.listdir(os.path.join(ROOT, "configs"))):
        if not name.endswith(".yaml"):
            continue
        s = yaml.safe_load(open(os.path.join(ROOT, "configs", name)))
        if isinstance(s, dict) and "stent" in s and ("balloon" in s or "artery" in s):
            out.append(os.path.join(ROOT, "configs", name))
    return out


def resolve(scene):
    return resolve_scene(scene) or sys.exit(f"bench_scenes: no scene '{scene}' (a path or a name in configs/)")


def alone_scene(scene):
    """The solid-only variant: no stent, no coupling, no stent contact; the rest as in the scene."""
    s = copy.deepcopy(scene)
    s.pop("stent", None)
    s.pop("coupling", None)
    c = s.get("contact")
    if isinstance(c, dict):
        for k in ("stent_balloon", "stent_artery", "line_regularization", "line_normals"):
            c.pop(k, None)
    return s


def launch(scene_path, run_dir, build_dir, ranks):
    """Runs one scene through the launcher; returns (exit code, wall s, peak RSS MiB of the largest process)."""
    cmd = launch_command(scene_path, run_dir, build_dir, *(["--ranks", str(ranks)] if ranks else []))
    log = open(run_dir + ".out", "w")
    t0 = time.time()
    p = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT)
    # wait4: the rusage of the launcher and everything it waited for (mpirun, the solvers);
    # ru_maxrss is the largest resident set of any of them (KiB on Linux)
    _, status, usage = os.wait4(p.pid, 0)
    p.returncode = os.waitstatus_to_exitcode(status)
    return p.returncode, time.time() - t0, usage.ru_maxrss / 1024.0


def load(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return {}


def row_of(name, run_dir, rc, wall, rss):
    c = load(os.path.join(run_dir, "coupling_summary.json"))
    t = load(os.path.join(run_dir, "solid", "summary.json")).get("timing", {})
    subprocess.run([PYTHON, os.path.join(ROOT, "scripts", "report.py"), run_dir], capture_output=True)
    stent = load(os.path.join(run_dir, "results.json")).get("stent", {})
    return {
        "scene": name,
        "status": c.get("status", f"exit {rc}") if rc == 0 else f"exit {rc}",
        "wall_s": wall,
        "steps": c.get("steps"),
        "cuts": c.get("rejected_attempts"),
        "coupling_iterations_total": c.get("coupling_iterations_total"),
        "coupling_iterations_mean": c.get("coupling_iterations_mean"),
        "coupling_iterations_max": c.get("coupling_iterations_max"),
        "solid_ranks": t.get("ranks"),
        "solid_dofs": t.get("dofs"),
        "solid_solves": t.get("solves"),
        "solid_newton_iterations": t.get("newton_iterations"),
        "solid_factorizations": t.get("factorizations"),
        "solid_s": c.get("solid_time"),
        "solid_assembly_s": t.get("assembly_seconds"),
        "solid_contact_s": t.get("contact_seconds"),
        "solid_contact_reply_s": t.get("contact_reply_seconds"),
        "solid_linear_s": t.get("linear_seconds"),
        "beam_s": c.get("beam_time"),
        "messaging_s": c.get("messaging_time"),
        "jacobian_products": c.get("jacobian_products"),
        "product_s": c.get("product_time"),
        "solid_product_s": t.get("interface_product_seconds"),
        "peak_rss_mib": rss,
        "stent_diameter_max": stent.get("max"),
        "stent_diameter_final": stent.get("final"),
        "recoil_percent": stent.get("recoil_percent"),
    }


def procedure_rows(name, run_dir, rc, wall, rss):
    """One row per coupled phase of a procedure's run (<run dir>/<k>-<phase>/ with a coupler's summary)."""
    rows = []
    listed = os.listdir(run_dir) if os.path.isdir(run_dir) else []  # none where the launch refused the scene
    phases = sorted(d for d in listed if os.path.isdir(os.path.join(run_dir, d)) and d[:1].isdigit())
    for phase in phases:
        phase_dir = os.path.join(run_dir, phase)
        c = load(os.path.join(phase_dir, "coupling_summary.json"))
        if not c:
            continue  # a solid-only phase (predilatation), or one the procedure did not reach
        row = row_of(f"{name}/{phase}", phase_dir, 0, c.get("wall_time", float("nan")), rss)
        row["procedure_wall_s"] = wall
        rows.append(row)
    if rc != 0 or not rows:
        rows.append({**row_of(name, run_dir, rc, wall, rss), "status": f"exit {rc}" if rc else "no coupled phase"})
    return rows


def alone_row(run_dir, rc, wall, rss):
    s = load(os.path.join(run_dir, "solid", "summary.json"))
    t = s.get("timing", {})
    return {
        "status": "ok" if rc == 0 else f"exit {rc}",
        "wall_s": wall,
        "steps": len(s.get("steps", [])) - 1,
        "solid_newton_iterations": t.get("newton_iterations"),
        "peak_rss_mib": rss,
    }


def fmt(v, spec):
    return "-" if v is None else format(v, spec)


def scene_width(rows):
    """The scene column: 26 characters, or the longest name (a procedure's phases) and a space."""
    return max([26] + [len(r["scene"]) + 1 for r in rows])


def print_table(rows):
    w = scene_width(rows)
    head = (
        f"{'scene':<{w}}{'status':>7}{'wall s':>9}{'steps':>6}{'cuts':>5}{'it mean':>8}{'it max':>7}"
        f"{'newton':>7}{'LU':>6}{'solid s':>8}{'assem s':>8}{'(cont.)':>8}{'lin s':>7}{'beam s':>7}{'msg s':>6}"
        f"{'MiB':>6}{'D max':>7}{'D fin':>7}{'alone s':>8}{'c/a':>7}"
    )
    print(head)
    for r in rows:
        a = r.get("alone") or {}
        ratio = r["wall_s"] / a["wall_s"] if a.get("wall_s") and a.get("status") == "ok" else None
        print(
            f"{r['scene']:<{w}}{r['status']:>7}{r['wall_s']:>9.1f}{fmt(r['steps'], 'd'):>6}{fmt(r['cuts'], 'd'):>5}"
            f"{fmt(r['coupling_iterations_mean'], '.2f'):>8}{fmt(r['coupling_iterations_max'], 'd'):>7}"
            f"{fmt(r['solid_newton_iterations'], 'd'):>7}{fmt(r['solid_factorizations'], 'd'):>6}"
            f"{fmt(r['solid_s'], '.1f'):>8}"
            f"{fmt(r['solid_assembly_s'], '.1f'):>8}{fmt(r['solid_contact_s'], '.1f'):>8}"
            f"{fmt(r['solid_linear_s'], '.1f'):>7}{fmt(r['beam_s'], '.1f'):>7}{fmt(r['messaging_s'], '.1f'):>6}"
            f"{r['peak_rss_mib']:>6.0f}{fmt(r['stent_diameter_max'], '.3f'):>7}"
            f"{fmt(r['stent_diameter_final'], '.3f'):>7}"
            f"{fmt(a.get('wall_s') if a.get('status') == 'ok' else None, '.1f'):>8}{fmt(ratio, '.2f'):>7}"
        )


def compare(rows, old_path):
    old = {r["scene"]: r for r in load(old_path).get("rows", [])}
    if not old:
        sys.exit(f"bench_scenes: {old_path} holds no rows")
    print(f"\nagainst {old_path} (commit {load(old_path).get('commit', '?')}):")
    w = scene_width(rows)
    print(f"{'scene':<{w}}{'wall old':>9}{'wall new':>9}{'speedup':>8}{'dD max mm':>11}{'dD fin mm':>11}")
    for r in rows:
        o = old.get(r["scene"])
        if not o:
            print(f"{r['scene']:<{w}} (not in the old file)")
            continue

        def d(k):
            return None if r.get(k) is None or o.get(k) is None else r[k] - o[k]

        print(
            f"{r['scene']:<{w}}{o['wall_s']:>9.1f}{r['wall_s']:>9.1f}{o['wall_s'] / r['wall_s']:>8.2f}"
            f"{fmt(d('stent_diameter_max'), '+.4f'):>11}{fmt(d('stent_diameter_final'), '+.4f'):>11}"
        )


def git_commit():
    r = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True)
    dirty = subprocess.run(["git", "-C", ROOT, "diff", "--quiet", "HEAD"]).returncode != 0
    return r.stdout.strip() + ("+changes" if dirty else "")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scenes", nargs="*", help="scene files or names in configs/ (default: every coupled scene)")
    ap.add_argument("--out-dir", default=os.path.join(ROOT, "runs", "bench"), help="run directories go here")
    ap.add_argument("--json", help="rows written here (default: OUT_DIR/bench_scenes.json)")
    ap.add_argument("--compare", metavar="OLD.json", help="rows of an earlier run to compare with")
    ap.add_argument("--no-alone", action="store_true", help="skip the solid-only runs")
    ap.add_argument("--ranks", type=int, help="solid ranks (default: the scene's solid.ranks)")
    ap.add_argument("--build-dir", default=os.path.join(ROOT, "build"))
    a = ap.parse_args()
    scenes = [resolve(s) for s in a.scenes] if a.scenes else coupled_scenes()
    os.makedirs(a.out_dir, exist_ok=True)
    rows = []
    for path in scenes:
        name = os.path.splitext(os.path.basename(path))[0]
        run_dir = os.path.join(a.out_dir, name)
        subprocess.run(["rm", "-rf", run_dir, run_dir + "_alone"])
        print(f"[bench] {name} ...", file=sys.stderr, flush=True)
        rc, wall, rss = launch(path, run_dir, a.build_dir, a.ranks)
        if "procedure" in yaml.safe_load(open(path)):
            rows += procedure_rows(name, run_dir, rc, wall, rss)
            continue
        row = row_of(name, run_dir, rc, wall, rss)
        if not a.no_alone:
            print(f"[bench] {name} alone ...", file=sys.stderr, flush=True)
            with variant_scene(
                path,
                alone_scene(yaml.safe_load(open(path))),
                f"bench_{name}_alone",
                f"generated by bench/bench_scenes.py: {name} without the stent",
                keep=os.path.join(a.out_dir, name + "_alone.yaml"),
            ) as alone_path:
                rc_a, wall_a, rss_a = launch(alone_path, run_dir + "_alone", a.build_dir, a.ranks)
            row["alone"] = alone_row(run_dir + "_alone", rc_a, wall_a, rss_a)
        rows.append(row)
    out = a.json or os.path.join(a.out_dir, "bench_scenes.json")
    doc = {
        "commit": git_commit(),
        "machine": f"{platform.node()} {os.cpu_count()} cpus {platform.processor()}",
        "date": time.strftime("%Y-%m-%d %H:%M"),
        "rows": rows,
    }
    with open(out, "w") as f:
        json.dump(doc, f, indent=1)
    print(f"commit {doc['commit']}, {doc['machine']}, {doc['date']}")
    print_table(rows)
    print(f"(rows in {out})")
    if a.compare:
        compare(rows, a.compare)
    return 0 if all(r["status"] == "ok" for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
