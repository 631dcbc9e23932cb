#!/usr/bin/python3
"""Summarize a finished run directory: results table on stdout, results.json, PNG plots.

  python3 scripts/report.py RUN_DIR

Reads what the run produced (scene.yaml, beam/summary.json, solid/summary.json, solid/apposition.csv,
coupling.csv, coupling_summary.json); parts that a scene did not have, and keys that an older or
unfinished run did not write, are skipped (null in results.json). Units: mm, N, MPa, s; the table
prints artery stresses in kPa.

A scene with an artery (paper §4.1) adds its phases: "prestressed" = the last step with t <= 0
(before the balloon pressure rises), "peak" = the step of the largest balloon pressure (without a
balloon pressure in solid/summary.json: the time of the stent's largest diameter), "after" = the
last step. Per phase and artery layer (the blocks whose part is "artery", inside out) the maximum
and the 99th percentile of the first principal Cauchy stress, per element (Gauss-point average) and
recovered at the nodes ("nodal": L2 projection onto the layer's own nodes, which reaches the surface
where the element value sits half an element inside), with the nodal maximum on the lumen surface
("endothelium nodal", the layers that touch it; the paper's endothelial peak of §4.1 compares with
that of the innermost layer), the artery displacement, the lumen
profile (and lumen gain over the stented stations), the apposition of the stent after deflation
and the contact forces on the artery. Plots: diameter_vs_time.png, diameter_vs_pressure.png and,
with an artery, stress_vs_time.png, lumen_profile.png, contact_force_vs_time.png and
artery_stress_peak.png / artery_stress_after.png (the wall cut open, coloured by stress; artery_views.py).
"""
import csv
import json
import math
import re
import sys
from pathlib import Path

try:  # plots are optional: without matplotlib the table and results.json are still written
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    plt = None

try:  # scene.yaml tells which parts the scene has; without PyYAML that is read off the summaries
    import yaml
except ImportError:
    yaml = None

# Paper values for the straight free expansion (§3.1), shown next to ours. Its dogboning, "the ratio
# between the distal and the central radius is 20.4 %" at 10.4 atm, is set beside "typical values
# for e.g. diamond-shaped stents" (its ref. [90]), i.e. the stent's dogboning: we compare it with
# the stent's (D_distal - D_central)/D_distal, the definition of that literature; the balloon's own
# bulge at the stent ends is reported without a paper value.
PAPER = {
    "diameter_initial": 1.15,
    "diameter_max": 2.59,
    "diameter_final": 2.31,
    "recoil": 0.28,
    "recoil_percent": 10.8,
    "dogboning_percent": 20.4,
    "dogboning_atm": 10.4,
}
# Paper §4.1 (stent in the generic artery, Figs. 8-10), used for scenes with a stent and an artery.
# Stent diameter at 13 atm and after deflation (the recoil in mm is their difference); the
# prestressed state (85 mmHg): max artery displacement and max first principal Cauchy stress per
# layer; at 13 atm ("peak") the 7.99 MPa is at the endothelium, i.e. the innermost layer (key
# "innermost"); after deflation per layer. Stresses in MPa.
PAPER_ARTERY = {
    "diameter_initial": 1.15,
    "diameter_peak": 2.12,
    "diameter_final": 1.89,
    "recoil": 0.23,
    "recoil_percent": 10.8,
    "prestressed_max_displacement": 0.14,
    "stress": {
        "prestressed": {"media": 0.0023, "adventitia": 0.00017},
        "peak": {"innermost": 7.99, "adventitia": 0.0495},
        "after": {"media": 0.1875, "adventitia": 0.0137},
    },
}
# Paper §4.2.3 (its patient's right coronary artery, Fig. 12), for patient scenes (a run directory
# with geometry/placement.json): max first principal Cauchy stress per layer, the intima being the
# innermost layer (endothelium); the prestressed media/adventitia values are not stated. A patient
# of our own (configs/patient_like.yaml) is a different artery: the column gives the magnitudes.
PAPER_PATIENT = {
    "stress": {
        "prestressed": {"innermost": 0.0481},
        "peak": {"innermost": 0.757, "media": 0.0783, "adventitia": 0.1359},
        "after": {"innermost": 0.1914, "media": 0.0489, "adventitia": 0.0495},
    }
}
ATM = 0.101325  # MPa
KPA = 1000.0  # kPa per MPa
PHASES = ("prestressed", "peak", "after")


def load_json(p):
    try:
        with open(p) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def load_scene(p):
    if yaml is None:
        return None
    try:
        with open(p) as f:
            scene = yaml.safe_load(f)
    except (OSError, yaml.YAMLError):
        return None
    return scene if isinstance(scene, dict) else None


def num(v):
    """v as a float if it is a finite number, else None."""
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        return None
    return float(v) if math.isfinite(v) else None


def get(d, *keys):
    """d[k0][k1]... or None when a level is missing or not a map."""
    for k in keys:
        if not isinstance(d, dict):
            return None
        d = d.get(k)
    return d


def clean(o):
    """o with every non-finite float replaced by None (results.json holds no NaN/Infinity)."""
    if isinstance(o, float):
        return o if math.isfinite(o) else None
    if isinstance(o, dict):
        return {str(k): clean(v) for k, v in o.items()}
    if isinstance(o, (list, tuple)):
        return [clean(v) for v in o]
    return o


def scaled(v, f):
    v = num(v)
    return None if v is None else v * f


def at_time(seq, t):
    """The entry of seq (dicts with "time") nearest to t, if within round-off of it."""
    if t is None:
        return None
    best = None
    for s in seq:
        ts = num(get(s, "time"))
        if ts is not None and abs(ts - t) <= 1e-6 * (1.0 + abs(t)):
            if best is None or abs(ts - t) < abs(best["time"] - t):
                best = s
    return best


def plot(path, x, y, xlabel, ylabel):
    if plt is None:
        print(f"report: matplotlib not available to {sys.executable}; {path.name} not written")
        return
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(x, y, "o-", ms=3)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_lines(path, series, xlabel, ylabel, logy=False, span=None):
    """Several curves in one plot: series = [(label, x, y, style, color)]; None/non-finite (and on a
    log axis non-positive) values leave gaps. span: (lo, hi) shaded along x (the stent)."""
    if plt is None:
        print(f"report: matplotlib not available to {sys.executable}; {path.name} not written")
        return
    drawn = []
    for label, x, y, style, color in series:
        yy = [float("nan") if num(v) is None or (logy and v <= 0) else v for v in y]
        if any(math.isfinite(v) for v in yy):
            drawn.append((label, x, yy, style, color))
    if not drawn:
        print(f"report: no data for {path.name}; not written")
        return
    fig, ax = plt.subplots(figsize=(6, 4))
    if span:
        ax.axvspan(span[0], span[1], color="0.9", label="stent")
    for label, x, y, style, color in drawn:
        ax.plot(x, y, style, ms=3, label=label, color=color)
    if logy:
        ax.set_yscale("log")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(True, alpha=0.3, which="both" if logy else "major")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


# ------------------------------------------------------------------------------------------------
# artery scenes
def artery_layers(solid, scene):
    """Artery layer (block) names, inside out: the solid blocks whose part is "artery", ordered as
    the scene's artery.mesh.layers list them (a generated tube lists them from the lumen out)."""
    names = [
        b.get("name")
        for b in (get(solid, "blocks") or [])
        if isinstance(b, dict) and b.get("part") == "artery" and isinstance(b.get("name"), str)
    ]
    listed = [l.get("name") for l in (get(scene, "artery", "mesh", "layers") or []) if isinstance(l, dict)]
    return [n for n in listed if n in names] + [n for n in names if n not in listed]


def read_apposition_csv(path):
    """Summary of solid/apposition.csv (the last step that measured apposition), or None."""
    try:
        text = path.read_text().splitlines()
    except OSError:
        return None
    comment = " ".join(l for l in text if l.startswith("#"))
    m_t = re.search(r"at t = (\S+) s", comment)
    m_thr = re.search(r"malapposed if gap > (\S+) mm", comment)
    rows = [l for l in text if l.strip() and not l.startswith("#")]
    n = nmal = 0
    length = mal_len = 0.0
    gaps = []
    try:
        for r in csv.DictReader(rows):
            w, g = float(r["weight"]), float(r["gap"])
            n += 1
            length += w
            if r["malapposed"].strip() == "1":
                nmal += 1
                mal_len += w
            if math.isfinite(g):
                gaps.append(g)
    except (KeyError, ValueError, TypeError, AttributeError):
        return None
    f = lambda s: num(float(s)) if s else None  # noqa: E731
    try:
        t, thr = f(m_t.group(1) if m_t else None), f(m_thr.group(1) if m_thr else None)
    except ValueError:
        t = thr = None
    return {
        "time": t,
        "threshold": thr,
        "points": n,
        "malapposed_points": nmal,
        "stent_length": length,
        "malapposed_length": mal_len,
        "malapposed_fraction": mal_len / length if length > 0 else None,
        "max_gap": max(gaps) if gaps else None,
        "min_gap": min(gaps) if gaps else None,
    }


def _g(v):
    """v formatted with :g, or "-" for None."""
    return "-" if v is None else f"{v:g}"


def _artery_phases(steps, beam, beam_steps):
    """(step per phase, time per phase, how the peak was found) of an artery scene."""
    # phases
    ph = {k: None for k in PHASES}
    times = {k: None for k in PHASES}
    pre = [s for s in steps if s["time"] <= 1e-9]
    if pre:
        ph["prestressed"] = pre[-1]
    peak_source = None
    bp = [(num(s.get("balloon_pressure")), i) for i, s in enumerate(steps)]
    bp = [(p, i) for p, i in bp if p is not None]
    if bp and max(bp)[0] > 0:
        ph["peak"] = steps[max(bp, key=lambda x: (x[0], -x[1]))[1]]
        peak_source = "largest balloon_pressure of solid/summary.json"
    elif num(get(beam, "diameter", "time_of_max")) is not None:
        times["peak"] = num(get(beam, "diameter", "time_of_max"))
        ph["peak"] = at_time(steps, times["peak"])
        peak_source = "time of the stent's largest diameter (beam/summary.json diameter.time_of_max)"
    if steps:
        ph["after"] = steps[-1]
    elif beam_steps:
        times["after"] = beam_steps[-1]["time"]
    for k in PHASES:
        if ph[k] is not None:
            times[k] = ph[k]["time"]
    return ph, times, peak_source


def _balloon_pressures(ph):
    """(balloon pressure at the peak, at the last step), None where not known."""
    return num(get(ph["peak"], "balloon_pressure")), num(get(ph["after"], "balloon_pressure"))


def _phase_entries(ph, times, beam_steps, layers, innermost, pstress):
    """(the results.json "phases" map with per-layer stresses, the notes on them)."""
    phase_out = {}
    for k in PHASES:
        s = ph[k]
        e = {"step": get(s, "step"), "time": times[k]}
        for key, v in (s or {}).items():
            if key.endswith("pressure") and num(v) is not None:
                e[key] = v
        bs = at_time(beam_steps, times[k])
        e["stent_diameter"] = num(get(bs, "diameter"))
        e["max_displacement"] = {part: num(u) for part, u in (get(s, "max_displacement") or {}).items()}
        e["layers"] = {}
        for L in layers:
            paper = pstress.get(k, {}).get(L)
            if paper is None and L == innermost:
                paper = pstress.get(k, {}).get("innermost")
            at = get(s, "max_principal_stress_at", L)
            at_n = get(s, "max_principal_stress_nodal_at", L)
            e["layers"][L] = {
                "max_principal_stress": num(get(s, "max_principal_stress", L)),
                "p99_principal_stress": num(get(s, "p99_principal_stress", L)),
                "max_principal_stress_at": at if isinstance(at, list) else None,
                # averaged over a ball of artery.summary.stress_average_radius (absent in older runs: None)
                "max_principal_stress_averaged": num(get(s, "max_principal_stress_averaged", L)),
                "max_principal_stress_nodal": num(get(s, "max_principal_stress_nodal", L)),
                "p99_principal_stress_nodal": num(get(s, "p99_principal_stress_nodal", L)),
                "max_principal_stress_nodal_at": at_n if isinstance(at_n, list) else None,
                "max_principal_stress_endothelium_nodal": num(get(s, "max_principal_stress_endothelium_nodal", L)),
                "paper_max_principal_stress": paper,
                # the paper's peak "at the endothelial surface" (§4.1): the innermost layer's
                "paper_max_principal_stress_endothelium": pstress.get(k, {}).get("innermost")
                if L == innermost
                else None,
            }
        e["artery_contact_force"] = {n: num(f) for n, f in (get(s, "artery_contact_force") or {}).items()}
        e["apposition"] = get(s, "apposition") if isinstance(get(s, "apposition"), dict) else None
        e["lumen_diameter_min_all_stations"] = num(get(s, "lumen_diameter_min"))
        e["lumen_diameter_max_all_stations"] = num(get(s, "lumen_diameter_max"))
        phase_out[k] = e
    pk_bp, after_bp = _balloon_pressures(ph)
    deflated = None if pk_bp is None or after_bp is None else after_bp <= 0.01 * pk_bp
    phase_out["after"]["deflated"] = deflated
    notes = []
    if deflated is False:
        notes.append(
            f"the run ended at t = {times['after']:g} s with the balloon at {after_bp / ATM:.3g} "
            "atm: the 'after' values are not after deflation"
        )
    return phase_out, notes


def _phase_rows(ph, times):
    """Table rows of the phase times and the balloon pressure at the peak."""
    rows = []
    pk_bp = _balloon_pressures(ph)[0]
    if any(t is not None for t in times.values()):
        rows.append(("artery phases t: prestressed / peak / after (s)", " / ".join(_g(times[k]) for k in PHASES), None))
    if pk_bp is not None:
        rows.append(("  balloon pressure at peak (atm)", pk_bp / ATM, None))
    return rows


def _stent_summary(beam, beam_steps, phase_out, times, P):
    """(the results.json "stent" map: diameter at peak and final, recoil; its table rows)."""
    # stent diameter at the peak-pressure step and after deflation; recoil between the two
    d = get(beam, "diameter") if isinstance(get(beam, "diameter"), dict) else {}
    D_peak = phase_out["peak"]["stent_diameter"]
    D_final = num(get(beam_steps[-1], "diameter")) if beam_steps else None
    if D_final is None:
        D_final = num(d.get("final"))
    recoil = D_peak - D_final if D_peak is not None and D_final is not None else None
    recoil_pct = 100 * recoil / D_peak if recoil is not None and D_peak else None
    stent = {
        "diameter_initial": num(d.get("initial")),
        "diameter_max": num(d.get("max")),
        "time_of_max": num(d.get("time_of_max")),
        "diameter_peak": D_peak,
        "time_peak": times["peak"],
        "diameter_final": D_final,
        "recoil": recoil,
        "recoil_percent": recoil_pct,
        "recoil_definition": "peak-pressure diameter minus final diameter (percent of the peak one)",
    }
    stent_rows = []
    if beam:
        stent_rows += [
            ("stent diameter crimped (mm)", num(d.get("initial")), P.get("diameter_initial")),
            ("stent diameter max (mm)", num(d.get("max")), None),
            ("stent diameter at peak pressure (mm)", D_peak, P.get("diameter_peak")),
            ("stent diameter final (mm)", D_final, P.get("diameter_final")),
            ("elastic recoil, peak - final (mm)", recoil, P.get("recoil")),
            ("elastic recoil, peak - final (%)", recoil_pct, P.get("recoil_percent")),
        ]
    return stent, stent_rows


def _stress_rows(ph, phase_out, layers, P, radius=None):
    """Table rows of the prestressed artery displacement and the stresses per phase and layer (kPa)."""
    rows = []
    # artery displacement and stresses per phase and layer (table in kPa)
    u_pre = num(get(phase_out, "prestressed", "max_displacement", "artery"))
    if u_pre is not None:
        rows.append(("prestressed: max artery displacement (mm)", u_pre, P.get("prestressed_max_displacement")))
    for k in PHASES:
        if ph[k] is None:
            continue
        for L in layers:
            e = phase_out[k]["layers"][L]
            if e["max_principal_stress"] is not None:
                rows.append(
                    (
                        f"{k}: {L} max principal stress (kPa)",
                        e["max_principal_stress"] * KPA,
                        scaled(e["paper_max_principal_stress"], KPA),
                    )
                )
            if k != "prestressed" and e["p99_principal_stress"] is not None:
                rows.append((f"{k}: {L} p99 principal stress (kPa)", e["p99_principal_stress"] * KPA, None))
            if e["max_principal_stress_averaged"] is not None:
                rows.append(
                    (
                        f"{k}: {L} max principal stress, averaged over {radius:g} mm (kPa)",
                        e["max_principal_stress_averaged"] * KPA,
                        None,
                    )
                )
            # recovered nodal values (solid/summary.json *_nodal; absent in older runs: no rows)
            if e["max_principal_stress_nodal"] is not None:
                rows.append(
                    (
                        f"{k}: {L} max principal stress, nodal (kPa)",
                        e["max_principal_stress_nodal"] * KPA,
                        scaled(e["paper_max_principal_stress"], KPA),
                    )
                )
            if e["max_principal_stress_endothelium_nodal"] is not None:
                rows.append(
                    (
                        f"{k}: {L} max principal stress, endothelium nodal (kPa)",
                        e["max_principal_stress_endothelium_nodal"] * KPA,
                        scaled(e["paper_max_principal_stress_endothelium"], KPA),
                    )
                )
            if k != "prestressed" and e["p99_principal_stress_nodal"] is not None:
                rows.append(
                    (f"{k}: {L} p99 principal stress, nodal (kPa)", e["p99_principal_stress_nodal"] * KPA, None)
                )
    return rows


def _lumen_summary(solid, ph):
    """(the results.json "lumen" map, the stent's axial extent (min, max) or None, its table rows)."""
    # lumen
    stations = [num(v) for v in (get(solid, "lumen_stations") or [])]
    lumen = {"stations": stations, "profiles": {}, "min": {}, "stent_extent": None}
    for k in PHASES:
        prof = get(ph[k], "lumen_diameter")
        lumen["profiles"][k] = [num(v) for v in prof] if isinstance(prof, list) else None
    # the stent's axial extent in the station coordinate, as the solid measured it at the last step
    ext = get(ph["after"], "stent_stations")
    ext = (num(ext[0]), num(ext[1])) if isinstance(ext, list) and len(ext) == 2 else None
    ext = ext if ext and None not in ext else None
    how = (
        "solid/summary.json stent_stations of the last step (the beam sample points on the lumen stations)"
        if ext
        else "not determined: no stent_stations in solid/summary.json"
    )
    lumen["stent_extent"] = (
        {"min": ext[0], "max": ext[1], "source": how} if ext else {"min": None, "max": None, "source": how}
    )
    n_st = len(stations)
    mask = [ext is not None and s is not None and ext[0] <= s <= ext[1] for s in stations]
    if any(mask):
        lumen["scope"] = f"stations within the stent's axial extent ({sum(mask)} of {n_st})"
        scope = "stented"
    else:
        mask = [True] * n_st
        lumen["scope"] = "all stations (stent extent " + ("not determined)" if ext is None else "covers no station)")
        scope = "all"
    lumen["stented"] = mask if scope == "stented" else None
    for k in PHASES:
        prof = lumen["profiles"][k]
        vals = [v for v, m in zip(prof, mask) if m and v is not None] if prof and len(prof) == n_st else []
        lumen["min"][k] = min(vals) if vals else None
    a, b = lumen["profiles"]["prestressed"], lumen["profiles"]["after"]
    if a and b and len(a) == len(b) == n_st:
        gain = [y - x if x is not None and y is not None else None for x, y in zip(a, b)]
        g = [v for v, m in zip(gain, mask) if m and v is not None]
        lumen["gain_per_station"] = gain
        lumen["gain_mean"] = sum(g) / len(g) if g else None
    else:
        lumen["gain_per_station"], lumen["gain_mean"] = None, None
    lumen["gain_definition"] = "lumen diameter after minus prestressed, mean over the scope's stations"
    lumen["min_lumen_diameter_gain"] = (
        lumen["min"]["after"] - lumen["min"]["prestressed"]
        if lumen["min"].get("after") is not None and lumen["min"].get("prestressed") is not None
        else None
    )
    rows = []
    where = "stented" if scope == "stented" else "all stations"
    for k in PHASES:
        if lumen["min"].get(k) is not None:
            rows.append((f"min lumen diameter {k}, {where} (mm)", lumen["min"][k], None))
    if lumen["gain_mean"] is not None:
        rows.append((f"lumen gain after - prestressed, mean {where} (mm)", lumen["gain_mean"], None))
    return lumen, ext, rows


def _apposition_summary(run, solid, phase_out, times):
    """(the results.json "apposition" map of the stent after deflation, its table rows)."""
    # apposition after deflation
    thr = num(get(solid, "apposition_threshold"))
    app = phase_out["after"]["apposition"]
    app_csv = read_apposition_csv(run / "solid" / "apposition.csv")
    ap = {
        "threshold": thr,
        "time": times["after"] if app else None,
        "source": "solid/summary.json, last step" if app else None,
    }
    for key in ("stent_length", "malapposed_length", "malapposed_fraction", "max_gap", "mean_gap"):
        ap[key] = num(get(app, key))
    ap["malapposed_percent"] = scaled(ap.get("malapposed_fraction"), 100.0)
    ap["csv"] = app_csv
    rows = []
    if ap["malapposed_percent"] is not None:
        gt = f"gap > {thr:g} mm" if thr is not None else "gap > threshold"
        rows.append((f"malapposed stent length after ({gt}) (%)", ap["malapposed_percent"], None))
    if ap.get("max_gap") is not None:
        rows.append(("max strut-wall gap after (mm)", ap["max_gap"], None))
    return ap, rows


def _contact_force_summary(phase_out):
    """(the results.json "contact_force_at_peak" map or None, its table rows)."""
    # contact forces on the artery at the peak
    cf = phase_out["peak"]["artery_contact_force"]
    rows = []
    for name, f in cf.items():
        if f is not None:
            rows.append((f"contact force {name} -> artery at peak (N)", f, None))
    return cf or None, rows


def _artery_plots(steps, layers, lumen, ext, times):
    """The plot data of an artery scene: stress, lumen and force series, the stent's span, the lumen x axis."""
    # plot data
    t = [s["time"] for s in steps]
    # stresses on a log axis: without the stress-free reference state (step 0, round-off only)
    loaded = [s for s in steps if s.get("step") != 0]
    t_loaded = [s["time"] for s in loaded]
    stress_series = []
    for i, L in enumerate(layers):
        stress_series.append(
            (f"{L} max", t_loaded, [scaled(get(s, "max_principal_stress", L), KPA) for s in loaded], "o-", f"C{i}")
        )
        stress_series.append(
            (f"{L} p99", t_loaded, [scaled(get(s, "p99_principal_stress", L), KPA) for s in loaded], "--", f"C{i}")
        )
        nodal = [scaled(get(s, "max_principal_stress_nodal", L), KPA) for s in loaded]
        if any(v is not None for v in nodal):
            stress_series.append((f"{L} max nodal", t_loaded, nodal, ":", f"C{i}"))
    stations = lumen["stations"]
    n_st = len(stations)
    lumen_series = []
    for i, k in enumerate(PHASES):
        prof = lumen["profiles"][k]
        if prof and (len(prof) == n_st or not n_st):
            x = stations if n_st and all(v is not None for v in stations) else list(range(len(prof)))
            lumen_series.append((f"{k} (t = {_g(times[k])} s)", x, prof, "o-", f"C{i}"))
    names = []
    for s in steps:
        for n in get(s, "artery_contact_force") or {}:
            if n not in names:
                names.append(n)
    force_series = [
        (f"{n} -> artery", t, [num(get(s, "artery_contact_force", n)) for s in steps], "o-", f"C{i}")
        for i, n in enumerate(names)
    ]
    x_is_station = n_st > 0 and all(v is not None for v in stations)
    return {
        "stress": stress_series,
        "lumen": lumen_series,
        "force": force_series,
        "span": ext if (ext and x_is_station) else None,
        "lumen_x": "station" if x_is_station else "index",
    }


def _straightening_rows(straight):
    """Table rows of the artery axis sagitta and radius per phase (straightening of a patient artery)."""
    labels = ["reference"] + [k for k in PHASES if k in straight]
    return [
        (
            f"artery axis sagitta {' / '.join(labels)} (mm)",
            " / ".join(f"{straight[k]['sagitta']:.3f}" for k in labels),
            None,
        ),
        (
            f"artery axis radius {' / '.join(labels)} (mm)",
            " / ".join(f"{straight[k]['radius']:.1f}" for k in labels),
            None,
        ),
    ]


def geometry_dir(run, scene):
    """The patient pipeline's geometry directory of a run (with placement.json): the run's own, or, for
    a run continued from another (launch.py --resume), the one its artery mesh was written to; None
    for a scene without the pipeline."""
    mesh = get(scene, "artery", "mesh", "file")
    for d in [run / "geometry"] + ([(run / str(mesh)).parent] if isinstance(mesh, str) else []):
        if (d / "placement.json").is_file():
            return d
    return None


def artery_report(run, scene, solid, beam, with_paper):
    """Table rows (stent rows, artery rows), the results.json "artery" section and the plot data of an
    artery scene."""
    geometry = geometry_dir(run, scene)
    P = (PAPER_PATIENT if geometry else PAPER_ARTERY) if with_paper else {}
    steps = [s for s in (get(solid, "steps") or []) if isinstance(s, dict) and num(s.get("time")) is not None]
    beam_steps = [s for s in (get(beam, "steps") or []) if isinstance(s, dict) and num(s.get("time")) is not None]
    layers = artery_layers(solid, scene)
    innermost = layers[0] if layers else None

    ph, times, peak_source = _artery_phases(steps, beam, beam_steps)
    phase_out, notes = _phase_entries(ph, times, beam_steps, layers, innermost, P.get("stress", {}))
    section = {
        "units": {"length": "mm", "stress": "MPa", "force": "N", "pressure": "MPa", "time": "s"},
        "layers": layers,
        "innermost_layer": innermost,
        "paper": P or None,
        "phase_definitions": {
            "prestressed": "last step with t <= 0 (before the balloon pressure rises)",
            "peak": peak_source,
            "after": "last step",
        },
        "phases": phase_out,
        "notes": notes,
        # the ball of max_principal_stress_averaged (mm; None in runs before the measure)
        "stress_average_radius": num(get(solid, "stress_average_radius")),
    }
    rows = _phase_rows(ph, times)
    section["stent"], stent_rows = _stent_summary(beam, beam_steps, phase_out, times, P)
    rows += _stress_rows(ph, phase_out, layers, P, section["stress_average_radius"])
    section["lumen"], ext, lumen_rows = _lumen_summary(solid, ph)
    rows += lumen_rows
    section["apposition"], apposition_rows = _apposition_summary(run, solid, phase_out, times)
    rows += apposition_rows
    section["contact_force_at_peak"], force_rows = _contact_force_summary(phase_out)
    rows += force_rows
    plots = _artery_plots(steps, layers, section["lumen"], ext, times)
    straight = artery_straightening(run, geometry, times)
    if straight:
        section["straightening"] = straight
        rows += _straightening_rows(straight)
    return (stent_rows, rows), section, plots


def artery_straightening(run, geometry, times):
    """Bow of a patient artery's lumen axis over the stented section (scripts/patient/straightening.py)."""
    if geometry is None:
        return None
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    try:
        from patient.straightening import artery_axis_bow

        return artery_axis_bow(run, times, geometry)
    except ImportError:  # h5py or numpy missing: the table goes without it
        return None


def _artery_views(run, solid, phases):
    """artery_stress_peak.png and artery_stress_after.png (artery_views.py): the wall cut open, coloured
    by the first principal stress, with the stent; none without h5py/matplotlib."""
    blocks = {
        b["id"]: b["name"] for b in get(solid, "blocks") or [] if isinstance(b, dict) and b.get("part") == "artery"
    }
    views = [(k, num(get(phases, k, "time"))) for k in ("peak", "after")]
    views = [(k, t) for k, t in views if t is not None]
    if not blocks or not views:
        return []
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    try:
        from artery_views import render

        return render(run, views, blocks, [f"artery_stress_{k}.png" for k, _ in views])
    except ImportError:  # h5py or matplotlib missing: the report goes without the pictures
        return []


# ------------------------------------------------------------------------------------------------
def main(run_dir):
    run = Path(run_dir)
    if not run.is_dir():
        sys.exit(f"report: {run}: no such run directory")
    out = {}
    rows = []
    scene = load_scene(run / "scene.yaml")
    beam = load_json(run / "beam" / "summary.json")
    solid = load_json(run / "solid" / "summary.json")
    coupling = load_json(run / "coupling_summary.json")
    beam = beam if isinstance(beam, dict) else None
    solid = solid if isinstance(solid, dict) else None
    coupling = coupling if isinstance(coupling, dict) else None
    steps_csv = []
    try:
        with open(run / "coupling.csv") as f:
            steps_csv = list(csv.DictReader(f))
    except (OSError, csv.Error):
        pass

    # pressure (atm) at a pseudo-time, from the coupler's per-step CSV
    p_of_t = {}
    for r in steps_csv:
        try:
            p_of_t[round(float(r["time"]), 9)] = float(r["pressure"]) / ATM
        except (KeyError, TypeError, ValueError):
            pass  # a truncated last line of a run that stopped
    key_t = lambda t: round(t, 9) if num(t) is not None else None  # noqa: E731

    # which parts: scene.yaml, else what the summaries show
    if scene is not None:
        has_stent, has_artery = "stent" in scene, "artery" in scene
    else:
        has_stent = beam is not None
        has_artery = any(isinstance(b, dict) and b.get("part") == "artery" for b in (get(solid, "blocks") or []))
    artery_with_stent = has_artery and has_stent
    t_start = num(get(scene, "time", "start")) or 0.0

    if beam and not has_artery:
        d = beam.get("diameter") if isinstance(beam.get("diameter"), dict) else {}
        out["stent"] = d
        rows += [
            ("stent diameter crimped (mm)", d.get("initial"), PAPER["diameter_initial"]),
            ("stent diameter max (mm)", d.get("max"), PAPER["diameter_max"]),
            ("stent diameter final (mm)", d.get("final"), PAPER["diameter_final"]),
            ("elastic recoil (mm)", d.get("recoil"), PAPER["recoil"]),
            ("elastic recoil (%)", d.get("recoil_percent"), PAPER["recoil_percent"]),
        ]
    elif beam:
        out["stent"] = beam.get("diameter") if isinstance(beam.get("diameter"), dict) else {}
    artery = artery_report(run, scene, solid, beam, artery_with_stent) if has_artery and (solid or beam) else None
    if artery:
        rows += artery[0][0]
    if beam:
        st = beam.get("stent")
        if isinstance(st, dict):
            out["stent"].update(st)
            tdb = num(st.get("time_of_dogboning_max"))
            free = not has_artery and st.get("axis_radius_initial") is None  # the straight free expansion
            rows += [
                (
                    "stent dogboning max (%)",
                    st.get("dogboning_max_percent"),
                    PAPER["dogboning_percent"] if free else None,
                ),
                ("  at time (s)", st.get("time_of_dogboning_max"), None),
                ("  at pressure (atm)", p_of_t.get(key_t(tdb), "-"), PAPER["dogboning_atm"] if free else None),
                ("foreshortening at max diameter (%)", st.get("foreshortening_at_max_diameter_percent"), None),
                ("foreshortening final (%)", st.get("foreshortening_final_percent"), None),
            ]
            if st.get("axis_radius_initial") is not None:  # curved device: straightening (paper §3.2)
                rows += [
                    (
                        "axis sagitta crimped / max / final (mm)",
                        " / ".join(
                            f"{st[k]:.3f}" if num(st.get(k)) is not None else "-"
                            for k in ("axis_sagitta_initial", "axis_sagitta_at_max_diameter", "axis_sagitta_final")
                        ),
                        None,
                    ),
                    (
                        "axis radius crimped / max / final (mm)",
                        " / ".join(
                            f"{st[k]:.1f}" if num(st.get(k)) is not None else "inf"
                            for k in ("axis_radius_initial", "axis_radius_at_max_diameter", "axis_radius_final")
                        ),
                        None,
                    ),
                ]
                halves = [
                    st.get(k)
                    for k in (
                        "axis_radius_halves_initial",
                        "axis_radius_halves_at_max_diameter",
                        "axis_radius_halves_final",
                    )
                ]
                if all(isinstance(h, list) and len(h) == 2 for h in halves):  # >= 5 rings (beam summary)
                    for i in (0, 1):
                        rows.append(
                            (
                                f"axis radius of half {i} crimped / max / final (mm)",
                                " / ".join(f"{h[i]:.1f}" if num(h[i]) is not None else "inf" for h in halves),
                                None,
                            )
                        )
    if solid:
        out["solid"] = {k: v for k, v in solid.items() if k != "steps"}
        for k, v in solid.items():
            if isinstance(v, (int, float)) and not isinstance(v, bool) and k != "apposition_threshold":
                rows.append((f"solid {k}", v, None))
        dog = [
            (num(get(s, "balloon_outer_diameter", "dogboning")), s)
            for s in (solid.get("steps") or [])
            if isinstance(s, dict)
        ]
        dog = [(v, s) for v, s in dog if v is not None]
        if dog:
            top, at = max(dog, key=lambda x: x[0])
            press = [v for k, v in at.items() if k.endswith("pressure") and num(v) is not None]
            if "balloon_pressure" in at and num(at["balloon_pressure"]) is not None:
                press = [at["balloon_pressure"]]  # an artery scene also has the blood pressure
            out["solid"]["balloon_dogboning_max_percent"] = 100 * top
            out["solid"]["time_of_balloon_dogboning_max"] = at.get("time")
            rows += [
                ("balloon dogboning max (%)", 100 * top, None),
                ("  at pressure (atm)", press[0] / ATM if press else "-", None),
            ]
    if artery:
        rows += artery[0][1]
        out["artery"] = artery[1]
    if coupling:
        out["coupling"] = coupling
        it_mean, it_max = num(coupling.get("coupling_iterations_mean")), coupling.get("coupling_iterations_max")
        share = num(coupling.get("messaging_share"))
        rows += [
            ("load steps", coupling.get("steps"), None),
            (
                "coupling iterations mean / max",
                f"{it_mean:.2f} / {it_max}" if it_mean is not None else f"- / {it_max}",
                None,
            ),
            ("wall time (s)", coupling.get("wall_time"), None),
            ("messaging share (%)", 100 * share if share is not None else None, None),
        ]

    rows = [r for r in rows if r[1] is not None]  # what a run did not write is skipped
    if rows:
        w = max(len(r[0]) for r in rows)
        print(f"{'quantity'.ljust(w)}  {'this run':>12}  {'paper':>8}")
        for name, ours, paper in rows:
            if isinstance(ours, (int, float)) and not isinstance(ours, bool):
                o = f"{ours:12.4g}"
            else:
                o = f"{'-' if ours is None else str(ours):>12}"
            p = f"{paper:8.4g}" if isinstance(paper, (int, float)) else f"{'':>8}"
            print(f"{name.ljust(w)}  {o}  {p}")
        for note in artery[1]["notes"] if artery else []:
            print(f"report: note: {note}")
    else:
        print(f"report: {run}: no summaries found (beam/summary.json, solid/summary.json, coupling_summary.json)")
    try:
        (run / "results.json").write_text(json.dumps(clean(out), indent=2, allow_nan=False) + "\n")
    except OSError as e:
        sys.exit(f"report: cannot write {run / 'results.json'}: {e.strerror}")

    written = []
    if beam and beam.get("steps") and num(get(beam, "diameter", "initial")) is not None:
        bsteps = [s for s in beam["steps"] if isinstance(s, dict) and num(s.get("time")) is not None]
        t = [t_start] + [s["time"] for s in bsteps]
        D = [beam["diameter"]["initial"]] + [s.get("diameter") for s in bsteps]
        plot(run / "diameter_vs_time.png", t, D, "pseudo-time t (s)", "stent diameter (mm)")
        written.append("diameter_vs_time.png")
        if steps_csv:
            pts = [(p_of_t[key_t(s["time"])], s.get("diameter")) for s in bsteps if key_t(s["time"]) in p_of_t]
            if pts:
                plot(
                    run / "diameter_vs_pressure.png",
                    [p for p, _ in pts],
                    [d for _, d in pts],
                    "balloon pressure (atm)",
                    "stent diameter (mm)",
                )
                written.append("diameter_vs_pressure.png")
    if artery:
        pl = artery[2]
        if pl["stress"]:
            plot_lines(
                run / "stress_vs_time.png",
                pl["stress"],
                "pseudo-time t (s)",
                "max first principal stress (kPa); dashed: p99, dotted: nodal max",
                logy=True,
            )
            written.append("stress_vs_time.png")
        if pl["lumen"]:
            plot_lines(
                run / "lumen_profile.png",
                pl["lumen"],
                "station along the vessel axis (mm)" if pl["lumen_x"] == "station" else "station index",
                "lumen diameter (mm)",
                span=pl["span"],
            )
            written.append("lumen_profile.png")
        if pl["force"]:
            plot_lines(
                run / "contact_force_vs_time.png", pl["force"], "pseudo-time t (s)", "contact force on the artery (N)"
            )
            written.append("contact_force_vs_time.png")
    if artery and (run / "solid" / "solid.h5").is_file():
        written += _artery_views(run, solid, artery[1]["phases"])
    written = [n for n in written if (run / n).is_file()]
    print(f"report: {run / 'results.json'}" + (f" and {', '.join(written)}" if written else ""))


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
