#!/usr/bin/env python3
"""Error against run time for a coupled scene: runs the scene at a ladder of settings for
each discretization knob and reports, per knob and output, the error against the finest run of the
ladder (or its Richardson extrapolation when three runs show a clean convergence order).

  bench/work_precision.py SCENE [--quick]
                            [--knobs steps,coupling_tol,newton_tol,mesh,artery_size,intima_size,artery_mesh,beam]
                            [--levels KNOB=V1,V2 ...] [--tol 0.01] [--out-dir DIR] [--build-dir DIR]
                            [--reuse JSON|RUN_DIR ...]

Knobs (each ladder holds the scene's own setting, "shipped"; the others are kept as shipped):
  steps         time.steps x 1/4, 1/2, 1, 2, 4 (fixed steps: `time.adaptive` is switched off)
  coupling_tol  coupling.rel_tol 1e-2, 3e-3, 1e-3, 3e-4, 1e-4
  newton_tol    solid.newton.rtol 1e-4, 1e-6, 1e-8, 1e-10, atol scaled alike (its ratio to rtol kept)
  mesh          balloon/artery divisions x 1, 1.5, 2 per direction (tube generators; a patient
                artery: patient.mesh.size and refine.size / 1, 1.5, 2)
  artery_size   a patient artery only: patient.mesh.size in mm, x 1, 1/1.5, 1/2 (refine.size scaled
                alike); the balloon's mesh kept, so the ladder isolates the wall's discretization
  intima_size   a patient artery only: the intima's element size over the balloon's span (patient.mesh.
                refine with layers [intima]) 1, 1/2, 1/3.2 of patient.mesh.size (0.8, 0.4, 0.25 mm in
                the shipped scene: to the paper's 0.25 mm), media, adventitia and plaque regions at
                patient.mesh.size; the struts press on the intima, and its stresses are the ones the
                wall's size moves most (docs/validation.md, patient-like artery)
  artery_mesh   a generated tube artery only (artery.mesh.generator: tube): its divisions x 1, 1.5, 2
                per direction, the balloon's kept (the same isolation; --levels artery_mesh=0.667,1.5)
  beam          stent.generator.elements_per_strut (and per connector) 2, 3, 4, 6
--quick: steps x 1/2, 1, 2; coupling_tol 1e-2, 1e-3, 1e-4; beam 2, 3 (a ladder CI can afford on a
short scene).

Outputs of each run (scripts/report.py's results.json): stent diameter at peak and final, recoil
(%), dogboning (%), and for an artery the max and 99th-percentile first principal stress per layer
at peak and after, and its recovered nodal maximum (`<layer>_max_nodal_<phase>`). Error of an output
= |q - q_ref| / |q_ref|. Richardson: with the three finest runs of a geometric ladder (ratio r), the
observed order p = ln(|q1 - q2| / |q2 - q3|) / ln r; when the differences keep their sign and
0.5 <= p <= 8, q_ref = q3 + (q3 - q2) / (r^p - 1) and p is reported.

Written to OUT_DIR: work_precision.json and .csv (every run: knob, level, wall time, outputs,
errors), work_precision.png (error against wall time, log-log, one panel per output, one curve per
knob) and a verdict (also printed): which knob dominates the error at the shipped settings, and per
knob the cheapest setting that keeps every output within --tol.
"""
import argparse
import copy
import csv
import hashlib
import json
import math
import os
import shutil
import subprocess
import sys
import time

import yaml

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "scripts"))  # the tools
from scene_keys import default  # noqa: E402
from scene_variant import coupling_settings, launch_command, resolve_scene, variant_scene  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PYTHON = "/usr/bin/python3" if os.path.exists("/usr/bin/python3") else sys.executable


# ------------------------------------------------------------------------------------------------
# knobs: (levels, apply(scene, level), value in the shipped scene, label, ratio for Richardson)
def _steps_levels(quick):
    return [0.5, 1.0, 2.0] if quick else [0.25, 0.5, 1.0, 2.0, 4.0]


def _set_steps(s, f):
    t = s["time"]
    t["steps"] = max(1, int(round(t["steps"] * f)))
    t.pop("adaptive", None)


def _set_coupling_tol(s, v):
    s.setdefault("coupling", {})["rel_tol"] = v


def _set_newton_tol(s, v):
    # The solid Newton stops at |r| <= atol or |r| <= rtol |r0| (solid_solver model.cpp), so rtol
    # alone does not move a scene whose atol is the looser criterion (the straight scene: rtol
    # 1e-4 ... 1e-10 gave identical results). Both are scaled together, atol keeping its ratio to
    # rtol in the scene (the declared defaults where it gives none).
    nw = s.setdefault("solid", {}).setdefault("newton", {})
    ratio = nw.get("atol", default("solid.newton.atol")) / nw.get("rtol", default("solid.newton.rtol"))
    nw["rtol"] = v
    nw["atol"] = v * ratio


def _scale_tube(s, part, f):
    """A generated tube's divisions (around, along, through each layer) x f, rounded."""
    m = s.get(part, {}).get("mesh")
    if isinstance(m, dict) and m.get("generator") == "tube":
        for k in ("n_circ", "n_axial"):
            if k in m:
                m[k] = max(3, int(round(m[k] * f)))
        for layer in m.get("layers", []):
            n = layer.get("n_radial", default("artery.mesh.layers[0].n_radial"))
            layer["n_radial"] = max(1, int(round(n * f)))


def _set_mesh(s, f):
    for part in ("balloon", "artery"):
        _scale_tube(s, part, f)
    if isinstance(s.get("patient"), dict):
        _set_artery_size(s, _artery_size(s) / f)


def _set_artery_mesh(s, f):
    _scale_tube(s, "artery", f)


def _artery_size(s):
    """A patient artery's element size (mm), the scene's or the declared default."""
    return (s["patient"].get("mesh") or {}).get("size", default("patient.mesh.size"))


def _refine(s):
    """A patient artery's own `patient.mesh.refine` map, or None."""
    r = (s["patient"].get("mesh") or {}).get("refine")
    return r if isinstance(r, dict) else None


def _set_artery_size(s, size):
    refine = _refine(s)
    if refine and "size" in refine:
        refine["size"] *= size / _artery_size(s)  # the fine span keeps its ratio to the rest
    s["patient"].setdefault("mesh", {})["size"] = size


def _set_intima_size(s, size):
    """The intima alone at `size` over the balloon's span (refine's default margins); at the wall's
    own size or above, no refinement (the scene as shipped: the knob is offered only without one)."""
    pm = s["patient"].setdefault("mesh", {})
    if size >= _artery_size(s):
        pm.pop("refine", None)
    else:
        pm["refine"] = {"size": size, "layers": ["intima"]}


def _set_beam(s, n):
    g = s["stent"]["generator"]
    g["elements_per_strut"] = n
    g["elements_per_connector"] = n


def knobs(scene, quick, coupling):
    """coupling: the scene's coupling settings as run (scene_variant.coupling_settings)."""
    nw = scene.get("solid", {}).get("newton", {})
    g = scene.get("stent", {}).get("generator", {})
    out = {
        "steps": (_steps_levels(quick), _set_steps, 1.0, "load steps x", 2.0),
        "coupling_tol": (
            [1e-2, 1e-3, 1e-4] if quick else [1e-2, 3e-3, 1e-3, 3e-4, 1e-4],
            _set_coupling_tol,
            coupling["rel_tol"],
            "coupling rel_tol",
            None,
        ),
        "newton_tol": (
            [1e-4, 1e-6, 1e-8, 1e-10],
            _set_newton_tol,
            nw.get("rtol", default("solid.newton.rtol")),
            "solid Newton rtol (atol alike)",
            100.0,
        ),
        "mesh": ([1.0, 1.5, 2.0], _set_mesh, 1.0, "mesh refinement x", None),
        "beam": (
            [2, 3] if quick else [2, 3, 4, 6],
            _set_beam,
            g.get("elements_per_strut", 3),
            "beam elements per strut",
            None,
        ),
    }
    if "generator" not in scene.get("stent", {}):
        out.pop("beam")
    if (scene.get("artery", {}).get("mesh") or {}).get("generator") == "tube":
        out["artery_mesh"] = ([1.0, 1.5, 2.0], _set_artery_mesh, 1.0, "artery mesh refinement x", None)
    if isinstance(scene.get("patient"), dict):
        h = _artery_size(scene)
        out["artery_size"] = ([h, h / 1.5, h / 2.0], _set_artery_size, h, "artery element size (mm)", None)
        if _refine(scene) is None:
            out["intima_size"] = ([h, h / 2.0, h / 3.2], _set_intima_size, h, "intima element size (mm)", None)
    return out


def is_finer(knob, a, b):
    """True when level a is a finer setting than b."""
    return a < b if knob in ("coupling_tol", "newton_tol", "artery_size", "intima_size") else a > b


# ------------------------------------------------------------------------------------------------
def outputs_of(run_dir):
    """The outputs a user reads, from report.py's results.json (None where absent). The launcher runs
    report.py after every successful run; only a missing results.json is made here."""
    if not os.path.isfile(os.path.join(run_dir, "results.json")):
        subprocess.run([PYTHON, os.path.join(ROOT, "scripts", "report.py"), run_dir], capture_output=True)
    try:
        res = json.load(open(os.path.join(run_dir, "results.json")))
    except (OSError, ValueError):
        return {}
    out = {}
    art = res.get("artery")
    st = res.get("stent", {})
    if art:
        ph = art.get("phases", {})
        out["D_peak"] = ph.get("peak", {}).get("stent_diameter")
        out["D_final"] = ph.get("after", {}).get("stent_diameter")
        for phase in ("peak", "after"):
            for layer, v in (ph.get(phase, {}).get("layers") or {}).items():
                out[f"{layer}_max_{phase}"] = v.get("max_principal_stress")
                out[f"{layer}_p99_{phase}"] = v.get("p99_principal_stress")
                # averaged over a ball of fixed radius: the measure that converges at a strut
                out[f"{layer}_avg_{phase}"] = v.get("max_principal_stress_averaged")
                # recovered at the nodes (report.py): where the element value sits half an element inside
                out[f"{layer}_max_nodal_{phase}"] = v.get("max_principal_stress_nodal")
    else:
        out["D_peak"] = st.get("max")
        out["D_final"] = st.get("final")
    out["recoil_percent"] = st.get("recoil_percent")
    out["dogboning_percent"] = st.get("dogboning_max_percent")
    return {k: v for k, v in out.items() if isinstance(v, (int, float)) and math.isfinite(v)}


def scene_key(scene):
    """The identity of a variant: a hash of its canonical YAML (names its run directory, matches --reuse)."""
    return hashlib.sha1(yaml.safe_dump(scene, sort_keys=True).encode()).hexdigest()[:12]


def run_scene(base_path, scene, out_dir, build_dir, cache, by="work_precision"):
    """Runs `scene` (a variant of base_path) in out_dir/run-<scene_key> unless `cache` holds its key;
    `by` names the calling script in the variant's header (bench/sensitivity.py uses it too)."""
    key = scene_key(scene)
    if key in cache:
        return cache[key]
    run_dir = os.path.join(out_dir, f"run-{key}")
    shutil.rmtree(run_dir, ignore_errors=True)
    with variant_scene(base_path, scene, f"{by}_{key}", f"generated by bench/{by}.py") as path:
        t0 = time.time()
        with open(run_dir + ".out", "w") as log:
            rc = subprocess.call(launch_command(path, run_dir, build_dir), stdout=log, stderr=subprocess.STDOUT)
        wall = time.time() - t0
    r = {
        "run": key,
        "status": "ok" if rc == 0 else f"exit {rc}",
        "wall_s": wall,
        "outputs": outputs_of(run_dir) if rc == 0 else {},
    }
    cache[key] = r
    return r


def reused_run_dir(path):
    """A run made by launch.py as a ladder run: its input scene identifies the variant, its wall time is
    the coupled run's (coupling_summary.json; without the launcher's few seconds before and after)."""
    # the user's scene: scene.input.yaml where the launcher completed it (a patient), else scene.yaml
    given = os.path.join(path, "scene.input.yaml")
    scene = yaml.safe_load(open(given if os.path.isfile(given) else os.path.join(path, "scene.yaml")))
    summary = json.load(open(os.path.join(path, "coupling_summary.json")))
    status = summary["status"]
    return {
        "run": scene_key(scene),
        "status": status,
        "wall_s": float(summary["wall_time"]),
        "outputs": outputs_of(path) if status == "ok" else {},
    }


# ------------------------------------------------------------------------------------------------
def richardson(values, ratio):
    """(q_ref, order) from the three finest runs of a geometric ladder, or (None, None)."""
    if ratio is None or len(values) < 3 or any(v is None for v in values[-3:]):
        return None, None
    q1, q2, q3 = values[-3:]
    d1, d2 = q2 - q1, q3 - q2
    if d1 == 0 or d2 == 0 or (d1 > 0) != (d2 > 0) or abs(d2) >= abs(d1):
        return None, None
    p = math.log(abs(d1) / abs(d2)) / math.log(ratio)
    if not 0.5 <= p <= 8:
        return None, None
    return q3 + d2 / (ratio**p - 1.0), p


def analyse(knob_runs, tol):
    """Errors per run and output, the reference used, and the verdict."""
    verdict = {
        "dominant_at_shipped": None,
        "cheapest_within_tol": {},
        "shipped_errors": {},
        "orders": {},
        "not_estimated": {},
    }
    worst = (0.0, None)
    for knob, k in knob_runs.items():
        runs = [r for r in k["runs"] if r["status"] == "ok"]
        runs.sort(key=lambda r: r["level"], reverse=is_finer(knob, 0, 1))  # coarse -> fine
        if not runs:
            continue
        names = sorted(set().union(*(r["outputs"] for r in runs)))
        for name in names:
            vals = [r["outputs"].get(name) for r in runs]
            q_ext, p = richardson(vals, k["ratio"])
            ref = q_ext if q_ext is not None else vals[-1]
            if p is not None:
                verdict["orders"].setdefault(knob, {})[name] = p
            for r, v in zip(runs, vals):
                if v is not None and ref not in (None, 0):
                    r.setdefault("errors", {})[name] = abs(v - ref) / abs(ref)
                    r.setdefault("reference", {})[name] = "richardson" if q_ext is not None else "finest"
        shipped = [r for r in runs if r["shipped"]]
        # the shipped run as its own reference (finest of the ladder, no Richardson value): its
        # error is unknown, not zero; what is known is how far the next coarser level lies from it
        own_ref = (
            bool(shipped)
            and shipped[0] is runs[-1]
            and all(v == "finest" for v in shipped[0].get("reference", {}).values())
        )
        if own_ref:
            coarser = runs[-2] if len(runs) > 1 else None
            verdict["not_estimated"][knob] = {
                "next_coarser_level": coarser["level"] if coarser else None,
                "its_difference": max(coarser.get("errors", {}).values(), default=0.0) if coarser else None,
            }
        elif shipped:
            e = shipped[0].get("errors", {})
            verdict["shipped_errors"][knob] = e
            m = max(e.values(), default=0.0)
            if m > worst[0]:
                worst = (m, knob)
        ok = [
            r for r in runs if r.get("errors") and max(r["errors"].values()) <= tol and not (own_ref and r is runs[-1])
        ]
        if ok:
            best = min(ok, key=lambda r: r["wall_s"])
            verdict["cheapest_within_tol"][knob] = {"level": best["level"], "wall_s": best["wall_s"]}
    verdict["dominant_at_shipped"] = worst[1]
    return verdict


def plot(knob_runs, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    names = sorted(set().union(*(r.get("errors", {}) for k in knob_runs.values() for r in k["runs"])))
    if not names:
        return False
    cols = min(3, len(names))
    rows = math.ceil(len(names) / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.4 * rows), squeeze=False)
    for ax, name in zip(axes.flat, names):
        for i, (knob, k) in enumerate(knob_runs.items()):
            pts = [
                (r["wall_s"], r["errors"][name], r["shipped"])
                for r in k["runs"]
                if r.get("errors", {}).get(name, 0) > 0
            ]
            if not pts:
                continue
            pts.sort()
            ax.loglog([p[0] for p in pts], [p[1] for p in pts], "o-", color=f"C{i}", label=knob)
            for w, e, shipped in pts:
                if shipped:
                    ax.loglog([w], [e], "*", color=f"C{i}", markersize=12)
        # wall times often span less than a decade: label 1-2-5 ticks instead of the decades only
        ax.xaxis.set_major_locator(matplotlib.ticker.LogLocator(subs=(1.0, 2.0, 5.0)))
        ax.xaxis.set_major_formatter(matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}"))
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set_title(name, fontsize=9)
        ax.set_xlabel("wall time (s)")
        ax.set_ylabel("relative error")
        ax.grid(True, which="both", alpha=0.3)
    axes.flat[0].legend(fontsize=7)
    for ax in list(axes.flat)[len(names) :]:
        ax.axis("off")
    fig.suptitle("error against run time (star: shipped setting)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return True


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene")
    ap.add_argument("--quick", action="store_true", help="coarse ladders (CI)")
    ap.add_argument(
        "--knobs",
        help="comma-separated subset of steps,coupling_tol,newton_tol,mesh,artery_size,intima_size,artery_mesh,beam",
    )
    ap.add_argument("--tol", type=float, default=0.01, help="relative error a setting must keep (default 1 %%)")
    ap.add_argument("--out-dir", default=os.path.join(ROOT, "runs", "work_precision"))
    ap.add_argument("--build-dir", default=os.path.join(ROOT, "build"))
    ap.add_argument(
        "--reuse",
        action="append",
        default=[],
        metavar="JSON|RUN_DIR",
        help="take the runs of an earlier work_precision.json, or a run directory of launch.py, "
        "instead of running them again (matched by the variant scene's hash; repeatable), "
        "e.g. to draw ladders run separately in one diagram or to use a long run made before",
    )
    ap.add_argument(
        "--levels",
        action="append",
        default=[],
        metavar="KNOB=V1,V2",
        help="run these settings of a knob instead of its ladder (the shipped one is always "
        "included; repeatable), e.g. coupling_tol=1e-2 for a scene whose runs take an hour",
    )
    a = ap.parse_args()
    if not (a.tol > 0 and math.isfinite(a.tol)):
        print(f"work_precision: --tol: expected a positive number, got {a.tol}", file=sys.stderr)
        return 2
    base_path = resolve_scene(a.scene)
    if base_path is None:
        print(f"work_precision: {a.scene}: no such scene", file=sys.stderr)
        return 2
    base = yaml.safe_load(open(base_path))
    if not (isinstance(base, dict) and "stent" in base and ("balloon" in base or "artery" in base)):
        print(f"work_precision: {base_path}: expected a coupled scene (stent and balloon/artery)", file=sys.stderr)
        return 2
    try:
        all_knobs = knobs(base, a.quick, coupling_settings(base_path, a.build_dir))
    except (OSError, ValueError) as e:
        print(f"work_precision: {base_path}: cannot read its coupling settings: {e}", file=sys.stderr)
        return 2
    chosen = a.knobs.split(",") if a.knobs else (["steps", "coupling_tol", "beam"] if a.quick else list(all_knobs))
    for k in chosen:
        if k not in all_knobs:
            print(
                f"work_precision: --knobs: unknown knob '{k}', expected some of {','.join(all_knobs)}", file=sys.stderr
            )
            return 2
    cache = {}
    for path in a.reuse:
        try:
            if os.path.isdir(path):
                r = reused_run_dir(path)
                cache[r["run"]] = r
                continue
            earlier = json.load(open(path))
            for kr in earlier["knobs"].values():
                for r in kr["runs"]:
                    cache[r["run"]] = {k: r[k] for k in ("run", "status", "wall_s", "outputs")}
        except (OSError, ValueError, KeyError, TypeError, yaml.YAMLError) as e:
            print(
                f"work_precision: --reuse {path}: expected a work_precision.json or a run directory of "
                f"launch.py (scene.yaml, coupling_summary.json), got {e}",
                file=sys.stderr,
            )
            return 2
    for spec in a.levels:
        knob, _, values = spec.partition("=")
        if knob not in chosen:
            print(
                f"work_precision: --levels {spec}: '{knob}' is not among the knobs run "
                f"({','.join(chosen)}; see --knobs)",
                file=sys.stderr,
            )
            return 2
        try:
            levels = [int(v) if knob == "beam" else float(v) for v in values.split(",")]
        except ValueError:
            levels = []
        if not levels or not all(math.isfinite(v) and v > 0 for v in levels):
            print(
                f"work_precision: --levels {spec}: expected {knob}=V1[,V2...] with positive "
                f"{'integers' if knob == 'beam' else 'numbers'}",
                file=sys.stderr,
            )
            return 2
        all_knobs[knob] = (levels,) + all_knobs[knob][1:]
    os.makedirs(a.out_dir, exist_ok=True)
    knob_runs = {}
    for k in chosen:
        levels, apply, shipped, label, ratio = all_knobs[k]
        if shipped not in levels:
            levels = sorted(set(levels) | {shipped})
        knob_runs[k] = {"label": label, "ratio": ratio, "runs": []}
        for lv in levels:
            s = copy.deepcopy(base)
            if lv != shipped:  # the shipped setting is the base scene itself (adaptive steps included)
                apply(s, lv)
            print(f"[work_precision] {k} = {lv} ...", file=sys.stderr, flush=True)
            r = dict(run_scene(base_path, s, a.out_dir, a.build_dir, cache))
            r.update(level=lv, shipped=(lv == shipped))
            knob_runs[k]["runs"].append(r)
            print(f"[work_precision]   {r['status']}, {r['wall_s']:.1f} s", file=sys.stderr, flush=True)
    verdict = analyse(knob_runs, a.tol)
    doc = {"scene": base_path, "quick": a.quick, "tol": a.tol, "knobs": knob_runs, "verdict": verdict}
    with open(os.path.join(a.out_dir, "work_precision.json"), "w") as f:
        json.dump(doc, f, indent=1)
    names = sorted(set().union(*(r["outputs"] for k in knob_runs.values() for r in k["runs"])))
    with open(os.path.join(a.out_dir, "work_precision.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["knob", "level", "shipped", "status", "wall_s"] + names + [f"err_{n}" for n in names])
        for k, kr in knob_runs.items():
            for r in kr["runs"]:
                w.writerow(
                    [k, r["level"], r["shipped"], r["status"], f"{r['wall_s']:.2f}"]
                    + [r["outputs"].get(n, "") for n in names]
                    + [r.get("errors", {}).get(n, "") for n in names]
                )
    png = os.path.join(a.out_dir, "work_precision.png")
    have_png = plot(knob_runs, png)
    print(f"scene {base_path}")
    for k, kr in knob_runs.items():
        for r in kr["runs"]:
            e = r.get("errors", {})
            worst = max(e.items(), key=lambda kv: kv[1]) if e else ("-", float("nan"))
            print(
                f"  {k:<13}{str(r['level']):>8}{'*' if r['shipped'] else ' '} {r['status']:<8}{r['wall_s']:>8.1f} s"
                f"   worst error {worst[1]:.2e} ({worst[0]})"
            )
    dom = verdict["dominant_at_shipped"]
    print(
        f"verdict: at the shipped settings the largest estimated error comes from '{dom}'"
        f" ({max(verdict['shipped_errors'].get(dom, {}).values(), default=0):.2e})"
        if dom
        else "verdict: no knob with an estimated error changes the outputs measurably at the shipped settings"
    )
    for k, ne in verdict["not_estimated"].items():
        diff = (
            f"; the next coarser level ({ne['next_coarser_level']}) differs from it by up to "
            f"{ne['its_difference']:.2e}"
            if ne["next_coarser_level"] is not None
            else ""
        )
        print(
            f"  {k}: the shipped setting is the finest of this ladder, its own error is not estimated{diff} "
            f"(add finer levels: --levels, or the full ladder without --quick)"
        )
    for k, c in verdict["cheapest_within_tol"].items():
        print(f"  cheapest {k} keeping every output within {100 * a.tol:g} %: {c['level']} ({c['wall_s']:.1f} s)")
    for k, o in verdict["orders"].items():
        print(f"  observed order ({k}): " + ", ".join(f"{n} {p:.2f}" for n, p in sorted(o.items())))
    print(f"(runs in {a.out_dir}; work_precision.json/.csv{', work_precision.png' if have_png else ''})")
    return 0 if all(r["status"] == "ok" for k in knob_runs.values() for r in k["runs"]) else 1


if __name__ == "__main__":
    sys.exit(main())
